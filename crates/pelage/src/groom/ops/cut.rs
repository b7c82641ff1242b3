//! `cut` (Sik §4.2.2: "the texture value specifies a curve parameter at
//! which the curve is cut").

use super::kind::{OperatorKind, Preparation};
use super::settings::{Start, operator_settings};
use super::{HairBatch, RootContext, Scratch, param};
use crate::groom::error::GroomError;
use crate::map::Map;

operator_settings! {
    /// `cut` as a groom file writes it.
    pub(crate) spec CutSpec;
    /// `cut`: each hair ends at curve parameter `at` (0 to 1, read from the
    /// map at its root) and keeps its point count: the kept part is
    /// resampled to as many evenly spaced parameters, so a short hair is
    /// as smooth as a long one. Widths, colours and opacities are cut with
    /// it. `at ≤ 0` removes the hair: paint black to make a bald patch.
    params Cut {
        required {
            /// Curve parameter (0 to 1) at which each hair is cut; 0
            /// removes it.
            at: map, start Start::Number(0.8);
        }
        optional {}
    }
}

impl Cut {
    /// The curve parameter map.
    pub fn at(&self) -> &Map {
        &self.at
    }

    /// The curve parameter map, to change.
    pub fn at_mut(&mut self) -> &mut Map {
        &mut self.at
    }

    /// Cuts every hair of `batch` at curve parameter `at`.
    pub(super) fn cut_at(&self, batch: &mut HairBatch, at: f32, scratch: &mut Scratch) {
        if at >= 1.0 {
            return;
        }
        if at <= 0.0 {
            batch.retain(|_| false);
            return;
        }
        for hair in batch.hairs_mut() {
            let n = hair.points.len();
            if n < 2 {
                continue;
            }
            // Point k of the cut hair sits at parameter at · t_k of the old
            // one: between old points j and j + 1.
            let locate = |k: usize| {
                let x = at * param(k, n) * (n - 1) as f32;
                let j = (x as usize).min(n - 2);
                (j, x - j as f32)
            };
            macro_rules! resample {
                ($values:expr, $tmp:expr) => {
                    if !$values.is_empty() {
                        $tmp.clear();
                        $tmp.extend((0..n).map(|k| {
                            let (j, f) = locate(k);
                            $values[j] + ($values[j + 1] - $values[j]) * f
                        }));
                        $values.copy_from_slice(&$tmp);
                    }
                };
            }
            resample!(hair.points, scratch.points);
            resample!(hair.colors, scratch.points);
            resample!(hair.widths, scratch.floats);
            resample!(hair.opacities, scratch.floats);
        }
    }
}

impl OperatorKind for Cut {
    const NAME: &'static str = "cut";
    const SUMMARY: &'static str = "Cuts every hair at curve parameter `at` (0 to 1).";
    type Params = Cut;
    const KEEPS_ONE_HAIR: bool = false;

    fn prepare(p: Cut, _: &Preparation<'_>) -> Result<Self, GroomError> {
        Ok(p)
    }

    fn apply(&self, batch: &mut HairBatch, root: &RootContext, scratch: &mut Scratch) {
        self.cut_at(batch, self.at.at(&root.site), scratch);
    }

    /// A half-masked cut is a cut half as deep (`1 − m(1 − at)`), so a
    /// half-masked bald patch is half-length hair.
    fn apply_faded(
        &self,
        batch: &mut HairBatch,
        root: &RootContext,
        m: f32,
        scratch: &mut Scratch,
    ) -> bool {
        let at = self.at.at(&root.site);
        self.cut_at(batch, 1.0 - m * (1.0 - at), scratch);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{batch, root, straight};
    use super::*;
    use glam::Vec3;

    #[test]
    fn cut_ends_the_hair_at_the_parameter_and_keeps_its_points() {
        let mut b = batch(straight(1, 11, 2.0));
        b.hairs_mut()[0].widths = (0..11).map(|j| j as f32).collect();
        Cut::new(Map::Constant(0.25)).apply(&mut b, &root(), &mut Scratch::default());
        let hair = &b.hairs()[0];
        assert_eq!(hair.points.len(), 11);
        assert!((hair.points[10] - Vec3::Z * 0.5).length() < 1e-6);
        assert!((hair.points[5] - Vec3::Z * 0.25).length() < 1e-6);
        assert!(
            (hair.widths[10] - 2.5).abs() < 1e-5,
            "attributes are cut too"
        );
    }

    #[test]
    fn cut_at_zero_removes_the_hair_and_at_one_keeps_it() {
        let mut b = batch(straight(1, 8, 1.0));
        Cut::new(Map::Constant(1.0)).apply(&mut b, &root(), &mut Scratch::default());
        assert_eq!(b.hairs()[0], straight(1, 8, 1.0));
        Cut::new(Map::Constant(0.0)).apply(&mut b, &root(), &mut Scratch::default());
        assert!(b.is_empty());
    }
}
