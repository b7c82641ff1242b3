//! The shell-fur formulas of Silva et al., one function per formula, as the
//! reference the WGSL in `pelage-gpu/src/shaders/shells.wgsl` mirrors line
//! by line (docs/design.md, "One formula, two homes"):
//!
//! - layer height `h = (1 + n) / N` (§4),
//! - the layer offset `v_offset(h) = β(h) + φ(h)` (Eq. 1), with `β` from the
//!   quadratic Bézier through `p_root`, `p0`, `p` (§3.2.1) and the curl
//!   `φ(h) = α(h)(cos(ωh) u + sin(ωh) v)`, `α(h) = (1 − ρ) K_α h` (Eq. 4),
//! - the clump displacement `d` (Eq. 5) and the fragment decision of Alg. 2,
//! - Kajiya-Kay shading with the shadow factor
//!   `γ = (K_shadow − 1 + h) / K_shadow` (Eq. 6).
//!
//! Two places where the paper as printed cannot be what was meant, and what
//! we do (both documented in docs/shells-format.md):
//!
//! - Eq. 5's scaling `k = −ln N` makes the logarithmic profile
//!   `1 + ln(h)/k` equal 2 at the root layer and 1 at the tip — clumps that
//!   squeeze the roots and open at the tips, the opposite of Fig. 9 (c, d).
//!   With `k = ln N` the profile runs from 0 at the root layer to 1 at the
//!   tip, the shape the figure shows. We use `k = ln N`
//!   ([`clump_profile`]); [`clump_profile_as_printed`] keeps the printed
//!   form, and a test shows the difference.
//! - Eq. 5 multiplies by the clump radius `r_mask`, whose unit the paper
//!   never gives; with radii in texture units (ours, and Alg. 1's) the
//!   product is a displacement of a few percent — invisible. The squeeze
//!   factor is a scene parameter instead, [`ClumpParams::strength`] (the
//!   paper's `r_mask` read as a dimensionless clump amount); `r_mask` keeps
//!   its role in Alg. 1 and in Alg. 2's "different clump" test.
//!
//! One file, past 600 lines: `shells.wgsl` mirrors it function by function,
//! and one file a side keeps the mirror checkable (about 220 of its lines are
//! tests).

use glam::{Vec2, Vec3};

/// Normalised fur length of layer `n` of `layers`: `h = (1 + n) / N`
/// (Silva §4), so the first layer sits one step above the skin and the last
/// at `h = 1`.
pub fn layer_height(n: u32, layers: u32) -> f32 {
    (1 + n) as f32 / layers.max(1) as f32
}

/// The virtual strand of one skin vertex (Silva §3.2.1): its root on the
/// surface, its rest tip `p0 = p_root + L0 n` and its current tip `p`
/// (equal to `p0` until the dynamics move it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Strand {
    /// `p_root`: the point on the surface.
    pub root: Vec3,
    /// `p0`: the rest position of the tip particle.
    pub rest_tip: Vec3,
    /// `p`: the tip particle now.
    pub tip: Vec3,
}

impl Strand {
    /// A strand at rest, grown `length` along the unit `normal`.
    pub fn at_rest(root: Vec3, normal: Vec3, length: f32) -> Self {
        let rest_tip = root + length * normal;
        Self {
            root,
            rest_tip,
            tip: rest_tip,
        }
    }

    /// The quadratic Bézier with control points `p_root`, `p0`, `p` at `h`:
    /// `B(h) = (1−h)² p_root + 2(1−h)h p0 + h² p`.
    pub fn point(&self, h: f32) -> Vec3 {
        let a = 1.0 - h;
        a * a * self.root + 2.0 * a * h * self.rest_tip + h * h * self.tip
    }

    /// `β(h) = B(h) − p_root`: how far the layer at `h` moves (Eq. 1's
    /// bending term).
    pub fn bend_offset(&self, h: f32) -> Vec3 {
        self.point(h) - self.root
    }

    /// `dB/dh = 2(1−h)(p0 − p_root) + 2h(p − p0)`: the strand's direction
    /// at `h`, before curling.
    pub fn bend_tangent(&self, h: f32) -> Vec3 {
        2.0 * (1.0 - h) * (self.rest_tip - self.root) + 2.0 * h * (self.tip - self.rest_tip)
    }
}

/// How a strand's tip moves the layers between root and tip.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Coupling {
    /// Silva §3.2.1: the quadratic Bézier through `p_root`, `p0`, `p`.
    #[default]
    Bezier,
    /// Banisch Fig. 6a: layers straight along `s = (p − p_root)/|p − p_root|`.
    Linear,
    /// Banisch Fig. 6b, Eq. 4: up the normal by the layer height, out
    /// towards `s` by `h^k (s − n)`: straight at the root, bent towards
    /// the tip. The paper does not give `k`; 2 by default.
    Bent {
        /// `k`.
        exponent: f32,
    },
}

impl Coupling {
    /// The number the shader reads: 0 Bézier, 1 linear, 2 bent.
    pub fn index(self) -> u32 {
        match self {
            Coupling::Bezier => 0,
            Coupling::Linear => 1,
            Coupling::Bent { .. } => 2,
        }
    }

    /// `k` for [`Coupling::Bent`], else 1.
    pub fn exponent(self) -> f32 {
        match self {
            Coupling::Bent { exponent } => exponent,
            _ => 1.0,
        }
    }
}

impl Strand {
    /// The unit stick direction `s` (Banisch Eq. 3) and the rest length
    /// `L0`; `s` is the rest direction for a degenerate stick.
    pub fn direction(&self) -> (Vec3, f32) {
        let rest = self.rest_tip - self.root;
        let length = rest.length();
        let s = (self.tip - self.root)
            .try_normalize()
            .unwrap_or_else(|| rest.normalize_or_zero());
        (s, length)
    }

    /// Where the layer at `h` moves a skin vertex, under `coupling`.
    pub fn coupled_offset(&self, coupling: Coupling, h: f32) -> Vec3 {
        match coupling {
            Coupling::Bezier => self.bend_offset(h),
            Coupling::Linear => {
                let (s, length) = self.direction();
                h * length * s
            }
            Coupling::Bent { exponent } => {
                let (s, length) = self.direction();
                let n = (self.rest_tip - self.root).normalize_or_zero();
                length * (h * n + h.powf(exponent) * (s - n))
            }
        }
    }

    /// `d/dh` of [`coupled_offset`](Self::coupled_offset).
    pub fn coupled_tangent(&self, coupling: Coupling, h: f32) -> Vec3 {
        match coupling {
            Coupling::Bezier => self.bend_tangent(h),
            Coupling::Linear => {
                let (s, length) = self.direction();
                length * s
            }
            Coupling::Bent { exponent } => {
                let (s, length) = self.direction();
                let n = (self.rest_tip - self.root).normalize_or_zero();
                let slope = if h > 0.0 {
                    exponent * h.powf(exponent - 1.0)
                } else {
                    0.0
                };
                length * (n + slope * (s - n))
            }
        }
    }
}

/// The curl of Eq. 4.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurlParams {
    /// `K_α`: the curl radius at the tip of dry fur, in world units.
    pub radius: f32,
    /// `ω`: radians turned from root to tip (2π: one full turn).
    pub frequency: f32,
}

/// `α(h) = (1 − ρ) K_α h`: the curl radius at `h` for wetness `ρ` — wet
/// fur loses its curl.
pub fn curl_radius(h: f32, wetness: f32, curl: CurlParams) -> f32 {
    (1.0 - wetness) * curl.radius * h
}

/// `φ(h) = α(h) cos(ωh) u + α(h) sin(ωh) v` (Eq. 4), with `u`, `v` spanning
/// the tangent plane.
pub fn curl_offset(h: f32, wetness: f32, curl: CurlParams, u: Vec3, v: Vec3) -> Vec3 {
    let alpha = curl_radius(h, wetness, curl);
    let angle = curl.frequency * h;
    alpha * angle.cos() * u + alpha * angle.sin() * v
}

/// `dφ/dh = α'(cos ωh u + sin ωh v) + αω(−sin ωh u + cos ωh v)`, with
/// `α' = (1 − ρ) K_α`.
pub fn curl_tangent(h: f32, wetness: f32, curl: CurlParams, u: Vec3, v: Vec3) -> Vec3 {
    let alpha = curl_radius(h, wetness, curl);
    let slope = (1.0 - wetness) * curl.radius;
    let angle = curl.frequency * h;
    let (s, c) = angle.sin_cos();
    slope * (c * u + s * v) + alpha * curl.frequency * (-s * u + c * v)
}

/// `v_offset(h) = β(h) + φ(h)` (Eq. 1): where the layer at `h` puts a skin
/// vertex, relative to the vertex.
pub fn layer_offset(
    strand: &Strand,
    h: f32,
    wetness: f32,
    curl: CurlParams,
    u: Vec3,
    v: Vec3,
) -> Vec3 {
    strand.bend_offset(h) + curl_offset(h, wetness, curl, u, v)
}

/// Eq. 1 with the bending term from `coupling` (Silva's Bézier, or
/// Banisch's linear or bent layers).
#[allow(clippy::too_many_arguments)]
pub fn coupled_layer_offset(
    coupling: Coupling,
    strand: &Strand,
    h: f32,
    wetness: f32,
    curl: CurlParams,
    u: Vec3,
    v: Vec3,
) -> Vec3 {
    strand.coupled_offset(coupling, h) + curl_offset(h, wetness, curl, u, v)
}

/// The unit strand tangent `T` at `h` (Eq. 6): the derivative of Eq. 1.
/// Falls back to the rest direction where the derivative vanishes — as it
/// does at the tip of a strand at rest: the Bézier through `p_root`, `p0`,
/// `p0` arrives at `p0` with zero speed.
pub fn strand_tangent(
    strand: &Strand,
    h: f32,
    wetness: f32,
    curl: CurlParams,
    u: Vec3,
    v: Vec3,
) -> Vec3 {
    coupled_strand_tangent(Coupling::Bezier, strand, h, wetness, curl, u, v)
}

/// [`strand_tangent`] under `coupling`.
#[allow(clippy::too_many_arguments)]
pub fn coupled_strand_tangent(
    coupling: Coupling,
    strand: &Strand,
    h: f32,
    wetness: f32,
    curl: CurlParams,
    u: Vec3,
    v: Vec3,
) -> Vec3 {
    let t = strand.coupled_tangent(coupling, h) + curl_tangent(h, wetness, curl, u, v);
    t.try_normalize()
        .unwrap_or_else(|| (strand.rest_tip - strand.root).normalize_or_zero())
}

/// The clumping of Eq. 5.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClumpParams {
    /// `w`: 0 keeps the fur straight while it leans to the clump centre,
    /// 1 bends it in along its length (Fig. 9).
    pub w: f32,
    /// How hard clumps squeeze: at the tip of fully wet fur a pixel shows
    /// the fur from `1 + strength` times as far from the clump centre. It
    /// stands where Eq. 5 has `r_mask` (see the module notes).
    pub strength: f32,
}

/// Eq. 5's profile along the fur, `(1 − w) h + w (1 + ln(h) / k)` with
/// `k = ln N`: it rises to 1 at the tip for every `w`; at the first layer,
/// `h = 1/N`, it is `(1 − w)/N` (0 for `w = 1`: the roots stay put). Linear
/// in `h` for `w = 0`. Clamped at 0 below the first layer.
pub fn clump_profile(h: f32, w: f32, layers: u32) -> f32 {
    let k = (layers.max(2) as f32).ln();
    ((1.0 - w) * h + w * (1.0 + h.max(1e-6).ln() / k)).max(0.0)
}

/// Eq. 5's profile exactly as printed, `k = −ln N`: largest at the root.
/// Kept to document why [`clump_profile`] differs; not used for rendering.
pub fn clump_profile_as_printed(h: f32, w: f32, layers: u32) -> f32 {
    let k = -(layers.max(2) as f32).ln();
    (1.0 - w) * h + w * (1.0 + h.max(1e-6).ln() / k)
}

/// The clump displacement `d = profile(h) · ρ · strength · (c_pixel −
/// c_mask)` (Eq. 5), in wetness-mask coordinates: the fur drawn at
/// `c_pixel` is the fur that grows at `c_pixel + d`, farther from the clump
/// centre, so the fur leans in.
pub fn clump_displacement(
    h: f32,
    layers: u32,
    clump: ClumpParams,
    wetness: f32,
    pixel: Vec2,
    centre: Vec2,
) -> Vec2 {
    clump_profile(h, clump.w, layers) * wetness * clump.strength * (pixel - centre)
}

/// One texel of the wetness mask: clump centre (R, G), radius (B) and
/// wetness (A), Silva §3.1.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WetTexel {
    /// `c_mask`: the clump centre, in mask coordinates.
    pub centre: Vec2,
    /// `r_mask`: the clump radius, in mask coordinates.
    pub radius: f32,
    /// `ρ_mask` in [0, 1]; 0 is dry.
    pub wetness: f32,
}

impl WetTexel {
    /// As the four channels of the mask texture.
    pub fn to_rgba(self) -> [f32; 4] {
        [self.centre.x, self.centre.y, self.radius, self.wetness]
    }

    /// From the four channels of the mask texture.
    pub fn from_rgba(c: [f32; 4]) -> Self {
        Self {
            centre: Vec2::new(c[0], c[1]),
            radius: c[2],
            wetness: c[3],
        }
    }
}

/// What Alg. 2 decides for one fragment of a layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ClumpDecision {
    /// Dry here (`ρ_mask = 0`): draw with the texture coordinates as they
    /// are.
    Dry,
    /// Wet: draw with the colour and fur coordinates moved by `d`.
    Displaced(Vec2),
    /// The pixel lies outside the radius of the clump its texel names:
    /// it belongs to a different clump; discard.
    DifferentClump,
    /// `c_pixel + d` is dry: that fur is not in the clump; discard.
    DryTarget,
}

/// Alg. 2 up to the geometry test: `here` is the mask at the pixel and
/// `mask_at` reads the mask elsewhere. The caller discards on
/// [`ClumpDecision::DifferentClump`] and [`ClumpDecision::DryTarget`] and
/// on transparent fur at the displaced coordinates ("no geometry").
pub fn clump_fragment(
    pixel: Vec2,
    here: WetTexel,
    h: f32,
    layers: u32,
    clump: ClumpParams,
    mask_at: impl Fn(Vec2) -> WetTexel,
) -> ClumpDecision {
    if here.wetness == 0.0 {
        return ClumpDecision::Dry;
    }
    let d = clump_displacement(h, layers, clump, here.wetness, pixel, here.centre);
    if pixel.distance(here.centre) > here.radius {
        return ClumpDecision::DifferentClump;
    }
    if mask_at(pixel + d).wetness == 0.0 {
        return ClumpDecision::DryTarget;
    }
    ClumpDecision::Displaced(d)
}

/// `γ = (K_shadow − 1 + h) / K_shadow` (Eq. 6): darkens the fur towards the
/// skin; `K_shadow ≥ 1` (1: γ = h, black at the skin; large: no shadow).
pub fn shadow_factor(h: f32, k_shadow: f32) -> f32 {
    let k = k_shadow.max(1.0);
    (k - 1.0 + h) / k
}

/// Kajiya-Kay lighting (Eq. 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KajiyaKay {
    /// `K_s`: the specular colour (linear RGB).
    pub specular: Vec3,
    /// `p_phong`: the specular exponent.
    pub exponent: f32,
    /// `K_shadow` of the shadow factor.
    pub k_shadow: f32,
}

/// Eq. 6: `C_d = K_color |T × L|`, `C_s = K_s [(T·L)(T·E) + |T×L||T×E|]^p`,
/// `C_frag = γ (C_d + C_s)`. `T`, `L` (towards the light) and `E` (towards
/// the eye) are unit vectors; a negative specular base gives no highlight.
pub fn kajiya_kay(color: Vec3, t: Vec3, l: Vec3, e: Vec3, h: f32, k: KajiyaKay) -> Vec3 {
    let sin_tl = t.cross(l).length();
    let sin_te = t.cross(e).length();
    let diffuse = color * sin_tl;
    let base = (t.dot(l) * t.dot(e) + sin_tl * sin_te).max(0.0);
    let specular = k.specular * base.powf(k.exponent);
    shadow_factor(h, k.k_shadow) * (diffuse + specular)
}

/// How layer fragments are coloured: the four stages of Banisch Fig. 2,
/// then Silva's Eq. 6.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShadingMode {
    /// The structure alone: grey hair, lighter towards each hair's tip.
    Structure,
    /// Adds the colour texture.
    Color,
    /// Adds the self-shadow `γ` (darker towards the skin).
    Shadow,
    /// Adds diffuse shading by Lambert's cosine law on the surface normal
    /// (Banisch), with a quarter ambient so the unlit side keeps its colour.
    Lambert,
    /// Kajiya-Kay along the strand tangent (Silva Eq. 6).
    #[default]
    KajiyaKay,
}

impl ShadingMode {
    /// The number the shader reads.
    pub fn index(self) -> u32 {
        self as u32
    }
}

/// The colour of one layer fragment (or of the skin, `h = 0`): `color` from
/// the colour texture, `along` how far along its hair the texel is (shell
/// texture channel B), `t` the shading tangent, `n` the surface normal, `l`
/// towards the light, `e` towards the eye.
#[allow(clippy::too_many_arguments)]
pub fn shade(
    mode: ShadingMode,
    color: Vec3,
    along: f32,
    t: Vec3,
    n: Vec3,
    l: Vec3,
    e: Vec3,
    h: f32,
    k: KajiyaKay,
) -> Vec3 {
    match mode {
        ShadingMode::Structure => Vec3::splat(0.5 + 0.5 * along),
        ShadingMode::Color => color,
        ShadingMode::Shadow => shadow_factor(h, k.k_shadow) * color,
        ShadingMode::Lambert => {
            shadow_factor(h, k.k_shadow) * color * (0.25 + 0.75 * n.dot(l).max(0.0))
        }
        ShadingMode::KajiyaKay => kajiya_kay(color, t, l, e, h, k),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::{PI, TAU};

    const NO_CURL: CurlParams = CurlParams {
        radius: 0.0,
        frequency: 0.0,
    };

    #[test]
    fn layers_run_from_one_step_above_the_skin_to_the_tip() {
        assert_eq!(layer_height(0, 16), 1.0 / 16.0);
        assert_eq!(layer_height(15, 16), 1.0);
    }

    #[test]
    fn resting_strand_is_a_straight_line_along_the_normal() {
        let s = Strand::at_rest(Vec3::new(1.0, 2.0, 3.0), Vec3::Y, 0.5);
        assert_eq!(s.bend_offset(0.0), Vec3::ZERO);
        assert!((s.bend_offset(1.0) - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-6);
        for h in [0.1f32, 0.5, 0.9] {
            let o = s.bend_offset(h);
            assert!(o.x.abs() < 1e-6 && o.z.abs() < 1e-6);
            // Control points p_root, p0, p0: B(h) = p_root + (2h − h²) L0 n.
            assert!((o.y - 0.5 * (2.0 * h - h * h)).abs() < 1e-6);
        }
    }

    #[test]
    fn bent_strand_ends_at_the_tip_particle_and_its_tangent_is_the_derivative() {
        let mut s = Strand::at_rest(Vec3::ZERO, Vec3::Y, 1.0);
        s.tip = Vec3::new(0.6, 0.8, 0.0);
        assert!((s.point(1.0) - s.tip).length() < 1e-6);
        let h = 0.37;
        let numeric = (s.point(h + 1e-3) - s.point(h - 1e-3)) / 2e-3;
        assert!((numeric - s.bend_tangent(h)).length() < 1e-3);
        // At the root the strand leaves along the normal.
        assert!(s.bend_tangent(0.0).normalize().abs_diff_eq(Vec3::Y, 1e-6));
    }

    #[test]
    fn curl_is_a_widening_helix_that_wetness_straightens() {
        let curl = CurlParams {
            radius: 0.2,
            frequency: 4.0 * PI,
        };
        let (u, v) = (Vec3::X, Vec3::Z);
        for h in [0.25f32, 0.5, 1.0] {
            let o = curl_offset(h, 0.0, curl, u, v);
            assert!((o.length() - 0.2 * h).abs() < 1e-6, "radius K_α h");
            assert!(o.y.abs() < 1e-9, "in the tangent plane");
        }
        // ω = 4π: two turns, so at h = 1/2 and h = 1 the curl points along u.
        assert!(
            curl_offset(0.5, 0.0, curl, u, v)
                .normalize()
                .abs_diff_eq(u, 1e-5)
        );
        assert!(curl_offset(1.0, 0.3, curl, u, v).abs_diff_eq(0.7 * 0.2 * u, 1e-5));
        assert_eq!(curl_offset(0.8, 1.0, curl, u, v), Vec3::ZERO);
        let h = 0.61;
        let numeric = (curl_offset(h + 1e-3, 0.2, curl, u, v)
            - curl_offset(h - 1e-3, 0.2, curl, u, v))
            / 2e-3;
        assert!((numeric - curl_tangent(h, 0.2, curl, u, v)).length() < 2e-3);
    }

    #[test]
    fn layer_offset_is_bend_plus_curl() {
        let s = Strand::at_rest(Vec3::ZERO, Vec3::Y, 1.0);
        let curl = CurlParams {
            radius: 0.1,
            frequency: TAU,
        };
        let o = layer_offset(&s, 0.25, 0.0, curl, Vec3::X, Vec3::Z);
        let expected = Vec3::new(0.0, 2.0 * 0.25 - 0.0625, 0.0) + Vec3::new(0.0, 0.0, 0.025);
        assert!(o.abs_diff_eq(expected, 1e-6), "{o} vs {expected}");
        let t = strand_tangent(&s, 0.0, 0.0, NO_CURL, Vec3::X, Vec3::Z);
        assert!(t.abs_diff_eq(Vec3::Y, 1e-6));
    }

    #[test]
    fn couplings_end_at_the_tip_and_differ_in_between() {
        let mut s = Strand::at_rest(Vec3::ZERO, Vec3::Y, 1.0);
        // Tipped 60° over in x, same length.
        s.tip = Vec3::new(0.75f32.sqrt(), 0.5, 0.0);
        let bent = Coupling::Bent { exponent: 2.0 };
        for c in [Coupling::Bezier, Coupling::Linear, bent] {
            assert!(s.coupled_offset(c, 1.0).abs_diff_eq(s.tip, 1e-6), "{c:?}");
            assert_eq!(s.coupled_offset(c, 0.0), Vec3::ZERO);
            let h = 0.4;
            let numeric = (s.coupled_offset(c, h + 1e-3) - s.coupled_offset(c, h - 1e-3)) / 2e-3;
            assert!((numeric - s.coupled_tangent(c, h)).length() < 1e-3, "{c:?}");
        }
        // Half way: linear is half the tip; bent is up 0.5 and out a quarter
        // of (s − n); the Bézier leans a quarter of (p − p0).
        let half = |c| s.coupled_offset(c, 0.5);
        assert!(half(Coupling::Linear).abs_diff_eq(0.5 * s.tip, 1e-6));
        let expected_bent = 0.5 * Vec3::Y + 0.25 * (s.tip - Vec3::Y);
        assert!(half(bent).abs_diff_eq(expected_bent, 1e-6));
        assert!((half(Coupling::Bezier).x - 0.25 * s.tip.x).abs() < 1e-6);
        // At rest every coupling is the straight strand.
        let rest = Strand::at_rest(Vec3::ZERO, Vec3::Y, 1.0);
        assert!(
            rest.coupled_offset(Coupling::Linear, 0.3)
                .abs_diff_eq(0.3 * Vec3::Y, 1e-6)
        );
        assert!(
            rest.coupled_offset(bent, 0.3)
                .abs_diff_eq(0.3 * Vec3::Y, 1e-6)
        );
    }

    #[test]
    fn clump_profile_with_k_ln_n_rises_from_root_to_tip_and_as_printed_falls() {
        let n = 16;
        let first = layer_height(0, n);
        // w = 0: straight lean, f = h.
        assert_eq!(clump_profile(0.5, 0.0, n), 0.5);
        // w = 1: 1 + ln h / ln N is 0 at the first layer and 1 at the tip.
        assert!(clump_profile(first, 1.0, n).abs() < 1e-6);
        assert!((clump_profile(1.0, 1.0, n) - 1.0).abs() < 1e-6);
        let mut last = -1.0;
        for k in 0..n {
            let f = clump_profile(layer_height(k, n), 1.0, n);
            assert!(f > last);
            last = f;
        }
        // As printed (k = −ln N): 2 at the first layer, 1 at the tip.
        assert!((clump_profile_as_printed(first, 1.0, n) - 2.0).abs() < 1e-5);
        assert!((clump_profile_as_printed(1.0, 1.0, n) - 1.0).abs() < 1e-6);
        // w = 1 bends early: above the straight lean everywhere in between.
        assert!(clump_profile(0.5, 1.0, n) > clump_profile(0.5, 0.0, n));
    }

    #[test]
    fn clump_displacement_points_away_from_the_centre_and_scales_with_wetness() {
        let clump = ClumpParams {
            w: 0.0,
            strength: 2.0,
        };
        let (p, c) = (Vec2::new(0.52, 0.5), Vec2::new(0.5, 0.5));
        let d = clump_displacement(1.0, 16, clump, 1.0, p, c);
        assert!(d.abs_diff_eq(Vec2::new(0.04, 0.0), 1e-6));
        let half = clump_displacement(1.0, 16, clump, 0.5, p, c);
        assert!(half.abs_diff_eq(0.5 * d, 1e-7));
        assert_eq!(clump_displacement(1.0, 16, clump, 1.0, c, c), Vec2::ZERO);
    }

    #[test]
    fn alg2_draws_dry_fur_as_is_and_discards_other_clumps_and_dry_targets() {
        let clump = ClumpParams {
            w: 0.0,
            strength: 1.0,
        };
        let wet = WetTexel {
            centre: Vec2::new(0.5, 0.5),
            radius: 0.1,
            wetness: 1.0,
        };
        // A mask wet within 0.15 of the centre.
        let mask = |q: Vec2| {
            if q.distance(wet.centre) <= 0.15 {
                wet
            } else {
                WetTexel::default()
            }
        };
        let dry = WetTexel::default();
        assert_eq!(
            clump_fragment(Vec2::new(0.9, 0.9), dry, 1.0, 16, clump, mask),
            ClumpDecision::Dry
        );
        // Inside the clump, target 0.55 + 0.05 = 0.6 … within 0.15: wet.
        match clump_fragment(Vec2::new(0.55, 0.5), wet, 1.0, 16, clump, mask) {
            ClumpDecision::Displaced(d) => assert!(d.abs_diff_eq(Vec2::new(0.05, 0.0), 1e-6)),
            other => panic!("{other:?}"),
        }
        // Target 0.59 + 0.09 = 0.68: dry.
        let far = Vec2::new(0.59, 0.5);
        assert_eq!(
            clump_fragment(far, wet, 1.0, 16, clump, mask),
            ClumpDecision::DryTarget
        );
        // A texel naming this clump but 0.12 from its centre (radius 0.1).
        assert_eq!(
            clump_fragment(Vec2::new(0.62, 0.5), wet, 1.0, 16, clump, mask),
            ClumpDecision::DifferentClump
        );
    }

    #[test]
    fn shadow_factor_darkens_towards_the_skin() {
        assert_eq!(shadow_factor(1.0, 4.0), 1.0);
        assert_eq!(shadow_factor(0.0, 4.0), 0.75);
        assert_eq!(shadow_factor(0.0, 1.0), 0.0);
        assert_eq!(shadow_factor(0.5, 1.0), 0.5);
    }

    #[test]
    fn kajiya_kay_matches_the_formula_on_known_angles() {
        let k = KajiyaKay {
            specular: Vec3::splat(0.5),
            exponent: 2.0,
            k_shadow: 2.0,
        };
        let color = Vec3::new(0.8, 0.4, 0.2);
        // Light perpendicular to the strand: full diffuse.
        let t = Vec3::Y;
        let (l, e) = (Vec3::X, Vec3::X);
        let c = kajiya_kay(color, t, l, e, 1.0, k);
        // (T·L)(T·E) + |T×L||T×E| = 0 + 1 → specular 0.5.
        assert!(c.abs_diff_eq(color + Vec3::splat(0.5), 1e-6));
        // Light along the strand: no diffuse; eye opposite → base −1 → 0.
        let c = kajiya_kay(color, t, Vec3::Y, -Vec3::Y, 1.0, k);
        assert!(c.abs_diff_eq(Vec3::ZERO, 1e-6));
        // 45°: |T×L| = √½; eye = light: base = ½ + ½ = 1; γ(0.5) = 0.75.
        let l = Vec3::new(1.0, 1.0, 0.0).normalize();
        let c = kajiya_kay(color, t, l, l, 0.5, k);
        let expected = 0.75 * (color * 0.5f32.sqrt() + Vec3::splat(0.5));
        assert!(c.abs_diff_eq(expected, 1e-5), "{c} vs {expected}");
    }
}
