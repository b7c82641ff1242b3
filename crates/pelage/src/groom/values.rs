//! The values every part of a groom is written in: a map as a groom file
//! or a program gives it ([`MapValue`]: a number, an image or a noise spec,
//! with where it was written), and the root-to-tip quantities and colours
//! that `width`, `opacity`, `color` and `[finish]` share. The lowest layer
//! of `groom/`: the operators, the spec and the file all read these.

use super::ramp::Ramp;
use serde::Deserialize;
use serde::de::{self, Deserializer, Visitor};
use std::fmt;
use toml::Spanned;

/// A map as written in a groom file: a number or a map spec string
/// (`"density.png:r"`, `"noise:frequency=8"`), with where it was written.
pub type MapValue = Spanned<MapText>;

/// The text of a map: a number or a spec.
#[derive(Debug, Clone, PartialEq)]
pub enum MapText {
    /// A constant.
    Number(f32),
    /// A map spec: image path with suffixes, or `noise:…`.
    Spec(String),
}

impl<'de> Deserialize<'de> for MapText {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct MapVisitor;
        impl Visitor<'_> for MapVisitor {
            type Value = MapText;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a map: a number, an image path such as \"length.png:r\", or \"noise:frequency=8\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<MapText, E> {
                Ok(MapText::Number(v as f32))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<MapText, E> {
                Ok(MapText::Number(v as f32))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<MapText, E> {
                Ok(MapText::Number(v as f32))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<MapText, E> {
                Ok(MapText::Spec(v.to_string()))
            }
        }
        deserializer.deserialize_any(MapVisitor)
    }
}

pub(crate) fn one() -> MapValue {
    Spanned::new(0..0, MapText::Number(1.0))
}
pub(crate) fn zero() -> MapValue {
    Spanned::new(0..0, MapText::Number(0.0))
}

/// A quantity from root to tip: `width` and `opacity` (and
/// `[finish.width]`, `[finish.opacity]`); see [`crate::groom::ops::Width`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RootToTipSpec {
    /// Value at the root (a width in world units, or an opacity).
    pub root: MapValue,
    /// Value at the tip.
    pub tip: MapValue,
    /// Profile from root to tip.
    #[serde(default)]
    pub ramp: Ramp,
    /// Per-hair random variation, a fraction.
    #[serde(default = "zero")]
    pub jitter: MapValue,
    /// Seed of the variation.
    #[serde(default)]
    pub seed: u64,
    /// Where the operator acts: its effect is faded by this map (0: none,
    /// 1: full).
    pub mask: Option<MapValue>,
}

/// `color` (and `[finish.color]`): see [`crate::groom::ops::Color`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColorSpec {
    /// Linear RGB at the root, each channel a map.
    pub root: [MapValue; 3],
    /// Linear RGB at the tip.
    pub tip: [MapValue; 3],
    /// Profile from root to tip.
    #[serde(default)]
    pub ramp: Ramp,
    /// Per-hair random brightness variation, a fraction.
    #[serde(default = "zero")]
    pub jitter: MapValue,
    /// Seed of the variation.
    #[serde(default)]
    pub seed: u64,
    /// Where the operator acts: its effect is faded by this map (0: none,
    /// 1: full).
    pub mask: Option<MapValue>,
}
