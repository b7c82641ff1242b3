//! What `width`, `opacity` and `color` share: a quantity from root to tip
//! with per-hair random variation (Sik §4.2.2: "the user specifies these
//! attributes at hair root and tip and we interpolate them to every hair
//! vertex. Again we add some noise to hair color").

use super::settings::operator_settings;
use super::{RampTables, RootContext, jittered};
use crate::groom::ramp::Ramp;
use crate::sample::SampleRng;

operator_settings! {
    /// A quantity from root to tip as a groom file writes it: `width` and
    /// `opacity` (and `[finish.width]`, `[finish.opacity]`); see
    /// [`crate::groom::ops::Width`].
    pub spec RootToTipSpec;
    /// A root-to-tip quantity: `root + ramp(t) · (tip − root)`, times
    /// `1 ± jitter` per hair.
    params RootToTip {
        required {
            /// Value at the root (a width in world units, or an opacity).
            root: map;
            /// Value at the tip.
            tip: map;
        }
        optional {
            /// Profile from root to tip.
            ramp: value(Ramp) = Ramp::default();
            /// Per-hair random variation, a fraction.
            jitter: map = 0.0;
            /// Seed of the variation.
            seed: value(u64) = 0;
        }
    }
}

/// Evaluates a [`RootToTip`] along a hair into `out` (resized to the
/// hair's point count).
pub(super) fn root_to_tip(
    spec: &RootToTip,
    salt: u64,
    hair_id: u64,
    root: &RootContext,
    out: &mut Vec<f32>,
    n: usize,
    ramps: &mut RampTables,
) {
    let ramp = ramps.along(&spec.ramp, n);
    let factor = varied(spec.jitter.at(&root.site), spec.seed ^ salt, hair_id);
    let (a, b) = (spec.root.at(&root.site), spec.tip.at(&root.site));
    out.clear();
    out.extend(ramp.iter().map(|&r| factor * (a + r * (b - a))));
}

/// The per-hair factor `1 ± jitter`; the random stream is only set up
/// when there is jitter (most grooms have none, and every hair pays for
/// the hashing).
pub(super) fn varied(jitter: f32, seed: u64, hair_id: u64) -> f32 {
    if jitter == 0.0 {
        1.0
    } else {
        jittered(jitter, &mut SampleRng::new(seed, hair_id))
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::map::Map;

    /// A root-to-tip quantity of constants.
    pub fn spec(root: f32, tip: f32, jitter: f32) -> RootToTip {
        RootToTip {
            root: Map::Constant(root),
            tip: Map::Constant(tip),
            ramp: Ramp::default(),
            jitter: Map::Constant(jitter),
            seed: 0,
        }
    }
}
