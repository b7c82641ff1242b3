//! The error of every curve reader: names the file and, where there is one,
//! the line, field or element that is wrong.

use crate::curves::CurvesError;
use crate::mesh::Location;
use std::fmt;
use std::path::Path;

/// What is wrong with a curves file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CurvesReadErrorKind {
    /// The file could not be opened or read.
    #[error("cannot read the file: {0}")]
    Io(std::io::Error),
    /// The extension names no format pelage reads curves from.
    #[error(
        "unknown curves format {extension:?}; pelage reads curves from .usda, .usdc, .usd, .abc, .hair and .ply"
    )]
    UnknownFormat {
        /// The extension found (may be empty).
        extension: String,
    },
    /// The text or header could not be parsed.
    #[error("{0}")]
    Syntax(String),
    /// Counts or sizes that do not add up; says which field.
    #[error("{0}")]
    Inconsistent(String),
    /// Something the format allows but pelage cannot use.
    #[error("{0}")]
    Unsupported(String),
    /// The file holds no curves.
    #[error("the file holds no curves{0}")]
    Empty(&'static str),
    /// The arrays read do not make valid curves (NaN, …).
    #[error(transparent)]
    Curves(#[from] CurvesError),
}

/// A curves file could not be read. Displays as
/// `FILE[:LINE | : ELEMENT N]: what is wrong`.
#[derive(Debug)]
pub struct CurvesReadError(Box<(String, Location, CurvesReadErrorKind)>);

impl CurvesReadError {
    /// An error at `location` of the file at `path`.
    pub fn new(path: &Path, location: Location, kind: CurvesReadErrorKind) -> Self {
        Self(Box::new((path.display().to_string(), location, kind)))
    }

    /// An error about the whole file.
    pub fn whole(path: &Path, kind: CurvesReadErrorKind) -> Self {
        Self::new(path, Location::Whole, kind)
    }

    /// The file.
    pub fn source_name(&self) -> &str {
        &self.0.0
    }

    /// Where in it.
    pub fn location(&self) -> &Location {
        &self.0.1
    }

    /// What is wrong.
    pub fn kind(&self) -> &CurvesReadErrorKind {
        &self.0.2
    }
}

impl fmt::Display for CurvesReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}: {}", self.0.0, self.0.1, self.0.2)
    }
}

/// Prints its cause in its message and returns none as `source()`:
/// front ends print each cause once by walking the chain. The cause stays
/// in its kind for programs that inspect it.
impl std::error::Error for CurvesReadError {}
