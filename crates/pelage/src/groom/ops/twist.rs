//! `twist`: each hair turned about its own root–tip axis, more toward the
//! tip, as groomers twist locks (Houdini's guide twist, Ornatrix's
//! rotate): point `j` turns by `angle · ramp(t_j) · (1 ± jitter)` about
//! the line from the root through the tip. The root and the tip stay
//! where they are; the hair's bends wind around its chord.

use super::kind::{OperatorKind, Preparation};
use super::root_to_tip::varied;
use super::settings::{Start, operator_settings};
use super::{Hair, RootContext, Scratch};
use crate::groom::error::GroomError;
use crate::groom::ramp::Ramp;
use glam::{Quat, Vec3};

/// The per-hair jitter of the angle.
const JITTER_SALT: u64 = 0x7_3157;

operator_settings! {
    /// `twist` as a groom file writes it.
    pub(crate) spec TwistSpec;
    /// `twist`: see [`Twist`].
    params TwistParams {
        required {
            /// Angle at the tip, in degrees (positive: counter-clockwise
            /// looking from the tip down to the root).
            angle: map, start Start::Number(90.0);
        }
        optional {
            /// Root-to-tip profile of the angle.
            ramp: value(Ramp) = Ramp::default();
            /// Per-hair random variation of the angle, a fraction (0.2 =
            /// ±20 %).
            jitter: map = 0.0;
            /// Seed of the variation.
            seed: value(u64) = 0;
        }
    }
}

/// `twist`, prepared: see the module docs.
#[derive(Debug, Clone)]
pub struct Twist(TwistParams);

impl Twist {
    /// Hair `id`'s turn at the tip, in radians (0: none).
    pub(crate) fn angle(&self, id: u64, root: &RootContext) -> f32 {
        let p = &self.0;
        let degrees = p.angle.at(&root.site);
        if degrees == 0.0 {
            return 0.0;
        }
        degrees.to_radians() * varied(p.jitter.at(&root.site), p.seed ^ JITTER_SALT, id)
    }

    /// The turn's profile root to tip.
    pub(crate) fn ramp(&self) -> &Ramp {
        &self.0.ramp
    }
}

impl OperatorKind for Twist {
    const NAME: &'static str = "twist";
    const SUMMARY: &'static str =
        "Turns each hair about its root–tip axis, `angle` degrees at the tip.";
    type Params = TwistParams;
    const SALTS: &'static [(&'static str, u64)] = &[("JITTER", JITTER_SALT)];

    fn prepare(mut p: TwistParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        p.seed = cx.seed(p.seed);
        Ok(Twist(p))
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        let p = &self.0;
        let (Some(&origin), Some(&tip)) = (hair.points.first(), hair.points.last()) else {
            return;
        };
        let axis = (tip - origin).normalize_or_zero();
        let angle = self.angle(hair.id, root);
        if angle == 0.0 || axis == Vec3::ZERO {
            return;
        }
        let n = hair.points.len();
        let ramp = scratch.ramps.along(&p.ramp, n);
        for (point, profile) in hair.points.iter_mut().zip(ramp).skip(1) {
            let turn = Quat::from_axis_angle(axis, angle * profile);
            *point = origin + turn * (*point - origin);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::root;
    use super::super::{Hair, param};
    use super::*;
    use crate::map::Map;

    /// A hair bowed sideways (+X) between a root at the origin and a tip
    /// on +Z: every point but the ends lies off the axis.
    fn bowed(id: u64, n: usize) -> Hair {
        Hair {
            id,
            points: (0..n)
                .map(|j| {
                    let t = param(j, n);
                    Vec3::new(0.2 * (std::f32::consts::PI * t).sin(), 0.0, t)
                })
                .collect(),
            widths: vec![0.01; n],
            ..Hair::default()
        }
    }

    /// The angle point `p` turned by about the Z axis, from +X.
    fn turned(p: Vec3) -> f32 {
        p.y.atan2(p.x)
    }

    #[test]
    fn each_point_turns_by_the_ramps_angle_about_the_root_tip_axis() {
        let n = 11;
        for ramp in [Ramp::default(), Ramp::Smooth, Ramp::Power(0.0)] {
            let op = Twist(TwistParams {
                ramp: ramp.clone(),
                ..TwistParams::new(Map::Constant(90.0))
            });
            let mut hair = bowed(1, n);
            let before = hair.clone();
            op.apply_to_hair(&mut hair, &root(), &mut Scratch::default());
            assert_eq!(hair.points[0], before.points[0], "the root stays");
            assert!((hair.points[n - 1] - before.points[n - 1]).length() < 1e-6);
            for j in 1..n - 1 {
                let (a, b) = (before.points[j], hair.points[j]);
                let want = 90f32.to_radians() * ramp.at(param(j, n));
                assert!((turned(b) - want).abs() < 1e-4, "{ramp:?} point {j}");
                // A turn about the axis keeps the height and the distance
                // from the axis.
                assert!((a.z - b.z).abs() < 1e-6);
                assert!((a.truncate().length() - b.truncate().length()).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn jitter_varies_the_angle_per_hair_within_its_bounds() {
        let op = Twist(TwistParams {
            jitter: Map::Constant(0.5),
            ramp: Ramp::Power(0.0),
            ..TwistParams::new(Map::Constant(60.0))
        });
        let angles: Vec<f32> = (0..200)
            .map(|id| {
                let mut hair = bowed(id, 5);
                op.apply_to_hair(&mut hair, &root(), &mut Scratch::default());
                turned(hair.points[2]).to_degrees()
            })
            .collect();
        assert!(angles.iter().all(|a| (29.9..=90.1).contains(a)));
        let (lo, hi) = angles
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), a| (lo.min(*a), hi.max(*a)));
        assert!(hi - lo > 40.0, "per-hair variation: {lo} to {hi}");
    }
}
