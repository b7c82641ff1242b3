//! What physically based hair shaders read, one value a hair: the Chiang
//! et al. (2016) hair model's melanin, melanin redness, tint and
//! roughnesses, as Cycles' Principled Hair BSDF, MaterialX's
//! `chiang_hair_bsdf`, Arnold's `standard_hair` and RenderMan's
//! `PxrMarschnerHair` take them, plus a per-hair random number for the
//! shader's own variation.
//!
//! Every renderer gets them under the names in [`HairShading::NAMES`]
//! (USD `uniform` primvars, Blender curve attributes), so one groom drives
//! whichever hair shader a scene binds (docs/curves-io.md, "Hair shading").

use glam::Vec3;

/// Per-curve values for a hair shader, structure of arrays (one value a
/// curve in each).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HairShading {
    /// Melanin, 0 (white) to 1 (black), on Cycles' scale: the pigment
    /// concentration is `−ln(1 − melanin)`.
    pub melanin: Vec<f32>,
    /// The share of pheomelanin (red) in the melanin, 0 to 1.
    pub melanin_redness: Vec<f32>,
    /// A colour the hair is dyed, linear RGB (white: none).
    pub tint: Vec<Vec3>,
    /// Longitudinal roughness, 0 to 1 (how far highlights spread along
    /// the hair).
    pub roughness: Vec<f32>,
    /// Azimuthal (radial) roughness, 0 to 1 (how far light spreads around
    /// the hair).
    pub radial_roughness: Vec<f32>,
    /// A uniform random number in [0, 1) from the hair's id: the same hair
    /// draws the same number in every part, run and preview.
    pub random: Vec<f32>,
}

impl HairShading {
    /// The attribute names every writer uses, in the order of
    /// [`Self::floats`], then the tint's.
    pub const NAMES: [&'static str; 6] = [
        "hair_melanin",
        "hair_melanin_redness",
        "hair_roughness",
        "hair_radial_roughness",
        "hair_random",
        "hair_tint",
    ];

    /// The scalar attributes' names, in the order of [`Self::floats`].
    pub const FLOAT_NAMES: [&'static str; 5] = [
        Self::NAMES[0],
        Self::NAMES[1],
        Self::NAMES[2],
        Self::NAMES[3],
        Self::NAMES[4],
    ];

    /// The tint's attribute name.
    pub const TINT: &'static str = Self::NAMES[5];

    /// The values of hairs nothing shades (no `[look]`, no colours), in
    /// the order of [`Self::FLOAT_NAMES`], with a white tint: Cycles'
    /// Principled Hair defaults (melanin 0.8, redness 1, roughness and
    /// radial roughness 0.3) and a `hair_random` of 0.5. The hair
    /// material reads these where a primvar is missing.
    pub const DEFAULTS: [f32; 5] = [0.8, 1.0, 0.3, 0.3, 0.5];

    /// The values a reader found under [`Self::FLOAT_NAMES`] (in that
    /// order) and [`Self::TINT`]: `None` unless all six are there, as
    /// pelage writes them. The inverse of [`Self::floats`].
    pub fn from_found(floats: [Option<Vec<f32>>; 5], tint: Option<Vec<Vec3>>) -> Option<Self> {
        let [
            melanin,
            melanin_redness,
            roughness,
            radial_roughness,
            random,
        ] = floats;
        Some(Self {
            melanin: melanin?,
            melanin_redness: melanin_redness?,
            tint: tint?,
            roughness: roughness?,
            radial_roughness: radial_roughness?,
            random: random?,
        })
    }

    /// Room for `curves` hairs.
    pub fn with_capacity(curves: usize) -> Self {
        Self {
            melanin: Vec::with_capacity(curves),
            melanin_redness: Vec::with_capacity(curves),
            tint: Vec::with_capacity(curves),
            roughness: Vec::with_capacity(curves),
            radial_roughness: Vec::with_capacity(curves),
            random: Vec::with_capacity(curves),
        }
    }

    /// The number of hairs it holds values for (the melanin's count; the
    /// builders of [`crate::Curves`] check that every array agrees).
    pub fn len(&self) -> usize {
        self.melanin.len()
    }

    /// Whether it holds no hair.
    pub fn is_empty(&self) -> bool {
        self.melanin.is_empty()
    }

    /// The scalar attributes with their names ([`Self::NAMES`] but the
    /// tint).
    pub fn floats(&self) -> [(&'static str, &[f32]); 5] {
        let [a, b, c, d, e] = Self::FLOAT_NAMES;
        [
            (a, &self.melanin),
            (b, &self.melanin_redness),
            (c, &self.roughness),
            (d, &self.radial_roughness),
            (e, &self.random),
        ]
    }

    /// Appends every value of `other`.
    pub fn extend_from(&mut self, other: &HairShading) {
        self.melanin.extend_from_slice(&other.melanin);
        self.melanin_redness
            .extend_from_slice(&other.melanin_redness);
        self.tint.extend_from_slice(&other.tint);
        self.roughness.extend_from_slice(&other.roughness);
        self.radial_roughness
            .extend_from_slice(&other.radial_roughness);
        self.random.extend_from_slice(&other.random);
    }

    /// Appends hair `i` of `other`.
    pub fn push_from(&mut self, other: &HairShading, i: usize) {
        self.melanin.push(other.melanin[i]);
        self.melanin_redness.push(other.melanin_redness[i]);
        self.tint.push(other.tint[i]);
        self.roughness.push(other.roughness[i]);
        self.radial_roughness.push(other.radial_roughness[i]);
        self.random.push(other.random[i]);
    }

    /// The first array whose length is not `curves`, with its length.
    pub(crate) fn mismatch(&self, curves: usize) -> Option<(&'static str, usize)> {
        self.floats()
            .into_iter()
            .map(|(name, values)| (name, values.len()))
            .chain([(Self::TINT, self.tint.len())])
            .find(|&(_, len)| len != curves)
    }

    /// The first value that is not finite: its attribute and hair.
    pub(crate) fn first_non_finite(&self) -> Option<(&'static str, usize)> {
        for (name, values) in self.floats() {
            if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                return Some((name, i));
            }
        }
        let i = self.tint.iter().position(|t| !t.is_finite())?;
        Some((Self::TINT, i))
    }
}
