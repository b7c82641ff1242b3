//! `pelage.GroomSession`: grooming by hand from Python, so any program's
//! own tools (a DCC's brushes, a script) can drive pelage's brushes on an
//! editable groom ([`pelage::groom::edit::EditableGroom`]) with undo, redo
//! and incremental regrowth, and save the result as a groom file.

use crate::curves::PyCurves;
use crate::groom::PyGroom;
use crate::to_py_err;
use glam::Vec3;
use numpy::{PyArray1, PyArrayMethods};
use pelage::groom::brush::{Brush, Dab, Falloff};
use pelage::groom::edit::{EditableGroom, Regrowth};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::Mutex;

/// A groom open for grooming by hand: brushes on its guides and paint
/// layers, undo and redo, and its hairs regrown where an edit reaches::
///
///     s = pelage.GroomSession(pelage.Groom.load("fur.toml"), fraction=0.1)
///     s.brush("comb", at=(0.1, 0.4, 0.2), radius=0.05,
///             direction=(0, 0, 0.02), strength=0.8)
///     s.undo(); s.redo()
///     hairs = s.curves()           # the groom's hairs now (Curves)
///     s.save("fur_groomed.toml")   # groom file + guides + paint layers
///
/// `fraction` grows that share of the hairs (the same hairs as the full
/// groom, a subset: a preview stays true to it).
#[pyclass(name = "GroomSession", module = "pelage", frozen)]
pub struct PyGroomSession {
    groom: Mutex<EditableGroom>,
    /// The groom file's text the session was opened from, kept for save.
    source: pelage::settings::SettingsSource,
}

impl PyGroomSession {
    fn with<T>(&self, f: impl FnOnce(&mut EditableGroom) -> T) -> T {
        let mut groom = self.groom.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut groom)
    }
}

fn regrowth_dict<'py>(py: Python<'py>, r: Regrowth) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("regrown", r.regrown_roots)?;
    d.set_item("hairs", r.hairs)?;
    Ok(d)
}

fn vec3(v: (f32, f32, f32)) -> Vec3 {
    Vec3::new(v.0, v.1, v.2)
}

#[pymethods]
impl PyGroomSession {
    #[new]
    #[pyo3(signature = (groom, *, fraction = 1.0))]
    fn new(py: Python<'_>, groom: &PyGroom, fraction: f64) -> PyResult<Self> {
        let spec = groom.groom().spec().map_err(to_py_err)?;
        // A session holds every hair: refused as `grow()` is (a failed
        // allocation would abort the interpreter).
        let hairs = (spec.roots.count as f64 * fraction.clamp(0.0, 1.0)).ceil() as u64;
        crate::groom::check_memory(
            hairs.saturating_mul(spec.most_hairs_per_root()),
            spec.finish.points,
            "a grooming session",
        )?;
        let editable = py
            .detach(|| EditableGroom::new(spec, fraction))
            .map_err(to_py_err)?;
        Ok(Self {
            groom: Mutex::new(editable),
            source: groom.groom().source().clone(),
        })
    }

    /// Applies one dab of brush `name` (`comb`, `length`, `cut`, `smooth`,
    /// `puff`, `clump`, `spread`, `add`, `delete`, `paint`, `part`) at the
    /// surface point `at` with `radius`, `strength`, `direction` (world
    /// space: comb moves points by it), `falloff` (`smooth`, `linear`,
    /// `constant`) and `mirror_x`. `paint` takes `layer` (default
    /// "density") and `value`; `part` takes `region`; `add` takes `count`.
    /// Returns `{"regrown": roots regrown, "hairs": hairs now}`, or None
    /// when the dab touched nothing; a guide brush (comb to spread) that
    /// reached no guide also warns (`UserWarning`), saying how far the
    /// nearest guide was.
    #[pyo3(signature = (name, *, at, radius, strength = 1.0, direction = (0.0, 0.0, 0.0), falloff = "smooth", mirror_x = false, layer = None, value = None, region = None, count = None))]
    #[allow(clippy::too_many_arguments)]
    fn brush<'py>(
        &self,
        py: Python<'py>,
        name: &str,
        at: (f32, f32, f32),
        radius: f32,
        strength: f32,
        direction: (f32, f32, f32),
        falloff: &str,
        mirror_x: bool,
        layer: Option<String>,
        value: Option<f32>,
        region: Option<u32>,
        count: Option<u32>,
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let mut brush = Brush::by_name(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "no brush '{name}': use one of {}",
                Brush::NAMES.join(", ")
            ))
        })?;
        match &mut brush {
            Brush::Paint { layer: l, value: v } => {
                if let Some(layer) = layer {
                    *l = layer;
                }
                if let Some(value) = value {
                    *v = value;
                }
            }
            Brush::Part { region: r } => *r = region.unwrap_or(*r),
            Brush::Add { count: c } => *c = count.unwrap_or(*c),
            _ => {}
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(PyValueError::new_err(format!(
                "radius = {radius}: give a positive brush radius in world units"
            )));
        }
        let falloff = Falloff::parse(falloff).ok_or_else(|| {
            PyValueError::new_err(format!(
                "falloff '{falloff}': use smooth, linear or constant"
            ))
        })?;
        let dab = Dab {
            center: vec3(at),
            radius,
            strength,
            direction: vec3(direction),
            falloff,
            mirror_x,
        };
        if !(dab.center.is_finite() && dab.direction.is_finite() && strength.is_finite()) {
            return Err(PyValueError::new_err(
                "at, direction and strength must be finite numbers",
            ));
        }
        let (done, missed) = py
            .detach(|| {
                self.with(|g| {
                    let done = g.brush(&brush, &dab)?;
                    // A guide brush that reached no guide: by how much.
                    let missed = (done.is_none() && brush.shapes_guides())
                        .then(|| pelage::groom::brush::nearest_guide_distance(g, dab.center));
                    Ok::<_, pelage::groom::GroomError>((done, missed))
                })
            })
            .map_err(to_py_err)?;
        if let Some(nearest) = missed {
            let how_far = nearest.map_or("the groom has no guides".to_string(), |d| {
                format!("the nearest guide point is {d:.4} away")
            });
            let message = std::ffi::CString::new(format!(
                "{name}: no guide within the brush's radius {radius} of {:?} ({how_far}); the dab changed nothing",
                at
            ))
            .expect("no NUL in the message");
            PyErr::warn(
                py,
                &py.get_type::<pyo3::exceptions::PyUserWarning>(),
                &message,
                1,
            )?;
        }
        done.map(|r| regrowth_dict(py, r)).transpose()
    }

    /// Takes `curves` (a DCC's guide curves, any point count, in the
    /// mesh's space) as the guides: only the guides whose points moved
    /// regrow their hairs; added, deleted or slid guides replace them all.
    /// Roots farther than `tolerance` from the surface are left out.
    /// Returns `{"regrown": roots regrown, "hairs": hairs now}`, or None
    /// when nothing changed. One undo step.
    #[pyo3(signature = (curves, *, tolerance = 1e-3))]
    fn set_guides<'py>(
        &self,
        py: Python<'py>,
        curves: &crate::curves::PyCurves,
        tolerance: f32,
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let curves = &curves.inner;
        let done = py
            .detach(|| self.with(|g| g.set_guide_curves(curves, tolerance)))
            .map_err(to_py_err)?;
        done.map(|r| regrowth_dict(py, r)).transpose()
    }

    /// Undoes the last edit; False when there is none.
    fn undo(&self, py: Python<'_>) -> PyResult<bool> {
        let done = py.detach(|| self.with(|g| g.undo())).map_err(to_py_err)?;
        Ok(done.is_some())
    }

    /// Redoes the last undone edit; False when there is none.
    fn redo(&self, py: Python<'_>) -> PyResult<bool> {
        let done = py.detach(|| self.with(|g| g.redo())).map_err(to_py_err)?;
        Ok(done.is_some())
    }

    /// The groom's hairs now (with ids and roots), as `Curves`.
    fn curves(&self, py: Python<'_>) -> PyCurves {
        PyCurves::new(py.detach(|| self.with(|g| g.curves())))
    }

    /// The hairs' points alone, (n, 3) float32, in the order of
    /// `curves()`: what a viewport refreshes after an edit that keeps the
    /// hair count, without assembling every attribute. With `matrix` (a
    /// 4×4 affine transform, row-major, as numpy and Blender write it)
    /// the points are turned by it first, on every thread: a DCC's object
    /// space without a pass of numpy over a million points.
    #[pyo3(signature = (matrix = None))]
    fn points<'py>(
        &self,
        py: Python<'py>,
        matrix: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<f32>>> {
        let matrix = match matrix {
            None => None,
            Some(m) => {
                let rows = crate::convert::rows::<f64, 4>(m, "matrix")?;
                if rows.len() != 4 {
                    return Err(pyo3::exceptions::PyValueError::new_err(format!(
                        "matrix: {} rows; expected a 4×4 transform",
                        rows.len()
                    )));
                }
                let c = |j: usize| glam::DVec3::new(rows[0][j], rows[1][j], rows[2][j]).as_vec3();
                Some(glam::Affine3A::from_cols(
                    c(0).into(),
                    c(1).into(),
                    c(2).into(),
                    c(3).into(),
                ))
            }
        };
        let points = py.detach(|| {
            let mut points = self.with(|g| g.points());
            if let Some(m) = matrix {
                use rayon::prelude::*;
                points
                    .par_iter_mut()
                    .for_each(|p| *p = m.transform_point3(*p));
            }
            points
        });
        let n = points.len();
        let flat: Vec<f32> = bytemuck::cast_vec(points);
        Ok(numpy::PyArray1::from_vec(py, flat)
            .reshape([n, 3])
            .expect("three floats a point"))
    }

    /// The guides now, as `Curves` (with their roots).
    fn guides(&self) -> PyCurves {
        PyCurves::new(self.with(|g| g.guides().curves().clone()))
    }

    /// The values of paint layer `name` (one a vertex), or None.
    fn layer<'py>(&self, py: Python<'py>, name: &str) -> Option<Bound<'py, PyArray1<f32>>> {
        self.with(|g| g.layer(name).map(|v| PyArray1::from_slice(py, v)))
    }

    /// The paint layers' names.
    #[getter]
    fn layers(&self) -> Vec<String> {
        self.with(|g| {
            g.mesh()
                .vertex_attributes()
                .iter()
                .map(|a| a.name.clone())
                .collect()
        })
    }

    /// The share of the groom's hairs grown.
    #[getter]
    fn fraction(&self) -> f64 {
        self.with(|g| g.fraction())
    }

    /// Grows another share of the hairs (not an edit: no undo step).
    #[setter]
    fn set_fraction(&self, py: Python<'_>, fraction: f64) -> PyResult<()> {
        py.detach(|| self.with(|g| g.set_fraction(fraction)))
            .map(|_| ())
            .map_err(to_py_err)
    }

    /// Hairs grown now.
    #[getter]
    fn hair_count(&self) -> usize {
        self.with(|g| g.hair_count())
    }

    /// Steps that can be undone and redone, `(undo, redo)`.
    #[getter]
    fn history(&self) -> (usize, usize) {
        self.with(|g| g.history_len())
    }

    /// Writes the groom file `path` with its guides (`NAME.guides.usdc`)
    /// and paint layers (`NAME.layers.ply`) beside it, and a mesh given as
    /// arrays (`NAME.mesh.obj`, which `[mesh] path` names); `pelage groom
    /// path` grows the groom as the session has it (in full). Returns the
    /// paths written (`mesh`: None when the mesh came from a file).
    fn save<'py>(&self, py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
        let saved = py
            .detach(|| self.with(|g| g.save(&path, Some(&self.source))))
            .map_err(to_py_err)?;
        let d = PyDict::new(py);
        d.set_item("groom", saved.groom)?;
        d.set_item("guides", saved.guides)?;
        d.set_item("layers", saved.layers)?;
        d.set_item("mesh", saved.mesh)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        self.with(|g| {
            let (undo, redo) = g.history_len();
            format!(
                "GroomSession({} hairs, {} guides, fraction {}, {undo} undo / {redo} redo)",
                g.hair_count(),
                g.guides().len(),
                g.fraction()
            )
        })
    }
}
