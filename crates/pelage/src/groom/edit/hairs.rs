//! The grown hairs of an editable groom, kept root cell by root cell, with
//! what each hair was grown from, so that an edit regrows only the hairs
//! it can change.
//!
//! Every hair of a groom with stable ids is hair `k` of a root cell `c`
//! ([`crate::sample::RootCells`]), and its growth reads only: its root,
//! its region, its guide weights (which guides, how much) and those
//! guides' shapes, the clump centre it follows at each clump level and
//! that centre's shape, and the maps at its root's triangle. Each cell
//! keeps, per root, the root, region, weights and centres (its
//! *recipe*), and the hairs grown from it. An edit builds the new
//! generator, finds the roots whose recipe or inputs changed, grows them
//! in one batch (sorted by triangle, as a part is) and splices them into
//! their cells. Since a hair's growth depends on nothing else, the result
//! is the full regrow's, bit for bit.
//!
//! Two indices make a guide edit cheap: guide → the hairs weighted by it,
//! and per clump level, centre → the hairs following it. A guide edit
//! that keeps the roots and weights regrows exactly the hairs in those
//! lists for the moved guides and the centres whose shape changed.

use crate::curves::Curves;
use crate::groom::error::GroomError;
use crate::groom::generator::Generator;
use crate::groom::ops::{ClumpCentres, Operator};
use crate::groom::parts::sorted_by_triangle_with_ids;
use crate::interp::{GuideWeight, HairRoot, HairScratch, NeighbourCache};
use crate::mesh::SurfacePoint;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// No centre at this clump level (a region without centres).
const NO_CENTRE: u32 = u32::MAX;

/// What changed between the hairs' generator and the next one.
#[derive(Debug, Default, Clone)]
pub(crate) struct Change {
    /// Regrow every hair (a parameter or the operator chain changed).
    pub everything: bool,
    /// The roots may have moved, appeared or gone (density, count,
    /// fraction): sample every cell again and compare.
    pub roots: bool,
    /// Regions, weights or clump centres' roots may differ: find every
    /// root's recipe again and compare.
    pub recipes: bool,
    /// Guides whose shape changed, by index (weights unchanged).
    pub moved_guides: Vec<u32>,
    /// Triangles whose maps changed (a painted layer an operator reads).
    pub touched_triangles: Vec<u32>,
}

/// One root cell's roots, their recipes and their hairs.
#[derive(Debug, Default, Clone)]
struct CellHairs {
    /// Root `k` of the cell (hair id `k · cells + c`).
    roots: Vec<SurfacePoint>,
    regions: Vec<u32>,
    /// Root `k`'s weights: `weights[weight_starts[k]..weight_starts[k + 1]]`.
    weight_starts: Vec<u32>,
    weights: Vec<GuideWeight>,
    /// Root `k`'s centre at clump level `j`: `centres[k · levels + j]`.
    centres: Vec<u32>,
    /// Root `k`'s hairs: curves `curve_starts[k]..curve_starts[k + 1]`.
    curve_starts: Vec<u32>,
    /// Curve `i`'s points: `point_starts[i]..point_starts[i + 1]`.
    point_starts: Vec<u32>,
    points: Vec<Vec3>,
    widths: Vec<f32>,
    normals: Vec<Vec3>,
    colors: Vec<Vec3>,
    opacities: Vec<f32>,
    /// Per curve.
    ids: Vec<u64>,
    curve_roots: Vec<SurfacePoint>,
    root_uvs: Vec<Vec2>,
}

/// A root's recipe: region, weights and centre at each clump level.
#[derive(Debug, Default, Clone, PartialEq)]
struct Recipe {
    region: u32,
    weights: Vec<GuideWeight>,
    centres: Vec<u32>,
}

impl CellHairs {
    fn recipe(&self, k: usize, levels: usize) -> Recipe {
        Recipe {
            region: self.regions[k],
            weights: self.weights
                [self.weight_starts[k] as usize..self.weight_starts[k + 1] as usize]
                .to_vec(),
            centres: self.centres[k * levels..(k + 1) * levels].to_vec(),
        }
    }

    fn weights_of(&self, k: usize) -> &[GuideWeight] {
        &self.weights[self.weight_starts[k] as usize..self.weight_starts[k + 1] as usize]
    }

    fn hair_count(&self) -> usize {
        self.ids.len()
    }
}

/// The per-thread buffers of finding recipes.
#[derive(Default)]
struct RecipeScratch {
    interpolation: HairScratch,
    near: NeighbourCache,
}

/// Finds the recipe of `root` under `generator`: exactly what growing it
/// reads (the same region, weight and centre lookups).
fn recipe_of(
    generator: &Generator,
    levels: &[&ClumpCentres],
    root: SurfacePoint,
    scratch: &mut RecipeScratch,
) -> Recipe {
    let context = generator.root_context(root);
    let hair_root = HairRoot {
        position: context.position,
        triangle: Some(root.tri),
        region: context.region,
    };
    generator.interpolator.weighting().weights_near(
        hair_root,
        &mut scratch.interpolation.near,
        &mut scratch.interpolation.weights,
    );
    let centres = levels
        .iter()
        .map(|c| {
            c.nearest_near(
                context.position,
                Some(context.normal),
                context.region,
                &mut scratch.near,
                context.skin_triangle,
            )
            .map_or(NO_CENTRE, |(i, _)| i as u32)
        })
        .collect();
    Recipe {
        region: context.region,
        weights: scratch.interpolation.weights.clone(),
        centres,
    }
}

/// The clump centres of each clump level of `generator`'s chain, in order.
pub(crate) fn clump_levels(generator: &Generator) -> Vec<&ClumpCentres> {
    generator
        .operators()
        .iter()
        .filter_map(|op| match op.unmasked() {
            Operator::Clump(c) => Some(c.centres()),
            _ => None,
        })
        .collect()
}

/// A list of hairs (packed `cell << 32 | k`) per key (a guide, a centre),
/// in compressed rows.
#[derive(Debug, Default, Clone)]
struct HairIndex {
    starts: Vec<u32>,
    hairs: Vec<u64>,
}

impl HairIndex {
    fn build(keys: usize, entries: impl Iterator<Item = (u32, u64)> + Clone) -> Self {
        let mut starts = vec![0u32; keys + 1];
        for (key, _) in entries.clone() {
            starts[key as usize + 1] += 1;
        }
        for i in 1..starts.len() {
            starts[i] += starts[i - 1];
        }
        let mut next = starts.clone();
        let mut hairs = vec![0u64; starts[keys] as usize];
        for (key, hair) in entries {
            let slot = &mut next[key as usize];
            hairs[*slot as usize] = hair;
            *slot += 1;
        }
        Self { starts, hairs }
    }

    fn of(&self, key: u32) -> &[u64] {
        match self.starts.get(key as usize..key as usize + 2) {
            Some(r) => &self.hairs[r[0] as usize..r[1] as usize],
            None => &[],
        }
    }
}

fn pack(cell: usize, k: usize) -> u64 {
    ((cell as u64) << 32) | k as u64
}

fn unpack(hair: u64) -> (usize, usize) {
    ((hair >> 32) as usize, (hair & 0xffff_ffff) as usize)
}

/// The hairs of an editable groom, cell by cell; see the module docs.
#[derive(Debug, Default, Clone)]
pub(crate) struct GrownHairs {
    cells: Vec<CellHairs>,
    /// Clump levels of the chain the hairs were grown with.
    levels: usize,
    by_guide: HairIndex,
    /// Per clump level.
    by_centre: Vec<HairIndex>,
    normals: bool,
    colors: bool,
    opacities: bool,
    root_uvs: bool,
}

/// What one regrowth did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Regrowth {
    /// Hairs grown again (roots whose hairs were replaced).
    pub regrown_roots: usize,
    /// Hairs in the groom after it.
    pub hairs: usize,
}

impl GrownHairs {
    /// Brings the hairs from their generator `old` to `new` for `change`,
    /// growing only what the change can reach. `counts` are each cell's
    /// roots under `new` (the preview's count).
    pub(crate) fn update(
        &mut self,
        old: Option<&Generator>,
        new: &Generator,
        counts: &[u64],
        change: &Change,
    ) -> Result<Regrowth, GroomError> {
        let cells = new
            .root_cells()
            .expect("editable grooms have stable ids (checked when opened)");
        let new_levels = clump_levels(new);
        let everything = change.everything || old.is_none() || self.cells.len() != counts.len();
        // Centres whose shape changed, per level (all when the centres'
        // roots changed: then every recipe is found again).
        let old_levels = old.map(clump_levels).unwrap_or_default();
        let centres_moved = old_levels.len() != new_levels.len()
            || old_levels
                .iter()
                .zip(&new_levels)
                .any(|(a, b)| a.roots() != b.roots());
        let changed_centres: Vec<Vec<bool>> = if everything || centres_moved {
            Vec::new()
        } else {
            old_levels
                .iter()
                .zip(&new_levels)
                .map(|(a, b)| {
                    (0..b.len())
                        .into_par_iter()
                        .map(|i| a.shape(i) != b.shape(i))
                        .collect()
                })
                .collect()
        };
        let recipes = everything || change.recipes || change.roots || centres_moved;
        let affected: Vec<u64> = if !recipes && change.touched_triangles.is_empty() {
            // Guides moved, nothing else: the indices answer. A hair
            // weighted by several moved guides is listed once for each;
            // `regrow` drops the repeats after its sort by triangle, which
            // puts them side by side (a sort of the packed list first cost
            // a twentieth of a comb dab).
            let mut hairs: Vec<u64> = Vec::new();
            for &g in &change.moved_guides {
                hairs.extend_from_slice(self.by_guide.of(g));
            }
            for (level, changed) in changed_centres.iter().enumerate() {
                for (centre, _) in changed.iter().enumerate().filter(|(_, c)| **c) {
                    hairs.extend_from_slice(self.by_centre[level].of(centre as u32));
                }
            }
            hairs
        } else {
            self.compare_all(
                new,
                &new_levels,
                counts,
                change,
                everything,
                recipes,
                &changed_centres,
            )
        };
        self.levels = new_levels.len();
        let regrown = self.regrow(new, cells.len(), &affected)?;
        if recipes {
            self.rebuild_indices(new.guides().len(), &new_levels);
        }
        Ok(Regrowth {
            regrown_roots: regrown,
            hairs: self.cells.iter().map(CellHairs::hair_count).sum(),
        })
    }

    /// Samples every cell's roots again where they may have changed, finds
    /// recipes again where they may have changed, and lists the roots to
    /// regrow; the cells keep their new roots and recipes (hairs are
    /// replaced next).
    #[allow(clippy::too_many_arguments)]
    fn compare_all(
        &mut self,
        new: &Generator,
        levels: &[&ClumpCentres],
        counts: &[u64],
        change: &Change,
        everything: bool,
        recipes: bool,
        changed_centres: &[Vec<bool>],
    ) -> Vec<u64> {
        let cells = new.root_cells().expect("stable ids");
        let mut moved = vec![false; new.guides().len()];
        for &g in &change.moved_guides {
            if let Some(m) = moved.get_mut(g as usize) {
                *m = true;
            }
        }
        let mut touched = vec![false; new.mesh().triangle_count()];
        for &t in &change.touched_triangles {
            touched[t as usize] = true;
        }
        if self.cells.len() != counts.len() {
            self.cells = vec![CellHairs::default(); counts.len()];
        }
        let old_levels = self.levels;
        let n_levels = levels.len();
        let per_cell: Vec<Vec<u64>> = self
            .cells
            .par_iter_mut()
            .enumerate()
            .map_init(RecipeScratch::default, |scratch, (c, cell)| {
                let count = counts[c] as usize;
                let roots = if change.roots || everything {
                    cells.roots(new.sampler(), new.seed(), c, count as u64)
                } else {
                    cell.roots.clone()
                };
                let mut affected = Vec::new();
                let mut regions = Vec::with_capacity(count);
                let mut weight_starts = Vec::with_capacity(count + 1);
                let mut weights = Vec::with_capacity(cell.weights.len());
                let mut centres = Vec::with_capacity(count * n_levels);
                weight_starts.push(0u32);
                let bits = |r: &SurfacePoint| (r.tri, r.bary.map(f32::to_bits));
                for (k, root) in roots.iter().enumerate() {
                    let known = k < cell.roots.len() && bits(&cell.roots[k]) == bits(root);
                    let recipe = if recipes || !known {
                        recipe_of(new, levels, *root, scratch)
                    } else {
                        cell.recipe(k, old_levels)
                    };
                    let mut regrow = everything || !known;
                    if !regrow && recipes {
                        regrow = recipe != cell.recipe(k, old_levels);
                    }
                    if !regrow {
                        regrow = touched[root.tri as usize]
                            || recipe.weights.iter().any(|w| moved[w.guide as usize])
                            || recipe.centres.iter().enumerate().any(|(j, &i)| {
                                changed_centres
                                    .get(j)
                                    .and_then(|level| level.get(i as usize))
                                    .copied()
                                    .unwrap_or(false)
                            });
                    }
                    if regrow {
                        affected.push(pack(c, k));
                    }
                    regions.push(recipe.region);
                    weights.extend_from_slice(&recipe.weights);
                    weight_starts.push(weights.len() as u32);
                    centres.extend_from_slice(&recipe.centres);
                }
                // Hairs of roots that are gone: drop them now (the cell's
                // hairs are rebuilt from its roots when it is spliced).
                let dropped = cell.roots.len() > roots.len();
                if dropped {
                    let keep_curves = cell.curve_starts[roots.len()] as usize;
                    truncate_hairs(cell, roots.len(), keep_curves);
                }
                cell.roots = roots;
                cell.regions = regions;
                cell.weight_starts = weight_starts;
                cell.weights = weights;
                cell.centres = centres;
                affected
            })
            .collect();
        per_cell.concat()
    }

    /// Grows the roots `affected` (packed cell and root, repeats allowed)
    /// with `generator` and splices their hairs into their cells; returns
    /// how many roots it grew.
    fn regrow(
        &mut self,
        generator: &Generator,
        cell_count: usize,
        affected: &[u64],
    ) -> Result<usize, GroomError> {
        self.normals = generator.normals;
        self.colors = generator.colors;
        self.opacities = generator.opacities;
        self.root_uvs = generator.mesh().has_uvs();
        let cells = generator.root_cells().expect("stable ids");
        let roots: Vec<SurfacePoint> = affected
            .iter()
            .map(|&h| {
                let (c, k) = unpack(h);
                self.cells[c].roots[k]
            })
            .collect();
        let ids = affected
            .iter()
            .map(|&h| {
                let (c, k) = unpack(h);
                cells.id(c, k as u64)
            })
            .collect();
        // Grown by triangle, which keeps the guide searches' candidate
        // lists warm.
        let (roots, ids) = sorted_by_triangle_with_ids(roots, ids);
        // A root listed twice is now next to itself (same root, same id;
        // ids are unique to a root).
        let (roots, ids): (Vec<SurfacePoint>, Vec<u64>) = {
            let mut pairs: Vec<_> = roots.into_iter().zip(ids).collect();
            pairs.dedup_by_key(|(_, id)| *id);
            pairs.into_iter().unzip()
        };
        let regrown = roots.len();
        let (grown, per_root) = if roots.is_empty() {
            (None, None)
        } else {
            let (curves, per_root) = generator.grow_roots(roots, ids.clone())?;
            (Some(curves), per_root)
        };
        // Each grown root's curves in `grown`, by cell.
        let mut by_cell: Vec<Vec<(usize, std::ops::Range<usize>)>> = vec![Vec::new(); cell_count];
        let mut first = 0usize;
        for (i, id) in ids.iter().enumerate() {
            let n = per_root.as_ref().map_or(1, |p| p[i] as usize);
            let (c, k) = (
                (*id % cell_count as u64) as usize,
                (*id / cell_count as u64) as usize,
            );
            by_cell[c].push((k, first..first + n));
            first += n;
        }
        let flags = (self.normals, self.colors, self.opacities, self.root_uvs);
        let grown_ref = grown.as_ref();
        self.cells
            .par_iter_mut()
            .zip(by_cell)
            .for_each(|(cell, mut replaced)| {
                let complete = cell.curve_starts.len() == cell.roots.len() + 1;
                if replaced.is_empty() && complete {
                    return;
                }
                replaced.sort_unstable_by_key(|(k, _)| *k);
                if !(complete && replace_in_place(cell, &replaced, grown_ref, flags)) {
                    splice(cell, &replaced, grown_ref, flags);
                }
            });
        // The next edit's generator shares this one's spare arrays (a
        // guide edit keeps the roots): it grows into them instead of into
        // fresh pages the kernel must zero.
        if let Some(grown) = grown {
            generator.recycle(grown);
        }
        Ok(regrown)
    }

    fn rebuild_indices(&mut self, guides: usize, levels: &[&ClumpCentres]) {
        let entries = self.cells.iter().enumerate().flat_map(|(c, cell)| {
            (0..cell.roots.len()).flat_map(move |k| {
                cell.weights_of(k)
                    .iter()
                    .map(move |w| (w.guide, pack(c, k)))
            })
        });
        self.by_guide = HairIndex::build(guides, entries);
        let n_levels = levels.len();
        self.by_centre = levels
            .iter()
            .enumerate()
            .map(|(j, centres)| {
                let entries = self.cells.iter().enumerate().flat_map(move |(c, cell)| {
                    (0..cell.roots.len()).filter_map(move |k| {
                        let i = cell.centres[k * n_levels + j];
                        (i != NO_CENTRE).then_some((i, pack(c, k)))
                    })
                });
                HairIndex::build(centres.len(), entries)
            })
            .collect();
    }

    /// Every hair, cell after cell (each cell's roots in order).
    /// Every hair's points, in the order of [`Self::curves`], alone.
    pub(crate) fn points(&self) -> Vec<Vec3> {
        let count = self.cells.iter().map(|c| c.points.len()).sum();
        let mut points = Vec::with_capacity(count);
        for cell in &self.cells {
            points.extend_from_slice(&cell.points);
        }
        points
    }

    pub(crate) fn curves(&self) -> Curves {
        let hairs: usize = self.cells.iter().map(CellHairs::hair_count).sum();
        let points: usize = self.cells.iter().map(|c| c.points.len()).sum();
        let mut a = crate::curves::CurveArrays {
            points: Vec::with_capacity(points),
            widths: Vec::with_capacity(points),
            offsets: Vec::with_capacity(hairs + 1),
            ids: Vec::with_capacity(hairs),
            roots: Vec::with_capacity(hairs),
            ..Default::default()
        };
        a.offsets.push(0);
        for cell in &self.cells {
            let base = a.points.len() as u32;
            a.points.extend_from_slice(&cell.points);
            a.widths.extend_from_slice(&cell.widths);
            a.normals.extend_from_slice(&cell.normals);
            a.colors.extend_from_slice(&cell.colors);
            a.opacities.extend_from_slice(&cell.opacities);
            a.offsets
                .extend(cell.point_starts.iter().skip(1).map(|s| base + s));
            a.ids.extend_from_slice(&cell.ids);
            a.roots.extend_from_slice(&cell.curve_roots);
            a.root_uvs.extend_from_slice(&cell.root_uvs);
        }
        Curves::assembled(a, self.normals, self.colors, self.opacities)
    }

    /// Hairs in the groom.
    pub(crate) fn hair_count(&self) -> usize {
        self.cells.iter().map(CellHairs::hair_count).sum()
    }

    /// Roots in the groom.
    pub(crate) fn root_count(&self) -> usize {
        self.cells.iter().map(|c| c.roots.len()).sum()
    }

    /// The guides and weights of every root, with its region, for checks
    /// and reports: `(root, region, weights)`.
    pub(crate) fn recipes(&self) -> impl Iterator<Item = (SurfacePoint, u32, &[GuideWeight])> {
        self.cells.iter().flat_map(|cell| {
            (0..cell.roots.len()).map(move |k| (cell.roots[k], cell.regions[k], cell.weights_of(k)))
        })
    }
}

/// Keeps the hairs of a cell's first `roots` roots (`curves` curves).
fn truncate_hairs(cell: &mut CellHairs, roots: usize, curves: usize) {
    let points = cell.point_starts[curves] as usize;
    cell.curve_starts.truncate(roots + 1);
    cell.point_starts.truncate(curves + 1);
    cell.points.truncate(points);
    cell.widths.truncate(points);
    let keep = |on: bool| if on { points } else { 0 };
    cell.normals.truncate(keep(!cell.normals.is_empty()));
    cell.colors.truncate(keep(!cell.colors.is_empty()));
    cell.opacities.truncate(keep(!cell.opacities.is_empty()));
    cell.ids.truncate(curves);
    cell.curve_roots.truncate(curves);
    cell.root_uvs
        .truncate(if cell.root_uvs.is_empty() { 0 } else { curves });
}

/// Overwrites the hairs of the roots `replaced` lists in place when each
/// grew as many curves of as many points as before (the common case: no
/// `cut` or `strands` changed a count); `false`, with nothing changed,
/// otherwise.
fn replace_in_place(
    cell: &mut CellHairs,
    replaced: &[(usize, std::ops::Range<usize>)],
    grown: Option<&Curves>,
    (normals, colors, opacities, root_uvs): (bool, bool, bool, bool),
) -> bool {
    let Some(g) = grown else {
        return replaced.is_empty();
    };
    let same_layout = cell.normals.is_empty() != normals
        && cell.colors.is_empty() != colors
        && cell.opacities.is_empty() != opacities
        && cell.root_uvs.is_empty() != root_uvs;
    let fits = |(k, range): &(usize, std::ops::Range<usize>)| {
        let old = cell.curve_starts[*k] as usize..cell.curve_starts[*k + 1] as usize;
        old.len() == range.len()
            && old.zip(range.clone()).all(|(o, i)| {
                (cell.point_starts[o + 1] - cell.point_starts[o]) as usize == g.range(i).len()
            })
    };
    // An empty cell (new roots) is rebuilt by `splice`.
    if cell.points.is_empty() || !same_layout || !replaced.iter().all(fits) {
        return false;
    }
    for (k, range) in replaced {
        let first = cell.curve_starts[*k] as usize;
        for (o, i) in (first..).zip(range.clone()) {
            let to = cell.point_starts[o] as usize..cell.point_starts[o + 1] as usize;
            let from = g.range(i);
            cell.points[to.clone()].copy_from_slice(&g.points()[from.clone()]);
            cell.widths[to.clone()].copy_from_slice(&g.widths()[from.clone()]);
            if normals {
                cell.normals[to.clone()]
                    .copy_from_slice(&g.normals().expect("normals")[from.clone()]);
            }
            if colors {
                cell.colors[to.clone()]
                    .copy_from_slice(&g.colors().expect("colours")[from.clone()]);
            }
            if opacities {
                cell.opacities[to].copy_from_slice(&g.opacities().expect("opacities")[from]);
            }
            cell.ids[o] = g.ids().expect("ids")[i];
            cell.curve_roots[o] = g.roots().expect("roots")[i];
            if root_uvs {
                cell.root_uvs[o] = g.root_uvs().expect("root UVs")[i];
            }
        }
    }
    true
}

/// Rebuilds a cell's hairs: root `k`'s from `grown` where `replaced` (by
/// ascending `k`) lists it, otherwise the cell's own.
fn splice(
    cell: &mut CellHairs,
    replaced: &[(usize, std::ops::Range<usize>)],
    grown: Option<&Curves>,
    (normals, colors, opacities, root_uvs): (bool, bool, bool, bool),
) {
    let old = std::mem::take(cell);
    let mut out = CellHairs {
        roots: old.roots,
        regions: old.regions,
        weight_starts: old.weight_starts,
        weights: old.weights,
        centres: old.centres,
        ..Default::default()
    };
    out.curve_starts.push(0);
    out.point_starts.push(0);
    let mut next = replaced.iter().peekable();
    for k in 0..out.roots.len() {
        match next.peek() {
            Some((rk, range)) if *rk == k => {
                let g = grown.expect("replaced hairs were grown");
                for i in range.clone() {
                    let r = g.range(i);
                    out.points.extend_from_slice(&g.points()[r.clone()]);
                    out.widths.extend_from_slice(&g.widths()[r.clone()]);
                    if normals {
                        out.normals
                            .extend_from_slice(&g.normals().expect("normals")[r.clone()]);
                    }
                    if colors {
                        out.colors
                            .extend_from_slice(&g.colors().expect("colours")[r.clone()]);
                    }
                    if opacities {
                        out.opacities
                            .extend_from_slice(&g.opacities().expect("opacities")[r]);
                    }
                    out.ids.push(g.ids().expect("ids")[i]);
                    out.curve_roots.push(g.roots().expect("roots")[i]);
                    if root_uvs {
                        out.root_uvs.push(g.root_uvs().expect("root UVs")[i]);
                    }
                    out.point_starts.push(out.points.len() as u32);
                }
                next.next();
            }
            _ => {
                // A root kept: its hairs as they were (a root without
                // hairs yet cannot be kept: it is in `replaced`).
                let curves = old.curve_starts[k] as usize..old.curve_starts[k + 1] as usize;
                let points =
                    old.point_starts[curves.start] as usize..old.point_starts[curves.end] as usize;
                out.points.extend_from_slice(&old.points[points.clone()]);
                out.widths.extend_from_slice(&old.widths[points.clone()]);
                if normals {
                    out.normals.extend_from_slice(&old.normals[points.clone()]);
                }
                if colors {
                    out.colors.extend_from_slice(&old.colors[points.clone()]);
                }
                if opacities {
                    out.opacities
                        .extend_from_slice(&old.opacities[points.clone()]);
                }
                let base = out.points.len() as u32 - points.len() as u32;
                for i in curves.clone() {
                    out.point_starts
                        .push(base + old.point_starts[i + 1] - points.start as u32);
                }
                out.ids.extend_from_slice(&old.ids[curves.clone()]);
                out.curve_roots
                    .extend_from_slice(&old.curve_roots[curves.clone()]);
                if root_uvs {
                    out.root_uvs.extend_from_slice(&old.root_uvs[curves]);
                }
            }
        }
        out.curve_starts.push(out.ids.len() as u32);
    }
    *cell = out;
}
