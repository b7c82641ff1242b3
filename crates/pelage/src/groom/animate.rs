//! Grooms on animated skins (Sik §4.1: hair generated per frame and per
//! part; Blender's Deform Curves on Surface). Roots are sampled once, on
//! the skin's rest pose, and keep their triangle, barycentrics and id in
//! every frame. Two modes:
//!
//! - **deform**: each part is grown once at rest, then carried to every
//!   frame by its roots' surface frames ([`SkinBinding`]). Noise, clumps
//!   and every other operator were evaluated at rest, so nothing swims.
//! - **regrow**: every frame, the animated guides are brought back to
//!   rest through their own roots' frames, the part is grown from them at
//!   rest (operators still in rest space), and carried to the frame.
//!   A hair at a guide's root reproduces that guide in every frame.
//!
//! Either way, with `[finish] outside_skin` (on by default for animated
//! grooms) every frame's hairs are then kept out of that frame's posed
//! skin ([`OutsideSkin::posed`]), as the still groom's are kept out of the
//! rest pose: carried rigidly by their roots, hairs go into the body
//! where it bends, and hairs between guides that collided can pass where
//! the guides did not.
//!
//! Output is one file with time samples (usdc or Alembic): parts are
//! written one after the other, each with all its frames, so memory holds
//! one part (and the skin's poses) whatever the frame count.
//!
//! ```
//! use glam::{Mat3, Vec3};
//! use pelage::anim::{AnimatedSkin, FrameRange};
//! use pelage::groom::{AnimatedGroom, AnimationMode, AnimationSpec, GroomSpec, RootsSpec};
//! use pelage::guides::{GuideGrowth, Guides};
//! use std::sync::Arc;
//!
//! let spot = Arc::new(pelage::assets::spot());
//! // A skin that turns about the vertical axis, a little more each frame.
//! let rest: Vec<Vec3> = spot.positions().to_vec();
//! let skin = AnimatedSkin::from_fn(&spot, move |frame| {
//!     let turn = Mat3::from_rotation_y(0.1 * (frame - 1.0) as f32);
//!     rest.iter().map(|&p| turn * p).collect()
//! });
//! let guides = Guides::grow(&spot, &GuideGrowth { count: 50, ..Default::default() })?;
//! let spec = GroomSpec::new(spot, guides, RootsSpec::new(2_000));
//! let animation = AnimationSpec {
//!     frames: FrameRange::parse("1-3")?,
//!     rest_frame: 1.0,
//!     mode: AnimationMode::Deform,
//!     shutter: vec![],
//!     velocities: true,
//! };
//! let groom = AnimatedGroom::new(spec, skin, animation, None)?;
//! let (first, third) = (groom.part(0, 1.0)?, groom.part(0, 3.0)?);
//! assert_eq!(first.ids(), third.ids()); // the same hairs, moved
//! let turned = Mat3::from_rotation_y(0.2) * first.points()[5];
//! assert!((turned - third.points()[5]).length() < 1e-5);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::error::{GroomError, GroomErrorKind};
use super::generator::{Generator, GroomSummary};
use super::output::{GroomWriteError, part_name};
use super::outside_skin::OutsideSkin;
use super::spec::GroomSpec;
use crate::Curves;
use crate::anim::{AnimatedSkin, FrameRange, RestFrames, SkinBinding, SkinPose};
use crate::guides::{Guides, resample_by_arc_length};
use crate::io::{AbcWriter, AtomicFile, CurvesFormat, PrimWriter, UsdOptions, UsdcWriter};
use crate::limits::MAX_OPEN_FRAME_FILES;
use glam::Vec3;
use rayon::prelude::*;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Half the time step, in frames, of deform grooms' velocities: the
/// hairs are carried to the skin this long before and after each time
/// code. Exact for a skin moving linearly between its samples (OBJ
/// sequences, linear glTF keys) away from a sample; at a sample it is
/// the mean of the two sides.
const VELOCITY_STEP: f64 = 1.0 / 32.0;

/// How an animated groom follows its skin.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AnimationMode {
    /// Grow once at rest, carry every frame with the skin (fast).
    #[default]
    Deform,
    /// Regrow every frame from animated guides, in rest space.
    Regrow,
    /// Simulate the guides over the frames (gravity, wind, the skin's
    /// motion, collisions with it: [`crate::dynamics::GuideSimulation`]),
    /// then regrow every frame from them.
    Simulate,
}

impl AnimationMode {
    /// `deform` or `regrow`.
    pub fn by_name(name: &str) -> Option<Self> {
        match name {
            "deform" => Some(Self::Deform),
            "regrow" => Some(Self::Regrow),
            "simulate" => Some(Self::Simulate),
            _ => None,
        }
    }

    /// Whether every frame is grown again from the frame's guides
    /// (regrow and simulate).
    pub fn regrows(self) -> bool {
        matches!(self, Self::Regrow | Self::Simulate)
    }

    /// The mode's name in groom files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Deform => "deform",
            Self::Regrow => "regrow",
            Self::Simulate => "simulate",
        }
    }
}

/// The frames of an animated groom and how they are made.
#[derive(Debug, Clone)]
pub struct AnimationSpec {
    /// The frames written.
    pub frames: FrameRange,
    /// The frame whose skin the roots are sampled on (and the guides
    /// bound to).
    pub rest_frame: f64,
    /// Deform or regrow.
    pub mode: AnimationMode,
    /// Shutter offsets in frames (e.g. `[-0.25, 0.25]`): each frame is
    /// also written at these sub-frame times, for motion blur.
    pub shutter: Vec<f64>,
    /// Write per-point velocities (deform grooms) so renderers blur from
    /// one sample.
    pub velocities: bool,
}

impl AnimationSpec {
    /// Every time code written: each frame, and each frame plus each
    /// shutter offset, ascending.
    pub fn sample_times(&self) -> Vec<f64> {
        self.times_of(self.frames.frames())
    }

    /// The time codes written for `frames` (a run's share of them): each
    /// frame, and each frame plus each shutter offset, ascending.
    pub fn times_of(&self, frames: &[i32]) -> Vec<f64> {
        let mut times: Vec<f64> = frames
            .iter()
            .flat_map(|&f| {
                std::iter::once(0.0)
                    .chain(self.shutter.iter().copied())
                    .map(move |o| f64::from(f) + o)
            })
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }
}

/// How a guide file's coordinates turn into its mesh's: a Z-up USD file
/// (Blender's export) of guides for a Y-up mesh (pelage's world, every
/// format but a Z-up USD mesh) is turned Y-up, and the other way round.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AxisTurn {
    /// The same up axis: no turn.
    #[default]
    None,
    /// Z up to Y up: (x, y, z) → (x, z, −y), as Blender's Y-up exports turn it.
    ZUpToYUp,
    /// Y up to Z up: (x, y, z) → (x, −z, y).
    YUpToZUp,
}

impl AxisTurn {
    /// The turn from a file whose up axis is `file` to a mesh whose up
    /// axis is `mesh`.
    pub fn between(file: crate::io::UpAxis, mesh: crate::io::UpAxis) -> Self {
        use crate::io::UpAxis::{Y, Z};
        match (file, mesh) {
            (Z, Y) => Self::ZUpToYUp,
            (Y, Z) => Self::YUpToZUp,
            _ => Self::None,
        }
    }

    /// A point turned.
    pub fn point(self, p: Vec3) -> Vec3 {
        match self {
            Self::None => p,
            Self::ZUpToYUp => Vec3::new(p.x, p.z, -p.y),
            Self::YUpToZUp => Vec3::new(p.x, -p.z, p.y),
        }
    }

    /// Guide `curves` turned: their points, widths and layout (what
    /// binding reads; other attributes are left behind).
    pub fn curves(self, curves: Curves) -> Curves {
        if self == Self::None {
            return curves;
        }
        let points = curves.points().iter().map(|&p| self.point(p)).collect();
        Curves::new(points, curves.widths().to_vec(), curves.offsets().to_vec())
            .expect("a turn keeps the layout and finite values")
    }
}

/// Guide shapes over time, for [`AnimationMode::Regrow`].
#[derive(Clone)]
pub enum GuideMotion {
    /// A time-sampled USD or Alembic file of the guides (read at each
    /// frame); `kept[i]` is the file's curve index of bound guide `i`.
    File {
        /// The guide file.
        path: PathBuf,
        /// Which of the file's curves were bound, in the guides' order.
        kept: Vec<usize>,
        /// Frames per second: Alembic samples are timed in seconds.
        fps: f64,
        /// The turn from the file's up axis to the mesh's.
        turn: AxisTurn,
    },
    /// A program giving every bound guide's points at a frame (one curve
    /// per guide, in order).
    Program(Arc<dyn Fn(f64) -> Curves + Send + Sync>),
}

impl std::fmt::Debug for GuideMotion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::File { path, .. } => write!(f, "GuideMotion::File({})", path.display()),
            Self::Program(_) => f.write_str("GuideMotion::Program"),
        }
    }
}

/// How far an animated write has come.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnimationProgress {
    /// The part being written.
    pub part: usize,
    /// The time code just written.
    pub time: f64,
    /// (part, time) pairs written so far, and in all.
    pub done: usize,
    /// All of them.
    pub total: usize,
}

/// A groom bound to an animated skin, ready to be grown frame by frame.
pub struct AnimatedGroom {
    spec: GroomSpec,
    generator: Generator,
    skin: Arc<AnimatedSkin>,
    animation: AnimationSpec,
    binding: SkinBinding,
    guides: Option<GuideMotion>,
    /// The gap every posed skin keeps hairs out by, and a hair's segment
    /// (`None`: the groom's `outside_skin` is off).
    keep_out: Option<(f32, f32)>,
}

impl std::fmt::Debug for AnimatedGroom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AnimatedGroom")
            .field("skin", &self.skin.name())
            .field("frames", &self.animation.frames.to_string())
            .field("mode", &self.animation.mode)
            .finish()
    }
}

impl AnimatedGroom {
    /// Binds `spec` (whose mesh must be `skin` at the rest frame) to the
    /// skin. `guides` moves the guides for regrow (required then).
    pub fn new(
        spec: GroomSpec,
        skin: impl Into<Arc<AnimatedSkin>>,
        animation: AnimationSpec,
        guides: Option<GuideMotion>,
    ) -> Result<Self, GroomError> {
        let skin = skin.into();
        let mesh_error = |e| spec.error("animation", GroomErrorKind::Mesh(e));
        let rest = skin
            .positions_at(animation.rest_frame)
            .map_err(mesh_error)?;
        let mesh = spec.mesh.clone();
        if rest.len() != mesh.vertex_count() {
            return Err(spec.error(
                "animation",
                GroomErrorKind::Mismatch(format!(
                    "the skin has {} vertices at its rest frame but the groom's mesh has {}",
                    rest.len(),
                    mesh.vertex_count()
                )),
            ));
        }
        if animation.mode.regrows() && guides.is_none() {
            return Err(spec.error(
                "animation.mode",
                GroomErrorKind::Conflict(
                    "regrow needs animated guides: a time-sampled USD or Alembic guide file ([guides] file)"
                        .into(),
                ),
            ));
        }
        if let Some(bad) = animation
            .shutter
            .iter()
            .find(|o| !(o.is_finite() && o.abs() < 1.0))
        {
            return Err(spec.error(
                "animation.motion_blur",
                GroomErrorKind::OutOfRange(format!(
                    "shutter offset {bad}: offsets are fractions of a frame, between -1 and 1"
                )),
            ));
        }
        // The rest pose is the groom's own mesh, so a hair at rest is
        // carried by exactly the identity.
        let binding = SkinBinding::new(
            mesh.triangles().to_vec(),
            SkinPose::new(mesh.positions().to_vec(), mesh.triangles()),
        );
        let generator = Generator::new(spec.clone())?;
        let keep_out = spec
            .finish
            .outside_skin
            .map(|gap| (gap, OutsideSkin::segment(&spec.guides, spec.finish.points)));
        Ok(Self {
            spec,
            generator,
            skin,
            animation,
            binding,
            guides,
            keep_out,
        })
    }

    /// The skin in `pose` that this groom's hairs are kept out of, when
    /// its `outside_skin` is on and the pose is not the rest pose (where
    /// the hairs were kept out of the skin as they grew, and are carried
    /// by the identity).
    pub fn outside_skin(&self, pose: &SkinPose) -> Option<OutsideSkin> {
        if pose.positions() == self.binding.rest().positions() {
            return None;
        }
        self.keep_out.map(|(gap, segment)| {
            let skin = (pose.positions(), pose.normals(), self.binding.triangles());
            OutsideSkin::posed(skin, gap, segment)
        })
    }

    /// The generator at rest (parts, layout, operators).
    pub fn generator(&self) -> &Generator {
        &self.generator
    }

    /// The frames and mode.
    pub fn animation(&self) -> &AnimationSpec {
        &self.animation
    }

    /// The skin.
    pub fn skin(&self) -> &AnimatedSkin {
        &self.skin
    }

    /// The binding of hairs to the skin.
    pub fn binding(&self) -> &SkinBinding {
        &self.binding
    }

    /// The skin's pose at time code `time`.
    pub fn pose(&self, time: f64) -> Result<SkinPose, GroomError> {
        let positions = self
            .skin
            .positions_at(time)
            .map_err(|e| self.spec.error("animation", GroomErrorKind::Mesh(e)))?;
        Ok(self.binding.pose(positions))
    }

    /// The generator of the frame at `time` in regrow mode: the guides at
    /// that time, brought back to rest through their roots' frames.
    pub fn regrown_generator(&self, time: f64, pose: &SkinPose) -> Result<Generator, GroomError> {
        let guides = self.guides_at(time, pose)?;
        let mut spec = self.spec.clone();
        spec.guides = Arc::new(guides);
        self.generator.reshaped(spec)
    }

    /// The frame's own generator in regrow mode; `None` in deform mode,
    /// where the rest generator grows every frame.
    fn frame_generator(&self, time: f64, pose: &SkinPose) -> Result<Option<Generator>, GroomError> {
        match self.animation.mode {
            AnimationMode::Deform => Ok(None),
            AnimationMode::Regrow | AnimationMode::Simulate => {
                self.regrown_generator(time, pose).map(Some)
            }
        }
    }

    /// The guides at `time`, in rest space.
    fn guides_at(&self, time: f64, pose: &SkinPose) -> Result<Guides, GroomError> {
        let rest = &self.spec.guides;
        let n = rest.points_per_guide();
        let (posed, kept): (Curves, Option<&[usize]>) = match &self.guides {
            Some(GuideMotion::File {
                path,
                kept,
                fps,
                turn,
            }) => (
                turn.curves(
                    read_guides_at(path, time, *fps)
                        .map_err(|e| self.spec.error("guides.file", GroomErrorKind::Guides(e)))?,
                ),
                Some(kept),
            ),
            Some(GuideMotion::Program(f)) => (f(time), None),
            None => return Ok((**rest).clone()),
        };
        let index = |i: usize| kept.map_or(Some(i), |k| k.get(i).copied());
        let mut points = Vec::with_capacity(rest.len() * n);
        let mut shape = vec![Vec3::ZERO; n];
        for (i, &root) in rest.roots().iter().enumerate() {
            let Some(c) = index(i).filter(|&c| c < posed.curve_count()) else {
                return Err(self.spec.error(
                    "guides.file",
                    GroomErrorKind::Mismatch(format!(
                        "at frame {time} the guides have {} curves; the rest frame bound {} of them",
                        posed.curve_count(),
                        rest.len()
                    )),
                ));
            };
            let resampled = resample_by_arc_length(&posed.points()[posed.range(c)], n);
            self.binding.to_rest(&resampled, root, pose, &mut shape);
            points.extend_from_slice(&shape);
        }
        rest.with_points(points).map_err(|e| {
            self.spec.error(
                "guides.file",
                GroomErrorKind::CurvesAtFrame {
                    frame: time,
                    error: e,
                },
            )
        })
    }

    /// Part `p` at `time` on `pose`: grown at rest by `grow` from
    /// `generator` (the rest generator in deform mode, the frame's in
    /// regrow mode), carried
    /// to the pose and kept out of its skin (`outside`, this pose's
    /// [`Self::outside_skin`]). `rest` caches the rest growth in deform
    /// mode.
    #[allow(clippy::too_many_arguments)]
    fn part_at(
        &self,
        p: usize,
        time: f64,
        (pose, outside): (&SkinPose, Option<&OutsideSkin>),
        (generator, grow): (&Generator, GeneratorGrower<'_>),
        rest: &mut Option<(Curves, RestFrames)>,
        out: &mut Curves,
    ) -> Result<(), GroomError> {
        let carried = match self.animation.mode {
            AnimationMode::Deform => match rest {
                // Later frames: the same hairs, only moved.
                Some((curves, frames)) => self.binding.carry_again(curves, frames, pose, out),
                None => {
                    let curves = grow(generator, p)?;
                    let frames = self.binding.rest_frames(&curves);
                    let carried = self.binding.carry_into(&curves, pose, out);
                    *rest = Some((curves, frames));
                    carried
                }
            },
            AnimationMode::Regrow | AnimationMode::Simulate => {
                // A fresh growth every frame: moved where it lies.
                let mut grown = grow(generator, p)?;
                let carried = self.binding.carry_in_place(&mut grown, pose);
                let spent = std::mem::replace(out, grown);
                generator.recycle(spent);
                carried
            }
        };
        if !carried {
            return Err(self.spec.error(
                "animation",
                GroomErrorKind::NotFinite(format!(
                    "part {p} at frame {time}: the skin's pose moved a hair to a value that is not finite"
                )),
            ));
        }
        if let Some(outside) = outside {
            let triangles = self.binding.triangles();
            outside.apply_all(out, |root| pose.frame_at(triangles, root).1.z_axis);
        }
        Ok(())
    }

    /// Per-point velocities (units a second) of a deform part grown at
    /// rest, between the skin just before and just after the time, in
    /// `out` (the last frame's, reused); `None` when one is not finite.
    fn velocities(
        &self,
        (rest, frames): (&Curves, &RestFrames),
        poses: (&SkinPose, &SkinPose),
        per_second: f32,
        mut out: Vec<Vec3>,
    ) -> Option<Vec<Vec3>> {
        self.binding
            .velocities(rest, frames, poses, per_second, &mut out)
            .then_some(out)
    }

    /// The skin in `pose`, with the rest mesh's UVs.
    pub fn posed_mesh(&self, pose: &SkinPose) -> Result<crate::Mesh, GroomError> {
        let rest = &self.spec.mesh;
        crate::Mesh::new(
            rest.name(),
            pose.positions().to_vec(),
            rest.triangles().to_vec(),
            None,
            rest.uvs().cloned(),
        )
        .map_err(|e| self.spec.error("animation", GroomErrorKind::Mesh(e)))
    }

    /// The hair a root at guide `guide`'s root gets at `time` from the
    /// guides alone (interpolated, no operator), carried to the skin's
    /// pose: in regrow mode, the guide itself as the file poses it.
    pub fn guide_hair(&self, guide: usize, time: f64) -> Result<Vec<Vec3>, GroomError> {
        let pose = self.pose(time)?;
        let regrown = self.frame_generator(time, &pose)?;
        let generator = regrown.as_ref().unwrap_or(&self.generator);
        let root = self.spec.guides.roots()[guide];
        let n = self.spec.guides.points_per_guide();
        let mut shape = vec![Vec3::ZERO; n];
        generator
            .interpolator
            .hair(&self.spec.mesh, root, &mut Default::default(), &mut shape);
        let at_rest = Curves::new(shape, vec![0.0; n], vec![0, n as u32])
            .and_then(|c| c.with_roots(vec![root]))
            .map_err(|e| {
                self.spec
                    .error("guides", GroomErrorKind::NotFinite(e.to_string()))
            })?;
        let carried = self.binding.carry(&at_rest, &pose).ok_or_else(|| {
            self.spec.error(
                "animation",
                GroomErrorKind::NotFinite(format!("guide {guide} at frame {time}")),
            )
        })?;
        Ok(carried.points().to_vec())
    }

    /// Part `p` at time code `time` with its per-point velocities in
    /// units a second at `fps` time codes a second (deform grooms; a
    /// regrown groom's come from its neighbouring frames, when written).
    pub fn part_with_velocities(
        &self,
        p: usize,
        time: f64,
        fps: f64,
    ) -> Result<Curves, GroomError> {
        if self.animation.mode != AnimationMode::Deform {
            return Err(self.spec.error(
                "animation.mode",
                GroomErrorKind::Conflict(
                    "a regrown groom's velocities come from its neighbouring frames: write it (AnimatedGroom::write) to get them".into(),
                ),
            ));
        }
        let pose = self.pose(time)?;
        let outside = self.outside_skin(&pose);
        let mut rest = None;
        let mut out = Curves::default();
        let at = (&pose, outside.as_ref());
        let growth = (&self.generator, &CPU_GROWTH as GeneratorGrower<'_>);
        self.part_at(p, time, at, growth, &mut rest, &mut out)?;
        let (minus, plus, per_second) = self.velocity_poses(time, &pose, fps);
        let (curves, frames) = rest.as_ref().expect("deform grows at rest");
        let velocities = self
            .velocities((curves, frames), (&minus, &plus), per_second, Vec::new())
            .ok_or_else(|| {
                self.spec.error(
                    "animation",
                    GroomErrorKind::NotFinite(format!("part {p} near frame {time}")),
                )
            })?;
        out.set_velocities(Some(velocities)).map_err(|e| {
            self.spec
                .error("animation", GroomErrorKind::NotFinite(e.to_string()))
        })?;
        Ok(out)
    }

    /// Part `p` regrown at `time` and carried there: with the window's
    /// pose, skin and generator when `time` is one of its times, else its
    /// own.
    fn regrown_part(&self, p: usize, time: f64, window: &Window<'_>) -> Result<Curves, GroomError> {
        let Some(k) = window.times.iter().position(|&t| t == time) else {
            return self.part_grown_by(p, time, window.grow);
        };
        let mut out = Curves::default();
        let generator = window.generators[k].as_ref().unwrap_or(&self.generator);
        let at = (&window.poses[k], window.outsides[k].as_ref());
        self.part_at(p, time, at, (generator, window.grow), &mut None, &mut out)?;
        Ok(out)
    }

    /// The skin just before and after `time` (or at it, on a side the skin
    /// has no sample), and the factor from their carries' difference to
    /// units a second.
    fn velocity_poses(&self, time: f64, pose: &SkinPose, fps: f64) -> (SkinPose, SkinPose, f32) {
        let (minus, plus) = (
            self.pose(time - VELOCITY_STEP),
            self.pose(time + VELOCITY_STEP),
        );
        let span = [minus.is_ok(), plus.is_ok()]
            .iter()
            .filter(|ok| **ok)
            .count() as f64
            * VELOCITY_STEP;
        let minus = minus.unwrap_or_else(|_| pose.clone());
        let plus = plus.unwrap_or_else(|_| pose.clone());
        // Neither side: no motion to measure.
        let per_second = if span > 0.0 { fps / span } else { 0.0 };
        (minus, plus, per_second as f32)
    }

    /// Part `p` at time code `time`, alone (tests, previews).
    pub fn part(&self, p: usize, time: f64) -> Result<Curves, GroomError> {
        self.part_grown_by(p, time, &CPU_GROWTH)
    }

    /// [`Self::part`] with its hairs grown at rest by `grow`.
    fn part_grown_by(
        &self,
        p: usize,
        time: f64,
        grow: GeneratorGrower<'_>,
    ) -> Result<Curves, GroomError> {
        let pose = self.pose(time)?;
        let outside = self.outside_skin(&pose);
        let regrown = self.frame_generator(time, &pose)?;
        let generator = regrown.as_ref().unwrap_or(&self.generator);
        let mut out = Curves::default();
        self.part_at(
            p,
            time,
            (&pose, outside.as_ref()),
            (generator, grow),
            &mut None,
            &mut out,
        )?;
        Ok(out)
    }

    /// Grows `parts` over every frame and writes them to `path` (`.usdc`
    /// or `.abc`), atomically, with one time sample per frame (and shutter
    /// offset). With `with_skin` the posed skin is written too, as a
    /// time-sampled `Mesh` named `skin` (usdc only). `progress` is called
    /// after each part's frame.
    pub fn write(
        &self,
        path: &Path,
        parts: Range<usize>,
        options: &UsdOptions,
        with_skin: bool,
        progress: impl FnMut(AnimationProgress),
    ) -> Result<GroomSummary, GroomWriteError> {
        let cancel = AtomicBool::new(false);
        self.write_until(path, parts, options, with_skin, &cancel, progress)
    }

    /// [`Self::write`] that stops after the part-frame during which
    /// `cancel` was set (a front end's Ctrl-C): the output is left as it
    /// was, and the error is [`GroomWriteError::Cancelled`].
    pub fn write_until(
        &self,
        path: &Path,
        parts: Range<usize>,
        options: &UsdOptions,
        with_skin: bool,
        cancel: &AtomicBool,
        progress: impl FnMut(AnimationProgress),
    ) -> Result<GroomSummary, GroomWriteError> {
        let output = FrameOutput {
            path: path.to_path_buf(),
            times: self.animation.sample_times(),
        };
        self.write_files_until(&[output], parts, options, with_skin, cancel, progress)
    }

    /// [`Self::write`] into several files, each with its own time codes
    /// (one file a frame, or a farm task's frame range). Files are written
    /// in windows of at most [`MAX_OPEN_FRAME_FILES`] open at once (a long
    /// range stays under the process's limit of open files, and its
    /// buffers and poses in memory): within a window every part is grown
    /// once (deform) and carried to every file's frames, and the window's
    /// files are written all or none.
    pub fn write_files(
        &self,
        outputs: &[FrameOutput],
        parts: Range<usize>,
        options: &UsdOptions,
        with_skin: bool,
        progress: impl FnMut(AnimationProgress),
    ) -> Result<GroomSummary, GroomWriteError> {
        let cancel = AtomicBool::new(false);
        self.write_files_until(outputs, parts, options, with_skin, &cancel, progress)
    }

    /// [`Self::write_files`] that stops once `cancel` is set, as
    /// [`Self::write_until`] does (windows already written stay).
    pub fn write_files_until(
        &self,
        outputs: &[FrameOutput],
        parts: Range<usize>,
        options: &UsdOptions,
        with_skin: bool,
        cancel: &AtomicBool,
        progress: impl FnMut(AnimationProgress),
    ) -> Result<GroomSummary, GroomWriteError> {
        let files = AnimatedFiles {
            outputs,
            parts,
            options,
            with_skin,
        };
        self.write_files_grown_until(files, &CPU_GROWTH, cancel, progress)
    }

    /// [`Self::write_files_until`] with each part's hairs grown at rest by
    /// `grow` instead of [`Generator::part`] (pelage-gpu grows them on a
    /// GPU); everything after the growth (the carry to each pose, the
    /// pushes out of the posed skin, the velocities) is the same.
    pub fn write_files_grown_until(
        &self,
        files: AnimatedFiles<'_>,
        grow: GeneratorGrower<'_>,
        cancel: &AtomicBool,
        mut progress: impl FnMut(AnimationProgress),
    ) -> Result<GroomSummary, GroomWriteError> {
        let parts = files.parts.len();
        let total = parts * files.outputs.iter().map(|o| o.times.len()).sum::<usize>();
        let mut done = 0;
        let mut summary = GroomSummary::default();
        for (k, window) in files.outputs.chunks(MAX_OPEN_FRAME_FILES).enumerate() {
            let counts = self.write_window(
                AnimatedFiles {
                    outputs: window,
                    ..files.clone()
                },
                grow,
                cancel,
                &mut |p: AnimationProgress| {
                    progress(AnimationProgress {
                        done: done + p.done,
                        total,
                        ..p
                    })
                },
            )?;
            done += parts * window.iter().map(|o| o.times.len()).sum::<usize>();
            // Every window holds the same hairs: count them once.
            if k == 0 {
                summary = counts;
            }
        }
        Ok(summary)
    }

    /// [`Self::write_files`] of one window of files, all open at once.
    fn write_window(
        &self,
        files: AnimatedFiles<'_>,
        grow: GeneratorGrower<'_>,
        cancel: &AtomicBool,
        progress: &mut dyn FnMut(AnimationProgress),
    ) -> Result<GroomSummary, GroomWriteError> {
        let AnimatedFiles {
            outputs,
            parts,
            options,
            with_skin,
        } = files;
        let mut layers = self.open_layers(outputs, options)?;
        // Poses once for every time of every file (files may share times).
        let mut times: Vec<f64> = outputs
            .iter()
            .flat_map(|o| o.times.iter().copied())
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        let index = |t: f64| times.partition_point(|&x| x < t);
        let mut poses = Vec::with_capacity(times.len());
        for &t in &times {
            poses.push(self.pose(t)?);
        }
        let generators = times
            .iter()
            .zip(&poses)
            .map(|(&t, pose)| self.frame_generator(t, pose))
            .collect::<Result<Vec<_>, _>>()?;
        let outsides: Vec<Option<OutsideSkin>> = poses
            .par_iter()
            .map(|pose| self.outside_skin(pose))
            .collect();
        // Deform: each time's skin a little before and after it, to carry
        // the hairs there for their velocities.
        // A skin with no sample past its first or last time (an OBJ
        // sequence's first file) is differenced on one side.
        let velocity_poses = match self.animation.mode {
            AnimationMode::Deform if self.animation.velocities => times
                .iter()
                .zip(&poses)
                .map(|(&t, pose)| self.velocity_poses(t, pose, options.time_codes_per_second))
                .collect::<Vec<_>>(),
            _ => Vec::new(),
        };
        if with_skin {
            self.write_skins(outputs, &mut layers, &times, &poses)?;
        }
        let mut summary = GroomSummary::default();
        let total = parts.len() * outputs.iter().map(|o| o.times.len()).sum::<usize>();
        let mut done = 0;
        let mut out = Curves::default();
        // Regrow: velocities by central differences over the neighbouring
        // time codes, whose growths are kept (three at most) as the
        // frames go by.
        let all_times = self.animation.sample_times();
        // One time code has no neighbour to differ from: its velocities
        // are left out, not written as zeros.
        let regrow_velocities =
            self.animation.mode.regrows() && self.animation.velocities && all_times.len() > 1;
        for p in parts {
            let mut rest = None;
            let mut counted = false;
            let mut grown: Vec<(f64, Curves)> = Vec::new();
            for (output, layer) in outputs.iter().zip(&mut layers) {
                for &time in &output.times {
                    let k = index(time);
                    let generator = generators[k].as_ref().unwrap_or(&self.generator);
                    let velocities = if regrow_velocities {
                        let window = Window {
                            times: &times,
                            poses: &poses,
                            outsides: &outsides,
                            generators: &generators,
                            time_codes_per_second: options.time_codes_per_second,
                            grow,
                        };
                        Some(self.regrow_at(p, time, &all_times, window, &mut grown, &mut out)?)
                    } else {
                        let at = (&poses[k], outsides[k].as_ref());
                        self.part_at(p, time, at, (generator, grow), &mut rest, &mut out)?;
                        // The last frame's velocities are this one's buffer.
                        let buffer = out.take_velocities().unwrap_or_default();
                        let poses = velocity_poses.get(k);
                        self.deform_velocities(p, time, poses, &rest, buffer)?
                    };
                    match velocities {
                        // Carried velocities were found finite as they
                        // were computed: not read a second time.
                        Some(v) if !regrow_velocities => out.set_finite_velocities(v),
                        Some(v) => out.set_velocities(Some(v)).map_err(|e| {
                            GroomWriteError::Groom(self.spec.error(
                                "animation",
                                GroomErrorKind::Velocities {
                                    part: p,
                                    frame: time,
                                    error: e,
                                },
                            ))
                        })?,
                        None => {}
                    }
                    if !counted {
                        summary.hairs += out.curve_count() as u64;
                        summary.points += out.points().len() as u64;
                        counted = true;
                    }
                    if out.curve_count() > 0 {
                        layer
                            .prims()
                            .write_part_at(&part_name(p), time, &out)
                            .map_err(|e| write_error(&output.path, e))?;
                    }
                    if regrow_velocities
                        && let Some(entry) = grown.iter_mut().find(|(x, _)| *x == time)
                    {
                        entry.1 = std::mem::take(&mut out);
                    }
                    done += 1;
                    progress(AnimationProgress {
                        part: p,
                        time,
                        done,
                        total,
                    });
                    if cancel.load(Ordering::Relaxed) {
                        return Err(GroomWriteError::Cancelled);
                    }
                }
            }
            if let Some((rest, _)) = rest {
                self.generator.recycle(rest);
            }
        }
        let mut files = Vec::with_capacity(layers.len());
        for (output, layer) in outputs.iter().zip(layers) {
            files.push(layer.finish().map_err(|e| write_error(&output.path, e))?);
        }
        for file in files {
            file.commit()?;
        }
        Ok(summary)
    }

    /// A time-sampled layer for each output (`.usdc` or `.abc`), each to a
    /// temporary file committed when the window is written.
    fn open_layers(
        &self,
        outputs: &[FrameOutput],
        options: &UsdOptions,
    ) -> Result<Vec<TimeSampledLayer>, GroomWriteError> {
        let mut layers = Vec::with_capacity(outputs.len());
        for output in outputs {
            let format = match CurvesFormat::from_path(&output.path) {
                Some(f) if f.writes_time_samples() => f,
                _ => {
                    return Err(GroomWriteError::Groom(self.spec.error(
                        "output.path",
                        GroomErrorKind::Conflict(format!(
                            "{}: animated grooms are {}",
                            output.path.display(),
                            CurvesFormat::NO_TIME_SAMPLES
                        )),
                    )));
                }
            };
            let file = AtomicFile::create(&output.path)?;
            let layer = match format {
                CurvesFormat::Usdc => {
                    UsdcWriter::new(file, options).map(|w| TimeSampledLayer::Usdc(Box::new(w)))
                }
                _ => AbcWriter::new(file, options).map(|w| TimeSampledLayer::Abc(Box::new(w))),
            }
            .map_err(|e| write_error(&output.path, e))?;
            layers.push(layer);
        }
        Ok(layers)
    }

    /// The posed skin at every time of every output, as a `skin` mesh.
    fn write_skins(
        &self,
        outputs: &[FrameOutput],
        layers: &mut [TimeSampledLayer],
        times: &[f64],
        poses: &[SkinPose],
    ) -> Result<(), GroomWriteError> {
        let index = |t: f64| times.partition_point(|&x| x < t);
        for (output, layer) in outputs.iter().zip(layers.iter_mut()) {
            for &time in &output.times {
                let mesh = self.posed_mesh(&poses[index(time)])?;
                layer
                    .prims()
                    .write_mesh_at("skin", time, &mesh)
                    .map_err(|e| write_error(&output.path, e))?;
            }
        }
        Ok(())
    }

    /// Part `p` regrown at `time` with its velocities by central
    /// differences over the neighbouring time codes among all the groom's
    /// (not this run's: a farm task's or a window's edge grows its
    /// neighbour, so every split writes what one run writes). The growths
    /// are kept in `grown` (three at most) as the frames go by; this
    /// time's is lent to `out` for the write.
    fn regrow_at(
        &self,
        p: usize,
        time: f64,
        all_times: &[f64],
        window: Window<'_>,
        grown: &mut Vec<(f64, Curves)>,
        out: &mut Curves,
    ) -> Result<Vec<Vec3>, GroomError> {
        let i = all_times.partition_point(|&x| x < time);
        let a = if i > 0 { all_times[i - 1] } else { time };
        let b = all_times.get(i + 1).copied().unwrap_or(time);
        for t in [a, time, b] {
            if !grown.iter().any(|(x, _)| *x == t) {
                let c = self.regrown_part(p, t, &window)?;
                grown.push((t, c));
            }
        }
        grown.retain(|(x, _)| *x >= a);
        let span = (b - a) as f32;
        let per_second = if span > 0.0 {
            window.time_codes_per_second as f32 / span
        } else {
            0.0
        };
        let slot = |t: f64| {
            grown
                .iter()
                .position(|(x, _)| *x == t)
                .expect("grown above")
        };
        let velocities = grown[slot(a)]
            .1
            .points()
            .iter()
            .zip(grown[slot(b)].1.points())
            .map(|(x, y)| (*y - *x) * per_second)
            .collect();
        // Lent to `out` for the write, given back after it.
        let now = slot(time);
        *out = std::mem::take(&mut grown[now].1);
        Ok(velocities)
    }

    /// A deform part's velocities at `time` from the skin a little before
    /// and after it (`None` without them).
    fn deform_velocities(
        &self,
        p: usize,
        time: f64,
        poses: Option<&(SkinPose, SkinPose, f32)>,
        rest: &Option<(Curves, RestFrames)>,
        buffer: Vec<Vec3>,
    ) -> Result<Option<Vec<Vec3>>, GroomWriteError> {
        Ok(match (poses, rest) {
            (Some((minus, plus, per_second)), Some((curves, frames))) => Some(
                self.velocities((curves, frames), (minus, plus), *per_second, buffer)
                    .ok_or_else(|| {
                        GroomWriteError::Groom(self.spec.error(
                            "animation",
                            GroomErrorKind::NotFinite(format!(
                                "part {p} at frame {time}: the skin's pose near it moved a hair to a value that is not finite"
                            )),
                        ))
                    })?,
            ),
            _ => None,
        })
    }
}

/// Guide curves from a time-sampled file at time code `time`: USD at that
/// time code, Alembic at `time / fps` seconds; other formats do not move.
pub(crate) fn read_guides_at(
    path: &Path,
    time: f64,
    fps: f64,
) -> Result<Curves, crate::io::CurvesReadError> {
    match CurvesFormat::from_path(path) {
        Some(CurvesFormat::Usda | CurvesFormat::Usdc) => {
            crate::io::read_usd_curves_at(path, Some(time))
        }
        Some(CurvesFormat::Abc) => crate::io::read_abc_curves_at(path, Some(time / fps)),
        _ => crate::io::read_curves(path),
    }
}

/// How [`AnimatedGroom::write_files_grown_until`] grows part `p` of a
/// generator at rest (the rest generator's in deform mode, each frame's
/// in regrow and simulate modes): [`Generator::part`] on the CPU, or
/// another evaluator that gives the same hairs.
pub type GeneratorGrower<'a> = &'a (dyn Fn(&Generator, usize) -> Result<Curves, GroomError> + Sync);

/// The CPU's growth, [`Generator::part`].
const CPU_GROWTH: fn(&Generator, usize) -> Result<Curves, GroomError> = |g, p| g.part(p);

/// What [`AnimatedGroom::write_files_grown_until`] writes: the files, the
/// parts of each, how, and whether the posed skin goes with them.
#[derive(Debug, Clone)]
pub struct AnimatedFiles<'a> {
    /// The files and their time codes.
    pub outputs: &'a [FrameOutput],
    /// The parts written (a farm task's range).
    pub parts: Range<usize>,
    /// The writer's options.
    pub options: &'a UsdOptions,
    /// Whether the posed skin is written too (usdc only).
    pub with_skin: bool,
}

/// A file of an animated groom and the time codes it holds.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameOutput {
    /// Where (`.usdc` or `.abc`).
    pub path: PathBuf,
    /// Its time codes, ascending.
    pub times: Vec<f64>,
}

/// The poses and generators of a window's times, in time order, and the
/// time codes a second they are written at.
#[derive(Clone, Copy)]
struct Window<'a> {
    times: &'a [f64],
    poses: &'a [SkinPose],
    /// Each pose's skin to keep hairs out of.
    outsides: &'a [Option<OutsideSkin>],
    generators: &'a [Option<Generator>],
    time_codes_per_second: f64,
    /// How the parts' hairs are grown at rest.
    grow: GeneratorGrower<'a>,
}

/// A writer's refusal of a prim, as the error of writing `path` (the
/// refusal kept typed inside: `error.get_ref()` downcasts to it).
fn write_error(
    path: &Path,
    e: impl Into<Box<dyn std::error::Error + Send + Sync>>,
) -> GroomWriteError {
    GroomWriteError::Write(crate::io::WriteError {
        path: path.to_path_buf(),
        error: std::io::Error::other(e),
    })
}

/// An open time-sampled output.
enum TimeSampledLayer {
    Usdc(Box<UsdcWriter<AtomicFile>>),
    Abc(Box<AbcWriter<AtomicFile>>),
}

impl TimeSampledLayer {
    fn prims(&mut self) -> &mut dyn PrimWriter {
        match self {
            Self::Usdc(w) => w.as_mut(),
            Self::Abc(w) => w.as_mut(),
        }
    }

    fn finish(self) -> Result<AtomicFile, crate::io::PrimWriteError> {
        match self {
            Self::Usdc(w) => w.finish(),
            Self::Abc(w) => w.finish(),
        }
    }
}
