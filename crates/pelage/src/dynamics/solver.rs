//! Forces and time stepping for [`MassSpringSystem`] (Banisch & Wüthrich,
//! "Mass–Spring System", "Shell Layer Displacement"; Silva §3.2.1).
//!
//! Forces on a tip: its stick's spring (to the root, rest length `L0`; for
//! Silva strands a zero-length spring to the rest position `p0`) with
//! damping along the spring; the prisms' tip-tip springs; Banisch's
//! restoring force `F = (n − s)(1 − n·s) w` (Eq. 5, `s` the unit stick
//! direction) so fur never flips into the body; gravity; air drag towards
//! the wind's velocity (gusts and turbulence in space and time); a brush.
//!
//! Two solvers:
//! - **explicit**: symplectic Euler, `v += h F/m; x += h v`, with substeps;
//! - **implicit**: backward Euler linearised once (Baraff & Witkin 1998):
//!   `(M − h ∂F/∂v − h² ∂F/∂x) Δv = h (F + h ∂F/∂x v)`, solved by conjugate
//!   gradients, matrix-free, with a 3×3 block-Jacobi preconditioner — or,
//!   where no springs join the tips, by a direct 3×3 solve per tip (the
//!   matrix is then block diagonal). The springs and the drag are
//!   implicit; gravity, wind, brush and the restoring force are taken at
//!   the start of the step.
//!
//! After each step the constraints are enforced by projection: every tip
//! stays above its root's tangent plane, and Silva tips within `L0` of their
//! root (Eq. 3); the velocity component that broke a constraint is removed.
//!
//! Every loop over tips runs on rayon and sums in a fixed order, so a step
//! gives the same bits on any number of threads.
//!
//! One file, past 600 lines: forces, both integrators and the constraints
//! share the per-tip state layout (about 120 of its lines are tests).

use super::system::{MassSpringSystem, Topology};
use crate::map::NoiseMap;
use glam::{Mat3, Vec3};
use rayon::prelude::*;

/// Below this many items a loop runs on the calling thread: handing a small
/// loop to rayon's pool costs more than the loop (a patch of fur stepped
/// 10⁵ times spent most of its time waking threads).
const PARALLEL_MIN: usize = 2048;

/// Tips a worker takes at a time in a state update: the wind at a chunk's
/// tips is read in one batch, so the turbulence's noise runs in SIMD lanes
/// ([`NoiseMap::perlin3_vectors`](crate::map::NoiseMap::perlin3_vectors)).
const CHUNK: usize = 256;

/// `(0..n).map(f).collect()`, in parallel for large `n`.
fn map_indexed<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    if n < PARALLEL_MIN {
        (0..n).map(f).collect()
    } else {
        (0..n).into_par_iter().map(f).collect()
    }
}

/// `f(i, &mut items[i])` for every item, in parallel for many items.
fn update_each<T: Send>(items: &mut [T], f: impl Fn(usize, &mut T) + Sync + Send) {
    if items.len() < PARALLEL_MIN {
        items.iter_mut().enumerate().for_each(|(i, t)| f(i, t));
    } else {
        items.par_iter_mut().enumerate().for_each(|(i, t)| f(i, t));
    }
}

/// `d̂d̂ᵀ`.
fn outer(dir: Vec3) -> Mat3 {
    Mat3::from_cols(dir * dir.x, dir * dir.y, dir * dir.z)
}

/// Wind: a base velocity that gusts in time, plus turbulence — a vector
/// noise field drifting with the wind. Build with [`Wind::new`].
#[derive(Debug, Clone)]
pub struct Wind {
    /// Mean wind velocity (units per second).
    pub velocity: Vec3,
    /// Gust amplitude as a fraction of the mean (0: steady).
    pub gust: f32,
    /// Gusts per second.
    pub gust_frequency: f32,
    /// Turbulence speed (units per second).
    pub turbulence: f32,
    /// Turbulence features per unit length.
    pub scale: f32,
    noise: NoiseMap,
}

impl Wind {
    /// Wind of mean `velocity`, gusting by `gust` (fraction of the mean)
    /// `gust_frequency` times a second, with turbulence of speed
    /// `turbulence` and `scale` features per unit length, from `seed`.
    pub fn new(
        velocity: Vec3,
        gust: f32,
        gust_frequency: f32,
        turbulence: f32,
        scale: f32,
        seed: u64,
    ) -> Self {
        Self {
            velocity,
            gust,
            gust_frequency,
            turbulence,
            scale,
            noise: NoiseMap::new(1.0, 1, seed, 0.0, 1.0),
        }
    }

    /// The wind's velocity at `p` and time `t`.
    pub fn at(&self, p: Vec3, t: f32) -> Vec3 {
        self.now(t).at(p)
    }

    /// The wind at time `t`, ready to be read at many points.
    pub fn now(&self, t: f32) -> WindNow<'_> {
        let phase = std::f32::consts::TAU * self.gust_frequency * t;
        // Two incommensurate sines: gusts that do not repeat every period.
        let gust = 1.0 + self.gust * (0.6 * phase.sin() + 0.4 * (2.31 * phase + 1.3).sin());
        WindNow {
            wind: self,
            mean: self.velocity * gust,
            drift: self.velocity * t + Vec3::new(0.0, 0.37 * t, 0.0),
        }
    }
}

/// [`Wind`] at one moment: the gust computed once for every point.
#[derive(Debug, Clone, Copy)]
pub struct WindNow<'w> {
    wind: &'w Wind,
    mean: Vec3,
    drift: Vec3,
}

impl WindNow<'_> {
    /// The gusting mean velocity at this moment.
    pub fn mean(&self) -> Vec3 {
        self.mean
    }

    /// How far the turbulence field has drifted with the wind by now: the
    /// field is read at `(p − drift) · scale`.
    pub fn drift(&self) -> Vec3 {
        self.drift
    }

    /// The turbulence's noise (its permutation table, for a GPU port).
    pub fn noise(&self) -> &NoiseMap {
        &self.wind.noise
    }

    /// The velocity at `p`.
    pub fn at(&self, p: Vec3) -> Vec3 {
        let w = self.wind;
        if w.turbulence == 0.0 {
            return self.mean;
        }
        self.mean + w.turbulence * w.noise.perlin3_vector((p - self.drift) * w.scale)
    }

    /// [`at`](Self::at) every point of `points`, into `out`: the same
    /// values, with the noise read several points at a time.
    pub fn at_many(&self, points: &[Vec3], out: &mut [Vec3]) {
        assert_eq!(points.len(), out.len(), "one output a point");
        let w = self.wind;
        if w.turbulence == 0.0 {
            out.fill(self.mean);
            return;
        }
        let mut field = [Vec3::ZERO; 64];
        for (points, out) in points.chunks(64).zip(out.chunks_mut(64)) {
            for (q, p) in out.iter_mut().zip(points) {
                *q = (*p - self.drift) * w.scale;
            }
            let field = &mut field[..points.len()];
            w.noise.perlin3_vectors(out, field);
            for (o, n) in out.iter_mut().zip(field.iter()) {
                *o = self.mean + w.turbulence * *n;
            }
        }
    }
}

/// A local push (the viewer's brush): `force` on every tip within `radius`
/// of `centre`, fading smoothly to zero at the edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PushBrush {
    /// Where.
    pub centre: Vec3,
    /// How far it reaches.
    pub radius: f32,
    /// The force at the centre.
    pub force: Vec3,
}

/// Physical parameters.
#[derive(Debug, Clone)]
pub struct DynamicsParams {
    /// Mass of each tip.
    pub mass: f32,
    /// Stiffness of each stick's spring (Silva: of the spring to `p0`).
    pub stiffness: f32,
    /// Stiffness of the prisms' tip-tip springs.
    pub lateral_stiffness: f32,
    /// Damping along every spring.
    pub damping: f32,
    /// Air drag: force `drag · (wind − v)`.
    pub drag: f32,
    /// `w` of Banisch Eq. 5.
    pub restoring: f32,
    /// Gravity (acceleration).
    pub gravity: Vec3,
    /// Wind, if any.
    pub wind: Option<Wind>,
    /// A brush, if any.
    pub brush: Option<PushBrush>,
}

impl Default for DynamicsParams {
    fn default() -> Self {
        Self {
            mass: 1e-3,
            stiffness: 2.0,
            lateral_stiffness: 1.0,
            damping: 0.02,
            drag: 2e-3,
            restoring: 0.02,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            wind: None,
            brush: None,
        }
    }
}

/// How to step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solver {
    /// Symplectic Euler with this many substeps per step.
    Explicit {
        /// Substeps per step (1: plain symplectic Euler; 0: as many as
        /// stability needs, [`MassSpringSystem::stable_substeps`]).
        substeps: u32,
    },
    /// Linearised backward Euler, at most this many CG iterations.
    Implicit {
        /// CG iteration limit.
        iterations: u32,
    },
}

impl Solver {
    /// The name scene files and the benchmark use.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Explicit { .. } => "explicit",
            Solver::Implicit { .. } => "implicit",
        }
    }
}

/// `k[(1 − L/l)(I − d̂d̂ᵀ) + d̂d̂ᵀ]`: minus the stiffness matrix of a spring
/// of rest length `rest` stretched to `d`, with `(1 − L/l)` clamped at 0 so
/// the matrix stays positive semi-definite (compressed springs do not make
/// the system indefinite; Choi & Ko's remedy).
fn spring_stiffness(k: f32, d: Vec3, rest: f32) -> (Mat3, Vec3) {
    let l = d.length();
    if l <= 1e-12 {
        return (Mat3::from_diagonal(Vec3::splat(k)), Vec3::ZERO);
    }
    let dir = d / l;
    let outer = outer(dir);
    let tangential = (1.0 - rest / l).max(0.0);
    (k * (tangential * (Mat3::IDENTITY - outer) + outer), dir)
}

impl MassSpringSystem {
    /// The force on tip `i` from everything but the tip-tip springs, where
    /// the air moves at `air` (the wind there, or zero).
    fn tip_force(&self, i: usize, p: &DynamicsParams, air: Vec3) -> Vec3 {
        let (x, v) = (self.tips[i], self.velocities[i]);
        let root = self.roots[i];
        let n = self.normals[i];
        let v_rel = v - self.root_velocities[i];
        let d = x - root;
        let l = d.length();
        let dir = if l > 1e-12 { d / l } else { n };
        let mut f = match self.topology {
            Topology::SilvaStrands => -p.stiffness * (x - self.rest_tip(i)) - p.damping * v_rel,
            _ => {
                let stretch = -p.stiffness * (l - self.lengths[i]) * dir;
                // Banisch Eq. 5.
                let restoring = (n - dir) * (1.0 - n.dot(dir)) * p.restoring;
                stretch - p.damping * v_rel.dot(dir) * dir + restoring
            }
        };
        f += p.mass * p.gravity;
        f += p.drag * (air - v);
        if let Some(b) = p.brush {
            let q = x.distance(b.centre) / b.radius.max(1e-9);
            if q < 1.0 {
                let fade = 1.0 - q * q;
                f += b.force * fade * fade;
            }
        }
        f
    }

    /// The tip at the other end of tip-tip spring `s` from tip `i`.
    fn other_end(&self, s: u32, i: usize) -> usize {
        let spring = self.springs[s as usize];
        if spring.a as usize == i {
            spring.b as usize
        } else {
            spring.a as usize
        }
    }

    /// The force on tip `i` from its tip-tip springs.
    fn lateral_force(&self, i: usize, p: &DynamicsParams) -> Vec3 {
        let mut f = Vec3::ZERO;
        for &s in self.tip_springs(i) {
            let other = self.other_end(s, i);
            let d = self.tips[i] - self.tips[other];
            let l = d.length();
            if l <= 1e-12 {
                continue;
            }
            let dir = d / l;
            let dv = self.velocities[i] - self.velocities[other];
            let rest = self.springs[s as usize].rest;
            f += -p.lateral_stiffness * (l - rest) * dir - p.damping * dv.dot(dir) * dir;
        }
        f
    }

    /// All tip forces at the current state.
    fn forces(&self, p: &DynamicsParams, time: f32) -> Vec<Vec3> {
        let wind = p.wind.as_ref().map(|w| w.now(time));
        let mut f = vec![Vec3::ZERO; self.tips.len()];
        let force_chunk = |(c, f): (usize, &mut [Vec3])| {
            let start = c * CHUNK;
            let air = self.air_at(wind, start, f.len());
            for (k, f) in f.iter_mut().enumerate() {
                *f = self.tip_force(start + k, p, air[k]) + self.lateral_force(start + k, p);
            }
        };
        if f.len() < PARALLEL_MIN {
            f.chunks_mut(CHUNK).enumerate().for_each(force_chunk);
        } else {
            f.par_chunks_mut(CHUNK).enumerate().for_each(force_chunk);
        }
        f
    }

    /// The air's velocity at tips `start..start + n` (n ≤ [`CHUNK`]).
    fn air_at(&self, wind: Option<WindNow>, start: usize, n: usize) -> [Vec3; CHUNK] {
        let mut air = [Vec3::ZERO; CHUNK];
        if let Some(w) = wind {
            w.at_many(&self.tips[start..start + n], &mut air[..n]);
        }
        air
    }

    /// Writes the next state of every tip, `next(i, air) = (x, v)` with
    /// `air` the wind's velocity at the tip (zero without wind), double
    /// buffered: `next` reads the current state only.
    fn update_state(
        &mut self,
        wind: Option<WindNow>,
        next: impl Fn(&Self, usize, Vec3) -> (Vec3, Vec3) + Sync + Send,
    ) {
        let mut tips = std::mem::take(&mut self.scratch_tips);
        let mut velocities = std::mem::take(&mut self.scratch_velocities);
        tips.resize(self.tips.len(), Vec3::ZERO);
        velocities.resize(self.tips.len(), Vec3::ZERO);
        let this = &*self;
        let write = |(c, (xs, vs)): (usize, (&mut [Vec3], &mut [Vec3]))| {
            let start = c * CHUNK;
            let air = this.air_at(wind, start, xs.len());
            for (k, (x, v)) in xs.iter_mut().zip(vs.iter_mut()).enumerate() {
                (*x, *v) = next(this, start + k, air[k]);
            }
        };
        if tips.len() < PARALLEL_MIN {
            tips.chunks_mut(CHUNK)
                .zip(velocities.chunks_mut(CHUNK))
                .enumerate()
                .for_each(write);
        } else {
            tips.par_chunks_mut(CHUNK)
                .zip(velocities.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(write);
        }
        self.scratch_tips = std::mem::replace(&mut self.tips, tips);
        self.scratch_velocities = std::mem::replace(&mut self.velocities, velocities);
    }

    /// The fewest substeps that keep an explicit step of `dt` stable.
    ///
    /// Symplectic Euler on `m x'' = −k x − c x'` is stable while
    /// `h² k/m + 2 h c/m < 4` (the update matrix has determinant `1 − hc/m`
    /// and trace `2 − h²k/m − hc/m`; Jury's conditions). For the whole
    /// system `k` and `c` are bounded by Gershgorin's theorem over each
    /// tip's springs: the stick's stiffness, twice the lateral stiffness a
    /// tip-tip spring, and Banisch's restoring force (`≤ 8w/L0`); damping
    /// likewise plus drag. The substep is then kept to 80 % of the bound.
    /// Prisms on spot (`L0` = 0.08) at the defaults take 11 substeps at 24
    /// steps a second, where one diverges (tested).
    ///
    /// The count is at most [`MAX_DYNAMICS_STEPS`](crate::limits::MAX_DYNAMICS_STEPS),
    /// the ceiling a scene's own `substeps` has: past it a step would take
    /// as long as a thousand frames. [`Self::substeps_for_stability`] says
    /// how many stability would need, so callers can warn that the cap
    /// was hit (the fur may then blow up; the implicit solver would not).
    pub fn stable_substeps(&self, dt: f32, p: &DynamicsParams) -> u32 {
        self.substeps_for_stability(dt, p)
            .min(crate::limits::MAX_DYNAMICS_STEPS) as u32
    }

    /// The substeps an explicit step of `dt` needs to be stable, without
    /// the ceiling of [`Self::stable_substeps`] (`u64::MAX` when nothing
    /// finite is enough).
    pub fn substeps_for_stability(&self, dt: f32, p: &DynamicsParams) -> u64 {
        let degree = self.max_tip_springs as f32;
        let shortest = self.lengths.iter().copied().fold(f32::INFINITY, f32::min);
        let restoring = if self.topology == Topology::SilvaStrands || !shortest.is_finite() {
            0.0
        } else {
            8.0 * p.restoring / shortest.max(1e-6)
        };
        let mass = p.mass.max(1e-12);
        let k = (p.stiffness + 2.0 * p.lateral_stiffness * degree + restoring) / mass;
        let c = (p.damping * (1.0 + 2.0 * degree) + p.drag) / mass;
        if k <= 0.0 {
            return 1;
        }
        if !k.is_finite() || !c.is_finite() {
            return u64::MAX;
        }
        // The positive root of (k/m) h² + 2 (c/m) h − 4 = 0.
        let h = (-2.0 * c + (4.0 * c * c + 16.0 * k).sqrt()) / (2.0 * k);
        let n = (f64::from(dt) / (0.8 * f64::from(h))).ceil();
        if n.is_nan() {
            1
        } else {
            // Saturates: an infinite need is u64::MAX.
            n.max(1.0) as u64
        }
    }

    /// The substeps an explicit step of `dt` takes: `requested`, or with
    /// 0, as many as stability needs ([`stable_substeps`](Self::stable_substeps)).
    pub fn explicit_substeps(&self, dt: f32, p: &DynamicsParams, requested: u32) -> u32 {
        if requested == 0 {
            self.stable_substeps(dt, p)
        } else {
            requested
        }
    }

    /// Advances the simulation by `dt` seconds; `time` is the time at the
    /// start of the step (the wind's clock).
    pub fn step(&mut self, dt: f32, params: &DynamicsParams, solver: Solver, time: f32) {
        match solver {
            Solver::Explicit { substeps } => {
                let n = self.explicit_substeps(dt, params, substeps);
                let h = dt / n as f32;
                for k in 0..n {
                    let wind = params.wind.as_ref().map(|w| w.now(time + k as f32 * h));
                    // One fused pass per substep: force, velocity, position,
                    // constraints.
                    self.update_state(wind, |this, i, air| {
                        let f = this.tip_force(i, params, air) + this.lateral_force(i, params);
                        let v = this.velocities[i] + (h / params.mass) * f;
                        this.constrained(i, this.tips[i] + h * v, v)
                    });
                }
            }
            Solver::Implicit { iterations } => {
                self.implicit_step(dt, params, iterations, time);
            }
        }
    }

    /// Tip `i`'s stick spring: its −∂F/∂x (K) and −∂F/∂v (C) blocks.
    fn stick_blocks(&self, i: usize, p: &DynamicsParams) -> (Mat3, Mat3) {
        match self.topology {
            Topology::SilvaStrands => (
                Mat3::from_diagonal(Vec3::splat(p.stiffness)),
                Mat3::from_diagonal(Vec3::splat(p.damping)),
            ),
            _ => {
                let d = self.tips[i] - self.roots[i];
                let (k, dir) = spring_stiffness(p.stiffness, d, self.lengths[i]);
                (k, p.damping * outer(dir))
            }
        }
    }

    /// One linearised backward-Euler step.
    fn implicit_step(&mut self, h: f32, p: &DynamicsParams, iterations: u32, time: f32) {
        if self.joins_tips() {
            self.implicit_step_joined(h, p, iterations, time);
        } else {
            self.implicit_step_unjoined(h, p, time);
        }
    }

    /// Backward Euler where no springs join the tips (spring-sticks,
    /// separable spring-sticks, Silva strands): the system matrix is block
    /// diagonal, so each tip's 3×3 block is solved directly — the answer
    /// preconditioned CG reaches in its first iteration, since its
    /// preconditioner is then the exact inverse — in one fused pass that
    /// stores no matrices.
    fn implicit_step_unjoined(&mut self, h: f32, p: &DynamicsParams, time: f32) {
        let wind = p.wind.as_ref().map(|w| w.now(time));
        let fixed = Mat3::from_diagonal(Vec3::splat(p.mass + h * p.drag));
        self.update_state(wind, |this, i, air| {
            let f = this.tip_force(i, p, air);
            let (k, c) = this.stick_blocks(i, p);
            let a = fixed + h * c + h * h * k;
            let dv = a.inverse() * (h * (f - h * (k * this.velocities[i])));
            let v = this.velocities[i] + dv;
            this.constrained(i, this.tips[i] + h * v, v)
        });
    }

    /// Backward Euler with tip-tip springs (prisms): matrix-free CG.
    fn implicit_step_joined(&mut self, h: f32, p: &DynamicsParams, iterations: u32, time: f32) {
        let n = self.tips.len();
        let f0 = self.forces(p, time);
        let stick_blocks: Vec<(Mat3, Mat3)> = map_indexed(n, |i| self.stick_blocks(i, p));
        // Per tip-tip spring: the a-a block of −∂F/∂x and −∂F/∂v (a-b is
        // its negative).
        let spring_blocks: Vec<(Mat3, Mat3)> = map_indexed(self.springs.len(), |s| {
            let spring = self.springs[s];
            let d = self.tips[spring.a as usize] - self.tips[spring.b as usize];
            let (k, dir) = spring_stiffness(p.lateral_stiffness, d, spring.rest);
            (k, p.damping * outer(dir))
        });
        // A = M − h ∂F/∂v − h² ∂F/∂x = M + h C + h² K (C, K as stored).
        let drag = Mat3::from_diagonal(Vec3::splat(p.drag));
        let diagonal: Vec<Mat3> = map_indexed(n, |i| {
            let (k, c) = stick_blocks[i];
            let mut a = Mat3::from_diagonal(Vec3::splat(p.mass)) + h * (c + drag) + h * h * k;
            for &s in self.tip_springs(i) {
                let (k, c) = spring_blocks[s as usize];
                a += h * c + h * h * k;
            }
            a
        });
        let apply = |x: &[Vec3], out: &mut [Vec3]| {
            update_each(out, |i, y| {
                let mut sum = diagonal[i] * x[i];
                for &s in self.tip_springs(i) {
                    let (k, c) = spring_blocks[s as usize];
                    sum -= (h * c + h * h * k) * x[self.other_end(s, i)];
                }
                *y = sum;
            });
        };
        // b = h (F0 + h ∂F/∂x v0) = h (F0 − h K v0).
        let b: Vec<Vec3> = map_indexed(n, |i| {
            let mut kv = stick_blocks[i].0 * self.velocities[i];
            for &s in self.tip_springs(i) {
                let other = self.other_end(s, i);
                kv += spring_blocks[s as usize].0 * (self.velocities[i] - self.velocities[other]);
            }
            h * (f0[i] - h * kv)
        });
        let preconditioner: Vec<Mat3> = map_indexed(n, |i| diagonal[i].inverse());
        let dv = conjugate_gradient(&apply, &b, &preconditioner, iterations.max(1), 1e-6);
        self.update_state(None, |this, i, _| {
            let v = this.velocities[i] + dv[i];
            this.constrained(i, this.tips[i] + h * v, v)
        });
    }

    fn tip_springs(&self, i: usize) -> &[u32] {
        &self.spring_index[self.spring_offsets[i] as usize..self.spring_offsets[i + 1] as usize]
    }

    /// Tip `i` at `x` moving at `v`, projected back into its allowed
    /// region: above the root's tangent plane, and (Silva strands) within
    /// `L0` of the root (Eq. 3); the velocity that pointed out of it is
    /// removed.
    fn constrained(&self, i: usize, mut x: Vec3, mut v: Vec3) -> (Vec3, Vec3) {
        let (root, n) = (self.roots[i], self.normals[i]);
        let root_velocity = self.root_velocities[i];
        let height = (x - root).dot(n);
        if height < 0.0 {
            x -= height * n;
            let vn = (v - root_velocity).dot(n);
            if vn < 0.0 {
                v -= vn * n;
            }
        }
        if self.topology == Topology::SilvaStrands {
            let d = x - root;
            let l = d.length();
            if l > self.lengths[i] {
                let dir = d / l;
                x = root + self.lengths[i] * dir;
                let vr = (v - root_velocity).dot(dir);
                if vr > 0.0 {
                    v -= vr * dir;
                }
            }
        }
        (x, v)
    }

    /// Kinetic energy plus the springs' potential energy plus gravity's
    /// (relative to the rest tips). Banisch's restoring force is not
    /// conservative and has no potential; tests of energy set it to 0.
    pub fn energy(&self, p: &DynamicsParams) -> f64 {
        let mut e = 0.0f64;
        for i in 0..self.tips.len() {
            let x = self.tips[i];
            e += 0.5 * f64::from(p.mass) * f64::from(self.velocities[i].length_squared());
            let spring = match self.topology {
                Topology::SilvaStrands => (x - self.rest_tip(i)).length_squared(),
                _ => {
                    let stretch = (x - self.roots[i]).length() - self.lengths[i];
                    stretch * stretch
                }
            };
            e += 0.5 * f64::from(p.stiffness) * f64::from(spring);
            e -= f64::from(p.mass) * f64::from(p.gravity.dot(x - self.rest_tip(i)));
        }
        for s in &self.springs {
            let stretch = self.tips[s.a as usize].distance(self.tips[s.b as usize]) - s.rest;
            e += 0.5 * f64::from(p.lateral_stiffness) * f64::from(stretch * stretch);
        }
        e
    }
}

/// Preconditioned conjugate gradients on 3-vectors: solves `A x = b` with
/// `apply(x, out)` computing `A x` and a block-diagonal preconditioner.
fn conjugate_gradient(
    apply: &impl Fn(&[Vec3], &mut [Vec3]),
    b: &[Vec3],
    preconditioner: &[Mat3],
    iterations: u32,
    tolerance: f64,
) -> Vec<Vec3> {
    let n = b.len();
    // Sums in fixed chunks, then the chunks in order: the same bits on any
    // number of threads.
    let dot = |a: &[Vec3], b: &[Vec3]| -> f64 {
        let chunk = |k: usize| -> f64 {
            let range = k * 4096..((k + 1) * 4096).min(a.len());
            a[range.clone()]
                .iter()
                .zip(&b[range])
                .map(|(a, b)| f64::from(a.dot(*b)))
                .sum()
        };
        map_indexed(a.len().div_ceil(4096), chunk).iter().sum()
    };
    let mut x = vec![Vec3::ZERO; n];
    let mut r = b.to_vec();
    let mut z: Vec<Vec3> = map_indexed(n, |i| preconditioner[i] * r[i]);
    let mut d = z.clone();
    let mut ad = vec![Vec3::ZERO; n];
    let mut rz = dot(&r, &z);
    let threshold = tolerance * tolerance * dot(b, b).max(1e-300);
    for _ in 0..iterations {
        if dot(&r, &r) <= threshold {
            break;
        }
        apply(&d, &mut ad);
        let dad = dot(&d, &ad);
        if dad <= 0.0 {
            break;
        }
        let alpha = (rz / dad) as f32;
        update_each(&mut x, |i, x| *x += alpha * d[i]);
        update_each(&mut r, |i, r| *r -= alpha * ad[i]);
        update_each(&mut z, |i, z| *z = preconditioner[i] * r[i]);
        let rz_next = dot(&r, &z);
        let beta = (rz_next / rz.max(1e-300)) as f32;
        rz = rz_next;
        update_each(&mut d, |i, d| *d = z[i] + beta * *d);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gusting, turbulent wind the tests below step in.
    fn gusting_wind(turbulence: f32) -> Wind {
        Wind::new(Vec3::new(3.0, 0.0, 1.0), 0.5, 1.0, turbulence, 4.0, 7)
    }

    /// The wind read a batch at a time (the solvers' way) is the wind read
    /// point by point, to the bit, with and without turbulence.
    #[test]
    fn wind_read_in_batches_equals_point_by_point() {
        for turbulence in [0.0, 2.0] {
            let wind = gusting_wind(turbulence);
            let now = wind.now(1.37);
            let points: Vec<Vec3> = (0..300)
                .map(|k| Vec3::new(k as f32 * 0.013 - 2.0, (k as f32).sin(), k as f32 * -0.007))
                .collect();
            let mut out = vec![Vec3::NAN; points.len()];
            now.at_many(&points, &mut out);
            for (p, o) in points.iter().zip(&out) {
                assert_eq!(
                    o.to_array().map(f32::to_bits),
                    now.at(*p).to_array().map(f32::to_bits)
                );
            }
        }
    }

    /// Explicit steps with `substeps: 0` take as many substeps as the
    /// stability bound asks and stay bounded in a gusting wind, for every
    /// topology, at a step where one substep diverges for prisms.
    #[test]
    fn automatic_substeps_keep_explicit_steps_stable() {
        let mesh = crate::assets::spot();
        let params = DynamicsParams {
            wind: Some(gusting_wind(2.0)),
            ..DynamicsParams::default()
        };
        let dt = 1.0 / 24.0;
        let length = 0.08;
        let run = |topology, substeps| {
            let mut system = MassSpringSystem::new(&mesh, topology, length);
            for k in 0..240 {
                system.step(dt, &params, Solver::Explicit { substeps }, k as f32 * dt);
            }
            (0..system.mass_count())
                .map(|i| system.tips[i].distance(system.rest_tip(i)))
                .fold(
                    0.0f32,
                    |a, b| if b.is_nan() { f32::INFINITY } else { a.max(b) },
                )
        };
        for topology in Topology::ALL {
            let n = MassSpringSystem::new(&mesh, topology, length).stable_substeps(dt, &params);
            let worst = run(topology, 0);
            eprintln!("{topology:?}: {n} substeps at dt = 1/24, tips within {worst:.4} of rest");
            assert!(
                worst < 3.0 * length,
                "{topology:?}: {n} automatic substeps let the tips run to {worst}"
            );
        }
        assert!(
            run(Topology::Prisms, 1) > 100.0 * length,
            "prisms at one substep of 1/24 s diverge: the bound is needed"
        );
    }

    /// A stiffness no explicit step can follow asks for more substeps
    /// than the ceiling; the automatic choice stops at the ceiling instead
    /// of hanging for a million substeps a step.
    #[test]
    fn automatic_substeps_stop_at_the_ceiling() {
        let mesh = crate::assets::spot();
        let params = DynamicsParams {
            stiffness: 1e30,
            ..DynamicsParams::default()
        };
        let system = MassSpringSystem::new(&mesh, Topology::Prisms, 0.08);
        let dt = 1.0 / 24.0;
        assert!(system.substeps_for_stability(dt, &params) > crate::limits::MAX_DYNAMICS_STEPS);
        assert_eq!(
            system.explicit_substeps(dt, &params, 0) as u64,
            crate::limits::MAX_DYNAMICS_STEPS
        );
        let infinite = DynamicsParams {
            stiffness: f32::INFINITY,
            ..DynamicsParams::default()
        };
        assert_eq!(system.substeps_for_stability(dt, &infinite), u64::MAX);
        assert_eq!(
            system.stable_substeps(dt, &infinite) as u64,
            crate::limits::MAX_DYNAMICS_STEPS
        );
    }

    /// The direct per-tip solve is the CG solve, where no springs join the
    /// tips: same tips and velocities after steps in a gusting wind.
    #[test]
    fn unjoined_implicit_step_equals_the_conjugate_gradient_step() {
        let mesh = crate::assets::spot();
        let params = DynamicsParams {
            wind: Some(gusting_wind(2.0)),
            ..DynamicsParams::default()
        };
        for topology in [Topology::SpringSticks, Topology::SilvaStrands] {
            let mut system = MassSpringSystem::new(&mesh, topology, 0.05);
            // Stir it first, so springs are stretched and tips moving.
            for k in 0..20 {
                system.step(
                    1.0 / 240.0,
                    &params,
                    Solver::Explicit { substeps: 2 },
                    k as f32 / 240.0,
                );
            }
            let mut direct = system.clone();
            let mut cg = system.clone();
            for k in 0..5 {
                let t = 0.1 + k as f32 / 60.0;
                direct.implicit_step_unjoined(1.0 / 60.0, &params, t);
                cg.implicit_step_joined(1.0 / 60.0, &params, 10, t);
            }
            let moved = direct
                .tips
                .iter()
                .zip(&system.tips)
                .map(|(a, b)| a.distance(*b))
                .fold(0.0f32, f32::max);
            assert!(moved > 1e-3, "{topology:?}: the steps moved the tips");
            for i in 0..direct.tips.len() {
                assert!(
                    direct.tips[i].distance(cg.tips[i]) <= 1e-5 * (1.0 + moved),
                    "{topology:?} tip {i}: {} vs {}",
                    direct.tips[i],
                    cg.tips[i]
                );
                assert!(
                    direct.velocities[i].distance(cg.velocities[i])
                        <= 1e-4 * (1.0 + cg.velocities[i].length()),
                    "{topology:?} velocity {i}: {} vs {}",
                    direct.velocities[i],
                    cg.velocities[i]
                );
            }
        }
    }
}
