//! `color`: linear RGB from root to tip, each channel a map, with
//! per-hair brightness variation (Sik §4.2.2: "Again we add some noise to
//! hair color").

use super::kind::{OperatorKind, Preparation, SpecReader};
use super::root_to_tip::varied;
use super::{Hair, RootContext, Scratch};
use crate::groom::error::GroomError;
use crate::groom::ramp::Ramp;
use crate::groom::values::{ColorSpec, MapValue};
use crate::map::Map;
use glam::Vec3;

/// The per-hair brightness jitter.
const JITTER_SALT: u64 = 0xC0_10E;

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

/// The maps of a colour setting, by name.
pub(crate) fn color_maps(s: &Color) -> Vec<(&'static str, &Map)> {
    let root = s.root.iter().map(|m| ("root", m));
    let tip = s.tip.iter().map(|m| ("tip", m));
    root.chain(tip).chain([("jitter", &s.jitter)]).collect()
}

/// The maps of a colour setting, to change.
pub(crate) fn color_maps_mut(s: &mut Color) -> Vec<(&'static str, &mut Map)> {
    let Color {
        root, tip, jitter, ..
    } = s;
    let mut maps: Vec<(&'static str, &mut Map)> = root.iter_mut().map(|m| ("root", m)).collect();
    maps.extend(tip.iter_mut().map(|m| ("tip", m)));
    maps.push(("jitter", jitter));
    maps
}

impl OperatorKind for Color {
    const NAME: &'static str = "color";
    const SUMMARY: &'static str = "Colours (three maps each, linear RGB) from `root` to `tip`.";
    type Spec = ColorSpec;
    type Params = Color;
    const SALTS: &'static [(&'static str, u64)] = &[("JITTER", JITTER_SALT)];
    const ADDS_COLORS: bool = true;

    fn mask(spec: &ColorSpec) -> Option<&MapValue> {
        spec.mask.as_ref()
    }

    fn read(s: &ColorSpec, r: &mut SpecReader<'_>) -> Result<Color, GroomError> {
        read_color(r, s)
    }

    fn maps(p: &Color) -> Vec<(&'static str, &Map)> {
        color_maps(p)
    }

    fn maps_mut(p: &mut Color) -> Vec<(&'static str, &mut Map)> {
        color_maps_mut(p)
    }

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

/// A colour from root to tip, its maps read where the spec wrote them
/// (the `color` operator's and `[finish.color]`).
pub(crate) fn read_color(r: &mut SpecReader<'_>, s: &ColorSpec) -> Result<Color, GroomError> {
    Ok(Color {
        root: r.rgb("root", &s.root)?,
        tip: r.rgb("tip", &s.tip)?,
        ramp: s.ramp.clone(),
        jitter: r.map("jitter", &s.jitter)?,
        seed: s.seed,
    })
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
