//! `pelage bench groom`: the Stubble figure (Sik §4.2.2, Fig. 17):
//! 1,600,000 hairs of 16 points, Shepard k = 4, noise + clump + normals +
//! widths, on spot ×2, all threads — the paper's 3.2 s on two cores. Also
//! the same groom with the style mesh; Blender's case (1 M hairs × 8
//! points, distribution and interpolation only); and the peak memory of streaming
//! 10 M hairs to USD (a child process, so its peak is its own).

use super::median_seconds;
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use pelage::groom::Groom;
use pelage::io::CurvesExport;
use std::time::Instant;

/// Arguments of `pelage bench groom`.
#[derive(Debug, Args)]
pub struct GroomBenchArgs {
    /// A reduced run (200,000 hairs; 1 M for the memory figure).
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Measure a peer in the same run: `blender` grows Blender's own case
    /// (Distribute Points on Faces + Interpolate Curves) with Blender as a
    /// Python module (bpy, set up in a cached venv by tools/bpy-python).
    #[arg(long, value_enum)]
    pub peer: Option<Peer>,
    /// Measure grooming by hand instead: one comb dab regrown
    /// incrementally against a full regrow, at full and preview density
    /// (with `--peer blender`: Blender re-evaluating Interpolate Curves
    /// after a guide edit).
    #[arg(long)]
    pub edit: bool,
    /// Internal: stream this many hairs to USD and print the peak RSS.
    #[arg(long, hide = true)]
    pub rss_child: Option<u64>,
}

impl GroomBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }
}

/// A program measured beside pelage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Peer {
    /// Blender (its geometry nodes or its hair dynamics), through bpy.
    Blender,
}

/// The paper's time for 1.6 M hairs on two cores (Sik §4.2.2).
const PAPER_SECONDS: f64 = 3.2;

/// Blender's case measured by Blender itself, in this run.
#[derive(Debug)]
struct BlenderRun {
    seconds: f64,
    hairs: u64,
    points: u64,
    version: String,
}

/// Runs Blender's own hair case (`blender_hair.py`: Distribute Points on
/// Faces + Interpolate Curves, k = 4 neighbours) on `groom`'s mesh and
/// guides for `hairs` hairs, with bpy from tools/bpy-python. An error says
/// why it was not measured.
fn measure_blender(groom: &Groom, hairs: u64, runs: usize) -> anyhow::Result<BlenderRun> {
    let report = super::run_bpy_case("blender_hair.py", include_str!("blender_hair.py"), |dir| {
        write_groom_case(dir, groom)?;
        let (mesh, guides) = (groom.mesh(), groom.guides());
        let case = serde_json::json!({
            "hairs": hairs,
            "area": mesh.surface_area(),
            "guides": guides.len(),
            "points_per_guide": guides.points_per_guide(),
            "neighbours": 4,
            "runs": runs,
        });
        std::fs::write(dir.join("case.json"), case.to_string())?;
        Ok(())
    })?;
    let number = |key: &str| report[key].as_f64().context("a number in Blender's report");
    Ok(BlenderRun {
        seconds: number("seconds")?,
        hairs: number("hairs")? as u64,
        points: number("points")? as u64,
        version: report["blender"].as_str().unwrap_or("?").to_string(),
    })
}

/// A groom's mesh and guide points, as Blender's cases read them
/// (`positions.f32`, `triangles.u32`, `guides.f32`).
pub(super) fn write_groom_case(dir: &std::path::Path, groom: &Groom) -> std::io::Result<()> {
    super::write_mesh_case(dir, groom.mesh())?;
    let points = groom
        .guides()
        .curves()
        .points()
        .iter()
        .flat_map(|p| p.to_array());
    super::write_le(&dir.join("guides.f32"), points.map(f32::to_le_bytes))
}

/// What both benchmark grooms share: spot ×2, a noise density, 1,000
/// grown guides of 8 points.
fn groom_head(hairs: u64) -> String {
    format!(
        r#"[mesh]
path = "spot"
subdivide = 2

[roots]
count = {hairs}
density = "noise:frequency=6,octaves=3,seed=2,offset=0.6,scale=0.4"

[guides]
points = 8
generate = {{ count = 1000, length = 0.06, comb = [0, -0.5, -1], gravity = 0.3 }}
"#
    )
}

/// The Stubble figure: `method` interpolation, clump + noise, 16 points,
/// normals and widths.
/// Hairs kept out of the skin, for the bench's groom: appended to its
/// last section, `[finish]`.
const OUTSIDE_SKIN: &str = "outside_skin = true\n";

/// A `[look]` for the bench's groom: melanin from a noise map, the rest
/// constants, every value jittered.
const LOOK: &str = "\n[look]\nmelanin = \"noise:frequency=3,seed=2,offset=0.5,scale=0.4\"\nroughness = 0.3\njitter = 0.1\n";

pub(super) fn groom_text(hairs: u64, method: &str) -> String {
    format!(
        r#"{head}
[interpolation]
method = "{method}"
k = 4

[[ops]]
clump = {{ count = {clumps}, rate = 0.6 }}

[[ops]]
noise = {{ amplitude = 0.004, frequency = 30 }}

[finish]
points = 16
width = {{ root = 0.0015, tip = 0.0002 }}
"#,
        head = groom_head(hairs),
        clumps = (hairs / 100).max(1)
    )
}

/// The Stubble figure with blue-noise roots (thinned all parts
/// together).
fn blue_noise_text(hairs: u64) -> String {
    groom_text(hairs, "shepard").replacen(
        "[roots]\n",
        "[roots]\ndistribution = \"blue-noise\"\n",
        1,
    )
}

/// The Stubble figure with hair ids numbered part by part, as before
/// stable ids (the baseline of their cost).
fn sequential_ids_text(hairs: u64) -> String {
    groom_text(hairs, "shepard").replacen("[roots]\n", "[roots]\nids = \"sequential\"\n", 1)
}

/// The Stubble figure with a parting and its clump and noise masked, the
/// way a groomer paints them: a parting image (black on one side of a
/// wavy line, white on the other) and a mask image (512², grey levels
/// from noise), written to `dir`.
fn parted_masked_text(hairs: u64, dir: &std::path::Path) -> anyhow::Result<String> {
    const SIDE: u32 = 512;
    let noise = pelage::map::NoiseMap::new(3.0, 4, 5, 0.6, 0.4);
    let mask = image::GrayImage::from_fn(SIDE, SIDE, |x, y| {
        let uv = glam::Vec2::new(x as f32 + 0.5, SIDE as f32 - y as f32 - 0.5) / SIDE as f32;
        image::Luma([(noise.eval(uv).clamp(0.0, 1.0) * 255.0) as u8])
    });
    let parting = image::GrayImage::from_fn(SIDE, SIDE, |x, y| {
        let (u, v) = (x as f32 / SIDE as f32, y as f32 / SIDE as f32);
        image::Luma([if u > 0.5 + 0.05 * (v * 12.0).sin() {
            255
        } else {
            0
        }])
    });
    let (mask_path, parting_path) = (dir.join("mask.png"), dir.join("parting.png"));
    mask.save(&mask_path)?;
    parting.save(&parting_path)?;
    let mask = format!("mask = \"{}\"", mask_path.display());
    Ok(groom_text(hairs, "shepard")
        .replace("rate = 0.6 }", &format!("rate = 0.6, {mask} }}"))
        .replace("frequency = 30 }", &format!("frequency = 30, {mask} }}"))
        + &format!(
            "\n[regions]\nmap = \"{}:nearest\"\n",
            parting_path.display()
        ))
}

/// Blender's case: distribution and interpolation only, 8 points, no
/// operators, no normals.
pub(super) fn blender_case_text(hairs: u64) -> String {
    format!(
        "{}\n[finish]\npoints = 8\nnormals = false\n",
        groom_head(hairs)
    )
}

/// Generates every part (in memory, each handed back when counted, as the
/// USD writer does); returns the hairs and points grown.
pub(super) fn grow_all(groom: &Groom) -> anyhow::Result<(u64, u64)> {
    let generator = groom.generator(None)?;
    let (mut hairs, mut points) = (0u64, 0u64);
    for p in 0..generator.parts().len() {
        let c = generator.part(p)?;
        hairs += c.curve_count() as u64;
        points += c.points().len() as u64;
        generator.recycle(c);
    }
    Ok((hairs, points))
}

/// Peak resident memory of this process (Linux `VmHWM`), in bytes.
pub(super) fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn rss_child(hairs: u64) -> anyhow::Result<()> {
    let groom = Groom::from_text("<bench>", groom_text(hairs, "shepard"))?;
    let generator = groom.generator(None)?;
    let start = Instant::now();
    let mut bytes = CountingSink(0);
    generator.write_usd(
        &mut bytes,
        0..generator.parts().len(),
        &CurvesExport::default(),
        |_, _| {},
    )?;
    println!(
        "{} {} {:.3}",
        peak_rss_bytes().unwrap_or(0),
        bytes.0,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Counts what is written to it.
struct CountingSink(u64);

impl std::io::Write for CountingSink {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0 += buf.len() as u64;
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Everything `pelage bench groom` measures, before it is printed.
struct GroomFigures {
    /// Hairs a second, Shepard, all of it.
    per_s: f64,
    /// The paper's seconds scaled to this run's hair count.
    paper_scaled: f64,
    runs: usize,
    rss_hairs: u64,
    threads: usize,
    triangles: usize,
    prep_s: f64,
    shepard_s: f64,
    hair_count: u64,
    point_count: u64,
    blender_hairs: u64,
    blender_s: f64,
    blender_per_million: f64,
    peer: Result<BlenderRun, String>,
    sequential_s: f64,
    parted_s: f64,
    /// `--fraction 0.1`: the first tenth of the arrivals, wider.
    fraction_s: f64,
    /// With a `[look]`: hair-shader values from a noise map, jittered.
    look_s: f64,
    /// With `[finish] outside_skin`: points pushed out of the skin.
    outside_s: f64,
    /// With `[roots] distribution = "blue-noise"`: the roots drawn twice
    /// over and thinned, all parts together.
    blue_noise_s: f64,
    stable_ratio: f64,
    parted_ratio: f64,
    style_prep_s: f64,
    style_s: f64,
    grow_s: f64,
    style_grow_s: f64,
    rss: u64,
    usd_bytes: u64,
    rss_s: f64,
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &GroomBenchArgs) -> anyhow::Result<()> {
    if let Some(hairs) = args.rss_child {
        return rss_child(hairs);
    }
    let figures = measure(args)?;
    if args.json {
        println!("{}", figures.to_json());
    } else {
        figures.print();
    }
    Ok(())
}

/// Grows the benchmark's grooms (and Blender's case with `--peer
/// blender`) and measures the memory of a large one in a child process.
fn measure(args: &GroomBenchArgs) -> anyhow::Result<GroomFigures> {
    let (hairs, rss_hairs, runs) = args.scale().pick(
        (1_600_000u64, 10_000_000u64, 3),
        (200_000, 1_000_000, 3),
        (5_000, 20_000, 1),
    );
    let threads = rayon::current_num_threads();
    let shepard = Groom::from_text("<bench>", groom_text(hairs, "shepard"))?;
    let style = Groom::from_text("<bench>", groom_text(hairs, "style-mesh"))?;
    let triangles = shepard.mesh().triangle_count();
    let (prep_s, _) = median_seconds(runs, false, || shepard.generator(None).map(|_| ()));
    let (shepard_s, counted) = median_seconds(runs, true, || grow_all(&shepard));
    let (hair_count, point_count) = counted?;
    let blender_hairs = args.scale().pick(1_000_000, 200_000, 5_000);
    let blender = Groom::from_text("<bench>", blender_case_text(blender_hairs))?;
    let (blender_s, blender_counted) = median_seconds(runs, false, || grow_all(&blender));
    blender_counted?;
    let blender_per_million = blender_s * 1e6 / blender_hairs as f64;
    let peer = match args.peer {
        Some(Peer::Blender) => {
            eprintln!("measuring Blender's case with bpy (tools/bpy-python)…");
            measure_blender(&blender, blender_hairs, runs).map_err(|e| format!("{e:#}"))
        }
        None => Err("run with --peer blender".to_string()),
    };
    let sequential = Groom::from_text("<bench>", sequential_ids_text(hairs))?;
    let (sequential_s, sequential_counted) = median_seconds(runs, false, || grow_all(&sequential));
    sequential_counted?;
    let images = std::env::temp_dir().join(format!("pelage-bench-groom-{}", std::process::id()));
    std::fs::create_dir_all(&images)?;
    let parted =
        parted_masked_text(hairs, &images).and_then(|text| Ok(Groom::from_text("<bench>", text)?));
    let (parted_s, parted_counted) = match parted {
        Ok(parted) => median_seconds(runs, false, || grow_all(&parted)),
        Err(e) => (0.0, Err(e)),
    };
    let _ = std::fs::remove_dir_all(&images);
    parted_counted?;
    let mut tenth = Groom::from_text("<bench>", groom_text(hairs, "shepard"))?;
    tenth.set_fraction(0.1)?;
    let (fraction_s, fraction_counted) = median_seconds(runs, false, || grow_all(&tenth));
    fraction_counted?;
    let looked = Groom::from_text("<bench>", groom_text(hairs, "shepard") + LOOK)?;
    let (look_s, look_counted) = median_seconds(runs, false, || grow_all(&looked));
    look_counted?;
    let outside = Groom::from_text("<bench>", groom_text(hairs, "shepard") + OUTSIDE_SKIN)?;
    let (outside_s, outside_counted) = median_seconds(runs, false, || grow_all(&outside));
    outside_counted?;
    let blue_noise = Groom::from_text("<bench>", blue_noise_text(hairs))?;
    let (blue_noise_s, blue_noise_counted) = median_seconds(runs, false, || grow_all(&blue_noise));
    blue_noise_counted?;
    let stable_ratio = shepard_s / sequential_s;
    let parted_ratio = parted_s / sequential_s;
    let (style_prep_s, _) = median_seconds(1, false, || style.generator(None).map(|_| ()));
    let (style_s, style_counted) = median_seconds(runs, false, || grow_all(&style));
    style_counted?;
    // Generation alone: the median run less its preparation.
    let grow_s = (shepard_s - prep_s).max(1e-9);
    let style_grow_s = (style_s - style_prep_s).max(1e-9);

    // Peak memory of streaming rss_hairs to USD, in a child process.
    let exe = std::env::current_exe().context("cannot find the pelage executable")?;
    let child = std::process::Command::new(exe)
        .args(["bench", "groom", "--rss-child", &rss_hairs.to_string()])
        .output()
        .context("cannot run the memory measurement")?;
    anyhow::ensure!(
        child.status.success(),
        "the memory measurement failed: {}",
        String::from_utf8_lossy(&child.stderr)
    );
    let out = String::from_utf8_lossy(&child.stdout);
    let fields: Vec<f64> = out
        .split_whitespace()
        .filter_map(|f| f.parse().ok())
        .collect();
    let (rss, usd_bytes, rss_s) = match fields[..] {
        [a, b, c] => (a as u64, b as u64, c),
        _ => anyhow::bail!("unexpected memory measurement output {out:?}"),
    };
    Ok(GroomFigures {
        per_s: hair_count as f64 / shepard_s,
        paper_scaled: PAPER_SECONDS * hairs as f64 / 1.6e6,
        runs,
        rss_hairs,
        threads,
        triangles,
        prep_s,
        shepard_s,
        hair_count,
        point_count,
        blender_hairs,
        blender_s,
        blender_per_million,
        peer,
        sequential_s,
        parted_s,
        fraction_s,
        look_s,
        outside_s,
        blue_noise_s,
        stable_ratio,
        parted_ratio,
        style_prep_s,
        style_s,
        grow_s,
        style_grow_s,
        rss,
        usd_bytes,
        rss_s,
    })
}

impl GroomFigures {
    /// The figures as one JSON object (`--json`).
    fn to_json(&self) -> serde_json::Value {
        let &GroomFigures {
            per_s,
            paper_scaled,
            rss_hairs,
            threads,
            triangles,
            prep_s,
            shepard_s,
            hair_count,
            point_count,
            blender_hairs,
            blender_s,
            blender_per_million,
            ref peer,
            sequential_s,
            parted_s,
            fraction_s,
            look_s,
            outside_s,
            blue_noise_s,
            stable_ratio,
            parted_ratio,
            style_prep_s,
            style_s,
            grow_s,
            rss,
            usd_bytes,
            rss_s,
            ..
        } = self;
        let report = serde_json::json!({
            "hairs": hair_count,
            "points_per_hair": 16,
            "points": point_count,
            "triangles": triangles,
            "threads": threads,
            "seconds": shepard_s,
            "hairs_per_s": per_s.round(),
            "prepare_s": prep_s,
            "grow_s": grow_s,
            "style_mesh_seconds": style_s,
            "style_mesh_prepare_s": style_prep_s,
            "style_mesh_hairs_per_s": (hair_count as f64 / style_s).round(),
            "paper_seconds": paper_scaled,
            "interpolation_only_8_points_s_per_million": blender_per_million,
            "blender": match &peer {
                Ok(b) => serde_json::json!({
                    "version": b.version,
                    "seconds": b.seconds,
                    "hairs": b.hairs,
                    "points": b.points,
                    "s_per_million": b.seconds * 1e6 / b.hairs.max(1) as f64,
                    "pelage_speedup": b.seconds / blender_s * blender_hairs as f64 / b.hairs.max(1) as f64,
                }),
                Err(why) => serde_json::json!({ "not_measured": why }),
            },
            "sequential_ids_seconds": sequential_s,
            "stable_ids_ratio": stable_ratio,
            "parting_two_masks_seconds": parted_s,
            "parting_two_masks_ratio": parted_ratio,
            "fraction_0_1_seconds": fraction_s,
            "fraction_0_1_ratio": fraction_s / shepard_s,
            "look_seconds": look_s,
            "look_ratio": look_s / shepard_s,
            "outside_skin_seconds": outside_s,
            "outside_skin_ratio": outside_s / shepard_s,
            "blue_noise_groom_seconds": blue_noise_s,
            "blue_noise_groom_ratio": blue_noise_s / shepard_s,
            "rss_hairs": rss_hairs,
            "peak_rss_bytes": rss,
            "rss_usd_bytes": usd_bytes,
            "rss_seconds": rss_s,
        });
        report
    }

    /// The figures as a table beside the paper's and the peer's.
    fn print(&self) {
        let &GroomFigures {
            per_s,
            paper_scaled,
            runs,
            rss_hairs,
            threads,
            triangles,
            prep_s,
            shepard_s,
            hair_count,
            blender_hairs,
            blender_s,
            ref peer,
            sequential_s,
            parted_s,
            fraction_s,
            look_s,
            outside_s,
            blue_noise_s,
            stable_ratio,
            parted_ratio,
            style_s,
            grow_s,
            style_grow_s,
            rss,
            usd_bytes,
            rss_s,
            ..
        } = self;
        println!(
            "pelage bench groom — {} hairs × 16 points on spot ×2 ({} triangles), 1,000 guides, clump + noise + normals + widths; {threads} threads, median of {runs}\n",
            thousands(hair_count),
            thousands(triangles as u64)
        );
        println!(
            "{:<40} {:>10} {:>12} {:>14}",
            "", "seconds", "M hairs/s", "paper / peer"
        );
        println!(
            "{:<40} {:>10.3} {:>12.2} {:>14}",
            "Shepard k = 4, all of it",
            shepard_s,
            per_s / 1e6,
            format!("{paper_scaled:.2} s")
        );
        println!(
            "{:<40} {:>10.3} {:>12} {:>14}",
            "  of which preparation (guides, kd-tree,", prep_s, "", ""
        );
        println!("{:<40}", "  sampler, clump centres)");
        println!(
            "{:<40} {:>10.3} {:>12.2} {:>14}",
            "  growing the hairs",
            grow_s,
            hair_count as f64 / grow_s / 1e6,
            ""
        );
        println!(
            "{:<40} {:>10.3} {:>12.2} {:>14}",
            "  ids part by part (the old numbering)",
            sequential_s,
            hair_count as f64 / sequential_s / 1e6,
            format!("stable {stable_ratio:.2}×")
        );
        println!(
            "{:<40} {:>10.3} {:>12.2} {:>14}",
            "  with a parting and two masked ops",
            parted_s,
            hair_count as f64 / parted_s / 1e6,
            format!("{parted_ratio:.2}× old")
        );
        // The same groom with one thing changed, against all of it.
        let variant = |label: &str, seconds: f64, hairs: f64, target: &str| {
            println!(
                "{label:<40} {seconds:>10.3} {:>12.2} {:>14}",
                hairs / seconds / 1e6,
                format!("{:.3}× all{target}", seconds / shepard_s)
            );
        };
        let hairs = hair_count as f64;
        variant(
            "  a tenth (--fraction 0.1), wider hairs",
            fraction_s,
            hairs / 10.0,
            "",
        );
        variant("  with a [look] (melanin map, jitter)", look_s, hairs, "");
        variant(
            "  hairs out of the skin (outside_skin)",
            outside_s,
            hairs,
            ", target ≤ 1.25×",
        );
        variant("  blue-noise roots", blue_noise_s, hairs, ", target ≤ 1.5×");
        println!(
            "{:<40} {:>10.3} {:>12.2} {:>14}",
            "style mesh, all of it",
            style_s,
            hair_count as f64 / style_s / 1e6,
            "—"
        );
        println!(
            "{:<40} {:>10.3} {:>12.2} {:>14}",
            "  growing the hairs",
            style_grow_s,
            hair_count as f64 / style_grow_s / 1e6,
            ""
        );
        println!(
            "{:<40} {:>10.3} {:>12.2} {:>14}",
            format!("{} × 8 points, no operators", thousands(blender_hairs)),
            blender_s,
            blender_hairs as f64 / blender_s / 1e6,
            ""
        );
        match &peer {
            Ok(b) => {
                // Per hair, in case Blender's random distribution made a few
                // more or fewer hairs than asked.
                let ratio = b.seconds / blender_s * blender_hairs as f64 / b.hairs.max(1) as f64;
                println!(
                    "{:<40} {:>10.3} {:>12.2} {:>14}",
                    format!(
                        "  peer: Blender {} ({} hairs)",
                        b.version,
                        thousands(b.hairs)
                    ),
                    b.seconds,
                    b.hairs as f64 / b.seconds / 1e6,
                    format!("pelage {ratio:.1}× faster"),
                );
            }
            Err(why) => println!("{:<40} not measured: {why}", "  peer: Blender"),
        }
        println!(
            "\ntarget: ≥ 5 M hairs/s (1.6 M in ≤ 0.32 s); stable ids ≤ 1.1× and a parting with two masked ops ≤ 1.3× the old numbering; a tenth ≤ 0.15× all of it. Paper: 1.6 M hairs in 3.2 s on 2 cores (0.5 M hairs/s)."
        );
        println!(
            "memory: {} hairs streamed to USD ({:.1} GB of text, {:.1} s): peak RSS {:.0} MB (limit 1,024 MB)",
            thousands(rss_hairs),
            usd_bytes as f64 / 1e9,
            rss_s,
            rss as f64 / 1e6
        );
    }
}
