//! Groom brushes: each a pure function from an editable groom and a dab
//! (a sphere on the skin with a falloff, a strength and a direction in
//! world space, optionally mirrored across X) to an [`Edit`], as the
//! groom brushes of Blender's curves sculpt mode, XGen and Ornatrix do.
//!
//! Guide brushes keep what a groomer expects of a guide:
//!
//! - roots never move (a guide is rooted where it was bound);
//! - segment lengths are kept by the shaping brushes (comb, smooth, puff,
//!   clump, spread): points are moved, then each segment is laid again
//!   from the root along its new direction at its old length
//!   (follow-the-leader, as Müller et al. 2012 keep hair inextensible);
//! - no point goes below the skin: a point laid under the surface (by
//!   its closest point's normal) is lifted to it and its segment laid
//!   again along the lifted direction.
//!
//! Paint brushes set a per-vertex layer under the dab: `paint` blends any
//! float layer toward a value, `part` writes a region id, so a parting
//! follows the stroke.

use super::edit::{EditableGroom, Regrowth};
use super::error::{GroomError, GroomErrorKind};
use super::regions::{RegionSource, RegionsSpec};
use super::spec::GroomSpec;
use crate::groom::edit::{Edit, LayerSetup};
use crate::guides::{Guides, resample_by_arc_length};
use crate::interp::HairScratch;
use crate::map::{Map, VertexMap};
use crate::mesh::{Mesh, SurfacePoint, TriangleBvh};
use crate::sample::{mix64, open_unit_pair};
use glam::Vec3;
use std::sync::Arc;

pub use super::error::{BrushRefusal, MAX_BRUSH_STRENGTH};

/// How a brush's effect fades from its centre (distance 0) to its rim
/// (distance 1).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum Falloff {
    /// `1 − 3d² + 2d³`: full at the centre, smooth to zero at the rim.
    #[default]
    Smooth,
    /// `1 − d`.
    Linear,
    /// 1 everywhere inside.
    Constant,
}

impl Falloff {
    /// The weight at distance `d` (0 centre, 1 rim); 0 outside.
    pub fn weight(self, d: f32) -> f32 {
        if !(0.0..1.0).contains(&d) {
            return 0.0;
        }
        match self {
            Falloff::Smooth => 1.0 - d * d * (3.0 - 2.0 * d),
            Falloff::Linear => 1.0 - d,
            Falloff::Constant => 1.0,
        }
    }

    /// `smooth`, `linear` or `constant`.
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "smooth" => Some(Self::Smooth),
            "linear" => Some(Self::Linear),
            "constant" => Some(Self::Constant),
            _ => None,
        }
    }
}

/// One application of a brush: where, how big, how strong.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dab {
    /// The centre (a point on the skin, world space).
    pub center: Vec3,
    /// The radius (world units).
    pub radius: f32,
    /// How strongly (0 to 1 for most brushes; `length`: negative shrinks).
    pub strength: f32,
    /// The stroke's direction and length (world space): `comb` moves
    /// points by it.
    pub direction: Vec3,
    /// How the effect fades toward the rim.
    pub falloff: Falloff,
    /// Also apply the dab mirrored across the X = 0 plane.
    pub mirror_x: bool,
}

impl Dab {
    /// A dab at `center` of `radius`, strength 1, no direction, smooth
    /// falloff, no mirror.
    pub fn new(center: Vec3, radius: f32) -> Self {
        Self {
            center,
            radius,
            strength: 1.0,
            direction: Vec3::ZERO,
            falloff: Falloff::Smooth,
            mirror_x: false,
        }
    }

    /// The dab mirrored across X = 0.
    pub fn mirrored(&self) -> Self {
        let flip = Vec3::new(-1.0, 1.0, 1.0);
        Self {
            center: self.center * flip,
            direction: self.direction * flip,
            mirror_x: false,
            ..*self
        }
    }

    /// This dab and, with X-mirror, its mirror image.
    fn sides(&self) -> Vec<Dab> {
        let mut dabs = vec![Dab {
            mirror_x: false,
            ..*self
        }];
        if self.mirror_x {
            dabs.push(self.mirrored());
        }
        dabs
    }

    /// The weight at `p`: falloff times strength (0 outside).
    pub fn weight(&self, p: Vec3) -> f32 {
        if self.radius.is_nan() || self.radius <= 0.0 {
            return 0.0;
        }
        self.falloff.weight(p.distance(self.center) / self.radius) * self.strength
    }

    fn contains(&self, p: Vec3) -> bool {
        p.distance_squared(self.center) < self.radius * self.radius
    }
}

/// A brush; [`Brush::NAMES`] lists them as front ends spell them.
#[derive(Debug, Clone, PartialEq)]
pub enum Brush {
    /// Bends guides along the dab's direction, keeping segment lengths.
    Comb,
    /// Grows (strength > 0) or shrinks (< 0) guides, keeping their shape.
    Length,
    /// Cuts guides where they enter the brush sphere.
    Cut,
    /// Straightens guides' kinks, keeping segment lengths.
    Smooth,
    /// Lifts guides away from the skin, toward its normal at their root.
    Puff,
    /// Draws guides together, toward their mean shape.
    Clump,
    /// Pushes guides apart, away from their mean shape.
    Spread,
    /// Adds `count` guides under the dab, shaped as their neighbours
    /// interpolate.
    Add {
        /// Guides a dab adds.
        count: u32,
    },
    /// Deletes the guides rooted under the dab.
    Delete,
    /// Blends a paint layer toward `value` under the dab (a new layer
    /// starts at 0; `density` starts at 1 and becomes the groom's
    /// `density_scale`, which multiplies its density map).
    Paint {
        /// The layer's name.
        layer: String,
        /// The value painted.
        value: f32,
    },
    /// Writes region id `region` under the dab on the `region` layer (the
    /// groom's regions come from it; a parting follows the stroke).
    Part {
        /// The region id painted.
        region: u32,
    },
}

/// The layer the `part` brush paints and regions read.
pub const REGION_LAYER: &str = "region";

impl Brush {
    /// Every brush's name.
    pub const NAMES: &'static [&'static str] = &[
        "comb", "length", "cut", "smooth", "puff", "clump", "spread", "add", "delete", "paint",
        "part",
    ];

    /// The brush called `name` with default settings (`add`: 1 guide a
    /// dab; `paint`: layer `density`, value 1; `part`: region 1).
    pub fn by_name(name: &str) -> Option<Self> {
        Some(match name {
            "comb" => Brush::Comb,
            "length" => Brush::Length,
            "cut" => Brush::Cut,
            "smooth" => Brush::Smooth,
            "puff" => Brush::Puff,
            "clump" => Brush::Clump,
            "spread" => Brush::Spread,
            "add" => Brush::Add { count: 1 },
            "delete" => Brush::Delete,
            "paint" => Brush::Paint {
                layer: "density".into(),
                value: 1.0,
            },
            "part" => Brush::Part { region: 1 },
            _ => return None,
        })
    }

    /// Whether the brush shapes the guides it reaches
    /// ([`guides_reached`]): comb, length, cut, smooth, puff, clump and
    /// spread.
    pub fn shapes_guides(&self) -> bool {
        matches!(
            self,
            Brush::Comb
                | Brush::Length
                | Brush::Cut
                | Brush::Smooth
                | Brush::Puff
                | Brush::Clump
                | Brush::Spread
        )
    }

    /// The brush's name.
    pub fn name(&self) -> &'static str {
        match self {
            Brush::Comb => "comb",
            Brush::Length => "length",
            Brush::Cut => "cut",
            Brush::Smooth => "smooth",
            Brush::Puff => "puff",
            Brush::Clump => "clump",
            Brush::Spread => "spread",
            Brush::Add { .. } => "add",
            Brush::Delete => "delete",
            Brush::Paint { .. } => "paint",
            Brush::Part { .. } => "part",
        }
    }
}

/// A dab every brush can use: finite, with a positive radius and a
/// strength within ±[`MAX_BRUSH_STRENGTH`] (a strength of 1e30 made guides
/// no later dab could move).
fn check_dab(dab: &Dab) -> Result<(), BrushRefusal> {
    let refuse = |what: String| Err(BrushRefusal::Dab(what));
    if !dab.center.is_finite() || !dab.direction.is_finite() {
        return refuse(format!(
            "a dab at {} moving by {}: both must be finite",
            dab.center, dab.direction
        ));
    }
    if !(dab.radius.is_finite() && dab.radius > 0.0) {
        return refuse(format!("radius {}: use a positive distance", dab.radius));
    }
    if dab.strength.is_nan() || dab.strength.abs() > MAX_BRUSH_STRENGTH {
        return refuse(format!(
            "strength {}: use -{MAX_BRUSH_STRENGTH} to {MAX_BRUSH_STRENGTH}",
            dab.strength
        ));
    }
    Ok(())
}

/// The edit `brush` makes with `dab` on `groom` (`None`: the dab touches
/// nothing). Pure: the groom is not changed. Paint brushes need their
/// layer on the mesh; [`EditableGroom::brush`] adds it first.
///
/// # Errors
/// A paint layer the mesh does not have; deleting every guide.
pub fn dab_edit(
    groom: &EditableGroom,
    brush: &Brush,
    dab: &Dab,
) -> Result<Option<Edit>, BrushRefusal> {
    check_dab(dab)?;
    let dabs = dab.sides();
    match brush {
        Brush::Comb
        | Brush::Length
        | Brush::Cut
        | Brush::Smooth
        | Brush::Puff
        | Brush::Clump
        | Brush::Spread => Ok(shape_guides(groom, brush, &dabs)),
        Brush::Add { count } => {
            let (have, most) = (groom.guides().len(), crate::limits::MAX_GUIDES);
            let adding = u64::from(*count) * dabs.len() as u64;
            if have as u64 + adding > most {
                return Err(BrushRefusal::TooManyGuides { have, adding, most });
            }
            Ok(add_guides(groom, *count, &dabs))
        }
        Brush::Delete => delete_guides(groom, &dabs),
        Brush::Paint { layer, value } => paint(groom, layer, &dabs, |old, w| {
            old + w.clamp(0.0, 1.0) * (value - old)
        }),
        Brush::Part { region } => paint(groom, REGION_LAYER, &dabs, |old, w| {
            if w > 0.0 { *region as f32 } else { old }
        }),
    }
}

impl EditableGroom {
    /// Applies `brush` with `dab`: the edit [`dab_edit`] makes, after
    /// adding the layer a paint brush needs (as one undo step with it).
    /// `Ok(None)`: the dab touched nothing.
    ///
    /// # Errors
    /// What [`dab_edit`] and [`EditableGroom::apply`] refuse; a `part`
    /// brush on a groom whose regions are face sets.
    pub fn brush(&mut self, brush: &Brush, dab: &Dab) -> Result<Option<Regrowth>, GroomError> {
        let invalid = |spec: &GroomSpec, kind: GroomErrorKind| spec.error("brush", kind);
        let setup = match brush {
            Brush::Paint { layer, .. } => self
                .layer_setup(layer)
                .map_err(|m| invalid(self.spec(), m))?,
            Brush::Part { .. } => self.region_setup().map_err(|m| invalid(self.spec(), m))?,
            _ => None,
        };
        let edit_on = |groom: &EditableGroom| {
            dab_edit(groom, brush, dab).map_err(|m| invalid(groom.spec(), GroomErrorKind::Brush(m)))
        };
        match setup {
            None => match edit_on(self)? {
                Some(edit) => self.apply(edit).map(Some),
                None => Ok(None),
            },
            // The layer first, then the dab on it, as one step.
            Some(setup) => self
                .apply_then(Edit::NewLayer(LayerSetup(Box::new(setup))), edit_on)
                .map(Some),
        }
    }

    /// The groom with paint layer `layer` added, when the mesh lacks it.
    fn layer_setup(&self, layer: &str) -> Result<Option<GroomSpec>, GroomErrorKind> {
        if self.mesh().vertex_attribute(layer).is_some() {
            return Ok(None);
        }
        check_layer_name(layer).map_err(GroomErrorKind::Brush)?;
        let mut spec = self.spec().clone();
        let mesh = self.mesh();
        let values = if layer == "density" {
            // A scale on the density, starting as the scale the groom has
            // (1 unless its file sets one): the density map itself stays,
            // so the first dab moves only the roots under it. (Painting
            // the density map read at the vertices would move every root.)
            let scale = spec
                .roots
                .density_scale
                .on_mesh(mesh)
                .map_err(GroomErrorKind::Map)?;
            let values = vertex_points(mesh)
                .into_iter()
                .map(|p| p.map_or(1.0, |p| scale.eval(p)))
                .collect();
            spec.roots.density_scale = Map::Vertex(VertexMap::new(layer));
            values
        } else {
            vec![0.0; mesh.vertex_count()]
        };
        spec.mesh = Arc::new(
            Mesh::clone(mesh)
                .with_vertex_attribute(layer, values)
                .map_err(GroomErrorKind::Mesh)?,
        );
        Ok(Some(spec))
    }

    /// The groom with a `region` layer its regions read, when it has none.
    fn region_setup(&self) -> Result<Option<GroomSpec>, GroomErrorKind> {
        let reads_layer = |spec: &GroomSpec| match &spec.regions {
            Some(RegionsSpec {
                source:
                    RegionSource::Map {
                        map: Map::Vertex(v),
                        ..
                    },
            }) => Some(v.name == REGION_LAYER),
            Some(RegionsSpec {
                source: RegionSource::Faces(_),
            }) => None,
            Some(_) => Some(false),
            None => Some(false),
        };
        match reads_layer(self.spec()) {
            Some(true) if self.mesh().vertex_attribute(REGION_LAYER).is_some() => Ok(None),
            None => Err(GroomErrorKind::Brush(BrushRefusal::RegionsAreFaceSets)),
            _ => {
                let mut spec = self.spec().clone();
                if self.mesh().vertex_attribute(REGION_LAYER).is_none() {
                    spec.mesh = Arc::new(
                        Mesh::clone(self.mesh())
                            .with_vertex_attribute(
                                REGION_LAYER,
                                vec![0.0; self.mesh().vertex_count()],
                            )
                            .map_err(GroomErrorKind::Mesh)?,
                    );
                }
                spec.regions = Some(RegionsSpec::from_map(
                    Map::Vertex(VertexMap::new(REGION_LAYER)),
                    1.0,
                ));
                Ok(Some(spec))
            }
        }
    }
}

/// A paint layer's name, refused unless it can be written as a PLY
/// property and read back as a `vertex:NAME` map (a letter or `_`, then
/// letters, digits and `_`, at most 64, not a coordinate's name).
pub fn check_layer_name(name: &str) -> Result<(), BrushRefusal> {
    let ok = !name.is_empty()
        && name.len() <= 64
        && name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !matches!(
            name,
            "x" | "y" | "z" | "nx" | "ny" | "nz" | "s" | "t" | "u" | "v"
        );
    if ok {
        Ok(())
    } else {
        Err(BrushRefusal::LayerName(name.to_string()))
    }
}

/// A surface point at each vertex (on the first triangle using it).
fn vertex_points(mesh: &Mesh) -> Vec<Option<SurfacePoint>> {
    let mut out = vec![None; mesh.vertex_count()];
    for (t, tri) in mesh.triangles().iter().enumerate() {
        for (corner, &v) in tri.iter().enumerate() {
            let slot = &mut out[v as usize];
            if slot.is_none() {
                let bary = match corner {
                    0 => [0.0, 0.0],
                    1 => [1.0, 0.0],
                    _ => [0.0, 1.0],
                };
                *slot = Some(SurfacePoint::new(t as u32, bary));
            }
        }
    }
    out
}

/// The guides a dab of a brush that shapes guides (comb, length, cut,
/// smooth, puff, clump, spread) reaches: those with a point within it
/// or, mirrored, within its mirror. They are the ones it may move; a dab
/// that reaches none changes nothing.
pub fn guides_reached(groom: &EditableGroom, dab: &Dab) -> Vec<usize> {
    reached(groom, &dab.sides())
}

/// How far the nearest guide point is from `at`, or `None` without guides:
/// what a dab that [`guides_reached`] nothing missed by.
pub fn nearest_guide_distance(groom: &EditableGroom, at: Vec3) -> Option<f32> {
    groom
        .guides()
        .curves()
        .points()
        .iter()
        .map(|p| p.distance(at))
        .min_by(f32::total_cmp)
}

/// The guides with a point within any of `dabs`.
fn reached(groom: &EditableGroom, dabs: &[Dab]) -> Vec<usize> {
    let guides = groom.guides();
    (0..guides.len())
        .filter(|&g| {
            let guide = guides.guide(g);
            dabs.iter().any(|d| guide.iter().any(|p| d.contains(*p)))
        })
        .collect()
}

/// The guide brushes that move points: one `MoveGuides` with the guides
/// whose points changed.
fn shape_guides(groom: &EditableGroom, brush: &Brush, dabs: &[Dab]) -> Option<Edit> {
    let guides = groom.guides();
    let mesh = groom.mesh();
    let bvh = groom.bvh();
    let n = guides.points_per_guide();
    let mut changed = Vec::new();
    let mut points = Vec::new();
    let touched = reached(groom, dabs);
    if touched.is_empty() {
        return None;
    }
    let mut current: Vec<Vec<Vec3>> = touched.iter().map(|&g| guides.guide(g).to_vec()).collect();
    for dab in dabs {
        // Clump and spread pull toward the mean of the guides under the
        // dab, point by point, weighted by their roots' weights.
        let mean: Vec<Vec3> = match brush {
            Brush::Clump | Brush::Spread => {
                let mut sum = vec![Vec3::ZERO; n];
                let mut total = 0.0;
                for guide in &current {
                    let w = dab.weight(guide[0]).max(0.0);
                    total += w;
                    for (s, p) in sum.iter_mut().zip(guide) {
                        *s += w * *p;
                    }
                }
                if total <= 0.0 {
                    continue;
                }
                sum.into_iter().map(|s| s / total).collect()
            }
            _ => Vec::new(),
        };
        for (i, &g) in touched.iter().enumerate() {
            let guide = &mut current[i];
            let root = guides.roots()[g];
            let normal = root.normal(mesh);
            reshape(guide, brush, dab, normal, &mean);
            let lengths = segment_lengths(guide);
            keep_above(guide, mesh, bvh, &lengths);
        }
    }
    for (i, &g) in touched.iter().enumerate() {
        if current[i] != guides.guide(g) {
            changed.push(g as u32);
            points.extend_from_slice(&current[i]);
        }
    }
    (!changed.is_empty()).then_some(Edit::MoveGuides {
        guides: changed,
        points,
    })
}

/// One dab of a shaping brush on one guide.
fn reshape(guide: &mut [Vec3], brush: &Brush, dab: &Dab, normal: Vec3, mean: &[Vec3]) {
    let n = guide.len();
    let lengths = segment_lengths(guide);
    match brush {
        Brush::Comb => {
            for p in guide.iter_mut().skip(1) {
                *p += dab.weight(*p).max(0.0) * dab.direction;
            }
            follow_the_leader(guide, &lengths);
        }
        Brush::Smooth => {
            let before = guide.to_vec();
            for k in 1..n.saturating_sub(1) {
                let target = 0.5 * (before[k - 1] + before[k + 1]);
                let w = dab.weight(before[k]).clamp(0.0, 1.0);
                guide[k] = before[k] + w * (target - before[k]);
            }
            follow_the_leader(guide, &lengths);
        }
        Brush::Puff => {
            let mut directions: Vec<Vec3> = guide
                .windows(2)
                .map(|s| (s[1] - s[0]).normalize_or(normal))
                .collect();
            for (k, d) in directions.iter_mut().enumerate() {
                let w = dab.weight(guide[k + 1]).clamp(0.0, 1.0);
                *d = (*d + w * (normal - *d)).normalize_or(normal);
            }
            lay(guide, &directions, &lengths);
        }
        Brush::Clump | Brush::Spread => {
            let sign = if *brush == Brush::Clump { 1.0 } else { -1.0 };
            let w = dab.weight(guide[0]).clamp(0.0, 1.0);
            for k in 1..n {
                let t = k as f32 / (n - 1) as f32;
                guide[k] += sign * w * t * (mean[k] - guide[k]);
            }
            follow_the_leader(guide, &lengths);
        }
        Brush::Length => {
            // Weighted at the root: the whole guide scales.
            let factor = (1.0 + dab.weight(guide[0])).max(0.05);
            if factor != 1.0 {
                let directions: Vec<Vec3> = guide
                    .windows(2)
                    .map(|s| (s[1] - s[0]).normalize_or(normal))
                    .collect();
                let scaled: Vec<f32> = lengths.iter().map(|l| l * factor).collect();
                lay(guide, &directions, &scaled);
            }
        }
        Brush::Cut => cut(guide, dab),
        _ => {}
    }
}

/// Cuts a guide where it first enters the dab's sphere: it keeps its
/// shape up to there, resampled to its point count. A guide rooted
/// inside keeps a stub of a thousandth of the radius.
fn cut(guide: &mut [Vec3], dab: &Dab) {
    let n = guide.len();
    let Some(k) = guide.iter().position(|p| dab.contains(*p)) else {
        return;
    };
    let kept: Vec<Vec3> = if k == 0 {
        let direction = (guide[1] - guide[0]).normalize_or(Vec3::Y);
        vec![guide[0], guide[0] + direction * (dab.radius * 1e-3)]
    } else {
        // Where segment k−1 → k crosses the sphere: |a + t (b − a) − c| = r.
        let (a, b) = (guide[k - 1], guide[k]);
        let (d, f) = (b - a, a - dab.center);
        let (qa, qb, qc) = (d.dot(d), 2.0 * f.dot(d), f.dot(f) - dab.radius * dab.radius);
        let disc = (qb * qb - 4.0 * qa * qc).max(0.0);
        let t = if qa > 0.0 {
            ((-qb - disc.sqrt()) / (2.0 * qa)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let mut kept = guide[..k].to_vec();
        kept.push(a + t * d);
        if kept.len() >= 2 && kept[kept.len() - 1].distance(kept[kept.len() - 2]) <= 0.0 {
            kept.pop();
        }
        if kept.len() < 2 {
            let direction = d.normalize_or(Vec3::Y);
            kept = vec![guide[0], guide[0] + direction * (dab.radius * 1e-3)];
        }
        kept
    };
    let resampled = resample_by_arc_length(&kept, n);
    guide.copy_from_slice(&resampled);
}

fn segment_lengths(guide: &[Vec3]) -> Vec<f32> {
    guide.windows(2).map(|s| s[0].distance(s[1])).collect()
}

/// Lays each segment again from the root along its moved direction at its
/// old length (follow-the-leader).
fn follow_the_leader(guide: &mut [Vec3], lengths: &[f32]) {
    for k in 1..guide.len() {
        let direction = guide[k] - guide[k - 1];
        let fallback = if k >= 2 {
            (guide[k - 1] - guide[k - 2]).normalize_or(Vec3::Y)
        } else {
            Vec3::Y
        };
        guide[k] = guide[k - 1] + direction.normalize_or(fallback) * lengths[k - 1];
    }
}

/// Lays segments from the root along `directions` at `lengths`.
fn lay(guide: &mut [Vec3], directions: &[Vec3], lengths: &[f32]) {
    for k in 1..guide.len() {
        guide[k] = guide[k - 1] + directions[k - 1] * lengths[k - 1];
    }
}

/// How far below the skin a point may be, as a share of the segment it
/// ends: a float's rounding, not a visible dip.
const BELOW_TOLERANCE: f32 = 1e-4;

/// Height of `p` above the skin: along the skin normal at its closest
/// point (negative: below).
pub fn height_above_skin(mesh: &Mesh, bvh: &TriangleBvh, p: Vec3) -> f32 {
    match bvh.closest(p) {
        Some(hit) => {
            let at = SurfacePoint::new(hit.triangle, [hit.weights[1], hit.weights[2]]);
            (p - hit.point).dot(at.normal(mesh))
        }
        None => 0.0,
    }
}

/// Lifts every point laid below the skin to it, keeping segment lengths:
/// the segment is turned toward the lifted point and laid again, and
/// every point after it follows at its length (follow-the-leader), so the
/// segment after a lifted point keeps its length too. Points before the
/// first lift keep every bit.
fn keep_above(guide: &mut [Vec3], mesh: &Mesh, bvh: &TriangleBvh, lengths: &[f32]) {
    let mut moved = false;
    for k in 1..guide.len() {
        if moved {
            let direction = (guide[k] - guide[k - 1]).normalize_or(Vec3::Y);
            guide[k] = guide[k - 1] + direction * lengths[k - 1];
        }
        for _ in 0..4 {
            let p = guide[k];
            let Some(hit) = bvh.closest(p) else {
                break;
            };
            let at = SurfacePoint::new(hit.triangle, [hit.weights[1], hit.weights[2]]);
            let normal = at.normal(mesh);
            let height = (p - hit.point).dot(normal);
            let lift = BELOW_TOLERANCE * lengths[k - 1];
            if height >= 0.0 {
                break;
            }
            let target = p + normal * (lift - height);
            let direction = (target - guide[k - 1]).normalize_or(normal);
            guide[k] = guide[k - 1] + direction * lengths[k - 1];
            moved = true;
        }
    }
}

/// `count` guides rooted at random under each dab, each shaped as the
/// guides interpolate at its root.
fn add_guides(groom: &EditableGroom, count: u32, dabs: &[Dab]) -> Option<Edit> {
    let guides = groom.guides();
    let mesh = groom.mesh();
    let bvh = groom.bvh();
    let n = guides.points_per_guide();
    let interpolator = &groom.generator().interpolator;
    let mut scratch = HairScratch::default();
    let (mut roots, mut points, mut widths) = (Vec::new(), Vec::new(), Vec::new());
    for dab in dabs {
        // A stream of its own for each dab (its place and the guide count).
        let seed = mix64(
            u64::from(dab.center.x.to_bits())
                ^ mix64(
                    u64::from(dab.center.y.to_bits()) ^ mix64(u64::from(dab.center.z.to_bits())),
                )
                ^ mix64(guides.len() as u64 + roots.len() as u64),
        );
        let mut added = 0;
        for attempt in 0..u64::from(count) * 16 {
            if added == count {
                break;
            }
            let [a, b] = open_unit_pair(mix64(seed ^ mix64(attempt)));
            let c = open_unit_pair(mix64(seed ^ mix64(attempt + (1 << 40))))[0];
            // A point in the ball, taken to the skin.
            let (z, phi) = (2.0 * a - 1.0, std::f32::consts::TAU * b);
            let s = (1.0 - z * z).max(0.0).sqrt();
            let offset = Vec3::new(s * phi.cos(), s * phi.sin(), z) * c.cbrt() * dab.radius;
            let Some(hit) = bvh.closest(dab.center + offset) else {
                continue;
            };
            if !dab.contains(hit.point) {
                continue;
            }
            let root = SurfacePoint::new(hit.triangle, [hit.weights[1], hit.weights[2]]);
            let mut shape = vec![Vec3::ZERO; n];
            interpolator.hair(mesh, root, &mut scratch, &mut shape);
            // Blended guides space their points unevenly; a guide is bound
            // evenly spaced by arc length, so the added one is laid out so
            // now, and the saved file binds it again to the same shape.
            let mut shape = resample_by_arc_length(&shape, n);
            let lengths = segment_lengths(&shape);
            keep_above(&mut shape, mesh, bvh, &lengths);
            // Widths of the guide weighted most.
            let nearest = scratch
                .weights
                .iter()
                .max_by(|x, y| x.weight.total_cmp(&y.weight))
                .map_or(0, |w| w.guide as usize);
            widths.extend_from_slice(guides.widths(nearest));
            points.extend(shape);
            roots.push(root);
            added += 1;
        }
    }
    if roots.is_empty() {
        return None;
    }
    let added = guides.appended(points, widths, roots).ok()?;
    Some(Edit::ReplaceGuides(Arc::new(added)))
}

/// Deletes the guides rooted under the dabs (never the last one).
fn delete_guides(groom: &EditableGroom, dabs: &[Dab]) -> Result<Option<Edit>, BrushRefusal> {
    let guides = groom.guides();
    let keep: Vec<u32> = (0..guides.len() as u32)
        .filter(|&g| {
            let root = guides.guide(g as usize)[0];
            !dabs.iter().any(|d| d.contains(root))
        })
        .collect();
    if keep.len() == guides.len() {
        return Ok(None);
    }
    if keep.is_empty() {
        return Err(BrushRefusal::DeletesEveryGuide);
    }
    Ok(Some(Edit::ReplaceGuides(Arc::new(guides.subset(&keep)))))
}

/// Paints `layer` at the vertices under the dabs with `blend(old, weight)`.
fn paint(
    groom: &EditableGroom,
    layer: &str,
    dabs: &[Dab],
    blend: impl Fn(f32, f32) -> f32,
) -> Result<Option<Edit>, BrushRefusal> {
    let mesh = groom.mesh();
    let Some(values) = groom.layer(layer) else {
        return Err(BrushRefusal::NoPaintLayer(layer.to_string()));
    };
    let mut painted: Vec<(u32, f32)> = Vec::new();
    let mut current = values.to_vec();
    for dab in dabs {
        for (v, p) in mesh.positions().iter().enumerate() {
            if dab.contains(*p) {
                let new = blend(current[v], dab.weight(*p));
                if new.to_bits() != current[v].to_bits() {
                    current[v] = new;
                    painted.push((v as u32, new));
                }
            }
        }
    }
    if painted.is_empty() {
        return Ok(None);
    }
    // The last value a vertex got (both sides of a mirror may paint it).
    painted.sort_by_key(|(v, _)| *v);
    painted.dedup_by_key(|(v, _)| *v);
    let vertices = painted.iter().map(|(v, _)| *v).collect::<Vec<_>>();
    let values = vertices.iter().map(|&v| current[v as usize]).collect();
    Ok(Some(Edit::Paint {
        layer: layer.to_string(),
        vertices,
        values,
    }))
}

impl Guides {
    /// These guides with more: `points` and `widths` hold
    /// `points_per_guide` values for each of `roots`, in order.
    pub fn appended(
        &self,
        points: Vec<Vec3>,
        widths: Vec<f32>,
        roots: Vec<SurfacePoint>,
    ) -> Result<Self, crate::curves::CurvesError> {
        let n = self.points_per_guide();
        let mut all_points = self.curves().points().to_vec();
        all_points.extend(points);
        let mut all_widths = self.curves().widths().to_vec();
        all_widths.extend(widths);
        let mut all_roots = self.roots().to_vec();
        all_roots.extend(roots);
        Guides::from_resampled(all_points, all_widths, all_roots, n)
    }
}
