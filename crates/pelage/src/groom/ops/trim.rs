//! `cut` (Sik §4.2.2: "the texture value specifies a curve parameter at
//! which the curve is cut") and `length` (scale about the root).

use super::{HairBatch, RootContext, Scratch, jittered, param};
use crate::map::Map;
use crate::sample::{SampleRng, salts};

/// `cut`: each hair ends at curve parameter `at` (0 to 1, read from the
/// map at its root) and keeps its point count: the kept part is resampled
/// to as many evenly spaced parameters, so a short hair is as smooth as a
/// long one. Widths, colours and opacities are cut with it. `at ≤ 0`
/// removes the hair: paint black to make a bald patch.
#[derive(Debug, Clone)]
pub struct Cut {
    at: Map,
}

impl Cut {
    /// A cut operator.
    pub fn new(at: Map) -> Self {
        Self { at }
    }

    /// The curve parameter map.
    pub fn at(&self) -> &Map {
        &self.at
    }

    /// The curve parameter map, to change.
    pub fn at_mut(&mut self) -> &mut Map {
        &mut self.at
    }

    pub(super) fn apply(&self, batch: &mut HairBatch, root: &RootContext, scratch: &mut Scratch) {
        self.apply_at(batch, self.at.at(&root.site), scratch);
    }

    /// Cuts every hair of `batch` at curve parameter `at`.
    pub(super) fn apply_at(&self, batch: &mut HairBatch, at: f32, scratch: &mut Scratch) {
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

    pub(super) fn apply(&self, hair: &mut super::Hair, root: &RootContext) {
        let mut rng = SampleRng::new(self.seed ^ salts::LENGTH_JITTER, hair.id);
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

    #[test]
    fn length_scales_about_the_root_with_jitter_per_hair() {
        let mut hair = straight(1, 8, 1.0);
        Length::new(Map::Constant(2.0), Map::Constant(0.0), 0).apply(&mut hair, &root());
        assert!((hair.points[7] - Vec3::Z * 2.0).length() < 1e-6);
        assert_eq!(hair.points[0], Vec3::ZERO);
        let lengths: Vec<f32> = (0..200)
            .map(|id| {
                let mut h = straight(id, 8, 1.0);
                Length::new(Map::Constant(1.0), Map::Constant(0.2), 0).apply(&mut h, &root());
                h.points[7].z
            })
            .collect();
        assert!(lengths.iter().all(|l| (0.8..=1.2).contains(l)));
        let spread = lengths.iter().cloned().fold(f32::MIN, f32::max)
            - lengths.iter().cloned().fold(f32::MAX, f32::min);
        assert!(spread > 0.3, "jitter varies per hair: {spread}");
    }
}
