//! `curl`: a helix around the hair's path, the shape of Silva et al.
//! Eq. 4 (`K_α h` for the radius, `ω` for the turns).

use super::kind::{OperatorKind, Preparation};
use super::settings::{Start, operator_settings};
use super::{Hair, RootContext, Scratch, param};
use crate::groom::error::GroomError;
use crate::groom::ramp::Ramp;
use crate::map::Map;
use crate::sample::SampleRng;
use std::f32::consts::TAU;

/// Each hair's phase.
const PHASE_SALT: u64 = 0xC0_11;

operator_settings! {
    /// `curl` as a groom file writes it.
    pub(crate) spec CurlSpec;
    /// `curl`: see [`Curl`].
    params CurlParams {
        required {
            /// Helix radius at the tip (world units): Silva's K_α.
            radius: map, start Start::Length(0.002);
            /// Turns along the hair: Silva's ω / 2π.
            turns: map, start Start::Number(3.0);
        }
        optional {
            /// Root-to-tip profile of the radius (Silva: linear).
            ramp: value(Ramp) = Ramp::default();
            /// Seed of each hair's phase.
            seed: value(u64) = 0;
        }
    }
}

/// `curl`: a helix around the hair's path, Silva et al. Eq. 4 with the
/// curve parameter for `h`: `p += α(t) (cos(2π·turns·t + φ) r + sin(…) b)`
/// with `α(t) = radius · ramp(t)` (Silva: `K_α h`, a linear ramp), `r` the
/// rotation-minimizing normal along the hair and `b = T × r`, `φ` a random
/// phase per hair. The frame does not twist, so the helix turns exactly
/// `turns` times; resolve it with enough points per hair.
#[derive(Debug, Clone)]
pub struct Curl {
    radius: Map,
    turns: Map,
    ramp: Ramp,
    seed: u64,
}

impl Curl {
    /// A curl operator.
    pub fn new(radius: Map, turns: Map, ramp: Ramp, seed: u64) -> Self {
        Self {
            radius,
            turns,
            ramp,
            seed,
        }
    }
}

impl Curl {
    /// Hair `id`'s helix at `root`: radius, turns and phase (radians).
    pub(crate) fn helix(&self, id: u64, root: &RootContext) -> [f32; 3] {
        let radius = self.radius.at(&root.site);
        if radius == 0.0 {
            return [0.0; 3];
        }
        let turns = self.turns.at(&root.site);
        let phase = TAU * SampleRng::new(self.seed ^ PHASE_SALT, id).uniform_f32();
        [radius, turns, phase]
    }

    /// The radius's profile root to tip.
    pub(crate) fn ramp(&self) -> &Ramp {
        &self.ramp
    }
}

impl OperatorKind for Curl {
    const NAME: &'static str = "curl";
    const SUMMARY: &'static str =
        "A helix of `radius` around each hair's path, `turns` times root to tip.";
    type Params = CurlParams;
    const SALTS: &'static [(&'static str, u64)] = &[("PHASE", PHASE_SALT)];

    fn prepare(p: CurlParams, cx: &Preparation<'_>) -> Result<Self, GroomError> {
        Ok(Curl::new(p.radius, p.turns, p.ramp, cx.seed(p.seed)))
    }

    fn apply_to_hair(&self, hair: &mut Hair, root: &RootContext, scratch: &mut Scratch) {
        let [radius, turns, phase] = self.helix(hair.id, root);
        if radius == 0.0 {
            return;
        }
        let n = hair.points.len();
        scratch.frame_along(&hair.points, root.normal);
        let ramp = scratch.ramps.along(&self.ramp, n);
        for (j, (p, profile)) in hair.points.iter_mut().zip(ramp).enumerate() {
            let t = param(j, n);
            let alpha = radius * profile;
            let (s, c) = (TAU * turns * t + phase).sin_cos();
            let r = scratch.frame[j];
            let b = scratch.tangents[j].cross(r);
            *p += alpha * (c * r + s * b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_hairs::{root, straight};
    use super::*;

    #[test]
    fn curl_is_a_helix_of_the_given_radius_and_turns() {
        // Straight hair up Z, constant ramp: every point lies at exactly
        // `radius` from the axis, at its own height, and the angle turns
        // 2 full times root to tip.
        let op = Curl::new(Map::Constant(0.05), Map::Constant(2.0), Ramp::Power(0.0), 9);
        let n = 65;
        let mut hair = straight(1, n, 1.0);
        op.apply_to_hair(&mut hair, &root(), &mut Scratch::default());
        let mut angle = 0.0f32;
        for j in 0..n {
            let p = hair.points[j];
            assert!((p.truncate().length() - 0.05).abs() < 1e-5, "{j}: {p}");
            assert!((p.z - param(j, n)).abs() < 1e-6);
            if j > 0 {
                let q = hair.points[j - 1].truncate();
                angle += q.angle_to(p.truncate());
            }
        }
        assert!((angle.abs() - 2.0 * TAU).abs() < 1e-3, "{angle}");
        // Silva's linear ramp: the radius grows from 0 at the root.
        let linear = Curl::new(Map::Constant(0.05), Map::Constant(2.0), Ramp::default(), 9);
        let mut hair = straight(1, n, 1.0);
        linear.apply_to_hair(&mut hair, &root(), &mut Scratch::default());
        assert!(hair.points[0].length() < 1e-7);
        assert!((hair.points[32].truncate().length() - 0.025).abs() < 1e-5);
    }
}
