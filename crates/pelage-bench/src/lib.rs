//! pelage's benchmark harness: what `pelage bench <what>` runs. Each
//! benchmark prints our figures beside the paper's (and, where there is
//! one, a peer's measured in the same run) as a table, or as one JSON
//! object with `--json`. One module a benchmark; the peers' Python scripts
//! (Blender's, the Python package's) sit beside the module that runs them.
//! The `pelage` command is a thin front end over [`run`].
//!
//! Machines here are small and noisy: every figure is the median of several
//! runs, and comparisons are ratios taken within one run.

pub mod animation;
pub mod bevy;
pub mod blender;
pub mod dynamics;
pub mod format;
pub mod groom;
mod groom_edit;
pub mod interp;
pub mod io;
pub mod python;
pub mod realtime;
pub mod render;
pub mod sampler;
pub mod shells;
mod shells_game;
mod strands;

use clap::{Args, Subcommand};
use std::time::Instant;

/// Arguments of `pelage bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    /// The benchmark to run.
    pub what: BenchWhat,
}

/// What to measure.
#[derive(Debug, Subcommand)]
pub enum BenchWhat {
    /// Root sampling (Sik §3, Tables 1–3, Figs. 8–9).
    Sampler(sampler::SamplerBenchArgs),
    /// Preview renderer frame time: skin alone, with 100 k and 1 M curves.
    Render(render::RenderBenchArgs),
    /// Guide interpolation: style-mesh build and weights, Shepard k = 4, 8.
    Interp(interp::InterpBenchArgs),
    /// The groom generator: the Stubble figure (1.6 M hairs) and peak memory.
    Groom(groom::GroomBenchArgs),
    /// Mass-spring fur: ms per step for every topology × solver.
    Dynamics(dynamics::DynamicsBenchArgs),
    /// Shell fur frame time, plain vs curl vs curl + clump (Silva Table 1).
    Shells(shells::ShellsBenchArgs),
    /// Writing a large groom as usdc, usda and Alembic: throughput, size, peak memory.
    Io(io::IoBenchArgs),
    /// Animated grooms: a frame of deform and of regrow against growing once.
    Animation(animation::AnimationBenchArgs),
    /// The Python package against the library, and the Blender add-on
    /// making hair Curves (`--blender`).
    Python(python::PythonBenchArgs),
    /// Grooming in Blender: a guide edit with the add-on's Live mode
    /// against Blender's Interpolate Curves.
    Blender(blender::BlenderBenchArgs),
    /// The groom in the game: the running Fox's guides simulated, its
    /// hairs grown and drawn on the GPU every frame, beside the CPU groom.
    Realtime(realtime::RealtimeBenchArgs),
    /// pelage's fur in a Bevy game: the plugin's Fox and crowd examples
    /// with and without fur, headless, in the same run.
    Bevy(bevy::BevyBenchArgs),
}

/// The demo groom file (`pelage demo`), which the I/O benchmark grows.
pub const DEMO_GROOM: &str = include_str!("../../pelage-cli/src/demo.toml");

/// The repository's test meshes (blub), where the benchmarks that go past
/// the embedded Spot find them: `tests/data/meshes/` of the source tree
/// this binary was built from.
pub fn test_meshes() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/meshes")
}

/// The repository's tools/ (tools/bpy-python), beside the source tree this
/// binary was built from.
pub fn tools_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools")
}

/// How big a run is: the full figures, `--quick` (a reduced run whose
/// figures still mean something), or `--smoke` (the smallest run that
/// goes through every row and prints every key; CI runs it in a debug
/// build to prove each benchmark still works, and its figures mean
/// nothing).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// The documented figures.
    Full,
    /// `--quick`.
    Quick,
    /// `--smoke`.
    Smoke,
}

impl Scale {
    /// The scale the two flags ask for (`--smoke` wins).
    pub fn of(quick: bool, smoke: bool) -> Self {
        match (quick, smoke) {
            (_, true) => Scale::Smoke,
            (true, false) => Scale::Quick,
            (false, false) => Scale::Full,
        }
    }

    /// One of three values, by scale.
    pub fn pick<T>(self, full: T, quick: T, smoke: T) -> T {
        match self {
            Scale::Full => full,
            Scale::Quick => quick,
            Scale::Smoke => smoke,
        }
    }

    /// Whether the run is reduced (`--quick` or `--smoke`).
    pub fn reduced(self) -> bool {
        self != Scale::Full
    }

    /// The flag that asks for it, as the report's heading prints it.
    pub fn flag(self) -> &'static str {
        self.pick("", " --quick", " --smoke")
    }
}

/// Runs the benchmark `args` names.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    match &args.what {
        BenchWhat::Sampler(a) => sampler::run(a),
        BenchWhat::Render(a) => render::run(a),
        BenchWhat::Io(a) => io::run(a),
        BenchWhat::Interp(a) => interp::run(a),
        // `--edit` and `--strands` are benchmarks of their own, under the
        // arguments of the one they extend.
        BenchWhat::Groom(a) if a.edit && a.rss_child.is_none() => groom_edit::run(a),
        BenchWhat::Groom(a) => groom::run(a),
        BenchWhat::Shells(a) => shells::run(a),
        BenchWhat::Dynamics(a) if a.strands => strands::run(a),
        BenchWhat::Dynamics(a) => dynamics::run(a),
        BenchWhat::Animation(a) => animation::run(a),
        BenchWhat::Python(a) => python::run(a),
        BenchWhat::Blender(a) => blender::run(a),
        BenchWhat::Realtime(a) => realtime::run(a),
        BenchWhat::Bevy(a) => bevy::run(a),
    }
}

/// Runs one of Blender's cases, `script` (its text; `name` is its file
/// name), with Blender as a Python module (tools/bpy-python, which sets bpy
/// up in a cached venv) on a temporary case folder that `write_case` fills.
/// Returns the JSON object the script prints last; an error says why the
/// case was not measured. The folder is removed either way.
pub fn run_bpy_case(
    name: &str,
    script: &str,
    write_case: impl FnOnce(&std::path::Path) -> anyhow::Result<()>,
) -> anyhow::Result<serde_json::Value> {
    let python = tools_dir().join("bpy-python");
    anyhow::ensure!(python.exists(), "{} not found", python.display());
    let stem = name.trim_end_matches(".py");
    let dir = std::env::temp_dir().join(format!("pelage-{stem}-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let result = (|| {
        write_case(&dir)?;
        let path = dir.join(name);
        std::fs::write(&path, script)?;
        let out = std::process::Command::new(&python)
            .arg(&path)
            .arg(&dir)
            .output()?;
        let stderr = String::from_utf8_lossy(&out.stderr);
        match out.status.code() {
            Some(0) => {}
            Some(2) => anyhow::bail!("bpy could not be set up: {}", stderr.trim()),
            _ => anyhow::bail!("Blender's case failed: {}", stderr.trim()),
        }
        last_json_line(&String::from_utf8_lossy(&out.stdout), name)
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// Writes numbers as their little-endian bytes, one after another: the
/// arrays a Python case reads with `numpy.fromfile`.
pub fn write_le<const N: usize>(
    path: &std::path::Path,
    values: impl IntoIterator<Item = [u8; N]>,
) -> std::io::Result<()> {
    std::fs::write(path, values.into_iter().flatten().collect::<Vec<u8>>())
}

/// Writes `mesh` into a case folder: `positions.f32` (xyz a vertex) and
/// `triangles.u32` (three indices a triangle).
pub fn write_mesh_case(dir: &std::path::Path, mesh: &pelage::Mesh) -> std::io::Result<()> {
    let positions = mesh.positions().iter().flat_map(|p| p.to_array());
    write_le(&dir.join("positions.f32"), positions.map(f32::to_le_bytes))?;
    let triangles = mesh.triangles().iter().flatten();
    write_le(
        &dir.join("triangles.u32"),
        triangles.map(|i| i.to_le_bytes()),
    )
}

/// The repository's Blender add-on (blender/pelage_fur), whose `fur.py`
/// the Blender cases import, beside the source tree this binary was built
/// from.
pub fn addon_dir() -> anyhow::Result<std::path::PathBuf> {
    use anyhow::Context;
    let addon = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../blender/pelage_fur");
    addon
        .canonicalize()
        .with_context(|| format!("the add-on is not at {}", addon.display()))
}

/// The JSON object a case script printed last on `stdout`; `script`
/// names it in the error.
pub fn last_json_line(stdout: &str, script: &str) -> anyhow::Result<serde_json::Value> {
    use anyhow::Context;
    let line = stdout
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .unwrap_or("");
    serde_json::from_str(line)
        .with_context(|| format!("unexpected output from {script}: {stdout:?}"))
}

/// The median of `values` (the upper one of an even count; NaN for none).
pub fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.get(sorted.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Median wall time in seconds of `runs` calls of `f` (after one warm-up
/// call when `warm_up`), and the last result.
pub fn median_seconds<T>(runs: usize, warm_up: bool, mut f: impl FnMut() -> T) -> (f64, T) {
    if warm_up {
        drop(f());
    }
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        let value = f();
        times.push(start.elapsed().as_secs_f64());
        last = Some(value);
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], last.expect("at least one run"))
}

/// Medians of `frames` runs of each of `runs`, interleaved (one warm-up
/// each first), in ms.
pub fn interleaved(
    frames: usize,
    runs: &mut [&mut dyn FnMut() -> anyhow::Result<()>],
) -> anyhow::Result<Vec<f64>> {
    for run in runs.iter_mut() {
        run()?;
    }
    let mut times = vec![Vec::new(); runs.len()];
    for _ in 0..frames.max(1) {
        for (k, run) in runs.iter_mut().enumerate() {
            let start = Instant::now();
            run()?;
            times[k].push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    Ok(times
        .into_iter()
        .map(|mut t| {
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        })
        .collect())
}

/// Runs `f` on a rayon pool of `threads` threads.
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> anyhow::Result<T> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    Ok(pool.install(f))
}
