//! Growing a part's hairs: each root's shape interpolated from the guides,
//! resampled, passed through the finish and the operators, with per-point
//! normals from rotation-minimizing frames (Sik §4.2.2; Wang et al. 2008).
//! Grooms whose roots each grow one hair are grown eight hairs at a time
//! into arrays sized in advance; `strands` and `cut` take the general path,
//! chunk by chunk. Both end in one assembly of the part's [`Curves`].

use super::blue_noise;
use super::error::{GroomError, GroomErrorKind};
use super::generator::{Generator, PartRoots};
use super::hair_look::HairLook;
use super::ops::{Hair, HairBatch, Operator, RootContext, Scratch};
use super::spec::RootDistribution;
use crate::curves::frames::{
    FrameScratch, catmull_rom_tangents, hair_normals, rotation_minimizing_normals,
};
use crate::curves::{CurveArrays, Curves, vectors_finite};
use crate::interp::{HairRoot, HairScratch, QueryRegion};
use crate::map::MapSite;
use crate::mesh::SurfacePoint;
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::Ordering;

/// Hairs a worker grows between hand-overs (fixed, so results never depend
/// on the number of threads).
const CHUNK: usize = 512;

/// Per-thread buffers.
#[derive(Default)]
pub(super) struct Workspace {
    pub(super) interpolation: HairScratch,
    pub(super) shape: Vec<Vec3>,
    pub(super) batch: HairBatch,
    pub(super) scratch: Scratch,
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

impl Generator {
    /// Roots of part `p`, in an order that walks the skin (so neighbouring
    /// hairs are grown together), and their hairs' ids. With stable ids
    /// each of the part's root cells samples its own hairs from its own
    /// stream, and the part walks its cells along their Morton curve, each
    /// cell's roots by triangle;
    /// otherwise the part samples its hairs in its triangles with its own
    /// stream, numbered from the part's first hair id. Blue-noise roots
    /// are then thinned, all parts together, from four times as many
    /// (`blue_noise.rs`).
    pub fn part_roots(&self, p: usize) -> (Vec<SurfacePoint>, Vec<u64>) {
        if self.distribution == RootDistribution::BlueNoise {
            return self
                .blue_noise_roots
                .get_or_init(|| blue_noise::all_part_roots(self))[p]
                .clone();
        }
        self.regular_part_roots(p)
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
        let (roots, ids) = self
            .take_prefetched(p)
            .unwrap_or_else(|| self.part_roots(p));
        // Parts asked for in order (a whole groom, a farm task's range):
        // the next part's roots are sampled and sorted beside this part's
        // growth, on threads that would otherwise wait for its last chunks.
        let previous = self.last_part.swap(p, Ordering::Relaxed);
        let prefetch = p + 1 < self.layout.len() && (p == 0 || previous == p - 1);
        let (curves, next) = rayon::join(
            || self.grow_part(roots, ids),
            || prefetch.then(|| self.part_roots(p + 1)),
        );
        if let Some(next) = next {
            *self.prefetched.lock().unwrap_or_else(|e| e.into_inner()) = Some((p + 1, next));
        }
        curves
    }

    /// The roots of part `p` if they were sampled ahead.
    fn take_prefetched(&self, p: usize) -> Option<PartRoots> {
        let mut prefetched = self.prefetched.lock().unwrap_or_else(|e| e.into_inner());
        match prefetched.take() {
            Some((q, roots)) if q == p => Some(roots),
            _ => None,
        }
    }

    /// Hair `id` grown from `root` through `ops` into `ws.batch`; returns
    /// the skin normal at the root.
    pub(super) fn grow(
        &self,
        root: SurfacePoint,
        id: u64,
        ops: &[Operator],
        ws: &mut Workspace,
    ) -> Vec3 {
        let context = self.root_context(root);
        let hair = ws.batch.reset();
        self.interpolated(&context, id, &mut ws.interpolation, &mut ws.shape, hair);
        for op in self.base.iter().chain(ops) {
            op.apply(&mut ws.batch, &context, &mut ws.scratch);
            if ws.batch.is_empty() {
                break;
            }
        }
        if let Some(skin) = &self.outside_skin {
            for hair in ws.batch.hairs_mut() {
                skin.apply(&mut hair.points, context.normal);
            }
        }
        context.normal
    }

    /// Hairs `first_id…` grown from `roots` (at most [`GROUP`]) through
    /// every operator side by side, into `ws.group` with their roots in
    /// `ws.contexts`: hair for hair what [`Self::grow`] makes, for grooms
    /// whose operators keep one hair a root.
    fn grow_group(&self, roots: &[SurfacePoint], ids: &[u64], ws: &mut Workspace) {
        if ws.group.len() < roots.len() {
            ws.group.resize_with(roots.len(), Hair::default);
        }
        ws.contexts.clear();
        for (i, root) in roots.iter().enumerate() {
            let context = self.root_context(*root);
            let hair = &mut ws.group[i];
            self.interpolated(&context, ids[i], &mut ws.interpolation, &mut ws.shape, hair);
            ws.contexts.push(context);
        }
        let hairs = &mut ws.group[..roots.len()];
        for op in self.base.iter().chain(&self.ops) {
            op.apply_each(hairs, &ws.contexts, &mut ws.scratch);
        }
        if let Some(skin) = &self.outside_skin {
            for (hair, context) in hairs.iter_mut().zip(&ws.contexts) {
                skin.apply(&mut hair.points, context.normal);
            }
        }
    }

    /// Where a hair grows: its root's position, skin normal and UV.
    pub(crate) fn root_context(&self, root: SurfacePoint) -> RootContext {
        let mesh = &self.mesh;
        let position = root.position(mesh);
        let site = MapSite::with_position(mesh, root, position);
        RootContext {
            point: root,
            position,
            normal: root.normal(mesh),
            region: self.regions.as_ref().map_or(0, |r| r.at(root, &site)),
            site,
            skin_triangle: self
                .clumps
                .then(|| QueryRegion::around_triangle(mesh.triangle_positions(root.tri as usize))),
        }
    }

    /// Starts `hair` as hair `id`: the guides' shape interpolated at its
    /// root, at the hairs' point count, no colours or opacities yet.
    pub(super) fn interpolated(
        &self,
        context: &RootContext,
        id: u64,
        scratch: &mut HairScratch,
        shape: &mut Vec<Vec3>,
        hair: &mut Hair,
    ) {
        shape.resize(self.guides.points_per_guide(), Vec3::ZERO);
        let hair_root = HairRoot {
            position: context.position,
            triangle: Some(context.point.tri),
            region: context.region,
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
    pub(super) fn resampled(&self, shape: &[Vec3], out: &mut Vec<Vec3>) {
        self.resampling.apply(shape, out);
    }

    /// A part grown from its `roots`, root `i` growing hair `ids[i]`.
    pub(super) fn grow_part(
        &self,
        roots: Vec<SurfacePoint>,
        ids: Vec<u64>,
    ) -> Result<Curves, GroomError> {
        self.grow_roots(roots, ids).map(|(curves, _)| curves)
    }

    /// [`Self::grow_part`] that also says how many hairs each root grew
    /// (`None`: one each), in the roots' order: an editable groom keeps
    /// each root's hairs apart to replace them alone.
    pub(crate) fn grow_roots(
        &self,
        roots: Vec<SurfacePoint>,
        ids: Vec<u64>,
    ) -> Result<(Curves, Option<Vec<u32>>), GroomError> {
        if self.one_hair_per_root() {
            return self.part_in_place(roots, ids).map(|c| (c, None));
        }
        let chunks: Vec<PartChunk> = roots
            .par_chunks(CHUNK)
            .zip(ids.par_chunks(CHUNK))
            .map_init(Workspace::default, |ws, (chunk, ids)| {
                self.grow_chunk(chunk, ids, ws)
            })
            .collect();
        // The first root, in the part's order, that grew a value that is
        // not a finite number.
        let bad = chunks
            .iter()
            .enumerate()
            .find_map(|(c, chunk)| chunk.first_non_finite.map(|i| c * CHUNK + i));
        if let Some(i) = bad {
            return Err(self.non_finite_error(roots[i], ids[i]));
        }
        let per_root = chunks
            .iter()
            .flat_map(|c| c.per_root.iter().copied())
            .collect();
        Ok((self.assemble(concat(chunks)), Some(per_root)))
    }

    /// Whether every root grows exactly one hair (no `strands`, no `cut`):
    /// then a part's arrays have a known size and workers fill them in
    /// place.
    pub(crate) fn one_hair_per_root(&self) -> bool {
        self.ops.iter().all(Operator::keeps_one_hair_a_root)
    }

    /// [`Self::part`] when each root grows one hair: the arrays are
    /// allocated once and each worker writes its chunk's slices; `roots`
    /// become the curves' roots.
    fn part_in_place(
        &self,
        roots: Vec<SurfacePoint>,
        hair_ids: Vec<u64>,
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
                let chunk_ids = &hair_ids[k * CHUNK..k * CHUNK + chunk.len()];
                jobs.push((k, chunk, chunk_ids, p0, w0, n0, c0, o0));
            }
            // Each job answers with its first hair whose values are not all
            // finite, if any (checked as it is copied, while in cache).
            let bad: Vec<Option<usize>> = jobs
                .into_par_iter()
                .map_init(
                    Workspace::default,
                    |ws, (job, chunk, chunk_ids, p, w, nr, c, o)| {
                        ws.skin_normals.clear();
                        let mut bad = None;
                        for (g, group) in chunk.chunks(GROUP).enumerate() {
                            let first_in_group = g * GROUP;
                            let group_ids =
                                &chunk_ids[first_in_group..first_in_group + group.len()];
                            self.grow_group(group, group_ids, ws);
                            for (k, (hair, root)) in ws.group.iter().zip(&ws.contexts).enumerate() {
                                let i = first_in_group + k;
                                if bad.is_none() && hair.non_finite().is_some() {
                                    bad = Some(i);
                                }
                                ws.skin_normals.push(root.normal);
                                let range = i * n..(i + 1) * n;
                                p[range.clone()].copy_from_slice(&hair.points);
                                w[range.clone()].copy_from_slice(&hair.widths);
                                if self.width_scale != 1.0 {
                                    w[range.clone()]
                                        .iter_mut()
                                        .for_each(|x| *x *= self.width_scale);
                                }
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
            return Err(self.non_finite_error(roots[i], hair_ids[i]));
        }
        let mut offsets = spare.offsets;
        offsets.clear();
        offsets.extend((0..=roots.len() as u32).map(|i| i * n as u32));
        let mut ids = spare.ids;
        ids.clear();
        ids.extend_from_slice(&hair_ids);
        Ok(self.assemble(CurveArrays {
            points,
            widths,
            normals,
            colors,
            opacities,
            offsets,
            ids,
            roots,
            root_uvs: Vec::new(),
        }))
    }

    /// A part assembled from hairs another evaluator grew (the GPU's,
    /// from a [`super::GroomRecipe`] of this groom): hair `i` rooted at
    /// `roots[i]` with id `ids[i]`, its points and widths the `n` values
    /// from `i · n`, colours and opacities as the groom has them. Normals,
    /// root UVs, the look's values and regions are added as
    /// [`Self::part`] adds them, so both write the same files.
    ///
    /// # Errors
    /// When a point, width or normal is not a finite number (named as
    /// [`Self::part`] names it); when the arrays do not hold one hair a
    /// root of the groom's point count.
    pub fn part_from_grown(
        &self,
        roots: Vec<SurfacePoint>,
        ids: Vec<u64>,
        points: Vec<Vec3>,
        widths: Vec<f32>,
        colors: Option<Vec<Vec3>>,
        opacities: Option<Vec<f32>>,
    ) -> Result<Curves, GroomError> {
        let n = self.points;
        let total = roots.len() * n;
        let colors = colors.filter(|_| self.colors).unwrap_or_default();
        let opacities = opacities.filter(|_| self.opacities).unwrap_or_default();
        let sized = |len: usize, on: bool| len == if on { total } else { 0 };
        if ids.len() != roots.len()
            || points.len() != total
            || widths.len() != total
            || !sized(colors.len(), self.colors)
            || !sized(opacities.len(), self.opacities)
        {
            return Err(self.error(
                "finish.points",
                GroomErrorKind::Mismatch(format!(
                    "{} grown points for {} roots of {n} points each",
                    points.len(),
                    roots.len()
                )),
            ));
        }
        let mut normals = vec![Vec3::ZERO; if self.normals { total } else { 0 }];
        if self.normals && n > 0 {
            let mesh = &self.mesh;
            normals
                .par_chunks_mut(CHUNK * n)
                .zip(points.par_chunks(CHUNK * n))
                .zip(roots.par_chunks(CHUNK))
                .for_each_init(FrameScratch::default, |frames, ((out, p), r)| {
                    let first: Vec<Vec3> = r.iter().map(|r| r.normal(mesh)).collect();
                    hair_normals(p, n, &first, out, frames);
                });
        }
        let bad = (0..roots.len()).find(|&i| {
            let range = i * n..(i + 1) * n;
            !vectors_finite(&points[range.clone()])
                || !widths[range.clone()].iter().all(|w| w.is_finite())
                || (self.normals && !vectors_finite(&normals[range]))
        });
        if let Some(i) = bad {
            return Err(self.non_finite_error(roots[i], ids[i]));
        }
        let offsets = (0..=roots.len() as u32).map(|i| i * n as u32).collect();
        Ok(self.assemble(CurveArrays {
            points,
            widths,
            normals,
            colors,
            opacities,
            offsets,
            ids,
            roots,
            root_uvs: Vec::new(),
        }))
    }

    /// Adds each hair's root UV (USD's uniform `st`, which renderers use to
    /// read skin textures along the hair) when the mesh has UVs.
    fn with_root_uvs(&self, curves: Curves) -> Curves {
        let mesh = &self.mesh;
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

    fn grow_chunk(&self, roots: &[SurfacePoint], ids: &[u64], ws: &mut Workspace) -> PartChunk {
        let n = self.points;
        let mut out = PartChunk::default();
        let mut tangents = vec![Vec3::ZERO; n];
        let mut frame = vec![Vec3::ZERO; n];
        for (i, root) in roots.iter().enumerate() {
            let normal = self.grow(*root, ids[i], &self.ops, ws);
            out.per_root.push(ws.batch.hairs().len() as u32);
            let finite = ws.batch.hairs().iter().all(|h| h.non_finite().is_none());
            if !finite && out.first_non_finite.is_none() {
                out.first_non_finite = Some(i);
            }
            for hair in ws.batch.hairs() {
                let a = &mut out.arrays;
                a.points.extend_from_slice(&hair.points);
                a.widths
                    .extend(hair.widths.iter().map(|x| x * self.width_scale));
                if self.colors {
                    a.colors.extend_from_slice(&hair.colors);
                }
                if self.opacities {
                    a.opacities.extend_from_slice(&hair.opacities);
                }
                if self.normals {
                    catmull_rom_tangents(&hair.points, &mut tangents);
                    rotation_minimizing_normals(&hair.points, &tangents, normal, &mut frame);
                    if !vectors_finite(&frame) && out.first_non_finite.is_none() {
                        out.first_non_finite = Some(i);
                    }
                    a.normals.extend_from_slice(&frame);
                }
                out.counts.push(hair.points.len() as u32);
                a.ids.push(hair.id);
                a.roots.push(*root);
            }
        }
        out
    }

    /// A part's curves from its arrays, with the attributes this groom
    /// has and each hair's root UV. Every hair was found finite as it grew,
    /// so `Curves` does not scan the values again.
    fn assemble(&self, a: CurveArrays) -> Curves {
        self.with_root_values(self.with_root_uvs(Curves::assembled(
            a,
            self.normals,
            self.colors,
            self.opacities,
        )))
    }

    /// Adds what each hair's root and id alone decide: its values for a
    /// hair shader (the groom's `[look]`, or without one, melanin fitted
    /// to each root's colour when the hairs have colours), its region
    /// when it has `[regions]`.
    pub(crate) fn with_root_values(&self, mut curves: Curves) -> Curves {
        let roots = curves.roots().expect("grown curves carry their roots");
        let regions = self.regions_at(roots);
        let ids = curves.ids().expect("grown curves carry their ids");
        let shading = match (&self.look, curves.colors()) {
            (Some(look), _) => Some(look.shade(&self.mesh, roots, ids)),
            (None, Some(colors)) => {
                let at_roots: Vec<Vec3> = curves.offsets()[..curves.curve_count()]
                    .iter()
                    .map(|&o| colors[o as usize])
                    .collect();
                Some(HairLook::fitted_to_colors(&at_roots, ids))
            }
            (None, None) => None,
        };
        if let Some(shading) = shading {
            curves = curves
                .with_shading(shading)
                .expect("one value a hair, each within 0 to 1 or a finite tint");
        }
        if let Some(regions) = regions {
            curves = curves.with_regions(regions).expect("one region a hair");
        }
        curves
    }
}

/// Hairs grown by one worker, in order: their arrays with a count of
/// points a hair (offsets come when the chunks are joined).
#[derive(Default)]
struct PartChunk {
    arrays: CurveArrays,
    counts: Vec<u32>,
    /// Hairs each root grew.
    per_root: Vec<u32>,
    /// The first of the chunk's roots that grew a value that is not
    /// finite.
    first_non_finite: Option<usize>,
}

/// The chunks of a part, in order, as one part's arrays.
fn concat(chunks: Vec<PartChunk>) -> CurveArrays {
    let mut all = CurveArrays {
        offsets: vec![0u32],
        ..Default::default()
    };
    for c in chunks {
        let a = c.arrays;
        all.points.extend_from_slice(&a.points);
        all.widths.extend_from_slice(&a.widths);
        all.normals.extend_from_slice(&a.normals);
        all.colors.extend_from_slice(&a.colors);
        all.opacities.extend_from_slice(&a.opacities);
        for n in c.counts {
            all.offsets
                .push(all.offsets.last().expect("starts at 0") + n);
        }
        all.ids.extend_from_slice(&a.ids);
        all.roots.extend_from_slice(&a.roots);
    }
    all
}

impl Generator {
    /// Hair `id`, grown from `root`, has a value that is not finite: grows
    /// it again one operator at a time to say which operator (its place in
    /// the groom file) took it there, and what went.
    pub(super) fn non_finite_error(&self, root: SurfacePoint, id: u64) -> GroomError {
        let mut ws = Workspace::default();
        let context = self.root_context(root);
        let hair = ws.batch.reset();
        self.interpolated(&context, id, &mut ws.interpolation, &mut ws.shape, hair);
        // The setting of operator `k` of the chain (the finishing ones
        // first): its line comes from the groom's origin, if it has one.
        let place = |k: usize| -> String {
            match k.checked_sub(self.base.len()) {
                Some(op) => format!("ops[{op}].{}", self.ops[op].name()),
                None => format!("finish.{}", self.base[k].name()),
            }
        };
        let error = |key: String, what: String| self.error(&key, GroomErrorKind::NotFinite(what));
        for (k, op) in self.base.iter().chain(&self.ops).enumerate() {
            op.apply(&mut ws.batch, &context, &mut ws.scratch);
            if let Some(what) = ws.batch.hairs().iter().find_map(Hair::non_finite) {
                return error(
                    place(k),
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
            "finish.normals".to_string(),
            format!(
                "hair {id}'s normals are not finite numbers: its points reach {farthest:e}, \
                 too far for their differences to fit in 32-bit floats; make the \
                 operators' values smaller (or set normals = false)"
            ),
        )
    }
}
