//! `pelage demo`: pelage on the embedded Spot mesh, with no files needed.
//!
//! For now it shows the mesh layer (what `pelage info` reports) and says
//! what the demo will grow into as the groom, export and GPU layers land.

use super::info::MeshSummary;
use clap::Args;
use std::time::Instant;

/// Arguments of `pelage demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {}

pub fn run(_args: &DemoArgs) -> anyhow::Result<()> {
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
        crate::format::thousands(fine.triangle_count() as u64),
        fine.surface_area(),
        spot.surface_area()
    );
    println!("done in {:.2} s\n", start.elapsed().as_secs_f64());
    println!("Coming as the next layers land: hair roots from a density map (Sik),");
    println!("guide interpolation, clump/curl/noise operators, 200,000 hairs written");
    println!("to ./pelage-demo/ as USD, and a preview picture of the result.");
    Ok(())
}
