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
use pelage::dynamics::{GuideSimulation, GuideStrandParams};
use pelage::groom::{AnimatedGroom, Groom, GroomRecipe, GroomSpec};
use pelage::guides::Guides;
use pelage_gpu::{
    Camera, GpuContext, GpuGroom, GpuStrands, ShellFeatures, ShellParams, ShellRenderer,
    ShellTarget, ShellUpload, ShellView, StrandParams, StrandRenderer,
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
    adapter: String,
    software: bool,
}

/// The Fox's groom: `hairs` hairs of `points` points from `guides`
/// guides, clumped, curled and waved, coloured by its texture.
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
         [finish]\npoints = {points}\noutside_skin = false\nwidth = {{ root = 0.9, tip = 0.25 }}\n\
         [animation]\nframes = \"1-28\"\nfps = 24\nclip = \"Run\"\nmode = \"deform\"\n"
    );
    Ok(Groom::from_text("fox.toml", &text)?)
}

/// The guide simulation's settings on a skin `size` long.
fn sim_params(size: f32) -> GuideStrandParams {
    GuideStrandParams {
        substeps: 4,
        gravity: Vec3::new(0.0, -9.81 * size / 1.4, 0.0),
        thickness: 0.004 * size,
        bend: 0.3,
        follow: 0.05,
        ..Default::default()
    }
}

/// Simulated guides (strand after strand, posed) brought back to the
/// rest pose through their roots' frames: the frame's guides as the
/// groom reads them.
fn guides_at_rest(animated: &AnimatedGroom, posed: &[Vec3], pose: &SkinPose) -> Guides {
    let rest = animated.generator().guides();
    let n = rest.points_per_guide();
    let mut points = vec![Vec3::ZERO; posed.len()];
    for (i, (&root, out)) in rest.roots().iter().zip(points.chunks_mut(n)).enumerate() {
        animated
            .binding()
            .to_rest(&posed[i * n..(i + 1) * n], root, pose, out);
    }
    rest.with_points(points)
        .expect("simulated guides keep their layout")
}

fn measure(scale: Scale) -> anyhow::Result<Figures> {
    let (hairs, guides, points) =
        scale.pick((100_000, 2_000, 16), (20_000, 500, 16), (1_000, 50, 8));
    let size = scale.pick((1920, 1080), (640, 360), (160, 90));
    let frames = scale.pick(24, 12, 2);
    let cpu_frames = scale.pick(3, 2, 1);
    let groom = fox_groom(hairs, guides, points)?;
    let spec = groom.spec()?;
    let animated = groom.animated(None)?.expect("the groom is animated");
    let rest = animated.generator();
    let (mut roots, mut ids) = (Vec::new(), Vec::new());
    for p in 0..rest.parts().len() {
        let (r, i) = rest.part_roots(p);
        roots.extend(r);
        ids.extend(i);
    }
    let ctx = GpuContext::headless()?;
    let recipe = GroomRecipe::new(rest, &roots, &ids)?;
    let gpu_groom = GpuGroom::new(&ctx, &recipe, animated.binding())?;
    // The skin: drawn by the shell renderer, skinned on the GPU by the
    // glTF's rig (the groom's skin, the same vertices).
    let skin = animated.skin();
    let rig = skin
        .rig()
        .ok_or_else(|| anyhow::anyhow!("the Fox has no rig"))?;
    let rest_mesh = skin.mesh_at(1.0)?;
    let shells = ShellRenderer::new(&ctx, ShellFeatures::default());
    let textures = pelage::shell::ShellTextures::generate(&pelage::shell::ShellTextureParams {
        resolution: 16,
        layers: 1,
        ..Default::default()
    });
    let color = image::load_from_memory(pelage::assets::FOX_TEXTURE_PNG)?.to_rgba8();
    let model = shells.upload_with(
        &ctx,
        &rest_mesh,
        &color,
        &textures,
        16,
        ShellUpload {
            rig: Some(rig),
            per_corner: false,
        },
    )?;
    let strands = StrandRenderer::new(&ctx, shells.target_formats());
    let binding = strands.bind(&ctx, &gpu_groom);
    let target = ShellTarget::new(&ctx, &shells, size.0, size.1)?;
    let (lo, hi) = rest_mesh.bounds();
    let length = 9.0;
    let view = ShellView::new(
        Some(Camera {
            eye: Vec3::new(190.0, 85.0, 140.0),
            target: Vec3::new(0.0, 40.0, -10.0),
            fov_y_degrees: 32.0,
        }),
        (lo, hi),
        length,
        size.0 as f32 / size.1 as f32,
        None,
    );
    let skin_params = ShellParams::plain(0, length);
    let params = StrandParams::for_length(length);
    let triangles = animated.binding().triangles().to_vec();
    let pose_at = |frame: usize| animated.pose(frame as f64);
    let fox_size = (hi - lo).max_element();
    let sim_settings = sim_params(fox_size);
    let first = pose_at(1)?;
    let mut sim = GuideSimulation::new(
        rest.guides(),
        &triangles,
        &first,
        sim_settings.clone(),
        true,
    )?;
    let mut gpu_strands = GpuStrands::new(&ctx, sim.strands())?;
    let dt = 1.0 / 24.0;
    let (mut sim_t, mut eval_t, mut draw_t, mut cpu_t) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let grown = (
        lo - Vec3::splat(2.0 * length),
        hi + Vec3::splat(2.0 * length),
    );
    for frame in 2..frames + 2 {
        let pose = pose_at(frame)?;
        let start = Instant::now();
        let root_frames = sim.root_frames(&pose);
        let grids = sim.substep_grids(&pose);
        gpu_strands.step(
            &ctx,
            &sim_settings,
            dt,
            frame as f32 * dt,
            &root_frames,
            &grids,
        )?;
        let posed = gpu_strands.read_positions(&ctx)?;
        sim.note_pose(&pose);
        let frame_guides = guides_at_rest(&animated, &posed, &pose);
        let offsets = GroomRecipe::guide_offsets(&frame_guides);
        sim_t.push(start.elapsed().as_secs_f64());

        let start = Instant::now();
        gpu_groom.grow(&ctx, &offsets, Some(&pose))?;
        ctx.wait()?;
        eval_t.push(start.elapsed().as_secs_f64());

        let start = Instant::now();
        let seconds = (frame as f64 - 1.0) / 24.0;
        let palette = skin
            .palette_at_seconds(seconds)
            .ok_or_else(|| anyhow::anyhow!("the Fox has no clip"))?;
        shells.pose_now(&ctx, &model, &palette)?;
        strands.draw(
            &ctx,
            &binding,
            &params,
            &view,
            grown,
            Some((&shells, &model, &skin_params)),
            &target,
        )?;
        draw_t.push(start.elapsed().as_secs_f64());

        if cpu_t.len() < cpu_frames {
            cpu_t.push(cpu_groom(&animated, &spec, frame_guides, &pose)?.0);
        }
    }
    let ms = |t: &[f64]| 1e3 * median(t);
    Ok(Figures {
        hairs: recipe.render_hairs().len(),
        points_per_hair: points,
        guides: rest.guides().len(),
        size,
        frames,
        sim_ms: ms(&sim_t),
        eval_ms: ms(&eval_t),
        draw_ms: ms(&draw_t),
        cpu_eval_ms: ms(&cpu_t),
        cpu_frames: cpu_t.len(),
        adapter: ctx.adapter_name(),
        software: ctx.is_software(),
    })
}

/// The CPU groom of the same frame (all threads): a generator reshaped to
/// the frame's guides, every part grown and carried to the pose, as
/// `AnimatedGroom` regrows a frame. Returns its seconds and hairs.
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
    let mut hairs = 0;
    for p in 0..generator.parts().len() {
        let mut part: Curves = generator.part(p)?;
        animated.binding().carry_in_place(&mut part, pose);
        hairs += part.curve_count();
    }
    Ok((start.elapsed().as_secs_f64(), hairs))
}

/// Runs the benchmark and prints its table (or its JSON).
pub fn run(args: &RealtimeBenchArgs) -> anyhow::Result<()> {
    let scale = Scale::of(args.quick, args.smoke);
    let f = measure(scale)?;
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
    Ok(())
}
