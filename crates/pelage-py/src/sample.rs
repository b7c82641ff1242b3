//! `pelage.sample`: hair roots on a mesh from a density map (Sik §3: the
//! density sampler's sub-triangle records and alias table), as numpy
//! arrays.

use crate::convert::owned_rows;
use crate::mesh::PyMesh;
use crate::to_py_err;
use numpy::{PyArray1, PyArray2};
use pelage::Map;
use pelage::SurfacePoint;
use pelage::sample::{DensitySampler, DensitySamplerOptions, sample_range};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Most roots one call samples (the CLI's `sample -n` ceiling); sample in
/// batches (`first=`) for more.
const MAX_SAMPLES: u64 = pelage::limits::MAX_SAMPLE_POINTS;

/// Sampled roots: `positions` and `normals` (n, 3), `uvs` (n, 2) or
/// `None` on a mesh without UVs, `triangles` (n,) and `barycentrics`
/// (n, 2). Plain numpy arrays, owned by Python.
#[pyclass(name = "Samples", module = "pelage", frozen, get_all)]
pub struct PySamples {
    /// Root positions on the surface, (n, 3) float32.
    positions: Py<PyArray2<f32>>,
    /// Interpolated vertex normals at the roots, (n, 3) float32.
    normals: Py<PyArray2<f32>>,
    /// UVs at the roots, (n, 2) float32, or `None`.
    uvs: Option<Py<PyArray2<f32>>>,
    /// The triangle each root lies in, (n,) uint32.
    triangles: Py<PyArray1<u32>>,
    /// Barycentric (u, v) of each root in its triangle, (n, 2) float32.
    barycentrics: Py<PyArray2<f32>>,
}

#[pymethods]
impl PySamples {
    fn __len__(&self, py: Python<'_>) -> usize {
        numpy::PyUntypedArrayMethods::len(self.triangles.bind(py))
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!("<pelage.Samples: {} roots>", self.__len__(py))
    }
}

/// Samples `n` hair roots on `mesh`, distributed by `density`: a number
/// (uniform), a map string as in groom files (`"density.png:r"`,
/// `"noise:frequency=8"`), or a 2-D numpy array read like an image over
/// the mesh's UVs (row 0 at the top, v = 1). Sample i depends only on (`seed`, `first` + i),
/// so batches with `first=` add up to one big sample and any thread count
/// gives the same roots. `distribution="blue-noise"` thins twice as
/// many to roots that keep their distance (the whole set at once: no
/// `first=`, at most 20,000,000).
#[pyfunction]
#[pyo3(signature = (mesh, n, *, density = None, seed = 1, first = 0, distribution = "random"))]
pub fn sample(
    py: Python<'_>,
    mesh: &PyMesh,
    n: u64,
    density: Option<&Bound<'_, PyAny>>,
    seed: u64,
    first: u64,
    distribution: &str,
) -> PyResult<PySamples> {
    let blue = match distribution {
        "random" => false,
        "blue-noise" | "blue_noise" => true,
        other => {
            return Err(PyValueError::new_err(format!(
                "distribution = {other:?}: use \"random\" or \"blue-noise\""
            )));
        }
    };
    if blue && first != 0 {
        return Err(PyValueError::new_err(
            "first = … with distribution=\"blue-noise\": blue noise is thinned as one set and cannot be drawn in batches",
        ));
    }
    let most = pelage::limits::MAX_BLUE_NOISE_POINTS;
    if blue && n > most {
        return Err(PyValueError::new_err(format!(
            "n = {n}: blue noise thins at most {most} roots at once (docs/limits.md)"
        )));
    }
    if n > MAX_SAMPLES {
        return Err(PyValueError::new_err(format!(
            "n = {n}: at most {MAX_SAMPLES} roots a call; sample in batches with first="
        )));
    }
    let density = match density {
        None => Map::Constant(1.0),
        Some(d) => map_argument(d, "density")?,
    };
    let mesh = mesh.inner.clone();
    let (roots, positions, normals, uvs) = py
        .detach(|| {
            let sampler = DensitySampler::new(&mesh, &density, DensitySamplerOptions::default())?;
            let roots: Vec<SurfacePoint> = if blue {
                pelage::sample::blue_noise_samples(&sampler, &mesh, seed, n)
            } else {
                sample_range(&sampler, seed, first..first + n)
            };
            let positions: Vec<glam::Vec3> = roots.iter().map(|r| r.position(&mesh)).collect();
            let normals: Vec<glam::Vec3> = roots.iter().map(|r| r.normal(&mesh)).collect();
            let uvs: Option<Vec<glam::Vec2>> = mesh.has_uvs().then(|| {
                roots
                    .iter()
                    .map(|r| r.uv(&mesh).unwrap_or_default())
                    .collect()
            });
            Ok::<_, pelage::sample::SampleError>((roots, positions, normals, uvs))
        })
        .map_err(to_py_err)?;
    Ok(PySamples {
        positions: owned_rows(py, positions)?.unbind(),
        normals: owned_rows(py, normals)?.unbind(),
        uvs: uvs
            .map(|u| crate::convert::owned_rows(py, u).map(Bound::unbind))
            .transpose()?,
        triangles: PyArray1::from_vec(py, roots.iter().map(|r| r.tri).collect()).unbind(),
        barycentrics: crate::convert::owned_rows(
            py,
            roots.iter().map(|r| glam::Vec2::from(r.bary)).collect(),
        )?
        .unbind(),
    })
}

/// A map argument: a number (constant), a map string, or a 2-D array of
/// texels (rows from the top of the image, as an image file's; repeated
/// past the UV square, bilinear).
pub(crate) fn map_argument(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Map> {
    if let Ok(x) = value.extract::<f64>() {
        return Ok(Map::Constant(x as f32));
    }
    if value.hasattr("ndim")? && value.hasattr("shape")? {
        let (height, width, texels) = crate::convert::image(value, what)?;
        let image =
            pelage::map::ImageMap::from_texels(width, height, texels, pelage::map::Wrap::Repeat)
                .map_err(|kind| PyValueError::new_err(format!("{what}: {kind}")))?;
        return Ok(Map::Image(image));
    }
    let text: String = value.extract().map_err(|_| {
        PyValueError::new_err(format!(
            "{what}: expected a number or a map string such as \"density.png:r\" or \"noise:frequency=8\""
        ))
    })?;
    Map::parse(&text).map_err(to_py_err)
}
