//! `pelage demo`: pelage on the embedded Spot mesh, with no files needed.
//!
//! Today it shows the mesh layer, root sampling and curve export: a summary
//! of Spot, then a million hair roots from a noise density, written to
//! `./pelage-demo/roots.ply`; the first 100,000 grown into straight,
//! tapering strands and written as USD with the skin
//! (`./pelage-demo/strands.usda`); and a picture of them, `preview.png`
//! (skipped with a message where no GPU adapter exists). The groom issue
//! grows it into the full demo (guides, operators).

use super::info::MeshSummary;
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use pelage::io::{CurvesExport, write_curves, write_points_ply};
use pelage::sample::{DensitySampler, DensitySamplerOptions, sample_range};
use pelage::{Curves, Map};
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
/// Of those, how many grow into strands.
const STRANDS: usize = 100_000;
/// The density the demo uses, as a user would write it.
const DENSITY: &str = "noise:frequency=6,octaves=3,seed=2,offset=0.5,scale=0.5";

/// Straight strands along the normals of `roots`, tapering, with their
/// root UVs and ids (the simplest groom, until guides and operators land).
fn strands(spot: &pelage::Mesh, roots: &[pelage::SurfacePoint]) -> anyhow::Result<Curves> {
    let uvs = roots
        .iter()
        .map(|r| r.uv(spot).unwrap_or_default())
        .collect();
    Ok(Curves::along_normals(spot, roots, 0.04, 5, 0.004, 0.0005)
        .with_root_uvs(uvs)?
        .with_ids((0..roots.len() as u64).collect())?
        .with_roots(roots.to_vec())?)
}

/// Renders strands on the skin to `path`; returns the adapter's name.
fn render_preview(
    spot: &pelage::Mesh,
    strands: &Curves,
    path: &std::path::Path,
) -> anyhow::Result<String> {
    use pelage_gpu::{GpuContext, PreviewScene, PreviewStyle, Renderer};
    let ctx = GpuContext::headless()?;
    let texture = image::load_from_memory(pelage::assets::SPOT_TEXTURE_PNG)?.to_rgba8();
    let scene = PreviewScene {
        mesh: Some(spot),
        points: &[],
        curves: Some(strands),
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
    let strands = strands(&spot, &roots[..STRANDS])?;
    let usd = args.out.join("strands.usda");
    let export = CurvesExport {
        mesh: Some(&spot),
        ..CurvesExport::default()
    };
    write_curves(&usd, [("strands".to_string(), &strands)], &export)?;
    println!(
        "{} of them grown into straight strands (5 points, Catmull-Rom) → {} with the skin",
        thousands(STRANDS as u64),
        usd.display()
    );
    let preview = args.out.join("preview.png");
    match render_preview(&spot, &strands, &preview) {
        Ok(adapter) => println!(
            "preview of the strands → {} (rendered on {adapter})",
            preview.display()
        ),
        // The demo still did its job; say why there is no picture.
        Err(e) => println!("preview skipped: {e:#}"),
    }
    println!("done in {:.2} s\n", start.elapsed().as_secs_f64());
    println!("Try: pelage render pelage-demo/strands.usda --mesh spot -o strands.png,");
    println!(
        "     pelage convert pelage-demo/strands.usda strands.hair, pelage bench sampler --quick."
    );
    println!("Coming as the next layers land: guides, interpolation, clump/curl/noise operators.");
    Ok(())
}
