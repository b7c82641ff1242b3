//! Groom files as one front end of [`GroomSpec`]: [`Groom`] reads a file,
//! loads its mesh and guides, and turns its settings into the values a
//! [`Generator`] is built from, keeping where each was written so that
//! errors found later still name the line.

use super::animate::{AnimatedGroom, AnimationMode, AnimationSpec, AxisTurn, GuideMotion};
use super::error::{GroomError, GroomErrorKind};
use super::file::{AnimationModeName, GroomFile, InterpolationKind, MapValue, MeshSection};
use super::generator::Generator;
use super::hair_look::HairLook;
use super::ops::{Color, OpKey, OperatorSettings, RootToTip, SpecReader, map_on_mesh};
use super::outside_skin::OutsideSkin;
use super::parts::part_count;
use super::simulate::{
    CacheUse, SimulatedGuides, SimulationSettings, cached_simulation_until, simulate_guides_until,
};
use super::spec::{FinishSpec, GroomSpec, RegionsSpec, RootsSpec, SpecOrigin};
use crate::anim::{AnimatedSkin, FrameRange, SkinOptions};
use crate::dynamics::{GuideStrandParams, Wind};
use crate::guides::{BindReport, CombMap, GuideGrowth, Guides};
use crate::interp::{InterpolationMethod, StyleMeshOptions};
use crate::map::Map;
use crate::mesh::{Mesh, MeshError, MeshErrorKind};
use crate::sample::SampleError;
use crate::settings::SettingsSource;
use glam::Vec3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::Spanned;

/// A groom file loaded: the file, its mesh and guides (and, for an
/// animated groom, its skin and frames).
pub struct Groom {
    source: SettingsSource,
    file: GroomFile,
    mesh: Arc<Mesh>,
    /// The mesh file's base colour texture, as red, green and blue maps:
    /// the hairs' colour when `[finish]` gives none.
    skin_colors: Option<[Map; 3]>,
    guides: Arc<Guides>,
    bind_report: Option<BindReport>,
    animation: Option<LoadedAnimation>,
    /// `--fraction`, in place of `[output] fraction`.
    fraction: Option<f64>,
}

/// What `[animation]` (or `--frames`) loaded.
struct LoadedAnimation {
    skin: Arc<AnimatedSkin>,
    spec: AnimationSpec,
    fps: f64,
    /// The guide file, when it is USD (regrow reads it frame by frame).
    guides: Option<GuideMotion>,
}

impl std::fmt::Debug for Groom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Groom")
            .field("path", &self.source.path)
            .field("mesh", &self.mesh.name())
            .field("guides", &self.guides.len())
            .finish()
    }
}

/// Values a program gives a groom in place of files its settings would
/// name: the Python binding builds grooms from arrays this way. The
/// settings (roots, operators, finish) still come as groom-file text, so
/// they are checked, and their errors worded, exactly as a file's.
#[derive(Debug, Clone, Default)]
pub struct GroomInputs {
    /// The surface, replacing `[mesh]` when the settings have one.
    pub mesh: Option<Arc<Mesh>>,
    /// Guide curves to bind to the surface (with `[guides] points` and
    /// `tolerance`), instead of `[guides] file` or `[guides.generate]`.
    pub guides: Option<crate::Curves>,
    /// An animated skin (a DCC's evaluated mesh at every frame), replacing
    /// `[mesh]` for an animated groom: the surface is the skin at the rest
    /// frame. Give it or `mesh`, not both.
    pub skin: Option<Arc<AnimatedSkin>>,
}

impl Groom {
    /// Reads, parses and loads the groom file at `path`.
    pub fn load(path: &Path) -> Result<Self, GroomError> {
        Self::from_source(SettingsSource::read_groom(path)?)
    }

    /// Loads a groom from its text (`path` names it in errors and is the
    /// base of relative paths).
    pub fn from_text(
        path: impl Into<PathBuf>,
        text: impl Into<String>,
    ) -> Result<Self, GroomError> {
        Self::from_source(SettingsSource {
            path: path.into(),
            text: text.into(),
        })
    }

    /// Parses the source, loads the mesh and the guides.
    pub fn from_source(source: SettingsSource) -> Result<Self, GroomError> {
        Self::from_source_with_frames(source, None)
    }

    /// [`Self::load`], with `frames` replacing `[animation] frames` (and
    /// making the groom animated when the file has no `[animation]`).
    pub fn load_with_frames(path: &Path, frames: Option<FrameRange>) -> Result<Self, GroomError> {
        Self::from_source_with_frames(SettingsSource::read_groom(path)?, frames)
    }

    /// [`Self::from_source`], with `frames` replacing `[animation] frames`.
    pub fn from_source_with_frames(
        source: SettingsSource,
        frames: Option<FrameRange>,
    ) -> Result<Self, GroomError> {
        Self::from_source_with_inputs(source, frames, GroomInputs::default())
    }

    /// [`Self::from_source_with_frames`], with the mesh and guides given
    /// as values where `inputs` has them. A mesh value replaces `[mesh]`;
    /// guide curves and a `[guides]` source together are an error, as is
    /// an animated groom on a mesh value (a skin comes from a file).
    pub fn from_source_with_inputs(
        source: SettingsSource,
        frames: Option<FrameRange>,
        inputs: GroomInputs,
    ) -> Result<Self, GroomError> {
        let file = source.parse()?;
        let animation = animation_spec(&source, &file, frames)?;
        let invalid = |key: &str, message: &str| {
            GroomError::new(
                source.path.clone(),
                None,
                Some(key.to_string()),
                GroomErrorKind::Conflict(message.to_string()),
            )
        };
        // A mesh value replaces `[mesh]`: a groom file written for the
        // command line grows on whatever mesh a DCC hands over.
        let mesh_is_value = inputs.skin.is_some() || inputs.mesh.is_some();
        let given_skin = match (inputs.skin, &inputs.mesh, &animation) {
            (Some(_), Some(_), _) => {
                return Err(invalid(
                    "mesh",
                    "the surface is given twice, as a mesh and as a skin; give one",
                ));
            }
            (Some(_), None, None) => {
                return Err(invalid(
                    "animation",
                    "a skin moves an animated groom: add an [animation] table with its frames",
                ));
            }
            (Some(skin), None, Some((spec, _, _))) => {
                let mesh = skin.mesh_at(spec.rest_frame).map_err(|e| {
                    GroomError::new(
                        source.path.clone(),
                        None,
                        Some("skin".into()),
                        GroomErrorKind::Mesh(e),
                    )
                })?;
                Some((Arc::new(mesh), skin))
            }
            (None, _, _) => None,
        };
        let (mesh, skin) = match (given_skin, &file.mesh, inputs.mesh, &animation) {
            (Some((mesh, skin)), ..) => (mesh, Some(skin)),
            (None, _, Some(_), Some(_)) => {
                return Err(invalid(
                    "animation",
                    "an animated groom reads its skin from [mesh] path (glTF, USD or an OBJ sequence) or from a skin given as a value; a mesh given as a value does not move",
                ));
            }
            (None, _, Some(mesh), None) => (mesh, None),
            (None, None, None, _) => {
                return Err(invalid(
                    "mesh",
                    "no mesh: add a [mesh] table with `path = \"model.obj\"`",
                ));
            }
            (None, Some(section), None, None) => {
                (Arc::new(load_mesh_section(&source, section)?), None)
            }
            (None, Some(section), None, Some((spec, fps, clip))) => {
                let skin = load_skin(&source, section, *fps, clip.as_ref())?;
                let mesh = skin
                    .mesh_at(spec.rest_frame)
                    .map_err(|e| source.error_at(section.path.span(), GroomErrorKind::Mesh(e)))?;
                // `[mesh] layers` paint the rest mesh the groom grows on,
                // as they paint a still one.
                let at = section
                    .layers
                    .as_ref()
                    .map_or(section.path.span(), |l| l.span());
                let mesh = section
                    .with_layers(mesh, source.folder())
                    .map_err(|e| source.error_at(at, GroomErrorKind::Mesh(e)))?;
                (Arc::new(mesh), Some(Arc::new(skin)))
            }
        };
        let rest_time = animation
            .as_ref()
            .map(|(spec, fps, _)| (spec.rest_frame, *fps));
        // The mesh's up axis: a value's is pelage's world (Y), a file's is
        // its own (a USD file's upAxis; every other format is Y up).
        let mesh_up = match (&file.mesh, mesh_is_value) {
            (Some(section), false) => usd_up_axis(&source.folder().join(section.path.get_ref())),
            _ => crate::io::UpAxis::Y,
        };
        let (guides, bind_report) = match inputs.guides {
            Some(_) if file.guides.file.is_some() || file.guides.generate.is_some() => {
                return Err(invalid(
                    "guides",
                    "the guides are given twice, as curves and in [guides]; give one",
                ));
            }
            Some(curves) => bind_guides(&source, &file, &mesh, &curves, 0..0)?,
            None => load_guides(&source, &file, &mesh, rest_time, mesh_up)?,
        };
        let animation = match (animation, skin) {
            (Some((spec, fps, _)), Some(skin)) => {
                let guide_file = file
                    .guides
                    .file
                    .as_ref()
                    .map(|p| source.folder().join(p.get_ref()));
                let guides = guide_file.filter(|p| is_animatable(p)).map(|path| {
                    let total = bind_report
                        .as_ref()
                        .map_or(guides.len(), |r| r.kept + r.dropped.len());
                    let dropped: std::collections::HashSet<usize> = bind_report
                        .as_ref()
                        .map(|r| r.dropped.iter().map(|d| d.index).collect())
                        .unwrap_or_default();
                    GuideMotion::File {
                        turn: AxisTurn::between(usd_up_axis(&path), mesh_up),
                        path,
                        kept: (0..total).filter(|i| !dropped.contains(i)).collect(),
                        fps,
                    }
                });
                Some(LoadedAnimation {
                    skin,
                    spec,
                    fps,
                    guides,
                })
            }
            _ => None,
        };
        let skin_colors = match &file.mesh {
            Some(section) if !mesh_is_value && section.base_color => skin_colors(&source, section)?,
            _ => None,
        };
        Ok(Self {
            source,
            file,
            mesh,
            skin_colors,
            guides: Arc::new(guides),
            bind_report,
            animation,
            fraction: None,
        })
    }

    /// The frames and mode, for an animated groom.
    pub fn animation(&self) -> Option<&AnimationSpec> {
        self.animation.as_ref().map(|a| &a.spec)
    }

    /// Frames per second of an animated groom (`[animation] fps`).
    pub fn fps(&self) -> Option<f64> {
        self.animation.as_ref().map(|a| a.fps)
    }

    /// The animated skin, for an animated groom.
    pub fn skin(&self) -> Option<&AnimatedSkin> {
        self.animation.as_ref().map(|a| a.skin.as_ref())
    }

    /// The groom bound to its animated skin (`None` for a still groom);
    /// `seed` overrides the file's.
    pub fn animated(&self, seed: Option<u64>) -> Result<Option<AnimatedGroom>, GroomError> {
        self.animated_until(seed, &|| false)
    }

    /// [`Self::animated`], asking `stop` after every frame a simulated
    /// groom's guides are simulated whether to give up (a Ctrl-C): then a
    /// [`GroomErrorKind::Stopped`] error.
    pub fn animated_until(
        &self,
        seed: Option<u64>,
        stop: &dyn Fn() -> bool,
    ) -> Result<Option<AnimatedGroom>, GroomError> {
        let Some(animation) = &self.animation else {
            return Ok(None);
        };
        if let Some(guides) = self.file.output.guides.as_ref().filter(|g| *g.get_ref()) {
            return Err(self.source.error_at(
                guides.span(),
                GroomErrorKind::Conflict(
                    "guides are written with still grooms; an animated groom's are not (set guides = false)".into(),
                ),
            ));
        }
        let mut spec = self.spec()?;
        if let Some(seed) = seed {
            spec.roots.seed = seed;
        }
        let guides = match animation.spec.mode {
            AnimationMode::Deform => None,
            AnimationMode::Regrow => {
                let Some(guides) = animation.guides.clone() else {
                    let span = self
                        .file
                        .animation
                        .as_ref()
                        .map_or(0..0, |a| a.frames.span());
                    return Err(self.source.error_at(
                        span,
                        GroomErrorKind::Conflict(
                            "mode = \"regrow\" needs time-sampled guides: a USD or Alembic guide file in [guides] file".into(),
                        ),
                    ));
                };
                Some(guides)
            }
            AnimationMode::Simulate => Some(self.simulate(&spec, animation, stop)?.0.motion()),
        };
        AnimatedGroom::new(spec, animation.skin.clone(), animation.spec.clone(), guides).map(Some)
    }

    /// `[simulation] cache`, relative to the groom file's folder.
    pub fn simulation_cache(&self) -> Option<PathBuf> {
        let cache = self.file.simulation.as_ref()?.cache.as_ref()?;
        Some(self.source.folder().join(cache.get_ref()))
    }

    /// The guides of an animated groom simulated over its frames
    /// (`[animation] mode = "simulate"`), through `[simulation] cache`
    /// when the file names one (and what was done with it). An error for
    /// a still groom or another mode.
    pub fn simulated_guides(&self) -> Result<(SimulatedGuides, Option<CacheUse>), GroomError> {
        self.simulated_guides_until(&|| false)
    }

    /// [`Self::simulated_guides`], asking `stop` after every simulated
    /// frame whether to give up (a Ctrl-C): then a
    /// [`GroomErrorKind::Stopped`] error, and no cache written.
    pub fn simulated_guides_until(
        &self,
        stop: &dyn Fn() -> bool,
    ) -> Result<(SimulatedGuides, Option<CacheUse>), GroomError> {
        let Some(animation) = self
            .animation
            .as_ref()
            .filter(|a| a.spec.mode == AnimationMode::Simulate)
        else {
            return Err(self.source.error_at(
                0..0,
                GroomErrorKind::Conflict(
                    "only an animated groom with mode = \"simulate\" in [animation] simulates its guides".into(),
                ),
            ));
        };
        self.simulate(&self.spec()?, animation, stop)
    }

    /// [`Self::simulated_guides`] of `spec` (the groom's values, with a
    /// seed given).
    fn simulate(
        &self,
        spec: &GroomSpec,
        animation: &LoadedAnimation,
        stop: &dyn Fn() -> bool,
    ) -> Result<(SimulatedGuides, Option<CacheUse>), GroomError> {
        let settings = self.simulation_settings(animation)?;
        let skin = &animation.skin;
        match self.simulation_cache() {
            Some(full) => {
                let (guides, used) = cached_simulation_until(spec, skin, &settings, &full, stop)?;
                Ok((guides, Some(used)))
            }
            None => Ok((simulate_guides_until(spec, skin, &settings, stop)?, None)),
        }
    }

    /// `[simulation]` as the solver takes it (its defaults where the file
    /// has none).
    fn simulation_settings(
        &self,
        animation: &LoadedAnimation,
    ) -> Result<SimulationSettings, GroomError> {
        let run = &animation.spec.frames;
        let (mut first, mut last) = (run.first(), run.last());
        if let Some(section) = &self.file.animation {
            let whole = FrameRange::parse(section.frames.get_ref()).map_err(|e| {
                self.source
                    .error_at(section.frames.span(), GroomErrorKind::Frames(e))
            })?;
            (first, last) = (first.min(whole.first()), last.max(whole.last()));
        }
        let section =
            self.file.simulation.clone().unwrap_or_else(|| {
                toml::from_str("").expect("every [simulation] key has a default")
            });
        let (lo, hi) = self.mesh.bounds();
        let size = (hi - lo).max_element();
        Ok(SimulationSettings {
            params: GuideStrandParams {
                substeps: section.substeps,
                iterations: section.iterations,
                gravity: Vec3::from(section.gravity),
                damping: section.damping,
                bend: section.bend,
                follow: section.follow,
                drag: section.drag,
                wind: (section.wind != [0.0; 3])
                    .then(|| Wind::new(Vec3::from(section.wind), 0.0, 0.0, 0.0, 1.0, 0)),
                thickness: match &section.thickness {
                    Some(t) => {
                        let most = crate::limits::MAX_THICKNESS_OF_SKIN * size;
                        if t.get_ref().is_nan() || *t.get_ref() > most {
                            return Err(self.source.error_at(
                                t.span(),
                                GroomErrorKind::OutOfRange(format!(
                                    "{}: at most {most} here, a tenth of the skin's size; guides are kept this far off the skin (the default is 0.2 % of its size; docs/limits.md)",
                                    t.get_ref()
                                )),
                            ));
                        }
                        *t.get_ref()
                    }
                    None => 2e-3 * size,
                },
                friction: section.friction,
                ..GuideStrandParams::default()
            },
            collide: section.collide,
            preroll: section.preroll,
            fps: animation.fps,
            frames: first..=last,
        })
    }

    /// The number of hairs `[roots] count` asks for (before `strands`
    /// multiplies them).
    pub fn hair_count(&self) -> u64 {
        *self.file.roots.count.get_ref()
    }

    /// The share of the hairs grown: `--fraction` ([`Self::set_fraction`]),
    /// else `[output] fraction`, else 1.
    pub fn fraction(&self) -> f64 {
        self.fraction
            .or_else(|| self.file.output.fraction.as_ref().map(|f| *f.get_ref()))
            .unwrap_or(1.0)
    }

    /// Grows this share of the hairs (a preview) in place of `[output]
    /// fraction`. Fails unless it is in (0, 1].
    pub fn set_fraction(&mut self, fraction: f64) -> Result<(), GroomError> {
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(GroomError::new(
                self.source.path.clone(),
                None,
                Some("--fraction".into()),
                GroomErrorKind::OutOfRange(format!(
                    "{fraction}: give the share of the hairs to grow, above 0 and at most 1"
                )),
            ));
        }
        self.fraction = Some(fraction);
        Ok(())
    }

    /// The hairs grown: [`Self::hair_count`] times [`Self::fraction`],
    /// rounded, at least 1.
    pub fn grown_count(&self) -> u64 {
        let mut roots = crate::groom::RootsSpec::new(self.hair_count());
        roots.fraction = self.fraction();
        roots.grown_count()
    }

    /// Points per hair (`[finish] points`).
    pub fn points_per_hair(&self) -> usize {
        *self.file.finish.points.get_ref()
    }

    /// The curves' basis (`[output] basis`).
    pub fn curve_basis(&self) -> crate::io::CurveBasis {
        self.file.output.basis
    }

    /// Whether curves with hair-shading values get a material that reads
    /// them (`[look] material`).
    pub fn writes_hair_material(&self) -> bool {
        self.file.look.as_ref().is_none_or(|l| l.material)
    }

    /// Whether the guide curves are written beside the hairs (`[output]
    /// guides`).
    pub fn writes_guides(&self) -> bool {
        self.file
            .output
            .guides
            .as_ref()
            .is_some_and(|g| *g.get_ref())
    }

    /// Whether the skin is written beside the curves (`[output]
    /// with_mesh`).
    pub fn writes_skin(&self) -> bool {
        self.file.output.with_mesh
    }

    /// The file's path and text.
    pub fn source(&self) -> &SettingsSource {
        &self.source
    }

    /// The mesh hairs grow on.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The groom file's path.
    pub fn path(&self) -> &Path {
        &self.source.path
    }

    /// The guides, bound to the mesh.
    pub fn guides(&self) -> &Guides {
        &self.guides
    }

    /// The `[mesh]` file's base colour texture (a glTF's), sRGB as stored,
    /// when it has one: what a renderer colours the skin with.
    ///
    /// # Errors
    /// When the texture cannot be read.
    pub fn base_color_texture(&self) -> Result<Option<image::DynamicImage>, GroomError> {
        let Some(section) = &self.file.mesh else {
            return Ok(None);
        };
        if section.path.get_ref() == "spot" {
            return Ok(None);
        }
        let path = self.source.folder().join(section.path.get_ref());
        crate::mesh::base_color_texture(&path).map_err(|e| {
            self.source
                .error_at(section.path.span(), GroomErrorKind::Mesh(e))
        })
    }

    /// `[simulation]` as the guide solver takes it, when the groom is
    /// animated with `mode = "simulate"`: what a real-time player
    /// simulates its guides with, frame by frame.
    ///
    /// # Errors
    /// When a `[simulation]` value is out of its range.
    pub fn simulation_settings_for_playing(
        &self,
    ) -> Result<Option<SimulationSettings>, GroomError> {
        match &self.animation {
            Some(a) if a.spec.mode == AnimationMode::Simulate => {
                self.simulation_settings(a).map(Some)
            }
            _ => Ok(None),
        }
    }

    /// Makes an animated groom's frames `mode`'s (a real-time player
    /// carries the hairs and simulates the guides itself: it asks for
    /// [`AnimationMode::Deform`] so that [`Self::animated`] does not
    /// simulate the whole range first). No effect on a still groom.
    pub fn set_animation_mode(&mut self, mode: AnimationMode) {
        if let Some(a) = &mut self.animation {
            a.spec.mode = mode;
        }
    }

    /// When the guides came from a file: what binding them kept and left
    /// out.
    pub fn bind_report(&self) -> Option<&BindReport> {
        self.bind_report.as_ref()
    }

    /// Where the curves go: `[output] path` relative to the groom file, or
    /// the groom file's name with `.usdc`.
    pub fn output_path(&self) -> PathBuf {
        match &self.file.output.path {
            Some(p) => self.source.folder().join(p),
            None => self.source.path.with_extension("usdc"),
        }
    }

    /// The number of parts: `[roots] parts`, or one per 100,000 hairs;
    /// never more than the mesh has triangles (root cells, with stable
    /// ids). Known before the generator is built.
    pub fn part_count(&self) -> usize {
        part_count(
            &self.mesh,
            self.grown_count(),
            self.file.roots.parts.as_ref().map(|p| *p.get_ref()),
            self.file.roots.ids,
        )
    }

    /// The groom as values: every map read (and checked against the mesh),
    /// every operator with its settings. Errors are at their line.
    pub fn spec(&self) -> Result<GroomSpec, GroomError> {
        let file = &self.file;
        let source = &self.source;
        // Where the settings the generator checks were written.
        let mut lines = HashMap::new();
        for (key, span) in [
            ("roots.count", file.roots.count.span()),
            ("roots.density", file.roots.density.span()),
            ("roots.density_scale", file.roots.density_scale.span()),
            ("finish.points", file.finish.points.span()),
            ("finish.width", file.finish.width.root.span()),
        ] {
            mark(&mut lines, key, source.line_of(span));
        }
        if let Some(o) = &file.finish.opacity {
            mark(&mut lines, "finish.opacity", source.line_of(o.root.span()));
        }
        if let Some(c) = &file.finish.color {
            mark(&mut lines, "finish.color", source.line_of(c.root[0].span()));
        }
        let roots = RootsSpec {
            count: *file.roots.count.get_ref(),
            density: map_on_mesh(source, &self.mesh, &file.roots.density)?,
            density_scale: map_on_mesh(source, &self.mesh, &file.roots.density_scale)?,
            seed: file.roots.seed,
            parts: file.roots.parts.as_ref().map(|p| *p.get_ref()),
            ids: file.roots.ids,
            distribution: file.roots.distribution,
            fraction: self.fraction(),
        };
        if let Some(f) = &file.output.fraction {
            mark(&mut lines, "output.fraction", source.line_of(f.span()));
        }
        let method = &file.interpolation;
        let interpolation = match method.method {
            InterpolationKind::Shepard => InterpolationMethod::Shepard {
                k: method.k.max(1),
                power: method.power,
                radius: method.radius,
            },
            InterpolationKind::StyleMesh => InterpolationMethod::StyleMesh(StyleMeshOptions {
                split_shared: method.split_shared,
            }),
        };
        let finish = self.finish_spec(&mut lines)?;
        let mut ops = Vec::with_capacity(file.ops.len());
        for (index, spec) in file.ops.iter().enumerate() {
            let key = OpKey {
                index,
                name: spec.name(),
            };
            if let Some(line) = source.line_of_op(index) {
                lines.insert(key.to_string(), line);
            }
            let mut reader = SpecReader::new(source, &self.mesh, &mut lines, key.to_string());
            ops.push(spec.read(&mut reader)?);
        }
        let regions = self.regions_spec(&mut lines)?;
        self.check_finish_has_no_masks()?;
        let look = self.look_spec(&mut lines)?;
        Ok(GroomSpec {
            name: source.path.clone(),
            mesh: self.mesh.clone(),
            guides: self.guides.clone(),
            roots,
            interpolation,
            ops,
            finish,
            regions,
            look,
            origin: Some(Arc::new(SpecOrigin { lines })),
        })
    }

    /// `[finish]`: every hair's starting width, colour and opacity, its
    /// points and normals, and whether hairs are kept out of the skin.
    fn finish_spec(&self, lines: &mut Lines) -> Result<FinishSpec, GroomError> {
        let (file, source) = (&self.file, &self.source);
        let width = RootToTip::read(
            &file.finish.width,
            &mut SpecReader::new(source, &self.mesh, lines, "finish.width".into()),
        )?;
        let color = match &file.finish.color {
            Some(c) => Some(Color::read(
                c,
                &mut SpecReader::new(source, &self.mesh, lines, "finish.color".into()),
            )?),
            // The skin's own colours, root to tip.
            None => self
                .skin_colors
                .clone()
                .map(|maps| Color::new(maps.clone(), maps)),
        };
        let opacity = file
            .finish
            .opacity
            .as_ref()
            .map(|o| {
                RootToTip::read(
                    o,
                    &mut SpecReader::new(source, &self.mesh, lines, "finish.opacity".into()),
                )
            })
            .transpose()?;
        let finish = FinishSpec {
            points: *file.finish.points.get_ref(),
            width,
            color,
            opacity,
            normals: file.finish.normals,
            outside_skin: file
                .finish
                .outside_skin
                .unwrap_or(self.animation.is_some())
                .then(|| {
                    file.finish
                        .skin_gap
                        .map_or_else(|| OutsideSkin::default_gap(&self.mesh), |g| g as f32)
                }),
        };
        Ok(finish)
    }

    /// `[regions]`: a map or the mesh's face sets, one of them.
    fn regions_spec(&self, lines: &mut Lines) -> Result<Option<RegionsSpec>, GroomError> {
        let (file, source) = (&self.file, &self.source);
        let map = |v: &MapValue| map_on_mesh(source, &self.mesh, v);
        Ok(match &file.regions {
            None => None,
            Some(r) => {
                let invalid = |span: std::ops::Range<usize>, m: &str| {
                    source.error_at(span, GroomErrorKind::Conflict(m.into()))
                };
                match (&r.map, &r.faces) {
                    (Some(m), None) => {
                        mark(lines, "regions", source.line_of(m.span()));
                        Some(RegionsSpec::from_map(map(m)?, r.scale))
                    }
                    (None, Some(kind)) => {
                        mark(lines, "regions", source.line_of(kind.span()));
                        if !matches!(kind.get_ref().as_str(), "groups" | "materials") {
                            return Err(invalid(
                                kind.span(),
                                "faces is \"groups\" (OBJ g/o) or \"materials\" (OBJ usemtl)",
                            ));
                        }
                        Some(RegionsSpec::from_faces(kind.get_ref().clone()))
                    }
                    (Some(m), Some(_)) => {
                        return Err(invalid(
                            m.span(),
                            "[regions] takes a map or faces, not both",
                        ));
                    }
                    (None, None) => {
                        return Err(source.error_at(
                            0..0,
                            GroomErrorKind::Conflict(
                                "[regions] needs map = \"…\" or faces = \"groups\"".into(),
                            ),
                        ));
                    }
                }
            }
        })
    }

    /// `[finish]` sets every hair's starting values: a mask there is an
    /// error at its line (a masked operator does what it would).
    fn check_finish_has_no_masks(&self) -> Result<(), GroomError> {
        let (file, source) = (&self.file, &self.source);
        for (key, mask) in [
            ("finish.width.mask", file.finish.width.mask.as_ref()),
            (
                "finish.opacity.mask",
                file.finish.opacity.as_ref().and_then(|o| o.mask.as_ref()),
            ),
            (
                "finish.color.mask",
                file.finish.color.as_ref().and_then(|c| c.mask.as_ref()),
            ),
        ] {
            if let Some(mask) = mask {
                return Err(source.error_at(
                    mask.span(),
                    GroomErrorKind::Conflict(format!(
                        "{key}: masks fade operators; [finish] sets every hair's starting values (add a masked width, color or opacity operator instead)"
                    )),
                ));
            }
        }
        Ok(())
    }

    /// `[look]`: each hair's values for a hair shader.
    fn look_spec(&self, lines: &mut Lines) -> Result<Option<HairLook>, GroomError> {
        let (file, source) = (&self.file, &self.source);
        Ok(match &file.look {
            None => None,
            Some(l) => {
                mark(lines, "look", source.line_of(l.melanin.span()));
                let mut r = SpecReader::new(source, &self.mesh, lines, "look".into());
                Some(HairLook {
                    melanin: r.map("melanin", &l.melanin)?,
                    melanin_redness: r.map("melanin_redness", &l.melanin_redness)?,
                    tint: r.rgb("tint", &l.tint)?,
                    roughness: r.map("roughness", &l.roughness)?,
                    radial_roughness: r.map("radial_roughness", &l.radial_roughness)?,
                    jitter: r.map("jitter", &l.jitter)?,
                    seed: l.seed,
                    material: l.material,
                })
            }
        })
    }

    /// Prepares generation from [`Self::spec`]; `seed` overrides the
    /// file's.
    pub fn generator(&self, seed: Option<u64>) -> Result<Generator, GroomError> {
        let mut spec = self.spec()?;
        if let Some(seed) = seed {
            spec.roots.seed = seed;
        }
        Generator::new(spec)
    }
}

/// An sRGB-encoded value (0–1) made linear: the sRGB transfer function's
/// inverse (IEC 61966-2-1).
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// A linear value (0–1) sRGB-encoded: the sRGB transfer function
/// (IEC 61966-2-1), [`srgb_to_linear`]'s inverse.
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The red, green and blue of the base colour texture of the mesh file a
/// `[mesh]` section names (a glTF's, made linear), when it has one; a texture that
/// cannot be read is an error at `mesh.path`.
fn skin_colors(
    source: &SettingsSource,
    section: &MeshSection,
) -> Result<Option<[Map; 3]>, GroomError> {
    if section.path.get_ref() == "spot" {
        return Ok(None);
    }
    let path = source.folder().join(section.path.get_ref());
    let at_path = |kind| source.error_at(section.path.span(), kind);
    let Some(image) =
        crate::mesh::base_color_texture(&path).map_err(|e| at_path(GroomErrorKind::Mesh(e)))?
    else {
        return Ok(None);
    };
    let name = format!("{}'s base colour texture", path.display());
    // glTF's base colour texture is sRGB-encoded; hair colours are linear.
    let mut linear = image.to_rgba32f();
    for texel in linear.pixels_mut() {
        for c in &mut texel.0[..3] {
            *c = srgb_to_linear(*c);
        }
    }
    let image = image::DynamicImage::ImageRgba32F(linear);
    let channel = |c| {
        crate::map::ImageMap::from_image(&name, &image, c, crate::map::Wrap::Repeat)
            .map(Map::Image)
            .map_err(|e| at_path(GroomErrorKind::Map(e)))
    };
    use crate::map::Channel;
    Ok(Some([
        channel(Channel::R)?,
        channel(Channel::G)?,
        channel(Channel::B)?,
    ]))
}

/// The mesh a `[mesh]` section names, subdivided as asked, with its paint
/// layers; a mesh that cannot be loaded is reported at its line, layers
/// that cannot at theirs.
fn load_mesh_section(source: &SettingsSource, section: &MeshSection) -> Result<Mesh, GroomError> {
    let mesh = section
        .load_mesh(source.folder())
        .map_err(|e| source.error_at(section.path.span(), GroomErrorKind::Mesh(e)))?;
    let at = section
        .layers
        .as_ref()
        .map_or(section.path.span(), |l| l.span());
    section
        .with_layers(mesh, source.folder())
        .map_err(|e| source.error_at(at, GroomErrorKind::Mesh(e)))
}

/// Where each setting the generator checks was written: key → (line,
/// column).
type Lines = HashMap<String, (usize, usize)>;

/// Notes where `key` was written, if it was.
fn mark(lines: &mut Lines, key: &str, line: Option<(usize, usize)>) {
    if let Some(line) = line {
        lines.insert(key.to_string(), line);
    }
}

/// Whether a path names a curves file that can hold time samples (USD,
/// Alembic), by extension.
fn is_animatable(path: &Path) -> bool {
    matches!(
        path.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref(),
        Some("usda" | "usdc" | "usd" | "abc")
    )
}
/// What a groom file (or `--frames`) asks to animate: the spec, the frame
/// rate and the glTF clip (where it is written, for errors).
type AnimationRequest = (AnimationSpec, f64, Option<Spanned<String>>);

/// The animation a groom file (or `--frames`) asks for.
fn animation_spec(
    source: &SettingsSource,
    file: &GroomFile,
    frames: Option<FrameRange>,
) -> Result<Option<AnimationRequest>, GroomError> {
    let section = file.animation.as_ref();
    let frames = match (frames, section) {
        (Some(f), _) => f,
        (None, Some(s)) => FrameRange::parse(s.frames.get_ref())
            .map_err(|e| source.error_at(s.frames.span(), GroomErrorKind::Frames(e)))?,
        (None, None) => return Ok(None),
    };
    let fps = section.map_or(24.0, |s| s.fps);
    if !(fps.is_finite() && fps > 0.0) {
        let span = section.map_or(0..0, |s| s.frames.span());
        return Err(source.error_at(
            span,
            GroomErrorKind::OutOfRange(format!("fps = {fps}: it must be a positive number")),
        ));
    }
    // The rest frame never depends on which frames a run writes (farm
    // tasks split the range): the file's rest_frame, else the first of the
    // file's frames, else frame 1.
    let file_first = match section {
        Some(s) => FrameRange::parse(s.frames.get_ref())
            .map_err(|e| source.error_at(s.frames.span(), GroomErrorKind::Frames(e)))?
            .first(),
        None => 1,
    };
    let rest_frame = section
        .and_then(|s| s.rest_frame)
        .unwrap_or(f64::from(file_first));
    if !rest_frame.is_finite() {
        return Err(source.error_at(
            section.map_or(0..0, |s| s.frames.span()),
            GroomErrorKind::NotFinite("rest_frame must be a finite number".into()),
        ));
    }
    if let (Some(_), false) = (
        &file.simulation,
        section.is_some_and(|s| s.mode == AnimationModeName::Simulate),
    ) {
        // The table at fault is [simulation] (or the mode it lacks), not
        // the frames.
        return Err(GroomError::new(
            source.path.clone(),
            source.line_of_table("simulation"),
            Some("simulation".into()),
            GroomErrorKind::Conflict(
                "[simulation] moves the guides of an animated groom with mode = \"simulate\" in [animation]: set it, or remove [simulation]".into(),
            ),
        ));
    }
    let mode = match section.map(|s| s.mode).unwrap_or_default() {
        AnimationModeName::Deform => AnimationMode::Deform,
        AnimationModeName::Regrow => AnimationMode::Regrow,
        AnimationModeName::Simulate => AnimationMode::Simulate,
    };
    let spec = AnimationSpec {
        frames,
        rest_frame,
        mode,
        shutter: section.map(|s| s.motion_blur.clone()).unwrap_or_default(),
        velocities: section.is_none_or(|s| s.velocities),
    };
    Ok(Some((spec, fps, section.and_then(|s| s.clip.clone()))))
}

/// The animated skin a `[mesh]` section names. A problem with the clip
/// (one the file does not have, or a clip for a skin that plays none) is
/// reported at `animation.clip`, anything else at `mesh.path`.
fn load_skin(
    source: &SettingsSource,
    section: &MeshSection,
    fps: f64,
    clip: Option<&Spanned<String>>,
) -> Result<AnimatedSkin, GroomError> {
    let error = |e: MeshError| match (e.kind(), clip) {
        (MeshErrorKind::Clip(_), Some(clip)) => {
            source.error_at(clip.span(), GroomErrorKind::Mesh(e))
        }
        _ => source.error_at(section.path.span(), GroomErrorKind::Mesh(e)),
    };
    let options = SkinOptions {
        fps,
        clip: clip.map(|c| c.get_ref().clone()),
        subdivide: section.subdivide,
    };
    match section.path.get_ref().as_str() {
        "spot" => match clip {
            Some(clip) => Err(source.error_at(
                clip.span(),
                GroomErrorKind::Conflict(format!(
                    "clip {:?}: the embedded spot has no clips to play; clips are glTF animations (a .gltf or .glb skin): remove `clip`",
                    clip.get_ref()
                )),
            )),
            None => Ok(AnimatedSkin::still(
                &crate::assets::spot().subdivided(section.subdivide),
            )),
        },
        path => AnimatedSkin::load(&source.folder().join(path), &options).map_err(error),
    }
}

/// Binds guide curves to the mesh with `[guides] points` and `tolerance`;
/// none within the tolerance is an error at `span` (the file's path).
fn bind_guides(
    source: &SettingsSource,
    file: &GroomFile,
    mesh: &Mesh,
    curves: &crate::Curves,
    span: std::ops::Range<usize>,
) -> Result<(Guides, Option<BindReport>), GroomError> {
    let section = &file.guides;
    let (guides, report) = Guides::bind(mesh, curves, section.points, section.tolerance);
    if guides.is_empty() {
        // Said as the guides were left out: a curve of one point is no
        // matter of tolerance.
        let short = report
            .dropped
            .iter()
            .filter(|d| matches!(d.reason, crate::guides::DropReason::TooFewPoints(_)))
            .count();
        let message = if short == report.dropped.len() && short > 0 {
            "every guide has fewer than two points: a guide needs a root and a tip (draw or grow the guides longer)"
        } else {
            "no guide is within the tolerance of the mesh; check that the guides belong to this mesh, or raise [guides] tolerance"
        };
        return Err(match span {
            std::ops::Range { start: 0, end: 0 } => GroomError::new(
                source.path.clone(),
                None,
                Some("guides".into()),
                GroomErrorKind::Mismatch(message.into()),
            ),
            s => source.error_at(s, GroomErrorKind::Mismatch(message.into())),
        });
    }
    Ok((guides, Some(report)))
}

/// The up axis a file's coordinates have: a USD layer's `upAxis` (Y when
/// not authored, or when the layer cannot be read: its reader says why
/// later); every other format Y (pelage's world: OBJ, PLY and glTF are Y
/// up, Blender's Alembic export turns its Z up into Y).
fn usd_up_axis(path: &Path) -> crate::io::UpAxis {
    let usd = matches!(
        crate::io::CurvesFormat::from_path(path),
        Some(crate::io::CurvesFormat::Usda | crate::io::CurvesFormat::Usdc)
    );
    match usd
        .then(|| crate::io::read_usd_layer_info(path).ok())
        .flatten()
    {
        Some(info) if info.up_axis.eq_ignore_ascii_case("z") => crate::io::UpAxis::Z,
        _ => crate::io::UpAxis::Y,
    }
}

fn load_guides(
    source: &SettingsSource,
    file: &GroomFile,
    mesh: &Mesh,
    rest_time: Option<(f64, f64)>,
    mesh_up: crate::io::UpAxis,
) -> Result<(Guides, Option<BindReport>), GroomError> {
    let section = &file.guides;
    match (&section.file, &section.generate) {
        (Some(path), None) => {
            let full = source.folder().join(path.get_ref());
            // Animated guides are bound as they are at the rest frame.
            let curves = match rest_time {
                Some((t, fps)) => super::animate::read_guides_at(&full, t, fps),
                None => crate::io::read_curves(&full),
            }
            .map_err(|e| source.error_at(path.span(), GroomErrorKind::Guides(e)))?;
            // A Z-up USD file (Blender's export) for a Y-up mesh, or the
            // other way round, is turned to the mesh's axes.
            let curves = AxisTurn::between(usd_up_axis(&full), mesh_up).curves(curves);
            bind_guides(source, file, mesh, &curves, path.span())
        }
        (None, Some(generate)) => {
            let map = |v: &MapValue| map_on_mesh(source, mesh, v);
            let growth = GuideGrowth {
                count: generate.count.max(1),
                density: map(&generate.density)?,
                length: map(&generate.length)?,
                comb: Vec3::from(generate.comb),
                comb_map: match &generate.comb_map {
                    Some([u, v]) => Some(CombMap {
                        u: map(u)?,
                        v: map(v)?,
                        strength: generate.comb_strength,
                    }),
                    None => None,
                },
                gravity: generate.gravity,
                points: section.points,
                width: 0.004,
                seed: generate.seed,
            };
            let guides = Guides::grow(mesh, &growth).map_err(|e| {
                // A mesh with no area has nowhere for a guide: its fault,
                // not the guides' length.
                let span = match (&e, &file.mesh) {
                    (
                        crate::guides::GuideError::Sample(SampleError::ZeroDensity { .. }),
                        Some(m),
                    ) => m.path.span(),
                    _ => generate.length.span(),
                };
                source.error_at(span, GroomErrorKind::GuideGrowth(e))
            })?;
            Ok((guides, None))
        }
        _ => Err(GroomError::new(
            source.path.clone(),
            None,
            Some("guides".into()),
            GroomErrorKind::Conflict(
                "give exactly one of `file = \"guides.usda\"` or a [guides.generate] table".into(),
            ),
        )),
    }
}
