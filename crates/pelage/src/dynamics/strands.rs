//! Guide strands that move on their own: Dynamic Follow-The-Leader
//! (Müller, Kim, Chentanez, "Fast Simulation of Inextensible Hair and
//! Fur", VRIPHYS 2012) with position-based bending toward the groomed
//! shape, a "follow" pull toward the groom carried by the root, and
//! collisions with the posed skin ([`SkinSdf`]).
//!
//! Every strand has the same number of points; point 0 is its root,
//! carried by the skin (a position and a surface frame a frame, linearly
//! interpolated across substeps). A substep of length `h`:
//!
//! 1. **Forces** (explicit): `v ← v·e^(−damping·h) + h·g`, and air drag
//!    toward the wind `v ← v + min(1, drag·h)·(wind(x) − v)`; the
//!    predicted point `p = x + h·v`.
//! 2. **Follow** (shape matching): `p ← p + k_f·(root + F·r − p)`, `r`
//!    the point in its root's rest frame and `F` the root's frame now.
//! 3. **Bending**, root to tip: segment `i` is pulled toward its groomed
//!    direction relative to segment `i − 1`, that is, the rest direction
//!    turned by the minimal rotation taking segment `i − 1`'s rest
//!    direction to its current one (the first segment's reference is the
//!    root frame itself, so stiff hair leaves the skin as groomed). This
//!    is the bending of a rod without twist: guides carry no material
//!    frame, so twist has nothing to act on.
//! 4. **Follow-the-leader** with collisions, root to tip: each point is
//!    put at its rest length from its predecessor along the line between
//!    them (exact inextensibility in one pass, FTL §4.1); a point closer
//!    to the skin than `thickness` is pushed out along the distance
//!    field's gradient and put back at its rest length along the new
//!    line.
//! 5. **Velocities** `v = (p − x)/h − s·d_{i+1}/h` (DFTL's Eq. 9: `d` the
//!    correction FTL applied to the next point, `s` ≈ 0.9, which cancels
//!    the energy FTL would otherwise inject and makes the chain behave
//!    as if its masses were equal); a point that touched the skin loses
//!    `friction` of its velocity along the surface.
//!
//! Steps 2–4 run `iterations` times. The follow and bend stiffnesses are
//! fractions of the error removed each 1/60 s; they are turned into
//! per-iteration fractions `1 − (1 − k)^(h·60/iterations)`, so changing
//! the substeps or iterations does not change how stiff a groom feels
//! (a departure from the papers, which use per-iteration factors).
//!
//! GuideStrands never read each other, so the step runs them in parallel and
//! the result is bit-identical on any number of threads.

use super::skin_sdf::SkinSdf;
use super::solver::{Wind, WindNow};
use glam::{Mat3, Vec3};
use rayon::prelude::*;

/// Times a point is pushed out of the skin and put back at its length.
const COLLISION_PASSES: usize = 3;

/// A point put back at its length may sink this far into its thickness
/// (as a fraction of it) before the push wins over the length. Below one:
/// a point resting on the skin sits at one thickness, and rounding must
/// not decide between its length and its push.
const KEEP_LENGTH_WITHIN: f32 = 0.9;

/// A point this close to the skin, in thicknesses, rubs on it (friction).
/// A little more than one: a point pushed out rests at exactly one
/// thickness, and rounding must not decide whether it rubs.
const CONTACT: f32 = 1.05;

/// The most points a simulated strand has (per-strand scratch lives on
/// the stack, and a guide needs far fewer).
pub const MAX_STRAND_POINTS: usize = 64;

/// Where a strand's root is and how the skin there is turned: the
/// surface point and its frame (columns tangent, bitangent, normal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RootFrame {
    /// The root's position.
    pub position: Vec3,
    /// The surface frame at the root.
    pub frame: Mat3,
}

/// The simulation's settings.
#[derive(Debug, Clone)]
pub struct GuideStrandParams {
    /// Substeps a frame.
    pub substeps: u32,
    /// Follow, bend and length passes a substep.
    pub iterations: u32,
    /// Gravity (acceleration, scene units per second²).
    pub gravity: Vec3,
    /// Velocity decay rate, per second (air resistance).
    pub damping: f32,
    /// Bend stiffness: the fraction of the bend away from the groomed
    /// shape removed each 1/60 s (0: a free chain; 1: rigid).
    pub bend: f32,
    /// Pull toward the groomed strand carried by its root, as a fraction
    /// removed each 1/60 s (0: free; 1: the groom exactly).
    pub follow: f32,
    /// DFTL's velocity correction `s` (0 to 1; Müller et al. use 0.9).
    pub ftl_damping: f32,
    /// Air drag toward the wind's velocity, per second.
    pub drag: f32,
    /// Wind, if any.
    pub wind: Option<Wind>,
    /// How far from the skin a point is kept (scene units).
    pub thickness: f32,
    /// Fraction of a touching point's velocity along the skin removed
    /// each substep (0 to 1).
    pub friction: f32,
}

impl Default for GuideStrandParams {
    fn default() -> Self {
        Self {
            substeps: 4,
            iterations: 1,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            damping: 1.0,
            bend: 0.3,
            follow: 0.02,
            ftl_damping: 0.9,
            drag: 0.0,
            wind: None,
            thickness: 0.0,
            friction: 0.3,
        }
    }
}

/// Why strands cannot be simulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StrandError {
    /// GuideStrands need a root and at least one more point.
    #[error("a strand needs 2 to {MAX_STRAND_POINTS} points, not {0}")]
    PointCount(usize),
    /// The arrays do not describe the same strands.
    #[error("{0}")]
    Shape(String),
    /// A collision thickness past pelage's limit for this skin.
    #[error(
        "a collision thickness of {thickness} is more than a tenth of the skin's size ({most} here): guides are kept this far off the skin (docs/limits.md)"
    )]
    Thickness {
        /// The thickness asked for.
        thickness: f32,
        /// The most this skin allows.
        most: f32,
    },
}

/// Simulated strands: positions and velocities, with each strand's
/// groomed shape in its root's rest frame.
#[derive(Debug, Clone)]
pub struct GuideStrands {
    points_per_strand: usize,
    positions: Vec<Vec3>,
    velocities: Vec<Vec3>,
    /// Each point in its root's rest frame: `Fᵀ (p − root)` at rest.
    rest_local: Vec<Vec3>,
    /// Each point's distance from its predecessor at rest (0 for roots).
    lengths: Vec<f32>,
    roots: Vec<RootFrame>,
}

impl GuideStrands {
    /// GuideStrands at rest with the points `points` (`points_per_strand` a
    /// strand, strand after strand, each starting at its root) and their
    /// roots' rest frames.
    pub fn new(
        points: &[Vec3],
        points_per_strand: usize,
        roots: &[RootFrame],
    ) -> Result<Self, StrandError> {
        let n = points_per_strand;
        if !(2..=MAX_STRAND_POINTS).contains(&n) {
            return Err(StrandError::PointCount(n));
        }
        if points.len() != roots.len() * n {
            return Err(StrandError::Shape(format!(
                "{} points are not {} strands of {n}",
                points.len(),
                roots.len()
            )));
        }
        if let Some(bad) = points.iter().position(|p| !p.is_finite()) {
            return Err(StrandError::Shape(format!(
                "point {bad} of the strands is not finite: {}",
                points[bad]
            )));
        }
        let mut rest_local = Vec::with_capacity(points.len());
        let mut lengths = Vec::with_capacity(points.len());
        for (strand, root) in points.chunks_exact(n).zip(roots) {
            let to_local = root.frame.transpose();
            for (i, &p) in strand.iter().enumerate() {
                rest_local.push(to_local * (p - root.position));
                lengths.push(if i == 0 {
                    0.0
                } else {
                    (p - strand[i - 1]).length()
                });
            }
        }
        Ok(Self {
            points_per_strand: n,
            positions: points.to_vec(),
            velocities: vec![Vec3::ZERO; points.len()],
            rest_local,
            lengths,
            roots: roots.to_vec(),
        })
    }

    /// How many strands.
    pub fn len(&self) -> usize {
        self.roots.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.roots.is_empty()
    }

    /// Points a strand.
    pub fn points_per_strand(&self) -> usize {
        self.points_per_strand
    }

    /// Every point now, strand after strand.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Every point's velocity (units per second).
    pub fn velocities(&self) -> &[Vec3] {
        &self.velocities
    }

    /// Each point's rest distance from its predecessor (0 for roots).
    pub fn rest_lengths(&self) -> &[f32] {
        &self.lengths
    }

    /// Each point in its root's rest frame.
    pub fn rest_local(&self) -> &[Vec3] {
        &self.rest_local
    }

    /// The roots' frames as of the last step.
    pub fn roots(&self) -> &[RootFrame] {
        &self.roots
    }

    /// The groomed strands carried by `roots` (where follow = 1 keeps
    /// them).
    pub fn groomed(&self, roots: &[RootFrame]) -> Vec<Vec3> {
        let n = self.points_per_strand;
        self.rest_local
            .chunks_exact(n)
            .zip(roots)
            .flat_map(|(local, r)| local.iter().map(move |&l| r.position + r.frame * l))
            .collect()
    }

    /// Puts every strand back in its groomed shape on `roots`, at rest.
    pub fn reset(&mut self, roots: &[RootFrame]) {
        assert_eq!(roots.len(), self.len(), "one root a strand");
        self.positions = self.groomed(roots);
        self.velocities.fill(Vec3::ZERO);
        self.roots = roots.to_vec();
    }

    /// Advances `dt` seconds, ending at time `time` (for the wind), in
    /// `params.substeps` substeps while the roots move linearly from
    /// where they were to `roots`, colliding with the skin: `skin[s]` is
    /// the skin at the end of substep `s` (one grid for all substeps: a
    /// skin standing still); empty for no collisions.
    pub fn step(
        &mut self,
        params: &GuideStrandParams,
        dt: f32,
        time: f32,
        roots: &[RootFrame],
        skin: &[SkinSdf],
    ) {
        assert_eq!(roots.len(), self.len(), "one root a strand");
        assert!(
            skin.len() <= 1 || skin.len() == params.substeps.max(1) as usize,
            "one skin grid, or one a substep"
        );
        let substeps = params.substeps.max(1);
        let consts = params.substep_constants(dt);
        let h = consts.h;
        let n = self.points_per_strand;
        let starts = &self.roots;
        let wind_at: Vec<Option<WindNow>> = (0..substeps)
            .map(|s| {
                let t = time - dt + h * (s + 1) as f32;
                params.wind.as_ref().map(|w| w.now(t))
            })
            .collect();
        self.positions
            .par_chunks_mut(n)
            .zip(self.velocities.par_chunks_mut(n))
            .zip(self.rest_local.par_chunks(n))
            .zip(self.lengths.par_chunks(n))
            .zip(starts.par_iter().zip(roots.par_iter()))
            .with_min_len(64)
            .for_each(|((((x, v), local), lengths), (from, to))| {
                for (s, wind) in wind_at.iter().enumerate() {
                    let a = (s + 1) as f32 / substeps as f32;
                    let root = lerp_root(from, to, a);
                    let grid = skin.get(s).or(skin.first());
                    substep(x, v, local, lengths, &root, &consts, wind.as_ref(), grid);
                }
            });
        self.roots = roots.to_vec();
    }

    /// The kinetic plus gravitational energy of the free points (unit
    /// masses) under gravity `g`.
    pub fn energy(&self, g: Vec3) -> f64 {
        let n = self.points_per_strand;
        self.positions
            .iter()
            .zip(&self.velocities)
            .enumerate()
            .filter(|(i, _)| i % n != 0)
            .map(|(_, (p, v))| 0.5 * f64::from(v.length_squared()) - f64::from(g.dot(*p)))
            .sum()
    }
}

/// What a substep of a step of `dt` computes with, derived once from
/// [`GuideStrandParams`] (and handed as is to a GPU port).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubstepConstants {
    /// The substep's length.
    pub h: f32,
    /// `e^(−damping·h)`.
    pub decay: f32,
    /// Gravity × `h`.
    pub gravity_h: Vec3,
    /// `min(1, drag·h)`.
    pub drag: f32,
    /// The follow and bend fractions an iteration.
    pub follow: f32,
    /// See `follow`.
    pub bend: f32,
    /// DFTL's `s`.
    pub ftl: f32,
    /// Collision thickness.
    pub thickness: f32,
    /// Friction, 0 to 1.
    pub friction: f32,
    /// Iterations a substep (at least 1).
    pub iterations: u32,
}

impl GuideStrandParams {
    /// The constants of a substep of a step of `dt` seconds.
    pub fn substep_constants(&self, dt: f32) -> SubstepConstants {
        let substeps = self.substeps.max(1);
        let iterations = self.iterations.max(1);
        let h = dt / substeps as f32;
        let per_iteration = |k: f32| {
            let k = k.clamp(0.0, 1.0);
            if k >= 1.0 {
                1.0
            } else {
                1.0 - (1.0 - k).powf(h * 60.0 / iterations as f32)
            }
        };
        SubstepConstants {
            h,
            decay: (-self.damping.max(0.0) * h).exp(),
            gravity_h: self.gravity * h,
            drag: (self.drag.max(0.0) * h).min(1.0),
            follow: per_iteration(self.follow),
            bend: per_iteration(self.bend),
            ftl: self.ftl_damping.clamp(0.0, 1.0),
            thickness: self.thickness,
            friction: self.friction.clamp(0.0, 1.0),
            iterations,
        }
    }
}

/// The root a fraction `a` of the way from `from` to `to`: positions and
/// frame columns interpolated, the frame made orthonormal again.
fn lerp_root(from: &RootFrame, to: &RootFrame, a: f32) -> RootFrame {
    if a >= 1.0 {
        return *to;
    }
    let position = from.position.lerp(to.position, a);
    let t = from.frame.x_axis.lerp(to.frame.x_axis, a);
    let n = from
        .frame
        .z_axis
        .lerp(to.frame.z_axis, a)
        .try_normalize()
        .unwrap_or(to.frame.z_axis);
    let t = (t - n * n.dot(t))
        .try_normalize()
        .unwrap_or(to.frame.x_axis);
    RootFrame {
        position,
        frame: Mat3::from_cols(t, n.cross(t), n),
    }
}

/// `r` turned by the minimal rotation taking unit `a` to unit `b`
/// (Rodrigues, with the axis unnormalised: `k = a × b`).
#[inline]
fn turn(a: Vec3, b: Vec3, r: Vec3) -> Vec3 {
    let c = a.dot(b);
    if c < -0.9999 {
        // Opposite directions: any half turn will do; a reflection
        // through the plane normal to `a` keeps the length.
        return r - 2.0 * r.dot(a) * a;
    }
    let k = a.cross(b);
    r * c + k.cross(r) + k * (k.dot(r) / (1.0 + c))
}

/// How [`follow_outside`] treats the skin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkinContact {
    /// Distance kept from the skin.
    pub thickness: f32,
    /// A point put back at its length is kept there if at least this far
    /// from the skin; nearer, the push wins over the length.
    pub keep_length_above: f32,
    /// Pushes out and back to length, at most.
    pub passes: usize,
}

/// Follow-the-leader with the skin: `target` put at `length` from
/// `leader` on the line between them, then, with a skin, pushed out to
/// the contact's thickness and put back at its length, up to `passes`
/// times (the length pass can turn a point back in where the skin is
/// curved). Returns the point and the way out of the skin where it came
/// within 1.05 thicknesses of it (zero otherwise). `fallback`: the
/// direction when `target` is on `leader`.
#[inline]
pub fn follow_outside(
    leader: Vec3,
    target: Vec3,
    length: f32,
    fallback: Vec3,
    skin: Option<&SkinSdf>,
    contact: &SkinContact,
) -> (Vec3, Vec3) {
    let mut q = leader + length * (target - leader).normalize_or(fallback);
    let mut touched = Vec3::ZERO;
    let Some(skin) = skin else {
        return (q, touched);
    };
    let thickness = contact.thickness;
    for _ in 0..contact.passes {
        let (d, out) = skin.sample(q);
        if out == Vec3::ZERO {
            break;
        }
        if d < thickness * CONTACT {
            touched = out;
        }
        if d >= thickness {
            break;
        }
        let pushed = q + (thickness - d) * out;
        q = leader + length * (pushed - leader).normalize_or(out);
        let (d, _) = skin.sample(q);
        if d < contact.keep_length_above {
            q = pushed;
        }
    }
    (q, touched)
}

#[allow(clippy::too_many_arguments)]
fn substep(
    x: &mut [Vec3],
    v: &mut [Vec3],
    local: &[Vec3],
    lengths: &[f32],
    root: &RootFrame,
    k: &SubstepConstants,
    wind: Option<&WindNow>,
    skin: Option<&SkinSdf>,
) {
    let n = x.len();
    let mut p = [Vec3::ZERO; MAX_STRAND_POINTS];
    let mut correction = [Vec3::ZERO; MAX_STRAND_POINTS];
    let mut touched = [Vec3::ZERO; MAX_STRAND_POINTS];
    p[0] = root.position;
    for i in 1..n {
        let mut vi = v[i] * k.decay + k.gravity_h;
        if let Some(w) = wind {
            vi += k.drag * (w.at(x[i]) - vi);
        }
        p[i] = x[i] + k.h * vi;
    }
    let frame = root.frame;
    let contact = SkinContact {
        thickness: k.thickness,
        keep_length_above: k.thickness * KEEP_LENGTH_WITHIN,
        passes: COLLISION_PASSES,
    };
    for _ in 0..k.iterations {
        if k.follow > 0.0 {
            for i in 1..n {
                let goal = root.position + frame * local[i];
                p[i] += k.follow * (goal - p[i]);
            }
        }
        if k.bend > 0.0 {
            // The previous segment's rest and current directions.
            let mut rest_prev = Vec3::ZERO;
            let mut now_prev = Vec3::ZERO;
            for i in 1..n {
                let rest = frame * (local[i] - local[i - 1]);
                let target = if i == 1 {
                    p[0] + rest
                } else {
                    p[i - 1] + turn(rest_prev, now_prev, rest)
                };
                p[i] += k.bend * (target - p[i]);
                rest_prev = rest.normalize_or_zero();
                now_prev = (p[i] - p[i - 1]).normalize_or_zero();
            }
        }
        for i in 1..n {
            let before = p[i];
            let (q, touch) =
                follow_outside(p[i - 1], p[i], lengths[i], frame.z_axis, skin, &contact);
            if touch != Vec3::ZERO {
                touched[i] = touch;
            }
            p[i] = q;
            correction[i] = q - before;
        }
    }
    let inv_h = 1.0 / k.h;
    v[0] = (p[0] - x[0]) * inv_h;
    x[0] = p[0];
    for i in 1..n {
        let mut vi = (p[i] - x[i]) * inv_h;
        if i + 1 < n {
            vi -= k.ftl * correction[i + 1] * inv_h;
        }
        let normal = touched[i];
        if normal != Vec3::ZERO {
            let along = normal * vi.dot(normal);
            vi = along + (vi - along) * (1.0 - k.friction);
        }
        v[i] = vi;
        x[i] = p[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn upright() -> RootFrame {
        RootFrame {
            position: Vec3::ZERO,
            frame: Mat3::IDENTITY,
        }
    }

    /// One strand of `n` points, `length` long, straight along `dir`.
    fn straight(n: usize, length: f32, dir: Vec3) -> GuideStrands {
        let points: Vec<Vec3> = (0..n)
            .map(|i| dir * length * i as f32 / (n - 1) as f32)
            .collect();
        GuideStrands::new(&points, n, &[upright()]).unwrap()
    }

    #[test]
    fn a_single_segment_swings_with_the_pendulums_period() {
        let (length, g) = (0.5f32, 9.81f32);
        let angle = 0.1f32;
        let dir = Vec3::new(angle.sin(), -angle.cos(), 0.0);
        let mut strand = straight(2, length, dir);
        let params = GuideStrandParams {
            substeps: 1,
            damping: 0.0,
            bend: 0.0,
            follow: 0.0,
            gravity: Vec3::new(0.0, -g, 0.0),
            ..Default::default()
        };
        let dt = 1.0 / 600.0;
        let mut crossings = Vec::new();
        let mut last = strand.positions()[1].x;
        for step in 1..=6000 {
            strand.step(&params, dt, step as f32 * dt, &[upright()], &[]);
            let x = strand.positions()[1].x;
            if last > 0.0 && x <= 0.0 {
                // Interpolated time of the downward crossing.
                crossings.push((step as f32 - x / (x - last)) * dt);
            }
            last = x;
        }
        let periods: Vec<f32> = crossings.windows(2).map(|w| w[1] - w[0]).collect();
        let expected = std::f32::consts::TAU * (length / g).sqrt();
        assert!(periods.len() >= 3, "{periods:?}");
        for period in periods {
            assert!(
                (period - expected).abs() < 0.05 * expected,
                "period {period} s, pendulum {expected} s"
            );
        }
    }

    #[test]
    fn segments_keep_their_length_over_a_thousand_steps() {
        let mut strand = straight(16, 1.0, Vec3::X);
        let params = GuideStrandParams {
            bend: 0.5,
            wind: Some(Wind::new(Vec3::new(0.0, 0.0, 3.0), 0.5, 1.0, 2.0, 2.0, 7)),
            drag: 2.0,
            ..Default::default()
        };
        for step in 1..=1000 {
            // A root that circles, so the chain is whipped about.
            let t = step as f32 / 240.0;
            let root = RootFrame {
                position: Vec3::new((3.0 * t).sin(), 0.0, (3.0 * t).cos()) * 0.3,
                frame: Mat3::IDENTITY,
            };
            strand.step(&params, 1.0 / 240.0, t, &[root], &[]);
        }
        let p = strand.positions();
        for i in 1..16 {
            let length = (p[i] - p[i - 1]).length();
            let rest = strand.rest_lengths()[i];
            assert!(
                (length - rest).abs() <= 1e-3 * rest,
                "segment {i}: {length} vs {rest}"
            );
        }
    }

    #[test]
    fn without_follow_strands_hang_and_with_full_follow_they_keep_their_groom() {
        let dir = Vec3::new(1.0, 0.3, 0.0).normalize();
        let mut params = GuideStrandParams {
            bend: 0.0,
            follow: 0.0,
            damping: 3.0,
            ..Default::default()
        };
        let mut free = straight(12, 0.3, dir);
        for step in 1..=480 {
            free.step(&params, 1.0 / 120.0, step as f32 / 120.0, &[upright()], &[]);
        }
        let p = free.positions();
        for i in 1..12 {
            let down = (p[i] - p[i - 1]).normalize().dot(Vec3::NEG_Y);
            assert!(down > 0.98, "segment {i} points {down} down");
        }
        params.follow = 1.0;
        let mut kept = straight(12, 0.3, dir);
        let groomed = kept.positions().to_vec();
        for step in 1..=480 {
            kept.step(&params, 1.0 / 120.0, step as f32 / 120.0, &[upright()], &[]);
        }
        for (a, b) in kept.positions().iter().zip(&groomed) {
            assert!((*a - *b).length() < 1e-5, "{a} vs groomed {b}");
        }
    }

    #[test]
    fn damping_makes_the_energy_fall_every_step() {
        let mut strand = straight(8, 0.4, Vec3::X);
        // No bending: a bent strand also stores elastic energy, which
        // this sum leaves out.
        let params = GuideStrandParams {
            bend: 0.0,
            follow: 0.0,
            damping: 0.5,
            ..Default::default()
        };
        let g = params.gravity;
        let mut energy = strand.energy(g);
        for step in 1..=400 {
            strand.step(&params, 1.0 / 60.0, step as f32 / 60.0, &[upright()], &[]);
            let now = strand.energy(g);
            assert!(now <= energy + 1e-9, "step {step}: {energy} → {now}");
            energy = now;
        }
    }
}
