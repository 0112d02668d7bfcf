//! Points in (any array-like of shape (n, 3)), numpy arrays out.

use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use aniso_alpha::io::Values;

/// Points borrowed from a C-contiguous float64 numpy array of shape (n, 3):
/// the caller's own array when it is one, else a converted copy.
pub struct Points<'py> {
    array: PyReadonlyArray2<'py, f64>,
}

impl<'py> Points<'py> {
    /// Converts `obj` (an array-like of shape (n, 3)).
    ///
    /// A C-contiguous, aligned float64 ndarray is borrowed as it is,
    /// without a copy; anything else (lists, other dtypes, Fortran order,
    /// strided views, unaligned buffers) is converted by
    /// `numpy.require(obj, dtype=float64, requirements=("C", "A"))`.
    ///
    /// # Errors
    /// `ValueError` for a wrong shape or a non-real dtype (numpy's own
    /// errors for what it cannot convert).
    pub fn extract(obj: &Bound<'py, PyAny>) -> PyResult<Self> {
        if let Ok(a) = obj.cast::<PyArray2<f64>>() {
            // Unaligned buffers (e.g. numpy arrays unpickled from one
            // message frame, as Dask does) are copied below.
            let aligned = (a.data() as usize).is_multiple_of(std::mem::align_of::<f64>());
            if a.is_c_contiguous() && aligned {
                check_shape(a.as_untyped())?;
                return Ok(Points {
                    array: a.try_readonly()?,
                });
            }
        }
        let py = obj.py();
        let np = py.import("numpy")?;
        let a = np.call_method1("asarray", (obj,))?;
        let dtype = a.getattr("dtype")?;
        let kind: String = dtype.getattr("kind")?.extract()?;
        if !matches!(kind.as_str(), "i" | "u" | "f") {
            return Err(PyValueError::new_err(format!(
                "points must be real numbers, got an array of dtype {}",
                dtype.str()?
            )));
        }
        // C-contiguous and aligned, float64: a copy unless `a` already is.
        let kwargs = PyDict::new(py);
        kwargs.set_item("dtype", np.getattr("float64")?)?;
        kwargs.set_item("requirements", ("C", "A"))?;
        let a = np.call_method("require", (a,), Some(&kwargs))?;
        check_shape(a.cast::<PyUntypedArray>()?)?;
        let a = a.cast_into::<PyArray2<f64>>()?;
        Ok(Points {
            array: a.try_readonly()?,
        })
    }

    /// The points, in the array's memory.
    pub fn as_slice(&self) -> &[[f64; 3]] {
        // Contiguous by construction, and the shape was checked: (n, 3).
        let flat = self.array.as_slice().unwrap_or(&[]);
        flat.as_chunks::<3>().0
    }

    /// The address of the first coordinate (for the tests that check that
    /// a float64 C-contiguous array is not copied).
    pub fn address(&self) -> usize {
        self.as_slice().as_ptr() as usize
    }
}

fn check_shape(a: &Bound<'_, PyUntypedArray>) -> PyResult<()> {
    let shape = a.shape();
    if shape.len() != 2 || shape[1] != 3 {
        let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
        let dims = if dims.len() == 1 {
            format!("({},)", dims[0])
        } else {
            format!("({})", dims.join(", "))
        };
        return Err(PyValueError::new_err(format!(
            "points must be an array of shape (n, 3), got shape {dims}"
        )));
    }
    Ok(())
}

/// `rows` as a numpy array of shape (rows.len(), N), without a copy.
pub fn rows_to_numpy<'py, T: numpy::Element, const N: usize>(
    py: Python<'py>,
    rows: Vec<[T; N]>,
) -> Bound<'py, PyArray2<T>> {
    let m = rows.len();
    let flat: Vec<T> = rows.into_flattened();
    Array2::from_shape_vec((m, N), flat)
        .expect("m * N elements")
        .into_pyarray(py)
}

/// A column of attribute values as a 1-D numpy array of its type.
pub fn values_to_numpy<'py>(py: Python<'py>, values: Values) -> Bound<'py, PyAny> {
    match values {
        Values::I8(v) => v.into_pyarray(py).into_any(),
        Values::U8(v) => v.into_pyarray(py).into_any(),
        Values::I16(v) => v.into_pyarray(py).into_any(),
        Values::U16(v) => v.into_pyarray(py).into_any(),
        Values::I32(v) => v.into_pyarray(py).into_any(),
        Values::U32(v) => v.into_pyarray(py).into_any(),
        Values::I64(v) => v.into_pyarray(py).into_any(),
        Values::U64(v) => v.into_pyarray(py).into_any(),
        Values::F32(v) => v.into_pyarray(py).into_any(),
        Values::F64(v) => v.into_pyarray(py).into_any(),
    }
}

/// A 1-D numpy array of `n` values (bool, integers up to 64 bits or
/// floats) as a column of attribute values of that type; `name` is
/// the attribute's, for the error.
pub fn numpy_to_values(name: &str, obj: &Bound<'_, PyAny>, n: usize) -> PyResult<Values> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let a = np.call_method1("ascontiguousarray", (obj,))?;
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    if shape != [n] {
        return Err(PyValueError::new_err(format!(
            "attribute {name:?}: {} values for {n} points (a 1-D array of one value per point is needed), got shape {shape:?}",
            shape.iter().product::<usize>()
        )));
    }
    // Bools as uint8; any other dtype in native byte order (a file's
    // big-endian column, e.g.), without a copy when it already is.
    let a = if a.getattr("dtype")?.getattr("kind")?.extract::<String>()? == "b" {
        a.call_method1("astype", (np.getattr("uint8")?,))?
    } else {
        a
    };
    let native = a.getattr("dtype")?.call_method1("newbyteorder", ("=",))?;
    let a = np.call_method1("ascontiguousarray", (a, &native))?;
    let dtype = a.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    let size: usize = dtype.getattr("itemsize")?.extract()?;
    macro_rules! take {
        ($t:ty, $variant:ident) => {{
            let arr = a.cast::<numpy::PyArray1<$t>>()?.try_readonly()?;
            Values::$variant(arr.as_slice()?.to_vec())
        }};
    }
    Ok(match (kind.as_str(), size) {
        ("i", 1) => take!(i8, I8),
        ("u", 1) => take!(u8, U8),
        ("i", 2) => take!(i16, I16),
        ("u", 2) => take!(u16, U16),
        ("i", 4) => take!(i32, I32),
        ("u", 4) => take!(u32, U32),
        ("i", 8) => take!(i64, I64),
        ("u", 8) => take!(u64, U64),
        ("f", 4) => take!(f32, F32),
        ("f", 8) => take!(f64, F64),
        _ => {
            return Err(PyValueError::new_err(format!(
                "attribute {name:?}: dtype {} cannot be written (integers, floats or bools)",
                dtype.str()?
            )))
        }
    })
}
