//! USD text (usda) output: one `UsdGeomBasisCurves` prim per part under a
//! default prim, optionally the skin as a `UsdGeomMesh` beside them.
//!
//! The writer streams: the header is written at once, each part is written
//! when it arrives, and large arrays are formatted in parallel blocks of a
//! bounded size, so the text of a groom is never held whole in memory. The
//! bytes do not depend on the number of threads.
//!
//! The attributes themselves come from `usd_schema`, shared with the usdc
//! writer.

use super::hair_material::{MATERIAL_NAME, NetworkPrim, NetworkValue, hair_material};
use super::text::{put_f32, put_tuple2, put_tuple3, put_u64};
use super::usd_options::{PrimWriteError, UpAxis, UsdOptions, check_name};
use super::usd_schema::{
    PrimWriter, SurfacePoints, UsdAttribute, UsdValues, basis_curves_attributes,
    binds_hair_material, guide_curves_attributes, mesh_attributes, points_attributes,
};
use crate::Curves;
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::collections::HashSet;
use std::io::Write;

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
    /// Whether the hair material is written (before the first part bound
    /// to it).
    material_written: bool,
}

impl<W: Write> UsdaWriter<W> {
    /// Writes the stage metadata and opens the default prim.
    pub fn new(mut out: W, options: &UsdOptions) -> Result<Self, PrimWriteError> {
        options.check()?;
        let up = match options.up_axis {
            UpAxis::Y => "Y",
            UpAxis::Z => "Z",
        };
        write!(
            out,
            "#usda 1.0\n(\n    defaultPrim = \"{root}\"\n    doc = \"{doc}\"\n    \
             metersPerUnit = {mpu}\n    upAxis = \"{up}\"\n)\n\ndef Xform \"{root}\"\n{{\n",
            root = options.root,
            doc = options
                .documentation
                .clone()
                .unwrap_or_else(|| format!("Written by pelage {}", env!("CARGO_PKG_VERSION"))),
            mpu = ryu::Buffer::new().format(options.meters_per_unit),
        )?;
        Ok(Self {
            out,
            options: options.clone(),
            names: HashSet::new(),
            material_written: false,
        })
    }

    fn claim(&mut self, name: &str) -> Result<(), PrimWriteError> {
        check_name(name)?;
        if !self.names.insert(name.to_string()) {
            return Err(PrimWriteError::DuplicateName(name.to_string()));
        }
        Ok(())
    }

    /// Writes one part as a `BasisCurves` prim named `name`.
    pub fn write_part(&mut self, name: &str, curves: &Curves) -> Result<(), PrimWriteError> {
        let attributes = basis_curves_attributes(name, curves, &self.options)?;
        let bound = binds_hair_material(&self.options);
        if bound && !self.material_written {
            self.claim(MATERIAL_NAME)?;
            let path = format!("/{}/{MATERIAL_NAME}", self.options.root);
            write_network(&mut self.out, &hair_material(), 1, &path)?;
            self.material_written = true;
        }
        self.write_prim_bound("BasisCurves", name, &attributes, bound)
    }

    /// Writes the groom's guides as a `BasisCurves` prim named `name` with
    /// `purpose = "guide"`.
    pub fn write_guides(&mut self, name: &str, guides: &Curves) -> Result<(), PrimWriteError> {
        let attributes = guide_curves_attributes(name, guides, &self.options)?;
        self.write_prim("BasisCurves", name, &attributes)
    }

    /// Writes sampled surface points as a `Points` prim named `name`.
    pub fn write_points(
        &mut self,
        name: &str,
        points: &SurfacePoints,
    ) -> Result<(), PrimWriteError> {
        self.write_prim("Points", name, &points_attributes(points))
    }

    /// Writes the skin as a `Mesh` prim named `name` (triangles, vertex
    /// normals, UVs as `st`), so the file opens complete in usdview or
    /// Blender.
    pub fn write_mesh(&mut self, name: &str, mesh: &Mesh) -> Result<(), PrimWriteError> {
        self.write_prim("Mesh", name, &mesh_attributes(mesh))
    }

    fn write_prim(
        &mut self,
        type_name: &str,
        name: &str,
        attributes: &[UsdAttribute],
    ) -> Result<(), PrimWriteError> {
        self.write_prim_bound(type_name, name, attributes, false)
    }

    /// [`Self::write_prim`], `bound` to the hair material or not.
    fn write_prim_bound(
        &mut self,
        type_name: &str,
        name: &str,
        attributes: &[UsdAttribute],
        bound: bool,
    ) -> Result<(), PrimWriteError> {
        self.claim(name)?;
        let out = &mut self.out;
        if bound {
            writeln!(
                out,
                "    def {type_name} \"{name}\" (\n        prepend apiSchemas = [\"MaterialBindingAPI\"]\n    )\n    {{"
            )?;
        } else {
            writeln!(out, "    def {type_name} \"{name}\"\n    {{")?;
        }
        for attribute in attributes {
            write_attribute(out, attribute)?;
        }
        if bound {
            let root = &self.options.root;
            writeln!(
                out,
                "        rel material:binding = </{root}/{MATERIAL_NAME}>"
            )?;
        }
        writeln!(out, "    }}")?;
        Ok(())
    }

    /// Closes the default prim and returns the output (not flushed).
    pub fn finish(mut self) -> Result<W, PrimWriteError> {
        writeln!(self.out, "}}")?;
        Ok(self.out)
    }
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

impl<W: Write> PrimWriter for UsdaWriter<W> {
    fn write_guides(&mut self, name: &str, guides: &Curves) -> Result<(), PrimWriteError> {
        UsdaWriter::write_guides(self, name, guides)
    }

    fn write_part(&mut self, name: &str, curves: &Curves) -> Result<(), PrimWriteError> {
        UsdaWriter::write_part(self, name, curves)
    }

    fn write_mesh(&mut self, name: &str, mesh: &Mesh) -> Result<(), PrimWriteError> {
        UsdaWriter::write_mesh(self, name, mesh)
    }

    fn write_points(&mut self, name: &str, points: &SurfacePoints) -> Result<(), PrimWriteError> {
        UsdaWriter::write_points(self, name, points)
    }
}

/// Writes one attribute line: a token, or an array with its
/// interpolation.
fn write_attribute(out: &mut impl Write, attribute: &UsdAttribute) -> std::io::Result<()> {
    let variability = if attribute.uniform { "uniform " } else { "" };
    let decl = format!("{variability}{} {}", attribute.type_name, attribute.name);
    let interpolation = attribute.interpolation;
    match &attribute.values {
        UsdValues::Token(token) => writeln!(out, "        {decl} = \"{token}\""),
        UsdValues::Ints(ints) => write_array(out, &decl, ints, interpolation, |n, s| {
            put_u64(*n as u64, s)
        }),
        UsdValues::Int64s(ints) => {
            write_array(out, &decl, ints, interpolation, |n, s| put_u64(*n, s))
        }
        UsdValues::Floats(floats) => {
            write_array(out, &decl, floats, interpolation, |v, s| put_f32(*v, s))
        }
        UsdValues::Vec2s(values) => write_array(out, &decl, values, interpolation, put_tuple2),
        UsdValues::Vec3s(values) => write_array(out, &decl, values, interpolation, put_tuple3),
    }
}

/// Writes a network prim and its children at `depth` levels of indent;
/// connections name shaders under `material` (the material's path).
fn write_network(
    out: &mut impl Write,
    prim: &NetworkPrim,
    depth: usize,
    material: &str,
) -> std::io::Result<()> {
    let indent = "    ".repeat(depth);
    writeln!(
        out,
        "{indent}def {} \"{}\"\n{indent}{{",
        prim.type_name, prim.name
    )?;
    for a in &prim.attributes {
        let variability = if a.uniform { "uniform " } else { "" };
        let decl = format!("{indent}    {variability}{} {}", a.type_name, a.name);
        let mut text = Vec::new();
        match a.value {
            NetworkValue::Declared => {}
            NetworkValue::Token(t) | NetworkValue::Text(t) => {
                text.extend_from_slice(format!(" = \"{t}\"").as_bytes())
            }
            NetworkValue::Float(v) => {
                text.extend_from_slice(b" = ");
                put_f32(v, &mut text);
            }
            NetworkValue::Color(c) => {
                text.extend_from_slice(b" = ");
                put_tuple3(&c, &mut text);
            }
            NetworkValue::Connect(shader, output) => text
                .extend_from_slice(format!(".connect = <{material}/{shader}.{output}>").as_bytes()),
        }
        out.write_all(decl.as_bytes())?;
        out.write_all(&text)?;
        writeln!(out)?;
    }
    for child in &prim.children {
        write_network(out, child, depth + 1, material)?;
    }
    writeln!(out, "{indent}}}")
}

/// `path` as a USD asset path in text USD: `@path@`, or where the path
/// holds an `@` (a legal file name character), USD's escaped form
/// `@@@path@@@`, so that a reader does not end the path at its `@`.
pub(crate) fn asset_path(path: &str) -> String {
    if path.contains('@') {
        format!("@@@{path}@@@")
    } else {
        format!("@{path}@")
    }
}
