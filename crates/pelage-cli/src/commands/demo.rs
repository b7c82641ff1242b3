//! `pelage demo`: pelage on the embedded Spot mesh, with no files needed.
//!
//! Today it shows the mesh layer and root sampling: a summary of Spot, then
//! a million hair roots from a noise density, written to
//! `./pelage-demo/roots.ply`, and a picture of them, `preview.png` (skipped
//! with a message where no GPU adapter exists). The groom and export
//! issues grow it into the full demo (hairs, USD).

use super::info::MeshSummary;
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use pelage::Map;
use pelage::io::write_points_ply;
use pelage::sample::{DensitySampler, DensitySamplerOptions, sample_range};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `pelage demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Folder the demo writes into.
    #[arg(long, default_value = "pelage-demo")]
    pub out: PathBuf,
}

/// Roots the demo places.
const ROOTS: u64 = 1_000_000;
/// The density the demo uses, as a user would write it.
const DENSITY: &str = "noise:frequency=6,octaves=3,seed=2,offset=0.5,scale=0.5";

/// Renders roots on the skin to `path`; returns the adapter's name.
fn render_preview(
    spot: &pelage::Mesh,
    roots: &[pelage::SurfacePoint],
    path: &std::path::Path,
) -> anyhow::Result<String> {
    use pelage_gpu::{GpuContext, PreviewScene, PreviewStyle, Renderer};
    let ctx = GpuContext::headless()?;
    let points: Vec<glam::Vec3> = roots.iter().map(|p| p.position(spot)).collect();
    let texture = image::load_from_memory(pelage::assets::SPOT_TEXTURE_PNG)?.to_rgba8();
    let scene = PreviewScene {
        mesh: Some(spot),
        points: &points,
        curves: None,
        skin_texture: Some(&texture),
    };
    let image =
        Renderer::new(&ctx).render(&ctx, &scene, &PreviewStyle::default(), None, 1280, 720)?;
    pelage::io::write_atomically(path, |out| {
        image
            .write_to(out, image::ImageFormat::Png)
            .map_err(std::io::Error::other)
    })?;
    Ok(ctx.adapter_name())
}

pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    let spot = pelage::assets::spot();
    println!(
        "pelage {} demo — the embedded Spot mesh\n",
        env!("CARGO_PKG_VERSION")
    );
    print!("{}", MeshSummary::of(&spot, 0).table());
    let fine = spot.subdivided(2);
    println!(
        "\nsubdivided ×2: {} triangles, area {:.6} (unchanged: {:.6})",
        thousands(fine.triangle_count() as u64),
        fine.surface_area(),
        spot.surface_area()
    );

    let density = Map::parse(DENSITY)?;
    let sampling = Instant::now();
    let sampler = DensitySampler::new(&spot, &density, DensitySamplerOptions::default())?;
    let roots = sample_range(&sampler, 1, 0..ROOTS);
    let sampled = sampling.elapsed();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create the folder {}", args.out.display()))?;
    let path = args.out.join("roots.ply");
    write_points_ply(&path, &spot, &roots)?;
    println!(
        "\n{} hair roots with density {DENSITY}\n  ({} sub-triangle records) in {:.1} ms → {}",
        thousands(ROOTS),
        thousands(sampler.records().len() as u64),
        sampled.as_secs_f64() * 1e3,
        path.display()
    );
    let preview = args.out.join("preview.png");
    match render_preview(&spot, &roots[..20_000], &preview) {
        Ok(adapter) => println!(
            "preview of 20,000 of them → {} (rendered on {adapter})",
            preview.display()
        ),
        // The demo still did its job; say why there is no picture.
        Err(e) => println!("preview skipped: {e:#}"),
    }
    println!("done in {:.2} s\n", start.elapsed().as_secs_f64());
    println!("Try: pelage sample --help, pelage bench sampler --quick.");
    println!("Coming as the next layers land: guide interpolation, clump/curl/noise");
    println!("operators, 200,000 hairs written to ./pelage-demo/ as USD, previewed");
    println!("as curves.");
    Ok(())
}
