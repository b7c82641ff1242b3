//! `clump`: hairs pulled toward clump centre hairs, as XGen's and Houdini's
//! clump operators do. Centres are roots sampled with their own density;
//! each centre hair is grown through every operator before this one, so a
//! second `clump` clumps the first level's clumps (multi-level clumping by
//! stacking). Each hair follows the centre whose root is nearest its own
//! among the centres that respect the surface: in the hair's region, and
//! on the hair's side of thin parts (a centre whose skin normal faces
//! away from the hair's, as on the other side of an ear, is passed over
//! for the next nearest).

use super::kind::{OperatorKind, Preparation, SpecReader, default_map};
use super::{Hair, RampTables, RootContext, Scratch};
use crate::groom::error::{GroomError, GroomErrorKind};
use crate::groom::file::MapValue;
use crate::groom::ramp::Ramp;
use crate::interp::{NearestPoints, NeighbourCache, QueryRegion};
use crate::limits::MAX_CLUMPS;
use crate::map::Map;
use crate::mesh::SurfacePoint;
use crate::sample::{DensitySampler, DensitySamplerOptions, sample_range};
use crate::settings::{Bound, Rule};
use glam::Vec3;
use serde::Deserialize;
use std::sync::Arc;
use toml::Spanned;

/// `clump` as a groom file writes it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ClumpSpec {
    /// Number of clumps over the whole mesh.
    pub count: Spanned<u64>,
    /// Density of clump centres.
    #[serde(default = "uniform")]
    pub density: MapValue,
    /// How far hairs move to their centre hair (0 to 1).
    #[serde(default = "default_rate")]
    pub rate: MapValue,
    /// Root-to-tip profile of the rate.
    #[serde(default)]
    pub ramp: Ramp,
    /// Clump radius: hairs this far from their centre's root are not
    /// pulled, nearer ones in proportion (default: no limit).
    pub size: Option<MapValue>,
    /// Seed of the clump centres.
    #[serde(default)]
    pub seed: u64,
    /// Where the operator acts: its effect is faded by this map (0: none,
    /// 1: full).
    pub mask: Option<MapValue>,
}

fn uniform() -> MapValue {
    default_map(1.0)
}

fn default_rate() -> MapValue {
    default_map(0.8)
}

/// `clump`: see [`Clump`].
#[derive(Debug, Clone)]
pub struct ClumpParams {
    /// Number of clumps over the whole mesh.
    pub count: u64,
    /// Density of clump centres.
    pub density: Map,
    /// How far hairs move to their centre hair (0 to 1).
    pub rate: Map,
    /// Root-to-tip profile of the rate.
    pub ramp: Ramp,
    /// Clump radius (`None`: no limit).
    pub size: Option<Map>,
    /// Seed of the clump centres.
    pub seed: u64,
}

impl ClumpParams {
    /// `count` clumps, uniform centres, rate 0.8, linear ramp, no size
    /// limit, seed 0.
    pub fn new(count: u64) -> Self {
        Self {
            count,
            density: Map::Constant(1.0),
            rate: Map::Constant(0.8),
            ramp: Ramp::default(),
            size: None,
            seed: 0,
        }
    }
}

/// The centre hairs of one clump level: roots in a kd-tree a region,
/// shapes with the hairs' point count, and each root's skin normal.
#[derive(Debug, Clone)]
pub struct ClumpCentres {
    /// Shared with the centres of a reshaped groom (same roots).
    roots: Arc<Vec<Vec3>>,
    /// Indexed by region: a kd-tree over the region's centres and their
    /// indices among all (`None`: no centre there).
    by_region: Arc<Vec<Option<RegionCentres>>>,
    /// Each centre's skin normal (empty: no side test).
    normals: Arc<Vec<Vec3>>,
    shapes: Vec<Vec3>,
    points: usize,
    /// The centres' roots on the skin, when grown by a groom.
    surface_roots: Arc<Vec<SurfacePoint>>,
    /// The guides each centre's shape depends on (its own weights' and
    /// those of the centres it follows at earlier levels), when known:
    /// a reshaped groom regrows only the centres of moved guides.
    guides: Option<Arc<CentreGuides>>,
}

/// One region's centres: a kd-tree over their roots and their indices
/// among all centres.
type RegionCentres = (NearestPoints, Vec<u32>);

/// The guides each centre depends on, in compressed rows.
#[derive(Debug, Default)]
pub struct CentreGuides {
    starts: Vec<u32>,
    guides: Vec<u32>,
}

impl CentreGuides {
    /// From each centre's guides (sorted, distinct).
    pub fn new(per_centre: Vec<Vec<u32>>) -> Self {
        let mut starts = Vec::with_capacity(per_centre.len() + 1);
        starts.push(0);
        let mut guides = Vec::new();
        for g in per_centre {
            guides.extend(g);
            starts.push(guides.len() as u32);
        }
        Self { starts, guides }
    }

    /// The guides centre `i` depends on.
    pub fn of(&self, i: usize) -> &[u32] {
        &self.guides[self.starts[i] as usize..self.starts[i + 1] as usize]
    }
}

/// Centres looked at first past the nearest when it lies on the other
/// side of a thin part; four times as many each time none of them is on
/// the hair's side, up to the whole region (a hair left with none there is
/// not clumped).
const SIDE_CANDIDATES: usize = 8;

impl ClumpCentres {
    /// Centres rooted at `roots`, centre `i` shaped
    /// `shapes[i * points..(i + 1) * points]`; one region, no side test.
    pub fn new(roots: Vec<Vec3>, shapes: Vec<Vec3>, points: usize) -> Self {
        let regions = vec![0; roots.len()];
        Self::on_surface(roots, Vec::new(), &regions, shapes, points)
    }

    /// Centres that respect the surface: centre `i` is in region
    /// `regions[i]` with skin normal `normals[i]` (empty: no side test).
    pub fn on_surface(
        roots: Vec<Vec3>,
        normals: Vec<Vec3>,
        regions: &[u32],
        shapes: Vec<Vec3>,
        points: usize,
    ) -> Self {
        assert_eq!(roots.len() * points, shapes.len());
        assert_eq!(roots.len(), regions.len());
        assert!(normals.is_empty() || normals.len() == roots.len());
        let by_region = crate::interp::indices_by_region(regions)
            .into_iter()
            .map(|indices| {
                (!indices.is_empty()).then(|| {
                    let points = indices.iter().map(|&i| roots[i as usize]).collect();
                    (NearestPoints::new(points), indices)
                })
            })
            .collect();
        Self {
            roots: Arc::new(roots),
            by_region: Arc::new(by_region),
            normals: Arc::new(normals),
            shapes,
            points,
            surface_roots: Arc::default(),
            guides: None,
        }
    }

    /// Records the centres' roots on the skin.
    pub(crate) fn with_surface_roots(mut self, roots: Vec<SurfacePoint>) -> Self {
        self.surface_roots = Arc::new(roots);
        self
    }

    /// The centres' roots on the skin (empty unless a groom grew them).
    pub(crate) fn surface_roots(&self) -> &[SurfacePoint] {
        &self.surface_roots
    }

    /// These centres (roots, search trees) in other shapes.
    pub(crate) fn with_shapes(&self, shapes: Vec<Vec3>) -> Self {
        assert_eq!(shapes.len(), self.shapes.len());
        Self {
            shapes,
            ..self.clone()
        }
    }

    /// Records the guides each centre depends on.
    pub(crate) fn with_guides(mut self, guides: CentreGuides) -> Self {
        self.guides = Some(Arc::new(guides));
        self
    }

    /// The guides each centre depends on, shared, when recorded.
    pub(crate) fn guides_shared(&self) -> Option<Arc<CentreGuides>> {
        self.guides.clone()
    }

    /// Records the guides each centre depends on, shared.
    pub(crate) fn with_shared_guides(mut self, guides: Arc<CentreGuides>) -> Self {
        self.guides = Some(guides);
        self
    }

    /// The guides each centre depends on, when recorded.
    pub(crate) fn guides(&self) -> Option<&CentreGuides> {
        self.guides.as_deref()
    }

    /// Number of centres.
    pub fn len(&self) -> usize {
        self.roots.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.roots.is_empty()
    }

    /// The centre nearest `position` in region 0 and its distance (ties:
    /// the lower index), without a side test.
    pub fn nearest(&self, position: Vec3) -> Option<(usize, f32)> {
        self.nearest_near(position, None, 0, &mut NeighbourCache::default(), None)
    }

    /// The centre a hair at `position` (skin normal `normal`, in
    /// `region`) follows, and its distance: the nearest of its region on
    /// its side of the surface. `near` is kept between a run of nearby
    /// positions, `ball` a ball around `position` that likely holds the
    /// next ones too (faster, same result).
    pub fn nearest_near(
        &self,
        position: Vec3,
        normal: Option<Vec3>,
        region: u32,
        near: &mut NeighbourCache,
        ball: Option<QueryRegion>,
    ) -> Option<(usize, f32)> {
        let (tree, indices) = self.by_region.get(region as usize)?.as_ref()?;
        let found = |n: crate::interp::Neighbour| {
            (
                indices[n.index as usize] as usize,
                n.distance_squared.sqrt(),
            )
        };
        let first = tree
            .nearest_cached_in(position, 1, near, ball)
            .next()
            .map(found)?;
        let (Some(normal), false) = (normal, self.normals.is_empty()) else {
            return Some(first);
        };
        let same_side = |c: usize| self.normals[c].dot(normal) > 0.0;
        if same_side(first.0) {
            return Some(first);
        }
        let mut k = SIDE_CANDIDATES;
        loop {
            let hit = tree
                .nearest_cached_in(position, k, near, ball)
                .map(found)
                .find(|&(c, _)| same_side(c));
            if hit.is_some() || k >= indices.len() {
                return hit;
            }
            k *= 4;
        }
    }

    /// Centre `i`'s points.
    pub fn shape(&self, i: usize) -> &[Vec3] {
        &self.shapes[i * self.points..(i + 1) * self.points]
    }

    /// Every centre's points, centre after centre.
    pub(crate) fn shape_array(&self) -> &[Vec3] {
        &self.shapes
    }

    /// Every centre's root.
    pub fn roots(&self) -> &[Vec3] {
        &self.roots
    }
}

/// `clump`: `p += w · ramp(t) · (c(t) − p)`, `c` the nearest centre hair,
/// `w = rate`, times `max(0, 1 − d / size)` when a size is given (`d` the
/// root-to-root distance), so clumps have soft edges. With rate 1 and the
/// default linear ramp, roots stay and tips meet at the centre's tip.
#[derive(Debug)]
pub struct Clump {
    centres: ClumpCentres,
    rate: Map,
    ramp: Ramp,
    size: Option<Map>,
}

impl Clump {
    /// A clump operator over grown centres.
    pub fn new(centres: ClumpCentres, rate: Map, ramp: Ramp, size: Option<Map>) -> Self {
        Self {
            centres,
            rate,
            ramp,
            size,
        }
    }

    /// The centre hairs.
    pub fn centres(&self) -> &ClumpCentres {
        &self.centres
    }

    /// Pulls one hair toward its centre.
    pub(super) fn pull(
        &self,
        hair: &mut Hair,
        root: &RootContext,
        near: &mut NeighbourCache,
        ramps: &mut RampTables,
    ) {
        let Some((centre, distance)) = self.centres.nearest_near(
            root.position,
            Some(root.normal),
            root.region,
            near,
            root.skin_triangle,
        ) else {
            return;
        };
        let mut w = self.rate.at(&root.site);
        if let Some(size) = &self.size {
            let size = size.at(&root.site);
            w *= if size > 0.0 {
                (1.0 - distance / size).max(0.0)
            } else {
                0.0
            };
        }
        let shape = self.centres.shape(centre);
        if w == 0.0 || shape.len() != hair.points.len() {
            return;
        }
        let ramp = ramps.along(&self.ramp, hair.points.len());
        for ((p, c), r) in hair.points.iter_mut().zip(shape).zip(ramp) {
            *p += w * r * (*c - *p);
        }
    }
}

impl OperatorKind for Clump {
    const NAME: &'static str = "clump";
    const SUMMARY: &'static str = "Pulls hairs toward `count` clump centre hairs (`rate` 0 to 1).";
    type Spec = ClumpSpec;
    type Params = ClumpParams;
    const RULES: &'static [Rule] = &[
        Rule::new(
            "count",
            Bound::Within(1.0, MAX_CLUMPS as f64),
            "pelage's clump limit",
        ),
        Rule::new("density", Bound::at_least(0.0), "a density"),
    ];
    const SEARCHES_NEIGHBOURS: bool = true;

    fn mask(spec: &ClumpSpec) -> Option<&MapValue> {
        spec.mask.as_ref()
    }

    fn read(s: &ClumpSpec, r: &mut SpecReader<'_>) -> Result<ClumpParams, GroomError> {
        Ok(ClumpParams {
            count: r.value("count", &s.count),
            density: r.map("density", &s.density)?,
            rate: r.map("rate", &s.rate)?,
            ramp: s.ramp.clone(),
            size: s.size.as_ref().map(|m| r.map("size", m)).transpose()?,
            seed: s.seed,
        })
    }

    fn maps(p: &ClumpParams) -> Vec<(&'static str, &Map)> {
        let mut maps = vec![("density", &p.density), ("rate", &p.rate)];
        maps.extend(p.size.as_ref().map(|m| ("size", m)));
        maps
    }

    fn maps_mut(p: &mut ClumpParams) -> Vec<(&'static str, &mut Map)> {
        let mut maps = vec![("density", &mut p.density), ("rate", &mut p.rate)];
        maps.extend(p.size.as_mut().map(|m| ("size", m)));
        maps
    }

    fn counts(p: &ClumpParams) -> Vec<(&'static str, u64, u64, &'static str)> {
        vec![("count", p.count, MAX_CLUMPS, "clumps")]
    }

    fn prepare(p: ClumpParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        if p.count == 0 {
            return Err(cx.error(
                "count",
                GroomErrorKind::Invalid("a clump operator needs at least 1 clump".into()),
            ));
        }
        // Reshaping a groom whose guides alone moved: the same centres.
        let roots = match cx.unchanged_centre_roots() {
            Some(roots) => roots,
            None => {
                let sampler =
                    DensitySampler::new(cx.mesh(), &p.density, DensitySamplerOptions::default())
                        .map_err(|e| cx.error("density", GroomErrorKind::Sample(e)))?;
                sample_range(&sampler, cx.seed(p.seed), 0..p.count)
            }
        };
        Ok(Clump::new(cx.centres(&roots), p.rate, p.ramp, p.size))
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        self.pull(hair, root, &mut scratch.near, &mut scratch.ramps);
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{root, straight};
    use super::*;

    fn centre_at(x: f32) -> ClumpCentres {
        let shape: Vec<Vec3> = straight(0, 8, 1.0)
            .points
            .iter()
            .map(|p| *p + Vec3::X * x)
            .collect();
        ClumpCentres::new(vec![Vec3::X * x], shape, 8)
    }

    #[test]
    fn full_rate_brings_the_tip_to_the_centre_and_keeps_the_root() {
        let op = Clump::new(centre_at(0.1), Map::Constant(1.0), Ramp::default(), None);
        let mut hair = straight(1, 8, 1.0);
        op.pull(
            &mut hair,
            &root(),
            &mut NeighbourCache::default(),
            &mut RampTables::default(),
        );
        assert_eq!(hair.points[0], Vec3::ZERO);
        assert!((hair.points[7] - Vec3::new(0.1, 0.0, 1.0)).length() < 1e-6);
        assert!(
            (hair.points[3].x - 0.1 * 3.0 / 7.0).abs() < 1e-6,
            "linear profile"
        );
    }

    #[test]
    fn centres_across_a_region_border_or_a_thin_part_are_passed_over() {
        // Three centres: 0 close but in region 1, 1 close but facing
        // away (the other side of a thin fin), 2 farther, on the hair's side.
        let mut shapes = centre_at(0.01).shapes;
        shapes.extend(centre_at(0.02).shapes);
        shapes.extend(centre_at(0.3).shapes);
        let roots = vec![Vec3::X * 0.01, Vec3::X * 0.02, Vec3::X * 0.3];
        let normals = vec![Vec3::Z, -Vec3::Z, Vec3::Z];
        let c = ClumpCentres::on_surface(roots, normals, &[1, 0, 0], shapes, 8);
        let mut near = NeighbourCache::default();
        let hit = |region| {
            c.nearest_near(
                Vec3::ZERO,
                Some(Vec3::Z),
                region,
                &mut NeighbourCache::default(),
                None,
            )
        };
        assert_eq!(hit(0).map(|h| h.0), Some(2));
        assert_eq!(hit(1).map(|h| h.0), Some(0));
        assert_eq!(hit(5), None, "a region without centres");
        // Without a normal: the nearest of the region.
        assert_eq!(
            c.nearest_near(Vec3::ZERO, None, 0, &mut near, None)
                .map(|h| h.0),
            Some(1)
        );
    }

    #[test]
    fn size_limits_the_pull_and_the_nearest_centre_wins() {
        let op = Clump::new(
            centre_at(0.1),
            Map::Constant(1.0),
            Ramp::default(),
            Some(Map::Constant(0.05)),
        );
        let mut hair = straight(1, 8, 1.0);
        op.pull(
            &mut hair,
            &root(),
            &mut NeighbourCache::default(),
            &mut RampTables::default(),
        );
        assert_eq!(hair, straight(1, 8, 1.0), "beyond the clump's size");
        let mut shapes = centre_at(0.1).shapes;
        shapes.extend(centre_at(-0.3).shapes);
        let two = ClumpCentres::new(vec![Vec3::X * 0.1, Vec3::X * -0.3], shapes, 8);
        assert_eq!(two.nearest(Vec3::ZERO).map(|h| h.0), Some(0));
        assert_eq!(two.nearest(Vec3::X * -0.25).map(|h| h.0), Some(1));
    }
}
