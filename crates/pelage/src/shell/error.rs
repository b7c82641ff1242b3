//! [`SceneError`]: a shell scene file that cannot be read, parsed or set
//! up, with its place in the file (`FILE:LINE:COL: KEY: what`).

use crate::settings::{Place, SettingsSource};
use std::fmt;
use std::ops::Range;
use std::path::PathBuf;

/// A shell scene could not be read, parsed or set up. Displays as
/// `FILE:LINE:COLUMN: KEY: what is wrong`; the error underneath, if any,
/// is in its kind and its message in this one's.
///
/// Boxed inside, so results stay small on the happy path.
#[derive(Debug)]
pub struct SceneError(Box<SceneErrorDetails>);

/// Where and what a [`SceneError`] is.
#[derive(Debug)]
pub struct SceneErrorDetails {
    /// The scene file (or a name such as `<spot>`).
    pub path: PathBuf,
    /// Where in the file, when there is a place.
    pub place: Place,
    /// What is wrong.
    pub kind: SceneErrorKind,
}

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
    /// A value that parses but cannot be used.
    #[error("{0}")]
    Invalid(String),
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

impl SceneError {
    /// An error at `place` of the file at `path`.
    pub fn new(path: PathBuf, place: Place, kind: SceneErrorKind) -> Self {
        Self(Box::new(SceneErrorDetails { path, place, kind }))
    }

    /// An error at a span of `source`'s text.
    pub fn at(source: &SettingsSource, span: Range<usize>, kind: SceneErrorKind) -> Self {
        Self::new(source.path.clone(), source.place(span), kind)
    }
}

impl std::ops::Deref for SceneError {
    type Target = SceneErrorDetails;
    fn deref(&self) -> &SceneErrorDetails {
        &self.0
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some((line, column)) = self.place.line {
            write!(f, ":{line}:{column}")?;
        }
        if let Some(key) = &self.place.key {
            write!(f, ": {key}")?;
        }
        write!(f, ": {}", self.kind)
    }
}

/// Prints its cause in its message and returns none as `source()`:
/// front ends print each cause once by walking the chain. The cause stays
/// in its kind for programs that inspect it.
impl std::error::Error for SceneError {}
