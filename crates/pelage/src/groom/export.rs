//! How a groom file says its hairs are written, resolved once for every
//! front end: the export of a still groom, the USD options of an animated
//! one, which run of a farm writes the skin, and the assembly of a farm's
//! files ([`Groom::assemble`]). The CLI, Python and the Blender add-on
//! call these instead of spelling the defaults (24 fps, the basis, the
//! skin in run 1) each on its own.

use super::animate::{AnimatedGroom, FrameOutput};
use super::clips::{ClipAssembly, FrameFile, find_frame_files, frames_file, write_clip_assembly};
use super::farm::{FarmError, FarmRun, check_part_keys, find_part_files, part_documentation};
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

    /// [`Self::usd_options`] for `run` of a farm: its files say which
    /// groom grew them ([`Self::farm_key`]), so the assembly can refuse a
    /// file left from an earlier version of the groom.
    pub fn run_usd_options(&self, run: Option<FarmRun>) -> UsdOptions {
        let mut usd = self.usd_options();
        usd.documentation = run.map(|run| part_documentation(self.farm_key(), run));
        usd
    }

    /// A key of everything a farm run's hairs come from: pelage's
    /// version, the groom file's text, the share grown, the mesh and the
    /// bound guides (FNV-1a over their bits). Each run writes it into its
    /// part file; the assembly refuses a part whose key is not the
    /// groom's (a run left from an earlier version of it).
    pub fn farm_key(&self) -> u64 {
        let mut key = super::simulate::Fnv1a::default();
        key.bytes(env!("CARGO_PKG_VERSION").as_bytes());
        key.bytes(self.source().text.as_bytes());
        key.bytes(&self.fraction().to_le_bytes());
        key.bytes(bytemuck::cast_slice(self.mesh().positions()));
        key.bytes(bytemuck::cast_slice(self.mesh().triangles()));
        key.bytes(bytemuck::cast_slice(self.guides().curves().points()));
        key.0
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
            usd: self.run_usd_options(run),
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

    /// Pre-flight of a still groom's run, before anything is prepared
    /// (preparing a billion hairs' roots takes seconds): the parts `run`
    /// grows and its file beside `output`, refused when pelage cannot
    /// write that format or that path (a folder, an input), or when the
    /// disk cannot hold the run's positions alone (12 bytes a point, a
    /// floor of any format's size).
    pub fn preflight(
        &self,
        output: &Path,
        run: Option<FarmRun>,
    ) -> Result<(std::ops::Range<usize>, PathBuf), PreflightError> {
        let (range, path) = self.run_output(output, run).map_err(PreflightError::Farm)?;
        if CurvesFormat::from_path(&path).is_none() {
            return Err(PreflightError::UnknownFormat(path));
        }
        crate::io::check_output(&path).map_err(PreflightError::Output)?;
        let parts = self.part_count().max(1) as u128;
        let share = self.grown_count() as u128 * range.len() as u128 / parts;
        let points = self.points_per_hair() as u64;
        crate::io::check_free_space(
            &path,
            (share as u64).saturating_mul(points).saturating_mul(12),
        )
        .map_err(PreflightError::Output)?;
        Ok((range, path))
    }

    /// Where a run of the animated groom `animated` writes, beside
    /// `output`: the parts it grows and its files, each with its time
    /// codes. One run writes `output` with every frame; run `K/N` of a
    /// farm writes its share of the parts, every frame, to
    /// `STEM.part-K-of-N.fA-B.usdc`; `frame_files` writes one file a frame
    /// (`STEM.fA.usdc`) and `output` (`.usda`) as the layer that stitches
    /// them ([`AnimatedPlan::stitch`]). Split outputs are binary USD
    /// beside a text layer, so a `.usda` output's frame files are `.usdc`.
    /// [`Groom::assemble`] finds a farm's frame files by these names.
    pub fn animated_plan(
        &self,
        animated: &AnimatedGroom,
        output: &Path,
        run: Option<FarmRun>,
        frame_files: bool,
    ) -> Result<AnimatedPlan, AnimatedPlanError> {
        let parts = animated.generator().parts().len();
        let animation = animated.animation();
        let frames = animation.frames.frames();
        let usda = output.extension().and_then(|e| e.to_str()) == Some("usda");
        let data = match usda && (run.is_some() || frame_files) {
            true => output.with_extension("usdc"),
            false => output.to_path_buf(),
        };
        let one = |path: PathBuf| FrameOutput {
            path,
            times: animation.times_of(frames),
        };
        match (run, frame_files) {
            (Some(_), true) => Err(AnimatedPlanError::FramesAndRun),
            (Some(run), false) => {
                let (first, last) = (animation.frames.first(), animation.frames.last());
                Ok(AnimatedPlan {
                    parts: run.parts(parts).map_err(AnimatedPlanError::Farm)?,
                    outputs: vec![one(frames_file(&data, Some((run.k, run.n)), first, last))],
                    stitching: None,
                })
            }
            (None, true) if !usda => Err(AnimatedPlanError::StitchingNotUsda(output.to_path_buf())),
            (None, true) => {
                let files: Vec<FrameFile> = frames
                    .iter()
                    .map(|&f| FrameFile {
                        path: frames_file(&data, None, f, f),
                        run: (1, 1),
                        first: f,
                        last: f,
                    })
                    .collect();
                Ok(AnimatedPlan {
                    parts: 0..parts,
                    outputs: files
                        .iter()
                        .map(|file| FrameOutput {
                            path: file.path.clone(),
                            times: animation.times_of(&[file.first]),
                        })
                        .collect(),
                    stitching: Some(Stitching {
                        layer: output.to_path_buf(),
                        files,
                        frames: animation.frames.clone(),
                    }),
                })
            }
            (None, false) => Ok(AnimatedPlan {
                parts: 0..parts,
                outputs: vec![one(output.to_path_buf())],
                stitching: None,
            }),
        }
    }

    /// Ties a farm's files beside `output` together: for a still groom a
    /// USD layer referencing every run's part file with its extent (or,
    /// for an `.abc` output, the runs' Alembic parts joined into one
    /// archive), for an animated one a layer stitching the frame files
    /// with value clips.
    pub fn assemble(&self, output: &Path) -> Result<Assembly, AssembleError> {
        let alembic =
            CurvesFormat::from_path(output).is_some_and(CurvesFormat::assembly_joins_parts);
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
                let runs: Vec<(PathBuf, FarmRun)> = found
                    .iter()
                    .map(|f| {
                        (
                            f.path.clone(),
                            FarmRun {
                                k: f.run.0,
                                n: f.run.1,
                            },
                        )
                    })
                    .collect();
                check_part_keys(&runs, Some(self.farm_key()))?;
                Ok(Assembly::Frames(write_clip_assembly(
                    output,
                    &found,
                    &animation.frames,
                )?))
            }
            None => {
                let files = find_part_files(output)?;
                let n = files.len();
                let runs: Vec<(PathBuf, FarmRun)> = (1..=n)
                    .zip(&files)
                    .map(|(k, f)| (f.clone(), FarmRun { k, n }))
                    .collect();
                check_part_keys(&runs, Some(self.farm_key()))?;
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

/// Where a run of an animated groom writes ([`Groom::animated_plan`]).
#[derive(Debug, Clone)]
pub struct AnimatedPlan {
    /// The parts the run grows.
    pub parts: std::ops::Range<usize>,
    /// Its files, each with its time codes (one, or one a frame).
    pub outputs: Vec<FrameOutput>,
    /// With a file a frame: the layer that stitches them.
    pub stitching: Option<Stitching>,
}

/// A text layer tying frame files together with USD value clips.
#[derive(Debug, Clone)]
pub struct Stitching {
    /// The layer (`.usda`).
    pub layer: PathBuf,
    /// The frame files, in frame order.
    pub files: Vec<FrameFile>,
    /// The frames they hold.
    pub frames: crate::anim::FrameRange,
}

impl AnimatedPlan {
    /// Every time code the run writes, file after file.
    pub fn times(&self) -> Vec<f64> {
        self.outputs
            .iter()
            .flat_map(|o| o.times.iter().copied())
            .collect()
    }

    /// After the files are written: writes the layer that stitches them,
    /// if the plan has one.
    pub fn stitch(&self) -> Result<Option<ClipAssembly>, WriteError> {
        self.stitching
            .as_ref()
            .map(|s| write_clip_assembly(&s.layer, &s.files, &s.frames))
            .transpose()
    }

    /// Removes a stitching layer an earlier run left: it would stitch
    /// this run's frames with its own if this run stopped half-way. The
    /// layer comes back, naming this run's frames only, from
    /// [`Self::stitch`] once all of them are written.
    pub fn remove_stale_stitching(&self) -> Result<(), WriteError> {
        let Some(stitching) = &self.stitching else {
            return Ok(());
        };
        match std::fs::remove_file(&stitching.layer) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(WriteError {
                path: stitching.layer.clone(),
                error: std::io::Error::new(
                    e.kind(),
                    format!("cannot remove the earlier stitching layer: {e}"),
                ),
            }),
            _ => Ok(()),
        }
    }
}

/// Why a still groom's run is refused before it grows ([`Groom::preflight`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PreflightError {
    /// The farm run does not fit the groom's parts.
    #[error("{0}")]
    Farm(FarmError),
    /// The output's extension names no format pelage writes.
    #[error("{}: {}", .0.display(), CurvesFormat::UNKNOWN_FOR_WRITING)]
    UnknownFormat(PathBuf),
    /// The output cannot be written there, or the disk cannot hold it.
    #[error("{0}")]
    Output(WriteError),
}

/// Why an animated groom's run cannot be planned.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AnimatedPlanError {
    /// The farm run does not fit the groom's parts.
    #[error("{0}")]
    Farm(FarmError),
    /// A file a frame was asked for with an output other than `.usda`.
    #[error("{}: with a file a frame the output is the stitching layer: name it .usda", .0.display())]
    StitchingNotUsda(PathBuf),
    /// A farm run and a file a frame at once.
    #[error(
        "a farm run writes its share of the parts over every frame; a file a frame is for one run of the whole groom"
    )]
    FramesAndRun,
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
