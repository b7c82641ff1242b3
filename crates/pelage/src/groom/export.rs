//! How a groom file says its hairs are written, resolved once for every
//! front end: the export of a still groom, the USD options of an animated
//! one, which run of a farm writes the skin, and the assembly of a farm's
//! files ([`Groom::assemble`]). The CLI, Python and the Blender add-on
//! call these instead of spelling the defaults (24 fps, the basis, the
//! skin in run 1) each on its own.

use super::clips::{ClipAssembly, find_frame_files, write_clip_assembly};
use super::farm::{FarmError, FarmRun, find_part_files};
use super::generator::Generator;
use super::load::Groom;
use super::output::{write_alembic_assembly, write_assembly};
use crate::io::{CurvesExport, CurvesFormat, UsdOptions, WriteError};
use glam::Vec3;
use std::path::{Path, PathBuf};

/// Frames per second when a groom does not say (`[animation] fps`).
pub const DEFAULT_FPS: f64 = 24.0;

impl Groom {
    /// The USD (and Alembic) options: `[output] basis`, and for an
    /// animated groom its frame rate as time codes per second.
    pub fn usd_options(&self) -> UsdOptions {
        UsdOptions {
            basis: self.curve_basis(),
            time_codes_per_second: self.fps().unwrap_or(DEFAULT_FPS),
            hair_material: self.writes_hair_material(),
            ..UsdOptions::default()
        }
    }

    /// What a still groom writes beside its curves: the USD options and,
    /// with `[output] with_mesh`, the skin.
    pub fn export(&self) -> CurvesExport<'_> {
        CurvesExport {
            usd: self.usd_options(),
            mesh: self.writes_skin().then(|| self.mesh()),
            guides: None,
        }
    }

    /// Whether run `run` writes the guides: with `[output] guides`, the
    /// first run only (as the skin).
    pub fn writes_guides_in(&self, run: Option<FarmRun>) -> bool {
        self.writes_guides() && run.is_none_or(|r| r.k == 1)
    }

    /// What a still groom (or run `run` of its farm) writes with
    /// `generator`: [`Self::export`], with the skin and (`[output]
    /// guides`) the guide curves with their regions in the first run only,
    /// so an assembly holds one of each.
    pub fn export_for(&self, generator: &Generator, run: Option<FarmRun>) -> CurvesExport<'_> {
        CurvesExport {
            usd: self.usd_options(),
            mesh: self.writes_skin_in(run).then(|| self.mesh()),
            guides: self.writes_guides_in(run).then(|| generator.guide_curves()),
        }
    }

    /// Whether `run` of a farm (or a run of its own, `None`) writes the
    /// skin: with `[output] with_mesh`, the first run only, so the
    /// assembly holds one skin.
    pub fn writes_skin_in(&self, run: Option<FarmRun>) -> bool {
        self.writes_skin() && run.is_none_or(|r| r.k == 1)
    }

    /// The parts `run` grows (every part for `None`) and the file it
    /// writes them to beside `output`.
    pub fn run_output(
        &self,
        output: &Path,
        run: Option<FarmRun>,
    ) -> Result<(std::ops::Range<usize>, PathBuf), FarmError> {
        let parts = self.part_count();
        match run {
            None => Ok((0..parts, output.to_path_buf())),
            Some(run) => Ok((run.parts(parts)?, run.file(output))),
        }
    }

    /// Ties a farm's files beside `output` together: for a still groom a
    /// USD layer referencing every run's part file with its extent (or,
    /// for an `.abc` output, the runs' Alembic parts joined into one
    /// archive), for an animated one a layer stitching the frame files
    /// with value clips.
    pub fn assemble(&self, output: &Path) -> Result<Assembly, AssembleError> {
        let alembic = CurvesFormat::from_path(output) == Some(CurvesFormat::Abc);
        match self.animation() {
            Some(_) if alembic => Err(AssembleError::AlembicFrames(output.to_path_buf())),
            Some(animation) => {
                let found = find_frame_files(output).map_err(|error| {
                    AssembleError::Farm(FarmError::List {
                        folder: crate::io::folder_of(output).to_path_buf(),
                        error,
                    })
                })?;
                if found.is_empty() {
                    return Err(AssembleError::NoFrames(output.to_path_buf()));
                }
                Ok(Assembly::Frames(write_clip_assembly(
                    output,
                    &found,
                    &animation.frames,
                )?))
            }
            None => {
                let files = find_part_files(output)?;
                let extent = if alembic {
                    let skin = self.writes_skin().then(|| self.mesh());
                    write_alembic_assembly(output, &files, &self.usd_options(), skin)?
                } else {
                    write_assembly(output, &files, &self.usd_options())?
                };
                Ok(Assembly::Parts { files, extent })
            }
        }
    }
}

/// What [`Groom::assemble`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub enum Assembly {
    /// A still groom's part files referenced from one layer.
    Parts {
        /// The part files, in run order.
        files: Vec<PathBuf>,
        /// The groom's extent: lowest and highest corner.
        extent: (Vec3, Vec3),
    },
    /// An animated groom's frame files stitched with value clips.
    Frames(ClipAssembly),
}

/// A farm's files could not be assembled.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AssembleError {
    /// The runs' files are not all there, or not of one farm.
    #[error(transparent)]
    Farm(#[from] FarmError),
    /// An animated groom's frame files are not there.
    #[error(
        "no frame files beside {} (NAME.part-K-of-N.fA-B.usdc); run `pelage groom FILE --part K/N` first",
        .0.display()
    )]
    NoFrames(PathBuf),
    /// An animated farm assembled into Alembic, which has no value clips
    /// to stitch frame files with.
    #[error(
        "{}: an animated farm's frame files are stitched with USD value clips, which Alembic lacks; assemble into a .usda (`--assemble -o NAME.usda`) and write the runs as .usdc",
        .0.display()
    )]
    AlembicFrames(PathBuf),
    /// The assembly layer could not be written (or a file read).
    #[error(transparent)]
    Write(#[from] WriteError),
}
