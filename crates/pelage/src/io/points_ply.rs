//! Points on a mesh as a binary little-endian PLY: a `vertex` element with
//! `x y z`, `nx ny nz`, `s t` (when the mesh has UVs) and `triangle` (the
//! mesh triangle each point lies on). Blender, MeshLab and Houdini read it
//! as a point cloud.

use super::{WriteError, write_atomically};
use crate::mesh::{Mesh, SurfacePoint};
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

/// Streams points into a PLY whose point count is known up front.
pub struct PointsPly<'a, W: Write> {
    mesh: &'a Mesh,
    out: W,
    buffer: Vec<u8>,
}

impl<'a, W: Write> PointsPly<'a, W> {
    /// Writes the header for `count` points of `mesh`.
    pub fn new(mesh: &'a Mesh, count: u64, mut out: W) -> std::io::Result<Self> {
        let uv = if mesh.has_uvs() {
            "property float s\nproperty float t\n"
        } else {
            ""
        };
        write!(
            out,
            "ply\nformat binary_little_endian 1.0\ncomment pelage points on {}\nelement vertex {count}\n\
             property float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n{uv}\
             property uint triangle\nend_header\n",
            mesh.name().replace('\n', " ")
        )?;
        Ok(Self {
            mesh,
            out,
            buffer: Vec::new(),
        })
    }

    /// Appends points (any number of calls, in order). Attributes are
    /// evaluated and encoded in parallel; the bytes do not depend on the
    /// number of threads.
    pub fn write(&mut self, points: &[SurfacePoint]) -> std::io::Result<()> {
        let stride = if self.mesh.has_uvs() { 36 } else { 28 };
        self.buffer.resize(points.len() * stride, 0);
        let mesh = self.mesh;
        self.buffer
            .par_chunks_mut(stride * 4096)
            .zip(points.par_chunks(4096))
            .for_each(|(bytes, points)| {
                for (record, p) in bytes.chunks_exact_mut(stride).zip(points) {
                    let mut fields = p
                        .position(mesh)
                        .to_array()
                        .into_iter()
                        .chain(p.normal(mesh).to_array());
                    let uv = p.uv(mesh).map(|uv| uv.to_array());
                    let mut at = 0;
                    let mut put = |b: [u8; 4]| {
                        record[at..at + 4].copy_from_slice(&b);
                        at += 4;
                    };
                    fields.by_ref().for_each(|v| put(v.to_le_bytes()));
                    if let Some([u, v]) = uv {
                        put(u.to_le_bytes());
                        put(v.to_le_bytes());
                    }
                    put(p.tri.to_le_bytes());
                }
            });
        self.out.write_all(&self.buffer)
    }

    /// The writer, for flushing.
    pub fn into_inner(self) -> W {
        self.out
    }
}

/// Writes `points` of `mesh` to `path` atomically.
pub fn write_points_ply(
    path: &Path,
    mesh: &Mesh,
    points: &[SurfacePoint],
) -> Result<(), WriteError> {
    write_atomically(path, |out| {
        let mut ply = PointsPly::new(mesh, points.len() as u64, out)?;
        ply.write(points)
    })
}

/// Reads the positions of a PLY point cloud (a `vertex` element with
/// `x y z`; faces, if any, are ignored). Errors name the file and the
/// line or vertex.
pub fn read_points_ply(path: &Path) -> Result<Vec<glam::Vec3>, crate::MeshError> {
    use crate::mesh::MeshErrorKind;
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::DefaultElement;
    let name = path.display().to_string();
    let bytes =
        std::fs::read(path).map_err(|e| crate::MeshError::whole(&name, MeshErrorKind::Io(e)))?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| {
            let kind = MeshErrorKind::Syntax(format!("not a readable PLY file: {e}"));
            crate::MeshError::whole(&name, kind)
        })?;
    let vertices = ply.payload.get("vertex").ok_or_else(|| {
        crate::MeshError::whole(
            &name,
            MeshErrorKind::Inconsistent("the file has no 'vertex' element".into()),
        )
    })?;
    vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let get = |k: &str| crate::mesh::ply_scalar(v.get(k));
            match (get("x"), get("y"), get("z")) {
                (Some(x), Some(y), Some(z)) if x.is_finite() && y.is_finite() && z.is_finite() => {
                    Ok(glam::Vec3::new(x, y, z))
                }
                _ => Err(crate::MeshError::at_element(
                    &name,
                    "vertex",
                    i,
                    MeshErrorKind::Syntax("x, y and z must be finite numbers".into()),
                )),
            }
        })
        .collect()
}

/// Whether a PLY file describes a mesh (it has faces) rather than points
/// or curves.
pub fn ply_has_faces(path: &Path) -> std::io::Result<bool> {
    Ok(ply_element_count(path, "face")? > 0)
}

/// The count a PLY header declares for `element` (0 when it declares
/// none), read from the header alone.
pub fn ply_element_count(path: &Path, element: &str) -> std::io::Result<u64> {
    use std::io::BufRead;
    let file = std::io::BufReader::new(std::fs::File::open(path)?);
    let prefix = format!("element {element} ");
    for line in file.split(b'\n') {
        let line = line?;
        if line.starts_with(b"end_header") {
            break;
        }
        if let Some(rest) = line.strip_prefix(prefix.as_bytes()) {
            return Ok(std::str::from_utf8(rest)
                .ok()
                .and_then(|n| n.trim().parse::<u64>().ok())
                .unwrap_or(0));
        }
    }
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};

    #[test]
    fn written_points_read_back_with_their_attributes() {
        let spot = crate::assets::spot();
        let points: Vec<SurfacePoint> = (0..100)
            .map(|i| SurfacePoint::new(i * 37, [0.25, 0.5]))
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("points.ply");
        write_points_ply(&path, &spot, &points).unwrap();

        let ply = Parser::<DefaultElement>::new()
            .read_ply(&mut std::fs::File::open(&path).unwrap())
            .unwrap();
        let vertices = &ply.payload["vertex"];
        assert_eq!(vertices.len(), 100);
        let float = |v: &DefaultElement, k: &str| match v[k] {
            Property::Float(x) => x,
            _ => panic!("{k} is not a float"),
        };
        let read = read_points_ply(&path).unwrap();
        assert_eq!(read.len(), 100);
        assert!(!ply_has_faces(&path).unwrap());
        for (p, v) in points.iter().zip(vertices) {
            let position = p.position(&spot);
            assert_eq!(
                [float(v, "x"), float(v, "y"), float(v, "z")],
                position.to_array()
            );
            assert_eq!(
                [float(v, "s"), float(v, "t")],
                p.uv(&spot).unwrap().to_array()
            );
            assert!(matches!(v["triangle"], Property::UInt(t) if t == p.tri));
        }
    }
}
