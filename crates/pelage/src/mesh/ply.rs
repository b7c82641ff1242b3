//! PLY reader (ASCII and binary, through ply-rs-bw): a `vertex` element with
//! `x y z`, optional `nx ny nz` and UVs (`s t`, `u v` or
//! `texture_u texture_v`), and a `face` element with a `vertex_indices` (or
//! `vertex_index`) list and an optional per-face `texcoord` list (MeshLab's
//! per-corner UVs). Polygons are fan triangulated.

use super::{Mesh, MeshError, MeshErrorKind, Uvs};
use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

/// Parses a PLY file's bytes. `name` is what errors call the file.
pub(crate) fn parse(name: &str, bytes: &[u8]) -> Result<Mesh, MeshError> {
    let parser = Parser::<DefaultElement>::new();
    let ply = parser
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| parse_error(name, e))?;
    let element = |key: &str| {
        ply.payload.get(key).ok_or_else(|| {
            MeshError::whole(
                name,
                MeshErrorKind::Inconsistent(format!("the file has no '{key}' element")),
            )
        })
    };
    let (vertices, faces) = (element("vertex")?, element("face")?);
    let layout = VertexLayout::of(name, &ply.header.elements["vertex"].properties)?;
    let read = layout.read(name, vertices)?;
    let face_props = &ply.header.elements["face"].properties;
    let (triangles, corner_uvs) = read_faces(name, faces, face_props, read.positions.len())?;
    let uvs = corner_uvs.or(read.uvs.map(Uvs::PerVertex));
    // Zero-length normals in the file (some exporters write them for
    // unused vertices) are replaced by the computed ones.
    let normals = read.normals.map(|file| {
        let computed = super::area_weighted_normals(&read.positions, &triangles);
        file.into_iter()
            .zip(computed)
            .map(|(n, c)| {
                if n.is_finite() {
                    n.try_normalize().unwrap_or(c)
                } else {
                    n
                }
            })
            .collect()
    });
    let mut mesh = Mesh::new(name, read.positions, triangles, normals, uvs)?;
    for ((key, _), values) in layout.attributes.into_iter().zip(read.attributes) {
        mesh = mesh.with_vertex_attribute(key, values)?;
    }
    Ok(mesh)
}

/// A PLY file's paint layers: its vertex count, and every scalar vertex
/// property but positions, normals and UVs, by name.
pub(crate) struct VertexLayers {
    /// Vertices in the file.
    pub count: usize,
    /// Each layer's name and one value a vertex.
    pub layers: Vec<(String, Vec<f32>)>,
}

/// The paint layers of a PLY file; faces are not needed (a layers file
/// may hold vertices alone).
pub(crate) fn vertex_layers(name: &str, bytes: &[u8]) -> Result<VertexLayers, MeshError> {
    let parser = Parser::<DefaultElement>::new();
    let ply = parser
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| parse_error(name, e))?;
    let vertices = ply.payload.get("vertex").ok_or_else(|| {
        MeshError::whole(
            name,
            MeshErrorKind::Inconsistent("the file has no 'vertex' element".into()),
        )
    })?;
    let layout = VertexLayout::of(name, &ply.header.elements["vertex"].properties)?;
    let read = layout.read(name, vertices)?;
    let layers = layout
        .attributes
        .into_iter()
        .map(|(key, _)| key.to_string())
        .zip(read.attributes)
        .collect();
    Ok(VertexLayers {
        count: read.positions.len(),
        layers,
    })
}

/// Which of a `vertex` element's properties pelage reads, and as what.
struct VertexLayout<'a> {
    normals: Option<[&'static str; 3]>,
    uvs: Option<[&'static str; 2]>,
    /// Every other scalar property, with the scale that brings it to a
    /// number (colours stored as bytes or shorts to 0–1).
    attributes: Vec<(&'a str, f32)>,
}

/// A `vertex` element's values.
struct VertexValues {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    attributes: Vec<Vec<f32>>,
}

impl<'a> VertexLayout<'a> {
    fn of(
        name: &str,
        props: &'a ply_rs_bw::ply::KeyMap<ply_rs_bw::ply::PropertyDef>,
    ) -> Result<Self, MeshError> {
        for axis in ["x", "y", "z"] {
            if !props.contains_key(axis) {
                return Err(MeshError::whole(
                    name,
                    MeshErrorKind::Inconsistent(format!(
                        "the 'vertex' element has no '{axis}' property"
                    )),
                ));
            }
        }
        let has = |p: &str| props.contains_key(p);
        let normals = (has("nx") && has("ny") && has("nz")).then_some(["nx", "ny", "nz"]);
        let uvs = [["s", "t"], ["u", "v"], ["texture_u", "texture_v"]]
            .into_iter()
            .find(|[a, b]| has(a) && has(b));
        let mut reserved: Vec<&str> = vec!["x", "y", "z"];
        reserved.extend(normals.iter().flatten());
        reserved.extend(uvs.iter().flatten());
        let attributes = props
            .iter()
            .filter(|(key, _)| !reserved.contains(&key.as_str()))
            .filter_map(|(key, def)| {
                use ply_rs_bw::ply::{PropertyType, ScalarType};
                let PropertyType::Scalar(kind) = &def.data_type else {
                    return None;
                };
                let colour = matches!(key.as_str(), "red" | "green" | "blue" | "alpha");
                let scale = match kind {
                    ScalarType::UChar if colour => 1.0 / 255.0,
                    ScalarType::UShort if colour => 1.0 / 65535.0,
                    _ => 1.0,
                };
                Some((key.as_str(), scale))
            })
            .collect();
        Ok(Self {
            normals,
            uvs,
            attributes,
        })
    }

    /// Every vertex's values, an error naming the vertex where one is not
    /// a number or a position is not finite.
    fn read(&self, name: &str, vertices: &[DefaultElement]) -> Result<VertexValues, MeshError> {
        let n = vertices.len();
        let mut out = VertexValues {
            positions: Vec::with_capacity(n),
            normals: self.normals.map(|_| Vec::with_capacity(n)),
            uvs: self.uvs.map(|_| Vec::with_capacity(n)),
            attributes: vec![Vec::with_capacity(n); self.attributes.len()],
        };
        for (i, v) in vertices.iter().enumerate() {
            let at = |kind| MeshError::at_element(name, "vertex", i, kind);
            let get = |key: &str| scalar(v.get(key)).ok_or_else(|| at(not_a_number(key)));
            let p = Vec3::new(get("x")?, get("y")?, get("z")?);
            if !p.is_finite() {
                return Err(at(MeshErrorKind::NonFinite {
                    what: "vertex position",
                }));
            }
            out.positions.push(p);
            if let (Some(keys), Some(normals)) = (self.normals, out.normals.as_mut()) {
                normals.push(Vec3::new(get(keys[0])?, get(keys[1])?, get(keys[2])?));
            }
            if let (Some([s, t]), Some(uvs)) = (self.uvs, out.uvs.as_mut()) {
                uvs.push(Vec2::new(get(s)?, get(t)?));
            }
            for ((key, scale), values) in self.attributes.iter().zip(&mut out.attributes) {
                values.push(get(key)? * scale);
            }
        }
        Ok(out)
    }
}

/// The faces, fan triangulated, and their per-corner UVs when the element
/// has a `texcoord` list (MeshLab's); errors name the face.
fn read_faces(
    name: &str,
    faces: &[DefaultElement],
    props: &ply_rs_bw::ply::KeyMap<ply_rs_bw::ply::PropertyDef>,
    vertex_count: usize,
) -> Result<(Vec<[u32; 3]>, Option<Uvs>), MeshError> {
    let index_key = ["vertex_indices", "vertex_index"]
        .into_iter()
        .find(|k| props.contains_key(*k))
        .ok_or_else(|| {
            MeshError::whole(
                name,
                MeshErrorKind::Inconsistent(
                    "the 'face' element has no 'vertex_indices' list".into(),
                ),
            )
        })?;
    let corner_uvs = props.contains_key("texcoord");
    let mut triangles = Vec::with_capacity(faces.len() * 2);
    let mut uv_values: Vec<Vec2> = Vec::new();
    let mut uv_indices: Vec<[u32; 3]> = Vec::new();
    for (f, face) in faces.iter().enumerate() {
        let at = |kind| MeshError::at_element(name, "face", f, kind);
        let indices = index_list(face.get(index_key)).ok_or_else(|| {
            at(MeshErrorKind::Syntax(format!(
                "'{index_key}' is not a list of integers"
            )))
        })?;
        if indices.len() < 3 {
            return Err(at(MeshErrorKind::Syntax(format!(
                "a face needs at least 3 vertices, this one has {}",
                indices.len()
            ))));
        }
        let mut resolved = Vec::with_capacity(indices.len());
        for index in indices {
            if index < 0 || index as usize >= vertex_count {
                return Err(at(MeshErrorKind::IndexOutOfRange {
                    what: "vertex",
                    what_plural: "vertices",
                    index,
                    count: vertex_count,
                    hint: "",
                }));
            }
            resolved.push(index as u32);
        }
        let first_uv = uv_values.len() as u32;
        if corner_uvs {
            let coords = float_list(face.get("texcoord"))
                .filter(|c| c.len() == 2 * resolved.len())
                .ok_or_else(|| {
                    at(MeshErrorKind::Syntax(
                        "'texcoord' must hold two numbers per face corner".into(),
                    ))
                })?;
            for pair in coords.chunks_exact(2) {
                let uv = Vec2::new(pair[0], pair[1]);
                if !uv.is_finite() {
                    return Err(at(MeshErrorKind::NonFinite {
                        what: "texture coordinate",
                    }));
                }
                uv_values.push(uv);
            }
        }
        for k in 1..resolved.len() - 1 {
            triangles.push([resolved[0], resolved[k], resolved[k + 1]]);
            if corner_uvs {
                uv_indices.push([first_uv, first_uv + k as u32, first_uv + k as u32 + 1]);
            }
        }
    }
    let uvs = corner_uvs.then_some(Uvs::PerCorner {
        values: uv_values,
        indices: uv_indices,
    });
    Ok((triangles, uvs))
}

fn parse_error(name: &str, e: ply_rs_bw::parser::ParseError) -> MeshError {
    let full = e.to_string();
    // ply-rs prefixes "Line N: " (pelage puts the line after the file name)
    // and quotes the offending line over several lines; make it one line.
    let message = match e.line() {
        Some(line) => full
            .strip_prefix(&format!("Line {line}: "))
            .unwrap_or(&full),
        None => &full,
    };
    let message = message
        .replace("\n'", "'")
        .replace("\n\t", " ")
        .replace('\n', " ");
    // What follows "Error:" is the inner parser's debug dump, not for people.
    let message = match message.find(" Error:") {
        Some(cut) => message[..cut].to_string(),
        None => message,
    };
    if e.kind() == std::io::ErrorKind::UnexpectedEof {
        // Binary bodies have no lines; the message names the element.
        let kind = MeshErrorKind::Inconsistent(format!(
            "the file ends before all the elements its header announces (truncated?): {message}"
        ));
        return MeshError::whole(name, kind);
    }
    let kind = MeshErrorKind::Syntax(format!("not a readable PLY file: {message}"));
    match e.line() {
        Some(line) => MeshError::at_line(name, line, kind),
        None => MeshError::whole(name, kind),
    }
}

fn not_a_number(key: &str) -> MeshErrorKind {
    MeshErrorKind::Syntax(format!("property '{key}' is missing or not a number"))
}

/// A numeric PLY property as f32 (lists and missing properties: `None`).
pub(crate) fn scalar(p: Option<&Property>) -> Option<f32> {
    Some(match p? {
        Property::Char(v) => f32::from(*v),
        Property::UChar(v) => f32::from(*v),
        Property::Short(v) => f32::from(*v),
        Property::UShort(v) => f32::from(*v),
        Property::Int(v) => *v as f32,
        Property::UInt(v) => *v as f32,
        Property::Float(v) => *v,
        Property::Double(v) => *v as f32,
        _ => return None,
    })
}

fn index_list(p: Option<&Property>) -> Option<Vec<i64>> {
    Some(match p? {
        Property::ListChar(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUChar(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListShort(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUShort(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListInt(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUInt(v) => v.iter().map(|&i| i64::from(i)).collect(),
        _ => return None,
    })
}

fn float_list(p: Option<&Property>) -> Option<Vec<f32>> {
    Some(match p? {
        Property::ListFloat(v) => v.clone(),
        Property::ListDouble(v) => v.iter().map(|&x| x as f32).collect(),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII_QUAD: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float s\nproperty float t\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";

    #[test]
    fn ascii_quad_with_vertex_uvs() {
        let m = parse("quad.ply", ASCII_QUAD.as_bytes()).unwrap();
        assert_eq!(m.triangle_count(), 2);
        assert!(matches!(m.uvs(), Some(Uvs::PerVertex(_))));
        assert!((m.surface_area() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn other_vertex_properties_become_attributes_and_colours_are_scaled() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty float density\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 255 0.5\n1 0 0 0 2\n0 1 0 51 1\n3 0 1 2\n";
        let m = parse("painted.ply", text.as_bytes()).unwrap();
        let red = m.vertex_attribute("red").unwrap();
        let expected = [1.0, 0.0, 0.2];
        assert!(
            red.values
                .iter()
                .zip(expected)
                .all(|(a, b)| (a - b).abs() < 1e-6),
            "{:?}",
            red.values
        );
        assert_eq!(
            &m.vertex_attribute("density").unwrap().values[..],
            &[0.5, 2.0, 1.0]
        );
        assert!(m.vertex_attribute("x").is_none());
    }

    #[test]
    fn binary_little_endian_triangle() {
        let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
        for p in [[0f32, 0., 0.], [2., 0., 0.], [0., 2., 0.]] {
            for c in p {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        bytes.push(3);
        for i in [0u32, 1, 2] {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
        let m = parse("tri.ply", &bytes).unwrap();
        assert!((m.surface_area() - 2.0).abs() < 1e-6);
    }
}
