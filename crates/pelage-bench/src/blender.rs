//! `pelage bench blender`: grooming in Blender with the add-on's Live mode
//! against Blender's own hair nodes, both timed in one bpy process
//! (`blender_live.py`).
//!
//! A guide edit in a hair Curves object → the fur updated: pelage's
//! incremental regrowth and the transfer of the points into the fur's
//! Curves object (the add-on's `live_update`), median of the edits;
//! beside it the peer, Blender 5's Distribute Points on Faces +
//! Interpolate Curves re-evaluated after the same edits on the same
//! surface, guides and hair count. And a comb end to end as the user
//! makes it (the depsgraph update, the add-on's handler, the regrow and
//! Blender's evaluation of the fur after it), on the bare grid and with a
//! shape key (the fur then carries Deform Curves on Surface). Targets:
//! ≤ 100 ms an edit at 100,000 hairs, ≥ 5× faster than the peer, ≤ 50 ms
//! a comb end to end.
//!
//! Needs pelage in bpy's venv: the first run puts a release wheel there
//! (`tools/python-wheel --release --into` bpy's Python), as `--peer
//! blender` sets bpy up.

use crate::format::thousands;
use anyhow::Context;
use clap::Args;

/// Arguments of `pelage bench blender`.
#[derive(Debug, Args)]
pub struct BlenderBenchArgs {
    /// A reduced run (20,000 hairs, 10 edits).
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

impl BlenderBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }
}

/// Puts pelage into bpy's venv when it is not there (a release wheel,
/// built once; minutes the first time).
fn ensure_pelage_in_bpy() -> anyhow::Result<()> {
    let bpy_python = super::tools_dir().join("bpy-python");
    let run = |args: &[&str]| {
        std::process::Command::new(&bpy_python)
            .args(args)
            .output()
            .with_context(|| format!("cannot run {}", bpy_python.display()))
    };
    if run(&["-c", "import pelage"])?.status.success() {
        return Ok(());
    }
    let which = run(&["-c", "import sys; print(sys.executable)"])?;
    anyhow::ensure!(
        which.status.success(),
        "bpy could not be set up: {}",
        String::from_utf8_lossy(&which.stderr).trim()
    );
    let python = String::from_utf8_lossy(&which.stdout).trim().to_string();
    eprintln!("installing pelage into bpy's venv ({python}): a release wheel, built once…");
    // Its stdout (the wheel's path) would come before the JSON.
    let status = std::process::Command::new(super::tools_dir().join("python-wheel"))
        .args(["--release", "--into", &python])
        .stdout(std::process::Stdio::null())
        .status()
        .context("cannot run tools/python-wheel")?;
    anyhow::ensure!(
        status.success(),
        "tools/python-wheel --release --into {python} failed"
    );
    Ok(())
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &BlenderBenchArgs) -> anyhow::Result<()> {
    ensure_pelage_in_bpy()?;
    let (hairs, edits) = args.scale().pick((100_000, 20), (20_000, 10), (2_000, 2));
    let report = super::run_bpy_case("blender_live.py", include_str!("blender_live.py"), |dir| {
        let case = serde_json::json!({
            "addon_dir": super::addon_dir()?,
            "hairs": hairs,
            "guides_a_side": 20,
            "edits": edits,
        });
        std::fs::write(dir.join("case.json"), case.to_string())?;
        Ok(())
    })
    .context("the Blender case did not run")?;
    let number = |key: &str| {
        report[key]
            .as_f64()
            .with_context(|| format!("{key}: a number in Blender's report"))
    };
    let (edit, full, peer) = (
        number("edit_update_s")?,
        number("full_update_s")?,
        number("blender_interpolate_s")?,
    );
    let hairs_made = number("hairs")? as u64;
    if args.json {
        let mut json = report.clone();
        json["speedup_over_blender"] = serde_json::json!(peer / edit);
        println!("{json}");
        return Ok(());
    }
    println!(
        "pelage bench blender — {} hairs × 12 points on a 40 × 40 grid, 400 guides in a hair Curves object; Blender {}; median of {} guide edits",
        thousands(hairs_made),
        report["blender"].as_str().unwrap_or("?"),
        report["edits"]
    );
    println!();
    println!("{:<52} {:>10}", "", "ms");
    println!(
        "{:<52} {:>10.1}",
        "pelage Live: an edit → the fur updated",
        edit * 1e3
    );
    println!(
        "{:<52} {:>10}",
        "  fastest – slowest",
        format!(
            "{:.0}–{:.0}",
            number("edit_update_min_s")? * 1e3,
            number("edit_update_max_s")? * 1e3
        )
    );
    println!(
        "{:<52} {:>10.1}",
        "a comb end to end (handler, regrow, Blender's update)",
        number("live_comb_s")? * 1e3
    );
    println!(
        "{:<52} {:>10.1}",
        "  on a deforming surface (Deform Curves on Surface)",
        number("live_comb_deforming_s")? * 1e3
    );
    println!(
        "{:<52} {:>10.1}",
        "pelage: Grow with Live on (the start)",
        full * 1e3
    );
    println!(
        "{:<52} {:>10.1}",
        format!(
            "peer: Blender's Interpolate Curves ({} hairs)",
            thousands(number("blender_hairs")? as u64)
        ),
        peer * 1e3
    );
    println!();
    println!(
        "pelage {:.1}× faster than Blender an edit; targets: ≤ 100 ms an edit at 100,000 hairs, ≥ 5× the peer, ≤ 50 ms a comb end to end",
        peer / edit
    );
    Ok(())
}
