//! `pelage.Mesh`: the surface hair grows on, loaded from a file or built
//! from numpy arrays.

use crate::convert::{floats, rows, vec2s, vec3s, view2};
use crate::to_py_err;
use numpy::PyArray2;
use pelage::mesh::Uvs;
use pelage::{Mesh, MeshError};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::Arc;

/// A triangle mesh: positions, triangles, normals and optional UVs
/// (per vertex or per corner). Immutable; build a new one to change it.
#[pyclass(name = "Mesh", module = "pelage", frozen)]
pub struct PyMesh {
    pub(crate) inner: Arc<Mesh>,
}

#[pymethods]
impl PyMesh {
    /// Loads a mesh file: .obj, .ply (ascii or binary), .gltf, .glb, or a
    /// USD mesh (.usda/.usdc/.usd); `"spot"` is the embedded demo cow.
    /// `subdivide` applies midpoint subdivision that many times (each ×4
    /// triangles).
    #[staticmethod]
    #[pyo3(signature = (path, subdivide = 0))]
    fn load(py: Python<'_>, path: PathBuf, subdivide: u32) -> PyResult<Self> {
        let mesh = py.detach(|| -> Result<Mesh, MeshError> {
            match path.to_str() {
                Some("spot") => Ok(pelage::assets::spot()),
                _ => Mesh::load(&path),
            }
        });
        let mesh = mesh.map_err(to_py_err)?;
        Ok(Self {
            inner: Arc::new(subdivide_checked(py, mesh, subdivide)?),
        })
    }

    /// The embedded demo mesh (Keenan Crane's Spot, with UVs).
    #[staticmethod]
    fn spot() -> Self {
        Self {
            inner: Arc::new(pelage::assets::spot()),
        }
    }

    /// Builds a mesh from arrays: `positions` (n, 3) floats, `triangles`
    /// (m, 3) vertex indices, and optionally `uvs`: (n, 2) per vertex, or
    /// (3m, 2) per corner (three a triangle, in the triangles' order, as
    /// Blender's UV layers are). `normals` (n, 3) when you have them
    /// (computed otherwise). `vertex_maps`: named per-vertex scalars, each
    /// (n,) floats, read by a groom's maps as `"vertex:NAME"` (a DCC's
    /// painted weights). `face_sets` and `materials`: (m,) integers, a set
    /// a triangle (a DCC's face sets, material slots), the regions of
    /// `regions={"faces": "groups"}` and `{"faces": "materials"}`.
    /// Everything is checked: finite values, indices in range, matching
    /// sizes.
    #[staticmethod]
    #[pyo3(signature = (positions, triangles, uvs = None, normals = None, name = "<python mesh>".to_string(), vertex_maps = None, face_sets = None, materials = None))]
    // Python callers pass these by keyword; a struct would only move the list.
    #[allow(clippy::too_many_arguments)]
    fn from_arrays(
        positions: &Bound<'_, PyAny>,
        triangles: &Bound<'_, PyAny>,
        uvs: Option<&Bound<'_, PyAny>>,
        normals: Option<&Bound<'_, PyAny>>,
        name: String,
        vertex_maps: Option<&Bound<'_, pyo3::types::PyDict>>,
        face_sets: Option<&Bound<'_, PyAny>>,
        materials: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let positions = vec3s(rows::<f32, 3>(positions, "positions")?);
        let triangles = triangle_rows(triangles)?;
        let normals = normals
            .map(|n| rows::<f32, 3>(n, "normals").map(vec3s))
            .transpose()?;
        let uvs = match uvs {
            None => None,
            Some(uvs) => {
                let values = vec2s(rows::<f32, 2>(uvs, "uvs")?);
                if values.len() == positions.len() {
                    Some(Uvs::PerVertex(values))
                } else if values.len() == 3 * triangles.len() {
                    let corners = (0..triangles.len() as u32)
                        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                        .collect();
                    Some(Uvs::PerCorner {
                        values,
                        indices: corners,
                    })
                } else {
                    return Err(PyValueError::new_err(format!(
                        "uvs: {} rows; expected one per vertex ({}) or one per triangle corner ({})",
                        values.len(),
                        positions.len(),
                        3 * triangles.len()
                    )));
                }
            }
        };
        let mut mesh = Mesh::new(name, positions, triangles, normals, uvs).map_err(to_py_err)?;
        for (key, values) in vertex_maps.into_iter().flat_map(|d| d.iter()) {
            let key: String = key.extract()?;
            let values = crate::convert::column::<f32>(&values, &format!("vertex_maps[{key:?}]"))?;
            mesh = mesh.with_vertex_attribute(key, values).map_err(to_py_err)?;
        }
        for (kind, sets) in [("groups", face_sets), ("materials", materials)] {
            let Some(sets) = sets else { continue };
            let what = if kind == "groups" {
                "face_sets"
            } else {
                "materials"
            };
            crate::convert::require_integers(sets, what)?;
            let ids = crate::convert::column::<i64>(sets, what)?;
            mesh = mesh
                .with_face_groups(face_groups(kind, &ids))
                .map_err(to_py_err)?;
        }
        Ok(Self {
            inner: Arc::new(mesh),
        })
    }

    /// The mesh subdivided `levels` times (midpoint, ×4 triangles a level).
    fn subdivided(&self, py: Python<'_>, levels: u32) -> PyResult<Self> {
        Ok(Self {
            inner: Arc::new(subdivide_checked(py, (*self.inner).clone(), levels)?),
        })
    }

    /// Vertex positions, (n, 3) float32, read-only (a view, no copy).
    #[getter]
    fn positions<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        view2(
            slf.clone().into_any(),
            floats(slf.get().inner.positions()),
            3,
        )
    }

    /// Triangles, (m, 3) uint32 vertex indices, read-only.
    #[getter]
    fn triangles<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let flat: &[u32] = bytemuck::cast_slice(slf.get().inner.triangles());
        view2(slf.clone().into_any(), flat, 3)
    }

    /// Vertex normals, (n, 3) float32, read-only.
    #[getter]
    fn normals<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        view2(slf.clone().into_any(), floats(slf.get().inner.normals()), 3)
    }

    /// UVs per triangle corner, (3m, 2) float32, or `None` without UVs.
    #[getter]
    fn corner_uvs<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray2<f32>>>> {
        let mesh = &slf.get().inner;
        if !mesh.has_uvs() {
            return Ok(None);
        }
        let corners: Vec<glam::Vec2> = (0..mesh.triangle_count())
            .flat_map(|t| mesh.triangle_uvs(t).expect("the mesh has UVs"))
            .collect();
        let array = crate::convert::owned_rows(slf.py(), corners)?;
        Ok(Some(array))
    }

    /// Number of vertices.
    #[getter]
    fn vertex_count(&self) -> usize {
        self.inner.vertex_count()
    }

    /// Number of triangles.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.inner.triangle_count()
    }

    /// Whether the mesh has UVs (maps read from images need them).
    #[getter]
    fn has_uvs(&self) -> bool {
        self.inner.has_uvs()
    }

    /// The name errors call the mesh (its path, for a loaded one).
    #[getter]
    fn name(&self) -> String {
        self.inner.name().to_string()
    }

    /// What `pelage info` prints, as a dict: counts, bounds, surface area,
    /// UVs, degenerate triangles, boundary and non-manifold edges.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mesh = &self.inner;
        let topology = py.detach(|| mesh.topology_report());
        let (lo, hi) = mesh.bounds();
        let info = PyDict::new(py);
        info.set_item("name", mesh.name())?;
        info.set_item("vertices", mesh.vertex_count())?;
        info.set_item("triangles", mesh.triangle_count())?;
        info.set_item("bounds", (lo.to_array(), hi.to_array()))?;
        info.set_item("surface_area", mesh.surface_area())?;
        info.set_item(
            "uvs",
            match mesh.uvs() {
                None => None,
                Some(Uvs::PerVertex(_)) => Some("per vertex"),
                Some(Uvs::PerCorner { .. }) => Some("per corner"),
            },
        )?;
        info.set_item("degenerate_triangles", mesh.degenerate_triangle_count())?;
        info.set_item("edges", topology.edges)?;
        info.set_item("boundary_edges", topology.boundary_edges)?;
        info.set_item("non_manifold_edges", topology.non_manifold_edges)?;
        info.set_item("isolated_vertices", topology.isolated_vertices)?;
        Ok(info)
    }

    fn __repr__(&self) -> String {
        format!(
            "<pelage.Mesh {:?}: {} vertices, {} triangles{}>",
            self.inner.name(),
            self.inner.vertex_count(),
            self.inner.triangle_count(),
            if self.inner.has_uvs() { ", UVs" } else { "" }
        )
    }
}

/// Triangles as (m, 3) indices: any integer array, checked non-negative
/// and below 2³² before it narrows.
fn triangle_rows(triangles: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 3]>> {
    crate::convert::require_integers(triangles, "triangles")?;
    let wide = rows::<i64, 3>(triangles, "triangles")?;
    wide.into_iter()
        .enumerate()
        .map(|(t, [a, b, c])| {
            let narrow = |i: i64| u32::try_from(i).ok();
            match (narrow(a), narrow(b), narrow(c)) {
                (Some(a), Some(b), Some(c)) => Ok([a, b, c]),
                _ => Err(PyValueError::new_err(format!(
                    "triangles[{t}] = [{a}, {b}, {c}]: vertex indices must be between 0 and 2^32 - 1"
                ))),
            }
        })
        .collect()
}

fn subdivide_checked(py: Python<'_>, mesh: Mesh, levels: u32) -> PyResult<Mesh> {
    if levels == 0 {
        return Ok(mesh);
    }
    py.detach(|| mesh.subdivided_within_limits(levels))
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Integer set ids, one a triangle, as named face sets of `kind`: each
/// distinct id a set named after it, in order of first appearance.
fn face_groups(kind: &str, ids: &[i64]) -> pelage::mesh::FaceGroups {
    let mut names = Vec::new();
    let mut index = std::collections::HashMap::new();
    let of_triangle = ids
        .iter()
        .map(|id| {
            *index.entry(*id).or_insert_with(|| {
                names.push(id.to_string());
                names.len() as u32 - 1
            })
        })
        .collect();
    pelage::mesh::FaceGroups {
        kind: kind.to_string(),
        names,
        of_triangle,
    }
}
