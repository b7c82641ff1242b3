//! Curves files by extension: one entry point to read guides or any curves
//! pelage understands, and one to write a finished groom in any format.

use super::read_error::{CurvesReadError, CurvesReadErrorKind};
use super::usd_options::PrimWriteError;
use super::{
    AbcWriter, HairFile, PrimWriter, UsdOptions, UsdaWriter, UsdcWriter, WriteError,
    read_abc_curves, read_curves_ply, read_usd_curves, write_atomically, write_curves_ply,
    write_pbrt, write_rib,
};
use crate::curves::join;
use crate::{Curves, Mesh};
use std::io::{Seek, Write};
use std::path::Path;

/// A curves file format, chosen by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurvesFormat {
    /// `.usda`: text USD.
    Usda,
    /// `.usdc`, and `.usd` as in Pixar's tools: binary USD when writing
    /// (reading sniffs text or binary).
    Usdc,
    /// Alembic (Ogawa) `.abc`.
    Abc,
    /// Cem Yuksel's `.hair`.
    Hair,
    /// `.ply` with vertex and edge elements.
    Ply,
    /// RenderMan `.rib`: write only.
    Rib,
    /// pbrt-v4 `.pbrt`: write only.
    Pbrt,
}

impl CurvesFormat {
    /// What to say of an output whose extension names no format pelage
    /// writes (every front end says the same).
    pub const UNKNOWN_FOR_WRITING: &'static str = "unknown curves format; pelage writes .usdc (or .usd), .usda, .abc, .hair, .ply, .rib and .pbrt";

    /// What to say of an output that must hold time samples (an animated
    /// groom, simulated guides) and cannot.
    pub const NO_TIME_SAMPLES: &'static str = "written with time samples to .usdc, .usd or .abc";

    /// Whether pelage writes time samples in this format (an animated
    /// groom, simulated guides): binary USD and Alembic. Text USD could
    /// hold them, but a groom's frames in text would be too large to
    /// read back.
    pub fn writes_time_samples(self) -> bool {
        matches!(self, Self::Usdc | Self::Abc)
    }

    /// Whether a groom's parts go into the file one at a time (a prim or
    /// object each, one part in memory at a time): USD and Alembic. The
    /// other formats hold one set of curves, so the parts are joined
    /// first.
    pub fn streams_parts(self) -> bool {
        matches!(self, Self::Usda | Self::Usdc | Self::Abc)
    }

    /// Whether a farm's runs are assembled by joining their objects into
    /// one file of this format (Alembic, which has no references) rather
    /// than by a USD layer that references each run's file.
    pub fn assembly_joins_parts(self) -> bool {
        matches!(self, Self::Abc)
    }

    /// The extension files of this format are written with.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Usda => "usda",
            Self::Usdc => "usdc",
            Self::Abc => "abc",
            Self::Hair => "hair",
            Self::Ply => "ply",
            Self::Rib => "rib",
            Self::Pbrt => "pbrt",
        }
    }

    /// The format a path's extension names, if any.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "usda" => Self::Usda,
            "usdc" | "usd" => Self::Usdc,
            "abc" => Self::Abc,
            "hair" => Self::Hair,
            "ply" => Self::Ply,
            "rib" => Self::Rib,
            "pbrt" => Self::Pbrt,
            _ => return None,
        })
    }
}

/// Reads curves from a `.usda`, `.usdc`, `.usd`, `.abc`, `.hair` or `.ply`
/// file.
pub fn read_curves(path: &Path) -> Result<Curves, CurvesReadError> {
    super::check_input(
        path,
        "a curves file (.usd, .usda, .usdc, .abc, .hair, .ply)",
    )
    .map_err(|e| CurvesReadError::whole(path, CurvesReadErrorKind::Io(e)))?;
    let unknown = || {
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default();
        CurvesReadError::whole(path, CurvesReadErrorKind::UnknownFormat { extension })
    };
    match CurvesFormat::from_path(path).ok_or_else(unknown)? {
        CurvesFormat::Usda | CurvesFormat::Usdc => read_usd_curves(path),
        CurvesFormat::Abc => read_abc_curves(path),
        CurvesFormat::Hair => HairFile::read(path)?.to_curves(path),
        CurvesFormat::Ply => read_curves_ply(path),
        CurvesFormat::Rib | CurvesFormat::Pbrt => Err(unknown()),
    }
}

/// [`read_curves`] and how many times the file samples its curves: 1 for
/// a still file (PLY, .hair, a USD or Alembic file without time samples),
/// the count for an animated USD or Alembic file, of which the curves are
/// the first. A USD file is parsed once for both.
pub fn read_curves_and_sample_count(path: &Path) -> Result<(Curves, usize), CurvesReadError> {
    if let Some(CurvesFormat::Usda | CurvesFormat::Usdc) = CurvesFormat::from_path(path)
        && path.is_file()
    {
        let sequence = super::UsdCurvesSequence::open(path)?;
        let samples = sequence.times().len().max(1);
        return match sequence.first() {
            Some(curves) => Ok((curves?, samples)),
            // An assembly: its references read by the ordinary reader.
            None => Ok((read_curves(path)?, samples)),
        };
    }
    let curves = read_curves(path)?;
    // Alembic's count is read apart (a file whose count cannot be read
    // counts as still, as its curves read).
    let samples = match CurvesFormat::from_path(path) {
        Some(CurvesFormat::Abc) => super::read_abc_sample_count(path).map_or(1, |n| n.max(1)),
        _ => 1,
    };
    Ok((curves, samples))
}

/// How [`write_curves`] writes.
#[derive(Debug, Clone, Default)]
pub struct CurvesExport<'a> {
    /// USD stage options; their basis also applies to RIB and pbrt.
    pub usd: UsdOptions,
    /// The skin, written beside the curves in USD and Alembic
    /// (`--with-mesh`).
    pub mesh: Option<&'a Mesh>,
    /// The guide curves, written beside the hairs in USD and Alembic
    /// (`[output] guides`) as `guides`.
    pub guides: Option<Curves>,
}

/// Writes `parts` (name, curves) to `path` in the format its extension
/// names, atomically. USD gets one prim per part; the other formats hold
/// one set of curves, so the parts are written one after another.
pub fn write_curves<'c>(
    path: &Path,
    parts: impl IntoIterator<Item = (String, &'c Curves)>,
    export: &CurvesExport,
) -> Result<(), WriteError> {
    // The refusal kept typed inside the I/O error (`get_ref` downcasts).
    let fail = |refusal: Box<dyn std::error::Error + Send + Sync>| WriteError {
        path: path.to_path_buf(),
        error: std::io::Error::new(std::io::ErrorKind::InvalidInput, refusal),
    };
    let format = CurvesFormat::from_path(path)
        .ok_or_else(|| fail(CurvesFormat::UNKNOWN_FOR_WRITING.into()))?;
    let basis = export.usd.basis;
    match format {
        CurvesFormat::Usda | CurvesFormat::Usdc | CurvesFormat::Abc => {
            write_atomically(path, |out| {
                write_streamed(out, format, &export.usd, |layer| {
                    write_usd_prims(layer, parts, export)
                })
            })
        }
        CurvesFormat::Hair | CurvesFormat::Ply => {
            // One array for the whole file: join the parts.
            let joined = join(parts.into_iter().map(|(_, c)| c)).map_err(|e| fail(e.into()))?;
            if format == CurvesFormat::Hair {
                let hair = HairFile::from_curves(&joined).map_err(|e| fail(e.into()))?;
                hair.write(path)
            } else {
                write_atomically(path, |out| write_curves_ply(out, &joined))
            }
        }
        CurvesFormat::Rib | CurvesFormat::Pbrt => write_atomically(path, |out| {
            for (_, curves) in parts {
                match format {
                    CurvesFormat::Rib => write_rib(out, curves, basis)?,
                    _ => write_pbrt(out, curves, basis)?,
                }
            }
            Ok(())
        }),
    }
}

/// Writes a streamed file of `format` (usdc, usda or Alembic) to `out`:
/// starts it, lets `body` write prims, and finishes it. The body's errors
/// are its own type `E` (a groom's part that did not grow stays a groom
/// error); the writers' become `E` through `From<PrimWriteError>`. The
/// other formats are refused (they are not streamed).
pub fn write_streamed<W: Write + Seek, E: From<PrimWriteError>>(
    out: W,
    format: CurvesFormat,
    options: &UsdOptions,
    body: impl FnOnce(&mut dyn PrimWriter) -> Result<(), E>,
) -> Result<(), E> {
    match format {
        CurvesFormat::Usdc => {
            let mut usd = UsdcWriter::new(out, options)?;
            body(&mut usd)?;
            usd.finish()?;
        }
        CurvesFormat::Usda => {
            let mut usd = UsdaWriter::new(out, options)?;
            body(&mut usd)?;
            usd.finish()?;
        }
        CurvesFormat::Abc => {
            let mut abc = AbcWriter::new(out, options)?;
            body(&mut abc)?;
            abc.finish()?;
        }
        other => {
            return Err(E::from(PrimWriteError::BadSetting(format!(
                "{other:?} is not written as a stream of prims"
            ))));
        }
    }
    Ok(())
}

/// The skin (if exported) and then every part, as prims of one layer (or
/// objects of one Alembic archive).
fn write_usd_prims<'c>(
    usd: &mut dyn PrimWriter,
    parts: impl IntoIterator<Item = (String, &'c Curves)>,
    export: &CurvesExport,
) -> std::io::Result<()> {
    let other = std::io::Error::other;
    if let Some(mesh) = export.mesh {
        usd.write_mesh("skin", mesh).map_err(other)?;
    }
    if let Some(guides) = &export.guides {
        usd.write_guides("guides", guides).map_err(other)?;
    }
    for (name, curves) in parts {
        usd.write_part(&name, curves).map_err(other)?;
    }
    Ok(())
}
