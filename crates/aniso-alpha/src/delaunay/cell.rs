//! The tetrahedron structure itself: the 32-byte [`Cell`], the face tables,
//! packed neighbour words, the flags an insertion sets, the cache-prefetch
//! hint and the compaction of a finished build.
//!
//! Nothing here knows about points or predicates: this is the topology
//! that the insertion ([`super::insert`]), the stores ([`super::store`]),
//! the queries and [`super::validate`] share.

/// Faces of a tetrahedron: for local vertex `i`, the other three local
/// indices in an order that makes `(FACE[i][0], FACE[i][1], FACE[i][2], i)`
/// an even permutation of `(0, 1, 2, 3)`. So face `i` of a positively
/// oriented tetrahedron, read in this order, is counter-clockwise seen from
/// vertex `i`: its normal (right-hand rule) points into the tetrahedron.
///
/// This is the one face table of the crate: the triangulation's
/// [`Triangle`](super::Triangle)s, the alpha complex's triangles and the
/// detector's faces all read their vertices through it.
///
/// ```
/// use aniso_alpha::delaunay::{Triangulation, FACE};
/// use aniso_alpha::geometry::predicates::{orient3d, Sign};
/// let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let tri = Triangulation::new(&pts)?;
/// let v = tri.finite_tets().next().unwrap();
/// let p = |k: usize| tri.point(v[k]);
/// for (i, f) in FACE.iter().enumerate() {
///     // Face i, then vertex i: positively oriented.
///     assert_eq!(orient3d(p(f[0]), p(f[1]), p(f[2]), p(i)), Sign::Positive);
/// }
/// # Ok::<(), aniso_alpha::delaunay::DelaunayError>(())
/// ```
pub const FACE: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];

/// For each face index, the other three (ascending).
pub(crate) const OTHER: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];

/// The six edges of a tetrahedron as pairs of local indices.
pub(crate) const EDGES: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

/// The vertices of a cell just allocated, before it is written.
pub(crate) const DEAD: u32 = u32::MAX - 1;
/// An adjacency slot not yet linked.
pub(crate) const UNSET: u32 = u32::MAX;
/// Flag on a tet's `v[0]`: the tet is in the current conflict region.
/// Vertex ids stay below 2^31 (see [`super::MAX_POINTS`]), and `v[0]` and
/// `v[1]` are never the infinite vertex (always at index 3), so the top bit
/// of either is free; flags live only during one insertion.
pub(crate) const IN_CONFLICT: u32 = 1 << 31;
/// Flag on a tet's `v[1]`: the tet was tested and is not in conflict.
pub(crate) const CLEAR: u32 = 1 << 31;

/// Tet ids are packed with a 2-bit face index into a `u32`, so there can be
/// at most 2^30 tetrahedra (about 150 million uniform points). An insertion
/// that would need more stops the build with
/// [`DelaunayError::TooManyTets`](super::DelaunayError::TooManyTets).
pub(crate) const MAX_CELLS: usize = 1 << 30;

/// One tetrahedron: vertex ids and packed neighbours (`4 * tet + mirror`),
/// interleaved so that visiting a tet touches one 32-byte block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub(crate) struct Cell {
    pub(crate) v: [u32; 4],
    pub(crate) n: [u32; 4],
}

/// A new cell's contents: vertices not yet written, neighbours not linked.
pub(crate) const FRESH: Cell = Cell {
    v: [DEAD; 4],
    n: [UNSET; 4],
};

/// Tet `t` and a face index `i` in one word: `4 * t + i`.
#[inline(always)]
pub(crate) fn pack(t: u32, i: usize) -> u32 {
    (t << 2) | i as u32
}

/// The tet and face index of a packed word ([`pack`]).
#[inline(always)]
pub(crate) fn unpack(p: u32) -> (u32, usize) {
    (p >> 2, (p & 3) as usize)
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

/// Links the faces of a few tets by brute force (the first five of a
/// build): each face of each tet is matched with the tet holding the same
/// three vertices.
pub(crate) fn link_by_faces(cells: &mut [Cell], ids: &[u32]) {
    let face = |c: &Cell, i: usize| {
        let mut f = FACE[i].map(|k| c.v[k]);
        f.sort_unstable();
        f
    };
    for &t in ids {
        for i in 0..4 {
            let fa = face(&cells[t as usize], i);
            for &u in ids {
                if u == t {
                    continue;
                }
                for j in 0..4 {
                    if fa == face(&cells[u as usize], j) {
                        cells[t as usize].n[i] = pack(u, j);
                    }
                }
            }
        }
    }
}

/// Drops the dead cells `holes` by moving live cells from the end into the
/// holes below the final length (only live cells above it move; the rest
/// stay where they are), rewriting the neighbour words that point at a
/// moved cell.
pub(crate) fn compact(cells: &mut Vec<Cell>, mut holes: Vec<u32>) {
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
            let (n, j) = unpack(cells[h].n[k]);
            cells[n as usize].n[j] = pack(h as u32, k);
        }
    }
    cells.truncate(len);
}

#[cfg(test)]
mod tests {
    use super::super::INFINITE;
    use super::*;

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
            let mut sorted = *f;
            sorted.sort_unstable();
            assert_eq!(sorted, OTHER[i]);
        }
    }

    #[test]
    fn pack_round_trips() {
        for t in [0, 1, 12345, (MAX_CELLS - 1) as u32] {
            for i in 0..4 {
                assert_eq!(unpack(pack(t, i)), (t, i));
            }
        }
    }

    /// Compaction keeps every live cell, drops the holes, and rewrites the
    /// neighbour words of the cells that moved: a ring of cells linked to
    /// each other survives with its links intact.
    #[test]
    fn compaction_moves_cells_and_their_links() {
        // Cells 0..10, holes everywhere but the ring 1, 4, 7, 9: each ring
        // cell's face 0 is linked to the next one's face 1, and its face 2
        // to the face 3 of the cell two along (and back).
        let ring = [1u32, 4, 7, 9];
        let mut cells = vec![FRESH; 10];
        for (k, &t) in ring.iter().enumerate() {
            let next = ring[(k + 1) % ring.len()];
            let prev = ring[(k + ring.len() - 1) % ring.len()];
            cells[t as usize].v = [t, t + 100, t + 200, INFINITE];
            cells[t as usize].n[0] = pack(next, 1);
            cells[t as usize].n[1] = pack(prev, 0);
            let across = ring[(k + 2) % ring.len()];
            cells[t as usize].n[2] = pack(across, 3);
            cells[t as usize].n[3] = pack(across, 2);
        }
        let holes: Vec<u32> = (0..10).filter(|t| !ring.contains(t)).collect();
        compact(&mut cells, holes);
        assert_eq!(cells.len(), 4);
        let mut seen: Vec<u32> = cells.iter().map(|c| c.v[0]).collect();
        seen.sort_unstable();
        assert_eq!(seen, ring);
        for (t, c) in cells.iter().enumerate() {
            for k in 0..4 {
                let (n, j) = unpack(c.n[k]);
                assert_eq!(cells[n as usize].n[j], pack(t as u32, k));
            }
            let (next, _) = unpack(c.n[0]);
            let i = ring.iter().position(|&r| r == c.v[0]).unwrap();
            assert_eq!(cells[next as usize].v[0], ring[(i + 1) % 4]);
        }
    }
}
