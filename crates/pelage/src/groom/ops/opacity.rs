//! `opacity`: hair opacities from root to tip, as `width` does widths.

use super::kind::{OperatorKind, Preparation};
use super::root_to_tip::root_to_tip;
use super::settings::Start;
use super::{Hair, RootContext, RootToTip, Scratch};
use crate::groom::error::GroomError;
use crate::settings::{Bound, Rule};

/// The per-hair jitter.
const JITTER_SALT: u64 = 0x00BA_C17E;

/// `opacity`: `(root + ramp(t)(tip − root)) · (1 ± jitter)` per hair, clamped to [0, 1].
#[derive(Debug, Clone)]
pub struct Opacity(pub RootToTip);

impl OperatorKind for Opacity {
    const NAME: &'static str = "opacity";
    const SUMMARY: &'static str = "Opacities from `root` to `tip`.";
    type Params = RootToTip;
    const RULES: &'static [Rule] = &[
        Rule::new("root", Bound::Within(0.0, 1.0), "an opacity"),
        Rule::new("tip", Bound::Within(0.0, 1.0), "an opacity"),
    ];
    const STARTS: &'static [(&'static str, Start)] =
        &[("root", Start::Number(1.0)), ("tip", Start::Number(0.5))];
    const SALTS: &'static [(&'static str, u64)] = &[("JITTER", JITTER_SALT)];
    const ADDS_OPACITIES: bool = true;

    fn prepare(p: RootToTip, _: &Preparation<'_>) -> Result<Self, GroomError> {
        Ok(Opacity(p))
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        let n = hair.points.len();
        root_to_tip(
            &self.0,
            JITTER_SALT,
            hair.id,
            root,
            &mut hair.opacities,
            n,
            &mut scratch.ramps,
        );
        hair.opacities
            .iter_mut()
            .for_each(|o| *o = o.clamp(0.0, 1.0));
    }
}

#[cfg(test)]
mod tests {
    use super::super::root_to_tip::tests::spec;
    use super::super::test_hairs::{root, straight};
    use super::*;

    #[test]
    fn jitter_varies_per_hair_within_bounds() {
        let roots: Vec<f32> = (0..100)
            .map(|id| {
                let mut h = straight(id, 5, 1.0);
                Opacity(spec(0.5, 0.5, 0.5)).apply_to_hair(
                    &mut h,
                    &root(),
                    &mut Scratch::default(),
                );
                h.opacities[0]
            })
            .collect();
        assert!(roots.iter().all(|o| (0.25..=0.75).contains(o)));
        assert!(roots.iter().any(|o| *o < 0.4) && roots.iter().any(|o| *o > 0.6));
    }
}
