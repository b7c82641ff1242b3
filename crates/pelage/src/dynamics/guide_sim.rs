//! Guides simulated on an animated skin: [`GuideStrands`] whose roots are the
//! guides' roots on the posed skin (the surface frames of
//! [`SkinPose::frame_at`], as deform carries hair), colliding with the
//! skin's [`SkinSdf`], built at every substep from the skin's vertices
//! interpolated linearly between frames: a running leg moves farther in
//! a frame than it is thick, and must push the fur on its way rather than
//! jump over it.

use super::skin_sdf::SkinSdf;
use super::strands::{GuideStrandParams, GuideStrands, RootFrame, StrandError};
use crate::Curves;
use crate::anim::SkinPose;
use crate::guides::Guides;
use crate::mesh::SurfacePoint;
use glam::Vec3;
use rayon::prelude::*;

/// Nodes along the skin's longest side of its collision grid: the grid
/// only has to find the triangles near a point (distances there are
/// exact), and it is rebuilt every substep.
const GRID_NODES_ALONG: f32 = 48.0;

/// A groom's guides moving with an animated skin.
#[derive(Debug, Clone)]
pub struct GuideSimulation {
    triangles: Vec<[u32; 3]>,
    roots: Vec<SurfacePoint>,
    widths: Vec<f32>,
    strands: GuideStrands,
    params: GuideStrandParams,
    collide: bool,
    /// Node spacing of the collision grid.
    cell: f32,
    /// The longest segment: how far a point can go into the skin in one
    /// length pass.
    segment: f32,
    /// The skin's vertices at the end of the last step.
    last_positions: Vec<Vec3>,
}

impl GuideSimulation {
    /// The guides at rest on `rest` (the pose they were bound on), to be
    /// moved with `params`, colliding with the skin when `collide`.
    pub fn new(
        guides: &Guides,
        triangles: &[[u32; 3]],
        rest: &SkinPose,
        params: GuideStrandParams,
        collide: bool,
    ) -> Result<Self, StrandError> {
        let roots: Vec<RootFrame> = guides
            .roots()
            .par_iter()
            .map(|&r| root_frame(rest, triangles, r))
            .collect();
        let strands =
            GuideStrands::new(guides.curves().points(), guides.points_per_guide(), &roots)?;
        let (lo, hi) = crate::mesh::bounds_of(rest.positions());
        let longest = (hi - lo).max_element().max(f32::MIN_POSITIVE);
        let most = crate::limits::MAX_THICKNESS_OF_SKIN * longest;
        if params.thickness.is_nan() || params.thickness > most {
            return Err(StrandError::Thickness {
                thickness: params.thickness,
                most,
            });
        }
        let segment = strands
            .rest_lengths()
            .iter()
            .copied()
            .fold(0.0f32, f32::max);
        let cell = longest / GRID_NODES_ALONG;
        Ok(Self {
            triangles: triangles.to_vec(),
            roots: guides.roots().to_vec(),
            widths: guides.curves().widths().to_vec(),
            strands,
            params,
            collide,
            cell,
            segment,
            last_positions: rest.positions().to_vec(),
        })
    }

    /// The strands as simulated so far.
    pub fn strands(&self) -> &GuideStrands {
        &self.strands
    }

    /// The settings.
    pub fn params(&self) -> &GuideStrandParams {
        &self.params
    }

    /// The guides' root frames on `pose`.
    pub fn root_frames(&self, pose: &SkinPose) -> Vec<RootFrame> {
        self.roots
            .par_iter()
            .map(|&r| root_frame(pose, &self.triangles, r))
            .collect()
    }

    /// The collision grid of `pose`.
    pub fn skin_sdf(&self, pose: &SkinPose) -> SkinSdf {
        SkinSdf::new(
            pose.positions(),
            pose.normals(),
            &self.triangles,
            self.cell,
            self.depth(0.0),
        )
    }

    /// How deep a grid's exact band must reach: a point goes into the skin
    /// by at most a segment (its own move) or by the skin's move in a
    /// substep over it, plus the thickness it is kept at, plus a cell of
    /// interpolation.
    fn depth(&self, skin_move: f32) -> f32 {
        self.segment.max(skin_move) + self.params.thickness.max(0.0) + self.cell
    }

    /// Puts the guides in their groomed shape on `pose`, at rest (the
    /// start of a simulation).
    pub fn reset(&mut self, pose: &SkinPose) {
        let roots = self.root_frames(pose);
        self.strands.reset(&roots);
        self.last_positions = pose.positions().to_vec();
    }

    /// The skin's grid at the end of every substep of a step to `pose`:
    /// the vertices interpolated from where they were, the band deepened
    /// by how far they move in a substep.
    pub fn substep_grids(&self, pose: &SkinPose) -> Vec<SkinSdf> {
        if !self.collide {
            return Vec::new();
        }
        let substeps = self.params.substeps.max(1);
        let to = pose.positions();
        let from = if self.last_positions.len() == to.len() {
            &self.last_positions[..]
        } else {
            to
        };
        let moved = from
            .iter()
            .zip(to)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0f32, f32::max);
        let depth = self.depth(moved / substeps as f32);
        (1..=substeps)
            .map(|s| {
                let a = s as f32 / substeps as f32;
                if a >= 1.0 {
                    return SkinSdf::new(to, pose.normals(), &self.triangles, self.cell, depth);
                }
                let positions: Vec<Vec3> =
                    from.iter().zip(to).map(|(p, q)| p.lerp(*q, a)).collect();
                let normals = crate::mesh::area_weighted_normals(&positions, &self.triangles);
                SkinSdf::new(&positions, &normals, &self.triangles, self.cell, depth)
            })
            .collect()
    }

    /// Advances `dt` seconds to time `time`, when the skin is at `pose`.
    pub fn advance(&mut self, pose: &SkinPose, dt: f32, time: f32) {
        let roots = self.root_frames(pose);
        let grids = self.substep_grids(pose);
        self.advance_with(pose, &roots, &grids, dt, time);
    }

    /// [`advance`](Self::advance) with the roots and the skin's grids
    /// already made (for a caller that times them or makes them
    /// elsewhere).
    pub fn advance_with(
        &mut self,
        pose: &SkinPose,
        roots: &[RootFrame],
        grids: &[SkinSdf],
        dt: f32,
        time: f32,
    ) {
        self.strands.step(&self.params, dt, time, roots, grids);
        self.last_positions.clear();
        self.last_positions.extend_from_slice(pose.positions());
    }

    /// Records that the skin is now at `pose` without stepping (for a
    /// caller that stepped the strands elsewhere, on a GPU): the next
    /// step's grids start from it.
    pub fn note_pose(&mut self, pose: &SkinPose) {
        self.last_positions.clear();
        self.last_positions.extend_from_slice(pose.positions());
    }

    /// The guides as they are now: one curve each, with the guides'
    /// widths and roots. Fails where a point is not finite (settings far
    /// out of range: a gravity of 1e38).
    pub fn curves(&self) -> Result<Curves, crate::curves::CurvesError> {
        let n = self.strands.points_per_strand();
        let offsets = (0..=self.roots.len()).map(|i| (i * n) as u32).collect();
        Curves::new(
            self.strands.positions().to_vec(),
            self.widths.clone(),
            offsets,
        )
        .and_then(|c| c.with_roots(self.roots.clone()))
    }
}

fn root_frame(pose: &SkinPose, triangles: &[[u32; 3]], root: SurfacePoint) -> RootFrame {
    let (position, frame) = pose.frame_at(triangles, root);
    RootFrame { position, frame }
}
