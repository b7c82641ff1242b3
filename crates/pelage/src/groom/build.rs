//! Building a [`Generator`] from a [`GroomSpec`]: the root sampler and
//! part layout, the interpolator (the style mesh is built here), every map
//! bound to the mesh, and the operator chain prepared in order. Preparing
//! a clump grows its centre hairs through the operators before it, so this
//! stands above the growth of hairs (`grow.rs`); the operators see the
//! chain built so far only as [`ChainSoFar`], never the generator.

use super::error::{GroomError, GroomErrorKind};
use super::generator::{Generator, Reuse};
use super::grow::Workspace;
use super::ops::{
    CentreGuides, ChainSoFar, ClumpCentres, GroomOp, OpKey, Opacity, Operator, OperatorSettings,
    Preparation, Resampling, Width,
};
use super::outside_skin::OutsideSkin;
use super::parts::{PartLayout, part_count};
use super::regions::RegionLookup;
use super::spec::{GroomSpec, HairIds, RootDistribution};
use crate::guides::Guides;
use crate::interp::Interpolator;
use crate::limits;
use crate::map::Map;
use crate::mesh::{Mesh, SurfacePoint};
use crate::sample::{DensitySampler, RootCells};
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::AtomicUsize;
use std::sync::{Arc, Mutex, OnceLock};

impl GroomSpec {
    /// Prepares generation: the root sampler and part layout, the
    /// interpolator (the style mesh is built here), the operator chain and
    /// its clump centres.
    ///
    /// # Errors
    /// A count of zero, fewer than 2 points a hair, a map that needs UVs on
    /// a mesh without them, a density that is zero everywhere; the error
    /// names the setting (`ops[2].clump.count`), and its line when the
    /// groom came from a file.
    pub fn generator(self) -> Result<Generator, GroomError> {
        Generator::new(self)
    }
}

impl Generator {
    /// Prepares `spec` for growing; see [`GroomSpec::generator`].
    pub fn new(spec: GroomSpec) -> Result<Self, GroomError> {
        Self::build(spec, Reuse::default())
    }

    /// A generator for `spec`, which must be this generator's spec with
    /// other guide shapes (the same guides, roots and everything else):
    /// the root sampler, part layout and guide weights are shared, only
    /// the shapes and what the operators grew from them (clump centres)
    /// are new. Animated grooms regrow each frame this way.
    pub fn reshaped(&self, spec: GroomSpec) -> Result<Self, GroomError> {
        Self::build(
            spec,
            Reuse {
                from: Some(self),
                roots: true,
                regions: true,
                weights: true,
                moved_guides: None,
                centre_guides: self.records_centre_guides,
            },
        )
    }

    /// A generator for `spec` that takes from `reuse.from` what `reuse`
    /// says is unchanged (an editable groom's edits: a guide added keeps
    /// the roots, a painted length keeps roots and weights). The caller
    /// answers for it: what is reused is not checked against `spec`.
    pub(crate) fn rebuilt(spec: GroomSpec, reuse: Reuse<'_>) -> Result<Self, GroomError> {
        Self::build(spec, reuse)
    }

    fn build(mut spec: GroomSpec, reuse: Reuse<'_>) -> Result<Self, GroomError> {
        let from = reuse.from;
        let shared_regions = from.filter(|_| reuse.regions);
        let shared_roots = from.filter(|_| reuse.roots);
        let shared_weights = from.filter(|_| reuse.weights && reuse.regions);
        let moved: Option<Vec<bool>> = reuse.moved_guides.map(|list| {
            let mut moved = vec![false; spec.guides.len()];
            for &g in list {
                if let Some(m) = moved.get_mut(g as usize) {
                    *m = true;
                }
            }
            moved
        });
        check_numbers(&spec)?;
        let points = spec.finish.points;
        bind_maps(&mut spec)?;
        let regions = match (shared_regions, &spec.regions) {
            (Some(g), _) => g.regions.clone(),
            (None, Some(r)) => Some(Arc::new(
                r.lookup(&spec.mesh).map_err(|m| spec.error("regions", m))?,
            )),
            (None, None) => None,
        };
        let (sampler, cells, layout) = match shared_roots {
            Some(g) => (g.sampler.clone(), g.cells.clone(), g.layout.clone()),
            None => root_sampling(&spec)?,
        };
        let interpolator = interpolator_for(&spec, shared_weights, regions.as_deref())?;
        let hairs_per_root = spec.most_hairs_per_root();
        let GroomSpec {
            name,
            mesh,
            guides,
            roots,
            ops,
            finish,
            origin,
            look,
            ..
        } = spec;
        let (colors, opacities) = (finish.color.is_some(), finish.opacity.is_some());
        // The skin's grid depends on the mesh alone: an edit's generator
        // shares its parent's.
        let outside_skin = finish
            .outside_skin
            .map(|gap| outside_skin_for(from, &mesh, &guides, gap, points));
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
            cells,
            distribution: roots.distribution,
            layout,
            interpolator,
            regions,
            ops: Vec::with_capacity(ops.len()),
            base,
            points,
            colors,
            opacities,
            clumps: false,
            records_centre_guides: reuse.centre_guides,
            // By the share actually kept: a fraction of a hair still
            // grows one (1e-300 would make widths infinite).
            hairs_per_root,
            width_scale: match roots.grown_count() {
                grown if grown < roots.count => (roots.count as f64 / grown as f64).sqrt() as f32,
                _ => 1.0,
            },
            normals: finish.normals,
            outside_skin,
            look,
            // A frame's generator (`reshaped`) grows parts of the same
            // sizes: it reuses its parent's arrays.
            spare: shared_roots.map_or_else(Default::default, |g| g.spare.clone()),
            last_part: AtomicUsize::new(usize::MAX),
            prefetched: Mutex::new(None),
            blue_noise_roots: OnceLock::new(),
        };
        generator.prepare_chain(ops, shared_weights.map(|g| (g, moved.as_deref())))?;
        Ok(generator)
    }

    /// Prepares the operator chain in order: each operator sees the ones
    /// before it (a clump grows its centres through them) and, reshaping,
    /// the generator reshaped with the guides that moved.
    fn prepare_chain(
        &mut self,
        ops: Vec<GroomOp>,
        reshaping: Option<(&Generator, Option<&[bool]>)>,
    ) -> Result<(), GroomError> {
        for (index, op) in ops.into_iter().enumerate() {
            let key = OpKey {
                index,
                name: op.name(),
            };
            // Clump centres are grown through the operators before this
            // one, which are already in `self.ops`.
            let chain = ChainBuild {
                generator: self,
                reshaping,
            };
            let op = op.prepare(&Preparation { chain: &chain, key })?;
            self.colors |= op.adds_colors();
            self.opacities |= op.adds_opacities();
            self.clumps |= op.searches_neighbours();
            self.ops.push(op);
        }
        Ok(())
    }

    /// Grows the centre hairs of the clump operator at chain position `k`
    /// through the operators before it. Centre ids live apart from hair ids
    /// (top bits set), so their random numbers are their own. Reshaping a
    /// generator whose centres recorded their guides, only the centres of
    /// moved guides grow again; the others keep their shapes.
    fn clump_centres(
        &self,
        k: usize,
        roots: &[SurfacePoint],
        reshaping: Option<(&Generator, Option<&[bool]>)>,
    ) -> ClumpCentres {
        let grow_one = |i: usize, ws: &mut Workspace, out: &mut Vec<Vec3>| {
            self.grow(roots[i], centre_hair_id(k, i), &self.ops[..k], ws);
            match ws.batch.hairs().first() {
                Some(hair) => out.extend_from_slice(&hair.points),
                // Cut away entirely: the centre is its interpolated shape.
                None => self.resampled(&ws.shape, out),
            }
        };
        let mesh = &self.mesh;
        let positions: Vec<Vec3> = roots.iter().map(|r| r.position(mesh)).collect();
        // The same centres as the generator reshaped (a painted density
        // may have moved them).
        let previous = reshaping.and_then(|(g, moved)| {
            let centres = match g.ops.get(k)?.unmasked() {
                Operator::Clump(c) => c.centres(),
                _ => return None,
            };
            (centres.roots() == positions.as_slice()).then_some((centres, moved))
        });
        if let Some((old, Some(moved))) = previous
            && let Some(guides) = old.guides()
        {
            let changed: Vec<usize> = (0..roots.len())
                .filter(|&i| guides.of(i).iter().any(|&g| moved[g as usize]))
                .collect();
            let grown: Vec<(usize, Vec<Vec3>)> = changed
                .par_iter()
                .map_init(Workspace::default, |ws, &i| {
                    let mut out = Vec::with_capacity(self.points);
                    grow_one(i, ws, &mut out);
                    (i, out)
                })
                .collect();
            let mut shapes = old.shape_array().to_vec();
            for (i, shape) in grown {
                shapes[i * self.points..(i + 1) * self.points].copy_from_slice(&shape);
            }
            return old.with_shapes(shapes);
        }
        // Grown in the order of their triangles, as a part's hairs are, so
        // that each worker's guide and centre searches walk the skin
        // (centres sampled at random refilled their candidate lists at
        // almost every one); placed back in the centres' own order.
        let mut order: Vec<u32> = (0..roots.len() as u32).collect();
        order.sort_unstable_by_key(|&i| (roots[i as usize].tri, i));
        let grown: Vec<Vec<Vec3>> = order
            .par_chunks(256)
            .map_init(Workspace::default, |ws, chunk| {
                let mut out = Vec::with_capacity(chunk.len() * self.points);
                for &i in chunk {
                    grow_one(i as usize, ws, &mut out);
                }
                out
            })
            .collect();
        let mut shapes = vec![Vec3::ZERO; roots.len() * self.points];
        for (&i, shape) in order
            .iter()
            .zip(grown.iter().flat_map(|c| c.chunks(self.points)))
        {
            let i = i as usize;
            shapes[i * self.points..(i + 1) * self.points].copy_from_slice(shape);
        }
        let normals = roots.iter().map(|r| r.normal(mesh)).collect();
        let regions: Vec<u32> = roots.iter().map(|r| self.region_of(*r)).collect();
        let centres = ClumpCentres::on_surface(positions, normals, &regions, shapes, self.points);
        let centres = centres.with_surface_roots(roots.to_vec());
        // Reshaped, the centres depend on the guides they did before.
        match previous.and_then(|(old, _)| old.guides_shared()) {
            Some(guides) => centres.with_shared_guides(guides),
            None if self.records_centre_guides => centres.with_guides(self.centre_guides(k, roots)),
            None => centres,
        }
    }

    /// The guides each centre of the clump at chain position `k` depends
    /// on: its own weights' guides and, through the clump levels before
    /// it, those of the centres it follows.
    fn centre_guides(&self, k: usize, roots: &[SurfacePoint]) -> CentreGuides {
        let earlier: Vec<&ClumpCentres> = self.ops[..k]
            .iter()
            .filter_map(|op| match op.unmasked() {
                Operator::Clump(c) => Some(c.centres()),
                _ => None,
            })
            .collect();
        let per_centre: Vec<Vec<u32>> = roots
            .par_iter()
            .map_init(
                || (Vec::new(), crate::interp::NeighbourCache::default()),
                |(weights, near), root| {
                    let context = self.root_context(*root);
                    let hair_root = crate::interp::HairRoot {
                        position: context.position,
                        triangle: Some(root.tri),
                        region: context.region,
                    };
                    self.interpolator.weighting().weights(hair_root, weights);
                    let mut guides: Vec<u32> = weights.iter().map(|w| w.guide).collect();
                    for level in &earlier {
                        let followed = level.nearest_near(
                            context.position,
                            Some(context.normal),
                            context.region,
                            near,
                            context.skin_triangle,
                        );
                        if let (Some((c, _)), Some(g)) = (followed, level.guides()) {
                            guides.extend_from_slice(g.of(c));
                        }
                    }
                    guides.sort_unstable();
                    guides.dedup();
                    guides
                },
            )
            .collect();
        CentreGuides::new(per_centre)
    }
}

/// A spec's root sampler, root cells (stable ids) and part layout.
type RootSampling = (Arc<DensitySampler>, Option<Arc<RootCells>>, Arc<PartLayout>);

/// The spec's numbers that no file check has held when it was built in
/// code: a preview fraction, at least one hair of two points, and every
/// count within its ceiling (docs/limits.md).
fn check_numbers(spec: &GroomSpec) -> Result<(), GroomError> {
    let fraction = spec.roots.fraction;
    if !(fraction > 0.0 && fraction <= 1.0) {
        return Err(spec.error(
            "output.fraction",
            GroomErrorKind::OutOfRange(format!(
                "fraction = {fraction}: the share of the hairs grown is above 0 and at most 1"
            )),
        ));
    }
    if fraction < 1.0
        && (spec.roots.ids != HairIds::Stable
            || spec.roots.distribution != RootDistribution::Random)
    {
        // Blamed on the roots setting that rules a fraction out: the
        // fraction itself may come from a flag, not the file.
        let key = match spec.roots.ids {
            HairIds::Stable => "roots.distribution",
            HairIds::Sequential => "roots.ids",
        };
        return Err(spec.error(
            key,
            GroomErrorKind::Conflict(
                "a fraction grows the first arrivals of the root cells, so that it is a subset of the groom: it needs stable ids and random roots (remove `ids = \"sequential\"` or `distribution = \"blue-noise\"`)".into(),
            ),
        ));
    }
    let count = spec.roots.count;
    if count == 0 {
        return Err(spec.error(
            "roots.count",
            GroomErrorKind::OutOfRange("the hair count must be at least 1".into()),
        ));
    }
    let points = spec.finish.points;
    if points < 2 {
        return Err(spec.error(
            "finish.points",
            GroomErrorKind::OutOfRange("hairs need at least 2 points".into()),
        ));
    }
    // Groom files are checked as they are read; grooms built in code
    // (the Python package, tests) meet the same ceilings here.
    let ceiling = |key: &str, value: u64, max: u64, what: &str| {
        limits::check_count(value, max, false, what)
            .map_err(|e| spec.error(key, GroomErrorKind::Count(e)))
    };
    ceiling("roots.count", count, limits::MAX_HAIRS, "hairs")?;
    if spec.roots.distribution == RootDistribution::BlueNoise
        && count > limits::MAX_BLUE_NOISE_POINTS
    {
        return Err(spec.error(
            "roots.count",
            GroomErrorKind::OutOfRange(format!(
                "blue-noise roots are thinned all at once, at most {} hairs (about 200 bytes a hair while they are placed); grow more with `distribution = \"random\"`",
                limits::grouped(limits::MAX_BLUE_NOISE_POINTS as f64)
            )),
        ));
    }
    ceiling(
        "finish.points",
        points as u64,
        limits::MAX_CURVE_POINTS,
        "points",
    )?;
    for (index, op) in spec.ops.iter().enumerate() {
        let key = OpKey {
            index,
            name: op.name(),
        };
        // An operator's numbers are held to the ranges a groom file's are
        // first, so a spec built in a program is refused with the file's
        // message.
        if let Some((field, message)) = op.out_of_range() {
            return Err(spec.error(&key.field(field), GroomErrorKind::OutOfRange(message)));
        }
        for (field, value, most, what) in op.counts() {
            ceiling(&key.field(field), value, most, what)?;
        }
    }
    Ok(())
}

/// The root sampler, the root cells (stable ids) and the part layout of
/// `spec`.
fn root_sampling(spec: &GroomSpec) -> Result<RootSampling, GroomError> {
    let mesh = &spec.mesh;
    let sampler = DensitySampler::new(mesh, &spec.roots.sampled_density(), Default::default())
        .map_err(|e| {
            // A scaled density that fails where the density alone does
            // not: the scale is what to fix (only on this error path is
            // the density sampled alone).
            let scaled = !matches!(spec.roots.density_scale, Map::Constant(c) if c == 1.0);
            let key = if scaled
                && DensitySampler::new(mesh, &spec.roots.density, Default::default()).is_ok()
            {
                "roots.density_scale"
            } else {
                "roots.density"
            };
            spec.error(key, GroomErrorKind::Sample(e))
        })?;
    // A fraction grows the first arrivals: a subset of the groom.
    let grown = spec.roots.grown_count();
    let parts = part_count(mesh, grown, spec.roots.parts, spec.roots.ids);
    let (cells, layout) = match spec.roots.ids {
        HairIds::Stable => {
            let cells = RootCells::new(mesh, &sampler);
            let counts = cells.counts(spec.roots.seed, grown);
            let layout = PartLayout::from_cells(&cells, &counts, parts);
            (Some(Arc::new(cells)), layout)
        }
        HairIds::Sequential => {
            let layout = PartLayout::new(
                mesh,
                |t| sampler.triangle_probability(t),
                spec.roots.count,
                parts,
            );
            (None, layout)
        }
    };
    Ok((Arc::new(sampler), cells, Arc::new(layout)))
}

/// The interpolator of `spec`: the one of `shared` reshaped to the new
/// guide shapes, or built (per region when the skin is split).
fn interpolator_for(
    spec: &GroomSpec,
    shared: Option<&Generator>,
    regions: Option<&RegionLookup>,
) -> Result<Interpolator, GroomError> {
    Ok(match shared {
        Some(g) => {
            if g.guides.len() != spec.guides.len() {
                return Err(spec.error(
                    "guides",
                    GroomErrorKind::Mismatch(format!(
                        "{} guides where the groom has {}",
                        spec.guides.len(),
                        g.guides.len()
                    )),
                ));
            }
            g.interpolator.reshaped(&spec.mesh, spec.guides.clone())
        }
        None => {
            let mesh = &spec.mesh;
            match regions {
                Some(lookup) => {
                    let guide_regions: Vec<u32> = spec
                        .guides
                        .roots()
                        .iter()
                        .map(|r| lookup.of(mesh, *r))
                        .collect();
                    Interpolator::with_regions(
                        mesh,
                        spec.guides.clone(),
                        &spec.interpolation,
                        &guide_regions,
                    )
                }
                None => Interpolator::new(mesh, spec.guides.clone(), &spec.interpolation),
            }
        }
    })
}

/// The skin hairs are kept out of: `from`'s when it has the same mesh and
/// gap (the grid depends on the mesh alone), else built with a hair's
/// segment (the longest guide over the hair's segments) as its step.
fn outside_skin_for(
    from: Option<&Generator>,
    mesh: &Arc<Mesh>,
    guides: &Guides,
    gap: f32,
    points: usize,
) -> Arc<OutsideSkin> {
    from.filter(|g| Arc::ptr_eq(&g.mesh, mesh))
        .and_then(|g| g.outside_skin.clone())
        .filter(|o| o.gap() == gap)
        .unwrap_or_else(|| {
            Arc::new(OutsideSkin::new(
                mesh,
                gap,
                OutsideSkin::segment(guides, points),
            ))
        })
}

/// The chain built so far, as preparing its next operator sees it: the
/// generator being built and, when reshaping, the generator it reshapes
/// with the guides that moved (`None`: any).
struct ChainBuild<'a> {
    generator: &'a Generator,
    reshaping: Option<(&'a Generator, Option<&'a [bool]>)>,
}

impl ChainSoFar for ChainBuild<'_> {
    fn seed(&self) -> u64 {
        self.generator.seed()
    }

    fn error(&self, key: &str, kind: GroomErrorKind) -> GroomError {
        self.generator.error(key, kind)
    }

    fn mesh(&self) -> &Mesh {
        self.generator.mesh()
    }

    fn unchanged_centre_roots(&self, k: usize) -> Option<Vec<SurfacePoint>> {
        let (previous, Some(_)) = self.reshaping? else {
            return None;
        };
        match previous.operators().get(k)?.unmasked() {
            Operator::Clump(c) if !c.centres().surface_roots().is_empty() => {
                Some(c.centres().surface_roots().to_vec())
            }
            _ => None,
        }
    }

    fn clump_centres(&self, k: usize, roots: &[SurfacePoint]) -> ClumpCentres {
        self.generator.clump_centres(k, roots, self.reshaping)
    }
}

/// The id of centre `i` of the clump at chain position `k`: apart from
/// every render hair's (the top bit), so no centre shares a hair's random
/// numbers.
pub(crate) fn centre_hair_id(k: usize, i: usize) -> u64 {
    (1u64 << 63) | ((k as u64) << 40) | i as u64
}

/// Binds every map of the groom to its mesh (per-vertex maps take their
/// values), or fails naming the setting whose map the mesh cannot serve
/// (image maps need UVs, per-vertex maps their attribute).
fn bind_maps(spec: &mut GroomSpec) -> Result<(), GroomError> {
    let mesh = spec.mesh.clone();
    let mut failed = None;
    {
        let mut bind = |key: String, map: &mut Map| {
            if failed.is_none()
                && let Err(e) = map.bind(&mesh)
            {
                failed = Some((key, e));
            }
        };
        bind("roots.density".into(), &mut spec.roots.density);
        bind("roots.density_scale".into(), &mut spec.roots.density_scale);
        let finish = &mut spec.finish;
        for (key, map) in finish.width.maps_mut() {
            bind(format!("finish.width.{key}"), map);
        }
        if let Some(color) = &mut finish.color {
            for (key, map) in color.maps_mut() {
                bind(format!("finish.color.{key}"), map);
            }
        }
        if let Some(opacity) = &mut finish.opacity {
            for (key, map) in opacity.maps_mut() {
                bind(format!("finish.opacity.{key}"), map);
            }
        }
        for (index, op) in spec.ops.iter_mut().enumerate() {
            let key = OpKey {
                index,
                name: op.name(),
            };
            for (field, map) in op.maps_mut() {
                bind(key.field(field), map);
            }
        }
        if let Some(regions) = &mut spec.regions {
            for map in regions.maps_mut() {
                bind("regions.map".into(), map);
            }
        }
        if let Some(look) = &mut spec.look {
            for (key, map) in look.maps_mut() {
                bind(format!("look.{key}"), map);
            }
        }
    }
    match failed {
        Some((key, e)) => Err(spec.error(&key, GroomErrorKind::Map(e))),
        None => Ok(()),
    }
}
