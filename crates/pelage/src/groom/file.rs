//! The groom file: TOML describing a whole groom — mesh, roots, guides,
//! interpolation, an ordered list of operators, finishing and output
//! (docs/groom-format.md has the reference and complete examples).
//!
//! Parsing is serde + toml with unknown keys refused everywhere, so a typo
//! is an error naming the file, line, column and key, never a silently
//! ignored setting. Every numeric operator parameter is a [`MapValue`]: a
//! number, an image path with channel, or a noise spec (Sik §4: "every user
//! parameter … is also specified by a texture"); maps are resolved against
//! the groom file's folder, and a map that cannot be read is reported at
//! its line too.

use crate::map::{Map, MapError};
use serde::Deserialize;
use serde::de::{self, Deserializer, Visitor};
use std::fmt;
use std::path::{Path, PathBuf};
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

fn one() -> MapValue {
    Spanned::new(0..0, MapText::Number(1.0))
}
fn zero() -> MapValue {
    Spanned::new(0..0, MapText::Number(0.0))
}
fn seed_one() -> u64 {
    1
}
fn one_f32() -> f32 {
    1.0
}

/// A whole groom file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroomFile {
    /// The surface.
    pub mesh: MeshSection,
    /// Where hairs grow.
    pub roots: RootsSection,
    /// The guide curves.
    pub guides: GuidesSection,
    /// How hairs take their shape from the guides.
    #[serde(default)]
    pub interpolation: InterpolationSection,
    /// The operators, applied in order to every hair.
    #[serde(default)]
    pub ops: Vec<OpSpec>,
    /// Points, widths, colours, normals.
    #[serde(default)]
    pub finish: FinishSection,
    /// Where the curves go.
    #[serde(default)]
    pub output: OutputSection,
}

/// `[mesh]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSection {
    /// Mesh file (.obj, .ply, .gltf, .glb) relative to the groom file, or
    /// `"spot"` for the embedded demo mesh.
    pub path: Spanned<String>,
    /// Midpoint subdivision steps applied after loading.
    #[serde(default)]
    pub subdivide: u32,
}

/// `[roots]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RootsSection {
    /// Number of hairs (before `strands` multiplies them).
    pub count: Spanned<u64>,
    /// Root density map.
    #[serde(default = "one")]
    pub density: MapValue,
    /// Seed of every random number in the groom.
    #[serde(default = "seed_one")]
    pub seed: u64,
    /// Number of parts (default: one per 100,000 hairs).
    pub parts: Option<Spanned<u32>>,
}

/// `[guides]`: from a file, or grown.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GuidesSection {
    /// A curves file (USD, .hair, PLY) relative to the groom file.
    pub file: Option<Spanned<String>>,
    /// With `file`: the farthest a root may be from the surface.
    #[serde(default = "default_tolerance")]
    pub tolerance: f32,
    /// Grow guides instead of reading them.
    pub generate: Option<GenerateSection>,
    /// Points every guide is resampled to.
    #[serde(default = "default_guide_points")]
    pub points: usize,
}

fn default_tolerance() -> f32 {
    1e-3
}
fn default_guide_points() -> usize {
    8
}

/// `[guides.generate]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GenerateSection {
    /// Number of guides.
    pub count: usize,
    /// Guide root density.
    #[serde(default = "one")]
    pub density: MapValue,
    /// Guide length.
    pub length: MapValue,
    /// Comb direction (world space; its length is the strength).
    #[serde(default)]
    pub comb: [f32; 3],
    /// A flow map instead of `comb`: two maps, the comb's components along
    /// +U and along `N × T` (0.5: none), e.g. `["flow.png:r", "flow.png:g"]`.
    pub comb_map: Option<[MapValue; 2]>,
    /// Multiplies the flow map's direction.
    #[serde(default = "one_f32")]
    pub comb_strength: f32,
    /// Pull toward world −Y.
    #[serde(default)]
    pub gravity: f32,
    /// Seed of the guide roots.
    #[serde(default = "seed_one")]
    pub seed: u64,
}

/// `[interpolation]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterpolationSection {
    /// `shepard` or `style-mesh`.
    #[serde(default = "default_method")]
    pub method: Spanned<String>,
    /// Shepard: guides per hair.
    #[serde(default = "default_k")]
    pub k: usize,
    /// Shepard: distance exponent.
    #[serde(default = "default_power")]
    pub power: f32,
    /// Shepard: largest distance at which a guide counts.
    pub radius: Option<f32>,
    /// Style mesh: split triangles so every guide keeps its own vertex.
    #[serde(default)]
    pub split_shared: bool,
}

fn default_method() -> Spanned<String> {
    Spanned::new(0..0, "shepard".to_string())
}
fn default_k() -> usize {
    4
}
fn default_power() -> f32 {
    2.0
}

impl Default for InterpolationSection {
    fn default() -> Self {
        Self {
            method: default_method(),
            k: default_k(),
            power: default_power(),
            radius: None,
            split_shared: false,
        }
    }
}

/// One operator: `[[ops]]` followed by `NAME = { … }` or `[ops.NAME]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OpSpec {
    /// Perlin displacement.
    Noise(NoiseSpec),
    /// Per-hair random high-frequency displacement.
    Frizz(FrizzSpec),
    /// Pull hairs toward clump centre hairs.
    Clump(ClumpSpec),
    /// Helix around the hair's path.
    Curl(CurlSpec),
    /// Cut at a curve parameter.
    Cut(CutSpec),
    /// Scale the length.
    Length(LengthSpec),
    /// Each hair becomes a strand of hairs.
    Strands(StrandsSpec),
    /// Widths root to tip.
    Width(RootToTipSpec),
    /// Colours root to tip.
    Color(ColorSpec),
    /// Opacity root to tip.
    Opacity(RootToTipSpec),
}

/// `noise`: see [`crate::groom::ops::Noise`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// Largest displacement (world units).
    pub amplitude: MapValue,
    /// Noise cycles per world unit.
    #[serde(default = "default_noise_frequency")]
    pub frequency: MapValue,
    /// Root-to-tip profile of the amplitude.
    #[serde(default)]
    pub ramp: Ramp,
    /// Noise vectors sampled along each hair, interpolated between (0:
    /// one at every point).
    #[serde(default = "default_noise_vectors")]
    pub vectors: usize,
    /// Seed of the noise field.
    #[serde(default)]
    pub seed: u64,
}

fn default_noise_vectors() -> usize {
    5
}

fn default_noise_frequency() -> MapValue {
    Spanned::new(0..0, MapText::Number(10.0))
}

/// `frizz`: see [`crate::groom::ops::Frizz`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrizzSpec {
    /// Largest displacement (world units).
    pub amplitude: MapValue,
    /// Wiggles along one hair.
    #[serde(default = "default_frizz_frequency")]
    pub frequency: MapValue,
    /// Share of hairs that frizz (0 to 1).
    #[serde(default = "one")]
    pub fraction: MapValue,
    /// Root-to-tip profile.
    #[serde(default)]
    pub ramp: Ramp,
    /// Seed.
    #[serde(default)]
    pub seed: u64,
}

fn default_frizz_frequency() -> MapValue {
    Spanned::new(0..0, MapText::Number(6.0))
}

/// `clump`: see [`crate::groom::ops::Clump`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClumpSpec {
    /// Number of clumps over the whole mesh.
    pub count: Spanned<u64>,
    /// Density of clump centres.
    #[serde(default = "one")]
    pub density: MapValue,
    /// How far hairs move to their centre hair (0 to 1).
    #[serde(default = "default_clump_rate")]
    pub rate: MapValue,
    /// Root-to-tip profile of the rate.
    #[serde(default)]
    pub ramp: Ramp,
    /// Clump radius: hairs this far from their centre's root are not
    /// pulled, nearer ones in proportion (default: no limit).
    pub size: Option<MapValue>,
    /// Seed of the clump centres.
    #[serde(default)]
    pub seed: u64,
}

fn default_clump_rate() -> MapValue {
    Spanned::new(0..0, MapText::Number(0.8))
}

/// `curl`: see [`crate::groom::ops::Curl`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurlSpec {
    /// Helix radius at the tip (world units): Silva's K_α.
    pub radius: MapValue,
    /// Turns along the hair: Silva's ω / 2π.
    pub turns: MapValue,
    /// Root-to-tip profile of the radius (Silva: linear).
    #[serde(default)]
    pub ramp: Ramp,
    /// Seed of each hair's phase.
    #[serde(default)]
    pub seed: u64,
}

/// `cut`: see [`crate::groom::ops::Cut`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CutSpec {
    /// Curve parameter (0 to 1) at which each hair is cut; 0 removes it.
    pub at: MapValue,
}

/// `length`: see [`crate::groom::ops::Length`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LengthSpec {
    /// Length factor.
    pub scale: MapValue,
    /// Per-hair random variation, a fraction (0.2 = ±20 %).
    #[serde(default = "zero")]
    pub jitter: MapValue,
    /// Seed of the variation.
    #[serde(default)]
    pub seed: u64,
}

/// `strands`: see [`crate::groom::ops::Strands`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrandsSpec {
    /// Hairs per strand.
    pub count: Spanned<u32>,
    /// Spread around the base hair at the root (world units).
    #[serde(default = "zero")]
    pub root_spread: MapValue,
    /// Spread at the tip.
    pub tip_spread: MapValue,
    /// Turns of the strand's hairs around the base hair, root to tip.
    #[serde(default = "zero")]
    pub twist: MapValue,
    /// Seed.
    #[serde(default)]
    pub seed: u64,
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
}

/// `[finish]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FinishSection {
    /// Points per hair.
    #[serde(default = "default_points")]
    pub points: Spanned<usize>,
    /// Widths before any `width` operator.
    #[serde(default = "default_width")]
    pub width: RootToTipSpec,
    /// Colours (none unless given here or by a `color` operator).
    pub color: Option<ColorSpec>,
    /// Opacity (none unless given here or by an `opacity` operator).
    pub opacity: Option<RootToTipSpec>,
    /// Per-point ribbon normals from rotation-minimizing frames.
    #[serde(default = "yes")]
    pub normals: bool,
}

fn default_points() -> Spanned<usize> {
    Spanned::new(0..0, 16)
}
fn yes() -> bool {
    true
}
fn default_width() -> RootToTipSpec {
    RootToTipSpec {
        root: Spanned::new(0..0, MapText::Number(0.002)),
        tip: Spanned::new(0..0, MapText::Number(0.0002)),
        ramp: Ramp::default(),
        jitter: zero(),
        seed: 0,
    }
}

impl Default for FinishSection {
    fn default() -> Self {
        Self {
            points: default_points(),
            width: default_width(),
            color: None,
            opacity: None,
            normals: true,
        }
    }
}

/// `[output]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    /// Output file relative to the groom file (default: the groom file's
    /// name with `.usda`).
    pub path: Option<String>,
    /// Also write the skin mesh (USD only).
    #[serde(default)]
    pub with_mesh: bool,
    /// `catmull-rom` (default) or `linear`.
    pub basis: Option<String>,
}

/// A groom file and where it came from, for error messages and relative
/// paths.
#[derive(Debug, Clone)]
pub struct GroomSource {
    /// The file (or a name such as `<demo>`).
    pub path: PathBuf,
    /// Its text.
    pub text: String,
}

impl GroomSource {
    /// Reads a groom file.
    pub fn read(path: &Path) -> Result<Self, GroomError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| GroomError::new(path.to_path_buf(), None, None, GroomErrorKind::Io(e)))?;
        Ok(Self {
            path: path.to_path_buf(),
            text,
        })
    }

    /// The folder relative paths are resolved against.
    pub fn folder(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new(""))
    }

    /// Parses the text.
    pub fn parse(&self) -> Result<GroomFile, GroomError> {
        self.parse_as()
    }

    /// Parses the text as any TOML file pelage reads (groom files, shell
    /// scenes), with errors at their line and key.
    pub fn parse_as<T: serde::de::DeserializeOwned>(&self) -> Result<T, GroomError> {
        toml::from_str(&self.text).map_err(|e| {
            let message = e.message().to_string();
            match e.span() {
                Some(span) => self.error_at(span, GroomErrorKind::Syntax(message)),
                None => GroomError::new(
                    self.path.clone(),
                    None,
                    None,
                    GroomErrorKind::Syntax(message),
                ),
            }
        })
    }

    /// An error at a span of the text: its line and column, and the key
    /// written there (with its table).
    pub fn error_at(&self, span: std::ops::Range<usize>, kind: GroomErrorKind) -> GroomError {
        if span == (0..0) {
            // A default value: no place in the file.
            return GroomError::new(self.path.clone(), None, None, kind);
        }
        let start = span.start.min(self.text.len());
        let line_start = self.text[..start].rfind('\n').map_or(0, |i| i + 1);
        GroomError::new(
            self.path.clone(),
            self.line_of(span),
            key_at(&self.text, line_start, start),
            kind,
        )
    }

    /// Line and column (1-based) of a span of the text; `None` for a
    /// default value (the empty span at 0).
    pub fn line_of(&self, span: std::ops::Range<usize>) -> Option<(usize, usize)> {
        if span == (0..0) {
            return None;
        }
        let start = span.start.min(self.text.len());
        let before = &self.text[..start];
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Some((
            before.matches('\n').count() + 1,
            before[line_start..].chars().count() + 1,
        ))
    }

    /// Line and column of operator `k`'s table: its `[[ops]]` header.
    pub fn line_of_op(&self, k: usize) -> Option<(usize, usize)> {
        let line = self
            .text
            .lines()
            .enumerate()
            .filter(|(_, l)| l.trim_start().starts_with("[[ops]]"))
            .nth(k)?
            .0;
        Some((line + 1, 1))
    }

    /// Resolves a map value, reporting a bad spec or unreadable image at its
    /// line.
    pub fn map(&self, value: &MapValue) -> Result<Map, GroomError> {
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

/// The dotted key at `offset` on the line starting at `line_start`, with
/// its table: `roots.count`, `ops[2].clump.rate`.
fn key_at(text: &str, line_start: usize, offset: usize) -> Option<String> {
    let line_end = text[line_start..]
        .find('\n')
        .map_or(text.len(), |i| line_start + i);
    let line = &text[line_start..line_end];
    let in_line = offset - line_start;
    let trimmed = line.trim_start();
    if trimmed.starts_with('[') {
        return Some(trimmed.trim().to_string());
    }
    // The key is what precedes the last `=` before the offset, or the bare
    // word at the offset (an unknown key is reported at the key itself).
    let head = &line[..in_line.min(line.len())];
    let rest = &line[in_line.min(line.len())..];
    let word_end = rest
        .find(|c: char| c == '=' || c == ',' || c == '}' || c.is_whitespace())
        .unwrap_or(rest.len());
    let at_key = rest[word_end..].trim_start().starts_with('=') && word_end > 0;
    // The key owning the inline table that is open at `pos`.
    let owner_of = |pos: usize| {
        let brace = line[..pos].rfind('{')?;
        let before = line[..brace].trim_end().strip_suffix('=')?.trim_end();
        let start = before.rfind(['{', ',']).map_or(0, |i| i + 1);
        Some(before[start..].trim().to_string())
    };
    let key = match head.rfind('=') {
        // An unknown key is reported at the key itself.
        _ if at_key => {
            let key = rest[..word_end].to_string();
            match owner_of(head.len()) {
                Some(owner) => format!("{owner}.{key}"),
                None => key,
            }
        }
        Some(eq) => {
            let left = &head[..eq];
            // Inside an inline table: the key after the last `{` or `,`.
            let start = left.rfind(['{', ',']).map_or(0, |i| i + 1);
            let inline_owner = owner_of(start);
            let key = left[start..].trim().to_string();
            match inline_owner {
                Some(owner) if start > 0 => format!("{owner}.{key}"),
                _ => key,
            }
        }
        None => rest[..word_end].to_string(),
    };
    if key.is_empty() {
        return None;
    }
    // The table the line is in: the last header above it.
    let mut table = None;
    let mut ops_seen = 0usize;
    for l in text[..line_start].lines() {
        let l = l.trim();
        if l.starts_with("[[ops]]") {
            ops_seen += 1;
            table = Some(format!("ops[{}]", ops_seen - 1));
        } else if let Some(name) = l.strip_prefix('[').and_then(|l| l.split(']').next()) {
            let name = name.trim_start_matches('[').trim();
            table = Some(match name.strip_prefix("ops.") {
                Some(rest) if ops_seen > 0 => format!("ops[{}].{rest}", ops_seen - 1),
                _ => name.to_string(),
            });
        }
    }
    Some(match table {
        Some(t) => format!("{t}.{key}"),
        None => key,
    })
}

/// A groom file could not be read, parsed or set up. Displays as
/// `FILE:LINE:COLUMN: KEY: what is wrong`.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct GroomError(Box<GroomErrorDetails>);

/// Where and what a [`GroomError`] is.
#[derive(Debug)]
pub struct GroomErrorDetails {
    /// The groom file.
    pub path: PathBuf,
    /// Line and column (1-based), where the problem is in the file.
    pub line: Option<(usize, usize)>,
    /// The key there, with its table (`roots.count`).
    pub key: Option<String>,
    /// What is wrong.
    pub kind: GroomErrorKind,
}

impl GroomError {
    /// An error in the groom file at `path`.
    pub fn new(
        path: PathBuf,
        line: Option<(usize, usize)>,
        key: Option<String>,
        kind: GroomErrorKind,
    ) -> Self {
        Self(Box::new(GroomErrorDetails {
            path,
            line,
            key,
            kind,
        }))
    }
}

impl std::ops::Deref for GroomError {
    type Target = GroomErrorDetails;
    fn deref(&self) -> &GroomErrorDetails {
        &self.0
    }
}

impl fmt::Display for GroomErrorDetails {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some((line, column)) = self.line {
            write!(f, ":{line}:{column}")?;
        }
        if let Some(key) = &self.key {
            write!(f, ": {key}")?;
        }
        write!(f, ": {}", self.kind)
    }
}

/// What is wrong with a groom.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GroomErrorKind {
    /// The file could not be read.
    #[error("cannot read the groom file: {0}")]
    Io(std::io::Error),
    /// Not valid TOML, an unknown key, or a value of the wrong type.
    #[error("{0}")]
    Syntax(String),
    /// A value that parses but cannot be used.
    #[error("{0}")]
    Invalid(String),
    /// A map that cannot be read or used.
    #[error("{0}")]
    Map(MapError),
    /// The mesh could not be loaded.
    #[error("{0}")]
    Mesh(crate::mesh::MeshError),
    /// The guides file could not be read.
    #[error("{0}")]
    Guides(crate::io::CurvesReadError),
    /// Guides could not be grown.
    #[error("{0}")]
    GuideGrowth(crate::guides::GuideError),
    /// Roots could not be sampled.
    #[error("{0}")]
    Sample(crate::sample::SampleError),
    /// A hair grew values that are not finite numbers.
    #[error("{0}")]
    NotFinite(String),
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<GroomFile, GroomError> {
        GroomSource {
            path: "test.toml".into(),
            text: text.into(),
        }
        .parse()
    }

    const MINIMAL: &str = "[mesh]\npath = \"spot\"\n[roots]\ncount = 1000\n[guides]\ngenerate = { count = 50, length = 0.05 }\n";

    #[test]
    fn minimal_file_takes_defaults() {
        let f = parse(MINIMAL).unwrap();
        assert_eq!(*f.roots.count.get_ref(), 1000);
        assert_eq!(f.interpolation.method.get_ref(), "shepard");
        assert_eq!(*f.finish.points.get_ref(), 16);
        assert!(f.ops.is_empty());
    }

    #[test]
    fn unknown_key_names_file_line_and_key() {
        let err = parse(&format!(
            "{MINIMAL}[[ops]]\nclump = {{ count = 10, rtae = 0.5 }}\n"
        ))
        .unwrap_err()
        .to_string();
        assert!(err.starts_with("test.toml:8:"), "{err}");
        assert!(err.contains("ops[0].clump.rtae"), "{err}");
        assert!(err.contains("unknown field `rtae`"), "{err}");
    }

    #[test]
    fn wrong_type_names_the_key() {
        let err = parse("[mesh]\npath = \"spot\"\n[roots]\ncount = \"many\"\n")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("test.toml:4:9: roots.count:"), "{err}");
        let err = parse(&format!(
            "{MINIMAL}[[ops]]\n[ops.curl]\nradius = 0.01\nturns = [1]\n"
        ))
        .unwrap_err()
        .to_string();
        assert!(
            err.contains(":10:") && err.contains("ops[0].curl.turns"),
            "{err}"
        );
        assert!(err.contains("a map: a number"), "{err}");
    }

    #[test]
    fn unknown_operator_lists_the_operators() {
        let err = parse(&format!("{MINIMAL}[[ops]]\ncrul = {{ radius = 1 }}\n"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("unknown variant `crul`"), "{err}");
        assert!(err.contains("`curl`"), "{err}");
    }

    #[test]
    fn ramps_read_every_form() {
        let f = parse(&format!(
            "{MINIMAL}[[ops]]\nnoise = {{ amplitude = 0.1, ramp = \"smooth\" }}\n[[ops]]\nnoise = {{ amplitude = \"noise:frequency=3\", ramp = [0, 1, 0.5] }}\n"
        ))
        .unwrap();
        let OpSpec::Noise(a) = &f.ops[0] else {
            panic!()
        };
        assert_eq!(a.ramp, Ramp::Smooth);
        let OpSpec::Noise(b) = &f.ops[1] else {
            panic!()
        };
        assert!((b.ramp.at(0.25) - 0.5).abs() < 1e-6);
        assert!((b.ramp.at(1.0) - 0.5).abs() < 1e-6);
        assert_eq!(Ramp::Power(2.0).at(0.5), 0.25);
        assert_eq!(Ramp::Power(0.0).at(0.3), 1.0);
    }

    #[test]
    fn bad_map_is_reported_at_its_line() {
        let source = GroomSource {
            path: "g.toml".into(),
            text: format!("{MINIMAL}[[ops]]\nnoise = {{ amplitude = \"missing.png:r\" }}\n"),
        };
        let f = source.parse().unwrap();
        let OpSpec::Noise(n) = &f.ops[0] else {
            panic!()
        };
        let err = source.map(&n.amplitude).unwrap_err().to_string();
        assert!(err.starts_with("g.toml:8:"), "{err}");
        assert!(err.contains("ops[0].noise.amplitude"), "{err}");
        assert!(err.contains("missing.png"), "{err}");
    }
}
