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
    #[arg(long, default_value_t = 30.0)]
    pub fov: f32,
    /// Point radius in pixels.
    #[arg(long, default_value_t = 1.5)]
    pub point_radius: f32,
    /// A colour texture (PNG) for the mesh, read at its UVs. The embedded
    /// Spot uses its own unless `--no-texture`.
    #[arg(long)]
    pub texture: Option<PathBuf>,
    /// Draw the embedded Spot without its texture.
    #[arg(long)]
    pub no_texture: bool,
}

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?} is not WIDTHxHEIGHT, e.g. 1280x720"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("{v:?} is not a whole number"))
    };
    Ok((parse(w)?, parse(h)?))
}

pub fn parse_vec3(s: &str) -> Result<[f32; 3], String> {
    let parts: Vec<f32> = s
        .split(',')
        .map(|v| {
            v.trim()
                .parse::<f32>()
                .map_err(|_| format!("{v:?} is not a number"))
        })
        .collect::<Result<_, _>>()?;
    <[f32; 3]>::try_from(parts).map_err(|_| format!("{s:?} is not X,Y,Z"))
}

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
        Some(path) => Some(
            image::open(path)
                .with_context(|| format!("cannot read the texture {}", path.display()))?
                .to_rgba8(),
        ),
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
