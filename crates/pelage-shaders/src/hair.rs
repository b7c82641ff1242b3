//! Real-time strands' drawing math, without a GPU API: [`MATH_WGSL`] holds
//! the ribbons a hair's points are drawn as (pulled by vertex index,
//! camera-facing, at least a pixel wide with their coverage scaled down)
//! and the hair model they are shaded with (Kajiya-Kay's diffuse and
//! Marschner's R, TRT and TT lobes as games approximate them).
//! pelage-gpu's `hair.wgsl` and pelage-bevy's strand material both call
//! it, each with its own bindings.

/// The ribbon and hair-shading functions in WGSL: pure functions without
/// bindings. pelage-gpu puts them before `hair.wgsl`; Bevy imports them as
/// [`MATH_IMPORT_PATH`].
pub const MATH_WGSL: &str = include_str!("wgsl/hair_math.wgsl");

/// The module path a shader composer (Bevy's naga_oil) imports
/// [`MATH_WGSL`] under.
pub const MATH_IMPORT_PATH: &str = "pelage::hair_math";

use glam::Vec3;

/// How hairs look: the colour of hairs the groom gave none, and the
/// highlights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrandLook {
    /// Colour of hairs without colours (linear RGB).
    pub color: Vec3,
    /// The white highlight's strength (R).
    pub specular: f32,
    /// Longitudinal roughness: the highlights' width (Marschner's β_R,
    /// radians; 0.3 is about 17°).
    pub roughness: f32,
    /// Light through back-lit hair (TT), times the hair's colour.
    pub transmission: f32,
    /// The share of the key light a hair stops where it crosses it (the
    /// rest goes on through, mostly forward): how dark hairs under
    /// others are.
    pub opacity: f32,
}

impl Default for StrandLook {
    fn default() -> Self {
        Self::from_melanin(0.5, 0.3, 0.3)
    }
}

impl StrandLook {
    /// The highlights' longitudinal shift: Marschner's measured α_R,
    /// about −3° (toward the root).
    pub const SHIFT: f32 = -0.05;
    /// TRT's strength.
    pub const TRT: f32 = 0.3;
    /// TT's azimuthal lobe's exponent.
    pub const TRANSMISSION_EXPONENT: f32 = 6.0;
    /// The light every hair gets without the key light, times its colour.
    pub const AMBIENT: f32 = 0.08;

    /// The look of hair with `melanin` and `redness` (0 to 1, as the
    /// groom's `[look]` spells them) and `roughness`: its colour from the
    /// same absorption the offline hair material uses.
    pub fn from_melanin(melanin: f32, redness: f32, roughness: f32) -> Self {
        Self {
            color: pelage::groom::color_of_melanin(melanin, redness, roughness),
            specular: 0.2,
            roughness,
            // Marschner's TT is the strongest lobe of light hair, and
            // absorbed away in dark hair.
            transmission: 4.0 * (1.0 - melanin),
            // The light a hair stops is what it absorbs: most of what
            // light hair scatters goes on forward (Zinke et al. 2008's
            // dual scattering), dark hair absorbs it.
            opacity: 0.1 + 0.7 * melanin,
        }
    }
}

/// Ribbon vertices a hair of `points` points is drawn with: six a
/// segment (two triangles).
pub fn ribbon_vertices(points: u32) -> u32 {
    6 * points.max(2).saturating_sub(1)
}

#[cfg(test)]
mod tests {
    /// The functions parse and validate as a module of their own (no
    /// bindings, nothing undeclared).
    #[test]
    fn the_math_validates_with_naga() {
        let module = naga::front::wgsl::parse_str(super::MATH_WGSL)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(super::MATH_WGSL)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .expect("valid WGSL");
    }
}
