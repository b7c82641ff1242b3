//! Root-to-tip profiles: how an operator's strength varies along a hair
//! (the `ramp` of noise, clump, curl, width, colour and opacity).

use serde::Deserialize;
use serde::de::{self, Deserializer, Visitor};
use std::fmt;

/// A root-to-tip profile `ramp(t)`, `t` from 0 at the root to 1 at the tip:
/// a number `p` for `t^p` (1: linear, 0: constant 1), a name (`linear`,
/// `constant`, `smooth` = smoothstep, `tip` = t², `root` = 1 − t), or a list
/// of values evenly spaced from root to tip, interpolated linearly.
#[derive(Debug, Clone, PartialEq)]
pub enum Ramp {
    /// `t^p`.
    Power(f32),
    /// Smoothstep `3t² − 2t³`.
    Smooth,
    /// `1 − t`: strongest at the root.
    Root,
    /// Piecewise linear through evenly spaced values.
    Values(Vec<f32>),
}

impl Default for Ramp {
    fn default() -> Self {
        Ramp::Power(1.0)
    }
}

impl Ramp {
    /// The profile's value at `t` ∈ [0, 1].
    #[inline]
    pub fn at(&self, t: f32) -> f32 {
        match self {
            Ramp::Power(p) if *p == 1.0 => t,
            Ramp::Power(p) if *p == 0.0 => 1.0,
            Ramp::Power(p) => t.max(0.0).powf(*p),
            Ramp::Smooth => t * t * (3.0 - 2.0 * t),
            Ramp::Root => 1.0 - t,
            Ramp::Values(v) => match v.len() {
                0 => 1.0,
                1 => v[0],
                n => {
                    let x = t.clamp(0.0, 1.0) * (n - 1) as f32;
                    let i = (x as usize).min(n - 2);
                    v[i] + (x - i as f32) * (v[i + 1] - v[i])
                }
            },
        }
    }
}

impl<'de> Deserialize<'de> for Ramp {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct RampVisitor;
        impl<'de> Visitor<'de> for RampVisitor {
            type Value = Ramp;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a ramp: an exponent (1 = linear), \"linear\", \"constant\", \"smooth\", \"tip\", \"root\", or a list of values from root to tip")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Ramp, E> {
                if v.is_finite() && v >= 0.0 {
                    Ok(Ramp::Power(v as f32))
                } else {
                    Err(E::custom(format!(
                        "a ramp exponent must be 0 or more, not {v}"
                    )))
                }
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Ramp, E> {
                self.visit_f64(v as f64)
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Ramp, E> {
                self.visit_f64(v as f64)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Ramp, E> {
                match v {
                    "linear" => Ok(Ramp::Power(1.0)),
                    "constant" => Ok(Ramp::Power(0.0)),
                    "smooth" => Ok(Ramp::Smooth),
                    "tip" => Ok(Ramp::Power(2.0)),
                    "root" => Ok(Ramp::Root),
                    _ => Err(E::invalid_value(de::Unexpected::Str(v), &self)),
                }
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<Ramp, A::Error> {
                let mut values = Vec::new();
                while let Some(v) = seq.next_element::<f32>()? {
                    values.push(v);
                }
                if values.is_empty() {
                    return Err(de::Error::custom("a ramp list needs at least one value"));
                }
                Ok(Ramp::Values(values))
            }
        }
        deserializer.deserialize_any(RampVisitor)
    }
}
