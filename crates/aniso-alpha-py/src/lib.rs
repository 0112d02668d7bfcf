//! The Python extension module `aniso_alpha._native`.
//!
//! The public API is the Python package `aniso_alpha` (`python/aniso_alpha`),
//! whose functions validate their keyword arguments, call the functions
//! here and wrap the results (`Detection`, `AlphaIntervals`). Each function
//! here converts its points once (a C-contiguous float64 array is borrowed,
//! not copied, see [`convert::Points`]), releases the GIL and runs the
//! library on a rayon pool of its own ([`run::detached`]), and turns every
//! library error into `ValueError` (or `OSError` for files) with the
//! library's message; a panic becomes `RuntimeError`, never a crash.

mod convert;
mod errors;
mod report;
mod run;
mod split;

use std::path::PathBuf;

use aniso_alpha::alpha::AlphaComplex;
use aniso_alpha::aniso::Anisotropy;
use aniso_alpha::delaunay::Triangulation;
use aniso_alpha::detect::StructureKind;
use aniso_alpha::detect::{Detector, Given};
use aniso_alpha::io::{read_points, ReadOptions};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use convert::{rows_to_numpy, Points};
use errors::{io_error, value_error};
use run::{detached, thread_count};

/// The finite tetrahedra of the Delaunay tetrahedralization of `points`:
/// uint32 (m, 4), input indices, each positively oriented.
#[pyfunction]
#[pyo3(signature = (points, threads = None))]
fn delaunay<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    threads: Option<i64>,
) -> PyResult<Bound<'py, PyArray2<u32>>> {
    let points = Points::extract(points)?;
    let threads = thread_count(threads)?;
    let pts = points.as_slice();
    let tets = detached(py, threads, |n| {
        let tri = Triangulation::with_threads(pts, n).map_err(value_error)?;
        Ok(tri.finite_tets_input().collect::<Vec<[u32; 4]>>())
    })?;
    Ok(rows_to_numpy(py, tets))
}

/// Edges (uint32 (m, 2)), their [alpha_min, alpha_max] (float64 (m, 2)),
/// triangles (uint32 (t, 3)) and theirs (float64 (t, 2)), of Del(Q·P) with
/// Q = diag(elongation)·R(euler); vertex indices ascending, rows sorted.
type Intervals<'py> = (
    Bound<'py, PyArray2<u32>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<u32>>,
    Bound<'py, PyArray2<f64>>,
);

/// The alpha intervals of every Delaunay edge and triangle.
#[pyfunction]
#[pyo3(signature = (points, elongation = None, euler = None, threads = None))]
fn alpha_intervals<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    elongation: Option<[f64; 3]>,
    euler: Option<[f64; 3]>,
    threads: Option<i64>,
) -> PyResult<Intervals<'py>> {
    let points = Points::extract(points)?;
    let threads = thread_count(threads)?;
    let [theta, psi, phi] = euler.unwrap_or([0.0; 3]);
    let e = elongation.unwrap_or([1.0; 3]);
    let aniso = Anisotropy::from_euler(theta, psi, phi, e).map_err(value_error)?;
    let euclidean = elongation.is_none() && euler.is_none();
    let pts = points.as_slice();
    let (edges, edge_alpha, tris, tri_alpha) = detached(py, threads, |n| {
        // As `aniso-alpha alpha`: the points mapped by Q (unless Euclidean),
        // triangulated, the intervals computed, rows sorted by vertices.
        let tri = if euclidean {
            Triangulation::with_threads(pts, n)
        } else {
            Triangulation::with_threads(&aniso.transform(pts), n)
        }
        .map_err(value_error)?;
        let ac = AlphaComplex::new(tri);
        let mut edges: Vec<_> = ac.edges().collect();
        edges.sort_unstable_by_key(|e| e.vertices);
        let mut tris: Vec<_> = ac.triangles().collect();
        tris.sort_unstable_by_key(|t| t.vertices);
        Ok((
            edges.iter().map(|e| e.vertices).collect::<Vec<_>>(),
            edges
                .iter()
                .map(|e| [e.alpha_min, e.alpha_max])
                .collect::<Vec<_>>(),
            tris.iter().map(|t| t.vertices).collect::<Vec<_>>(),
            tris.iter()
                .map(|t| [t.alpha_min, t.alpha_max])
                .collect::<Vec<_>>(),
        ))
    })?;
    Ok((
        rows_to_numpy(py, edges),
        rows_to_numpy(py, edge_alpha),
        rows_to_numpy(py, tris),
        rows_to_numpy(py, tri_alpha),
    ))
}

/// Labels (int64 (n,)), part labels (int64 (n,)) and the JSON text of
/// `{"structures": [...], "parameters": {...}}`.
pub(crate) type DetectOut<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>, String);

/// The parameters of a detection call, checked.
pub(crate) struct Params {
    kind: StructureKind,
    given: Given,
}

impl Params {
    /// Checks `structure` and the values given.
    pub(crate) fn new(
        structure: &str,
        alpha: Option<f64>,
        lambda2: Option<f64>,
        lambda3: Option<f64>,
        min_size: Option<i64>,
    ) -> PyResult<Self> {
        let planes = match structure {
            "lines" => false,
            "planes" => true,
            other => {
                return Err(PyValueError::new_err(format!(
                    "structure must be \"lines\" or \"planes\", got {other:?}"
                )))
            }
        };
        if !planes && lambda2.is_some() {
            return Err(PyValueError::new_err(
                "lambda2 is a parameter of planes (lines use lambda3 only)",
            ));
        }
        let min_size = min_size
            .map(|m| {
                u32::try_from(m).map_err(|_| {
                    PyValueError::new_err(format!(
                        "bad parameter: min_size must be between 1 and {}, got {m}",
                        u32::MAX
                    ))
                })
            })
            .transpose()?;
        let kind = if planes {
            StructureKind::Planes
        } else {
            StructureKind::Lines
        };
        Ok(Params {
            kind,
            given: Given {
                alpha,
                lambda2,
                lambda3,
                min_size,
            },
        })
    }
}

/// The normals of a call (an array-like of shape (n, 3)); a `ValueError`
/// naming them otherwise.
pub(crate) fn extract_normals<'py>(n: &Bound<'py, PyAny>) -> PyResult<Points<'py>> {
    Points::extract(n).map_err(|e| PyValueError::new_err(format!("normals: {e}")))
}

/// The detector of a call: with alpha, lambda3 and min_size all given, the
/// CLI's explicit run (the paper's box sampler; lambda2 of planes defaults
/// to lambda3); otherwise parameters and orientations from the data, the
/// given ones kept ([`Detector::auto`]).
pub(crate) fn detector_for(
    p: &Params,
    pts: &[[f64; 3]],
    normals: Option<&[[f64; 3]]>,
) -> PyResult<Detector> {
    let g = &p.given;
    Ok(match (g.alpha, g.lambda3, g.min_size) {
        (Some(alpha), Some(lambda3), Some(min_size)) => {
            let d = match p.kind {
                StructureKind::Planes => {
                    Detector::planes(alpha, g.lambda2.unwrap_or(lambda3), lambda3, min_size)
                }
                StructureKind::Lines => Detector::lines(alpha, lambda3, min_size),
            };
            match normals {
                Some(n) => d.normals(n),
                None => d,
            }
        }
        _ => match normals {
            Some(n) => Detector::auto_oriented(p.kind, pts, n, g, 12).map_err(value_error)?,
            None => Detector::auto(p.kind, pts, g).map_err(value_error)?,
        },
    })
}

/// Structure detection (docs/method.md §4): `structure` is "lines" or "planes". With
/// alpha, lambda3 and min_size all given, the CLI's explicit run (the
/// paper's box sampler); otherwise [`Detector::auto`] estimates what is
/// missing and scans the data orientation set.
#[pyfunction]
#[pyo3(signature = (points, structure, alpha = None, lambda2 = None, lambda3 = None, min_size = None, threads = None, normals = None))]
#[allow(clippy::too_many_arguments)]
fn detect<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    structure: &str,
    alpha: Option<f64>,
    lambda2: Option<f64>,
    lambda3: Option<f64>,
    min_size: Option<i64>,
    threads: Option<i64>,
    normals: Option<&Bound<'py, PyAny>>,
) -> PyResult<DetectOut<'py>> {
    let params = Params::new(structure, alpha, lambda2, lambda3, min_size)?;
    let points = Points::extract(points)?;
    let normals = normals.map(extract_normals).transpose()?;
    let threads = thread_count(threads)?;
    let pts = points.as_slice();
    let normals = normals.as_ref().map(|n| n.as_slice());
    // The whole call (estimation included) runs on the pool of `detached`,
    // which the library's parallel loops use: no `Detector::threads`, which
    // would start a second pool.
    let (labels, parts, json) = detached(py, threads, |_| {
        let detector = detector_for(&params, pts, normals)?;
        let det = detector.run(pts).map_err(value_error)?;
        let json = report::detection_json(&det, &detector);
        let parts = det.part_labels();
        Ok((det.labels, parts, json))
    })?;
    Ok((labels.into_pyarray(py), parts.into_pyarray(py), json))
}

/// The points of a point file, float64 (n, 3), in file order.
#[pyfunction]
fn read(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let cloud = detached(py, 1, |_| {
        read_points(&path, &ReadOptions::default()).map_err(io_error)
    })?;
    Ok(rows_to_numpy(py, cloud.points))
}

/// The address of the memory the library reads `points` from (tests check
/// that a C-contiguous float64 array is used in place).
#[pyfunction]
fn _points_address(points: &Bound<'_, PyAny>) -> PyResult<usize> {
    Ok(Points::extract(points)?.address())
}

/// Panics inside [`detached`], on the calling thread or on a worker of the
/// pool (tests check that this raises `RuntimeError`, not a crash).
#[pyfunction]
fn _panic(py: Python<'_>, on_worker: bool) -> PyResult<()> {
    detached(py, 2, |_| {
        if on_worker {
            rayon::join(|| (), || panic!("test panic on a worker"));
        }
        panic!("test panic");
    })
}

/// The Rust side of `aniso_alpha` (private: use the package's functions).
#[pymodule(name = "_native")]
mod native {
    #[pymodule_export]
    use super::split::{plan, tile_step, PyPlan};
    #[pymodule_export]
    use super::{_panic, _points_address, alpha_intervals, delaunay, detect, read};

    use pyo3::prelude::*;

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        m.add("__version__", env!("CARGO_PKG_VERSION"))
    }
}
