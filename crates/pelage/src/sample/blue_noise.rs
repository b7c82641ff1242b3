//! Blue-noise samples: candidates drawn [`OVERSAMPLING`] times over and
//! thinned by dart throwing, run in parallel the way Wei's parallel
//! Poisson disk sampling runs it (Wei 2008, "Parallel Poisson Disk
//! Sampling"); Sik's stated future work ("better than random" placement).
//!
//! - **Conflicts.** Two candidates conflict when they lie closer than
//!   [`SPACING`]` · (r_i + r_j)`. The radius follows the density,
//!   `r = √(1 / (2√3 ρ))` with `ρ` the samples a unit area expects there
//!   (Yuksel's `r_max`, half the spacing of a hexagonal packing), so the
//!   samples still follow the map while neighbours keep their distance.
//!   Radii are capped at [`RADIUS_CAP`] times the median, which bounds the
//!   widest conflict.
//! - **Dart throwing in phases.** Space is cut into grid cells twice as
//!   wide as the widest conflict and coloured by the parities of their
//!   coordinates (eight colours). Two cells of one colour are a cell
//!   apart, so they never see each other's candidates: the cells of a
//!   colour are decided in parallel, one colour after another. Within a
//!   cell the candidates come in their order of arrival (a stream's `k`-th
//!   of `m` at `k / m`, so streams interleave), and one is kept when no
//!   kept candidate conflicts with it; its conflicts can only lie in the
//!   eight cells around the corner of its cell it is nearest. The result
//!   depends on nothing but the candidates: the same on any number of
//!   threads, and no seams anywhere.
//! - **The count.** Each unit (a groom's part, or the whole mesh) keeps
//!   exactly the count asked of it. [`SPACING`] is set so that dart
//!   throwing keeps about 2 % more than asked; a unit then drops its last
//!   arrivals (a few holes, never a close pair). Where a unit kept too
//!   few, rejected candidates come back in order of arrival, each only as
//!   far from the kept ones as a spacing lowered pass by pass allows.
//!
//! Where the time goes is timed in [`BlueNoiseTimes`]. Yuksel's weighted
//! sample elimination, which pelage used before, spaces the samples a
//! little more evenly but removes one candidate at a time from a global
//! priority queue: serial, and about thirty times slower
//! (docs/benchmarks/sampler.md).

use super::{DensitySampler, SurfaceSampler, mix64, salts, sample_range};
use crate::mesh::{Mesh, SurfacePoint};
use glam::Vec3;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Candidates drawn for each sample kept.
pub const OVERSAMPLING: u64 = 2;

/// Two candidates conflict closer than `SPACING · (r_i + r_j)`: at two
/// candidates a sample, dart throwing then keeps about 2 % more than
/// asked (measured on spot and blub, uniform and noise densities).
pub const SPACING: f32 = 0.51;

/// Radii are capped at this many times the median radius; the grid's
/// cells are twice as wide as the widest conflict this allows (wider
/// cells were faster up to four times the median, measured on the
/// Stubble figure).
pub const RADIUS_CAP: f32 = 4.0;

/// Seconds spent in each step of [`blue_noise_samples`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BlueNoiseTimes {
    /// Drawing the candidates, their positions and radii.
    pub candidates: f64,
    /// Sorting the candidates into grid cells and indexing the cells.
    pub neighbours: f64,
    /// Dart throwing and each unit's count.
    pub elimination: f64,
}

/// Candidates `candidates` of which exactly `keep` are kept.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unit {
    /// The unit's candidates, in their order of arrival.
    pub candidates: Range<usize>,
    /// How many of them are kept.
    pub keep: usize,
}

/// `n` points of `sampler` over `mesh`, thinned to blue noise from
/// [`OVERSAMPLING`]` · n` candidates of stream `seed`, in candidate order;
/// the same on any number of threads.
pub fn blue_noise_samples(
    sampler: &DensitySampler,
    mesh: &Mesh,
    seed: u64,
    n: u64,
) -> Vec<SurfacePoint> {
    blue_noise_samples_timed(sampler, mesh, seed, n).0
}

/// [`blue_noise_samples`] and where its time went.
pub fn blue_noise_samples_timed(
    sampler: &DensitySampler,
    mesh: &Mesh,
    seed: u64,
    n: u64,
) -> (Vec<SurfacePoint>, BlueNoiseTimes) {
    let mut times = BlueNoiseTimes::default();
    let started = Instant::now();
    let stream = mix64(seed ^ mix64(salts::BLUE_NOISE));
    let candidates = sample_range(sampler, stream, 0..OVERSAMPLING * n);
    let (positions, radii) = positions_and_radii(sampler, mesh, &candidates, n);
    times.candidates = started.elapsed().as_secs_f64();
    let unit = Unit {
        candidates: 0..candidates.len(),
        keep: n as usize,
    };
    let arrivals: Vec<u32> = (0..candidates.len())
        .map(|k| arrival(k, candidates.len()))
        .collect();
    let kept = thin_timed(&positions, &radii, &arrivals, &[unit], &mut times);
    let points = candidates
        .into_iter()
        .zip(kept)
        .filter_map(|(c, k)| k.then_some(c))
        .collect();
    (points, times)
}

/// Each candidate's position, and the radius `√(1 / (2√3 ρ))` of the
/// density `ρ = n · pdf` of `n` kept samples there.
pub(crate) fn positions_and_radii(
    sampler: &impl SurfaceSampler,
    mesh: &Mesh,
    candidates: &[SurfacePoint],
    n: u64,
) -> (Vec<Vec3>, Vec<f32>) {
    candidates
        .par_iter()
        .map(|c| (c.position(mesh), radius(n as f64 * sampler.pdf(*c))))
        .unzip()
}

/// The radius `√(1 / (2√3 ρ))` of samples of density `ρ`.
pub fn radius(density: f64) -> f32 {
    (1.0 / (2.0 * 3f64.sqrt() * density.max(1e-30))).sqrt() as f32
}

/// Candidate `k` of a stream of `len`: its place `k / len` in 32 bits,
/// the order in which dart throwing takes candidates.
pub fn arrival(k: usize, len: usize) -> u32 {
    (((k as u64) << 32) / len.max(1) as u64) as u32
}

/// Thins the candidates at `positions` (radii `radii`, order of arrival
/// `arrivals`, see [`arrival`]) to blue noise, each unit keeping exactly
/// its count: whether each candidate is kept. The units cover the
/// candidates one after another.
///
/// # Panics
/// When the units do not cover the candidates in order, or the arrays'
/// lengths differ.
pub fn thin(positions: &[Vec3], radii: &[f32], arrivals: &[u32], units: &[Unit]) -> Vec<bool> {
    thin_timed(
        positions,
        radii,
        arrivals,
        units,
        &mut BlueNoiseTimes::default(),
    )
}

/// [`thin`], adding its steps' seconds to `times`.
pub(crate) fn thin_timed(
    positions: &[Vec3],
    radii: &[f32],
    arrivals: &[u32],
    units: &[Unit],
    times: &mut BlueNoiseTimes,
) -> Vec<bool> {
    let m = positions.len();
    assert!(
        radii.len() == m && arrivals.len() == m,
        "one radius and arrival a candidate"
    );
    let mut end = 0;
    for u in units {
        assert_eq!(
            u.candidates.start, end,
            "the units cover the candidates in order"
        );
        end = u.candidates.end;
    }
    assert_eq!(end, m, "the units cover the candidates in order");
    let started = Instant::now();
    let Some(grid) = Grid::new(positions, radii, arrivals) else {
        return Vec::new();
    };
    times.neighbours += started.elapsed().as_secs_f64();
    let started = Instant::now();
    let kept_here: Vec<AtomicBool> = (0..m).map(|_| AtomicBool::new(false)).collect();
    for phase in &grid.phases {
        phase
            .par_iter()
            .with_min_len(64)
            .for_each_init(DartScratch::default, |scratch, &c| {
                grid.throw_darts(c as usize, &kept_here, scratch)
            });
    }
    let mut kept = vec![false; m];
    for (s, k) in kept_here.into_iter().enumerate() {
        kept[grid.index[s] as usize] = k.into_inner();
    }
    grid.fix_counts(units, arrivals, &mut kept);
    times.elimination += started.elapsed().as_secs_f64();
    kept
}

/// Offsets of a cell's 27 neighbours (itself at [`SELF`]) are numbered
/// `(dx + 1) + 3 (dy + 1) + 9 (dz + 1)`.
const SELF: usize = 13;

/// The coordinates whose parity a step to neighbour `slot` flips, as
/// colour bits.
fn parity_flips(slot: usize) -> u64 {
    let [x, y, z] = offset(slot).map(|d| (d != 0) as u64);
    x | y << 1 | z << 2
}

/// A neighbour's offset from its number.
fn offset(slot: usize) -> [i64; 3] {
    [slot % 3, slot / 3 % 3, slot / 9].map(|d| d as i64 - 1)
}

/// A worker's buffers for [`Grid::throw_darts`].
#[derive(Default)]
struct DartScratch {
    /// The kept candidates of the neighbours decided before, neighbour by
    /// neighbour (`slots[n]` is neighbour `n`'s range).
    around: Vec<[f32; 4]>,
    slots: [(u32, u32); 27],
    /// The cell's own kept candidates so far.
    own: Vec<[f32; 4]>,
}

/// The candidates sorted into grid cells: cell by cell in Morton order,
/// each cell's candidates in their order of arrival. Sorted arrays are
/// indexed by a candidate's place `s` in that order.
struct Grid {
    /// Each sorted candidate's index in the caller's arrays.
    index: Vec<u32>,
    /// Position and radius (capped at [`RADIUS_CAP`] times the median),
    /// side by side.
    sphere: Vec<[f32; 4]>,
    /// The grid's corner and its cells' width: twice the widest conflict,
    /// so that a candidate's conflicts lie in the eight cells around the
    /// corner of its own cell it is nearest.
    corner: Vec3,
    width: f32,
    /// Each cell's Morton code, ascending.
    keys: Vec<u64>,
    /// Each cell's first candidate, and the end.
    starts: Vec<u32>,
    /// The cells by block of 4 × 4 × 4: each block's Morton code (its
    /// cells' codes without their last six bits), ascending, its table of
    /// cells (by those six bits; [`NO_CELL`]: none), and each cell's block.
    blocks: Vec<u64>,
    tables: Vec<[u32; 64]>,
    block_of: Vec<u32>,
    /// The cells of each colour.
    phases: [Vec<u32>; 8],
}

impl Grid {
    /// `None` when there are no candidates.
    fn new(positions: &[Vec3], radii: &[f32], arrivals: &[u32]) -> Option<Self> {
        let m = positions.len();
        if m == 0 {
            return None;
        }
        let mut sample: Vec<f32> = radii.iter().step_by(16).copied().collect();
        let middle = sample.len() / 2;
        let cap = RADIUS_CAP * *sample.select_nth_unstable_by(middle, f32::total_cmp).1;
        let (corner, hi) = positions.par_iter().map(|&p| (p, p)).reduce(
            || (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
        // At most 2^20 cells along an axis (a wider cell only sees more).
        let extent = (hi - corner).max_element();
        let width = (4.0 * SPACING * cap)
            .max(extent / (MAX_CELLS - 1) as f32)
            .max(f32::MIN_POSITIVE);
        let axis_bits = (32 - ((extent / width) as u32).min(MAX_CELLS - 1).leading_zeros()).max(1);
        let (mut index, starts, keys) = sorted_by_cell(m, 3 * axis_bits, |i| {
            morton(cell_of(positions[i], corner, width).0)
        });
        // Each cell's candidates in order of arrival (the sort kept the
        // caller's order).
        let mut pieces: Vec<&mut [u32]> = Vec::with_capacity(keys.len());
        let mut rest = &mut index[..];
        for w in starts.windows(2) {
            let (head, tail) = rest.split_at_mut((w[1] - w[0]) as usize);
            pieces.push(head);
            rest = tail;
        }
        pieces
            .par_iter_mut()
            .with_min_len(256)
            .for_each(|cell| cell.sort_unstable_by_key(|&i| (arrivals[i as usize], i)));
        let mut phases: [Vec<u32>; 8] = Default::default();
        let (mut blocks, mut tables, mut block_of) = (Vec::new(), Vec::new(), Vec::new());
        for (c, &key) in keys.iter().enumerate() {
            phases[colour(key) as usize].push(c as u32);
            if blocks.last() != Some(&(key >> 6)) {
                blocks.push(key >> 6);
                tables.push([NO_CELL; 64]);
            }
            tables.last_mut().expect("pushed")[(key & 63) as usize] = c as u32;
            block_of.push(blocks.len() as u32 - 1);
        }
        Some(Self {
            sphere: index
                .par_iter()
                .map(|&i| {
                    let p = positions[i as usize];
                    [p.x, p.y, p.z, radii[i as usize].min(cap)]
                })
                .collect(),
            index,
            corner,
            width,
            keys,
            starts,
            blocks,
            tables,
            block_of,
            phases,
        })
    }

    fn range(&self, c: usize) -> Range<usize> {
        self.starts[c] as usize..self.starts[c + 1] as usize
    }

    /// Cell `c`'s neighbour at offset `slot`, if it holds candidates
    /// (found from `c`'s block: a neighbour's is mostly the same one).
    fn neighbour(&self, c: usize, slot: usize) -> Option<usize> {
        let [x, y, z] = unmorton(self.keys[c]).map(|v| v as i64);
        let d = offset(slot);
        let n = [x + d[0], y + d[1], z + d[2]];
        if n.iter().any(|&v| v < 0 || v >= MAX_CELLS as i64) {
            return None;
        }
        let key = morton(n.map(|v| v as u32));
        let own = self.block_of[c] as usize;
        let block = if self.blocks[own] == key >> 6 {
            own
        } else {
            search_from(&self.blocks, own, key >> 6)?
        };
        let found = self.tables[block][(key & 63) as usize];
        (found != NO_CELL).then_some(found as usize)
    }

    /// The eight neighbours (by number) that may hold the conflicts of a
    /// candidate at `point`: those beside the corner of its cell it is
    /// nearest.
    fn octant(&self, point: Vec3) -> [usize; 8] {
        let (_, fraction) = cell_of(point, self.corner, self.width);
        let toward = fraction.map(|f| if f < 0.5 { 0 } else { 2 });
        std::array::from_fn(|k| {
            let pick = |axis: usize| if k >> axis & 1 == 0 { 1 } else { toward[axis] };
            pick(0) + 3 * pick(1) + 9 * pick(2)
        })
    }

    /// Decides cell `c`'s candidates in their order: each is kept when no
    /// kept candidate of its own cell or of a cell of an earlier colour
    /// conflicts with it.
    fn throw_darts(&self, c: usize, kept: &[AtomicBool], scratch: &mut DartScratch) {
        let own_colour = colour(self.keys[c]);
        let DartScratch { around, slots, own } = scratch;
        around.clear();
        own.clear();
        for (slot, range) in slots.iter_mut().enumerate() {
            let start = around.len() as u32;
            // Only the neighbours decided before are looked up: a step
            // along an axis flips that coordinate's parity, so a
            // neighbour's colour is the cell's with those bits flipped
            // (never the cell's own).
            let earlier = slot != SELF && own_colour ^ parity_flips(slot) < own_colour;
            if let Some(n) = earlier.then(|| self.neighbour(c, slot)).flatten() {
                around.extend(
                    self.range(n)
                        .filter(|&j| kept[j].load(Ordering::Relaxed))
                        .map(|j| self.sphere[j]),
                );
            }
            *range = (start, around.len() as u32);
        }
        for i in self.range(c) {
            let sphere = self.sphere[i];
            let [x, y, z, _] = sphere;
            let clear = self.octant(Vec3::new(x, y, z)).iter().all(|&slot| {
                let near = if slot == SELF {
                    &own[..]
                } else {
                    let (a, b) = slots[slot];
                    &around[a as usize..b as usize]
                };
                near.iter().all(|other| !conflict(&sphere, other))
            });
            if clear {
                kept[i].store(true, Ordering::Relaxed);
                own.push(sphere);
            }
        }
    }

    /// Gives each unit exactly its count (`kept` in the caller's order).
    /// Dart throwing keeps about as many as asked; where it kept more, the
    /// last to arrive go (a few holes, no crowding); where fewer, the
    /// rejected candidates come back in their order of arrival, each only
    /// where it lies at least a closeness apart from every kept one, the
    /// closeness lowered pass by pass until the count is reached.
    fn fix_counts(&self, units: &[Unit], arrivals: &[u32], kept: &mut [bool]) {
        let by_arrival = |&i: &u32| (arrivals[i as usize], i);
        // Each candidate's place in the grid, once a unit needs it.
        let mut places: Option<Vec<u32>> = None;
        for unit in units {
            let range = unit.candidates.clone();
            let count = kept[range.clone()].iter().filter(|&&k| k).count();
            if count > unit.keep {
                let mut list: Vec<u32> = range.filter(|&i| kept[i]).map(|i| i as u32).collect();
                let go = count - unit.keep;
                list.select_nth_unstable_by_key(count - go, by_arrival);
                for &i in &list[count - go..] {
                    kept[i as usize] = false;
                }
            } else if count < unit.keep {
                let places = places.get_or_insert_with(|| {
                    let mut out = vec![0u32; kept.len()];
                    for (s, &i) in self.index.iter().enumerate() {
                        out[i as usize] = s as u32;
                    }
                    out
                });
                let mut list: Vec<u32> = range.filter(|&i| !kept[i]).map(|i| i as u32).collect();
                list.sort_unstable_by_key(by_arrival);
                let mut missing = unit.keep - count;
                let mut apart = SPACING;
                while missing > 0 && !list.is_empty() {
                    apart *= 0.8;
                    let last_pass = apart < 1e-3;
                    list.retain(|&i| {
                        let s = places[i as usize] as usize;
                        if missing == 0 || !(last_pass || self.clear_of_kept(s, apart, kept)) {
                            return true;
                        }
                        kept[i as usize] = true;
                        missing -= 1;
                        false
                    });
                }
            }
        }
    }

    /// Whether every kept candidate (`kept` in the caller's order) lies at
    /// least `apart` (a closeness: the distance over the sum of the radii)
    /// from the candidate at place `s`.
    fn clear_of_kept(&self, s: usize, apart: f32, kept: &[bool]) -> bool {
        let c = self.starts.partition_point(|&start| start as usize <= s) - 1;
        let [a @ .., ra] = self.sphere[s];
        (0..27)
            .filter_map(|slot| self.neighbour(c, slot))
            .flat_map(|n| self.range(n))
            .all(|j| {
                let [b @ .., rb] = self.sphere[j];
                j == s
                    || !kept[self.index[j] as usize]
                    || Vec3::from(a).distance(Vec3::from(b)) >= apart * (ra + rb)
            })
    }
}

/// Whether two candidates (position and radius) conflict.
#[inline]
fn conflict(a: &[f32; 4], b: &[f32; 4]) -> bool {
    let reach = SPACING * (a[3] + b[3]);
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < reach * reach
}

/// The cell `point` lies in, and where in it (0 to 1 along each axis).
/// Points lie above the corner, so truncation is the floor.
fn cell_of(point: Vec3, corner: Vec3, width: f32) -> ([u32; 3], [f32; 3]) {
    let q = ((point - corner) / width).max(Vec3::ZERO).to_array();
    let cell = q.map(|v| (v as u32).min(MAX_CELLS - 1));
    (cell, std::array::from_fn(|k| q[k] - cell[k] as f32))
}

/// Where `key` is in the ascending `keys`, searched outward from `from`
/// (steps doubling, then halving).
fn search_from(keys: &[u64], from: usize, key: u64) -> Option<usize> {
    let (lo, hi) = if key > keys[from] {
        let mut step = 1;
        while from + step < keys.len() && keys[from + step] < key {
            step *= 2;
        }
        (from + step / 2, (from + step + 1).min(keys.len()))
    } else {
        let mut step = 1;
        while step <= from && keys[from - step] > key {
            step *= 2;
        }
        (from.saturating_sub(step), from - step / 2 + 1)
    };
    keys[lo..hi].binary_search(&key).ok().map(|k| lo + k)
}

/// The candidates `0..m` sorted by their cells (`cell(i)`, a key of
/// `key_bits` bits), stably: the sorted indices, the first place of each
/// cell (and the end), and each cell's key. The index rides in the key's
/// low bits when both fit in 64 (half the bytes to move), beside it
/// otherwise.
fn sorted_by_cell(
    m: usize,
    key_bits: u32,
    cell: impl Fn(usize) -> u64 + Sync,
) -> (Vec<u32>, Vec<u32>, Vec<u64>) {
    let index_bits = (usize::BITS - m.leading_zeros()).max(1);
    if key_bits + index_bits <= 64 {
        let mask = (1u64 << index_bits) - 1;
        let mut packed: Vec<u64> = (0..m)
            .into_par_iter()
            .map(|i| cell(i) << index_bits | i as u64)
            .collect();
        radix_sort(&mut packed, |&v| v >> index_bits, key_bits);
        runs(&packed, |&v| v >> index_bits, |&v| (v & mask) as u32)
    } else {
        let mut pairs: Vec<(u64, u32)> = (0..m)
            .into_par_iter()
            .map(|i| (cell(i), i as u32))
            .collect();
        radix_sort(&mut pairs, |&(k, _)| k, key_bits);
        runs(&pairs, |&(k, _)| k, |&(_, i)| i)
    }
}

/// The indices of sorted items, the first place of each run of equal keys
/// (and the end), and each run's key.
fn runs<T: Sync>(
    sorted: &[T],
    key: impl Fn(&T) -> u64,
    index: impl Fn(&T) -> u32 + Sync + Send,
) -> (Vec<u32>, Vec<u32>, Vec<u64>) {
    let mut starts = Vec::new();
    let mut keys = Vec::new();
    for (s, item) in sorted.iter().enumerate() {
        let k = key(item);
        if keys.last() != Some(&k) {
            starts.push(s as u32);
            keys.push(k);
        }
    }
    starts.push(sorted.len() as u32);
    (sorted.par_iter().map(index).collect(), starts, keys)
}

/// Sorts items by the low `bits` bits of their keys, stably: split by the
/// top byte first, then each part least significant byte first, the
/// parts in parallel.
fn radix_sort<T: Copy + Default + Send + Sync>(
    items: &mut Vec<T>,
    key: impl Fn(&T) -> u64 + Sync,
    bits: u32,
) {
    let top = bits.saturating_sub(8);
    let mut split = vec![T::default(); items.len()];
    let starts = scatter_by_byte(items, &mut split, &key, top);
    let mut parts: Vec<&mut [T]> = Vec::with_capacity(256);
    let mut rest = &mut split[..];
    for b in 0..256 {
        let (head, tail) = rest.split_at_mut(starts[b + 1] - starts[b]);
        parts.push(head);
        rest = tail;
    }
    parts.into_par_iter().for_each(|part| {
        let mut other = vec![T::default(); part.len()];
        let mut in_part = true;
        for shift in (0..top).step_by(8) {
            if in_part {
                scatter_by_byte(part, &mut other, &key, shift);
            } else {
                scatter_by_byte(&other, part, &key, shift);
            }
            in_part = !in_part;
        }
        if !in_part {
            part.copy_from_slice(&other);
        }
    });
    *items = split;
}

/// One stable pass of a radix sort: `src` into `dst` by the byte of the
/// keys at `shift`. Returns where each byte's items start in `dst` (and
/// the end).
fn scatter_by_byte<T: Copy>(
    src: &[T],
    dst: &mut [T],
    key: impl Fn(&T) -> u64,
    shift: u32,
) -> [usize; 257] {
    let digit = |item: &T| ((key(item) >> shift) & 0xff) as usize;
    let mut starts = [0usize; 257];
    for item in src {
        starts[digit(item) + 1] += 1;
    }
    for b in 0..256 {
        starts[b + 1] += starts[b];
    }
    let mut fill = starts;
    for item in src {
        let slot = &mut fill[digit(item)];
        dst[*slot] = *item;
        *slot += 1;
    }
    starts
}

/// No cell there.
const NO_CELL: u32 = u32::MAX;

/// Cells along an axis, at most.
const MAX_CELLS: u32 = 1 << 20;

/// A cell's colour: the parities of its coordinates. Two cells of one
/// colour are at least a cell apart.
fn colour(key: u64) -> u64 {
    // The Morton code's lowest three bits are the coordinates' lowest.
    key & 7
}

/// The Morton code of a cell's coordinates (20 bits each).
fn morton(c: [u32; 3]) -> u64 {
    spread(c[0]) | spread(c[1]) << 1 | spread(c[2]) << 2
}

/// A cell's coordinates from its Morton code.
fn unmorton(key: u64) -> [u32; 3] {
    [key, key >> 1, key >> 2].map(compact)
}

/// Spreads 20 bits to every third bit of 60.
fn spread(v: u32) -> u64 {
    let mut x = (v & 0xf_ffff) as u64;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    (x | x << 2) & 0x1249_2492_4924_9249
}

/// The inverse of [`spread`]: every third bit gathered.
fn compact(v: u64) -> u32 {
    let mut x = v & 0x1249_2492_4924_9249;
    x = (x | x >> 2) & 0x10c3_0c30_c30c_30c3;
    x = (x | x >> 4) & 0x100f_00f0_0f00_f00f;
    x = (x | x >> 8) & 0x1f_0000_ff00_00ff;
    x = (x | x >> 16) & 0x1f_0000_0000_ffff;
    x = (x | x >> 32) & 0xf_ffff;
    x as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nearest::NearestPoints;

    /// `n` random points on the unit square (z = 0).
    fn points_on_square(n: u64) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let h = mix64(i);
                Vec3::new(
                    (h >> 40) as f32 / 16_777_216.0,
                    (h & 0xFF_FFFF) as f32 / 16_777_216.0,
                    0.0,
                )
            })
            .collect()
    }

    #[test]
    fn thinning_keeps_each_units_count_and_spreads_the_points() {
        // 4,000 random points on the unit square, thinned to 1,000: the
        // left half's candidates (a unit) to 600, the right half's to 400.
        let mut points = points_on_square(4000);
        points.sort_by(|a, b| a.x.total_cmp(&b.x));
        let units = [
            Unit {
                candidates: 0..2000,
                keep: 600,
            },
            Unit {
                candidates: 2000..4000,
                keep: 400,
            },
        ];
        // Each half's radius follows its own density.
        let radii: Vec<f32> = points
            .iter()
            .map(|p| radius(if p.x < 0.5 { 1200.0 } else { 800.0 }))
            .collect();
        // Sorted by x, so arrivals come from a hash of the place.
        let arrivals: Vec<u32> = (0..4000u64).map(|k| mix64(k) as u32).collect();
        let flags = thin(&points, &radii, &arrivals, &units);
        assert_eq!(flags[..2000].iter().filter(|&&k| k).count(), 600);
        assert_eq!(flags[2000..].iter().filter(|&&k| k).count(), 400);
        let kept: Vec<usize> = (0..4000).filter(|&i| flags[i]).collect();
        let min_distance = |set: &[Vec3]| {
            let tree = NearestPoints::new(set.to_vec());
            let mut out = Vec::new();
            set.iter()
                .map(|p| {
                    tree.nearest(*p, 2, &mut out);
                    out[1].distance_squared.sqrt()
                })
                .fold(f32::INFINITY, f32::min)
        };
        let thinned: Vec<Vec3> = kept.iter().map(|&i| points[i]).collect();
        let random = &points[..1000];
        assert!(min_distance(&thinned) > 3.0 * min_distance(random));
    }

    /// Counts far from what dart throwing keeps by itself still come out
    /// exact: a unit asking for nearly every candidate (rejected ones come
    /// back, the least crowded first), one asking for a few, an empty one
    /// and one that keeps nothing.
    #[test]
    fn every_unit_gets_its_count_however_far_from_the_spacing() {
        let points = points_on_square(3000);
        let radii = vec![radius(500.0); points.len()];
        let arrivals: Vec<u32> = (0..3000).map(|k| arrival(k, 3000)).collect();
        let units = [
            Unit {
                candidates: 0..1000,
                keep: 950,
            },
            Unit {
                candidates: 1000..2000,
                keep: 7,
            },
            Unit {
                candidates: 2000..2000,
                keep: 0,
            },
            Unit {
                candidates: 2000..3000,
                keep: 0,
            },
        ];
        let kept = thin(&points, &radii, &arrivals, &units);
        for unit in &units {
            let count = kept[unit.candidates.clone()].iter().filter(|&&k| k).count();
            assert_eq!(count, unit.keep, "{unit:?}");
        }
    }

    /// A whole mesh's blue noise: the count asked for, spread further than
    /// random points, and the same on one thread and on two.
    #[test]
    fn whole_mesh_blue_noise_is_spread_and_deterministic() {
        let mesh = crate::assets::spot();
        let sampler = DensitySampler::new(
            &mesh,
            &crate::Map::Constant(1.0),
            super::super::DensitySamplerOptions::default(),
        )
        .unwrap();
        let on = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| blue_noise_samples(&sampler, &mesh, 7, 3000))
        };
        let points = on(1);
        assert_eq!(points.len(), 3000);
        assert!(points == on(2), "one thread and two differ");
        let nearest = |set: &[SurfacePoint]| {
            let positions: Vec<Vec3> = set.iter().map(|p| p.position(&mesh)).collect();
            let tree = NearestPoints::new(positions.clone());
            let mut out = Vec::new();
            let mut d: Vec<f32> = positions
                .iter()
                .map(|p| {
                    tree.nearest(*p, 2, &mut out);
                    out[1].distance_squared.sqrt()
                })
                .collect();
            d.sort_by(f32::total_cmp);
            d[d.len() / 100] // the closest 1 %
        };
        let random = sample_range(&sampler, 7, 0..3000);
        assert!(
            nearest(&points) > 2.0 * nearest(&random),
            "blue noise {} vs random {}",
            nearest(&points),
            nearest(&random)
        );
    }
}
