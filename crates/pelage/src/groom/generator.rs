//! The generator: a [`GroomSpec`] prepared for growing (the root sampler
//! and part layout, the interpolator, the operator chain with its clump
//! centres), and the part-by-part API over it. How a part's hairs grow is
//! in `grow.rs`; how a hair that overflows is traced to its operator, in
//! `diagnose.rs`. See the module docs of [`crate::groom`] for the path of
//! one hair.

use super::error::{GroomError, GroomErrorKind};
use super::grow::{Workspace, sorted_by_triangle};
use super::load::part_count;
use super::ops::{
    Clump, ClumpCentres, Curl, Frizz, Length, Noise, Opacity, Operator, Resampling, Strands, Width,
};
use super::parts::{Part, PartLayout};
use super::spec::{
    ClumpParams, GroomOp, GroomSpec, SpecOrigin, color_maps, root_to_tip_maps, setting_error,
};
use crate::curves::{CurveArrays, Curves};
use crate::guides::Guides;
use crate::interp::Interpolator;
use crate::limits;
use crate::map::Map;
use crate::mesh::{Mesh, SurfacePoint};
use crate::sample::{DensitySampler, DensitySamplerOptions, mix64, salts, sample_range};
use glam::Vec3;
use rayon::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

pub use super::load::HAIRS_PER_PART;

/// What a generated part holds, for progress and summaries.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GroomSummary {
    /// Hairs (curves) written.
    pub hairs: u64,
    /// Points written.
    pub points: u64,
}

/// A groom prepared for generation. Shared by every thread; [`Self::part`]
/// may be called in any order, any number of times.
pub struct Generator {
    pub(super) mesh: Arc<Mesh>,
    pub(super) guides: Arc<Guides>,
    /// The groom's name and where its settings were written, for errors.
    name: PathBuf,
    origin: Option<Arc<SpecOrigin>>,
    pub(super) sampler: Arc<DensitySampler>,
    pub(super) layout: Arc<PartLayout>,
    pub(super) interpolator: Interpolator,
    pub(super) ops: Vec<Operator>,
    /// The finish's width, colour and opacity, before the operators.
    pub(super) base: Vec<Operator>,
    pub(super) points: usize,
    /// From the guides' points to the hairs'.
    pub(super) resampling: Resampling,
    pub(super) colors: bool,
    pub(super) opacities: bool,
    /// Whether a `clump` searches for centres: only then do roots carry
    /// the ball around their triangle.
    pub(super) clumps: bool,
    pub(super) normals: bool,
    pub(super) seed: u64,
    /// Arrays of parts handed back by [`Self::recycle`], for the next parts.
    pub(super) spare: Arc<Mutex<Vec<CurveArrays>>>,
    /// The part asked for last (`usize::MAX`: none yet), and the roots of
    /// the one after it, sampled ahead.
    last_part: AtomicUsize,
    prefetched: Mutex<Option<(usize, Vec<SurfacePoint>)>>,
}

/// Parts' arrays kept for reuse: a writer holds one part while the next
/// grows, so two cover the stream.
const SPARE_PARTS: usize = 2;

impl std::fmt::Debug for Generator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Generator")
            .field("parts", &self.layout.len())
            .field(
                "ops",
                &self.ops.iter().map(Operator::name).collect::<Vec<_>>(),
            )
            .finish()
    }
}

impl Generator {
    /// Prepares `spec` for growing; see [`GroomSpec::generator`].
    pub fn new(spec: GroomSpec) -> Result<Self, GroomError> {
        Self::build(spec, None)
    }

    /// A generator for `spec`, which must be this generator's spec with
    /// other guide shapes (the same guides, roots and everything else):
    /// the root sampler, part layout and guide weights are shared, only
    /// the shapes and what the operators grew from them (clump centres)
    /// are new. Animated grooms regrow each frame this way.
    pub fn reshaped(&self, spec: GroomSpec) -> Result<Self, GroomError> {
        Self::build(spec, Some(self))
    }

    fn build(spec: GroomSpec, shared: Option<&Generator>) -> Result<Self, GroomError> {
        let count = spec.roots.count;
        if count == 0 {
            return Err(spec.error(
                "roots.count",
                GroomErrorKind::Invalid("the hair count must be at least 1".into()),
            ));
        }
        let points = spec.finish.points;
        if points < 2 {
            return Err(spec.error(
                "finish.points",
                GroomErrorKind::Invalid("hairs need at least 2 points".into()),
            ));
        }
        // Groom files are checked as they are read; grooms built in code
        // (the Python package, tests) meet the same ceilings here.
        let ceiling = |key: &str, value: u64, max: u64, what: &str| {
            limits::check_count(value, max, false, what)
                .map_err(|m| spec.error(key, GroomErrorKind::Invalid(m)))
        };
        ceiling("roots.count", count, limits::MAX_HAIRS, "hairs")?;
        ceiling(
            "finish.points",
            points as u64,
            limits::MAX_CURVE_POINTS,
            "points",
        )?;
        for (k, op) in spec.ops.iter().enumerate() {
            match op {
                GroomOp::Clump(c) => ceiling(
                    &format!("ops[{k}].clump.count"),
                    c.count,
                    limits::MAX_CLUMPS,
                    "clumps",
                )?,
                GroomOp::Strands(s) => ceiling(
                    &format!("ops[{k}].strands.count"),
                    u64::from(s.count),
                    limits::MAX_STRANDS,
                    "hairs a strand",
                )?,
                _ => {}
            }
        }
        let (sampler, layout, interpolator) = match shared {
            Some(g) => {
                if g.guides.len() != spec.guides.len() {
                    return Err(spec.error(
                        "guides",
                        GroomErrorKind::Invalid(format!(
                            "{} guides where the groom has {}",
                            spec.guides.len(),
                            g.guides.len()
                        )),
                    ));
                }
                (
                    g.sampler.clone(),
                    g.layout.clone(),
                    g.interpolator.reshaped(&spec.mesh, spec.guides.clone()),
                )
            }
            None => {
                check_maps_on_mesh(&spec)?;
                let mesh = &spec.mesh;
                let sampler = DensitySampler::new(mesh, &spec.roots.density, Default::default())
                    .map_err(|e| spec.error("roots.density", GroomErrorKind::Sample(e)))?;
                let layout = PartLayout::new(
                    mesh,
                    |t| sampler.triangle_probability(t),
                    count,
                    part_count(mesh, count, spec.roots.parts),
                );
                let interpolator =
                    Interpolator::new(mesh, spec.guides.clone(), &spec.interpolation);
                (Arc::new(sampler), Arc::new(layout), interpolator)
            }
        };
        let GroomSpec {
            name,
            mesh,
            guides,
            roots,
            ops,
            finish,
            origin,
            ..
        } = spec;
        let (colors, opacities) = (finish.color.is_some(), finish.opacity.is_some());
        let mut base = vec![Operator::Width(Width(finish.width))];
        base.extend(finish.color.map(Operator::Color));
        base.extend(finish.opacity.map(|o| Operator::Opacity(Opacity(o))));
        let mut generator = Self {
            resampling: Resampling::new(guides.points_per_guide(), points),
            seed: roots.seed,
            mesh,
            guides,
            name,
            origin,
            sampler,
            layout,
            interpolator,
            ops: Vec::with_capacity(ops.len()),
            base,
            points,
            colors,
            opacities,
            clumps: false,
            normals: finish.normals,
            // A frame's generator (`reshaped`) grows parts of the same
            // sizes: it reuses its parent's arrays.
            spare: shared.map_or_else(Default::default, |g| g.spare.clone()),
            last_part: AtomicUsize::new(usize::MAX),
            prefetched: Mutex::new(None),
        };
        for (k, op) in ops.into_iter().enumerate() {
            let op = generator.operator(k, op)?;
            generator.colors |= matches!(op, Operator::Color(_));
            generator.opacities |= matches!(op, Operator::Opacity(_));
            generator.clumps |= matches!(op, Operator::Clump(_));
            generator.ops.push(op);
        }
        Ok(generator)
    }

    /// Builds operator `k` (clump centres are grown through the operators
    /// before it, which are already in `self.ops`).
    fn operator(&self, k: usize, op: GroomOp) -> Result<Operator, GroomError> {
        // Each operator's own random streams: the groom's seed mixed with
        // its position in the chain and its own seed.
        let op_seed = |s: u64| mix64(self.seed ^ mix64((k as u64 + 1) << 32 ^ s));
        let invalid = |key: &str, message: &str| {
            self.error(
                &format!("ops[{k}].{key}"),
                GroomErrorKind::Invalid(message.into()),
            )
        };
        Ok(match op {
            GroomOp::Noise(s) => Operator::Noise(Noise::new(
                s.amplitude,
                s.frequency,
                s.ramp,
                op_seed(s.seed),
                s.vectors,
            )),
            GroomOp::Frizz(s) => Operator::Frizz(Frizz::new(
                s.amplitude,
                s.frequency,
                s.fraction,
                s.ramp,
                op_seed(s.seed),
            )),
            GroomOp::Curl(s) => {
                Operator::Curl(Curl::new(s.radius, s.turns, s.ramp, op_seed(s.seed)))
            }
            GroomOp::Cut(s) => Operator::Cut(s),
            GroomOp::Length(s) => Operator::Length(Length::new(s.scale, s.jitter, op_seed(s.seed))),
            GroomOp::Strands(s) => {
                if s.count == 0 {
                    return Err(invalid("strands.count", "a strand needs at least 1 hair"));
                }
                Operator::Strands(Strands::new(
                    s.count,
                    s.root_spread,
                    s.tip_spread,
                    s.twist,
                    op_seed(s.seed),
                ))
            }
            GroomOp::Width(s) => Operator::Width(Width(s)),
            GroomOp::Color(s) => Operator::Color(s),
            GroomOp::Opacity(s) => Operator::Opacity(Opacity(s)),
            GroomOp::Clump(s) => {
                if s.count == 0 {
                    return Err(invalid(
                        "clump.count",
                        "a clump operator needs at least 1 clump",
                    ));
                }
                let ClumpParams {
                    count,
                    density,
                    rate,
                    ramp,
                    size,
                    seed,
                } = s;
                let sampler =
                    DensitySampler::new(&self.mesh, &density, DensitySamplerOptions::default())
                        .map_err(|e| {
                            self.error(
                                &format!("ops[{k}].clump.density"),
                                GroomErrorKind::Sample(e),
                            )
                        })?;
                let roots = sample_range(&sampler, op_seed(seed), 0..count);
                let centres = self.clump_centres(k, &roots);
                Operator::Clump(Clump::new(centres, rate, ramp, size))
            }
        })
    }

    /// Grows the centre hairs of the clump operator at chain position `k`
    /// through the operators before it. Centre ids live apart from hair ids
    /// (top bits set), so their random numbers are their own.
    fn clump_centres(&self, k: usize, roots: &[SurfacePoint]) -> ClumpCentres {
        let mesh = &self.mesh;
        let shapes: Vec<Vec<Vec3>> = roots
            .par_chunks(256)
            .enumerate()
            .map_init(Workspace::default, |ws, (c, chunk)| {
                let mut out = Vec::with_capacity(chunk.len() * self.points);
                for (i, root) in chunk.iter().enumerate() {
                    let id = (1u64 << 63) | ((k as u64) << 40) | (c * 256 + i) as u64;
                    self.grow(*root, id, &self.ops[..k], ws);
                    match ws.batch.hairs().first() {
                        Some(hair) => out.extend_from_slice(&hair.points),
                        // Cut away entirely: the centre is its interpolated shape.
                        None => self.resampled(&ws.shape, &mut out),
                    }
                }
                out
            })
            .collect();
        let positions = roots.iter().map(|r| r.position(mesh)).collect();
        ClumpCentres::new(positions, shapes.concat(), self.points)
    }

    /// An error about the setting `key`, at its line when the groom came
    /// from a file.
    pub(super) fn error(&self, key: &str, kind: GroomErrorKind) -> GroomError {
        setting_error(&self.name, self.origin.as_deref(), key, kind)
    }

    /// The mesh hairs grow on.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The guides.
    pub fn guides(&self) -> &Guides {
        &self.guides
    }

    /// The seed every random number of the groom derives from.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The parts, in order.
    pub fn parts(&self) -> &[Part] {
        self.layout.parts()
    }

    /// The operator chain.
    pub fn operators(&self) -> &[Operator] {
        &self.ops
    }

    /// Points per hair.
    pub fn points_per_hair(&self) -> usize {
        self.points
    }

    /// Roots of part `p`: sampled in the part's triangles with the part's
    /// own stream, ordered by triangle (so neighbouring hairs are grown
    /// together), numbered from the part's first hair id.
    pub fn part_roots(&self, p: usize) -> Vec<SurfacePoint> {
        let part = &self.layout.parts()[p];
        if part.hair_count == 0 {
            return Vec::new();
        }
        let Some(sampler) = self.sampler.restricted(&part.triangles) else {
            return Vec::new();
        };
        let stream = mix64(self.seed ^ mix64(salts::PART_ROOTS + p as u64));
        let roots = sample_range(&sampler, stream, 0..part.hair_count);
        sorted_by_triangle(roots)
    }

    /// Grows part `p`: its curves with per-point widths, normals (unless
    /// turned off), colours and opacities (when the groom has them), roots,
    /// root UVs (meshes with UVs) and ids. Identical on any thread count:
    /// workers grow fixed chunks of roots, in order.
    ///
    /// # Errors
    /// When a hair's positions, widths, normals, colours or opacities are
    /// not finite (an operator's parameters took it past `f32`'s range):
    /// the error names the operator in the groom file, from growing that
    /// hair again one operator at a time.
    pub fn part(&self, p: usize) -> Result<Curves, GroomError> {
        let roots = self
            .take_prefetched(p)
            .unwrap_or_else(|| self.part_roots(p));
        // Parts asked for in order (a whole groom, a farm task's range):
        // the next part's roots are sampled and sorted beside this part's
        // growth, on threads that would otherwise wait for its last chunks.
        let previous = self.last_part.swap(p, Ordering::Relaxed);
        let prefetch = p + 1 < self.layout.len() && (p == 0 || previous == p - 1);
        let (curves, next) = rayon::join(
            || self.grow_part(p, roots),
            || prefetch.then(|| self.part_roots(p + 1)),
        );
        if let Some(next) = next {
            *self.prefetched.lock().unwrap_or_else(|e| e.into_inner()) = Some((p + 1, next));
        }
        curves
    }

    /// The roots of part `p` if they were sampled ahead.
    fn take_prefetched(&self, p: usize) -> Option<Vec<SurfacePoint>> {
        let mut prefetched = self.prefetched.lock().unwrap_or_else(|e| e.into_inner());
        match prefetched.take() {
            Some((q, roots)) if q == p => Some(roots),
            _ => None,
        }
    }

    /// Hands a grown part back once it is written, so that a later part
    /// reuses its memory instead of asking the kernel for fresh pages
    /// (whose first touch faults and zeroes them: a tenth of a groom's
    /// time). Optional; a part not handed back is simply freed.
    pub fn recycle(&self, curves: Curves) {
        let mut spare = self.spare.lock().unwrap_or_else(|e| e.into_inner());
        if spare.len() < SPARE_PARTS {
            spare.push(curves.into_arrays());
        }
    }

    pub(super) fn spare_arrays(&self) -> CurveArrays {
        let mut spare = self.spare.lock().unwrap_or_else(|e| e.into_inner());
        spare.pop().unwrap_or_default()
    }
}

/// Every map of the groom can be read on its mesh (image and noise maps
/// need UVs): an error naming the setting otherwise.
fn check_maps_on_mesh(spec: &GroomSpec) -> Result<(), GroomError> {
    let finish = &spec.finish;
    let mut maps: Vec<(String, &Map)> = vec![("roots.density".into(), &spec.roots.density)];
    fn add<'m>(maps: &mut Vec<(String, &'m Map)>, prefix: &str, named: Vec<(&str, &'m Map)>) {
        for (key, map) in named {
            maps.push((format!("{prefix}.{key}"), map));
        }
    }
    add(&mut maps, "finish.width", root_to_tip_maps(&finish.width));
    if let Some(color) = &finish.color {
        add(&mut maps, "finish.color", color_maps(color));
    }
    if let Some(opacity) = &finish.opacity {
        add(&mut maps, "finish.opacity", root_to_tip_maps(opacity));
    }
    for (k, op) in spec.ops.iter().enumerate() {
        add(&mut maps, &format!("ops[{k}].{}", op.name()), op.maps());
    }
    for (key, map) in maps {
        map.on_mesh(&spec.mesh)
            .map_err(|e| spec.error(&key, GroomErrorKind::Map(e)))?;
    }
    Ok(())
}
