//! Loading meshes from files or bytes, by format: [`Mesh::load`] and
//! [`Mesh::from_bytes`].
//!
//! The parsers of OBJ, PLY and glTF are the mesh layer's own; reading a
//! mesh from USD needs this layer's USD reader. The dispatch by format is
//! therefore written here, above both, so `mesh/` never uses `io/`.

use super::{CurvesReadError, check_input, read_usd_skin, usd_skin_from_bytes};
use crate::mesh::{Mesh, MeshError, MeshErrorKind, MeshFormat, gltf, obj, ply};
use std::path::Path;

impl Mesh {
    /// Loads a mesh, choosing the reader by the file's extension. Errors
    /// name the file and, where there is one, the line or element.
    pub fn load(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        check_input(path, "a mesh file (.obj, .ply, .gltf, .glb, .usd)")
            .map_err(|e| MeshError::whole(&name, MeshErrorKind::Io(e)))?;
        let format = MeshFormat::from_path(path).ok_or_else(|| {
            let extension = path
                .extension()
                .map(|e| e.to_string_lossy().into_owned())
                .unwrap_or_default();
            MeshError::whole(&name, MeshErrorKind::UnknownFormat { extension })
        })?;
        if format == MeshFormat::Usd {
            return read_usd_mesh(path);
        }
        let bytes =
            std::fs::read(path).map_err(|e| MeshError::whole(&name, MeshErrorKind::Io(e)))?;
        match format {
            MeshFormat::Gltf => gltf::parse(&name, &bytes, path.parent()),
            _ => Self::from_bytes(&name, &bytes, format),
        }
    }

    /// Reads a mesh from bytes already in memory (an embedded asset, a
    /// network buffer). `name` is what errors call it. A `.gltf` with
    /// external buffers cannot be read this way; use [`Mesh::load`]. USD
    /// meshes (usda or usdc, by their first bytes) are read at their first
    /// time sample, as [`Mesh::load`] reads them.
    pub fn from_bytes(name: &str, bytes: &[u8], format: MeshFormat) -> Result<Mesh, MeshError> {
        match format {
            MeshFormat::Obj => obj::parse(name, bytes),
            MeshFormat::Ply => ply::parse(name, bytes),
            MeshFormat::Gltf => gltf::parse(name, bytes, None),
            MeshFormat::Usd => {
                let path = Path::new(name);
                let skin = usd_skin_from_bytes(bytes, path).map_err(usd_mesh_error)?;
                Mesh::new(
                    name.to_string(),
                    skin.positions,
                    skin.triangles,
                    None,
                    skin.uvs,
                )
            }
        }
    }
}

/// A USD file's `Mesh` prims as one mesh, at their first time sample.
fn read_usd_mesh(path: &Path) -> Result<Mesh, MeshError> {
    let skin = read_usd_skin(path).map_err(usd_mesh_error)?;
    Mesh::new(
        path.display().to_string(),
        skin.positions,
        skin.triangles,
        None,
        skin.uvs,
    )
}

/// A USD reader's error as a mesh error (same file, same place, its kind
/// kept typed inside).
pub(crate) fn usd_mesh_error(e: CurvesReadError) -> MeshError {
    e.map_kind(|kind| MeshErrorKind::Read(Box::new(kind)))
}
