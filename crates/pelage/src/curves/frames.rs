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
//!
//! One file, past 600 lines: the scalar, portable-lane and AVX versions of
//! one algorithm must stay bit-identical, so they sit side by side (about 130
//! of its lines are tests).

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
        // Reflections are orthogonal maps: they keep `r` unit, and the
        // second takes the reflected tangent onto `t`, so `r` stays
        // perpendicular to it (fallback tangents of repeated points are
        // unit copies, so this holds there too). Rounding adds an ulp or so
        // a step, which is why nothing renormalises: a square root and a
        // division a point for no visible change. Only a vector that is no
        // longer off the tangent (it cannot happen with unit tangents; a
        // guard) restarts the frame.
        let t = tangents[i + 1];
        let projected = reflected - t * t.dot(reflected);
        if projected.length_squared() > 1e-12 {
            r = reflected;
            out[i + 1] = reflected;
        } else {
            r = t.any_orthonormal_vector();
            out[i + 1] = r;
        }
    }
}

/// Hairs framed at once by [`hair_normals`]. One hair's double reflection
/// is a chain of dependent steps that leaves the CPU idle between them;
/// eight hairs side by side, lane by lane, fill that time and compile to
/// SIMD (one AVX register a value, or two SSE registers without AVX).
const LANES: usize = 8;

type Lanes = [f32; LANES];

/// Three coordinates, each for [`LANES`] hairs.
#[derive(Debug, Clone, Copy, Default)]
struct LaneVec {
    x: Lanes,
    y: Lanes,
    z: Lanes,
}

impl LaneVec {
    #[inline(always)]
    fn at(&self, l: usize) -> Vec3 {
        Vec3::new(self.x[l], self.y[l], self.z[l])
    }

    #[inline(always)]
    fn set(&mut self, l: usize, v: Vec3) {
        (self.x[l], self.y[l], self.z[l]) = (v.x, v.y, v.z);
    }
}

/// Reusable buffers for [`hair_normals`].
#[derive(Debug, Default)]
pub struct FrameScratch {
    points: Vec<LaneVec>,
    tangents: Vec<LaneVec>,
    normals: Vec<LaneVec>,
}

/// `a · b` in glam's order, so the lanes round as [`Vec3::dot`] does.
#[inline(always)]
fn dot(ax: f32, ay: f32, az: f32, bx: f32, by: f32, bz: f32) -> f32 {
    ax * bx + ay * by + az * bz
}

/// Per-point normals of many hairs of `n` points each (`points` holds them
/// one after another; hair `h` starts its frame from `first[h]`): the same
/// values, to the bit, as [`catmull_rom_tangents`] and
/// [`rotation_minimizing_normals`] hair by hair, computed `LANES` hairs at
/// a time.
///
/// On x86-64 CPUs with AVX the lanes are AVX registers (module `avx`; the same
/// operations, no fused multiply-adds, so the same bits).
///
/// # Panics
/// If `points` and `out` do not hold `first.len()` hairs of `n` points.
pub fn hair_normals(
    points: &[Vec3],
    n: usize,
    first: &[Vec3],
    out: &mut [Vec3],
    scratch: &mut FrameScratch,
) {
    assert_eq!(points.len(), first.len() * n);
    assert_eq!(out.len(), first.len() * n);
    #[cfg(target_arch = "x86_64")]
    if n >= 2 && std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX (checked just above).
        unsafe { avx::hair_normals(points, n, first, out, scratch) };
        return;
    }
    hair_normals_in_lanes(points, n, first, out, scratch);
}

/// [`hair_normals`] in portable lanes: what runs without AVX (and for
/// one-point hairs), and what the AVX version matches operation for
/// operation.
// Loops over lane indices are the form the compiler vectorises.
#[allow(clippy::needless_range_loop)]
fn hair_normals_in_lanes(
    points: &[Vec3],
    n: usize,
    first: &[Vec3],
    out: &mut [Vec3],
    scratch: &mut FrameScratch,
) {
    let hairs = first.len();
    if n < 2 {
        // No segment to follow: the single-point rule of the scalar path.
        let mut tangent = [Vec3::ZERO; 1];
        for (h, start) in first.iter().enumerate() {
            let range = h * n..(h + 1) * n;
            catmull_rom_tangents(&points[range.clone()], &mut tangent[..n]);
            rotation_minimizing_normals(
                &points[range.clone()],
                &tangent[..n],
                *start,
                &mut out[range],
            );
        }
        return;
    }
    scratch.points.resize(n, LaneVec::default());
    scratch.tangents.resize(n, LaneVec::default());
    for group in (0..hairs).step_by(LANES) {
        let count = (hairs - group).min(LANES);
        // Spare lanes repeat the group's last hair and are not written out.
        let hair = |l: usize| group + l.min(count - 1);
        let (p, t) = (&mut scratch.points[..], &mut scratch.tangents[..]);
        gather(points, n, hair, p);
        lane_tangents(p, t);
        let mut r = start_vectors(&t[0], |l| first[hair(l)]);
        store(out, n, 0, count, group, &r);
        for i in 0..n - 1 {
            let mut degenerate = [false; LANES];
            for l in 0..LANES {
                let (a, b, ta, tb) = (&p[i], &p[i + 1], &t[i], &t[i + 1]);
                let (v1x, v1y, v1z) = (b.x[l] - a.x[l], b.y[l] - a.y[l], b.z[l] - a.z[l]);
                let c1 = dot(v1x, v1y, v1z, v1x, v1y, v1z);
                let k1 = if c1 > 1e-20 { 2.0 / c1 } else { 0.0 };
                let s = k1 * dot(v1x, v1y, v1z, ta.x[l], ta.y[l], ta.z[l]);
                let (tlx, tly, tlz) = (ta.x[l] - s * v1x, ta.y[l] - s * v1y, ta.z[l] - s * v1z);
                let (v2x, v2y, v2z) = (tb.x[l] - tlx, tb.y[l] - tly, tb.z[l] - tlz);
                let c2 = dot(v2x, v2y, v2z, v2x, v2y, v2z);
                let k2 = if c2 > 1e-20 { 2.0 / c2 } else { 0.0 };
                let s = k1 * dot(v1x, v1y, v1z, r.x[l], r.y[l], r.z[l]);
                let (rlx, rly, rlz) = (r.x[l] - s * v1x, r.y[l] - s * v1y, r.z[l] - s * v1z);
                let s = k2 * dot(v2x, v2y, v2z, rlx, rly, rlz);
                let (fx, fy, fz) = (rlx - s * v2x, rly - s * v2y, rlz - s * v2z);
                let s = dot(tb.x[l], tb.y[l], tb.z[l], fx, fy, fz);
                let (qx, qy, qz) = (fx - tb.x[l] * s, fy - tb.y[l] * s, fz - tb.z[l] * s);
                degenerate[l] = dot(qx, qy, qz, qx, qy, qz) <= 1e-12;
                (r.x[l], r.y[l], r.z[l]) = (fx, fy, fz);
            }
            for l in 0..LANES {
                if degenerate[l] {
                    r.set(l, t[i + 1].at(l).any_orthonormal_vector());
                }
            }
            store(out, n, i + 1, count, group, &r);
        }
    }
}

/// [`catmull_rom_tangents`] lane by lane (`n ≥ 2`).
#[inline(always)]
fn lane_tangents(p: &[LaneVec], t: &mut [LaneVec]) {
    let n = p.len();
    for i in 0..n {
        let (a, b) = (&p[i.saturating_sub(1)], &p[(i + 1).min(n - 1)]);
        for l in 0..LANES {
            let (dx, dy, dz) = (b.x[l] - a.x[l], b.y[l] - a.y[l], b.z[l] - a.z[l]);
            // Vec3::normalize_or_zero.
            let rcp = dot(dx, dy, dz, dx, dy, dz).sqrt().recip();
            let ok = rcp.is_finite() && rcp > 0.0;
            let scaled = |d: f32| if ok { d * rcp } else { 0.0 };
            (t[i].x[l], t[i].y[l], t[i].z[l]) = (scaled(dx), scaled(dy), scaled(dz));
        }
    }
    fill_zero_tangents(t);
}

/// [`catmull_rom_tangents`]' fallback, lane by lane: zero tangents
/// (repeated points) take the one before, else the one after.
#[inline(always)]
fn fill_zero_tangents(t: &mut [LaneVec]) {
    let n = t.len();
    let zero = |v: &LaneVec, l: usize| v.x[l] == 0.0 && v.y[l] == 0.0 && v.z[l] == 0.0;
    for i in 1..n {
        for l in 0..LANES {
            if zero(&t[i], l) {
                let before = t[i - 1].at(l);
                t[i].set(l, before);
            }
        }
    }
    for i in (0..n - 1).rev() {
        for l in 0..LANES {
            if zero(&t[i], l) {
                let after = t[i + 1].at(l);
                t[i].set(l, after);
            }
        }
    }
}

/// Point `i` of the hairs `hair(l)` into lane `l` of `p[i]`.
#[inline(always)]
fn gather(points: &[Vec3], n: usize, hair: impl Fn(usize) -> usize, p: &mut [LaneVec]) {
    for (i, lane) in p.iter_mut().enumerate() {
        for l in 0..LANES {
            lane.set(l, points[hair(l) * n + i]);
        }
    }
}

/// The frames' first vectors: lane `l`'s `first(l)` made perpendicular to
/// its tangent `t0` (as [`rotation_minimizing_normals`] starts). Per hair
/// and rarely degenerate, so scalar.
#[inline(always)]
fn start_vectors(t0: &LaneVec, first: impl Fn(usize) -> Vec3) -> LaneVec {
    let mut r = LaneVec::default();
    for l in 0..LANES {
        let (t0, f) = (t0.at(l), first(l));
        let mut start = (f - t0 * t0.dot(f)).normalize_or_zero();
        if start == Vec3::ZERO {
            start = t0.any_orthonormal_vector();
        }
        r.set(l, start);
    }
    r
}

/// Writes point `i`'s lanes to the group's real hairs.
#[inline(always)]
fn store(out: &mut [Vec3], n: usize, i: usize, count: usize, group: usize, v: &LaneVec) {
    for l in 0..count {
        out[(group + l) * n + i] = v.at(l);
    }
}

/// [`hair_normals`] in AVX registers: the arithmetic of
/// [`hair_normals_in_lanes`] operation for operation (no fused
/// multiply-add, the same order), so the bits agree; the rare cases (a zero
/// tangent, a degenerate step) are found with a lane mask and handed to the
/// scalar rules. Written with intrinsics because the compiler kept the
/// portable version's lanes on the stack between steps and branched lane
/// by lane on the rare cases.
#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{FrameScratch, LANES, LaneVec, fill_zero_tangents, start_vectors};
    use glam::Vec3;
    use std::arch::x86_64::*;

    /// Three coordinates in three registers.
    #[derive(Clone, Copy)]
    struct V {
        x: __m256,
        y: __m256,
        z: __m256,
    }

    #[inline]
    #[target_feature(enable = "avx")]
    fn load(v: &LaneVec) -> V {
        // SAFETY: each field is eight f32s.
        unsafe {
            V {
                x: _mm256_loadu_ps(v.x.as_ptr()),
                y: _mm256_loadu_ps(v.y.as_ptr()),
                z: _mm256_loadu_ps(v.z.as_ptr()),
            }
        }
    }

    #[inline]
    #[target_feature(enable = "avx")]
    fn save(v: V, out: &mut LaneVec) {
        // SAFETY: each field is eight f32s.
        unsafe {
            _mm256_storeu_ps(out.x.as_mut_ptr(), v.x);
            _mm256_storeu_ps(out.y.as_mut_ptr(), v.y);
            _mm256_storeu_ps(out.z.as_mut_ptr(), v.z);
        }
    }

    #[inline]
    #[target_feature(enable = "avx")]
    fn sub(a: V, b: V) -> V {
        V {
            x: _mm256_sub_ps(a.x, b.x),
            y: _mm256_sub_ps(a.y, b.y),
            z: _mm256_sub_ps(a.z, b.z),
        }
    }

    /// `a − s·b`, per lane.
    #[inline]
    #[target_feature(enable = "avx")]
    fn sub_scaled(a: V, s: __m256, b: V) -> V {
        V {
            x: _mm256_sub_ps(a.x, _mm256_mul_ps(s, b.x)),
            y: _mm256_sub_ps(a.y, _mm256_mul_ps(s, b.y)),
            z: _mm256_sub_ps(a.z, _mm256_mul_ps(s, b.z)),
        }
    }

    /// `(ax·bx + ay·by) + az·bz`, glam's order.
    #[inline]
    #[target_feature(enable = "avx")]
    fn dot(a: V, b: V) -> __m256 {
        let xy = _mm256_add_ps(_mm256_mul_ps(a.x, b.x), _mm256_mul_ps(a.y, b.y));
        _mm256_add_ps(xy, _mm256_mul_ps(a.z, b.z))
    }

    /// `if c > 1e-20 { 2 / c } else { 0 }`.
    #[inline]
    #[target_feature(enable = "avx")]
    fn reflection_scale(c: __m256) -> __m256 {
        let usable = _mm256_cmp_ps::<_CMP_GT_OQ>(c, _mm256_set1_ps(1e-20));
        _mm256_and_ps(usable, _mm256_div_ps(_mm256_set1_ps(2.0), c))
    }

    /// [`super::lane_tangents`]: `Vec3::normalize_or_zero` of each chord,
    /// then the fallback for zero ones when a lane has any.
    #[inline]
    #[target_feature(enable = "avx")]
    fn tangents(p: &[LaneVec], t: &mut [LaneVec]) {
        let n = p.len();
        let zero = _mm256_setzero_ps();
        let (one, infinity) = (_mm256_set1_ps(1.0), _mm256_set1_ps(f32::INFINITY));
        let mut any_zero = 0;
        for i in 0..n {
            let d = sub(load(&p[(i + 1).min(n - 1)]), load(&p[i.saturating_sub(1)]));
            let rcp = _mm256_div_ps(one, _mm256_sqrt_ps(dot(d, d)));
            // Finite and positive; NaN fails both.
            let ok = _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GT_OQ>(rcp, zero),
                _mm256_cmp_ps::<_CMP_LT_OQ>(rcp, infinity),
            );
            let scaled = |c: __m256| _mm256_and_ps(ok, _mm256_mul_ps(c, rcp));
            let tangent = V {
                x: scaled(d.x),
                y: scaled(d.y),
                z: scaled(d.z),
            };
            save(tangent, &mut t[i]);
            let is_zero = |c: __m256| _mm256_cmp_ps::<_CMP_EQ_OQ>(c, zero);
            let all_zero = _mm256_and_ps(
                _mm256_and_ps(is_zero(tangent.x), is_zero(tangent.y)),
                is_zero(tangent.z),
            );
            any_zero |= _mm256_movemask_ps(all_zero);
        }
        if any_zero != 0 {
            fill_zero_tangents(t);
        }
    }

    /// Point `index` of `points` as (x, y, z, junk).
    #[inline]
    #[target_feature(enable = "avx")]
    fn point4(points: &[Vec3], index: usize) -> __m128 {
        if index + 1 < points.len() {
            // SAFETY: the point and the next one's x (the junk) are in
            // `points`: four floats from the point's first.
            unsafe { _mm_loadu_ps(points.as_ptr().add(index).cast::<f32>()) }
        } else {
            let p = points[index];
            _mm_set_ps(0.0, p.z, p.y, p.x)
        }
    }

    /// [`super::gather`] in registers: eight (x, y, z, junk) loads and a
    /// 4×4 transpose a point instead of 24 single-float moves.
    #[inline]
    #[target_feature(enable = "avx")]
    fn gather(points: &[Vec3], n: usize, hair: impl Fn(usize) -> usize, p: &mut [LaneVec]) {
        for (i, lane) in p.iter_mut().enumerate() {
            let at = |l: usize| point4(points, hair(l) * n + i);
            // Lanes l and l + 4 share a register, low and high half.
            let pair =
                |l: usize| _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(at(l)), at(l + 4));
            let (m0, m1, m2, m3) = (pair(0), pair(1), pair(2), pair(3));
            let (xy01, xy23) = (_mm256_unpacklo_ps(m0, m1), _mm256_unpacklo_ps(m2, m3));
            let (zw01, zw23) = (_mm256_unpackhi_ps(m0, m1), _mm256_unpackhi_ps(m2, m3));
            save(
                V {
                    x: _mm256_shuffle_ps::<0x44>(xy01, xy23),
                    y: _mm256_shuffle_ps::<0xEE>(xy01, xy23),
                    z: _mm256_shuffle_ps::<0x44>(zw01, zw23),
                },
                lane,
            );
        }
    }

    /// The group's normals (`normals[i]` point `i` of each lane) out to
    /// its `count` real hairs: the transpose of [`gather`], each point
    /// written as four floats. The fourth lands on the next point's x,
    /// which the next, later store overwrites; a hair's last point,
    /// whose next float is another hair's, is written as three.
    #[inline]
    #[target_feature(enable = "avx")]
    fn scatter(out: &mut [Vec3], n: usize, count: usize, group: usize, normals: &[LaneVec]) {
        let zero = _mm256_setzero_ps();
        for (i, v) in normals.iter().enumerate() {
            let v = load(v);
            let (xy01, xy23) = (_mm256_unpacklo_ps(v.x, v.y), _mm256_unpackhi_ps(v.x, v.y));
            let (zw01, zw23) = (_mm256_unpacklo_ps(v.z, zero), _mm256_unpackhi_ps(v.z, zero));
            // Lane l in the low half of rows[l % 4] for l < 4, the high
            // half for l ≥ 4.
            let rows = [
                _mm256_shuffle_ps::<0x44>(xy01, zw01),
                _mm256_shuffle_ps::<0xEE>(xy01, zw01),
                _mm256_shuffle_ps::<0x44>(xy23, zw23),
                _mm256_shuffle_ps::<0xEE>(xy23, zw23),
            ];
            for l in 0..count {
                let row = rows[l % 4];
                let point = if l < 4 {
                    _mm256_castps256_ps128(row)
                } else {
                    _mm256_extractf128_ps::<1>(row)
                };
                let index = (group + l) * n + i;
                if i + 1 < n {
                    // SAFETY: point `index` and the next one's x are in
                    // `out` (the next point belongs to the same hair).
                    unsafe { _mm_storeu_ps(out.as_mut_ptr().add(index).cast::<f32>(), point) };
                } else {
                    let mut xyzw = [0.0; 4];
                    // SAFETY: writes the four floats of `xyzw`.
                    unsafe { _mm_storeu_ps(xyzw.as_mut_ptr(), point) };
                    out[index] = Vec3::new(xyzw[0], xyzw[1], xyzw[2]);
                }
            }
        }
    }

    /// See [`super::hair_normals`], which checks the lengths; `n ≥ 2`.
    #[target_feature(enable = "avx")]
    pub(super) fn hair_normals(
        points: &[Vec3],
        n: usize,
        first: &[Vec3],
        out: &mut [Vec3],
        scratch: &mut FrameScratch,
    ) {
        let hairs = first.len();
        scratch.points.resize(n, LaneVec::default());
        scratch.tangents.resize(n, LaneVec::default());
        scratch.normals.resize(n, LaneVec::default());
        for group in (0..hairs).step_by(LANES) {
            let count = (hairs - group).min(LANES);
            // Spare lanes repeat the group's last hair and are not written out.
            let hair = |l: usize| group + l.min(count - 1);
            let (p, t) = (&mut scratch.points[..], &mut scratch.tangents[..]);
            let normals = &mut scratch.normals[..];
            gather(points, n, hair, p);
            tangents(p, t);
            normals[0] = start_vectors(&t[0], |l| first[hair(l)]);
            let mut r = load(&normals[0]);
            let mut a = load(&p[0]);
            let mut ta = load(&t[0]);
            for i in 0..n - 1 {
                let (b, tb) = (load(&p[i + 1]), load(&t[i + 1]));
                let v1 = sub(b, a);
                let k1 = reflection_scale(dot(v1, v1));
                let t_l = sub_scaled(ta, _mm256_mul_ps(k1, dot(v1, ta)), v1);
                let v2 = sub(tb, t_l);
                let k2 = reflection_scale(dot(v2, v2));
                let r_l = sub_scaled(r, _mm256_mul_ps(k1, dot(v1, r)), v1);
                let f = sub_scaled(r_l, _mm256_mul_ps(k2, dot(v2, r_l)), v2);
                // `f − tb·s` is `f − s·tb` to the bit (products commute).
                let q = sub_scaled(f, dot(tb, f), tb);
                let usable = _mm256_cmp_ps::<_CMP_GT_OQ>(dot(q, q), _mm256_set1_ps(1e-12));
                r = f;
                save(r, &mut normals[i + 1]);
                let degenerate = _mm256_movemask_ps(usable) ^ 0xff;
                if degenerate != 0 {
                    for l in (0..LANES).filter(|l| degenerate & (1 << l) != 0) {
                        normals[i + 1].set(l, t[i + 1].at(l).any_orthonormal_vector());
                    }
                    r = load(&normals[i + 1]);
                }
                (a, ta) = (b, tb);
            }
            scatter(out, n, count, group, normals);
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
    fn long_noisy_hairs_stay_unit_and_perpendicular_without_renormalising() {
        // 5,000 points of an irregular curve (a step of any direction and
        // length, some tiny): rounding must not pile up along the chain.
        // (It reaches about 8e-6 here; a 16-point hair, about 1e-7.)
        let mut h = 7u32;
        let mut random = || {
            h ^= h << 13;
            h ^= h >> 17;
            h ^= h << 5;
            h as f32 / u32::MAX as f32 - 0.5
        };
        let mut p = Vec3::ZERO;
        let points: Vec<Vec3> = (0..5000)
            .map(|i| {
                let scale = if i % 97 == 0 { 1e-4 } else { 0.05 };
                p += Vec3::new(random(), random(), random() + 0.3) * scale;
                p
            })
            .collect();
        let (t, r) = frames(&points, Vec3::X);
        for (i, (ti, ri)) in t.iter().zip(&r).enumerate() {
            assert!((ri.length() - 1.0).abs() < 5e-5, "length at {i}: {ri}");
            assert!(ri.dot(*ti).abs() < 5e-5, "off perpendicular at {i}");
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

    #[test]
    fn many_hairs_at_once_match_one_at_a_time_to_the_bit() {
        // Wiggly hairs of several lengths, some with repeated points, a
        // straight one, one collapsed to a point, and a start vector along
        // the tangent; 11 hairs leave a partial group of lanes.
        for n in [1, 2, 3, 16, 31] {
            let hairs = 11;
            let mut points = Vec::new();
            let mut first = Vec::new();
            for h in 0..hairs {
                for i in 0..n {
                    let s = i as f32 * 0.1 + h as f32;
                    let p = match h {
                        3 => Vec3::new(0.0, 0.0, i as f32),
                        4 => Vec3::splat(2.0),
                        _ => Vec3::new((3.0 * s).sin(), (1.7 * s).cos() * 0.5, s),
                    };
                    // Hair 5 repeats every other point.
                    points.push(if h == 5 && i % 2 == 1 {
                        points[points.len() - 1]
                    } else {
                        p
                    });
                }
                first.push(if h == 3 {
                    Vec3::Z
                } else {
                    Vec3::new(1.0, 0.2 * h as f32, 0.0)
                });
            }
            // The dispatching entry (AVX intrinsics where the CPU has
            // them) and the portable lanes, both against the scalar path.
            let mut lanes = vec![Vec3::NAN; points.len()];
            let mut portable = vec![Vec3::NAN; points.len()];
            let scratch = &mut FrameScratch::default();
            hair_normals(&points, n, &first, &mut lanes, scratch);
            hair_normals_in_lanes(&points, n, &first, &mut portable, scratch);
            for (h, start) in first.iter().enumerate() {
                let range = h * n..(h + 1) * n;
                let (_, one) = frames(&points[range.clone()], *start);
                for ((a, b), c) in one.iter().zip(&lanes[range.clone()]).zip(&portable[range]) {
                    let bits = |v: &Vec3| v.to_array().map(f32::to_bits);
                    assert_eq!(bits(a), bits(b), "n {n} hair {h}");
                    assert_eq!(bits(a), bits(c), "n {n} hair {h}, portable lanes");
                }
            }
        }
    }
}
