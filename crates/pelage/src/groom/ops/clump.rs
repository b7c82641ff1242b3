//! `clump`: hairs pulled toward clump centre hairs, as XGen's and Houdini's
//! clump operators do. Centres are roots sampled with their own density;
//! each centre hair is grown through every operator before this one, so a
//! second `clump` clumps the first level's clumps (multi-level clumping by
//! stacking). Each hair follows the centre whose root is nearest its own.

use super::{Hair, RampTables, RootContext};
use crate::groom::file::Ramp;
use crate::interp::{NearestPoints, NeighbourCache, QueryRegion};
use crate::map::Map;
use glam::Vec3;

/// The centre hairs of one clump level: roots in a kd-tree, shapes with
/// the hairs' point count.
#[derive(Debug)]
pub struct ClumpCentres {
    roots: NearestPoints,
    shapes: Vec<Vec3>,
    points: usize,
}

impl ClumpCentres {
    /// Centres rooted at `roots`, centre `i` shaped
    /// `shapes[i * points..(i + 1) * points]`.
    pub fn new(roots: Vec<Vec3>, shapes: Vec<Vec3>, points: usize) -> Self {
        assert_eq!(roots.len() * points, shapes.len());
        Self {
            roots: NearestPoints::new(roots),
            shapes,
            points,
        }
    }

    /// Number of centres.
    pub fn len(&self) -> usize {
        self.roots.points().len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.roots.points().is_empty()
    }

    /// The centre nearest `position` and its distance (ties: the lower
    /// index).
    pub fn nearest(&self, position: Vec3) -> Option<(usize, f32)> {
        self.nearest_near(position, &mut NeighbourCache::default(), None)
    }

    /// [`Self::nearest`] for one of a run of nearby positions, `near`
    /// kept between them, `region` a ball around `position` that likely
    /// holds the next ones too (faster, same result).
    pub fn nearest_near(
        &self,
        position: Vec3,
        near: &mut NeighbourCache,
        region: Option<QueryRegion>,
    ) -> Option<(usize, f32)> {
        self.roots
            .nearest_cached_in(position, 1, near, region)
            .next()
            .map(|n| (n.index as usize, n.distance_squared.sqrt()))
    }

    /// Centre `i`'s points.
    pub fn shape(&self, i: usize) -> &[Vec3] {
        &self.shapes[i * self.points..(i + 1) * self.points]
    }

    /// Every centre's root.
    pub fn roots(&self) -> &[Vec3] {
        self.roots.points()
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

    pub(super) fn apply(
        &self,
        hair: &mut Hair,
        root: &RootContext,
        near: &mut NeighbourCache,
        ramps: &mut RampTables,
    ) {
        let Some((centre, distance)) =
            self.centres
                .nearest_near(root.position, near, root.skin_triangle)
        else {
            return;
        };
        let mut w = self.rate.eval(root.uv);
        if let Some(size) = &self.size {
            let size = size.eval(root.uv);
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
        op.apply(
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
    fn size_limits_the_pull_and_the_nearest_centre_wins() {
        let op = Clump::new(
            centre_at(0.1),
            Map::Constant(1.0),
            Ramp::default(),
            Some(Map::Constant(0.05)),
        );
        let mut hair = straight(1, 8, 1.0);
        op.apply(
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
