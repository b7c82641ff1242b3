//! One module per subcommand: its arguments (clap) and its `run`.

pub mod args;
pub mod convert;
pub mod demo;
pub mod groom;
pub mod guides;
pub mod info;
pub mod render;
pub mod sample;
pub mod shells;
pub mod simulate;
pub mod view;

/// `pelage bench`: the harness is its own crate, `pelage-bench`.
pub use pelage_bench as bench;

use anyhow::Context;
use pelage::Mesh;
use pelage_gpu::{Camera, GpuContext, PreviewScene, PreviewStyle, Renderer};
use std::path::Path;

/// The background of groom previews: white fur on white would vanish.
pub const FUR_BACKGROUND: [f32; 3] = [0.62, 0.66, 0.72];

/// Draws `scene` headless (`camera`: `None` frames it automatically) and
/// writes it to `path` as a PNG, atomically; returns the adapter's name.
pub fn render_png(
    scene: &PreviewScene,
    style: &PreviewStyle,
    camera: Option<Camera>,
    (width, height): (u32, u32),
    path: &Path,
) -> anyhow::Result<String> {
    let ctx = GpuContext::headless()?;
    let image = Renderer::new(&ctx).render(&ctx, scene, style, camera, width, height)?;
    pelage::io::write_atomically(path, |out| {
        image
            .write_to(out, image::ImageFormat::Png)
            .map_err(std::io::Error::other)
    })?;
    Ok(ctx.adapter_name())
}

/// Loads the mesh at `path`, or the embedded Spot when there is none.
pub fn load_mesh(path: Option<&Path>) -> anyhow::Result<Mesh> {
    match path {
        Some(path) => Mesh::load(path).context("cannot load the mesh"),
        None => Ok(pelage::assets::spot()),
    }
}
