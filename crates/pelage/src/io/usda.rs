//! USD text (usda) output: one `UsdGeomBasisCurves` prim per part under a
//! default prim, optionally the skin as a `UsdGeomMesh` beside them.
//!
//! The writer streams: the header is written at once, each part is written
//! when it arrives, and large arrays are formatted in parallel blocks of a
//! bounded size, so the text of a groom is never held whole in memory. The
//! bytes do not depend on the number of threads.
//!
//! What each attribute means and how many values it needs follows the
//! `UsdGeomBasisCurves` schema: `widths`, `normals`, `displayColor` and
//! `displayOpacity` are per point (`vertex`), the root UV (`st`) and the
//! hair id are per curve (`uniform`), and every prim has an `extent`
//! padded by half the widest hair, as `UsdGeomCurves::ComputeExtent` does.
//! docs/curves-io.md says why pelage writes usda itself rather than usdc.

use super::text::{put_f32, put_tuple2, put_tuple3, put_u64};
use crate::Curves;
use crate::mesh::{Mesh, Uvs};
use glam::Vec3;
use rayon::prelude::*;
use std::collections::HashSet;
use std::io::Write;

/// How the points of each curve are interpolated (USD `type` + `basis`);
/// `linear` or `catmull-rom` in groom files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CurveBasis {
    /// Straight segments between the points.
    Linear,
    /// A cubic Catmull-Rom spline through the points (also spelled
    /// `catmullRom`, as USD does).
    #[default]
    #[serde(alias = "catmullRom")]
    CatmullRom,
}

/// How curve ends are treated (USD `wrap`; only meaningful for cubic
/// curves).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UsdWrap {
    /// The spline passes through the first and last points (USD adds
    /// phantom end points). Blender writes and reads this.
    #[default]
    Pinned,
    /// The first and last points only steer the ends; a curve needs at
    /// least four points.
    Nonperiodic,
}

/// The stage's up axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// Y up (Maya, Houdini, USD's default).
    #[default]
    Y,
    /// Z up (Blender).
    Z,
}

/// Stage-wide choices of a USD file.
#[derive(Debug, Clone, PartialEq)]
pub struct UsdOptions {
    /// Curve interpolation.
    pub basis: CurveBasis,
    /// End treatment of cubic curves.
    pub wrap: UsdWrap,
    /// `upAxis` stage metadata.
    pub up_axis: UpAxis,
    /// `metersPerUnit` stage metadata.
    pub meters_per_unit: f64,
    /// Name of the default prim (an `Xform`) holding the parts.
    pub root: String,
}

impl Default for UsdOptions {
    fn default() -> Self {
        Self {
            basis: CurveBasis::default(),
            wrap: UsdWrap::default(),
            up_axis: UpAxis::default(),
            meters_per_unit: 1.0,
            root: "groom".into(),
        }
    }
}

impl UsdOptions {
    /// The fewest points a curve may have under these options.
    pub fn min_points_per_curve(&self) -> usize {
        match (self.basis, self.wrap) {
            (CurveBasis::Linear, _) | (CurveBasis::CatmullRom, UsdWrap::Pinned) => 2,
            (CurveBasis::CatmullRom, UsdWrap::Nonperiodic) => 4,
        }
    }
}

/// A part or mesh could not be written as USD.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum UsdWriteError {
    /// Writing failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A prim name USD does not accept.
    #[error(
        "{0:?} is not a valid USD prim name (letters, digits and '_', not starting with a digit)"
    )]
    BadName(String),
    /// Two prims with one name.
    #[error("a prim named {0:?} was already written")]
    DuplicateName(String),
    /// A curve too short for the basis.
    #[error(
        "part {part:?}: curve {curve} has {points} points; {basis} curves need at least {min} (use linear curves or resample)"
    )]
    ShortCurve {
        /// The part.
        part: String,
        /// The curve's index in the part.
        curve: usize,
        /// Its point count.
        points: usize,
        /// What the basis needs.
        min: usize,
        /// The basis and wrap, in words.
        basis: &'static str,
    },
}

/// Values per formatted block: large enough to keep two threads busy,
/// small enough that a window of blocks stays a few tens of megabytes.
const BLOCK: usize = 1 << 14;
/// Blocks formatted at once before they are written.
const WINDOW: usize = 64;

/// Streams a usda file: [`UsdaWriter::new`], then any number of
/// [`write_part`](Self::write_part) / [`write_mesh`](Self::write_mesh),
/// then [`finish`](Self::finish).
pub struct UsdaWriter<W: Write> {
    out: W,
    options: UsdOptions,
    names: HashSet<String>,
}

impl<W: Write> UsdaWriter<W> {
    /// Writes the stage metadata and opens the default prim.
    pub fn new(mut out: W, options: &UsdOptions) -> Result<Self, UsdWriteError> {
        check_name(&options.root)?;
        let up = match options.up_axis {
            UpAxis::Y => "Y",
            UpAxis::Z => "Z",
        };
        write!(
            out,
            "#usda 1.0\n(\n    defaultPrim = \"{root}\"\n    doc = \"Written by pelage {version}\"\n    \
             metersPerUnit = {mpu}\n    upAxis = \"{up}\"\n)\n\ndef Xform \"{root}\"\n{{\n",
            root = options.root,
            version = env!("CARGO_PKG_VERSION"),
            mpu = ryu::Buffer::new().format(options.meters_per_unit),
        )?;
        Ok(Self {
            out,
            options: options.clone(),
            names: HashSet::new(),
        })
    }

    fn claim(&mut self, name: &str) -> Result<(), UsdWriteError> {
        check_name(name)?;
        if !self.names.insert(name.to_string()) {
            return Err(UsdWriteError::DuplicateName(name.to_string()));
        }
        Ok(())
    }

    /// Writes one part as a `BasisCurves` prim named `name`.
    pub fn write_part(&mut self, name: &str, curves: &Curves) -> Result<(), UsdWriteError> {
        let min = self.options.min_points_per_curve();
        if let Some(curve) = (0..curves.curve_count()).find(|&i| curves.range(i).len() < min) {
            return Err(UsdWriteError::ShortCurve {
                part: name.to_string(),
                curve,
                points: curves.range(curve).len(),
                min,
                basis: match (self.options.basis, self.options.wrap) {
                    (CurveBasis::Linear, _) => "linear",
                    (CurveBasis::CatmullRom, UsdWrap::Pinned) => "pinned Catmull-Rom",
                    (CurveBasis::CatmullRom, UsdWrap::Nonperiodic) => "nonperiodic Catmull-Rom",
                },
            });
        }
        self.claim(name)?;
        let out = &mut self.out;
        writeln!(out, "    def BasisCurves \"{name}\"\n    {{")?;
        match self.options.basis {
            CurveBasis::Linear => writeln!(out, "        uniform token type = \"linear\"")?,
            CurveBasis::CatmullRom => {
                let wrap = match self.options.wrap {
                    UsdWrap::Pinned => "pinned",
                    UsdWrap::Nonperiodic => "nonperiodic",
                };
                writeln!(
                    out,
                    "        uniform token type = \"cubic\"\n        uniform token basis = \"catmullRom\"\n        \
                     uniform token wrap = \"{wrap}\""
                )?;
            }
        }
        let counts: Vec<u32> = curves.offsets().windows(2).map(|w| w[1] - w[0]).collect();
        write_array(out, "int[] curveVertexCounts", &counts, None, |n, s| {
            put_u64(*n as u64, s)
        })?;
        write_array(out, "point3f[] points", curves.points(), None, put_tuple3)?;
        let (lo, hi) = curve_extent(curves);
        write_array(out, "float3[] extent", &[lo, hi], None, put_tuple3)?;
        write_array(
            out,
            "float[] widths",
            curves.widths(),
            Some("vertex"),
            |w, s| put_f32(*w, s),
        )?;
        if let Some(normals) = curves.normals() {
            write_array(
                out,
                "normal3f[] normals",
                normals,
                Some("vertex"),
                put_tuple3,
            )?;
        }
        if let Some(colors) = curves.colors() {
            let decl = "color3f[] primvars:displayColor";
            write_array(out, decl, colors, Some("vertex"), put_tuple3)?;
        }
        if let Some(opacities) = curves.opacities() {
            let decl = "float[] primvars:displayOpacity";
            write_array(out, decl, opacities, Some("vertex"), |o, s| put_f32(*o, s))?;
        }
        if let Some(uvs) = curves.root_uvs() {
            write_array(
                out,
                "texCoord2f[] primvars:st",
                uvs,
                Some("uniform"),
                put_tuple2,
            )?;
        }
        if let Some(ids) = curves.ids() {
            // int is what Blender and Houdini read; larger ids need int64.
            let decl = if ids.iter().all(|&id| id <= i32::MAX as u64) {
                "int[] primvars:hair_id"
            } else {
                "int64[] primvars:hair_id"
            };
            write_array(out, decl, ids, Some("uniform"), |id, s| put_u64(*id, s))?;
        }
        writeln!(out, "    }}")?;
        Ok(())
    }

    /// Writes the skin as a `Mesh` prim named `name` (triangles, vertex
    /// normals, UVs as `st`), so the file opens complete in usdview or
    /// Blender.
    pub fn write_mesh(&mut self, name: &str, mesh: &Mesh) -> Result<(), UsdWriteError> {
        self.claim(name)?;
        let out = &mut self.out;
        writeln!(
            out,
            "    def Mesh \"{name}\"\n    {{\n        uniform token subdivisionScheme = \"none\""
        )?;
        let (lo, hi) = mesh.bounds();
        write_array(out, "float3[] extent", &[lo, hi], None, put_tuple3)?;
        let threes = vec![3u32; mesh.triangle_count()];
        write_array(out, "int[] faceVertexCounts", &threes, None, |n, s| {
            put_u64(*n as u64, s)
        })?;
        write_array(
            out,
            "int[] faceVertexIndices",
            mesh.triangles(),
            None,
            put_u32x3,
        )?;
        write_array(out, "point3f[] points", mesh.positions(), None, put_tuple3)?;
        let normals = mesh.normals();
        write_array(
            out,
            "normal3f[] normals",
            normals,
            Some("vertex"),
            put_tuple3,
        )?;
        match mesh.uvs() {
            None => {}
            Some(Uvs::PerVertex(uvs)) => {
                write_array(
                    out,
                    "texCoord2f[] primvars:st",
                    uvs,
                    Some("vertex"),
                    put_tuple2,
                )?;
            }
            Some(Uvs::PerCorner { values, indices }) => {
                let decl = "texCoord2f[] primvars:st";
                write_array(out, decl, values, Some("faceVarying"), put_tuple2)?;
                write_array(out, "int[] primvars:st:indices", indices, None, put_u32x3)?;
            }
        }
        writeln!(out, "    }}")?;
        Ok(())
    }

    /// Closes the default prim and returns the output (not flushed).
    pub fn finish(mut self) -> Result<W, UsdWriteError> {
        writeln!(self.out, "}}")?;
        Ok(self.out)
    }
}

/// USD prim names: an identifier.
fn check_name(name: &str) -> Result<(), UsdWriteError> {
    let mut chars = name.chars();
    let ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(UsdWriteError::BadName(name.to_string()))
    }
}

/// Bounds of the points padded by half the widest width (a hair is a tube
/// of that diameter around its points).
fn curve_extent(curves: &Curves) -> (Vec3, Vec3) {
    let Some((lo, hi)) = curves.bounds() else {
        return (Vec3::ZERO, Vec3::ZERO);
    };
    let pad = curves.widths().iter().fold(0.0f32, |m, &w| m.max(w.abs())) * 0.5;
    (lo - Vec3::splat(pad), hi + Vec3::splat(pad))
}

/// Writes `decl = [v, v, …]`, with an `interpolation` metadata block when
/// given. Values are formatted in parallel blocks, written in order.
fn write_array<T: Sync>(
    out: &mut impl Write,
    decl: &str,
    values: &[T],
    interpolation: Option<&str>,
    put: impl Fn(&T, &mut Vec<u8>) + Sync,
) -> std::io::Result<()> {
    write!(out, "        {decl} = [")?;
    let blocks: Vec<&[T]> = values.chunks(BLOCK).collect();
    for (w, window) in blocks.chunks(WINDOW).enumerate() {
        let texts: Vec<Vec<u8>> = window
            .par_iter()
            .enumerate()
            .map(|(b, block)| {
                let mut s = Vec::with_capacity(block.len() * 16);
                for (k, v) in block.iter().enumerate() {
                    if w + b + k > 0 {
                        s.extend_from_slice(b", ");
                    }
                    put(v, &mut s);
                }
                s
            })
            .collect();
        for text in texts {
            out.write_all(&text)?;
        }
    }
    match interpolation {
        None => writeln!(out, "]"),
        Some(i) => writeln!(out, "] (\n            interpolation = \"{i}\"\n        )"),
    }
}

fn put_u32x3(t: &[u32; 3], s: &mut Vec<u8>) {
    for (k, i) in t.iter().enumerate() {
        if k > 0 {
            s.extend_from_slice(b", ");
        }
        put_u64(*i as u64, s);
    }
}
