//! `pelage groom`: grows a groom file's hairs and writes them, part by part
//! (`--part K/N` for one run of a farm, `--assemble` to tie the runs'
//! files together in one USD layer).

use crate::format::thousands;
use anyhow::{Context, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use pelage::anim::FrameRange;
use pelage::groom::{
    AnimatedGroom, FrameFile, FrameOutput, Groom, find_frame_files, frames_file, part_file,
    part_slice, write_assembly, write_clip_assembly,
};
use pelage::io::{CurvesExport, CurvesFormat, UsdOptions};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `pelage groom`.
#[derive(Debug, Args)]
pub struct GroomArgs {
    /// The groom file (TOML; see docs/groom-format.md).
    pub file: PathBuf,
    /// Output (.usdc or .usd: binary USD; .usda: text USD; .hair, .ply,
    /// .rib, .pbrt). Default: the file's `[output] path`, or the groom
    /// file's name with .usdc.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Grow only run K of N (1-based): a contiguous share of the parts,
    /// written to OUTPUT with `.part-K-of-N` before the extension.
    #[arg(long, value_name = "K/N", value_parser = parse_part)]
    pub part: Option<(usize, usize)>,
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
    /// Frames of an animated skin, e.g. 1-24 (replaces `[animation]
    /// frames`; makes the groom animated when the file has no
    /// `[animation]`). Output: one .usdc or .abc with time samples.
    #[arg(long, value_name = "RANGE", value_parser = parse_frames)]
    pub frames: Option<FrameRange>,
    /// Animated grooms: write one .usdc a frame beside OUTPUT
    /// (`NAME.f0001.usdc`, …) and OUTPUT itself (.usda) as the layer that
    /// stitches them with USD value clips.
    #[arg(long, conflicts_with_all = ["part", "assemble"])]
    pub frame_files: bool,
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

fn parse_frames(s: &str) -> Result<FrameRange, String> {
    FrameRange::parse(s).map_err(|e| e.to_string())
}

fn parse_part(s: &str) -> Result<(usize, usize), String> {
    let (k, n) = s
        .split_once('/')
        .ok_or_else(|| format!("{s:?}: write the part as K/N, e.g. 3/8"))?;
    let (k, n): (usize, usize) = (
        k.trim()
            .parse()
            .map_err(|_| format!("{k:?} is not a whole number"))?,
        n.trim()
            .parse()
            .map_err(|_| format!("{n:?} is not a whole number"))?,
    );
    if n == 0 || k == 0 || k > n {
        return Err(format!("{s}: K must be 1 to N (runs are numbered from 1)"));
    }
    Ok((k, n))
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
    let groom = Groom::load_with_frames(&args.file, args.frames.clone())?;
    let output = args.output.clone().unwrap_or_else(|| groom.output_path());
    if args.assemble {
        if let Some(animation) = groom.animation() {
            return assemble_frames(&output, &animation.frames);
        }
        return assemble(&output, &UsdOptions::default());
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
    let (range, path) = match args.part {
        Some((k, n)) => (run_parts(args, k, n, parts)?, part_file(&output, k, n)),
        None => (0..parts, output.clone()),
    };
    if CurvesFormat::from_path(&path).is_none() {
        bail!(
            "{}: unknown curves format; pelage writes .usdc (or .usd), .usda, .hair, .ply, .rib and .pbrt",
            path.display()
        );
    }
    pelage::io::check_output(&path)?;
    let count = *groom.file().roots.count.get_ref();
    let share = count as u128 * range.len() as u128 / parts.max(1) as u128;
    // Positions alone (12 bytes a point) are a floor of any format's size.
    let points = *groom.file().finish.points.get_ref() as u64;
    pelage::io::check_free_space(
        &path,
        (share as u64).saturating_mul(points).saturating_mul(12),
    )?;
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
    let file = groom.file();
    let basis = file.output.basis;
    let export = CurvesExport {
        usd: UsdOptions {
            basis,
            ..UsdOptions::default()
        },
        mesh: file.output.with_mesh.then(|| groom.mesh()),
    };
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
    let mut report = args.report.as_ref().map(|_| GroomReport::new(&generator));
    let summary = generator.write(&path, range.clone(), &export, |p, curves| {
        if args.preview.is_some() {
            shown.push(curves.every_nth(stride));
        }
        if let Some(report) = &mut report {
            report.add_part(&generator, p, curves);
        }
        done += curves.curve_count() as u64;
        bar.set_message(format!("{} hairs", thousands(done)));
        bar.inc(1);
    })?;
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
    if let Some(report) = &report {
        for warning in report.borrowed_regions() {
            eprintln!("warning: regions: {warning}");
        }
    }
    if let (Some(report), Some(json)) = (report, &args.report) {
        let value = report.finish(&groom, &path, prepared.as_secs_f64(), seconds, &lost);
        pelage::io::write_atomically(json, |w| {
            serde_json::to_writer_pretty(&mut *w, &value)?;
            std::io::Write::write_all(w, b"\n")
        })?;
        println!("report → {}", json.display());
    }
    if let Some(png) = &args.preview {
        let curves = pelage::io::join(shown.iter())?;
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
    let parts = generator.parts().len();
    let animation = animated.animation();
    let frames = animation.frames.frames();
    // Split outputs are binary USD beside a text stitching layer.
    let data = match output.extension().and_then(|e| e.to_str()) {
        Some("usda") if args.part.is_some() || args.frame_files => output.with_extension("usdc"),
        _ => output.to_path_buf(),
    };
    let (range, outputs) = match args.part {
        Some((k, n)) => {
            let range = run_parts(args, k, n, parts)?;
            let path = frames_file(
                &data,
                Some((k, n)),
                animation.frames.first(),
                animation.frames.last(),
            );
            let output = FrameOutput {
                path,
                times: animation.times_of(frames),
            };
            (range, vec![output])
        }
        None if args.frame_files => {
            if output.extension().and_then(|e| e.to_str()) != Some("usda") {
                bail!(
                    "{}: with --frame-files the output is the stitching layer: name it .usda",
                    output.display()
                );
            }
            let outputs = frames
                .iter()
                .map(|&f| FrameOutput {
                    path: frames_file(&data, None, f, f),
                    times: animation.times_of(&[f]),
                })
                .collect();
            (0..parts, outputs)
        }
        None => {
            let output = FrameOutput {
                path: output.to_path_buf(),
                times: animation.times_of(frames),
            };
            (0..parts, vec![output])
        }
    };
    let path = outputs[0].path.clone();
    let times: Vec<f64> = outputs
        .iter()
        .flat_map(|o| o.times.iter().copied())
        .collect();
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
    let options = UsdOptions {
        basis: groom.file().output.basis,
        time_codes_per_second: groom.fps().unwrap_or(24.0),
        ..UsdOptions::default()
    };
    let growing = Instant::now();
    // In a farm, the first run writes the skin.
    let with_skin = groom.file().output.with_mesh && args.part.is_none_or(|(k, _)| k == 1);
    let summary = animated.write_files(&outputs, range.clone(), &options, with_skin, |p| {
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
    if args.frame_files {
        let files: Vec<FrameFile> = outputs
            .iter()
            .zip(frames)
            .map(|(o, &f)| FrameFile {
                path: o.path.clone(),
                run: (1, 1),
                first: f,
                last: f,
            })
            .collect();
        let stitched = write_clip_assembly(output, &files, &animation.frames)?;
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

/// `--assemble` for an animated groom: the farm's frame files beside
/// OUTPUT stitched with value clips.
fn assemble_frames(output: &Path, frames: &FrameRange) -> anyhow::Result<()> {
    let found = find_frame_files(output)
        .with_context(|| format!("cannot list the folder of {}", output.display()))?;
    if found.is_empty() {
        bail!(
            "no frame files beside {} (NAME.part-K-of-N.fA-B.usdc); run `pelage groom FILE --part K/N` first",
            output.display()
        );
    }
    let stitched = write_clip_assembly(output, &found, frames)?;
    println!(
        "{} → {} files of {} runs stitched with value clips ({} prims, time codes {} to {})",
        output.display(),
        stitched.files,
        stitched.runs,
        stitched.prims,
        stitched.time_range.0,
        stitched.time_range.1
    );
    Ok(())
}

/// The parts run `k` of `n` grows, or an error when there are fewer parts
/// than runs.
fn run_parts(args: &GroomArgs, k: usize, n: usize, parts: usize) -> anyhow::Result<Range<usize>> {
    if n > parts {
        bail!(
            "--part {k}/{n}: the groom has {parts} parts, so at most {parts} runs; set [roots] parts in {} for more",
            args.file.display()
        );
    }
    Ok(part_slice(k, n, parts))
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

/// Finds `OUTPUT.part-K-of-N.usda` for one N and every K, and writes the
/// root layer.
fn assemble(output: &Path, options: &UsdOptions) -> anyhow::Result<()> {
    let folder = match output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let stem = output
        .file_stem()
        .and_then(|s| s.to_str())
        .context("the output needs a file name")?;
    let mut runs: Option<usize> = None;
    for entry in
        std::fs::read_dir(&folder).with_context(|| format!("cannot list {}", folder.display()))?
    {
        let name = entry?.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some(rest) = name.strip_prefix(&format!("{stem}.part-")) else {
            continue;
        };
        let Some((_, n)) = rest.split_once("-of-") else {
            continue;
        };
        let Some(n) = n.split('.').next().and_then(|n| n.parse::<usize>().ok()) else {
            continue;
        };
        match runs {
            Some(m) if m != n => bail!(
                "{}: part files of two different farm runs (of {m} and of {n}); remove one set",
                folder.display()
            ),
            _ => runs = Some(n),
        }
    }
    let n = runs.with_context(|| {
        format!(
            "no part files {stem}.part-K-of-N.* in {}; run `pelage groom FILE --part K/N` first",
            folder.display()
        )
    })?;
    // A run's file is text or binary USD, whatever the root layer's name.
    let files: Vec<PathBuf> = (1..=n)
        .map(|k| {
            let named = part_file(output, k, n);
            ["usda", "usdc", "usd"]
                .iter()
                .map(|ext| named.with_extension(ext))
                .find(|f| f.exists())
                .unwrap_or(named)
        })
        .collect();
    if let Some(missing) = files.iter().find(|f| !f.exists()) {
        bail!(
            "{} is missing: run {} of {n} has not finished",
            missing.display(),
            { files.iter().position(|f| f == missing).unwrap_or(0) + 1 }
        );
    }
    let (lo, hi) = write_assembly(output, &files, options)?;
    println!(
        "{} → {} part files referenced, extent ({:.4}, {:.4}, {:.4}) to ({:.4}, {:.4}, {:.4})",
        output.display(),
        n,
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z
    );
    Ok(())
}

/// What `--report` gathers while a groom grows.
struct GroomReport {
    /// Per part: index, hairs planned, hairs and points grown, triangles.
    parts: Vec<serde_json::Value>,
    /// Per region id: guides, hairs grown.
    regions: std::collections::BTreeMap<u32, (usize, u64)>,
    /// Each region's name (face sets) or number.
    names: std::collections::BTreeMap<u32, String>,
    split: bool,
}

impl GroomReport {
    fn new(generator: &pelage::groom::Generator) -> Self {
        let mut regions = std::collections::BTreeMap::new();
        let split = generator.regions().is_some();
        if split {
            for root in generator.guides().roots() {
                regions
                    .entry(generator.region_of(*root))
                    .or_insert((0, 0))
                    .0 += 1;
            }
        }
        Self {
            parts: Vec::new(),
            regions,
            names: Default::default(),
            split,
        }
    }

    fn add_part(
        &mut self,
        generator: &pelage::groom::Generator,
        p: usize,
        curves: &pelage::Curves,
    ) {
        let part = &generator.parts()[p];
        self.parts.push(serde_json::json!({
            "part": p,
            "hairs_planned": part.hair_count,
            "hairs": curves.curve_count(),
            "points": curves.points().len(),
            "triangles": part.triangles.len(),
        }));
        if self.split
            && let Some(roots) = curves.roots()
        {
            for root in roots {
                self.regions
                    .entry(generator.region_of(*root))
                    .or_insert((0, 0))
                    .1 += 1;
            }
            if let Some(lookup) = generator.regions() {
                for id in self.regions.keys() {
                    self.names.entry(*id).or_insert_with(|| lookup.name(*id));
                }
            }
        }
    }

    /// Regions whose hairs had no guide of their own (they borrowed from
    /// every guide).
    fn borrowed_regions(&self) -> Vec<String> {
        self.regions
            .iter()
            .filter(|(_, (guides, hairs))| *guides == 0 && *hairs > 0)
            .map(|(id, (_, hairs))| {
                let id = self.names.get(id).cloned().unwrap_or_else(|| id.to_string());
                format!("region {id} has no guides: its {} hairs took their shape from all guides; add guides there", thousands(*hairs))
            })
            .collect()
    }

    fn finish(
        self,
        groom: &Groom,
        output: &Path,
        setup_s: f64,
        grow_s: f64,
        lost: &[pelage::interp::LostGuide],
    ) -> serde_json::Value {
        let dropped: Vec<serde_json::Value> = groom
            .bind_report()
            .map(|r| {
                r.dropped
                    .iter()
                    .map(|d| serde_json::json!({ "guide": d.index, "why": d.to_string() }))
                    .collect()
            })
            .unwrap_or_default();
        let lost: Vec<serde_json::Value> = lost
            .iter()
            .map(|l| serde_json::json!({ "guide": l.guide, "kept_by": l.kept_by, "vertex": l.vertex, "why": l.to_string() }))
            .collect();
        let regions: Vec<serde_json::Value> = self
            .regions
            .iter()
            .map(|(id, (guides, hairs))| {
                let name = self
                    .names
                    .get(id)
                    .cloned()
                    .unwrap_or_else(|| id.to_string());
                serde_json::json!({ "region": id, "name": name, "guides": guides, "hairs": hairs })
            })
            .collect();
        let hairs: u64 = self.parts.iter().filter_map(|p| p["hairs"].as_u64()).sum();
        serde_json::json!({
            "groom": groom.path().display().to_string(),
            "output": output.display().to_string(),
            "hairs": hairs,
            "parts": self.parts,
            "guides": {
                "kept": groom.guides().len(),
                "dropped": dropped,
                "unused_by_style_mesh": lost,
            },
            "regions": regions,
            "seconds": { "setup": setup_s, "grow_and_write": grow_s },
        })
    }
}
