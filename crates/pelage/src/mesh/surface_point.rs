//! A point on a mesh ([`SurfacePoint`]: triangle index and two barycentric
//! coordinates) and what is evaluated there: position, shading normal, UV
//! and an orthonormal tangent frame.
//!
//! Hair roots are surface points. Storing the triangle and barycentrics,
//! not a position, keeps every attribute (UV for maps, the frame hair is
//! shaped in) exactly recoverable, as Blender's curves do ("the third
//! [coordinate] can be derived").

use super::Mesh;
use glam::{Vec2, Vec3};

/// A point on a triangle of a mesh: `tri` and barycentric coordinates
/// `bary = [b1, b2]`. The corner weights are `(1 − b1 − b2, b1, b2)`, so
/// `position = p0 + b1 (p1 − p0) + b2 (p2 − p0)`. Points inside the
/// triangle have `b1, b2 ≥ 0` and `b1 + b2 ≤ 1`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SurfacePoint {
    /// Triangle index into [`Mesh::triangles`].
    pub tri: u32,
    /// Barycentric coordinates of corners 1 and 2.
    pub bary: [f32; 2],
}

/// An orthonormal, right-handed frame at a surface point:
/// `tangent × bitangent = normal`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentFrame {
    /// Unit tangent. With UVs, the direction of increasing U projected
    /// into the tangent plane; without, a stable direction derived from
    /// the normal alone.
    pub tangent: Vec3,
    /// Unit bitangent, `normal × tangent`.
    pub bitangent: Vec3,
    /// Unit shading normal.
    pub normal: Vec3,
}

impl TangentFrame {
    /// A frame around `normal` (unit) with no preferred tangent: the
    /// branch-free construction of Duff et al. 2017, "Building an
    /// Orthonormal Basis, Revisited", continuous except across z = 0's sign.
    pub fn from_normal(normal: Vec3) -> Self {
        let (tangent, bitangent) = normal.any_orthonormal_pair();
        Self {
            tangent,
            bitangent,
            normal,
        }
    }

    /// Expresses a world-space vector in this frame: `(t·v, b·v, n·v)`.
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(
            self.tangent.dot(v),
            self.bitangent.dot(v),
            self.normal.dot(v),
        )
    }

    /// Turns a vector in this frame's coordinates back into world space.
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.tangent * v.x + self.bitangent * v.y + self.normal * v.z
    }
}

impl SurfacePoint {
    /// A point on triangle `tri` with barycentrics `[b1, b2]`.
    pub fn new(tri: u32, bary: [f32; 2]) -> Self {
        Self { tri, bary }
    }

    /// The corner weights `(1 − b1 − b2, b1, b2)`.
    pub fn weights(&self) -> [f32; 3] {
        let [b1, b2] = self.bary;
        [1.0 - b1 - b2, b1, b2]
    }

    /// Whether `tri` exists in `mesh` and the barycentrics lie in the
    /// triangle (with a small tolerance for rounding).
    pub fn is_valid_for(&self, mesh: &Mesh) -> bool {
        const EPS: f32 = 1e-5;
        let [w0, w1, w2] = self.weights();
        (self.tri as usize) < mesh.triangle_count()
            && self.bary.iter().all(|b| b.is_finite())
            && w0 >= -EPS
            && w1 >= -EPS
            && w2 >= -EPS
    }

    /// Position on the surface.
    pub fn position(&self, mesh: &Mesh) -> Vec3 {
        let [p0, p1, p2] = mesh.triangle_positions(self.tri as usize);
        let [b1, b2] = self.bary;
        p0 + b1 * (p1 - p0) + b2 * (p2 - p0)
    }

    /// Unit shading normal: the vertex normals interpolated and
    /// renormalised, or the face normal where they cancel out.
    pub fn normal(&self, mesh: &Mesh) -> Vec3 {
        let [a, b, c] = mesh.triangles()[self.tri as usize];
        let n = mesh.normals();
        let [w0, w1, w2] = self.weights();
        let interpolated = w0 * n[a as usize] + w1 * n[b as usize] + w2 * n[c as usize];
        interpolated
            .try_normalize()
            .or_else(|| mesh.face_normal(self.tri as usize).try_normalize())
            .unwrap_or(Vec3::Z)
    }

    /// Texture coordinate, or `None` if the mesh has no UVs.
    pub fn uv(&self, mesh: &Mesh) -> Option<Vec2> {
        let [t0, t1, t2] = mesh.triangle_uvs(self.tri as usize)?;
        let [b1, b2] = self.bary;
        Some(t0 + b1 * (t1 - t0) + b2 * (t2 - t0))
    }

    /// Orthonormal frame around the shading normal. With UVs the tangent
    /// follows ∂P/∂u of the triangle (so hair combed "along U" points the
    /// same way across a chart); where UVs are missing or degenerate on this
    /// triangle it falls back to [`TangentFrame::from_normal`]. The frame is
    /// constant in tangent direction per triangle; it is not smoothed
    /// across edges.
    pub fn tangent_frame(&self, mesh: &Mesh) -> TangentFrame {
        let normal = self.normal(mesh);
        let Some(dp_du) = dp_du(mesh, self.tri as usize) else {
            return TangentFrame::from_normal(normal);
        };
        match (dp_du - normal * normal.dot(dp_du)).try_normalize() {
            Some(tangent) => TangentFrame {
                tangent,
                bitangent: normal.cross(tangent),
                normal,
            },
            None => TangentFrame::from_normal(normal),
        }
    }
}

/// ∂P/∂u of a triangle from its positions and UVs (the standard per-face
/// tangent: solve `[e1 e2] = [∂P/∂u ∂P/∂v] [Δuv1 Δuv2]`), or `None` when the
/// mesh has no UVs or the triangle's UV footprint has no area.
fn dp_du(mesh: &Mesh, tri: usize) -> Option<Vec3> {
    let [t0, t1, t2] = mesh.triangle_uvs(tri)?;
    let [p0, p1, p2] = mesh.triangle_positions(tri);
    let (e1, e2) = (p1 - p0, p2 - p0);
    let (d1, d2) = (t1 - t0, t2 - t0);
    let det = d1.x * d2.y - d2.x * d1.y;
    if det.abs() <= f32::EPSILON * (d1.length_squared() + d2.length_squared()) {
        return None;
    }
    Some((e1 * d2.y - e2 * d1.y) / det)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tests::{tetrahedron, unit_square};

    #[test]
    fn corners_evaluate_to_vertices() {
        let m = unit_square();
        for (bary, vertex) in [([0.0, 0.0], 0), ([1.0, 0.0], 1), ([0.0, 1.0], 2)] {
            let sp = SurfacePoint::new(0, bary);
            assert_eq!(sp.position(&m), m.positions()[vertex]);
        }
    }

    #[test]
    fn uv_follows_position_on_planar_square() {
        let m = unit_square();
        let sp = SurfacePoint::new(1, [0.25, 0.5]);
        let p = sp.position(&m);
        assert!((sp.uv(&m).unwrap() - p.truncate()).length() < 1e-6);
    }

    #[test]
    fn frame_tangent_follows_u_when_uvs_exist() {
        let m = unit_square();
        let f = SurfacePoint::new(0, [0.3, 0.3]).tangent_frame(&m);
        assert!((f.tangent - Vec3::X).length() < 1e-6);
        assert!((f.bitangent - Vec3::Y).length() < 1e-6);
        assert!((f.normal - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn frame_without_uvs_is_orthonormal_and_right_handed() {
        let m = tetrahedron();
        for tri in 0..4 {
            let f = SurfacePoint::new(tri, [0.2, 0.3]).tangent_frame(&m);
            assert!((f.tangent.length() - 1.0).abs() < 1e-5);
            assert!(f.tangent.dot(f.normal).abs() < 1e-5);
            assert!(f.bitangent.dot(f.normal).abs() < 1e-5);
            assert!((f.tangent.cross(f.bitangent) - f.normal).length() < 1e-5);
            let v = Vec3::new(0.3, -1.2, 2.0);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }

    #[test]
    fn validity_check_rejects_points_outside() {
        let m = unit_square();
        assert!(SurfacePoint::new(1, [0.5, 0.5]).is_valid_for(&m));
        assert!(!SurfacePoint::new(2, [0.1, 0.1]).is_valid_for(&m));
        assert!(!SurfacePoint::new(0, [0.8, 0.8]).is_valid_for(&m));
        assert!(!SurfacePoint::new(0, [f32::NAN, 0.1]).is_valid_for(&m));
    }
}
