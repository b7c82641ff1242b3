//! `pelage render`: a picture of a mesh, a point cloud or curves (headless,
//! wgpu).

use super::load_mesh;
use anyhow::Context;
use clap::Args;
use pelage::io::{CurvesFormat, ply_element_count, read_curves, read_points_ply};
use pelage_gpu::{Camera, PreviewScene, PreviewStyle};
use std::path::{Path, PathBuf};

/// Arguments of `pelage render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// A mesh (.obj, .ply, .gltf, .glb), a points PLY (as `pelage sample`
    /// writes) or curves (.usda, .usdc, .usd, .hair, or a PLY with edges).
    /// Without it, the embedded Spot.
    pub file: Option<PathBuf>,
    /// A mesh to draw under the points or curves (`spot` for the embedded
    /// one).
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// Output PNG.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Camera position, X,Y,Z (default: framed automatically).
    #[arg(long, value_parser = parse_vec3)]
    pub eye: Option<[f32; 3]>,
    /// Camera target, X,Y,Z (default: the centre of what is drawn).
    #[arg(long, value_parser = parse_vec3)]
    pub target: Option<[f32; 3]>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 30.0, value_parser = super::args::field_of_view)]
    pub fov: f32,
    /// Point radius in pixels.
    #[arg(long, default_value_t = 1.5, value_parser = super::args::positive_f32)]
    pub point_radius: f32,
    /// A colour texture (PNG) for the mesh, read at its UVs. The embedded
    /// Spot uses its own unless `--no-texture`.
    #[arg(long)]
    pub texture: Option<PathBuf>,
    /// Draw the embedded Spot without its texture.
    #[arg(long)]
    pub no_texture: bool,
    /// Render these frames of an animated USD file (e.g. 1-24): OUTPUT is
    /// then a folder that gets one PNG a frame and an animated GIF. The
    /// file's time-sampled `skin` mesh (`[output] with_mesh`) is drawn
    /// under the curves, moving with them.
    #[arg(long, value_name = "RANGE", allow_hyphen_values = true)]
    pub frames: Option<pelage::anim::FrameRange>,
    /// Frames per second of the GIF.
    #[arg(long, default_value_t = 24.0, value_parser = super::args::positive)]
    pub fps: f64,
}

pub use super::args::{size as parse_size, vec3 as parse_vec3};

/// What a file given to `pelage render` holds.
#[derive(Debug, PartialEq)]
pub(crate) enum FileKind {
    Mesh,
    Points,
    Curves,
}

pub(crate) fn file_kind(path: &Path) -> anyhow::Result<FileKind> {
    let count = |element| {
        ply_element_count(path, element).with_context(|| format!("cannot read {}", path.display()))
    };
    Ok(match CurvesFormat::from_path(path) {
        Some(CurvesFormat::Ply) if count("face")? > 0 => FileKind::Mesh,
        Some(CurvesFormat::Ply) if count("edge")? > 0 => FileKind::Curves,
        Some(CurvesFormat::Ply) => FileKind::Points,
        Some(_) => FileKind::Curves,
        None => FileKind::Mesh,
    })
}

pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    if let Some(frames) = &args.frames {
        return run_frames(args, frames);
    }
    let under = || -> anyhow::Result<Option<pelage::Mesh>> {
        match args.mesh.as_deref() {
            None => Ok(None),
            Some(m) if m == Path::new("spot") => Ok(Some(load_mesh(None)?)),
            Some(m) => Ok(Some(load_mesh(Some(m))?)),
        }
    };
    let kind = match &args.file {
        Some(file) => file_kind(file)?,
        None => FileKind::Mesh,
    };
    let (points, curves, mesh) = match (&args.file, kind) {
        (Some(file), FileKind::Points) => {
            let points = read_points_ply(file).context("cannot load the points")?;
            (points, None, under()?)
        }
        (Some(file), FileKind::Curves) => {
            let curves = read_curves(file).context("cannot load the curves")?;
            (Vec::new(), Some(curves), under()?)
        }
        (file, _) => (Vec::new(), None, Some(load_mesh(file.as_deref())?)),
    };
    let texture = match &args.texture {
        Some(path) => Some(load_texture(path)?),
        // The embedded Spot gets its own texture.
        None if (args.file.is_none() || args.mesh.as_deref() == Some(Path::new("spot")))
            && !args.no_texture =>
        {
            Some(image::load_from_memory(pelage::assets::SPOT_TEXTURE_PNG)?.to_rgba8())
        }
        None => None,
    };
    let scene = PreviewScene {
        mesh: mesh.as_ref(),
        points: &points,
        curves: curves.as_ref(),
        skin_texture: texture.as_ref(),
    };
    let (width, height) = args.size;
    let camera = match (args.eye, scene.bounds()) {
        (Some(eye), Some((lo, hi))) => Some(Camera {
            eye: eye.into(),
            target: args.target.map_or(0.5 * (lo + hi), Into::into),
            fov_y_degrees: args.fov,
        }),
        _ => None,
    };
    let style = PreviewStyle {
        point_radius: args.point_radius,
        ..Default::default()
    };
    let adapter = super::render_png(&scene, &style, camera, (width, height), &args.output)?;
    println!(
        "wrote {} ({width}×{height}, {} on {})",
        args.output.display(),
        match (&mesh, points.len(), &curves) {
            (mesh, _, Some(c)) => format!(
                "{} curves{}",
                c.curve_count(),
                mesh.as_ref()
                    .map(|m| format!(" on {}", m.name()))
                    .unwrap_or_default()
            ),
            (Some(m), 0, None) => m.name().to_string(),
            (Some(m), n, None) => format!("{n} points on {}", m.name()),
            (None, n, None) => format!("{n} points"),
        },
        adapter
    );
    Ok(())
}

/// The skin's colour texture (`--texture`).
fn load_texture(path: &Path) -> anyhow::Result<image::RgbaImage> {
    Ok(pelage::map::open_image(path)
        .with_context(|| format!("cannot read the texture {}", path.display()))?
        .to_rgba8())
}

/// `pelage render FILE --frames RANGE -o DIR`: one PNG a frame of an
/// animated USD file, with its animated skin, from one fixed camera, and
/// the frames as a GIF.
fn run_frames(args: &RenderArgs, frames: &pelage::anim::FrameRange) -> anyhow::Result<()> {
    use pelage::anim::{AnimatedSkin, SkinOptions};
    use pelage::io::UsdCurvesSequence;
    let Some(file) = &args.file else {
        anyhow::bail!("--frames renders an animated USD file: give its path");
    };
    if !matches!(
        CurvesFormat::from_path(file),
        Some(CurvesFormat::Usda | CurvesFormat::Usdc)
    ) {
        anyhow::bail!(
            "{}: --frames reads animated USD (.usdc, .usd, .usda), as `pelage groom` writes with [animation]",
            file.display()
        );
    }
    if !(args.fps.is_finite() && args.fps > 0.0) {
        anyhow::bail!("--fps {}: it must be a positive number", args.fps);
    }
    let curves = UsdCurvesSequence::open(file).context("cannot load the curves")?;
    // The skin written beside the curves moves with them; a --mesh stands
    // still under them.
    let skin = match args.mesh.as_deref() {
        Some(m) if m == Path::new("spot") => Some(AnimatedSkin::still(&load_mesh(None)?)),
        Some(m) => {
            Some(AnimatedSkin::load(m, &SkinOptions::default()).context("cannot load the mesh")?)
        }
        None => AnimatedSkin::load(file, &SkinOptions::default()).ok(),
    };
    let out = &args.output;
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create the folder {}", out.display()))?;
    let (width, height) = args.size;
    // One camera for every frame: framed on the skin's (or the first
    // frame's) bounds over all frames.
    let mut bounds: Option<(glam::Vec3, glam::Vec3)> = None;
    let mut grow = |lo: glam::Vec3, hi: glam::Vec3| {
        bounds = Some(match bounds {
            Some((a, b)) => (a.min(lo), b.max(hi)),
            None => (lo, hi),
        });
    };
    for &f in frames.frames() {
        if let Some(skin) = &skin {
            let m = skin.mesh_at(f64::from(f))?;
            let (lo, hi) = m.bounds();
            grow(lo, hi);
        }
    }
    let first = curves.at(f64::from(frames.first()))?;
    if let Some((lo, hi)) = first.bounds() {
        grow(lo, hi);
    }
    let Some((lo, hi)) = bounds else {
        anyhow::bail!("{}: nothing to draw", file.display());
    };
    let camera = match args.eye {
        Some(eye) => Camera {
            eye: eye.into(),
            target: args.target.map_or(0.5 * (lo + hi), Into::into),
            fov_y_degrees: args.fov,
        },
        None => Camera::framing(lo, hi, width as f32 / height as f32),
    };
    let style = PreviewStyle {
        background: super::FUR_BACKGROUND,
        ..Default::default()
    };
    let texture = args.texture.as_deref().map(load_texture).transpose()?;
    let ctx = pelage_gpu::GpuContext::headless()?;
    let renderer = pelage_gpu::Renderer::new(&ctx);
    let stem = file
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("frames")
        .to_string();
    let mut images = Vec::with_capacity(frames.len());
    for &f in frames.frames() {
        let time = f64::from(f);
        let hairs = curves.at(time)?;
        let mesh = skin.as_ref().map(|s| s.mesh_at(time)).transpose()?;
        let scene = PreviewScene {
            mesh: mesh.as_ref(),
            points: &[],
            curves: Some(&hairs),
            skin_texture: texture.as_ref(),
        };
        let image = renderer.render(&ctx, &scene, &style, Some(camera), width, height)?;
        let png = out.join(format!("{stem}.{f:04}.png"));
        pelage::io::write_atomically(&png, |w| {
            image
                .write_to(w, image::ImageFormat::Png)
                .map_err(std::io::Error::other)
        })?;
        images.push(image);
    }
    let gif = out.join(format!("{stem}.gif"));
    let delay = image::Delay::from_numer_denom_ms(1000, args.fps.round().max(1.0) as u32);
    pelage::io::write_atomically(&gif, |w| {
        let mut encoder = image::codecs::gif::GifEncoder::new_with_speed(w, 10);
        encoder
            .set_repeat(image::codecs::gif::Repeat::Infinite)
            .map_err(std::io::Error::other)?;
        for image in &images {
            let frame = image::Frame::from_parts(image.clone(), 0, 0, delay);
            encoder.encode_frame(frame).map_err(std::io::Error::other)?;
        }
        Ok(())
    })?;
    println!(
        "wrote {} frames ({width}×{height}) and {} to {} (rendered on {})",
        images.len(),
        gif.display(),
        out.display(),
        ctx.adapter_name()
    );
    Ok(())
}
