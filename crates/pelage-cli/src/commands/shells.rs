//! `pelage shells`: shell fur (Silva et al., Banisch & Wüthrich) drawn
//! headless — one frame to a PNG, or a sequence (droplets falling, fur
//! drying) to numbered PNGs plus an animated GIF.

use super::render::parse_size;
use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use pelage::shell::ShellScene;
use pelage_gpu::{GpuContext, ShellScenePlayer};
use std::path::{Path, PathBuf};

/// Arguments of `pelage shells`.
#[derive(Debug, Args)]
pub struct ShellsArgs {
    /// A shell scene (TOML, see docs/shells-format.md). Without it: the
    /// embedded Spot with dry fur.
    pub scene: Option<PathBuf>,
    /// Output: a PNG for one frame, a folder with `--frames`.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Draw a sequence of this many frames (overrides the scene's
    /// `[animation] frames`) into the output folder, with `shells.gif`.
    #[arg(long, value_parser = super::args::count_up_to::<u32>(pelage::limits::MAX_FRAMES, "frames"))]
    pub frames: Option<u32>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Draw this moment of the scene (seconds) for a single frame.
    #[arg(long, default_value_t = 0.0, value_parser = super::args::finite)]
    pub time: f32,
    /// Also write the wetness mask (as Silva Fig. 11's insets) next to each
    /// image, as `*-mask.png`.
    #[arg(long)]
    pub mask: bool,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `pelage shells`.
pub fn run(args: &ShellsArgs) -> anyhow::Result<()> {
    let scene = match &args.scene {
        Some(path) => ShellScene::load(path)?,
        None => ShellScene::spot(),
    };
    let ctx = GpuContext::headless()?;
    let (width, height) = args.size;
    let mut player = ShellScenePlayer::new(&ctx, &scene, width, height)?;
    for warning in player.warnings() {
        eprintln!("warning: {warning}");
    }
    let frames = args.frames.unwrap_or(scene.frames);
    println!(
        "{}: {} layers over {} ({} triangles), texture {}² × {}, on {}",
        args.scene
            .as_deref()
            .map_or("embedded spot".into(), |p| p.display().to_string()),
        scene.fur.layers,
        scene.mesh.name(),
        scene.mesh.triangle_count(),
        scene.texture.resolution,
        scene.texture.layers,
        ctx.adapter_name()
    );
    if args.frames.is_none() && frames == 1 {
        let image = player.render_at(&ctx, args.time)?;
        write_png(&args.output, &image)?;
        if args.mask {
            write_png(&mask_path(&args.output), &player.wetness().preview())?;
        }
        println!("wrote {}", args.output.display());
        return Ok(());
    }

    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create the folder {}", args.output.display()))?;
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::new(u64::from(frames));
        bar.set_style(
            ProgressStyle::with_template("{bar:40} frame {pos}/{len} {eta} left")
                .expect("the template is valid"),
        );
        bar
    };
    let mut images = Vec::with_capacity(frames as usize);
    for frame in 0..frames {
        let time = frame as f32 / scene.fps;
        let image = player.render_at(&ctx, time)?;
        let path = args.output.join(format!("frame-{frame:04}.png"));
        write_png(&path, &image)?;
        if args.mask {
            write_png(&mask_path(&path), &player.wetness().preview())?;
        }
        images.push(image);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let gif = args.output.join("shells.gif");
    write_gif(&gif, &images, scene.fps)?;
    println!(
        "wrote {} frames ({:.1} s at {} fps) to {} and {}",
        frames,
        frames as f32 / scene.fps,
        scene.fps,
        args.output.display(),
        gif.display()
    );
    Ok(())
}

fn mask_path(image: &Path) -> PathBuf {
    let stem = image
        .file_stem()
        .map_or("shells".into(), |s| s.to_string_lossy());
    image.with_file_name(format!("{stem}-mask.png"))
}

fn write_png(path: &Path, image: &image::RgbaImage) -> anyhow::Result<()> {
    pelage::io::write_atomically(path, |out| {
        image
            .write_to(out, image::ImageFormat::Png)
            .map_err(std::io::Error::other)
    })
    .with_context(|| format!("cannot write {}", path.display()))
}

/// An animated GIF of the frames, looping, at `fps`.
pub fn write_gif(path: &Path, images: &[image::RgbaImage], fps: f32) -> anyhow::Result<()> {
    use image::codecs::gif::{GifEncoder, Repeat};
    let delay = image::Delay::from_numer_denom_ms(1000, fps.max(0.1).round() as u32);
    pelage::io::write_atomically(path, |out| {
        let mut encoder = GifEncoder::new_with_speed(out, 20);
        encoder
            .set_repeat(Repeat::Infinite)
            .map_err(std::io::Error::other)?;
        for image in images {
            encoder
                .encode_frame(image::Frame::from_parts(image.clone(), 0, 0, delay))
                .map_err(std::io::Error::other)?;
        }
        Ok(())
    })
    .with_context(|| format!("cannot write {}", path.display()))
}
