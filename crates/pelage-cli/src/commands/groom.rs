//! `pelage groom`: grows a groom file's hairs and writes them, part by part
//! (`--part K/N` for one run of a farm, `--assemble` to tie the runs'
//! files together in one USD layer).

use crate::format::thousands;
use anyhow::{Context, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use pelage::anim::FrameRange;
use pelage::groom::{
    AnimatedFiles, AnimatedGroom, AnimatedPlanError, Assembly, FarmRun, Groom, PreflightError,
    ReportBuilder, Timings,
};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `pelage groom`.
#[derive(Debug, Args)]
pub struct GroomArgs {
    /// The groom file (TOML; see docs/groom-format.md).
    pub file: PathBuf,
    /// Output (.usdc or .usd: binary USD; .usda: text USD; .abc: Alembic;
    /// .hair, .ply, .rib, .pbrt). Default: the file's `[output] path`, or the groom
    /// file's name with .usdc.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Grow only run K of N (1-based): a contiguous share of the parts,
    /// written to OUTPUT with `.part-K-of-N` before the extension.
    #[arg(long, value_name = "K/N")]
    pub part: Option<FarmRun>,
    /// Instead of growing: write OUTPUT as a USD layer referencing every
    /// part file `OUTPUT.part-K-of-N.EXT` beside it, with extents (the
    /// layer is text: name OUTPUT .usda).
    #[arg(long, conflicts_with = "part")]
    pub assemble: bool,
    /// Worker threads (default: all cores; more than the machine runs at
    /// once are capped). The output is identical for any number.
    #[arg(long, value_parser = super::args::threads)]
    pub threads: Option<usize>,
    /// Override the groom file's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Write this share of the hairs (0 to 1; replaces `[output]
    /// fraction`): the hairs a full groom would have, chosen by stable id,
    /// so 0.1 is a subset of 0.2; widths times 1/√F so the fur covers the
    /// skin as the whole groom does. For layout, crowds and viewports.
    #[arg(long, value_name = "F")]
    pub fraction: Option<f64>,
    /// Frames of an animated skin, e.g. 1-24 (replaces `[animation]
    /// frames`; makes the groom animated when the file has no
    /// `[animation]`). Output: one .usdc or .abc with time samples.
    #[arg(long, value_name = "RANGE", allow_hyphen_values = true)]
    pub frames: Option<FrameRange>,
    /// Animated grooms: write one .usdc a frame beside OUTPUT
    /// (`NAME.f0001.usdc`, …) and OUTPUT itself (.usda) as the layer that
    /// stitches them with USD value clips.
    #[arg(long, conflicts_with_all = ["part", "assemble"])]
    pub frame_files: bool,
    /// Grow the hairs on the GPU, with the evaluator real-time strands
    /// use (docs/realtime.md): the same file, every point within 1e-4 of
    /// the groom's size of the CPU's. Animated grooms grow their hairs at
    /// rest there (each frame's, in regrow and simulate modes) and carry
    /// them to each pose as without it. Without a GPU adapter it says so
    /// and exits 2.
    #[arg(long)]
    pub gpu: bool,
    /// Also draw the hairs on the skin into this PNG (headless GPU; at
    /// most 300,000 hairs, evenly chosen).
    #[arg(long, value_name = "PNG")]
    pub preview: Option<PathBuf>,
    /// Also write a JSON report: per-part hair counts, the guides left
    /// out and why, the regions with their guides and hairs, timings.
    #[arg(long, value_name = "JSON")]
    pub report: Option<PathBuf>,
    /// Do not print the progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(args: &GroomArgs) -> anyhow::Result<()> {
    if let Some(wanted) = args.threads {
        let (threads, capped) = super::args::worker_threads(wanted);
        if capped {
            eprintln!(
                "note: --threads {wanted}: this machine runs {threads} at once; using {threads}"
            );
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .context("cannot set up the worker threads")?;
    }
    let start = Instant::now();
    let mut groom = Groom::load_with_frames(&args.file, args.frames.clone())?;
    if let Some(fraction) = args.fraction {
        groom.set_fraction(fraction)?;
    }
    let output = args.output.clone().unwrap_or_else(|| groom.output_path());
    if args.assemble {
        return assemble(&groom, &output);
    }
    if let Some(report) = groom.bind_report() {
        for dropped in &report.dropped {
            eprintln!("warning: guides: {dropped}");
        }
    }
    if let Some(animated) = groom.animated(args.seed)? {
        if args.report.is_some() {
            bail!(
                "--report describes still grooms; grow this one without --frames (or without [animation]) to get its report"
            );
        }
        return run_animated(args, &groom, &animated, &output, start);
    }
    // What to grow and where, known from the file: refuse an output
    // pelage cannot write, or a disk too small for it, before preparing
    // anything (preparing a billion hairs' roots takes seconds).
    let parts = groom.part_count();
    let (range, path) = groom.preflight(&output, args.part).map_err(|e| match e {
        PreflightError::Farm(_) => {
            anyhow::Error::new(e).context(format!("--part: {}", args.file.display()))
        }
        e => anyhow::Error::new(e),
    })?;
    let generator = groom.generator(args.seed)?;
    let prepared = start.elapsed();
    let lost = generator.lost_guides();
    for guide in &lost {
        eprintln!("warning: style mesh: {guide}");
    }
    debug_assert_eq!(
        generator.parts().len(),
        parts,
        "the file and the generator agree on parts"
    );
    let export = groom.export_for(&generator, args.part);
    let planned: u64 = generator.parts()[range.clone()]
        .iter()
        .map(|p| p.hair_count)
        .sum();
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::new(range.len() as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} part {pos}/{len}, {msg} {eta} left")
                .expect("the template is valid"),
        );
        bar
    };
    println!(
        "{}; operators: {}",
        heading(args, &groom, planned, range.len()),
        match generator.operators().len() {
            0 => "none".to_string(),
            _ => generator
                .operators()
                .iter()
                .map(|o| o.name())
                .collect::<Vec<_>>()
                .join(" → "),
        }
    );
    let growing = Instant::now();
    let mut done = 0u64;
    // Hairs kept for the preview: every `stride`-th of each part.
    let stride = planned.div_ceil(PREVIEW_HAIRS).max(1) as usize;
    let mut shown = Vec::new();
    let mut report = args.report.as_ref().map(|_| ReportBuilder::new(&generator));
    // On the GPU: each part grown there and finished as the CPU
    // finishes it.
    let gpu = gpu_context(args)?;
    let grower = gpu
        .as_ref()
        .map(|ctx| pelage_gpu::GpuPartGrower::new(ctx, &generator));
    let grow = |p: usize| match &grower {
        Some(g) => g.part(p),
        None => generator.part(p),
    };
    let never = std::sync::atomic::AtomicBool::new(false);
    let summary = generator.write_grown_until(
        &path,
        range.clone(),
        &export,
        &never,
        &grow,
        |p, curves| {
            if args.preview.is_some() {
                shown.push(curves.every_nth(stride));
            }
            if let Some(report) = &mut report {
                report.add_part(&generator, p, curves);
            }
            done += curves.curve_count() as u64;
            bar.set_message(format!("{} hairs", thousands(done)));
            bar.inc(1);
        },
    )?;
    bar.finish_and_clear();
    let seconds = growing.elapsed().as_secs_f64();
    println!(
        "{} hairs, {} points in {} → {} in {:.2} s ({:.2} M hairs/s; setup {:.2} s)",
        thousands(summary.hairs),
        thousands(summary.points),
        parts_text(range.len()),
        path.display(),
        seconds,
        summary.hairs as f64 / seconds / 1e6,
        prepared.as_secs_f64()
    );
    if let (Some(report), Some(json)) = (report, &args.report) {
        let timings = Timings {
            setup: prepared.as_secs_f64(),
            grow_and_write: seconds,
        };
        let report = report.finish(&generator, Some(&groom), Some(&path), timings);
        for region in report.regions_without_guides() {
            eprintln!(
                "warning: regions: region {} has no guides: its {} hairs took their shape from all guides; add guides there",
                region.name,
                thousands(region.hairs)
            );
        }
        pelage::io::write_atomically(json, |w| {
            serde_json::to_writer_pretty(&mut *w, &report)?;
            std::io::Write::write_all(w, b"\n")
        })?;
        println!("report → {}", json.display());
    }
    if let Some(png) = &args.preview {
        let curves = pelage::curves::join(shown.iter())?;
        let scene = pelage_gpu::PreviewScene {
            mesh: Some(groom.mesh()),
            points: &[],
            curves: Some(&curves),
            skin_texture: None,
        };
        let style = pelage_gpu::PreviewStyle {
            background: super::FUR_BACKGROUND,
            ..pelage_gpu::PreviewStyle::default()
        };
        match super::render_png(&scene, &style, None, (1280, 720), png) {
            Ok(adapter) => println!(
                "preview of {} hairs → {} (rendered on {adapter})",
                thousands(curves.curve_count() as u64),
                png.display()
            ),
            Err(e) => eprintln!("warning: no preview: {e:#}"),
        }
    }
    Ok(())
}

/// With `--gpu`, an adapter to grow on (none: exit 2 with why), named on
/// stdout.
fn gpu_context(args: &GroomArgs) -> anyhow::Result<Option<pelage_gpu::GpuContext>> {
    if !args.gpu {
        return Ok(None);
    }
    let ctx = pelage_gpu::GpuContext::headless()
        .context("--gpu: no GPU to grow on; grow without --gpu")?;
    println!("growing on {}", ctx.adapter_name());
    Ok(Some(ctx))
}

/// `pelage groom` for an animated groom: every part over every frame,
/// into one file with time samples.
fn run_animated(
    args: &GroomArgs,
    groom: &Groom,
    animated: &AnimatedGroom,
    output: &Path,
    start: Instant,
) -> anyhow::Result<()> {
    if args.preview.is_some() {
        bail!(
            "--preview draws still grooms; for an animated one, render its frames: pelage render FILE --frames {}",
            animated.animation().frames
        );
    }
    let generator = animated.generator();
    let animation = animated.animation();
    let plan = groom
        .animated_plan(animated, output, args.part, args.frame_files)
        .map_err(|e| match e {
            AnimatedPlanError::Farm(_) => {
                anyhow::Error::new(e).context(format!("--part: {}", args.file.display()))
            }
            e => anyhow::Error::new(e).context("--frame-files"),
        })?;
    let range = plan.parts.clone();
    let outputs = &plan.outputs;
    let path = outputs[0].path.clone();
    let times = plan.times();
    let planned: u64 = generator.parts()[range.clone()]
        .iter()
        .map(|p| p.hair_count)
        .sum();
    let clip = match animated.skin().clip() {
        Some((name, seconds)) => format!(", clip {name:?} ({seconds:.2} s)"),
        None => String::new(),
    };
    println!(
        "{}; frames {} ({} samples, rest frame {}, {}{clip})",
        heading(args, groom, planned, range.len()),
        animation.frames,
        times.len(),
        animation.rest_frame,
        animation.mode.name(),
    );
    if !animated.skin().is_animated() {
        eprintln!(
            "warning: {} does not move; every frame will be the rest frame",
            groom.mesh().name()
        );
    }
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::new((range.len() * times.len()) as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} part-frames, {msg} {eta} left")
                .expect("the template is valid"),
        );
        bar
    };
    let options = groom.run_usd_options(args.part);
    // On the GPU: the hairs grown at rest there (each frame's in regrow
    // and simulate modes), carried to the poses as on the CPU.
    let gpu = gpu_context(args)?;
    let grower = gpu
        .as_ref()
        .map(|ctx| pelage_gpu::GpuPartGrower::new(ctx, generator));
    let grow = |g: &pelage::groom::Generator, p: usize| match &grower {
        Some(gpu) => gpu.part_of(g, p),
        None => g.part(p),
    };
    plan.remove_stale_stitching()?;
    let growing = Instant::now();
    // In a farm, the first run writes the skin.
    let files = AnimatedFiles {
        outputs,
        parts: range.clone(),
        options: &options,
        with_skin: groom.writes_skin_in(args.part),
    };
    let never = std::sync::atomic::AtomicBool::new(false);
    let summary = animated.write_files_grown_until(files, &grow, &never, |p| {
        bar.set_message(format!("part {} frame {}", p.part, p.time));
        bar.set_position(p.done as u64);
    })?;
    bar.finish_and_clear();
    let seconds = growing.elapsed().as_secs_f64();
    let written = match outputs.len() {
        1 => path.display().to_string(),
        n => format!("{n} frame files ({} …)", path.display()),
    };
    println!(
        "{} hairs, {} points × {} samples in {} → {written} in {:.2} s ({:.3} s a frame; setup {:.2} s)",
        thousands(summary.hairs),
        thousands(summary.points),
        times.len(),
        parts_text(range.len()),
        seconds,
        seconds / times.len() as f64,
        start.elapsed().as_secs_f64() - seconds
    );
    if let Some(stitched) = plan.stitch()? {
        println!(
            "{} → {} frame files stitched with value clips ({} prims, time codes {} to {})",
            output.display(),
            stitched.files,
            stitched.prims,
            stitched.time_range.0,
            stitched.time_range.1
        );
    }
    Ok(())
}

/// "FILE: N hairs on MESH (T triangles) from G guides, P parts": what a
/// run is about to grow.
fn heading(args: &GroomArgs, groom: &Groom, planned: u64, parts: usize) -> String {
    format!(
        "{}: {} hairs on {} ({} triangles) from {} guides, {}",
        args.file.display(),
        thousands(planned),
        groom.mesh().name(),
        thousands(groom.mesh().triangle_count() as u64),
        thousands(groom.guides().len() as u64),
        parts_text(parts),
    )
}

/// "1 part", "3 parts".
fn parts_text(n: usize) -> String {
    if n == 1 {
        "1 part".into()
    } else {
        format!("{} parts", thousands(n as u64))
    }
}

/// Hairs the preview draws at most.
const PREVIEW_HAIRS: u64 = 300_000;

/// `--assemble`: ties the farm's files beside `output` together (part
/// files referenced from one layer, or frame files stitched with value
/// clips) and says what it tied.
fn assemble(groom: &Groom, output: &Path) -> anyhow::Result<()> {
    match groom.assemble(output)? {
        Assembly::Parts {
            files,
            extent: (lo, hi),
        } => println!(
            "{} → {} part files {}, extent ({:.4}, {:.4}, {:.4}) to ({:.4}, {:.4}, {:.4})",
            output.display(),
            files.len(),
            match pelage::io::CurvesFormat::from_path(output)
                .is_some_and(pelage::io::CurvesFormat::assembly_joins_parts)
            {
                true => "joined",
                false => "referenced",
            },
            lo.x,
            lo.y,
            lo.z,
            hi.x,
            hi.y,
            hi.z
        ),
        Assembly::Frames(stitched) => println!(
            "{} → {} files of {} runs stitched with value clips ({} prims, time codes {} to {})",
            output.display(),
            stitched.files,
            stitched.runs,
            stitched.prims,
            stitched.time_range.0,
            stitched.time_range.1
        ),
    }
    Ok(())
}
