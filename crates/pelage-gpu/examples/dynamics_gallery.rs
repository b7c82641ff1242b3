//! Moving shell fur, for `docs/gallery/` (run from the repository root):
//!
//! ```text
//! cargo run --release -p pelage-gpu --example dynamics_gallery
//! ```
//!
//! - `banisch-fig13-wind.gif` and `banisch-fig13.png` (four frames): grass
//!   waving in gusting, turbulent wind (prisms, bent layers, implicit),
//! - `banisch-fig12-parting.png`: a brush pushing into grass — prisms drag
//!   their neighbours along (left), separable prisms part (right),
//! - `shells-spot-shake.gif` and `shells-spot-shake.png`: spot shaken for a
//!   second, its fur lagging and settling (spring-sticks, implicit).

use glam::Vec3;
use pelage::Mesh;
use pelage::dynamics::{DynamicsParams, MassSpringSystem, PushBrush, Solver, Topology, Wind};
use pelage::shell::math::{ClumpParams, Coupling, CurlParams, ShadingMode};
use pelage::shell::scene::{DynamicsSettings, Shake};
use pelage::shell::{ShellScene, ShellTextureParams, ShellTextures, WetnessMask};
use pelage_gpu::{
    Camera, GpuContext, ShellFeatures, ShellParams, ShellRenderer, ShellScenePlayer, ShellTarget,
    ShellView,
};
use std::path::Path;

#[path = "common/patch.rs"]
mod patch;
use patch::patch;

const WIDTH: u32 = 360;
const HEIGHT: u32 = 270;
const FPS: f32 = 12.0;

fn write_gif(path: &Path, frames: &[image::RgbaImage]) {
    use image::codecs::gif::{GifEncoder, Repeat};
    let file = std::fs::File::create(path).expect("create the GIF");
    let mut encoder = GifEncoder::new_with_speed(file, 20);
    encoder.set_repeat(Repeat::Infinite).expect("repeat");
    let delay = image::Delay::from_numer_denom_ms(1000, FPS as u32);
    for f in frames {
        encoder
            .encode_frame(image::Frame::from_parts(f.clone(), 0, 0, delay))
            .expect("a frame");
    }
    println!("wrote {}", path.display());
}

fn strip(path: &Path, frames: &[&image::RgbaImage]) {
    let (w, h) = (frames[0].width(), frames[0].height());
    let mut sheet = image::RgbaImage::from_pixel(
        w * frames.len() as u32 + 4 * (frames.len() as u32 - 1),
        h,
        image::Rgba([255; 4]),
    );
    for (i, f) in frames.iter().enumerate() {
        image::imageops::replace(&mut sheet, *f, i64::from(i as u32 * (w + 4)), 0);
    }
    sheet.save(path).expect("write the strip");
    println!("wrote {}", path.display());
}

/// A patch of grass: its mesh, textures and drawing parameters.
struct Grass {
    mesh: Mesh,
    color: image::RgbaImage,
    textures: ShellTextures,
    params: ShellParams,
    camera: Camera,
}

fn grass() -> Grass {
    let mesh = patch(24);
    let textures = ShellTextures::generate(&ShellTextureParams {
        layers: 32,
        density: 0.012,
        thickness: 1.8,
        lean: 0.006,
        undercoat_ratio: 1.0,
        undercoat_length: 0.3,
        ..Default::default()
    });
    let params = ShellParams {
        layers: 32,
        length: 0.22,
        tiles: 2.5,
        curl: CurlParams {
            radius: 0.0,
            frequency: 0.0,
        },
        coupling: Coupling::Bent { exponent: 2.0 },
        offset: Vec3::ZERO,
        clump: ClumpParams {
            w: 0.0,
            strength: 0.0,
        },
        mode: ShadingMode::Lambert,
        kajiya_kay: pelage::shell::KajiyaKay {
            specular: Vec3::splat(0.05),
            exponent: 20.0,
            k_shadow: 1.6,
        },
        background: [0.62, 0.66, 0.72],
        fins: None,
        lod: None,
        opacity: 1.0,
    };
    Grass {
        mesh,
        color: image::RgbaImage::from_pixel(1, 1, image::Rgba([70, 140, 45, 255])),
        textures,
        params,
        camera: Camera {
            eye: Vec3::new(0.0, 0.75, 1.25),
            target: Vec3::new(0.0, 0.05, 0.0),
            fov_y_degrees: 38.0,
        },
    }
}

/// Simulates `system` on `grass` for `frames` frames, drawing each.
fn film(
    ctx: &GpuContext,
    grass: &Grass,
    system: &mut MassSpringSystem,
    dynamics: &DynamicsParams,
    frames: u32,
) -> Vec<image::RgbaImage> {
    let renderer = ShellRenderer::new(ctx, ShellFeatures::PLAIN);
    let model = renderer
        .upload(ctx, &grass.mesh, &grass.color, &grass.textures, 8)
        .expect("upload");
    renderer
        .set_wetness(ctx, &model, &WetnessMask::dry_mask(8, 8))
        .expect("mask");
    let target = ShellTarget::new(ctx, &renderer, WIDTH, HEIGHT).expect("target");
    let view = ShellView::new(
        Some(grass.camera),
        grass.mesh.bounds(),
        grass.params.length,
        WIDTH as f32 / HEIGHT as f32,
        Some(Vec3::new(0.3, 1.0, 0.5)),
    );
    let steps = 4;
    let dt = 1.0 / (FPS * steps as f32);
    let mut images = Vec::new();
    for frame in 0..frames {
        for k in 0..steps {
            let t = (frame * steps + k) as f32 * dt;
            system.step(dt, dynamics, Solver::Implicit { iterations: 30 }, t);
        }
        renderer
            .set_tip_offsets(ctx, &model, &system.corner_tip_offsets())
            .expect("tips");
        images.push(
            renderer
                .render(ctx, &model, &grass.params, &view, &target)
                .expect("render"),
        );
    }
    images
}

fn main() {
    let out = Path::new("docs/gallery");
    std::fs::create_dir_all(out).expect("docs/gallery");
    let ctx = GpuContext::headless().expect("a GPU adapter (lavapipe will do)");
    println!("rendering on {}", ctx.adapter_name());

    // Banisch Fig. 13: grass waving in the wind.
    let field = grass();
    let windy = DynamicsParams {
        stiffness: 1.5,
        lateral_stiffness: 0.5,
        restoring: 0.01,
        drag: 3e-3,
        gravity: Vec3::new(0.0, -2.0, 0.0),
        wind: Some(Wind::new(Vec3::new(2.5, 0.0, 0.6), 0.7, 0.4, 2.0, 2.5, 5)),
        ..Default::default()
    };
    let mut system = MassSpringSystem::new(&field.mesh, Topology::Prisms, field.params.length);
    let frames = film(&ctx, &field, &mut system, &windy, 36);
    write_gif(&out.join("banisch-fig13-wind.gif"), &frames);
    strip(
        &out.join("banisch-fig13.png"),
        &[&frames[8], &frames[16], &frames[24], &frames[32]],
    );

    // Banisch Fig. 12: parting under a brush, prisms vs separable prisms.
    let push = DynamicsParams {
        stiffness: 1.5,
        lateral_stiffness: 3.0,
        restoring: 0.01,
        gravity: Vec3::ZERO,
        brush: Some(PushBrush {
            centre: Vec3::new(-0.12, 0.2, 0.05),
            radius: 0.16,
            force: Vec3::new(-0.15, -0.04, 0.0),
        }),
        ..Default::default()
    };
    // Seen from closer and higher, over the brushed spot.
    let close = Grass {
        camera: Camera {
            eye: Vec3::new(0.1, 0.7, 0.55),
            target: Vec3::new(-0.08, 0.0, 0.0),
            fov_y_degrees: 40.0,
        },
        ..grass()
    };
    let parted: Vec<image::RgbaImage> = [Topology::Prisms, Topology::SeparablePrisms]
        .into_iter()
        .map(|topology| {
            let mut system = MassSpringSystem::new(&close.mesh, topology, close.params.length);
            film(&ctx, &close, &mut system, &push, 12)
                .pop()
                .expect("a frame")
        })
        .collect();
    strip(
        &out.join("banisch-fig12-parting.png"),
        &[&parted[0], &parted[1]],
    );

    // Spot shaken for a second, then still: the fur lags and settles.
    let mut scene = ShellScene::spot();
    scene.fur.layers = 24;
    scene.fur.length *= 2.0;
    scene.texture.layers = 24;
    scene.fps = FPS;
    scene.dynamics = Some(DynamicsSettings {
        topology: Topology::SpringSticks,
        solver: Solver::Implicit { iterations: 30 },
        steps_per_frame: 4,
        coupling: Coupling::Bent { exponent: 2.0 },
        params: DynamicsParams {
            gravity: Vec3::new(0.0, -3.0, 0.0),
            ..Default::default()
        },
        shake: Some(Shake {
            amplitude: Vec3::new(0.15, 0.02, 0.0),
            frequency: 2.0,
            duration: 1.0,
        }),
        ..Default::default()
    });
    let mut player = ShellScenePlayer::new(&ctx, &scene, WIDTH, HEIGHT).expect("player");
    let frames: Vec<image::RgbaImage> = (0..30)
        .map(|f| player.render_at(&ctx, f as f32 / FPS).expect("frame"))
        .collect();
    write_gif(&out.join("shells-spot-shake.gif"), &frames);
    strip(
        &out.join("shells-spot-shake.png"),
        &[&frames[0], &frames[3], &frames[9], &frames[14], &frames[29]],
    );
}
