//! What `width`, `opacity` and `color` share: a quantity from root to tip
//! with per-hair random variation (Sik §4.2.2: "the user specifies these
//! attributes at hair root and tip and we interpolate them to every hair
//! vertex. Again we add some noise to hair color").

use super::{RampTables, RootContext, RootToTip, jittered};
use crate::map::Map;
use crate::sample::SampleRng;

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

/// The maps of a root-to-tip setting, by name.
pub(crate) fn root_to_tip_maps(s: &RootToTip) -> Vec<(&'static str, &Map)> {
    vec![("root", &s.root), ("tip", &s.tip), ("jitter", &s.jitter)]
}

/// The maps of a root-to-tip setting, to change.
pub(crate) fn root_to_tip_maps_mut(s: &mut RootToTip) -> Vec<(&'static str, &mut Map)> {
    vec![
        ("root", &mut s.root),
        ("tip", &mut s.tip),
        ("jitter", &mut s.jitter),
    ]
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::groom::ramp::Ramp;

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
