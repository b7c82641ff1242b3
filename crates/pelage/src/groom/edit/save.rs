//! Saving an editable groom: the guides as a usdc file, the paint layers
//! as a PLY mesh whose vertex properties are the layers, and a groom file
//! that points at both (read back by `[mesh] layers` and `[guides] file`).
//! Each file is written atomically; the groom file last, so a groom file
//! never names files that are not there.

use super::EditableGroom;
use crate::io::{CurvesExport, WriteError, write_atomically, write_curves};
use crate::map::Map;
use crate::settings::SettingsSource;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The files [`EditableGroom::save`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct SavedGroom {
    /// The groom file.
    pub groom: PathBuf,
    /// The guides (usdc).
    pub guides: PathBuf,
    /// The mesh with its paint layers (PLY), when it has any.
    pub layers: Option<PathBuf>,
    /// The mesh itself (OBJ: positions, UVs, normals), when it was not
    /// read from a file the groom file could name (a mesh given as
    /// values).
    pub mesh: Option<PathBuf>,
}

/// Why a groom could not be saved.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SaveError {
    /// A file could not be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// The groom file the session was opened from is not valid TOML any
    /// more (it was read when the session opened; it is read again here).
    #[error("{path}: {message}")]
    Groom {
        /// The groom file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// `NAME.layers.ply` beside the groom file `NAME.toml`.
pub fn layers_file_name(groom: &Path) -> PathBuf {
    sibling(groom, "layers.ply")
}

fn sibling(groom: &Path, suffix: &str) -> PathBuf {
    let stem = groom
        .file_stem()
        .map_or_else(|| "groom".into(), |s| s.to_string_lossy().into_owned());
    groom.with_file_name(format!("{stem}.{suffix}"))
}

impl EditableGroom {
    /// Writes the groom as it is now to `groom_path` (TOML) with its
    /// guides (`NAME.guides.usdc`) and paint layers (`NAME.layers.ply`)
    /// beside it. `original` is the groom file the session was opened
    /// from: every setting is kept from it except the guides, the layers,
    /// and the density and regions maps when they are paint layers. A
    /// relative mesh path is rewritten when the file moves to another
    /// folder, and so are relative image maps (in `[roots]`, the
    /// operators, `[finish]`, `[look]` and `[regions]`) whose file is
    /// there. Without `original`, a groom file of the session's own
    /// settings that groom files can hold is written (mesh, roots,
    /// guides, interpolation by name, regions).
    pub fn save(
        &self,
        groom_path: &Path,
        original: Option<&SettingsSource>,
    ) -> Result<SavedGroom, SaveError> {
        // Every path checked before any file is written: a groom path
        // that names no file left a stray guides file beside it.
        crate::io::check_output(groom_path)?;
        let guides_path = sibling(groom_path, "guides.usdc");
        let layers_path =
            (!self.mesh().vertex_attributes().is_empty()).then(|| layers_file_name(groom_path));
        crate::io::check_output(&guides_path)?;
        if let Some(path) = &layers_path {
            crate::io::check_output(path)?;
        }
        let fail = |message: String| SaveError::Groom {
            path: groom_path.to_path_buf(),
            message,
        };
        // Read before anything is written, and once.
        let mut table: toml::Table = match original {
            Some(source) => source
                .text
                .parse()
                .map_err(|e: toml::de::Error| fail(e.message().to_string()))?,
            None => toml::Table::new(),
        };
        // A mesh given as values has no file for `[mesh] path` to name:
        // it is written beside the groom file.
        let names_its_mesh = table.get("mesh").and_then(|m| m.get("path")).is_some();
        let mesh_name = self.mesh().name();
        let mesh_path = (!names_its_mesh
            && mesh_name != crate::assets::SPOT_NAME
            && !Path::new(mesh_name).is_file())
        .then(|| sibling(groom_path, "mesh.obj"));
        if let Some(path) = &mesh_path {
            crate::io::check_output(path)?;
        }
        let folder = groom_path.parent().unwrap_or(Path::new("."));
        write_curves(
            &guides_path,
            [("guides".to_string(), self.guides().curves())],
            &CurvesExport::default(),
        )?;
        if let Some(path) = &layers_path {
            write_atomically(path, |out| write_layers_ply(out, self.mesh()))?;
        }
        if let Some(path) = &mesh_path {
            write_atomically(path, |out| write_mesh_obj(out, self.mesh()))?;
        }
        let section = |table: &mut toml::Table, name: &str| -> toml::Table {
            match table.remove(name) {
                Some(toml::Value::Table(t)) => t,
                _ => toml::Table::new(),
            }
        };
        let name_of = |p: &Path| {
            p.file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
        };
        // [mesh]: the path as it was, made to work from the new folder.
        let mut mesh = section(&mut table, "mesh");
        let moved = original.is_some_and(|s| !same_folder(s.folder(), folder));
        match (mesh.get("path").and_then(|p| p.as_str()), original) {
            (Some(path), Some(source)) if moved && path != "spot" => {
                let absolute = source.folder().join(path);
                let absolute = absolute.canonicalize().unwrap_or(absolute);
                mesh.insert(
                    "path".into(),
                    absolute.to_string_lossy().into_owned().into(),
                );
            }
            (Some(_), _) => {}
            (None, _) => {
                let path = match &mesh_path {
                    Some(p) => name_of(p),
                    None if mesh_name == crate::assets::SPOT_NAME => "spot".into(),
                    None => Path::new(mesh_name)
                        .canonicalize()
                        .map_or_else(|_| mesh_name.to_string(), |p| p.to_string_lossy().into()),
                };
                mesh.insert("path".into(), path.into());
            }
        }
        match &layers_path {
            Some(p) => mesh.insert("layers".into(), name_of(p).into()),
            None => mesh.remove("layers"),
        };
        // Image maps: their files, named from the new folder.
        if let Some(source) = original.filter(|_| moved) {
            for name in ["roots", "ops", "finish", "look", "regions"] {
                if let Some(value) = table.get_mut(name) {
                    rebase_image_maps(value, source.folder());
                }
            }
        }
        table.insert("mesh".into(), mesh.into());
        // [guides]: the file just written.
        let mut guides = toml::Table::new();
        guides.insert("file".into(), name_of(&guides_path).into());
        guides.insert(
            "points".into(),
            (self.guides().points_per_guide() as i64).into(),
        );
        table.insert("guides".into(), guides.into());
        // [roots]: count and seed as the session has them; the density
        // and its scale when they are paint layers.
        let spec = self.spec();
        let mut roots = section(&mut table, "roots");
        roots.insert("count".into(), (spec.roots.count as i64).into());
        roots.insert("seed".into(), (spec.roots.seed as i64).into());
        if let Map::Vertex(v) = &spec.roots.density {
            roots.insert("density".into(), format!("vertex:{}", v.name).into());
        }
        if let Map::Vertex(v) = &spec.roots.density_scale {
            roots.insert("density_scale".into(), format!("vertex:{}", v.name).into());
        }
        table.insert("roots".into(), roots.into());
        // [regions]: a paint layer's.
        if let Some(regions) = &spec.regions
            && let super::super::RegionSource::Map {
                map: Map::Vertex(v),
                scale,
            } = &regions.source
        {
            let mut section = toml::Table::new();
            section.insert("map".into(), format!("vertex:{}", v.name).into());
            section.insert("scale".into(), f64::from(*scale).into());
            table.insert("regions".into(), section.into());
        }
        let text = format!(
            "# Saved by pelage's groom editor: the guides and paint layers are\n# the files beside this one.\n{}",
            toml::to_string(&table).map_err(|e| fail(e.to_string()))?
        );
        write_atomically(groom_path, |out| out.write_all(text.as_bytes()))?;
        Ok(SavedGroom {
            groom: groom_path.to_path_buf(),
            guides: guides_path,
            layers: layers_path,
            mesh: mesh_path,
        })
    }
}

/// Every image map in `value` (a string, or strings in its tables and
/// arrays) whose relative path names a file in `from` made absolute, so
/// a groom file saved elsewhere still finds it.
fn rebase_image_maps(value: &mut toml::Value, from: &Path) {
    match value {
        toml::Value::String(spec) => {
            if let Some((path, suffixes)) = crate::map::image_path_in_spec(spec)
                && Path::new(path).is_relative()
            {
                let file = from.join(path);
                let tiles = path.contains(crate::map::UDIM_TOKEN);
                if tiles || file.is_file() {
                    let folder = file
                        .parent()
                        .map(|f| f.canonicalize().unwrap_or(f.to_path_buf()));
                    let absolute = match (folder, file.file_name()) {
                        (Some(folder), Some(name)) => folder.join(name),
                        _ => file.clone(),
                    };
                    *spec = format!("{}{suffixes}", absolute.to_string_lossy());
                }
            }
        }
        toml::Value::Array(items) => items.iter_mut().for_each(|v| rebase_image_maps(v, from)),
        toml::Value::Table(table) => table
            .iter_mut()
            .for_each(|(_, v)| rebase_image_maps(v, from)),
        _ => {}
    }
}

fn same_folder(a: &Path, b: &Path) -> bool {
    let canonical = |p: &Path| {
        let p = if p.as_os_str().is_empty() {
            Path::new(".")
        } else {
            p
        };
        p.canonicalize().unwrap_or_else(|_| p.to_path_buf())
    };
    canonical(a) == canonical(b)
}

/// The mesh as an OBJ file: positions, normals and UVs (per vertex or
/// per corner), each triangle's corners `v/vt/vn`, so a mesh given as
/// values loads back as it was.
fn write_mesh_obj(out: &mut impl Write, mesh: &crate::Mesh) -> std::io::Result<()> {
    writeln!(
        out,
        "# Written by pelage: the mesh a hand-groomed file grows on"
    )?;
    for p in mesh.positions() {
        writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for n in mesh.normals() {
        writeln!(out, "vn {} {} {}", n.x, n.y, n.z)?;
    }
    let corner_uvs: Option<Vec<[u32; 3]>> = match mesh.uvs() {
        None => None,
        Some(crate::mesh::Uvs::PerVertex(values)) => {
            for uv in values {
                writeln!(out, "vt {} {}", uv.x, uv.y)?;
            }
            Some(mesh.triangles().to_vec())
        }
        Some(crate::mesh::Uvs::PerCorner { values, indices }) => {
            for uv in values {
                writeln!(out, "vt {} {}", uv.x, uv.y)?;
            }
            Some(indices.clone())
        }
    };
    for (t, tri) in mesh.triangles().iter().enumerate() {
        let corner = |k: usize| match &corner_uvs {
            Some(uv) => format!("{0}/{1}/{0}", tri[k] + 1, uv[t][k] + 1),
            None => format!("{0}//{0}", tri[k] + 1),
        };
        writeln!(out, "f {} {} {}", corner(0), corner(1), corner(2))?;
    }
    Ok(())
}

/// The mesh as a binary PLY with every paint layer as a float vertex
/// property (what `[mesh] layers` reads back).
fn write_layers_ply(out: &mut impl Write, mesh: &crate::Mesh) -> std::io::Result<()> {
    let layers = mesh.vertex_attributes();
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment pelage paint layers\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        mesh.vertex_count()
    );
    for layer in layers {
        header.push_str(&format!("property float {}\n", layer.name));
    }
    header.push_str(&format!(
        "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.triangle_count()
    ));
    out.write_all(header.as_bytes())?;
    let mut row = Vec::with_capacity(12 + 4 * layers.len());
    for (v, p) in mesh.positions().iter().enumerate() {
        row.clear();
        for x in p.to_array() {
            row.extend_from_slice(&x.to_le_bytes());
        }
        for layer in layers {
            row.extend_from_slice(&layer.values[v].to_le_bytes());
        }
        out.write_all(&row)?;
    }
    for t in mesh.triangles() {
        row.clear();
        row.push(3);
        for i in t {
            row.extend_from_slice(&i.to_le_bytes());
        }
        out.write_all(&row)?;
    }
    Ok(())
}
