//! The viewer's groom session: a curves file (USD, .hair, PLY) or a groom
//! file grown in memory, drawn by the preview renderer with toggles for the
//! skin, roots, guides and hairs, a slider for how many hairs to draw, and
//! a reload whenever the file changes on disk — edit a groom file in one
//! window, see it regrow in the other. A time-sampled USD file (an
//! animated or simulated groom as `pelage groom` writes it) plays: a
//! timeline over its samples, with its own posed skin when it has one.

use anyhow::Context as _;
use glam::Vec3;
use pelage::groom::Groom;
use pelage::{Curves, Mesh};
use pelage_gpu::{Camera, GpuContext, GpuScene, OrbitCamera, PreviewScene, PreviewStyle, Renderer};
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

/// Where the hairs come from.
#[derive(Debug, Clone)]
pub enum CurvesSource {
    /// A curves file, over an optional mesh (`--mesh`, or `spot`).
    File {
        /// The curves.
        path: PathBuf,
        /// The skin: a mesh file, `spot`, or none.
        mesh: Option<PathBuf>,
    },
    /// A groom file (docs/groom-format.md), grown here.
    Groom(PathBuf),
}

impl CurvesSource {
    fn path(&self) -> &Path {
        match self {
            CurvesSource::File { path, .. } | CurvesSource::Groom(path) => path,
        }
    }
}

/// What was loaded.
struct Loaded {
    hairs: Curves,
    guides: Option<Curves>,
    skin: Skin,
    texture: Option<image::RgbaImage>,
    summary: String,
    /// A time-sampled file's samples, to play.
    timeline: Option<Timeline>,
}

/// A time-sampled USD file, parsed once with every sample.
struct Timeline {
    file: pelage::io::UsdCurvesSequence,
    /// The time codes of its samples, ascending (two at least).
    times: Vec<f64>,
    /// Time codes a second.
    per_second: f64,
    /// The file's own posed skin (a `Mesh` prim written with the fur).
    skin: Option<pelage::anim::AnimatedSkin>,
    /// The time code of the hairs (and skin) loaded.
    shown: f64,
}

enum Skin {
    None,
    Mesh(Box<Mesh>),
    Groom(Box<Groom>),
}

impl Skin {
    fn mesh(&self) -> Option<&Mesh> {
        match self {
            Skin::None => None,
            Skin::Mesh(m) => Some(m),
            Skin::Groom(g) => Some(g.mesh()),
        }
    }
}

/// Which parts are drawn and how many hairs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvesControls {
    /// The mesh.
    pub skin: bool,
    /// A dot at each drawn hair's root.
    pub roots: bool,
    /// The guide curves (groom files), in orange.
    pub guides: bool,
    /// The hairs.
    pub hairs: bool,
    /// Percentage of the hairs drawn (every n-th).
    pub percent: f32,
    /// Reload when the file changes.
    pub watch: bool,
    /// The time code shown, for a time-sampled file.
    pub time: f64,
    /// Play the time-sampled file (looping).
    pub playing: bool,
}

/// A groom or curves file being looked at.
pub struct CurvesSession {
    source: CurvesSource,
    loaded: Loaded,
    renderer: Renderer,
    scene: Option<GpuScene>,
    uploaded: Option<CurvesControls>,
    /// The panel's toggles.
    pub controls: CurvesControls,
    modified: Option<SystemTime>,
    last_check: Instant,
    /// The last reload's outcome (errors stay on screen, the old groom too).
    pub status: String,
}

const GUIDE_COLOR: Vec3 = Vec3::new(1.0, 0.3, 0.0);

impl CurvesSession {
    /// Loads `source` for drawing into targets of `format`.
    pub fn new(
        ctx: &GpuContext,
        source: CurvesSource,
        format: pelage_gpu::wgpu::TextureFormat,
    ) -> anyhow::Result<Self> {
        let loaded = load(&source)?;
        let status = loaded.summary.clone();
        let time = loaded.timeline.as_ref().map_or(0.0, |t| t.shown);
        let playing = loaded.timeline.is_some();
        // A million hairs draw slowly in software: start with at most
        // 200,000 and let the slider bring the rest.
        let count = loaded.hairs.curve_count().max(1) as f32;
        Ok(Self {
            modified: modified(source.path()),
            source,
            loaded,
            renderer: Renderer::for_format(ctx, format),
            scene: None,
            uploaded: None,
            controls: CurvesControls {
                skin: true,
                roots: false,
                guides: true,
                hairs: true,
                percent: (100.0 * 200_000.0 / count).min(100.0),
                watch: true,
                time,
                playing,
            },
            last_check: Instant::now(),
            status,
        })
    }

    /// Where the camera starts: framing everything.
    pub fn initial_orbit(&self, aspect: f32) -> OrbitCamera {
        let (lo, hi) = self.bounds();
        OrbitCamera::from_camera(Camera::framing(lo, hi, aspect))
    }

    fn bounds(&self) -> (Vec3, Vec3) {
        let mesh = self.loaded.skin.mesh().map(Mesh::bounds);
        let hairs = self.loaded.hairs.bounds();
        match (mesh, hairs) {
            (Some((a, b)), Some((c, d))) => (a.min(c), b.max(d)),
            (Some(m), None) | (None, Some(m)) => m,
            (None, None) => (Vec3::splat(-1.0), Vec3::ONE),
        }
    }

    /// Plays a time-sampled file `dt` seconds on (looping), then
    /// [`Self::watch`].
    pub fn advance(&mut self, dt: f32) {
        if let (Some(timeline), true) = (&self.loaded.timeline, self.controls.playing) {
            let (first, last) = (timeline.times[0], timeline.times[timeline.times.len() - 1]);
            let mut time = self.controls.time + f64::from(dt) * timeline.per_second;
            if time > last {
                time = first;
            }
            self.controls.time = time;
        }
        self.watch();
    }

    /// Holds a time-sampled file `seconds` after its first sample, paused
    /// (a script's `time`); false for a file without samples.
    pub fn hold_at(&mut self, seconds: f32) -> bool {
        let Some(timeline) = &self.loaded.timeline else {
            return false;
        };
        let (first, last) = (timeline.times[0], timeline.times[timeline.times.len() - 1]);
        self.controls.time = (first + f64::from(seconds) * timeline.per_second).clamp(first, last);
        self.controls.playing = false;
        true
    }

    /// Reloads when the file changed (checked twice a second).
    fn watch(&mut self) {
        if !self.controls.watch || self.last_check.elapsed().as_secs_f32() < 0.5 {
            return;
        }
        self.last_check = Instant::now();
        let now = modified(self.source.path());
        if now == self.modified {
            return;
        }
        self.modified = now;
        match load(&self.source) {
            Ok(loaded) => {
                self.status = format!("reloaded: {}", loaded.summary);
                self.loaded = loaded;
                self.uploaded = None;
            }
            Err(err) => self.status = format!("not reloaded: {}", crate::one_line(&err)),
        }
    }

    /// Reads the hairs (and the file's skin) at the sample at or before
    /// `controls.time`, when another is shown.
    fn seek(&mut self) -> anyhow::Result<()> {
        let Some(timeline) = &mut self.loaded.timeline else {
            return Ok(());
        };
        let at = timeline.times.partition_point(|&t| t <= self.controls.time);
        let time = timeline.times[at.saturating_sub(1)];
        if time == timeline.shown {
            return Ok(());
        }
        self.loaded.hairs = timeline.file.at(time)?;
        if let Some(skin) = &timeline.skin {
            self.loaded.skin = Skin::Mesh(Box::new(skin.mesh_at(time)?));
        }
        timeline.shown = time;
        Ok(())
    }

    fn upload(&mut self, ctx: &GpuContext) -> anyhow::Result<()> {
        self.seek()?;
        let c = self.controls;
        let count = self.loaded.hairs.curve_count();
        let shown = (count as f32 * c.percent / 100.0).round().max(1.0);
        let stride = (count as f32 / shown).round().max(1.0) as usize;
        let hairs = self.loaded.hairs.every_nth(stride);
        // Hairs keep their own colours (or get the preview's brown); guides
        // stand out in orange. Both carry colours, so they join with them.
        let mut parts: Vec<Curves> = Vec::new();
        if c.hairs {
            let brown = Vec3::from(PreviewStyle::default().hair);
            parts.push(match hairs.colors() {
                Some(_) => hairs.clone(),
                None => painted(hairs.clone(), brown)?,
            });
        }
        if let (true, Some(guides)) = (c.guides, &self.loaded.guides) {
            // Three hairs wide, so they read among the hairs.
            let hair_widths = self.loaded.hairs.widths();
            let mean = hair_widths.iter().sum::<f32>() / hair_widths.len().max(1) as f32;
            let widths = vec![3.0 * mean.max(1e-5); guides.points().len()];
            let wide = Curves::new(guides.points().to_vec(), widths, guides.offsets().to_vec())?;
            parts.push(painted(wide, GUIDE_COLOR)?);
        }
        let curves = pelage::curves::join(parts.iter())?;
        let roots: Vec<Vec3> = if c.roots {
            (0..hairs.curve_count())
                .map(|i| hairs.points()[hairs.range(i).start])
                .collect()
        } else {
            Vec::new()
        };
        let scene = PreviewScene {
            mesh: self.loaded.skin.mesh().filter(|_| c.skin),
            points: &roots,
            curves: (curves.curve_count() > 0).then_some(&curves),
            skin_texture: self.loaded.texture.as_ref(),
        };
        self.scene = Some(self.renderer.upload(ctx, &scene));
        self.uploaded = Some(c);
        Ok(())
    }

    /// Records the groom into `resolve` (`width × height`).
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut pelage_gpu::wgpu::CommandEncoder,
        orbit: &OrbitCamera,
        resolve: &pelage_gpu::wgpu::TextureView,
        width: u32,
        height: u32,
    ) -> anyhow::Result<()> {
        if self.uploaded != Some(self.controls) {
            self.upload(ctx)?;
        }
        let scene = self.scene.as_ref().expect("uploaded above");
        encode_preview(
            &self.renderer,
            ctx,
            encoder,
            scene,
            orbit,
            resolve,
            (width, height),
        )
    }

    /// The control panel.
    pub fn panel(&mut self, ui: &mut egui::Ui) {
        let c = &mut self.controls;
        ui.heading("Groom");
        ui.label(&self.status);
        ui.checkbox(&mut c.skin, "skin");
        ui.checkbox(&mut c.hairs, "hairs");
        ui.add_enabled(
            self.loaded.guides.is_some(),
            egui::Checkbox::new(&mut c.guides, "guides (orange)"),
        );
        ui.checkbox(&mut c.roots, "roots");
        let count = self.loaded.hairs.curve_count();
        ui.add(
            egui::Slider::new(&mut c.percent, 0.1..=100.0)
                .logarithmic(true)
                .suffix(" %")
                .text(format!("of {count} hairs")),
        );
        ui.checkbox(&mut c.watch, "reload when the file changes");
        if let Some(timeline) = &self.loaded.timeline {
            let (first, last) = (timeline.times[0], timeline.times[timeline.times.len() - 1]);
            ui.horizontal(|ui| {
                if ui
                    .button(if c.playing { "Pause" } else { "Play" })
                    .clicked()
                {
                    c.playing = !c.playing;
                }
                let slider = ui.add(egui::Slider::new(&mut c.time, first..=last).text("frame"));
                if slider.dragged() {
                    c.playing = false;
                }
            });
        }
    }
}

/// Records an uploaded preview scene over the viewer's background, seen
/// by `orbit`, into `resolve` (groom and curves sessions alike).
pub(super) fn encode_preview(
    renderer: &Renderer,
    ctx: &GpuContext,
    encoder: &mut pelage_gpu::wgpu::CommandEncoder,
    scene: &GpuScene,
    orbit: &OrbitCamera,
    resolve: &pelage_gpu::wgpu::TextureView,
    (width, height): (u32, u32),
) -> anyhow::Result<()> {
    let style = PreviewStyle {
        background: super::super::FUR_BACKGROUND,
        ..PreviewStyle::default()
    };
    renderer.encode(
        ctx,
        encoder,
        scene,
        &style,
        Some(orbit.camera()),
        resolve,
        width,
        height,
    )?;
    Ok(())
}

/// `curves` all in one colour.
fn painted(curves: Curves, colour: Vec3) -> Result<Curves, pelage::curves::CurvesError> {
    let n = curves.points().len();
    curves.with_colors(vec![colour; n])
}

fn modified(path: &Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

fn load(source: &CurvesSource) -> anyhow::Result<Loaded> {
    let spot_texture =
        || image::load_from_memory(pelage::assets::SPOT_TEXTURE_PNG).map(|i| i.to_rgba8());
    match source {
        CurvesSource::File { path, mesh } => {
            let hairs = pelage::io::read_curves(path).context("cannot load the curves")?;
            let timeline = timeline_of(path, mesh.is_none())?;
            let (skin, texture) = match mesh.as_deref() {
                // The file's own skin, at the sample shown first.
                None => match timeline
                    .as_ref()
                    .and_then(|t| Some((t.skin.as_ref()?, t.shown)))
                {
                    Some((skin, time)) => (Skin::Mesh(Box::new(skin.mesh_at(time)?)), None),
                    None => (Skin::None, None),
                },
                Some(m) if m == Path::new("spot") => (
                    Skin::Mesh(Box::new(pelage::assets::spot())),
                    Some(spot_texture()?),
                ),
                Some(m) => (
                    Skin::Mesh(Box::new(Mesh::load(m).context("cannot load the mesh")?)),
                    None,
                ),
            };
            let summary = match &timeline {
                Some(t) => format!(
                    "{} hairs from {}, {} samples",
                    hairs.curve_count(),
                    path.display(),
                    t.times.len()
                ),
                None => format!("{} hairs from {}", hairs.curve_count(), path.display()),
            };
            let hairs = match &timeline {
                Some(t) => t.file.at(t.shown)?,
                None => hairs,
            };
            Ok(Loaded {
                hairs,
                guides: None,
                skin,
                texture,
                summary,
                timeline,
            })
        }
        CurvesSource::Groom(path) => {
            let started = Instant::now();
            let groom = Groom::load(path)?;
            let generator = groom.generator(None)?;
            let parts = (0..generator.parts().len())
                .map(|p| generator.part(p))
                .collect::<Result<Vec<Curves>, _>>()?;
            let hairs = pelage::curves::join(parts.iter())?;
            let guides = groom.guides().curves().clone();
            drop(generator);
            let texture = if groom.mesh().name() == pelage::assets::spot().name() {
                Some(spot_texture()?)
            } else {
                None
            };
            let summary = format!(
                "{} hairs from {} guides, grown in {:.2} s",
                hairs.curve_count(),
                guides.curve_count(),
                started.elapsed().as_secs_f64()
            );
            Ok(Loaded {
                hairs,
                guides: Some(guides),
                skin: Skin::Groom(Box::new(groom)),
                texture,
                summary,
                timeline: None,
            })
        }
    }
}

/// The samples of a time-sampled USD file (none for other files, or a
/// USD file with one sample); with `own_skin`, its posed skin too.
fn timeline_of(path: &Path, own_skin: bool) -> anyhow::Result<Option<Timeline>> {
    let usd = matches!(
        pelage::io::CurvesFormat::from_path(path),
        Some(pelage::io::CurvesFormat::Usda | pelage::io::CurvesFormat::Usdc)
    );
    if !usd {
        return Ok(None);
    }
    let file = pelage::io::UsdCurvesSequence::open(path).context("cannot load the curves")?;
    let times = file.times();
    if times.len() < 2 {
        return Ok(None);
    }
    let per_second = pelage::io::read_usd_layer_info(path)
        .map(|i| i.time_codes_per_second)
        .unwrap_or(24.0);
    // A file without a skin is hairs alone: no error, no skin.
    let skin = own_skin
        .then(|| pelage::anim::AnimatedSkin::load(path, &Default::default()).ok())
        .flatten()
        .filter(pelage::anim::AnimatedSkin::is_animated);
    let shown = times[0];
    Ok(Some(Timeline {
        file,
        times,
        per_second,
        skin,
        shown,
    }))
}
