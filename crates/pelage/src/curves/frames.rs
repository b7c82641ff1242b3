//! Tangents and rotation-minimizing frames along a polyline, for the
//! per-point normals renderers use to orient hair ribbons (Sik §4.2.2:
//! "curve normals … computed by the method of [Wang et al. 2008]").
//!
//! The frame is the double reflection method (Wang, Jüttler, Zheng, Liu
//! 2008, "Computation of rotation minimizing frames", ACM TOG 27(1),
//! Algorithm 1): the frame at point `i + 1` is the frame at `i` reflected
//! in the bisector plane of the chord `x(i+1) − x(i)`, then in the plane
//! that takes the reflected tangent onto the tangent at `i + 1`. It is
//! exact for circles and fourth-order accurate elsewhere, with no
//! trigonometry.

use glam::Vec3;

/// Unit tangents of the Catmull-Rom curve through `points` (uniform
/// parameterisation): `(x(i+1) − x(i−1)) / 2` inside, one-sided at the
/// ends (where USD's pinned curves have the same tangent). Zero-length
/// steps fall back to the neighbouring tangent.
pub fn catmull_rom_tangents(points: &[Vec3], out: &mut [Vec3]) {
    let n = points.len();
    debug_assert_eq!(out.len(), n);
    if n < 2 {
        out.iter_mut().for_each(|t| *t = Vec3::Z);
        return;
    }
    for i in 0..n {
        let (a, b) = (points[i.saturating_sub(1)], points[(i + 1).min(n - 1)]);
        out[i] = (b - a).normalize_or_zero();
    }
    // Fill zero tangents (repeated points) from a neighbour.
    for i in 1..n {
        if out[i] == Vec3::ZERO {
            out[i] = out[i - 1];
        }
    }
    for i in (0..n - 1).rev() {
        if out[i] == Vec3::ZERO {
            out[i] = out[i + 1];
        }
    }
}

/// Rotation-minimizing reference vectors along `points`: `out[0]` is
/// `first` made perpendicular to `tangents[0]`, each next one follows by
/// double reflection (module docs). Every output is a unit vector
/// perpendicular to its tangent.
pub fn rotation_minimizing_normals(
    points: &[Vec3],
    tangents: &[Vec3],
    first: Vec3,
    out: &mut [Vec3],
) {
    let n = points.len();
    if n == 0 {
        return;
    }
    let t0 = tangents[0];
    let mut r = (first - t0 * t0.dot(first)).normalize_or_zero();
    if r == Vec3::ZERO {
        r = t0.any_orthonormal_vector();
    }
    out[0] = r;
    for i in 0..n - 1 {
        // The reflection planes depend on the curve alone, not on `r`, so
        // their divisions overlap with the previous step's work; only the
        // two reflections of `r` are in the loop-carried chain.
        let v1 = points[i + 1] - points[i];
        let c1 = v1.dot(v1);
        let k1 = if c1 > 1e-20 { 2.0 / c1 } else { 0.0 };
        let t_l = tangents[i] - k1 * v1.dot(tangents[i]) * v1;
        let v2 = tangents[i + 1] - t_l;
        let c2 = v2.dot(v2);
        let k2 = if c2 > 1e-20 { 2.0 / c2 } else { 0.0 };
        let r_l = r - k1 * v1.dot(r) * v1;
        let reflected = r_l - k2 * v2.dot(r_l) * v2;
        // Reflections keep `r` unit and perpendicular up to rounding; the
        // projection only matters where a tangent fell back to a
        // neighbour's (repeated points). Cleaning up the output, not the
        // carried vector, keeps it out of the chain.
        let t = tangents[i + 1];
        let projected = reflected - t * t.dot(reflected);
        let length_squared = projected.length_squared();
        if length_squared > 1e-12 {
            r = reflected;
            out[i + 1] = projected * length_squared.sqrt().recip();
        } else {
            r = t.any_orthonormal_vector();
            out[i + 1] = r;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(points: &[Vec3], first: Vec3) -> (Vec<Vec3>, Vec<Vec3>) {
        let mut t = vec![Vec3::ZERO; points.len()];
        let mut r = vec![Vec3::ZERO; points.len()];
        catmull_rom_tangents(points, &mut t);
        rotation_minimizing_normals(points, &t, first, &mut r);
        (t, r)
    }

    #[test]
    fn planar_curve_keeps_the_plane_normal() {
        // A wiggly curve in the XY plane: the rotation-minimizing frame of a
        // planar curve started on the plane normal stays on it (no twist).
        let points: Vec<Vec3> = (0..40)
            .map(|i| {
                let s = i as f32 * 0.1;
                Vec3::new(s, (3.0 * s).sin() * 0.5, 0.0)
            })
            .collect();
        let (_, r) = frames(&points, Vec3::Z);
        for v in r {
            assert!((v - Vec3::Z).length() < 1e-5, "{v}");
        }
    }

    #[test]
    fn helix_normals_are_unit_perpendicular_and_do_not_twist() {
        // Along a helix the RMF turns about the tangent at the rate of the
        // torsion only; the frame stays perpendicular and unit, and
        // consecutive normals change smoothly (no flips).
        let points: Vec<Vec3> = (0..200)
            .map(|i| {
                let a = i as f32 * 0.1;
                Vec3::new(a.cos(), a.sin(), 0.05 * a)
            })
            .collect();
        let (t, r) = frames(&points, Vec3::X);
        for i in 0..points.len() {
            assert!((r[i].length() - 1.0).abs() < 1e-5);
            assert!(r[i].dot(t[i]).abs() < 1e-5);
            if i > 0 {
                assert!(r[i].dot(r[i - 1]) > 0.98, "flip at {i}");
            }
        }
    }

    #[test]
    fn straight_line_keeps_its_normal_and_repeated_points_are_harmless() {
        let points = [Vec3::ZERO, Vec3::Y, Vec3::Y, 2.0 * Vec3::Y, 3.0 * Vec3::Y];
        let (t, r) = frames(&points, Vec3::new(1.0, 1.0, 0.0));
        for (ti, ri) in t.iter().zip(&r) {
            assert!((*ti - Vec3::Y).length() < 1e-6);
            assert!((*ri - Vec3::X).length() < 1e-6);
        }
    }
}
