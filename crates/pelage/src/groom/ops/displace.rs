//! Displacement operators: `noise` (Sik §4.2.2, Fig. 15: "random vectors
//! generated from Perlin noise added to the hair curve's vertices"),
//! `frizz` (per-hair random high-frequency wiggle) and `curl` (a helix
//! around the hair's path, the shape of Silva et al. Eq. 4).

use super::{Hair, RootContext, Scratch, param};
use crate::groom::file::Ramp;
use crate::map::{Map, NoiseMap};
use crate::sample::SampleRng;
use glam::Vec3;
use std::f32::consts::TAU;

/// A smooth random vector field in space (three Perlin noises sharing
/// their lattice, see [`NoiseMap::perlin3_vector`]).
#[derive(Debug, Clone)]
struct VectorNoise(NoiseMap);

impl VectorNoise {
    fn new(seed: u64) -> Self {
        Self(NoiseMap::new(1.0, 1, seed, 0.0, 1.0))
    }

    /// Each component in about [−1, 1]. Perlin noise is zero on its
    /// lattice; the offset keeps round coordinates (a hair along an axis)
    /// off it.
    #[inline]
    fn at(&self, p: Vec3) -> Vec3 {
        self.0.perlin3_vector(p + Self::OFF_LATTICE)
    }

    const OFF_LATTICE: Vec3 = Vec3::new(0.371, 0.713, 0.137);

    /// [`at`](Self::at) each of `points` (at most [`MAX_VECTORS`]), into
    /// `out`: the same values, the noise read several points at a time.
    fn at_many(&self, points: &[Vec3], out: &mut [Vec3]) {
        let mut shifted = [Vec3::ZERO; MAX_VECTORS];
        let shifted = &mut shifted[..points.len()];
        for (s, p) in shifted.iter_mut().zip(points) {
            *s = *p + Self::OFF_LATTICE;
        }
        self.0.perlin3_vectors(shifted, out);
    }
}

/// `noise`: the hair moves by a Perlin vector field sampled in space:
/// `p += amplitude · ramp(t) · N(frequency · p)`. As in Stubble, the field
/// is sampled at `vectors` points evenly spaced along the hair ("the number
/// of vectors used on a single hair … are user parameters", Sik §4.2.2)
/// and the displacement interpolated linearly between them; `vectors = 0`
/// samples at every point. The field is continuous in space, so
/// neighbouring hairs wave alike (Stubble's Fig. 15); `ramp` keeps roots on
/// the skin (linear by default).
#[derive(Debug, Clone)]
pub struct Noise {
    field: VectorNoise,
    amplitude: Map,
    frequency: Map,
    ramp: Ramp,
    vectors: usize,
}

impl Noise {
    /// A noise operator sampling `vectors` noise vectors a hair (0: one a
    /// point).
    pub fn new(amplitude: Map, frequency: Map, ramp: Ramp, seed: u64, vectors: usize) -> Self {
        Self {
            field: VectorNoise::new(seed),
            amplitude,
            frequency,
            ramp,
            vectors,
        }
    }

    pub(super) fn apply(&self, hair: &mut Hair, root: &RootContext) {
        let amplitude = self.amplitude.eval(root.uv);
        if amplitude == 0.0 {
            return;
        }
        let frequency = self.frequency.eval(root.uv);
        let n = hair.points.len();
        let m = if self.vectors == 0 || self.vectors >= n {
            n
        } else {
            self.vectors.max(2)
        };
        if m == n {
            for (j, p) in hair.points.iter_mut().enumerate() {
                let a = amplitude * self.ramp.at(param(j, n));
                if a != 0.0 {
                    *p += a * self.field.at(*p * frequency);
                }
            }
            return;
        }
        // Noise vectors at m evenly spaced parameters (positions along the
        // polyline), then each point's displacement between its two.
        let m = m.min(MAX_VECTORS);
        let mut at = [Vec3::ZERO; MAX_VECTORS];
        for (k, at) in at.iter_mut().enumerate().take(m) {
            let x = param(k, m) * (n - 1) as f32;
            let j = (x as usize).min(n - 2);
            *at = hair.points[j].lerp(hair.points[j + 1], x - j as f32) * frequency;
        }
        let mut samples = [Vec3::ZERO; MAX_VECTORS];
        self.field.at_many(&at[..m], &mut samples[..m]);
        for (j, p) in hair.points.iter_mut().enumerate() {
            let t = param(j, n);
            let a = amplitude * self.ramp.at(t);
            if a != 0.0 {
                let x = t * (m - 1) as f32;
                let k = (x as usize).min(m - 2);
                *p += a * samples[k].lerp(samples[k + 1], x - k as f32);
            }
        }
    }
}

/// The most noise vectors a hair samples (more points than this are
/// interpolated).
const MAX_VECTORS: usize = 64;

/// `frizz`: a share of the hairs (`fraction`) each wiggle on their own:
/// `p += amplitude · ramp(t) · N(φ + frequency · t · X)`, where `φ` is a
/// random point of the noise field drawn per hair, so hairs side by side
/// frizz differently (unlike `noise`), `frequency` wiggles along the hair.
#[derive(Debug, Clone)]
pub struct Frizz {
    field: VectorNoise,
    amplitude: Map,
    frequency: Map,
    fraction: Map,
    ramp: Ramp,
    seed: u64,
}

impl Frizz {
    /// A frizz operator.
    pub fn new(amplitude: Map, frequency: Map, fraction: Map, ramp: Ramp, seed: u64) -> Self {
        Self {
            field: VectorNoise::new(seed ^ 0xF122),
            amplitude,
            frequency,
            fraction,
            ramp,
            seed,
        }
    }

    pub(super) fn apply(&self, hair: &mut Hair, root: &RootContext) {
        let mut rng = SampleRng::new(self.seed ^ 0xF122_F122, hair.id);
        if rng.uniform_f32() >= self.fraction.eval(root.uv) {
            return;
        }
        let amplitude = self.amplitude.eval(root.uv);
        let frequency = self.frequency.eval(root.uv);
        let [a, b] = rng.uniform_f32_pair();
        let phase = Vec3::new(a, b, rng.uniform_f32()) * 256.0;
        let n = hair.points.len();
        for (j, p) in hair.points.iter_mut().enumerate() {
            let t = param(j, n);
            *p += amplitude * self.ramp.at(t) * self.field.at(phase + Vec3::X * (frequency * t));
        }
    }
}

/// `curl`: a helix around the hair's path, Silva et al. Eq. 4 with the
/// curve parameter for `h`: `p += α(t) (cos(2π·turns·t + φ) r + sin(…) b)`
/// with `α(t) = radius · ramp(t)` (Silva: `K_α h`, a linear ramp), `r` the
/// rotation-minimizing normal along the hair and `b = T × r`, `φ` a random
/// phase per hair. The frame does not twist, so the helix turns exactly
/// `turns` times; resolve it with enough points per hair.
#[derive(Debug, Clone)]
pub struct Curl {
    radius: Map,
    turns: Map,
    ramp: Ramp,
    seed: u64,
}

impl Curl {
    /// A curl operator.
    pub fn new(radius: Map, turns: Map, ramp: Ramp, seed: u64) -> Self {
        Self {
            radius,
            turns,
            ramp,
            seed,
        }
    }

    pub(super) fn apply(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        let radius = self.radius.eval(root.uv);
        if radius == 0.0 {
            return;
        }
        let turns = self.turns.eval(root.uv);
        let phase = TAU * SampleRng::new(self.seed ^ 0xC0_11, hair.id).uniform_f32();
        let n = hair.points.len();
        scratch.frame_along(&hair.points, root.normal);
        for (j, p) in hair.points.iter_mut().enumerate() {
            let t = param(j, n);
            let alpha = radius * self.ramp.at(t);
            let (s, c) = (TAU * turns * t + phase).sin_cos();
            let r = scratch.frame[j];
            let b = scratch.tangents[j].cross(r);
            *p += alpha * (c * r + s * b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{root, straight};
    use super::*;

    #[test]
    fn noise_keeps_the_root_and_is_coherent_in_space() {
        let op = Noise::new(
            Map::Constant(0.1),
            Map::Constant(3.0),
            Ramp::default(),
            4,
            0,
        );
        let mut a = straight(1, 16, 1.0);
        op.apply(&mut a, &root());
        assert_eq!(a.points[0], Vec3::ZERO, "a linear ramp leaves the root");
        let moved = (a.points[15] - Vec3::Z).length();
        assert!(moved > 1e-3 && moved <= 0.1 * 3f32.sqrt() * 1.01, "{moved}");
        // A neighbouring hair (another id, 1e-3 away) moves almost alike;
        // noise is a field in space, not per hair.
        let mut b = straight(2, 16, 1.0);
        b.points.iter_mut().for_each(|p| *p += Vec3::X * 1e-3);
        op.apply(&mut b, &root());
        let db = b.points[15] - Vec3::Z - Vec3::X * 1e-3;
        assert!((db - (a.points[15] - Vec3::Z)).length() < 0.1 * 0.05);
    }

    #[test]
    fn frizz_differs_per_hair_and_respects_fraction() {
        let op = Frizz::new(
            Map::Constant(0.05),
            Map::Constant(6.0),
            Map::Constant(1.0),
            Ramp::default(),
            0,
        );
        let (mut a, mut b) = (straight(1, 16, 1.0), straight(2, 16, 1.0));
        op.apply(&mut a, &root());
        op.apply(&mut b, &root());
        assert!((a.points[15] - b.points[15]).length() > 1e-3, "per hair");
        let mut again = straight(1, 16, 1.0);
        op.apply(&mut again, &root());
        assert_eq!(again, a, "same id, same frizz");
        let none = Frizz::new(
            Map::Constant(0.05),
            Map::Constant(6.0),
            Map::Constant(0.0),
            Ramp::default(),
            0,
        );
        let mut c = straight(3, 16, 1.0);
        none.apply(&mut c, &root());
        assert_eq!(c, straight(3, 16, 1.0), "fraction 0 frizzes nothing");
    }

    #[test]
    fn curl_is_a_helix_of_the_given_radius_and_turns() {
        // Straight hair up Z, constant ramp: every point lies at exactly
        // `radius` from the axis, at its own height, and the angle turns
        // 2 full times root to tip.
        let op = Curl::new(Map::Constant(0.05), Map::Constant(2.0), Ramp::Power(0.0), 9);
        let n = 65;
        let mut hair = straight(1, n, 1.0);
        op.apply(&mut hair, &root(), &mut Scratch::default());
        let mut angle = 0.0f32;
        for j in 0..n {
            let p = hair.points[j];
            assert!((p.truncate().length() - 0.05).abs() < 1e-5, "{j}: {p}");
            assert!((p.z - param(j, n)).abs() < 1e-6);
            if j > 0 {
                let q = hair.points[j - 1].truncate();
                angle += q.angle_to(p.truncate());
            }
        }
        assert!((angle.abs() - 2.0 * TAU).abs() < 1e-3, "{angle}");
        // Silva's linear ramp: the radius grows from 0 at the root.
        let linear = Curl::new(Map::Constant(0.05), Map::Constant(2.0), Ramp::default(), 9);
        let mut hair = straight(1, n, 1.0);
        linear.apply(&mut hair, &root(), &mut Scratch::default());
        assert!(hair.points[0].length() < 1e-7);
        assert!((hair.points[32].truncate().length() - 0.025).abs() < 1e-5);
    }
}
