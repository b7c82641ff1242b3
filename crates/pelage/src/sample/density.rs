//! The density-texture sampler of Sik §3: sub-triangle subdivision with
//! sibling merging (Fig. 5), 12-byte records with shared positions (Fig. 4),
//! selection by CDF + uniform grid (Fig. 7) or by an alias table, and a
//! uniform point in the chosen sub-triangle (Fig. 6).
//!
//! One file, past 600 lines: the §3 sampler end to end (records, both
//! selectors, prefetched block sampling, the PDF) reads best as one
//! algorithm.

use super::alias::{AliasBins, build_alias_bins};
use super::cdf::CdfGrid;
use super::rng::{PairDraws, open_unit_pair};
use super::subtriangle::{MAX_LEVEL, PositionTable, SubTriangle, WHOLE_TRIANGLE, child_index};
use super::{SampleError, SurfaceSampler, prefetch, warp};
use crate::map::{Map, MapSite};
use crate::mesh::{Mesh, SurfacePoint};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::sync::Arc;

/// One sub-triangle of the distribution: 12 bytes, as in the paper.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub struct SubTriangleRecord {
    /// The mesh triangle it lies in.
    pub triangle: u32,
    /// Its position index inside that triangle (see [`super::subtriangle`]).
    pub position: u32,
    /// Its probability, unnormalised: area × density at its centroid.
    pub probability: f32,
}

const _: () = assert!(std::mem::size_of::<SubTriangleRecord>() == 12);

/// How a sub-triangle is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Selector {
    /// The paper's CDF with a uniform grid of `grid_percent` % as many cells
    /// as records (0 = bisection over the whole CDF).
    CdfGrid {
        /// Grid cells as a percentage of the record count.
        grid_percent: u32,
    },
    /// Walker's alias table: O(1) per sample.
    Alias,
}

impl Default for Selector {
    /// The alias table: measured faster than CDF + grid at every size in
    /// `pelage bench sampler` (see docs/benchmarks/sampler.md).
    fn default() -> Self {
        Selector::Alias
    }
}

/// Options of [`DensitySampler::new`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DensitySamplerOptions {
    /// How sub-triangles are chosen.
    pub selector: Selector,
    /// Deepest subdivision level (the paper stops at one texel per
    /// sub-triangle; this caps it for huge triangles on huge textures).
    pub max_level: u32,
}

impl Default for DensitySamplerOptions {
    fn default() -> Self {
        Self {
            selector: Selector::default(),
            max_level: 12,
        }
    }
}

#[derive(Debug, Clone)]
enum SelectorTable {
    Cdf(CdfGrid),
    /// One entry per record: its alias bin fused with its own triangle and
    /// position, so a sample that keeps its bin reads one cache line.
    Alias(Vec<AliasedRecord>),
}

/// An alias bin with a copy of its record's triangle and position.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(16))]
struct AliasedRecord {
    threshold: u32,
    alias: u32,
    triangle: u32,
    position: u32,
}

impl AliasBins for [AliasedRecord] {
    fn set(&mut self, i: usize, threshold: u32, alias: u32) {
        self[i].threshold = threshold;
        self[i].alias = alias;
    }
}

/// The alias bin that 64 random bits draw among `n`.
#[inline]
fn alias_bin(bits: u64, n: usize) -> usize {
    (((bits >> 32) * n as u64) >> 32) as usize
}

/// Samples points on a mesh with a density given by a [`Map`] (Sik §3).
///
/// ```
/// use pelage::map::Map;
/// use pelage::sample::{DensitySampler, SurfaceSampler, sample_range};
///
/// let spot = pelage::assets::spot();
/// // Twice as many roots where the texture's red channel is twice as bright.
/// let density = Map::Image(pelage::assets::spot_texture(pelage::map::Channel::R));
/// let sampler = DensitySampler::new(&spot, &density, Default::default())?;
/// // Sample i of a stream is a pure function of (seed, i): any range, on
/// // any number of threads, gives the same points.
/// let roots = sample_range(&sampler, 7, 0..1000);
/// assert_eq!(roots.len(), 1000);
/// assert_eq!(sample_range(&sampler, 7, 500..1000), roots[500..]);
/// assert!(roots.iter().all(|r| sampler.pdf(*r) > 0.0));
/// # Ok::<(), pelage::sample::SampleError>(())
/// ```
#[derive(Debug, Clone)]
pub struct DensitySampler {
    /// The mesh's triangle areas (shared by the samplers restricted from
    /// this one): all the sampler needs of the mesh once built, so it
    /// holds no borrow and a binding or a generator can own it.
    areas: Arc<[f32]>,
    records: Vec<SubTriangleRecord>,
    /// Records of triangle t are `records[first[t]..first[t + 1]]`.
    first_record: Vec<u32>,
    total: f64,
    selector: SelectorTable,
    positions: PositionTable,
    options: DensitySamplerOptions,
}

/// Fig. 5's output for a whole mesh: the records, where each triangle's
/// start, and their total probability. The density sampler selects among
/// them; the rejection sampler only needs the total (and the validation).
pub(crate) struct SubTriangleRecords {
    pub(crate) records: Vec<SubTriangleRecord>,
    /// Records of triangle t are `records[first_record[t]..first_record[t + 1]]`.
    pub(crate) first_record: Vec<u32>,
    /// Sum of the probabilities: ∫ density dA by the centroid rule.
    pub(crate) total: f64,
}

impl SubTriangleRecords {
    /// Subdivides every triangle (in parallel, fixed chunks, so the result
    /// never depends on threads). Errors name the mesh: a map that needs
    /// UVs on a mesh without them, a negative or NaN density (with the
    /// triangle and UV), a density that is zero everywhere.
    pub(crate) fn build(mesh: &Mesh, density: &Map, max_level: u32) -> Result<Self, SampleError> {
        // Refuses maps that need UVs on meshes without them; takes a
        // per-vertex map's values.
        let density = &*density.bound(mesh)?;
        let max_level = max_level.min(MAX_LEVEL);
        let texels = Resolution {
            uv: density.resolution(),
            object: density.object_resolution(mesh.has_uvs()),
            linear: density.varies_within_triangles(),
        };

        // Triangles are independent: build in parallel, in fixed chunks
        // concatenated in order, so the records never depend on threads.
        const CHUNK: usize = 2048;
        let chunks: Vec<Result<Chunk, SampleError>> = (0..mesh.triangle_count())
            .into_par_iter()
            .step_by(CHUNK)
            .map(|start| {
                let end = (start + CHUNK).min(mesh.triangle_count());
                let levels: Vec<u32> = (start..end)
                    .map(|t| level_for(mesh, texels, max_level, t))
                    .collect();
                let leaves: usize = levels.iter().map(|&l| 1usize << (2 * l)).sum();
                let mut chunk = Chunk {
                    records: Vec::with_capacity(leaves),
                    counts: Vec::with_capacity(end - start),
                    total: 0.0,
                };
                for (t, level) in (start..end).zip(levels) {
                    let before = chunk.records.len();
                    subdivide_triangle(mesh, density, level, t, &mut chunk.records)?;
                    chunk.counts.push((chunk.records.len() - before) as u32);
                }
                chunk.total = chunk.records.iter().map(|r| f64::from(r.probability)).sum();
                Ok(chunk)
            })
            .collect();
        let mut records = Vec::with_capacity(
            chunks
                .iter()
                .map(|c| c.as_ref().map_or(0, |c| c.records.len()))
                .sum(),
        );
        let mut first_record = Vec::with_capacity(mesh.triangle_count() + 1);
        first_record.push(0u32);
        let mut total = 0.0;
        for chunk in chunks {
            let chunk = chunk?;
            records.extend_from_slice(&chunk.records);
            for count in chunk.counts {
                first_record.push(first_record.last().expect("starts with 0") + count);
            }
            total += chunk.total;
        }
        if records.is_empty() || total <= 0.0 || !total.is_finite() {
            return Err(SampleError::ZeroDensity {
                mesh: mesh.name().to_string(),
            });
        }
        Ok(Self {
            records,
            first_record,
            total,
        })
    }
}

/// What a chunk of triangles contributes.
struct Chunk {
    records: Vec<SubTriangleRecord>,
    /// Records per triangle.
    counts: Vec<u32>,
    total: f64,
}

impl DensitySampler {
    /// Builds the distribution (the paper's preprocess). Errors name the
    /// mesh: a map that needs UVs on a mesh without them, a negative or NaN
    /// density (with the triangle and UV), a density that is zero everywhere.
    pub fn new(
        mesh: &Mesh,
        density: &Map,
        options: DensitySamplerOptions,
    ) -> Result<Self, SampleError> {
        let SubTriangleRecords {
            records,
            first_record,
            total,
        } = SubTriangleRecords::build(mesh, density, options.max_level)?;
        Ok(Self::from_records(
            mesh.triangle_areas().into(),
            records,
            first_record,
            total,
            options,
        ))
    }

    /// The same distribution restricted to `triangles` (ascending, no
    /// repeats) and renormalised: where one part of a groom places its
    /// roots. `None` if the density is zero on all of them.
    pub fn restricted(&self, triangles: &[u32]) -> Option<DensitySampler> {
        debug_assert!(triangles.windows(2).all(|w| w[0] < w[1]));
        let mut records = Vec::new();
        let mut first_record = vec![0u32; self.first_record.len()];
        let mut next = triangles.iter().peekable();
        for t in 0..self.triangle_count() {
            if next.next_if(|&&k| k as usize == t).is_some() {
                let range = self.first_record[t] as usize..self.first_record[t + 1] as usize;
                records.extend_from_slice(&self.records[range]);
            }
            first_record[t + 1] = records.len() as u32;
        }
        let total: f64 = records.iter().map(|r| f64::from(r.probability)).sum();
        (total > 0.0).then(|| {
            Self::from_records(
                self.areas.clone(),
                records,
                first_record,
                total,
                self.options,
            )
        })
    }

    /// The same distribution restricted to a few `triangles` (any order)
    /// and renormalised, as a small sampler that borrows this one: where
    /// one cell of [`super::RootCells`] places its roots. Building it costs
    /// the cell's records, not the mesh's triangles (as
    /// [`Self::restricted`] does). `None` if the density is zero on all
    /// of them.
    pub fn cell_sampler(&self, triangles: &[u32]) -> Option<CellSampler<'_>> {
        let mut entries = Vec::new();
        let mut weights = Vec::new();
        for &t in triangles {
            let range =
                self.first_record[t as usize] as usize..self.first_record[t as usize + 1] as usize;
            for r in &self.records[range] {
                entries.push(AliasedRecord {
                    threshold: u32::MAX,
                    alias: entries.len() as u32,
                    triangle: r.triangle,
                    position: r.position,
                });
                weights.push(f64::from(r.probability));
            }
        }
        let total: f64 = weights.iter().sum();
        if entries.is_empty() || total <= 0.0 {
            return None;
        }
        build_alias_bins(weights, entries.as_mut_slice());
        Some(CellSampler {
            whole: self,
            entries,
            share: total / self.total,
        })
    }

    /// The probability that a sample lands in `triangles` (any order).
    pub fn probability_of(&self, triangles: &[u32]) -> f64 {
        triangles
            .iter()
            .map(|&t| {
                let range = self.first_record[t as usize] as usize
                    ..self.first_record[t as usize + 1] as usize;
                self.records[range]
                    .iter()
                    .map(|r| f64::from(r.probability))
                    .sum::<f64>()
            })
            .sum::<f64>()
            / self.total
    }

    fn from_records(
        areas: Arc<[f32]>,
        records: Vec<SubTriangleRecord>,
        first_record: Vec<u32>,
        total: f64,
        options: DensitySamplerOptions,
    ) -> Self {
        let weights = records.iter().map(|r| f64::from(r.probability));
        let selector = match options.selector {
            Selector::CdfGrid { grid_percent } => {
                SelectorTable::Cdf(CdfGrid::new(weights, grid_percent))
            }
            Selector::Alias => {
                let mut entries: Vec<AliasedRecord> = records
                    .iter()
                    .enumerate()
                    .map(|(i, r)| AliasedRecord {
                        threshold: u32::MAX,
                        alias: i as u32,
                        triangle: r.triangle,
                        position: r.position,
                    })
                    .collect();
                build_alias_bins(weights, entries.as_mut_slice());
                SelectorTable::Alias(entries)
            }
        };
        Self {
            areas,
            records,
            first_record,
            total,
            selector,
            positions: PositionTable::new(),
            options,
        }
    }

    /// The sub-triangle records (zero-probability ones are left out).
    pub fn records(&self) -> &[SubTriangleRecord] {
        &self.records
    }

    /// Sum of the records' probabilities: ∫ density dA by the centroid rule
    /// at texel resolution.
    pub fn total_probability(&self) -> f64 {
        self.total
    }

    /// Probability that a sample lands in triangle `t`.
    pub fn triangle_probability(&self, t: usize) -> f64 {
        let range = self.first_record[t] as usize..self.first_record[t + 1] as usize;
        self.records[range]
            .iter()
            .map(|r| f64::from(r.probability))
            .sum::<f64>()
            / self.total
    }

    /// Bytes of the distribution: records, selector, per-triangle offsets
    /// and the position table.
    pub fn memory_bytes(&self) -> usize {
        let selector = match &self.selector {
            SelectorTable::Cdf(c) => c.memory_bytes(),
            SelectorTable::Alias(a) => a.len() * std::mem::size_of::<AliasedRecord>(),
        };
        self.records.len() * std::mem::size_of::<SubTriangleRecord>()
            + selector
            + self.first_record.len() * 4
            + self.positions.memory_bytes()
    }

    /// Triangles of the mesh sampled.
    pub fn triangle_count(&self) -> usize {
        self.areas.len()
    }
}

impl DensitySampler {
    /// Fig. 6 steps 2–3: a uniform point in the sub-triangle at
    /// `position` of `triangle` (from 48 bits of `bits`), mapped to the
    /// triangle's barycentrics.
    #[inline]
    fn point_in(&self, triangle: u32, position: u32, bits: u64) -> SurfacePoint {
        let sub = self.positions.get(position);
        let b = sub.to_parent(warp::sample_uniform_triangle(open_unit_pair(bits)));
        SurfacePoint {
            tri: triangle,
            bary: [b.x, b.y],
        }
    }
}

/// A [`DensitySampler`] restricted to a few triangles: an alias table
/// over their records (see [`DensitySampler::cell_sampler`]).
#[derive(Debug, Clone)]
pub struct CellSampler<'a> {
    whole: &'a DensitySampler,
    entries: Vec<AliasedRecord>,
    /// The cell's share of the whole distribution.
    share: f64,
}

impl SurfaceSampler for CellSampler<'_> {
    /// As [`DensitySampler::sample`], among the cell's records.
    #[inline]
    fn sample(&self, seed: u64, index: u64) -> SurfacePoint {
        let [select, place] = PairDraws::new(seed).draws(index);
        let e = self.entries[alias_bin(select, self.entries.len())];
        let e = if (select as u32) < e.threshold {
            e
        } else {
            self.entries[e.alias as usize]
        };
        self.whole.point_in(e.triangle, e.position, place)
    }

    /// The whole sampler's density renormalised to the cell (for points
    /// in the cell's triangles).
    fn pdf(&self, point: SurfacePoint) -> f64 {
        self.whole.pdf(point) / self.share
    }
}

/// Samples per block of [`DensitySampler::sample_block`]'s pipeline.
const BLOCK: usize = 64;

impl SurfaceSampler for DensitySampler {
    /// Sample `index`: its first draw selects the sub-triangle, its second
    /// places the point in it.
    #[inline]
    fn sample(&self, seed: u64, index: u64) -> SurfacePoint {
        let [select, place] = PairDraws::new(seed).draws(index);
        let (triangle, position) = match &self.selector {
            SelectorTable::Cdf(c) => {
                let r = self.records[c.select(select)];
                (r.triangle, r.position)
            }
            SelectorTable::Alias(entries) => {
                let e = entries[alias_bin(select, entries.len())];
                let e = if (select as u32) < e.threshold {
                    e
                } else {
                    entries[e.alias as usize]
                };
                (e.triangle, e.position)
            }
        };
        self.point_in(triangle, position, place)
    }

    /// The same points as `sample`, in stages over a block: every stage
    /// issues the memory reads of all samples before the next stage uses
    /// them, so a block waits for DRAM about once per stage instead of once
    /// per read. On a million-record distribution this is the difference
    /// between memory latency and memory throughput.
    // Each stage walks several per-sample arrays in step; indices say so
    // more plainly than zipped iterators.
    #[allow(clippy::needless_range_loop)]
    fn sample_block(&self, seed: u64, first: u64, out: &mut [SurfacePoint]) {
        let stream = PairDraws::new(seed);
        for (b, block) in out.chunks_mut(BLOCK).enumerate() {
            let first = first + (b * BLOCK) as u64;
            let n = block.len();
            let mut draws = [[0u64; 2]; BLOCK];
            let mut chosen = [0usize; BLOCK];
            let mut picked = [(0u32, 0u32); BLOCK];
            match &self.selector {
                SelectorTable::Alias(entries) => {
                    for i in 0..n {
                        draws[i] = stream.draws(first + i as u64);
                        chosen[i] = alias_bin(draws[i][0], entries.len());
                        prefetch(&entries[chosen[i]]);
                    }
                    // Most samples keep their bin and are done here; the
                    // others fetch their alias's entry in one more stage.
                    let mut aliased = [0u8; BLOCK];
                    let mut count = 0;
                    for i in 0..n {
                        let e = entries[chosen[i]];
                        if (draws[i][0] as u32) < e.threshold {
                            picked[i] = (e.triangle, e.position);
                        } else {
                            chosen[i] = e.alias as usize;
                            prefetch(&entries[chosen[i]]);
                            aliased[count] = i as u8;
                            count += 1;
                        }
                    }
                    for &i in &aliased[..count] {
                        let e = entries[chosen[i as usize]];
                        picked[i as usize] = (e.triangle, e.position);
                    }
                }
                SelectorTable::Cdf(cdf) => {
                    for i in 0..n {
                        draws[i] = stream.draws(first + i as u64);
                        prefetch(cdf.cell_entry(draws[i][0]));
                    }
                    let mut ranges = [(0usize, 0usize); BLOCK];
                    for i in 0..n {
                        ranges[i] = cdf.range_of(draws[i][0]);
                        prefetch(cdf.entry(ranges[i].0));
                    }
                    for i in 0..n {
                        chosen[i] = cdf.search(draws[i][0], ranges[i]);
                        prefetch(&self.records[chosen[i]]);
                    }
                    for i in 0..n {
                        let r = self.records[chosen[i]];
                        picked[i] = (r.triangle, r.position);
                    }
                }
            }
            for i in 0..n {
                let (triangle, position) = picked[i];
                block[i] = self.point_in(triangle, position, draws[i][1]);
            }
        }
    }

    /// Piecewise constant: the probability of the sub-triangle holding the
    /// point over its area.
    fn pdf(&self, point: SurfacePoint) -> f64 {
        let t = point.tri as usize;
        let area = f64::from(self.areas[t]);
        let b = Vec2::from(point.bary);
        let range = self.first_record[t] as usize..self.first_record[t + 1] as usize;
        self.records[range]
            .iter()
            .map(|r| (r, self.positions.get(r.position)))
            .find(|(_, sub)| sub.contains(b, 1e-6))
            .map_or(0.0, |(r, sub)| {
                f64::from(r.probability) / self.total / (area * f64::from(sub.area_fraction()))
            })
    }
}

/// How finely a density varies: the texel grid over UV, the samples a
/// world unit of object-space noise, or linearly inside triangles.
#[derive(Debug, Clone, Copy)]
struct Resolution {
    uv: Option<(u32, u32)>,
    object: Option<f32>,
    linear: bool,
}

/// Levels a triangle is subdivided to for a per-vertex density: the
/// triangle's probability is exact at level 0 (a linear function's mean
/// is its centroid value); two levels follow the gradient inside it.
const LINEAR_LEVELS: u32 = 2;

/// Subdivision level of a triangle: the smallest level at which each
/// sub-triangle covers at most one texel (Sik §3.1), capped. Object-space
/// noise counts its samples over the triangle's area instead.
fn level_for(mesh: &Mesh, texels: Resolution, max_level: u32, t: usize) -> u32 {
    let footprint = if let Some(per_unit) = texels.object {
        mesh.triangle_areas()[t] * per_unit * per_unit
    } else if let (Some((w, h)), Some([t0, t1, t2])) = (texels.uv, mesh.triangle_uvs(t)) {
        let (d1, d2) = (t1 - t0, t2 - t0);
        0.5 * (d1.x * d2.y - d2.x * d1.y).abs() * w as f32 * h as f32
    } else if texels.linear {
        return LINEAR_LEVELS.min(max_level);
    } else {
        return 0;
    };
    let mut level = 0;
    let mut per_sub = footprint;
    while per_sub > 1.0 && level < max_level {
        per_sub *= 0.25;
        level += 1;
    }
    level
}

/// Fig. 5 for one triangle: subdivide to its level, evaluate the density at
/// each leaf's centroid, merge equal siblings, append the records.
fn subdivide_triangle(
    mesh: &Mesh,
    map: &Map,
    level: u32,
    t: usize,
    out: &mut Vec<SubTriangleRecord>,
) -> Result<(), SampleError> {
    let area = mesh.triangle_areas()[t];
    if area == 0.0 {
        return Ok(()); // degenerate: zero probability, no records
    }
    // UV and position corners once per triangle.
    let uv_frame = mesh
        .triangle_uvs(t)
        .map(|[t0, t1, t2]| (t0, t1 - t0, t2 - t0));
    let [p0, p1, p2] = mesh.triangle_positions(t);
    let leaf = Leaf {
        map,
        uv_frame,
        position_frame: (p0, p1 - p0, p2 - p0),
        corners: mesh.triangles()[t],
        t: t as u32,
        area,
        level,
        bad: std::cell::Cell::new(None),
    };
    let root = leaf.visit(WHOLE_TRIANGLE, SubTriangle::WHOLE, 0, out);
    if let Some((value, uv)) = leaf.bad.get() {
        return Err(SampleError::BadDensity {
            mesh: mesh.name().to_string(),
            triangle: leaf.t,
            uv: uv.map(|uv| uv.to_array()),
            value,
        });
    }
    if let Some(p) = root {
        push(out, leaf.t, WHOLE_TRIANGLE, p);
    }
    Ok(())
}

struct Leaf<'a> {
    map: &'a Map,
    /// UV of corner 0 and the UV edges to corners 1 and 2.
    uv_frame: Option<(Vec2, Vec2, Vec2)>,
    /// The same for positions (object-space noise reads them).
    position_frame: (Vec3, Vec3, Vec3),
    /// The triangle's vertices (per-vertex maps read them).
    corners: [u32; 3],
    t: u32,
    area: f32,
    level: u32,
    /// The first negative or non-finite density met, and its UV. Kept
    /// aside so the recursion returns a plain `Option<f32>`.
    bad: std::cell::Cell<Option<(f32, Option<Vec2>)>>,
}

impl Leaf<'_> {
    /// The density at parent barycentrics `b`.
    #[inline]
    fn density_at(&self, b: Vec2) -> (f32, Option<Vec2>) {
        if let Map::Constant(c) = self.map {
            return (*c, None);
        }
        let uv = self.uv_frame.map(|(t0, e1, e2)| t0 + b.x * e1 + b.y * e2);
        let (p0, e1, e2) = self.position_frame;
        let site = MapSite {
            uv,
            position: p0 + b.x * e1 + b.y * e2,
            corners: self.corners,
            weights: [1.0 - b.x - b.y, b.x, b.y],
        };
        (self.map.at(&site), uv)
    }

    /// Returns `Some(probability)` when the node is uniform (a leaf, or four
    /// equal children merged), leaving it to the caller to store; `None`
    /// when its records have been stored already.
    fn visit(
        &self,
        position: u32,
        sub: SubTriangle,
        depth: u32,
        out: &mut Vec<SubTriangleRecord>,
    ) -> Option<f32> {
        if depth == self.level {
            let (density, uv) = self.density_at(sub.centroid());
            if density.is_nan() || density < 0.0 || density.is_infinite() {
                if self.bad.get().is_none() {
                    self.bad.set(Some((density, uv)));
                }
                return Some(0.0);
            }
            // area · s² is exact in binary (s = ±2^−level), so four equal
            // children sum exactly to the parent's probability.
            return Some(self.area * sub.area_fraction() * density);
        }
        let children: [Option<f32>; 4] = std::array::from_fn(|j| {
            let j = j as u32;
            self.visit(child_index(position, j), sub.child(j), depth + 1, out)
        });
        // Fig. 5 step 3(b): four unsubdivided siblings with the same
        // probability are replaced by their parent.
        if let [Some(a), Some(b), Some(c), Some(d)] = children
            && a == b
            && b == c
            && c == d
        {
            return Some(4.0 * a);
        }
        for (j, child) in children.iter().enumerate() {
            if let Some(p) = child {
                push(out, self.t, child_index(position, j as u32), *p);
            }
        }
        None
    }
}

/// Stores a record unless its probability is zero: zero-density regions
/// are then never selected, and cost no memory.
fn push(out: &mut Vec<SubTriangleRecord>, triangle: u32, position: u32, probability: f32) {
    if probability > 0.0 {
        out.push(SubTriangleRecord {
            triangle,
            position,
            probability,
        });
    }
}
