//! `pelage bench animation`: the Stubble figure (spot ×2, 1.6 M hairs of
//! 16 points, clump + noise) on a skin the bench twists over 24 frames.
//! Figures: growing the groom once; a frame of `deform` (the skin's pose
//! and every hair carried to it); a frame of `regrow` (guides brought back
//! to rest, every part regrown and carried) — the part-by-part loop that
//! `pelage groom` runs, without the file. The paper's baseline is Stubble's
//! per-frame generation (Sik §4.1–4.2: every frame generated anew, 1.6 M
//! hairs in 3.2 s on two cores). Peers measured in the same run: that
//! approach done by pelage (a generator prepared from scratch on the posed
//! skin, the groom grown, every frame), and with `--peer blender`
//! Blender's Deform Curves on Surface moving the same grown curves
//! (`blender_deform.py`).

use super::groom::{groom_text, peak_rss_bytes};
use super::median_seconds;
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use glam::{Mat3, Vec3};
use pelage::anim::{AnimatedSkin, FrameRange};
use pelage::groom::{AnimatedGroom, AnimationMode, AnimationSpec, Groom, GuideMotion};
use pelage::{Curves, Mesh};
use std::sync::Arc;
use std::time::Instant;

/// Arguments of `pelage bench animation`.
#[derive(Debug, Args)]
pub struct AnimationBenchArgs {
    /// A reduced run (200,000 hairs).
    #[arg(long)]
    pub quick: bool,
    /// The smallest run, through every row and key; its figures mean
    /// nothing (CI runs it in a debug build: tools/bench-smoke).
    #[arg(long)]
    pub smoke: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also measure a peer in the same run: `blender` moves the same
    /// grown groom with Blender's Deform Curves on Surface node on the
    /// skin twisted by its Simple Deform modifier (bpy from PyPI, set up
    /// in a cached venv by tools/bpy-python).
    #[arg(long, value_enum)]
    pub peer: Option<super::groom::Peer>,
}

impl AnimationBenchArgs {
    /// The run's size, from `--quick` and `--smoke`.
    pub fn scale(&self) -> super::Scale {
        super::Scale::of(self.quick, self.smoke)
    }
}

/// Blender's per-frame deform, measured by Blender itself in this run.
#[derive(Debug)]
struct BlenderDeform {
    seconds: f64,
    hairs: u64,
    version: String,
}

/// Runs `blender_deform.py` on the groom grown at rest by `groom`: the
/// skin (positions, triangles, corner UVs), every part's points and root
/// UVs. An error says why it was not measured.
fn measure_blender(groom: &AnimatedGroom, twist_radians: f32) -> anyhow::Result<BlenderDeform> {
    let script = include_str!("blender_deform.py");
    let report = super::run_bpy_case("blender_deform.py", script, |dir| {
        let generator = groom.generator();
        let mesh = generator.mesh();
        super::write_mesh_case(dir, mesh)?;
        let corners = (0..mesh.triangle_count())
            .map(|t| mesh.triangle_uvs(t).unwrap_or_default())
            .flat_map(|uvs| uvs.into_iter().flat_map(|uv| uv.to_array()));
        super::write_le(&dir.join("corner_uvs.f32"), corners.map(f32::to_le_bytes))?;
        let (mut points, mut uvs, mut hairs) = (Vec::new(), Vec::new(), 0u64);
        for k in 0..generator.parts().len() {
            let part = generator.part(k)?;
            points.extend(part.points().iter().flat_map(|p| p.to_array()));
            let roots = part.root_uvs().context("a mesh with UVs gives root UVs")?;
            uvs.extend(roots.iter().flat_map(|uv| uv.to_array()));
            hairs += part.curve_count() as u64;
        }
        super::write_le(
            &dir.join("points.f32"),
            points.into_iter().map(f32::to_le_bytes),
        )?;
        super::write_le(
            &dir.join("root_uvs.f32"),
            uvs.into_iter().map(f32::to_le_bytes),
        )?;
        let case = serde_json::json!({
            "hairs": hairs,
            "points_per_hair": generator.points_per_hair(),
            "frames": FRAMES,
            "twist_radians": twist_radians,
            "addon_dir": super::addon_dir()?,
        });
        std::fs::write(dir.join("case.json"), case.to_string())?;
        Ok(())
    })?;
    let travel = report["max_travel"].as_f64().unwrap_or(0.0);
    anyhow::ensure!(
        travel > 1e-3,
        "Blender's node moved no hair (largest travel {travel}): it found no root by UV"
    );
    Ok(BlenderDeform {
        seconds: report["seconds"]
            .as_f64()
            .context("seconds in Blender's report")?,
        hairs: report["hairs"]
            .as_u64()
            .context("hairs in Blender's report")?,
        version: report["blender"].as_str().unwrap_or("?").to_string(),
    })
}

/// Frames of the deformed skin.
const FRAMES: i32 = 24;
/// Frames regrown (regrowing is a whole groom a frame: a few tell its
/// cost).
const REGROWN_FRAMES: usize = 3;
/// The paper's time for 1.6 M hairs on two cores (Sik §4.2.2): what
/// Stubble spends on every frame.
const PAPER_SECONDS: f64 = 3.2;

/// The bench's deformation: a twist about the vertical axis that grows
/// with height and with the frame, plus a sway.
fn twist(p: Vec3, frame: f64) -> Vec3 {
    let t = (frame - 1.0) as f32 / (FRAMES - 1) as f32;
    let angle = 1.2 * t * (p.y + 0.5);
    Mat3::from_rotation_y(angle) * p + Vec3::new(0.1 * t, 0.0, 0.0)
}

/// Everything `pelage bench animation` measures, before it is printed.
struct AnimationFigures {
    runs: usize,
    threads: usize,
    hair_count: u64,
    point_count: u64,
    times: Vec<f64>,
    grow_s: f64,
    deform_per_frame: f64,
    regrow_per_frame: f64,
    regrown: Vec<f64>,
    scratch_s: f64,
    paper_scaled: f64,
    rss: u64,
    peer: Result<BlenderDeform, String>,
    /// Part 0 written over every frame to usdc, with and without
    /// velocities (medians, alternated runs).
    write_with_velocities_s: f64,
    write_without_velocities_s: f64,
    /// Whether those files were written to memory (`/dev/shm`).
    written_in_memory: bool,
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &AnimationBenchArgs) -> anyhow::Result<()> {
    let figures = measure(args)?;
    if args.json {
        figures.print_json();
    } else {
        figures.print_table();
    }
    Ok(())
}

/// Grows the groom once, then deforms and regrows it frame by frame on
/// the twisted skin, beside growing from scratch (and Blender with
/// `--peer blender`).
fn measure(args: &AnimationBenchArgs) -> anyhow::Result<AnimationFigures> {
    let (hairs, runs) = args
        .scale()
        .pick((1_600_000u64, 5), (200_000, 3), (5_000, 1));
    let threads = rayon::current_num_threads();
    let groom = Groom::from_text("<bench>", groom_text(hairs, "shepard"))?;
    let spec = groom.spec()?;
    let mesh: Arc<Mesh> = spec.mesh.clone();
    let rest: Vec<Vec3> = mesh.positions().to_vec();
    let skin = AnimatedSkin::from_fn(&mesh, move |f| rest.iter().map(|&p| twist(p, f)).collect());
    let skin = Arc::new(skin);
    let frames = FrameRange::parse(&format!("1-{FRAMES}"))?;
    let animation = |mode| AnimationSpec {
        frames: frames.clone(),
        rest_frame: 1.0,
        mode,
        shutter: Vec::new(),
        velocities: true,
    };
    // Guides that ride the twisting skin, as a simulation following it
    // would give them.
    let guides = spec.guides.clone();
    let guide_mesh = mesh.clone();
    let animated_guides = move |f: f64| -> Curves {
        let n = guides.points_per_guide();
        let twisted: Vec<Vec3> = guide_mesh
            .positions()
            .iter()
            .map(|&p| twist(p, f))
            .collect();
        let posed = Mesh::new(
            "twisted",
            twisted,
            guide_mesh.triangles().to_vec(),
            None,
            None,
        )
        .expect("a twisted mesh is a mesh");
        let mut points = Vec::with_capacity(guides.len() * n);
        for (i, root) in guides.roots().iter().enumerate() {
            let g = guides.guide(i);
            let (p0, n0) = (root.position(&guide_mesh), root.normal(&guide_mesh));
            let (p1, n1) = (root.position(&posed), root.normal(&posed));
            let turn = Mat3::from_quat(glam::Quat::from_rotation_arc(n0, n1));
            points.extend(g.iter().map(|&q| p1 + turn * (q - p0)));
        }
        let offsets = (0..=guides.len() as u32).map(|i| i * n as u32).collect();
        Curves::new(points, vec![0.001; guides.len() * n], offsets).expect("finite guides")
    };
    let deform = AnimatedGroom::new(
        spec.clone(),
        skin.clone(),
        animation(AnimationMode::Deform),
        None,
    )?;
    let regrow = AnimatedGroom::new(
        spec.clone(),
        skin.clone(),
        animation(AnimationMode::Regrow),
        Some(GuideMotion::Program(Arc::new(animated_guides))),
    )?;
    let generator = deform.generator();
    let parts = generator.parts().len();

    // Growing once, at rest.
    let (grow_s, counted) = median_seconds(runs, true, || -> anyhow::Result<(u64, u64)> {
        let (mut h, mut p) = (0u64, 0u64);
        for k in 0..parts {
            let c = generator.part(k)?;
            h += c.curve_count() as u64;
            p += c.points().len() as u64;
            generator.recycle(c);
        }
        Ok((h, p))
    });
    let (hair_count, point_count) = counted?;

    // Deform: the poses of every frame, then part by part every frame
    // carried (growth itself is timed apart).
    let times: Vec<f64> = frames.frames().iter().map(|&f| f64::from(f)).collect();
    let mut deform_s = 0.0;
    let start = Instant::now();
    let poses = times
        .iter()
        .map(|&t| deform.pose(t))
        .collect::<Result<Vec<_>, _>>()?;
    deform_s += start.elapsed().as_secs_f64();
    let mut out = Curves::default();
    let mut carried_points = 0u64;
    for k in 0..parts {
        let rest = generator.part(k)?;
        let start = Instant::now();
        let binding = deform.binding();
        let frames = binding.rest_frames(&rest);
        for (f, pose) in poses.iter().enumerate() {
            let carried = if f == 0 {
                binding.carry_into(&rest, pose, &mut out)
            } else {
                binding.carry_again(&rest, &frames, pose, &mut out)
            };
            anyhow::ensure!(carried, "a hair moved to a value that is not finite");
            carried_points += out.points().len() as u64;
        }
        deform_s += start.elapsed().as_secs_f64();
        generator.recycle(rest);
    }
    anyhow::ensure!(carried_points == point_count * times.len() as u64);
    let deform_per_frame = deform_s / times.len() as f64;

    // Regrow: a few frames, whole (guides to rest, generator, every part
    // grown and carried).
    let regrown: Vec<f64> = [
        times[FRAMES as usize / 3],
        times[FRAMES as usize / 2],
        times[FRAMES as usize - 1],
    ]
    .into_iter()
    .take(REGROWN_FRAMES)
    .collect();
    let start = Instant::now();
    for &t in &regrown {
        let pose = regrow.pose(t)?;
        let frame_generator = regrow.regrown_generator(t, &pose)?;
        for k in 0..parts {
            let mut grown = frame_generator.part(k)?;
            anyhow::ensure!(regrow.binding().carry_in_place(&mut grown, &pose));
            frame_generator.recycle(grown);
        }
    }
    let regrow_per_frame = start.elapsed().as_secs_f64() / regrown.len() as f64;

    // The peer: Stubble's way, every frame a generator prepared from
    // scratch on the posed skin and the whole groom grown there (what the
    // paper times per frame; its noise would swim with the skin).
    let posed_spec = {
        let mut s = spec.clone();
        let frame = times[FRAMES as usize / 2];
        s.mesh = Arc::new(Mesh::new(
            "twisted",
            mesh.positions().iter().map(|&p| twist(p, frame)).collect(),
            mesh.triangles().to_vec(),
            None,
            mesh.uvs().cloned(),
        )?);
        s
    };
    let (scratch_s, scratch) = median_seconds(runs, false, || -> anyhow::Result<()> {
        let g = posed_spec.clone().generator()?;
        for k in 0..g.parts().len() {
            let c = g.part(k)?;
            g.recycle(c);
        }
        Ok(())
    });
    scratch?;
    // Velocities' cost: part 0 written over every frame, with and
    // without them, runs alternated so that drift falls on both.
    let without = AnimatedGroom::new(
        spec.clone(),
        skin.clone(),
        AnimationSpec {
            velocities: false,
            ..animation(AnimationMode::Deform)
        },
        None,
    )?;
    // In memory where the system has it: each write ends with an fsync of
    // a gigabyte, and a disk's speed (and its caches) made the ratio
    // swing from 0.6 to 1.9 between runs on one machine.
    let memory = std::path::Path::new("/dev/shm");
    let written_in_memory = memory.is_dir();
    let base = if written_in_memory {
        memory.to_path_buf()
    } else {
        std::env::temp_dir()
    };
    let folder = base.join(format!("pelage-bench-anim-{}", std::process::id()));
    std::fs::create_dir_all(&folder)?;
    let file = folder.join("part.usdc");
    let options = pelage::io::UsdOptions::default();
    let (mut with_times, mut without_times) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        for (groom, times) in [(&deform, &mut with_times), (&without, &mut without_times)] {
            let start = Instant::now();
            groom.write(&file, 0..1, &options, false, |_| {})?;
            times.push(start.elapsed().as_secs_f64());
        }
    }
    let _ = std::fs::remove_dir_all(&folder);
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (write_with_velocities_s, write_without_velocities_s) =
        (median(&mut with_times), median(&mut without_times));
    let rss = peak_rss_bytes().unwrap_or(0);
    let peer = match args.peer {
        Some(super::groom::Peer::Blender) => {
            eprintln!("measuring Blender's Deform Curves on Surface with bpy (tools/bpy-python)…");
            measure_blender(&deform, 1.2).map_err(|e| format!("{e:#}"))
        }
        None => Err("run with --peer blender".to_string()),
    };
    let paper_scaled = PAPER_SECONDS * hairs as f64 / 1.6e6;
    Ok(AnimationFigures {
        runs,
        threads,
        hair_count,
        point_count,
        times,
        grow_s,
        deform_per_frame,
        regrow_per_frame,
        regrown,
        scratch_s,
        paper_scaled,
        rss,
        peer,
        write_with_velocities_s,
        write_without_velocities_s,
        written_in_memory,
    })
}

impl AnimationFigures {
    /// The figures as one JSON object (`--json`).
    fn print_json(&self) {
        let AnimationFigures {
            threads,
            hair_count,
            point_count,
            ref times,
            grow_s,
            deform_per_frame,
            regrow_per_frame,
            ref regrown,
            scratch_s,
            paper_scaled,
            rss,
            ref peer,
            ..
        } = *self;
        let report = serde_json::json!({
            "hairs": hair_count,
            "points": point_count,
            "frames": times.len(),
            "threads": threads,
            "grow_s": grow_s,
            "deform_s_per_frame": deform_per_frame,
            "regrow_s_per_frame": regrow_per_frame,
            "regrown_frames": regrown.len(),
            "deform_over_grow": deform_per_frame / grow_s,
            "regrow_over_grow": regrow_per_frame / grow_s,
            "peer_from_scratch_s_per_frame": scratch_s,
            "paper_s_per_frame": paper_scaled,
            "peak_rss_bytes": rss,
            "write_part_with_velocities_s": self.write_with_velocities_s,
            "write_part_without_velocities_s": self.write_without_velocities_s,
            "velocities_cost": self.write_with_velocities_s / self.write_without_velocities_s,
            "blender": match &peer {
                Ok(b) => serde_json::json!({
                    "version": b.version,
                    "deform_s_per_frame": b.seconds,
                    "hairs": b.hairs,
                    "pelage_speedup": b.seconds / deform_per_frame,
                }),
                Err(why) => serde_json::json!({ "not_measured": why }),
            },
        });
        println!("{report}");
    }

    /// The figures as a table beside growing, the peers and the paper.
    fn print_table(&self) {
        let AnimationFigures {
            runs,
            threads,
            hair_count,
            ref times,
            grow_s,
            deform_per_frame,
            regrow_per_frame,
            ref regrown,
            scratch_s,
            paper_scaled,
            rss,
            ref peer,
            ..
        } = *self;
        println!(
            "pelage bench animation — the Stubble figure ({} hairs × 16 points on spot ×2, clump + noise) on a skin twisted over {} frames; {threads} threads\n",
            thousands(hair_count),
            times.len()
        );
        println!("{:<66} {:>12} {:>12}", "", "s / frame", "× growing");
        let row = |name: &str, s: f64| {
            println!("{name:<66} {s:>12.3} {:>12.2}", s / grow_s);
        };
        row(
            &format!("growing the groom once (median of {runs})"),
            grow_s,
        );
        row("deform: pose + every hair carried", deform_per_frame);
        row(
            &format!(
                "regrow: guides to rest + regrown + carried ({} frames)",
                regrown.len()
            ),
            regrow_per_frame,
        );
        row(
            "peer: from scratch on the posed skin (Stubble's way)",
            scratch_s,
        );
        row("paper: Stubble, 2 cores (Sik §4.2.2)", paper_scaled);
        match &peer {
            Ok(b) => {
                row(
                    &format!(
                        "peer: Blender {} Deform Curves on Surface ({} hairs)",
                        b.version,
                        thousands(b.hairs)
                    ),
                    b.seconds,
                );
                println!(
                    "{:66} pelage's deform {:.1}× faster",
                    "",
                    b.seconds / deform_per_frame
                );
            }
            Err(why) => println!("{:<66} not measured: {why}", "peer: Blender"),
        }
        println!(
            "{:<66} {:>12.3} {:>12}",
            format!(
                "part 0 written to usdc{}, {} frames, with velocities",
                if self.written_in_memory {
                    " in memory"
                } else {
                    ""
                },
                times.len()
            ),
            self.write_with_velocities_s,
            format!(
                "{:.2}× without",
                self.write_with_velocities_s / self.write_without_velocities_s
            )
        );
        println!(
            "{:<66} {:>12.3}",
            "  without velocities", self.write_without_velocities_s
        );
        println!(
            "\ntargets: deform ≤ 0.25× growing, regrow ≤ 1.2× growing, velocities ≤ 1.2× a write without them (the write rows are seconds for all frames). Peak RSS {:.0} MB.",
            rss as f64 / 1e6
        );
    }
}
