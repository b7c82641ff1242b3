//! `length`: hairs scaled about their root, with per-hair variation (the
//! length control of every groom tool).

use super::kind::{OperatorKind, Preparation, SpecReader, default_map};
use super::{Hair, RootContext, Scratch, jittered};
use crate::groom::error::GroomError;
use crate::groom::values::MapValue;
use crate::map::Map;
use crate::sample::SampleRng;
use crate::settings::{Bound, Rule};
use serde::Deserialize;

/// The per-hair jitter.
const JITTER_SALT: u64 = 0x1E_4674;

/// `length` as a groom file writes it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LengthSpec {
    /// Length factor.
    pub scale: MapValue,
    /// Per-hair random variation, a fraction (0.2 = ±20 %).
    #[serde(default = "no_jitter")]
    pub jitter: MapValue,
    /// Seed of the variation.
    #[serde(default)]
    pub seed: u64,
    /// Where the operator acts: its effect is faded by this map (0: none,
    /// 1: full).
    pub mask: Option<MapValue>,
}

fn no_jitter() -> MapValue {
    default_map(0.0)
}

/// `length`: see [`Length`].
#[derive(Debug, Clone)]
pub struct LengthParams {
    /// Length factor.
    pub scale: Map,
    /// Per-hair random variation, a fraction (0.2 = ±20 %).
    pub jitter: Map,
    /// Seed of the variation.
    pub seed: u64,
}

impl LengthParams {
    /// Lengths times `scale`, no jitter, seed 0.
    pub fn new(scale: Map) -> Self {
        Self {
            scale,
            jitter: Map::Constant(0.0),
            seed: 0,
        }
    }
}

/// `length`: points scale about the root by `scale · (1 ± jitter)`,
/// the variation drawn per hair.
#[derive(Debug, Clone)]
pub struct Length {
    scale: Map,
    jitter: Map,
    seed: u64,
}

impl Length {
    /// A length operator.
    pub fn new(scale: Map, jitter: Map, seed: u64) -> Self {
        Self {
            scale,
            jitter,
            seed,
        }
    }

    /// Scales one hair about its root.
    pub(super) fn lengthen(&self, hair: &mut Hair, root: &RootContext) {
        let mut rng = SampleRng::new(self.seed ^ JITTER_SALT, hair.id);
        let factor =
            (self.scale.at(&root.site) * jittered(self.jitter.at(&root.site), &mut rng)).max(0.0);
        let Some(&origin) = hair.points.first() else {
            return;
        };
        for p in &mut hair.points[1..] {
            *p = origin + (*p - origin) * factor;
        }
    }
}

impl OperatorKind for Length {
    const NAME: &'static str = "length";
    const SUMMARY: &'static str =
        "Scales hair length by `scale`, ± `jitter` (a fraction) per hair.";
    type Spec = LengthSpec;
    type Params = LengthParams;
    const RULES: &'static [Rule] = &[Rule::new("scale", Bound::at_least(0.0), "a factor")];
    const SALTS: &'static [(&'static str, u64)] = &[("JITTER", JITTER_SALT)];

    fn mask(spec: &LengthSpec) -> Option<&MapValue> {
        spec.mask.as_ref()
    }

    fn read(s: &LengthSpec, r: &mut SpecReader<'_>) -> Result<LengthParams, GroomError> {
        Ok(LengthParams {
            scale: r.map("scale", &s.scale)?,
            jitter: r.map("jitter", &s.jitter)?,
            seed: s.seed,
        })
    }

    fn maps(p: &LengthParams) -> Vec<(&'static str, &Map)> {
        vec![("scale", &p.scale), ("jitter", &p.jitter)]
    }

    fn maps_mut(p: &mut LengthParams) -> Vec<(&'static str, &mut Map)> {
        vec![("scale", &mut p.scale), ("jitter", &mut p.jitter)]
    }

    fn prepare(p: LengthParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        Ok(Length::new(p.scale, p.jitter, cx.seed(p.seed)))
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, _: &mut Scratch) {
        self.lengthen(hair, root);
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{root, straight};
    use super::*;
    use glam::Vec3;

    #[test]
    fn length_scales_about_the_root_with_jitter_per_hair() {
        let mut hair = straight(1, 8, 1.0);
        Length::new(Map::Constant(2.0), Map::Constant(0.0), 0).lengthen(&mut hair, &root());
        assert!((hair.points[7] - Vec3::Z * 2.0).length() < 1e-6);
        assert_eq!(hair.points[0], Vec3::ZERO);
        let lengths: Vec<f32> = (0..200)
            .map(|id| {
                let mut h = straight(id, 8, 1.0);
                Length::new(Map::Constant(1.0), Map::Constant(0.2), 0).lengthen(&mut h, &root());
                h.points[7].z
            })
            .collect();
        assert!(lengths.iter().all(|l| (0.8..=1.2).contains(l)));
        let spread = lengths.iter().cloned().fold(f32::MIN, f32::max)
            - lengths.iter().cloned().fold(f32::MAX, f32::min);
        assert!(spread > 0.3, "jitter varies per hair: {spread}");
    }
}
