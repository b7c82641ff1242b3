//! `pelage sample`: hair-root positions on a mesh from a density map
//! (Sik §3), written as a PLY point cloud.

use super::load_mesh;
use crate::format::thousands;
use anyhow::Context;
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use pelage::Map;
use pelage::io::{PointsPly, write_atomically};
use pelage::mesh::SurfacePoint;
use pelage::sample::{
    DensitySampler, DensitySamplerOptions, RejectionSampler, Selector, SurfaceSampler, sample_into,
};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `pelage sample`.
#[derive(Debug, Args)]
pub struct SampleArgs {
    /// Mesh file (.obj, .ply, .gltf, .glb). Without it, the embedded Spot.
    pub mesh: Option<PathBuf>,
    /// Density: a number, an image (`map.png[:channel][:wrap][:filter]`) or
    /// `noise[:frequency=…,octaves=…,seed=…,offset=…,scale=…]`.
    #[arg(long, default_value = "1")]
    pub density: String,
    /// Number of points.
    #[arg(short = 'n', long = "count")]
    pub count: u64,
    /// Seed: the same seed gives the same points, on any number of threads.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// How sub-triangles are chosen: the paper's CDF + grid
    /// (`subdivision`), an alias table (`alias`, fastest), or the paper's
    /// rejection-sampling baseline (`rejection`).
    #[arg(long, value_enum, default_value_t = Method::Alias)]
    pub method: Method,
    /// Grid cells as a percentage of the CDF size, for `--method subdivision`.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u32).range(0..=400))]
    pub grid: u32,
    /// Output PLY file.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Sampling methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Sub-triangle records with the CDF and uniform grid (Sik §3).
    Subdivision,
    /// Sub-triangle records with an alias table.
    Alias,
    /// Rejection sampling (Sik §3.4.1), for comparison.
    Rejection,
}

/// Points generated and written per batch (bounded memory, progress).
const BATCH: u64 = 1 << 20;

pub fn run(args: &SampleArgs) -> anyhow::Result<()> {
    let mesh = load_mesh(args.mesh.as_deref())?;
    let density = Map::parse(&args.density).context("cannot read the density map")?;
    let start = Instant::now();
    let sampler: Box<dyn SurfaceSampler + '_> = match args.method {
        Method::Rejection => Box::new(RejectionSampler::new(&mesh, &density)?),
        method => {
            let selector = match method {
                Method::Subdivision => Selector::CdfGrid {
                    grid_percent: args.grid,
                },
                _ => Selector::Alias,
            };
            let options = DensitySamplerOptions {
                selector,
                ..Default::default()
            };
            Box::new(DensitySampler::new(&mesh, &density, options)?)
        }
    };
    let preprocess = start.elapsed();

    let progress = if args.count >= 4 * BATCH {
        let bar = ProgressBar::new(args.count);
        bar.set_style(
            ProgressStyle::with_template(
                "{bar:40} {percent:>3}% {human_pos}/{human_len} points, {eta} left",
            )
            .expect("the template is valid"),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let sampling = Instant::now();
    write_atomically(&args.output, |out| {
        let mut ply = PointsPly::new(&mesh, args.count, out)?;
        let mut batch = vec![SurfacePoint::default(); BATCH.min(args.count) as usize];
        let mut first = 0;
        while first < args.count {
            let n = BATCH.min(args.count - first) as usize;
            sample_into(sampler.as_ref(), args.seed, first, &mut batch[..n]);
            ply.write(&batch[..n])?;
            first += n as u64;
            progress.set_position(first);
        }
        Ok(())
    })?;
    progress.finish_and_clear();
    let total = start.elapsed();
    let bytes = std::fs::metadata(&args.output)
        .map(|m| m.len())
        .unwrap_or(0);
    println!(
        "wrote {} points on {} to {} ({:.1} MB) in {:.2} s: preprocess {:.1} ms, then {:.1} M points/s sampled and written",
        thousands(args.count),
        mesh.name(),
        args.output.display(),
        bytes as f64 / 1e6,
        total.as_secs_f64(),
        preprocess.as_secs_f64() * 1e3,
        args.count as f64 / sampling.elapsed().as_secs_f64() / 1e6,
    );
    Ok(())
}
