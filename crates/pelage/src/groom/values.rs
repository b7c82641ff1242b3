//! The values every part of a groom is written in: a map as a groom file
//! or a program gives it ([`MapValue`]: a number, an image or a noise spec,
//! with where it was written). The lowest layer of `groom/`: the
//! operators, the spec and the file all read it.

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

/// A constant map as a groom file's default (no line of its own).
pub(crate) fn default_map(value: f32) -> MapValue {
    Spanned::new(0..0, MapText::Number(value))
}

/// `default_map(1.0)`, for serde's `default = "one"`.
pub(crate) fn one() -> MapValue {
    default_map(1.0)
}

/// `default_map(0.0)`, for serde's `default = "zero"`.
pub(crate) fn zero() -> MapValue {
    default_map(0.0)
}
