//! An editable groom: a groom's mesh with its paint layers, its guides,
//! its operator stack and its grown hairs (at a preview fraction or in
//! full), changed by [`Edit`]s on an undo/redo stack, each regrowing only
//! the hairs it can change (`hairs.rs`). The brushes
//! ([`crate::groom::brush`]) turn a dab into an `Edit`; the viewer's groom
//! mode, Python's `GroomSession` and the benchmarks all drive this one
//! type.
//!
//! What an edit regrows:
//!
//! - guide points moved: the hairs weighted by those guides, and the hairs
//!   following a clump centre whose shape changed with them;
//! - guides added or deleted: the hairs whose guide weights changed (every
//!   root's weights are found again and compared);
//! - a paint layer: where it feeds the root density, the roots of the
//!   cells under the stroke (and the few that arrive or leave at the
//!   margin as the total shifts); where it feeds regions, every hair whose
//!   region or weights changed; where it feeds an operator or the finish,
//!   the hairs rooted on triangles with a painted corner;
//! - the groom's settings (count, operators, finish): everything.
//!
//! The result equals growing the edited groom from nothing, bit for bit
//! (tests replay random edits of every kind and compare), because a
//! hair's growth reads nothing but its recipe and its stable id.

mod hairs;
mod save;

pub use hairs::Regrowth;
pub use save::{SavedGroom, layers_file_name};

use super::error::{GroomError, GroomErrorKind};
use super::generator::{Generator, Reuse};
use super::spec::{GroomSpec, HairIds, RootDistribution};
use crate::curves::Curves;
use crate::guides::Guides;
use crate::interp::GuideWeight;
use crate::map::Map;
use crate::mesh::{Mesh, SurfacePoint, TriangleBvh};
use glam::Vec3;
use hairs::{Change, GrownHairs};
use std::sync::Arc;

/// One change to an editable groom. Brushes make them; so may a program.
#[derive(Debug, Clone)]
pub enum Edit {
    /// New points for some guides (roots unchanged): `points` holds
    /// `points_per_guide` points for each of `guides`, in order.
    MoveGuides {
        /// Guide indices.
        guides: Vec<u32>,
        /// Their new points.
        points: Vec<Vec3>,
    },
    /// Another set of guides (guides added or deleted), bound to the mesh.
    ReplaceGuides(Arc<Guides>),
    /// New values of a paint layer (a per-vertex attribute of the mesh) at
    /// some vertices.
    Paint {
        /// The layer's name (maps read it as `vertex:NAME`).
        layer: String,
        /// Vertex indices.
        vertices: Vec<u32>,
        /// Their new values.
        values: Vec<f32>,
    },
    /// Other settings (count, operators, finish, regions): regrows
    /// everything.
    ReplaceSpec(Box<GroomSpec>),
    /// A paint layer added (or, undone, taken away) that leaves every
    /// hair as it was: a density scale of ones, a region layer of zeros.
    /// The roots and recipes are found again and compared, so only the
    /// hairs whose recipe differs (none, or a few at float rounding) are
    /// regrown. Made by the paint and part brushes only.
    NewLayer(LayerSetup),
    /// Several edits undone and redone as one.
    Group(Vec<Edit>),
}

impl Edit {
    /// About how many bytes the edit holds (for the undo budget).
    fn bytes(&self) -> usize {
        match self {
            Edit::MoveGuides { guides, points } => guides.len() * 4 + points.len() * 12,
            Edit::ReplaceGuides(g) => g.curves().points().len() * 16 + g.len() * 24,
            Edit::Paint {
                vertices, values, ..
            } => vertices.len() * 4 + values.len() * 4,
            Edit::ReplaceSpec(spec) | Edit::NewLayer(LayerSetup(spec)) => {
                spec.mesh.vertex_count() * 4 * (spec.mesh.vertex_attributes().len() + 1) + 1024
            }
            Edit::Group(edits) => edits.iter().map(Edit::bytes).sum(),
        }
    }
}

/// A groom that differs from the one it follows by paint layers, the
/// density scale and the regions alone. Only the brushes make one: its
/// regrowth compares roots and recipes, and would miss any other change.
#[derive(Debug, Clone)]
pub struct LayerSetup(pub(crate) Box<GroomSpec>);

/// An edit and its inverse, as the undo and redo stacks keep them.
#[derive(Debug, Clone)]
struct Step {
    forward: Edit,
    inverse: Edit,
    bytes: usize,
}

/// The most bytes the undo and redo stacks hold by default; the oldest
/// steps are forgotten past it.
pub const DEFAULT_HISTORY_BYTES: usize = 256 << 20;

/// A groom being groomed; see the module docs.
pub struct EditableGroom {
    spec: GroomSpec,
    generator: Generator,
    /// The share of the groom's hairs grown (the first arrivals of every
    /// root cell: a preview is a subset of the full groom).
    fraction: f64,
    /// Each root cell's hairs at the fraction.
    counts: Vec<u64>,
    hairs: GrownHairs,
    undo: Vec<Step>,
    redo: Vec<Step>,
    history_budget: usize,
    /// The skin, for brushes' closest-point queries.
    bvh: Arc<TriangleBvh>,
}

impl std::fmt::Debug for EditableGroom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EditableGroom")
            .field("guides", &self.spec.guides.len())
            .field("hairs", &self.hairs.hair_count())
            .field("fraction", &self.fraction)
            .field("undo", &self.undo.len())
            .field("redo", &self.redo.len())
            .finish()
    }
}

impl EditableGroom {
    /// Opens `spec` for editing, growing `fraction` (0 to 1) of its hairs.
    ///
    /// # Errors
    /// What [`GroomSpec::generator`] refuses; a groom whose hairs are not
    /// numbered by root cells (`ids = "sequential"`) or whose roots are
    /// blue noise (both move every root when anything changes, so no edit
    /// could regrow less than everything); a fraction outside (0, 1].
    pub fn new(spec: GroomSpec, fraction: f64) -> Result<Self, GroomError> {
        if spec.roots.ids != HairIds::Stable {
            return Err(spec.error(
                "roots.ids",
                GroomErrorKind::Conflict(
                    "grooming by hand needs stable hair ids: remove `ids = \"sequential\"`".into(),
                ),
            ));
        }
        if spec.roots.distribution != RootDistribution::Random {
            return Err(spec.error(
                "roots.distribution",
                GroomErrorKind::Conflict(
                    "grooming by hand needs random roots: blue-noise roots move as a whole when one changes; groom with `distribution = \"random\"` and switch back to write".into(),
                ),
            ));
        }
        check_fraction(&spec, fraction)?;
        let generator = Generator::rebuilt(
            spec.clone(),
            Reuse {
                centre_guides: true,
                ..Reuse::default()
            },
        )?;
        let mesh = &spec.mesh;
        let bvh = Arc::new(TriangleBvh::new(mesh.positions(), mesh.triangles()));
        let mut groom = Self {
            spec,
            generator,
            fraction,
            counts: Vec::new(),
            hairs: GrownHairs::default(),
            undo: Vec::new(),
            redo: Vec::new(),
            history_budget: DEFAULT_HISTORY_BYTES,
            bvh,
        };
        let counts = groom.counts(&groom.generator);
        let change = Change {
            everything: true,
            ..Default::default()
        };
        groom
            .hairs
            .update(None, &groom.generator, &counts, &change)?;
        groom.counts = counts;
        Ok(groom)
    }

    /// The groom as it is now.
    pub fn spec(&self) -> &GroomSpec {
        &self.spec
    }

    /// The generator of the groom as it is now (for writing it in full).
    pub fn generator(&self) -> &Generator {
        &self.generator
    }

    /// The mesh, with its paint layers.
    pub fn mesh(&self) -> &Mesh {
        &self.spec.mesh
    }

    /// The guides.
    pub fn guides(&self) -> &Guides {
        &self.spec.guides
    }

    /// The values of paint layer `name`, one a vertex.
    pub fn layer(&self, name: &str) -> Option<&[f32]> {
        self.spec.mesh.vertex_attribute(name).map(|a| &*a.values)
    }

    /// The skin's closest-point hierarchy (rest pose).
    pub fn bvh(&self) -> &TriangleBvh {
        &self.bvh
    }

    /// The share of the hairs grown.
    pub fn fraction(&self) -> f64 {
        self.fraction
    }

    /// Hairs grown now.
    pub fn hair_count(&self) -> usize {
        self.hairs.hair_count()
    }

    /// Roots grown now.
    pub fn root_count(&self) -> usize {
        self.hairs.root_count()
    }

    /// The grown hairs, root cell after root cell, with their ids and
    /// roots (the order differs from a written groom's parts; ids match).
    pub fn curves(&self) -> Curves {
        self.generator.with_root_values(self.hairs.curves())
    }

    /// The hairs' points alone, in the order of [`Self::curves`]: what a
    /// viewport refreshes after an edit that keeps the hair count.
    pub fn points(&self) -> Vec<Vec3> {
        self.hairs.points()
    }

    /// Every root with its region and its guide weights.
    pub fn hair_weights(&self) -> impl Iterator<Item = (SurfacePoint, u32, &[GuideWeight])> {
        self.hairs.recipes()
    }

    /// Sets how many bytes of history the undo and redo stacks keep.
    pub fn set_history_budget(&mut self, bytes: usize) {
        self.history_budget = bytes;
        self.trim_history();
    }

    /// Bytes the undo and redo stacks hold.
    pub fn history_bytes(&self) -> usize {
        self.undo.iter().chain(&self.redo).map(|s| s.bytes).sum()
    }

    /// Steps that can be undone and redone.
    pub fn history_len(&self) -> (usize, usize) {
        (self.undo.len(), self.redo.len())
    }

    /// Grows another share of the hairs (not an edit: no undo step).
    pub fn set_fraction(&mut self, fraction: f64) -> Result<Regrowth, GroomError> {
        check_fraction(&self.spec, fraction)?;
        self.fraction = fraction;
        self.counts = self.counts(&self.generator);
        let change = Change {
            roots: true,
            ..Default::default()
        };
        self.hairs.update(
            Some(&self.generator),
            &self.generator,
            &self.counts,
            &change,
        )
    }

    /// Applies `edit`, regrowing what it changes, and puts it on the undo
    /// stack (clearing the redo stack).
    ///
    /// # Errors
    /// An edit that does not fit the groom (a guide or vertex index out of
    /// range, a layer the mesh does not have, values that are not finite)
    /// or a groom the generator refuses; the groom is left as it was.
    pub fn apply(&mut self, edit: Edit) -> Result<Regrowth, GroomError> {
        let (inverse, regrowth) = self.perform(edit.clone())?;
        self.push_step(edit, inverse);
        Ok(regrowth)
    }

    /// Takes a DCC's guide curves (any point count) as the guides, bound to
    /// the mesh as [`Guides::bind`] binds them. Where they keep the guides'
    /// count and roots (the artist moved points, as most sculpt brushes
    /// do), only the guides whose points changed are moved
    /// ([`Edit::MoveGuides`]): hairs out of their reach are not regrown.
    /// Otherwise (guides added, deleted or slid) the guides are replaced
    /// ([`Edit::ReplaceGuides`]). `None` when nothing changed.
    ///
    /// # Errors
    /// As [`Self::apply`].
    pub fn set_guide_curves(
        &mut self,
        curves: &Curves,
        tolerance: f32,
    ) -> Result<Option<Regrowth>, GroomError> {
        let old = self.guides();
        let (bound, _) = Guides::bind(self.mesh(), curves, old.points_per_guide(), tolerance);
        if bound.len() != old.len() || bound.roots() != old.roots() {
            return self.apply(Edit::ReplaceGuides(Arc::new(bound))).map(Some);
        }
        let (mut guides, mut points) = (Vec::new(), Vec::new());
        for i in 0..bound.len() {
            if bound.guide(i) != old.guide(i) {
                guides.push(i as u32);
                points.extend_from_slice(bound.guide(i));
            }
        }
        if guides.is_empty() {
            return Ok(None);
        }
        self.apply(Edit::MoveGuides { guides, points }).map(Some)
    }

    /// Applies `first`, then the edit `then` makes on the groom it left
    /// (`None`: nothing more), as one undo step; on an error nothing
    /// changed.
    pub(crate) fn apply_then(
        &mut self,
        first: Edit,
        then: impl FnOnce(&Self) -> Result<Option<Edit>, GroomError>,
    ) -> Result<Regrowth, GroomError> {
        let (first_inverse, first_regrowth) = self.perform(first.clone())?;
        let second = match then(self) {
            Ok(second) => second,
            Err(e) => {
                self.perform(first_inverse)?;
                return Err(e);
            }
        };
        let (forward, inverse, regrowth) = match second {
            None => (first, first_inverse, first_regrowth),
            Some(edit) => match self.perform(edit.clone()) {
                Ok((inverse, regrowth)) => (
                    Edit::Group(vec![first, edit]),
                    Edit::Group(vec![inverse, first_inverse]),
                    // Roots both steps regrew count once: never more
                    // than the groom has (101,774 of 100,000 was said).
                    Regrowth {
                        regrown_roots: (first_regrowth.regrown_roots + regrowth.regrown_roots)
                            .min(regrowth.hairs),
                        hairs: regrowth.hairs,
                    },
                ),
                Err(e) => {
                    self.perform(first_inverse)?;
                    return Err(e);
                }
            },
        };
        self.push_step(forward, inverse);
        Ok(regrowth)
    }

    /// Joins the last `n` undo steps into one, undone and redone together
    /// (a stroke's dabs, as a groomer expects one Ctrl+Z to take back).
    pub fn join_last_steps(&mut self, n: usize) {
        let n = n.min(self.undo.len());
        if n < 2 {
            return;
        }
        let steps = self.undo.split_off(self.undo.len() - n);
        let bytes = steps.iter().map(|s| s.bytes).sum();
        let (forward, mut inverse): (Vec<Edit>, Vec<Edit>) =
            steps.into_iter().map(|s| (s.forward, s.inverse)).unzip();
        inverse.reverse();
        self.undo.push(Step {
            forward: Edit::Group(forward),
            inverse: Edit::Group(inverse),
            bytes,
        });
    }

    /// Undoes the last edit (`None`: nothing to undo).
    pub fn undo(&mut self) -> Result<Option<Regrowth>, GroomError> {
        let Some(step) = self.undo.pop() else {
            return Ok(None);
        };
        match self.perform(step.inverse.clone()) {
            Ok((_, regrowth)) => {
                self.redo.push(step);
                Ok(Some(regrowth))
            }
            Err(e) => {
                self.undo.push(step);
                Err(e)
            }
        }
    }

    /// Redoes the last undone edit (`None`: nothing to redo).
    pub fn redo(&mut self) -> Result<Option<Regrowth>, GroomError> {
        let Some(step) = self.redo.pop() else {
            return Ok(None);
        };
        match self.perform(step.forward.clone()) {
            Ok((_, regrowth)) => {
                self.undo.push(step);
                Ok(Some(regrowth))
            }
            Err(e) => {
                self.redo.push(step);
                Err(e)
            }
        }
    }

    /// The same groom grown from nothing (what the incremental regrowth
    /// must equal).
    pub fn regrown_from_scratch(&self) -> Result<Self, GroomError> {
        Self::new(self.spec.clone(), self.fraction)
    }

    /// A new step on the undo stack: the redo stack is dropped, and the
    /// history trimmed to its budget.
    fn push_step(&mut self, forward: Edit, inverse: Edit) {
        let bytes = forward.bytes() + inverse.bytes();
        self.undo.push(Step {
            forward,
            inverse,
            bytes,
        });
        self.redo.clear();
        self.trim_history();
    }

    fn trim_history(&mut self) {
        while self.history_bytes() > self.history_budget && !self.undo.is_empty() {
            self.undo.remove(0);
        }
        while self.history_bytes() > self.history_budget && !self.redo.is_empty() {
            self.redo.remove(0);
        }
    }

    /// Each root cell's count at the groom's fraction.
    fn counts(&self, generator: &Generator) -> Vec<u64> {
        let grown = self.spec.roots.grown_count();
        let hairs = ((grown as f64 * self.fraction).round() as u64).max(1);
        generator
            .root_cells()
            .expect("stable ids (checked when opened)")
            .counts(self.spec.roots.seed, hairs)
    }

    /// Applies `edit` and returns its inverse; on an error nothing changed.
    fn perform(&mut self, edit: Edit) -> Result<(Edit, Regrowth), GroomError> {
        match edit {
            Edit::Group(edits) => {
                let mut inverses = Vec::with_capacity(edits.len());
                let mut regrowth = Regrowth::default();
                for e in edits {
                    match self.perform(e) {
                        Ok((inverse, r)) => {
                            inverses.push(inverse);
                            regrowth.regrown_roots += r.regrown_roots;
                            regrowth.hairs = r.hairs;
                        }
                        Err(err) => {
                            for inverse in inverses.into_iter().rev() {
                                self.perform(inverse)?;
                            }
                            return Err(err);
                        }
                    }
                }
                inverses.reverse();
                Ok((Edit::Group(inverses), regrowth))
            }
            Edit::MoveGuides { guides, points } => self.move_guides(guides, points),
            Edit::ReplaceGuides(new) => {
                let mut spec = self.spec.clone();
                let old = std::mem::replace(&mut spec.guides, new);
                let keep = Keep {
                    roots: true,
                    regions: true,
                    weights: false,
                    only_guides_moved: false,
                };
                let change = Change {
                    recipes: true,
                    ..Default::default()
                };
                let regrowth = self.transition(spec, Some(keep), change)?;
                Ok((Edit::ReplaceGuides(old), regrowth))
            }
            Edit::Paint {
                layer,
                vertices,
                values,
            } => self.paint(layer, vertices, values),
            Edit::ReplaceSpec(spec) => {
                let old = Box::new(self.spec.clone());
                let change = Change {
                    everything: true,
                    ..Default::default()
                };
                let regrowth = self.transition(*spec, None, change)?;
                self.bvh = Arc::new(TriangleBvh::new(
                    self.spec.mesh.positions(),
                    self.spec.mesh.triangles(),
                ));
                Ok((Edit::ReplaceSpec(old), regrowth))
            }
            Edit::NewLayer(LayerSetup(spec)) => {
                let old = LayerSetup(Box::new(self.spec.clone()));
                let keep = Keep {
                    roots: false,
                    regions: false,
                    weights: false,
                    only_guides_moved: false,
                };
                let change = Change {
                    roots: true,
                    recipes: true,
                    ..Default::default()
                };
                let regrowth = self.transition(*spec, Some(keep), change)?;
                Ok((Edit::NewLayer(old), regrowth))
            }
        }
    }

    fn move_guides(
        &mut self,
        guides: Vec<u32>,
        points: Vec<Vec3>,
    ) -> Result<(Edit, Regrowth), GroomError> {
        let current = &self.spec.guides;
        let n = current.points_per_guide();
        let invalid = |m: String| Err(self.spec.error("guides", GroomErrorKind::Mismatch(m)));
        if points.len() != guides.len() * n {
            return invalid(format!(
                "{} points for {} guides of {n} points",
                points.len(),
                guides.len()
            ));
        }
        if let Some(g) = guides.iter().find(|g| **g as usize >= current.len()) {
            return invalid(format!("guide {g} of {}", current.len()));
        }
        if points.iter().any(|p| !p.is_finite()) {
            return invalid("guide points must be finite".into());
        }
        let mut all = current.curves().points().to_vec();
        let mut before = Vec::with_capacity(points.len());
        let mut moved = Vec::new();
        for (i, &g) in guides.iter().enumerate() {
            let range = g as usize * n..(g as usize + 1) * n;
            before.extend_from_slice(&all[range.clone()]);
            let new = &points[i * n..(i + 1) * n];
            if all[range.clone()] != *new {
                moved.push(g);
            }
            all[range].copy_from_slice(new);
        }
        let reshaped = current
            .with_points(all)
            .map_err(|e| self.spec.error("guides", GroomErrorKind::Curves(e)))?;
        let mut spec = self.spec.clone();
        spec.guides = Arc::new(reshaped);
        moved.sort_unstable();
        moved.dedup();
        let keep = Keep {
            roots: true,
            regions: true,
            weights: true,
            only_guides_moved: true,
        };
        let change = Change {
            moved_guides: moved,
            ..Default::default()
        };
        let regrowth = self.transition(spec, Some(keep), change)?;
        Ok((
            Edit::MoveGuides {
                guides,
                points: before,
            },
            regrowth,
        ))
    }

    fn paint(
        &mut self,
        layer: String,
        vertices: Vec<u32>,
        values: Vec<f32>,
    ) -> Result<(Edit, Regrowth), GroomError> {
        let mesh = &self.spec.mesh;
        let refuse = |kind: GroomErrorKind| Err(self.spec.error("mesh", kind));
        let Some(current) = mesh.vertex_attribute(&layer) else {
            return refuse(GroomErrorKind::Missing(format!(
                "the mesh has no paint layer '{layer}' (it has: {})",
                layer_names(mesh)
            )));
        };
        if vertices.len() != values.len() {
            return refuse(GroomErrorKind::Mismatch(format!(
                "{} values for {} vertices",
                values.len(),
                vertices.len()
            )));
        }
        if let Some(v) = vertices
            .iter()
            .find(|v| **v as usize >= mesh.vertex_count())
        {
            return refuse(GroomErrorKind::OutOfRange(format!(
                "vertex {v} of {}",
                mesh.vertex_count()
            )));
        }
        if values.iter().any(|v| !v.is_finite()) {
            return refuse(GroomErrorKind::NotFinite(format!(
                "values painted on '{layer}' must be finite"
            )));
        }
        let mut all = current.values.to_vec();
        let before: Vec<f32> = vertices.iter().map(|&v| all[v as usize]).collect();
        for (&v, &x) in vertices.iter().zip(&values) {
            all[v as usize] = x;
        }
        let painted: Vec<bool> = {
            let mut p = vec![false; mesh.vertex_count()];
            for (&v, (&a, &b)) in vertices.iter().zip(before.iter().zip(&values)) {
                if a.to_bits() != b.to_bits() {
                    p[v as usize] = true;
                }
            }
            p
        };
        let new_mesh = Mesh::clone(mesh)
            .with_vertex_attribute(layer.clone(), all)
            .map_err(|e| self.spec.error("mesh", GroomErrorKind::Mesh(e)))?;
        let mut spec = self.spec.clone();
        spec.mesh = Arc::new(new_mesh);
        let reads = |map: &Map| matches!(map, Map::Vertex(v) if v.name == layer);
        let density = reads(&spec.roots.density) || reads(&spec.roots.density_scale);
        let regions = spec
            .regions
            .as_mut()
            .is_some_and(|r| r.maps_mut().into_iter().any(|m| reads(m)));
        let touched: Vec<u32> = if reads_elsewhere(&mut spec, &layer) {
            mesh.triangles()
                .iter()
                .enumerate()
                .filter(|(_, t)| t.iter().any(|&v| painted[v as usize]))
                .map(|(t, _)| t as u32)
                .collect()
        } else {
            Vec::new()
        };
        let keep = Keep {
            roots: !density,
            regions: !regions,
            weights: !regions,
            only_guides_moved: false,
        };
        let change = Change {
            roots: density,
            recipes: regions,
            touched_triangles: touched,
            ..Default::default()
        };
        let regrowth = self.transition(spec, Some(keep), change)?;
        Ok((
            Edit::Paint {
                layer,
                vertices,
                values: before,
            },
            regrowth,
        ))
    }

    /// Builds the generator of `spec` (reusing what `reuse` says) and
    /// brings the hairs to it; on an error nothing changed.
    fn transition(
        &mut self,
        spec: GroomSpec,
        keep: Option<Keep>,
        change: Change,
    ) -> Result<Regrowth, GroomError> {
        let reuse = match keep {
            Some(k) => Reuse {
                from: Some(&self.generator),
                roots: k.roots,
                regions: k.regions,
                weights: k.weights,
                moved_guides: k.only_guides_moved.then_some(&change.moved_guides[..]),
                centre_guides: true,
            },
            None => Reuse {
                centre_guides: true,
                ..Reuse::default()
            },
        };
        let generator = Generator::rebuilt(spec.clone(), reuse)?;
        if generator.root_cells().is_none() {
            return Err(spec.error(
                "roots.ids",
                GroomErrorKind::Conflict("grooming by hand needs stable hair ids".into()),
            ));
        }
        let previous_spec = std::mem::replace(&mut self.spec, spec);
        // The counts change only with the roots' sampler.
        let counts = match keep {
            Some(k) if k.roots => std::mem::take(&mut self.counts),
            _ => self.counts(&generator),
        };
        match self
            .hairs
            .update(Some(&self.generator), &generator, &counts, &change)
        {
            Ok(regrowth) => {
                self.generator = generator;
                self.counts = counts;
                Ok(regrowth)
            }
            Err(e) => {
                // A hair of the new groom did not grow (a value past f32's
                // range): grow the old groom again, whole.
                self.spec = previous_spec;
                let counts = self.counts(&self.generator);
                self.counts = counts.clone();
                let everything = Change {
                    everything: true,
                    ..Default::default()
                };
                self.hairs
                    .update(None, &self.generator, &counts, &everything)
                    .expect("the groom grew before this edit");
                Err(e)
            }
        }
    }
}

/// What an edit keeps of the groom's generator (see [`Reuse`]).
#[derive(Debug, Clone, Copy)]
struct Keep {
    roots: bool,
    regions: bool,
    weights: bool,
    /// Nothing changed but the shapes of `Change::moved_guides`.
    only_guides_moved: bool,
}

/// Whether an operator's or the finish's map reads layer `name`.
fn reads_elsewhere(spec: &mut GroomSpec, name: &str) -> bool {
    use super::ops::OperatorSettings;
    let reads = |map: &Map| matches!(map, Map::Vertex(v) if v.name == name);
    let finish = &mut spec.finish;
    let mut any = finish.width.maps_mut().into_iter().any(|(_, m)| reads(m));
    if let Some(color) = &mut finish.color {
        any |= color.maps_mut().into_iter().any(|(_, m)| reads(m));
    }
    if let Some(opacity) = &mut finish.opacity {
        any |= opacity.maps_mut().into_iter().any(|(_, m)| reads(m));
    }
    any || spec
        .ops
        .iter_mut()
        .any(|op| op.maps_mut().into_iter().any(|(_, m)| reads(m)))
}

fn layer_names(mesh: &Mesh) -> String {
    let names: Vec<&str> = mesh
        .vertex_attributes()
        .iter()
        .map(|a| a.name.as_str())
        .collect();
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

fn check_fraction(spec: &GroomSpec, fraction: f64) -> Result<(), GroomError> {
    if fraction > 0.0 && fraction <= 1.0 {
        Ok(())
    } else {
        Err(spec.error(
            "fraction",
            GroomErrorKind::OutOfRange(format!(
                "the preview fraction is {fraction}; use a share of the hairs in (0, 1]"
            )),
        ))
    }
}
