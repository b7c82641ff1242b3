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
//! skin, and thin parts (ears, tails) seen as such. An animated groom
//! keeps its hairs out of each frame's posed skin the same way
//! ([`OutsideSkin::posed`]): carried by their roots' frames, or regrown
//! from guides that collided, hairs still go into the body where it
//! bends (a shoulder, a haunch) or between the guides.

use crate::dynamics::SkinSdf;
use crate::dynamics::strands::{SkinContact, follow_outside};
use crate::mesh::SurfacePoint;
use crate::{Curves, Mesh};
use glam::Vec3;
use rayon::prelude::*;

/// Grid nodes along the mesh's longest side: fine, since a still groom's
/// grid is built once.
const NODES_ALONG: f32 = 128.0;

/// Grid nodes along a posed skin's longest side: an animated groom keeps
/// a grid for every frame a write holds, and a query within a cell of the
/// skin is exact at any cell size (it measures the nearby triangles).
const POSED_NODES_ALONG: f32 = 64.0;

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
        Self::with_cells(
            (mesh.positions(), mesh.normals(), mesh.triangles()),
            NODES_ALONG,
            gap,
            2.0 * segment,
        )
    }

    /// The skin in one pose (`positions` and their `normals`, on
    /// `triangles`), as [`Self::new`] keeps hairs out of it. The band is
    /// as deep as there: however a pose folds the skin over a hair, the
    /// first of its points inside lies within a segment of the one before
    /// it, outside.
    pub fn posed(
        (positions, normals, triangles): (&[Vec3], &[Vec3], &[[u32; 3]]),
        gap: f32,
        segment: f32,
    ) -> Self {
        Self::with_cells(
            (positions, normals, triangles),
            POSED_NODES_ALONG,
            gap,
            2.0 * segment,
        )
    }

    /// The grid, `nodes_along` nodes along its longest side, exact
    /// `depth + gap` deep.
    fn with_cells(
        (positions, normals, triangles): (&[Vec3], &[Vec3], &[[u32; 3]]),
        nodes_along: f32,
        gap: f32,
        depth: f32,
    ) -> Self {
        let (lo, hi) = positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let size = (hi - lo).max_element().max(f32::MIN_POSITIVE);
        let cell = size / nodes_along;
        let skin = SkinSdf::new(positions, normals, triangles, cell, depth + gap);
        Self { skin, gap }
    }

    /// A hair's segment, for hairs of `points` points shaped by `guides`:
    /// the longest guide's length over the hair's segments (the depth of
    /// band a pushed hair crosses).
    pub fn segment(guides: &crate::guides::Guides, points: usize) -> f32 {
        let longest = (0..guides.len())
            .map(|g| guides.length(g))
            .fold(0.0f32, f32::max);
        longest / (points.max(2) - 1) as f32
    }

    /// The skin as a distance grid (for a GPU port of [`Self::apply`]).
    pub fn sdf(&self) -> &SkinSdf {
        &self.skin
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

    /// [`Self::apply`] to every hair of `curves`, in parallel;
    /// `normal_at(root)` is the skin normal at a hair's root (curves
    /// without roots take their first segment's direction). Returns how
    /// many hairs moved.
    pub fn apply_all(
        &self,
        curves: &mut Curves,
        normal_at: impl Fn(SurfacePoint) -> Vec3 + Sync,
    ) -> usize {
        let (points, _, offsets, roots) = curves.carry_view();
        let mut hairs = Vec::with_capacity(offsets.len().saturating_sub(1));
        let mut rest = points;
        for w in offsets.windows(2) {
            let (hair, after) = std::mem::take(&mut rest).split_at_mut((w[1] - w[0]) as usize);
            hairs.push(hair);
            rest = after;
        }
        hairs
            .into_par_iter()
            .enumerate()
            .map(|(c, hair)| {
                let normal = match roots {
                    Some(roots) => normal_at(roots[c]),
                    None if hair.len() > 1 => (hair[1] - hair[0]).normalize_or(Vec3::Y),
                    None => Vec3::Y,
                };
                usize::from(self.apply(hair, normal))
            })
            .sum()
    }
}
