//! One module per subcommand: its arguments (clap) and its `run`.

pub mod bench;
pub mod convert;
pub mod demo;
pub mod groom;
pub mod guides;
pub mod info;
pub mod render;
pub mod sample;

use anyhow::Context;
use pelage::Mesh;
use std::path::Path;

/// Loads the mesh at `path`, or the embedded Spot when there is none.
pub fn load_mesh(path: Option<&Path>) -> anyhow::Result<Mesh> {
    match path {
        Some(path) => Mesh::load(path).context("cannot load the mesh"),
        None => Ok(pelage::assets::spot()),
    }
}
