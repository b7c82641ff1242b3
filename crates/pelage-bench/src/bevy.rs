//! `pelage bench bevy`: what pelage's fur costs a Bevy game. Runs the
//! plugin's two examples headless (`bevy_fox`: the running Fox with a
//! ground and a passing ball; `bevy_crowd`: a hundred running foxes with
//! the fur's level of detail), each with and without fur, in the same
//! run, and reads their median frame time (each frame waits for the GPU
//! to finish it, so the GPU's work counts).
//!
//! The examples are their own programs (Bevy is not linked into
//! `pelage`): the bench looks for them beside this binary
//! (`target/<profile>/examples/`), or in `PELAGE_BEVY_EXAMPLES`.
//!
//! A third row runs `bevy_fox --groom` near the Fox: its groom's hairs
//! grown on the GPU every frame and drawn as strands, against the same
//! view without fur.
//!
//! Targets (issue "pelage in Bevy"), on an H100-class GPU at 1920×1080:
//! the Fox with fur ≤ 1.3× the same frame without; the crowd ≥ 60 frames/s.

use crate::Scale;
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Arguments of `pelage bench bevy`.
#[derive(Debug, Args)]
pub struct BevyBenchArgs {
    /// 960×540 and fewer frames: a figure in a few minutes on lavapipe.
    #[arg(long)]
    pub quick: bool,
    /// The smallest run through every row (CI); its figures mean nothing.
    #[arg(long, hide = true)]
    pub smoke: bool,
    /// One JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// One example's run: its median frame time, and the adapter it drew on.
struct Run {
    frame_ms: f64,
    frames: usize,
    adapter: String,
}

/// The folder the examples are in.
fn examples_dir() -> anyhow::Result<PathBuf> {
    if let Some(dir) = std::env::var_os("PELAGE_BEVY_EXAMPLES") {
        return Ok(dir.into());
    }
    let exe = std::env::current_exe()?;
    let dir = exe.parent().map(|d| d.join("examples")).unwrap_or_default();
    Ok(dir)
}

/// Runs `example` headless for `frames` frames at `size`, with or without
/// fur, and reads the frame time it prints.
fn run_example(
    dir: &Path,
    example: &str,
    frames: u32,
    size: (u32, u32),
    fur: bool,
    extra: &[&str],
) -> anyhow::Result<Run> {
    let exe = dir.join(example);
    if !exe.exists() {
        anyhow::bail!(
            "{} not found: build the Bevy examples first (cargo build --release -p pelage-bevy --examples), \
             or set PELAGE_BEVY_EXAMPLES to their folder",
            exe.display()
        );
    }
    let mut cmd = Command::new(&exe);
    cmd.args(["--headless", "--timing", "--frames"])
        .arg(frames.to_string())
        .arg("--size")
        .arg(format!("{}x{}", size.0, size.1));
    if !fur {
        cmd.arg("--no-fur");
    }
    cmd.args(extra);
    let out = cmd.output()?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        anyhow::bail!(
            "{example} failed ({}): {}",
            out.status,
            stderr.lines().rev().take(8).collect::<Vec<_>>().join(" | ")
        );
    }
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix("frame_ms "))
        .ok_or_else(|| anyhow::anyhow!("{example} printed no frame time"))?;
    let mut words = line.split_whitespace();
    let frame_ms: f64 = words.next().unwrap_or("nan").parse()?;
    let frames = words.nth(1).and_then(|w| w.parse().ok()).unwrap_or(0);
    // Bevy logs the adapter it chose: `AdapterInfo { name: "…"`.
    let adapter = stderr
        .split("AdapterInfo { name: \"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .unwrap_or("unknown adapter")
        .to_string();
    Ok(Run {
        frame_ms,
        frames,
        adapter,
    })
}

/// Runs the benchmark.
pub fn run(args: &BevyBenchArgs) -> anyhow::Result<()> {
    let scale = Scale::of(args.quick, args.smoke);
    let dir = examples_dir()?;
    let size = scale.pick((1920, 1080), (960, 540), (320, 180));
    let fox_frames = scale.pick(240, 90, 12);
    let crowd_frames = scale.pick(120, 30, 6);
    let fox = run_example(&dir, "bevy_fox", fox_frames, size, true, &[])?;
    let fox_bare = run_example(&dir, "bevy_fox", fox_frames, size, false, &[])?;
    let crowd = run_example(&dir, "bevy_crowd", crowd_frames, size, true, &[])?;
    let crowd_bare = run_example(&dir, "bevy_crowd", crowd_frames, size, false, &[])?;
    // Near enough for strands: the Fox fills most of the screen's height.
    let near = ["--groom", "--distance", "120"];
    let strands = run_example(&dir, "bevy_fox", crowd_frames, size, true, &near)?;
    let strands_bare = run_example(&dir, "bevy_fox", crowd_frames, size, false, &near)?;
    let software = ["llvmpipe", "lavapipe", "SwiftShader", "softpipe"]
        .iter()
        .any(|s| fox.adapter.contains(s));
    let ratio = fox.frame_ms / fox_bare.frame_ms;
    let crowd_fps = 1e3 / crowd.frame_ms;
    if args.json {
        let report = serde_json::json!({
            "width": size.0,
            "height": size.1,
            "fur_ms": fox.frame_ms,
            "no_fur_ms": fox_bare.frame_ms,
            "ratio": ratio,
            "frames": fox.frames,
            "crowd": 100,
            "crowd_ms": crowd.frame_ms,
            "crowd_no_fur_ms": crowd_bare.frame_ms,
            "crowd_fps": crowd_fps,
            "crowd_ratio": crowd.frame_ms / crowd_bare.frame_ms,
            "strands_ms": strands.frame_ms,
            "strands_no_fur_ms": strands_bare.frame_ms,
            "strands_ratio": strands.frame_ms / strands_bare.frame_ms,
            "adapter": fox.adapter,
            "software": software,
        });
        println!("{report}");
        return Ok(());
    }
    println!(
        "pelage bench bevy{} — Bevy 0.19 headless at {}×{}, each frame waited for; median frame time",
        scale.flag(),
        size.0,
        size.1
    );
    println!(
        "on {}{}",
        fox.adapter,
        if software {
            " (software: the CPU runs the shaders; the targets need a GPU)"
        } else {
            ""
        }
    );
    println!();
    println!(
        "{:>34}  {:>10}  {:>10}  {:>7}",
        "", "fur ms", "no fur ms", "ratio"
    );
    println!(
        "{:>34}  {:>10.2}  {:>10.2}  {:>6.2}×   (goal ≤ 1.3× on a GPU)",
        "bevy_fox (the running Fox)", fox.frame_ms, fox_bare.frame_ms, ratio
    );
    println!(
        "{:>34}  {:>10.2}  {:>10.2}  {:>6.2}×   {:.1} frames/s with fur (goal ≥ 60 on a GPU)",
        "bevy_crowd (100 foxes, LOD)",
        crowd.frame_ms,
        crowd_bare.frame_ms,
        crowd.frame_ms / crowd_bare.frame_ms,
        crowd_fps
    );
    println!(
        "{:>34}  {:>10.2}  {:>10.2}  {:>6.2}×   (no target set)",
        "bevy_fox --groom (strands, near)",
        strands.frame_ms,
        strands_bare.frame_ms,
        strands.frame_ms / strands_bare.frame_ms
    );
    Ok(())
}
