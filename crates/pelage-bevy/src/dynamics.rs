//! Fur moved by its character's motion: one damped spring per furred
//! entity (a strand's tip about its rest place, pelage's `[dynamics]`
//! mass, stiffness, damping and drag), pushed by the entity's own
//! acceleration as Bevy's transforms move it, by gravity and by wind
//! ([`FurForces`], a resource). The tip's offset bends every layer
//! through the file's coupling in the vertex shader.
//!
//! pelage's own renderers step a spring per skin vertex (four topologies,
//! two solvers); here the whole coat shares one, so fur sways as the
//! character starts, stops and turns, and hangs with gravity, but does
//! not ripple across the body.

use bevy::prelude::*;
use pelage::dynamics::DynamicsParams;

/// The forces on every coat in the world (world units per second²; wind
/// in world units per second). Gravity `None`: each file's own.
#[derive(Resource, Debug, Clone, Copy, PartialEq, Default)]
pub struct FurForces {
    /// Gravity, overriding the shells files' `[dynamics] gravity`.
    pub gravity: Option<Vec3>,
    /// The air's velocity: fur is dragged towards it.
    pub wind: Vec3,
}

/// One coat's spring: where its tips are pushed, and how fast they move.
#[derive(Component, Debug, Clone, Copy, Default)]
pub struct FurMotion {
    /// The tips' offset from their rest place (world units).
    pub offset: Vec3,
    /// Its rate of change.
    pub velocity: Vec3,
    /// The entity's position and velocity at the last step.
    last: Option<(Vec3, Vec3)>,
}

/// Substeps are at most this long: the explicit spring stays stable for
/// the stiffnesses shells files use.
const MAX_STEP: f32 = 1.0 / 240.0;

impl FurMotion {
    /// Advances the spring by `dt` with the entity now at `position`; the
    /// offset stays within `reach` (a tip cannot leave its strand).
    pub fn step(
        &mut self,
        params: &DynamicsParams,
        forces: &FurForces,
        position: Vec3,
        dt: f32,
        reach: f32,
    ) {
        if dt <= 0.0 {
            return;
        }
        let (last_position, last_velocity) = self.last.unwrap_or((position, Vec3::ZERO));
        let velocity = (position - last_position) / dt;
        let acceleration = (velocity - last_velocity) / dt;
        self.last = Some((position, velocity));
        let mass = params.mass.max(1e-6);
        let gravity = forces
            .gravity
            .unwrap_or(Vec3::from_array(params.gravity.to_array()));
        let steps = (dt / MAX_STEP).ceil().max(1.0);
        let h = dt / steps;
        for _ in 0..steps as u32 {
            // The rest place accelerates with the entity: in its frame the
            // tip feels the opposite (the coat trails as it sets off).
            let spring = -params.stiffness * self.offset - params.damping * self.velocity;
            let air = params.drag * (forces.wind - (velocity + self.velocity));
            let a = (spring + air) / mass + gravity - acceleration;
            self.velocity += h * a;
            self.offset += h * self.velocity;
            let length = self.offset.length();
            if length > reach {
                self.offset *= reach / length;
                let n = self.offset / length.max(1e-12);
                self.velocity -= n * self.velocity.dot(n).max(0.0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> DynamicsParams {
        DynamicsParams {
            mass: 1.0,
            stiffness: 3.0,
            damping: 0.5,
            drag: 0.0,
            gravity: glam::Vec3::new(0.0, -2.0, 0.0),
            ..DynamicsParams::default()
        }
    }

    /// Standing still, the tips settle where gravity and the spring
    /// balance: g / k below their rest place.
    #[test]
    fn still_fur_hangs_by_gravity_over_stiffness() {
        let mut m = FurMotion::default();
        for _ in 0..2000 {
            m.step(
                &params(),
                &FurForces::default(),
                Vec3::ZERO,
                1.0 / 60.0,
                10.0,
            );
        }
        assert!(
            (m.offset - Vec3::new(0.0, -2.0 / 3.0, 0.0)).length() < 1e-3,
            "{}",
            m.offset
        );
    }

    /// Setting off along +x, the coat trails behind (−x); wind pushes it
    /// downwind; the reach holds.
    #[test]
    fn the_coat_trails_its_motion_and_follows_the_wind() {
        let mut m = FurMotion::default();
        let forces = FurForces {
            gravity: Some(Vec3::ZERO),
            wind: Vec3::ZERO,
        };
        m.step(&params(), &forces, Vec3::ZERO, 1.0 / 60.0, 10.0);
        m.step(
            &params(),
            &forces,
            Vec3::new(1.0, 0.0, 0.0),
            1.0 / 60.0,
            10.0,
        );
        assert!(m.offset.x < 0.0, "{}", m.offset);
        let mut windy = FurMotion::default();
        let p = DynamicsParams {
            drag: 1.0,
            ..params()
        };
        let forces = FurForces {
            gravity: Some(Vec3::ZERO),
            wind: Vec3::new(0.0, 0.0, 5.0),
        };
        for _ in 0..600 {
            windy.step(&p, &forces, Vec3::ZERO, 1.0 / 60.0, 0.5);
        }
        assert!(
            windy.offset.z > 0.49 && windy.offset.length() <= 0.5 + 1e-5,
            "{}",
            windy.offset
        );
    }
}
