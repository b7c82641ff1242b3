//! pelage for Python: the `pelage._pelage` extension module.
//!
//! A thin layer over the library (docs/design.md, "Library first, front
//! ends thin": it holds no logic the library lacks). Each Python class
//! wraps one Rust value, one file each:
//!
//! - `mesh.rs`: `PyMesh` wraps [`pelage::Mesh`] (loaded, or built from numpy
//!   arrays);
//! - `sample.rs`: `sample` runs the density sampler (Sik §3) and hands back
//!   numpy arrays;
//! - `groom.rs`: `PyGroom` wraps a [`pelage::groom::Groom`]: a groom file, or
//!   Python dicts turned into the same settings and checked by the same
//!   code, so errors name the same keys;
//! - `curves.rs`: `PyCurves` wraps [`pelage::Curves`], with read-only numpy
//!   views of its arrays (no copy) and every curves format in and out.
//!
//! Errors become `pelage.PelageError` carrying pelage's message (file,
//! line, key). Long work (loading, growing, writing) runs with the
//! interpreter detached, so other Python threads keep running.

use pyo3::prelude::*;

mod convert;
mod curves;
mod groom;
mod mesh;
mod sample;
mod session;

pyo3::create_exception!(
    _pelage,
    PelageError,
    pyo3::exceptions::PyException,
    "An error from pelage: a file that cannot be read or written, a groom setting that is out of range, a mesh that is malformed. The message names the file, the line and the setting where there is one."
);

/// Turns any pelage error into a `PelageError` carrying its message and
/// the messages of its causes, "a: b: c" (each error prints its cause or
/// returns it as its `source`, never both, so each is said once).
pub(crate) fn to_py_err(error: impl std::error::Error) -> PyErr {
    PelageError::new_err(with_causes(error.to_string(), error.source()))
}

/// `message`, then the message of `cause` and of each cause under it.
pub(crate) fn with_causes(
    mut message: String,
    mut cause: Option<&(dyn std::error::Error + 'static)>,
) -> String {
    while let Some(error) = cause {
        message.push_str(": ");
        message.push_str(&error.to_string());
        cause = error.source();
    }
    message
}

#[pymodule]
fn _pelage(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // Benchmarks refuse to compare a debug build with a release one.
    let profile = if cfg!(debug_assertions) {
        "debug"
    } else {
        "release"
    };
    m.add("__build_profile__", profile)?;
    m.add("PelageError", m.py().get_type::<PelageError>())?;
    m.add_class::<mesh::PyMesh>()?;
    m.add_class::<curves::PyCurves>()?;
    m.add_class::<groom::PyGroom>()?;
    m.add_class::<session::PyGroomSession>()?;
    m.add_class::<sample::PySamples>()?;
    m.add_function(wrap_pyfunction!(sample::sample, m)?)?;
    m.add_function(wrap_pyfunction!(curves::read_curves, m)?)?;
    m.add_function(wrap_pyfunction!(curves::write_curves, m)?)?;
    m.add_function(wrap_pyfunction!(operator_schema, m)?)?;
    Ok(())
}

/// Every groom operator's settings as the library declares them: a list
/// of dicts with `name`, `summary`, `fields` (every key, `mask` included),
/// `required`, and `settings` (each but `mask`: `name`, `doc`,
/// `required`, `start`, where a front end starts it: a number, three for
/// a colour, or `None`, and `start_is_length`, whether the start is a
/// world length to scale by the mesh's size). `pelage.ops` builds these
/// tables (a test holds its functions to this schema); the Blender panel
/// starts a new operator's settings from it.
#[pyfunction]
fn operator_schema(py: Python<'_>) -> PyResult<Vec<Bound<'_, pyo3::types::PyDict>>> {
    pelage::groom::ops::operator_schema()
        .into_iter()
        .map(|op| {
            let d = pyo3::types::PyDict::new(py);
            d.set_item("name", op.name)?;
            d.set_item("summary", op.summary)?;
            d.set_item("fields", op.fields)?;
            d.set_item("required", op.required)?;
            let settings = op
                .settings
                .iter()
                .map(|s| {
                    let setting = pyo3::types::PyDict::new(py);
                    setting.set_item("name", s.name)?;
                    let doc: Vec<&str> = s.doc.iter().map(|line| line.trim()).collect();
                    setting.set_item("doc", doc.join(" "))?;
                    setting.set_item("required", s.required)?;
                    use pelage::groom::ops::Start;
                    // A whole number stays one (a count reads no `200.0`).
                    let number = |x: f64| -> PyResult<Py<PyAny>> {
                        Ok(if x.fract() == 0.0 && x.abs() < 1e15 {
                            (x as i64).into_pyobject(py)?.into_any().unbind()
                        } else {
                            x.into_pyobject(py)?.into_any().unbind()
                        })
                    };
                    match s.start {
                        None => setting.set_item("start", py.None())?,
                        Some(Start::Number(x) | Start::Length(x)) => {
                            setting.set_item("start", number(x)?)?
                        }
                        Some(Start::Rgb(rgb)) => setting.set_item("start", rgb.to_vec())?,
                    }
                    let length = matches!(s.start, Some(Start::Length(_)));
                    setting.set_item("start_is_length", length)?;
                    Ok(setting)
                })
                .collect::<PyResult<Vec<_>>>()?;
            d.set_item("settings", settings)?;
            Ok(d)
        })
        .collect()
}
