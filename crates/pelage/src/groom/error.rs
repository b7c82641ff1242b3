//! [`GroomError`]: what went wrong with a groom, and where: the file (or
//! the groom's name), line, column and setting.

use crate::map::MapError;
use std::fmt;
use std::path::PathBuf;

/// A groom file could not be read, parsed or set up. Displays as
/// `FILE:LINE:COLUMN: KEY: what is wrong`.
///
/// Its [`source`](std::error::Error::source) is the error underneath, when
/// there is one (a [`MapError`], a [`crate::mesh::MeshError`], an I/O
/// error …), whose message the display already includes.
#[derive(Debug)]
pub struct GroomError(Box<GroomErrorDetails>);

impl fmt::Display for GroomError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for GroomError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        std::error::Error::source(&self.0.kind)
    }
}

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
/// display its message and give it as their `source`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GroomErrorKind {
    /// The file could not be read.
    #[error("cannot read the groom file: {0}")]
    Io(#[source] std::io::Error),
    /// Not valid TOML, an unknown key, or a value of the wrong type.
    #[error("{0}")]
    Syntax(String),
    /// A value that parses but cannot be used.
    #[error("{0}")]
    Invalid(String),
    /// A map that cannot be read or used.
    #[error("{0}")]
    Map(#[source] MapError),
    /// The mesh could not be loaded.
    #[error("{0}")]
    Mesh(#[source] crate::mesh::MeshError),
    /// The guides file could not be read.
    #[error("{0}")]
    Guides(#[source] crate::io::CurvesReadError),
    /// Guides could not be grown.
    #[error("{0}")]
    GuideGrowth(#[source] crate::guides::GuideError),
    /// Roots could not be sampled.
    #[error("{0}")]
    Sample(#[source] crate::sample::SampleError),
    /// A hair grew values that are not finite numbers.
    #[error("{0}")]
    NotFinite(String),
}
