//! numpy arrays in and out: shape checks with errors that say what was
//! expected, and read-only views of Rust vectors owned by a Python object.

use glam::{Vec2, Vec3};
use numpy::ndarray::{ArrayView1, ArrayView2};
use numpy::{Element, PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// `value` (anything `numpy.asarray` accepts) as a C-contiguous numpy
/// array of `T`, converted if need be. `what` names the argument in
/// errors.
fn contiguous<'py, T: Element>(
    value: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    numpy
        .call_method1("ascontiguousarray", (value, numpy::dtype::<T>(py)))
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?
        .cast_into::<PyArrayDyn<T>>()
        .map_err(|_| PyValueError::new_err(format!("{what}: expected a numeric array")))
}

/// Refuses an array of indices (triangles, offsets, ids) whose values
/// are not integers: numpy would cast floats by truncating them (1.7
/// becomes 1) and bools to 0 and 1, silently. Empty input passes (an
/// empty list is a float array to numpy).
pub fn require_integers(value: &Bound<'_, PyAny>, what: &str) -> PyResult<()> {
    let py = value.py();
    let array = py
        .import("numpy")?
        .call_method1("asarray", (value,))
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    let size: usize = array.getattr("size")?.extract()?;
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    if size == 0 || kind == "i" || kind == "u" {
        return Ok(());
    }
    let dtype = array.getattr("dtype")?.str()?.to_string();
    Err(PyTypeError::new_err(format!(
        "{what}: expected integer indices, got an array of {dtype} (numpy would truncate or reinterpret them): convert deliberately, e.g. .astype(np.uint32)"
    )))
}

/// `f` of the values of a contiguous array, in order.
fn with_values<T: Element, R>(
    array: &Bound<'_, PyArrayDyn<T>>,
    what: &str,
    f: impl FnOnce(&[T]) -> R,
) -> PyResult<R> {
    let readonly = array.readonly();
    let values = readonly
        .as_slice()
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    Ok(f(values))
}

/// A numpy array (or anything `numpy.asarray` accepts) as a contiguous
/// `(n, WIDTH)` array of `T`, copied into a vector. `what` names the
/// argument in errors.
pub fn rows<T: Element + Copy, const WIDTH: usize>(
    value: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<Vec<[T; WIDTH]>> {
    let array = contiguous::<T>(value, what)?;
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
    with_values(&array, what, |flat| {
        flat.chunks_exact(WIDTH)
            .map(|c| std::array::from_fn(|i| c[i]))
            .collect()
    })
}

/// A 1-D array of `T`, copied.
pub fn column<T: Element + Copy>(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<T>> {
    let array = contiguous::<T>(value, what)?;
    if array.ndim() != 1 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected a 1-D array, got shape {:?}",
            array.shape()
        )));
    }
    with_values(&array, what, <[T]>::to_vec)
}

/// A 2-D array as `(height, width, texels)`, float32, row-major.
pub fn image(value: &Bound<'_, PyAny>, what: &str) -> PyResult<(u32, u32, Vec<f32>)> {
    let array = contiguous::<f32>(value, what)?;
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
    let texels = with_values(&array, what, <[f32]>::to_vec)?;
    Ok((narrow(height)?, narrow(width)?, texels))
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

/// The f32s of packed float vectors (`Vec2`, `Vec3`), as one flat slice.
pub fn floats<V: bytemuck::Pod>(v: &[V]) -> &[f32] {
    bytemuck::cast_slice(v)
}

/// An owned `(n, k)` float32 array from `n` values of `k` packed f32s
/// (`Vec2`, `Vec3`): the vector is handed to numpy, not copied.
pub fn owned_rows<V: bytemuck::Pod>(
    py: Python<'_>,
    v: Vec<V>,
) -> PyResult<Bound<'_, PyArray2<f32>>> {
    let (n, width) = (v.len(), size_of::<V>() / size_of::<f32>());
    let flat: Vec<f32> = bytemuck::allocation::cast_vec(v);
    PyArray1::from_vec(py, flat).reshape([n, width])
}
