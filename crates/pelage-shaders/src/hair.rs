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
