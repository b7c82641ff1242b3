//! [`RealtimeFur`]: a groom file played in real time, what `pelage view
//! --realtime`, `pelage demo fox --realtime` and `pelage bench realtime`
//! drive. Each frame: the skin posed (its glTF rig, on the GPU), the
//! guides simulated on the GPU when the groom's `[animation]` says
//! `simulate` (else they follow the skin), every hair grown again
//! ([`GpuGroom`]), then the skin, the shell stand-in and the strands drawn
//! at the level of detail the character's size on screen asks for
//! ([`FurLod`]).

use crate::{
    FurLevel, FurLevelParams, FurLod, GpuContext, GpuError, GpuGroom, GpuStrands, ShellFeatures,
    ShellModel, ShellParams, ShellRenderer, ShellStandIn, ShellTarget, ShellTargetFormats,
    ShellUpload, ShellView, StrandBinding, StrandParams, StrandRenderer,
};
use glam::Vec3;
use pelage::anim::SkinPose;
use pelage::dynamics::{GuideSimulation, GuideStrandParams};
use pelage::groom::{AnimatedGroom, AnimationMode, Groom, GroomError, GroomRecipe};
use pelage::guides::Guides;
use pelage::shell::ShellTextures;
use std::time::Instant;

/// Shell layers of the stand-in far away.
const STAND_IN_LAYERS: u32 = 16;

/// What playing a groom in real time failed on.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RealtimeError {
    /// The groom (its file, its guides, its simulation settings).
    #[error(transparent)]
    Groom(#[from] GroomError),
    /// The GPU.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// The skin at a frame.
    #[error(transparent)]
    Mesh(#[from] pelage::mesh::MeshError),
    /// The guides' simulation.
    #[error(transparent)]
    Strands(#[from] pelage::dynamics::StrandError),
    /// A skin real-time strands cannot follow.
    #[error("{0}")]
    Unsupported(String),
}

/// Milliseconds of each stage of the last frame, and what it drew.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RealtimeStats {
    /// Render hairs in the groom.
    pub hairs: u32,
    /// Strands drawn (the level of detail's share).
    pub drawn: u32,
    /// The level drawn.
    pub level: FurLevel,
    /// The guides simulated (or carried) and brought to rest space.
    pub sim_ms: f64,
    /// Every hair grown on the GPU.
    pub eval_ms: f64,
    /// The skin, shells and strands drawn.
    pub draw_ms: f64,
}

/// The guides simulated on the GPU, a step a frame.
struct Simulated {
    sim: GuideSimulation,
    gpu: GpuStrands,
    params: GuideStrandParams,
    fps: f64,
}

/// A groom file played in real time (module docs).
pub struct RealtimeFur {
    animated: Option<AnimatedGroom>,
    hairs: u32,
    groom: GpuGroom,
    rest_offsets: Vec<Vec3>,
    strands: StrandRenderer,
    binding: StrandBinding,
    shells: ShellRenderer,
    model: ShellModel,
    stand_in: ShellStandIn,
    simulated: Option<Simulated>,
    guides: usize,
    bounds: (Vec3, Vec3),
    frame: f64,
    stats: RealtimeStats,
    /// When to draw what (change it between frames).
    pub lod: FurLod,
    /// The strands' look and shadows at full detail.
    pub strand_params: StrandParams,
    /// The skin's and shells' shading and background.
    pub shell_params: ShellParams,
}

impl std::fmt::Debug for RealtimeFur {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RealtimeFur")
            .field("hairs", &self.hairs)
            .field("frame", &self.frame)
            .finish_non_exhaustive()
    }
}

impl RealtimeFur {
    /// Prepares `groom` (loaded from its file) for playing into targets of
    /// `formats`: its hairs ordered by arrival (a level of detail draws
    /// the first), uploaded once; a glTF skin's rig on the GPU; the shell
    /// stand-in. An animated groom in `simulate` mode has its guides
    /// simulated frame by frame on the GPU instead of over its range
    /// first.
    ///
    /// # Errors
    /// When the groom cannot be prepared or uploaded, or its animated
    /// skin has no glTF rig.
    pub fn new(
        ctx: &GpuContext,
        mut groom: Groom,
        formats: ShellTargetFormats,
    ) -> Result<Self, RealtimeError> {
        let simulation = groom.simulation_settings_for_playing()?;
        groom.set_animation_mode(AnimationMode::Deform);
        let animated = groom.animated(None)?;
        let still;
        let generator = match &animated {
            Some(a) => a.generator(),
            None => {
                still = groom.generator(None)?;
                &still
            }
        };
        let (roots, ids) = pelage::groom::roots_by_arrival(generator);
        let recipe = GroomRecipe::new(generator, &roots, &ids)?;
        let skin = match &animated {
            Some(a) => a.binding().clone(),
            None => GpuGroom::skin_at_rest(generator.mesh()),
        };
        let hairs = GpuGroom::new(ctx, &recipe, &skin)?;
        let rest_offsets = GroomRecipe::guide_offsets(generator.guides());
        // The stand-in clumps as the groom's first clump does.
        let clumps = pelage_shaders::stand_in::clump_mask(generator);
        let features = ShellFeatures {
            clump: clumps.is_some(),
            ..ShellFeatures::default()
        };
        let shells = ShellRenderer::for_targets(&ctx.device, formats, features);
        let mask_size = clumps.as_ref().map_or(16, |(mask, _)| mask.width());
        let strands = StrandRenderer::new(ctx, formats);
        let binding = strands.bind(ctx, &hairs);
        let stand_in = ShellStandIn::of(generator, STAND_IN_LAYERS);
        let look = crate::StrandLook::default();
        let texture = stand_in.color_texture(&groom, look.color)?;
        let textures = ShellTextures::generate(&stand_in.texture);
        let (model, bounds) = match &animated {
            Some(a) => {
                let rig = a.skin().rig().ok_or_else(|| {
                    RealtimeError::Unsupported(format!(
                        "{}: real-time strands follow a glTF skin's rig; this animated skin has none",
                        groom.path().display()
                    ))
                })?;
                let rest = a.skin().mesh_at(a.animation().rest_frame)?;
                let upload = ShellUpload {
                    rig: Some(rig),
                    per_corner: false,
                };
                let model =
                    shells.upload_with(ctx, &rest, &texture, &textures, mask_size, upload)?;
                (model, rest.bounds())
            }
            None => {
                let mesh = generator.mesh();
                (
                    shells.upload(ctx, mesh, &texture, &textures, mask_size)?,
                    mesh.bounds(),
                )
            }
        };
        let mut shell_params = ShellParams::plain(0, stand_in.length).for_stand_in(&stand_in);
        if let Some((mask, clump)) = &clumps {
            shells.set_wetness(ctx, &model, mask)?;
            shell_params.clump = *clump;
        }
        let simulated = match (&animated, simulation) {
            (Some(a), Some(settings)) => {
                let pose = a.pose(a.animation().frames.first() as f64)?;
                let sim = GuideSimulation::new(
                    generator.guides(),
                    a.binding().triangles(),
                    &pose,
                    settings.params.clone(),
                    settings.collide,
                )?;
                let gpu = GpuStrands::new(ctx, sim.strands())?;
                Some(Simulated {
                    sim,
                    gpu,
                    params: settings.params,
                    fps: settings.fps,
                })
            }
            _ => None,
        };
        let hair_count = recipe.render_hairs().len() as u32;
        Ok(Self {
            hairs: hair_count,
            groom: hairs,
            rest_offsets,
            strands,
            binding,
            shells,
            model,
            simulated,
            guides: generator.guides().len(),
            bounds,
            frame: f64::NAN,
            stats: RealtimeStats {
                hairs: hair_count,
                drawn: hair_count,
                level: FurLod::default().level(f32::INFINITY),
                sim_ms: 0.0,
                eval_ms: 0.0,
                draw_ms: 0.0,
            },
            lod: FurLod::default(),
            strand_params: StrandParams::for_length(stand_in.length),
            shell_params,
            stand_in,
            animated,
        })
    }

    /// The groom's frames (`None`: a still groom).
    pub fn frames(&self) -> Option<pelage::anim::FrameRange> {
        self.animated.as_ref().map(|a| a.animation().frames.clone())
    }

    /// Frames per second of the groom's animation (24 for a still one).
    pub fn fps(&self) -> f64 {
        self.animated.as_ref().map_or(24.0, |a| a.skin().fps())
    }

    /// The skin's bounds at rest, grown by the hairs' length: where the fur is.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let grow = Vec3::splat(2.0 * self.stand_in.length);
        (self.bounds.0 - grow, self.bounds.1 + grow)
    }

    /// The groom's guides.
    pub fn guide_count(&self) -> usize {
        self.guides
    }

    /// The animated groom played (`None`: a still one), carried frame by
    /// frame: what a CPU reference grows from.
    pub fn animated(&self) -> Option<&AnimatedGroom> {
        self.animated.as_ref()
    }

    /// The last frame's guides in rest space, when they were simulated:
    /// read back from the GPU and turned to rest on the CPU (a reference
    /// for comparisons; a frame itself reads nothing back).
    ///
    /// # Errors
    /// When the read-back fails.
    pub fn frame_guides(&self, ctx: &GpuContext) -> Result<Option<Guides>, RealtimeError> {
        let (Some(s), Some(a)) = (&self.simulated, &self.animated) else {
            return Ok(None);
        };
        let pose = a.pose(self.frame)?;
        let posed = s.gpu.read_positions(ctx)?;
        let rest = a.generator().guides();
        let n = rest.points_per_guide();
        let mut points = vec![Vec3::ZERO; posed.len()];
        for (i, (&root, out)) in rest.roots().iter().zip(points.chunks_mut(n)).enumerate() {
            a.binding()
                .to_rest(&posed[i * n..(i + 1) * n], root, &pose, out);
        }
        let guides = rest.with_points(points).map_err(|e| {
            RealtimeError::Unsupported(format!("simulated guides at frame {}: {e}", self.frame))
        })?;
        Ok(Some(guides))
    }

    /// The last frame's figures.
    pub fn stats(&self) -> RealtimeStats {
        self.stats
    }

    /// Moves to `frame`: the skin posed, the guides stepped once (a
    /// simulated groom; frames are meant to follow each other), every hair
    /// grown again. Waits for the GPU to time each stage.
    ///
    /// # Errors
    /// When the skin cannot be posed or the GPU fails.
    pub fn advance_to(&mut self, ctx: &GpuContext, frame: f64) -> Result<(), RealtimeError> {
        let start = Instant::now();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let pose = match &self.animated {
            None => None,
            Some(a) => {
                let pose = a.pose(frame)?;
                if let Some(s) = &mut self.simulated {
                    step_guides(ctx, s, &pose, frame)?;
                }
                if let Some(palette) = a.skin().palette_at_frame(frame) {
                    self.shells.pose_now(ctx, &self.model, &palette)?;
                }
                Some(pose)
            }
        };
        let sim_ms = 1e3 * start.elapsed().as_secs_f64();
        let start = Instant::now();
        match (&self.simulated, &pose) {
            // The guides straight from the GPU strands: no read-back.
            (Some(s), Some(pose)) => {
                self.groom
                    .record_from_strands(ctx, &mut encoder, &s.gpu, pose)?;
            }
            _ => {
                self.groom
                    .record(ctx, &mut encoder, &self.rest_offsets, pose.as_ref())?;
            }
        }
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
        self.stats.sim_ms = sim_ms;
        self.stats.eval_ms = 1e3 * start.elapsed().as_secs_f64();
        self.frame = frame;
        Ok(())
    }

    /// The level of detail `view` sees the character at in a target
    /// `height_px` pixels high.
    pub fn level(&self, view: &ShellView, height_px: f32) -> FurLevel {
        let (lo, hi) = self.bounds;
        let centre = 0.5 * (lo + hi);
        let size = (hi - lo).max_element();
        self.lod
            .level(view.projected_length(centre, size, height_px))
    }

    /// The frame drawn into pelage's own `target` (the key light's maps,
    /// then the skin, shells and strands in one pass), waited for.
    ///
    /// # Errors
    /// When the GPU fails.
    pub fn draw(
        &mut self,
        ctx: &GpuContext,
        view: &ShellView,
        target: &ShellTarget,
    ) -> Result<(), RealtimeError> {
        let start = Instant::now();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.encode(ctx, &mut encoder, view, target)?;
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()?;
        self.stats.draw_ms = 1e3 * start.elapsed().as_secs_f64();
        Ok(())
    }

    /// [`Self::draw`] read back: a picture.
    ///
    /// # Errors
    /// When the GPU fails or the read-back does.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        view: &ShellView,
        target: &ShellTarget,
    ) -> Result<image::RgbaImage, RealtimeError> {
        let start = Instant::now();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.encode(ctx, &mut encoder, view, target)?;
        let image = crate::readback::read_texture(ctx, encoder, target.resolved())?;
        self.stats.draw_ms = 1e3 * start.elapsed().as_secs_f64();
        Ok(image)
    }

    /// Records the frame into `encoder` and pelage's own `target`.
    fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        view: &ShellView,
        target: &ShellTarget,
    ) -> Result<(), RealtimeError> {
        let resolve = target.resolved().create_view(&Default::default());
        self.encode_to(ctx, encoder, view, target, &resolve)
    }

    /// Records the frame into `encoder`: drawn in `target` (of this
    /// player's formats), resolved into `resolve` (a view of its size: a
    /// window's surface texture). The key light's maps are a pass of their
    /// own before it.
    ///
    /// # Errors
    /// When the skin cannot be drawn.
    pub fn encode_to(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        view: &ShellView,
        target: &ShellTarget,
        resolve: &wgpu::TextureView,
    ) -> Result<(), RealtimeError> {
        let (_, height) = target.size();
        let level = self.level(view, height as f32);
        let strands = level
            .strands(self.strand_params, self.hairs)
            .unwrap_or(StrandParams {
                hairs: Some(0),
                ..self.strand_params
            });
        let shells = level.shells(ShellParams {
            layers: self.stand_in.texture.layers,
            ..self.shell_params
        });
        self.stats.level = level;
        self.stats.drawn = strands.hairs.unwrap_or(self.hairs);
        let skin = (&self.shells, &self.model, &shells);
        self.strands.encode_to(
            ctx,
            encoder,
            &self.binding,
            &strands,
            view,
            self.bounds(),
            (Some(skin), target, resolve),
        )?;
        Ok(())
    }

    /// The shell renderer drawing the skin and the stand-in (for targets).
    pub fn shell_renderer(&self) -> &ShellRenderer {
        &self.shells
    }
}

/// One step of the simulated guides to `frame` on the GPU, the skin's
/// roots and grids made on the CPU.
fn step_guides(
    ctx: &GpuContext,
    s: &mut Simulated,
    pose: &SkinPose,
    frame: f64,
) -> Result<(), RealtimeError> {
    let roots = s.sim.root_frames(pose);
    let grids = s.sim.substep_grids(pose);
    let dt = (1.0 / s.fps) as f32;
    s.gpu
        .step(ctx, &s.params, dt, (frame / s.fps) as f32, &roots, &grids)?;
    s.sim.note_pose(pose);
    Ok(())
}
