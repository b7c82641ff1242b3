//! `pelage bench shells`, the rows for game characters: what indexed
//! layer vertices, back-face culling and the level of detail save on one
//! heavy mesh; a skinned character (GPU skinning + dynamics fed by the
//! skin + shells) against the same mesh standing still; a crowd of 100
//! furred objects spread in depth with and without the level of detail;
//! and fins against shells alone. Every figure is a median of frames
//! interleaved with its peers', so a noisy machine's drift hits them alike.

use super::interleaved;
use glam::Vec3;
use pelage::shell::scene::DynamicsSettings;
use pelage::shell::{ShellAnimation, ShellScene, ShellTextureParams, ShellTextures};
use pelage_gpu::{
    FinParams, FurMotion, GpuContext, ShellFeatures, ShellLod, ShellParams, ShellRenderer,
    ShellTarget, ShellUpload, ShellView, SkinMotion,
};

/// One measured configuration: a name and its median frame in ms.
pub struct Timed {
    pub name: &'static str,
    pub ms: f64,
}

/// A row: what was drawn, and its configurations (the first is the peer
/// the others are divided by).
pub struct GameRow {
    pub what: String,
    pub timed: Vec<Timed>,
}

impl GameRow {
    /// The peer's time over configuration `k`'s (> 1: `k` is faster).
    pub fn speedup(&self, k: usize) -> f64 {
        self.timed[0].ms / self.timed[k].ms
    }

    /// Configuration `k`'s time over the peer's.
    pub fn ratio(&self, k: usize) -> f64 {
        self.timed[k].ms / self.timed[0].ms
    }
}

/// The four rows.
pub struct GameFigures {
    pub geometry: GameRow,
    pub skinned: GameRow,
    pub crowd: GameRow,
    pub fins: GameRow,
}

fn row(what: String, names: &[&'static str], ms: Vec<f64>) -> GameRow {
    GameRow {
        what,
        timed: names
            .iter()
            .zip(ms)
            .map(|(&name, ms)| Timed { name, ms })
            .collect(),
    }
}

/// Runs the four rows (`quick`: smaller meshes and images).
pub fn measure(ctx: &GpuContext, quick: bool, frames: usize) -> anyhow::Result<GameFigures> {
    Ok(GameFigures {
        geometry: geometry(ctx, quick, frames)?,
        skinned: skinned(ctx, quick, frames)?,
        crowd: crowd(ctx, quick, frames)?,
        fins: fins(ctx, frames)?,
    })
}

fn textures(layers: u32) -> ShellTextures {
    ShellTextures::generate(&ShellTextureParams {
        layers,
        ..ShellScene::spot().texture
    })
}

/// spot ×3 (×2 quick), 64 layers at 1680×1050 (16 at 800×600 quick):
/// a vertex per triangle corner (what pelage drew before), indexed, + back
/// faces culled, + the level of detail.
fn geometry(ctx: &GpuContext, quick: bool, frames: usize) -> anyhow::Result<GameRow> {
    let (levels, layers, size) = if quick {
        (2, 16, (800, 600))
    } else {
        (3, 64, (1680, 1050))
    };
    let scene = ShellScene::spot();
    let mesh = pelage::assets::spot().subdivided(levels);
    let textures = textures(layers);
    let plain = ShellRenderer::new(ctx, ShellFeatures::PLAIN);
    let culled = ShellRenderer::new(
        ctx,
        ShellFeatures {
            cull_back: true,
            ..ShellFeatures::PLAIN
        },
    );
    let upload = |r: &ShellRenderer, per_corner| {
        r.upload_with(
            ctx,
            &mesh,
            &scene.color,
            &textures,
            64,
            ShellUpload {
                rig: None,
                per_corner,
            },
        )
    };
    let corners = upload(&plain, true)?;
    let indexed = upload(&plain, false)?;
    let indexed_culled = upload(&culled, false)?;
    let target = ShellTarget::new(ctx, &plain, size.0, size.1)?;
    let length = 0.025 * (mesh.bounds().1 - mesh.bounds().0).length();
    let view = ShellView::new(
        None,
        mesh.bounds(),
        length,
        size.0 as f32 / size.1 as f32,
        None,
    );
    let params = ShellParams {
        layers,
        length,
        ..ShellParams::from_scene(&scene)
    };
    let with_lod = ShellParams {
        lod: Some(ShellLod::default()),
        ..params
    };
    let level = culled.level(&indexed_culled, &with_lod, &view, size.1 as f32);
    let ms = interleaved(
        frames,
        &mut [
            &mut || Ok(plain.draw(ctx, &corners, &params, &view, &target)?),
            &mut || Ok(plain.draw(ctx, &indexed, &params, &view, &target)?),
            &mut || Ok(culled.draw(ctx, &indexed_culled, &params, &view, &target)?),
            &mut || Ok(culled.draw(ctx, &indexed_culled, &with_lod, &view, &target)?),
        ],
    )?;
    Ok(row(
        format!(
            "spot ×{levels} ({} triangles, {} → {} vertices a layer), {layers} layers, {}×{}; the level of detail draws {:.1}",
            crate::format::thousands(mesh.triangle_count() as u64),
            crate::format::thousands(corners.vertex_count() as u64),
            crate::format::thousands(indexed.vertex_count() as u64),
            size.0,
            size.1,
            level.layers
        ),
        &[
            "a vertex a corner",
            "indexed",
            "+ culled",
            "+ level of detail",
        ],
        ms,
    ))
}

/// The Fox subdivided 5 times (590 k triangles; 2 quick), running: the
/// skinning pass, the dynamics fed by the posed skin (CPU posing +
/// implicit spring-sticks) and 32 layers (16 quick) at 800×600, against
/// the same mesh standing still with the same dynamics and layers.
fn skinned(ctx: &GpuContext, quick: bool, frames: usize) -> anyhow::Result<GameRow> {
    let (levels, layers) = if quick { (2, 16) } else { (5, 32) };
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../pelage/assets/fox/Fox.gltf");
    let fox = ShellAnimation::load(&path, "Run", levels)?;
    let still = fox.mesh_at(0.0)?;
    let textures = textures(layers);
    let color = image::RgbaImage::from_pixel(1, 1, image::Rgba([190, 110, 50, 255]));
    let renderer = ShellRenderer::new(ctx, ShellFeatures::PLAIN);
    let skinned = renderer.upload_with(
        ctx,
        fox.rest_mesh(),
        &color,
        &textures,
        64,
        ShellUpload {
            rig: Some(fox.rig()),
            per_corner: false,
        },
    )?;
    let standing = renderer.upload(ctx, &still, &color, &textures, 64)?;
    let target = ShellTarget::new(ctx, &renderer, 800, 600)?;
    let (lo, hi) = still.bounds();
    let length = 0.02 * (hi - lo).length();
    let view = ShellView::new(None, still.bounds(), 4.0 * length, 800.0 / 600.0, None);
    let settings = DynamicsSettings::default();
    let params = ShellParams {
        layers,
        length,
        coupling: settings.coupling,
        ..ShellParams::from_scene(&ShellScene::spot())
    };
    let mut moving = FurMotion::new(&still, settings.topology, length);
    let mut resting = FurMotion::new(&still, settings.topology, length);
    let dt = 1.0 / 48.0;
    let mut frame_of_still = || -> anyhow::Result<()> {
        for _ in 0..2 {
            resting.step(ctx, dt, SkinMotion::Offset(Vec3::ZERO), &settings)?;
        }
        resting.show(ctx, &renderer, &standing)?;
        Ok(renderer.draw(ctx, &standing, &params, &view, &target)?)
    };
    let mut frame_of_run = || -> anyhow::Result<()> {
        for _ in 0..2 {
            let t = moving.time() + dt;
            moving.step_scene(ctx, dt, Some(&fox), t, Vec3::ZERO, &settings)?;
        }
        renderer.pose_now(ctx, &skinned, &fox.palette_at(moving.time()))?;
        moving.show(ctx, &renderer, &skinned)?;
        Ok(renderer.draw(ctx, &skinned, &params, &view, &target)?)
    };
    let ms = interleaved(frames, &mut [&mut frame_of_still, &mut frame_of_run])?;
    Ok(row(
        format!(
            "the Fox ×{levels} ({} triangles), {layers} layers, 800×600, dynamics 2 steps a frame",
            crate::format::thousands(still.triangle_count() as u64)
        ),
        &["standing still", "running (skinned)"],
        ms,
    ))
}

/// 100 spots spread in depth, 32 layers, 800×600 (16 quick), drawn in
/// one pass with and without the level of detail.
fn crowd(ctx: &GpuContext, quick: bool, frames: usize) -> anyhow::Result<GameRow> {
    let layers = if quick { 16 } else { 32 };
    let scene = ShellScene::spot();
    let textures = textures(layers);
    let renderer = ShellRenderer::new(ctx, ShellFeatures::PLAIN);
    let model = renderer.upload(ctx, &scene.mesh, &scene.color, &textures, 64)?;
    let target = ShellTarget::new(ctx, &renderer, 800, 600)?;
    let (view, offsets) = crowd_layout();
    let base = ShellParams {
        layers,
        ..ShellParams::from_scene(&scene)
    };
    let objects = |lod: Option<ShellLod>| -> Vec<_> {
        offsets
            .iter()
            .map(|&offset| {
                (
                    &model,
                    ShellParams {
                        offset,
                        lod,
                        ..base
                    },
                )
            })
            .collect()
    };
    let (all, lod) = (objects(None), objects(Some(ShellLod::default())));
    let drawn: f32 = lod
        .iter()
        .map(|(m, p)| renderer.level(m, p, &view, 600.0).layers.ceil())
        .sum();
    let frame = |objects: &[(&pelage_gpu::ShellModel, ShellParams)]| -> anyhow::Result<()> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let resolve = target.resolve_view();
        renderer.encode_all(ctx, &mut encoder, objects, &view, &target, &resolve)?;
        ctx.queue.submit([encoder.finish()]);
        ctx.device
            .poll(pelage_gpu::wgpu::PollType::wait_indefinitely())
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(())
    };
    let ms = interleaved(frames, &mut [&mut || frame(&all), &mut || frame(&lod)])?;
    Ok(row(
        format!(
            "100 spots spread in depth, {layers} layers, 800×600; the level of detail draws {:.1} layers on average",
            drawn / 100.0
        ),
        &["every layer", "level of detail"],
        ms,
    ))
}

/// The crowd's camera and the 100 objects' offsets: ten rows of ten
/// (1.8 units apart; rows 3 units apart), seen from above the first row,
/// from 8 to 35 units away; the near rows spill out of the view.
fn crowd_layout() -> (ShellView, Vec<Vec3>) {
    let eye = Vec3::new(0.0, 4.0, 6.0);
    let view = pelage_gpu::Camera {
        eye,
        target: Vec3::new(0.0, 0.0, -20.0),
        fov_y_degrees: 40.0,
    };
    let clip_from_world = view.clip_from_world(800.0 / 600.0, 80.0);
    let offsets = (0..100)
        .map(|i| {
            let (row, column) = ((i / 10) as f32, (i % 10) as f32);
            Vec3::new((column - 4.5) * 1.8, 0.0, -2.0 - 3.0 * row)
        })
        .collect();
    (
        ShellView {
            clip_from_world,
            eye,
            light: Vec3::new(0.4, 0.9, 0.5).normalize(),
        },
        offsets,
    )
}

/// spot ×2, 16 layers, 800×600 (quick or not): shells alone, and with fins.
fn fins(ctx: &GpuContext, frames: usize) -> anyhow::Result<GameRow> {
    let scene = ShellScene::spot();
    let mesh = pelage::assets::spot().subdivided(2);
    let textures = textures(16);
    let renderer = ShellRenderer::new(ctx, ShellFeatures::PLAIN);
    let model = renderer.upload(ctx, &mesh, &scene.color, &textures, 64)?;
    let target = ShellTarget::new(ctx, &renderer, 800, 600)?;
    let length = 0.025 * (mesh.bounds().1 - mesh.bounds().0).length();
    let view = ShellView::new(None, mesh.bounds(), length, 800.0 / 600.0, None);
    let params = ShellParams {
        layers: 16,
        length,
        ..ShellParams::from_scene(&scene)
    };
    let with_fins = ShellParams {
        fins: Some(FinParams::default()),
        ..params
    };
    let ms = interleaved(
        frames,
        &mut [
            &mut || Ok(renderer.draw(ctx, &model, &params, &view, &target)?),
            &mut || Ok(renderer.draw(ctx, &model, &with_fins, &view, &target)?),
            &mut || {
                let none_shown = ShellParams {
                    fins: Some(FinParams {
                        opacity: 1.0,
                        width: 1e-6,
                    }),
                    ..params
                };
                Ok(renderer.draw(ctx, &model, &none_shown, &view, &target)?)
            },
        ],
    )?;
    Ok(row(
        format!(
            "spot ×2 ({} triangles, {} fins), 16 layers, 800×600",
            crate::format::thousands(mesh.triangle_count() as u64),
            crate::format::thousands(u64::from(model.fin_count()))
        ),
        &["shells", "shells + fins", "fins, none shown"],
        ms,
    ))
}
