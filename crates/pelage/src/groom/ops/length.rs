//! `length`: hairs scaled about their root, with per-hair variation (the
//! length control of every groom tool).

use super::kind::{OperatorKind, Preparation};
use super::settings::{Start, operator_settings};
use super::{Hair, RootContext, Scratch, jittered};
use crate::groom::error::GroomError;
use crate::map::Map;
use crate::sample::SampleRng;
use crate::settings::Bound;

/// The per-hair jitter.
const JITTER_SALT: u64 = 0x1E_4674;

operator_settings! {
    /// `length` as a groom file writes it.
    pub(crate) spec LengthSpec;
    /// `length`: see [`Length`].
    params LengthParams {
        required {
            /// Length factor.
            scale: map, start Start::Number(1.0), rule Bound::at_least(0.0), "a factor";
        }
        optional {
            /// Per-hair random variation, a fraction (0.2 = ±20 %).
            jitter: map = 0.0;
            /// Seed of the variation.
            seed: value(u64) = 0;
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
    /// Hair `id`'s factor at `root`: the scale map's value, jittered.
    pub(crate) fn factor(&self, id: u64, root: &RootContext) -> f32 {
        let mut rng = SampleRng::new(self.seed ^ JITTER_SALT, id);
        (self.scale.at(&root.site) * jittered(self.jitter.at(&root.site), &mut rng)).max(0.0)
    }

    pub(super) fn lengthen(&self, hair: &mut Hair, root: &RootContext) {
        let factor = self.factor(hair.id, root);
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
    type Params = LengthParams;
    const SALTS: &'static [(&'static str, u64)] = &[("JITTER", JITTER_SALT)];

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
