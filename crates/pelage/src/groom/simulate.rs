//! `[animation] mode = "simulate"`: a groom's guides simulated over its
//! frames on the animated skin ([`GuideSimulation`]: gravity, wind, the
//! skin's motion through the roots, collisions with the body), then every
//! frame regrown from them (the regrow path of [`super::animate`]).
//!
//! The simulation runs from the first frame written, after `preroll`
//! frames at that frame's pose for the guides to settle from their
//! groomed shape, to the last. It is deterministic (the same input gives
//! the same bits on any thread count), so the tasks of a farm each
//! simulate it again and agree; sub-frame times (motion blur) read the
//! guides interpolated linearly between the two frames around them.

use super::animate::{AnimationSpec, GuideMotion};
use super::error::{GroomError, GroomErrorKind};
use super::spec::GroomSpec;
use crate::Curves;
use crate::anim::{AnimatedSkin, SkinPose};
use crate::dynamics::{GuideSimulation, StrandParams};
use std::sync::Arc;

/// How a groom's guides are simulated.
#[derive(Debug, Clone)]
pub struct SimulationSettings {
    /// The solver's settings.
    pub params: StrandParams,
    /// Collide with the skin.
    pub collide: bool,
    /// Frames at the first frame's pose before it.
    pub preroll: u32,
    /// Frames per second.
    pub fps: f64,
}

/// The guides of `spec` (bound to its mesh, the skin's rest pose)
/// simulated over `animation`'s frames on `skin`: a [`GuideMotion`] the
/// regrow path reads frame by frame.
pub fn simulate_guides(
    spec: &GroomSpec,
    skin: &AnimatedSkin,
    animation: &AnimationSpec,
    settings: &SimulationSettings,
) -> Result<GuideMotion, GroomError> {
    let triangles = spec.mesh.triangles();
    let rest = SkinPose::new(spec.mesh.positions().to_vec(), triangles);
    let mut sim = GuideSimulation::new(
        &spec.guides,
        triangles,
        &rest,
        settings.params.clone(),
        settings.collide,
    )
    .map_err(|e| spec.error("simulation", GroomErrorKind::Invalid(e.to_string())))?;
    let frames = animation.frames.frames();
    let (first, last) = match (frames.iter().min(), frames.iter().max()) {
        (Some(&a), Some(&b)) => (a, b),
        _ => {
            return Err(spec.error(
                "animation.frames",
                GroomErrorKind::Invalid("no frames to simulate".into()),
            ));
        }
    };
    let pose = |frame: i32| -> Result<SkinPose, GroomError> {
        let positions = skin
            .positions_at(f64::from(frame))
            .map_err(|e| spec.error("animation", GroomErrorKind::Mesh(e)))?;
        Ok(SkinPose::new(positions, triangles))
    };
    let dt = (1.0 / settings.fps) as f32;
    let start = pose(first)?;
    sim.reset(&start);
    for k in 0..settings.preroll {
        sim.advance(&start, dt, k as f32 * dt);
    }
    let shape = |sim: &GuideSimulation, frame: i32| {
        sim.curves().map_err(|e| {
            spec.error(
                "simulation",
                GroomErrorKind::Invalid(format!(
                    "the simulated guides at frame {frame} are not finite ({e}): the [simulation] settings are out of any sensible range"
                )),
            )
        })
    };
    let mut shapes: Vec<Curves> = Vec::with_capacity((last - first + 1) as usize);
    shapes.push(shape(&sim, first)?);
    for frame in first + 1..=last {
        let now = pose(frame)?;
        let time = (settings.preroll as i32 + frame - first) as f32 * dt;
        sim.advance(&now, dt, time);
        shapes.push(shape(&sim, frame)?);
    }
    let shapes = Arc::new(shapes);
    Ok(GuideMotion::Program(Arc::new(move |time: f64| {
        guides_between(&shapes, time - f64::from(first))
    })))
}

/// The simulated guides `offset` frames after the first: a frame's own,
/// or the two around a sub-frame time blended linearly (held at the ends).
fn guides_between(shapes: &[Curves], offset: f64) -> Curves {
    let last = shapes.len() - 1;
    let at = offset.clamp(0.0, last as f64);
    let (i, a) = (at.floor() as usize, (at - at.floor()) as f32);
    if a == 0.0 || i >= last {
        return shapes[i.min(last)].clone();
    }
    let (from, to) = (&shapes[i], &shapes[i + 1]);
    let points = from
        .points()
        .iter()
        .zip(to.points())
        .map(|(p, q)| p.lerp(*q, a))
        .collect();
    Curves::new(points, from.widths().to_vec(), from.offsets().to_vec())
        .expect("the guides' own layout")
}
