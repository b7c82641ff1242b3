//! Shepard interpolation over a kd-tree (Sik §4.2.2, as Stubble does it):
//! the k guide roots nearest a hair root in space, each weighted
//! `1 / d^p` (Shepard 1968), normalised to sum 1. A hair exactly at a guide
//! root takes that guide alone; with a radius, guides farther away are
//! ignored, and a hair with none inside takes its nearest guide alone.
//! A run of nearby roots is answered from a candidate list instead of the
//! tree ([`crate::nearest::NearestPoints`]), with the same result.

use super::{GuideWeight, GuideWeights, HairRoot, normalise};
use crate::guides::Guides;
use crate::mesh::Mesh;
use crate::nearest::{NearestPoints, Neighbour, NeighbourCache};

/// Inverse-distance weights over the k nearest guide roots.
pub struct Shepard {
    roots: NearestPoints,
    k: usize,
    power: f32,
    radius_squared: f32,
}

impl Shepard {
    /// A kd-tree over the guides' root positions.
    pub fn new(mesh: &Mesh, guides: &Guides, k: usize, power: f32, radius: Option<f32>) -> Self {
        let roots = guides.roots().iter().map(|r| r.position(mesh)).collect();
        Self {
            roots: NearestPoints::new(roots),
            k: k.max(1),
            power,
            radius_squared: radius.map_or(f32::INFINITY, |r| r * r),
        }
    }
}

impl Shepard {
    /// Weights from the nearest guides, nearest first.
    fn weigh(&self, nearest: impl IntoIterator<Item = Neighbour>, out: &mut Vec<GuideWeight>) {
        out.clear();
        for (i, hit) in nearest.into_iter().enumerate() {
            let guide = hit.index;
            let distance = hit.distance_squared;
            // At a guide's root: that guide alone (1/0 would swamp the rest).
            if distance <= 1e-14 {
                out.clear();
                out.push(GuideWeight { guide, weight: 1.0 });
                return;
            }
            if distance > self.radius_squared && i > 0 {
                break;
            }
            // The usual power 2 needs no powf.
            let weight = if self.power == 2.0 {
                distance.recip()
            } else {
                distance.powf(-0.5 * self.power)
            };
            out.push(GuideWeight { guide, weight });
        }
        normalise(out);
    }
}

impl GuideWeights for Shepard {
    fn weights(&self, root: HairRoot, out: &mut Vec<GuideWeight>) {
        let mut nearest = Vec::with_capacity(self.k);
        self.roots.nearest(root.position, self.k, &mut nearest);
        self.weigh(nearest, out);
    }

    fn weights_near(&self, root: HairRoot, near: &mut NeighbourCache, out: &mut Vec<GuideWeight>) {
        self.weigh(self.roots.nearest_cached(root.position, self.k, near), out);
    }
}
