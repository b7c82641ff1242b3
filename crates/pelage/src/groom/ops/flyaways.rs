//! `flyaways`: the stray hairs of a real coat (XGen's and Yeti's
//! flyaway modifiers). A share of the hairs (`fraction`, drawn per hair)
//! grows longer than its neighbours and leaves its clump: each is
//! scaled about its root by `length` and pushed sideways, `spread` world
//! units at the tip, in a direction of its own that wanders along the hair
//! (its own noise, `frequency` wiggles root to tip). Put it after `clump`
//! so the strays leave the clumps; the other hairs are untouched.

use super::kind::{OperatorKind, Preparation};
use super::noise::VectorNoise;
use super::settings::{Start, operator_settings};
use super::{Hair, RootContext, Scratch, param};
use crate::groom::error::GroomError;
use crate::groom::ramp::Ramp;
use crate::sample::SampleRng;
use crate::settings::Bound;
use glam::Vec3;

/// Whether a hair flies away, its push direction and its place in the
/// noise field.
const HAIR_SALT: u64 = 0xF1_7A4A;
/// The noise field the strays wander by.
const FIELD_SALT: u64 = 0xF1_7F1E;

operator_settings! {
    /// `flyaways` as a groom file writes it.
    pub(crate) spec FlyawaysSpec;
    /// `flyaways`: see [`Flyaways`].
    params FlyawaysParams {
        required {
            /// How far the tip is pushed off (world units).
            spread: map, start Start::Length(0.01);
        }
        optional {
            /// Share of the hairs that fly away (0 to 1).
            fraction: map = 0.02, rule Bound::Within(0.0, 1.0), "a fraction of the hairs";
            /// Length factor of a stray (1: as long as the others).
            length: map = 1.3, rule Bound::at_least(0.0), "a factor";
            /// Wiggles of a stray's own noise along it.
            frequency: map = 2.0, rule Bound::at_least(0.0), "cycles per hair";
            /// Root-to-tip profile of the push (strays leave the groom
            /// late: `t²`).
            ramp: value(Ramp) = Ramp::Power(2.0);
            /// Seed.
            seed: value(u64) = 0;
        }
    }
}

/// `flyaways`, prepared: see the module docs.
#[derive(Debug, Clone)]
pub struct Flyaways {
    params: FlyawaysParams,
    field: VectorNoise,
}

impl Flyaways {
    /// Whether hair `id` flies away where the fraction is `fraction`, and
    /// its random stream for the rest.
    fn stray(&self, id: u64, fraction: f32) -> Option<SampleRng> {
        let mut rng = SampleRng::new(self.params.seed ^ HAIR_SALT, id);
        (rng.uniform_f32() < fraction).then_some(rng)
    }
}

/// How one stray hair flies away.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Stray {
    /// Its length's factor.
    pub(crate) length: f32,
    /// How far it is pushed at the tip.
    pub(crate) spread: f32,
    /// The wander's cycles along the hair.
    pub(crate) frequency: f32,
    /// Its place in the noise field.
    pub(crate) phase: Vec3,
    /// The push's direction.
    pub(crate) across: Vec3,
}

impl Flyaways {
    /// How hair `id` flies away, when it is among the strays.
    pub(crate) fn strayed(&self, id: u64, root: &RootContext) -> Option<Stray> {
        let p = &self.params;
        let mut rng = self.stray(id, p.fraction.at(&root.site))?;
        // The push: a direction of the hair's own, across the skin
        // normal's side of the hair (strays stand off the coat, never into
        // the skin), wandering by the noise along the hair.
        let [a, b] = rng.uniform_f32_pair();
        let phase = Vec3::new(a, b, rng.uniform_f32()) * 256.0;
        let angle = std::f32::consts::TAU * rng.uniform_f32();
        let side = root.normal.any_orthonormal_pair();
        Some(Stray {
            length: p.length.at(&root.site).max(0.0),
            spread: p.spread.at(&root.site),
            frequency: p.frequency.at(&root.site),
            phase,
            across: (angle.cos() * side.0 + angle.sin() * side.1 + root.normal).normalize(),
        })
    }

    /// The wander's permutation table.
    pub(crate) fn permutation(&self) -> &[u8; 512] {
        self.field.permutation()
    }

    /// The push's profile root to tip.
    pub(crate) fn ramp(&self) -> &Ramp {
        &self.params.ramp
    }
}

impl OperatorKind for Flyaways {
    const NAME: &'static str = "flyaways";
    const SUMMARY: &'static str = "A `fraction` of the hairs lengthened and pushed `spread` off their clump, each its own way.";
    type Params = FlyawaysParams;
    const SALTS: &'static [(&'static str, u64)] = &[("HAIR", HAIR_SALT), ("FIELD", FIELD_SALT)];

    fn prepare(mut params: FlyawaysParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        params.seed = cx.seed(params.seed);
        Ok(Flyaways {
            field: VectorNoise::new(params.seed ^ FIELD_SALT),
            params,
        })
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        let p = &self.params;
        let Some(&origin) = hair.points.first() else {
            return;
        };
        let Some(Stray {
            length,
            spread,
            frequency,
            phase,
            across,
        }) = self.strayed(hair.id, root)
        else {
            return;
        };
        let n = hair.points.len();
        let ramp = scratch.ramps.along(&p.ramp, n);
        for (j, (point, profile)) in hair.points.iter_mut().zip(ramp).enumerate() {
            let t = param(j, n);
            let wander = self.field.at(phase + Vec3::X * (frequency * t));
            *point =
                origin + (*point - origin) * length + spread * profile * (across + 0.5 * wander);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{batch, root, straight};
    use super::super::{Masked, Operator};
    use super::*;
    use crate::map::Map;

    fn flyaways(fraction: f32) -> Flyaways {
        let params = FlyawaysParams {
            fraction: Map::Constant(fraction),
            ..FlyawaysParams::new(Map::Constant(0.1))
        };
        Flyaways {
            field: VectorNoise::new(params.seed ^ FIELD_SALT),
            params,
        }
    }

    #[test]
    fn only_the_fraction_flies_and_strays_are_longer_and_off_their_path() {
        let op = flyaways(0.1);
        let hairs = 4000;
        let mut strays = 0;
        for id in 0..hairs {
            let mut hair = straight(id, 8, 1.0);
            op.apply_to_hair(&mut hair, &root(), &mut Scratch::default());
            if hair == straight(id, 8, 1.0) {
                continue;
            }
            strays += 1;
            assert_eq!(hair.points[0], Vec3::ZERO, "the root stays");
            assert!(hair.points[7].z > 1.2, "lengthened: {}", hair.points[7]);
            let off = hair.points[7].truncate().length();
            assert!(off > 0.02 && off < 0.2, "pushed off, {off}");
        }
        // Binomial(4000, 0.1): mean 400, σ ≈ 19; ±5σ.
        assert!((305..=495).contains(&strays), "{strays} strays");
        let none = flyaways(0.0);
        let mut hair = straight(3, 8, 1.0);
        none.apply_to_hair(&mut hair, &root(), &mut Scratch::default());
        assert_eq!(hair, straight(3, 8, 1.0), "fraction 0: no strays");
    }

    #[test]
    fn a_mask_of_zero_keeps_every_hair() {
        let op = Masked::new(Operator::Flyaways(flyaways(1.0)), Map::Constant(0.0));
        for id in 0..100 {
            let mut b = batch(straight(id, 8, 1.0));
            op.apply(&mut b, &root(), &mut Scratch::default());
            assert_eq!(b.hairs()[0], straight(id, 8, 1.0));
        }
    }
}
