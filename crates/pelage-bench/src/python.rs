//! `pelage bench python`: what the Python package and the Blender add-on
//! cost over the library.
//!
//! - The Stubble figure (Sik §4.2.2: spot ×2, 1.6 M hairs of 16 points,
//!   clump + noise) loaded and grown part by part, by the library in this
//!   process (the CLI's path) and by `pelage.Groom.load(...).parts()` in
//!   Python (`python_grow.py`), in alternating rounds of the same run;
//!   the ratio is the median of the rounds' ratios. Target: Python ≤
//!   1.05× the library.
//! - With `--blender`: 1 M hairs × 16 points made into a Blender hair
//!   Curves object by the add-on's bulk transfer (`blender_curves.py`,
//!   target ≤ 2 s), beside the peer measured in the same run: Blender's
//!   own USD importer reading the same curves from pelage's usdc.

use super::groom::{groom_text, grow_all};
use super::{median, median_seconds};
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use pelage::groom::Groom;
use std::path::{Path, PathBuf};

/// Arguments of `pelage bench python`.
#[derive(Debug, Args)]
pub struct PythonBenchArgs {
    /// A reduced run (200,000 hairs; 100,000 into Blender).
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// The Python with pelage installed (default: $PELAGE_PYTHON, else
    /// the venv tools/python-wheel installs into, else python3). Build a
    /// release wheel for it first: `tools/python-wheel --release`.
    #[arg(long)]
    pub python: Option<PathBuf>,
    /// Also time making the Blender Curves object (bpy from PyPI, set up
    /// in a cached venv by tools/bpy-python).
    #[arg(long)]
    pub blender: bool,
}

impl PythonBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }
}

/// The interpreter the bench runs `python_grow.py` with.
fn python_of(args: &PythonBenchArgs) -> PathBuf {
    if let Some(p) = &args.python {
        return p.clone();
    }
    if let Some(p) = std::env::var_os("PELAGE_PYTHON") {
        return p.into();
    }
    let cache = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cache")));
    if let Some(venv) = cache.map(|c| c.join("pelage/py-venv/bin/python"))
        && venv.exists()
    {
        return venv;
    }
    PathBuf::from("python3")
}

/// What `python_grow.py` measured.
#[derive(Debug)]
struct PythonRun {
    seconds: f64,
    hairs: u64,
    version: String,
    profile: String,
}

fn measure_python(python: &Path, groom: &Path, runs: usize) -> anyhow::Result<PythonRun> {
    let script = groom.with_file_name("python_grow.py");
    std::fs::write(&script, include_str!("python_grow.py"))?;
    let out = std::process::Command::new(python)
        .arg(&script)
        .arg(groom)
        .arg(runs.to_string())
        .output()
        .with_context(|| format!("cannot run {}", python.display()))?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        if stderr.contains("No module named 'pelage'") {
            anyhow::bail!(
                "{} has no pelage; install it with tools/python-wheel --release (or pass --python)",
                python.display()
            );
        }
        anyhow::bail!("the Python run failed: {}", stderr.trim());
    }
    let v = super::last_json_line(&String::from_utf8_lossy(&out.stdout), "python_grow.py")?;
    Ok(PythonRun {
        seconds: v["seconds"].as_f64().unwrap_or(f64::NAN),
        hairs: v["hairs"].as_u64().unwrap_or(0),
        version: v["version"].as_str().unwrap_or("?").to_string(),
        profile: v["profile"].as_str().unwrap_or("?").to_string(),
    })
}

/// What `blender_curves.py` measured.
#[derive(Debug)]
struct BlenderCurves {
    seconds: f64,
    curves: u64,
    points: u64,
    usd_import_seconds: f64,
    version: String,
}

/// Grows `hairs` of the Stubble figure, writes the arrays and a usdc of
/// them, and times the add-on's Curves creation and Blender's USD import.
fn measure_blender(hairs: u64, dir: &Path) -> anyhow::Result<BlenderCurves> {
    let groom_path = dir.join("blender.toml");
    std::fs::write(&groom_path, groom_text(hairs, "shepard"))?;
    let groom = Groom::load(&groom_path)?;
    let generator = groom.generator(None)?;
    let parts: Vec<_> = (0..generator.parts().len())
        .map(|p| generator.part(p))
        .collect::<Result<_, _>>()?;
    let curves = pelage::curves::join(parts.iter())?;
    drop(parts);
    let report = super::run_bpy_case(
        "blender_curves.py",
        include_str!("blender_curves.py"),
        |case| {
            use super::write_le;
            let points = curves.points().iter().flat_map(|p| p.to_array());
            write_le(&case.join("points.f32"), points.map(f32::to_le_bytes))?;
            let widths = curves.widths().iter().map(|w| w.to_le_bytes());
            write_le(&case.join("widths.f32"), widths)?;
            let offsets = curves.offsets().iter().map(|o| o.to_le_bytes());
            write_le(&case.join("offsets.u32"), offsets)?;
            let uvs = curves.root_uvs().context("the groom has root UVs")?;
            let uvs = uvs.iter().flat_map(|u| u.to_array());
            write_le(&case.join("root_uvs.f32"), uvs.map(f32::to_le_bytes))?;
            let ids = curves.ids().context("the groom has ids")?;
            write_le(&case.join("ids.u64"), ids.iter().map(|i| i.to_le_bytes()))?;
            pelage::io::write_curves(
                &case.join("groom.usdc"),
                [("fur".to_string(), &curves)],
                &pelage::io::CurvesExport::default(),
            )?;
            let json = serde_json::json!({
                "addon_dir": super::addon_dir()?,
                "hairs": curves.curve_count(),
            });
            std::fs::write(case.join("case.json"), json.to_string())?;
            Ok(())
        },
    )?;
    Ok(BlenderCurves {
        seconds: report["seconds"].as_f64().unwrap_or(f64::NAN),
        curves: report["curves"].as_u64().unwrap_or(0),
        points: report["points"].as_u64().unwrap_or(0),
        usd_import_seconds: report["usd_import_seconds"].as_f64().unwrap_or(f64::NAN),
        version: report["blender"].as_str().unwrap_or("?").to_string(),
    })
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &PythonBenchArgs) -> anyhow::Result<()> {
    let scale = args.scale();
    let hairs: u64 = scale.pick(1_600_000, 200_000, 5_000);
    let (rounds, runs): (usize, usize) = scale.pick((5, 3), (3, 3), (1, 1));
    let dir = std::env::temp_dir().join(format!("pelage-bench-python-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let result = (|| -> anyhow::Result<()> {
        let groom_path = dir.join("stubble.toml");
        std::fs::write(&groom_path, groom_text(hairs, "shepard"))?;
        let load_and_grow =
            || -> anyhow::Result<(u64, u64)> { grow_all(&Groom::load(&groom_path)?) };
        // Rounds of (library, Python), each side a median of `runs`; the
        // ratio is taken within each round and its median reported, so
        // the drift of a noisy machine lands on both sides of a ratio.
        let python = python_of(args);
        eprintln!(
            "growing through the library and through Python ({})…",
            python.display()
        );
        let mut library = Vec::new();
        let mut through_python = Vec::new();
        let mut ratios = Vec::new();
        let mut grown = (0, 0);
        let mut py: Result<PythonRun, String> = Err("not run".into());
        for round in 0..rounds {
            let (lib_s, counts) = median_seconds(runs, round == 0, load_and_grow);
            grown = counts?;
            library.push(lib_s);
            py = measure_python(&python, &groom_path, runs).map_err(|e| format!("{e:#}"));
            match &py {
                Ok(p) => {
                    through_python.push(p.seconds);
                    ratios.push(p.seconds / lib_s);
                }
                Err(_) => break,
            }
        }
        let (hair_count, point_count) = grown;
        let rust_s = median(&library);
        let ratio = (!ratios.is_empty()).then(|| median(&ratios));
        let py = py.map(|p| PythonRun {
            seconds: median(&through_python),
            ..p
        });
        let blender = match args.blender {
            true => {
                let hairs = scale.pick(1_000_000, 100_000, 2_000);
                eprintln!(
                    "making Blender Curves from {} hairs with bpy (tools/bpy-python)…",
                    thousands(hairs)
                );
                measure_blender(hairs, &dir).map_err(|e| format!("{e:#}"))
            }
            false => Err("run with --blender".to_string()),
        };
        if args.json {
            let report = serde_json::json!({
                "hairs": hair_count,
                "points": point_count,
                "library_s": rust_s,
                "python": match &py {
                    Ok(p) => serde_json::json!({
                        "seconds": p.seconds,
                        "hairs": p.hairs,
                        "version": p.version,
                        "profile": p.profile,
                        "over_library": ratio,
                        "over_library_each_round": ratios,
                    }),
                    Err(why) => serde_json::json!({ "not_measured": why }),
                },
                "blender_curves": match &blender {
                    Ok(b) => serde_json::json!({
                        "version": b.version,
                        "curves": b.curves,
                        "points": b.points,
                        "addon_s": b.seconds,
                        "usd_import_s": b.usd_import_seconds,
                        "addon_speedup_over_usd_import": b.usd_import_seconds / b.seconds,
                    }),
                    Err(why) => serde_json::json!({ "not_measured": why }),
                },
            });
            println!("{report}");
            return Ok(());
        }
        println!(
            "pelage bench python — the Stubble figure ({} hairs × 16 points on spot ×2, clump + noise), loaded and grown part by part\n",
            thousands(hair_count)
        );
        println!("{:<60} {:>10} {:>12}", "", "seconds", "× library");
        println!(
            "{:<60} {rust_s:>10.3} {:>12.2}",
            "library (the CLI's path), in this process", 1.0
        );
        println!(
            "{:<60} medians of {rounds} rounds, {runs} runs a side; the ratio: the median of the rounds'",
            ""
        );
        match &py {
            Ok(p) => {
                println!(
                    "{:<60} {:>10.3} {:>12.3}",
                    format!(
                        "Python: pelage {} ({} build), Groom.load().parts()",
                        p.version, p.profile
                    ),
                    p.seconds,
                    ratio.unwrap_or(f64::NAN)
                );
                let each: Vec<String> = ratios.iter().map(|r| format!("{r:.3}")).collect();
                println!("{:<60} each round: {}", "", each.join(", "));
                if p.profile != "release" {
                    println!(
                        "{:<60} warning: a {} wheel; build a release one (tools/python-wheel --release)",
                        "", p.profile
                    );
                }
            }
            Err(why) => println!("{:<60} not measured: {why}", "Python"),
        }
        println!("\ntarget: Python ≤ 1.05× the library.");
        match &blender {
            Ok(b) => {
                println!(
                    "\nBlender {} hair Curves from {} curves × {} points:",
                    b.version,
                    thousands(b.curves),
                    b.points / b.curves.max(1)
                );
                println!(
                    "{:<60} {:>10.3}",
                    "add-on: bulk foreach_set from arrays (median of 3)", b.seconds
                );
                println!(
                    "{:<60} {:>10.3}   add-on {:.1}× faster",
                    "peer: Blender's USD importer reading pelage's usdc",
                    b.usd_import_seconds,
                    b.usd_import_seconds / b.seconds
                );
                println!("target: ≤ 2 s for 1 M hairs × 16 points.");
            }
            Err(why) => println!("\nBlender Curves: not measured: {why}"),
        }
        Ok(())
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}
