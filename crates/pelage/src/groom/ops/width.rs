//! `width`: hair widths from root to tip (Sik §4.2.2).

use super::kind::{OperatorKind, Preparation};
use super::root_to_tip::root_to_tip;
use super::settings::Start;
use super::{Hair, RootContext, RootToTip, Scratch};
use crate::groom::error::GroomError;
use crate::settings::{Bound, Rule};

/// The per-hair jitter.
const JITTER_SALT: u64 = 0x3D_7714;

/// `width`: `(root + ramp(t)(tip − root)) · (1 ± jitter)` per hair; widths never go below zero.
#[derive(Debug, Clone)]
pub struct Width(pub RootToTip);

impl OperatorKind for Width {
    const NAME: &'static str = "width";
    const SUMMARY: &'static str = "Widths (diameters) from `root` to `tip`.";
    type Params = RootToTip;
    const RULES: &'static [Rule] = &[
        Rule::new("root", Bound::at_least(0.0), "a width"),
        Rule::new("tip", Bound::at_least(0.0), "a width"),
    ];
    const STARTS: &'static [(&'static str, Start)] = &[
        ("root", Start::Length(0.002)),
        ("tip", Start::Length(0.0002)),
    ];
    const SALTS: &'static [(&'static str, u64)] = &[("JITTER", JITTER_SALT)];

    fn prepare(p: RootToTip, _: &Preparation<'_>) -> Result<Self, GroomError> {
        Ok(Width(p))
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        let n = hair.points.len();
        root_to_tip(
            &self.0,
            JITTER_SALT,
            hair.id,
            root,
            &mut hair.widths,
            n,
            &mut scratch.ramps,
        );
        hair.widths.iter_mut().for_each(|w| *w = w.max(0.0));
    }
}

#[cfg(test)]
mod tests {
    use super::super::root_to_tip::tests::spec;
    use super::super::test_hairs::{root, straight};
    use super::*;

    #[test]
    fn width_runs_root_to_tip() {
        let mut hair = straight(1, 5, 1.0);
        Width(spec(0.01, 0.002, 0.0)).apply_to_hair(&mut hair, &root(), &mut Scratch::default());
        assert_eq!(hair.widths[0], 0.01);
        assert!((hair.widths[4] - 0.002).abs() < 1e-9);
        assert!((hair.widths[2] - 0.006).abs() < 1e-9);
    }
}
