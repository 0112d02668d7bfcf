//! Where the build keeps its tetrahedra: one plain `Vec` for a
//! single-threaded build ([`Owned`]), or one array of atomic words shared by
//! the threads of a parallel build ([`Shared`], see [`super::parallel`]).
//!
//! The insertion code ([`super::insert`]) is generic over [`Store`], so the
//! single-threaded build compiles to plain loads and stores as before, and
//! a parallel build runs the same code with two more checks: a tet is
//! changed only by the thread that owns it, and an insertion that needs a
//! tet this thread does not own is undone and done later.

use super::cell::{prefetch, Cell, CLEAR, FRESH, IN_CONFLICT};
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Why an insertion stopped before it was complete.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Stop {
    /// The build reached its tet limit (fatal).
    TetLimit,
    /// A parallel build met a tet that this thread does not own, or ran out
    /// of the cells given to it: the insertion is undone and the point is
    /// inserted later, by one thread (never for [`Owned`]).
    Busy,
}

/// Cell storage of the incremental construction.
pub(crate) trait Store {
    /// Tet `t`, whole.
    fn cell(&self, t: u32) -> Cell;
    /// Vertex word `i` of tet `t`.
    fn v(&self, t: u32, i: usize) -> u32;
    /// Neighbour word `i` of tet `t`.
    fn n(&self, t: u32, i: usize) -> u32;
    /// Sets neighbour word `i` of tet `t`.
    fn set_n(&mut self, t: u32, i: usize, x: u32);
    /// Changes tet `t` through `f` (one index into the cells for
    /// [`Owned`]), returning what `f` returns.
    fn update<R>(&mut self, t: u32, f: impl FnOnce(&mut Cell) -> R) -> R;
    /// Hints that tet `t` is about to be read.
    fn prefetch(&self, t: u32);
    /// Whether this thread may change the tet with vertices `v` (always
    /// for [`Owned`]).
    fn owns(&self, v: &[u32; 4]) -> bool;
    /// Whether this thread may read the neighbours of the tet with
    /// vertices `v`, which no other thread changes (always for [`Owned`]).
    fn may_read(&self, v: &[u32; 4]) -> bool;
    /// A cell for a new tet, owned by this thread ([`Stop::Busy`] when a
    /// [`Shared`] thread has none left).
    fn alloc(&mut self) -> Result<u32, Stop>;
    /// The cells of dead tets, reused first by [`Store::alloc`].
    fn free_cells(&mut self) -> &mut Vec<u32>;
    /// Returns the cell of a dead tet for reuse.
    #[inline(always)]
    fn release(&mut self, t: u32) {
        self.free_cells().push(t);
    }
    /// Returns the cells of dead tets for reuse.
    #[inline(always)]
    fn release_all(&mut self, t: impl Iterator<Item = u32>) {
        self.free_cells().extend(t);
    }
}

/// The cells of a single-threaded build.
pub(crate) struct Owned {
    pub(crate) cells: Vec<Cell>,
    /// Dead cells, reused first.
    pub(crate) free: Vec<u32>,
    /// The most cells (live or free) the build may hold.
    pub(crate) max_cells: usize,
}

impl Store for Owned {
    #[inline(always)]
    fn cell(&self, t: u32) -> Cell {
        self.cells[t as usize]
    }
    #[inline(always)]
    fn v(&self, t: u32, i: usize) -> u32 {
        self.cells[t as usize].v[i]
    }
    #[inline(always)]
    fn n(&self, t: u32, i: usize) -> u32 {
        self.cells[t as usize].n[i]
    }
    #[inline(always)]
    fn set_n(&mut self, t: u32, i: usize, x: u32) {
        self.cells[t as usize].n[i] = x;
    }
    #[inline(always)]
    fn update<R>(&mut self, t: u32, f: impl FnOnce(&mut Cell) -> R) -> R {
        f(&mut self.cells[t as usize])
    }
    #[inline(always)]
    fn prefetch(&self, t: u32) {
        prefetch(&self.cells, t as usize);
    }
    #[inline(always)]
    fn owns(&self, _v: &[u32; 4]) -> bool {
        true
    }
    #[inline(always)]
    fn may_read(&self, _v: &[u32; 4]) -> bool {
        true
    }
    #[inline]
    fn alloc(&mut self) -> Result<u32, Stop> {
        if let Some(t) = self.free.pop() {
            Ok(t)
        } else if self.cells.len() >= self.max_cells {
            Err(Stop::TetLimit)
        } else {
            let t = self.cells.len() as u32;
            self.cells.push(FRESH);
            Ok(t)
        }
    }
    #[inline(always)]
    fn free_cells(&mut self) -> &mut Vec<u32> {
        &mut self.free
    }
}

/// One tet of a [`Shared`] store: the words of a [`Cell`] (`v` then `n`),
/// each atomic so that threads may share the array without `unsafe`
/// (relaxed loads and stores are plain moves on x86_64 and AArch64).
#[derive(Debug, Default)]
#[repr(C, align(32))]
pub(crate) struct AtomicCell([AtomicU32; 8]);

impl From<Cell> for AtomicCell {
    fn from(c: Cell) -> Self {
        let w = [
            c.v[0], c.v[1], c.v[2], c.v[3], c.n[0], c.n[1], c.n[2], c.n[3],
        ];
        AtomicCell(w.map(AtomicU32::new))
    }
}

impl AtomicCell {
    /// The cell's contents, from an exclusive reference (no atomic loads).
    pub(crate) fn into_cell(self) -> Cell {
        let w = self.0.map(AtomicU32::into_inner);
        Cell {
            v: [w[0], w[1], w[2], w[3]],
            n: [w[4], w[5], w[6], w[7]],
        }
    }

    #[inline(always)]
    fn load(&self) -> Cell {
        let w = &self.0;
        Cell {
            v: [
                w[0].load(Relaxed),
                w[1].load(Relaxed),
                w[2].load(Relaxed),
                w[3].load(Relaxed),
            ],
            n: [
                w[4].load(Relaxed),
                w[5].load(Relaxed),
                w[6].load(Relaxed),
                w[7].load(Relaxed),
            ],
        }
    }
}

/// One thread's view of a parallel build's cells.
///
/// Ownership (why threads may share the cells without locks, and why the
/// result does not depend on how they race):
/// - during a round, each vertex belongs to one thread's *piece* (its bit
///   in `piece`); a tet whose finite vertices all belong to this thread's
///   piece is *owned* by it, a tet whose vertices belong to two pieces or
///   more is *frozen*, and a tet owned by another thread is *foreign*;
/// - a thread changes only tets it owns: the tets of a cavity, the outer
///   tets whose neighbour words it rewrites, and the new tets, built from
///   its own cells (its free list and its own unused range of cells);
/// - so a frozen tet does not change during the round, nor do the vertices
///   of any live tet (only the flag bits, which are masked), nor the
///   neighbour words of a thread's own or frozen tets except through that
///   thread; and every pointer in them leads to a live tet, because a tet
///   next to one that may not change cannot die;
/// - a thread reads the neighbour words only of its own and frozen tets,
///   and stops ([`Stop::Busy`]) on a foreign one (whose vertices it reads
///   to tell): what it sees, and so everything it does, depends only on
///   the start of the round and its own insertions, never on the timing of
///   the others.
pub(crate) struct Shared<'a> {
    pub(crate) cells: &'a [AtomicCell],
    /// Vertex id -> the bit of its piece this round; the last slot, which
    /// stands for the infinite vertex, is 0.
    pub(crate) piece: &'a [u8],
    /// This thread's piece bit (all ones when it runs alone: it owns every
    /// tet).
    pub(crate) me: u8,
    /// This thread's own cells.
    pub(crate) own: ThreadCells,
    /// The cell this thread took last (with debug assertions only; the
    /// one cell it may write before the cell holds its own vertices).
    pub(crate) fresh: u32,
}

/// The cells a thread of a parallel build may take for new tets; it keeps
/// them between passes.
#[derive(Default)]
pub(crate) struct ThreadCells {
    /// Dead cells of this thread, reused first.
    pub(crate) free: Vec<u32>,
    /// This thread's unused cells: `chunk.0..chunk.1`.
    pub(crate) chunk: (usize, usize),
}

impl Shared<'_> {
    /// Whether this thread may change tet `t` under the ownership rule: it
    /// owns the tet, or just took its cell and has not written its
    /// vertices yet (checked with debug assertions only).
    fn may_write(&self, t: u32) -> bool {
        t == self.fresh || self.owns(&self.cells[t as usize].load().v)
    }

    /// The pieces of the vertices `v` (flags masked), or-ed.
    #[inline(always)]
    fn pieces(&self, v: &[u32; 4]) -> u8 {
        let top = self.piece.len() - 1;
        let p = |w: u32| self.piece[(w as usize).min(top)];
        p(v[0] & !IN_CONFLICT) | p(v[1] & !CLEAR) | p(v[2]) | p(v[3])
    }
}

impl Store for Shared<'_> {
    #[inline(always)]
    fn cell(&self, t: u32) -> Cell {
        self.cells[t as usize].load()
    }
    #[inline(always)]
    fn v(&self, t: u32, i: usize) -> u32 {
        self.cells[t as usize].0[i].load(Relaxed)
    }
    #[inline(always)]
    fn n(&self, t: u32, i: usize) -> u32 {
        self.cells[t as usize].0[4 + i].load(Relaxed)
    }
    #[inline(always)]
    fn set_n(&mut self, t: u32, i: usize, x: u32) {
        debug_assert!(self.may_write(t), "tet {t} is not this thread's");
        self.cells[t as usize].0[4 + i].store(x, Relaxed);
    }
    #[inline(always)]
    fn update<R>(&mut self, t: u32, f: impl FnOnce(&mut Cell) -> R) -> R {
        debug_assert!(self.may_write(t), "tet {t} is not this thread's");
        let cell = &self.cells[t as usize];
        let old = cell.load();
        let mut c = old;
        let r = f(&mut c);
        for i in 0..4 {
            if c.v[i] != old.v[i] {
                cell.0[i].store(c.v[i], Relaxed);
            }
            if c.n[i] != old.n[i] {
                cell.0[4 + i].store(c.n[i], Relaxed);
            }
        }
        r
    }
    #[inline(always)]
    fn prefetch(&self, t: u32) {
        prefetch(self.cells, t as usize);
    }
    #[inline(always)]
    fn owns(&self, v: &[u32; 4]) -> bool {
        self.pieces(v) & !self.me == 0
    }
    #[inline(always)]
    fn may_read(&self, v: &[u32; 4]) -> bool {
        let p = self.pieces(v);
        p & !self.me == 0 || p & p.wrapping_sub(1) != 0
    }
    #[inline]
    fn alloc(&mut self) -> Result<u32, Stop> {
        let own = &mut self.own;
        let t = if let Some(t) = own.free.pop() {
            t
        } else if own.chunk.0 < own.chunk.1 {
            own.chunk.0 += 1;
            own.chunk.0 as u32 - 1
        } else {
            return Err(Stop::Busy);
        };
        if cfg!(debug_assertions) {
            self.fresh = t;
        }
        Ok(t)
    }
    #[inline(always)]
    fn free_cells(&mut self) -> &mut Vec<u32> {
        &mut self.own.free
    }
}
