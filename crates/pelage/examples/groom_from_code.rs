//! A groom grown from a Rust program, with no groom file: Spot's fur as
//! values (guides grown on the mesh, a density map, a clump, a curl, noise
//! and colours), grown part by part and written as USD.
//!
//! ```sh
//! cargo run --release -p pelage --example groom_from_code [-- OUT.usda]
//! ```

use glam::Vec3;
use pelage::groom::ops::{Color, RootToTip};
use pelage::groom::{
    ClumpParams, CurlParams, FinishSpec, GroomOp, GroomSpec, NoiseParams, Ramp, RootsSpec,
};
use pelage::guides::{GuideGrowth, Guides};
use pelage::io::CurvesExport;
use pelage::map::{Map, NoiseMap};
use std::path::PathBuf;
use std::sync::Arc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from("groom_from_code.usda"), PathBuf::from);

    // The surface, shared by the guides, the generator and the writer.
    let mesh = Arc::new(pelage::assets::spot());

    // 300 guides, combed back and pulled down a little.
    let guides = Guides::grow(
        &mesh,
        &GuideGrowth {
            count: 300,
            length: Map::Constant(0.05),
            comb: Vec3::new(0.0, -0.3, -1.0),
            gravity: 0.3,
            points: 8,
            ..Default::default()
        },
    )?;

    // 100,000 hairs, thinner where a noise map is low.
    let density = Map::Noise(NoiseMap::new(6.0, 3, 2, 0.6, 0.4));
    let roots = RootsSpec::new(100_000).with_density(density).with_seed(7);

    let spec = GroomSpec::new(mesh.clone(), guides, roots)
        .with_op(GroomOp::Clump(ClumpParams {
            rate: Map::Constant(0.7),
            ramp: Ramp::Smooth,
            ..ClumpParams::new(1_500)
        }))
        .with_op(GroomOp::Curl(CurlParams::new(
            Map::Constant(0.002),
            Map::Constant(1.5),
        )))
        .with_op(GroomOp::Noise(NoiseParams::new(Map::Constant(0.002))))
        .with_finish(FinishSpec {
            width: RootToTip::new(Map::Constant(0.0015), Map::Constant(0.0002)),
            color: Some(Color {
                root: [0.25, 0.15, 0.1].map(Map::Constant),
                tip: [0.8, 0.65, 0.45].map(Map::Constant),
                ramp: Ramp::Smooth,
                jitter: Map::Constant(0.15),
                seed: 3,
            }),
            ..FinishSpec::default()
        });

    let generator = spec.generator()?;
    let export = CurvesExport {
        mesh: Some(&mesh),
        ..Default::default()
    };
    let parts = generator.parts().len();
    let summary = generator.write(&out, 0..parts, &export, |p, curves| {
        eprintln!("part {}/{parts}: {} hairs", p + 1, curves.curve_count());
    })?;
    println!(
        "{} hairs, {} points in {parts} parts -> {}",
        summary.hairs,
        summary.points,
        out.display()
    );
    Ok(())
}
