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
        let roots = rest.roots().expect("carried curves have roots");
        out.clone_from(rest);
        let offsets = rest.offsets();
        let (points, normals) = out.points_and_normals_mut();
        let rest_points = rest.points();
        let rest_normals = rest.normals();
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
                    let (root0, frame0) = self.rest.frame_at(&self.triangles, roots[i]);
                    let (root1, frame1) = pose.frame_at(&self.triangles, roots[i]);
                    let turn = frame1 * frame0.transpose();
                    let range = offsets[i] as usize..offsets[i + 1] as usize;
                    let local = range.start - base..range.end - base;
                    for (out, &q) in p[local.clone()].iter_mut().zip(&rest_points[range.clone()]) {
                        *out = root1 + turn * (q - root0);
                        finite &= out.is_finite();
                    }
                    if let (Some(n), Some(rn)) = (n.as_deref_mut(), rest_normals) {
                        for (out, &v) in n[local].iter_mut().zip(&rn[range]) {
                            *out = turn * v;
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
