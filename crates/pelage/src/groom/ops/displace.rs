//! Displacement operators: `noise` (Sik §4.2.2, Fig. 15: "random vectors
//! generated from Perlin noise added to the hair curve's vertices"),
//! `frizz` (per-hair random high-frequency wiggle) and `curl` (a helix
//! around the hair's path, the shape of Silva et al. Eq. 4).

use super::{Hair, RampTables, Resampling, RootContext, Scratch, param};
use crate::groom::file::Ramp;
use crate::map::{Map, NoiseMap};
use crate::sample::{SampleRng, salts};
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

    /// Where [`at`](Self::at) reads the noise for `p`.
    #[inline]
    fn shifted(p: Vec3) -> Vec3 {
        p + Self::OFF_LATTICE
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

    /// Displaces one hair.
    pub(super) fn apply(
        &self,
        hair: &mut Hair,
        root: &RootContext,
        scratch: &mut NoiseScratch,
        ramps: &mut RampTables,
    ) {
        self.apply_each(
            std::slice::from_mut(hair),
            std::slice::from_ref(root),
            scratch,
            ramps,
        );
    }

    /// Displaces each of `hairs` (`hairs[i]` grown from `roots[i]`): the
    /// same values as one at a time, with the noise vectors of all of them
    /// read in one go, so the eight-lane noise runs full (a hair's handful
    /// of vectors leaves lanes idle).
    pub(super) fn apply_each(
        &self,
        hairs: &mut [Hair],
        roots: &[RootContext],
        scratch: &mut NoiseScratch,
        ramps: &mut RampTables,
    ) {
        let NoiseScratch {
            at,
            samples,
            hairs: per_hair,
            spacing,
        } = scratch;
        at.clear();
        per_hair.clear();
        for (hair, root) in hairs.iter().zip(roots) {
            let amplitude = self.amplitude.at(&root.site);
            let n = hair.points.len();
            if amplitude == 0.0 || n == 0 {
                per_hair.push((0.0, 0));
                continue;
            }
            let frequency = self.frequency.at(&root.site);
            let m = self.vectors_along(n);
            per_hair.push((amplitude, m));
            if m == n {
                at.extend(
                    hair.points
                        .iter()
                        .map(|p| VectorNoise::shifted(*p * frequency)),
                );
            } else {
                // Noise vectors at m evenly spaced parameters (positions
                // along the polyline).
                let points = &hair.points;
                at.extend(spacing.fit(n, m).0.between().iter().map(|&(j, f)| {
                    let j = j as usize;
                    VectorNoise::shifted(points[j].lerp(points[j + 1], f) * frequency)
                }));
            }
        }
        samples.resize(at.len(), Vec3::ZERO);
        self.field.0.perlin3_vectors(at, samples);
        let mut next = 0;
        for (hair, &(amplitude, m)) in hairs.iter_mut().zip(per_hair.iter()) {
            if m == 0 {
                continue;
            }
            let samples = &samples[next..next + m];
            next += m;
            let n = hair.points.len();
            let ramp = ramps.along(&self.ramp, n);
            if m == n {
                for ((p, s), ramp) in hair.points.iter_mut().zip(samples).zip(ramp) {
                    let a = amplitude * ramp;
                    if a != 0.0 {
                        *p += a * *s;
                    }
                }
            } else {
                // Each point's displacement between its two vectors.
                let between = spacing.fit(n, m).1.between();
                for ((p, &(k, f)), ramp) in hair.points.iter_mut().zip(between).zip(ramp) {
                    let a = amplitude * ramp;
                    if a != 0.0 {
                        let k = k as usize;
                        *p += a * samples[k].lerp(samples[k + 1], f);
                    }
                }
            }
        }
    }

    /// How many noise vectors a hair of `n` points samples.
    fn vectors_along(&self, n: usize) -> usize {
        if self.vectors == 0 || self.vectors >= n {
            n
        } else {
            self.vectors.clamp(2, MAX_VECTORS)
        }
    }
}

/// Buffers of [`Noise::apply_each`], reused.
#[derive(Debug, Default)]
pub struct NoiseScratch {
    /// Where the noise is read (scaled and shifted), every hair's in turn.
    at: Vec<Vec3>,
    /// The noise vectors read there.
    samples: Vec<Vec3>,
    /// Each hair's amplitude and number of vectors (0: not displaced).
    hairs: Vec<(f32, usize)>,
    spacing: VectorSpacing,
}

/// Where a hair of `n` points reads its `m < n` noise vectors, and where
/// each point lies between them: the two resamplings, kept while `n` and
/// `m` stay the same (for a whole groom unless hairs are cut).
#[derive(Debug, Default)]
struct VectorSpacing {
    fitted: Option<(usize, usize, Resampling, Resampling)>,
}

impl VectorSpacing {
    /// (points → vectors, vectors → points) for `n` points, `m` vectors.
    fn fit(&mut self, n: usize, m: usize) -> (&Resampling, &Resampling) {
        if !matches!(&self.fitted, Some((kn, km, ..)) if (*kn, *km) == (n, m)) {
            self.fitted = Some((n, m, Resampling::new(n, m), Resampling::new(m, n)));
        }
        let (_, _, to_vectors, to_points) = self.fitted.as_ref().expect("just fitted");
        (to_vectors, to_points)
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
            field: VectorNoise::new(seed ^ salts::FRIZZ_FIELD),
            amplitude,
            frequency,
            fraction,
            ramp,
            seed,
        }
    }

    pub(super) fn apply(&self, hair: &mut Hair, root: &RootContext, ramps: &mut RampTables) {
        let mut rng = SampleRng::new(self.seed ^ salts::FRIZZ_HAIR, hair.id);
        if rng.uniform_f32() >= self.fraction.at(&root.site) {
            return;
        }
        let amplitude = self.amplitude.at(&root.site);
        let frequency = self.frequency.at(&root.site);
        let [a, b] = rng.uniform_f32_pair();
        let phase = Vec3::new(a, b, rng.uniform_f32()) * 256.0;
        let n = hair.points.len();
        let ramp = ramps.along(&self.ramp, n);
        for (j, (p, profile)) in hair.points.iter_mut().zip(ramp).enumerate() {
            let t = param(j, n);
            *p += amplitude * profile * self.field.at(phase + Vec3::X * (frequency * t));
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
        let radius = self.radius.at(&root.site);
        if radius == 0.0 {
            return;
        }
        let turns = self.turns.at(&root.site);
        let phase = TAU * SampleRng::new(self.seed ^ salts::CURL_PHASE, hair.id).uniform_f32();
        let n = hair.points.len();
        scratch.frame_along(&hair.points, root.normal);
        let ramp = scratch.ramps.along(&self.ramp, n);
        for (j, (p, profile)) in hair.points.iter_mut().zip(ramp).enumerate() {
            let t = param(j, n);
            let alpha = radius * profile;
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
        op.apply(
            &mut a,
            &root(),
            &mut NoiseScratch::default(),
            &mut RampTables::default(),
        );
        assert_eq!(a.points[0], Vec3::ZERO, "a linear ramp leaves the root");
        let moved = (a.points[15] - Vec3::Z).length();
        assert!(moved > 1e-3 && moved <= 0.1 * 3f32.sqrt() * 1.01, "{moved}");
        // A neighbouring hair (another id, 1e-3 away) moves almost alike;
        // noise is a field in space, not per hair.
        let mut b = straight(2, 16, 1.0);
        b.points.iter_mut().for_each(|p| *p += Vec3::X * 1e-3);
        op.apply(
            &mut b,
            &root(),
            &mut NoiseScratch::default(),
            &mut RampTables::default(),
        );
        let db = b.points[15] - Vec3::Z - Vec3::X * 1e-3;
        assert!((db - (a.points[15] - Vec3::Z)).length() < 0.1 * 0.05);
    }

    #[test]
    fn noise_on_many_hairs_at_once_matches_one_at_a_time_to_the_bit() {
        // Hairs of several point counts (one too short to interpolate
        // between vectors), bent so no two read the same noise; vectors
        // sampled every point, a few a hair, and none (amplitude 0).
        let hairs: Vec<Hair> = [16usize, 1, 2, 3, 16, 9, 16, 16, 16, 4, 16]
            .iter()
            .enumerate()
            .map(|(i, &n)| {
                let mut hair = straight(i as u64, n, 1.0 + 0.1 * i as f32);
                for (j, p) in hair.points.iter_mut().enumerate() {
                    *p += Vec3::new(0.3 * i as f32, (j as f32 * 0.7).sin() * 0.1, 0.0);
                }
                hair
            })
            .collect();
        let roots = vec![root(); hairs.len()];
        for (vectors, amplitude) in [(5, 0.1), (0, 0.1), (2, 0.05), (5, 0.0)] {
            let op = Noise::new(
                Map::Constant(amplitude),
                Map::Constant(4.0),
                Ramp::Smooth,
                7,
                vectors,
            );
            let mut together = hairs.clone();
            op.apply_each(
                &mut together,
                &roots,
                &mut NoiseScratch::default(),
                &mut RampTables::default(),
            );
            let (mut scratch, mut ramps) = (NoiseScratch::default(), RampTables::default());
            for (i, (hair, root)) in hairs.iter().zip(&roots).enumerate() {
                let mut alone = hair.clone();
                op.apply(&mut alone, root, &mut scratch, &mut ramps);
                let bits = |h: &Hair| -> Vec<[u32; 3]> {
                    h.points
                        .iter()
                        .map(|p| p.to_array().map(f32::to_bits))
                        .collect()
                };
                assert_eq!(
                    bits(&alone),
                    bits(&together[i]),
                    "vectors {vectors} hair {i}"
                );
            }
            if amplitude == 0.0 {
                assert_eq!(together, hairs, "amplitude 0 moves nothing");
            } else {
                assert_ne!(together[0], hairs[0], "the noise moves hairs");
            }
        }
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
        let ramps = &mut RampTables::default();
        let (mut a, mut b) = (straight(1, 16, 1.0), straight(2, 16, 1.0));
        op.apply(&mut a, &root(), ramps);
        op.apply(&mut b, &root(), ramps);
        assert!((a.points[15] - b.points[15]).length() > 1e-3, "per hair");
        let mut again = straight(1, 16, 1.0);
        op.apply(&mut again, &root(), ramps);
        assert_eq!(again, a, "same id, same frizz");
        let none = Frizz::new(
            Map::Constant(0.05),
            Map::Constant(6.0),
            Map::Constant(0.0),
            Ramp::default(),
            0,
        );
        let mut c = straight(3, 16, 1.0);
        none.apply(&mut c, &root(), ramps);
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
