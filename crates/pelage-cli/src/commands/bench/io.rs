//! `pelage bench io`: writing a large groom as usda, part by part — the
//! streaming target (2 M hairs × 16 points with bounded memory). Hairs are straight strands on Spot with widths, normals, root
//! UVs and ids (what the groom generator writes), generated one part at a
//! time as the generator will; only the writing is timed.
//!
//! Peak memory is the process's peak resident set (`VmHWM`), reset before
//! each run through `/proc/self/clear_refs`, so a small and a large run can
//! be compared: if the writer streams, they peak at about the same size.

use super::on_threads;
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use pelage::io::{UsdOptions, UsdaWriter, write_atomically};
use pelage::sample::{DensitySampler, DensitySamplerOptions, sample_range};
use pelage::{Curves, Map};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Arguments of `pelage bench io`.
#[derive(Debug, Args)]
pub struct IoBenchArgs {
    /// A reduced run (200,000 hairs).
    #[arg(long)]
    pub quick: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Hairs in the large run.
    #[arg(long, default_value_t = 2_000_000)]
    pub hairs: u64,
    /// Points per hair.
    #[arg(long, default_value_t = 16)]
    pub points: usize,
    /// Hairs per part (one BasisCurves prim each).
    #[arg(long, default_value_t = 50_000)]
    pub part_hairs: u64,
    /// Folder for the files (deleted afterwards).
    #[arg(long, default_value_os_t = std::env::temp_dir())]
    pub dir: PathBuf,
}

struct Run {
    hairs: u64,
    bytes: u64,
    write: Duration,
    generate: Duration,
    peak_rss: Option<u64>,
}

/// `VmHWM` (peak resident set) in bytes, Linux only.
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Resets `VmHWM` to the current resident set (Linux ≥ 4.0).
fn reset_peak_rss() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

fn part(
    spot: &pelage::Mesh,
    sampler: &DensitySampler,
    first: u64,
    count: u64,
    points: usize,
) -> anyhow::Result<Curves> {
    let roots = sample_range(sampler, 9, first..first + count);
    let curves = Curves::along_normals(spot, &roots, 0.05, points, 0.002, 0.0004);
    // Ribbon normals: the root's tangent, the same for every point of a
    // straight strand.
    let normals = roots
        .iter()
        .flat_map(|r| std::iter::repeat_n(r.tangent_frame(spot).tangent, points))
        .collect();
    let uvs = roots
        .iter()
        .map(|r| r.uv(spot).unwrap_or_default())
        .collect();
    Ok(curves
        .with_normals(normals)?
        .with_root_uvs(uvs)?
        .with_ids((first..first + count).collect())?)
}

fn write_groom(args: &IoBenchArgs, hairs: u64) -> anyhow::Result<Run> {
    let spot = pelage::assets::spot();
    let sampler =
        DensitySampler::new(&spot, &Map::Constant(1.0), DensitySamplerOptions::default())?;
    let path = args
        .dir
        .join(format!("pelage-bench-io-{}.usda", std::process::id()));
    let mut generate = Duration::ZERO;
    reset_peak_rss();
    let start = Instant::now();
    write_atomically(&path, |out| {
        let mut usd =
            UsdaWriter::new(out, &UsdOptions::default()).map_err(std::io::Error::other)?;
        let mut first = 0;
        let mut index = 0;
        while first < hairs {
            let count = args.part_hairs.min(hairs - first);
            let t = Instant::now();
            let curves =
                part(&spot, &sampler, first, count, args.points).map_err(std::io::Error::other)?;
            generate += t.elapsed();
            usd.write_part(&format!("part_{index:04}"), &curves)
                .map_err(std::io::Error::other)?;
            first += count;
            index += 1;
        }
        usd.finish().map_err(std::io::Error::other)?;
        Ok(())
    })?;
    // Writing includes the final flush, fsync and rename.
    let write = start.elapsed() - generate;
    let peak = peak_rss();
    let bytes = std::fs::metadata(&path)
        .with_context(|| format!("cannot read {}", path.display()))?
        .len();
    std::fs::remove_file(&path).ok();
    Ok(Run {
        hairs,
        bytes,
        write,
        generate,
        peak_rss: peak,
    })
}

pub fn run(args: &IoBenchArgs) -> anyhow::Result<()> {
    let threads = rayon::current_num_threads();
    let sizes: Vec<u64> = if args.quick {
        vec![200_000]
    } else {
        vec![200_000, args.hairs]
    };
    let runs = sizes
        .iter()
        .map(|&h| on_threads(threads, || write_groom(args, h))?)
        .collect::<anyhow::Result<Vec<Run>>>()?;
    let mb = |b: u64| b as f64 / 1e6;
    let large = runs.last().expect("at least one run");
    if args.json {
        let peak = |r: &Run| r.peak_rss.map(mb);
        let report = serde_json::json!({
            "threads": threads,
            "hairs": large.hairs,
            "points_per_hair": args.points,
            "part_hairs": args.part_hairs,
            "file_mb": mb(large.bytes),
            "write_s": large.write.as_secs_f64(),
            "mb_per_s": mb(large.bytes) / large.write.as_secs_f64(),
            "peak_rss_mb": peak(large),
            "small_hairs": runs[0].hairs,
            "small_peak_rss_mb": peak(&runs[0]),
        });
        println!("{report}");
        return Ok(());
    }
    println!(
        "pelage bench io — usda, {} points a hair, parts of {} hairs, {threads} threads, into {}",
        args.points,
        thousands(args.part_hairs),
        args.dir.display()
    );
    println!("hairs carry widths, normals, root UVs and ids; generation is not timed\n");
    println!(
        "{:>11}  {:>10}  {:>9}  {:>10}  {:>13}  {:>10}",
        "hairs", "file", "write", "MB/s", "peak RSS", "generate"
    );
    for r in &runs {
        println!(
            "{:>11}  {:>7.0} MB  {:>7.2} s  {:>10.1}  {:>13}  {:>8.2} s",
            thousands(r.hairs),
            mb(r.bytes),
            r.write.as_secs_f64(),
            mb(r.bytes) / r.write.as_secs_f64(),
            r.peak_rss
                .map_or("n/a".into(), |p| format!("{:.0} MB", mb(p))),
            r.generate.as_secs_f64()
        );
    }
    if let [small, large] = runs.as_slice()
        && let (Some(a), Some(b)) = (small.peak_rss, large.peak_rss)
    {
        println!(
            "\n{:.0}× the hairs, {:.2}× the peak memory: the writer streams (memory follows the part size, not the groom)",
            large.hairs as f64 / small.hairs as f64,
            b as f64 / a as f64
        );
    }
    Ok(())
}
