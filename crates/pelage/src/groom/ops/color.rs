//! `color`: linear RGB from root to tip, each channel a map, with
//! per-hair brightness variation (Sik §4.2.2: "Again we add some noise to
//! hair color").

use super::kind::{OperatorKind, Preparation};
use super::root_to_tip::varied;
use super::settings::{Start, operator_settings};
use super::{Hair, RootContext, Scratch};
use crate::groom::error::GroomError;
use crate::groom::ramp::Ramp;
use crate::map::Map;
use glam::Vec3;

/// The per-hair brightness jitter.
const JITTER_SALT: u64 = 0xC0_10E;

operator_settings! {
    /// `color` (and `[finish.color]`) as a groom file writes it: see
    /// [`Color`].
    pub spec ColorSpec;
    /// `color`: linear RGB from root to tip, each channel a map, brightness
    /// varied per hair by `± jitter`; never negative.
    params Color {
        required {
            /// Linear RGB at the root, each channel a map.
            root: rgb, start Start::Rgb([0.1, 0.07, 0.05]);
            /// Linear RGB at the tip.
            tip: rgb, start Start::Rgb([0.5, 0.4, 0.3]);
        }
        optional {
            /// Profile from root to tip.
            ramp: value(Ramp) = Ramp::default();
            /// Per-hair random brightness variation, a fraction.
            jitter: map = 0.0;
            /// Seed of the variation.
            seed: value(u64) = 0;
        }
    }
}

impl OperatorKind for Color {
    const NAME: &'static str = "color";
    const SUMMARY: &'static str = "Colours (three maps each, linear RGB) from `root` to `tip`.";
    type Params = Color;
    const SALTS: &'static [(&'static str, u64)] = &[("JITTER", JITTER_SALT)];
    const ADDS_COLORS: bool = true;

    fn prepare(p: Color, _: &Preparation<'_>) -> Result<Self, GroomError> {
        Ok(p)
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        let factor = varied(self.jitter.at(&root.site), self.seed ^ JITTER_SALT, hair.id);
        let rgb = |m: &[Map; 3]| Vec3::from(m.each_ref().map(|c| c.at(&root.site)));
        let (a, b) = (rgb(&self.root), rgb(&self.tip));
        let ramp = scratch.ramps.along(&self.ramp, hair.points.len());
        hair.colors.clear();
        hair.colors.extend(
            ramp.iter()
                .map(|&r| (factor * a.lerp(b, r)).max(Vec3::ZERO)),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{root, straight};
    use super::*;

    #[test]
    fn colour_blends_each_channel() {
        let mut hair = straight(1, 3, 1.0);
        let c = |r, g, b| [Map::Constant(r), Map::Constant(g), Map::Constant(b)];
        Color {
            root: c(0.2, 0.1, 0.0),
            tip: c(1.0, 0.9, 0.8),
            ramp: Ramp::default(),
            jitter: Map::Constant(0.0),
            seed: 0,
        }
        .apply_to_hair(&mut hair, &root(), &mut Scratch::default());
        assert_eq!(hair.colors.len(), 3);
        assert!((hair.colors[1] - Vec3::new(0.6, 0.5, 0.4)).length() < 1e-6);
    }
}
