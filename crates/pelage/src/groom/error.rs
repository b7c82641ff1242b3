//! [`GroomError`]: what went wrong with a groom, and where: the file (or
//! the groom's name), line, column and setting.

use crate::map::MapError;
use std::fmt;
use std::path::PathBuf;

/// A groom file could not be read, parsed or set up. Displays as
/// `FILE:LINE:COLUMN: KEY: what is wrong`.
///
/// The error underneath, when there is one (a [`MapError`], a
/// [`crate::mesh::MeshError`], an I/O error …), is in its
/// [`kind`](GroomErrorDetails::kind) and its message in this one's.
#[derive(Debug)]
pub struct GroomError(Box<GroomErrorDetails>);

impl fmt::Display for GroomError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        self.0.fmt(f)
    }
}

/// Prints its cause in its message and returns none as `source()`:
/// front ends print each cause once by walking the chain. The cause stays
/// in its kind for programs that inspect it.
impl std::error::Error for GroomError {}

/// Where and what a [`GroomError`] is.
#[derive(Debug)]
pub struct GroomErrorDetails {
    /// The groom file.
    pub path: PathBuf,
    /// Line and column (1-based), where the problem is in the file.
    pub line: Option<(usize, usize)>,
    /// The key there, with its table (`roots.count`).
    pub key: Option<String>,
    /// What is wrong.
    pub kind: GroomErrorKind,
}

impl GroomError {
    /// An error in the groom file at `path`.
    pub fn new(
        path: PathBuf,
        line: Option<(usize, usize)>,
        key: Option<String>,
        kind: GroomErrorKind,
    ) -> Self {
        Self(Box::new(GroomErrorDetails {
            path,
            line,
            key,
            kind,
        }))
    }
}

impl std::ops::Deref for GroomError {
    type Target = GroomErrorDetails;
    fn deref(&self) -> &GroomErrorDetails {
        &self.0
    }
}

impl fmt::Display for GroomErrorDetails {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some((line, column)) = self.line {
            write!(f, ":{line}:{column}")?;
        }
        if let Some(key) = &self.key {
            write!(f, ": {key}")?;
        }
        write!(f, ": {}", self.kind)
    }
}

/// What is wrong with a groom. The variants that wrap another error
/// display its message (and hold it, typed).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GroomErrorKind {
    /// The file could not be read.
    #[error("cannot read the groom file: {0}")]
    Io(std::io::Error),
    /// Not valid TOML, an unknown key, or a value of the wrong type.
    #[error("{0}")]
    Syntax(String),
    /// A value that parses but cannot be used.
    #[error("{0}")]
    Invalid(String),
    /// A map that cannot be read or used.
    #[error("{0}")]
    Map(MapError),
    /// The mesh could not be loaded.
    #[error("{0}")]
    Mesh(crate::mesh::MeshError),
    /// The guides file could not be read.
    #[error("{0}")]
    Guides(crate::io::CurvesReadError),
    /// Guides could not be grown.
    #[error("{0}")]
    GuideGrowth(crate::guides::GuideError),
    /// Roots could not be sampled.
    #[error("{0}")]
    Sample(crate::sample::SampleError),
    /// A hair grew values that are not finite numbers.
    #[error("{0}")]
    NotFinite(String),
}
