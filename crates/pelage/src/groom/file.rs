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
//!
//! One file, past 600 lines: the groom file's schema in one place (about 130
//! of its lines are tests).

use super::error::{GroomError, GroomErrorKind};
pub(crate) use super::ops::OpSpec;
pub use super::ops::{ColorSpec, RootToTipSpec};
pub use super::values::{MapText, MapValue};
use super::values::{one, zero};
use crate::io::CurveBasis;
use crate::limits::*;
use crate::settings::{Bound, Rule, SettingsSource};
use serde::Deserialize;
use serde::de::{self, Deserializer};
use toml::Spanned;

fn seed_one() -> u64 {
    1
}
fn one_f32() -> f32 {
    1.0
}

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
    Rule::new(
        "roots.density_scale",
        Bound::at_least(0.0),
        "a density scale",
    ),
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
    /// Parses and checks the text as a groom file (every key known, every
    /// number in its range), loading nothing it names.
    pub fn check_groom(&self) -> Result<(), GroomError> {
        self.parse().map(drop)
    }

    /// Parses the text as a groom file.
    pub(crate) fn parse(&self) -> Result<GroomFile, GroomError> {
        if let Some((place, message)) = self.single_bracket_list(&["ops"]) {
            return Err(GroomError::with(
                self.path.clone(),
                place,
                GroomErrorKind::Syntax(message),
            ));
        }
        let file = self.parse_as()?;
        let mut rules = GROOM_RULES.to_vec();
        rules.extend(super::ops::operator_rules());
        self.check(&rules).map_err(|(place, message)| {
            GroomError::with(
                self.path.clone(),
                place,
                GroomErrorKind::OutOfRange(message),
            )
        })?;
        Ok(file)
    }
}

/// A whole groom file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroomFile {
    /// The surface (absent only when a program gives the mesh as a value,
    /// [`super::GroomInputs`]).
    pub mesh: Option<MeshSection>,
    /// Where hairs grow.
    pub roots: RootsSection,
    /// The guide curves.
    #[serde(default)]
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
    /// Frames of an animated skin (absent: a still groom).
    pub animation: Option<AnimationSection>,
    /// `[simulation]`: how `[animation] mode = "simulate"` moves the
    /// guides.
    pub simulation: Option<SimulationSection>,
    /// Regions of the skin that do not share guides or clumps (absent:
    /// one region).
    pub regions: Option<RegionsSection>,
    /// Each hair's values for a hair shader (absent: none written).
    pub look: Option<LookSection>,
}

/// `[look]`: see [`crate::groom::HairLook`]; the defaults are Cycles'
/// Principled Hair defaults.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LookSection {
    /// Melanin, 0 (white) to 1 (black).
    #[serde(default = "look_melanin")]
    pub melanin: MapValue,
    /// The share of red pheomelanin, 0 to 1.
    #[serde(default = "one")]
    pub melanin_redness: MapValue,
    /// Dye colour, linear RGB, each channel a map.
    #[serde(default = "white")]
    pub tint: [MapValue; 3],
    /// Longitudinal roughness, 0 to 1.
    #[serde(default = "look_roughness")]
    pub roughness: MapValue,
    /// Azimuthal roughness, 0 to 1.
    #[serde(default = "look_roughness")]
    pub radial_roughness: MapValue,
    /// Per-hair variation of melanin, redness and roughnesses, a fraction.
    #[serde(default = "zero")]
    pub jitter: MapValue,
    /// Seed of the variation and of `hair_random`.
    #[serde(default)]
    pub seed: u64,
    /// Write a material reading the values (false: bind your own).
    #[serde(default = "yes")]
    pub material: bool,
}

fn look_melanin() -> MapValue {
    Spanned::new(0..0, MapText::Number(0.8))
}
fn look_roughness() -> MapValue {
    Spanned::new(0..0, MapText::Number(0.3))
}
fn white() -> [MapValue; 3] {
    [one(), one(), one()]
}

/// `[regions]`: the skin split into regions. Hairs take their shape only
/// from guides of their own region and clump only with centres of it; a
/// parting is the two-region case. Exactly one of `map` or `faces`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionsSection {
    /// A map whose value, times `scale` and rounded, is the region id.
    pub map: Option<MapValue>,
    /// Multiplies the map's value before rounding (255 for ids painted as
    /// 8-bit grey levels).
    #[serde(default = "one_f32")]
    pub scale: f32,
    /// The mesh's face sets: `"groups"` (OBJ `g`/`o`) or `"materials"`
    /// (OBJ `usemtl`).
    pub faces: Option<Spanned<String>>,
}

/// `[animation]`: the groom follows an animated skin (the `[mesh]` path:
/// a USD mesh with time-sampled points, a glTF/GLB with animations, or an
/// OBJ/PLY sequence such as `"skin.####.obj"`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnimationSection {
    /// The frames written: `"1-24"`, `"1-48x2"`, `"1,5,9"`.
    pub frames: Spanned<String>,
    /// Frames per second (the output's `timeCodesPerSecond`; glTF clips
    /// are played at this rate, frame 1 at their time 0).
    #[serde(default = "default_fps")]
    pub fps: f64,
    /// The frame whose skin the roots are sampled on and the guides bound
    /// to (default: the first frame).
    pub rest_frame: Option<f64>,
    /// `deform` (grow once, carry with the skin) or `regrow` (regrow every
    /// frame from time-sampled guides).
    #[serde(default)]
    pub mode: AnimationModeName,
    /// The glTF animation to play, by name (default: the file's first).
    pub clip: Option<Spanned<String>>,
    /// Shutter offsets in frames, e.g. `[-0.25, 0.25]`: every frame is
    /// also written at these sub-frame times (motion blur).
    #[serde(default)]
    pub motion_blur: Vec<f64>,
    /// Write per-point velocities (deform grooms), for motion blur from
    /// one sample.
    #[serde(default = "default_true")]
    pub velocities: bool,
}

fn default_true() -> bool {
    true
}

fn default_fps() -> f64 {
    24.0
}

/// `[simulation]`: the guide strands' settings (docs/dynamics.md).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSection {
    /// Substeps a frame.
    #[serde(default = "default_substeps")]
    pub substeps: u32,
    /// Follow, bend and length passes a substep.
    #[serde(default = "default_one")]
    pub iterations: u32,
    /// Gravity, scene units per second² (default: 9.81 down −Y, for a
    /// skin in metres).
    #[serde(default = "default_gravity")]
    pub gravity: [f32; 3],
    /// Velocity decay rate, per second.
    #[serde(default = "default_damping")]
    pub damping: f32,
    /// Bend stiffness, 0 to 1.
    #[serde(default = "default_bend")]
    pub bend: f32,
    /// Pull toward the groomed guide, 0 to 1.
    #[serde(default = "default_follow")]
    pub follow: f32,
    /// Wind velocity, scene units per second.
    #[serde(default)]
    pub wind: [f32; 3],
    /// Air drag toward the wind, per second.
    #[serde(default)]
    pub drag: f32,
    /// Collide with the skin.
    #[serde(default = "default_true")]
    pub collide: bool,
    /// How far from the skin guides are kept (default: 0.2 % of the
    /// mesh's size).
    pub thickness: Option<Spanned<f32>>,
    /// Friction against the skin, 0 to 1.
    #[serde(default = "default_friction")]
    pub friction: f32,
    /// Frames simulated at the first frame's pose before it, for the
    /// guides to settle.
    #[serde(default = "default_preroll")]
    pub preroll: u32,
    /// A `.usdc` file (relative to the groom file) the simulated guides
    /// are kept in: read when it holds this simulation, else simulated
    /// and written, so farm tasks simulate once.
    pub cache: Option<Spanned<String>>,
}

fn default_substeps() -> u32 {
    4
}
fn default_one() -> u32 {
    1
}
fn default_gravity() -> [f32; 3] {
    [0.0, -9.81, 0.0]
}
fn default_damping() -> f32 {
    1.0
}
fn default_bend() -> f32 {
    0.3
}
fn default_follow() -> f32 {
    0.05
}
fn default_friction() -> f32 {
    0.3
}
fn default_preroll() -> u32 {
    12
}

/// `[animation] mode`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AnimationModeName {
    /// Grow once at rest; carry every frame.
    #[default]
    Deform,
    /// Regrow every frame from animated guides.
    Regrow,
    /// Simulate the guides, regrow every frame from them.
    Simulate,
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
    /// A PLY mesh (the groom editor's `NAME.layers.ply`) whose vertex
    /// properties become the mesh's paint layers (`vertex:NAME` maps),
    /// after subdivision; it must have the same vertex count.
    pub layers: Option<Spanned<String>>,
    /// Fur takes the mesh's base colour texture (a glTF material's
    /// `baseColorTexture`) at its root when `[finish]` gives no colour.
    #[serde(default = "default_true")]
    pub base_color: bool,
}

impl MeshSection {
    /// The mesh it names (`"spot"`: the embedded one, otherwise a file
    /// relative to `folder`), subdivided as asked, with its paint layers.
    pub fn load(&self, folder: &std::path::Path) -> Result<crate::Mesh, crate::mesh::MeshError> {
        self.with_layers(self.load_mesh(folder)?, folder)
    }

    /// The mesh it names, subdivided, without `layers`.
    pub fn load_mesh(
        &self,
        folder: &std::path::Path,
    ) -> Result<crate::Mesh, crate::mesh::MeshError> {
        let mesh = match self.path.get_ref().as_str() {
            "spot" => crate::assets::spot(),
            path => crate::Mesh::load(folder.join(path))?,
        };
        match self.subdivide {
            0 => Ok(mesh),
            n => mesh.subdivided_within_limits(n),
        }
    }

    /// `mesh` with the paint layers of `layers` (none: as it is).
    pub fn with_layers(
        &self,
        mut mesh: crate::Mesh,
        folder: &std::path::Path,
    ) -> Result<crate::Mesh, crate::mesh::MeshError> {
        let Some(layers) = &self.layers else {
            return Ok(mesh);
        };
        use crate::mesh::{MeshError, MeshErrorKind};
        let path = folder.join(layers.get_ref());
        let name = path.display().to_string();
        let other_mesh = |count: u64| {
            MeshError::whole(
                &name,
                MeshErrorKind::Inconsistent(format!(
                    "the paint layers have {count} vertices where the mesh has {}: they were painted on another mesh (or another subdivision)",
                    mesh.vertex_count()
                )),
            )
        };
        let io = |e| MeshError::whole(&name, MeshErrorKind::Io(e));
        crate::io::check_input(&path, "a paint layers file (PLY)").map_err(io)?;
        // The header's count first: a file painted on another mesh is
        // refused before its vertices are read (30 M of them took 7.5 GB).
        let declared = crate::io::ply_element_count(&path, "vertex").map_err(io)?;
        if declared != mesh.vertex_count() as u64 {
            return Err(other_mesh(declared));
        }
        let bytes = std::fs::read(&path).map_err(io)?;
        let painted = crate::mesh::ply::vertex_layers(&name, &bytes)?;
        if painted.count != mesh.vertex_count() {
            return Err(other_mesh(painted.count as u64));
        }
        for (layer, values) in painted.layers {
            mesh = mesh.with_vertex_attribute(layer, values)?;
        }
        Ok(mesh)
    }
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
    /// A map the density is multiplied by (a grooming session's painted
    /// density layer).
    #[serde(default = "one")]
    pub density_scale: MapValue,
    /// Seed of every random number in the groom.
    #[serde(default = "seed_one")]
    pub seed: u64,
    /// Number of parts (default: one per 100,000 hairs).
    pub parts: Option<Spanned<u32>>,
    /// `stable` (default) or `sequential` hair ids.
    #[serde(default, deserialize_with = "hair_ids")]
    pub ids: super::spec::HairIds,
    /// `random` (default) or `blue-noise` roots.
    #[serde(default, deserialize_with = "root_distribution")]
    pub distribution: super::spec::RootDistribution,
}

fn hair_ids<'de, D: Deserializer<'de>>(d: D) -> Result<super::spec::HairIds, D::Error> {
    let s = String::deserialize(d)?;
    super::spec::HairIds::parse(&s).ok_or_else(|| {
        de::Error::custom(format!(
            "unknown ids {s:?}; use \"stable\" (hairs keep their ids and roots as the count changes) or \"sequential\""
        ))
    })
}

fn root_distribution<'de, D: Deserializer<'de>>(
    d: D,
) -> Result<super::spec::RootDistribution, D::Error> {
    let s = String::deserialize(d)?;
    super::spec::RootDistribution::parse(&s).ok_or_else(|| {
        de::Error::custom(format!(
            "unknown distribution {s:?}; use \"random\" or \"blue-noise\""
        ))
    })
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

impl Default for GuidesSection {
    /// No guides named: a program gives them as a value
    /// ([`super::GroomInputs`]).
    fn default() -> Self {
        Self {
            file: None,
            tolerance: default_tolerance(),
            generate: None,
            points: default_guide_points(),
        }
    }
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
    #[serde(default)]
    pub method: InterpolationKind,
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

/// `[interpolation] method`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum InterpolationKind {
    /// Shepard's inverse-distance weights over the k nearest guides.
    #[default]
    Shepard,
    /// Furtility's style mesh.
    #[serde(alias = "style_mesh")]
    StyleMesh,
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
            method: InterpolationKind::default(),
            k: default_k(),
            power: default_power(),
            radius: None,
            split_shared: false,
        }
    }
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
    /// Push hair points out of the skin after the operators (default: on
    /// for animated grooms, off for still ones).
    pub outside_skin: Option<bool>,
    /// How far above the skin `outside_skin` keeps points (default: a
    /// thousandth of the mesh's size).
    pub skin_gap: Option<f64>,
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
        ramp: None,
        jitter: None,
        seed: None,
        mask: None,
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
            outside_skin: None,
            skin_gap: None,
        }
    }
}

/// `[output]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    /// Output file relative to the groom file (default: the groom file's
    /// name with `.usdc`: binary USD).
    pub path: Option<String>,
    /// Also write the skin mesh (USD, Alembic).
    #[serde(default)]
    pub with_mesh: bool,
    /// Also write the guide curves (USD `purpose = "guide"`, Alembic
    /// `groom_guide`); still grooms only.
    #[serde(default)]
    pub guides: Option<Spanned<bool>>,
    /// `catmull-rom` (default) or `linear`.
    #[serde(default)]
    pub basis: CurveBasis,
    /// The share of the hairs written (a preview that stays true to the
    /// groom): see [`crate::groom::RootsSpec::fraction`].
    pub fraction: Option<Spanned<f64>>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::groom::GroomError;
    use crate::groom::ramp::Ramp;
    use crate::settings::SettingsSource;

    fn parse(text: &str) -> Result<GroomFile, GroomError> {
        SettingsSource {
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
        assert_eq!(f.interpolation.method, InterpolationKind::Shepard);
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
    fn bad_enum_values_name_line_key_and_accepted_values() {
        let err = parse(&format!(
            "{MINIMAL}[interpolation]\nmethod = \"shepherd\"\n"
        ))
        .unwrap_err()
        .to_string();
        assert!(
            err.starts_with("test.toml:8:10: interpolation.method: unknown variant `shepherd`"),
            "{err}"
        );
        assert!(
            err.contains("`shepard`") && err.contains("`style-mesh`"),
            "{err}"
        );
        let err = parse(&format!("{MINIMAL}[output]\nbasis = \"bspline\"\n"))
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("test.toml:8:9: output.basis: "), "{err}");
        assert!(
            err.contains("`linear`") && err.contains("`catmull-rom`"),
            "{err}"
        );
        let f = parse(&format!(
            "{MINIMAL}[interpolation]\nmethod = \"style_mesh\"\n"
        ))
        .unwrap();
        assert_eq!(f.interpolation.method, InterpolationKind::StyleMesh);
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
        assert_eq!(a.ramp, Some(Ramp::Smooth));
        let OpSpec::Noise(b) = &f.ops[1] else {
            panic!()
        };
        let ramp = b.ramp.as_ref().unwrap();
        assert!((ramp.at(0.25) - 0.5).abs() < 1e-6);
        assert!((ramp.at(1.0) - 0.5).abs() < 1e-6);
        assert_eq!(Ramp::Power(2.0).at(0.5), 0.25);
        assert_eq!(Ramp::Power(0.0).at(0.3), 1.0);
    }

    #[test]
    fn bad_map_is_reported_at_its_line() {
        let source = SettingsSource {
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

#[cfg(test)]
mod docs_tests {
    use super::SimulationSection;
    use crate::docs_tests::{documented_default, documented_number};

    #[test]
    fn the_simulation_table_says_the_defaults_a_groom_file_gets() {
        let s: SimulationSection = toml::from_str("").unwrap();
        let page = "groom-format.md";
        let heading = "### `[simulation]`";
        let number = |key: &str| documented_number(page, heading, key);
        assert_eq!(number("substeps"), s.substeps as f32);
        assert_eq!(number("iterations"), s.iterations as f32);
        assert_eq!(number("damping"), s.damping);
        assert_eq!(number("bend"), s.bend);
        assert_eq!(number("follow"), s.follow);
        assert_eq!(number("friction"), s.friction);
        assert_eq!(number("preroll"), s.preroll as f32);
        assert_eq!(
            documented_default(page, heading, "collide"),
            s.collide.to_string()
        );
    }
}
