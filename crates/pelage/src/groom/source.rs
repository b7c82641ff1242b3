//! Groom files' errors at their place: [`SettingsSource`] read and parsed
//! as a groom, and maps resolved against the file's folder.

use super::error::{GroomError, GroomErrorKind};
use super::file::{GroomFile, MapText, MapValue};
use crate::limits::*;
use crate::map::Map;
use crate::settings::{Bound, Rule, SettingsSource};
use std::path::Path;

/// The documented range of every numeric groom setting that has one
/// (docs/groom-format.md, docs/limits.md), checked when the file is read.
/// Map-valued settings are checked here when written as numbers. Each
/// operator's rules are its module's ([`super::ops::operator_rules`]).
const GROOM_RULES: &[Rule] = &[
    Rule::new(
        "mesh.subdivide",
        Bound::Within(0.0, MAX_SUBDIVIDE as f64),
        "each step makes 4 triangles of 1",
    ),
    Rule::new(
        "roots.count",
        Bound::Within(1.0, MAX_HAIRS as f64),
        "pelage's hair limit, docs/limits.md",
    ),
    Rule::new("roots.parts", Bound::Within(1.0, MAX_PARTS as f64), ""),
    Rule::new(
        "output.fraction",
        Bound::Above(0.0, 1.0),
        "a share of the hairs",
    ),
    Rule::new(
        "guides.points",
        Bound::Within(2.0, MAX_CURVE_POINTS as f64),
        "points per guide",
    ),
    Rule::new("guides.tolerance", Bound::at_least(0.0), "a distance"),
    Rule::new(
        "guides.generate.count",
        Bound::Within(1.0, MAX_GUIDES as f64),
        "pelage's guide limit",
    ),
    Rule::new("guides.generate.length", Bound::at_least(0.0), "a length"),
    Rule::new("guides.generate.density", Bound::at_least(0.0), "a density"),
    Rule::new(
        "interpolation.k",
        Bound::Within(1.0, 1024.0),
        "guides per hair",
    ),
    Rule::new(
        "interpolation.power",
        Bound::more_than(0.0),
        "Shepard's distance exponent",
    ),
    Rule::new("interpolation.radius", Bound::more_than(0.0), "a distance"),
    Rule::new("roots.density", Bound::at_least(0.0), "a density"),
    Rule::new("finish.skin_gap", Bound::at_least(0.0), "a distance"),
    Rule::new(
        "simulation.substeps",
        Bound::Within(1.0, 64.0),
        "substeps a frame",
    ),
    Rule::new(
        "simulation.iterations",
        Bound::Within(1.0, 100.0),
        "passes a substep",
    ),
    Rule::new(
        "simulation.damping",
        Bound::at_least(0.0),
        "a rate per second",
    ),
    Rule::new("simulation.bend", Bound::Within(0.0, 1.0), "a fraction"),
    Rule::new("simulation.follow", Bound::Within(0.0, 1.0), "a fraction"),
    Rule::new("simulation.drag", Bound::at_least(0.0), "a rate per second"),
    Rule::new("simulation.thickness", Bound::at_least(0.0), "a distance"),
    Rule::new("simulation.friction", Bound::Within(0.0, 1.0), "a fraction"),
    Rule::new(
        "simulation.preroll",
        Bound::Within(0.0, MAX_FRAMES as f64),
        "frames",
    ),
    Rule::new(
        "finish.points",
        Bound::Within(2.0, MAX_CURVE_POINTS as f64),
        "points per hair",
    ),
    Rule::new("finish.width.root", Bound::at_least(0.0), "a width"),
    Rule::new("finish.width.tip", Bound::at_least(0.0), "a width"),
    Rule::new("finish.opacity.root", Bound::Within(0.0, 1.0), "an opacity"),
    Rule::new("finish.opacity.tip", Bound::Within(0.0, 1.0), "an opacity"),
    Rule::new("animation.fps", Bound::more_than(0.0), "frames per second"),
    Rule::new(
        "look.melanin",
        Bound::Within(0.0, 1.0),
        "Cycles' melanin scale",
    ),
    Rule::new("look.melanin_redness", Bound::Within(0.0, 1.0), "a share"),
    Rule::new("look.tint", Bound::at_least(0.0), "a linear colour"),
    Rule::new("look.roughness", Bound::Within(0.0, 1.0), "a roughness"),
    Rule::new(
        "look.radial_roughness",
        Bound::Within(0.0, 1.0),
        "a roughness",
    ),
    Rule::new("look.jitter", Bound::Within(0.0, 1.0), "a fraction"),
];

impl SettingsSource {
    /// Reads a groom (or other settings) file, the error a [`GroomError`].
    pub fn read_groom(path: &Path) -> Result<Self, GroomError> {
        Self::read(path)
            .map_err(|e| GroomError::new(path.to_path_buf(), None, None, GroomErrorKind::Io(e)))
    }

    /// Parses and checks the text as a groom file (every key known, every
    /// number in its range), loading nothing it names.
    pub fn check_groom(&self) -> Result<(), GroomError> {
        self.parse().map(drop)
    }

    /// Parses the text as a groom file.
    pub(crate) fn parse(&self) -> Result<GroomFile, GroomError> {
        if let Some((place, message)) = self.single_bracket_list(&["ops"]) {
            return Err(GroomError::new(
                self.path.clone(),
                place.line,
                place.key,
                GroomErrorKind::Syntax(message),
            ));
        }
        let file = self.parse_as()?;
        let mut rules = GROOM_RULES.to_vec();
        rules.extend(super::ops::operator_rules());
        self.check(&rules).map_err(|(place, message)| {
            GroomError::new(
                self.path.clone(),
                place.line,
                place.key,
                GroomErrorKind::Invalid(message),
            )
        })?;
        Ok(file)
    }

    /// Parses the text as `T`, the error a [`GroomError`] at its line and
    /// key.
    pub fn parse_as<T: serde::de::DeserializeOwned>(&self) -> Result<T, GroomError> {
        self.deserialize().map_err(|(place, message)| {
            GroomError::new(
                self.path.clone(),
                place.line,
                place.key,
                GroomErrorKind::Syntax(message),
            )
        })
    }

    /// A [`GroomError`] at a span of the text: its line and column, and the
    /// key written there (with its table).
    pub fn error_at(&self, span: std::ops::Range<usize>, kind: GroomErrorKind) -> GroomError {
        let place = self.place(span);
        GroomError::new(self.path.clone(), place.line, place.key, kind)
    }

    /// Resolves a map value, reporting a bad spec or unreadable image at its
    /// line.
    pub(crate) fn map(&self, value: &MapValue) -> Result<Map, GroomError> {
        match value.get_ref() {
            MapText::Number(n) if n.is_finite() => Ok(Map::Constant(*n)),
            MapText::Number(n) => Err(self.error_at(
                value.span(),
                GroomErrorKind::Invalid(format!("{n} is not a finite number")),
            )),
            MapText::Spec(spec) => Map::parse_with_base(spec, Some(self.folder()))
                .map_err(|e| self.error_at(value.span(), GroomErrorKind::Map(e))),
        }
    }
}
