//! `aniso_alpha.detect_regions`: the detection region by region
//! (`aniso_alpha::detect::regions`), for clouds whose whole run would not
//! fit in memory.

use aniso_alpha::detect::regions::{detect_by_regions_with_progress, side_for};
use aniso_alpha::detect::Primitive;
use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::Points;
use crate::errors::value_error;
use crate::run::{detached, thread_count};
use crate::{extract_normals, options, progress};

/// One joined part: id, structure, points, pieces, then a plane's
/// `[a, b, c, d]` (and nothing) or a line's direction (and a point on it),
/// and its RMS distance.
type PartRow = (u32, u32, usize, usize, Vec<f64>, Vec<f64>, f64);

/// What `detect_regions` returns: structure and part labels (int64 (n,)),
/// the joined parts, the region side (`None`: one whole run, the cloud
/// being about one region) and the region count, widenings, joins and
/// regions of one position left as background.
type RegionsOut<'py> = (
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Vec<PartRow>,
    Option<f64>,
    usize,
    usize,
    usize,
    usize,
);

/// The detection region by region (docs/method.md §8 "Regions"): regions of
/// side `side` (input units), or of about 500,000 points when `side` is
/// `None`; a cloud of about one region runs whole. `options`, `normals`,
/// `threads` and `progress` (called after each region; `False` cancels)
/// as for `detect`.
#[pyfunction]
#[pyo3(signature = (points, structure, side = None, options = None, threads = None, normals = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn detect_regions<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    structure: &str,
    side: Option<f64>,
    options: Option<&Bound<'py, PyDict>>,
    threads: Option<i64>,
    normals: Option<&Bound<'py, PyAny>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<RegionsOut<'py>> {
    let options = options::detect_options(structure, options)?;
    let points = Points::extract(points)?;
    let normals = normals.map(extract_normals).transpose()?;
    let threads = thread_count(threads)?;
    let pts = points.as_slice();
    let normals = normals.as_ref().map(|n| n.as_slice());
    let callback = progress.map(progress::Callback::new);
    let side = match side {
        Some(s) if !(s.is_finite() && s > 0.0) => {
            return Err(PyValueError::new_err(format!(
                "region side {s}: must be positive and finite"
            )))
        }
        Some(s) => Some(s),
        None => side_for(pts),
    };
    let run = detached(py, threads, |_| {
        let region_side = side.unwrap_or(f64::INFINITY);
        let build = |ids: &[u32]| {
            let sub: Vec<[f64; 3]> = ids.iter().map(|&i| pts[i as usize]).collect();
            let nsub: Option<Vec<[f64; 3]>> =
                normals.map(|n| ids.iter().map(|&i| n[i as usize]).collect());
            options.build(&sub, nsub.as_deref(), aniso_alpha::options::Style::Python)
        };
        let tick = callback.as_ref().map(|cb| cb.tick());
        let mut on_region =
            |done: usize, total: usize| tick.as_ref().is_none_or(|t| t(done, total));
        // An infinite side is one region: the whole cloud, as `detect`.
        let side = if region_side.is_finite() {
            region_side
        } else {
            let (lo, hi) = aniso_alpha::geometry::bounding_box(pts);
            2.0 * (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1.0)
        };
        detect_by_regions_with_progress(pts, side, build, &mut on_region).map_err(|e| {
            callback
                .as_ref()
                .and_then(|cb| cb.error(&e))
                .unwrap_or_else(|| value_error(e))
        })
    })?;
    let parts: Vec<PartRow> = run
        .parts
        .iter()
        .map(|p| {
            let (a, b, rms) = match &p.primitive {
                Primitive::Plane(f) => (
                    p.primitive
                        .plane_equation()
                        .map_or_else(Vec::new, |e| e.to_vec()),
                    Vec::new(),
                    f.rms_residual,
                ),
                Primitive::Line(f) => (f.direction.to_vec(), f.centroid.to_vec(), f.rms_residual),
                Primitive::None => (Vec::new(), Vec::new(), f64::NAN),
            };
            (p.id, p.structure, p.points, p.pieces, a, b, rms)
        })
        .collect();
    Ok((
        run.labels.into_pyarray(py),
        run.part_labels.into_pyarray(py),
        parts,
        side,
        run.regions,
        run.widened,
        run.joins,
        run.skipped,
    ))
}
