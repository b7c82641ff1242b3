//! Errors of the mesh layer: each names the file (or mesh) and, where there
//! is one, the line or element that is wrong.

use crate::error::{Located, Where};
use std::path::PathBuf;

/// What is wrong with a mesh.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshErrorKind {
    /// The file could not be opened or read.
    #[error("cannot read the file: {0}")]
    Io(std::io::Error),
    /// The extension names no format pelage reads.
    #[error(
        "unknown mesh format {extension:?}; pelage reads .obj, .ply, .gltf, .glb, .usda, .usdc and .usd"
    )]
    UnknownFormat {
        /// The extension found (may be empty).
        extension: String,
    },
    /// A statement or value could not be parsed.
    #[error("{0}")]
    Syntax(String),
    /// An index refers to an element that does not exist.
    #[error("{what} index {index} is out of range: {}{hint}", count_of(*.count, .what, .what_plural))]
    IndexOutOfRange {
        /// What is indexed: "vertex", "uv", "normal".
        what: &'static str,
        /// Its plural: "vertices", "uvs", "normals".
        what_plural: &'static str,
        /// The index as written in the file.
        index: i64,
        /// How many elements of that kind exist.
        count: usize,
        /// An extra explanation (e.g. OBJ indices start at 1).
        hint: &'static str,
    },
    /// A coordinate is NaN or infinite.
    #[error("{what} has a non-finite value (NaN or infinity)")]
    NonFinite {
        /// Which value: "vertex position", "texture coordinate", …
        what: &'static str,
    },
    /// The mesh has no vertices or no triangles.
    #[error("the mesh is empty: {0}")]
    Empty(&'static str),
    /// Something the format allows but pelage cannot use.
    #[error("{0}")]
    Unsupported(String),
    /// An animation clip the skin does not have, or a clip asked of a
    /// skin that plays none (only glTF skins have clips): the setting to
    /// fix is the clip's, not the mesh's.
    #[error("{0}")]
    Clip(String),
    /// The file is inconsistent with itself (counts that do not add up, …).
    #[error("{0}")]
    Inconsistent(String),
    /// A reader of another layer refused the file (a USD stage's skin read
    /// by the curves reader): its error, kept typed inside.
    #[error("{0}")]
    Read(Box<dyn std::error::Error + Send + Sync>),
}

/// "there is 1 vertex" / "there are 3 vertices".
fn count_of(count: usize, singular: &str, plural: &str) -> String {
    match count {
        1 => format!("there is 1 {singular}"),
        n => format!("there are {n} {plural}"),
    }
}

/// A mesh could not be loaded or built. Displays as
/// `FILE[:LINE | : ELEMENT N]: what is wrong` ([`Located`]; the source is
/// a path, or a name such as `embedded spot` for a mesh not read from a
/// file).
pub type MeshError = Located<MeshErrorKind>;

impl Located<MeshErrorKind> {
    /// An error at `location` of `source_name`.
    pub fn new(source_name: impl Into<PathBuf>, location: Where, kind: MeshErrorKind) -> Self {
        Located::with(source_name, location, kind)
    }

    /// An error about the whole file or mesh.
    pub fn whole(source_name: impl Into<PathBuf>, kind: MeshErrorKind) -> Self {
        Self::new(source_name, Where::whole(), kind)
    }

    /// An error at a 1-based line of a text file.
    pub fn at_line(source_name: impl Into<PathBuf>, line: usize, kind: MeshErrorKind) -> Self {
        Self::new(source_name, Where::line(line), kind)
    }

    /// An error at an element (`vertex 12`, `triangle 3`).
    pub fn at_element(
        source_name: impl Into<PathBuf>,
        element: &'static str,
        index: usize,
        kind: MeshErrorKind,
    ) -> Self {
        Self::new(source_name, Where::element(element, index), kind)
    }
}
