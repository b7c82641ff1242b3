//! Shell scene files (TOML, docs/shells-format.md): what `pelage shells`
//! draws — the mesh and its fur colour, the shell layers and their texture,
//! curl (Silva Eq. 4), clumping (Eq. 5), shading (Eq. 6 or Banisch's
//! stages), droplets over time with drying, light and camera.
//!
//! Errors are [`SceneError`]s: `FILE:LINE:COL: KEY: what`; names (texture
//! style, shading, topology, solver, coupling) are serde enums, so an
//! unknown one lists the accepted names.
//!
//! One file, past 600 lines: a section-by-section reading of the scene file
//! (about 190 of its lines are tests).

use super::error::{SceneError, SceneErrorKind};
use super::math::{ClumpParams, Coupling, CurlParams, KajiyaKay, ShadingMode};
use super::scene_file::{
    CouplingName, DropletsSection, DynamicsSection, FurSection, RadiusText, SceneFile, SolverName,
    TextureSection,
};
use super::textures::{ShellTextureParams, TextureStyle};
use super::wetness::{
    Droplet, DropletStyle, WetnessMask, droplets_from_image, droplets_on_mesh, mask_coordinates,
};
use crate::Mesh;
use crate::dynamics::{DynamicsParams, Solver, Topology, Wind};
use crate::limits::*;
use crate::settings::{Bound, Rule, SettingsSource};
use glam::{Vec2, Vec3};
use std::f32::consts::TAU;
use std::path::Path;

/// The shell layers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FurSettings {
    /// Number of layers N.
    pub layers: u32,
    /// Shell length `L0` in world units.
    pub length: f32,
    /// How many times the shell texture repeats across the UV square.
    pub tiles: f32,
    /// Draw only the skin and layers that face the camera.
    pub cull_back: bool,
}

/// Shading parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingSettings {
    /// Which stage of shading.
    pub mode: ShadingMode,
    /// Kajiya-Kay's specular colour, exponent and `K_shadow`.
    pub kajiya_kay: KajiyaKay,
}

/// A camera placed by hand; what is not given is framed on the mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneCamera {
    /// Where the camera is (`None`: backed off until the mesh fits).
    pub eye: Option<Vec3>,
    /// What it looks at (`None`: the centre of the mesh).
    pub target: Option<Vec3>,
    /// Vertical field of view, degrees.
    pub fov_y_degrees: f32,
}

/// The object shaken back and forth, then still: the skin is offset by
/// `amplitude · sin(2π f t)` for `t < duration`, whole periods only.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shake {
    /// Largest offset.
    pub amplitude: Vec3,
    /// Shakes per second.
    pub frequency: f32,
    /// How long it shakes (rounded to whole periods).
    pub duration: f32,
}

impl Shake {
    /// The skin's offset at time `t`.
    pub fn offset(&self, t: f32) -> Vec3 {
        let periods = (self.duration * self.frequency).round();
        if t < 0.0 || t * self.frequency >= periods {
            return Vec3::ZERO;
        }
        self.amplitude * (TAU * self.frequency * t).sin()
    }
}

/// Moving fur: the mass-spring system the shells follow.
#[derive(Debug, Clone)]
pub struct DynamicsSettings {
    /// Which masses and springs.
    pub topology: Topology,
    /// How to step.
    pub solver: Solver,
    /// Steps per frame.
    pub steps_per_frame: u32,
    /// How the tips bend the layers.
    pub coupling: Coupling,
    /// Masses, springs and forces.
    pub params: DynamicsParams,
    /// The object shaken, if at all.
    pub shake: Option<Shake>,
    /// Step on the GPU (explicit solver only): the renderer then reads the
    /// tips where they are computed, with no copy through the CPU.
    pub gpu: bool,
}

impl Default for DynamicsSettings {
    /// What an empty `[dynamics]` section gives: spring-sticks, implicit
    /// (30 CG iterations), two steps a frame, bent layers (k = 2).
    fn default() -> Self {
        Self {
            topology: Topology::SpringSticks,
            solver: Solver::Implicit { iterations: 30 },
            steps_per_frame: 2,
            coupling: Coupling::Bent { exponent: 2.0 },
            params: DynamicsParams::default(),
            shake: None,
            gpu: false,
        }
    }
}

/// Fins (Lengyel et al. 2001): quads on the mesh's edges, drawn where an
/// edge is seen edge-on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FinSettings {
    /// Opacity of a fin seen exactly edge-on.
    pub opacity: f32,
    /// `|n · e|` at which a fin has faded out.
    pub width: f32,
}

/// Level of detail by projected size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LodSettings {
    /// The largest spacing between layers on screen, pixels.
    pub max_gap_px: f32,
    /// Never fewer layers than this.
    pub min_layers: u32,
}

/// A droplet and when it falls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimedDroplet {
    /// Seconds into the sequence.
    pub time: f32,
    /// The droplet.
    pub droplet: Droplet,
}

/// A shell scene, loaded and ready to draw.
#[derive(Debug)]
pub struct ShellScene {
    /// The skin.
    pub mesh: Mesh,
    /// The fur colour texture (sRGB), read at the mesh's UVs.
    pub color: image::RgbaImage,
    /// The layers.
    pub fur: FurSettings,
    /// The shell texture.
    pub texture: ShellTextureParams,
    /// Curl (world units).
    pub curl: CurlParams,
    /// Clumping; `None` when off.
    pub clump: Option<ClumpParams>,
    /// Shading.
    pub shading: ShadingSettings,
    /// Direction towards the light, if fixed (else a key light beside the
    /// camera).
    pub light: Option<Vec3>,
    /// Camera, if placed (else framed automatically).
    pub camera: Option<SceneCamera>,
    /// Wetness mask resolution.
    pub wetness_resolution: u32,
    /// How fast wetness decays, per second (0: never dries).
    pub drying_rate: f32,
    /// Every droplet, in time order.
    pub droplets: Vec<TimedDroplet>,
    /// Frames of a sequence (`--frames` overrides).
    pub frames: u32,
    /// Frames per second of a sequence.
    pub fps: f32,
    /// Moving fur, if the scene has a `[dynamics]` section.
    pub dynamics: Option<DynamicsSettings>,
    /// Fins, if on.
    pub fins: Option<FinSettings>,
    /// Level of detail, if on.
    pub lod: Option<LodSettings>,
    /// The skinned character and its clip, when `[animation] clip` names
    /// one; [`Self::mesh`] is then its pose at time 0.
    pub animation: Option<super::ShellAnimation>,
}

impl ShellScene {
    /// Reads a scene file.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let source = SettingsSource::read(path).map_err(|e| {
            SceneError::new(
                path.to_path_buf(),
                Default::default(),
                SceneErrorKind::Io(e),
            )
        })?;
        Self::from_source(&source)
    }

    /// The scene without a file: spot with its texture, dry straight fur.
    pub fn spot() -> Self {
        Self::from_source(&SettingsSource {
            path: "<spot>".into(),
            text: String::new(),
        })
        .expect("the default scene is valid")
    }

    /// Checks a scene file's text without building the scene (no mesh or
    /// image is read): its syntax, keys and the range of every number.
    pub fn check_text(source: &SettingsSource) -> Result<(), SceneError> {
        Self::parse(source).map(|_| ())
    }

    fn parse(source: &SettingsSource) -> Result<SceneFile, SceneError> {
        if let Some((place, message)) = source.single_bracket_list(&["droplets"]) {
            return Err(SceneError::new(
                source.path.clone(),
                place,
                SceneErrorKind::Syntax(message),
            ));
        }
        let file: SceneFile = source.deserialize().map_err(|(place, message)| {
            SceneError::new(source.path.clone(), place, SceneErrorKind::Syntax(message))
        })?;
        source.check(SCENE_RULES).map_err(|(place, message)| {
            SceneError::new(
                source.path.clone(),
                place,
                SceneErrorKind::OutOfRange(message),
            )
        })?;
        Ok(file)
    }

    /// Builds a scene from a file's text (relative paths against its folder).
    pub fn from_source(source: &SettingsSource) -> Result<Self, SceneError> {
        let file = Self::parse(source)?;
        let (mesh, color, animation) = mesh_and_color(source, &file)?;
        let (lo, hi) = mesh.bounds();
        let fur = fur_settings(source, &file.fur, (hi - lo).length())?;
        let length = fur.length;
        let texture = texture_params(source, &file.texture, fur.layers)?;
        // Curl radius is written as a fraction of the shell length.
        let curl = CurlParams {
            radius: file.curl.radius.unwrap_or(0.0) * length,
            frequency: TAU * file.curl.turns.unwrap_or(2.0),
        };
        let clump = (file.clump.enabled != Some(false)).then(|| ClumpParams {
            w: file.clump.w.unwrap_or(0.6).clamp(0.0, 1.0),
            strength: file.clump.strength.unwrap_or(4.0).max(0.0),
        });
        let mode = file.shading.mode.unwrap_or(ShadingMode::KajiyaKay);
        let shading = ShadingSettings {
            mode,
            kajiya_kay: KajiyaKay {
                specular: Vec3::from(file.shading.specular.unwrap_or([0.12, 0.11, 0.1])),
                exponent: file.shading.exponent.unwrap_or(30.0),
                k_shadow: file.shading.shadow.unwrap_or(2.0).max(1.0),
            },
        };
        let wetness_resolution =
            count_in(source, &file.wetness.resolution, 8..=4096, "texels", 256)?;

        let droplets = droplets(source, &file.droplets, &mesh)?;
        let dynamics = file
            .dynamics
            .as_ref()
            .map(|d| dynamics_settings(source, d))
            .transpose()?;
        Ok(Self {
            mesh,
            color,
            fur,
            texture,
            curl,
            clump,
            shading,
            light: file.light.map(|l| Vec3::from(l).normalize_or(Vec3::Y)),
            camera: file.camera.map(|c| SceneCamera {
                eye: c.eye.map(Vec3::from),
                target: c.target.map(Vec3::from),
                fov_y_degrees: c.fov.unwrap_or(30.0),
            }),
            wetness_resolution,
            drying_rate: file.wetness.drying_rate.unwrap_or(0.0).max(0.0),
            droplets,
            frames: file.animation.frames.unwrap_or(1).max(1),
            fps: file.animation.fps.unwrap_or(12.0).max(1e-3),
            dynamics,
            fins: file
                .fins
                .as_ref()
                .filter(|f| f.enabled != Some(false))
                .map(|f| FinSettings {
                    opacity: f.opacity.unwrap_or(1.0),
                    width: f.width.unwrap_or(0.15),
                }),
            lod: file
                .lod
                .as_ref()
                .filter(|l| l.enabled != Some(false))
                .map(|l| {
                    Ok::<_, SceneError>(LodSettings {
                        max_gap_px: l.max_gap.unwrap_or(0.75),
                        min_layers: count_in(source, &l.min_layers, 1..=256, "layers", 4)?,
                    })
                })
                .transpose()?,
            animation,
        })
    }

    /// A timeline of the wetness mask: droplets fall at their times, the
    /// mask dries in between.
    pub fn wetness_timeline(&self) -> WetnessTimeline<'_> {
        WetnessTimeline {
            scene: self,
            mask: WetnessMask::dry_mask(self.wetness_resolution, self.wetness_resolution),
            time: 0.0,
            next: 0,
        }
    }
}

/// The documented range of every numeric scene setting
/// (docs/shells-format.md, docs/limits.md), checked when the file is read.
const SCENE_RULES: &[Rule] = &[
    Rule::new(
        "mesh.subdivide",
        Bound::Within(0.0, MAX_SUBDIVIDE as f64),
        "each step makes 4 triangles of 1",
    ),
    Rule::new("fur.tiles", Bound::more_than(0.0), "texture repeats"),
    Rule::new(
        "texture.density",
        Bound::Within(0.0, 1.0),
        "guard hairs per texel: each is a blade drawn through every layer",
    ),
    Rule::new(
        "texture.thickness",
        Bound::Above(0.0, 64.0),
        "a radius in texels: each blade stamps a disk this wide on every layer",
    ),
    Rule::new(
        "texture.length_variance",
        Bound::Within(0.0, 1.0),
        "a fraction of the length",
    ),
    Rule::new(
        "texture.bend",
        Bound::at_least(0.0),
        "the exponent's bending",
    ),
    Rule::new(
        "texture.undercoat_ratio",
        Bound::Within(0.0, 100.0),
        "hairs per guard hair",
    ),
    Rule::new(
        "texture.undercoat_length",
        Bound::Within(0.0, 1.0),
        "a fraction of the length",
    ),
    Rule::new(
        "curl.radius",
        Bound::at_least(0.0),
        "a fraction of the shell length",
    ),
    Rule::new("clump.w", Bound::Within(0.0, 1.0), "a blend"),
    Rule::new("clump.strength", Bound::at_least(0.0), "a squeeze"),
    Rule::new("shading.specular", Bound::at_least(0.0), "a colour"),
    Rule::new("shading.exponent", Bound::at_least(0.0), "a Phong exponent"),
    Rule::new(
        "shading.shadow",
        Bound::at_least(1.0),
        "K_shadow of γ = (K_shadow − 1 + h) / K_shadow",
    ),
    Rule::new("wetness.drying_rate", Bound::at_least(0.0), "per second"),
    Rule::new(
        "droplets.time",
        Bound::at_least(0.0),
        "seconds into the sequence",
    ),
    Rule::new(
        "droplets.count",
        Bound::Within(1.0, MAX_DROPLETS as f64),
        "pelage's droplet limit",
    ),
    Rule::new(
        "droplets.radius",
        Bound::more_than(0.0),
        "mask units, the UV square is 1",
    ),
    Rule::new(
        "droplets.spacing",
        Bound::at_least(1e-3),
        "mask units: a grid of at most a million droplets over the mask",
    ),
    Rule::new("droplets.wetness", Bound::Within(0.0, 1.0), "ρ_drop"),
    Rule::new(
        "camera.fov",
        Bound::Above(0.0, 179.0),
        "vertical field of view, degrees",
    ),
    Rule::new(
        "animation.frames",
        Bound::Within(1.0, MAX_FRAMES as f64),
        "pelage's frame limit",
    ),
    Rule::new("animation.fps", Bound::more_than(0.0), "frames per second"),
    Rule::new("fins.opacity", Bound::Within(0.0, 1.0), "an opacity"),
    Rule::new(
        "fins.width",
        Bound::Above(0.0, 1.0),
        "|n · e| at which a fin fades out",
    ),
    Rule::new(
        "lod.max_gap",
        Bound::more_than(0.0),
        "pixels between layers on screen",
    ),
    Rule::new(
        "dynamics.substeps",
        Bound::Within(0.0, MAX_DYNAMICS_STEPS as f64),
        "substeps per step, 0: automatic",
    ),
    Rule::new(
        "dynamics.iterations",
        Bound::Within(1.0, MAX_SOLVER_ITERATIONS as f64),
        "conjugate-gradient iterations",
    ),
    Rule::new(
        "dynamics.steps_per_frame",
        Bound::Within(1.0, MAX_DYNAMICS_STEPS as f64),
        "steps per frame",
    ),
    Rule::new(
        "dynamics.exponent",
        Bound::at_least(1.0),
        "k of Banisch Eq. 4",
    ),
    Rule::new(
        "dynamics.mass",
        Bound::more_than(0.0),
        "a tip without mass cannot be moved by a force",
    ),
    Rule::new(
        "dynamics.stiffness",
        Bound::at_least(0.0),
        "a spring constant",
    ),
    Rule::new(
        "dynamics.lateral_stiffness",
        Bound::at_least(0.0),
        "a spring constant",
    ),
    Rule::new(
        "dynamics.damping",
        Bound::at_least(0.0),
        "a damping constant",
    ),
    Rule::new("dynamics.drag", Bound::at_least(0.0), "air drag"),
    Rule::new(
        "dynamics.restoring",
        Bound::at_least(0.0),
        "w of Banisch Eq. 5",
    ),
    Rule::new(
        "dynamics.wind.gust",
        Bound::at_least(0.0),
        "a fraction of the mean",
    ),
    Rule::new(
        "dynamics.wind.gust_frequency",
        Bound::at_least(0.0),
        "per second",
    ),
    Rule::new("dynamics.wind.turbulence", Bound::at_least(0.0), "a speed"),
    Rule::new(
        "dynamics.wind.scale",
        Bound::more_than(0.0),
        "features per unit length",
    ),
    Rule::new(
        "dynamics.shake.frequency",
        Bound::more_than(0.0),
        "per second",
    ),
    Rule::new("dynamics.shake.duration", Bound::at_least(0.0), "seconds"),
];

/// An error of `kind` at a span of the scene file.
fn invalid(
    source: &SettingsSource,
    kind: impl FnOnce(String) -> SceneErrorKind,
    span: std::ops::Range<usize>,
    message: String,
) -> SceneError {
    SceneError::at(source, span, kind(message))
}

/// A count that must lie in `range`: `default` when not given, an error
/// at its place when outside ("0 layers: use 1 to 256").
fn count_in(
    source: &SettingsSource,
    value: &Option<toml::Spanned<u32>>,
    range: std::ops::RangeInclusive<u32>,
    unit: &str,
    default: u32,
) -> Result<u32, SceneError> {
    match value {
        None => Ok(default),
        Some(v) if range.contains(v.get_ref()) => Ok(*v.get_ref()),
        Some(v) => Err(invalid(
            source,
            SceneErrorKind::OutOfRange,
            v.span(),
            format!(
                "{} {unit}: use {} to {}",
                v.get_ref(),
                range.start(),
                range.end()
            ),
        )),
    }
}

/// An image at `path` (written at `span`) that cannot be read.
fn unreadable_image(
    source: &SettingsSource,
    span: std::ops::Range<usize>,
    path: std::path::PathBuf,
) -> impl FnOnce(image::ImageError) -> SceneError + '_ {
    move |error| SceneError::at(source, span, SceneErrorKind::Image { path, error })
}

/// `[mesh]` (Spot by default) and `color`: the skin, which must have UVs,
/// and the fur colour texture.
fn mesh_and_color(
    source: &SettingsSource,
    file: &SceneFile,
) -> Result<(Mesh, image::RgbaImage, Option<super::ShellAnimation>), SceneError> {
    let mut animation = None;
    let (mesh, default_color) = match (&file.mesh, &file.animation.clip) {
        (None, None) => (crate::assets::spot(), Some(spot_color())),
        (None, Some(clip)) => {
            return Err(invalid(
                source,
                SceneErrorKind::Conflict,
                clip.span(),
                "a clip is played by a skinned mesh: add [mesh] path = \"character.gltf\"".into(),
            ));
        }
        (Some(section), Some(clip)) => {
            if section.path.get_ref() == "spot" {
                return Err(invalid(
                    source,
                    SceneErrorKind::Conflict,
                    clip.span(),
                    "a clip is played from a glTF or GLB skin; the embedded spot has none".into(),
                ));
            }
            let path = source.folder().join(section.path.get_ref());
            let skinned = super::ShellAnimation::load(&path, clip.get_ref(), section.subdivide)
                .map_err(|e| {
                    // A clip the file lacks is the clip's fault.
                    let span = match e.kind() {
                        crate::mesh::MeshErrorKind::Clip(_) => clip.span(),
                        _ => section.path.span(),
                    };
                    SceneError::at(source, span, SceneErrorKind::Mesh(e))
                })?;
            let mesh = skinned.mesh_at(0.0).map_err(|e| {
                SceneError::at(source, section.path.span(), SceneErrorKind::Mesh(e))
            })?;
            animation = Some(skinned);
            (mesh, None)
        }
        (Some(section), None) => {
            let mesh = section.load(source.folder()).map_err(|e| {
                SceneError::at(source, section.path.span(), SceneErrorKind::Mesh(e))
            })?;
            let spot = section.path.get_ref() == "spot";
            (mesh, spot.then(spot_color))
        }
    };
    if !mesh.has_uvs() {
        let span = file.mesh.as_ref().map_or(0..0, |m| m.path.span());
        return Err(invalid(
            source,
            SceneErrorKind::Missing,
            span,
            format!(
                "the mesh {} has no UVs; shell fur reads its textures and wetness mask at the mesh's UVs",
                mesh.name()
            ),
        ));
    }
    let color = match &file.color {
        Some(path) => {
            let full = source.folder().join(path.get_ref());
            crate::map::open_image(&full)
                .map_err(unreadable_image(source, path.span(), full.clone()))?
                .to_rgba8()
        }
        None => default_color.unwrap_or_else(|| {
            image::RgbaImage::from_pixel(1, 1, image::Rgba([150, 110, 70, 255]))
        }),
    };
    Ok((mesh, color, animation))
}

/// `[fur]`: layers (1 to 256) and length (by default 2.5 % of the mesh's
/// diagonal).
fn fur_settings(
    source: &SettingsSource,
    fur: &FurSection,
    diagonal: f32,
) -> Result<FurSettings, SceneError> {
    let layers = count_in(source, &fur.layers, 1..=256, "layers", 16)?;
    let length = match &fur.length {
        Some(l) if !(l.get_ref().is_finite() && *l.get_ref() > 0.0) => {
            return Err(invalid(
                source,
                SceneErrorKind::OutOfRange,
                l.span(),
                format!("{} is not a positive length", l.get_ref()),
            ));
        }
        Some(l) => *l.get_ref(),
        None => 0.025 * diagonal,
    };
    let fur = FurSettings {
        layers,
        length,
        tiles: fur.tiles.unwrap_or(8.0).max(1e-3),
        cull_back: fur.cull_back.unwrap_or(false),
    };

    Ok(fur)
}

/// `[texture]`: the shell texture's blades and undercoat.
fn texture_params(
    source: &SettingsSource,
    t: &TextureSection,
    layers: u32,
) -> Result<ShellTextureParams, SceneError> {
    let defaults = ShellTextureParams::default();
    let style = t.style.unwrap_or(TextureStyle::Blades);
    let resolution = count_in(
        source,
        &t.resolution,
        8..=4096,
        "texels",
        defaults.resolution,
    )?;
    let texels = u64::from(resolution).pow(2) * u64::from(layers);
    if texels > MAX_SHELL_TEXELS {
        let span = t.resolution.as_ref().map_or(0..0, |r| r.span());
        return Err(invalid(
            source,
            SceneErrorKind::OutOfRange,
            span,
            format!(
                "{resolution}² texels × {layers} layers is {} texels; pelage's limit is {} (4 bytes each): lower the resolution or the layers (docs/limits.md)",
                grouped(texels as f64),
                grouped(MAX_SHELL_TEXELS as f64)
            ),
        ));
    }
    let texture = ShellTextureParams {
        resolution,
        layers,
        density: t.density.unwrap_or(defaults.density),
        thickness: t.thickness.unwrap_or(defaults.thickness),
        length_variance: t.length_variance.unwrap_or(defaults.length_variance),
        lean: t.lean.unwrap_or(defaults.lean),
        bend: t.bend.unwrap_or(defaults.bend),
        undercoat_ratio: t.undercoat_ratio.unwrap_or(defaults.undercoat_ratio),
        undercoat_length: t.undercoat_length.unwrap_or(defaults.undercoat_length),
        style,
        seed: t.seed.unwrap_or(defaults.seed),
    };

    Ok(texture)
}

/// `[[droplets]]`: every droplet, in time order.
fn droplets(
    source: &SettingsSource,
    sections: &[DropletsSection],
    mesh: &Mesh,
) -> Result<Vec<TimedDroplet>, SceneError> {
    let mut droplets = Vec::new();
    for (i, d) in sections.iter().enumerate() {
        let (radius_min, radius_max) = match d.radius {
            Some(RadiusText::One(r)) => (r, r),
            Some(RadiusText::Range([a, b])) => (a.min(b), a.max(b)),
            None => (0.015, 0.03),
        };
        let style = DropletStyle {
            radius_min,
            radius_max,
            wetness: d.wetness.unwrap_or(1.0).clamp(0.0, 1.0),
        };
        let seed = d.seed.unwrap_or(i as u64 + 1);
        let drops: Vec<Droplet> = match (d.at, d.count, &d.image) {
            (Some(uv), None, None) => vec![Droplet {
                centre: mask_coordinates(Vec2::from(uv)),
                radius: radius_max,
                wetness: style.wetness,
            }],
            (None, Some(count), None) => {
                droplets_on_mesh(mesh, count, style, seed).map_err(|error| {
                    SceneError::at(source, 0..0, SceneErrorKind::Droplets { index: i, error })
                })?
            }
            (None, None, Some(path)) => {
                let full = source.folder().join(path.get_ref());
                let image = crate::map::open_image(&full)
                    .map_err(unreadable_image(source, path.span(), full.clone()))?
                    .to_luma32f();
                let (w, h) = (image.width() as f32, image.height() as f32);
                let brightness = |p: Vec2| {
                    let x = (p.x * w).clamp(0.0, w - 1.0) as u32;
                    let y = (p.y * h).clamp(0.0, h - 1.0) as u32;
                    image.get_pixel(x, y).0[0]
                };
                // The default spacing follows the radius, kept to the
                // coarsest grid `spacing` itself may ask for.
                let spacing = d.spacing.unwrap_or(radius_max.max(1e-3));
                droplets_from_image(brightness, spacing, style, seed)
            }
            _ => {
                let span = d.image.as_ref().map_or(0..0, |p| p.span());
                return Err(invalid(
                    source,
                    SceneErrorKind::Conflict,
                    span,
                    format!(
                        "droplets[{i}]: give exactly one of `at = [u, v]`, `count = N` or `image = \"FILE\"`"
                    ),
                ));
            }
        };
        droplets.extend(drops.into_iter().map(|droplet| TimedDroplet {
            time: d.time.max(0.0),
            droplet,
        }));
    }
    droplets.sort_by(|a, b| a.time.total_cmp(&b.time));

    Ok(droplets)
}

/// `[dynamics]`: the mass-spring system the shells follow.
fn dynamics_settings(
    source: &SettingsSource,
    d: &DynamicsSection,
) -> Result<DynamicsSettings, SceneError> {
    let topology = d.topology.unwrap_or(Topology::SpringSticks);
    let solver = match d.solver.unwrap_or(SolverName::Implicit) {
        SolverName::Implicit => Solver::Implicit {
            iterations: d.iterations.unwrap_or(30).max(1),
        },
        SolverName::Explicit => Solver::Explicit {
            // 0: as many as stability needs.
            substeps: d.substeps.unwrap_or(0),
        },
    };
    let gpu = d.gpu.as_ref().is_some_and(|g| *g.get_ref());
    if let (true, Solver::Implicit { .. }, true) = (gpu, solver, topology.joins_tips()) {
        let span = d.gpu.as_ref().map_or(0..0, |g| g.span());
        return Err(invalid(
            source,
            SceneErrorKind::Conflict,
            span,
            format!(
                "the GPU steps {} with the explicit solver only (their implicit step solves all tips at once, on the CPU): set solver = \"explicit\", or gpu = false",
                topology.name()
            ),
        ));
    }
    let default_coupling = if topology == Topology::SilvaStrands {
        CouplingName::Bezier
    } else {
        CouplingName::Bent
    };
    let coupling = match d.coupling.unwrap_or(default_coupling) {
        CouplingName::Bezier => Coupling::Bezier,
        CouplingName::Linear => Coupling::Linear,
        CouplingName::Bent => Coupling::Bent {
            exponent: d.exponent.unwrap_or(2.0).max(1.0),
        },
    };
    let defaults = DynamicsParams::default();
    let params = DynamicsParams {
        mass: d.mass.unwrap_or(defaults.mass).max(1e-9),
        stiffness: d.stiffness.unwrap_or(defaults.stiffness).max(0.0),
        lateral_stiffness: d
            .lateral_stiffness
            .unwrap_or(defaults.lateral_stiffness)
            .max(0.0),
        damping: d.damping.unwrap_or(defaults.damping).max(0.0),
        drag: d.drag.unwrap_or(defaults.drag).max(0.0),
        restoring: d.restoring.unwrap_or(defaults.restoring).max(0.0),
        gravity: d.gravity.map_or(defaults.gravity, Vec3::from),
        wind: d.wind.as_ref().map(|w| {
            Wind::new(
                Vec3::from(w.velocity),
                w.gust.unwrap_or(0.5),
                w.gust_frequency.unwrap_or(0.5),
                w.turbulence.unwrap_or(0.0),
                w.scale.unwrap_or(4.0),
                w.seed.unwrap_or(1),
            )
        }),
        brush: None,
    };
    Ok(DynamicsSettings {
        topology,
        solver,
        steps_per_frame: d.steps_per_frame.unwrap_or(2).max(1),
        coupling,
        params,
        shake: d.shake.as_ref().map(|s| Shake {
            amplitude: Vec3::from(s.amplitude),
            frequency: s.frequency.unwrap_or(3.0).max(1e-3),
            duration: s.duration.unwrap_or(1.0).max(0.0),
        }),
        gpu,
    })
}

fn spot_color() -> image::RgbaImage {
    image::load_from_memory(crate::assets::SPOT_TEXTURE_PNG)
        .expect("the embedded texture is a PNG")
        .to_rgba8()
}

/// The wetness mask as time passes (see [`ShellScene::wetness_timeline`]).
#[derive(Debug)]
pub struct WetnessTimeline<'s> {
    scene: &'s ShellScene,
    mask: WetnessMask,
    time: f32,
    next: usize,
}

impl WetnessTimeline<'_> {
    /// Moves on to `time` (seconds, not before the current time): the
    /// droplets due by then fall, each followed by drying until the next.
    pub fn advance_to(&mut self, time: f32) -> &WetnessMask {
        let rate = self.scene.drying_rate;
        while let Some(d) = self.scene.droplets.get(self.next) {
            if d.time > time {
                break;
            }
            if d.time > self.time {
                self.mask.dry(d.time - self.time, rate);
                self.time = d.time;
            }
            self.mask.add_droplet(d.droplet);
            self.next += 1;
        }
        if time > self.time {
            self.mask.dry(time - self.time, rate);
            self.time = time;
        }
        &self.mask
    }

    /// The mask now.
    pub fn mask(&self) -> &WetnessMask {
        &self.mask
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(text: &str) -> Result<ShellScene, SceneError> {
        ShellScene::from_source(&SettingsSource {
            path: "fur.toml".into(),
            text: text.into(),
        })
    }

    #[test]
    fn an_empty_dynamics_section_is_the_default() {
        let d = scene("[dynamics]\n").unwrap().dynamics.unwrap();
        let e = DynamicsSettings::default();
        assert_eq!(
            (d.topology, d.solver, d.steps_per_frame, d.coupling, d.shake),
            (e.topology, e.solver, e.steps_per_frame, e.coupling, e.shake)
        );
        assert_eq!(format!("{:?}", d.params), format!("{:?}", e.params));
    }

    #[test]
    fn an_empty_file_is_dry_straight_fur_on_spot() {
        let s = scene("").unwrap();
        assert_eq!(s.mesh.triangle_count(), 5856);
        assert_eq!(s.fur.layers, 16);
        assert!(s.droplets.is_empty());
        assert_eq!(s.shading.mode, ShadingMode::KajiyaKay);
        assert_eq!(s.color.width(), 1024);
    }

    #[test]
    fn errors_name_the_file_line_and_key() {
        let e = scene("[fur]\nlayers = 0\n").unwrap_err();
        assert!(matches!(e.kind, SceneErrorKind::OutOfRange(_)), "{e}");
        assert_eq!(e.at.line_column(), Some((2, 10)));
        assert_eq!(e.at.key.as_deref(), Some("fur.layers"));
        let e = e.to_string();
        assert!(e.starts_with("fur.toml:2:10: fur.layers: 0 layers"), "{e}");
        let e = scene("[animation]\nclip = \"run\"\n").unwrap_err();
        assert!(matches!(e.kind, SceneErrorKind::Conflict(_)), "{e}");
        let e = scene("[curl]\nradus = 1\n").unwrap_err().to_string();
        assert!(
            e.starts_with("fur.toml:2:1: curl.radus: unknown field"),
            "{e}"
        );
        let e = scene("[shading]\nmode = \"toon\"\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("fur.toml:2:8: shading.mode: unknown variant `toon`"),
            "{e}"
        );
        assert!(e.contains("`lambert`") && e.contains("`kajiya-kay`"), "{e}");
        let e = scene("[[droplets]]\nimage = \"nope.png\"\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("fur.toml:2:9: droplets.image: nope.png"),
            "{e}"
        );
    }

    #[test]
    fn every_named_setting_lists_the_accepted_names() {
        let cases = [
            (
                "[texture]\nstyle = \"fuzzy\"\n",
                "texture.style",
                "`random-strands`",
            ),
            (
                "[shading]\nmode = \"toon\"\n",
                "shading.mode",
                "`structure`",
            ),
            (
                "[dynamics]\ntopology = \"x\"\n",
                "dynamics.topology",
                "`silva-strands`",
            ),
            (
                "[dynamics]\nsolver = \"x\"\n",
                "dynamics.solver",
                "`implicit`",
            ),
            (
                "[dynamics]\ncoupling = \"x\"\n",
                "dynamics.coupling",
                "`bezier`",
            ),
        ];
        for (text, key, accepted) in cases {
            let e = scene(text).unwrap_err();
            assert!(matches!(e.kind, SceneErrorKind::Syntax(_)), "{e}");
            let e = e.to_string();
            assert!(e.starts_with("fur.toml:2:"), "{e}");
            assert!(e.contains(&format!(": {key}: unknown variant")), "{e}");
            assert!(e.contains(accepted), "{e}");
        }
        // The error underneath an unreadable image is in the message once,
        // and kept typed in the kind (not handed on to be said again).
        let e = scene("color = \"missing.png\"\n").unwrap_err();
        assert!(std::error::Error::source(&e).is_none(), "{e}");
        assert!(matches!(e.kind, SceneErrorKind::Image { .. }), "{e}");
        assert_eq!(e.to_string().matches("missing.png").count(), 1, "{e}");
    }

    #[test]
    fn the_documented_example_parses_key_for_key() {
        let doc = include_str!("../../../../docs/shells-format.md");
        let start = doc.find("```toml\n").expect("a toml block") + 8;
        let end = start + doc[start..].find("```").expect("its end");
        let file: SceneFile = toml::from_str(&doc[start..end]).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(file.droplets.len(), 3);
        assert!(file.color.is_some() && file.light.is_some() && file.camera.is_some());
    }

    #[test]
    fn dynamics_sections_parse_with_errors_at_their_line() {
        let s = scene("[dynamics]\ntopology = \"silva-strands\"\nsolver = \"explicit\"\n").unwrap();
        let d = s.dynamics.unwrap();
        assert_eq!(d.topology, Topology::SilvaStrands);
        assert_eq!(
            d.coupling,
            Coupling::Bezier,
            "Silva strands default to the Bézier"
        );
        // No substeps given: as many as stability needs.
        assert_eq!(d.solver, Solver::Explicit { substeps: 0 });
        let s = scene("[dynamics]\n[dynamics.shake]\namplitude = [0.1, 0, 0]\nfrequency = 2\n")
            .unwrap();
        let d = s.dynamics.unwrap();
        assert_eq!(d.coupling, Coupling::Bent { exponent: 2.0 });
        let shake = d.shake.unwrap();
        assert!((shake.offset(0.125).x - 0.1).abs() < 1e-6);
        assert_eq!(shake.offset(1.0), Vec3::ZERO, "still after its second");
        let e = scene("[dynamics]\ntopology = \"springs\"\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("fur.toml:2:12: dynamics.topology: unknown variant `springs`"),
            "{e}"
        );
        assert!(e.contains("`separable-prisms`"), "{e}");
        let e = scene("[dynamics.wind]\nvelocty = [1, 0, 0]\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("fur.toml:2:1") && e.contains("unknown field `velocty`"),
            "{e}"
        );
        assert!(scene("").unwrap().dynamics.is_none());
        let d = scene("[dynamics]\nsolver = \"explicit\"\ngpu = true\n")
            .unwrap()
            .dynamics
            .unwrap();
        assert!(d.gpu);
        // Spring-sticks (the default) step implicitly on the GPU too;
        // prisms only explicitly.
        assert!(
            scene("[dynamics]\ngpu = true\n")
                .unwrap()
                .dynamics
                .unwrap()
                .gpu
        );
        let e = scene("[dynamics]\ntopology = \"prisms\"\ngpu = true\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(
                "fur.toml:3:7: dynamics.gpu: the GPU steps prisms with the explicit solver only"
            ),
            "{e}"
        );
    }

    #[test]
    fn droplets_fall_on_time_and_dry_between() {
        let s = scene(
            "[wetness]\nresolution = 64\ndrying_rate = 1.0\n\
             [[droplets]]\nat = [0.5, 0.5]\nradius = 0.1\n\
             [[droplets]]\ntime = 2.0\nat = [0.2, 0.2]\nradius = 0.1\n",
        )
        .unwrap();
        let mut timeline = s.wetness_timeline();
        let first = Vec2::new(0.5, 0.5);
        let second = mask_coordinates(Vec2::new(0.2, 0.2));
        assert_eq!(timeline.advance_to(0.0).at(first).wetness, 1.0);
        assert_eq!(timeline.mask().at(second).wetness, 0.0);
        let mask = timeline.advance_to(2.0);
        assert!((mask.at(first).wetness - (-2.0f32).exp()).abs() < 1e-5);
        assert_eq!(mask.at(second).wetness, 1.0);
    }
}
