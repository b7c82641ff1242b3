//! `mask`: any operator's effect faded by a map read at the root, as
//! groomers paint where noise, clumping or curl apply (XGen's and
//! Houdini's per-operator masks). With mask value `m` (clamped to 0–1) a
//! hair becomes `before + m · (after − before)`, point for point and
//! attribute for attribute; `m = 0` skips the operator, `m = 1` is the
//! operator alone. `cut` fades its parameter instead (`1 − m(1 − at)`), so
//! a half-masked bald patch is half-length hair, and `strands` fades each
//! new hair toward its base hair.
//!
//! An operator that gives hairs an attribute they did not have (the first
//! `color` or `opacity`) blends from what the hair shows without it: fully
//! opaque ([`UNMASKED_OPACITY`]) and the mid grey renderers draw uncoloured
//! curves in ([`UNMASKED_COLOR`]), so `mask = 0` leaves every hair as it
//! would be without the operator.

use super::{Hair, HairBatch, Operator, RootContext, Scratch};
use crate::map::Map;
use glam::Vec3;

/// The opacity a masked `opacity` fades from where the hair had none.
pub const UNMASKED_OPACITY: f32 = 1.0;
/// The colour a masked `color` fades from where the hair had none.
pub const UNMASKED_COLOR: Vec3 = Vec3::splat(0.5);

/// An operator whose effect a map fades.
#[derive(Debug)]
pub struct Masked {
    op: Box<Operator>,
    mask: Map,
}

impl Masked {
    /// `op` faded by `mask`.
    pub fn new(op: Operator, mask: Map) -> Self {
        Self {
            op: Box::new(op),
            mask,
        }
    }

    /// The operator masked.
    pub fn operator(&self) -> &Operator {
        &self.op
    }

    /// The mask.
    pub fn mask(&self) -> &Map {
        &self.mask
    }

    /// The mask's value at the root, clamped to 0–1 (NaN reads 0).
    /// The mask's weight at `root`, 0 to 1.
    #[inline]
    pub(crate) fn weight(&self, root: &RootContext) -> f32 {
        let m = self.mask.at(&root.site);
        if m > 0.0 { m.min(1.0) } else { 0.0 }
    }

    /// Gives `hair` the attributes the operator adds, at the values it
    /// fades from, where it has none yet.
    fn start_attributes(&self, hair: &mut Hair) {
        let n = hair.points.len();
        if self.op.adds_opacities() && hair.opacities.is_empty() {
            hair.opacities.resize(n, UNMASKED_OPACITY);
        }
        if self.op.adds_colors() && hair.colors.is_empty() {
            hair.colors.resize(n, UNMASKED_COLOR);
        }
    }

    pub(super) fn apply(&self, batch: &mut HairBatch, root: &RootContext, scratch: &mut Scratch) {
        let m = self.weight(root);
        for hair in batch.hairs_mut() {
            self.start_attributes(hair);
        }
        if m == 0.0 {
            return self.op.masked_out(batch);
        }
        if m == 1.0 {
            return self.op.apply(batch, root, scratch);
        }
        if self.op.apply_faded(batch, root, m, scratch) {
            return;
        }
        let mut before = std::mem::take(&mut scratch.masked);
        before.len = 0;
        for hair in batch.hairs() {
            before.push().copy_from(hair);
        }
        self.op.apply(batch, root, scratch);
        let (from, to) = (before.len(), batch.len());
        if from > 0 {
            for (i, hair) in batch.hairs_mut().iter_mut().enumerate() {
                // Strands make `to / from` hairs of each, base by base.
                blend(hair, &before.hairs()[(i * from / to).min(from - 1)], m);
            }
        }
        scratch.masked = before;
    }

    /// [`Self::apply`] for hairs grown one a root (the operator keeps one
    /// hair a root), the operator's shared work kept.
    pub(super) fn apply_each(
        &self,
        hairs: &mut [Hair],
        roots: &[RootContext],
        scratch: &mut Scratch,
    ) {
        let mut before = std::mem::take(&mut scratch.masked);
        before.len = 0;
        for hair in hairs.iter_mut() {
            self.start_attributes(hair);
            before.push().copy_from(hair);
        }
        self.op.apply_each(hairs, roots, scratch);
        for ((hair, root), old) in hairs.iter_mut().zip(roots).zip(before.hairs()) {
            let m = self.weight(root);
            if m < 1.0 {
                blend(hair, old, m);
            }
        }
        scratch.masked = before;
    }
}

/// `hair = before + m · (hair − before)` for every attribute both have
/// point for point (an attribute the hair gained, such as a first colour,
/// is kept as the operator made it).
fn blend(hair: &mut Hair, before: &Hair, m: f32) {
    if hair.points.len() == before.points.len() {
        for (p, b) in hair.points.iter_mut().zip(&before.points) {
            *p = *b + m * (*p - *b);
        }
    }
    if hair.colors.len() == before.colors.len() {
        for (c, b) in hair.colors.iter_mut().zip(&before.colors) {
            *c = *b + m * (*c - *b);
        }
    }
    for (values, old) in [
        (&mut hair.widths, &before.widths),
        (&mut hair.opacities, &before.opacities),
    ] {
        if values.len() == old.len() {
            for (v, b) in values.iter_mut().zip(old) {
                *v = *b + m * (*v - *b);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{batch, root, straight};
    use super::super::{Cut, Length};
    use super::*;

    #[test]
    fn half_a_mask_is_half_the_effect_and_zero_is_none() {
        let length = || Operator::Length(Length::new(Map::Constant(3.0), Map::Constant(0.0), 0));
        let mut scratch = Scratch::default();
        for (m, tip) in [(0.0, 1.0), (0.5, 2.0), (1.0, 3.0)] {
            let op = Masked::new(length(), Map::Constant(m));
            let mut b = batch(straight(1, 8, 1.0));
            op.apply(&mut b, &root(), &mut scratch);
            assert!((b.hairs()[0].points[7].z - tip).abs() < 1e-5, "mask {m}");
        }
        // The grouped path agrees.
        let op = Masked::new(length(), Map::Constant(0.25));
        let mut hairs = vec![straight(1, 8, 1.0)];
        op.apply_each(&mut hairs, &[root()], &mut scratch);
        assert!((hairs[0].points[7].z - 1.5).abs() < 1e-5);
        // A masked cut fades its parameter: at 0 with mask 0.5 keeps half.
        let op = Masked::new(
            Operator::Cut(Cut::new(Map::Constant(0.0))),
            Map::Constant(0.5),
        );
        let mut b = batch(straight(1, 8, 1.0));
        op.apply(&mut b, &root(), &mut scratch);
        assert_eq!(b.len(), 1);
        assert!((b.hairs()[0].points[7].z - 0.5).abs() < 1e-5);
    }

    /// The first opacity or colour a hair gets under a mask fades from
    /// what the hair shows without one: `mask = 0` is no operator, half a
    /// mask is halfway, on both paths.
    #[test]
    fn a_masked_first_look_fades_from_the_unmasked_look() {
        use super::super::Opacity;
        use super::super::root_to_tip::tests::spec;
        let opacity = || Operator::Opacity(Opacity(spec(0.2, 0.2, 0.0)));
        let mut scratch = Scratch::default();
        for (m, want) in [(0.0, UNMASKED_OPACITY), (0.5, 0.6), (1.0, 0.2)] {
            let op = Masked::new(opacity(), Map::Constant(m));
            let mut b = batch(straight(1, 8, 1.0));
            op.apply(&mut b, &root(), &mut scratch);
            let o = &b.hairs()[0].opacities;
            assert_eq!(o.len(), 8, "mask {m}");
            assert!(o.iter().all(|v| (v - want).abs() < 1e-5), "mask {m}: {o:?}");
            let mut hairs = vec![straight(1, 8, 1.0)];
            op.apply_each(&mut hairs, &[root()], &mut scratch);
            let o = &hairs[0].opacities;
            assert!(o.iter().all(|v| (v - want).abs() < 1e-5), "mask {m}: {o:?}");
        }
    }
}
