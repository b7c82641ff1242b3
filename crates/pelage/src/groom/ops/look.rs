//! Appearance operators: `width`, `color` and `opacity` from root to tip
//! with per-hair random variation (Sik §4.2.2: "the user specifies these
//! attributes at hair root and tip and we interpolate them to every hair
//! vertex. Again we add some noise to hair color").

use super::{Hair, RampTables, RootContext, RootToTip, jittered};
use crate::groom::file::Ramp;
use crate::map::Map;
use crate::sample::{SampleRng, salts};
use glam::Vec3;

/// Evaluates a [`RootToTip`] along a hair into `out` (resized to the
/// hair's point count).
fn root_to_tip(
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
fn varied(jitter: f32, seed: u64, hair_id: u64) -> f32 {
    if jitter == 0.0 {
        1.0
    } else {
        jittered(jitter, &mut SampleRng::new(seed, hair_id))
    }
}

/// `width`: `(root + ramp(t)(tip − root)) · (1 ± jitter)` per hair;
/// widths never go below zero.
#[derive(Debug, Clone)]
pub struct Width(pub RootToTip);

impl Width {
    pub(super) fn apply(&self, hair: &mut Hair, root: &RootContext, ramps: &mut RampTables) {
        let n = hair.points.len();
        root_to_tip(
            &self.0,
            salts::WIDTH_JITTER,
            hair.id,
            root,
            &mut hair.widths,
            n,
            ramps,
        );
        hair.widths.iter_mut().for_each(|w| *w = w.max(0.0));
    }
}

/// `opacity`: like [`Width`], clamped to [0, 1].
#[derive(Debug, Clone)]
pub struct Opacity(pub RootToTip);

impl Opacity {
    pub(super) fn apply(&self, hair: &mut Hair, root: &RootContext, ramps: &mut RampTables) {
        let n = hair.points.len();
        root_to_tip(
            &self.0,
            salts::OPACITY_JITTER,
            hair.id,
            root,
            &mut hair.opacities,
            n,
            ramps,
        );
        hair.opacities
            .iter_mut()
            .for_each(|o| *o = o.clamp(0.0, 1.0));
    }
}

/// `color`: linear RGB from root to tip, each channel a map, brightness
/// varied per hair by `± jitter`; never negative.
#[derive(Debug, Clone)]
pub struct Color {
    /// Root colour channels.
    pub root: [Map; 3],
    /// Tip colour channels.
    pub tip: [Map; 3],
    /// Profile.
    pub ramp: Ramp,
    /// Per-hair brightness variation.
    pub jitter: Map,
    /// Seed.
    pub seed: u64,
}

impl Color {
    pub(super) fn apply(&self, hair: &mut Hair, root: &RootContext, ramps: &mut RampTables) {
        let factor = varied(
            self.jitter.at(&root.site),
            self.seed ^ salts::COLOR_JITTER,
            hair.id,
        );
        let rgb = |m: &[Map; 3]| Vec3::from(m.each_ref().map(|c| c.at(&root.site)));
        let (a, b) = (rgb(&self.root), rgb(&self.tip));
        let ramp = ramps.along(&self.ramp, hair.points.len());
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

    fn spec(root: f32, tip: f32, jitter: f32) -> RootToTip {
        RootToTip {
            root: Map::Constant(root),
            tip: Map::Constant(tip),
            ramp: Ramp::default(),
            jitter: Map::Constant(jitter),
            seed: 0,
        }
    }

    #[test]
    fn width_runs_root_to_tip() {
        let mut hair = straight(1, 5, 1.0);
        Width(spec(0.01, 0.002, 0.0)).apply(&mut hair, &root(), &mut RampTables::default());
        assert_eq!(hair.widths[0], 0.01);
        assert!((hair.widths[4] - 0.002).abs() < 1e-9);
        assert!((hair.widths[2] - 0.006).abs() < 1e-9);
    }

    #[test]
    fn jitter_varies_per_hair_within_bounds() {
        let roots: Vec<f32> = (0..100)
            .map(|id| {
                let mut h = straight(id, 5, 1.0);
                Opacity(spec(0.5, 0.5, 0.5)).apply(&mut h, &root(), &mut RampTables::default());
                h.opacities[0]
            })
            .collect();
        assert!(roots.iter().all(|o| (0.25..=0.75).contains(o)));
        assert!(roots.iter().any(|o| *o < 0.4) && roots.iter().any(|o| *o > 0.6));
    }

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
        .apply(&mut hair, &root(), &mut RampTables::default());
        assert_eq!(hair.colors.len(), 3);
        assert!((hair.colors[1] - Vec3::new(0.6, 0.5, 0.4)).length() < 1e-6);
    }
}
