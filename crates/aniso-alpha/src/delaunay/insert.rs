//! The insertion core shared by the sequential build ([`super::sequential`])
//! and the parallel one ([`super::parallel`]): one [`Builder`] per thread
//! inserts points one at a time over a cell [`Store`] (plain cells, or the
//! shared cells of a parallel build) by a remembering walk and a
//! Bowyer–Watson cavity, under CGAL's symbolic perturbation.
//!
//! Also here: the points of a build in insertion order ([`Input`]), its
//! limits ([`Limits`]), its first tetrahedron ([`first_tet`]) and what a
//! finished run hands back ([`Built`]).

use super::cavity::{Cavity, MAX_LOCAL};
use super::cell::{link_by_faces, pack, unpack, Cell, CLEAR, FACE, IN_CONFLICT, MAX_CELLS, OTHER};
use super::isa::Isa;
use super::store::{Owned, Stop, Store};
use super::INFINITE;
use crate::geometry::predicates::{
    coplanar_incircle_perturbed, insphere_perturbed_k, insphere_tie_keyed, orient3d, Kernel,
    SmallGrid, StaticFilter,
};
use crate::geometry::Point3;
use crate::rng::SplitMix64;

/// A point of the build, padded to 32 bytes and aligned so that it never
/// straddles two cache lines (24-byte points straddle one time in four),
/// with its lexicographic key in the padding when the set has one
/// ([`SmallGrid::lex_key`]; else 0).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct Slot(pub(crate) Point3, u64);

/// Whether inserting `q` destroys the tetrahedron with vertices `v` (an
/// infinite tet has the infinite vertex at index 3), under
/// CGAL's symbolic perturbation: for a finite tet, `q` is inside its
/// circumsphere; for an infinite tet, `q` is strictly beyond its hull facet,
/// or in the facet's plane and inside its circumcircle.
#[inline(always)]
fn tet_in_conflict<K: Kernel>(
    pts: &[Slot],
    v: &[u32; 4],
    q: &Point3,
    filter: &StaticFilter,
) -> bool {
    let p = |w: u32| &pts[w as usize].0;
    if v[3] == INFINITE {
        let o = K::orient3d_static(p(v[0]), p(v[1]), p(v[2]), q, filter);
        if o != 0 {
            return o > 0;
        }
        coplanar_incircle_perturbed(p(v[0]), p(v[1]), p(v[2]), q).is_positive()
    } else {
        insphere_perturbed_k::<K>(p(v[0]), p(v[1]), p(v[2]), p(v[3]), q, filter) > 0
    }
}

/// [`tet_in_conflict`] when the kernel's quick stage settles it: `1` in
/// conflict, `-1` not, `0` undecided.
#[inline(always)]
fn conflict_quick<K: Kernel>(pts: &[Slot], v: &[u32; 4], q: &Point3, filter: &StaticFilter) -> i32 {
    let p = |w: u32| &pts[w as usize].0;
    if v[3] == INFINITE {
        K::orient3d_quick(p(v[0]), p(v[1]), p(v[2]), q, filter)
    } else {
        K::insphere_quick(p(v[0]), p(v[1]), p(v[2]), p(v[3]), q, filter)
    }
}

/// Working state of the incremental construction, over the cells of
/// store `S` (one per thread in a parallel build).
pub(crate) struct Builder<'p, K: Kernel, S> {
    kernel: std::marker::PhantomData<K>,
    /// Static bounds for the predicates over the whole input.
    filter: StaticFilter,
    /// The [`SmallGrid::frame`] of the input when its lexicographic keys
    /// are kept in the point slots and break in-sphere ties.
    grid: Option<([f64; 3], f64)>,
    /// Every point to insert, by vertex id.
    pts: &'p [Slot],
    pub(crate) store: S,
    rng: SplitMix64,
    /// The current insertion's cavity (scratch, reused across insertions).
    cav: Cavity,
    /// Where the next walk starts: a live tet this builder may read (one
    /// it made last, or where it found the last duplicate).
    pub(crate) last: u32,
    /// Whether insertions run the x86-64-v3 copy of the code (set only
    /// when [`has_v3`](super::isa::has_v3) holds).
    v3: bool,
}

impl<'p, K: Kernel, S> Builder<'p, K, S> {
    /// A builder over `store` for the points `pts` (by vertex id).
    pub(crate) fn new(
        pts: &'p [Slot],
        store: S,
        filter: StaticFilter,
        grid: Option<([f64; 3], f64)>,
        limits: &Limits,
        seed: u64,
    ) -> Self {
        Builder {
            kernel: std::marker::PhantomData,
            filter,
            grid,
            pts,
            store,
            rng: SplitMix64::new(seed),
            cav: Cavity::new(pts.len(), limits.max_local),
            last: 0,
            v3: limits.isa.use_v3(),
        }
    }

    /// The same builder (scratch, walk position) over another store.
    pub(crate) fn with_store<T>(self, store: T) -> (Builder<'p, K, T>, S) {
        let b = Builder {
            kernel: std::marker::PhantomData,
            filter: self.filter,
            grid: self.grid,
            pts: self.pts,
            store,
            rng: self.rng,
            cav: self.cav,
            last: self.last,
            v3: self.v3,
        };
        (b, self.store)
    }
}

impl<K: Kernel, S: Store> Builder<'_, K, S> {
    #[inline(always)]
    fn p(&self, v: u32) -> &Point3 {
        &self.pts[v as usize].0
    }

    /// Orientation of tet `t` with its vertex `i` replaced by point `q`
    /// (`t` finite): > 0 when `q` is on the same side of face `i` as vertex `i`.
    #[inline(always)]
    fn orient_replaced(&self, t: &[u32; 4], i: usize, q: &Point3) -> i32 {
        let mut p = [self.p(t[0]), self.p(t[1]), self.p(t[2]), self.p(t[3])];
        p[i] = q;
        K::orient3d_static(p[0], p[1], p[2], p[3], &self.filter)
    }

    /// Remembering stochastic walk from `self.last` to a tetrahedron in
    /// conflict with `q`: either a finite tet whose closure contains `q`, or
    /// an infinite tet whose hull facet `q` sees strictly. Stops on a tet
    /// whose neighbours this thread may not read ([`Stop::Busy`]).
    #[inline(always)]
    fn locate_impl(&mut self, q: &Point3) -> Result<u32, Stop> {
        let mut t = self.last;
        let v = self.store.cell(t).v;
        if !self.store.may_read(&v) {
            return Err(Stop::Busy);
        }
        if v[3] == INFINITE {
            if K::orient3d_static(self.p(v[0]), self.p(v[1]), self.p(v[2]), q, &self.filter) > 0 {
                return Ok(t);
            }
            t = self.store.n(t, 3) >> 2;
        }
        let mut prev = u32::MAX;
        'walk: loop {
            let c = self.store.cell(t);
            if !self.store.may_read(&c.v) {
                return Err(Stop::Busy);
            }
            if c.v[3] == INFINITE {
                // Entered through the hull facet with q strictly beyond it.
                return Ok(t);
            }
            let r = (self.rng.next_u64() >> 62) as usize;
            for j in 0..4 {
                let f = (r + j) & 3;
                let n = c.n[f] >> 2;
                if n == prev {
                    continue;
                }
                if self.orient_replaced(&c.v, f, q) < 0 {
                    prev = t;
                    t = n;
                    continue 'walk;
                }
            }
            return Ok(t);
        }
    }

    /// [`Builder::locate_impl`] for the target's baseline instruction set.
    #[inline(never)]
    fn locate(&mut self, q: &Point3) -> Result<u32, Stop> {
        self.locate_impl(q)
    }

    /// [`Builder::locate_impl`] compiled for x86-64-v3 (called only by
    /// [`Builder::insert_v3`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    #[inline(never)]
    fn locate_v3(&mut self, q: &Point3) -> Result<u32, Stop> {
        self.locate_impl(q)
    }

    /// Walks to point `vid` without inserting it, and makes the tet found
    /// the start of the next walk (a parallel build aims each thread at
    /// its first point this way).
    pub(crate) fn aim(&mut self, vid: u32) -> Result<(), Stop> {
        let q = self.pts[vid as usize].0;
        self.last = self.locate(&q)?;
        Ok(())
    }

    /// Inserts point `vid`; returns the vertex it duplicates, if any (then
    /// nothing changes), or why it stopped (then nothing changes either,
    /// except for [`Stop::TetLimit`], after which the builder must be
    /// dropped). Runs the copy compiled for the best instruction set the
    /// CPU has (see [`has_v3`](super::isa::has_v3)), unless the build
    /// limits ask for the baseline.
    #[inline(always)]
    #[allow(unsafe_code)]
    pub(crate) fn insert(&mut self, vid: u32) -> Result<Option<u32>, Stop> {
        #[cfg(target_arch = "x86_64")]
        if self.v3 {
            // SAFETY: a `#[target_feature]` function may be called only
            // on a CPU with the features it enables; `v3` is set only
            // when `has_v3()` found every one of them.
            return unsafe { self.insert_v3(vid) };
        }
        self.insert_baseline(vid)
    }

    /// [`Builder::insert`] after point `prev.0`, which became vertex
    /// `prev.1` (itself, or the vertex it duplicates): a point equal to it
    /// duplicates that vertex without a walk. Equal points are consecutive
    /// in the insertion order wherever they crowd (see
    /// `order::refine_crowded`), so a run of copies costs one comparison
    /// each.
    #[inline]
    pub(crate) fn insert_after(
        &mut self,
        vid: u32,
        prev: Option<(u32, u32)>,
    ) -> Result<Option<u32>, Stop> {
        if let Some((p, w)) = prev {
            if self.pts[p as usize].0 == self.pts[vid as usize].0 {
                return Ok(Some(w));
            }
        }
        self.insert(vid)
    }

    /// [`Builder::insert`] for the target's baseline instruction set.
    #[inline(never)]
    fn insert_baseline(&mut self, vid: u32) -> Result<Option<u32>, Stop> {
        let q = self.pts[vid as usize].0;
        let start = self.locate(&q)?;
        self.insert_at(vid, q, start)
    }

    /// [`Builder::insert`] compiled for x86-64-v3: the same source, and
    /// the same result bit for bit (Rust never fuses or reorders
    /// floating-point operations, whatever the target features), but the
    /// three-operand AVX instructions take about a fifth off the
    /// predicates' instruction count.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    #[inline(never)]
    fn insert_v3(&mut self, vid: u32) -> Result<Option<u32>, Stop> {
        let q = self.pts[vid as usize].0;
        let start = self.locate_v3(&q)?;
        self.insert_at(vid, q, start)
    }

    /// Inserts `q`, vertex `vid`, whose walk ended at tet `start` (see
    /// [`Builder::insert`]).
    #[inline(always)]
    fn insert_at(&mut self, vid: u32, q: Point3, start: u32) -> Result<Option<u32>, Stop> {
        // A duplicate lies on a vertex of the located (finite) tet, which
        // is where the next walk starts (the next point is often another
        // copy, or near it).
        let sv = self.store.cell(start).v;
        for w in sv {
            if w != INFINITE && self.pts[w as usize].0 == q {
                self.last = start;
                return Ok(Some(w));
            }
        }
        if !self.store.owns(&sv) {
            return Err(Stop::Busy);
        }

        // Conflict region by graph search; `conflicts` doubles as the stack.
        // Each boundary facet found (conflict tet c, face f, outer tet
        // not in conflict) immediately gets its new tet: c with vertex f
        // replaced by q, keeping c's outer neighbour.
        self.cav.conflicts.clear();
        self.cav.new_tets.clear();
        if let Err(stop) = self.search(start, vid, &q) {
            self.undo();
            return Err(stop);
        }

        self.cav.link(&mut self.store, vid);
        self.clear_flags();

        // Free the cavity (the dead cells are exactly the free cells, which
        // is how compaction finds them; their flags do not matter, as a
        // reused cell is overwritten whole).
        self.store
            .release_all(self.cav.conflicts.iter().map(|&e| e >> 2));
        // Start the next walk from a new finite tet if there is one.
        let mut last = self.cav.new_tets[0].0 >> 2;
        for &(p, _) in self.cav.new_tets.iter().rev() {
            if self.store.v(p >> 2, 3) != INFINITE {
                last = p >> 2;
                break;
            }
        }
        self.last = last;
        Ok(None)
    }

    /// The conflict search of [`Builder::insert_at`] from tet `start`,
    /// building the new tets on the cavity's boundary as it finds them.
    #[inline(always)]
    fn search(&mut self, start: u32, vid: u32, q: &Point3) -> Result<(), Stop> {
        // The stack holds each conflict tet packed with the face through
        // which it was found (its parent, in conflict): only the other
        // three faces are visited. The start has no parent: its face
        // field is unused, and all four faces are visited.
        self.enqueue(start << 2);
        {
            let cell = self.store.cell(start);
            let v = [cell.v[0] & !IN_CONFLICT, cell.v[1], cell.v[2], cell.v[3]];
            for f in 0..4 {
                self.visit(start, &v, cell.n[f], f, vid, q)?;
            }
        }
        let mut k = 1;
        while k < self.cav.conflicts.len() {
            let entry = self.cav.conflicts[k];
            k += 1;
            let c = entry >> 2;
            let cell = self.store.cell(c);
            // The vertices without the conflict flag (cleared in a
            // register: a byte-wide clear in memory followed by a wide
            // copy stalls store forwarding).
            let v = [cell.v[0] & !IN_CONFLICT, cell.v[1], cell.v[2], cell.v[3]];
            for f in OTHER[(entry & 3) as usize] {
                self.visit(c, &v, cell.n[f], f, vid, q)?;
            }
        }
        Ok(())
    }

    /// Clears the CLEAR flags set during this insertion.
    #[inline(always)]
    fn clear_flags(&mut self) {
        for &n in &self.cav.cleared {
            self.store.update(n, |c| c.v[1] &= !CLEAR);
        }
        self.cav.cleared.clear();
    }

    /// Undoes an insertion whose search stopped: gives the outer tets
    /// back their neighbours, frees the new tets and clears every flag,
    /// which leaves the cells as they were.
    #[cold]
    fn undo(&mut self) {
        for &(packed, c) in &self.cav.new_tets {
            let (nt, f) = unpack(packed);
            let (outer, j) = unpack(self.store.n(nt, f));
            self.store.set_n(outer, j, pack(c, f));
            self.store.release(nt);
        }
        for &e in &self.cav.conflicts {
            self.store.update(e >> 2, |c| c.v[0] &= !IN_CONFLICT);
        }
        self.clear_flags();
        self.cav.reset_linking();
        self.cav.conflicts.clear();
        self.cav.new_tets.clear();
    }

    /// Queues tet `packed >> 2`, found in conflict through its face
    /// `packed & 3`: flags it and prefetches its four neighbours, which
    /// it will visit.
    #[inline(always)]
    fn enqueue(&mut self, packed: u32) {
        let n = self.store.update(packed >> 2, |c| {
            c.v[0] |= IN_CONFLICT;
            c.n
        });
        for x in n {
            self.store.prefetch(x >> 2);
        }
        self.cav.conflicts.push(packed);
    }

    /// Visits face `f` (packed neighbour `outer`) of conflict tet `c`
    /// (vertices `v`, flags cleared) while inserting `q` as vertex `vid`:
    /// queues the neighbour if it is in conflict too, else builds the new
    /// tet on the boundary facet.
    #[inline(always)]
    fn visit(
        &mut self,
        c: u32,
        v: &[u32; 4],
        outer: u32,
        f: usize,
        vid: u32,
        q: &Point3,
    ) -> Result<(), Stop> {
        let n = outer >> 2;
        let nv = self.store.cell(n).v;
        if !self.store.owns(&nv) {
            return Err(Stop::Busy);
        }
        if nv[0] & IN_CONFLICT != 0 {
            return Ok(());
        }
        if nv[1] & CLEAR == 0 && self.in_conflict(n, &nv, vid, q) {
            self.enqueue(outer);
            return Ok(());
        }
        let nt = self.store.alloc()?;
        // Written in place: building the cell on the stack with
        // `v[f] = vid` and copying it whole stalls store forwarding.
        self.store.update(nt, |new| {
            new.v = *v;
            new.v[f] = vid;
            // (Its other neighbours are set by the linking.)
            new.n[f] = outer;
        });
        self.store.set_n(n, (outer & 3) as usize, pack(nt, f));
        if self.cav.filing {
            self.cav.file_faces(nt, f, v);
        }
        self.cav.new_tets.push((pack(nt, f), c));
        Ok(())
    }

    /// Whether inserting `q` destroys tet `n` (vertices `nv`). A tet found
    /// not in conflict only after the kernel's slow stages (a tie, or a
    /// determinant the static filter cannot settle) is marked CLEAR and
    /// remembered, so that the other conflict tets next to it do not test
    /// it again; the usual quick answers are cheaper to repeat than to
    /// mark and unmark.
    #[inline(always)]
    fn in_conflict(&mut self, n: u32, nv: &[u32; 4], vid: u32, q: &Point3) -> bool {
        let quick = conflict_quick::<K>(self.pts, nv, q, &self.filter);
        if quick != 0 {
            return quick > 0;
        }
        let conflict = if K::QUICK_IS_EXACT && self.grid.is_some() && nv[3] != INFINITE {
            // An exact quick stage answered 0: a tie.
            self.tie_keyed(nv, vid) > 0
        } else {
            tet_in_conflict::<K>(self.pts, nv, q, &self.filter)
        };
        if !conflict {
            self.store.update(n, |c| c.v[1] |= CLEAR);
            self.cav.cleared.push(n);
        }
        conflict
    }

    /// The symbolic perturbation of an exact in-sphere tie between finite
    /// tet `v` and vertex `vid`, ranking the points by the lexicographic
    /// keys in their slots (only when `self.grid` is set): one integer
    /// compare per comparison instead of up to three float compares (the
    /// grid's ties are a sixth of its build).
    #[inline(always)]
    fn tie_keyed(&self, v: &[u32; 4], vid: u32) -> i32 {
        let s = |w: u32| &self.pts[w as usize];
        let pts = [s(v[0]), s(v[1]), s(v[2]), s(v[3]), s(vid)];
        insphere_tie_keyed::<K>(pts.map(|slot| &slot.0), pts.map(|slot| slot.1))
    }
}

/// Build limits that tests lower to reach rare paths.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Limits {
    /// The most cells the build may hold (at most [`MAX_CELLS`]).
    pub(crate) max_cells: usize,
    /// The largest cavity (in boundary vertices) linked by table.
    pub(crate) max_local: usize,
    /// The instruction set of the insertion loop.
    pub(crate) isa: Isa,
    /// Whether a [`SmallGrid`] input keeps lexicographic keys for ties.
    pub(crate) grid_keys: bool,
    /// Threads of the build (1: the single-threaded build).
    pub(crate) threads: usize,
    /// The smallest BRIO round that a parallel build splits between its
    /// threads, per thread (earlier rounds run on one thread).
    pub(crate) par_min: usize,
}

impl Limits {
    pub(crate) const DEFAULT: Limits = Limits {
        max_cells: MAX_CELLS,
        max_local: MAX_LOCAL,
        isa: Isa::Detect,
        grid_keys: true,
        threads: 1,
        par_min: 8192,
    };
}

/// The points of a build in insertion order, with their input indices.
pub(crate) struct Input {
    /// Every point, by vertex id: the first four make the first tet
    /// (positively oriented), the others follow the BRIO order. A
    /// duplicate's id is dropped at the end
    /// ([`super::build`]'s `finish`).
    pub(crate) pts: Vec<Slot>,
    /// Vertex id -> input index.
    pub(crate) ins_input: Vec<u32>,
    /// The vertex id at which each BRIO round starts, and `pts.len()`.
    pub(crate) bounds: Vec<usize>,
    /// The number of input points.
    pub(crate) n: usize,
    /// Their bounding box.
    pub(crate) bbox: ([f64; 3], [f64; 3]),
}

impl Input {
    /// Gathers `points` in the order of the first tet `init`, then `order`
    /// (BRIO rounds of sizes `rounds`).
    pub(crate) fn new(
        points: &[Point3],
        order: &[u32],
        rounds: &[usize],
        init: [u32; 4],
        grid: Option<([f64; 3], f64)>,
        bbox: ([f64; 3], [f64; 3]),
    ) -> Input {
        let n = points.len();
        let slot = |p: &Point3| match &grid {
            Some((lo, step)) => Slot(*p, SmallGrid::lex_key(p, lo, *step)),
            None => Slot(*p, 0),
        };
        let mut s = init;
        if orient3d(
            &points[s[0] as usize],
            &points[s[1] as usize],
            &points[s[2] as usize],
            &points[s[3] as usize],
        )
        .is_negative()
        {
            s.swap(0, 1);
        }
        let mut pts = Vec::with_capacity(n);
        let mut ins_input = Vec::with_capacity(n);
        for &i in &s {
            pts.push(slot(&points[i as usize]));
            ins_input.push(i);
        }
        let mut bounds = Vec::with_capacity(rounds.len() + 1);
        let mut k = 0;
        for &size in rounds {
            bounds.push(pts.len());
            for &i in &order[k..k + size] {
                if !init.contains(&i) {
                    pts.push(slot(&points[i as usize]));
                    ins_input.push(i);
                }
            }
            k += size;
        }
        bounds.push(pts.len());
        Input {
            pts,
            ins_input,
            bounds,
            n,
            bbox,
        }
    }
}

/// Each duplicate's vertex id, with the vertex it duplicates.
pub(crate) type Dups = Vec<(u32, u32)>;

/// The cells of a finished build, before compaction.
pub(crate) struct Built {
    /// Every cell, live or dead.
    pub(crate) cells: Vec<Cell>,
    /// The dead cells (in any order).
    pub(crate) holes: Vec<u32>,
    /// Each duplicate's vertex id, with the vertex it duplicates.
    pub(crate) dups: Dups,
    /// How the build went.
    pub(crate) stats: BuildStats,
}

/// What a build reports about itself, besides its result (tests read it
/// to check that a rare path ran).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct BuildStats {
    /// The threads that shared rounds (1: the build ran on one thread).
    pub(crate) threads: usize,
    /// Points that a parallel pass left over for a later pass because
    /// their cavity reached another thread's tets (counted once per pass
    /// that left them).
    pub(crate) deferred: usize,
}

/// The seed of the walks' random choices (of the first thread's, in a
/// parallel build).
pub(crate) const SEED: u64 = 0xC0FFEE;

/// Writes the first tetrahedron, vertices 0 to 3, and its four infinite
/// neighbours into an empty store; returns the first.
pub(crate) fn first_tet(store: &mut Owned) -> Result<u32, Stop> {
    let t0 = store.alloc()?;
    store.update(t0, |c| c.v = [0, 1, 2, 3]);
    let mut ids = [t0; 5];
    for i in 0..4 {
        let ti = store.alloc()?;
        // Face i of the first tet, reversed so that the infinite vertex (at
        // index 3, as in every infinite tet) is on its outer side.
        let f = FACE[i];
        store.update(ti, |c| {
            c.v = [f[1] as u32, f[0] as u32, f[2] as u32, INFINITE]
        });
        ids[i + 1] = ti;
    }
    link_by_faces(&mut store.cells, &ids);
    Ok(t0)
}

#[cfg(test)]
mod tests {
    use super::super::build::{build_with, initial_simplex};
    use super::super::order::brio_order;
    use super::super::sequential::run_owned;
    use super::super::test_points::{int_grid, integer_sphere, uniform_points};
    use super::{Builder, Cell, Input, Isa, Limits, Stop};
    use crate::geometry::predicates::{Filtered, StaticFilter};
    use crate::rng::SplitMix64;
    use std::io::Write;

    /// An insertion stopped part way through its cavity (here by the tet
    /// limit; in a parallel build by a tet of another thread) is undone:
    /// every live cell is as it was, and the cells it took are free again.
    #[test]
    fn a_stopped_insertion_is_undone() {
        let pts = uniform_points(9, 3000);
        let bbox = crate::geometry::bounding_box(&pts);
        let (order, rounds, _) = brio_order(&pts, &bbox, 1, Isa::Detect);
        let init = initial_simplex(&pts, &order).unwrap();
        let input = Input::new(&pts, &order, &rounds, init, None, bbox);
        let filter = StaticFilter::for_box(&bbox.0, &bbox.1);
        let mut undone = 0;
        for end in (100..3000).step_by(97) {
            let (mut b, _) =
                run_owned::<Filtered>(&input, &Limits::DEFAULT, filter, None, end).unwrap();
            let live = |b: &Builder<'_, Filtered, super::Owned>| {
                let free: std::collections::HashSet<u32> = b.store.free.iter().copied().collect();
                let cells: Vec<(usize, Cell)> = (0..b.store.cells.len())
                    .filter(|t| !free.contains(&(*t as u32)))
                    .map(|t| (t, b.store.cells[t]))
                    .collect();
                (cells, free)
            };
            let before = live(&b);
            // No cell beyond the free ones: the insertion stops when it
            // needs more new tets than its cavity frees as it goes.
            b.store.max_cells = b.store.cells.len();
            match b.insert(end as u32) {
                Err(Stop::TetLimit) => {
                    undone += 1;
                    let after = live(&b);
                    assert!(after.0 == before.0, "end {end}");
                    assert_eq!(after.1, before.1, "end {end}");
                    // And the builder goes on from there.
                    b.store.max_cells = usize::MAX;
                    assert_eq!(b.insert(end as u32), Ok(None));
                }
                other => assert_eq!(other, Ok(None)),
            }
        }
        assert!(undone > 10, "{undone}");
    }

    /// The x86-64-v3 copy of the insertion and of the order gives the
    /// baseline's triangulation bit for bit: same cells in the same
    /// slots, same vertex maps, on both kernels, with exact ties, and
    /// through both linkings. On a CPU without v3 both runs take the
    /// baseline, and the test says so on the terminal (written past the
    /// test harness's capture, so it shows even when the test passes).
    #[test]
    fn instruction_sets_agree() {
        if !crate::delaunay::isa::has_v3() {
            let _ = writeln!(
                std::io::stderr(),
                "instruction_sets_agree: SKIPPED the comparison: this CPU lacks \
                 x86-64-v3, so both runs take the baseline copy"
            );
        }
        let uniform = uniform_points(11, 20_000);
        let grid = int_grid(10);
        // A grid under a shear and a non-dyadic scale: the filtered
        // kernel, with exact and near ties.
        let affine: Vec<[f64; 3]> = grid
            .iter()
            .map(|p| [0.1 * p[0] + 0.3 * p[1], 0.7 * p[1], 0.1 * p[2] - 0.2 * p[0]])
            .collect();
        let mut rng = SplitMix64::new(12);
        let sphere: Vec<[f64; 3]> = (0..2000)
            .map(|_| {
                let (a, b) = (
                    rng.uniform() * std::f64::consts::TAU,
                    rng.uniform() * 2.0 - 1.0,
                );
                let r = (1.0 - b * b).sqrt();
                [r * a.cos(), r * a.sin(), b]
            })
            .collect();
        for (name, pts) in [
            ("uniform", &uniform),
            ("grid", &grid),
            ("affine", &affine),
            ("sphere", &sphere),
        ] {
            for max_local in [0, Limits::DEFAULT.max_local] {
                let run = |isa| {
                    let limits = Limits {
                        max_local,
                        isa,
                        ..Limits::DEFAULT
                    };
                    build_with(pts, limits).unwrap()
                };
                let (v3, base) = (run(Isa::Detect), run(Isa::Baseline));
                v3.validate().unwrap();
                assert!(v3.cells.len() > pts.len(), "{name}");
                assert!(v3.cells == base.cells, "{name}, max_local {max_local}");
                assert!(v3.pts == base.pts, "{name}");
                assert!(v3.input_vert == base.input_vert, "{name}");
                assert!(v3.vert_input == base.vert_input, "{name}");
            }
        }
    }

    /// Breaking in-sphere ties on a small grid by the keys kept in the
    /// point slots gives the triangulation the plain tie-break gives, on
    /// a grid (where most tests tie) and on cospherical integer points.
    #[test]
    fn grid_keys_agree() {
        let grid: Vec<[f64; 3]> = (0..1728)
            .map(|i| {
                [
                    (i % 12) as f64 * 0.5,
                    (i / 12 % 12) as f64,
                    (i / 144) as f64 - 7.0,
                ]
            })
            .collect();
        let sphere = integer_sphere(841);
        for pts in [&grid, &sphere] {
            let run = |grid_keys| {
                let limits = Limits {
                    grid_keys,
                    ..Limits::DEFAULT
                };
                build_with(pts, limits).unwrap()
            };
            let (keyed, plain) = (run(true), run(false));
            keyed.validate().unwrap();
            assert!(keyed.cells.len() > pts.len());
            assert!(keyed.cells == plain.cells);
            assert!(keyed.input_vert == plain.input_vert);
        }
    }
}
