//! `clump`: hairs pulled toward clump centre hairs, as XGen's and Houdini's
//! clump operators do. Centres are roots sampled with their own density;
//! each centre hair is grown through every operator before this one, so a
//! second `clump` clumps the first level's clumps (multi-level clumping by
//! stacking). Each hair follows the centre whose root is nearest its own
//! among the centres that respect the surface: in the hair's region, and
//! on the hair's side of thin parts (a centre whose skin normal faces
//! away from the hair's, as on the other side of an ear, is passed over
//! for the next nearest).

use super::centres::ClumpCentres;
use super::kind::{OperatorKind, Preparation};
use super::settings::{Start, operator_settings};
use super::{Hair, RampTables, RootContext, Scratch};
use crate::groom::error::{GroomError, GroomErrorKind};
use crate::groom::ramp::Ramp;
use crate::interp::NeighbourCache;
use crate::limits::MAX_CLUMPS;
use crate::map::Map;
use crate::sample::{DensitySampler, DensitySamplerOptions, sample_range};
use crate::settings::Bound;

operator_settings! {
    /// `clump` as a groom file writes it.
    pub(crate) spec ClumpSpec;
    /// `clump`: see [`Clump`].
    params ClumpParams {
        required {
            /// Number of clumps over the whole mesh.
            count: count(u64), start Start::Number(200.0),
                rule Bound::Within(1.0, MAX_CLUMPS as f64), "pelage's clump limit";
        }
        optional {
            /// Density of clump centres.
            density: map = 1.0, rule Bound::at_least(0.0), "a density";
            /// How far hairs move to their centre hair (0 to 1).
            rate: map = 0.8, start Start::Number(0.5);
            /// Root-to-tip profile of the rate.
            ramp: value(Ramp) = Ramp::default();
            /// Clump radius: hairs this far from their centre's root are
            /// not pulled, nearer ones in proportion (`None`: no limit).
            size: maybe_map = None;
            /// Seed of the clump centres.
            seed: value(u64) = 0;
        }
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

    /// The share of the way a hair's tip is pulled to its centre (a map
    /// over the skin).
    pub fn rate(&self) -> &Map {
        &self.rate
    }

    /// The centre a hair rooted at `root` follows, and how strongly (the
    /// rate, faded by the distance when the clump has a size).
    pub(crate) fn target(
        &self,
        root: &RootContext,
        near: &mut NeighbourCache,
    ) -> Option<(usize, f32)> {
        let (centre, distance) = self.centres.nearest_near(
            root.position,
            Some(root.normal),
            root.region,
            near,
            root.skin_triangle,
        )?;
        let mut w = self.rate.at(&root.site);
        if let Some(size) = &self.size {
            let size = size.at(&root.site);
            w *= if size > 0.0 {
                (1.0 - distance / size).max(0.0)
            } else {
                0.0
            };
        }
        Some((centre, w))
    }

    /// The pull's profile root to tip.
    pub(crate) fn ramp(&self) -> &Ramp {
        &self.ramp
    }

    pub(super) fn pull(
        &self,
        hair: &mut Hair,
        root: &RootContext,
        near: &mut NeighbourCache,
        ramps: &mut RampTables,
    ) {
        let Some((centre, w)) = self.target(root, near) else {
            return;
        };
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
    type Params = ClumpParams;
    const SEARCHES_NEIGHBOURS: bool = true;

    fn counts(p: &ClumpParams) -> Vec<(&'static str, u64, u64, &'static str)> {
        vec![("count", p.count, MAX_CLUMPS, "clumps")]
    }

    fn prepare(p: ClumpParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        if p.count == 0 {
            return Err(cx.error(
                "count",
                GroomErrorKind::OutOfRange("a clump operator needs at least 1 clump".into()),
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
    use glam::Vec3;

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
        let mut shapes = centre_at(0.01).shape_array().to_vec();
        shapes.extend(centre_at(0.02).shape_array().to_vec());
        shapes.extend(centre_at(0.3).shape_array().to_vec());
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
        let mut shapes = centre_at(0.1).shape_array().to_vec();
        shapes.extend(centre_at(-0.3).shape_array().to_vec());
        let two = ClumpCentres::new(vec![Vec3::X * 0.1, Vec3::X * -0.3], shapes, 8);
        assert_eq!(two.nearest(Vec3::ZERO).map(|h| h.0), Some(0));
        assert_eq!(two.nearest(Vec3::X * -0.25).map(|h| h.0), Some(1));
    }
}
