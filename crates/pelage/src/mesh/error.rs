//! Errors of the mesh layer: each names the file (or mesh) and, where there
//! is one, the line or element that is wrong.

use std::fmt;

/// Where in a mesh file (or in-memory mesh) a problem was found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    /// The whole file or mesh.
    Whole,
    /// A 1-based line of a text file.
    Line(usize),
    /// An element by kind and 0-based index, e.g. `vertex 12`, `triangle 3`.
    Element {
        /// The element's kind: "vertex", "triangle", "face", "uv", …
        kind: &'static str,
        /// Its 0-based index.
        index: usize,
    },
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Whole => Ok(()),
            Location::Line(line) => write!(f, ":{line}"),
            Location::Element { kind, index } => write!(f, ": {kind} {index}"),
        }
    }
}

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
}

/// "there is 1 vertex" / "there are 3 vertices".
fn count_of(count: usize, singular: &str, plural: &str) -> String {
    match count {
        1 => format!("there is 1 {singular}"),
        n => format!("there are {n} {plural}"),
    }
}

/// A mesh could not be loaded or built. Displays as
/// `FILE[:LINE | : ELEMENT N]: what is wrong`.
///
/// Boxed inside, so `Result<Mesh, MeshError>` stays small on the happy path.
#[derive(Debug)]
pub struct MeshError(Box<MeshErrorInner>);

#[derive(Debug)]
struct MeshErrorInner {
    source_name: String,
    location: Location,
    kind: MeshErrorKind,
}

impl MeshError {
    /// An error at `location` of `source_name` (a path, or a name such as
    /// `embedded spot` for meshes not read from a file).
    pub fn new(source_name: impl Into<String>, location: Location, kind: MeshErrorKind) -> Self {
        Self(Box::new(MeshErrorInner {
            source_name: source_name.into(),
            location,
            kind,
        }))
    }

    /// An error about the whole file or mesh.
    pub fn whole(source_name: impl Into<String>, kind: MeshErrorKind) -> Self {
        Self::new(source_name, Location::Whole, kind)
    }

    /// An error at a 1-based line of a text file.
    pub fn at_line(source_name: impl Into<String>, line: usize, kind: MeshErrorKind) -> Self {
        Self::new(source_name, Location::Line(line), kind)
    }

    /// An error at an element (`vertex 12`, `triangle 3`).
    pub fn at_element(
        source_name: impl Into<String>,
        element: &'static str,
        index: usize,
        kind: MeshErrorKind,
    ) -> Self {
        let location = Location::Element {
            kind: element,
            index,
        };
        Self::new(source_name, location, kind)
    }

    /// The file path or mesh name.
    pub fn source_name(&self) -> &str {
        &self.0.source_name
    }

    /// Where in it.
    pub fn location(&self) -> &Location {
        &self.0.location
    }

    /// What is wrong.
    pub fn kind(&self) -> &MeshErrorKind {
        &self.0.kind
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}{}: {}",
            self.0.source_name, self.0.location, self.0.kind
        )
    }
}

/// Prints its cause in its message and returns none as `source()`:
/// front ends print each cause once by walking the chain. The cause stays
/// in its kind for programs that inspect it.
impl std::error::Error for MeshError {}
