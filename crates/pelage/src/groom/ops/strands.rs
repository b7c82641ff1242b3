//! `strands` (Sik §4.2.2, Fig. 16): each hair becomes a strand of `count`
//! hairs around it: "we use the just generated hair as a basic hair around
//! which all hair from this strand is generated … parameters control the
//! spread of hair roots and tips from the basic hair, twisting of hair
//! around the basic hair".

use super::kind::{OperatorKind, Preparation};
use super::settings::{Start, operator_settings};
use super::{HairBatch, RootContext, Scratch};
use crate::groom::error::{GroomError, GroomErrorKind};
use crate::limits::MAX_STRANDS;
use crate::map::Map;
use crate::sample::SampleRng;
use crate::settings::Bound;
use std::f32::consts::TAU;

/// Where each strand hair sits around its base hair.
const SPREAD_SALT: u64 = 0x57_2A4D;

operator_settings! {
    /// `strands` as a groom file writes it.
    pub(crate) spec StrandsSpec;
    /// `strands`: see [`Strands`].
    params StrandsParams {
        required {
            /// Hairs per strand.
            count: count(u32), start Start::Number(3.0),
                rule Bound::Within(1.0, MAX_STRANDS as f64), "hairs per strand";
            /// Spread at the tip (world units).
            tip_spread: map, start Start::Length(0.002);
        }
        optional {
            /// Spread around the base hair at the root (world units).
            root_spread: map = 0.0;
            /// Turns of the strand's hairs around the base hair, root to
            /// tip.
            twist: map = 0.0;
            /// Seed.
            seed: value(u64) = 0;
        }
    }
}

/// `strands`: hair `k` of the strand of base hair `b` has id
/// `b.id · count + k` (a hair a mask of 0 leaves whole: `b.id · count`)
/// and points `b(t) + s(t) · ρ · (cos θ(t) r + sin θ(t) B)`,
/// where `s(t)` runs from `root_spread` to `tip_spread`, `ρ = √ξ` and
/// `θ(t) = 2π(ξ' + twist · t)` (a uniform point of the unit disc, turned
/// `twist` times along the hair), `r, B` the base hair's
/// rotation-minimizing frame. The base hair itself is replaced by its
/// strand; widths, colours and opacities are inherited.
#[derive(Debug, Clone)]
pub struct Strands {
    count: u32,
    root_spread: Map,
    tip_spread: Map,
    twist: Map,
    seed: u64,
}

impl Strands {
    /// A strands operator (`count` at least 1).
    pub fn new(count: u32, root_spread: Map, tip_spread: Map, twist: Map, seed: u64) -> Self {
        Self {
            count: count.max(1),
            root_spread,
            tip_spread,
            twist,
            seed,
        }
    }

    /// Replaces every hair of `batch` by its strand.
    /// Hairs a strand.
    pub(crate) fn count(&self) -> u32 {
        self.count
    }

    /// The id of hair `k` of the strand around the hair `base_id`.
    pub(crate) fn strand_id(&self, base_id: u64, k: u64) -> u64 {
        base_id.wrapping_mul(u64::from(self.count)).wrapping_add(k)
    }

    /// Where strand hair `id` sits around its base hair: its share of the
    /// spread (`√ξ`, even over the disc) and its angle (turns).
    pub(crate) fn place(&self, id: u64) -> (f32, f32) {
        let [a, b] = SampleRng::new(self.seed ^ SPREAD_SALT, id).uniform_f32_pair();
        (a.sqrt(), b)
    }

    /// The spreads at the root and the tip, and the twist, at `root`.
    pub(crate) fn spreads(&self, root: &RootContext) -> [f32; 3] {
        [
            self.root_spread.at(&root.site),
            self.tip_spread.at(&root.site),
            self.twist.at(&root.site),
        ]
    }

    pub(super) fn split(&self, batch: &mut HairBatch, root: &RootContext, scratch: &mut Scratch) {
        // Taken out of the scratch (and put back) so the frame buffers can
        // be borrowed beside it.
        let mut bases = std::mem::take(&mut scratch.bases);
        bases.len = 0;
        for hair in batch.hairs() {
            bases.push().copy_from(hair);
        }
        let [s0, s1, twist] = self.spreads(root);
        batch.len = 0;
        for base in bases.hairs() {
            let n = base.points.len();
            scratch.frame_along(&base.points, root.normal);
            for k in 0..u64::from(self.count) {
                let id = self.strand_id(base.id, k);
                let (rho, b) = self.place(id);
                let hair = batch.push();
                hair.copy_from(base);
                hair.id = id;
                for (j, p) in hair.points.iter_mut().enumerate() {
                    let t = super::param(j, n);
                    let (sin, cos) = (TAU * (b + twist * t)).sin_cos();
                    let r = scratch.frame[j];
                    let side = scratch.tangents[j].cross(r);
                    *p += (s0 + t * (s1 - s0)) * rho * (cos * r + sin * side);
                }
            }
        }
        scratch.bases = bases;
    }
}

impl OperatorKind for Strands {
    const NAME: &'static str = "strands";
    const SUMMARY: &'static str = "Each hair becomes a strand of `count` hairs.";
    type Params = StrandsParams;
    const SALTS: &'static [(&'static str, u64)] = &[("SPREAD", SPREAD_SALT)];
    const KEEPS_ONE_HAIR: bool = false;

    fn counts(p: &StrandsParams) -> Vec<(&'static str, u64, u64, &'static str)> {
        vec![("count", u64::from(p.count), MAX_STRANDS, "hairs a strand")]
    }

    fn prepare(p: StrandsParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        if p.count == 0 {
            return Err(cx.error(
                "count",
                GroomErrorKind::OutOfRange("a strand needs at least 1 hair".into()),
            ));
        }
        Ok(Strands::new(
            p.count,
            p.root_spread,
            p.tip_spread,
            p.twist,
            cx.seed(p.seed),
        ))
    }

    fn apply(&self, batch: &mut HairBatch, root: &RootContext, scratch: &mut Scratch) {
        self.split(batch, root, scratch);
    }

    /// A hair a mask leaves whole is its strand's only hair, with the id
    /// of its strand's first: ids stay distinct (an unsplit hair's own id
    /// could be another strand's hair's).
    fn masked_out(&self, batch: &mut HairBatch) {
        for hair in batch.hairs_mut() {
            hair.id = self.strand_id(hair.id, 0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{batch, root, straight};
    use super::*;
    use glam::Vec3;

    #[test]
    fn strand_hairs_stay_within_the_spreads_with_distinct_ids() {
        let op = Strands::new(
            12,
            Map::Constant(0.01),
            Map::Constant(0.1),
            Map::Constant(0.5),
            3,
        );
        let mut b = batch(straight(5, 9, 1.0));
        op.apply(&mut b, &root(), &mut Scratch::default());
        assert_eq!(b.len(), 12);
        let mut ids: Vec<u64> = b.hairs().iter().map(|h| h.id).collect();
        ids.dedup();
        assert_eq!(ids, (60..72).collect::<Vec<_>>());
        let mut widest_tip = 0.0f32;
        for hair in b.hairs() {
            let root_off = hair.points[0].length();
            let tip_off = (hair.points[8] - Vec3::Z).length();
            assert!(root_off <= 0.01 + 1e-6 && tip_off <= 0.1 + 1e-6);
            assert!(
                hair.points[0].z.abs() < 1e-6,
                "roots spread in the skin's plane"
            );
            widest_tip = widest_tip.max(tip_off);
        }
        assert!(widest_tip > 0.05, "the strand opens toward the tip");
    }
}
