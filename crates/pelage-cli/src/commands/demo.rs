//! `pelage demo`: the groom generator on the embedded Spot mesh, with no
//! files needed. It writes a groom file (`demo.toml`, with Spot's texture
//! beside it for the hair colour) into the output folder, grows it —
//! 400 guides, 200,000 hairs, clump + curl + noise — into `groom.usdc`
//! (with the skin), and renders `preview.png` (skipped with a message
//! where no GPU adapter exists). The groom file is the user's to edit and
//! rerun with `pelage groom`.

use super::info::MeshSummary;
use crate::format::thousands;
use anyhow::Context;
use clap::Args;
use pelage::Curves;
use pelage::groom::Groom;
use pelage::io::write_atomically;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `pelage demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Which demo: `spot` (a still groom) or `fox` (the Khronos Fox
    /// walking, its fur following the skin frame by frame).
    #[arg(value_enum, default_value = "spot")]
    pub which: DemoName,
    /// Folder the demo writes into (default: pelage-demo, pelage-fox, or
    /// pelage-fox-simulate).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// With `fox`: the Fox running with long fur whose guides are
    /// simulated (gravity, inertia, collisions with the body).
    #[arg(long)]
    pub simulate: bool,
    /// With `fox`: the groom in real time, on the GPU: guides simulated,
    /// hairs grown and drawn every frame, strands near and shell fur far
    /// as the camera pulls back; writes a GIF and each stage's time.
    #[arg(long, conflicts_with = "simulate")]
    pub realtime: bool,
}

/// The demos.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DemoName {
    /// A still groom on the embedded Spot.
    Spot,
    /// An animated groom on the embedded Khronos Fox (walk cycle).
    Fox,
}

/// The fox demo's groom file, as written for the user.
pub const FOX_GROOM: &str = include_str!("../demo_fox.toml");

/// `demo fox --simulate`'s groom file.
pub const FOX_SIMULATE_GROOM: &str = include_str!("../demo_fox_simulate.toml");

/// `demo fox --realtime`'s groom file.
pub const FOX_REALTIME_GROOM: &str = include_str!("../demo_fox_realtime.toml");

/// The demo's groom file, as written for the user.
pub const DEMO_GROOM: &str = include_str!("../demo.toml");

/// Renders the groom on the textured skin, close on the head; returns the
/// adapter's name.
fn render_preview(
    spot: &pelage::Mesh,
    curves: &Curves,
    path: &std::path::Path,
) -> anyhow::Result<String> {
    use pelage_gpu::{Camera, PreviewScene, PreviewStyle};
    let texture = image::load_from_memory(pelage::assets::SPOT_TEXTURE_PNG)?.to_rgba8();
    let scene = PreviewScene {
        mesh: Some(spot),
        points: &[],
        curves: Some(curves),
        skin_texture: Some(&texture),
    };
    let camera = Camera {
        eye: glam::Vec3::new(2.1, 0.9, 1.1),
        target: glam::Vec3::new(0.0, 0.2, 0.1),
        fov_y_degrees: 36.0,
    };
    let style = PreviewStyle {
        background: super::FUR_BACKGROUND,
        ..PreviewStyle::default()
    };
    super::render_png(&scene, &style, Some(camera), (1280, 720), path)
}

pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    if args.which == DemoName::Fox && args.realtime {
        let out = args.out.clone();
        return run_fox_realtime(&out.unwrap_or_else(|| PathBuf::from("pelage-fox-realtime")));
    }
    anyhow::ensure!(
        !args.realtime,
        "--realtime goes with the fox demo: pelage demo fox --realtime"
    );
    if args.which == DemoName::Fox {
        let folder = if args.simulate {
            "pelage-fox-simulate"
        } else {
            "pelage-fox"
        };
        return run_fox(
            &args.out.clone().unwrap_or_else(|| PathBuf::from(folder)),
            args.simulate,
        );
    }
    anyhow::ensure!(
        !args.simulate,
        "--simulate goes with the fox demo: pelage demo fox --simulate"
    );
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("pelage-demo"));
    let start = Instant::now();
    let spot = pelage::assets::spot();
    println!(
        "pelage {} demo — a groom on the embedded Spot mesh\n",
        env!("CARGO_PKG_VERSION")
    );
    print!("{}", MeshSummary::of(&spot, 0).table());

    std::fs::create_dir_all(&out)
        .with_context(|| format!("cannot create the folder {}", out.display()))?;
    let groom_path = out.join("demo.toml");
    write_atomically(&groom_path, |out| out.write_all(DEMO_GROOM.as_bytes()))?;
    let texture_path = out.join("spot.png");
    write_atomically(&texture_path, |out| {
        out.write_all(pelage::assets::SPOT_TEXTURE_PNG)
    })?;

    let groom = Groom::load(&groom_path)?;
    let prepared = Instant::now();
    let generator = groom.generator(None)?;
    let output = groom.output_path();
    let export = groom.export();
    println!(
        "\ngrowing {} hairs from {} guides in {} parts: {} …",
        thousands(generator.parts().iter().map(|p| p.hair_count).sum()),
        thousands(groom.guides().len() as u64),
        generator.parts().len(),
        generator
            .operators()
            .iter()
            .map(|o| o.name())
            .collect::<Vec<_>>()
            .join(" → ")
    );
    let mut grown = Vec::new();
    let parts = 0..generator.parts().len();
    let summary = generator.write(&output, parts, &export, |_, curves| {
        grown.push(curves.clone());
    })?;
    let seconds = prepared.elapsed().as_secs_f64();
    println!(
        "{} hairs, {} points → {} in {:.2} s ({:.2} M hairs/s, writing included)",
        thousands(summary.hairs),
        thousands(summary.points),
        output.display(),
        seconds,
        summary.hairs as f64 / seconds / 1e6
    );
    println!(
        "the groom file it used → {} (with {})",
        groom_path.display(),
        texture_path.display()
    );
    let curves = pelage::curves::join(grown.iter())?;
    let preview = out.join("preview.png");
    match render_preview(&spot, &curves, &preview) {
        Ok(adapter) => println!("preview → {} (rendered on {adapter})", preview.display()),
        // The demo still did its job; say why there is no picture.
        Err(e) => println!("preview skipped: {e:#}"),
    }
    println!("done in {:.2} s\n", start.elapsed().as_secs_f64());
    println!(
        "Next: edit {} and run `pelage groom {}`;",
        groom_path.display(),
        groom_path.display()
    );
    println!(
        "      `pelage render {} --mesh spot -o groom.png`, `pelage bench groom --quick`.",
        output.display()
    );
    Ok(())
}

/// Writes the fox demo's files (`groom` as `fox.toml`, the Fox, its
/// texture and licence) into `out`.
fn write_fox_files(out: &std::path::Path, groom: &str) -> anyhow::Result<()> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create the folder {}", out.display()))?;
    for (name, bytes) in [
        ("fox.toml", groom.as_bytes()),
        ("Fox.gltf", pelage::assets::FOX_GLTF),
        ("fox.png", pelage::assets::FOX_TEXTURE_PNG),
        ("LICENSE-fox.md", pelage::assets::FOX_LICENSE.as_bytes()),
    ] {
        write_atomically(&out.join(name), |w| w.write_all(bytes))?;
    }
    Ok(())
}

/// `pelage demo fox --realtime`: the Fox running, played by the
/// real-time player (GPU guides, GPU hairs, strands near and shells far)
/// while the camera pulls back from near to far; a GIF and a still.
fn run_fox_realtime(out: &std::path::Path) -> anyhow::Result<()> {
    use pelage_gpu::{Camera, GpuContext, RealtimeFur, ShellTarget, ShellView};
    let start = Instant::now();
    println!(
        "pelage {} demo — the running Khronos Fox in real time (GPU)\n",
        env!("CARGO_PKG_VERSION")
    );
    write_fox_files(out, FOX_REALTIME_GROOM)?;
    let groom = Groom::load(&out.join("fox.toml"))?;
    let ctx = GpuContext::headless().context("--realtime draws on the GPU")?;
    let (w, h) = (480, 300);
    let mut fur = RealtimeFur::new(&ctx, groom, pelage_gpu::ShellTargetFormats::own())?;
    let target = ShellTarget::new(&ctx, fur.shell_renderer(), w, h)?;
    let frames = fur.frames().map_or(vec![1], |f| f.frames().to_vec());
    println!(
        "{} hairs from {} guides, {} frames, {}×{} on {}",
        thousands(u64::from(fur.stats().hairs)),
        thousands(fur.guide_count() as u64),
        frames.len(),
        w,
        h,
        ctx.adapter_name()
    );
    let (lo, hi) = fur.bounds();
    let target_point = 0.5 * (lo + hi);
    let mut images = Vec::with_capacity(frames.len());
    let mut stats = Vec::with_capacity(frames.len());
    for (i, &frame) in frames.iter().enumerate() {
        fur.advance_to(&ctx, f64::from(frame))?;
        // From beside the Fox to far away: strands, fewer strands, shells.
        let t = i as f32 / (frames.len().max(2) - 1) as f32;
        let eye =
            target_point + glam::Vec3::new(1.0, 0.35, 0.75).normalize() * (220.0 * 6f32.powf(t));
        let camera = Camera {
            eye,
            target: target_point,
            fov_y_degrees: 30.0,
        };
        let view = ShellView::new(Some(camera), (lo, hi), 0.0, w as f32 / h as f32, None);
        images.push(fur.render(&ctx, &view, &target)?);
        stats.push(fur.stats());
    }
    let gif = out.join("fox-realtime.gif");
    super::shells::write_gif(&gif, &images, 24.0)?;
    // A still: near (strands), the hand-over (both), far (shells).
    let handover = stats
        .iter()
        .position(|s| s.level.shell_opacity > 0.3)
        .unwrap_or(images.len() / 2);
    let mut strip = image::RgbaImage::new(3 * w, h);
    for (k, &i) in [0, handover, images.len() - 1].iter().enumerate() {
        image::GenericImage::copy_from(&mut strip, &images[i], k as u32 * w, 0)?;
    }
    strip.save(out.join("fox-realtime.png"))?;
    let median = |f: fn(&pelage_gpu::RealtimeStats) -> f64| {
        let mut v: Vec<f64> = stats.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    println!(
        "a frame (median): guides {:.1} ms, hairs {:.1} ms, drawing {:.1} ms",
        median(|s| s.sim_ms),
        median(|s| s.eval_ms),
        median(|s| s.draw_ms)
    );
    let first = stats.first().expect("a frame");
    let last = stats.last().expect("a frame");
    println!(
        "near: {} strands; far: {} strands, shells at {:.0} %",
        thousands(u64::from(first.drawn)),
        thousands(u64::from(last.drawn)),
        100.0 * last.level.shell_opacity
    );
    println!(
        "→ {} and {}",
        gif.display(),
        out.join("fox-realtime.png").display()
    );
    println!("done in {:.2} s", start.elapsed().as_secs_f64());
    Ok(())
}

/// `pelage demo fox`: the fox groom grown over the walk cycle into one
/// time-sampled usdc (with the walking skin), rendered to a PNG a frame
/// and a GIF.
fn run_fox(out: &std::path::Path, simulate: bool) -> anyhow::Result<()> {
    let start = Instant::now();
    let (what, groom_text) = if simulate {
        (
            "long fur swinging on the running Khronos Fox (simulated guides)",
            FOX_SIMULATE_GROOM,
        )
    } else {
        ("fur on the walking Khronos Fox", FOX_GROOM)
    };
    println!("pelage {} demo — {what}\n", env!("CARGO_PKG_VERSION"));
    write_fox_files(out, groom_text)?;
    let groom_path = out.join("fox.toml");
    let groom = Groom::load(&groom_path)?;
    let simulating = Instant::now();
    if simulate {
        println!(
            "simulating {} guides on the running skin …",
            thousands(groom.guides().len() as u64)
        );
    }
    let animated = groom
        .animated(None)?
        .context("the fox groom file has an [animation] section")?;
    if simulate {
        println!("simulated in {:.2} s", simulating.elapsed().as_secs_f64());
    }
    let how = if simulate {
        "regrown from them over"
    } else {
        "carried over"
    };
    let output = groom.output_path();
    let animation = animated.animation();
    let frames = animation.frames.frames().to_vec();
    let clip = animated
        .skin()
        .clip()
        .map_or(String::new(), |(n, s)| format!(", clip {n:?} ({s:.2} s)"));
    println!(
        "growing {} hairs from {} guides on {} ({} triangles), {how} frames {}{clip} …",
        thousands(
            animated
                .generator()
                .parts()
                .iter()
                .map(|p| p.hair_count)
                .sum()
        ),
        thousands(groom.guides().len() as u64),
        groom.mesh().name(),
        thousands(groom.mesh().triangle_count() as u64),
        animation.frames,
    );
    let options = groom.usd_options();
    let growing = Instant::now();
    let parts = 0..animated.generator().parts().len();
    let summary = animated.write(&output, parts, &options, true, |_| {})?;
    println!(
        "{} hairs, {} points × {} frames → {} in {:.2} s",
        thousands(summary.hairs),
        thousands(summary.points),
        frames.len(),
        output.display(),
        growing.elapsed().as_secs_f64()
    );
    let folder = out.join("frames");
    let render = super::render::RenderArgs {
        file: Some(output.clone()),
        mesh: None,
        output: folder.clone(),
        size: (640, 400),
        eye: None,
        target: None,
        fov: 30.0,
        point_radius: 1.5,
        texture: Some(out.join("fox.png")),
        no_texture: false,
        frames: Some(animation.frames.clone()),
        fps: options.time_codes_per_second,
    };
    if let Err(e) = super::render::run(&render) {
        // The demo still did its job; say why there are no pictures.
        println!("frames skipped: {e:#}");
    }
    println!("done in {:.2} s\n", start.elapsed().as_secs_f64());
    println!(
        "Next: edit {} and run `pelage groom {}`;",
        groom_path.display(),
        groom_path.display()
    );
    println!(
        "      open {} in Blender (File › Import › USD) or usdview; `pelage bench animation --quick`.",
        output.display()
    );
    Ok(())
}
