//! Curves as a PLY polyline set: a `vertex` element (`x y z width`, and
//! `red green blue` floats when the curves have colours) and an `edge`
//! element (`vertex1 vertex2`) joining consecutive points of each curve —
//! what Houdini, MeshLab and Blender's PLY import read as lines.
//!
//! Reading accepts any edge order: chains are followed from each vertex no
//! edge points to. A vertex with two outgoing or two incoming edges (a
//! branch) is an error naming the edge.

use super::read_error::{CurvesReadError, CurvesReadErrorKind as Kind};
use crate::Curves;
use crate::error::Where;
use crate::mesh::ply_scalar;
use glam::Vec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};
use std::io::Write;
use std::path::Path;

/// Writes `curves` as binary little-endian PLY.
pub fn write_curves_ply(out: &mut impl Write, curves: &Curves) -> std::io::Result<()> {
    let color = if curves.colors().is_some() {
        "property float red\nproperty float green\nproperty float blue\n"
    } else {
        ""
    };
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment pelage curves\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nproperty float width\n{color}\
         element edge {}\nproperty int vertex1\nproperty int vertex2\nend_header\n",
        curves.points().len(),
        curves.segment_count()
    )?;
    let mut bytes = Vec::with_capacity(curves.points().len() * 28);
    for (i, (p, w)) in curves.points().iter().zip(curves.widths()).enumerate() {
        let mut values = p.to_array().to_vec();
        values.push(*w);
        if let Some(colors) = curves.colors() {
            values.extend(colors[i].to_array());
        }
        values
            .iter()
            .for_each(|v| bytes.extend_from_slice(&v.to_le_bytes()));
    }
    for c in 0..curves.curve_count() {
        let r = curves.range(c);
        for i in r.start..r.end.saturating_sub(1) {
            bytes.extend_from_slice(&(i as i32).to_le_bytes());
            bytes.extend_from_slice(&(i as i32 + 1).to_le_bytes());
        }
    }
    out.write_all(&bytes)
}

/// Reads curves from a PLY with `vertex` and `edge` elements.
pub fn read_curves_ply(path: &Path) -> Result<Curves, CurvesReadError> {
    let whole = |kind| CurvesReadError::whole(path, kind);
    let bytes = std::fs::read(path).map_err(|e| whole(Kind::Io(e)))?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| whole(Kind::Syntax(format!("not a readable PLY file: {e}"))))?;
    let vertices = ply.payload.get("vertex").ok_or_else(|| {
        whole(Kind::Inconsistent(
            "the file has no 'vertex' element".into(),
        ))
    })?;
    let edges = ply.payload.get("edge").ok_or_else(|| {
        whole(Kind::Inconsistent(
            "the file has no 'edge' element, so it holds no curves".into(),
        ))
    })?;
    let mut points = Vec::with_capacity(vertices.len());
    let mut widths = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let get = |k: &str| ply_scalar(v.get(k));
        match (get("x"), get("y"), get("z")) {
            (Some(x), Some(y), Some(z)) => points.push(Vec3::new(x, y, z)),
            _ => {
                return Err(CurvesReadError::new(
                    path,
                    Where::element("vertex", i),
                    Kind::Syntax("x, y and z must be numbers".into()),
                ));
            }
        }
        widths.push(get("width").unwrap_or(crate::curves::DEFAULT_WIDTH));
    }
    let n = points.len();
    let (mut next, mut has_previous) = (vec![u32::MAX; n], vec![false; n]);
    for (e, edge) in edges.iter().enumerate() {
        let at = |message: String| {
            CurvesReadError::new(path, Where::element("edge", e), Kind::Inconsistent(message))
        };
        let index = |k: &str| match edge.get(k) {
            Some(Property::Int(i)) => Some(*i as i64),
            Some(Property::UInt(i)) => Some(*i as i64),
            Some(Property::Short(i)) => Some(*i as i64),
            Some(Property::UShort(i)) => Some(*i as i64),
            Some(Property::Char(i)) => Some(*i as i64),
            Some(Property::UChar(i)) => Some(*i as i64),
            _ => None,
        };
        let (Some(a), Some(b)) = (index("vertex1"), index("vertex2")) else {
            return Err(at("an edge needs integer 'vertex1' and 'vertex2'".into()));
        };
        for v in [a, b] {
            if v < 0 || v as usize >= n {
                return Err(at(format!(
                    "vertex index {v} is out of range: there are {n} vertices"
                )));
            }
        }
        let (a, b) = (a as usize, b as usize);
        if next[a] != u32::MAX || has_previous[b] || a == b {
            return Err(at(format!(
                "edge {a}–{b} makes a branch or a loop; curves must be simple chains"
            )));
        }
        next[a] = b as u32;
        has_previous[b] = true;
    }
    // Follow each chain from its first point; points on no edge are
    // single-point curves.
    let mut order = Vec::with_capacity(n);
    let mut offsets = vec![0u32];
    for start in (0..n).filter(|&v| !has_previous[v]) {
        let mut v = start as u32;
        while v != u32::MAX {
            order.push(v as usize);
            v = next[v as usize];
        }
        offsets.push(order.len() as u32);
    }
    if order.len() != n {
        return Err(whole(Kind::Inconsistent(format!(
            "{} vertices lie on closed loops of edges; curves must be open chains",
            n - order.len()
        ))));
    }
    let points = order.iter().map(|&i| points[i]).collect();
    let widths = order.iter().map(|&i| widths[i]).collect();
    Curves::new(points, widths, offsets).map_err(|e| whole(e.into()))
}
