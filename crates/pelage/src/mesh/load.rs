//! Loading meshes from files or bytes, by format.

use super::{Mesh, MeshError, MeshErrorKind};
use std::path::Path;

/// The mesh file formats pelage reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ.
    Obj,
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`).
    Gltf,
    /// USD, text or binary (`.usda`, `.usdc`, `.usd`): every `Mesh` prim,
    /// at its first time sample.
    Usd,
}

impl MeshFormat {
    /// The format a file name's extension names (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Self::Obj),
            "ply" => Some(Self::Ply),
            "gltf" | "glb" => Some(Self::Gltf),
            "usda" | "usdc" | "usd" => Some(Self::Usd),
            _ => None,
        }
    }
}

impl Mesh {
    /// Loads a mesh, choosing the reader by the file's extension. Errors
    /// name the file and, where there is one, the line or element.
    pub fn load(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        crate::io::check_input(path, "a mesh file (.obj, .ply, .gltf, .glb, .usd)")
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
            MeshFormat::Gltf => super::gltf::parse(&name, &bytes, path.parent()),
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
            MeshFormat::Obj => super::obj::parse(name, bytes),
            MeshFormat::Ply => super::ply::parse(name, bytes),
            MeshFormat::Gltf => super::gltf::parse(name, bytes, None),
            MeshFormat::Usd => {
                let path = Path::new(name);
                let skin =
                    crate::io::usd_skin_from_bytes(bytes, path).map_err(|e| usd_error(&e))?;
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
    let skin = crate::io::read_usd_skin(path).map_err(|e| usd_error(&e))?;
    Mesh::new(
        path.display().to_string(),
        skin.positions,
        skin.triangles,
        None,
        skin.uvs,
    )
}

/// A USD reader's error as a mesh error (same file, same place).
pub(crate) fn usd_error(e: &crate::io::CurvesReadError) -> MeshError {
    MeshError::new(
        e.source_name(),
        e.location().clone(),
        MeshErrorKind::Syntax(e.kind().to_string()),
    )
}
