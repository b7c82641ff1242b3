//! `[animation] mode = "simulate"`: a groom's guides simulated over its
//! frames on the animated skin ([`GuideSimulation`]: gravity, wind, the
//! skin's motion through the roots, collisions with the body), then every
//! frame regrown from them (the regrow path of [`super::animate`]).
//!
//! The simulation runs from the first frame written, after `preroll`
//! frames at that frame's pose for the guides to settle from their
//! groomed shape, to the last. It is deterministic (the same input gives
//! the same bits on any thread count), so the tasks of a farm may each
//! simulate it again and agree; or one simulates it into a cache file
//! (`[simulation] cache`, [`cached_simulation`]) that the others read.
//! A cache carries a key of everything the simulation read (the
//! settings, the guides, the skin at every frame, pelage's version), so
//! a stale one is simulated again, never used. Sub-frame times (motion
//! blur) read the guides interpolated linearly between the two frames
//! around them.

use super::animate::GuideMotion;
use super::error::{GroomError, GroomErrorKind};
use super::output::GroomWriteError;
use super::spec::GroomSpec;
use crate::Curves;
use crate::anim::{AnimatedSkin, SkinPose};
use crate::dynamics::{GuideSimulation, GuideStrandParams};
use crate::io::{AbcWriter, AtomicFile, CurvesFormat, UsdOptions, UsdcWriter};
use std::ops::RangeInclusive;
use std::path::Path;
use std::sync::Arc;

/// The name of the guides' prim (USD) or object (Alembic) in a file of
/// simulated guides.
pub const SIMULATED_GUIDES_NAME: &str = "guides";

/// How a groom's guides are simulated.
#[derive(Debug, Clone)]
pub struct SimulationSettings {
    /// The solver's settings.
    pub params: GuideStrandParams,
    /// Collide with the skin.
    pub collide: bool,
    /// Frames at the first frame's pose before it.
    pub preroll: u32,
    /// Frames per second.
    pub fps: f64,
    /// The frames simulated, first to last: a groom's whole range (the
    /// file's, and any frame a run writes beyond it), whichever frames a
    /// run writes, so every task of a farm simulates the same.
    pub frames: RangeInclusive<i32>,
}

/// Guides simulated over a groom's frames: their shape on the posed skin
/// (scene space) at every frame from the first to the last.
#[derive(Debug, Clone)]
pub struct SimulatedGuides {
    first: i32,
    shapes: Arc<Vec<Curves>>,
    key: u64,
}

impl SimulatedGuides {
    /// The frames simulated, first to last.
    pub fn frames(&self) -> RangeInclusive<i32> {
        self.first..=self.first + self.shapes.len() as i32 - 1
    }

    /// The guides at `frame`, when it was simulated.
    pub fn at(&self, frame: i32) -> Option<&Curves> {
        let k = usize::try_from(frame.checked_sub(self.first)?).ok()?;
        self.shapes.get(k)
    }

    /// The key of everything the simulation read ([`simulation_key`]).
    pub fn key(&self) -> u64 {
        self.key
    }

    /// The guides as the regrow path reads them, frame by frame.
    pub fn motion(&self) -> GuideMotion {
        let (shapes, first) = (self.shapes.clone(), self.first);
        GuideMotion::Program(Arc::new(move |time: f64| {
            guides_between(&shapes, time - f64::from(first))
        }))
    }

    /// Writes the guides to `path` with a time sample a frame: `.usdc` (or
    /// `.usd`) as a `BasisCurves` prim with `purpose = "guide"` and the key
    /// in the layer's `documentation`, or `.abc` as a curves object
    /// flagged `groom_guide = 1`, both named [`SIMULATED_GUIDES_NAME`].
    /// Atomically: a reader sees the old file or the whole new one.
    pub fn write(&self, path: &Path, options: &UsdOptions) -> Result<(), GroomWriteError> {
        let failed = |e: crate::io::PrimWriteError| {
            GroomWriteError::Write(crate::io::WriteError {
                path: path.to_path_buf(),
                error: std::io::Error::other(e),
            })
        };
        let file = AtomicFile::create(path)?;
        let file = match CurvesFormat::from_path(path) {
            Some(CurvesFormat::Usdc) => {
                let mut usd = UsdcWriter::new(file, options).map_err(failed)?;
                usd.set_documentation(&cache_documentation(self.key));
                for frame in self.frames() {
                    let guides = self.at(frame).expect("a simulated frame");
                    usd.write_guides_at(SIMULATED_GUIDES_NAME, f64::from(frame), guides)
                        .map_err(failed)?;
                }
                usd.finish().map_err(failed)?
            }
            Some(CurvesFormat::Abc) => {
                let mut abc = AbcWriter::new(file, options).map_err(failed)?;
                for frame in self.frames() {
                    let guides = self.at(frame).expect("a simulated frame");
                    abc.write_guides_at(SIMULATED_GUIDES_NAME, f64::from(frame), guides)
                        .map_err(failed)?;
                }
                abc.finish().map_err(failed)?
            }
            _ => {
                return Err(failed(crate::io::PrimWriteError::BadSetting(format!(
                    "simulated guides are {}",
                    CurvesFormat::NO_TIME_SAMPLES
                ))));
            }
        };
        file.commit()?;
        Ok(())
    }
}

/// The `documentation` string of a cache of simulated guides with `key`.
fn cache_documentation(key: u64) -> String {
    format!(
        "Guides simulated by pelage {}; simulation key {key:016x}",
        env!("CARGO_PKG_VERSION")
    )
}

/// What [`cached_simulation`] did with the cache file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CacheUse {
    /// Read it: its key matched.
    Read,
    /// There was none: simulated, and wrote it.
    Written,
    /// It was stale (another key, or not a cache of these guides):
    /// simulated again, and replaced it.
    Replaced,
}

/// The first and last frame simulated.
fn frame_span(spec: &GroomSpec, settings: &SimulationSettings) -> Result<(i32, i32), GroomError> {
    let (first, last) = (*settings.frames.start(), *settings.frames.end());
    if first > last {
        return Err(spec.error(
            "animation.frames",
            GroomErrorKind::Conflict("no frames to simulate".into()),
        ));
    }
    Ok((first, last))
}

/// The skin's vertices at `frame`.
fn skin_at(
    spec: &GroomSpec,
    skin: &AnimatedSkin,
    frame: i32,
) -> Result<Vec<glam::Vec3>, GroomError> {
    skin.positions_at(f64::from(frame))
        .map_err(|e| spec.error("animation", GroomErrorKind::Mesh(e)))
}

/// A key of everything a simulation of `spec`'s guides reads: pelage's
/// version, the settings, the frames, the guides and their roots, the
/// skin's triangles and its vertices at rest and at every frame
/// (FNV-1a, 64 bits, over their bits). Two runs with the same key
/// simulate the same bits.
pub fn simulation_key(
    spec: &GroomSpec,
    skin: &AnimatedSkin,
    settings: &SimulationSettings,
) -> Result<u64, GroomError> {
    let (first, last) = frame_span(spec, settings)?;
    let mut key = Fnv1a::default();
    key.bytes(env!("CARGO_PKG_VERSION").as_bytes());
    key.bytes(format!("{settings:?}").as_bytes());
    key.bytes(&first.to_le_bytes());
    key.bytes(&last.to_le_bytes());
    key.bytes(bytemuck::cast_slice(spec.guides.curves().points()));
    key.bytes(format!("{:?}", spec.guides.roots()).as_bytes());
    key.bytes(bytemuck::cast_slice(spec.mesh.triangles()));
    key.bytes(bytemuck::cast_slice(spec.mesh.positions()));
    for frame in first..=last {
        key.bytes(bytemuck::cast_slice(&skin_at(spec, skin, frame)?));
    }
    Ok(key.0)
}

/// FNV-1a, 64 bits: small, stable across platforms and versions of Rust
/// (unlike `std`'s hasher), which a key written to a file needs.
pub(crate) struct Fnv1a(pub(crate) u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    pub(crate) fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
}

/// The guides of `spec` simulated as [`simulate_guides`] does, read from
/// the `.usdc` file `cache` when it holds this simulation (its key
/// matches), else simulated and written there (atomically: farm tasks
/// that race to write it write the same bits).
pub fn cached_simulation(
    spec: &GroomSpec,
    skin: &AnimatedSkin,
    settings: &SimulationSettings,
    cache: &Path,
) -> Result<(SimulatedGuides, CacheUse), GroomError> {
    cached_simulation_until(spec, skin, settings, cache, &|| false)
}

/// [`cached_simulation`], asking `stop` after every simulated frame
/// whether to give up (a Ctrl-C): then a [`GroomErrorKind::Stopped`]
/// error, and the cache is left as it was.
pub fn cached_simulation_until(
    spec: &GroomSpec,
    skin: &AnimatedSkin,
    settings: &SimulationSettings,
    cache: &Path,
    stop: &dyn Fn() -> bool,
) -> Result<(SimulatedGuides, CacheUse), GroomError> {
    if CurvesFormat::from_path(cache) != Some(CurvesFormat::Usdc) {
        return Err(spec.error(
            "simulation.cache",
            GroomErrorKind::Conflict(format!(
                "{}: a simulation cache is a .usdc file",
                cache.display()
            )),
        ));
    }
    let key = simulation_key(spec, skin, settings)?;
    let (first, last) = frame_span(spec, settings)?;
    let existed = cache.exists();
    if existed && let Some(shapes) = read_cache(cache, key, (first, last), spec) {
        let guides = SimulatedGuides {
            first,
            shapes: Arc::new(shapes),
            key,
        };
        return Ok((guides, CacheUse::Read));
    }
    // The cache must take the result: checked before the simulation.
    crate::io::check_writable(cache)
        .map_err(|e| spec.error("simulation.cache", GroomErrorKind::Cache(Box::new(e))))?;
    let guides = simulate_with_key(spec, skin, settings, key, stop)?;
    let options = UsdOptions {
        time_codes_per_second: settings.fps,
        ..UsdOptions::default()
    };
    guides
        .write(cache, &options)
        .map_err(|e| spec.error("simulation.cache", GroomErrorKind::Cache(Box::new(e))))?;
    let used = if existed {
        CacheUse::Replaced
    } else {
        CacheUse::Written
    };
    Ok((guides, used))
}

/// The frames of a cache file when it holds the simulation with `key`
/// of `spec`'s guides over `first..=last`; `None` for any other file.
fn read_cache(
    cache: &Path,
    key: u64,
    (first, last): (i32, i32),
    spec: &GroomSpec,
) -> Option<Vec<Curves>> {
    let info = crate::io::read_usd_layer_info(cache).ok()?;
    if info.documentation.as_deref() != Some(cache_documentation(key).as_str()) {
        return None;
    }
    let (guides, n) = (spec.guides.len(), spec.guides.points_per_guide());
    let file = crate::io::UsdCurvesSequence::open(cache).ok()?;
    (first..=last)
        .map(|frame| {
            let curves = file.at(f64::from(frame)).ok()?;
            let whole = curves.curve_count() == guides && curves.points().len() == guides * n;
            whole.then_some(curves)
        })
        .collect()
}

/// The guides of `spec` (bound to its mesh, the skin's rest pose)
/// simulated over `settings.frames` on `skin`.
pub fn simulate_guides(
    spec: &GroomSpec,
    skin: &AnimatedSkin,
    settings: &SimulationSettings,
) -> Result<SimulatedGuides, GroomError> {
    simulate_guides_until(spec, skin, settings, &|| false)
}

/// [`simulate_guides`], asking `stop` after every simulated frame (and
/// preroll step) whether to give up: then a [`GroomErrorKind::Stopped`]
/// error.
pub fn simulate_guides_until(
    spec: &GroomSpec,
    skin: &AnimatedSkin,
    settings: &SimulationSettings,
    stop: &dyn Fn() -> bool,
) -> Result<SimulatedGuides, GroomError> {
    let key = simulation_key(spec, skin, settings)?;
    simulate_with_key(spec, skin, settings, key, stop)
}

/// [`simulate_guides_until`], its key known.
fn simulate_with_key(
    spec: &GroomSpec,
    skin: &AnimatedSkin,
    settings: &SimulationSettings,
    key: u64,
    stop: &dyn Fn() -> bool,
) -> Result<SimulatedGuides, GroomError> {
    let triangles = spec.mesh.triangles();
    let rest = SkinPose::new(spec.mesh.positions().to_vec(), triangles);
    let mut sim = GuideSimulation::new(
        &spec.guides,
        triangles,
        &rest,
        settings.params.clone(),
        settings.collide,
    )
    .map_err(|e| spec.error("simulation", GroomErrorKind::Strands(e)))?;
    let (first, last) = frame_span(spec, settings)?;
    let pose = |frame: i32| -> Result<SkinPose, GroomError> {
        Ok(SkinPose::new(skin_at(spec, skin, frame)?, triangles))
    };
    let stopped = |frame: i32| {
        spec.error(
            "simulation",
            GroomErrorKind::Stopped(format!("simulating the guides, at frame {frame}")),
        )
    };
    let dt = (1.0 / settings.fps) as f32;
    let start = pose(first)?;
    sim.reset(&start);
    for k in 0..settings.preroll {
        if stop() {
            return Err(stopped(first));
        }
        sim.advance(&start, dt, k as f32 * dt);
    }
    let shape = |sim: &GuideSimulation, frame: i32| {
        sim.curves().map_err(|e| {
            spec.error(
                "simulation",
                GroomErrorKind::NotFinite(format!(
                    "the simulated guides at frame {frame} are not finite ({e}): the [simulation] settings are out of any sensible range"
                )),
            )
        })
    };
    let mut shapes: Vec<Curves> = Vec::with_capacity((last - first + 1) as usize);
    shapes.push(shape(&sim, first)?);
    for frame in first + 1..=last {
        if stop() {
            return Err(stopped(frame));
        }
        let now = pose(frame)?;
        let time = (settings.preroll as i32 + frame - first) as f32 * dt;
        sim.advance(&now, dt, time);
        shapes.push(shape(&sim, frame)?);
    }
    Ok(SimulatedGuides {
        first,
        shapes: Arc::new(shapes),
        key,
    })
}

/// The simulated guides `offset` frames after the first: a frame's own,
/// or the two around a sub-frame time blended linearly (held at the ends).
fn guides_between(shapes: &[Curves], offset: f64) -> Curves {
    let last = shapes.len() - 1;
    let at = offset.clamp(0.0, last as f64);
    let (i, a) = (at.floor() as usize, (at - at.floor()) as f32);
    if a == 0.0 || i >= last {
        return shapes[i.min(last)].clone();
    }
    let (from, to) = (&shapes[i], &shapes[i + 1]);
    let points = from
        .points()
        .iter()
        .zip(to.points())
        .map(|(p, q)| p.lerp(*q, a))
        .collect();
    Curves::new(points, from.widths().to_vec(), from.offsets().to_vec())
        .expect("the guides' own layout")
}
