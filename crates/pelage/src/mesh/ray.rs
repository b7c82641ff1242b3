//! Rays against the surface: the first triangle a ray meets, as a
//! [`SurfacePoint`] — what the viewer needs to turn a click into a UV
//! (a droplet on the fur, Silva §3.1) or a point to push (Banisch's
//! "locally apply forces by user input").
//!
//! Möller & Trumbore's test (1997) over every triangle: a click is one ray,
//! and a hundred thousand triangles take well under a millisecond, so no
//! acceleration structure is kept for it.

use super::{Mesh, SurfacePoint};
use glam::Vec3;

/// Where a ray first meets the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// The point on the mesh.
    pub point: SurfacePoint,
    /// Distance along the ray, in units of the ray's direction.
    pub distance: f32,
}

/// The nearest hit of the ray `origin + t · direction`, `t > 0`, with any
/// triangle (either side), or `None`. Degenerate triangles are never hit.
pub fn first_hit(mesh: &Mesh, origin: Vec3, direction: Vec3) -> Option<RayHit> {
    let mut best: Option<RayHit> = None;
    for t in 0..mesh.triangle_count() {
        let [p0, p1, p2] = mesh.triangle_positions(t);
        let Some((distance, b1, b2)) = intersect(origin, direction, p0, p1, p2) else {
            continue;
        };
        if best.is_none_or(|b| distance < b.distance) {
            best = Some(RayHit {
                point: SurfacePoint::new(t as u32, [b1, b2]),
                distance,
            });
        }
    }
    best
}

/// Möller–Trumbore: `(t, b1, b2)` with the hit at `(1 − b1 − b2) p0 + b1 p1
/// + b2 p2 = origin + t · direction`, for `t > 0` inside the triangle.
fn intersect(
    origin: Vec3,
    direction: Vec3,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
) -> Option<(f32, f32, f32)> {
    let (e1, e2) = (p1 - p0, p2 - p0);
    let h = direction.cross(e2);
    let det = e1.dot(h);
    // Relative to the triangle's size and the ray's length, so tiny and
    // huge meshes behave alike.
    if det.abs() <= 1e-12 * e1.length_squared().max(e2.length_squared()) * direction.length() {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - p0;
    let b1 = s.dot(h) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = direction.dot(q) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0).then_some((t, b1, b2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    #[test]
    fn a_ray_down_the_axis_hits_the_near_side_of_spot_at_the_right_uv() {
        let mesh = crate::assets::spot();
        let (lo, hi) = mesh.bounds();
        let centre = 0.5 * (lo + hi);
        let origin = Vec3::new(centre.x, centre.y, hi.z + 1.0);
        let hit = first_hit(&mesh, origin, Vec3::NEG_Z).expect("spot is in the way");
        let p = hit.point.position(&mesh);
        // On the ray, and no triangle is nearer than the one reported.
        assert!((p - (origin + hit.distance * Vec3::NEG_Z)).length() < 1e-4);
        assert!(p.z > centre.z, "the near side, not the far one: {p}");
        let uv = hit.point.uv(&mesh).expect("spot has UVs");
        assert!(uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all());
        // The same point reached from the far side is the far hit.
        let back = first_hit(&mesh, Vec3::new(centre.x, centre.y, lo.z - 1.0), Vec3::Z).unwrap();
        assert!(back.point.position(&mesh).z < centre.z);
    }

    #[test]
    fn rays_that_miss_or_point_away_find_nothing() {
        let mesh = crate::assets::spot();
        let (lo, hi) = mesh.bounds();
        let above = Vec3::new(0.5 * (lo.x + hi.x), hi.y + 1.0, 0.5 * (lo.z + hi.z));
        assert!(first_hit(&mesh, above, Vec3::Y).is_none(), "pointing away");
        let beside = Vec3::new(hi.x + 1.0, hi.y + 1.0, hi.z + 1.0);
        assert!(
            first_hit(&mesh, beside, Vec3::X).is_none(),
            "parallel, outside"
        );
        assert!(
            first_hit(&mesh, above, Vec3::ZERO).is_none(),
            "no direction"
        );
    }

    #[test]
    fn edges_and_corners_count_as_inside() {
        let (p0, p1, p2) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let down = Vec3::NEG_Z;
        let at = |x, y| intersect(Vec3::new(x, y, 1.0), down, p0, p1, p2);
        assert_eq!(at(0.0, 0.0).map(|h| h.0), Some(1.0));
        assert!(at(0.5, 0.5).is_some(), "on the hypotenuse");
        assert!(at(0.6, 0.6).is_none());
        let (t, b1, b2) = at(0.25, 0.5).unwrap();
        assert_eq!((t, b1, b2), (1.0, 0.25, 0.5));
    }
}
