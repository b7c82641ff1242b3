//! The options of a USD layer pelage writes (curve basis and wrap, up
//! axis, scale, frame rate, the hair material) and the ways a prim can be
//! refused ([`PrimWriteError`]), shared by the usda and usdc writers, the
//! attribute lists of `usd_schema` and the Alembic writer.

use crate::Curves;
use crate::mesh::Mesh;

/// How the points of each curve are interpolated (USD `type` + `basis`);
/// `linear` or `catmull-rom` in groom files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CurveBasis {
    /// Straight segments between the points.
    Linear,
    /// A cubic Catmull-Rom spline through the points (also spelled
    /// `catmullRom`, as USD does).
    #[default]
    #[serde(alias = "catmullRom")]
    CatmullRom,
}

impl CurveBasis {
    /// Every basis's name, as groom files, flags and Python spell it.
    pub const NAMES: [&'static str; 2] = ["catmull-rom", "linear"];
}

impl std::fmt::Display for CurveBasis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            CurveBasis::Linear => "linear",
            CurveBasis::CatmullRom => "catmull-rom",
        })
    }
}

impl std::str::FromStr for CurveBasis {
    type Err = String;

    /// `catmull-rom` (or USD's `catmullRom`) or `linear`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "catmull-rom" | "catmullRom" => Ok(CurveBasis::CatmullRom),
            "linear" => Ok(CurveBasis::Linear),
            other => Err(format!(
                "basis {other:?}: use \"catmull-rom\" or \"linear\""
            )),
        }
    }
}

/// How curve ends are treated (USD `wrap`; only meaningful for cubic
/// curves).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UsdWrap {
    /// The spline passes through the first and last points (USD adds
    /// phantom end points). Blender writes and reads this.
    #[default]
    Pinned,
    /// The first and last points only steer the ends; a curve needs at
    /// least four points.
    Nonperiodic,
}

/// The stage's up axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// Y up (Maya, Houdini, USD's default).
    #[default]
    Y,
    /// Z up (Blender).
    Z,
}

/// Stage-wide choices of a USD file.
#[derive(Debug, Clone, PartialEq)]
pub struct UsdOptions {
    /// Curve interpolation.
    pub basis: CurveBasis,
    /// End treatment of cubic curves.
    pub wrap: UsdWrap,
    /// `upAxis` stage metadata.
    pub up_axis: UpAxis,
    /// `metersPerUnit` stage metadata.
    pub meters_per_unit: f64,
    /// Name of the default prim (an `Xform`) holding the parts.
    pub root: String,
    /// `timeCodesPerSecond` (and `framesPerSecond`) of an animated stage.
    pub time_codes_per_second: f64,
    /// Bind curves that carry hair-shading values to a MaterialX hair
    /// material written beside them (`hair_material`).
    pub hair_material: bool,
    /// The layer's `documentation` (USD) or the archive's description
    /// (Alembic), in place of "Written by pelage VERSION": what a farm
    /// run's part file says of the groom that grew it. Plain text, no
    /// `;`, `=` or `"`.
    pub documentation: Option<String>,
}

impl Default for UsdOptions {
    fn default() -> Self {
        Self {
            basis: CurveBasis::default(),
            wrap: UsdWrap::default(),
            up_axis: UpAxis::default(),
            meters_per_unit: 1.0,
            root: "groom".into(),
            time_codes_per_second: 24.0,
            hair_material: true,
            documentation: None,
        }
    }
}

impl UsdOptions {
    /// Refuses options no file can hold: a root name USD does not accept,
    /// and a scale or frame rate that is not a positive number (a file
    /// with `metersPerUnit = NaN` would be written and then misread).
    pub fn check(&self) -> Result<(), PrimWriteError> {
        check_name(&self.root)?;
        for (what, value) in [
            ("metersPerUnit", self.meters_per_unit),
            (
                "timeCodesPerSecond (frames per second)",
                self.time_codes_per_second,
            ),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(PrimWriteError::BadSetting(format!(
                    "{what} must be a positive number, not {value}"
                )));
            }
        }
        Ok(())
    }

    /// The fewest points a curve may have under these options.
    pub fn min_points_per_curve(&self) -> usize {
        match (self.basis, self.wrap) {
            (CurveBasis::Linear, _) | (CurveBasis::CatmullRom, UsdWrap::Pinned) => 2,
            (CurveBasis::CatmullRom, UsdWrap::Nonperiodic) => 4,
        }
    }
}

/// The I/O error underneath, or the writer's refusal as one (for callers
/// whose writes are all I/O to them).
impl From<PrimWriteError> for std::io::Error {
    fn from(error: PrimWriteError) -> Self {
        match error {
            PrimWriteError::Io(e) => e,
            other => std::io::Error::other(other),
        }
    }
}

/// A part or mesh could not be written as a prim (of a USD layer or an
/// Alembic archive).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PrimWriteError {
    /// Writing failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A prim name USD does not accept.
    #[error(
        "{0:?} is not a valid USD prim name (letters, digits and '_', not starting with a digit)"
    )]
    BadName(String),
    /// Two prims with one name.
    #[error("a prim named {0:?} was already written")]
    DuplicateName(String),
    /// A setting or value USD cannot hold (a NaN time, a zero scale).
    #[error("{0}")]
    BadSetting(String),
    /// A frame of an animated part whose curves differ from the first
    /// frame's.
    #[error(
        "part {part:?} at time {time}: {} curves and {} points, but its first frame had {} and {} (an animated part keeps its curves)",
        curves.1, points.1, curves.0, points.0
    )]
    FrameMismatch {
        /// The part.
        part: String,
        /// The frame's time.
        time: f64,
        /// Curves in the first frame and in this one.
        curves: (usize, usize),
        /// Points in the first frame and in this one.
        points: (usize, usize),
    },
    /// A curve too short for the basis.
    #[error(
        "part {part:?}: curve {curve} has {points} points; {basis} curves need at least {min} ({})",
        short_curve_hint(.basis)
    )]
    ShortCurve {
        /// The part.
        part: String,
        /// The curve's index in the part.
        curve: usize,
        /// Its point count.
        points: usize,
        /// What the basis needs.
        min: usize,
        /// The basis and wrap, in words.
        basis: &'static str,
    },
}

/// What to do about a curve too short for `basis`: a curve shorter than
/// linear curves need has no basis to turn to.
fn short_curve_hint(basis: &str) -> &'static str {
    if basis == "linear" {
        "remove the curve, or give it a second point"
    } else {
        "write linear curves (--basis linear), or resample to more points"
    }
}

impl PrimWriteError {
    /// Refuses a frame time that is not a number.
    pub(crate) fn check_time(part: &str, time: f64) -> Result<(), Self> {
        if time.is_finite() {
            return Ok(());
        }
        Err(Self::BadSetting(format!(
            "part {part:?}: the time {time} is not a number"
        )))
    }

    /// Refuses a frame of an animated mesh whose vertex or triangle count
    /// differs from its first frame's (`first`: those two counts).
    pub(crate) fn check_mesh_frame(
        name: &str,
        time: f64,
        first: &[u32],
        mesh: &Mesh,
    ) -> Result<(), Self> {
        let shape = [mesh.vertex_count() as u32, mesh.triangle_count() as u32];
        if first == shape {
            return Ok(());
        }
        Err(Self::BadSetting(format!(
            "mesh {name:?} at time {time}: {} vertices and {} triangles where the first frame had {} and {}",
            shape[0], shape[1], first[0], first[1]
        )))
    }

    /// Refuses a frame of an animated part whose curves differ from its
    /// first frame's (`first`: that frame's offsets).
    pub(crate) fn check_frame(
        part: &str,
        time: f64,
        first: &[u32],
        curves: &Curves,
    ) -> Result<(), Self> {
        if first == curves.offsets() {
            return Ok(());
        }
        Err(Self::FrameMismatch {
            part: part.to_string(),
            time,
            curves: (first.len().saturating_sub(1), curves.curve_count()),
            points: (*first.last().unwrap_or(&0) as usize, curves.points().len()),
        })
    }
}

/// USD prim names: an identifier.
pub(crate) fn check_name(name: &str) -> Result<(), PrimWriteError> {
    let mut chars = name.chars();
    let ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(PrimWriteError::BadName(name.to_string()))
    }
}
