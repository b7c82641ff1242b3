//! numpy arrays in and out: shape checks with errors that say what was
//! expected, and read-only views of Rust vectors owned by a Python object.

use glam::{Vec2, Vec3};
use numpy::ndarray::{ArrayView1, ArrayView2};
use numpy::{Element, PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A numpy array (or anything `numpy.asarray` accepts) as a contiguous
/// `(n, WIDTH)` array of `T`, copied into a vector. `what` names the
/// argument in errors.
pub fn rows<'py, T: Element + Copy, const WIDTH: usize>(
    value: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Vec<[T; WIDTH]>> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    let dtype = numpy::dtype::<T>(py);
    let array = numpy
        .call_method1("ascontiguousarray", (value, dtype))
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    let array = array
        .cast_into::<numpy::PyArrayDyn<T>>()
        .map_err(|_| PyValueError::new_err(format!("{what}: expected a numeric array")))?;
    let shape = array.shape().to_vec();
    let shape_ok = match shape.as_slice() {
        [_, w] => *w == WIDTH,
        [n] => WIDTH == 1 || *n == 0,
        _ => false,
    };
    if !shape_ok {
        return Err(PyValueError::new_err(format!(
            "{what}: expected an array of shape (n, {WIDTH}), got {shape:?}"
        )));
    }
    let readonly = array.readonly();
    let flat = readonly
        .as_slice()
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    Ok(flat
        .chunks_exact(WIDTH)
        .map(|c| std::array::from_fn(|i| c[i]))
        .collect())
}

/// A 1-D array of `T`, copied.
pub fn column<'py, T: Element + Copy>(value: &Bound<'py, PyAny>, what: &str) -> PyResult<Vec<T>> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    let array = numpy
        .call_method1("ascontiguousarray", (value, numpy::dtype::<T>(py)))
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    let array = array
        .cast_into::<numpy::PyArrayDyn<T>>()
        .map_err(|_| PyValueError::new_err(format!("{what}: expected a numeric array")))?;
    if array.ndim() != 1 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected a 1-D array, got shape {:?}",
            array.shape()
        )));
    }
    let readonly = array.readonly();
    Ok(readonly
        .as_slice()
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?
        .to_vec())
}

pub fn vec3s(rows: Vec<[f32; 3]>) -> Vec<Vec3> {
    rows.into_iter().map(Vec3::from).collect()
}

pub fn vec2s(rows: Vec<[f32; 2]>) -> Vec<Vec2> {
    rows.into_iter().map(Vec2::from).collect()
}

/// A read-only `(n, width)` numpy view of `data`, kept alive by `owner`
/// (the Python object that owns the Rust vector). No copy.
///
/// The owner must never change or free `data` while it lives: the
/// classes that use this are frozen and their vectors are never touched
/// after construction.
pub fn view2<'py, T: Element>(
    owner: Bound<'py, PyAny>,
    data: &[T],
    width: usize,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let view = ArrayView2::from_shape((data.len() / width, width), data)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    // SAFETY: `owner` holds the vector `data` points into and never
    // mutates or drops it while alive; the array keeps `owner` alive.
    let array = unsafe { PyArray2::borrow_from_array(&view, owner) };
    array.call_method1("setflags", (false,))?;
    Ok(array)
}

/// A read-only 1-D numpy view of `data`, kept alive by `owner`.
pub fn view1<'py, T: Element>(
    owner: Bound<'py, PyAny>,
    data: &[T],
) -> PyResult<Bound<'py, PyArray1<T>>> {
    let view = ArrayView1::from(data);
    // SAFETY: as in `view2`.
    let array = unsafe { PyArray1::borrow_from_array(&view, owner) };
    array.call_method1("setflags", (false,))?;
    Ok(array)
}

/// Floats of `Vec3`s, as a flat slice (Vec3 is three packed f32).
pub fn flat3(v: &[Vec3]) -> &[f32] {
    bytemuck::cast_slice(v)
}

/// Floats of `Vec2`s, as a flat slice.
pub fn flat2(v: &[Vec2]) -> &[f32] {
    bytemuck::cast_slice(v)
}

/// Owned `(n, 3)` array from `Vec3`s (moved, not copied element-wise).
pub fn owned3<'py>(py: Python<'py>, v: Vec<Vec3>) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let n = v.len();
    let flat: Vec<f32> = bytemuck::allocation::cast_vec(v);
    PyArray1::from_vec(py, flat).reshape([n, 3])
}

/// Owned `(n, 2)` array from `Vec2`s.
pub fn owned2<'py>(py: Python<'py>, v: Vec<Vec2>) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let n = v.len();
    let flat: Vec<f32> = bytemuck::allocation::cast_vec(v);
    PyArray1::from_vec(py, flat).reshape([n, 2])
}

/// A 2-D array as `(height, width, texels)`, float32, row-major.
pub fn image(value: &Bound<'_, PyAny>, what: &str) -> PyResult<(u32, u32, Vec<f32>)> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    let array = numpy
        .call_method1("ascontiguousarray", (value, numpy::dtype::<f32>(py)))
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    let array = array
        .cast_into::<numpy::PyArrayDyn<f32>>()
        .map_err(|_| PyValueError::new_err(format!("{what}: expected a numeric array")))?;
    let (height, width) = match array.shape() {
        [h, w] => (*h, *w),
        shape => {
            return Err(PyValueError::new_err(format!(
                "{what}: expected a 2-D array (height, width), got shape {shape:?}"
            )));
        }
    };
    let narrow = |n: usize| {
        u32::try_from(n)
            .map_err(|_| PyValueError::new_err(format!("{what}: {n} texels across is too many")))
    };
    let readonly = array.readonly();
    let texels = readonly
        .as_slice()
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?
        .to_vec();
    Ok((narrow(height)?, narrow(width)?, texels))
}
