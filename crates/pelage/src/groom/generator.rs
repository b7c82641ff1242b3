//! The groom generator: [`Groom`] (a loaded groom file) and [`Generator`]
//! (prepared to grow parts). See the module docs of [`crate::groom`] for
//! the path of one hair.

use super::file::{
    ColorSpec, GroomError, GroomErrorKind, GroomFile, GroomSource, MapValue, OpSpec, RootToTipSpec,
};
use super::ops::{
    Clump, ClumpCentres, Color, Curl, Cut, Frizz, Hair, HairBatch, Length, Noise, Opacity,
    Operator, Resampling, RootContext, RootToTip, Scratch, Strands, Width,
};
use super::parts::{Part, PartLayout};
use crate::curves::frames::{
    FrameScratch, catmull_rom_tangents, hair_normals, rotation_minimizing_normals,
};
use crate::curves::{CurveArrays, Curves, Values, vectors_finite};
use crate::guides::{BindReport, CombMap, GuideGrowth, Guides};
use crate::interp::{
    HairRoot, HairScratch, InterpolationMethod, Interpolator, QueryRegion, StyleMeshOptions,
};
use crate::map::Map;
use crate::mesh::{Mesh, SurfacePoint};
use crate::sample::{DensitySampler, DensitySamplerOptions, mix64, sample_range};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Hairs per part when the groom file does not say.
pub const HAIRS_PER_PART: u64 = 100_000;

/// Hairs a worker grows between hand-overs (fixed, so results never depend
/// on the number of threads).
const CHUNK: usize = 512;

/// A groom file loaded: the file, its mesh and guides.
pub struct Groom {
    source: GroomSource,
    file: GroomFile,
    mesh: Mesh,
    guides: Guides,
    bind_report: Option<BindReport>,
}

impl std::fmt::Debug for Groom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Groom")
            .field("path", &self.source.path)
            .field("mesh", &self.mesh.name())
            .field("guides", &self.guides.len())
            .finish()
    }
}

impl Groom {
    /// Reads, parses and loads the groom file at `path`.
    pub fn load(path: &Path) -> Result<Self, GroomError> {
        Self::from_source(GroomSource::read(path)?)
    }

    /// Loads a groom from its text (`path` names it in errors and is the
    /// base of relative paths).
    pub fn from_text(
        path: impl Into<PathBuf>,
        text: impl Into<String>,
    ) -> Result<Self, GroomError> {
        Self::from_source(GroomSource {
            path: path.into(),
            text: text.into(),
        })
    }

    /// Parses the source, loads the mesh and the guides.
    pub fn from_source(source: GroomSource) -> Result<Self, GroomError> {
        let file = source.parse()?;
        let mesh = load_mesh(&source, &file)?;
        let (guides, bind_report) = load_guides(&source, &file, &mesh)?;
        Ok(Self {
            source,
            file,
            mesh,
            guides,
            bind_report,
        })
    }

    /// The parsed file.
    pub fn file(&self) -> &GroomFile {
        &self.file
    }

    /// The file's path and text.
    pub fn source(&self) -> &GroomSource {
        &self.source
    }

    /// The mesh hairs grow on.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The guides, bound to the mesh.
    pub fn guides(&self) -> &Guides {
        &self.guides
    }

    /// When the guides came from a file: what binding them kept and left
    /// out.
    pub fn bind_report(&self) -> Option<&BindReport> {
        self.bind_report.as_ref()
    }

    /// Where the curves go: `[output] path` relative to the groom file, or
    /// the groom file's name with `.usda`.
    pub fn output_path(&self) -> PathBuf {
        match &self.file.output.path {
            Some(p) => self.source.folder().join(p),
            None => self.source.path.with_extension("usda"),
        }
    }

    /// The number of parts: `[roots] parts`, or one per
    /// 100,000 hairs; never more than the mesh has triangles.
    pub fn part_count(&self) -> usize {
        let wanted = match &self.file.roots.parts {
            Some(p) => (*p.get_ref()).max(1) as usize,
            None => self
                .file
                .roots
                .count
                .get_ref()
                .div_ceil(HAIRS_PER_PART)
                .max(1) as usize,
        };
        wanted.min(self.mesh.triangle_count()).max(1)
    }

    /// Prepares generation: the root sampler and part layout, the
    /// interpolator (the style mesh is built here), the operator chain and
    /// its clump centres. `seed` overrides the file's.
    pub fn generator(&self, seed: Option<u64>) -> Result<Generator<'_>, GroomError> {
        Generator::new(self, seed)
    }

    fn map(&self, value: &MapValue) -> Result<Map, GroomError> {
        map_on_mesh(&self.source, &self.mesh, value)
    }
}

/// Resolves a map value and checks it can be read on `mesh` (UVs), both
/// errors at the value's line.
fn map_on_mesh(source: &GroomSource, mesh: &Mesh, value: &MapValue) -> Result<Map, GroomError> {
    let map = source.map(value)?;
    map.on_mesh(mesh)
        .map_err(|e| source.error_at(value.span(), GroomErrorKind::Map(e)))?;
    Ok(map)
}

fn load_mesh(source: &GroomSource, file: &GroomFile) -> Result<Mesh, GroomError> {
    load_mesh_section(source, &file.mesh)
}

/// The mesh a `[mesh]` section names (`"spot"`: the embedded one),
/// subdivided as asked; a mesh that cannot be loaded is reported at its
/// line.
pub(crate) fn load_mesh_section(
    source: &GroomSource,
    section: &super::file::MeshSection,
) -> Result<Mesh, GroomError> {
    let path = &section.path;
    let mesh = if path.get_ref() == "spot" {
        crate::assets::spot()
    } else {
        Mesh::load(source.folder().join(path.get_ref()))
            .map_err(|e| source.error_at(path.span(), GroomErrorKind::Mesh(e)))?
    };
    Ok(match section.subdivide {
        0 => mesh,
        n => mesh.subdivided(n),
    })
}

fn load_guides(
    source: &GroomSource,
    file: &GroomFile,
    mesh: &Mesh,
) -> Result<(Guides, Option<BindReport>), GroomError> {
    let section = &file.guides;
    let invalid =
        |span, message: &str| source.error_at(span, GroomErrorKind::Invalid(message.to_string()));
    match (&section.file, &section.generate) {
        (Some(path), None) => {
            let full = source.folder().join(path.get_ref());
            let curves = crate::io::read_curves(&full)
                .map_err(|e| source.error_at(path.span(), GroomErrorKind::Guides(e)))?;
            let (guides, report) = Guides::bind(mesh, &curves, section.points, section.tolerance);
            if guides.is_empty() {
                return Err(invalid(
                    path.span(),
                    "no guide is within the tolerance of the mesh; check that the guides belong to this mesh, or raise [guides] tolerance",
                ));
            }
            Ok((guides, Some(report)))
        }
        (None, Some(generate)) => {
            let map = |v: &MapValue| map_on_mesh(source, mesh, v);
            let growth = GuideGrowth {
                count: generate.count.max(1),
                density: map(&generate.density)?,
                length: map(&generate.length)?,
                comb: Vec3::from(generate.comb),
                comb_map: match &generate.comb_map {
                    Some([u, v]) => Some(CombMap {
                        u: map(u)?,
                        v: map(v)?,
                        strength: generate.comb_strength,
                    }),
                    None => None,
                },
                gravity: generate.gravity,
                points: section.points,
                width: 0.004,
                seed: generate.seed,
            };
            let guides = Guides::grow(mesh, &growth).map_err(|e| {
                source.error_at(generate.length.span(), GroomErrorKind::GuideGrowth(e))
            })?;
            Ok((guides, None))
        }
        _ => Err(GroomError::new(
            source.path.clone(),
            None,
            Some("guides".into()),
            GroomErrorKind::Invalid(
                "give exactly one of `file = \"guides.usda\"` or a [guides.generate] table".into(),
            ),
        )),
    }
}

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
pub struct Generator<'g> {
    groom: &'g Groom,
    sampler: DensitySampler<'g>,
    layout: PartLayout,
    interpolator: Interpolator<'g>,
    ops: Vec<Operator>,
    base: Vec<Operator>,
    points: usize,
    /// From the guides' points to the hairs'.
    resampling: Resampling,
    colors: bool,
    opacities: bool,
    /// Whether a `clump` searches for centres: only then do roots carry
    /// the ball around their triangle.
    clumps: bool,
    normals: bool,
    seed: u64,
    /// Arrays of parts handed back by [`Self::recycle`], for the next parts.
    spare: Mutex<Vec<CurveArrays>>,
    /// The part asked for last (`usize::MAX`: none yet), and the roots of
    /// the one after it, sampled ahead.
    last_part: AtomicUsize,
    prefetched: Mutex<Option<(usize, Vec<SurfacePoint>)>>,
}

/// Parts' arrays kept for reuse: a writer holds one part while the next
/// grows, so two cover the stream.
const SPARE_PARTS: usize = 2;

impl std::fmt::Debug for Generator<'_> {
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

/// Per-thread buffers.
#[derive(Default)]
struct Workspace {
    interpolation: HairScratch,
    shape: Vec<Vec3>,
    batch: HairBatch,
    scratch: Scratch,
    /// Each hair's skin normal, the start of its frame.
    skin_normals: Vec<Vec3>,
    frames: FrameScratch,
    /// A group of hairs grown side by side ([`Generator::grow_group`]) and
    /// their roots.
    group: Vec<Hair>,
    contexts: Vec<RootContext>,
}

/// Hairs grown side by side through the operators when each root grows one
/// hair: enough to fill the noise's eight SIMD lanes several times over.
const GROUP: usize = 8;

impl<'g> Generator<'g> {
    fn new(groom: &'g Groom, seed: Option<u64>) -> Result<Self, GroomError> {
        let file = &groom.file;
        let source = &groom.source;
        let mesh = &groom.mesh;
        let seed = seed.unwrap_or(file.roots.seed);
        let count = *file.roots.count.get_ref();
        if count == 0 {
            return Err(source.error_at(
                file.roots.count.span(),
                GroomErrorKind::Invalid("the hair count must be at least 1".into()),
            ));
        }
        let points = *file.finish.points.get_ref();
        if points < 2 {
            return Err(source.error_at(
                file.finish.points.span(),
                GroomErrorKind::Invalid("hairs need at least 2 points".into()),
            ));
        }
        let density = groom.map(&file.roots.density)?;
        let sampler = DensitySampler::new(mesh, &density, DensitySamplerOptions::default())
            .map_err(|e| source.error_at(file.roots.density.span(), GroomErrorKind::Sample(e)))?;
        let layout = PartLayout::new(
            mesh,
            |t| sampler.triangle_probability(t),
            count,
            groom.part_count(),
        );

        let method = &file.interpolation;
        let interpolation = match method.method.get_ref().as_str() {
            "shepard" => InterpolationMethod::Shepard {
                k: method.k.max(1),
                power: method.power,
                radius: method.radius,
            },
            "style-mesh" | "style_mesh" => InterpolationMethod::StyleMesh(StyleMeshOptions {
                split_shared: method.split_shared,
            }),
            other => {
                return Err(source.error_at(
                    method.method.span(),
                    GroomErrorKind::Invalid(format!(
                        "unknown interpolation method {other:?}; the methods are \"shepard\" and \"style-mesh\""
                    )),
                ));
            }
        };
        let interpolator = Interpolator::new(mesh, &groom.guides, &interpolation);

        let mut base = vec![Operator::Width(Width(root_to_tip(
            groom,
            &file.finish.width,
        )?))];
        if let Some(color) = &file.finish.color {
            base.push(Operator::Color(color_spec(groom, color)?));
        }
        if let Some(opacity) = &file.finish.opacity {
            base.push(Operator::Opacity(Opacity(root_to_tip(groom, opacity)?)));
        }
        let mut generator = Self {
            groom,
            sampler,
            layout,
            interpolator,
            ops: Vec::with_capacity(file.ops.len()),
            base,
            points,
            resampling: Resampling::new(groom.guides.points_per_guide(), points),
            colors: file.finish.color.is_some(),
            opacities: file.finish.opacity.is_some(),
            clumps: false,
            normals: file.finish.normals,
            seed,
            spare: Mutex::new(Vec::new()),
            last_part: AtomicUsize::new(usize::MAX),
            prefetched: Mutex::new(None),
        };
        for (k, spec) in file.ops.iter().enumerate() {
            let op = generator.operator(k, spec)?;
            generator.colors |= matches!(op, Operator::Color(_));
            generator.opacities |= matches!(op, Operator::Opacity(_));
            generator.clumps |= matches!(op, Operator::Clump(_));
            generator.ops.push(op);
        }
        Ok(generator)
    }

    /// Builds operator `k` (clump centres are grown through the operators
    /// before it, which are already in `self.ops`).
    fn operator(&self, k: usize, spec: &OpSpec) -> Result<Operator, GroomError> {
        let groom = self.groom;
        let m = |v: &MapValue| groom.map(v);
        // Each operator's own random streams: the file's seed mixed with
        // its position in the chain and its seed key.
        let op_seed = |s: u64| mix64(self.seed ^ mix64((k as u64 + 1) << 32 ^ s));
        Ok(match spec {
            OpSpec::Noise(s) => Operator::Noise(Noise::new(
                m(&s.amplitude)?,
                m(&s.frequency)?,
                s.ramp.clone(),
                op_seed(s.seed),
                s.vectors,
            )),
            OpSpec::Frizz(s) => Operator::Frizz(Frizz::new(
                m(&s.amplitude)?,
                m(&s.frequency)?,
                m(&s.fraction)?,
                s.ramp.clone(),
                op_seed(s.seed),
            )),
            OpSpec::Curl(s) => Operator::Curl(Curl::new(
                m(&s.radius)?,
                m(&s.turns)?,
                s.ramp.clone(),
                op_seed(s.seed),
            )),
            OpSpec::Cut(s) => Operator::Cut(Cut::new(m(&s.at)?)),
            OpSpec::Length(s) => {
                Operator::Length(Length::new(m(&s.scale)?, m(&s.jitter)?, op_seed(s.seed)))
            }
            OpSpec::Strands(s) => {
                if *s.count.get_ref() == 0 {
                    return Err(groom.source.error_at(
                        s.count.span(),
                        GroomErrorKind::Invalid("a strand needs at least 1 hair".into()),
                    ));
                }
                Operator::Strands(Strands::new(
                    *s.count.get_ref(),
                    m(&s.root_spread)?,
                    m(&s.tip_spread)?,
                    m(&s.twist)?,
                    op_seed(s.seed),
                ))
            }
            OpSpec::Width(s) => Operator::Width(Width(root_to_tip(groom, s)?)),
            OpSpec::Color(s) => Operator::Color(color_spec(groom, s)?),
            OpSpec::Opacity(s) => Operator::Opacity(Opacity(root_to_tip(groom, s)?)),
            OpSpec::Clump(s) => {
                let count = *s.count.get_ref();
                if count == 0 {
                    return Err(groom.source.error_at(
                        s.count.span(),
                        GroomErrorKind::Invalid("a clump operator needs at least 1 clump".into()),
                    ));
                }
                let density = m(&s.density)?;
                let sampler =
                    DensitySampler::new(&groom.mesh, &density, DensitySamplerOptions::default())
                        .map_err(|e| {
                            groom
                                .source
                                .error_at(s.density.span(), GroomErrorKind::Sample(e))
                        })?;
                let roots = sample_range(&sampler, op_seed(s.seed), 0..count);
                let centres = self.clump_centres(k, &roots);
                Operator::Clump(Clump::new(
                    centres,
                    m(&s.rate)?,
                    s.ramp.clone(),
                    s.size.as_ref().map(m).transpose()?,
                ))
            }
        })
    }

    /// Grows the centre hairs of the clump operator at chain position `k`
    /// through the operators before it. Centre ids live apart from hair ids
    /// (top bits set), so their random numbers are their own.
    fn clump_centres(&self, k: usize, roots: &[SurfacePoint]) -> ClumpCentres {
        let mesh = &self.groom.mesh;
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

    /// The groom.
    pub fn groom(&self) -> &'g Groom {
        self.groom
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

    /// Hair `id` grown from `root` through `ops` into `ws.batch`; returns
    /// the skin normal at the root.
    fn grow(&self, root: SurfacePoint, id: u64, ops: &[Operator], ws: &mut Workspace) -> Vec3 {
        let context = self.root_context(root);
        let hair = ws.batch.reset();
        self.interpolated(&context, id, &mut ws.interpolation, &mut ws.shape, hair);
        for op in self.base.iter().chain(ops) {
            op.apply(&mut ws.batch, &context, &mut ws.scratch);
            if ws.batch.is_empty() {
                break;
            }
        }
        context.normal
    }

    /// Hairs `first_id…` grown from `roots` (at most [`GROUP`]) through
    /// every operator side by side, into `ws.group` with their roots in
    /// `ws.contexts`: hair for hair what [`Self::grow`] makes, for grooms
    /// whose operators keep one hair a root.
    fn grow_group(&self, roots: &[SurfacePoint], first_id: u64, ws: &mut Workspace) {
        if ws.group.len() < roots.len() {
            ws.group.resize_with(roots.len(), Hair::default);
        }
        ws.contexts.clear();
        for (i, root) in roots.iter().enumerate() {
            let context = self.root_context(*root);
            let hair = &mut ws.group[i];
            let id = first_id + i as u64;
            self.interpolated(&context, id, &mut ws.interpolation, &mut ws.shape, hair);
            ws.contexts.push(context);
        }
        let hairs = &mut ws.group[..roots.len()];
        for op in self.base.iter().chain(&self.ops) {
            op.apply_each(hairs, &ws.contexts, &mut ws.scratch);
        }
    }

    /// Where a hair grows: its root's position, skin normal and UV.
    fn root_context(&self, root: SurfacePoint) -> RootContext {
        let mesh = &self.groom.mesh;
        RootContext {
            point: root,
            position: root.position(mesh),
            normal: root.normal(mesh),
            uv: root.uv(mesh).unwrap_or(Vec2::ZERO),
            skin_triangle: self
                .clumps
                .then(|| QueryRegion::around_triangle(mesh.triangle_positions(root.tri as usize))),
        }
    }

    /// Starts `hair` as hair `id`: the guides' shape interpolated at its
    /// root, at the hairs' point count, no colours or opacities yet.
    fn interpolated(
        &self,
        context: &RootContext,
        id: u64,
        scratch: &mut HairScratch,
        shape: &mut Vec<Vec3>,
        hair: &mut Hair,
    ) {
        shape.resize(self.groom.guides.points_per_guide(), Vec3::ZERO);
        let hair_root = HairRoot {
            position: context.position,
            triangle: Some(context.point.tri),
        };
        self.interpolator
            .hair_at(hair_root, context.normal, scratch, shape);
        hair.id = id;
        hair.points.clear();
        self.resampled(shape, &mut hair.points);
        hair.colors.clear();
        hair.opacities.clear();
    }

    /// Appends the interpolated `shape` (guide resolution) at the hairs'
    /// point count.
    fn resampled(&self, shape: &[Vec3], out: &mut Vec<Vec3>) {
        self.resampling.apply(shape, out);
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
        let stream = mix64(self.seed ^ mix64(0x9A27 + p as u64));
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

    /// Part `p` grown from its `roots`.
    fn grow_part(&self, p: usize, roots: Vec<SurfacePoint>) -> Result<Curves, GroomError> {
        let part = &self.layout.parts()[p];
        if self.one_hair_per_root() {
            return self.part_in_place(roots, part.first_hair);
        }
        let chunks: Vec<PartChunk> = roots
            .par_chunks(CHUNK)
            .enumerate()
            .map_init(Workspace::default, |ws, (c, chunk)| {
                let first = part.first_hair + (c * CHUNK) as u64;
                self.grow_chunk(chunk, first, ws)
            })
            .collect();
        // The first root, in the part's order, that grew a value that is
        // not a finite number.
        let bad = chunks
            .iter()
            .enumerate()
            .find_map(|(c, chunk)| chunk.first_non_finite.map(|i| c * CHUNK + i));
        if let Some(i) = bad {
            return Err(self.non_finite_error(roots[i], part.first_hair + i as u64));
        }
        Ok(self.concat(chunks))
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

    fn spare_arrays(&self) -> CurveArrays {
        let mut spare = self.spare.lock().unwrap_or_else(|e| e.into_inner());
        spare.pop().unwrap_or_default()
    }

    /// Whether every root grows exactly one hair (no `strands`, no `cut`):
    /// then a part's arrays have a known size and workers fill them in
    /// place.
    fn one_hair_per_root(&self) -> bool {
        self.ops.iter().all(Operator::keeps_one_hair_a_root)
    }

    /// [`Self::part`] when each root grows one hair: the arrays are
    /// allocated once and each worker writes its chunk's slices; `roots`
    /// become the curves' roots.
    fn part_in_place(
        &self,
        roots: Vec<SurfacePoint>,
        first_hair: u64,
    ) -> Result<Curves, GroomError> {
        let n = self.points;
        let total = roots.len() * n;
        let sized = |on: bool| if on { total } else { 0 };
        // Every element is overwritten by the workers below, so a recycled
        // array keeps its old values and only grows where this part is
        // larger: parts are nearly equal in size, so most of the time
        // nothing is filled at all. The growth is filled on all threads:
        // zeroing a part's ~50 MB on this one was time every other core
        // waited for (Amdahl: at 16 threads it kept the groom at a third of
        // the cores' worth).
        fn sized_to<T: Copy + Send + Default>(mut v: Vec<T>, len: usize) -> Vec<T> {
            v.truncate(len);
            let more = len - v.len();
            v.par_extend(rayon::iter::repeat_n(T::default(), more));
            v
        }
        let spare = self.spare_arrays();
        let mut points = sized_to(spare.points, total);
        let mut widths = sized_to(spare.widths, total);
        let mut normals = sized_to(spare.normals, sized(self.normals));
        let mut colors = sized_to(spare.colors, sized(self.colors));
        let mut opacities = sized_to(spare.opacities, sized(self.opacities));
        let bad = {
            let mut jobs = Vec::with_capacity(roots.len().div_ceil(CHUNK));
            let (mut p, mut w, mut nr, mut c, mut o) = (
                &mut points[..],
                &mut widths[..],
                &mut normals[..],
                &mut colors[..],
                &mut opacities[..],
            );
            for (k, chunk) in roots.chunks(CHUNK).enumerate() {
                let len = chunk.len() * n;
                let take = |on: bool| if on { len } else { 0 };
                let (p0, p1) = std::mem::take(&mut p).split_at_mut(len);
                let (w0, w1) = std::mem::take(&mut w).split_at_mut(len);
                let (n0, n1) = std::mem::take(&mut nr).split_at_mut(take(self.normals));
                let (c0, c1) = std::mem::take(&mut c).split_at_mut(take(self.colors));
                let (o0, o1) = std::mem::take(&mut o).split_at_mut(take(self.opacities));
                (p, w, nr, c, o) = (p1, w1, n1, c1, o1);
                let first = first_hair + (k * CHUNK) as u64;
                jobs.push((k, chunk, first, p0, w0, n0, c0, o0));
            }
            // Each job answers with its first hair whose values are not all
            // finite, if any (checked as it is copied, while in cache).
            let bad: Vec<Option<usize>> = jobs
                .into_par_iter()
                .map_init(
                    Workspace::default,
                    |ws, (job, chunk, first, p, w, nr, c, o)| {
                        ws.skin_normals.clear();
                        let mut bad = None;
                        for (g, group) in chunk.chunks(GROUP).enumerate() {
                            let first_in_group = g * GROUP;
                            self.grow_group(group, first + first_in_group as u64, ws);
                            for (k, (hair, root)) in ws.group.iter().zip(&ws.contexts).enumerate() {
                                let i = first_in_group + k;
                                if bad.is_none() && hair.non_finite().is_some() {
                                    bad = Some(i);
                                }
                                ws.skin_normals.push(root.normal);
                                let range = i * n..(i + 1) * n;
                                p[range.clone()].copy_from_slice(&hair.points);
                                w[range.clone()].copy_from_slice(&hair.widths);
                                if self.colors {
                                    c[range.clone()].copy_from_slice(&hair.colors);
                                }
                                if self.opacities {
                                    o[range].copy_from_slice(&hair.opacities);
                                }
                            }
                        }
                        if self.normals {
                            hair_normals(p, n, &ws.skin_normals, nr, &mut ws.frames);
                            if !vectors_finite(nr) {
                                let normals_bad = nr.chunks(n).position(|h| !vectors_finite(h));
                                bad = bad.into_iter().chain(normals_bad).min();
                            }
                        }
                        bad.map(|i| job * CHUNK + i)
                    },
                )
                .collect();
            bad.into_iter().flatten().next()
        };
        if let Some(i) = bad {
            return Err(self.non_finite_error(roots[i], first_hair + i as u64));
        }
        let mut offsets = spare.offsets;
        offsets.clear();
        offsets.extend((0..=roots.len() as u32).map(|i| i * n as u32));
        let mut ids = spare.ids;
        ids.clear();
        ids.extend(first_hair..first_hair + roots.len() as u64);
        // Every hair was found finite above.
        let checked = Values::Checked;
        let mut curves =
            Curves::build(points, widths, offsets, checked).expect("consistent part arrays");
        if self.normals {
            curves = curves
                .with_normals_as(normals, checked)
                .expect("one normal a point");
        }
        if self.colors {
            curves = curves
                .with_colors_as(colors, checked)
                .expect("one colour a point");
        }
        if self.opacities {
            curves = curves
                .with_opacities_as(opacities, checked)
                .expect("one opacity a point");
        }
        Ok(self.with_root_uvs(
            curves
                .with_ids(ids)
                .and_then(|c| c.with_roots(roots))
                .expect("one id and root a curve"),
        ))
    }

    /// Hair `id`, grown from `root`, has a value that is not finite: grows
    /// it again one operator at a time to say which operator (its place in
    /// the groom file) took it there, and what went.
    fn non_finite_error(&self, root: SurfacePoint, id: u64) -> GroomError {
        let mut ws = Workspace::default();
        let context = self.root_context(root);
        let hair = ws.batch.reset();
        self.interpolated(&context, id, &mut ws.interpolation, &mut ws.shape, hair);
        // Where operator `k` of the chain (the finishing ones first) is
        // written in the groom file, and its key.
        let place = |k: usize| -> (Option<(usize, usize)>, String) {
            let source = &self.groom.source;
            let finish = &self.groom.file.finish;
            if let Some(op) = k.checked_sub(self.base.len()) {
                let key = format!("ops[{op}].{}", self.ops[op].name());
                return (source.line_of_op(op), key);
            }
            let (name, span) = match &self.base[k] {
                Operator::Width(_) => ("width", finish.width.root.span()),
                Operator::Opacity(_) => (
                    "opacity",
                    finish.opacity.as_ref().map_or(0..0, |o| o.root.span()),
                ),
                _ => (
                    "color",
                    finish.color.as_ref().map_or(0..0, |c| c.root[0].span()),
                ),
            };
            (source.line_of(span), format!("finish.{name}"))
        };
        let error = |line, key, what: String| {
            GroomError::new(
                self.groom.source.path.clone(),
                line,
                Some(key),
                GroomErrorKind::NotFinite(what),
            )
        };
        for (k, op) in self.base.iter().chain(&self.ops).enumerate() {
            op.apply(&mut ws.batch, &context, &mut ws.scratch);
            if let Some(what) = ws.batch.hairs().iter().find_map(Hair::non_finite) {
                let (line, key) = place(k);
                return error(
                    line,
                    key,
                    format!(
                        "hair {id}'s {what} are no longer finite numbers after this operator: \
                         its values take the hair past the range of 32-bit floats (about \
                         ±3.4e38); make them smaller"
                    ),
                );
            }
            if ws.batch.is_empty() {
                break;
            }
        }
        // The values are finite, the normals are not: differences of
        // points near the float range overflow.
        let farthest = ws
            .batch
            .hairs()
            .iter()
            .flat_map(|h| h.points.iter())
            .map(|p| p.abs().max_element())
            .fold(0.0f32, f32::max);
        error(
            None,
            "finish.normals".to_string(),
            format!(
                "hair {id}'s normals are not finite numbers: its points reach {farthest:e}, \
                 too far for their differences to fit in 32-bit floats; make the \
                 operators' values smaller (or set normals = false)"
            ),
        )
    }

    /// Adds each hair's root UV (USD's uniform `st`, which renderers use to
    /// read skin textures along the hair) when the mesh has UVs.
    fn with_root_uvs(&self, curves: Curves) -> Curves {
        let mesh = &self.groom.mesh;
        if !mesh.has_uvs() {
            return curves;
        }
        let uvs = curves
            .roots()
            .expect("grown curves carry their roots")
            .par_iter()
            .map(|r| r.uv(mesh).unwrap_or_default())
            .collect();
        curves.with_root_uvs(uvs).expect("one UV a curve")
    }

    fn grow_chunk(&self, roots: &[SurfacePoint], first_id: u64, ws: &mut Workspace) -> PartChunk {
        let n = self.points;
        let mut out = PartChunk::default();
        let mut tangents = vec![Vec3::ZERO; n];
        let mut frame = vec![Vec3::ZERO; n];
        for (i, root) in roots.iter().enumerate() {
            let normal = self.grow(*root, first_id + i as u64, &self.ops, ws);
            let finite = ws.batch.hairs().iter().all(|h| h.non_finite().is_none());
            if !finite && out.first_non_finite.is_none() {
                out.first_non_finite = Some(i);
            }
            for hair in ws.batch.hairs() {
                out.points.extend_from_slice(&hair.points);
                out.widths.extend_from_slice(&hair.widths);
                if self.colors {
                    out.colors.extend_from_slice(&hair.colors);
                }
                if self.opacities {
                    out.opacities.extend_from_slice(&hair.opacities);
                }
                if self.normals {
                    catmull_rom_tangents(&hair.points, &mut tangents);
                    rotation_minimizing_normals(&hair.points, &tangents, normal, &mut frame);
                    if !vectors_finite(&frame) && out.first_non_finite.is_none() {
                        out.first_non_finite = Some(i);
                    }
                    out.normals.extend_from_slice(&frame);
                }
                out.counts.push(hair.points.len() as u32);
                out.ids.push(hair.id);
                out.roots.push(*root);
            }
        }
        out
    }

    /// One part's curves from its workers' chunks, in order, with the
    /// attributes this groom has.
    fn concat(&self, chunks: Vec<PartChunk>) -> Curves {
        let mut all = PartChunk::default();
        let mut offsets = vec![0u32];
        for c in chunks {
            all.points.extend_from_slice(&c.points);
            all.widths.extend_from_slice(&c.widths);
            all.normals.extend_from_slice(&c.normals);
            all.colors.extend_from_slice(&c.colors);
            all.opacities.extend_from_slice(&c.opacities);
            for n in c.counts {
                offsets.push(offsets.last().expect("starts at 0") + n);
            }
            all.ids.extend_from_slice(&c.ids);
            all.roots.extend_from_slice(&c.roots);
        }
        // The generator builds consistent arrays (a failure here is a bug),
        // and every hair was found finite as it grew.
        let checked = Values::Checked;
        let mut curves = Curves::build(all.points, all.widths, offsets, checked)
            .expect("consistent part arrays");
        if self.normals {
            curves = curves
                .with_normals_as(all.normals, checked)
                .expect("one normal a point");
        }
        if self.colors {
            curves = curves
                .with_colors_as(all.colors, checked)
                .expect("one colour a point");
        }
        if self.opacities {
            curves = curves
                .with_opacities_as(all.opacities, checked)
                .expect("one opacity a point");
        }
        self.with_root_uvs(
            curves
                .with_ids(all.ids)
                .and_then(|c| c.with_roots(all.roots))
                .expect("one id and root a curve"),
        )
    }
}

/// Hairs grown by one worker, in order (per-point arrays stay empty for
/// attributes the groom does not have).
#[derive(Default)]
struct PartChunk {
    points: Vec<Vec3>,
    widths: Vec<f32>,
    normals: Vec<Vec3>,
    colors: Vec<Vec3>,
    opacities: Vec<f32>,
    counts: Vec<u32>,
    ids: Vec<u64>,
    roots: Vec<SurfacePoint>,
    /// The first of the chunk's roots that grew a value that is not
    /// finite.
    first_non_finite: Option<usize>,
}

fn root_to_tip(groom: &Groom, s: &RootToTipSpec) -> Result<RootToTip, GroomError> {
    Ok(RootToTip {
        root: groom.map(&s.root)?,
        tip: groom.map(&s.tip)?,
        ramp: s.ramp.clone(),
        jitter: groom.map(&s.jitter)?,
        seed: s.seed,
    })
}

fn color_spec(groom: &Groom, s: &ColorSpec) -> Result<Color, GroomError> {
    let three = |c: &[MapValue; 3]| -> Result<[Map; 3], GroomError> {
        Ok([groom.map(&c[0])?, groom.map(&c[1])?, groom.map(&c[2])?])
    };
    Ok(Color {
        root: three(&s.root)?,
        tip: three(&s.tip)?,
        ramp: s.ramp.clone(),
        jitter: groom.map(&s.jitter)?,
        seed: s.seed,
    })
}

/// `roots` ordered by (triangle, first barycentric, second barycentric),
/// the order [`Generator::part_roots`] grows hairs in: the same order as
/// a comparison sort by that key, found faster. A counting sort by
/// triangle moves each root once; each triangle's few roots (a dozen or
/// two) are then sorted among themselves. A comparison sort of the whole
/// part took a tenth of a groom's time on one core.
fn sorted_by_triangle(roots: Vec<SurfacePoint>) -> Vec<SurfacePoint> {
    let (Some(lo), Some(hi)) = (
        roots.iter().map(|r| r.tri).min(),
        roots.iter().map(|r| r.tri).max(),
    ) else {
        return roots;
    };
    // starts[t − lo] .. starts[t − lo + 1]: where triangle t's roots go.
    let mut starts = vec![0u32; (hi - lo) as usize + 2];
    for r in &roots {
        starts[(r.tri - lo) as usize + 1] += 1;
    }
    for t in 1..starts.len() {
        starts[t] += starts[t - 1];
    }
    let mut next = starts.clone();
    let mut sorted = vec![SurfacePoint::default(); roots.len()];
    for r in &roots {
        let slot = &mut next[(r.tri - lo) as usize];
        sorted[*slot as usize] = *r;
        *slot += 1;
    }
    for range in starts.windows(2) {
        let triangle = &mut sorted[range[0] as usize..range[1] as usize];
        if triangle.len() > 1 {
            triangle.sort_unstable_by_key(|r| (r.bary[0].to_bits(), r.bary[1].to_bits()));
        }
    }
    sorted
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_sorted_by_triangle_match_a_comparison_sort() {
        // Random roots over a few hundred triangles, with repeated
        // triangles and first barycentrics (ties broken by the second),
        // exact duplicates, and a negative zero.
        let mut roots: Vec<SurfacePoint> = (0..5000u64)
            .map(|i| {
                let h = mix64(i);
                let unit = |h: u64| (h >> 40) as f32 / (1u64 << 24) as f32;
                let b0 = if i % 7 == 0 { 0.25 } else { unit(h) };
                SurfacePoint::new((h % 300) as u32 * 77, [b0, unit(mix64(h))])
            })
            .collect();
        roots.extend_from_within(..50);
        roots.push(SurfacePoint::new(3, [-0.0, 0.5]));
        roots.push(SurfacePoint::new(3, [0.0, 0.5]));
        let mut expected = roots.clone();
        expected.sort_unstable_by_key(|r| (r.tri, r.bary[0].to_bits(), r.bary[1].to_bits()));
        let got = sorted_by_triangle(roots);
        let bits = |r: &SurfacePoint| (r.tri, r.bary.map(f32::to_bits));
        assert_eq!(
            got.iter().map(bits).collect::<Vec<_>>(),
            expected.iter().map(bits).collect::<Vec<_>>()
        );
        assert!(sorted_by_triangle(Vec::new()).is_empty());
    }
}
