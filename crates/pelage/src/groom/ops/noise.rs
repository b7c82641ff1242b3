//! `noise` (Sik §4.2.2, Fig. 15: "random vectors generated from Perlin
//! noise added to the hair curve's vertices"): every hair displaced by one
//! smooth vector field in space, so neighbouring hairs wave alike.

use super::kind::{OperatorKind, Preparation};
use super::settings::{Start, operator_settings};
use super::{Hair, RampTables, Resampling, RootContext, Scratch};
use crate::groom::error::GroomError;
use crate::groom::ramp::Ramp;
use crate::limits::MAX_CURVE_POINTS;
use crate::map::{Map, NoiseMap};
use crate::settings::Bound;
use glam::Vec3;

operator_settings! {
    /// `noise` as a groom file writes it.
    pub(crate) spec NoiseSpec;
    /// `noise`: see [`Noise`].
    params NoiseParams {
        required {
            /// Largest displacement (world units).
            amplitude: map, start Start::Length(0.004);
        }
        optional {
            /// Noise cycles per world unit.
            frequency: map = 10.0, rule Bound::at_least(0.0), "cycles per unit";
            /// Root-to-tip profile of the amplitude.
            ramp: value(Ramp) = Ramp::default();
            /// Noise vectors sampled along each hair, interpolated between
            /// (0: one at every point).
            vectors: value(usize) = 5,
                rule Bound::Within(0.0, MAX_CURVE_POINTS as f64), "noise vectors per hair";
            /// Seed of the noise field.
            seed: value(u64) = 0;
        }
    }
}

impl OperatorKind for Noise {
    const NAME: &'static str = "noise";
    const SUMMARY: &'static str =
        "Perlin displacement of every point, `amplitude` world units at most.";
    type Params = NoiseParams;

    fn prepare(p: NoiseParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        Ok(Noise::new(
            p.amplitude,
            p.frequency,
            p.ramp,
            cx.seed(p.seed),
            p.vectors,
        ))
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        self.displace(hair, root, &mut scratch.noise, &mut scratch.ramps);
    }

    fn apply_each(&self, hairs: &mut [Hair], roots: &[RootContext], scratch: &mut Scratch) {
        self.displace_each(hairs, roots, &mut scratch.noise, &mut scratch.ramps);
    }
}

/// A smooth random vector field in space (three Perlin noises sharing
/// their lattice, see [`NoiseMap::perlin3_vector`]).
#[derive(Debug, Clone)]
pub(super) struct VectorNoise(NoiseMap);

impl VectorNoise {
    pub(super) fn new(seed: u64) -> Self {
        Self(NoiseMap::new(1.0, 1, seed, 0.0, 1.0))
    }

    /// Each component in about [−1, 1]. Perlin noise is zero on its
    /// lattice; the offset keeps round coordinates (a hair along an axis)
    /// off it.
    #[inline]
    pub(super) fn at(&self, p: Vec3) -> Vec3 {
        self.0.perlin3_vector(p + Self::OFF_LATTICE)
    }

    pub(crate) const OFF_LATTICE: Vec3 = Vec3::new(0.371, 0.713, 0.137);

    /// The field's permutation table.
    pub(crate) fn permutation(&self) -> &[u8; 512] {
        self.0.permutation_table()
    }

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
    pub(super) fn displace(
        &self,
        hair: &mut Hair,
        root: &RootContext,
        scratch: &mut NoiseScratch,
        ramps: &mut RampTables,
    ) {
        self.displace_each(
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
    pub(super) fn displace_each(
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
    /// The amplitude and frequency at `root`.
    pub(crate) fn strength(&self, root: &RootContext) -> (f32, f32) {
        (self.amplitude.at(&root.site), self.frequency.at(&root.site))
    }

    /// The field's permutation table.
    pub(crate) fn permutation(&self) -> &[u8; 512] {
        self.field.permutation()
    }

    /// The displacement's profile root to tip.
    pub(crate) fn ramp(&self) -> &Ramp {
        &self.ramp
    }

    /// Noise vectors along an `n`-point hair, and the resamplings from
    /// its points to them and back (empty when there is a vector a point).
    pub(crate) fn vector_spacing(&self, n: usize) -> (usize, Resampling, Resampling) {
        let m = self.vectors_along(n);
        (m, Resampling::new(n, m), Resampling::new(m, n))
    }

    pub(crate) fn vectors_along(&self, n: usize) -> usize {
        if self.vectors == 0 || self.vectors >= n {
            n
        } else {
            self.vectors.clamp(2, MAX_VECTORS)
        }
    }
}

/// Buffers of the noise operator when it displaces many hairs at once, reused.
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
        op.displace(
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
        op.displace(
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
            op.displace_each(
                &mut together,
                &roots,
                &mut NoiseScratch::default(),
                &mut RampTables::default(),
            );
            let (mut scratch, mut ramps) = (NoiseScratch::default(), RampTables::default());
            for (i, (hair, root)) in hairs.iter().zip(&roots).enumerate() {
                let mut alone = hair.clone();
                op.displace(&mut alone, root, &mut scratch, &mut ramps);
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
}
