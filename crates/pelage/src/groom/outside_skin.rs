//! Hairs out of the skin: a finishing step after the operators. Noise,
//! curl, clumps and frizz move points without looking at the skin, and
//! where the skin curves away under a hair they push points into it.
//! Every point nearer the skin than a gap is pushed out to the gap, and
//! the rest of the hair follows, each point at its length from the one
//! before (follow-the-leader, the step the guide strands' solver uses:
//! [`crate::dynamics::strands::follow_outside`]). Hairs clear of the skin
//! are left bit for bit as they were.
//!
//! The skin is the groom's mesh at rest, as a [`SkinSdf`]: exact near the
//! skin, and thin parts (ears, tails) seen as such.

use crate::Mesh;
use crate::dynamics::SkinSdf;
use crate::dynamics::strands::{SkinContact, follow_outside};
use glam::Vec3;

/// Grid nodes along the mesh's longest side: fine, since a still groom's
/// grid is built once.
const NODES_ALONG: f32 = 128.0;

/// The skin a groom's hairs are kept out of.
#[derive(Debug, Clone)]
pub struct OutsideSkin {
    skin: SkinSdf,
    gap: f32,
}

impl OutsideSkin {
    /// The skin of `mesh` (at rest), keeping hairs `gap` above it, for
    /// hairs whose segments are about `segment` long.
    ///
    /// The grid's exact band reaches two segments deep: follow-the-leader
    /// puts each point at its length from a predecessor outside the skin,
    /// so no point it places is deeper than a segment, and a hair that an
    /// operator sent deeper crosses the band on its way in from the root.
    pub fn new(mesh: &Mesh, gap: f32, segment: f32) -> Self {
        let (lo, hi) = mesh.bounds();
        let size = (hi - lo).max_element().max(f32::MIN_POSITIVE);
        let cell = size / NODES_ALONG;
        let skin = SkinSdf::new(
            mesh.positions(),
            mesh.normals(),
            mesh.triangles(),
            cell,
            2.0 * segment + gap,
        );
        Self { skin, gap }
    }

    /// The gap kept between hairs and the skin.
    pub fn gap(&self) -> f32 {
        self.gap
    }

    /// The default gap for `mesh`: a thousandth of its size.
    pub fn default_gap(mesh: &Mesh) -> f32 {
        let (lo, hi) = mesh.bounds();
        1e-3 * (hi - lo).max_element()
    }

    /// Pushes the hair `points` (root first; the root stays) out of the
    /// skin, keeping every segment's length; `normal` is the skin normal
    /// at the root (the direction of a point that sits on its leader).
    /// Returns whether anything moved.
    pub fn apply(&self, points: &mut [Vec3], normal: Vec3) -> bool {
        let Some(first) = points
            .iter()
            .skip(1)
            .position(|&p| !self.skin.clear_of(p, self.gap) && self.skin.sample(p).0 < self.gap)
            .map(|i| i + 1)
        else {
            return false;
        };
        let mut before = points[first - 1];
        for i in first..points.len() {
            let target = points[i];
            let length = (target - before).length();
            let (q, _) = follow_outside(
                points[i - 1],
                target,
                length,
                normal,
                Some(&self.skin),
                &SkinContact {
                    thickness: self.gap,
                    // Any point outside the skin keeps its length; only
                    // one that would go back in stays where the push put
                    // it.
                    keep_length_above: 0.0,
                    // A still groom is pushed once: it can afford to look
                    // harder for a place at the segment's length.
                    passes: 8,
                },
            );
            before = target;
            points[i] = q;
        }
        true
    }
}
