//! Procedural noise maps: 2D Perlin gradient noise (Perlin 2002, "Improving
//! Noise": quintic fade, hashed gradients) summed in octaves (fBm), as the
//! Stubble generator uses for density and displacement (Sik, section 4.3).
//! On a mesh without UVs (or with `space=object`) the same fBm is summed
//! over 3D Perlin noise at the point's rest position, so a noise map needs
//! no texture coordinates.

use glam::Vec2;

/// `offset + scale · fbm(frequency · uv)`, where fBm sums `octaves`
/// octaves of Perlin noise, each at twice the frequency and half the
/// amplitude of the last, normalised so the sum stays in about [−1, 1].
/// With the defaults the map lies in about [0, 1] around 0.5.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseMap {
    /// Cells of the base octave per UV unit.
    pub frequency: f32,
    /// Number of octaves (at least 1).
    pub octaves: u32,
    /// Seed of the permutation table.
    pub seed: u64,
    /// Added to the scaled noise.
    pub offset: f32,
    /// Multiplies the noise.
    pub scale: f32,
    /// Where the noise is read: UV, object space, or UV when the mesh has
    /// UVs and object space when it has none.
    pub space: NoiseSpace,
    permutation: Box<[u8; 512]>,
    /// The permutation table widened to `u32`, for SIMD gathers.
    permutation32: Box<[u32; 512]>,
    /// For each index `i` of the permutation table, the gradient rows
    /// (low four bits of the hash) [`NoiseMap::perlin3_vector`]'s three
    /// components pick where Perlin's chain ends at `h = perm[i]`: bits
    /// 0–3 from `h`, 4–7 from `perm[h + 101]`, 8–11 from `perm[h + 203]`.
    /// The SIMD path reads a corner's three gradients with one gather.
    corner_gradients: Box<[u32; 512]>,
}

/// Where a noise map is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NoiseSpace {
    /// UV on a mesh with UVs, object space on one without (the default).
    #[default]
    Auto,
    /// Always at the UV (the mesh needs UVs).
    Uv,
    /// Always at the rest position, `frequency` cells per world unit.
    Object,
}

impl NoiseSpace {
    /// `auto`, `uv` or `object`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(Self::Auto),
            "uv" => Some(Self::Uv),
            "object" => Some(Self::Object),
            _ => None,
        }
    }
}

impl Default for NoiseMap {
    fn default() -> Self {
        Self::new(4.0, 4, 0, 0.5, 0.5)
    }
}

impl NoiseMap {
    /// A noise map; `octaves` below 1 is treated as 1.
    pub fn new(frequency: f32, octaves: u32, seed: u64, offset: f32, scale: f32) -> Self {
        let permutation = permutation(seed);
        let row = |k: usize| u32::from(permutation[k]) & 15;
        let corner_gradients = Box::new(permutation.map(|h| {
            let h = usize::from(h);
            (h as u32 & 15) | row(h + 101) << 4 | row(h + 203) << 8
        }));
        Self {
            frequency,
            octaves: octaves.max(1),
            seed,
            offset,
            scale,
            space: NoiseSpace::Auto,
            permutation32: Box::new(permutation.map(u32::from)),
            corner_gradients,
            permutation,
        }
    }

    /// The doubled permutation table the noise hashes lattice points with
    /// (a GPU port of the noise uploads it).
    pub fn permutation_table(&self) -> &[u8; 512] {
        &self.permutation
    }

    /// The map's value at `uv`.
    pub fn eval(&self, uv: Vec2) -> f32 {
        self.fbm(|octave| self.perlin(uv * (self.frequency * octave)))
    }

    /// `offset + scale · Σ 2⁻ᵏ noise(2ᵏ p) / Σ 2⁻ᵏ` over the octaves
    /// `k`, `noise(2ᵏ)` given the octave's frequency factor `2ᵏ`.
    #[inline]
    fn fbm(&self, noise: impl Fn(f32) -> f32) -> f32 {
        let mut sum = 0.0;
        let mut amplitude = 1.0;
        let mut total = 0.0;
        let mut octave = 1.0;
        for _ in 0..self.octaves {
            sum += amplitude * noise(octave);
            total += amplitude;
            amplitude *= 0.5;
            octave *= 2.0;
        }
        self.offset + self.scale * sum / total
    }

    /// The noise read at `space`.
    pub fn with_space(mut self, space: NoiseSpace) -> Self {
        self.space = space;
        self
    }

    /// The map's value at object-space position `p`: the same fBm over 3D
    /// Perlin noise.
    pub fn eval3(&self, p: glam::Vec3) -> f32 {
        self.fbm(|octave| self.perlin3(p * (self.frequency * octave)))
    }

    /// One octave of 3D Perlin noise (Perlin 2002), in about [−1, 1].
    pub fn perlin3(&self, p: glam::Vec3) -> f32 {
        let cell = glam::Vec3::new(floor(p.x), floor(p.y), floor(p.z));
        let f = p - cell;
        let [xi, yi, zi] = [cell.x, cell.y, cell.z].map(|c| (c as i64 & 255) as usize);
        let perm = &self.permutation;
        let at = |i: usize| perm[i & 511] as usize;
        let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
        let corner = |dx: usize, dy: usize, dz: usize| {
            let h = at(at(at(xi + dx) + yi + dy) + zi + dz);
            gradient3(h as u8, f.x - dx as f32, f.y - dy as f32, f.z - dz as f32)
        };
        let lerp = |a: f32, b: f32, t: f32| a + t * (b - a);
        let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), u);
        let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), u);
        let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), u);
        let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), u);
        lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
    }

    /// One octave of 2D Perlin noise, in about [−1, 1].
    pub fn perlin(&self, p: Vec2) -> f32 {
        let cell = Vec2::new(floor(p.x), floor(p.y));
        let f = p - cell;
        let (xi, yi) = (
            (cell.x as i64 & 255) as usize,
            (cell.y as i64 & 255) as usize,
        );
        let perm = &self.permutation;
        let hash = |x: usize, y: usize| perm[perm[x] as usize + y];
        let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let (u, v) = (fade(f.x), fade(f.y));
        let g00 = gradient(hash(xi, yi), f.x, f.y);
        let g10 = gradient(hash(xi + 1, yi), f.x - 1.0, f.y);
        let g01 = gradient(hash(xi, yi + 1), f.x, f.y - 1.0);
        let g11 = gradient(hash(xi + 1, yi + 1), f.x - 1.0, f.y - 1.0);
        let bottom = g00 + u * (g10 - g00);
        let top = g01 + u * (g11 - g01);
        bottom + v * (top - bottom)
    }
}

impl NoiseMap {
    /// Three independent octaves of 3D Perlin noise (Perlin 2002: quintic
    /// fade, the twelve edge-direction gradients) at `p`, one a component —
    /// the groom's noise operator displaces hair points with it: the lattice cell and fade weights are shared, each
    /// component hashes its corners with its own salt. A smooth random
    /// vector field, each component in about [−1, 1].
    pub fn perlin3_vector(&self, p: glam::Vec3) -> glam::Vec3 {
        // floor without libm (no SSE4.1 rounding on baseline x86-64);
        // exact for |x| < 2³¹.
        let floor = |x: f32| {
            let i = x as i32 as f32;
            if i > x { i - 1.0 } else { i }
        };
        let cell = glam::Vec3::new(floor(p.x), floor(p.y), floor(p.z));
        let f = p - cell;
        let [xi, yi, zi] = [cell.x, cell.y, cell.z].map(|c| (c as i64 & 255) as usize);
        let perm: &[u8; 512] = &self.permutation;
        // Indices masked to the table: they never exceed it (see below),
        // and the mask lets the compiler drop every bounds check.
        let at = |i: usize| perm[i & 511] as usize;
        let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
        let lerp = |a: glam::Vec3, b: glam::Vec3, t: f32| a + t * (b - a);
        // Perlin's hash chain perm[perm[perm[x] + y] + z], its first two
        // links shared by the corners that share them (x ≤ 256, each
        // table entry ≤ 255, so every index stays below 512).
        let hx = [at(xi), at(xi + 1)];
        let hxy = [
            [at(hx[0] + yi), at(hx[0] + yi + 1)],
            [at(hx[1] + yi), at(hx[1] + yi + 1)],
        ];
        let corner = |dx: usize, dy: usize, dz: usize| {
            let h = at(hxy[dx][dy] + zi + dz);
            let (x, y, z) = (f.x - dx as f32, f.y - dy as f32, f.z - dz as f32);
            glam::Vec3::new(
                gradient3(h as u8, x, y, z),
                gradient3(at(h + 101) as u8, x, y, z),
                gradient3(at(h + 203) as u8, x, y, z),
            )
        };
        let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), u);
        let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), u);
        let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), u);
        let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), u);
        lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
    }
}

/// How many points [`NoiseMap::perlin3_vectors`] works on side by side.
const LANES: usize = 8;

impl NoiseMap {
    /// [`perlin3_vector`](Self::perlin3_vector) at every point of `points`,
    /// into `out` (of the same length): bit for bit the same values
    /// (tested), faster on x86-64 CPUs with AVX2, where eight points go
    /// through the noise together in SIMD lanes (the permutation table read
    /// by gathers; docs/benchmarks/groom.md has the figures). Elsewhere, one
    /// point at a time.
    pub fn perlin3_vectors(&self, points: &[glam::Vec3], out: &mut [glam::Vec3]) {
        assert_eq!(points.len(), out.len(), "one output a point");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut chunks = points.chunks_exact(LANES);
            let mut outs = out.chunks_exact_mut(LANES);
            for (p, o) in (&mut chunks).zip(&mut outs) {
                // SAFETY: the CPU has AVX2 (checked above).
                unsafe { avx2::perlin3_lanes(&self.permutation32, &self.corner_gradients, p, o) };
            }
            let (rest, rest_out) = (chunks.remainder(), outs.into_remainder());
            // A part-filled batch costs a full one, about three single
            // points: worth it from three points up.
            if rest.len() >= 3 {
                let mut p = [glam::Vec3::ZERO; LANES];
                p[..rest.len()].copy_from_slice(rest);
                let mut o = [glam::Vec3::ZERO; LANES];
                // SAFETY: as above.
                unsafe {
                    avx2::perlin3_lanes(&self.permutation32, &self.corner_gradients, &p, &mut o)
                };
                rest_out.copy_from_slice(&o[..rest.len()]);
            } else {
                for (p, o) in rest.iter().zip(rest_out) {
                    *o = self.perlin3_vector(*p);
                }
            }
            return;
        }
        for (p, o) in points.iter().zip(out) {
            *o = self.perlin3_vector(*p);
        }
    }
}

/// [`NoiseMap::perlin3_vector`] for eight points at once with AVX2: the
/// same operations in the same order, lane by lane, so the results are
/// the scalar code's to the bit (no fused multiply-adds).
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    /// `points` and `out` hold eight points each.
    #[target_feature(enable = "avx2")]
    pub(super) fn perlin3_lanes(
        perm: &[u32; 512],
        corner_gradients: &[u32; 512],
        points: &[glam::Vec3],
        out: &mut [glam::Vec3],
    ) {
        debug_assert!(points.len() == super::LANES && out.len() == super::LANES);
        let coordinate = |axis: usize| {
            let c: [f32; 8] = std::array::from_fn(|l| points[l][axis]);
            // SAFETY: reads the eight floats of `c`.
            unsafe { _mm256_loadu_ps(c.as_ptr()) }
        };
        let one = _mm256_set1_ps(1.0);
        let mask255 = _mm256_set1_epi32(255);
        let mask511 = _mm256_set1_epi32(511);
        // Cell (wrapped to the table), offset in the cell, fade weight.
        let split = |c: __m256| {
            let i = _mm256_cvtepi32_ps(_mm256_cvttps_epi32(c));
            // floor: one less where truncation rounded up (c < 0).
            let floor = _mm256_sub_ps(i, _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(i, c), one));
            let cell = _mm256_and_si256(_mm256_cvttps_epi32(floor), mask255);
            let t = _mm256_sub_ps(c, floor);
            let t3 = _mm256_mul_ps(_mm256_mul_ps(t, t), t);
            let inner = _mm256_add_ps(
                _mm256_mul_ps(
                    t,
                    _mm256_sub_ps(_mm256_mul_ps(t, _mm256_set1_ps(6.0)), _mm256_set1_ps(15.0)),
                ),
                _mm256_set1_ps(10.0),
            );
            (cell, t, _mm256_mul_ps(t3, inner))
        };
        let (xi, fx, u) = split(coordinate(0));
        let (yi, fy, v) = split(coordinate(1));
        let (zi, fz, w) = split(coordinate(2));
        let at = |i: __m256i| {
            // SAFETY: indices masked below 512, the table's length.
            unsafe {
                _mm256_i32gather_epi32::<4>(perm.as_ptr().cast(), _mm256_and_si256(i, mask511))
            }
        };
        let gradients_at = |i: __m256i| {
            // SAFETY: indices masked below 512, the table's length.
            unsafe {
                _mm256_i32gather_epi32::<4>(
                    corner_gradients.as_ptr().cast(),
                    _mm256_and_si256(i, mask511),
                )
            }
        };
        let add = |a: __m256i, k: i32| _mm256_add_epi32(a, _mm256_set1_epi32(k));
        let hx = [at(xi), at(add(xi, 1))];
        let hxy = [
            [
                at(_mm256_add_epi32(hx[0], yi)),
                at(add(_mm256_add_epi32(hx[0], yi), 1)),
            ],
            [
                at(_mm256_add_epi32(hx[1], yi)),
                at(add(_mm256_add_epi32(hx[1], yi), 1)),
            ],
        ];
        // Perlin's `grad` in lanes (see [`super::gradient3`]): the hash's
        // bits pick the two offsets that are summed and their signs. Plain
        // selects, not a lookup of the gradient rows by `vpermps`: fewer
        // instructions, and about 0.76× the time of the lookup on the
        // first Zen cores, where a 256-bit permute costs several µops.
        let sign_bit = _mm256_set1_epi32(i32::MIN);
        let gradient_dot = |h: __m256i, x: __m256, y: __m256, z: __m256| {
            let as_mask = _mm256_castsi256_ps;
            // h < 8 ? x : y — bit 3 moved to the sign bit `blendv` reads.
            let u = _mm256_blendv_ps(x, y, as_mask(_mm256_slli_epi32::<28>(h)));
            // h < 4 ? y : (h == 12 || h == 14 ? x : z)
            // (The masks read only bits 0–3: the other components' hash
            // bits above them are ignored.)
            let is_x = _mm256_cmpeq_epi32(
                _mm256_and_si256(h, _mm256_set1_epi32(13)),
                _mm256_set1_epi32(12),
            );
            let is_y = _mm256_cmpeq_epi32(
                _mm256_and_si256(h, _mm256_set1_epi32(12)),
                _mm256_setzero_si256(),
            );
            let v = _mm256_blendv_ps(z, x, as_mask(is_x));
            let v = _mm256_blendv_ps(v, y, as_mask(is_y));
            // Bit 0 negates u, bit 1 negates v.
            let u = _mm256_xor_ps(u, as_mask(_mm256_slli_epi32::<31>(h)));
            let v = _mm256_xor_ps(
                v,
                as_mask(_mm256_and_si256(_mm256_slli_epi32::<30>(h), sign_bit)),
            );
            _mm256_add_ps(u, v)
        };
        let lerp = |a: __m256, b: __m256, t: __m256| {
            _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)))
        };
        // Each corner's dot products, one a component. A loop in this
        // function's body, not a closure handed to `array::from_fn`: the
        // compiler sometimes kept that closure out of line, reloading the
        // tables and spilling its results at every corner.
        let mut corner = [[_mm256_setzero_ps(); 3]; 8];
        for (c, dots) in corner.iter_mut().enumerate() {
            let (dx, dy, dz) = (c & 1, (c >> 1) & 1, c >> 2);
            let rows = gradients_at(add(_mm256_add_epi32(hxy[dx][dy], zi), dz as i32));
            let x = _mm256_sub_ps(fx, _mm256_set1_ps(dx as f32));
            let y = _mm256_sub_ps(fy, _mm256_set1_ps(dy as f32));
            let z = _mm256_sub_ps(fz, _mm256_set1_ps(dz as f32));
            let component_rows = [
                rows,
                _mm256_srli_epi32::<4>(rows),
                _mm256_srli_epi32::<8>(rows),
            ];
            for (dot, hc) in dots.iter_mut().zip(component_rows) {
                *dot = gradient_dot(hc, x, y, z);
            }
        }
        for component in 0..3 {
            let k: [__m256; 8] = std::array::from_fn(|c| corner[c][component]);
            let x00 = lerp(k[0], k[1], u);
            let x10 = lerp(k[2], k[3], u);
            let x01 = lerp(k[4], k[5], u);
            let x11 = lerp(k[6], k[7], u);
            let r = lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
            let mut lanes = [0.0f32; 8];
            // SAFETY: writes the eight floats of `lanes`.
            unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), r) };
            for (o, value) in out.iter_mut().zip(lanes) {
                o[component] = value;
            }
        }
    }
}

/// `x.floor()` without a libm call (baseline x86-64 has no SSE4.1
/// rounding instruction, so `f32::floor` is a function call): exact for
/// |x| < 2³¹, where the noise lattice lives.
#[inline]
fn floor(x: f32) -> f32 {
    let i = x as i32 as f32;
    if i > x { i - 1.0 } else { i }
}

/// Dot product of the offset with one of Perlin's twelve gradients (the
/// cube's edge midpoints, four of them repeated to make sixteen), picked
/// by the hash's low four bits as his reference code's `grad` picks them:
/// selects and sign flips, no multiplications. Hashes are random, so the
/// selects are bit masks: written as `if`s the compiler made them branches,
/// which mispredicted often enough to double the scalar noise's time.
#[inline]
fn gradient3(hash: u8, x: f32, y: f32, z: f32) -> f32 {
    let h = u32::from(hash & 15);
    // All ones where `condition` holds, else zero.
    let mask = |condition: bool| u32::from(condition).wrapping_neg();
    let pick = |m: u32, a: f32, b: f32| f32::from_bits((a.to_bits() & m) | (b.to_bits() & !m));
    let u = pick(mask(h < 8), x, y);
    let v = pick(mask(h < 4), y, pick(mask(h == 12 || h == 14), x, z));
    let flip =
        |value: f32, bit: u32| f32::from_bits(value.to_bits() ^ (u32::from(h & bit != 0) << 31));
    flip(u, 1) + flip(v, 2)
}

/// Dot product of the offset with one of eight gradients: the four axis
/// directions and four diagonals scaled to unit length. Noise built this way
/// reaches about ±1.
fn gradient(hash: u8, x: f32, y: f32) -> f32 {
    const D: f32 = std::f32::consts::FRAC_1_SQRT_2;
    match hash & 7 {
        0 => x,
        1 => -x,
        2 => y,
        3 => -y,
        4 => D * (x + y),
        5 => D * (x - y),
        6 => D * (-x + y),
        _ => D * (-x - y),
    }
}

/// The doubled permutation table of 0..256, shuffled by `seed` with
/// Fisher–Yates driven by SplitMix64 (deterministic on every platform).
fn permutation(seed: u64) -> Box<[u8; 512]> {
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    let mut table: [u8; 256] = std::array::from_fn(|i| i as u8);
    for i in (1..256).rev() {
        let j = (next() % (i as u64 + 1)) as usize;
        table.swap(i, j);
    }
    let mut doubled = Box::new([0u8; 512]);
    doubled[..256].copy_from_slice(&table);
    doubled[256..].copy_from_slice(&table);
    doubled
}

#[cfg(test)]
mod tests {
    #[test]
    fn vector_noise_is_continuous_across_cells_negative_ones_too() {
        let n = NoiseMap::new(1.0, 1, 7, 0.0, 1.0);
        for x in [-3.0f32, -1.0, 0.0, 2.0] {
            let p = glam::Vec3::new(x, 0.37, -1.21);
            let (a, b) = (
                n.perlin3_vector(p - glam::Vec3::X * 1e-4),
                n.perlin3_vector(p + glam::Vec3::X * 1e-4),
            );
            assert!((a - b).length() < 1e-2, "jump at x = {x}: {a} vs {b}");
        }
        // Zero on the lattice, as Perlin noise is; components differ.
        assert_eq!(
            n.perlin3_vector(glam::Vec3::new(-2.0, 5.0, 1.0)),
            glam::Vec3::ZERO
        );
        let v = n.perlin3_vector(glam::Vec3::new(0.3, 0.6, 0.2));
        assert!(v.x != v.y && v.y != v.z);
    }

    use super::*;

    /// Perlin's `grad`, as his reference code (Improved Noise, 2002)
    /// writes it.
    fn grad(hash: usize, x: f32, y: f32, z: f32) -> f32 {
        let h = hash & 15;
        let u = if h < 8 { x } else { y };
        let v = if h < 4 {
            y
        } else if h == 12 || h == 14 {
            x
        } else {
            z
        };
        (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
    }

    #[test]
    fn gradients_are_the_cube_edge_midpoints_perlin_lists() {
        // Perlin 2002: the twelve edge directions, padded to sixteen with
        // (1,1,0), (−1,1,0), (0,−1,1), (0,−1,−1).
        const GRADIENTS: [[f32; 3]; 16] = [
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [1.0, -1.0, 0.0],
            [-1.0, -1.0, 0.0],
            [1.0, 0.0, 1.0],
            [-1.0, 0.0, 1.0],
            [1.0, 0.0, -1.0],
            [-1.0, 0.0, -1.0],
            [0.0, 1.0, 1.0],
            [0.0, -1.0, 1.0],
            [0.0, 1.0, -1.0],
            [0.0, -1.0, -1.0],
            [1.0, 1.0, 0.0],
            [0.0, -1.0, 1.0],
            [-1.0, 1.0, 0.0],
            [0.0, -1.0, -1.0],
        ];
        for (h, g) in GRADIENTS.iter().enumerate() {
            // Each of the hash's higher bits is ignored.
            let hash = (h | 0xa0) as u8;
            let picked = [
                gradient3(hash, 1.0, 0.0, 0.0),
                gradient3(hash, 0.0, 1.0, 0.0),
                gradient3(hash, 0.0, 0.0, 1.0),
            ];
            assert_eq!(&picked, g, "hash {h}");
            let (x, y, z) = (0.3, -0.7, 0.45);
            assert_eq!(
                gradient3(hash, x, y, z),
                g[0] * x + g[1] * y + g[2] * z,
                "hash {h}"
            );
        }
    }

    /// Perlin's 3-D noise as his reference code writes it, the full hash
    /// chain at every corner; a component other than the first rehashes
    /// the corner's hash with its salt.
    fn reference_perlin3(perm: &[u8; 512], salt: Option<usize>, p: glam::Vec3) -> f32 {
        let cell = p.floor();
        let f = p - cell;
        let [xi, yi, zi] = [cell.x, cell.y, cell.z].map(|c| (c as i64 & 255) as usize);
        let at = |i: usize| perm[i] as usize;
        let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let corner = |dx: usize, dy: usize, dz: usize| {
            let h = at(at(at(xi + dx) + yi + dy) + zi + dz);
            let h = salt.map_or(h, |salt| at(h + salt));
            grad(h, f.x - dx as f32, f.y - dy as f32, f.z - dz as f32)
        };
        let lerp = |a: f32, b: f32, t: f32| a + t * (b - a);
        let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
        let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), u);
        let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), u);
        let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), u);
        let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), u);
        lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
    }

    #[test]
    fn vector_noise_equals_perlins_reference_bit_for_bit() {
        for seed in [0, 1, 99] {
            let n = NoiseMap::new(1.0, 1, seed, 0.0, 1.0);
            let perm = n.permutation_table();
            for k in 0..20_000 {
                let f = k as f32;
                let p = glam::Vec3::new(
                    f * 0.0137 - 130.0,
                    (f * 0.00731).sin() * 300.0,
                    f * -0.0091 + 7.5,
                );
                let v = n.perlin3_vector(p);
                let reference = glam::Vec3::new(
                    reference_perlin3(perm, None, p),
                    reference_perlin3(perm, Some(101), p),
                    reference_perlin3(perm, Some(203), p),
                );
                assert_eq!(
                    v.to_array().map(f32::to_bits),
                    reference.to_array().map(f32::to_bits),
                    "seed {seed}, p = {p}"
                );
            }
        }
    }

    #[test]
    fn batched_vector_noise_equals_one_point_at_a_time_bit_for_bit() {
        let n = NoiseMap::new(1.0, 1, 5, 0.0, 1.0);
        let points: Vec<glam::Vec3> = (0..1_003)
            .map(|k| {
                let f = k as f32;
                glam::Vec3::new(f * 0.731 - 400.0, (f * 0.37).cos() * 9.0, -f * 0.113)
            })
            // Lattice points and cell edges too.
            .chain([
                glam::Vec3::ZERO,
                glam::Vec3::new(-1.0, 2.0, -3.0),
                glam::Vec3::splat(-0.0),
            ])
            .collect();
        // Every length around the SIMD width, to cover the tails.
        for len in (0..20).chain([points.len()]) {
            let mut out = vec![glam::Vec3::NAN; len];
            n.perlin3_vectors(&points[..len], &mut out);
            for (p, o) in points.iter().zip(&out) {
                assert_eq!(
                    o.to_array().map(f32::to_bits),
                    n.perlin3_vector(*p).to_array().map(f32::to_bits),
                    "p = {p}, {len} points"
                );
            }
        }
    }

    #[test]
    fn perlin_is_zero_on_lattice_points_and_bounded() {
        let n = NoiseMap::default();
        assert_eq!(n.perlin(Vec2::new(3.0, 7.0)), 0.0);
        let mut lo: f32 = 0.0;
        let mut hi: f32 = 0.0;
        for i in 0..200 {
            for j in 0..200 {
                let v = n.perlin(Vec2::new(i as f32 * 0.0731, j as f32 * 0.0619));
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        assert!(lo >= -1.0 && hi <= 1.0, "{lo} {hi}");
        assert!(
            hi - lo > 1.0,
            "noise should use most of its range: {lo}..{hi}"
        );
    }

    #[test]
    fn default_fbm_stays_in_unit_interval_with_mean_near_half() {
        let n = NoiseMap::default();
        let samples: Vec<f32> = (0..10_000)
            .map(|k| {
                n.eval(Vec2::new(
                    (k % 100) as f32 / 100.0,
                    (k / 100) as f32 / 100.0,
                ))
            })
            .collect();
        assert!(samples.iter().all(|v| (0.0..=1.0).contains(v)));
        let mean = samples.iter().sum::<f32>() / samples.len() as f32;
        assert!((mean - 0.5).abs() < 0.1, "mean {mean}");
    }

    #[test]
    fn seeds_give_different_fields_and_same_seed_the_same() {
        let uv = Vec2::new(0.37, 0.61);
        let a = NoiseMap::new(4.0, 3, 1, 0.0, 1.0);
        let b = NoiseMap::new(4.0, 3, 2, 0.0, 1.0);
        assert_eq!(a.eval(uv), NoiseMap::new(4.0, 3, 1, 0.0, 1.0).eval(uv));
        assert_ne!(a.eval(uv), b.eval(uv));
    }
}
