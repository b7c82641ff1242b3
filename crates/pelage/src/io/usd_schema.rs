//! What pelage puts in a USD layer, whatever the encoding: the prims'
//! attributes (name, value type, variability, interpolation, values) for
//! `UsdGeomBasisCurves` and `UsdGeomMesh`. The text writer (usda) and the
//! binary writer (usdc) both walk these lists, so the two files hold the
//! same layer.
//!
//! What each attribute means and how many values it needs follows the
//! `UsdGeomBasisCurves` schema: `widths`, `normals`, `displayColor` and
//! `displayOpacity` are per point (`vertex`), the root UV (`st`), the
//! hair id and the hair-shading values (`hair_melanin`, …) are per curve
//! (`uniform`), and every prim has an `extent`
//! padded by half the widest hair, as `UsdGeomCurves::ComputeExtent` does.

use super::usd_options::{CurveBasis, PrimWriteError, UsdOptions, UsdWrap};
use crate::Curves;
use crate::curves::HairShading;
use crate::mesh::{Mesh, Uvs};
use glam::{Vec2, Vec3};
use std::borrow::Cow;

/// A file being written prim by prim: a USD layer as text ([`UsdaWriter`])
/// or binary ([`UsdcWriter`]), or an Alembic archive ([`AbcWriter`]), so
/// code that streams parts works with any of them.
///
/// [`UsdaWriter`]: super::UsdaWriter
/// [`UsdcWriter`]: super::UsdcWriter
/// [`AbcWriter`]: super::AbcWriter
pub trait PrimWriter {
    /// Writes one part as a `BasisCurves` prim named `name`.
    fn write_part(&mut self, name: &str, curves: &Curves) -> Result<(), PrimWriteError>;
    /// Writes the skin as a `Mesh` prim named `name`.
    fn write_mesh(&mut self, name: &str, mesh: &Mesh) -> Result<(), PrimWriteError>;
    /// Writes sampled surface points as a `Points` prim named `name`.
    fn write_points(&mut self, name: &str, points: &SurfacePoints) -> Result<(), PrimWriteError>;
    /// Writes one frame of an animated part (time code `time`): the first
    /// call for `name` writes the prim, later ones add time samples of
    /// points, normals and extent. Writers without time samples refuse.
    fn write_part_at(
        &mut self,
        name: &str,
        time: f64,
        curves: &Curves,
    ) -> Result<(), PrimWriteError> {
        let _ = (name, time, curves);
        Err(PrimWriteError::BadSetting(
            "this format has no time samples; write animated grooms to .usdc or .abc".into(),
        ))
    }
    /// Writes the groom's guide curves as `name`: in USD a `BasisCurves`
    /// prim with `purpose = "guide"` (drawn by DCCs, skipped by
    /// renderers), in Alembic an `ICurves` object flagged
    /// `groom_guide = 1` (Unreal's groom importer).
    fn write_guides(&mut self, name: &str, guides: &Curves) -> Result<(), PrimWriteError>;
    /// Writes one frame of animated guides (time code `time`), as
    /// [`Self::write_part_at`] does for a part, flagged as
    /// [`Self::write_guides`] flags them. Writers without time samples
    /// refuse.
    fn write_guides_at(
        &mut self,
        name: &str,
        time: f64,
        guides: &Curves,
    ) -> Result<(), PrimWriteError> {
        let _ = (name, time, guides);
        Err(PrimWriteError::BadSetting(
            "this format has no time samples; write animated guides to .usdc or .abc".into(),
        ))
    }
    /// Writes one frame of an animated skin (time code `time`), as
    /// [`Self::write_part_at`] does for curves. Writers without animated
    /// meshes refuse.
    fn write_mesh_at(&mut self, name: &str, time: f64, mesh: &Mesh) -> Result<(), PrimWriteError> {
        let _ = (name, time, mesh);
        Err(PrimWriteError::BadSetting(
            "this format cannot write an animated skin; write it to .usdc".into(),
        ))
    }
}

/// Points sampled on a mesh (`pelage sample`), as a `UsdGeomPoints` prim:
/// positions, surface normals, the surface UV (`st`) where the mesh has
/// UVs and the triangle each lies on (`triangle`), all per point.
pub struct SurfacePoints<'a> {
    /// Positions.
    pub positions: &'a [Vec3],
    /// The surface's normal at each.
    pub normals: &'a [Vec3],
    /// The surface's UV at each, if the mesh has UVs.
    pub uvs: Option<&'a [Vec2]>,
    /// The triangle each lies on.
    pub triangles: &'a [u32],
}

/// The attributes of a `Points` prim of sampled surface points.
pub(crate) fn points_attributes<'a>(points: &SurfacePoints<'a>) -> Vec<UsdAttribute<'a>> {
    let bounds = points
        .positions
        .iter()
        .fold(None, |b: Option<(Vec3, Vec3)>, &p| {
            Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))))
        });
    let (lo, hi) = bounds.unwrap_or((Vec3::ZERO, Vec3::ZERO));
    let mut attributes = vec![
        UsdAttribute::new(
            "points",
            "point3f[]",
            UsdValues::Vec3s(Cow::Borrowed(points.positions)),
        ),
        UsdAttribute::new(
            "extent",
            "float3[]",
            UsdValues::Vec3s(Cow::Owned(vec![lo, hi])),
        ),
        UsdAttribute::new(
            "normals",
            "normal3f[]",
            UsdValues::Vec3s(Cow::Borrowed(points.normals)),
        )
        .interpolated("vertex"),
    ];
    if let Some(uvs) = points.uvs {
        attributes.push(
            UsdAttribute::new("primvars:st", "texCoord2f[]", UsdValues::Vec2s(uvs))
                .interpolated("vertex"),
        );
    }
    attributes.push(
        UsdAttribute::new(
            "primvars:triangle",
            "int[]",
            UsdValues::Ints(Cow::Borrowed(points.triangles)),
        )
        .interpolated("vertex"),
    );
    attributes
}

/// The values of one attribute.
pub(crate) enum UsdValues<'a> {
    /// One token (`uniform token type = "cubic"`).
    Token(&'static str),
    /// `int[]`. Stored unsigned: every writer of these keeps them below
    /// 2³¹ (counts, indices, ids that fit).
    Ints(Cow<'a, [u32]>),
    /// `int64[]` (ids that need more than 31 bits).
    Int64s(&'a [u64]),
    /// `float[]`.
    Floats(&'a [f32]),
    /// `float2[]`-shaped (`texCoord2f[]`).
    Vec2s(&'a [Vec2]),
    /// `float3[]`-shaped (`point3f[]`, `normal3f[]`, `color3f[]`,
    /// `float3[]`).
    Vec3s(Cow<'a, [Vec3]>),
}

/// One attribute of a prim.
pub(crate) struct UsdAttribute<'a> {
    /// The property name (`points`, `primvars:displayColor`).
    pub name: &'static str,
    /// The USD value type name (`point3f[]`, `token`).
    pub type_name: &'static str,
    /// `uniform` variability (does not change over time).
    pub uniform: bool,
    /// The primvar interpolation (`vertex`, `uniform`, `faceVarying`).
    pub interpolation: Option<&'static str>,
    /// The values.
    pub values: UsdValues<'a>,
}

impl<'a> UsdAttribute<'a> {
    fn new(name: &'static str, type_name: &'static str, values: UsdValues<'a>) -> Self {
        Self {
            name,
            type_name,
            uniform: false,
            interpolation: None,
            values,
        }
    }

    fn uniform_token(name: &'static str, value: &'static str) -> Self {
        Self {
            uniform: true,
            ..Self::new(name, "token", UsdValues::Token(value))
        }
    }

    fn interpolated(mut self, interpolation: &'static str) -> Self {
        self.interpolation = Some(interpolation);
        self
    }
}

/// The attributes of a part's `BasisCurves` prim, in the order the files
/// list them. Refuses curves too short for the basis, naming the part.
pub(crate) fn basis_curves_attributes<'a>(
    part: &str,
    curves: &'a Curves,
    options: &UsdOptions,
) -> Result<Vec<UsdAttribute<'a>>, PrimWriteError> {
    check_curve_lengths(part, curves, options)?;
    let mut attributes = Vec::with_capacity(12);
    match options.basis {
        CurveBasis::Linear => attributes.push(UsdAttribute::uniform_token("type", "linear")),
        CurveBasis::CatmullRom => {
            attributes.push(UsdAttribute::uniform_token("type", "cubic"));
            attributes.push(UsdAttribute::uniform_token("basis", "catmullRom"));
            let wrap = match options.wrap {
                UsdWrap::Pinned => "pinned",
                UsdWrap::Nonperiodic => "nonperiodic",
            };
            attributes.push(UsdAttribute::uniform_token("wrap", wrap));
        }
    }
    let counts: Vec<u32> = curves.offsets().windows(2).map(|w| w[1] - w[0]).collect();
    attributes.push(UsdAttribute::new(
        "curveVertexCounts",
        "int[]",
        UsdValues::Ints(Cow::Owned(counts)),
    ));
    attributes.push(UsdAttribute::new(
        "points",
        "point3f[]",
        UsdValues::Vec3s(Cow::Borrowed(curves.points())),
    ));
    let (lo, hi) = curve_extent(curves);
    attributes.push(UsdAttribute::new(
        "extent",
        "float3[]",
        UsdValues::Vec3s(Cow::Owned(vec![lo, hi])),
    ));
    attributes.push(
        UsdAttribute::new("widths", "float[]", UsdValues::Floats(curves.widths()))
            .interpolated("vertex"),
    );
    if let Some(normals) = curves.normals() {
        let values = UsdValues::Vec3s(Cow::Borrowed(normals));
        attributes.push(UsdAttribute::new("normals", "normal3f[]", values).interpolated("vertex"));
    }
    if let Some(velocities) = curves.velocities() {
        // UsdGeomPointBased's velocities: one a point, units a second.
        let values = UsdValues::Vec3s(Cow::Borrowed(velocities));
        attributes.push(UsdAttribute::new("velocities", "vector3f[]", values));
    }
    if let Some(colors) = curves.colors() {
        let values = UsdValues::Vec3s(Cow::Borrowed(colors));
        attributes.push(
            UsdAttribute::new("primvars:displayColor", "color3f[]", values).interpolated("vertex"),
        );
    }
    if let Some(opacities) = curves.opacities() {
        let values = UsdValues::Floats(opacities);
        attributes.push(
            UsdAttribute::new("primvars:displayOpacity", "float[]", values).interpolated("vertex"),
        );
    }
    if let Some(shading) = curves.shading() {
        for ((_, values), name) in shading.floats().into_iter().zip(SHADING_PRIMVARS) {
            attributes.push(
                UsdAttribute::new(name, "float[]", UsdValues::Floats(values))
                    .interpolated("uniform"),
            );
        }
        let tint = UsdValues::Vec3s(Cow::Borrowed(&shading.tint));
        attributes.push(
            UsdAttribute::new("primvars:hair_tint", "color3f[]", tint).interpolated("uniform"),
        );
    } else if binds_hair_material(options) {
        // Bound to the material all the same: one value for the whole
        // prim (constant primvars), the material's defaults, so that
        // every primvar it reads is there.
        static DEFAULTS: [f32; 5] = HairShading::DEFAULTS;
        for (value, name) in DEFAULTS.iter().zip(SHADING_PRIMVARS) {
            let one = UsdValues::Floats(std::slice::from_ref(value));
            attributes.push(UsdAttribute::new(name, "float[]", one).interpolated("constant"));
        }
        let tint = UsdValues::Vec3s(Cow::Owned(vec![Vec3::ONE]));
        attributes.push(
            UsdAttribute::new("primvars:hair_tint", "color3f[]", tint).interpolated("constant"),
        );
    }
    if let Some(uvs) = curves.root_uvs() {
        let values = UsdValues::Vec2s(uvs);
        attributes
            .push(UsdAttribute::new("primvars:st", "texCoord2f[]", values).interpolated("uniform"));
    }
    if let Some(ids) = curves.ids() {
        // int is what Blender and Houdini read; larger ids need int64.
        let attribute = if ids.iter().all(|&id| id <= i32::MAX as u64) {
            let narrow = ids.iter().map(|&id| id as u32).collect();
            UsdAttribute::new(
                "primvars:hair_id",
                "int[]",
                UsdValues::Ints(Cow::Owned(narrow)),
            )
        } else {
            UsdAttribute::new("primvars:hair_id", "int64[]", UsdValues::Int64s(ids))
        };
        attributes.push(attribute.interpolated("uniform"));
    }
    if let Some(regions) = curves.regions() {
        // Regions are few (a parting's sides, face sets): always int.
        let values = UsdValues::Ints(Cow::Borrowed(regions));
        attributes.push(
            UsdAttribute::new("primvars:hair_region", "int[]", values).interpolated("uniform"),
        );
    }
    Ok(attributes)
}

/// The attributes of the guides' `BasisCurves` prim: a part's, with
/// `purpose = "guide"` (DCCs draw them, renderers skip them).
pub(crate) fn guide_curves_attributes<'a>(
    name: &str,
    guides: &'a Curves,
    options: &UsdOptions,
) -> Result<Vec<UsdAttribute<'a>>, PrimWriteError> {
    // Guides are not bound to the hair material: no default primvars.
    let unbound = UsdOptions {
        hair_material: false,
        ..options.clone()
    };
    let mut attributes = basis_curves_attributes(name, guides, &unbound)?;
    attributes.push(UsdAttribute::uniform_token("purpose", "guide"));
    Ok(attributes)
}

/// The primvars of [`crate::curves::HairShading::floats`], in its order:
/// `primvars:` and the attribute's name.
const SHADING_PRIMVARS: [&str; 5] = [
    "primvars:hair_melanin",
    "primvars:hair_melanin_redness",
    "primvars:hair_roughness",
    "primvars:hair_radial_roughness",
    "primvars:hair_random",
];

/// Whether a part's prim is bound to the hair material: whenever the
/// options ask for it. Curves without hair-shading values are shaded by
/// the network's defaults (Cycles' Principled Hair's: a brown of melanin
/// 0.8), not left to a renderer's grey.
pub(crate) fn binds_hair_material(options: &UsdOptions) -> bool {
    options.hair_material
}

/// The attributes of the skin's `Mesh` prim: triangles, vertex normals,
/// UVs as `st` (per vertex, or per corner with their own indices).
pub(crate) fn mesh_attributes(mesh: &Mesh) -> Vec<UsdAttribute<'_>> {
    let (lo, hi) = mesh.bounds();
    let mut attributes = vec![
        UsdAttribute::uniform_token("subdivisionScheme", "none"),
        UsdAttribute::new(
            "extent",
            "float3[]",
            UsdValues::Vec3s(Cow::Owned(vec![lo, hi])),
        ),
        UsdAttribute::new(
            "faceVertexCounts",
            "int[]",
            UsdValues::Ints(Cow::Owned(vec![3u32; mesh.triangle_count()])),
        ),
        UsdAttribute::new(
            "faceVertexIndices",
            "int[]",
            UsdValues::Ints(Cow::Borrowed(mesh.triangles().as_flattened())),
        ),
        UsdAttribute::new(
            "points",
            "point3f[]",
            UsdValues::Vec3s(Cow::Borrowed(mesh.positions())),
        ),
        UsdAttribute::new(
            "normals",
            "normal3f[]",
            UsdValues::Vec3s(Cow::Borrowed(mesh.normals())),
        )
        .interpolated("vertex"),
    ];
    match mesh.uvs() {
        None => {}
        Some(Uvs::PerVertex(uvs)) => attributes.push(
            UsdAttribute::new("primvars:st", "texCoord2f[]", UsdValues::Vec2s(uvs))
                .interpolated("vertex"),
        ),
        Some(Uvs::PerCorner { values, indices }) => {
            attributes.push(
                UsdAttribute::new("primvars:st", "texCoord2f[]", UsdValues::Vec2s(values))
                    .interpolated("faceVarying"),
            );
            attributes.push(UsdAttribute::new(
                "primvars:st:indices",
                "int[]",
                UsdValues::Ints(Cow::Borrowed(indices.as_flattened())),
            ));
        }
    }
    attributes
}

/// Refuses a curve with fewer points than the basis needs.
fn check_curve_lengths(
    part: &str,
    curves: &Curves,
    options: &UsdOptions,
) -> Result<(), PrimWriteError> {
    let min = options.min_points_per_curve();
    match (0..curves.curve_count()).find(|&i| curves.range(i).len() < min) {
        None => Ok(()),
        Some(curve) => Err(PrimWriteError::ShortCurve {
            part: part.to_string(),
            curve,
            points: curves.range(curve).len(),
            min,
            basis: match (options.basis, options.wrap) {
                (CurveBasis::Linear, _) => "linear",
                (CurveBasis::CatmullRom, UsdWrap::Pinned) => "pinned Catmull-Rom",
                (CurveBasis::CatmullRom, UsdWrap::Nonperiodic) => "nonperiodic Catmull-Rom",
            },
        }),
    }
}

/// Bounds of the points padded by half the widest width (a hair is a tube
/// of that diameter around its points).
pub(crate) fn curve_extent(curves: &Curves) -> (Vec3, Vec3) {
    let Some((lo, hi)) = curves.bounds() else {
        return (Vec3::ZERO, Vec3::ZERO);
    };
    let pad = curves.widths().iter().fold(0.0f32, |m, &w| m.max(w.abs())) * 0.5;
    (lo - Vec3::splat(pad), hi + Vec3::splat(pad))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curves::HairShading;

    #[test]
    fn shading_primvars_are_the_attribute_names() {
        let floats = HairShading::default();
        for ((name, _), primvar) in floats.floats().into_iter().zip(SHADING_PRIMVARS) {
            assert_eq!(primvar, format!("primvars:{name}"));
        }
    }
}
