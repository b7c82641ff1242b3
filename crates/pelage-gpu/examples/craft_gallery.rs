//! The groom-craft gallery, `docs/gallery/craft-*.png`, each a pair
//! without / with the feature where a pair says more:
//!
//! - `craft-parted-back.png`: Spot's back, guides combed away from the
//!   spine on each side; without regions the hairs along the spine take
//!   both sides' guides and stand up, with two regions (x < 0, x > 0)
//!   they part;
//! - `craft-mane.png`: long guides standing up along the top of the neck
//!   and head, short ones elsewhere; without regions the mane bleeds into
//!   the neck, with a "mane" region it stops at its border;
//! - `craft-uvless-noise.png`: Spot with its UVs removed, the density a
//!   noise map read in object space;
//! - `craft-blue-noise.png`: 1,500 roots on a square, random and blue
//!   noise, seen from above.
//!
//! Rendered by the preview renderer (lavapipe serves without a GPU).
//!
//! ```sh
//! cargo run --release -p pelage-gpu --example craft_gallery
//! ```

use glam::Vec3;
use pelage::Curves;
use pelage::groom::GroomError;
use pelage::groom::{GroomSpec, RegionsSpec, RootDistribution, RootsSpec};
use pelage::guides::Guides;
use pelage::map::Map;
use pelage::mesh::{Mesh, SurfacePoint};
use pelage::sample::{DensitySampler, sample_range};
use pelage_gpu::{Camera, GpuContext, PreviewScene, PreviewStyle, Renderer};
use std::sync::Arc;

#[path = "common/patch.rs"]
mod patch;
use patch::patch;

const WIDTH: u32 = 560;
const HEIGHT: u32 = 420;

/// Guides at `count` roots of `mesh`, each shaped by `shape(root
/// position, normal)`: its direction and length.
fn guides(mesh: &Mesh, count: u64, shape: impl Fn(Vec3, Vec3) -> (Vec3, f32)) -> Guides {
    let sampler = DensitySampler::new(mesh, &Map::Constant(1.0), Default::default()).unwrap();
    let roots = sample_range(&sampler, 21, 0..count);
    let (mut points, mut offsets) = (Vec::new(), vec![0u32]);
    for r in &roots {
        let (p, n) = (r.position(mesh), r.normal(mesh));
        let (direction, length) = shape(p, n);
        for k in 0..6 {
            let t = k as f32 / 5.0;
            // Out along the normal first, then toward the direction.
            let bend = (n * (1.0 - t) + direction * t).normalize_or(n);
            points.push(p + bend * length * t);
        }
        offsets.push(points.len() as u32);
    }
    let widths = vec![0.001; points.len()];
    let curves = Curves::new(points, widths, offsets).unwrap();
    Guides::bind(mesh, &curves, 6, 1e-4).0
}

fn grow(spec: GroomSpec) -> Result<Curves, GroomError> {
    let generator = spec.generator()?;
    let parts = (0..generator.parts().len())
        .map(|p| generator.part(p))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(pelage::curves::join(parts.iter()).expect("parts of one groom join"))
}

/// `left` and `right` side by side on one image.
fn pair(left: &image::RgbaImage, right: &image::RgbaImage) -> image::RgbaImage {
    let mut out = image::RgbaImage::new(left.width() + right.width(), left.height());
    image::imageops::replace(&mut out, left, 0, 0);
    image::imageops::replace(&mut out, right, i64::from(left.width()), 0);
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ctx = GpuContext::headless()?;
    let renderer = Renderer::new(&ctx);
    let gallery = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/gallery");
    let style = PreviewStyle {
        skin: [0.62, 0.55, 0.47],
        hair: [0.30, 0.17, 0.08],
        ..PreviewStyle::default()
    };
    let render = |mesh: &Mesh, curves: Option<&Curves>, points: &[Vec3], camera: Option<Camera>| {
        let scene = PreviewScene {
            mesh: Some(mesh),
            points,
            curves,
            skin_texture: None,
        };
        renderer.render(&ctx, &scene, &style, camera, WIDTH, HEIGHT)
    };
    let spot = Arc::new(pelage::assets::spot());
    let finish = |spec: GroomSpec| {
        let mut spec = spec;
        spec.finish.points = 12;
        spec.finish.width =
            pelage::groom::ops::RootToTip::new(Map::Constant(0.004), Map::Constant(0.001));
        spec
    };

    // A parted back: guides combed away from the spine (x = 0).
    let combed = guides(&spot, 500, |p, _| {
        (Vec3::new(p.x.signum(), -0.6, 0.0).normalize(), 0.09)
    });
    let back = Camera {
        eye: Vec3::new(0.0, 1.7, 1.9),
        target: Vec3::new(0.0, 0.2, 0.25),
        fov_y_degrees: 34.0,
    };
    let sides = spot
        .positions()
        .iter()
        .map(|p| if p.x > 0.0 { 1.0 } else { 0.0 })
        .collect();
    let sided = Arc::new(spot.as_ref().clone().with_vertex_attribute("side", sides)?);
    let parted = |regions: bool| {
        let spec = GroomSpec::new(sided.clone(), combed.clone(), RootsSpec::new(40_000));
        let spec = if regions {
            spec.with_regions(RegionsSpec::from_map(
                Map::Vertex(pelage::map::VertexMap::new("side")),
                1.0,
            ))
        } else {
            spec
        };
        grow(finish(spec))
    };
    let image = pair(
        &render(&sided, Some(&parted(false)?), &[], Some(back))?,
        &render(&sided, Some(&parted(true)?), &[], Some(back))?,
    );
    image.save(gallery.join("craft-parted-back.png"))?;

    // A mane: long guides standing up along the top of the neck and head.
    let in_mane = |p: Vec3| p.x.abs() < 0.09 && p.y > 0.28 && p.z < 0.15;
    let mane_values = spot
        .positions()
        .iter()
        .map(|p| if in_mane(*p) { 1.0 } else { 0.0 })
        .collect();
    let maned = Arc::new(
        spot.as_ref()
            .clone()
            .with_vertex_attribute("mane", mane_values)?,
    );
    let mane_guides = guides(&maned, 600, |p, n| {
        if in_mane(p) {
            (Vec3::new(0.0, 1.0, 0.5).normalize(), 0.16)
        } else {
            ((n + Vec3::new(0.0, -0.5, 0.8)).normalize(), 0.035)
        }
    });
    let side = Camera {
        eye: Vec3::new(2.3, 0.9, 0.3),
        target: Vec3::new(0.0, 0.25, 0.1),
        fov_y_degrees: 36.0,
    };
    let mane = |regions: bool| {
        let spec = GroomSpec::new(maned.clone(), mane_guides.clone(), RootsSpec::new(40_000));
        let spec = if regions {
            spec.with_regions(RegionsSpec::from_map(
                Map::Vertex(pelage::map::VertexMap::new("mane")),
                1.0,
            ))
        } else {
            spec
        };
        grow(finish(spec))
    };
    let image = pair(
        &render(&maned, Some(&mane(false)?), &[], Some(side))?,
        &render(&maned, Some(&mane(true)?), &[], Some(side))?,
    );
    image.save(gallery.join("craft-mane.png"))?;

    // Spot without UVs, density from object-space noise.
    let uvless = Arc::new(Mesh::new(
        "spot without UVs",
        spot.positions().to_vec(),
        spot.triangles().to_vec(),
        Some(spot.normals().to_vec()),
        None,
    )?);
    let short = guides(&uvless, 300, |_, n| {
        ((n + Vec3::new(0.0, -0.4, 0.6)).normalize(), 0.05)
    });
    let density = Map::parse("noise:frequency=2.5,octaves=1,seed=4,offset=0.5,scale=0.5")?;
    let spec = GroomSpec::new(
        uvless.clone(),
        short,
        RootsSpec::new(15_000).with_density(density),
    );
    let curves = grow(finish(spec))?;
    render(&uvless, Some(&curves), &[], Some(side))?
        .save(gallery.join("craft-uvless-noise.png"))?;

    // Random against blue-noise roots on a square, from above.
    let square = Arc::new(patch(8));
    let up = guides(&square, 16, |_, n| (n, 0.05));
    let above = Camera {
        eye: Vec3::new(0.0, 1.35, 0.001),
        target: Vec3::ZERO,
        fov_y_degrees: 42.0,
    };
    let roots = |distribution| -> Result<Vec<Vec3>, GroomError> {
        let spec = GroomSpec::new(
            square.clone(),
            up.clone(),
            RootsSpec::new(1_500)
                .with_distribution(distribution)
                .with_parts(1),
        );
        let curves = grow(spec)?;
        Ok(curves
            .roots()
            .expect("grown curves carry roots")
            .iter()
            .map(|r: &SurfacePoint| r.position(&square))
            .collect())
    };
    let dots = PreviewStyle {
        point_radius: 2.5,
        ..style
    };
    let render_dots = |points: &[Vec3]| {
        let scene = PreviewScene {
            mesh: Some(&square),
            points,
            curves: None,
            skin_texture: None,
        };
        renderer.render(&ctx, &scene, &dots, Some(above), WIDTH, HEIGHT)
    };
    let image = pair(
        &render_dots(&roots(RootDistribution::Random)?)?,
        &render_dots(&roots(RootDistribution::BlueNoise)?)?,
    );
    image.save(gallery.join("craft-blue-noise.png"))?;
    println!("rendered on {}", ctx.adapter_name());
    Ok(())
}
