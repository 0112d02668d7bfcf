//! The split run of the library (`aniso_alpha::detect::{Plan, Step}`) for
//! `aniso_alpha.distributed`: a [`PyPlan`] on the driver (the parameters,
//! the tiles, the finishing step) and [`tile_step`], the per-tile work a
//! Dask worker runs on the tile's numpy arrays and a few numbers (the
//! step's spec), without the plan or the rest of the cloud.

use aniso_alpha::aniso::Anisotropy;
use aniso_alpha::detect::quantized::Quantization;
use aniso_alpha::detect::StructureKind;
use aniso_alpha::detect::{Members, Plan, SplitJob, Step, TileOutput};
use numpy::ndarray::Array3;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::{rows_to_numpy, Points};
use crate::errors::value_error;
use crate::run::{detached, thread_count};
use crate::{options, DetectInput, DetectOut, PyDetection};
use aniso_alpha::options::{run_warnings, Style};
use pyo3::types::PyDict;

/// A split detection run (`aniso_alpha.distributed`); made by [`plan`].
#[pyclass(frozen, name = "Plan", module = "aniso_alpha._native")]
pub struct PyPlan {
    plan: Plan,
    /// The warnings the CLI would print for these options and points.
    warnings: Vec<String>,
}

/// The plan of a split run over `points` with tiles of side `tile`: the
/// parameters as `detect` would choose them (estimated from the data when
/// alpha, lambda3 or min_size is missing), fixed for every tile.
#[pyfunction]
#[pyo3(signature = (points, structure, tile, options = None, threads = None, normals = None))]
pub fn plan(
    py: Python<'_>,
    points: &Bound<'_, PyAny>,
    structure: &str,
    tile: f64,
    options: Option<&Bound<'_, PyDict>>,
    threads: Option<i64>,
    normals: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyPlan> {
    let options = options::detect_options(structure, options)?;
    let input = DetectInput::extract(points, normals, threads)?;
    let (pts, normals, threads) = (input.points(), input.normals(), input.threads);
    let (plan, warnings) = detached(py, threads, |n| {
        let detector = options::build(&options, pts, normals)?;
        let mut warnings = run_warnings(&options, &detector, pts.len(), n, Style::Python);
        // The tiles run on the coordinates as given: a quantized cloud is
        // not dithered here (its levels would have to travel with every
        // tile), so its result is not `detect`'s; said, not hidden.
        warnings.extend(Quantization::of(pts).describe().into_iter().map(|w| {
            format!("{w}; not here: aniso_alpha.distributed runs on the coordinates as given, aa.detect and the CLI dither them")
        }));
        Ok((detector.plan(pts, tile).map_err(value_error)?, warnings))
    })?;
    Ok(PyPlan { plan, warnings })
}

/// A tile: its cell (3 ints) and the ids of its points (uint32, ascending).
type PyTile<'py> = ((i64, i64, i64), Bound<'py, PyArray1<u32>>);

#[pymethods]
impl PyPlan {
    /// The same plan with tiles of side `tile` (the parameters kept).
    fn with_tile(&self, tile: f64) -> PyResult<PyPlan> {
        Ok(PyPlan {
            plan: self.plan.with_side(tile).map_err(value_error)?,
            warnings: self.warnings.clone(),
        })
    }

    /// The warnings the CLI would print for this run (normals not used,
    /// a very large run).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The halo width (the largest 2·alpha·lambda_max of the jobs).
    #[getter]
    fn halo(&self) -> f64 {
        self.plan.halo()
    }

    /// The tile side.
    #[getter]
    fn tile(&self) -> f64 {
        self.plan.step().side
    }

    /// The number of jobs (orientations).
    #[getter]
    fn jobs(&self) -> usize {
        self.plan.step().jobs.len()
    }

    /// The tiles of `points` (the plan's cloud): a list of (cell, ids).
    fn tiles<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Vec<PyTile<'py>>> {
        let points = Points::extract(points)?;
        let pts = points.as_slice();
        let tiles = detached(py, 1, |_| Ok(self.plan.tiles(pts)))?;
        Ok(tiles
            .into_iter()
            .map(|t| {
                let [a, b, c] = t.cell;
                ((a, b, c), t.ids.into_pyarray(py))
            })
            .collect())
    }

    /// The members of each group among a tile's ids: (offsets uint64
    /// (groups + 1,), positions uint32), or None when every group looks at
    /// every point.
    #[allow(clippy::type_complexity)]
    fn members<'py>(
        &self,
        py: Python<'py>,
        ids: PyReadonlyArray1<'py, u32>,
    ) -> PyResult<Option<(Bound<'py, PyArray1<u64>>, Bound<'py, PyArray1<u32>>)>> {
        Ok(match self.plan.members(ids.as_slice()?) {
            Members::All => None,
            Members::Groups { offsets, ids } => Some((
                offsets
                    .into_iter()
                    .map(|o| o as u64)
                    .collect::<Vec<_>>()
                    .into_pyarray(py),
                ids.into_pyarray(py),
            )),
        })
    }

    /// What a worker needs for every tile: (kind, side, rotations float64
    /// (jobs, 3, 3), elongations float64 (jobs, 3), alphas float64 (jobs,),
    /// groups uint32 (jobs,)).
    #[allow(clippy::type_complexity)]
    fn step_spec<'py>(
        &self,
        py: Python<'py>,
    ) -> (
        &'static str,
        f64,
        Bound<'py, PyArray3<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<u32>>,
    ) {
        let step = self.plan.step();
        let j = step.jobs.len();
        let rot: Vec<f64> = step
            .jobs
            .iter()
            .flat_map(|s| s.anisotropy.rotation().into_iter().flatten())
            .collect();
        let rot = Array3::from_shape_vec((j, 3, 3), rot).expect("9 per job");
        (
            match step.kind {
                StructureKind::Lines => "lines",
                StructureKind::Planes => "planes",
            },
            step.side,
            rot.into_pyarray(py),
            rows_to_numpy(
                py,
                step.jobs
                    .iter()
                    .map(|s| s.anisotropy.elongation())
                    .collect(),
            ),
            step.jobs
                .iter()
                .map(|s| s.alpha)
                .collect::<Vec<_>>()
                .into_pyarray(py),
            step.jobs
                .iter()
                .map(|s| s.group)
                .collect::<Vec<_>>()
                .into_pyarray(py),
        )
    }

    /// Gathers the tiles' outputs (a list of (faces uint32, offsets uint64,
    /// triangulated)) and finishes the run: (labels, part labels, JSON
    /// report), as `detect`.
    #[pyo3(signature = (points, outputs, threads = None))]
    fn finish<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        outputs: Vec<(PyReadonlyArray1<'py, u32>, PyReadonlyArray1<'py, u64>, u64)>,
        threads: Option<i64>,
    ) -> PyResult<DetectOut<'py>> {
        let points = Points::extract(points)?;
        let threads = thread_count(threads)?;
        let mut outs = Vec::with_capacity(outputs.len());
        for (faces, offsets, triangulated) in &outputs {
            outs.push(TileOutput {
                faces: faces.as_slice()?.to_vec(),
                offsets: offsets.as_slice()?.iter().map(|&o| o as usize).collect(),
                triangulated: *triangulated,
            });
        }
        drop(outputs);
        let pts = points.as_slice();
        let plan = &self.plan;
        let (det, json) = detached(py, threads, |_| {
            let det = plan.finish(pts, outs).map_err(value_error)?;
            let json =
                crate::report::detection_json(&det, plan.detector(), &Quantization::default());
            Ok((det, json))
        })?;
        Ok(PyDetection::output(py, det, json, self.warnings.clone()))
    }
}

/// Faces (uint32, flat), offsets (uint64, jobs + 1) and the points
/// triangulated, of one tile.
type TileOut<'py> = (Bound<'py, PyArray1<u32>>, Bound<'py, PyArray1<u64>>, u64);

/// The per-tile step: every job of the spec (see `Plan.step_spec`) on the
/// tile's points (float64 (m, 3)) with their global ids (uint32,
/// ascending); `member_offsets`/`member_ids` from `Plan.members` (None:
/// every point).
#[pyfunction]
#[pyo3(signature = (kind, side, rotations, elongations, alphas, groups, cell, points, ids, member_offsets = None, member_ids = None, threads = None))]
#[allow(clippy::too_many_arguments)]
pub fn tile_step<'py>(
    py: Python<'py>,
    kind: &str,
    side: f64,
    rotations: PyReadonlyArray3<'py, f64>,
    elongations: PyReadonlyArray2<'py, f64>,
    alphas: PyReadonlyArray1<'py, f64>,
    groups: PyReadonlyArray1<'py, u32>,
    cell: [i64; 3],
    points: &Bound<'py, PyAny>,
    ids: PyReadonlyArray1<'py, u32>,
    member_offsets: Option<PyReadonlyArray1<'py, u64>>,
    member_ids: Option<PyReadonlyArray1<'py, u32>>,
    threads: Option<i64>,
) -> PyResult<TileOut<'py>> {
    let kind = match kind {
        "lines" => StructureKind::Lines,
        "planes" => StructureKind::Planes,
        other => {
            return Err(PyValueError::new_err(format!(
                "kind must be \"lines\" or \"planes\", got {other:?}"
            )))
        }
    };
    let rot = rotations.as_array();
    let el = elongations.as_array();
    let alphas = alphas.as_slice()?;
    let groups = groups.as_slice()?;
    let j = alphas.len();
    if rot.shape() != [j, 3, 3] || el.shape() != [j, 3] || groups.len() != j {
        return Err(PyValueError::new_err(
            "a step spec needs rotations (j, 3, 3), elongations (j, 3), alphas (j,), groups (j,)",
        ));
    }
    let mut jobs = Vec::with_capacity(j);
    for i in 0..j {
        let r = [0, 1, 2].map(|a| [0, 1, 2].map(|b| rot[[i, a, b]]));
        let e = [0, 1, 2].map(|a| el[[i, a]]);
        jobs.push(SplitJob {
            anisotropy: Anisotropy::from_matrix_rows(r, e).map_err(value_error)?,
            alpha: alphas[i],
            group: groups[i],
        });
    }
    let step = Step { kind, side, jobs };
    let members = match (member_offsets, member_ids) {
        (None, None) => Members::All,
        (Some(o), Some(m)) => Members::Groups {
            offsets: o.as_slice()?.iter().map(|&x| x as usize).collect(),
            ids: m.as_slice()?.to_vec(),
        },
        _ => {
            return Err(PyValueError::new_err(
                "member_offsets and member_ids go together",
            ))
        }
    };
    let points = Points::extract(points)?;
    let threads = thread_count(threads)?;
    let pts = points.as_slice();
    let ids = ids.as_slice()?;
    let out = detached(py, threads, |_| {
        step.run(cell, pts, ids, &members).map_err(value_error)
    })?;
    Ok((
        out.faces.into_pyarray(py),
        out.offsets
            .into_iter()
            .map(|o| o as u64)
            .collect::<Vec<_>>()
            .into_pyarray(py),
        out.triangulated,
    ))
}
