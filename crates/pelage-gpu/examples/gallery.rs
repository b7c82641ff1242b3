//! Regenerates the gallery pictures in `docs/gallery/` with the preview
//! renderer (headless; lavapipe serves without a GPU):
//!
//! - `sik-fig11-12-spot.png`: Sik's Figs. 11–12 on Spot — 8,000 uniform
//!   samples (left) and 8,000 samples of a density rising from left to
//!   right (right).
//! - `preview-strands-spot.png`: the curve preview — 150,000 straight
//!   strands along the normals, roots from a noise density, Kajiya-Kay
//!   ribbons (no groom operators yet).
//! - `furtility-fig1-style-mesh.png`: the Furtility talk's Figure 1 on
//!   blub — the style mesh built from the surface (left) beside what a
//!   point-cloud method connects, each guide root to its 6 nearest roots
//!   in space (right): it ignores the surface, so it joins the two sides
//!   of the fins and the fins to the body.
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

    let out = out.with_file_name("furtility-fig1-style-mesh.png");
    style_mesh_figure(&ctx, &renderer, &out)?;
    println!("wrote {}", out.display());
    Ok(())
}

/// Edges between guide roots as thin ribbons, lifted off the skin along
/// the roots' normals so chords stay visible.
fn edge_curves(
    roots: &[Vec3],
    normals: &[Vec3],
    edges: &[[u32; 2]],
    lift: f32,
    width: f32,
) -> pelage::Curves {
    let mut points = Vec::new();
    for e in edges {
        for &g in e {
            points.push(roots[g as usize] + lift * normals[g as usize]);
        }
    }
    let widths = vec![width; points.len()];
    let offsets = (0..=edges.len() as u32).map(|i| 2 * i).collect();
    pelage::Curves::new(points, widths, offsets).expect("finite edges")
}

fn style_mesh_figure(
    ctx: &GpuContext,
    renderer: &Renderer,
    out: &std::path::Path,
) -> Result<(), Box<dyn std::error::Error>> {
    use pelage::guides::{GuideGrowth, Guides};
    use pelage::interp::{StyleMesh, StyleMeshOptions};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/meshes/blub_triangulated.obj");
    let blub = Mesh::load(&path)?;
    let guides = Guides::grow(
        &blub,
        &GuideGrowth {
            count: 350,
            seed: 5,
            ..GuideGrowth::default()
        },
    )?;
    let style = StyleMesh::build(&blub, &guides, &StyleMeshOptions { split_shared: true });
    let roots: Vec<Vec3> = guides.roots().iter().map(|r| r.position(&blub)).collect();
    let normals: Vec<Vec3> = guides.roots().iter().map(|r| r.normal(&blub)).collect();
    // The point-cloud view: each root joined to its 6 nearest in space.
    let mut knn = Vec::new();
    for (i, p) in roots.iter().enumerate() {
        let mut by_distance: Vec<(f32, u32)> = roots
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != i)
            .map(|(j, q)| ((*q - *p).length_squared(), j as u32))
            .collect();
        by_distance.sort_by(|a, b| a.0.total_cmp(&b.0));
        for &(_, j) in &by_distance[..6] {
            knn.push([(i as u32).min(j), (i as u32).max(j)]);
        }
    }
    knn.sort_unstable();
    knn.dedup();
    let surface: std::collections::HashSet<[u32; 2]> = style.edges().iter().copied().collect();
    let unsupported = knn.iter().filter(|e| !surface.contains(*e)).count();
    println!(
        "style mesh: {} edges, {} triangles; 6-nearest graph: {} edges, {unsupported} of them between guides whose cells do not touch",
        style.edges().len(),
        style.triangles().len(),
        knn.len()
    );
    let (lo, hi) = blub.bounds();
    let size = (hi - lo).length();
    let camera = Camera {
        eye: 0.5 * (lo + hi) + Vec3::new(4.6, 2.6, -0.4),
        target: 0.5 * (lo + hi) + Vec3::new(0.0, 0.1, 0.0),
        fov_y_degrees: 30.0,
    };
    let style_look = PreviewStyle {
        hair: [0.05, 0.12, 0.45],
        hair_specular: 0.0,
        point_radius: 2.2,
        point: [0.75, 0.1, 0.05],
        ..Default::default()
    };
    let panel = |edges: &[[u32; 2]]| {
        let curves = edge_curves(&roots, &normals, edges, 0.012 * size, 0.002 * size);
        let scene = PreviewScene {
            mesh: Some(&blub),
            points: &roots,
            curves: Some(&curves),
            skin_texture: None,
        };
        renderer.render(ctx, &scene, &style_look, Some(camera), WIDTH, HEIGHT)
    };
    let (left, right) = (panel(style.edges())?, panel(&knn)?);
    let gap = 16;
    let mut image = image::RgbaImage::from_pixel(2 * WIDTH + gap, HEIGHT, image::Rgba([255; 4]));
    image::imageops::replace(&mut image, &left, 0, 0);
    image::imageops::replace(&mut image, &right, i64::from(WIDTH + gap), 0);
    image.save(out)?;
    Ok(())
}
