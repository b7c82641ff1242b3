//! A groom flattened for an evaluator that grows every hair again each
//! frame: `pelage-gpu`'s `GpuGroom`, whose compute shader runs the steps
//! below, the same math as the CPU operators.
//!
//! What a hair's growth reads splits in two. Its root, its guide weights,
//! its clump centre and every number an operator draws from the hair's id
//! or reads from a map at its root do not change from frame to frame: they
//! are worked out here once, by the operators' own functions, so the two
//! evaluators cannot draw them differently. What does change is the
//! guides' shapes and the skin's pose: an evaluator reads those each frame
//! and runs, per hair, the interpolation and each operator's per-point math
//! (curl's helix, the noise field at the hair's points, the pull toward
//! the clump centre, …).
//!
//! Widths, colours and opacities never read a hair's points, so they are
//! made once here by the CPU operators themselves and the evaluator only
//! copies them. `[finish] outside_skin` comes as the skin at rest it keeps
//! hairs out of ([`GroomRecipe::outside_skin`]). A `cut` is a step (its
//! parameter per hair); the hairs it takes away whole are not in the
//! recipe, as the CPU drops them. `strands` is a step too: the recipe
//! holds each strand hair, whose steps before the split read its base
//! hair's numbers. Strands of strands split again: a hair's steps read
//! the numbers of the hair it was at that point of the chain (its base's
//! base, its base, itself).
//!
//! Every operator has a step or is made once here; the match in
//! `add_steps` names each, so an operator added to the CPU does not
//! build until an evaluator grows it too.
//!
//! Clump centres are hairs of the recipe too: each clump level's centres
//! are grown in a pass of their own through the steps before the clump,
//! and later passes read their points (multi-level clumping, as the CPU
//! grows its centres).

use super::build::centre_hair_id;
use super::error::{GroomError, GroomErrorKind};
use super::generator::Generator;
use super::ops::{HairBatch, Operator, RootContext, Scratch, Strands, param};
use super::outside_skin::OutsideSkin;
use crate::interp::{GuideWeight, HairRoot, HairScratch, NeighbourCache};
use crate::mesh::SurfacePoint;
use glam::Vec3;
use rayon::prelude::*;
use std::ops::Range;

/// Guides a hair takes its shape from, at most (Shepard's `k`, the style
/// mesh's three corners).
pub const MAX_RECIPE_WEIGHTS: usize = 8;

/// What one step of a hair's growth does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum StepKind {
    /// `length`: values `[factor]`.
    Length = 0,
    /// `curl`: values `[radius, turns, phase]`.
    Curl = 1,
    /// `twist`: values `[angle]` (radians at the tip).
    Twist = 2,
    /// `noise`: values `[amplitude, frequency]`.
    Noise = 3,
    /// `frizz`: values `[amplitude, frequency, phase.x, phase.y, phase.z]`
    /// (amplitude 0: not frizzed).
    Frizz = 4,
    /// `flyaways`: values `[stray, length, spread, frequency, phase.xyz,
    /// across.xyz]` (stray 0: stays in the coat).
    Flyaways = 5,
    /// `clump`: values `[centre (u32 bits), weight]`.
    Clump = 6,
    /// `cut`: values `[at]`, a mask folded in (`1 − m (1 − at)`, as a
    /// masked cut fades its parameter); at 1 or more, no cut. A hair cut
    /// at 0 or less is not in the recipe (a clump centre grows bare).
    Cut = 7,
    /// `strands`: values `[root spread, tip spread, twist, ρ, turn]`: the
    /// hair is one of its base hair's strand, offset around it. The
    /// recipe holds every strand hair; the steps before this one read the
    /// base hair's numbers, the ones after the strand hair's.
    Strands = 8,
}

impl StepKind {
    /// Values a hair holds for a step of this kind (without its mask).
    pub fn values(self) -> u32 {
        match self {
            Self::Length | Self::Twist | Self::Cut => 1,
            Self::Noise | Self::Clump => 2,
            Self::Curl => 3,
            Self::Frizz | Self::Strands => 5,
            Self::Flyaways => 10,
        }
    }
}

/// One operator of the chain as an evaluator runs it.
#[derive(Debug, Clone, PartialEq)]
pub struct RecipeStep {
    /// What it does.
    pub kind: StepKind,
    /// Its place in the groom's `[[ops]]`.
    pub chain_index: usize,
    /// Where its values start in a hair's block of [`GroomRecipe::values`]
    /// (the mask's weight first when it is masked).
    pub values: u32,
    /// Whether a mask fades it: the hair becomes `before + m (after −
    /// before)` with `m` its first value.
    pub masked: bool,
    /// Where its profile root to tip starts in [`GroomRecipe::tables`]
    /// (one value a point). A noise step's resamplings follow: to its
    /// vectors, `(segment, fraction)` a vector, and back, one a point.
    pub table: u32,
    /// A noise field's 512-entry permutation table in
    /// [`GroomRecipe::permutations`] (noise, frizz, flyaways).
    pub permutation: u32,
    /// Noise vectors along a hair (`noise`; the point count: one a point).
    pub vectors: u32,
    /// The clump's first centre hair (`clump`).
    pub centres: u32,
}

/// Hairs grown together: a clump level's centres, or the render hairs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecipePass {
    /// The hairs.
    pub hairs: Range<u32>,
    /// How many of [`GroomRecipe::steps`] they go through.
    pub steps: u32,
}

/// A groom flattened for an evaluator that runs every frame (module docs).
/// Hairs are numbered centres first, pass after pass; the render hairs
/// are the last pass.
#[derive(Debug, Clone)]
pub struct GroomRecipe {
    /// Points a hair.
    pub points: u32,
    /// Points a guide.
    pub guide_points: u32,
    /// Guides.
    pub guides: u32,
    /// Each hair's id.
    pub ids: Vec<u64>,
    /// Whether a hair grows bare: a clump centre cut away entirely is its
    /// interpolated shape, no step applied.
    pub bare: Vec<bool>,
    /// Each hair's root on the skin.
    pub roots: Vec<SurfacePoint>,
    /// Each root's position at rest.
    pub root_positions: Vec<Vec3>,
    /// Each root's skin normal at rest.
    pub root_normals: Vec<Vec3>,
    /// Each hair's guides, [`MAX_RECIPE_WEIGHTS`] a hair (unused ones
    /// weigh 0).
    pub weights: Vec<GuideWeight>,
    /// Each guide's skin normal at its root.
    pub guide_normals: Vec<Vec3>,
    /// Each guide's root on the skin (where an evaluator turns posed
    /// guides back to rest space).
    pub guide_roots: Vec<SurfacePoint>,
    /// From a guide's points to a hair's: `(segment, fraction)` a hair
    /// point; empty when both have as many points.
    pub resampling: Vec<(u32, f32)>,
    /// The steps, in chain order.
    pub steps: Vec<RecipeStep>,
    /// The passes, in order.
    pub passes: Vec<RecipePass>,
    /// Each hair's values, [`Self::values_per_hair`] a hair.
    pub values: Vec<f32>,
    /// Values a hair.
    pub values_per_hair: u32,
    /// Profiles and resamplings the steps read (see [`RecipeStep::table`]).
    pub tables: Vec<f32>,
    /// Noise permutation tables, 512 entries each.
    pub permutations: Vec<u32>,
    /// Each render hair's widths, a value a point.
    pub widths: Vec<f32>,
    /// Each render hair's colours, when the groom has them.
    pub colors: Option<Vec<Vec3>>,
    /// Each render hair's opacities, when the groom has them.
    pub opacities: Option<Vec<f32>>,
    /// `[finish] outside_skin`: the skin at rest the hairs are kept out
    /// of after the operators (centres too), and the hairs' segment
    /// length, with which an evaluator keeps carried hairs out of a posed
    /// skin (`OutsideSkin::posed`), as an animated groom does.
    pub outside_skin: Option<(OutsideSkin, f32)>,
    /// The chain positions of the `strands` operators, where the recipe
    /// splits hairs.
    strands: Vec<usize>,
}

/// Every root of `generator`'s groom with its hair's id, ordered so that
/// the first `k` are the hairs a preview fraction of `k` hairs grows:
/// with stable ids, by the time each arrives in its root cell (a groom of
/// `N` hairs is the `N` earliest; `--fraction`); otherwise by a hash of
/// the id (an even share, stable by id). A level of detail draws a prefix.
pub fn roots_by_arrival(generator: &Generator) -> (Vec<SurfacePoint>, Vec<u64>) {
    let (mut roots, mut ids) = (Vec::new(), Vec::new());
    for p in 0..generator.parts().len() {
        let (r, i) = generator.part_roots(p);
        roots.extend(r);
        ids.extend(i);
    }
    let keys: Vec<f64> = match generator.root_cells() {
        Some(cells) => {
            let mut most = vec![0u64; cells.len()];
            for &id in &ids {
                let (c, k) = cells.cell_of(id);
                most[c] = most[c].max(k + 1);
            }
            let seed = generator.seed();
            let times: Vec<Vec<f64>> = (0..cells.len())
                .into_par_iter()
                .map(|c| cells.arrivals(seed, c, most[c]))
                .collect();
            ids.iter()
                .map(|&id| {
                    let (c, k) = cells.cell_of(id);
                    times[c].get(k as usize).copied().unwrap_or(f64::INFINITY)
                })
                .collect()
        }
        None => ids
            .iter()
            .map(|&id| crate::sample::mix64(id) as f64)
            .collect(),
    };
    let mut order: Vec<usize> = (0..ids.len()).collect();
    order.sort_by(|&a, &b| keys[a].total_cmp(&keys[b]).then(ids[a].cmp(&ids[b])));
    (
        order.iter().map(|&i| roots[i]).collect(),
        order.iter().map(|&i| ids[i]).collect(),
    )
}

impl GroomRecipe {
    /// The recipe of the hairs `ids` rooted at `roots` (from
    /// [`Generator::part_roots`]) of `generator`'s groom.
    ///
    /// # Errors
    /// When a hair takes its shape from more than [`MAX_RECIPE_WEIGHTS`]
    /// guides.
    pub fn new(
        generator: &Generator,
        roots: &[SurfacePoint],
        ids: &[u64],
    ) -> Result<Self, GroomError> {
        assert_eq!(roots.len(), ids.len(), "a hair id a root");
        let n = generator.points;
        let mut recipe = Self {
            points: n as u32,
            guide_points: generator.guides.points_per_guide() as u32,
            guides: generator.guides.len() as u32,
            ids: Vec::new(),
            bare: Vec::new(),
            roots: Vec::new(),
            root_positions: Vec::new(),
            root_normals: Vec::new(),
            weights: Vec::new(),
            guide_normals: generator.interpolator.guide_normals().collect(),
            guide_roots: generator.guides.roots().to_vec(),
            resampling: generator.resampling.between().to_vec(),
            steps: Vec::new(),
            passes: Vec::new(),
            values: Vec::new(),
            values_per_hair: 0,
            tables: Vec::new(),
            permutations: Vec::new(),
            widths: Vec::new(),
            colors: None,
            opacities: None,
            outside_skin: None,
            strands: Vec::new(),
        };
        recipe.add_steps(generator);
        // Each clump level's centres, then the render hairs.
        let mut hairs: Vec<(Vec<SurfacePoint>, Vec<u64>, u32)> = Vec::new();
        for step in recipe.steps.clone() {
            if step.kind != StepKind::Clump {
                continue;
            }
            let k = step.chain_index;
            let Operator::Clump(clump) = generator.ops[k].unmasked() else {
                unreachable!("a clump step is a clump operator");
            };
            let centre_roots = clump.centres().surface_roots().to_vec();
            let centre_ids = (0..centre_roots.len())
                .map(|i| centre_hair_id(k, i))
                .collect();
            let before = recipe.steps.iter().filter(|s| s.chain_index < k).count();
            hairs.push((centre_roots, centre_ids, before as u32));
        }
        let centre_passes = hairs.len();
        hairs.push((roots.to_vec(), ids.to_vec(), recipe.steps.len() as u32));
        let mut first = 0u32;
        for (pass, (roots, ids, steps)) in hairs.into_iter().enumerate() {
            let centres = pass < centre_passes;
            let (kept, _) =
                recipe.add_hairs(generator, (&roots, &ids), (steps as usize, centres))?;
            let count = kept.len() as u32;
            recipe.passes.push(RecipePass {
                hairs: first..first + count,
                steps,
            });
            first += count;
        }
        let centres: Vec<u32> = recipe.passes.iter().map(|p| p.hairs.start).collect();
        for (step, start) in recipe
            .steps
            .iter_mut()
            .filter(|s| s.kind == StepKind::Clump)
            .zip(centres)
        {
            step.centres = start;
        }
        // By root: the operators split and drop hairs as they grow them.
        recipe.add_attributes(generator, roots, ids);
        Ok(recipe)
    }

    /// Hairs in all.
    pub fn hair_count(&self) -> usize {
        self.ids.len()
    }

    /// The render hairs (the last pass).
    pub fn render_hairs(&self) -> Range<u32> {
        self.passes.last().map_or(0..0, |p| p.hairs.clone())
    }

    /// The guides' offsets from their roots, a point after another, as an
    /// evaluator reads a frame's guides (`guides`: the frame's, in rest
    /// space, with the groom's guides' roots and point count).
    pub fn guide_offsets(guides: &crate::guides::Guides) -> Vec<Vec3> {
        let mut out = Vec::with_capacity(guides.curves().points().len());
        for i in 0..guides.len() {
            let g = guides.guide(i);
            out.extend(g.iter().map(|p| *p - g[0]));
        }
        out
    }

    /// The steps of `generator`'s chain, their tables and noise fields.
    fn add_steps(&mut self, generator: &Generator) {
        let n = generator.points;
        let mut offset = 0u32;
        for (k, op) in generator.ops.iter().enumerate() {
            // A masked cut fades its parameter, not its result.
            let masked =
                matches!(op, Operator::Masked(_)) && !matches!(op.unmasked(), Operator::Cut(_));
            let (kind, ramp) = match op.unmasked() {
                Operator::Length(_) => (StepKind::Length, None),
                Operator::Curl(c) => (StepKind::Curl, Some(c.ramp())),
                Operator::Twist(t) => (StepKind::Twist, Some(t.ramp())),
                Operator::Noise(x) => (StepKind::Noise, Some(x.ramp())),
                Operator::Frizz(f) => (StepKind::Frizz, Some(f.ramp())),
                Operator::Flyaways(f) => (StepKind::Flyaways, Some(f.ramp())),
                Operator::Clump(c) => (StepKind::Clump, Some(c.ramp())),
                // Widths, colours and opacities: made once (module docs).
                Operator::Width(_) | Operator::Color(_) | Operator::Opacity(_) => continue,
                Operator::Cut(_) => (StepKind::Cut, None),
                Operator::Strands(_) => {
                    self.strands.push(k);
                    (StepKind::Strands, None)
                }
                Operator::Masked(_) => unreachable!("an unmasked operator"),
            };
            let table = self.tables.len() as u32;
            match ramp {
                Some(ramp) => self.tables.extend((0..n).map(|j| ramp.at(param(j, n)))),
                None => self.tables.extend(std::iter::repeat_n(1.0, n)),
            }
            let mut step = RecipeStep {
                kind,
                chain_index: k,
                values: offset,
                masked,
                table,
                permutation: 0,
                vectors: n as u32,
                centres: 0,
            };
            let permutation = match op.unmasked() {
                Operator::Noise(x) => {
                    let (m, to_vectors, to_points) = x.vector_spacing(n);
                    step.vectors = m as u32;
                    if m != n {
                        for &(j, f) in to_vectors.between().iter().chain(to_points.between()) {
                            self.tables.extend([j as f32, f]);
                        }
                    }
                    Some(x.permutation())
                }
                Operator::Frizz(f) => Some(f.permutation()),
                Operator::Flyaways(f) => Some(f.permutation()),
                _ => None,
            };
            if let Some(table) = permutation {
                step.permutation = self.permutations.len() as u32;
                self.permutations
                    .extend(table.iter().map(|&p| u32::from(p)));
            }
            offset += kind.values() + u32::from(masked);
            self.steps.push(step);
        }
        self.values_per_hair = offset;
        self.outside_skin = generator.outside_skin.as_ref().map(|skin| {
            let segment = OutsideSkin::segment(&generator.guides, generator.points);
            ((**skin).clone(), segment)
        });
    }

    /// Appends the hairs `ids` at `roots`: their roots, weights and
    /// values.
    /// Returns the roots and ids kept: render hairs cut away entirely
    /// (a `cut` at 0 or less among the pass's `steps`) are left out, as
    /// the CPU removes them; a clump centre cut away grows bare (its
    /// interpolated shape, no step), as the CPU grows it.
    fn add_hairs(
        &mut self,
        generator: &Generator,
        (roots, ids): (&[SurfacePoint], &[u64]),
        (steps_run, centres): (usize, bool),
    ) -> Result<(Vec<SurfacePoint>, Vec<u64>), GroomError> {
        const CHUNK: usize = 1024;
        let per_hair = self.values_per_hair as usize;
        let steps = &self.steps;
        // The strands operators the pass splits hairs at, in chain order.
        let splits: Vec<(usize, &Strands)> = self
            .strands
            .iter()
            .filter(|&&k| steps[..steps_run].iter().any(|s| s.chain_index == k))
            .map(|&k| match generator.ops[k].unmasked() {
                Operator::Strands(s) => (k, s),
                _ => unreachable!("a strands step is a strands operator"),
            })
            .collect();
        // Which id a hair's values for each step are drawn from: the one
        // it has after the splits up to that step (0: its root's).
        let id_after: Vec<usize> = steps
            .iter()
            .map(|step| {
                splits
                    .iter()
                    .filter(|(k, _)| *k <= step.chain_index)
                    .count()
            })
            .collect();
        // Whether a hair's values cut it away within the pass's steps.
        let cut_away = |values: &[f32]| {
            steps[..steps_run]
                .iter()
                .any(|s| s.kind == StepKind::Cut && values[s.values as usize] <= 0.0)
        };
        type Chunk = (
            Vec<Vec3>,
            Vec<Vec3>,
            Vec<GuideWeight>,
            Vec<f32>,
            usize,
            Vec<(SurfacePoint, u64, bool)>,
        );
        let chunks: Vec<Chunk> = roots
            .par_chunks(CHUNK)
            .zip(ids.par_chunks(CHUNK))
            .map_init(
                || (HairScratch::default(), NeighbourCache::default()),
                |(interp, near), (roots, ids)| {
                    let mut out: Chunk = (
                        Vec::with_capacity(roots.len()),
                        Vec::with_capacity(roots.len()),
                        Vec::with_capacity(roots.len() * MAX_RECIPE_WEIGHTS),
                        Vec::with_capacity(roots.len() * per_hair),
                        0,
                        Vec::with_capacity(roots.len()),
                    );
                    let mut hair_values = Vec::with_capacity(per_hair);
                    let mut lineages = Lineages::default();
                    for (&root, &base_id) in roots.iter().zip(ids) {
                        let context = generator.root_context(root);
                        let hair_root = HairRoot {
                            position: context.position,
                            triangle: Some(root.tri),
                            region: context.region,
                        };
                        generator.interpolator.weighting().weights_near(
                            hair_root,
                            &mut interp.near,
                            &mut interp.weights,
                        );
                        out.4 = out.4.max(interp.weights.len());
                        let padding = GuideWeight {
                            guide: 0,
                            weight: 0.0,
                        };
                        lineages.split(base_id, &splits, !centres, |k| {
                            mask_weight(&generator.ops[k], &context) > 0.0
                        });
                        for lineage in lineages.hairs() {
                            hair_values.clear();
                            for (step, &at) in steps.iter().zip(&id_after) {
                                let id = lineage[at];
                                step_values(generator, step, id, &context, near, &mut hair_values);
                            }
                            let bare = cut_away(&hair_values);
                            if bare && !centres {
                                continue;
                            }
                            // A centre keeps its root's id (its clump's).
                            let id = if centres {
                                base_id
                            } else {
                                lineage[splits.len()]
                            };
                            out.5.push((root, id, bare));
                            out.3.extend_from_slice(&hair_values);
                            out.2.extend(
                                interp
                                    .weights
                                    .iter()
                                    .copied()
                                    .chain(std::iter::repeat(padding))
                                    .take(MAX_RECIPE_WEIGHTS),
                            );
                            out.0.push(context.position);
                            out.1.push(context.normal);
                        }
                    }
                    out
                },
            )
            .collect();
        let (mut kept_roots, mut kept_ids) = (Vec::new(), Vec::new());
        for (positions, normals, weights, values, most, kept) in chunks {
            if most > MAX_RECIPE_WEIGHTS {
                return Err(generator.error(
                    "interpolation",
                    GroomErrorKind::Mismatch(format!(
                        "hairs take their shape from {most} guides; an evaluator that runs every frame takes at most {MAX_RECIPE_WEIGHTS}"
                    )),
                ));
            }
            self.root_positions.extend(positions);
            self.root_normals.extend(normals);
            self.weights.extend(weights);
            self.values.extend(values);
            for (root, id, bare) in kept {
                kept_roots.push(root);
                kept_ids.push(id);
                self.bare.push(bare);
            }
        }
        self.roots.extend_from_slice(&kept_roots);
        self.ids.extend_from_slice(&kept_ids);
        Ok((kept_roots, kept_ids))
    }

    /// The render hairs' widths, colours and opacities, made by the CPU
    /// operators (the finish's, then the chain's).
    fn add_attributes(&mut self, generator: &Generator, roots: &[SurfacePoint], ids: &[u64]) {
        let n = generator.points;
        let attribute_ops: Vec<&Operator> = generator
            .base
            .iter()
            .chain(&generator.ops)
            // A cut resamples the attributes there are when it cuts.
            .filter(|op| {
                matches!(
                    op.unmasked(),
                    Operator::Width(_)
                        | Operator::Color(_)
                        | Operator::Opacity(_)
                        | Operator::Cut(_)
                        | Operator::Strands(_)
                )
            })
            .collect();
        type Attributes = (Vec<f32>, Vec<Vec3>, Vec<f32>);
        let scale = generator.width_scale;
        let chunks: Vec<Attributes> = roots
            .par_chunks(1024)
            .zip(ids.par_chunks(1024))
            .map_init(
                || (HairBatch::default(), Scratch::default()),
                |(batch, scratch), (roots, ids)| {
                    let mut out: Attributes = Default::default();
                    for (&root, &id) in roots.iter().zip(ids) {
                        let context = generator.root_context(root);
                        let hair = batch.reset();
                        hair.id = id;
                        hair.points.clear();
                        hair.points.resize(n, context.position);
                        hair.widths.clear();
                        hair.colors.clear();
                        hair.opacities.clear();
                        for op in &attribute_ops {
                            op.apply(batch, &context, scratch);
                        }
                        // Every hair the root grew: its strand's, none
                        // when a cut took them away.
                        for hair in batch.hairs() {
                            out.0.extend(hair.widths.iter().map(|w| w * scale));
                            if generator.colors {
                                out.1.extend_from_slice(&hair.colors);
                            }
                            if generator.opacities {
                                out.2.extend_from_slice(&hair.opacities);
                            }
                        }
                    }
                    out
                },
            )
            .collect();
        let (mut colors, mut opacities) = (Vec::new(), Vec::new());
        for (w, c, o) in chunks {
            self.widths.extend(w);
            colors.extend(c);
            opacities.extend(o);
        }
        self.colors = generator.colors.then_some(colors);
        self.opacities = generator.opacities.then_some(opacities);
    }
}

/// The hairs a root grows in a pass, each as the ids it has after each
/// split (its root's first), in the CPU's order: `Strands::split`
/// replaces each hair by its strand, base after base.
#[derive(Default)]
struct Lineages {
    ids: Vec<u64>,
    next: Vec<u64>,
    stride: usize,
}

impl Lineages {
    /// The hairs of the root `base_id` through `splits`. `whole`: each
    /// split grows its whole strand, or only the first hair (a clump
    /// centre follows its strand's first). `splits_here(k)`: whether the
    /// split at chain position `k` splits at this root (a mask of 0 there
    /// leaves the hair whole, as the CPU's masked strands do).
    fn split(
        &mut self,
        base_id: u64,
        splits: &[(usize, &Strands)],
        whole: bool,
        mut splits_here: impl FnMut(usize) -> bool,
    ) {
        self.ids.clear();
        self.ids.push(base_id);
        self.stride = 1;
        for &(k, strands) in splits {
            let count = match whole && splits_here(k) {
                true => strands.count(),
                // A hair left whole takes its strand's first id.
                false => 1,
            };
            self.next.clear();
            for lineage in self.ids.chunks_exact(self.stride) {
                let last = lineage[self.stride - 1];
                for c in 0..u64::from(count) {
                    self.next.extend_from_slice(lineage);
                    self.next.push(strands.strand_id(last, c));
                }
            }
            std::mem::swap(&mut self.ids, &mut self.next);
            self.stride += 1;
        }
    }

    /// Each hair's ids, its root's first.
    fn hairs(&self) -> std::slice::ChunksExact<'_, u64> {
        self.ids.chunks_exact(self.stride)
    }
}

/// The weight of every mask over `op` at `context` (1: none).
fn mask_weight(mut op: &Operator, context: &RootContext) -> f32 {
    let mut m = 1.0;
    while let Operator::Masked(masked) = op {
        m *= masked.weight(context);
        op = masked.operator();
    }
    m
}

/// Appends hair `id`'s values for `step` at `context`, by the operator's
/// own functions.
fn step_values(
    generator: &Generator,
    step: &RecipeStep,
    id: u64,
    context: &RootContext,
    near: &mut NeighbourCache,
    out: &mut Vec<f32>,
) {
    let m = mask_weight(&generator.ops[step.chain_index], context);
    let op = generator.ops[step.chain_index].unmasked();
    if step.masked {
        out.push(m);
    }
    match op {
        Operator::Cut(c) => out.push(1.0 - m * (1.0 - c.at().at(&context.site))),
        Operator::Strands(s) => {
            let (rho, turn) = s.place(id);
            out.extend(s.spreads(context));
            out.extend([rho, turn]);
        }
        Operator::Length(l) => out.push(l.factor(id, context)),
        Operator::Curl(c) => out.extend(c.helix(id, context)),
        Operator::Twist(t) => out.push(t.angle(id, context)),
        Operator::Noise(x) => {
            let (amplitude, frequency) = x.strength(context);
            out.extend([amplitude, frequency]);
        }
        Operator::Frizz(f) => match f.frizzed(id, context) {
            Some((amplitude, frequency, phase)) => {
                out.extend([amplitude, frequency, phase.x, phase.y, phase.z]);
            }
            None => out.extend([0.0; 5]),
        },
        Operator::Flyaways(f) => match f.strayed(id, context) {
            Some(s) => out.extend([
                1.0,
                s.length,
                s.spread,
                s.frequency,
                s.phase.x,
                s.phase.y,
                s.phase.z,
                s.across.x,
                s.across.y,
                s.across.z,
            ]),
            None => out.extend([0.0; 10]),
        },
        Operator::Clump(c) => match c.target(context, near) {
            Some((centre, w)) => out.extend([f32::from_bits(centre as u32), w]),
            None => out.extend([0.0, 0.0]),
        },
        _ => unreachable!("only operators with a step have values"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::groom::{GroomSpec, RootsSpec};
    use crate::guides::{GuideGrowth, Guides};
    use std::collections::HashSet;
    use std::sync::Arc;

    fn spot_groom(roots: RootsSpec) -> Generator {
        let mesh = Arc::new(crate::assets::spot());
        let guides = Guides::grow(
            &mesh,
            &GuideGrowth {
                count: 30,
                ..Default::default()
            },
        )
        .unwrap();
        GroomSpec::new(mesh, guides, roots).generator().unwrap()
    }

    #[test]
    fn the_first_hairs_by_arrival_are_the_hairs_a_preview_fraction_grows() {
        let full = spot_groom(RootsSpec::new(20_000));
        let (_, ordered) = roots_by_arrival(&full);
        assert_eq!(ordered.len(), 20_000);
        for fraction in [0.05, 0.3, 0.77] {
            let preview = spot_groom(RootsSpec::new(20_000).with_fraction(fraction));
            let (_, ids) = roots_by_arrival(&preview);
            let grown: HashSet<u64> = ids.iter().copied().collect();
            let first: HashSet<u64> = ordered[..ids.len()].iter().copied().collect();
            assert_eq!(grown, first, "fraction {fraction}");
            // And in the same order: a prefix of a prefix.
            assert_eq!(ids, ordered[..ids.len()]);
        }
    }
}
