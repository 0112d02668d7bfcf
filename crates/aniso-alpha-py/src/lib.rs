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
mod las_writer;
mod options;
mod progress;
mod regions;
mod report;
mod run;
mod split;
mod tiles;

use std::path::PathBuf;
use std::sync::Arc;

use aniso_alpha::alpha::AlphaComplex;
use aniso_alpha::aniso::Anisotropy;
use aniso_alpha::delaunay::Triangulation;
use aniso_alpha::detect::quantized::Quantization;
use aniso_alpha::detect::Detection;
use aniso_alpha::io::{
    las_point_count, read_las_range, read_las_range_records, read_points, write_labelled_cloud,
    Attribute, Format, Labelled, LasSource, PointCloud, ReadOptions, ReadWarning,
};
use aniso_alpha::options::{run_warnings, Style};
use aniso_alpha::report::{part_meshes, PartMeshes};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use convert::{rows_to_numpy, values_to_numpy, Points};
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

/// What a detection returns to Python: labels (int64 (n,)), part labels
/// (int64 (n,)), the JSON text of `{"structures": [...], "parameters":
/// {...}}`, the warnings the CLI would print, and the detection itself
/// (for `write`).
pub(crate) type DetectOut<'py> = (
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    String,
    Vec<String>,
    PyDetection,
);

/// A detection kept on the Rust side, for the meshes `write` adds to a
/// PLY (opaque to Python).
#[pyclass(frozen, name = "NativeDetection", module = "aniso_alpha._native")]
pub struct PyDetection {
    det: Arc<Detection>,
}

impl PyDetection {
    /// The Python side of a finished detection: labels, part labels,
    /// report and warnings, and the detection.
    pub(crate) fn output<'py>(
        py: Python<'py>,
        det: Detection,
        json: String,
        warnings: Vec<String>,
    ) -> DetectOut<'py> {
        let labels = det.labels.clone().into_pyarray(py);
        let parts = det.part_labels().into_pyarray(py);
        (
            labels,
            parts,
            json,
            warnings,
            PyDetection { det: Arc::new(det) },
        )
    }
}

/// The normals of a call (an array-like of shape (n, 3)); a `ValueError`
/// naming them otherwise.
fn extract_normals<'py>(n: &Bound<'py, PyAny>) -> PyResult<Points<'py>> {
    Points::extract(n).map_err(|e| PyValueError::new_err(format!("normals: {e}")))
}

/// A detection's input from Python: its points, their normals if given,
/// and the thread count, each checked.
pub(crate) struct DetectInput<'py> {
    points: Points<'py>,
    normals: Option<Points<'py>>,
    /// The threads of the call's pool.
    pub threads: usize,
}

impl<'py> DetectInput<'py> {
    /// Extracts the points, the normals (`ValueError` naming them) and
    /// the thread count.
    pub(crate) fn extract(
        points: &Bound<'py, PyAny>,
        normals: Option<&Bound<'py, PyAny>>,
        threads: Option<i64>,
    ) -> PyResult<Self> {
        Ok(DetectInput {
            points: Points::extract(points)?,
            normals: normals.map(extract_normals).transpose()?,
            threads: thread_count(threads)?,
        })
    }

    /// The points.
    pub(crate) fn points(&self) -> &[[f64; 3]] {
        self.points.as_slice()
    }

    /// The normals, if given.
    pub(crate) fn normals(&self) -> Option<&[[f64; 3]]> {
        self.normals.as_ref().map(|n| n.as_slice())
    }
}

/// Structure detection (docs/method.md §4): `structure` is "lines" or
/// "planes", `options` the keyword arguments of `aniso_alpha.detect`
/// (alpha, lambda2, lambda3, min_size, sampler, m1, m2, step, epsilon,
/// tile), built into a detector as the CLI builds its flags
/// ([`DetectOptions::build`](aniso_alpha::options::DetectOptions::build)).
///
/// `progress`, when given, is called as `progress(done, total)` after each
/// orientation scanned, from the worker threads (the GIL taken for the
/// call); returning `False` cancels the run, and an exception it raises
/// cancels the run and is raised again from here.
///
/// `outlines` false skips the plane parts' outlines and meshes
/// ([`Detector::outlines`](aniso_alpha::detect::Detector::outlines)):
/// everything else is the same.
#[pyfunction]
#[pyo3(signature = (points, structure, options = None, threads = None, normals = None, progress = None, outlines = true))]
#[allow(clippy::too_many_arguments)]
fn detect<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    structure: &str,
    options: Option<&Bound<'py, PyDict>>,
    threads: Option<i64>,
    normals: Option<&Bound<'py, PyAny>>,
    progress: Option<Py<PyAny>>,
    outlines: bool,
) -> PyResult<DetectOut<'py>> {
    let options = options::detect_options(structure, options)?;
    let input = DetectInput::extract(points, normals, threads)?;
    let (pts, normals, threads) = (input.points(), input.normals(), input.threads);
    // The whole call (estimation included) runs on the pool of `detached`,
    // which the library's parallel loops use: no `Detector::threads`, which
    // would start a second pool.
    let callback = progress.map(progress::Callback::new);
    let (det, json, warnings) = detached(py, threads, |n| {
        // Coordinates in steps coarser than a neighbourhood (a depth
        // camera's) are seen dithered within their step, as the CLI sees
        // them.
        let quantization = Quantization::of(pts);
        let seen = quantization.seen(pts);
        let seen: &[[f64; 3]] = &seen;
        let mut detector = options::build(&options, seen, normals)?.outlines(outlines);
        if let Some(cb) = &callback {
            detector = detector.progress(cb.tick());
        }
        let mut warnings = quantization.describe();
        warnings.extend(run_warnings(
            &options,
            &detector,
            pts.len(),
            n,
            Style::Python,
        ));
        let det = detector.run(seen).map_err(|e| {
            callback
                .as_ref()
                .and_then(|cb| cb.error(&e))
                .unwrap_or_else(|| value_error(e))
        })?;
        let json = report::detection_json(&det, &detector, &quantization);
        Ok((det, json, warnings))
    })?;
    Ok(PyDetection::output(py, det, json, warnings))
}

/// A LAS/LAZ file's header, VLRs and point records, kept for `write` to
/// copy every record byte for byte (opaque to Python).
#[pyclass(frozen, name = "LasSource", module = "aniso_alpha._native")]
pub struct PyLas {
    las: Arc<LasSource>,
}

/// What `read` returns: points (float64 (n, 3)), the attributes as (name,
/// 1-D array of the file's type) in file order, the normals (float64 (n,
/// 3)) when the file gives them, the reader's warnings, a LAS/LAZ file's
/// records, the format's name, and when an organized cloud's points
/// without a return were left out, the file row of each point kept.
type ReadOut<'py> = (
    Bound<'py, PyArray2<f64>>,
    Vec<(String, Bound<'py, PyAny>)>,
    Option<Bound<'py, PyArray2<f64>>>,
    Vec<String>,
    Option<PyLas>,
    &'static str,
    Option<Bound<'py, PyArray1<i64>>>,
);

/// The points of a point file in file order, with every attribute the
/// file has (as the CLI reads an input for `detect --output`); the
/// normals are those `detect` uses: a PLY's `nx ny nz` or a PCD's
/// `normal_x normal_y normal_z`.
/// With `start` or `count`, the points `start..start + count` of a LAS/LAZ
/// file alone ([`read_las_range`]).
#[pyfunction]
#[pyo3(signature = (path, attributes = true, start = None, count = None))]
fn read(
    py: Python<'_>,
    path: PathBuf,
    attributes: bool,
    start: Option<u64>,
    count: Option<u64>,
) -> PyResult<ReadOut<'_>> {
    let (cloud, format, rows) = detached(py, 1, |_| {
        let options = ReadOptions {
            attributes,
            ..ReadOptions::default()
        };
        let format = Format::resolve(&path, &options).map_err(io_error)?;
        let cloud = match (start, count) {
            (None, None) => read_points(&path, &options),
            _ if format != Format::Las => {
                return Err(PyValueError::new_err(format!(
                    "{}: a range of points (start, count) is read from LAS/LAZ files only",
                    path.display()
                )))
            }
            (s, c) => read_las_range(&path, s.unwrap_or(0), c.unwrap_or(u64::MAX), &options),
        }
        .map_err(io_error)?;
        // An organized cloud's points without a return (NaN) are left
        // out, as Open3D's reader does with `remove_nan_points=True`; their
        // rows are kept.
        let (cloud, rows) = match cloud.finite_rows() {
            None => (cloud, None),
            Some(rows) => {
                let mut kept = cloud.select(&rows);
                kept.warnings = cloud.warnings;
                (kept, Some(rows))
            }
        };
        Ok((cloud, format, rows))
    })?;
    let normals = match format {
        Format::Ply | Format::Pcd => cloud.normals().map(|n| rows_to_numpy(py, n)),
        _ => None,
    };
    let warnings = cloud
        .warnings
        .iter()
        .map(|w| match w {
            ReadWarning::NoReturn { .. } => {
                format!("{w}: left out of the Cloud (Cloud.rows: each point's row in the file)")
            }
            _ => w.to_string(),
        })
        .collect();
    let las = cloud.las.map(|l| PyLas { las: Arc::from(l) });
    let attrs = cloud
        .attributes
        .into_iter()
        .map(|a| (a.name, values_to_numpy(py, a.values)))
        .collect();
    let name = match format {
        Format::Text => "text",
        Format::Ply => "ply",
        Format::Las => "las",
        Format::Pcd => "pcd",
        Format::E57 => "e57",
    };
    Ok((
        rows_to_numpy(py, cloud.points),
        attrs,
        normals,
        warnings,
        las,
        name,
        rows.map(|r| {
            r.into_iter()
                .map(i64::from)
                .collect::<Vec<_>>()
                .into_pyarray(py)
        }),
    ))
}

/// Writes the labelled cloud as `aniso-alpha detect --output` does
/// ([`write_labelled_cloud`]): the points with their attributes (a LAS
/// source's records byte for byte when its point count matches), the
/// structure and part ids, the parts' meshes (PLY) when the detection is
/// given, and `classify` as the structures' LAS classification.
#[pyfunction]
#[pyo3(signature = (path, points, attributes, las, labels, part_labels, detection = None, classify = None))]
#[allow(clippy::too_many_arguments)]
fn write(
    py: Python<'_>,
    path: PathBuf,
    points: &Bound<'_, PyAny>,
    attributes: Vec<(String, Bound<'_, PyAny>)>,
    las: Option<&PyLas>,
    labels: PyReadonlyArray1<'_, i64>,
    part_labels: PyReadonlyArray1<'_, i64>,
    detection: Option<&PyDetection>,
    classify: Option<u8>,
) -> PyResult<()> {
    let points = Points::extract(points)?;
    let n = points.as_slice().len();
    let mut attrs = Vec::with_capacity(attributes.len());
    for (name, values) in &attributes {
        attrs.push(Attribute::new(
            name.clone(),
            convert::numpy_to_values(name, values, n)?,
        ));
    }
    let cloud = PointCloud {
        points: points.as_slice().to_vec(),
        attributes: attrs,
        las: las.map(|l| Box::new(LasSource::clone(&l.las))),
        ..PointCloud::default()
    };
    let det = detection.map(|d| Arc::clone(&d.det));
    let (labels, part_labels) = (labels.as_slice()?, part_labels.as_slice()?);
    detached(py, 1, |_| {
        let meshes = match &det {
            Some(d) if d.labels.len() == n => part_meshes(d, &cloud.points),
            _ => PartMeshes::default(),
        };
        let labelled = Labelled {
            edges: &meshes.edges,
            faces: &meshes.faces,
            element_labels: &meshes.element_labels,
            classify,
            ..Labelled::new(labels, part_labels)
        };
        write_labelled_cloud(&path, &cloud, &labelled).map_err(io_error)
    })
}

/// The points `start..start + count` of a LAS/LAZ file and their records
/// undecoded ([`read_las_range_records`]): what a labelled copy needs.
#[pyfunction]
fn read_las_records<'py>(
    py: Python<'py>,
    path: PathBuf,
    start: u64,
    count: u64,
) -> PyResult<(Bound<'py, PyArray2<f64>>, PyLas)> {
    let cloud = detached(py, 1, |_| {
        read_las_range_records(&path, start, count).map_err(io_error)
    })?;
    let las = cloud
        .las
        .map(|l| PyLas { las: Arc::from(l) })
        .ok_or_else(|| PyValueError::new_err("no LAS records read"))?;
    Ok((rows_to_numpy(py, cloud.points), las))
}

/// The number of points a LAS/LAZ file declares ([`las_point_count`]).
#[pyfunction]
fn las_points(py: Python<'_>, path: PathBuf) -> PyResult<u64> {
    detached(py, 1, |_| las_point_count(&path).map_err(io_error))
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
    use super::las_writer::PyLasLabelWriter;
    #[pymodule_export]
    use super::regions::{detect_regions, region_plan, region_task, PyRegionJoin, PyRegionPlan};
    #[pymodule_export]
    use super::split::{plan, tile_step, PyPlan};
    #[pymodule_export]
    use super::tiles::{region_cells, region_grid, region_select, region_window, PyRegionJoined};
    #[pymodule_export]
    use super::{
        _panic, _points_address, alpha_intervals, delaunay, detect, las_points, read,
        read_las_records, write, PyDetection, PyLas,
    };

    use pyo3::prelude::*;

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        m.add("__version__", env!("CARGO_PKG_VERSION"))
    }
}
