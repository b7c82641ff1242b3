//! Procedural noise maps: 2D Perlin gradient noise (Perlin 2002, "Improving
//! Noise": quintic fade, hashed gradients) summed in octaves (fBm), as the
//! Stubble generator uses for density and displacement (Sik, section 4.3).

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
    permutation: Box<[u8; 512]>,
}

impl Default for NoiseMap {
    fn default() -> Self {
        Self::new(4.0, 4, 0, 0.5, 0.5)
    }
}

impl NoiseMap {
    /// A noise map; `octaves` below 1 is treated as 1.
    pub fn new(frequency: f32, octaves: u32, seed: u64, offset: f32, scale: f32) -> Self {
        Self {
            frequency,
            octaves: octaves.max(1),
            seed,
            offset,
            scale,
            permutation: permutation(seed),
        }
    }

    /// The doubled permutation table the noise hashes lattice points with
    /// (a GPU port of the noise uploads it).
    pub fn permutation_table(&self) -> &[u8; 512] {
        &self.permutation
    }

    /// The map's value at `uv`.
    pub fn eval(&self, uv: Vec2) -> f32 {
        let mut sum = 0.0;
        let mut amplitude = 1.0;
        let mut total = 0.0;
        let mut p = uv * self.frequency;
        for _ in 0..self.octaves {
            sum += amplitude * self.perlin(p);
            total += amplitude;
            amplitude *= 0.5;
            p *= 2.0;
        }
        self.offset + self.scale * sum / total
    }

    /// One octave of 2D Perlin noise, in about [−1, 1].
    pub fn perlin(&self, p: Vec2) -> f32 {
        let cell = p.floor();
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

/// Perlin's twelve gradients (the cube's edge midpoints), padded to 16
/// with four repeated, indexed by a hash's low four bits.
const GRADIENTS3: [[f32; 3]; 16] = [
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

/// Dot product of the offset with the gradient a hash picks. A table, not
/// a `match`: hashes are random, so a branch per corner would mispredict
/// about half the time.
#[inline]
fn gradient3(hash: u8, x: f32, y: f32, z: f32) -> f32 {
    let [gx, gy, gz] = GRADIENTS3[usize::from(hash & 15)];
    gx * x + gy * y + gz * z
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
            let [gx, gy, gz] = GRADIENTS3[h & 15];
            gx * (f.x - dx as f32) + gy * (f.y - dy as f32) + gz * (f.z - dz as f32)
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
