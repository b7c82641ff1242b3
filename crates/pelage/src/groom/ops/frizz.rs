//! `frizz`: a share of the hairs each wiggle on their own, at high
//! frequency (the per-hair noise of XGen's and Houdini's frizz), unlike
//! `noise`, whose field neighbouring hairs share.

use super::kind::{OperatorKind, Preparation};
use super::noise::VectorNoise;
use super::settings::{Start, operator_settings};
use super::{Hair, RootContext, Scratch, param};
use crate::groom::error::GroomError;
use crate::groom::ramp::Ramp;
use crate::map::Map;
use crate::sample::SampleRng;
use crate::settings::Bound;
use glam::Vec3;

/// The noise field frizz follows.
const FIELD_SALT: u64 = 0xF122;
/// Whether a hair frizzes, and its offset into the field.
const HAIR_SALT: u64 = 0xF122_F122;

operator_settings! {
    /// `frizz` as a groom file writes it.
    pub(crate) spec FrizzSpec;
    /// `frizz`: see [`Frizz`].
    params FrizzParams {
        required {
            /// Largest displacement (world units).
            amplitude: map, start Start::Length(0.002);
        }
        optional {
            /// Wiggles along one hair.
            frequency: map = 6.0, rule Bound::at_least(0.0), "cycles per unit";
            /// Share of hairs that frizz (0 to 1).
            fraction: map = 1.0, rule Bound::Within(0.0, 1.0), "a fraction of the hairs";
            /// Root-to-tip profile.
            ramp: value(Ramp) = Ramp::default();
            /// Seed.
            seed: value(u64) = 0;
        }
    }
}

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
            field: VectorNoise::new(seed ^ FIELD_SALT),
            amplitude,
            frequency,
            fraction,
            ramp,
            seed,
        }
    }
}

impl Frizz {
    /// Hair `id`'s amplitude, frequency and place in the noise field
    /// when it is among the frizzed `fraction`.
    pub(crate) fn frizzed(&self, id: u64, root: &RootContext) -> Option<(f32, f32, Vec3)> {
        let mut rng = SampleRng::new(self.seed ^ HAIR_SALT, id);
        if rng.uniform_f32() >= self.fraction.at(&root.site) {
            return None;
        }
        let amplitude = self.amplitude.at(&root.site);
        let frequency = self.frequency.at(&root.site);
        let [a, b] = rng.uniform_f32_pair();
        Some((
            amplitude,
            frequency,
            Vec3::new(a, b, rng.uniform_f32()) * 256.0,
        ))
    }

    /// The noise field's permutation table.
    pub(crate) fn permutation(&self) -> &[u8; 512] {
        self.field.permutation()
    }

    /// The displacement's profile root to tip.
    pub(crate) fn ramp(&self) -> &Ramp {
        &self.ramp
    }
}

impl OperatorKind for Frizz {
    const NAME: &'static str = "frizz";
    const SUMMARY: &'static str =
        "Per-hair random high-frequency displacement on a `fraction` of hairs.";
    type Params = FrizzParams;
    const SALTS: &'static [(&'static str, u64)] = &[("FIELD", FIELD_SALT), ("HAIR", HAIR_SALT)];

    fn prepare(p: FrizzParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        Ok(Frizz::new(
            p.amplitude,
            p.frequency,
            p.fraction,
            p.ramp,
            cx.seed(p.seed),
        ))
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        let Some((amplitude, frequency, phase)) = self.frizzed(hair.id, root) else {
            return;
        };
        let n = hair.points.len();
        let ramp = scratch.ramps.along(&self.ramp, n);
        for (j, (p, profile)) in hair.points.iter_mut().zip(ramp).enumerate() {
            let t = param(j, n);
            *p += amplitude * profile * self.field.at(phase + Vec3::X * (frequency * t));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{root, straight};
    use super::*;

    #[test]
    fn frizz_differs_per_hair_and_respects_fraction() {
        let op = Frizz::new(
            Map::Constant(0.05),
            Map::Constant(6.0),
            Map::Constant(1.0),
            Ramp::default(),
            0,
        );
        let scratch = &mut Scratch::default();
        let (mut a, mut b) = (straight(1, 16, 1.0), straight(2, 16, 1.0));
        op.apply_to_hair(&mut a, &root(), scratch);
        op.apply_to_hair(&mut b, &root(), scratch);
        assert!((a.points[15] - b.points[15]).length() > 1e-3, "per hair");
        let mut again = straight(1, 16, 1.0);
        op.apply_to_hair(&mut again, &root(), scratch);
        assert_eq!(again, a, "same id, same frizz");
        let none = Frizz::new(
            Map::Constant(0.05),
            Map::Constant(6.0),
            Map::Constant(0.0),
            Ramp::default(),
            0,
        );
        let mut c = straight(3, 16, 1.0);
        none.apply_to_hair(&mut c, &root(), scratch);
        assert_eq!(c, straight(3, 16, 1.0), "fraction 0 frizzes nothing");
    }
}
