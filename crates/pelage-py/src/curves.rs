//! `pelage.Curves`: hair curves as structure of arrays (points, offsets,
//! widths and optional attributes), with read-only numpy views, and
//! `read_curves` / `write_curves` for every format pelage reads or writes.

use crate::convert::{column, floats, rows, vec2s, vec3s, view1, view2};
use crate::mesh::PyMesh;
use crate::to_py_err;
use numpy::{PyArray1, PyArray2};
use pelage::Curves;
use pelage::groom::Generator;
use pelage::io::{CurveBasis, CurvesExport, UpAxis, UsdOptions};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::Arc;

/// Hair curves: curve `i` is `points[offsets[i]:offsets[i + 1]]`
/// (Blender's `CurvesGeometry`, USD's `BasisCurves`). The arrays are
/// read-only numpy views of pelage's own memory; `.copy()` one to edit it,
/// then build new curves with `Curves.from_arrays`.
#[pyclass(name = "Curves", module = "pelage", frozen)]
pub struct PyCurves {
    pub(crate) inner: Curves,
    /// The generator that grew these curves: their memory goes back to it
    /// when Python lets go of them, so the next part reuses it instead of
    /// faulting in fresh pages (as the CLI's loop does).
    recycle_into: Option<Arc<Generator>>,
}

impl PyCurves {
    pub(crate) fn new(inner: Curves) -> Self {
        Self {
            inner,
            recycle_into: None,
        }
    }

    /// Curves grown by `generator`, handed back to it when dropped.
    pub(crate) fn grown_by(inner: Curves, generator: Arc<Generator>) -> Self {
        Self {
            inner,
            recycle_into: Some(generator),
        }
    }
}

impl Drop for PyCurves {
    fn drop(&mut self) {
        if let Some(generator) = self.recycle_into.take() {
            generator.recycle(std::mem::take(&mut self.inner));
        }
    }
}

#[pymethods]
impl PyCurves {
    /// Builds curves from arrays: `points` (n, 3), `offsets` (curves + 1,)
    /// starting at 0 and ending at n, `widths` (n,) (default 0.001), and
    /// optionally per point `colors` (n, 3), `opacities` (n,), `normals`
    /// (n, 3), and per curve `root_uvs` (curves, 2) and `ids` (curves,).
    #[staticmethod]
    #[pyo3(signature = (points, offsets, widths = None, colors = None, opacities = None, normals = None, root_uvs = None, ids = None))]
    #[allow(
        clippy::too_many_arguments,
        reason = "one keyword argument an attribute"
    )]
    fn from_arrays(
        points: &Bound<'_, PyAny>,
        offsets: &Bound<'_, PyAny>,
        widths: Option<&Bound<'_, PyAny>>,
        colors: Option<&Bound<'_, PyAny>>,
        opacities: Option<&Bound<'_, PyAny>>,
        normals: Option<&Bound<'_, PyAny>>,
        root_uvs: Option<&Bound<'_, PyAny>>,
        ids: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let points = vec3s(rows::<f32, 3>(points, "points")?);
        let offsets = offsets_column(offsets)?;
        let widths = match widths {
            Some(w) => column::<f32>(w, "widths")?,
            None => vec![0.001; points.len()],
        };
        let mut curves = Curves::new(points, widths, offsets).map_err(to_py_err)?;
        if let Some(c) = colors {
            curves = curves
                .with_colors(vec3s(rows::<f32, 3>(c, "colors")?))
                .map_err(to_py_err)?;
        }
        if let Some(o) = opacities {
            curves = curves
                .with_opacities(column::<f32>(o, "opacities")?)
                .map_err(to_py_err)?;
        }
        if let Some(n) = normals {
            curves = curves
                .with_normals(vec3s(rows::<f32, 3>(n, "normals")?))
                .map_err(to_py_err)?;
        }
        if let Some(u) = root_uvs {
            curves = curves
                .with_root_uvs(vec2s(rows::<f32, 2>(u, "root_uvs")?))
                .map_err(to_py_err)?;
        }
        if let Some(i) = ids {
            crate::convert::require_integers(i, "ids")?;
            curves = curves
                .with_ids(column::<u64>(i, "ids")?)
                .map_err(to_py_err)?;
        }
        Ok(Self::new(curves))
    }

    /// Points, (n, 3) float32.
    #[getter]
    fn points<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        view2(slf.clone().into_any(), floats(slf.get().inner.points()), 3)
    }

    /// Offsets, (curves + 1,) uint32: curve i is points[offsets[i]:offsets[i+1]].
    #[getter]
    fn offsets<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<u32>>> {
        view1(slf.clone().into_any(), slf.get().inner.offsets())
    }

    /// Widths (diameters), (n,) float32.
    #[getter]
    fn widths<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f32>>> {
        view1(slf.clone().into_any(), slf.get().inner.widths())
    }

    /// Colours, (n, 3) float32 linear RGB, or `None`.
    #[getter]
    fn colors<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray2<f32>>>> {
        slf.get()
            .inner
            .colors()
            .map(|c| view2(slf.clone().into_any(), floats(c), 3))
            .transpose()
    }

    /// Opacities, (n,) float32, or `None`.
    #[getter]
    fn opacities<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray1<f32>>>> {
        slf.get()
            .inner
            .opacities()
            .map(|o| view1(slf.clone().into_any(), o))
            .transpose()
    }

    /// Ribbon normals (rotation-minimizing), (n, 3) float32, or `None`.
    #[getter]
    fn normals<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray2<f32>>>> {
        slf.get()
            .inner
            .normals()
            .map(|n| view2(slf.clone().into_any(), floats(n), 3))
            .transpose()
    }

    /// The surface UV under each root, (curves, 2) float32, or `None`.
    #[getter]
    fn root_uvs<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray2<f32>>>> {
        slf.get()
            .inner
            .root_uvs()
            .map(|u| view2(slf.clone().into_any(), floats(u), 2))
            .transpose()
    }

    /// Stable hair ids, (curves,) uint64, or `None`.
    #[getter]
    fn ids<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray1<u64>>>> {
        slf.get()
            .inner
            .ids()
            .map(|i| view1(slf.clone().into_any(), i))
            .transpose()
    }

    /// The skin region each curve grew in (a groom with `[regions]`),
    /// (curves,) uint32, or `None`.
    #[getter]
    fn regions<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray1<u32>>>> {
        slf.get()
            .inner
            .regions()
            .map(|r| view1(slf.clone().into_any(), r))
            .transpose()
    }

    /// Hair-shader values of a groom with a `[look]`, or `None`: a dict
    /// from the attribute names (`hair_melanin`, `hair_melanin_redness`,
    /// `hair_roughness`, `hair_radial_roughness`, `hair_random`: (curves,)
    /// float32; `hair_tint`: (curves, 3) float32 linear RGB).
    #[getter]
    fn shading<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, pyo3::types::PyDict>>> {
        let Some(shading) = slf.get().inner.shading() else {
            return Ok(None);
        };
        let py = slf.py();
        let dict = pyo3::types::PyDict::new(py);
        let owner = slf.clone().into_any();
        for (name, values) in shading.floats() {
            dict.set_item(name, view1(owner.clone(), values)?)?;
        }
        let tint = view2(owner, floats(&shading.tint), 3)?;
        dict.set_item(pelage::curves::HairShading::TINT, tint)?;
        Ok(Some(dict))
    }

    /// The mesh triangle under each root, (curves,) uint32, or `None`
    /// when the curves carry no roots (read from a file).
    #[getter]
    fn root_triangles<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<u32>>> {
        let roots = self.inner.roots()?;
        Some(PyArray1::from_vec(
            py,
            roots.iter().map(|r| r.tri).collect(),
        ))
    }

    /// Barycentric coordinates (u, v) of each root in its triangle,
    /// (curves, 2) float32, or `None`.
    #[getter]
    fn root_barycentrics<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Option<Bound<'py, PyArray2<f32>>>> {
        let Some(roots) = self.inner.roots() else {
            return Ok(None);
        };
        let bary = roots.iter().map(|r| glam::Vec2::from(r.bary)).collect();
        crate::convert::owned_rows(py, bary).map(Some)
    }

    /// Number of curves.
    #[getter]
    fn curve_count(&self) -> usize {
        self.inner.curve_count()
    }

    /// Number of points (all curves).
    #[getter]
    fn point_count(&self) -> usize {
        self.inner.points().len()
    }

    /// Axis-aligned bounds `((x, y, z), (x, y, z))`, or `None` when empty.
    #[getter]
    fn bounds(&self) -> Option<([f32; 3], [f32; 3])> {
        self.inner
            .bounds()
            .map(|(lo, hi)| (lo.to_array(), hi.to_array()))
    }

    /// Writes the curves; see `pelage.write_curves`.
    #[pyo3(signature = (path, *, basis = "catmull-rom", up_axis = "y", mesh = None))]
    fn write(
        &self,
        py: Python<'_>,
        path: PathBuf,
        basis: &str,
        up_axis: &str,
        mesh: Option<&PyMesh>,
    ) -> PyResult<()> {
        write_one(py, &self.inner, path, basis, up_axis, mesh)
    }

    fn __len__(&self) -> usize {
        self.inner.curve_count()
    }

    fn __repr__(&self) -> String {
        let mut attributes = vec!["widths"];
        let c = &self.inner;
        for (has, name) in [
            (c.colors().is_some(), "colors"),
            (c.opacities().is_some(), "opacities"),
            (c.normals().is_some(), "normals"),
            (c.root_uvs().is_some(), "root_uvs"),
            (c.ids().is_some(), "ids"),
        ] {
            if has {
                attributes.push(name);
            }
        }
        format!(
            "<pelage.Curves: {} curves, {} points; {}>",
            c.curve_count(),
            c.points().len(),
            attributes.join(", ")
        )
    }
}

/// Reads a curves file: USD (.usda, .usdc, .usd: every BasisCurves prim,
/// joined), Alembic (.abc), Cem Yuksel's .hair, or PLY curves. `time`
/// picks a time sample (USD time code, Alembic seconds) of an animated
/// file; the default is the file's default or first sample.
#[pyfunction]
#[pyo3(signature = (path, *, time = None))]
pub fn read_curves(py: Python<'_>, path: PathBuf, time: Option<f64>) -> PyResult<PyCurves> {
    let curves = py.detach(|| {
        let is = |ext: &[&str]| {
            path.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| ext.contains(&e.to_ascii_lowercase().as_str()))
        };
        match time {
            Some(t) if is(&["usda", "usdc", "usd"]) => {
                pelage::io::read_usd_curves_at(&path, Some(t))
            }
            Some(t) if is(&["abc"]) => pelage::io::read_abc_curves_at(&path, Some(t)),
            _ => pelage::io::read_curves(&path),
        }
    });
    curves.map(PyCurves::new).map_err(to_py_err)
}

/// Writes curves to `path`, in the format its extension names: .usdc
/// (or .usd), .usda, .abc, .hair, .ply, .rib, .pbrt. The file appears
/// whole or not at all (written to a temporary name, then renamed).
/// `basis`: "catmull-rom" or "linear"; `up_axis`: "y" or "z" (USD);
/// `mesh`: also write the skin (USD).
#[pyfunction]
#[pyo3(signature = (curves, path, *, basis = "catmull-rom", up_axis = "y", mesh = None))]
pub fn write_curves(
    py: Python<'_>,
    curves: &PyCurves,
    path: PathBuf,
    basis: &str,
    up_axis: &str,
    mesh: Option<&PyMesh>,
) -> PyResult<()> {
    write_one(py, &curves.inner, path, basis, up_axis, mesh)
}

fn write_one(
    py: Python<'_>,
    curves: &Curves,
    path: PathBuf,
    basis: &str,
    up_axis: &str,
    mesh: Option<&PyMesh>,
) -> PyResult<()> {
    let export = CurvesExport {
        usd: UsdOptions {
            basis: parse_basis(basis)?,
            up_axis: match up_axis.to_ascii_lowercase().as_str() {
                "y" => UpAxis::Y,
                "z" => UpAxis::Z,
                other => {
                    return Err(PyValueError::new_err(format!(
                        "up_axis = {other:?}: use \"y\" or \"z\""
                    )));
                }
            },
            ..UsdOptions::default()
        },
        mesh: mesh.map(|m| m.inner.as_ref()),
        guides: None,
    };
    py.detach(|| pelage::io::write_curves(&path, [("curves".to_string(), curves)], &export))
        .map_err(to_py_err)
}

pub(crate) fn parse_basis(basis: &str) -> PyResult<CurveBasis> {
    basis.parse().map_err(PyValueError::new_err)
}

/// Offsets: a 1-D integer column, checked to fit u32 before it narrows.
fn offsets_column(value: &Bound<'_, PyAny>) -> PyResult<Vec<u32>> {
    crate::convert::require_integers(value, "offsets")?;
    let wide = column::<i64>(value, "offsets")?;
    wide.into_iter()
        .enumerate()
        .map(|(i, o)| {
            u32::try_from(o).map_err(|_| {
                PyValueError::new_err(format!(
                    "offsets[{i}] = {o}: offsets must be between 0 and 2^32 - 1"
                ))
            })
        })
        .collect()
}
