//! `pelage bench io`: writing a large groom as usdc, usda and Alembic,
//! part by part, with bounded memory. Hairs are straight strands on Spot
//! with widths, normals, root UVs and ids (what the groom generator
//! writes), generated one part at a time as the generator does; only the
//! writing is timed. `dd` writes as many bytes as the usdc file in the same
//! run: the disk's own bandwidth, what a writer can aim at.
//!
//! Peak memory is the process's peak resident set (`VmHWM`), reset before
//! each run through `/proc/self/clear_refs`, so a small and a large run can
//! be compared: if the writer streams, they peak at about the same size.
//!
//! With `--peer blender`, Blender imports the demo groom twice in the same
//! run: pelage's usdc, and the usdc Pixar's usd-core writes of the same
//! layer (from pelage's usda, `tools/usdcheck --convert`).

use super::on_threads;
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use pelage::io::{
    CurvesExport, CurvesFormat, PrimWriter, UsdOptions, write_atomically, write_streamed,
};
use pelage::sample::{DensitySampler, DensitySamplerOptions, sample_range};
use pelage::{Curves, Map};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Arguments of `pelage bench io`.
#[derive(Debug, Args)]
pub struct IoBenchArgs {
    /// A reduced run (200,000 hairs only).
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Hairs in the large run.
    #[arg(long, default_value_t = 2_000_000)]
    pub hairs: u64,
    /// Points per hair.
    #[arg(long, default_value_t = 16)]
    pub points: usize,
    /// Hairs per part (one BasisCurves prim or ICurves object each).
    #[arg(long, default_value_t = 50_000)]
    pub part_hairs: u64,
    /// Folder for the files (deleted afterwards).
    #[arg(long, default_value_os_t = std::env::temp_dir())]
    pub dir: PathBuf,
    /// Measure a peer in the same run: `blender` imports pelage's usdc of
    /// the demo groom and usd-core's usdc of the same layer.
    #[arg(long, value_enum)]
    pub peer: Option<super::groom::Peer>,
}

impl IoBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }
}

/// The formats measured, in the order of the table.
const FORMATS: [CurvesFormat; 3] = [CurvesFormat::Usdc, CurvesFormat::Usda, CurvesFormat::Abc];

struct Run {
    format: CurvesFormat,
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

fn write_groom(args: &IoBenchArgs, hairs: u64, format: CurvesFormat) -> anyhow::Result<Run> {
    let spot = pelage::assets::spot();
    let sampler =
        DensitySampler::new(&spot, &Map::Constant(1.0), DensitySamplerOptions::default())?;
    let path = args.dir.join(format!(
        "pelage-bench-io-{}.{}",
        std::process::id(),
        format.extension()
    ));
    let mut generate = Duration::ZERO;
    reset_peak_rss();
    let start = Instant::now();
    write_atomically(&path, |out| {
        use std::io::Error as E;
        let mut stream = |writer: &mut dyn PrimWriter| {
            let mut first = 0;
            let mut index = 0;
            while first < hairs {
                let count = args.part_hairs.min(hairs - first);
                let t = Instant::now();
                let curves = part(&spot, &sampler, first, count, args.points).map_err(E::other)?;
                generate += t.elapsed();
                writer
                    .write_part(&format!("part_{index:04}"), &curves)
                    .map_err(E::other)?;
                first += count;
                index += 1;
            }
            Ok::<(), std::io::Error>(())
        };
        write_streamed(out, format, &UsdOptions::default(), |writer| stream(writer))?;
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
        format,
        hairs,
        bytes,
        write,
        generate,
        peak_rss: peak,
    })
}

/// `dd` writing `bytes` of zeros with an fsync, as the writers' files are
/// synced: MB/s, or why it was not measured.
fn dd_mb_per_s(dir: &Path, bytes: u64) -> Result<f64, String> {
    let path = dir.join(format!("pelage-bench-io-dd-{}", std::process::id()));
    let count = bytes.div_ceil(1 << 20).max(1);
    let start = Instant::now();
    let status = std::process::Command::new("dd")
        .arg("if=/dev/zero")
        .arg(format!("of={}", path.display()))
        .args([
            "bs=1M",
            &format!("count={count}"),
            "conv=fsync",
            "status=none",
        ])
        .status();
    let seconds = start.elapsed().as_secs_f64();
    std::fs::remove_file(&path).ok();
    match status {
        Ok(s) if s.success() => Ok((count << 20) as f64 / 1e6 / seconds),
        Ok(s) => Err(format!("dd exited with {s}")),
        Err(e) => Err(format!("dd did not start: {e}")),
    }
}

/// Blender's import time (median of 5) of pelage's usdc of the demo groom
/// and of usd-core's usdc of the same layer.
struct BlenderImports {
    pelage: f64,
    usd_core: f64,
    pelage_bytes: u64,
    usd_core_bytes: u64,
    version: String,
}

fn blender_imports() -> anyhow::Result<BlenderImports> {
    let tools = super::tools_dir();
    let dir = std::env::temp_dir().join(format!("pelage-io-peer-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let result = (|| {
        std::fs::write(dir.join("demo.toml"), crate::DEMO_GROOM)?;
        std::fs::write(dir.join("spot.png"), pelage::assets::SPOT_TEXTURE_PNG)?;
        let groom = pelage::groom::Groom::load(&dir.join("demo.toml"))?;
        let generator = groom.generator(None)?;
        let export = CurvesExport {
            usd: UsdOptions::default(),
            mesh: Some(groom.mesh()),
            guides: None,
        };
        let parts = 0..generator.parts().len();
        let (ours, text, theirs) = (
            dir.join("pelage.usdc"),
            dir.join("pelage.usda"),
            dir.join("usd-core.usdc"),
        );
        generator.write(&ours, parts.clone(), &export, |_, _| {})?;
        generator.write(&text, parts, &export, |_, _| {})?;
        let out = std::process::Command::new(tools.join("usdcheck"))
            .arg("--convert")
            .args([&text, &theirs])
            .output()?;
        anyhow::ensure!(
            out.status.success(),
            "usd-core could not convert the layer: {}",
            String::from_utf8_lossy(&out.stdout)
        );
        let import = |file: &Path| -> anyhow::Result<(f64, String)> {
            let out = std::process::Command::new(tools.join("blendercheck"))
                .arg(file)
                .args(["--repeat", "5"])
                .output()?;
            let text = String::from_utf8_lossy(&out.stdout).into_owned();
            anyhow::ensure!(
                out.status.success(),
                "Blender could not import {}: {text}",
                file.display()
            );
            let seconds = text
                .lines()
                .find_map(|l| {
                    l.strip_prefix("import ")?
                        .strip_suffix(" seconds")?
                        .parse()
                        .ok()
                })
                .context("blendercheck printed no import time")?;
            let version = text
                .lines()
                .find_map(|l| l.strip_prefix("blender "))
                .unwrap_or("?")
                .to_string();
            Ok((seconds, version))
        };
        let (pelage, version) = import(&ours)?;
        let (usd_core, _) = import(&theirs)?;
        Ok(BlenderImports {
            pelage,
            usd_core,
            pelage_bytes: std::fs::metadata(&ours)?.len(),
            usd_core_bytes: std::fs::metadata(&theirs)?.len(),
            version,
        })
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &IoBenchArgs) -> anyhow::Result<()> {
    let threads = rayon::current_num_threads();
    let sizes: Vec<u64> = args
        .scale()
        .pick(vec![200_000, args.hairs], vec![200_000], vec![5_000]);
    let mut runs = Vec::new();
    for format in FORMATS {
        for &hairs in &sizes {
            runs.push(on_threads(threads, || write_groom(args, hairs, format))??);
        }
    }
    let large = |format| {
        runs.iter()
            .rfind(|r: &&Run| r.format == format)
            .expect("every format ran")
    };
    let (usdc, usda, abc) = (
        large(CurvesFormat::Usdc),
        large(CurvesFormat::Usda),
        large(CurvesFormat::Abc),
    );
    let dd = dd_mb_per_s(&args.dir, usdc.bytes);
    let blender = args
        .peer
        .map(|_| blender_imports().map_err(|e| format!("{e:#}")));
    let mb = |b: u64| b as f64 / 1e6;
    let rate = |r: &Run| mb(r.bytes) / r.write.as_secs_f64();
    let peak = runs.iter().filter_map(|r| r.peak_rss).max();
    if args.json {
        let report = serde_json::json!({
            "threads": threads,
            "hairs": usdc.hairs,
            "points_per_hair": args.points,
            "part_hairs": args.part_hairs,
            "usdc_seconds": usdc.write.as_secs_f64(),
            "usda_seconds": usda.write.as_secs_f64(),
            "abc_seconds": abc.write.as_secs_f64(),
            "usdc_bytes": usdc.bytes,
            "usda_bytes": usda.bytes,
            "abc_bytes": abc.bytes,
            "peak_rss_bytes": peak,
            "usdc_mb_per_s": rate(usdc),
            "dd_mb_per_s": dd.as_ref().ok(),
            "usdc_speedup_over_usda": usda.write.as_secs_f64() / usdc.write.as_secs_f64(),
            "usdc_size_over_usda": usdc.bytes as f64 / usda.bytes as f64,
            "blender": match &blender {
                Some(Ok(b)) => serde_json::json!({
                    "version": b.version,
                    "import_pelage_usdc_seconds": b.pelage,
                    "import_usd_core_usdc_seconds": b.usd_core,
                    "pelage_usdc_bytes": b.pelage_bytes,
                    "usd_core_usdc_bytes": b.usd_core_bytes,
                }),
                Some(Err(why)) => serde_json::json!({ "error": why }),
                None => serde_json::Value::Null,
            },
        });
        println!("{report}");
        return Ok(());
    }
    println!(
        "pelage bench io — {} points a hair, parts of {} hairs, {threads} threads, into {}",
        args.points,
        thousands(args.part_hairs),
        args.dir.display()
    );
    println!("hairs carry widths, normals, root UVs and ids; generation is not timed\n");
    println!(
        "{:>6}  {:>11}  {:>10}  {:>9}  {:>8}  {:>10}  {:>9}",
        "format", "hairs", "file", "write", "MB/s", "peak RSS", "generate"
    );
    for r in &runs {
        println!(
            "{:>6}  {:>11}  {:>7.0} MB  {:>7.2} s  {:>8.0}  {:>10}  {:>7.2} s",
            r.format.extension(),
            thousands(r.hairs),
            mb(r.bytes),
            r.write.as_secs_f64(),
            rate(r),
            r.peak_rss
                .map_or("n/a".into(), |p| format!("{:.0} MB", mb(p))),
            r.generate.as_secs_f64()
        );
    }
    println!(
        "\n{} hairs: usdc is {:.1}× as fast as usda and {:.2} of its size (target: ≥ 5×, ≤ 1/3); Alembic {:.1}× as fast as usda",
        thousands(usdc.hairs),
        usda.write.as_secs_f64() / usdc.write.as_secs_f64(),
        usdc.bytes as f64 / usda.bytes as f64,
        usda.write.as_secs_f64() / abc.write.as_secs_f64(),
    );
    match &dd {
        Ok(d) => println!(
            "dd writes {:.0} MB/s to the same folder (fsync included): usdc reaches {:.0}% of the disk's bandwidth",
            d,
            100.0 * rate(usdc) / d
        ),
        Err(why) => println!("dd: not measured ({why})"),
    }
    if let Some(p) = peak {
        println!(
            "peak RSS over every run: {:.0} MB (target at 10 M hairs: ≤ 1 GB)",
            mb(p)
        );
    }
    match &blender {
        Some(Ok(b)) => println!(
            "Blender {} imports the demo groom (200,000 hairs, median of 5): pelage's usdc {:.2} s ({:.0} MB), usd-core's usdc {:.2} s ({:.0} MB): {:.2}×",
            b.version,
            b.pelage,
            mb(b.pelage_bytes),
            b.usd_core,
            mb(b.usd_core_bytes),
            b.usd_core / b.pelage
        ),
        Some(Err(why)) => println!("Blender import: not measured: {why}"),
        None => println!("Blender import: run with --peer blender"),
    }
    Ok(())
}
