//! Bulk construction: BRIO order, remembering walk, Bowyer–Watson cavity.

use super::isa::Isa;
use super::order::{brio_order, SplitMix64};
use super::store::{Owned, Stop, Store};
use super::{DelaunayError, Triangulation, INFINITE};
use crate::geometry::predicates::{
    collinear, coplanar_incircle_perturbed, insphere_perturbed_k, insphere_tie_keyed, orient3d,
    Filtered, Kernel, SmallGrid, StaticFilter,
};
use crate::geometry::Point3;

/// The vertices of a cell just allocated, before it is written.
pub(crate) const DEAD: u32 = u32::MAX - 1;
/// An adjacency slot not yet linked.
pub(crate) const UNSET: u32 = u32::MAX;
/// Flag on a tet's `v[0]`: the tet is in the current conflict region.
/// Vertex ids stay below 2^31 (see [`DelaunayError::TooManyPoints`]), and
/// `v[0]` and `v[1]` are never the infinite vertex (always at index 3), so
/// the top bit of either is free; flags live only during one insertion.
pub(crate) const IN_CONFLICT: u32 = 1 << 31;
/// Flag on a tet's `v[1]`: the tet was tested and is not in conflict.
pub(crate) const CLEAR: u32 = 1 << 31;

/// One tetrahedron: vertex ids and packed neighbours (`4 * tet + mirror`),
/// interleaved so that visiting a tet touches one 32-byte block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub(crate) struct Cell {
    pub(crate) v: [u32; 4],
    pub(crate) n: [u32; 4],
}

/// Faces: for vertex index `i`, the other three indices in an order that
/// makes `(face[i][0], face[i][1], face[i][2], i)` an even permutation of
/// `(0, 1, 2, 3)`, so face `i` seen from vertex `i` is counter-clockwise.
pub(crate) const FACE: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];

/// For each face index, the other three.
const OTHER: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];

/// For each face index `f`, the three directed edges of the facet opposite
/// vertex `f`, in the cyclic order of [`FACE`]`[f]`, each as `(g, a, b)`:
/// the edge goes from vertex `a` to vertex `b`, and `g` is the third
/// vertex of the facet (the face opposite `g` holds the edge and vertex `f`).
const DIRECTED: [[(usize, usize, usize); 3]; 4] = {
    let mut d = [[(0, 0, 0); 3]; 4];
    let mut f = 0;
    while f < 4 {
        let c = FACE[f];
        d[f] = [(c[2], c[0], c[1]), (c[0], c[1], c[2]), (c[1], c[2], c[0])];
        f += 1;
    }
    d
};

/// Bound on the local numbers of the edge table (a power of two): filing
/// stops, and the cavity is linked by rotation, when a new tet could take
/// the count past it, i.e. for cavities of more than 61 boundary vertices.
const MAX_LOCAL: usize = 64;
/// Local number of a vertex not on the current cavity's boundary.
const NO_LOCAL: u8 = u8::MAX;
/// New tets whose faces can be filed (at least 2·MAX_LOCAL − 4, the facets
/// of a boundary with MAX_LOCAL vertices; a power of two).
const FACES: usize = 128;

/// Scratch of the table linking of new tets: the boundary vertices with a
/// local number; per directed edge (a, b) of local numbers, the new tet's
/// face that holds it; per new tet, the local numbers of its vertices.
/// Entries are never cleared: every entry read was written during the
/// same insertion.
struct EdgeTable {
    nloc: usize,
    bverts: [u32; MAX_LOCAL],
    faces: [u32; MAX_LOCAL * MAX_LOCAL],
    local: [[u8; 4]; FACES],
}

/// Asks the cache to start fetching `cells[i]`, which the conflict search
/// is about to read: a tet found in conflict has its four neighbours
/// prefetched when it is queued, so their cache misses overlap with the
/// tests of the tets queued before it (about 8% of the build at 1M
/// points, see BENCHMARKS.md). No effect on results; a no-op off x86_64.
///
/// One of the crate's three `unsafe` calls (the others enter the x86-64-v3
/// copies, see [`super::isa`]): `_mm_prefetch` is a `#[target_feature
/// (enable = "sse")]` function, and SSE is part of the x86_64 baseline. A
/// prefetch is a hint that never dereferences in the language's sense and
/// never faults, whatever the address (`prefetch_never_faults` passes
/// addresses far outside the slice), and the pointer is formed with
/// `wrapping_add`, which is defined for any offset.
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn prefetch<T>(cells: &[T], i: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = cells.as_ptr().wrapping_add(i) as *const i8;
        // SAFETY: SSE is enabled on every x86_64 target, and a prefetch
        // has no memory-safety requirement on its address (see above).
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (cells, i);
}

#[inline(always)]
fn pack(t: u32, i: usize) -> u32 {
    (t << 2) | i as u32
}

/// A point of the build, padded to 32 bytes and aligned so that it never
/// straddles two cache lines (24-byte points straddle one time in four),
/// with its lexicographic key in the padding when the set has one
/// ([`SmallGrid::lex_key`]; else 0).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct Slot(pub(crate) Point3, u64);

/// Points indexed by vertex id.
pub(crate) trait Points {
    /// The point of vertex `w`.
    fn at(&self, w: u32) -> &Point3;
}

impl Points for [Point3] {
    #[inline(always)]
    fn at(&self, w: u32) -> &Point3 {
        &self[w as usize]
    }
}

impl Points for [Slot] {
    #[inline(always)]
    fn at(&self, w: u32) -> &Point3 {
        &self[w as usize].0
    }
}

/// Whether inserting `q` destroys the tetrahedron with vertices `v` (an
/// infinite tet has the infinite vertex at index 3), under
/// CGAL's symbolic perturbation: for a finite tet, `q` is inside its
/// circumsphere; for an infinite tet, `q` is strictly beyond its hull facet,
/// or in the facet's plane and inside its circumcircle.
#[inline(always)]
pub(crate) fn tet_in_conflict<K: Kernel, P: Points + ?Sized>(
    pts: &P,
    v: &[u32; 4],
    q: &Point3,
    filter: &StaticFilter,
) -> bool {
    let p = |w: u32| pts.at(w);
    if v[3] == INFINITE {
        let o = K::orient3d_static(p(v[0]), p(v[1]), p(v[2]), q, filter);
        if o != 0 {
            return o > 0;
        }
        coplanar_incircle_perturbed(p(v[0]), p(v[1]), p(v[2]), q) > 0
    } else {
        insphere_perturbed_k::<K>(p(v[0]), p(v[1]), p(v[2]), p(v[3]), q, filter) > 0
    }
}

/// [`tet_in_conflict`] when the kernel's quick stage settles it: `1` in
/// conflict, `-1` not, `0` undecided.
#[inline(always)]
fn conflict_quick<K: Kernel, P: Points + ?Sized>(
    pts: &P,
    v: &[u32; 4],
    q: &Point3,
    filter: &StaticFilter,
) -> i32 {
    let p = |w: u32| pts.at(w);
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
    // Scratch, reused across insertions.
    conflicts: Vec<u32>,
    /// Tets marked CLEAR during the current insertion.
    cleared: Vec<u32>,
    /// New tets of the current insertion: each packed with the face index
    /// of its outer neighbour, and the conflict tet it replaces.
    new_tets: Vec<(u32, u32)>,
    /// Local number of each vertex on the current cavity's boundary
    /// ([`NO_LOCAL`] otherwise); the last slot stands for the infinite
    /// vertex. One byte per vertex keeps this mostly in cache.
    loc: Vec<u8>,
    /// Scratch of [`Builder::file_faces`] and [`Builder::link_filed`].
    table: Box<EdgeTable>,
    /// The bound on local numbers ([`MAX_LOCAL`]; lower in tests, 0 to
    /// link every cavity by rotation).
    max_local: usize,
    /// Whether the current insertion's new tets are being filed in
    /// `table` (until the cavity proves too large for it).
    filing: bool,
    /// Where the next walk starts (a tet this builder owns).
    pub(crate) last: u32,
    /// Whether insertions run the x86-64-v3 copy of the code (set only
    /// when [`has_v3`](super::isa::has_v3) holds).
    v3: bool,
}

/// Tet ids are packed with a 2-bit face index into a `u32`, so there can be
/// at most 2^30 tetrahedra (about 150 million uniform points). An insertion
/// that would need more stops the build with
/// [`DelaunayError::TooManyTets`].
pub(crate) const MAX_CELLS: usize = 1 << 30;

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
            conflicts: Vec::new(),
            cleared: Vec::new(),
            new_tets: Vec::new(),
            loc: vec![NO_LOCAL; pts.len() + 1],
            table: Box::new(EdgeTable {
                nloc: 0,
                bverts: [0; MAX_LOCAL],
                faces: [0; MAX_LOCAL * MAX_LOCAL],
                local: [[0; 4]; FACES],
            }),
            max_local: limits.max_local,
            filing: limits.max_local > 0,
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
            conflicts: self.conflicts,
            cleared: self.cleared,
            new_tets: self.new_tets,
            loc: self.loc,
            table: self.table,
            max_local: self.max_local,
            filing: self.filing,
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
        // A duplicate lies on a vertex of the located (finite) tet.
        let sv = self.store.cell(start).v;
        for w in sv {
            if w != INFINITE && self.pts[w as usize].0 == q {
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
        self.conflicts.clear();
        self.new_tets.clear();
        if let Err(stop) = self.search(start, vid, &q) {
            self.undo();
            return Err(stop);
        }

        if self.filing {
            self.link_filed();
        } else {
            self.forget_local_numbers();
            // Point slot f of each conflict tet with a boundary facet f at
            // its new tet (c is about to die), which is how the rotation
            // recognises boundary facets, and mark the new tets' inner
            // faces unlinked.
            for &(packed, c) in &self.new_tets {
                let (nt, f) = (packed >> 2, (packed & 3) as usize);
                for g in OTHER[f] {
                    self.store.set_n(nt, g, UNSET);
                }
                self.store.set_n(c, f, packed);
            }
            self.link_by_rotation(vid);
        }
        self.filing = self.max_local > 0;
        self.clear_flags();

        // Free the cavity (the dead cells are exactly the free cells, which
        // is how compaction finds them; their flags do not matter, as a
        // reused cell is overwritten whole).
        self.store
            .release_all(self.conflicts.iter().map(|&e| e >> 2));
        // Start the next walk from a new finite tet if there is one.
        let mut last = self.new_tets[0].0 >> 2;
        for &(p, _) in self.new_tets.iter().rev() {
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
        while k < self.conflicts.len() {
            let entry = self.conflicts[k];
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
        for &n in &self.cleared {
            self.store.update(n, |c| c.v[1] &= !CLEAR);
        }
        self.cleared.clear();
    }

    /// Undoes an insertion whose search stopped: gives the outer tets
    /// back their neighbours, frees the new tets and clears every flag,
    /// which leaves the cells as they were.
    #[cold]
    fn undo(&mut self) {
        for &(packed, c) in &self.new_tets {
            let (nt, f) = (packed >> 2, (packed & 3) as usize);
            let outer = self.store.n(nt, f);
            self.store
                .set_n(outer >> 2, (outer & 3) as usize, pack(c, f));
            self.store.release(nt);
        }
        for &e in &self.conflicts {
            self.store.update(e >> 2, |c| c.v[0] &= !IN_CONFLICT);
        }
        self.clear_flags();
        self.forget_local_numbers();
        self.filing = self.max_local > 0;
        self.conflicts.clear();
        self.new_tets.clear();
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
        self.conflicts.push(packed);
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
        if self.filing {
            self.file_faces(nt, f, v);
        }
        self.new_tets.push((pack(nt, f), c));
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
        let quick = conflict_quick::<K, _>(self.pts, nv, q, &self.filter);
        if quick != 0 {
            return quick > 0;
        }
        let conflict = if K::QUICK_IS_EXACT && self.grid.is_some() && nv[3] != INFINITE {
            // An exact quick stage answered 0: a tie.
            self.tie_keyed(nv, vid) > 0
        } else {
            tet_in_conflict::<K, _>(self.pts, nv, q, &self.filter)
        };
        if !conflict {
            self.store.update(n, |c| c.v[1] |= CLEAR);
            self.cleared.push(n);
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

    /// Files the three inner faces of new tet `nt` (built on facet `f` of
    /// a conflict tet whose vertices, flags cleared, are `v`) in the edge
    /// table; on a cavity too large for it, stops filing for this
    /// insertion.
    ///
    /// Every face of a new tet other than its outer one holds `q` and an
    /// edge (a, b) of the cavity boundary, a closed triangulated sphere,
    /// so each edge is on exactly two such faces, which are then
    /// neighbours. All new tets are positively oriented with `q` at the
    /// slot of their outer facet, so walking each outer facet in the order
    /// of [`FACE`] orients the boundary consistently: the two facets on an
    /// edge traverse it in opposite directions. The boundary vertices get
    /// local numbers 0..K (the infinite vertex too, at slot `loc.len() -
    /// 1`); the face holding directed edge a → b is filed at (a, b), and
    /// its partner is later read at (b, a) ([`Builder::link_filed`]).
    /// Unlike a rotation around the edge, the lookups are independent of
    /// each other, so their latencies overlap, and the vertices are
    /// already loaded.
    #[inline(always)]
    fn file_faces(&mut self, nt: u32, f: usize, v: &[u32; 4]) {
        let i = self.new_tets.len();
        let t = &mut *self.table;
        if i >= FACES || t.nloc + 3 > self.max_local {
            self.filing = false;
            return;
        }
        let top = self.loc.len() - 1;
        let mut lv = [0u8; 4];
        for h in OTHER[f] {
            let w = (v[h] as usize).min(top);
            let mut l = self.loc[w];
            if l == NO_LOCAL {
                l = t.nloc as u8;
                self.loc[w] = l;
                // (The masks are no-ops that drop bounds checks.)
                t.bverts[t.nloc & (MAX_LOCAL - 1)] = w as u32;
                t.nloc += 1;
            }
            lv[h] = l;
        }
        for &(g, a, b) in &DIRECTED[f] {
            let e = lv[a] as usize * MAX_LOCAL + lv[b] as usize;
            t.faces[e & (MAX_LOCAL * MAX_LOCAL - 1)] = pack(nt, g);
        }
        t.local[i & (FACES - 1)] = lv;
    }

    /// Links the new tets, all filed by [`Builder::file_faces`], to each
    /// other and forgets the local numbers.
    #[inline(always)]
    fn link_filed(&mut self) {
        let t = &mut *self.table;
        for (i, &(packed, _)) in self.new_tets.iter().enumerate() {
            let (nt, f) = (packed >> 2, (packed & 3) as usize);
            let lv = t.local[i & (FACES - 1)];
            self.store.update(nt, |c| {
                for &(g, a, b) in &DIRECTED[f] {
                    let e = lv[b] as usize * MAX_LOCAL + lv[a] as usize;
                    c.n[g] = t.faces[e & (MAX_LOCAL * MAX_LOCAL - 1)];
                }
            });
        }
        self.forget_local_numbers();
    }

    /// Resets the local numbers given during this insertion.
    fn forget_local_numbers(&mut self) {
        let t = &mut *self.table;
        for &w in &t.bverts[..t.nloc] {
            self.loc[w as usize] = NO_LOCAL;
        }
        t.nloc = 0;
    }

    /// Links the new tets of an insertion to each other by turning around
    /// the cavity's boundary edges (any cavity size).
    fn link_by_rotation(&mut self, vid: u32) {
        let cells = &mut self.store;
        // Link the new tets to each other. The face of new tet nt (built
        // on facet f of conflict tet c) opposite g != f holds q and an edge
        // (a, b) of the cavity boundary. Its neighbour is the new tet of
        // the next boundary facet met when turning around (a, b) from c
        // across its face g, through conflict tets only: every cell
        // visited is part of this insertion and already in cache.
        for &(packed, c) in &self.new_tets {
            let (nt, f) = (packed >> 2, (packed & 3) as usize);
            for g in OTHER[f] {
                if cells.n(nt, g) != UNSET {
                    continue;
                }
                // Invariant: we are about to cross face `gc` of conflict
                // tet `cur`; its faces `gc` and `hc` both contain (a, b).
                let (mut cur, mut gc, mut hc) = (c, g, f);
                loop {
                    let x = cells.n(cur, gc);
                    let t2 = x >> 2;
                    if cells.v(t2, gc) == vid {
                        // (cur, gc) is a boundary facet and t2 its new tet;
                        // the face of t2 holding (q, a, b) is opposite hc.
                        cells.set_n(nt, g, pack(t2, hc));
                        cells.set_n(t2, hc, pack(nt, g));
                        break;
                    }
                    // t2 is in conflict too: the face crossed is (a, b, w)
                    // with w = cur.v[hc]; next cross t2's face opposite w
                    // (only `v[0]` of a conflict tet carries a flag; it is
                    // never the infinite vertex, whose id has the top bit).
                    let w = cells.v(cur, hc);
                    let w = if hc == 0 { w & !IN_CONFLICT } else { w };
                    let tv = cells.cell(t2).v;
                    let kw = (tv[1] == w) as usize
                        + 2 * (tv[2] == w) as usize
                        + 3 * (tv[3] == w) as usize;
                    hc = (x & 3) as usize;
                    gc = kw;
                    cur = t2;
                }
            }
        }
    }
}

/// Checks the input and finds four affinely independent points, or the
/// dimension if there are none.
fn initial_simplex(points: &[Point3], order: &[u32]) -> Result<[u32; 4], usize> {
    let p0 = order[0];
    let a = &points[p0 as usize];
    let Some(&p1) = order.iter().find(|&&i| points[i as usize] != *a) else {
        return Err(0);
    };
    let b = &points[p1 as usize];
    let Some(&p2) = order
        .iter()
        .find(|&&i| !collinear(a, b, &points[i as usize]))
    else {
        return Err(1);
    };
    let c = &points[p2 as usize];
    let Some(&p3) = order
        .iter()
        .find(|&&i| orient3d(a, b, c, &points[i as usize]) != 0)
    else {
        return Err(2);
    };
    Ok([p0, p1, p2, p3])
}

/// Vertex mapping for inputs of dimension < 3: merge duplicates by sorting.
fn lower_dimensional(points: &[Point3], dim: usize) -> Triangulation {
    let n = points.len();
    let mut idx: Vec<u32> = (0..n as u32).collect();
    idx.sort_by(|&i, &j| {
        let (p, q) = (&points[i as usize], &points[j as usize]);
        p.partial_cmp(q)
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(i.cmp(&j))
    });
    let mut pts = Vec::new();
    let mut vert_input = Vec::new();
    let mut input_vert = vec![0u32; n];
    for (k, &i) in idx.iter().enumerate() {
        if k == 0 || points[idx[k - 1] as usize] != points[i as usize] {
            pts.push(points[i as usize]);
            vert_input.push(i);
        }
        input_vert[i as usize] = (pts.len() - 1) as u32;
    }
    let nv = pts.len();
    Triangulation {
        pts,
        vert_input,
        input_vert,
        cells: Vec::new(),
        num_finite: 0,
        vert_tet: vec![u32::MAX; nv],
        dim,
    }
}

pub(super) fn build(points: &[[f64; 3]], threads: usize) -> Result<Triangulation, DelaunayError> {
    build_with(
        points,
        Limits {
            threads: threads.max(1),
            ..Limits::DEFAULT
        },
    )
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

/// [`build`] with given limits (lower than the defaults only in tests).
pub(crate) fn build_with(
    points: &[[f64; 3]],
    limits: Limits,
) -> Result<Triangulation, DelaunayError> {
    let n = points.len();
    if n == 0 {
        return Err(DelaunayError::Empty);
    }
    if n >= (u32::MAX - 2) as usize / 8 {
        return Err(DelaunayError::TooManyPoints(n));
    }
    for (index, p) in points.iter().enumerate() {
        for (coord, &value) in p.iter().enumerate() {
            if !value.is_finite() {
                return Err(DelaunayError::NonFinite {
                    index,
                    coord,
                    value,
                });
            }
            let m = value.abs();
            if m > super::COORD_RANGE.1 || (m != 0.0 && m < super::COORD_RANGE.0) {
                return Err(DelaunayError::OutOfRange {
                    index,
                    coord,
                    value,
                });
            }
        }
    }
    // A parallel build's shared cells are zeroed by another thread while
    // this one orders the points.
    let zeroed = super::parallel::start(n, &limits);
    // (-0.0 == 0.0 for every comparison below, so signed zeros are one point.)
    // The bounding box orders the points and gives the static filter.
    let bbox = crate::geometry::bounding_box(points);
    let (order, rounds) = brio_order(points, &bbox, 0x5EED_0A11_A1FA_u64, limits.isa);
    let init = match initial_simplex(points, &order) {
        Ok(s) => s,
        Err(dim) => return Ok(lower_dimensional(points, dim)),
    };

    let filter = StaticFilter::for_box(&bbox.0, &bbox.1);
    let frame = SmallGrid::frame(points);
    let grid = frame.filter(|_| limits.grid_keys);
    let input = Input::new(points, &order, &rounds, init, grid, bbox);
    let built = match frame {
        Some(_) => run::<SmallGrid>(&input, &limits, filter, grid, zeroed),
        None => run::<Filtered>(&input, &limits, filter, None, zeroed),
    };
    let built = built.map_err(|_| DelaunayError::TooManyTets(n))?;
    Ok(finish(input, built))
}

/// The points of a build in insertion order, with their input indices.
pub(crate) struct Input {
    /// Every point, by vertex id: the first four make the first tet
    /// (positively oriented), the others follow the BRIO order. A
    /// duplicate's id is dropped at the end ([`finish`]).
    pub(crate) pts: Vec<Slot>,
    /// Vertex id -> input index.
    ins_input: Vec<u32>,
    /// The vertex id at which each BRIO round starts, and `pts.len()`.
    pub(crate) bounds: Vec<usize>,
    /// The number of input points.
    n: usize,
    /// Their bounding box.
    pub(crate) bbox: ([f64; 3], [f64; 3]),
}

impl Input {
    /// Gathers `points` in the order of the first tet `init`, then `order`
    /// (BRIO rounds of sizes `rounds`).
    fn new(
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
        ) < 0
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
}

/// The incremental construction proper, monomorphised over the kernel: on
/// one thread, or split between threads by [`super::parallel`] when
/// `zeroed` brings the cells of a parallel build.
fn run<K: Kernel>(
    input: &Input,
    limits: &Limits,
    filter: StaticFilter,
    grid: Option<([f64; 3], f64)>,
    zeroed: Option<super::parallel::Zeroed>,
) -> Result<Built, Stop> {
    if let Some(zeroed) = zeroed {
        return super::parallel::run::<K>(input, limits, filter, grid, zeroed);
    }
    let m = input.pts.len();
    let (b, dups) = run_owned::<K>(input, limits, filter, grid, m)?;
    let Owned { cells, free, .. } = b.store;
    Ok(Built {
        cells,
        holes: free,
        dups,
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
    // Uniform points give about 6.8 tets per point; untouched capacity costs
    // address space, not resident memory.
    let expected_tets = (7 * end + end / 2 + 64).min(limits.max_cells);
    let store = Owned {
        cells: Vec::with_capacity(expected_tets),
        free: Vec::new(),
        max_cells: limits.max_cells.min(MAX_CELLS),
    };
    let mut b = Builder::<K, _>::new(&input.pts, store, filter, grid, limits, SEED);
    b.last = first_tet(&mut b.store)?;
    let mut dups = Vec::new();
    for vid in 4..end as u32 {
        if let Some(w) = b.insert(vid)? {
            dups.push((vid, w));
        }
    }
    Ok((b, dups))
}

/// The seed of the walks' random choices (of the first thread's, in a
/// parallel build).
pub(crate) const SEED: u64 = 0xC0FFEE;

/// Writes the first tetrahedron, vertices 0 to 3, and its four infinite
/// neighbours into an empty store; returns the first.
pub(crate) fn first_tet<S: Store>(store: &mut S) -> Result<u32, Stop> {
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
    link_by_faces(store, &ids);
    Ok(t0)
}

/// Links the faces of a few tets by brute force (used for the first five).
fn link_by_faces<S: Store>(cells: &mut S, ids: &[u32]) {
    for &t in ids {
        for i in 0..4 {
            let mut fa: Vec<u32> = (0..4).filter(|&k| k != i).map(|k| cells.v(t, k)).collect();
            fa.sort_unstable();
            for &u in ids {
                if u == t {
                    continue;
                }
                for j in 0..4 {
                    let mut fb: Vec<u32> =
                        (0..4).filter(|&k| k != j).map(|k| cells.v(u, k)).collect();
                    fb.sort_unstable();
                    if fa == fb {
                        cells.set_n(t, i, pack(u, j));
                    }
                }
            }
        }
    }
}

/// The triangulation of a finished build: drops the dead cells and the
/// duplicates' vertex ids, and maps inputs to vertices.
fn finish(input: Input, built: Built) -> Triangulation {
    let Input {
        pts, ins_input, n, ..
    } = input;
    let Built {
        mut cells,
        holes,
        dups,
    } = built;
    compact(&mut cells, holes);
    let mut input_vert = vec![u32::MAX; n];
    let (pts, vert_input) = if dups.is_empty() {
        for (v, &i) in ins_input.iter().enumerate() {
            input_vert[i as usize] = v as u32;
        }
        (pts.into_iter().map(|s| s.0).collect(), ins_input)
    } else {
        // Number the vertices without the duplicates' ids, keeping their
        // order, and give each duplicate's input the vertex it duplicates.
        const DUP: u32 = u32::MAX;
        let mut id = vec![0u32; pts.len()];
        for &(d, _) in &dups {
            id[d as usize] = DUP;
        }
        let mut kept = 0;
        for x in id.iter_mut() {
            if *x != DUP {
                *x = kept;
                kept += 1;
            }
        }
        for c in cells.iter_mut() {
            for w in c.v.iter_mut() {
                if *w != INFINITE {
                    *w = id[*w as usize];
                }
            }
        }
        let mut vert_input = Vec::with_capacity(kept as usize);
        let mut kept_pts = Vec::with_capacity(kept as usize);
        for (v, s) in pts.iter().enumerate() {
            if id[v] != DUP {
                vert_input.push(ins_input[v]);
                kept_pts.push(s.0);
            }
        }
        for (v, &i) in ins_input.iter().enumerate() {
            if id[v] != DUP {
                input_vert[i as usize] = id[v];
            }
        }
        for &(d, w) in &dups {
            let (i, w) = (ins_input[d as usize], id[w as usize]);
            input_vert[i as usize] = w;
            // The vertex stands for the first occurrence of its point.
            let first = &mut vert_input[w as usize];
            *first = (*first).min(i);
        }
        (kept_pts, vert_input)
    };
    let mut num_finite = 0;
    let mut vert_tet = vec![u32::MAX; pts.len()];
    for (t, c) in cells.iter().enumerate() {
        num_finite += (c.v[3] != INFINITE) as usize;
        for &w in &c.v {
            if w != INFINITE {
                vert_tet[w as usize] = t as u32;
            }
        }
    }
    Triangulation {
        pts,
        vert_input,
        input_vert,
        cells,
        num_finite,
        vert_tet,
        dim: 3,
    }
}

/// Drops the dead cells `holes` by moving live cells from the end into the
/// holes below the final length (only live cells above it move; the rest
/// stay where they are).
fn compact(cells: &mut Vec<Cell>, mut holes: Vec<u32>) {
    holes.sort_unstable();
    let len = cells.len() - holes.len();
    let mut tail_holes = holes.len();
    let mut src = cells.len();
    for &h in &holes {
        let h = h as usize;
        if h >= len {
            break;
        }
        // The last live cell not yet moved.
        loop {
            src -= 1;
            if tail_holes > 0 && holes[tail_holes - 1] as usize == src {
                tail_holes -= 1;
            } else {
                break;
            }
        }
        cells[h] = cells[src];
        for k in 0..4 {
            let p = cells[h].n[k];
            let (n, j) = ((p >> 2) as usize, (p & 3) as usize);
            cells[n].n[j] = pack(h as u32, k);
        }
    }
    cells.truncate(len);
}

#[cfg(test)]
pub(crate) mod tests {
    use super::{
        build_with, prefetch, run_owned, Cell, DelaunayError, Input, Isa, Limits, SplitMix64, Stop,
        FACE,
    };
    use crate::geometry::predicates::{Filtered, StaticFilter};

    #[test]
    fn prefetch_never_faults() {
        // The hint may be given for any index: inside, just past, far past
        // the slice, and on an empty slice.
        let cells = vec![
            Cell {
                v: [0; 4],
                n: [0; 4]
            };
            3
        ];
        for i in [0, 2, 3, 1 << 20, 1 << 40, usize::MAX / 64, usize::MAX] {
            prefetch(&cells, i);
            prefetch::<Cell>(&[], i);
        }
        assert_eq!(cells[2].v, [0; 4]);
    }

    /// An insertion stopped part way through its cavity (here by the tet
    /// limit; in a parallel build by a tet of another thread) is undone:
    /// every live cell is as it was, and the cells it took are free again.
    #[test]
    fn a_stopped_insertion_is_undone() {
        let pts = uniform_points(9, 3000);
        let bbox = crate::geometry::bounding_box(&pts);
        let (order, rounds) = super::brio_order(&pts, &bbox, 1, Isa::Detect);
        let init = super::initial_simplex(&pts, &order).unwrap();
        let input = Input::new(&pts, &order, &rounds, init, None, bbox);
        let filter = StaticFilter::for_box(&bbox.0, &bbox.1);
        let mut undone = 0;
        for end in (100..3000).step_by(97) {
            let (mut b, _) =
                run_owned::<Filtered>(&input, &Limits::DEFAULT, filter, None, end).unwrap();
            let live = |b: &super::Builder<'_, Filtered, super::Owned>| {
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

    #[test]
    fn tet_limit_is_a_typed_error() {
        let mut rng = SplitMix64::new(99);
        let mut unif = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let pts: Vec<[f64; 3]> = (0..2000).map(|_| [unif(), unif(), unif()]).collect();
        // About 13k finite tets plus the hull's: limits below that stop the
        // build at the first tet too many, whether during the first five
        // tets or in the middle of an insertion, without a panic.
        for max in [0, 4, 5, 6, 100, 5000, 12_000] {
            assert_eq!(
                build_with(
                    &pts,
                    Limits {
                        max_cells: max,
                        ..Limits::DEFAULT
                    }
                )
                .err(),
                Some(DelaunayError::TooManyTets(2000)),
                "limit {max}"
            );
        }
        let tri = build_with(
            &pts,
            Limits {
                max_cells: 1 << 20,
                ..Limits::DEFAULT
            },
        )
        .unwrap();
        tri.validate().unwrap();
        assert_eq!(tri.num_vertices(), 2000);
    }

    /// `n` points drawn uniformly in the unit cube (seed `seed`).
    pub(crate) fn uniform_points(seed: u64, n: usize) -> Vec<[f64; 3]> {
        let mut rng = SplitMix64::new(seed);
        let mut unif = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        (0..n).map(|_| [unif(), unif(), unif()]).collect()
    }

    /// The integer grid k × k × k, x fastest.
    pub(crate) fn int_grid(k: usize) -> Vec<[f64; 3]> {
        (0..k * k * k)
            .map(|i| [(i % k) as f64, (i / k % k) as f64, (i / (k * k)) as f64])
            .collect()
    }

    /// The centre and the integer points on the sphere x² + y² + z² = r2
    /// (cospherical: in-sphere tests among the points on the sphere tie).
    pub(crate) fn integer_sphere(r2: i32) -> Vec<[f64; 3]> {
        let r = (r2 as f64).sqrt() as i32 + 1;
        let mut sphere = vec![[0.0; 3]];
        for x in -r..=r {
            for y in -r..=r {
                for z in -r..=r {
                    if x * x + y * y + z * z == r2 {
                        sphere.push([x as f64, y as f64, z as f64]);
                    }
                }
            }
        }
        sphere
    }

    /// The edge table and the rotation link the new tets identically, also
    /// when a cavity outgrows the table part way through an insertion
    /// (small `max_local`) and on cospherical points, where inserting the
    /// centre late makes one cavity of every tet.
    #[test]
    fn table_and_rotation_linking_agree() {
        let uniform = uniform_points(7, 3000);
        let grid = int_grid(8);
        // The 672 integer points with x² + y² + z² = 1154, and the centre.
        let sphere = integer_sphere(1154);
        assert_eq!(sphere.len(), 673);
        for pts in [&uniform, &grid, &sphere] {
            let tets = |max_local| {
                let limits = Limits {
                    max_local,
                    ..Limits::DEFAULT
                };
                let tri = build_with(pts, limits).unwrap();
                tri.validate().unwrap();
                let mut t: Vec<[u32; 4]> = tri
                    .finite_tets_input()
                    .map(|mut t| {
                        t.sort_unstable();
                        t
                    })
                    .collect();
                t.sort_unstable();
                t
            };
            let reference = tets(0);
            assert!(reference.len() > pts.len());
            for max_local in [5, 12, 30, Limits::DEFAULT.max_local] {
                assert!(tets(max_local) == reference, "max_local {max_local}");
            }
        }
    }

    /// The x86-64-v3 copy of the insertion and of the order gives the
    /// baseline's triangulation bit for bit: same cells in the same
    /// slots, same vertex maps, on both kernels, with exact ties, and
    /// through both linkings. (On a CPU without v3 both runs take the
    /// baseline and the test says so.)
    #[test]
    fn instruction_sets_agree() {
        if !crate::delaunay::isa::has_v3() {
            eprintln!("this CPU lacks x86-64-v3: only the baseline copy runs");
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
        let mut unif = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let sphere: Vec<[f64; 3]> = (0..2000)
            .map(|_| {
                let (a, b) = (unif() * std::f64::consts::TAU, unif() * 2.0 - 1.0);
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

    #[test]
    fn face_table_is_even() {
        for (i, f) in FACE.iter().enumerate() {
            let perm = [f[0], f[1], f[2], i];
            let mut inv = 0;
            for a in 0..4 {
                for b in a + 1..4 {
                    if perm[a] > perm[b] {
                        inv += 1;
                    }
                }
            }
            assert_eq!(inv % 2, 0, "face {i}");
        }
    }
}
