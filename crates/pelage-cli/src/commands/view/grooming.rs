//! The viewer's groom mode (`pelage view fur.toml --groom`): the groom
//! opened as an editable groom ([`pelage::groom::edit::EditableGroom`]) at
//! a preview fraction, brushes from a palette (and keys) applied where the
//! pointer's ray meets the skin, each dab regrowing only the hairs it can
//! change; undo and redo; the paint layer shown on the hairs' colours; and
//! save, which writes the guides, the paint layers and a groom file that
//! points at them.

use anyhow::Context as _;
use glam::Vec3;
use pelage::groom::Groom;
use pelage::groom::brush::{Brush, Dab, Falloff, REGION_LAYER};
use pelage::groom::edit::EditableGroom;
use pelage::map::MapSite;
use pelage::settings::SettingsSource;
use pelage::{Curves, Mesh};
use pelage_gpu::{Camera, GpuContext, GpuScene, OrbitCamera, PreviewScene, PreviewStyle, Renderer};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Hairs a groom opens with in the viewer (the full groom is grown when
/// saved and written by `pelage groom`).
pub const PREVIEW_HAIRS: f64 = 50_000.0;

/// The palette's brushes, in key order (1–9, 0, then `-`): the library's
/// brushes, in its order.
pub const PALETTE: &[&str] = pelage::groom::brush::Brush::NAMES;

/// The brush settings and what is drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct GroomingControls {
    /// Index into [`PALETTE`].
    pub brush: usize,
    /// Brush radius, world units.
    pub radius: f32,
    /// Brush strength.
    pub strength: f32,
    /// The falloff curve.
    pub falloff: Falloff,
    /// Mirror every dab across X = 0.
    pub mirror_x: bool,
    /// The layer `paint` paints.
    pub layer: String,
    /// The value `paint` paints.
    pub value: f32,
    /// The region `part` paints.
    pub region: u32,
    /// Guides added by one `add` dab.
    pub add_count: u32,
    /// Draw the skin.
    pub skin: bool,
    /// Draw the guides.
    pub guides: bool,
    /// Draw the hairs.
    pub hairs: bool,
    /// Colour the hairs by the paint layer at their roots.
    pub show_layer: bool,
}

/// A stroke in progress: where its last dab was.
#[derive(Debug, Clone, Copy)]
struct Stroke {
    last: Option<Vec3>,
    /// Dabs that changed the groom (joined into one undo step at its end).
    edits: usize,
}

/// A groom being groomed in the window.
pub struct GroomingSession {
    path: PathBuf,
    source: SettingsSource,
    groom: EditableGroom,
    renderer: Renderer,
    scene: Option<GpuScene>,
    uploaded: Option<GroomingControls>,
    dirty: bool,
    texture: Option<image::RgbaImage>,
    stroke: Option<Stroke>,
    /// The panel's settings.
    pub controls: GroomingControls,
    /// What the last action did.
    pub status: String,
    /// Milliseconds each dab took (edit + regrowth).
    pub dab_ms: Vec<f64>,
    /// The slider's share of the hairs, in percent: the groom grows it
    /// when the slider is released.
    percent_slider: f32,
    /// The guides a dab of the brush where the pointer is would move
    /// (drawn in [`REACHED_COLOR`]).
    reached: Vec<usize>,
}

const GUIDE_COLOR: Vec3 = Vec3::new(1.0, 0.3, 0.0);
/// The guides under the brush (those a dab there would move): green, and
/// twice as wide, apart from the orange guides and any skin.
const REACHED_COLOR: Vec3 = Vec3::new(0.1, 1.0, 0.2);

impl GroomingSession {
    /// Opens the groom file `path` for grooming.
    pub fn new(
        ctx: &GpuContext,
        path: &Path,
        format: pelage_gpu::wgpu::TextureFormat,
    ) -> anyhow::Result<Self> {
        let started = Instant::now();
        let loaded = Groom::load(path)?;
        let spec = loaded.spec()?;
        let fraction = (PREVIEW_HAIRS / spec.roots.count.max(1) as f64).min(1.0);
        let groom = EditableGroom::new(spec, fraction)?;
        let texture = (groom.mesh().name() == pelage::assets::spot().name())
            .then(|| {
                image::load_from_memory(pelage::assets::SPOT_TEXTURE_PNG).map(|i| i.to_rgba8())
            })
            .transpose()?;
        let diagonal = {
            let (lo, hi) = groom.mesh().bounds();
            (hi - lo).length()
        };
        let percent = (fraction * 100.0) as f32;
        let status = format!(
            "{} hairs of {} ({:.1} %), {} guides, opened in {:.2} s",
            groom.hair_count(),
            groom.spec().roots.count,
            percent,
            groom.guides().len(),
            started.elapsed().as_secs_f64()
        );
        Ok(Self {
            path: path.to_path_buf(),
            source: loaded.source().clone(),
            groom,
            renderer: Renderer::for_format(ctx, format),
            scene: None,
            uploaded: None,
            dirty: true,
            texture,
            stroke: None,
            controls: GroomingControls {
                brush: 0,
                radius: 0.05 * diagonal,
                strength: 0.5,
                falloff: Falloff::Smooth,
                mirror_x: false,
                layer: "density".into(),
                value: 0.0,
                region: 1,
                add_count: 1,
                skin: true,
                guides: true,
                hairs: true,
                show_layer: false,
            },
            status,
            dab_ms: Vec::new(),
            percent_slider: percent,
            reached: Vec::new(),
        })
    }

    /// Where the camera starts: framing the skin.
    pub fn initial_orbit(&self, aspect: f32) -> OrbitCamera {
        let (lo, hi) = self.groom.mesh().bounds();
        OrbitCamera::from_camera(Camera::framing(lo, hi, aspect))
    }

    /// The brush the palette has selected, with its settings.
    pub fn brush(&self) -> Brush {
        let c = &self.controls;
        match PALETTE[c.brush] {
            "paint" => Brush::Paint {
                layer: c.layer.clone(),
                value: c.value,
            },
            "part" => Brush::Part { region: c.region },
            "add" => Brush::Add {
                count: c.add_count.max(1),
            },
            name => Brush::by_name(name).expect("the palette names brushes"),
        }
    }

    /// The pointer's ray moved over the window: the guides a dab of a
    /// guide brush there would move are drawn highlighted (none off the
    /// mesh, or for the other brushes).
    pub fn hover(&mut self, origin: Vec3, direction: Vec3) {
        let brush = self.brush();
        let reached = match pelage::mesh::first_hit(self.groom.mesh(), origin, direction) {
            Some(hit) if brush.shapes_guides() => {
                let dab = self.dab_at(hit.point.position(self.groom.mesh()), Vec3::ZERO);
                pelage::groom::brush::guides_reached(&self.groom, &dab)
            }
            _ => Vec::new(),
        };
        if reached != self.reached {
            self.reached = reached;
            self.dirty = true;
        }
    }

    /// The dab of the panel's settings at `at`, combing along `moved`.
    fn dab_at(&self, at: Vec3, moved: Vec3) -> Dab {
        let c = &self.controls;
        Dab {
            center: at,
            radius: c.radius,
            strength: c.strength,
            direction: moved * c.strength,
            falloff: c.falloff,
            mirror_x: c.mirror_x,
        }
    }

    /// Starts a stroke.
    pub fn begin_stroke(&mut self) {
        self.stroke = Some(Stroke {
            last: None,
            edits: 0,
        });
    }

    /// Ends the stroke: its dabs become one undo step.
    /// Ends the stroke: its dabs' edits become one undo step. Returns how
    /// many dabs changed the groom.
    pub fn end_stroke(&mut self) -> usize {
        match self.stroke.take() {
            Some(stroke) => {
                self.groom.join_last_steps(stroke.edits);
                stroke.edits
            }
            None => 0,
        }
    }

    /// The stroke reaches the ray `origin + t · direction`: a dab where it
    /// meets the skin, once the pointer has moved a quarter of the radius
    /// since the last dab (comb: along the move). Returns whether the ray
    /// met the skin.
    pub fn stroke_to(&mut self, origin: Vec3, direction: Vec3) -> anyhow::Result<bool> {
        let Some(hit) = pelage::mesh::first_hit(self.groom.mesh(), origin, direction) else {
            return Ok(false);
        };
        let at = hit.point.position(self.groom.mesh());
        let stroke = self.stroke.get_or_insert(Stroke {
            last: None,
            edits: 0,
        });
        let spacing = 0.25 * self.controls.radius;
        let moved = match stroke.last {
            Some(last) if at.distance(last) < spacing => return Ok(true),
            Some(last) => at - last,
            None => Vec3::ZERO,
        };
        stroke.last = Some(at);
        let brush = self.brush();
        // A comb needs a direction: its first dab waits for the pointer
        // to move.
        if brush == Brush::Comb && moved == Vec3::ZERO {
            return Ok(true);
        }
        self.dab(&brush, at, moved)?;
        Ok(true)
    }

    /// One dab of `brush` at `at`, combing along `moved`.
    pub fn dab(&mut self, brush: &Brush, at: Vec3, moved: Vec3) -> anyhow::Result<()> {
        let dab = self.dab_at(at, moved);
        let started = Instant::now();
        match self.groom.brush(brush, &dab) {
            Ok(Some(r)) => {
                let ms = started.elapsed().as_secs_f64() * 1e3;
                if let Some(stroke) = &mut self.stroke {
                    stroke.edits += 1;
                }
                self.dab_ms.push(ms);
                self.status = format!(
                    "{}: {} of {} hairs regrown in {ms:.1} ms",
                    brush.name(),
                    r.regrown_roots,
                    r.hairs
                );
                self.dirty = true;
            }
            // A guide brush that reached no guide says so, and how far the
            // nearest was: a dab that changes nothing is otherwise silent.
            Ok(None) if brush.shapes_guides() => {
                self.status = match pelage::groom::brush::nearest_guide_distance(&self.groom, at) {
                    Some(d) => format!(
                        "{}: no guide within the radius {:.4} (the nearest is {d:.4} away)",
                        brush.name(),
                        dab.radius
                    ),
                    None => format!("{}: the groom has no guides", brush.name()),
                };
            }
            Ok(None) => {}
            // The window shows a refusal in its status line; a script
            // stops on it.
            Err(e) => return Err(anyhow::Error::from(e).context(brush.name())),
        }
        Ok(())
    }

    /// Undoes the last edit.
    pub fn undo(&mut self) -> anyhow::Result<()> {
        self.status = match self.groom.undo()? {
            Some(r) => format!("undone: {} hairs regrown", r.regrown_roots),
            None => "nothing to undo".into(),
        };
        self.dirty = true;
        Ok(())
    }

    /// Redoes the last undone edit.
    pub fn redo(&mut self) -> anyhow::Result<()> {
        self.status = match self.groom.redo()? {
            Some(r) => format!("redone: {} hairs regrown", r.regrown_roots),
            None => "nothing to redo".into(),
        };
        self.dirty = true;
        Ok(())
    }

    /// Where save writes by default: `NAME.groomed.toml` beside the groom.
    pub fn default_save_path(&self) -> PathBuf {
        let stem = self
            .path
            .file_stem()
            .map_or_else(|| "groom".into(), |s| s.to_string_lossy().into_owned());
        self.path.with_file_name(format!("{stem}.groomed.toml"))
    }

    /// Saves the groom, its guides and layers to `path`.
    pub fn save(&mut self, path: &Path) -> anyhow::Result<()> {
        let saved = self
            .groom
            .save(path, Some(&self.source))
            .with_context(|| format!("cannot save {}", path.display()))?;
        self.status = format!(
            "saved {} (guides {}{})",
            saved.groom.display(),
            saved.guides.display(),
            saved
                .layers
                .map(|l| format!(", layers {}", l.display()))
                .unwrap_or_default()
        );
        println!("{}", self.status);
        Ok(())
    }

    /// Writes the hairs the window shows (at the preview fraction) to a
    /// curves file.
    pub fn export(&self, path: &Path) -> anyhow::Result<()> {
        let curves = self.groom.curves();
        pelage::io::write_curves(path, [("hairs".to_string(), &curves)], &Default::default())?;
        Ok(())
    }

    /// Grows another share of the hairs.
    pub fn set_percent(&mut self, percent: f32) -> anyhow::Result<()> {
        let percent = percent.clamp(0.01, 100.0);
        self.percent_slider = percent;
        let started = Instant::now();
        let r = self.groom.set_fraction(f64::from(percent) / 100.0)?;
        self.status = format!(
            "{} hairs ({percent:.1} %) in {:.2} s",
            r.hairs,
            started.elapsed().as_secs_f64()
        );
        self.dirty = true;
        Ok(())
    }

    fn upload(&mut self, ctx: &GpuContext) -> anyhow::Result<()> {
        let c = self.controls.clone();
        let mut parts: Vec<Curves> = Vec::new();
        let hairs = self.groom.curves();
        let mean_width = hairs.widths().iter().sum::<f32>() / hairs.widths().len().max(1) as f32;
        if c.hairs && hairs.curve_count() > 0 {
            let colored = if c.show_layer {
                layer_colored(hairs, self.groom.mesh(), &self.layer_shown())?
            } else if hairs.colors().is_some() {
                hairs
            } else {
                let brown = Vec3::from(PreviewStyle::default().hair);
                let n = hairs.points().len();
                hairs.with_colors(vec![brown; n])?
            };
            parts.push(colored);
        }
        if c.guides {
            let guides = self.groom.guides().curves();
            let width = 3.0 * mean_width.max(1e-5);
            let mut widths = vec![width; guides.points().len()];
            let mut colors = vec![GUIDE_COLOR; guides.points().len()];
            for &g in self.reached.iter().filter(|&&g| g < guides.curve_count()) {
                widths[guides.range(g)].fill(2.0 * width);
                colors[guides.range(g)].fill(REACHED_COLOR);
            }
            let wide = Curves::new(guides.points().to_vec(), widths, guides.offsets().to_vec())?;
            parts.push(wide.with_colors(colors)?);
        }
        let curves = pelage::curves::join(parts.iter())?;
        let scene = PreviewScene {
            mesh: Some(self.groom.mesh()).filter(|_| c.skin),
            points: &[],
            curves: (curves.curve_count() > 0).then_some(&curves),
            skin_texture: self.texture.as_ref(),
        };
        self.scene = Some(self.renderer.upload(ctx, &scene));
        self.uploaded = Some(c);
        self.dirty = false;
        Ok(())
    }

    /// The layer the hairs are coloured by: the paint brush's, or the
    /// regions when parting.
    fn layer_shown(&self) -> String {
        if PALETTE[self.controls.brush] == "part" {
            REGION_LAYER.into()
        } else {
            self.controls.layer.clone()
        }
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
        if self.dirty || self.uploaded.as_ref() != Some(&self.controls) {
            self.upload(ctx)?;
        }
        let scene = self.scene.as_ref().expect("uploaded above");
        super::curves::encode_preview(
            &self.renderer,
            ctx,
            encoder,
            scene,
            orbit,
            resolve,
            (width, height),
        )
    }

    /// The control panel. Returns the actions asked for.
    pub fn panel(&mut self, ui: &mut egui::Ui) -> PanelActions {
        let mut actions = PanelActions::default();
        ui.heading("Groom by hand");
        ui.label(&self.status);
        if let Some(ms) = self.dab_ms.last() {
            let mut sorted = self.dab_ms.clone();
            sorted.sort_by(f64::total_cmp);
            ui.small(format!(
                "last dab {ms:.1} ms · median {:.1} ms over {}",
                sorted[sorted.len() / 2],
                sorted.len()
            ));
        }
        ui.separator();
        let c = &mut self.controls;
        ui.label("brush (keys 1–9, 0, -)");
        ui.horizontal_wrapped(|ui| {
            for (i, name) in PALETTE.iter().enumerate() {
                ui.selectable_value(&mut c.brush, i, *name);
            }
        });
        ui.add(
            egui::Slider::new(&mut c.radius, 1e-4..=1.0)
                .logarithmic(true)
                .text("radius ([ ])"),
        );
        ui.add(egui::Slider::new(&mut c.strength, -1.0..=1.0).text("strength (, .)"));
        egui::ComboBox::from_label("falloff")
            .selected_text(format!("{:?}", c.falloff).to_lowercase())
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut c.falloff, Falloff::Smooth, "smooth");
                ui.selectable_value(&mut c.falloff, Falloff::Linear, "linear");
                ui.selectable_value(&mut c.falloff, Falloff::Constant, "constant");
            });
        ui.checkbox(&mut c.mirror_x, "X-mirror (M)");
        match PALETTE[c.brush] {
            "paint" => {
                ui.horizontal(|ui| {
                    ui.label("layer");
                    ui.text_edit_singleline(&mut c.layer);
                });
                ui.add(egui::Slider::new(&mut c.value, 0.0..=4.0).text("value"));
            }
            "part" => {
                ui.add(egui::Slider::new(&mut c.region, 0..=16).text("region"));
            }
            "add" => {
                ui.add(egui::Slider::new(&mut c.add_count, 1..=16).text("guides a dab"));
            }
            _ => {}
        }
        ui.separator();
        ui.checkbox(&mut c.skin, "skin");
        ui.checkbox(&mut c.hairs, "hairs");
        ui.checkbox(&mut c.guides, "guides (orange)");
        ui.checkbox(&mut c.show_layer, "hairs coloured by the paint layer");
        let slider = ui.add(
            egui::Slider::new(&mut self.percent_slider, 0.1..=100.0)
                .logarithmic(true)
                .suffix(" %")
                .text("of the hairs grown"),
        );
        if slider.drag_stopped() || (slider.changed() && !slider.dragged()) {
            actions.percent = Some(self.percent_slider);
        }
        ui.separator();
        let (undo, redo) = self.groom.history_len();
        ui.horizontal(|ui| {
            actions.undo = ui
                .add_enabled(undo > 0, egui::Button::new("undo (Ctrl+Z)"))
                .clicked();
            actions.redo = ui
                .add_enabled(redo > 0, egui::Button::new("redo (Ctrl+Shift+Z)"))
                .clicked();
        });
        actions.save = ui.button("save (Ctrl+S)").clicked();
        ui.small(format!("saves {}", self.default_save_path().display()));
        actions
    }
}

/// What the panel's buttons asked for this frame.
#[derive(Debug, Default, Clone, Copy)]
pub struct PanelActions {
    /// Undo.
    pub undo: bool,
    /// Redo.
    pub redo: bool,
    /// Save.
    pub save: bool,
    /// Grow this share of the hairs.
    pub percent: Option<f32>,
}

/// The hairs coloured by `layer` at their roots (blue 0 → yellow 1 → red
/// above); grey where the mesh has no such layer yet.
fn layer_colored(hairs: Curves, mesh: &Mesh, layer: &str) -> anyhow::Result<Curves> {
    let values = mesh.vertex_attribute(layer).map(|a| a.values.clone());
    let roots = hairs.roots().context("grown hairs have roots")?.to_vec();
    let mut colors = Vec::with_capacity(hairs.points().len());
    for (i, root) in roots.iter().enumerate() {
        let color = match &values {
            Some(values) => {
                let site = MapSite::on(mesh, *root);
                let v: f32 = site
                    .corners
                    .iter()
                    .zip(site.weights)
                    .map(|(c, w)| w * values[*c as usize])
                    .sum();
                ramp(v)
            }
            None => Vec3::splat(0.5),
        };
        colors.extend(std::iter::repeat_n(color, hairs.range(i).len()));
    }
    Ok(hairs.with_colors(colors)?)
}

fn ramp(v: f32) -> Vec3 {
    let t = v.clamp(0.0, 2.0);
    if t < 1.0 {
        Vec3::new(0.1, 0.2, 0.8).lerp(Vec3::new(1.0, 0.85, 0.2), t)
    } else {
        Vec3::new(1.0, 0.85, 0.2).lerp(Vec3::new(0.9, 0.1, 0.1), t - 1.0)
    }
}
