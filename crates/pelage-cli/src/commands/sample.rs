//! `pelage sample`: hair-root positions on a mesh from a density map
//! (Sik §3), written as a PLY point cloud or as USD `Points` prims (one per
//! batch of a million points).

use super::load_mesh;
use crate::format::thousands;
use anyhow::Context;
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use pelage::Map;
use pelage::io::{
    CurvesFormat, PointsPly, SurfacePoints, UsdOptions, write_atomically, write_streamed,
};
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
    #[arg(short = 'n', long = "count",
          value_parser = super::args::count_up_to::<u64>(pelage::limits::MAX_SAMPLE_POINTS, "points"))]
    pub count: u64,
    /// Seed: the same seed gives the same points, on any number of threads.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// How sub-triangles are chosen: the paper's CDF + grid
    /// (`subdivision`), an alias table (`alias`, fastest), or the paper's
    /// rejection-sampling baseline (`rejection`).
    #[arg(long, value_enum, default_value_t = Method::Alias)]
    pub method: Method,
    /// `random` (independent samples, streamed in batches) or
    /// `blue-noise` (four times as many thinned to keep their distance:
    /// the whole set at once, no seams; at most 20,000,000 points).
    #[arg(long, value_enum, default_value_t = Distribution::Random)]
    pub distribution: Distribution,
    /// Grid cells as a percentage of the CDF size, for `--method subdivision`.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u32).range(0..=400))]
    pub grid: u32,
    /// Output: .ply (a point cloud), .usdc or .usd (binary USD), .usda.
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

/// How the points are spread.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Distribution {
    /// Independent samples of the density.
    Random,
    /// Samples of the density that keep their distance (twice as many
    /// thinned by dart throwing over the whole mesh).
    BlueNoise,
}

/// What `--output`'s extension asks for.
enum PointsFormat {
    Ply,
    /// usdc or usda.
    Usd(CurvesFormat),
}

/// A batch's points evaluated on the mesh, for a USD `Points` prim.
struct SampledBatch {
    positions: Vec<glam::Vec3>,
    normals: Vec<glam::Vec3>,
    uvs: Option<Vec<glam::Vec2>>,
    triangles: Vec<u32>,
}

impl SampledBatch {
    fn of(mesh: &pelage::Mesh, points: &[SurfacePoint]) -> Self {
        use rayon::prelude::*;
        Self {
            positions: points.par_iter().map(|p| p.position(mesh)).collect(),
            normals: points.par_iter().map(|p| p.normal(mesh)).collect(),
            uvs: mesh.has_uvs().then(|| {
                points
                    .par_iter()
                    .map(|p| p.uv(mesh).unwrap_or_default())
                    .collect()
            }),
            triangles: points.iter().map(|p| p.tri).collect(),
        }
    }

    fn view(&self) -> SurfacePoints<'_> {
        SurfacePoints {
            positions: &self.positions,
            normals: &self.normals,
            uvs: self.uvs.as_deref(),
            triangles: &self.triangles,
        }
    }
}

/// Points generated and written per batch (bounded memory, progress).
const BATCH: u64 = 1 << 20;

pub fn run(args: &SampleArgs) -> anyhow::Result<()> {
    // A point's position alone is 12 bytes in any of the formats.
    pelage::io::check_free_space(&args.output, args.count.saturating_mul(12))?;
    let mesh = load_mesh(args.mesh.as_deref())?;
    let density = Map::parse(&args.density).context("cannot read the density map")?;
    pelage::io::check_output(&args.output)?;
    let start = Instant::now();
    let blue = args.distribution == Distribution::BlueNoise;
    if blue && args.method == Method::Rejection {
        anyhow::bail!(
            "--distribution blue-noise thins samples of the density sampler: use --method alias or subdivision"
        );
    }
    if blue && args.count > pelage::limits::MAX_BLUE_NOISE_POINTS {
        anyhow::bail!(
            "--distribution blue-noise: {} points is more than pelage's limit of {} thinned at once (docs/limits.md); sample fewer, or use random points",
            thousands(args.count),
            thousands(pelage::limits::MAX_BLUE_NOISE_POINTS)
        );
    }
    // Blue noise is thinned whole here, then written in batches like the
    // rest.
    let (sampler, thinned): (Box<dyn SurfaceSampler + '_>, _) = match args.method {
        Method::Rejection => (Box::new(RejectionSampler::new(&mesh, &density)?), None),
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
            let sampler = DensitySampler::new(&mesh, &density, options)?;
            let thinned = blue.then(|| {
                pelage::sample::blue_noise_samples(&sampler, &mesh, args.seed, args.count)
            });
            (Box::new(sampler), thinned)
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
    let format = match args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("ply") => PointsFormat::Ply,
        Some("usdc" | "usd") => PointsFormat::Usd(CurvesFormat::Usdc),
        Some("usda") => PointsFormat::Usd(CurvesFormat::Usda),
        _ => anyhow::bail!(
            "{}: unknown points format; pelage writes sampled points as .ply, .usdc (or .usd) and .usda",
            args.output.display()
        ),
    };
    let sampling = Instant::now();
    write_atomically(&args.output, |out| {
        let mut batch = vec![SurfacePoint::default(); BATCH.min(args.count) as usize];
        let mut batches = (0..args.count).step_by(BATCH as usize).map(|first| {
            let n = BATCH.min(args.count - first) as usize;
            match &thinned {
                Some(points) => {
                    batch[..n].copy_from_slice(&points[first as usize..first as usize + n])
                }
                None => sample_into(sampler.as_ref(), args.seed, first, &mut batch[..n]),
            }
            progress.set_position(first + n as u64);
            batch[..n].to_vec()
        });
        match format {
            PointsFormat::Ply => {
                let mut ply = PointsPly::new(&mesh, args.count, out)?;
                batches.try_for_each(|b| ply.write(&b))?;
            }
            PointsFormat::Usd(format) => {
                write_streamed(out, format, &UsdOptions::default(), |usd| {
                    for (k, b) in batches.enumerate() {
                        let points = SampledBatch::of(&mesh, &b);
                        usd.write_points(&format!("points_{k:04}"), &points.view())?;
                    }
                    Ok::<(), std::io::Error>(())
                })?;
            }
        }
        Ok(())
    })?;
    progress.finish_and_clear();
    let total = start.elapsed();
    let bytes = std::fs::metadata(&args.output)
        .map(|m| m.len())
        .unwrap_or(0);
    println!(
        "wrote {} points on {} to {} ({:.1} MB) in {:.2} s: preprocess{} {:.1} ms, then {:.1} M points/s sampled and written",
        thousands(args.count),
        mesh.name(),
        args.output.display(),
        bytes as f64 / 1e6,
        total.as_secs_f64(),
        if blue { " and blue-noise thinning" } else { "" },
        preprocess.as_secs_f64() * 1e3,
        args.count as f64 / sampling.elapsed().as_secs_f64() / 1e6,
    );
    Ok(())
}
