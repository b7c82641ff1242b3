//! Blue-noise roots: the groom's roots drawn twice over and thinned
//! back by dart throwing (`sample/blue_noise.rs` says how), all parts
//! together, so that roots either side of a part border are thinned
//! against each other (no seams).
//!
//! The candidates are each root cell's first twice its count of the
//! cell's own stream (the first of them its regular roots) with stable
//! ids, or each part's regular roots and as many more from the part's own
//! stream. Each part keeps exactly its hairs, and hairs keep
//! their part's ids: a survivor that was a regular root keeps its id, the
//! others take the ids of the regular roots removed, in order. Ids stay
//! unique and the same on every run. (A cell's count may change: blue
//! noise is not a subset of a larger groom, which is why fractions and
//! brushes ask for random roots.)
//!
//! The thinning needs every part's candidates, so the first part asked
//! for thins the whole groom's roots at once, and the other parts read
//! theirs from it (a farm task that grows one part places every root).

use super::generator::{Generator, PartRoots};
use super::parts::{sort_cell_roots, sorted_by_triangle_with_payload};
use crate::mesh::SurfacePoint;
use crate::sample::blue_noise::{OVERSAMPLING, Unit, arrival, positions_and_radii, thin};
use crate::sample::{mix64, salts, sample_range};
use rayon::prelude::*;

/// A part's candidates (each stream's in its order of arrival), each
/// one's place of arrival in its stream and, for a regular root, its
/// hair's id.
#[derive(Default)]
struct PartCandidates {
    candidates: Vec<SurfacePoint>,
    arrivals: Vec<u32>,
    ids: Vec<Option<u64>>,
    /// The hairs it keeps: as many as its regular roots.
    keep: usize,
    /// Where each stream's candidates start (a root cell's, in the cells'
    /// Morton order, or the part's own).
    streams: Vec<usize>,
}

impl PartCandidates {
    /// Appends a stream's candidates, of which the first are regular roots
    /// with ids `ids`.
    fn push_stream(&mut self, candidates: Vec<SurfacePoint>, ids: impl Iterator<Item = u64>) {
        let (before, len) = (self.ids.len(), candidates.len());
        self.streams.push(before);
        self.ids.extend(ids.map(Some));
        self.keep += self.ids.len() - before;
        self.ids.resize(before + len, None);
        self.arrivals.extend((0..len).map(|k| arrival(k, len)));
        self.candidates.extend(candidates);
    }
}

/// Every part's roots thinned to blue noise, in the order they grow
/// (as regular roots), with ids.
pub(super) fn all_part_roots(generator: &Generator) -> Vec<PartRoots> {
    let parts = candidates(generator);
    let mut all = Vec::with_capacity(parts.iter().map(|p| p.candidates.len()).sum());
    let mut arrivals = Vec::with_capacity(all.capacity());
    let mut units = Vec::with_capacity(parts.len());
    for part in &parts {
        units.push(Unit {
            candidates: all.len()..all.len() + part.candidates.len(),
            keep: part.keep,
        });
        all.extend_from_slice(&part.candidates);
        arrivals.extend_from_slice(&part.arrivals);
    }
    let hairs = generator.layout.parts().iter().map(|p| p.hair_count).sum();
    let (positions, radii) =
        positions_and_radii(&*generator.sampler, generator.mesh(), &all, hairs);
    drop(all);
    let kept = thin(&positions, &radii, &arrivals, &units);
    parts
        .into_par_iter()
        .zip(units)
        .map(|(part, unit)| survivors(part, &kept[unit.candidates]))
        .collect()
}

/// A part's survivors, in the order a part's regular roots grow (root
/// cells along their Morton curve, each by triangle; without cells, by
/// triangle), with ids.
fn survivors(part: PartCandidates, kept: &[bool]) -> PartRoots {
    let mut free = (0..kept.len())
        .filter(|&k| !kept[k])
        .filter_map(|k| part.ids[k]);
    let mut roots = Vec::with_capacity(part.keep);
    let ends = part.streams.iter().skip(1).copied();
    for (start, end) in part.streams.iter().copied().zip(ends.chain([kept.len()])) {
        let first = roots.len();
        for k in (start..end).filter(|&k| kept[k]) {
            let id = part.ids[k].unwrap_or_else(|| free.next().expect("a free id a new survivor"));
            roots.push((part.candidates[k], id));
        }
        if part.streams.len() > 1 {
            sort_cell_roots(&mut roots[first..]);
        }
    }
    if part.streams.len() <= 1 {
        // Without root cells, the part's one stream: by triangle.
        roots = sorted_by_triangle_with_payload(roots);
    }
    roots.into_iter().unzip()
}

/// Every part's candidates: its root cells' streams (stable ids) or its
/// own.
fn candidates(generator: &Generator) -> Vec<PartCandidates> {
    let seed = generator.seed();
    let sampler = &generator.sampler;
    generator
        .layout
        .parts()
        .par_iter()
        .enumerate()
        .map(|(p, part)| {
            let mut out = PartCandidates::default();
            match &generator.cells {
                Some(cells) => {
                    for &(c, n) in &part.cells {
                        let c = c as usize;
                        let candidates = cells.roots(sampler, seed, c, OVERSAMPLING * n);
                        let regular = (n as usize).min(candidates.len()) as u64;
                        out.push_stream(candidates, (0..regular).map(|k| cells.id(c, k)));
                    }
                }
                None => {
                    let Some(sampler) = sampler.restricted(&part.triangles) else {
                        return out;
                    };
                    let n = part.hair_count;
                    let stream = mix64(seed ^ mix64(salts::PART_ROOTS + p as u64));
                    let mut candidates = sample_range(&sampler, stream, 0..n);
                    let stream = mix64(seed ^ mix64(salts::BLUE_NOISE + p as u64));
                    candidates.extend(sample_range(&sampler, stream, 0..(OVERSAMPLING - 1) * n));
                    out.push_stream(candidates, part.first_hair..part.first_hair + n);
                }
            }
            out
        })
        .collect()
}
