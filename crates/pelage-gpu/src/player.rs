//! [`ShellScenePlayer`]: a shell scene file drawn frame by frame.

use crate::{Camera, FurMotion, GpuContext, GpuError};
use glam::Vec3;

use crate::shells::{
    ShellFeatures, ShellModel, ShellParams, ShellRenderer, ShellTarget, ShellView,
};
use pelage::shell::{ShellScene, WetnessMask};

/// A scene file drawn frame by frame: the model uploaded once, the
/// wetness mask advanced in time (droplets falling, fur drying) and
/// re-uploaded each frame.
#[derive(Debug)]
pub struct ShellScenePlayer<'s> {
    scene: &'s ShellScene,
    renderer: ShellRenderer,
    model: ShellModel,
    target: ShellTarget,
    /// What is drawn; change it between frames.
    pub params: ShellParams,
    /// From where; change it between frames.
    pub view: ShellView,
    timeline: pelage::shell::scene::WetnessTimeline<'s>,
    motion: Option<FurMotion>,
}

impl<'s> ShellScenePlayer<'s> {
    /// Generates the shell texture, uploads the scene and sets up
    /// `width × height` targets. Curl and clumping are computed when the
    /// scene asks for them.
    pub fn new(
        ctx: &GpuContext,
        scene: &'s ShellScene,
        width: u32,
        height: u32,
    ) -> Result<Self, GpuError> {
        let features = ShellFeatures {
            curl: scene.curl.radius != 0.0,
            clump: scene.clump.is_some(),
            cull_back: scene.fur.cull_back,
        };
        let renderer = ShellRenderer::new(ctx, features);
        let model = renderer.upload_scene(ctx, scene)?;
        let target = ShellTarget::new(ctx, &renderer, width, height)?;
        let camera = scene.camera.map(|c| {
            let (lo, hi) = scene.mesh.bounds();
            let l = Vec3::splat(scene.fur.length);
            Camera::from_scene(&c, lo - l, hi + l, width as f32 / height as f32)
        });
        let view = ShellView::new(
            camera,
            scene.mesh.bounds(),
            scene.fur.length,
            width as f32 / height as f32,
            scene.light,
        );
        Ok(Self {
            scene,
            renderer,
            model,
            target,
            params: ShellParams::from_scene(scene),
            view,
            timeline: scene.wetness_timeline(),
            motion: scene
                .dynamics
                .as_ref()
                .map(|d| FurMotion::new(&scene.mesh, d.topology, scene.fur.length)),
        })
    }

    /// Warnings about the scene as it will play (today: automatic
    /// explicit substeps capped at pelage's ceiling), for the caller to
    /// show.
    pub fn warnings(&self) -> Vec<String> {
        let (Some(motion), Some(settings)) = (&self.motion, &self.scene.dynamics) else {
            return Vec::new();
        };
        let dt = 1.0 / (self.scene.fps * settings.steps_per_frame as f32);
        motion.substeps_warning(dt, settings).into_iter().collect()
    }

    /// Runs the scene's mass-spring system up to `time`, in steps of
    /// `1 / (fps · steps_per_frame)`, the skin posed by its animation at
    /// each step and moved as the shake says.
    fn simulate_to(&mut self, ctx: &GpuContext, time: f32) -> Result<(), GpuError> {
        let (Some(motion), Some(settings)) = (&mut self.motion, &self.scene.dynamics) else {
            return Ok(());
        };
        let dt = 1.0 / (self.scene.fps * settings.steps_per_frame as f32);
        let shake = |t: f32| settings.shake.map_or(Vec3::ZERO, |s| s.offset(t));
        while motion.time() + 0.5 * dt < time {
            let t = motion.time() + dt;
            let animation = self.scene.animation.as_ref();
            motion.step_scene(ctx, dt, animation, t, shake(t), settings)?;
        }
        self.params.coupling = settings.coupling;
        self.params.offset = shake(motion.time());
        motion.show(ctx, &self.renderer, &self.model)
    }

    /// The frame at `time` seconds (not before the last one drawn).
    pub fn render_at(&mut self, ctx: &GpuContext, time: f32) -> Result<image::RgbaImage, GpuError> {
        if let Some(animation) = &self.scene.animation {
            self.renderer
                .pose_now(ctx, &self.model, &animation.palette_at(time))?;
        }
        self.simulate_to(ctx, time)?;
        let mask = self.timeline.advance_to(time);
        self.renderer.set_wetness(ctx, &self.model, mask)?;
        self.renderer
            .render(ctx, &self.model, &self.params, &self.view, &self.target)
    }

    /// The wetness mask as of the last frame.
    pub fn wetness(&self) -> &WetnessMask {
        self.timeline.mask()
    }

    /// The scene.
    pub fn scene(&self) -> &'s ShellScene {
        self.scene
    }
}
