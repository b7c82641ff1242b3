//! Blue-noise roots: a part's roots drawn four times over and thinned back
//! by weighted sample elimination (`sample/blue_noise.rs` says how).
//!
//! The candidates are the part's own roots and three times as many more
//! from its own stream; hairs keep the part's ids (a survivor that was a
//! root keeps its id, the others take the ids of the roots removed, in
//! order), so ids stay unique and the same on every run. The elimination
//! runs inside one part, so neighbours across a part border are not
//! thinned against each other.

use super::generator::Generator;
use super::parts::sorted_by_triangle_with_ids;
use crate::mesh::SurfacePoint;
use crate::sample::blue_noise::{OVERSAMPLING, eliminate, positions_and_radii};
use crate::sample::{mix64, salts, sample_range};

/// Part `p`'s roots thinned to blue noise, ordered by triangle, with ids.
pub(super) fn part_roots(generator: &Generator, p: usize) -> (Vec<SurfacePoint>, Vec<u64>) {
    let part = &generator.layout.parts()[p];
    let (roots, ids) = generator.regular_part_roots(p);
    let n = roots.len() as u64;
    if n < 2 {
        return (roots, ids);
    }
    let Some(sampler) = generator.sampler.restricted(&part.triangles) else {
        return (roots, ids);
    };
    let mesh = generator.mesh();
    let stream = mix64(generator.seed() ^ mix64(salts::BLUE_NOISE + p as u64));
    let mut candidates = roots.clone();
    candidates.extend(sample_range(&sampler, stream, 0..(OVERSAMPLING - 1) * n));
    let (positions, radii) = positions_and_radii(&sampler, mesh, &candidates, n);
    let kept = eliminate(&positions, &radii, n as usize);
    // Survivors that were roots keep their ids; the others take the ids
    // of the roots removed, in order.
    let mut is_kept = vec![false; candidates.len()];
    for &i in &kept {
        is_kept[i] = true;
    }
    let mut free = (0..roots.len()).filter(|&i| !is_kept[i]).map(|i| ids[i]);
    let mut out_roots = Vec::with_capacity(kept.len());
    let mut out_ids = Vec::with_capacity(kept.len());
    for i in kept {
        out_roots.push(candidates[i]);
        out_ids.push(if i < roots.len() {
            ids[i]
        } else {
            free.next().expect("as many free ids as new survivors")
        });
    }
    sorted_by_triangle_with_ids(out_roots, out_ids)
}
