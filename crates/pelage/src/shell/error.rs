//! [`SceneError`]: a shell scene file that cannot be read, parsed or set
//! up, with its place in the file (`FILE:LINE:COL: KEY: what`).

use crate::error::{Located, Where};
use crate::settings::SettingsSource;
use std::ops::Range;
use std::path::PathBuf;

/// A shell scene could not be read, parsed or set up. Displays as
/// `FILE:LINE:COLUMN: KEY: what is wrong` ([`Located`]); the error
/// underneath, if any, is in its kind and its message in this one's.
pub type SceneError = Located<SceneErrorKind>;

/// What is wrong with a shell scene.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneErrorKind {
    /// The file could not be read.
    #[error("cannot read the scene file: {0}")]
    Io(std::io::Error),
    /// Not valid TOML, an unknown key, or a value of the wrong type (an
    /// unknown name lists the accepted ones).
    #[error("{0}")]
    Syntax(String),
    /// A value outside what its setting allows (a range rule's refusal,
    /// a length that is not positive, texels over pelage's limit).
    #[error("{0}")]
    OutOfRange(String),
    /// Settings that cannot be used together (a clip without a skin, the
    /// implicit solver on the GPU for tips that are joined).
    #[error("{0}")]
    Conflict(String),
    /// Something the scene needs that is not there (the mesh's UVs).
    #[error("{0}")]
    Missing(String),
    /// Droplets that cannot be placed on the mesh.
    #[error("droplets[{index}]: cannot place droplets: {error}")]
    Droplets {
        /// The `[[droplets]]` entry.
        index: usize,
        /// Why.
        error: crate::sample::SampleError,
    },
    /// The mesh could not be loaded.
    #[error("{0}")]
    Mesh(crate::mesh::MeshError),
    /// An image (colour texture, droplet mask) could not be read.
    #[error("{path}: {error}")]
    Image {
        /// The image file.
        path: PathBuf,
        /// Why.
        error: image::ImageError,
    },
}

impl Located<SceneErrorKind> {
    /// An error at `place` of the file at `path`.
    pub fn new(path: PathBuf, place: Where, kind: SceneErrorKind) -> Self {
        Located::with(path, place, kind)
    }

    /// An error at a span of `source`'s text.
    pub fn at(source: &SettingsSource, span: Range<usize>, kind: SceneErrorKind) -> Self {
        Self::new(source.path.clone(), source.place(span), kind)
    }
}
