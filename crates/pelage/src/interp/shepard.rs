//! Shepard interpolation over a kd-tree (Sik §4.2.2, as Stubble does it):
//! the k guide roots nearest a hair root in space, each weighted
//! `1 / d^p` (Shepard 1968), normalised to sum 1. A hair exactly at a guide
//! root takes that guide alone; with a radius, guides farther away are
//! ignored, and a hair with none inside takes its nearest guide alone.

use super::{GuideWeight, GuideWeights, HairRoot, normalise};
use crate::guides::Guides;
use crate::mesh::Mesh;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::num::NonZeroUsize;

/// Inverse-distance weights over the k nearest guide roots.
pub struct Shepard {
    tree: Option<ImmutableKdTree<f32, 3>>,
    k: NonZeroUsize,
    power: f32,
    radius_squared: f32,
}

impl Shepard {
    /// A kd-tree over the guides' root positions.
    pub fn new(mesh: &Mesh, guides: &Guides, k: usize, power: f32, radius: Option<f32>) -> Self {
        let roots: Vec<[f32; 3]> = guides
            .roots()
            .iter()
            .map(|r| r.position(mesh).to_array())
            .collect();
        Self {
            tree: (!roots.is_empty())
                .then(|| ImmutableKdTree::new_from_slice(&roots).expect("finite guide roots")),
            k: NonZeroUsize::new(k.clamp(1, roots.len().max(1))).expect("at least 1"),
            power,
            radius_squared: radius.map_or(f32::INFINITY, |r| r * r),
        }
    }
}

impl GuideWeights for Shepard {
    fn weights(&self, root: HairRoot, out: &mut Vec<GuideWeight>) {
        out.clear();
        let Some(tree) = &self.tree else { return };
        let nearest = tree
            .query(&root.position.to_array())
            .nearest_n::<SquaredEuclidean<f32>>(self.k)
            .execute();
        for (i, hit) in nearest.iter().enumerate() {
            let guide = hit.item;
            // At a guide's root: that guide alone (1/0 would swamp the rest).
            if hit.distance <= 1e-14 {
                out.clear();
                out.push(GuideWeight { guide, weight: 1.0 });
                return;
            }
            if hit.distance > self.radius_squared && i > 0 {
                break;
            }
            // The usual power 2 needs no powf.
            let weight = if self.power == 2.0 {
                hit.distance.recip()
            } else {
                hit.distance.powf(-0.5 * self.power)
            };
            out.push(GuideWeight { guide, weight });
        }
        normalise(out);
    }
}
