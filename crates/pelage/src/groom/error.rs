//! [`GroomError`]: what went wrong with a groom, and where: the file (or
//! the groom's name), line, column and setting.

use crate::error::{Located, Where};
use crate::map::MapError;
use std::path::PathBuf;

/// A groom file could not be read, parsed or set up. Displays as
/// `FILE:LINE:COLUMN: KEY: what is wrong` ([`Located`]).
///
/// The error underneath, when there is one (a [`MapError`], a
/// [`crate::mesh::MeshError`], an I/O error …), is in its kind and its
/// message in this one's.
pub type GroomError = Located<GroomErrorKind>;

impl Located<GroomErrorKind> {
    /// An error in the groom file at `path`, at a line and column (both
    /// 1-based) and the key there, where known.
    pub fn new(
        path: PathBuf,
        line: Option<(usize, usize)>,
        key: Option<String>,
        kind: GroomErrorKind,
    ) -> Self {
        Located::with(path, Where::at(line, key), kind)
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
    /// A value outside what its setting allows: a range rule's refusal
    /// (the same for a groom file and for values built in a program), a
    /// share of the hairs, a frame rate, a shutter offset, a point count.
    #[error("{0}")]
    OutOfRange(String),
    /// A count that is zero or over pelage's limit (docs/limits.md).
    #[error("{0}")]
    Count(crate::limits::CountError),
    /// Settings that cannot be used together, or a setting a feature
    /// needs and does not have (regrow without time-sampled guides,
    /// grooming by hand with sequential ids, a still format for an
    /// animated groom).
    #[error("{0}")]
    Conflict(String),
    /// Counts that must agree and do not (the skin's vertices and the
    /// mesh's, the guides at a frame and at rest, values and vertices).
    #[error("{0}")]
    Mismatch(String),
    /// Something the groom names that is not there (a paint layer, the
    /// face sets its regions are read from).
    #[error("{0}")]
    Missing(String),
    /// A frame range that cannot be read.
    #[error("{0}")]
    Frames(crate::anim::FrameRangeError),
    /// Curves that cannot be made from the values given (guides moved to
    /// points that are not finite).
    #[error("{0}")]
    Curves(crate::curves::CurvesError),
    /// The guides at a frame cannot be made.
    #[error("at frame {frame}: {error}")]
    CurvesAtFrame {
        /// The frame.
        frame: f64,
        /// Why.
        error: crate::curves::CurvesError,
    },
    /// A part's velocities cannot be set.
    #[error("part {part} at frame {frame}: {error}; write velocities = false")]
    Velocities {
        /// The part.
        part: usize,
        /// The frame.
        frame: f64,
        /// Why.
        error: crate::curves::CurvesError,
    },
    /// The guides cannot be simulated as set.
    #[error("{0}")]
    Strands(crate::dynamics::StrandError),
    /// The simulation cache cannot be written (the writer's error, kept
    /// typed inside).
    #[error("cannot write the cache: {0}")]
    Cache(Box<dyn std::error::Error + Send + Sync>),
    /// A brush cannot make its edit.
    #[error("{0}")]
    Brush(BrushRefusal),
    /// Another evaluator of the groom (the GPU's) could not grow it; its
    /// error, kept typed inside.
    #[error("the GPU evaluator: {0}")]
    Evaluator(Box<dyn std::error::Error + Send + Sync>),
    /// Stopped by its caller (a Ctrl-C) before the work was done.
    #[error("stopped {0}")]
    Stopped(String),
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

/// The largest strength a dab takes, either way: the length brush scales
/// guides by `1 + strength` at a dab's centre, so a strength of 10 makes
/// them eleven times as long in one dab.
pub const MAX_BRUSH_STRENGTH: f32 = 10.0;

/// Why a brush cannot make its edit.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum BrushRefusal {
    /// The dab would leave the groom without guides.
    #[error("the dab would delete every guide; a groom needs at least one")]
    DeletesEveryGuide,
    /// A paint brush on a layer the mesh does not have.
    #[error("the mesh has no paint layer '{0}'")]
    NoPaintLayer(String),
    /// A paint layer's name that is not a name (or is a reserved one).
    #[error("paint layer '{0}': use letters, digits and '_' (not x, y, z, nx, ny, nz, s, t, u, v)")]
    LayerName(String),
    /// A dab whose centre, radius, strength or direction cannot be used
    /// (not finite, a radius that is not positive, a strength past
    /// ±[`MAX_BRUSH_STRENGTH`]).
    #[error("{0}")]
    Dab(String),
    /// The add brush would take the groom past pelage's guide limit.
    #[error(
        "adding {adding} guides to {have} would pass pelage's limit of {most} guides (docs/limits.md)"
    )]
    TooManyGuides {
        /// Guides the groom has.
        have: usize,
        /// Guides the dab would add (at most).
        adding: u64,
        /// The limit.
        most: u64,
    },
    /// The part brush on a groom whose regions are face sets.
    #[error(
        "this groom's regions are the mesh's face sets; the part brush paints a 'region' layer: set [regions] map = \"vertex:region\" to paint partings"
    )]
    RegionsAreFaceSets,
}
