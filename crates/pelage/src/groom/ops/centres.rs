//! The centre hairs of one clump level ([`ClumpCentres`]): their roots in
//! a kd-tree a region, their grown shapes, skin normals and the guides
//! each depends on. Growing them is the generator's (through the operators
//! before the clump); the `clump` operator and an operator chain being
//! prepared both read them, so they sit below both.

use crate::interp::{NearestPoints, NeighbourCache, QueryRegion};
use crate::mesh::SurfacePoint;
use glam::Vec3;
use std::sync::Arc;

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
    pub fn surface_roots(&self) -> &[SurfacePoint] {
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
