//! `pelage bench realtime`: the groom in the game, a frame at a time, on
//! the running Khronos Fox. Each frame: the guides simulated on the GPU
//! (`GpuStrands`: follow-the-leader with body collisions, 4 substeps)
//! and brought back to rest space, every hair grown again from them on
//! the GPU (`GpuGroom`) and carried to the pose, then the skin and the
//! strands drawn (`StrandRenderer`: deep opacity shadows, the hair lobes)
//! at 1920×1080. Beside the GPU evaluation, the CPU groom of the same
//! hairs from the same guides, measured in the same run.
//!
//! Targets (issue "Real-time strands"): on an H100-class GPU, 100,000
//! hairs × 16 points from 2,000 guides at ≥ 60 frames/s counting
//! simulation, evaluation and drawing; the GPU evaluation ≥ 50× the CPU
//! groom. On lavapipe (no GPU) the figures are the CPU's running the
//! shaders, and say only that the path works.

use crate::Scale;
use crate::format::thousands;
use crate::median;
use clap::Args;
use glam::Vec3;
use pelage::Curves;
use pelage::anim::SkinPose;
use pelage::groom::{AnimatedGroom, Groom, GroomSpec};
use pelage::guides::Guides;
use pelage_gpu::{
    Camera, FurLod, GpuContext, RealtimeFur, ShellTarget, ShellTargetFormats, ShellView,
};
use std::sync::Arc;
use std::time::Instant;

/// Arguments of `pelage bench realtime`.
#[derive(Debug, Args)]
pub struct RealtimeBenchArgs {
    /// 20,000 hairs from 500 guides at 640×360: a figure in a minute.
    #[arg(long)]
    pub quick: bool,
    /// The smallest run through every row (CI); its figures mean nothing.
    #[arg(long, hide = true)]
    pub smoke: bool,
    /// One JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Hairs instead of the case's (100,000; 20,000 with `--quick`), from
    /// the same guides: `--hairs 1000000` for the million-hair figure.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=pelage::limits::MAX_HAIRS))]
    pub hairs: Option<u64>,
}

/// What one run measured: medians over its frames, in milliseconds.
struct Figures {
    hairs: usize,
    points_per_hair: usize,
    guides: usize,
    size: (u32, u32),
    frames: usize,
    sim_ms: f64,
    eval_ms: f64,
    draw_ms: f64,
    cpu_eval_ms: f64,
    cpu_frames: usize,
    lod: Vec<LodRow>,
    adapter: String,
    software: bool,
}

/// The fur at one distance: the character's height on screen, what the
/// level of detail drew and its cost, beside shells alone at that size.
struct LodRow {
    screen_share: f32,
    hairs: u32,
    shell_opacity: f32,
    ms: f64,
    shells_ms: f64,
}

/// The Fox's groom: `hairs` hairs of `points` points from `guides`
/// guides, clumped, curled and waved, coloured by its texture, the
/// guides simulated.
fn fox_groom(hairs: usize, guides: usize, points: usize) -> anyhow::Result<Groom> {
    let fox =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../pelage/assets/fox/Fox.gltf");
    let text = format!(
        "[mesh]\npath = {fox:?}\n\
         [roots]\ncount = {hairs}\nseed = 1\n\
         [guides]\npoints = {points}\ngenerate = {{ count = {guides}, length = 9, comb = [0, -0.2, -0.8], gravity = 0.3, seed = 7 }}\n\
         [[ops]]\nclump = {{ count = 3000, rate = 0.35 }}\n\
         [[ops]]\ncurl = {{ radius = 0.3, turns = 2 }}\n\
         [[ops]]\nnoise = {{ amplitude = 0.4, frequency = 0.15 }}\n\
         [finish]\npoints = {points}\nwidth = {{ root = 0.9, tip = 0.25 }}\n\
         [animation]\nframes = \"1-48\"\nfps = 24\nclip = \"Run\"\nmode = \"simulate\"\n\
         [simulation]\ngravity = [0, -1200, 0]\ndamping = 2\nbend = 0.3\nfollow = 0.05\n"
    );
    Ok(Groom::from_text("fox.toml", &text)?)
}

/// A camera on the Fox from `distance` units away.
fn view_from(fur: &RealtimeFur, distance: f32, size: (u32, u32)) -> ShellView {
    let (lo, hi) = fur.bounds();
    let centre = 0.5 * (lo + hi);
    ShellView::new(
        Some(Camera {
            eye: centre + distance * Vec3::new(1.0, 0.35, 0.75).normalize(),
            target: centre,
            fov_y_degrees: 30.0,
        }),
        (lo, hi),
        0.0,
        size.0 as f32 / size.1 as f32,
        None,
    )
}

fn measure(scale: Scale, hairs: Option<u64>) -> anyhow::Result<Figures> {
    let (case_hairs, guides, points) =
        scale.pick((100_000, 2_000, 16), (20_000, 500, 16), (1_000, 50, 8));
    let hairs = hairs.map_or(case_hairs, |h| h as usize);
    let size = scale.pick((1920, 1080), (640, 360), (160, 90));
    let frames = scale.pick(24, 12, 2);
    let cpu_frames = scale.pick(3, 2, 1);
    let groom = fox_groom(hairs, guides, points)?;
    let spec = groom.spec()?;
    let ctx = GpuContext::headless()?;
    let mut fur = RealtimeFur::new(&ctx, groom, ShellTargetFormats::own())?;
    let target = ShellTarget::new(&ctx, fur.shell_renderer(), size.0, size.1)?;
    // Every strand, whatever the size on screen, for the frame rows.
    let lod = fur.lod;
    fur.lod = FurLod {
        full_px: 1.0,
        ..lod
    };
    let near = view_from(&fur, 260.0, size);
    let (mut sim_t, mut eval_t, mut draw_t, mut cpu_t) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for frame in 1..=frames {
        fur.advance_to(&ctx, frame as f64)?;
        fur.draw(&ctx, &near, &target)?;
        let stats = fur.stats();
        sim_t.push(stats.sim_ms);
        eval_t.push(stats.eval_ms);
        draw_t.push(stats.draw_ms);
        if cpu_t.len() < cpu_frames
            && let (Some(animated), Some(guides)) = (fur.animated(), fur.frame_guides(&ctx)?)
        {
            let pose = animated.pose(frame as f64)?;
            cpu_t.push(1e3 * cpu_groom(animated, &spec, guides, &pose)?.0);
        }
    }
    // The level of detail: the Fox at shares of the screen's height, each
    // drawn as the level of detail draws it and as shells alone.
    let mut rows = Vec::new();
    for share in [0.75f32, 0.25, 0.1] {
        let (lo, hi) = fur.bounds();
        let extent = (hi - lo).max_element();
        let fov = 30f32.to_radians();
        let distance = extent / (share * 2.0 * (0.5 * fov).tan());
        let view = view_from(&fur, distance, size);
        let draws = scale.pick(5, 3, 1);
        let mut timed = |lod: FurLod| -> anyhow::Result<(f64, pelage_gpu::RealtimeStats)> {
            fur.lod = lod;
            let mut t = Vec::new();
            for _ in 0..draws {
                fur.draw(&ctx, &view, &target)?;
                t.push(fur.stats().draw_ms);
            }
            Ok((median(&t), fur.stats()))
        };
        let (ms, stats) = timed(lod)?;
        // Shells alone: a hand-over height past any screen.
        let (shells_ms, _) = timed(FurLod {
            full_px: 1e9,
            ..lod
        })?;
        rows.push(LodRow {
            screen_share: share,
            hairs: stats.drawn,
            shell_opacity: stats.level.shell_opacity,
            ms,
            shells_ms,
        });
    }
    let ms = |t: &[f64]| median(t);
    Ok(Figures {
        hairs: fur.stats().hairs as usize,
        points_per_hair: points,
        guides: fur.guide_count(),
        size,
        frames,
        sim_ms: ms(&sim_t),
        eval_ms: ms(&eval_t),
        draw_ms: ms(&draw_t),
        cpu_eval_ms: ms(&cpu_t),
        cpu_frames: cpu_t.len(),
        lod: rows,
        adapter: ctx.adapter_name(),
        software: ctx.is_software(),
    })
}

/// The CPU groom of the same frame (all threads): a generator reshaped to
/// the frame's guides, every part grown, carried to the pose and kept out
/// of the posed skin, as `AnimatedGroom` regrows a frame. Returns its
/// seconds and hairs.
fn cpu_groom(
    animated: &AnimatedGroom,
    spec: &GroomSpec,
    guides: Guides,
    pose: &SkinPose,
) -> anyhow::Result<(f64, usize)> {
    let start = Instant::now();
    let mut spec = spec.clone();
    spec.guides = Arc::new(guides);
    let generator = animated.generator().reshaped(spec)?;
    let outside = animated.outside_skin(pose);
    let triangles = animated.binding().triangles();
    let mut hairs = 0;
    for p in 0..generator.parts().len() {
        let mut part: Curves = generator.part(p)?;
        animated.binding().carry_in_place(&mut part, pose);
        if let Some(outside) = &outside {
            outside.apply_all(&mut part, |root| pose.frame_at(triangles, root).1.z_axis);
        }
        hairs += part.curve_count();
    }
    Ok((start.elapsed().as_secs_f64(), hairs))
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &RealtimeBenchArgs) -> anyhow::Result<()> {
    let scale = Scale::of(args.quick, args.smoke);
    let f = measure(scale, args.hairs)?;
    let frame_ms = f.sim_ms + f.eval_ms + f.draw_ms;
    let speedup = f.cpu_eval_ms / f.eval_ms;
    if args.json {
        let report = serde_json::json!({
            "hairs": f.hairs,
            "points_per_hair": f.points_per_hair,
            "guides": f.guides,
            "width": f.size.0,
            "height": f.size.1,
            "frames": f.frames,
            "sim_ms": f.sim_ms,
            "eval_ms": f.eval_ms,
            "draw_ms": f.draw_ms,
            "frame_ms": frame_ms,
            "fps": 1e3 / frame_ms,
            "cpu_eval_ms": f.cpu_eval_ms,
            "cpu_frames": f.cpu_frames,
            "eval_speedup": speedup,
            "threads": rayon::current_num_threads(),
            "lod": f.lod.iter().map(|r| serde_json::json!({
                "screen_share": r.screen_share,
                "hairs": r.hairs,
                "shell_opacity": r.shell_opacity,
                "ms": r.ms,
                "shells_ms": r.shells_ms,
                "over_shells": r.ms / r.shells_ms,
            })).collect::<Vec<_>>(),
            "adapter": f.adapter,
            "software": f.software,
        });
        println!("{report}");
        return Ok(());
    }
    println!(
        "pelage bench realtime{} — the running Fox, {} hairs × {} points from {} simulated guides, {}×{}; median of {} frames",
        scale.flag(),
        thousands(f.hairs as u64),
        f.points_per_hair,
        thousands(f.guides as u64),
        f.size.0,
        f.size.1,
        f.frames
    );
    println!(
        "on {}{}",
        f.adapter,
        if f.software {
            " (software: the CPU runs the shaders; GPU targets need a GPU)"
        } else {
            ""
        }
    );
    println!();
    println!("{:>28}  {:>10}", "", "ms");
    println!("{:>28}  {:>10.2}", "guides simulated (GPU)", f.sim_ms);
    println!("{:>28}  {:>10.2}", "hairs grown (GPU)", f.eval_ms);
    println!("{:>28}  {:>10.2}", "skin and strands drawn", f.draw_ms);
    println!(
        "{:>28}  {:>10.2}   {:.1} frames/s   target ≥ 60 frames/s (H100-class GPU)",
        "frame",
        frame_ms,
        1e3 / frame_ms
    );
    println!();
    println!(
        "{:>28}  {:>10.2}   (median of {} frames, {} threads)",
        "CPU groom, same hairs",
        f.cpu_eval_ms,
        f.cpu_frames,
        rayon::current_num_threads()
    );
    println!(
        "{:>28}  {:>10.1}×   target ≥ 50×",
        "GPU evaluation speedup", speedup
    );
    println!();
    println!("level of detail: the Fox at a share of the screen's height, drawn (median ms)");
    println!(
        "{:>10}  {:>10}  {:>8}  {:>10}  {:>12}  {:>10}",
        "height", "strands", "shells", "fur", "shells alone", "ratio"
    );
    for r in &f.lod {
        println!(
            "{:>9.0} %  {:>10}  {:>6.0} %  {:>10.2}  {:>12.2}  {:>9.2}×{}",
            100.0 * r.screen_share,
            thousands(u64::from(r.hairs)),
            100.0 * r.shell_opacity,
            r.ms,
            r.shells_ms,
            r.ms / r.shells_ms,
            if (r.screen_share - 0.1).abs() < 1e-3 {
                "   target ≤ 1.2×"
            } else {
                ""
            }
        );
    }
    Ok(())
}
