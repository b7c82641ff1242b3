//! `pelage bench dynamics --strands`: guides simulated on the running
//! Khronos Fox (Dynamic Follow-The-Leader with bending, follow and body
//! collisions; `pelage::dynamics::GuideSimulation`), frames per second on
//! the CPU (all threads) and on the GPU adapter present
//! (`pelage_gpu::GpuStrands`; lavapipe without a GPU), 4 substeps a
//! frame. Targets (2 cores): ≥ 24 simulated frames a second at 10,000
//! guides × 16 points (2,000 in `--quick`).
//!
//! With `--peer blender`, Blender's own hair dynamics on the same body,
//! guide count, points and length, measured in the same run
//! (`blender_strands.py`): the target is ≥ 10× faster a frame.
//!
//! Beside them, the choice of collision structure measured in the same
//! run: the skin's distance grid (built once a substep, read per point)
//! against closest-point queries over a triangle BVH (built once a
//! substep, queried per point), on the same points.

use crate::format::thousands;
use crate::median;
use glam::Vec3;
use pelage::anim::{AnimatedSkin, SkinOptions, SkinPose};
use pelage::dynamics::{GuideSimulation, GuideStrandParams};
use pelage::guides::{GuideGrowth, Guides};
use pelage::map::Map;
use pelage::mesh::TriangleBvh;
use std::time::Instant;

/// What one run measured.
struct Figures {
    guides: usize,
    points_per_guide: usize,
    substeps: u32,
    frames: usize,
    /// Median seconds a frame: all of it, and its parts.
    frame_s: f64,
    roots_s: f64,
    grids_s: f64,
    step_s: f64,
    /// The collision structures on the same points.
    grid_build_s: f64,
    grid_query_ns: f64,
    bvh_build_s: f64,
    bvh_query_ns: f64,
    gpu: Option<GpuFigures>,
    /// Blender's hair dynamics, or why they were not measured.
    blender: Result<BlenderStrands, String>,
}

/// Blender's hair dynamics on the running Fox, measured by Blender.
struct BlenderStrands {
    /// Median seconds a frame with hair dynamics.
    frame_s: f64,
    /// … and with the hair static (the armature, the collision modifier).
    static_frame_s: f64,
    frames: usize,
    version: String,
}

impl BlenderStrands {
    /// What the dynamics add to a frame.
    fn dynamics_s(&self) -> f64 {
        (self.frame_s - self.static_frame_s).max(0.0)
    }
}

/// Frames Blender simulates: its solver takes about a second a frame at
/// 10,000 guides on two cores.
const BLENDER_FRAMES: usize = 8;

/// Runs `blender_strands.py`: `count` guides of `points` points on the
/// Fox running, `substeps` a frame, with `params`' collision distance.
fn measure_blender(
    count: usize,
    points: usize,
    substeps: u32,
    thickness: f32,
) -> anyhow::Result<BlenderStrands> {
    use anyhow::Context;
    let script = include_str!("blender_strands.py");
    let report = crate::run_bpy_case("blender_strands.py", script, |dir| {
        let gltf = dir.join("Fox.gltf");
        std::fs::write(&gltf, pelage::assets::FOX_GLTF)?;
        let case = serde_json::json!({
            "gltf": gltf,
            "guides": count,
            "points": points,
            "frames": BLENDER_FRAMES,
            "substeps": substeps,
            "length": GUIDE_LENGTH,
            "thickness": thickness,
        });
        std::fs::write(dir.join("case.json"), case.to_string())?;
        Ok(())
    })?;
    let number = |key: &str| {
        report[key]
            .as_f64()
            .with_context(|| format!("{key} in Blender's report"))
    };
    let (guides, keys) = (
        number("guides")? as usize,
        number("points_per_guide")? as usize,
    );
    anyhow::ensure!(
        guides == count && keys == points,
        "Blender grew {guides} guides of {keys} points, not {count} of {points}"
    );
    Ok(BlenderStrands {
        frame_s: number("frame_s")?,
        static_frame_s: number("static_frame_s")?,
        frames: number("frames")? as usize,
        version: report["blender"].as_str().unwrap_or("?").to_string(),
    })
}

/// Guide length, a fraction of the Fox's size.
const GUIDE_LENGTH: f32 = 0.06;

struct GpuFigures {
    adapter: String,
    software: bool,
    frame_s: f64,
    /// Median seconds of the GPU's step alone (upload, dispatch, wait).
    step_s: f64,
    /// Largest distance between a CPU and a GPU point after the frames,
    /// as a fraction of the Fox's size.
    max_difference: f32,
}

/// The Fox running, its skin posed for `frames` frames, and `count`
/// guides of `points` points grown on its first frame.
struct FoxRun {
    triangles: Vec<[u32; 3]>,
    poses: Vec<SkinPose>,
    guides: Guides,
    size: f32,
}

fn fox_run(count: usize, points: usize, frames: usize) -> anyhow::Result<FoxRun> {
    let dir = std::env::temp_dir().join(format!("pelage-bench-strands-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("Fox.gltf");
    std::fs::write(&path, pelage::assets::FOX_GLTF)?;
    let options = SkinOptions {
        clip: Some("Run".into()),
        ..Default::default()
    };
    let skin = AnimatedSkin::load(&path, &options);
    let _ = std::fs::remove_dir_all(&dir);
    let skin = skin?;
    let rest = skin.mesh_at(1.0)?;
    let (lo, hi) = rest.bounds();
    let size = (hi - lo).max_element();
    let guides = Guides::grow(
        &rest,
        &GuideGrowth {
            count,
            length: Map::Constant(GUIDE_LENGTH * size),
            points,
            width: 0.002 * size,
            ..Default::default()
        },
    )?;
    let triangles = rest.triangles().to_vec();
    let poses = (1..=frames)
        .map(|f| Ok(SkinPose::new(skin.positions_at(f as f64)?, &triangles)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok(FoxRun {
        triangles,
        poses,
        guides,
        size,
    })
}

/// The settings the benchmark simulates with: long fur on a Fox about
/// 1.4 m long in its own units.
fn fox_params(size: f32) -> GuideStrandParams {
    GuideStrandParams {
        substeps: 4,
        gravity: Vec3::new(0.0, -9.81 * size / 1.4, 0.0),
        thickness: 0.004 * size,
        bend: 0.3,
        follow: 0.05,
        ..Default::default()
    }
}

fn measure(args: &super::dynamics::DynamicsBenchArgs) -> anyhow::Result<Figures> {
    let (count, frames) = args.scale().pick((10_000, 48), (2_000, 24), (100, 2));
    let count = args.guides.unwrap_or(count);
    let points = args.points;
    let run = fox_run(count, points, frames + 1)?;
    let params = fox_params(run.size);
    let substeps = params.substeps;
    let mut sim = GuideSimulation::new(
        &run.guides,
        &run.triangles,
        &run.poses[0],
        params.clone(),
        true,
    )?;
    let dt = 1.0 / 24.0;
    let (mut frame_t, mut roots_t, mut grids_t, mut step_t) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (f, pose) in run.poses.iter().enumerate().skip(1) {
        let start = Instant::now();
        let roots = sim.root_frames(pose);
        let t_roots = start.elapsed().as_secs_f64();
        let grids = sim.substep_grids(pose);
        let t_grids = start.elapsed().as_secs_f64();
        sim.advance_with(pose, &roots, &grids, dt, f as f32 * dt);
        let t_all = start.elapsed().as_secs_f64();
        frame_t.push(t_all);
        roots_t.push(t_roots);
        grids_t.push(t_grids - t_roots);
        step_t.push(t_all - t_grids);
    }
    // The two collision structures on the last frame's points.
    let last = run.poses.last().expect("frames");
    let queries: Vec<Vec3> = sim.strands().positions().to_vec();
    let (grid_build_s, grid) = crate::median_seconds(5, true, || sim.skin_sdf(last));
    let (grid_all, _) = crate::median_seconds(5, true, || {
        queries.iter().map(|&p| grid.sample(p).0).sum::<f32>()
    });
    let (bvh_build_s, bvh) = crate::median_seconds(5, true, || {
        TriangleBvh::new(last.positions(), &run.triangles)
    });
    let (bvh_all, _) = crate::median_seconds(3, false, || {
        queries
            .iter()
            .map(|&p| bvh.closest(p).map_or(0.0, |c| c.distance_squared))
            .sum::<f32>()
    });
    let per_query = |s: f64| s * 1e9 / queries.len() as f64;
    let gpu = if args.no_gpu {
        None
    } else {
        match gpu_figures(&run, &params, &sim) {
            Ok(g) => Some(g),
            Err(e) => {
                eprintln!("no GPU column: {e:#}");
                None
            }
        }
    };
    let blender = match args.peer {
        Some(super::groom::Peer::Blender) => {
            eprintln!("measuring Blender's hair dynamics with bpy (tools/bpy-python)…");
            measure_blender(
                run.guides.len(),
                points,
                substeps,
                params.thickness / run.size,
            )
            .map_err(|e| format!("{e:#}"))
        }
        None => Err("run with --peer blender".to_string()),
    };
    Ok(Figures {
        blender,
        guides: run.guides.len(),
        points_per_guide: points,
        substeps,
        frames,
        frame_s: median(&frame_t),
        roots_s: median(&roots_t),
        grids_s: median(&grids_t),
        step_s: median(&step_t),
        grid_build_s,
        grid_query_ns: per_query(grid_all),
        bvh_build_s,
        bvh_query_ns: per_query(bvh_all),
        gpu,
    })
}

/// The same frames on the GPU: the strands' step as a compute shader,
/// the skin's grids and roots made on the CPU and uploaded each frame.
fn gpu_figures(
    run: &FoxRun,
    params: &GuideStrandParams,
    cpu: &GuideSimulation,
) -> anyhow::Result<GpuFigures> {
    let ctx = pelage_gpu::GpuContext::headless()?;
    let mut sim = GuideSimulation::new(
        &run.guides,
        &run.triangles,
        &run.poses[0],
        params.clone(),
        true,
    )?;
    let mut gpu = pelage_gpu::GpuStrands::new(&ctx, sim.strands())?;
    let dt = 1.0 / 24.0;
    let (mut times, mut steps) = (Vec::new(), Vec::new());
    for (f, pose) in run.poses.iter().enumerate().skip(1) {
        let start = Instant::now();
        let roots = sim.root_frames(pose);
        let grids = sim.substep_grids(pose);
        let stepping = Instant::now();
        gpu.step(&ctx, params, dt, f as f32 * dt, &roots, &grids)?;
        gpu.wait(&ctx)?;
        times.push(start.elapsed().as_secs_f64());
        steps.push(stepping.elapsed().as_secs_f64());
        sim.note_pose(pose);
    }
    let points = gpu.read_positions(&ctx)?;
    let max_difference = points
        .iter()
        .zip(cpu.strands().positions())
        .map(|(a, b)| (*a - *b).length() / run.size)
        .fold(0.0f32, f32::max);
    Ok(GpuFigures {
        adapter: ctx.adapter_name(),
        software: ctx.is_software(),
        frame_s: median(&times),
        step_s: median(&steps),
        max_difference,
    })
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &super::dynamics::DynamicsBenchArgs) -> anyhow::Result<()> {
    let f = measure(args)?;
    let fps = 1.0 / f.frame_s;
    let gpu_fps = f.gpu.as_ref().map(|g| 1.0 / g.frame_s);
    if args.json {
        let report = serde_json::json!({
            "guides": f.guides,
            "points_per_guide": f.points_per_guide,
            "substeps": f.substeps,
            "frames": f.frames,
            "threads": rayon::current_num_threads(),
            "cpu_frames_per_s": fps,
            "cpu_frame_s": f.frame_s,
            "cpu_roots_s": f.roots_s,
            "cpu_grids_s": f.grids_s,
            "cpu_step_s": f.step_s,
            "grid_build_s": f.grid_build_s,
            "grid_query_ns": f.grid_query_ns,
            "bvh_build_s": f.bvh_build_s,
            "bvh_query_ns": f.bvh_query_ns,
            "gpu_frames_per_s": gpu_fps,
            "gpu_steps_per_s": f.gpu.as_ref().map(|g| 1.0 / g.step_s),
            "gpu_adapter": f.gpu.as_ref().map(|g| g.adapter.clone()),
            "gpu_software": f.gpu.as_ref().map(|g| g.software),
            "gpu_max_difference": f.gpu.as_ref().map(|g| g.max_difference),
            "blender_frame_s": f.blender.as_ref().ok().map(|b| b.frame_s),
            "blender_static_frame_s": f.blender.as_ref().ok().map(|b| b.static_frame_s),
            "blender_dynamics_s": f.blender.as_ref().ok().map(|b| b.dynamics_s()),
            "blender_frames": f.blender.as_ref().ok().map(|b| b.frames),
            "blender_version": f.blender.as_ref().ok().map(|b| b.version.clone()),
            "blender_error": f.blender.as_ref().err(),
            "cpu_speedup_over_blender": f.blender.as_ref().ok().map(|b| b.dynamics_s() / f.frame_s),
            "gpu_speedup_over_blender": f.blender.as_ref().ok().zip(f.gpu.as_ref()).map(|(b, g)| b.dynamics_s() / g.frame_s),
        });
        println!("{report}");
        return Ok(());
    }
    println!(
        "pelage bench dynamics --strands — the running Fox, {} guides × {} points, {} substeps a frame, body collisions; median of {} frames, {} threads",
        thousands(f.guides as u64),
        f.points_per_guide,
        f.substeps,
        f.frames,
        rayon::current_num_threads()
    );
    println!();
    println!(
        "{:>10}  {:>12}  {:>14}  {:>10}  {:>10}  {:>10}",
        "", "frames/s", "frame", "roots", "grids", "strands"
    );
    println!(
        "{:>10}  {:>12.1}  {:>11.2} ms  {:>7.2} ms  {:>7.2} ms  {:>7.2} ms   target ≥ 24 frames/s",
        "CPU",
        fps,
        f.frame_s * 1e3,
        f.roots_s * 1e3,
        f.grids_s * 1e3,
        f.step_s * 1e3
    );
    match &f.gpu {
        Some(g) => println!(
            "{:>10}  {:>12.1}  {:>11.2} ms  (the step alone: {:.2} ms; on {}{}; CPU and GPU points within {:.2e} of the Fox's size after {} frames)",
            "GPU",
            1.0 / g.frame_s,
            g.frame_s * 1e3,
            g.step_s * 1e3,
            g.adapter,
            if g.software { ", software" } else { "" },
            g.max_difference,
            f.frames
        ),
        None => println!("{:>10}  {:>12}", "GPU", "—"),
    }
    match &f.blender {
        Ok(b) => {
            println!(
                "{:>10}  {:>12.1}  {:>11.2} ms  (Blender {} hair dynamics, the same count, points, length and body, its own roots; a frame {:.2} ms, {:.2} ms of it the skin and static hair; median of {} frames)",
                "Blender",
                1.0 / b.dynamics_s().max(f64::MIN_POSITIVE),
                b.dynamics_s() * 1e3,
                b.version,
                b.frame_s * 1e3,
                b.static_frame_s * 1e3,
                b.frames
            );
            let gpu = f.gpu.as_ref().map_or(String::new(), |g| {
                format!(", GPU {:.1}×", b.dynamics_s() / g.frame_s)
            });
            println!(
                "{:>10}  CPU {:.1}× Blender's dynamics a frame{gpu}   target ≥ 10×",
                "",
                b.dynamics_s() / f.frame_s
            );
        }
        Err(why) => println!("{:>10}  {:>12}  ({why})", "Blender", "—"),
    }
    println!();
    println!("collision structure, on the last frame's points (the grid is what the solver uses):");
    println!(
        "  distance grid: built in {:.2} ms, {:.0} ns a query",
        f.grid_build_s * 1e3,
        f.grid_query_ns
    );
    println!(
        "  triangle BVH:  built in {:.2} ms, {:.0} ns a query ({:.1}× the grid's query)",
        f.bvh_build_s * 1e3,
        f.bvh_query_ns,
        f.bvh_query_ns / f.grid_query_ns
    );
    Ok(())
}
