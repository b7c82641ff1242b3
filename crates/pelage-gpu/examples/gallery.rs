//! Regenerates the gallery pictures in `docs/gallery/` with the preview
//! renderer (headless; lavapipe serves without a GPU):
//!
//! - `sik-fig11-12-spot.png`: Sik's Figs. 11–12 on Spot — 8,000 uniform
//!   samples (left) and 8,000 samples of a density rising from left to
//!   right (right).
//! - `preview-strands-spot.png`: the curve preview — 150,000 straight
//!   strands along the normals, roots from a noise density, Kajiya-Kay
//!   ribbons (no groom operators yet).
//!
//! ```sh
//! cargo run --release -p pelage-gpu --example gallery
//! ```

use glam::{Vec2, Vec3};
use pelage::Mesh;
use pelage::map::{ImageMap, Map, Wrap};
use pelage::mesh::Uvs;
use pelage::sample::{DensitySampler, DensitySamplerOptions, sample_range};
use pelage_gpu::{Camera, GpuContext, PreviewScene, PreviewStyle, Renderer};

const WIDTH: u32 = 640;
const HEIGHT: u32 = 560;
const SAMPLES: u64 = 8_000;

/// Spot with planar UVs seen from the camera's side (+x): u runs left to
/// right on screen, so a horizontal ramp is a left-to-right density.
fn with_side_uvs(mesh: &Mesh) -> Mesh {
    let (lo, hi) = mesh.bounds();
    let uvs = mesh
        .positions()
        .iter()
        .map(|p| Vec2::new((hi.z - p.z) / (hi.z - lo.z), (p.y - lo.y) / (hi.y - lo.y)))
        .collect();
    Mesh::new(
        "spot with side-projected UVs",
        mesh.positions().to_vec(),
        mesh.triangles().to_vec(),
        Some(mesh.normals().to_vec()),
        Some(Uvs::PerVertex(uvs)),
    )
    .expect("same geometry, new UVs")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let spot = with_side_uvs(&pelage::assets::spot());
    let uniform =
        DensitySampler::new(&spot, &Map::Constant(1.0), DensitySamplerOptions::default())?;
    let ramp: Vec<f32> = (0..256).map(|x| (x as f32 + 0.5) / 256.0).collect();
    let gradient = Map::Image(ImageMap::from_texels(256, 1, ramp, Wrap::Clamp)?);
    let gradient_sampler = DensitySampler::new(&spot, &gradient, DensitySamplerOptions::default())?;

    let ctx = GpuContext::headless()?;
    let renderer = Renderer::new(&ctx);
    let (lo, hi) = spot.bounds();
    let center = 0.5 * (lo + hi);
    let camera = Camera {
        eye: center + Vec3::new(5.2, 0.4, 0.0),
        target: center,
        fov_y_degrees: 25.0,
    };
    let style = PreviewStyle {
        point_radius: 1.6,
        ..Default::default()
    };
    let panel = |sampler: &DensitySampler| {
        let points: Vec<Vec3> = sample_range(sampler, 11, 0..SAMPLES)
            .iter()
            .map(|p| p.position(&spot))
            .collect();
        let scene = PreviewScene {
            mesh: Some(&spot),
            points: &points,
            curves: None,
            skin_texture: None,
        };
        renderer.render(&ctx, &scene, &style, Some(camera), WIDTH, HEIGHT)
    };
    let (left, right) = (panel(&uniform)?, panel(&gradient_sampler)?);
    let gap = 16;
    let mut image = image::RgbaImage::from_pixel(2 * WIDTH + gap, HEIGHT, image::Rgba([255; 4]));
    image::imageops::replace(&mut image, &left, 0, 0);
    image::imageops::replace(&mut image, &right, i64::from(WIDTH + gap), 0);
    let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs/gallery/sik-fig11-12-spot.png");
    std::fs::create_dir_all(out.parent().expect("has a folder"))?;
    image.save(&out)?;
    println!(
        "wrote {} (rendered on {})",
        out.display(),
        ctx.adapter_name()
    );

    let plain = pelage::assets::spot();
    let density = Map::parse("noise:frequency=5,octaves=2,seed=4,offset=0.6,scale=0.5")?;
    let roots_sampler = DensitySampler::new(&plain, &density, DensitySamplerOptions::default())?;
    let roots = sample_range(&roots_sampler, 3, 0..150_000);
    let strands = pelage::Curves::along_normals(&plain, &roots, 0.06, 8, 0.002, 0.0004);
    let scene = PreviewScene {
        mesh: Some(&plain),
        points: &[],
        curves: Some(&strands),
        skin_texture: None,
    };
    // Close on the head, where ribbons are several pixels wide.
    let close = Camera {
        eye: Vec3::new(1.45, 0.85, 0.05),
        target: Vec3::new(0.0, 0.45, -0.45),
        fov_y_degrees: 30.0,
    };
    let image = renderer.render(
        &ctx,
        &scene,
        &PreviewStyle::default(),
        Some(close),
        1280,
        720,
    )?;
    let out = out.with_file_name("preview-strands-spot.png");
    image.save(&out)?;
    println!("wrote {}", out.display());
    Ok(())
}
