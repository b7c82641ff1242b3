//! Carrying hair with a deforming skin: each hair is bound at rest to its
//! root's triangle (triangle, barycentrics) and, every frame, moved by the
//! change of that point's surface frame — the approach of Blender's
//! "Deform Curves on Surface" and of Stubble's per-frame generation from
//! bound roots (Sik §4.1).
//!
//! A skin pose is its vertex positions plus area-weighted vertex normals.
//! The frame at a surface point is `(t, n × t, n)`: `n` the vertex normals
//! interpolated at the point, `t` the triangle's first edge made
//! orthogonal to `n`. A hair point `p` at rest goes to
//!
//! ```text
//! p' = root' + F' Fᵀ (p − root)
//! ```
//!
//! with `root`, `F` the root and frame at rest and `root'`, `F'` on the
//! posed skin. A rigid motion of the skin turns every frame by the same
//! rotation, so hairs move rigidly with it to float precision; roots are
//! the barycentric point of the posed triangle, so they stay on the
//! surface however the skin bends.

use crate::Curves;
use crate::mesh::SurfacePoint;
use glam::{Mat3, Vec3};
use rayon::prelude::*;

/// A skin's vertex positions in one pose, with their area-weighted normals.
#[derive(Debug, Clone, PartialEq)]
pub struct SkinPose {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
}

impl SkinPose {
    /// The pose with `positions` (one per vertex of `triangles`' mesh).
    pub fn new(positions: Vec<Vec3>, triangles: &[[u32; 3]]) -> Self {
        let normals = crate::mesh::area_weighted_normals(&positions, triangles);
        Self { positions, normals }
    }

    /// The vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// The area-weighted vertex normals.
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// The point `root` of this pose and its surface frame, as a matrix
    /// whose columns are tangent, bitangent and normal.
    pub fn frame_at(&self, triangles: &[[u32; 3]], root: SurfacePoint) -> (Vec3, Mat3) {
        let [a, b, c] = triangles[root.tri as usize].map(|i| i as usize);
        let (p0, p1, p2) = (self.positions[a], self.positions[b], self.positions[c]);
        let [b1, b2] = root.bary;
        let position = p0 + b1 * (p1 - p0) + b2 * (p2 - p0);
        let [w0, w1, w2] = root.weights();
        let face = (p1 - p0).cross(p2 - p0);
        let normal = (w0 * self.normals[a] + w1 * self.normals[b] + w2 * self.normals[c])
            .try_normalize()
            .or_else(|| face.try_normalize())
            .unwrap_or(Vec3::Z);
        // The longest edge, so a sliver's frame is as well-defined as its
        // triangle allows.
        let edges = [p1 - p0, p2 - p1, p0 - p2];
        let edge = edges
            .into_iter()
            .max_by(|x, y| x.length_squared().total_cmp(&y.length_squared()))
            .unwrap_or(Vec3::X);
        let tangent = (edge - normal * normal.dot(edge))
            .try_normalize()
            .unwrap_or_else(|| normal.any_orthonormal_vector());
        (
            position,
            Mat3::from_cols(tangent, normal.cross(tangent), normal),
        )
    }
}

/// Hairs grown on a rest pose, carried to other poses of the same skin.
#[derive(Debug, Clone)]
pub struct SkinBinding {
    triangles: Vec<[u32; 3]>,
    rest: SkinPose,
}

/// Each curve's root and surface frame at rest ([`SkinBinding::rest_frames`]).
#[derive(Debug, Clone, Default)]
pub struct RestFrames(Vec<(Vec3, Mat3)>);

/// Hairs a worker carries between hand-overs.
const CHUNK: usize = 1024;

impl SkinBinding {
    /// Binds to the skin with `triangles`, whose rest pose is `rest`.
    pub fn new(triangles: Vec<[u32; 3]>, rest: SkinPose) -> Self {
        Self { triangles, rest }
    }

    /// The rest pose.
    pub fn rest(&self) -> &SkinPose {
        &self.rest
    }

    /// The skin's triangles.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// A pose of this skin from its vertex positions.
    pub fn pose(&self, positions: Vec<Vec3>) -> SkinPose {
        SkinPose::new(positions, &self.triangles)
    }

    /// `rest` (curves grown on the rest pose, with their roots) carried to
    /// `pose`, written into `out`: points and normals moved, every other
    /// attribute kept. `out` is reused frame after frame (its arrays are
    /// overwritten, not reallocated). Returns false when a moved value is
    /// not finite (a pose with non-finite positions).
    ///
    /// # Panics
    /// When `rest` has no roots (only grown curves can be carried).
    pub fn carry_into(&self, rest: &Curves, pose: &SkinPose, out: &mut Curves) -> bool {
        out.copy_unmoved_from(rest);
        self.carry_points(rest, None, pose, out)
    }

    /// Each curve's root and surface frame at rest, for carrying the same
    /// curves to many poses ([`Self::carry_again`]).
    pub fn rest_frames(&self, rest: &Curves) -> RestFrames {
        let roots = rest.roots().expect("carried curves have roots");
        RestFrames(
            roots
                .par_iter()
                .map(|&r| self.rest.frame_at(&self.triangles, r))
                .collect(),
        )
    }

    /// [`Self::carry_into`] for an `out` that already holds `rest` carried
    /// to another pose: only points and normals are rewritten, and the
    /// rest frames come from `frames` (deform mode: one growth, every
    /// frame).
    ///
    /// # Panics
    /// When `out` or `frames` were not made from `rest`.
    pub fn carry_again(
        &self,
        rest: &Curves,
        frames: &RestFrames,
        pose: &SkinPose,
        out: &mut Curves,
    ) -> bool {
        assert_eq!(out.offsets(), rest.offsets(), "out holds rest's curves");
        assert_eq!(
            frames.0.len(),
            rest.curve_count(),
            "frames of rest's curves"
        );
        self.carry_points(rest, Some(&frames.0), pose, out)
    }

    /// The velocities of `rest`'s points carried between the poses
    /// `minus` and `plus`: `(x₊ − x₋) · per_second`, where a point's carry
    /// is `root + turn · (q − root₀)`. Each root's two frames are found
    /// once and the difference of the two turns applied to each point,
    /// instead of carrying the part twice. `false` when a value is not
    /// finite.
    pub fn velocities(
        &self,
        rest: &Curves,
        frames: &RestFrames,
        (minus, plus): (&SkinPose, &SkinPose),
        per_second: f32,
        out: &mut Vec<Vec3>,
    ) -> bool {
        let roots = rest.roots().expect("carried curves have roots");
        let offsets = rest.offsets();
        let points = rest.points();
        // Every value is written below (the curves cover every point), so
        // a buffer of the right length from the last frame is reused as it
        // is, not cleared.
        if out.len() != points.len() {
            out.clear();
            out.resize(points.len(), Vec3::ZERO);
        }
        let chunks: Vec<(std::ops::Range<usize>, &mut [Vec3])> = {
            let mut jobs = Vec::new();
            let mut left = &mut out[..];
            let mut start = 0usize;
            for first in (0..roots.len()).step_by(CHUNK) {
                let last = (first + CHUNK).min(roots.len());
                let end = offsets[last] as usize;
                let (a, b) = std::mem::take(&mut left).split_at_mut(end - start);
                left = b;
                jobs.push((first..last, a));
                start = end;
            }
            jobs
        };
        chunks
            .into_par_iter()
            .map(|(hairs, v)| {
                let base = offsets[hairs.start] as usize;
                let mut finite = true;
                for i in hairs {
                    let (root0, frame0) = frames.0[i];
                    let (root_m, frame_m) = minus.frame_at(&self.triangles, roots[i]);
                    let (root_p, frame_p) = plus.frame_at(&self.triangles, roots[i]);
                    let turn = (frame_p - frame_m) * frame0.transpose() * per_second;
                    let shift = (root_p - root_m) * per_second;
                    let range = offsets[i] as usize..offsets[i + 1] as usize;
                    for (o, &q) in v[range.start - base..range.end - base]
                        .iter_mut()
                        .zip(&points[range])
                    {
                        *o = shift + turn * (q - root0);
                        finite &= o.is_finite();
                    }
                }
                finite
            })
            .reduce(|| true, |a, b| a && b)
    }

    /// Curves grown at rest carried to `pose` where they are (no copy:
    /// regrow mode grows a part for each frame and moves it).
    pub fn carry_in_place(&self, curves: &mut Curves, pose: &SkinPose) -> bool {
        let (points, normals, offsets, roots) = curves.carry_view();
        let roots = roots.expect("carried curves have roots");
        self.carry_slices(roots, offsets, None, pose, points, normals, None)
    }

    /// Writes `out`'s points and normals: `rest`'s carried to `pose`.
    fn carry_points(
        &self,
        rest: &Curves,
        rest_frames: Option<&[(Vec3, Mat3)]>,
        pose: &SkinPose,
        out: &mut Curves,
    ) -> bool {
        let roots = rest.roots().expect("carried curves have roots");
        let (points, normals, _, _) = out.carry_view();
        let from = Some((rest.points(), rest.normals()));
        self.carry_slices(
            roots,
            rest.offsets(),
            rest_frames,
            pose,
            points,
            normals,
            from,
        )
    }

    /// The carry: each curve's points (read from `from`, or from `points`
    /// themselves when `None`) turned by its root's change of frame.
    #[allow(clippy::too_many_arguments)]
    fn carry_slices(
        &self,
        roots: &[SurfacePoint],
        offsets: &[u32],
        rest_frames: Option<&[(Vec3, Mat3)]>,
        pose: &SkinPose,
        points: &mut [Vec3],
        normals: Option<&mut [Vec3]>,
        from: Option<(&[Vec3], Option<&[Vec3]>)>,
    ) -> bool {
        // Split the point arrays at chunk boundaries so each worker owns
        // its hairs' slices.
        let curves = roots.len();
        let mut jobs = Vec::with_capacity(curves.div_ceil(CHUNK));
        let (mut p_rest, mut n_rest) = (points, normals);
        let mut start = 0usize;
        for first in (0..curves).step_by(CHUNK) {
            let last = (first + CHUNK).min(curves);
            let end = offsets[last] as usize;
            let (p0, p1) = std::mem::take(&mut p_rest).split_at_mut(end - start);
            p_rest = p1;
            let n0 = match n_rest.take() {
                Some(n) => {
                    let (n0, n1) = n.split_at_mut(end - start);
                    n_rest = Some(n1);
                    Some(n0)
                }
                None => None,
            };
            jobs.push((first..last, start, p0, n0));
            start = end;
        }
        jobs.into_par_iter()
            .map(|(hairs, base, p, mut n)| {
                let mut finite = true;
                for i in hairs {
                    let (root0, frame0) = match rest_frames {
                        Some(f) => f[i],
                        None => self.rest.frame_at(&self.triangles, roots[i]),
                    };
                    let (root1, frame1) = pose.frame_at(&self.triangles, roots[i]);
                    let turn = frame1 * frame0.transpose();
                    let range = offsets[i] as usize..offsets[i + 1] as usize;
                    let local = range.start - base..range.end - base;
                    let out = &mut p[local.clone()];
                    match from {
                        Some((rest, _)) => {
                            for (o, &q) in out.iter_mut().zip(&rest[range.clone()]) {
                                *o = root1 + turn * (q - root0);
                            }
                        }
                        None => out
                            .iter_mut()
                            .for_each(|o| *o = root1 + turn * (*o - root0)),
                    }
                    finite &= out.iter().all(|o| o.is_finite());
                    if let Some(n) = n.as_deref_mut() {
                        let out = &mut n[local];
                        match from {
                            Some((_, Some(rest))) => {
                                for (o, &v) in out.iter_mut().zip(&rest[range]) {
                                    *o = turn * v;
                                }
                            }
                            _ => out.iter_mut().for_each(|o| *o = turn * *o),
                        }
                    }
                }
                finite
            })
            .reduce(|| true, |a, b| a && b)
    }

    /// `rest` carried to `pose`, as new curves.
    pub fn carry(&self, rest: &Curves, pose: &SkinPose) -> Option<Curves> {
        let mut out = Curves::default();
        self.carry_into(rest, pose, &mut out).then_some(out)
    }

    /// Guide curves posed on `pose` (their roots bound at rest) brought
    /// back to rest: the inverse of [`Self::carry`], each guide turned
    /// about its own first point, which lands on its rest root. Used to
    /// regrow from animated guides with every operator in rest space.
    pub fn to_rest(&self, posed: &[Vec3], root: SurfacePoint, pose: &SkinPose, out: &mut [Vec3]) {
        let (root0, frame0) = self.rest.frame_at(&self.triangles, root);
        let (_, frame1) = pose.frame_at(&self.triangles, root);
        let turn = frame0 * frame1.transpose();
        let Some(&first) = posed.first() else {
            return;
        };
        for (o, &p) in out.iter_mut().zip(posed) {
            *o = root0 + turn * (p - first);
        }
    }
}
