//! A candidate's footprint (docs/method.md §4, step 2): the cells that its
//! points occupy on its plane (2D) or along its line (1D), grown by one
//! cell, and the query of the points near a primitive and over its
//! footprint ([`for_near`]) that the claims, the claims' widening and the
//! significance test's background share.

use super::super::detection::Primitive;
use crate::geometry::kdtree::{KdTree, OrientedBox};
use crate::geometry::{cross, dot, floor_i64, normalize, sub};
use crate::par::map_each;

/// The cells a candidate covers on its plane (2D) or along its line (1D).
#[derive(Debug, Clone)]
pub(crate) struct Footprint {
    /// The primitive's centroid.
    origin: [f64; 3],
    /// The plane's two axes, or the line's direction and zero.
    axes: [[f64; 3]; 2],
    /// The cell side.
    pub(super) cell: f64,
    /// The first cell of the grid (with one cell of margin).
    lo: [i64; 2],
    /// The grid's size in cells, margin included (a line's grid is one
    /// cell wide across, plus the margin).
    dims: [usize; 2],
    /// Per cell (row-major): covered.
    bits: Vec<bool>,
}

/// The fewest cells along a side of a block of [`for_near`]'s boxes: 8.
/// A cell is the ellipsoid's long reach (α·λ), wider than the claim
/// radius α, so blocks of about 2·radius were single cells of a few dozen
/// points, and each box's descent from the kd-tree's root cost as much as
/// its points. The box is tight around its block (the plane's slab, the
/// line's square tube), so a wider block reaches no point farther from
/// the primitive. Measured on mOSD learn 5 (train, one thread): the
/// claims stage 0.115 s with blocks of one cell, 0.072–0.081 s of 4,
/// 0.060–0.066 s of 8; labels identical.
const BLOCK_CELLS: usize = 8;

/// Largest number of cells of one footprint; beyond it the cell is
/// doubled (a coarser footprint, never a failure).
const MAX_CELLS: usize = 1 << 24;

impl Footprint {
    /// The footprint's frame on a primitive: its centroid and axes (a
    /// line's direction and zero).
    fn frame(fit: &Primitive) -> Option<([f64; 3], [[f64; 3]; 2])> {
        match fit {
            Primitive::Plane(f) => Some((f.centroid, f.axes)),
            Primitive::Line(f) => Some((f.centroid, [f.direction, [0.0; 3]])),
            Primitive::None => None,
        }
    }

    /// The cell of `p`'s projection.
    fn coords(&self, p: &[f64; 3]) -> [i64; 2] {
        let w = sub(*p, self.origin);
        [
            floor_i64(dot(w, self.axes[0]) / self.cell),
            floor_i64(dot(w, self.axes[1]) / self.cell),
        ]
    }

    /// The cells of side `cell` (doubled until there are at most
    /// [`MAX_CELLS`]) that `seeds` occupy on `fit`, grown by one; `None`
    /// without seeds or without a primitive.
    pub(super) fn new(
        fit: &Primitive,
        points: &[[f64; 3]],
        seeds: &[u32],
        cell: f64,
    ) -> Option<Self> {
        let (origin, axes) = Self::frame(fit)?;
        let mut cell = cell;
        loop {
            let mut f = Footprint {
                origin,
                axes,
                cell,
                lo: [0; 2],
                dims: [0; 2],
                bits: Vec::new(),
            };
            let cs: Vec<[i64; 2]> = seeds
                .iter()
                .map(|&v| f.coords(&points[v as usize]))
                .collect();
            if cs.is_empty() {
                return None;
            }
            let mut lo = [i64::MAX; 2];
            let mut hi = [i64::MIN; 2];
            for c in &cs {
                for k in 0..2 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
            // One cell of margin for the dilation.
            let lo = [lo[0] - 1, lo[1] - 1];
            let dims = [(hi[0] + 2 - lo[0]) as usize, (hi[1] + 2 - lo[1]) as usize];
            if dims[0].saturating_mul(dims[1]) > MAX_CELLS {
                cell *= 2.0;
                continue;
            }
            let mut marked = vec![false; dims[0] * dims[1]];
            for c in &cs {
                marked[(c[0] - lo[0]) as usize * dims[1] + (c[1] - lo[1]) as usize] = true;
            }
            // Dilate by one cell (8-neighbourhood; along a line, 2).
            let mut bits = marked.clone();
            for i in 0..dims[0] {
                for j in 0..dims[1] {
                    if !marked[i * dims[1] + j] {
                        continue;
                    }
                    for di in -1i64..=1 {
                        for dj in -1i64..=1 {
                            let (a, b) = (i as i64 + di, j as i64 + dj);
                            if a >= 0 && b >= 0 && (a as usize) < dims[0] && (b as usize) < dims[1]
                            {
                                bits[a as usize * dims[1] + b as usize] = true;
                            }
                        }
                    }
                }
            }
            f.lo = lo;
            f.dims = dims;
            f.bits = bits;
            return Some(f);
        }
    }

    /// Whether `p`'s projection falls in a covered cell.
    #[cfg(test)]
    pub(super) fn contains(&self, p: &[f64; 3]) -> bool {
        self.cell_of(p).is_some()
    }

    /// The covered cell (row, column of the grid) under `p`'s projection.
    fn cell_of(&self, p: &[f64; 3]) -> Option<[usize; 2]> {
        let c = self.coords(p);
        let (a, b) = (c[0] - self.lo[0], c[1] - self.lo[1]);
        let inside = a >= 0
            && b >= 0
            && (a as usize) < self.dims[0]
            && (b as usize) < self.dims[1]
            && self.bits[a as usize * self.dims[1] + b as usize];
        inside.then_some([a as usize, b as usize])
    }

    /// Number of covered cells.
    pub(super) fn count(&self) -> usize {
        self.bits.iter().filter(|&&b| b).count()
    }

    /// Blocks of `b` × `b` cells (`b` along a line) holding a covered
    /// cell, each as the box of the points within `radius` of the
    /// primitive over it: the block's rectangle on the plane and `radius`
    /// either side (along a line: the block's interval and `radius` across
    /// both ways).
    fn blocks(&self, b: usize, radius: f64) -> impl Iterator<Item = Block> + '_ {
        let planar = self.axes[1] != [0.0; 3];
        let bj = if planar { b } else { self.dims[1] };
        let axes = self.box_axes();
        (0..self.dims[0]).step_by(b).flat_map(move |i0| {
            (0..self.dims[1]).step_by(bj).filter_map(move |j0| {
                let (i1, j1) = ((i0 + b).min(self.dims[0]), (j0 + bj).min(self.dims[1]));
                let any = (i0..i1).any(|i| (j0..j1).any(|j| self.bits[i * self.dims[1] + j]));
                if !any {
                    return None;
                }
                let u = (self.lo[0] + i0 as i64) as f64 + 0.5 * (i1 - i0) as f64;
                let v = (self.lo[1] + j0 as i64) as f64 + 0.5 * (j1 - j0) as f64;
                let centre = [0, 1, 2].map(|k| {
                    self.origin[k] + self.cell * (u * self.axes[0][k] + v * self.axes[1][k])
                });
                let hu = 0.5 * (i1 - i0) as f64 * self.cell;
                let half = if planar {
                    [hu, 0.5 * (j1 - j0) as f64 * self.cell, radius]
                } else {
                    [hu, radius, radius]
                };
                Some(Block {
                    region: OrientedBox::new(centre, axes, half),
                    rows: (i0, i1),
                    columns: (j0, j1),
                })
            })
        })
    }

    /// The blocks' axes: the plane's two axes and its normal, or the
    /// line's direction and two directions across it.
    fn box_axes(&self) -> [[f64; 3]; 3] {
        let [a, b] = self.axes;
        if b != [0.0; 3] {
            return [a, b, cross(a, b)];
        }
        // Across a line: from the world axis least along it.
        let k = (0..3)
            .min_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
            .unwrap_or(0);
        let mut e = [0.0; 3];
        e[k] = 1.0;
        let p = normalize(cross(a, e)).unwrap_or([0.0; 3]);
        [a, p, cross(a, p)]
    }
}

/// A block of a footprint's cells ([`Footprint::near_blocks`]): the box
/// of the points within a radius of the primitive over it, and its rows
/// and columns of the footprint's grid.
#[derive(Debug, Clone)]
pub(super) struct Block {
    region: OrientedBox,
    rows: (usize, usize),
    columns: (usize, usize),
}

impl Block {
    /// Whether the grid cell `c` is one of the block's.
    fn owns(&self, c: [usize; 2]) -> bool {
        (self.rows.0..self.rows.1).contains(&c[0])
            && (self.columns.0..self.columns.1).contains(&c[1])
    }
}

/// Calls `f(point, distance)` for every point of `index` within `radius`
/// of the primitive `fit` and over its footprint `foot`, once, block after
/// block ([`for_near_in`]).
pub(super) fn for_near(
    fit: &Primitive,
    foot: &Footprint,
    radius: f64,
    index: &KdTree,
    f: &mut dyn FnMut(u32, f64),
) {
    let blocks = foot.near_blocks(radius);
    for_near_in(fit, foot, radius, index, &blocks, f);
}

/// Blocks from which [`near_points`] cuts its query into slices for the
/// threads: 16, each of 8 × 8 cells or more ([`BLOCK_CELLS`]).
const PARALLEL_BLOCKS: usize = 16;

/// The (point, distance) pairs [`for_near`] reports, in its order; the
/// blocks in slices on the pool's threads from [`PARALLEL_BLOCKS`] blocks
/// (a scan's ground, a depth frame's table).
pub(super) fn near_points(
    fit: &Primitive,
    foot: &Footprint,
    radius: f64,
    index: &KdTree,
) -> Vec<(u32, f64)> {
    let blocks = foot.near_blocks(radius);
    let gather = |slice: &[Block]| {
        let mut out = Vec::new();
        for_near_in(fit, foot, radius, index, slice, &mut |i, d| {
            out.push((i, d))
        });
        out
    };
    if blocks.len() < PARALLEL_BLOCKS {
        return gather(&blocks);
    }
    let size = blocks.len().div_ceil(4 * crate::par::threads()).max(1);
    let slices: Vec<&[Block]> = blocks.chunks(size).collect();
    map_each(slices.len(), |k| gather(slices[k])).concat()
}

impl Footprint {
    /// The boxes [`for_near`] queries for `radius`: one per block of
    /// cells about 2·radius wide, and [`BLOCK_CELLS`] wide at least.
    pub(super) fn near_blocks(&self, radius: f64) -> Vec<Block> {
        self.blocks(self.block_cells(radius), radius).collect()
    }

    /// How many boxes [`Self::near_blocks`] gives for `radius`.
    pub(super) fn near_block_count(&self, radius: f64) -> usize {
        self.blocks(self.block_cells(radius), radius).count()
    }

    /// Boxes `from..to` of [`Self::near_blocks`] for `radius`, without
    /// holding the others.
    pub(super) fn near_blocks_in(&self, radius: f64, (from, to): (usize, usize)) -> Vec<Block> {
        self.blocks(self.block_cells(radius), radius)
            .skip(from)
            .take(to.saturating_sub(from))
            .collect()
    }

    /// Cells along a side of [`Self::near_blocks`]' blocks for `radius`:
    /// about 2·radius, and at least [`BLOCK_CELLS`].
    fn block_cells(&self, radius: f64) -> usize {
        ((2.0 * radius / self.cell).ceil() as usize).max(BLOCK_CELLS)
    }
}

/// [`for_near`] over some of the footprint's [`Footprint::near_blocks`]:
/// each point within `radius` and over a covered cell of those blocks,
/// once. A point within `radius` over a covered cell lies in that cell's
/// block's box, and is reported there only (boxes overlap by their
/// padding), so disjoint slices of the blocks report disjoint points (the
/// claims of a large candidate are gathered slice by slice, in parallel).
pub(super) fn for_near_in(
    fit: &Primitive,
    foot: &Footprint,
    radius: f64,
    index: &KdTree,
    blocks: &[Block],
    f: &mut dyn FnMut(u32, f64),
) {
    for b in blocks {
        index.within_box(&b.region, |i, p| {
            let d = fit.distance(p);
            if d <= radius && foot.cell_of(p).is_some_and(|c| b.owns(c)) {
                f(i, d);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::fit::{fit_line_indices, fit_plane_indices};
    use crate::rng::SplitMix64;

    #[test]
    fn a_footprint_is_the_seeds_cells_grown_by_one() {
        // Seeds at x = 0.5, 1.5, 8.5 on the x axis: cells of side 1 from
        // their centroid 3.5, along the fitted direction (±x). Covered are
        // their cells and the next ones: x within 1.5 of 1 or of 8.5,
        // rounded to the cells (either sign of the direction covers
        // [−0.5, 2.5] and [7.5, 9.5], and neither x < −1.5, (3.5, 6.5] nor
        // x > 10.5).
        let pts: Vec<[f64; 3]> = [0.5, 1.5, 8.5].iter().map(|&x| [x, 0.0, 0.0]).collect();
        let fit = Primitive::Line(fit_line_indices(&pts, &[0, 1, 2]).unwrap());
        let foot = Footprint::new(&fit, &pts, &[0, 1, 2], 1.0).unwrap();
        let along = |x: f64| foot.contains(&[x, 0.0, 0.0]);
        for x in [-0.4, 0.5, 2.4, 7.6, 8.5, 9.4] {
            assert!(along(x), "{x}");
        }
        for x in [-1.6, 3.6, 5.0, 6.4, 10.6] {
            assert!(!along(x), "{x}");
        }
        // A line's footprint is along it: a point beside it projects in.
        assert!(foot.contains(&[0.5, 5.0, -3.0]));
        // Seven cells along, and the growth marks the rows beside them (a
        // line's length is taken from its points' span, not its cells).
        assert_eq!(foot.count(), 21);
        assert!(Footprint::new(&fit, &pts, &[], 1.0).is_none());
        assert!(Footprint::new(&Primitive::None, &pts, &[0], 1.0).is_none());
    }

    #[test]
    fn too_many_cells_double_the_cell() {
        // Two seeds 1e5 cells apart on a plane would need 1e10 cells.
        let pts = [[0.0, 0.0, 0.0], [1e5, 1e5, 0.0], [1e5, 0.0, 0.0]];
        let fit = Primitive::Plane(fit_plane_indices(&pts, &[0, 1, 2]).unwrap());
        let foot = Footprint::new(&fit, &pts, &[0, 1, 2], 1.0).unwrap();
        assert!(foot.cell >= 16.0, "{}", foot.cell);
        assert!(foot.dims[0] * foot.dims[1] <= MAX_CELLS);
        assert!(pts.iter().all(|p| foot.contains(p)));
    }

    #[test]
    fn near_points_by_blocks_are_the_brute_force_set() {
        // A plane and a line candidate among random points; for radii from
        // a tenth of a cell to ten cells (one box per cell, then blocks),
        // `for_near` reports each point within the radius and over the
        // footprint exactly once.
        let mut rng = SplitMix64::new(21);
        let pts: Vec<[f64; 3]> = (0..4000)
            .map(|_| {
                [
                    10.0 * rng.uniform(),
                    10.0 * rng.uniform(),
                    2.0 * rng.uniform() - 1.0,
                ]
            })
            .collect();
        let seeds_plane: Vec<u32> = (0..4000u32)
            .filter(|&i| {
                let p = pts[i as usize];
                p[2].abs() < 0.2 && (p[0] < 4.0 || p[1] > 6.0)
            })
            .collect();
        let seeds_line: Vec<u32> = (0..4000u32)
            .filter(|&i| {
                let p = pts[i as usize];
                p[2].abs() < 0.3 && (p[1] - 5.0).abs() < 0.3 && p[0] < 7.0
            })
            .collect();
        let index = KdTree::new(&pts, None);
        for (seeds, line) in [(&seeds_plane, false), (&seeds_line, true)] {
            let fit = if line {
                Primitive::Line(fit_line_indices(&pts, seeds).unwrap())
            } else {
                Primitive::Plane(fit_plane_indices(&pts, seeds).unwrap())
            };
            let foot = Footprint::new(&fit, &pts, seeds, 0.3).unwrap();
            for radius in [0.03, 0.1, 0.3, 0.7, 1.5, 3.0] {
                let mut got = Vec::new();
                for_near(&fit, &foot, radius, &index, &mut |i, d| got.push((i, d)));
                // The parallel gathering reports the same, in the same order.
                assert_eq!(near_points(&fit, &foot, radius, &index), got);
                got.sort_by_key(|a| a.0);
                let want: Vec<(u32, f64)> = (0..pts.len() as u32)
                    .filter_map(|i| {
                        let p = &pts[i as usize];
                        let d = fit.distance(p);
                        (d <= radius && foot.contains(p)).then_some((i, d))
                    })
                    .collect();
                assert_eq!(got, want, "line {line}, radius {radius}");
                // Slices of the blocks, as the claims take them: together
                // the same points, each once (no duplicate to remove).
                let blocks = foot.near_blocks(radius);
                let mut sliced = Vec::new();
                for slice in blocks.chunks(2) {
                    for_near_in(&fit, &foot, radius, &index, slice, &mut |i, d| {
                        sliced.push((i, d))
                    });
                }
                sliced.sort_by_key(|a| a.0);
                assert_eq!(sliced, want, "sliced: line {line}, radius {radius}");
                // (not vacuous: from 0.3 on, dozens of points at least)
                assert!(radius < 0.3 || want.len() > 20, "{}", want.len());
            }
        }
    }
}
