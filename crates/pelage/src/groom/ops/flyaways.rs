//! `flyaways`: the stray hairs of a real coat (XGen's and Yeti's
//! flyaway modifiers). A share of the hairs (`fraction`, drawn per hair)
//! grows longer than its neighbours and leaves its clump: each is
//! scaled about its root by `length` and pushed sideways, `spread` world
//! units at the tip, in a direction of its own that wanders along the hair
//! (its own noise, `frequency` wiggles root to tip). Put it after `clump`
//! so the strays leave the clumps; the other hairs are untouched.

use super::kind::{OperatorKind, Preparation, SpecReader, default_map};
use super::noise::VectorNoise;
use super::{Hair, RootContext, Scratch, param};
use crate::groom::error::GroomError;
use crate::groom::ramp::Ramp;
use crate::groom::values::MapValue;
use crate::map::Map;
use crate::sample::SampleRng;
use crate::settings::{Bound, Rule};
use glam::Vec3;
use serde::Deserialize;

/// Whether a hair flies away, its push direction and its place in the
/// noise field.
const HAIR_SALT: u64 = 0xF1_7A4A;
/// The noise field the strays wander by.
const FIELD_SALT: u64 = 0xF1_7F1E;

/// `flyaways` as a groom file writes it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct FlyawaysSpec {
    /// How far the tip is pushed off (world units).
    pub spread: MapValue,
    /// Share of the hairs that fly away (0 to 1).
    #[serde(default = "default_fraction")]
    pub fraction: MapValue,
    /// Length factor of a stray (1: as long as the others).
    #[serde(default = "default_length")]
    pub length: MapValue,
    /// Wiggles of a stray's own noise along it.
    #[serde(default = "default_frequency")]
    pub frequency: MapValue,
    /// Root-to-tip profile of the push.
    #[serde(default = "default_ramp")]
    pub ramp: Ramp,
    /// Seed.
    #[serde(default)]
    pub seed: u64,
    /// Where the operator acts: its effect is faded by this map (0: none,
    /// 1: full).
    pub mask: Option<MapValue>,
}

fn default_fraction() -> MapValue {
    default_map(0.02)
}

fn default_length() -> MapValue {
    default_map(1.3)
}

fn default_frequency() -> MapValue {
    default_map(2.0)
}

/// Strays leave the groom late: `t²`.
fn default_ramp() -> Ramp {
    Ramp::Power(2.0)
}

/// `flyaways`: see [`Flyaways`].
#[derive(Debug, Clone)]
pub struct FlyawaysParams {
    /// How far the tip is pushed off (world units).
    pub spread: Map,
    /// Share of the hairs that fly away (0 to 1).
    pub fraction: Map,
    /// Length factor of a stray.
    pub length: Map,
    /// Wiggles of a stray's own noise along it.
    pub frequency: Map,
    /// Root-to-tip profile of the push.
    pub ramp: Ramp,
    /// Seed.
    pub seed: u64,
}

impl FlyawaysParams {
    /// Strays pushed `spread` off at the tip; a groom file's defaults for
    /// the rest (2 % of the hairs, 1.3 times as long, frequency 2, ramp
    /// t², seed 0).
    pub fn new(spread: Map) -> Self {
        Self {
            spread,
            fraction: Map::Constant(0.02),
            length: Map::Constant(1.3),
            frequency: Map::Constant(2.0),
            ramp: default_ramp(),
            seed: 0,
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

impl OperatorKind for Flyaways {
    const NAME: &'static str = "flyaways";
    const SUMMARY: &'static str = "A `fraction` of the hairs lengthened and pushed `spread` off their clump, each its own way.";
    type Spec = FlyawaysSpec;
    type Params = FlyawaysParams;
    const RULES: &'static [Rule] = &[
        Rule::new(
            "fraction",
            Bound::Within(0.0, 1.0),
            "a fraction of the hairs",
        ),
        Rule::new("length", Bound::at_least(0.0), "a factor"),
        Rule::new("frequency", Bound::at_least(0.0), "cycles per hair"),
    ];
    const SALTS: &'static [(&'static str, u64)] = &[("HAIR", HAIR_SALT), ("FIELD", FIELD_SALT)];

    fn mask(spec: &FlyawaysSpec) -> Option<&MapValue> {
        spec.mask.as_ref()
    }

    fn read(s: &FlyawaysSpec, r: &mut SpecReader<'_>) -> Result<FlyawaysParams, GroomError> {
        Ok(FlyawaysParams {
            spread: r.map("spread", &s.spread)?,
            fraction: r.map("fraction", &s.fraction)?,
            length: r.map("length", &s.length)?,
            frequency: r.map("frequency", &s.frequency)?,
            ramp: s.ramp.clone(),
            seed: s.seed,
        })
    }

    fn maps(p: &FlyawaysParams) -> Vec<(&'static str, &Map)> {
        vec![
            ("spread", &p.spread),
            ("fraction", &p.fraction),
            ("length", &p.length),
            ("frequency", &p.frequency),
        ]
    }

    fn maps_mut(p: &mut FlyawaysParams) -> Vec<(&'static str, &mut Map)> {
        vec![
            ("spread", &mut p.spread),
            ("fraction", &mut p.fraction),
            ("length", &mut p.length),
            ("frequency", &mut p.frequency),
        ]
    }

    fn prepare(mut params: FlyawaysParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        params.seed = cx.seed(params.seed);
        Ok(Flyaways {
            field: VectorNoise::new(params.seed ^ FIELD_SALT),
            params,
        })
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        let p = &self.params;
        let Some(mut rng) = self.stray(hair.id, p.fraction.at(&root.site)) else {
            return;
        };
        let Some(&origin) = hair.points.first() else {
            return;
        };
        let length = p.length.at(&root.site).max(0.0);
        let spread = p.spread.at(&root.site);
        let frequency = p.frequency.at(&root.site);
        // The push: a direction of the hair's own, across the skin
        // normal's side of the hair (strays stand off the coat, never into
        // the skin), wandering by the noise along the hair.
        let [a, b] = rng.uniform_f32_pair();
        let phase = Vec3::new(a, b, rng.uniform_f32()) * 256.0;
        let angle = std::f32::consts::TAU * rng.uniform_f32();
        let side = root.normal.any_orthonormal_pair();
        let across = (angle.cos() * side.0 + angle.sin() * side.1 + root.normal).normalize();
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
