//! `pelage view fur.toml --realtime`: a groom file played in real time
//! by `pelage_gpu::RealtimeFur` (docs/realtime.md): the skin running, its
//! guides simulated when the groom says so, every hair grown on the GPU
//! each frame, strands near and shells far; a panel with the counts, the
//! level of detail and each stage's milliseconds.

use anyhow::Context as _;
use pelage::groom::Groom;
use pelage_gpu::{
    Camera, GpuContext, OrbitCamera, RealtimeFur, ShellTarget, ShellTargetFormats, ShellView,
};
use std::path::Path;

/// A groom played in the window.
pub struct RealtimeSession {
    fur: RealtimeFur,
    target: Option<ShellTarget>,
    /// The animation frame shown, and the groom's frames.
    frame: f64,
    frames: Option<(f64, f64)>,
    /// Whether frames advance.
    pub playing: bool,
    /// Whether the level of detail is on (off: every strand).
    lod: bool,
    /// The player's level of detail, kept while it is off.
    lod_settings: pelage_gpu::FurLod,
    /// Milliseconds of the guides and the hairs, last frame.
    pub last_simulation_ms: f64,
}

impl RealtimeSession {
    /// The groom file at `path`, played into targets of `format`.
    pub fn new(
        ctx: &GpuContext,
        path: &Path,
        format: pelage_gpu::wgpu::TextureFormat,
    ) -> anyhow::Result<Self> {
        let groom = Groom::load(path)?;
        let fur = RealtimeFur::new(ctx, groom, ShellTargetFormats::pelage(format))
            .with_context(|| format!("{}: cannot play it in real time", path.display()))?;
        let frames = fur
            .frames()
            .map(|f| (f64::from(f.first()), f64::from(f.last())));
        let lod_settings = fur.lod;
        println!(
            "{}: {} hairs from {} guides, in real time{}",
            path.display(),
            fur.stats().hairs,
            fur.guide_count(),
            frames.map_or(String::new(), |(a, b)| format!(", frames {a}–{b}"))
        );
        Ok(Self {
            fur,
            target: None,
            frame: frames.map_or(1.0, |f| f.0),
            frames,
            playing: true,
            lod: true,
            lod_settings,
            last_simulation_ms: 0.0,
        })
    }

    /// Holds the frame `seconds` into the animation (a script's `time`):
    /// paused there.
    pub fn hold_at(&mut self, seconds: f32) {
        if let Some((first, last)) = self.frames {
            let frame = first + f64::from(seconds) * self.fur.fps();
            self.frame = frame.clamp(first, last).round();
        }
        self.playing = false;
    }

    /// The camera framing the fur.
    pub fn initial_orbit(&self, aspect: f32) -> OrbitCamera {
        let (lo, hi) = self.fur.bounds();
        OrbitCamera::from_camera(Camera::framing(lo, hi, aspect))
    }

    /// The next frame: one animation frame on while playing (a simulated
    /// groom steps its guides once a frame), the hairs grown again.
    pub fn advance(&mut self, ctx: &GpuContext) -> anyhow::Result<()> {
        if self.playing
            && let Some((first, last)) = self.frames
        {
            self.frame = if self.frame + 1.0 > last {
                first
            } else {
                self.frame + 1.0
            };
        }
        self.fur.advance_to(ctx, self.frame)?;
        let stats = self.fur.stats();
        self.last_simulation_ms = stats.sim_ms + stats.eval_ms;
        Ok(())
    }

    /// Records the frame into `resolve` (`width × height`).
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut pelage_gpu::wgpu::CommandEncoder,
        orbit: &OrbitCamera,
        resolve: &pelage_gpu::wgpu::TextureView,
        width: u32,
        height: u32,
    ) -> anyhow::Result<()> {
        if self
            .target
            .as_ref()
            .is_none_or(|t| t.size() != (width, height))
        {
            self.target = Some(ShellTarget::new(
                ctx,
                self.fur.shell_renderer(),
                width,
                height,
            )?);
        }
        let (lo, hi) = self.fur.bounds();
        let view = ShellView::new(
            Some(orbit.camera()),
            (lo, hi),
            0.0,
            width as f32 / height.max(1) as f32,
            None,
        );
        self.fur.lod = if self.lod {
            self.lod_settings
        } else {
            pelage_gpu::FurLod {
                full_px: 1.0,
                ..self.lod_settings
            }
        };
        let target = self.target.as_ref().expect("made above");
        self.fur.encode_to(ctx, encoder, &view, target, resolve)?;
        Ok(())
    }

    /// The panel: the counts, the level of detail, each stage's time.
    pub fn panel(&mut self, ui: &mut egui::Ui) {
        let s = self.fur.stats();
        ui.heading("Real time");
        ui.label(format!(
            "{} hairs, {} guides",
            s.hairs,
            self.fur.guide_count()
        ));
        if let Some((first, last)) = self.frames {
            ui.horizontal(|ui| {
                if ui
                    .button(if self.playing { "Pause" } else { "Play" })
                    .clicked()
                {
                    self.playing = !self.playing;
                }
                let slider = ui.add(egui::Slider::new(&mut self.frame, first..=last).text("frame"));
                if slider.dragged() {
                    self.playing = false;
                }
            });
        }
        ui.separator();
        ui.checkbox(&mut self.lod, "level of detail");
        ui.add(
            egui::Slider::new(&mut self.lod_settings.full_px, 50.0..=2000.0)
                .logarithmic(true)
                .text("every strand at (px)"),
        );
        ui.label(format!(
            "strands drawn: {} ({:.0} %), strands {:.0} %, shells {:.0} %",
            s.drawn,
            100.0 * f64::from(s.drawn) / f64::from(s.hairs.max(1)),
            100.0 * s.level.strand_opacity,
            100.0 * s.level.shell_opacity
        ));
        ui.separator();
        ui.label(format!("guides: {:.1} ms", s.sim_ms));
        ui.label(format!("hairs grown: {:.1} ms", s.eval_ms));
    }
}
