//! The regions of a cloud (module doc of `regions`, step 1): the grid of
//! square columns in x–y, each region's window (its column grown by a
//! margin), and the plan of a cloud in memory (each region's core points).
//! A cloud held as tiles makes the same plan from its bounds and the cells
//! its points occupy ([`RegionGrid::of_extent`], [`RegionGrid::cells`]),
//! and each region's points from the tiles with the same window test
//! ([`RegionWindow::contains`]).

use super::{REGIONS_ABOVE, REGION_POINTS};
use crate::detect::DetectError;
use crate::geometry::floor_i64;
use std::collections::{BTreeMap, BTreeSet};

/// The first margin, as a fraction of the side (a region's run is widened
/// when its reach asks for more).
pub const FIRST_MARGIN: f64 = 1.0 / 16.0;

/// The side of square regions holding about [`REGION_POINTS`] points each
/// at the cloud's mean density over its x–y extent; `None` for a cloud of
/// at most [`REGIONS_ABOVE`] points (one whole run), or flat in x or y.
pub fn side_for(points: &[[f64; 3]]) -> Option<f64> {
    if points.len() <= REGIONS_ABOVE {
        return None;
    }
    let (lo, hi) = crate::geometry::bounding_box(points);
    side_for_extent(lo, hi, points.len())
}

/// [`side_for`] of a cloud of `n` points with bounding box `lo`–`hi`.
pub fn side_for_extent(lo: [f64; 3], hi: [f64; 3], n: usize) -> Option<f64> {
    if n <= REGIONS_ABOVE {
        return None;
    }
    let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
    if !(w > 0.0 && h > 0.0) {
        return None;
    }
    Some((w * h * REGION_POINTS as f64 / n as f64).sqrt())
}

/// The region grid of a cloud: origin (the cloud's x–y minimum) and side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegionGrid {
    origin: [f64; 2],
    side: f64,
}

impl RegionGrid {
    /// The grid of side `side` over a cloud whose bounding box starts at
    /// `lo`.
    ///
    /// # Errors
    /// A side that is not positive and finite; a non-finite `lo`.
    pub fn of_extent(lo: [f64; 3], side: f64) -> Result<Self, DetectError> {
        if !(side.is_finite() && side > 0.0) {
            return Err(DetectError::BadParameter(format!(
                "region side {side}: must be positive and finite"
            )));
        }
        if !(lo[0].is_finite() && lo[1].is_finite()) {
            return Err(DetectError::BadParameter(format!(
                "region grid origin {lo:?}: must be finite"
            )));
        }
        Ok(RegionGrid {
            origin: [lo[0], lo[1]],
            side,
        })
    }

    /// The origin (x, y).
    pub fn origin(&self) -> [f64; 2] {
        self.origin
    }

    /// The side.
    pub fn side(&self) -> f64 {
        self.side
    }

    /// The cell (column indices in x and y) of point `p`.
    pub fn cell(&self, p: &[f64; 3]) -> (i64, i64) {
        (
            floor_i64((p[0] - self.origin[0]) / self.side),
            floor_i64((p[1] - self.origin[1]) / self.side),
        )
    }

    /// The cells `points` occupy, ascending (x, then y).
    pub fn cells(&self, points: &[[f64; 3]]) -> Vec<(i64, i64)> {
        let set: BTreeSet<(i64, i64)> = points.iter().map(|p| self.cell(p)).collect();
        set.into_iter().collect()
    }

    /// The window of the region of cell `cell` grown by `margin`.
    pub fn window(&self, cell: (i64, i64), margin: f64) -> RegionWindow {
        let lo = [
            self.origin[0] + cell.0 as f64 * self.side - margin,
            self.origin[1] + cell.1 as f64 * self.side - margin,
        ];
        RegionWindow {
            grid: *self,
            cell,
            reach: (margin / self.side).ceil() as i64,
            lo,
            hi: [
                lo[0] + self.side + 2.0 * margin,
                lo[1] + self.side + 2.0 * margin,
            ],
        }
    }
}

/// A region's column grown by a margin in x and y: the points its run
/// takes (its core and margin).
#[derive(Debug, Clone, Copy)]
pub struct RegionWindow {
    grid: RegionGrid,
    cell: (i64, i64),
    /// Cells the margin reaches, each way.
    reach: i64,
    lo: [f64; 2],
    hi: [f64; 2],
}

impl RegionWindow {
    /// Whether `p` is in the window: within `reach` cells of the region's
    /// and within the grown column (the test [`RegionPlan::points_within`]
    /// makes on the cells it visits).
    pub fn contains(&self, p: &[f64; 3]) -> bool {
        let c = self.grid.cell(p);
        (c.0 - self.cell.0).abs() <= self.reach
            && (c.1 - self.cell.1).abs() <= self.reach
            && self.in_box(p)
    }

    /// Whether `p` is in the region's core (its own cell).
    pub fn is_core(&self, p: &[f64; 3]) -> bool {
        self.grid.cell(p) == self.cell
    }

    /// The grown column's corners (x, y): lower and upper.
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        (self.lo, self.hi)
    }

    fn in_box(&self, p: &[f64; 3]) -> bool {
        p[0] >= self.lo[0] && p[0] <= self.hi[0] && p[1] >= self.lo[1] && p[1] <= self.hi[1]
    }
}

/// The regions of a cloud (module doc, step 1): the grid, and each
/// non-empty region's core points, regions in (x, y) cell order. What a
/// driver keeps while the regions run elsewhere.
#[derive(Debug, Clone)]
pub struct RegionPlan {
    grid: RegionGrid,
    cells: BTreeMap<(i64, i64), Vec<u32>>,
    order: Vec<(i64, i64)>,
}

impl RegionPlan {
    /// The regions of side `side` of `points`.
    ///
    /// # Errors
    /// No points; a side that is not positive and finite.
    pub fn new(points: &[[f64; 3]], side: f64) -> Result<Self, DetectError> {
        if points.is_empty() {
            return Err(DetectError::Empty);
        }
        let (lo, _) = crate::geometry::bounding_box(points);
        let grid = RegionGrid::of_extent(lo, side)?;
        let mut cells: BTreeMap<(i64, i64), Vec<u32>> = BTreeMap::new();
        for (i, p) in points.iter().enumerate() {
            cells.entry(grid.cell(p)).or_default().push(i as u32);
        }
        let order = cells.keys().copied().collect();
        Ok(RegionPlan { grid, cells, order })
    }

    /// The number of regions.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// Whether there is no region (never, for a plan made of points).
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// The side of the regions.
    pub fn side(&self) -> f64 {
        self.grid.side
    }

    /// The grid.
    pub fn grid(&self) -> RegionGrid {
        self.grid
    }

    /// Region `r`'s cell (column indices in x and y).
    pub fn cell(&self, r: usize) -> (i64, i64) {
        self.order[r]
    }

    /// Region `r`'s core points (input indices, ascending).
    pub fn core(&self, r: usize) -> &[u32] {
        &self.cells[&self.order[r]]
    }

    /// The first margin of every region ([`FIRST_MARGIN`] × side).
    pub fn first_margin(&self) -> f64 {
        FIRST_MARGIN * self.grid.side
    }

    /// Region `r`'s points grown by `margin` in x and y (input indices,
    /// ascending): its core and its margin, the points of its window.
    pub fn points_within(&self, points: &[[f64; 3]], r: usize, margin: f64) -> Vec<u32> {
        let cell = self.order[r];
        let window = self.grid.window(cell, margin);
        let reach = window.reach;
        let mut ids = Vec::new();
        for cx in cell.0 - reach..=cell.0 + reach {
            for (_, list) in self
                .cells
                .range((cx, cell.1 - reach)..=(cx, cell.1 + reach))
            {
                ids.extend(
                    list.iter()
                        .copied()
                        .filter(|&i| window.in_box(&points[i as usize])),
                );
            }
        }
        ids.sort_unstable();
        ids
    }
}
