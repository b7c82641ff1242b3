//! `pelage guides`: guide curves for a mesh — grown on it (roots from the
//! density sampler, combed by a direction or a flow map, pulled by gravity), or read from a file and
//! bound to it (with a report of every guide left out) — written in any
//! curves format.

use super::load_mesh;
use super::render::parse_vec3;
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use glam::Vec3;
use pelage::Map;
use pelage::guides::{CombMap, GuideGrowth, Guides};
use pelage::io::{CurvesExport, read_curves, write_curves};
use std::path::PathBuf;

/// Arguments of `pelage guides`.
#[derive(Debug, Args)]
pub struct GuidesArgs {
    /// The mesh (.obj, .ply, .gltf, .glb); without it, the embedded Spot.
    pub mesh: Option<PathBuf>,
    /// Number of guides to grow.
    #[arg(short = 'n', long = "count", default_value_t = 500,
          value_parser = super::args::count_up_to::<usize>(pelage::limits::MAX_GUIDES, "guides"))]
    pub count: usize,
    /// Guide length, a map (`0.1`, `length.png:r`, `noise:…`).
    #[arg(long, default_value = "0.1")]
    pub length: String,
    /// Root density, a map.
    #[arg(long, default_value = "1")]
    pub density: String,
    /// Comb direction X,Y,Z: its part along the surface bends each guide;
    /// its length is the strength.
    #[arg(long, value_parser = parse_vec3)]
    pub comb: Option<[f32; 3]>,
    /// A flow map instead of --comb: an image whose red and green channels
    /// give the comb along +U and along N × T at each root's UV (0.5: none);
    /// the mesh needs UVs.
    #[arg(long, value_name = "IMAGE", conflicts_with = "comb")]
    pub comb_map: Option<String>,
    /// Multiplies the comb map's direction.
    #[arg(long, default_value_t = 1.0, value_parser = super::args::finite)]
    pub comb_strength: f32,
    /// Gravity's pull (world −Y) relative to the normal.
    #[arg(long, default_value_t = 0.0, value_parser = super::args::finite)]
    pub gravity: f32,
    /// Points per guide.
    #[arg(long, default_value_t = 8,
          value_parser = super::args::count_up_to::<usize>(pelage::limits::MAX_CURVE_POINTS, "points"))]
    pub points: usize,
    /// Seed of the roots.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Instead of growing: read guides from this file and bind them to the
    /// mesh.
    #[arg(long, value_name = "CURVES")]
    pub from: Option<PathBuf>,
    /// With --from: the farthest a root may be from the surface.
    #[arg(long, default_value_t = 1e-3, value_parser = super::args::positive_f32)]
    pub tolerance: f32,
    /// Output: .usdc (or .usd), .usda, .hair, .ply, .rib or .pbrt.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: &GuidesArgs) -> anyhow::Result<()> {
    let points = (args.count as u64).saturating_mul(args.points as u64);
    pelage::io::check_free_space(&args.output, points.saturating_mul(12))?;
    let mesh = load_mesh(args.mesh.as_deref())?;
    let guides = match &args.from {
        Some(file) => {
            let curves = read_curves(file).context("cannot read the guides")?;
            let (guides, report) = Guides::bind(&mesh, &curves, args.points, args.tolerance);
            for dropped in &report.dropped {
                eprintln!("warning: {}: {dropped}", file.display());
            }
            println!(
                "bound {} of {} guides to {} (largest root distance {:.2e}; {} left out)",
                thousands(report.kept as u64),
                thousands(curves.curve_count() as u64),
                mesh.name(),
                report.max_distance,
                report.dropped.len()
            );
            guides
        }
        None => {
            let growth = GuideGrowth {
                count: args.count,
                density: Map::parse(&args.density).context("cannot read the density map")?,
                length: Map::parse(&args.length).context("cannot read the length map")?,
                comb: args.comb.map_or(Vec3::ZERO, Vec3::from),
                comb_map: match &args.comb_map {
                    Some(image) => Some(CombMap {
                        u: Map::parse(&format!("{image}:r")).context("cannot read the comb map")?,
                        v: Map::parse(&format!("{image}:g")).context("cannot read the comb map")?,
                        strength: args.comb_strength,
                    }),
                    None => None,
                },
                gravity: args.gravity,
                points: args.points,
                seed: args.seed,
                ..GuideGrowth::default()
            };
            let guides = Guides::grow(&mesh, &growth)?;
            println!(
                "grew {} guides of {} points on {}",
                thousands(guides.len() as u64),
                guides.points_per_guide(),
                mesh.name()
            );
            guides
        }
    };
    write_curves(
        &args.output,
        [("guides".to_string(), guides.curves())],
        &CurvesExport::default(),
    )?;
    println!("wrote {}", args.output.display());
    Ok(())
}
