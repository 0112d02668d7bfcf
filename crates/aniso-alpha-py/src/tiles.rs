//! The halves of `aniso_alpha.distributed.detect_tiles`, a region run over
//! a cloud held as tiles (files) that no process reads whole: the grid from
//! the tiles' bounds ([`region_grid`]), the cells each tile occupies
//! ([`region_cells`]), a region's points cut from the tiles that meet its
//! window ([`region_window`], [`region_select`]), and the joined parts'
//! labels and fits streamed over the tiles in input order
//! ([`PyRegionJoined`]). The same plan, steps and joining as
//! `detect_regions` on the tiles' points stacked in list order, so the
//! same labels and parts.

use aniso_alpha::detect::regions::{
    side_for_extent, PartsRefit, RegionGrid, RegionJoined, FIRST_MARGIN,
};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::{rows_to_numpy, Points};
use crate::errors::value_error;
use crate::regions::{run_out, RunOut};
use crate::run::detached;

/// The side to run a cloud of `n` points with bounding box `lo`–`hi` and
/// the side to report: `side` when given (checked by the grid), else
/// about 250,000 points a region; a cloud of at most 1,000,000 points runs
/// as one region holding it all, reported as `None`.
pub fn region_side_extent(
    lo: [f64; 3],
    hi: [f64; 3],
    n: usize,
    side: Option<f64>,
) -> (f64, Option<f64>) {
    match side.or_else(|| side_for_extent(lo, hi, n)) {
        Some(s) => (s, Some(s)),
        None if n == 0 => (1.0, None),
        None => (2.0 * (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1.0), None),
    }
}

/// A region grid as Python takes it: origin (x, y), the side its regions
/// run with, the side to report (`None`: one region holds the cloud) and
/// the first margin.
type GridOut = ((f64, f64), f64, Option<f64>, f64);

/// A region's points among some points: their indices and which are its
/// core.
type Selection<'py> = (Bound<'py, PyArray1<u32>>, Bound<'py, PyArray1<bool>>);

/// Structure and part labels (int64, −1: none).
type LabelsOut<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>);

fn grid(origin: (f64, f64), side: f64) -> PyResult<RegionGrid> {
    RegionGrid::of_extent([origin.0, origin.1, 0.0], side).map_err(value_error)
}

/// The region grid of a cloud of `n` points with bounding box `lo`–`hi`:
/// its origin (x, y), the side its regions run with, the side to report
/// (`None`: one region holds the cloud) and the first margin.
#[pyfunction]
#[pyo3(signature = (lo, hi, n, side = None))]
pub fn region_grid(lo: [f64; 3], hi: [f64; 3], n: usize, side: Option<f64>) -> PyResult<GridOut> {
    if n == 0 {
        return Err(PyValueError::new_err("no points"));
    }
    if n > u32::MAX as usize {
        return Err(PyValueError::new_err(format!(
            "{n} points: a region run numbers points with 32 bits (at most {})",
            u32::MAX
        )));
    }
    let (run_side, reported) = region_side_extent(lo, hi, n, side);
    let g = grid((lo[0], lo[1]), run_side)?;
    let [x, y] = g.origin();
    Ok(((x, y), run_side, reported, FIRST_MARGIN * run_side))
}

/// The cells (int64 (k, 2), ascending) `points` occupy on the grid of
/// `origin` and `side`.
#[pyfunction]
pub fn region_cells<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    origin: (f64, f64),
    side: f64,
) -> PyResult<Bound<'py, PyArray2<i64>>> {
    let g = grid(origin, side)?;
    let points = Points::extract(points)?;
    let pts = points.as_slice();
    let cells = detached(py, 1, |_| Ok(g.cells(pts)))?;
    Ok(rows_to_numpy(
        py,
        cells.into_iter().map(|(x, y)| [x, y]).collect(),
    ))
}

/// The box (x₀, y₀, x₁, y₁) of the region of `cell` grown by `margin`: a
/// tile whose bounds miss it holds none of the region's points.
#[pyfunction]
pub fn region_window(
    origin: (f64, f64),
    side: f64,
    cell: (i64, i64),
    margin: f64,
) -> PyResult<(f64, f64, f64, f64)> {
    let (lo, hi) = grid(origin, side)?.window(cell, margin).bounds();
    Ok((lo[0], lo[1], hi[0], hi[1]))
}

/// The points of `points` in the region of `cell` grown by `margin`
/// (uint32 indices, ascending) and which of them are its core (bool).
#[pyfunction]
pub fn region_select<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    origin: (f64, f64),
    side: f64,
    cell: (i64, i64),
    margin: f64,
) -> PyResult<Selection<'py>> {
    let window = grid(origin, side)?.window(cell, margin);
    let points = Points::extract(points)?;
    let pts = points.as_slice();
    if pts.len() > u32::MAX as usize {
        return Err(PyValueError::new_err("more points than 32-bit indices"));
    }
    let (ids, core): (Vec<u32>, Vec<bool>) = detached(py, 1, |_| {
        Ok(pts
            .iter()
            .enumerate()
            .filter(|(_, p)| window.contains(p))
            .map(|(i, p)| (i as u32, window.is_core(p)))
            .unzip())
    })?;
    Ok((ids.into_pyarray(py), core.into_pyarray(py)))
}

/// The joined parts of a region run (`RegionJoin.resolve`), on a driver
/// that streams the points: `labels` of each tile's points, and their
/// fits by three passes of `refit` over every tile in input order (each
/// ended by `end_pass`), then `finish`.
#[pyclass(name = "RegionJoined", module = "aniso_alpha._native")]
pub struct PyRegionJoined {
    joined: RegionJoined,
    refit: PartsRefit,
}

impl PyRegionJoined {
    /// The joined parts of `joined`, before any pass.
    pub fn new(joined: RegionJoined) -> Self {
        let refit = joined.refit();
        PyRegionJoined { joined, refit }
    }

    fn check(&self, first: usize, n: usize) -> PyResult<()> {
        if first
            .checked_add(n)
            .is_none_or(|end| end > self.joined.len())
        {
            return Err(PyValueError::new_err(format!(
                "points {first}..{} of a cloud of {}",
                first.saturating_add(n),
                self.joined.len()
            )));
        }
        Ok(())
    }
}

#[pymethods]
impl PyRegionJoined {
    /// The number of points of the cloud.
    fn __len__(&self) -> usize {
        self.joined.len()
    }

    /// The structure and part labels (int64, −1: none) of the `n` points
    /// from input index `first` on.
    fn labels<'py>(&self, py: Python<'py>, first: usize, n: usize) -> PyResult<LabelsOut<'py>> {
        self.check(first, n)?;
        let joined = &self.joined;
        let (parts, structures) =
            detached(py, 1, |_| joined.labels(first, n).map_err(value_error))?;
        Ok((structures.into_pyarray(py), parts.into_pyarray(py)))
    }

    /// Adds `points`, input indices `first..`, to the refit's pass under
    /// way.
    fn refit(&mut self, py: Python<'_>, first: usize, points: &Bound<'_, PyAny>) -> PyResult<()> {
        let points = Points::extract(points)?;
        let pts = points.as_slice();
        self.check(first, pts.len())?;
        if self.refit.pass() >= 3 {
            return Err(PyValueError::new_err("the refit's three passes are done"));
        }
        let (joined, refit) = (&self.joined, &mut self.refit);
        detached(py, 1, |_| {
            refit.add_points(joined, first, pts).map_err(value_error)
        })
    }

    /// Ends the refit's pass under way.
    fn end_pass(&mut self) {
        self.refit.end_pass();
    }

    /// The run (`RunOut`, its labels empty: `labels` gives them), after
    /// the refit's three passes.
    fn finish<'py>(&self, py: Python<'py>) -> PyResult<RunOut<'py>> {
        if self.refit.pass() < 3 {
            return Err(PyValueError::new_err(format!(
                "the refit has made {} of its three passes",
                self.refit.pass()
            )));
        }
        Ok(run_out(py, self.joined.run(&self.refit)))
    }
}
