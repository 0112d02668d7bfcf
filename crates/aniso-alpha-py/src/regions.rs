//! `aniso_alpha.detect_regions`: the detection region by region
//! (`aniso_alpha::detect::regions`), for clouds whose whole run would not
//! fit in memory.

use aniso_alpha::detect::quantized::Quantization;
use aniso_alpha::detect::regions::{
    detect_by_regions_with_progress, region_step, wider_margin, RegionJoin, RegionPlan, RegionRun,
    RegionStep,
};
use aniso_alpha::detect::DetectError;
use aniso_alpha::detect::Primitive;
use aniso_alpha::options::region_warnings;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::Points;
use crate::errors::value_error;
use crate::run::detached;
use crate::{options, progress, DetectInput};

/// One joined part: id, structure, points, pieces, then a plane's
/// `[a, b, c, d]` (and nothing) or a line's direction (and a point on it),
/// and its RMS distance.
type PartRow = (u32, u32, usize, usize, Vec<f64>, Vec<f64>, f64);

/// A region run as Python takes it: structure and part labels (int64
/// (n,)), the joined parts, the region count, widenings, joins, regions
/// of one position left as background, and the run's warnings.
pub type RunOut<'py> = (
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Vec<PartRow>,
    usize,
    usize,
    usize,
    usize,
    Vec<String>,
);

/// [`RunOut`] of `run`.
pub fn run_out(py: Python<'_>, run: RegionRun) -> RunOut<'_> {
    let parts = part_rows(&run);
    let warnings = region_warnings(&run);
    (
        run.labels.into_pyarray(py),
        run.part_labels.into_pyarray(py),
        parts,
        run.regions,
        run.widened,
        run.joins,
        run.skipped,
        warnings,
    )
}

/// The detection region by region (docs/method.md §8 "Regions"): regions of
/// side `side` (input units), or of about 250,000 points when `side` is
/// `None`; a cloud of at most 1,000,000 points runs whole. `options`, `normals`,
/// `threads` and `progress` (called after each region; `False` cancels)
/// as for `detect`. Returns the run ([`RunOut`]) and the region side
/// (`None`: one whole run, the cloud being about one region).
#[pyfunction]
#[pyo3(signature = (points, structure, side = None, options = None, threads = None, normals = None, progress = None, jobs = None))]
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
    jobs: Option<i64>,
) -> PyResult<(RunOut<'py>, Option<f64>)> {
    let options = options::detect_options(structure, options)?;
    let jobs = match jobs {
        None => 0,
        Some(j) if j >= 1 => j as usize,
        Some(j) => return Err(value_error(format!("jobs {j}: must be at least 1"))),
    };
    let input = DetectInput::extract(points, normals, threads)?;
    let (pts, normals, threads) = (input.points(), input.normals(), input.threads);
    let callback = progress.map(progress::Callback::new);
    // Coordinates in steps coarser than a neighbourhood: the regions see
    // them dithered, as `detect` does (the draw is per point, so every
    // region sees the same points).
    let quantization = detached(py, threads, |_| Ok(Quantization::of(pts)))?;
    let seen = quantization.seen(pts);
    let pts: &[[f64; 3]] = &seen;
    let (run_side, side) = region_side(pts, side);
    let run = detached(py, threads, |_| {
        let build = |ids: &[u32], sub: &[[f64; 3]]| {
            options.build_region(ids, sub, normals, aniso_alpha::options::Style::Python)
        };
        let tick = callback.as_ref().map(|cb| cb.tick());
        let mut on_region =
            |done: usize, total: usize| tick.as_ref().is_none_or(|t| t(done, total));
        detect_by_regions_with_progress(pts, run_side, jobs, build, &mut on_region).map_err(|e| {
            callback
                .as_ref()
                .and_then(|cb| cb.error(&e))
                .unwrap_or_else(|| value_error(e))
        })
    })?;
    let mut out = run_out(py, run);
    out.7.splice(0..0, quantization.describe());
    Ok((out, side))
}

/// The joined parts of a region run as rows ([`PartRow`]).
fn part_rows(run: &RegionRun) -> Vec<PartRow> {
    run.parts
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
        .collect()
}

/// The regions of a cloud, kept by a driver (`aniso_alpha.distributed.
/// detect_regions`): the grid and each region's core points.
#[pyclass(frozen, name = "RegionPlan", module = "aniso_alpha._native")]
pub struct PyRegionPlan {
    plan: RegionPlan,
    /// One region made to hold the whole cloud (no side given, and the
    /// cloud about one region).
    whole: bool,
}

/// The regions of `points` of side `side` (`None`: about 250,000 points a
/// region; a cloud of at most 1,000,000 points is one region).
#[pyfunction]
#[pyo3(signature = (points, side = None))]
pub fn region_plan(points: &Bound<'_, PyAny>, side: Option<f64>) -> PyResult<PyRegionPlan> {
    let points = Points::extract(points)?;
    let pts = points.as_slice();
    let (run_side, side) = region_side(pts, side);
    Ok(PyRegionPlan {
        plan: RegionPlan::new(pts, run_side).map_err(value_error)?,
        whole: side.is_none(),
    })
}

/// The side to run `pts` with and the side to report
/// ([`crate::tiles::region_side_extent`] of their bounding box).
fn region_side(pts: &[[f64; 3]], side: Option<f64>) -> (f64, Option<f64>) {
    if pts.is_empty() {
        return crate::tiles::region_side_extent([0.0; 3], [0.0; 3], 0, side);
    }
    let (lo, hi) = aniso_alpha::geometry::bounding_box(pts);
    crate::tiles::region_side_extent(lo, hi, pts.len(), side)
}

#[pymethods]
impl PyRegionPlan {
    fn __len__(&self) -> usize {
        self.plan.len()
    }

    /// The region side, or `None` when the plan is one region made to
    /// hold the whole cloud.
    #[getter]
    fn side(&self) -> Option<f64> {
        (!self.whole).then(|| self.plan.side())
    }

    /// The first margin of every region.
    #[getter]
    fn first_margin(&self) -> f64 {
        self.plan.first_margin()
    }

    /// Region `r`'s core points (uint32, ascending).
    fn core<'py>(&self, py: Python<'py>, r: usize) -> PyResult<Bound<'py, PyArray1<u32>>> {
        self.check(r)?;
        Ok(self.plan.core(r).to_vec().into_pyarray(py))
    }

    /// Region `r`'s points grown by `margin` (uint32, ascending).
    fn points_within<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        r: usize,
        margin: f64,
    ) -> PyResult<Bound<'py, PyArray1<u32>>> {
        self.check(r)?;
        let points = Points::extract(points)?;
        Ok(self
            .plan
            .points_within(points.as_slice(), r, margin)
            .into_pyarray(py))
    }
}

impl PyRegionPlan {
    fn check(&self, r: usize) -> PyResult<()> {
        if r < self.plan.len() {
            Ok(())
        } else {
            Err(PyValueError::new_err(format!(
                "region {r} of {}",
                self.plan.len()
            )))
        }
    }
}

/// What a region task returns: `("skip", 0.0, None)` for a region of one
/// position, `("wider", margin, None)` when its estimate
/// reaches past its margin, or `("step", margin, (part int64, structure
/// int64, part structures uint32, part axes float64 (p, 3) NaN when not
/// fitted, structures, part angle, lines, normals ignored))`.
type StepArrays<'py> = (
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<u32>>,
    Bound<'py, PyArray2<f64>>,
    u32,
    f64,
    bool,
    bool,
);

/// One region's task (a worker's half of `distributed.detect_regions`):
/// the detector of the region's `points` (its core and `margin`, in input
/// order) from their data and `options`, then its step, unless the
/// estimate reaches past `margin`.
#[pyfunction]
#[pyo3(signature = (points, structure, margin, options = None, normals = None, threads = None))]
pub fn region_task<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    structure: &str,
    margin: f64,
    options: Option<&Bound<'py, PyDict>>,
    normals: Option<&Bound<'py, PyAny>>,
    threads: Option<i64>,
) -> PyResult<(&'static str, f64, Option<StepArrays<'py>>)> {
    let options = options::detect_options(structure, options)?;
    let input = DetectInput::extract(points, normals, threads)?;
    let (pts, normals, threads) = (input.points(), input.normals(), input.threads);
    let out = detached(py, threads, |_| {
        let detector = match options.build(pts, normals, aniso_alpha::options::Style::Python) {
            Ok(d) => d,
            Err(DetectError::NoSpacing) => return Ok(("skip", 0.0, None)),
            Err(e) => return Err(value_error(e)),
        };
        if let Some(m) = wider_margin(&detector, margin).map_err(value_error)? {
            return Ok(("wider", m, None));
        }
        let step = region_step(detector, pts).map_err(value_error)?;
        Ok(("step", margin, Some(step)))
    })?;
    let (kind, m, step) = out;
    Ok((
        kind,
        m,
        step.map(|st| {
            let axes: Vec<[f64; 3]> = st
                .parts
                .iter()
                .map(|(_, a)| a.unwrap_or([f64::NAN; 3]))
                .collect();
            let ps: Vec<u32> = st.parts.iter().map(|(s, _)| *s).collect();
            (
                st.part.into_pyarray(py),
                st.structure.into_pyarray(py),
                ps.into_pyarray(py),
                crate::convert::rows_to_numpy(py, axes),
                st.structures,
                st.part_angle,
                st.lines,
                st.normals_ignored,
            )
        }),
    ))
}

/// A region step from Python (`region_task`'s arrays), as the joining
/// takes it.
type StepIn<'py> = (
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, u32>,
    PyReadonlyArray2<'py, f64>,
    u32,
    f64,
    bool,
    bool,
);

/// The joining of region steps on a driver (`distributed.detect_regions`):
/// `add` each region's step in the plan's order, then `finish`.
#[pyclass(name = "RegionJoin", module = "aniso_alpha._native")]
pub struct PyRegionJoin {
    join: Option<RegionJoin>,
}

#[pymethods]
impl PyRegionJoin {
    /// A joining over `n` points; with `scratch` (a folder), their part
    /// ids are kept in a file there rather than in memory.
    #[new]
    #[pyo3(signature = (n, scratch = None))]
    fn new(n: usize, scratch: Option<std::path::PathBuf>) -> PyResult<Self> {
        let join = match scratch {
            None => RegionJoin::new(n),
            Some(dir) => RegionJoin::with_scratch(n, &dir).map_err(value_error)?,
        };
        Ok(PyRegionJoin { join: Some(join) })
    }

    /// Counts a region whose margin was widened.
    fn widened(&mut self) -> PyResult<()> {
        self.get()?.widened();
        Ok(())
    }

    /// Adds a region: its points `ids` and `core` (uint32, ascending) and
    /// its step (`region_task`'s arrays), or `None` for a region of one
    /// position.
    #[pyo3(signature = (ids, core, step = None))]
    fn add(
        &mut self,
        ids: PyReadonlyArray1<'_, u32>,
        core: PyReadonlyArray1<'_, u32>,
        step: Option<StepIn<'_>>,
    ) -> PyResult<()> {
        let step = match step {
            None => None,
            Some((part, structure, ps, axes, structures, part_angle, lines, normals_ignored)) => {
                let axes = axes.as_array();
                let ps = ps.as_slice()?;
                if axes.shape() != [ps.len(), 3] {
                    return Err(PyValueError::new_err(
                        "a region step's axes must be (parts, 3)",
                    ));
                }
                let parts = ps
                    .iter()
                    .enumerate()
                    .map(|(k, &s)| {
                        let a = [axes[[k, 0]], axes[[k, 1]], axes[[k, 2]]];
                        (s, a.iter().all(|v| v.is_finite()).then_some(a))
                    })
                    .collect();
                Some(RegionStep {
                    part: part.as_slice()?.to_vec(),
                    structure: structure.as_slice()?.to_vec(),
                    parts,
                    structures,
                    part_angle,
                    lines,
                    normals_ignored,
                })
            }
        };
        let ids = ids.as_slice()?;
        let core = core.as_slice()?;
        self.get()?
            .add(ids, core, step.as_ref())
            .map_err(value_error)
    }

    /// The parts joined and numbered, for a driver that streams the
    /// points (`RegionJoined`).
    fn resolve(&mut self, py: Python<'_>) -> PyResult<crate::tiles::PyRegionJoined> {
        let join = self
            .join
            .take()
            .ok_or_else(|| PyValueError::new_err("this joining is finished"))?;
        let joined = detached(py, 1, |_| join.resolve().map_err(value_error))?;
        Ok(crate::tiles::PyRegionJoined::new(joined))
    }

    /// The joined run over `points` ([`RunOut`]), as `detect_regions`
    /// gives it.
    fn finish<'py>(
        &mut self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<RunOut<'py>> {
        let join = self
            .join
            .take()
            .ok_or_else(|| PyValueError::new_err("this joining is finished"))?;
        let points = Points::extract(points)?;
        let pts = points.as_slice();
        let run = detached(py, 1, |_| join.finish(pts).map_err(value_error))?;
        Ok(run_out(py, run))
    }
}

impl PyRegionJoin {
    fn get(&mut self) -> PyResult<&mut RegionJoin> {
        self.join
            .as_mut()
            .ok_or_else(|| PyValueError::new_err("this joining is finished"))
    }
}
