//! The single-threaded build: one [`Builder`] inserts every point, in the
//! order of [`Input`], into plain cells ([`Owned`]). The parallel build
//! runs its first rounds with the same function before it shares the cells.

use super::cell::MAX_CELLS;
use super::insert::{first_tet, BuildStats, Builder, Built, Dups, Input, Limits, SEED};
use super::store::{Owned, Stop};
use crate::geometry::predicates::{Kernel, StaticFilter};

/// Cells per point that a build of uniform points needs (about 6.8), with
/// some margin: the capacity it reserves up front. Untouched capacity costs
/// address space, not resident memory.
pub(crate) fn expected_cells(points: usize) -> usize {
    7 * points + points / 2 + 64
}

/// The whole build on one thread.
pub(crate) fn run<K: Kernel>(
    input: &Input,
    limits: &Limits,
    filter: StaticFilter,
    grid: Option<([f64; 3], f64)>,
) -> Result<Built, Stop> {
    let m = input.pts.len();
    let (b, dups) = run_owned::<K>(input, limits, filter, grid, m)?;
    let Owned { cells, free, .. } = b.store;
    Ok(Built {
        cells,
        holes: free,
        dups,
        stats: BuildStats {
            threads: 1,
            deferred: 0,
        },
    })
}

/// Builds the first tet and inserts the points `4..end` on one thread,
/// into plain cells; returns the builder and the duplicates found.
pub(crate) fn run_owned<'p, K: Kernel>(
    input: &'p Input,
    limits: &Limits,
    filter: StaticFilter,
    grid: Option<([f64; 3], f64)>,
    end: usize,
) -> Result<(Builder<'p, K, Owned>, Dups), Stop> {
    let store = Owned {
        cells: Vec::with_capacity(expected_cells(end).min(limits.max_cells)),
        free: Vec::new(),
        max_cells: limits.max_cells.min(MAX_CELLS),
    };
    let mut b = Builder::<K, _>::new(&input.pts, store, filter, grid, limits, SEED);
    b.last = first_tet(&mut b.store)?;
    let mut dups = Vec::new();
    // The previous point and the vertex it became (the first tet's last
    // vertex before the first insertion).
    let mut prev = (3, 3);
    for vid in 4..end as u32 {
        let w = match b.insert_after(vid, Some(prev))? {
            Some(w) => {
                dups.push((vid, w));
                w
            }
            None => vid,
        };
        prev = (vid, w);
    }
    Ok((b, dups))
}
