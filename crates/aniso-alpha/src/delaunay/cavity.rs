//! The cavity of one insertion: the conflict tets found by the search, the
//! new tets built on its boundary, and how the new tets are linked to each
//! other: through a table of directed edges between local vertex numbers,
//! filed while the search runs, or, for cavities too large for the table,
//! by turning around the boundary edges through the conflict tets.
//!
//! The search itself (which tets are in conflict) belongs to the insertion
//! ([`super::insert`]); this module only keeps its scratch and links.

use super::cell::{pack, unpack, FACE, IN_CONFLICT, OTHER, UNSET};
use super::store::Store;

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
pub(crate) const MAX_LOCAL: usize = 64;
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

/// The scratch of one insertion's cavity, reused from one insertion to the
/// next.
pub(crate) struct Cavity {
    /// The conflict tets found so far, each packed with the face through
    /// which it was found (the search's queue).
    pub(crate) conflicts: Vec<u32>,
    /// Tets marked CLEAR during the current insertion.
    pub(crate) cleared: Vec<u32>,
    /// New tets of the current insertion: each packed with the face index
    /// of its outer neighbour, and the conflict tet it replaces.
    pub(crate) new_tets: Vec<(u32, u32)>,
    /// Local number of each vertex on the current cavity's boundary
    /// ([`NO_LOCAL`] otherwise); the last slot stands for the infinite
    /// vertex. One byte per vertex keeps this mostly in cache.
    loc: Vec<u8>,
    /// Scratch of [`Cavity::file_faces`] and [`Cavity::link_filed`].
    table: Box<EdgeTable>,
    /// The bound on local numbers ([`MAX_LOCAL`]; lower in tests, 0 to
    /// link every cavity by rotation).
    max_local: usize,
    /// Whether the current insertion's new tets are being filed in
    /// `table` (until the cavity proves too large for it).
    pub(crate) filing: bool,
}

impl Cavity {
    /// The scratch of a build of `num_points` points whose cavities are
    /// linked by table up to `max_local` boundary vertices.
    pub(crate) fn new(num_points: usize, max_local: usize) -> Cavity {
        Cavity {
            conflicts: Vec::new(),
            cleared: Vec::new(),
            new_tets: Vec::new(),
            loc: vec![NO_LOCAL; num_points + 1],
            table: Box::new(EdgeTable {
                nloc: 0,
                bverts: [0; MAX_LOCAL],
                faces: [0; MAX_LOCAL * MAX_LOCAL],
                local: [[0; 4]; FACES],
            }),
            max_local: max_local.min(MAX_LOCAL),
            filing: max_local > 0,
        }
    }

    /// Forgets the current insertion's local numbers and starts filing
    /// again for the next one (after it was linked, or undone).
    #[inline(always)]
    pub(crate) fn reset_linking(&mut self) {
        self.forget_local_numbers();
        self.filing = self.max_local > 0;
    }

    /// Files the three inner faces of new tet `nt` (built on facet `f` of
    /// a conflict tet whose vertices, flags cleared, are `v`) in the edge
    /// table; on a cavity too large for it, stops filing for this
    /// insertion. Called before `nt` joins `new_tets`.
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
    /// its partner is later read at (b, a) ([`Cavity::link_filed`]).
    /// Unlike a rotation around the edge, the lookups are independent of
    /// each other, so their latencies overlap, and the vertices are
    /// already loaded.
    #[inline(always)]
    pub(crate) fn file_faces(&mut self, nt: u32, f: usize, v: &[u32; 4]) {
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

    /// Links the new tets of the insertion of vertex `vid` to each other:
    /// through the edge table if every one was filed, else by rotation;
    /// then gets ready for the next insertion.
    #[inline(always)]
    pub(crate) fn link<S: Store>(&mut self, store: &mut S, vid: u32) {
        if self.filing {
            self.link_filed(store);
        } else {
            self.forget_local_numbers();
            // Point slot f of each conflict tet with a boundary facet f at
            // its new tet (c is about to die), which is how the rotation
            // recognises boundary facets, and mark the new tets' inner
            // faces unlinked.
            for &(packed, c) in &self.new_tets {
                let (nt, f) = unpack(packed);
                for g in OTHER[f] {
                    store.set_n(nt, g, UNSET);
                }
                store.set_n(c, f, packed);
            }
            self.link_by_rotation(store, vid);
        }
        self.filing = self.max_local > 0;
    }

    /// Links the new tets, all filed by [`Cavity::file_faces`], to each
    /// other and forgets the local numbers.
    #[inline(always)]
    fn link_filed<S: Store>(&mut self, store: &mut S) {
        let t = &mut *self.table;
        for (i, &(packed, _)) in self.new_tets.iter().enumerate() {
            let (nt, f) = unpack(packed);
            let lv = t.local[i & (FACES - 1)];
            store.update(nt, |c| {
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
    fn link_by_rotation<S: Store>(&self, cells: &mut S, vid: u32) {
        // Link the new tets to each other. The face of new tet nt (built
        // on facet f of conflict tet c) opposite g != f holds q and an edge
        // (a, b) of the cavity boundary. Its neighbour is the new tet of
        // the next boundary facet met when turning around (a, b) from c
        // across its face g, through conflict tets only: every cell
        // visited is part of this insertion and already in cache.
        for &(packed, c) in &self.new_tets {
            let (nt, f) = unpack(packed);
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

#[cfg(test)]
mod tests {
    use super::super::build::build_with;
    use super::super::insert::Limits;
    use super::super::test_points::{int_grid, integer_sphere, uniform_points};
    use super::MAX_LOCAL;

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
            for max_local in [5, 12, 30, MAX_LOCAL] {
                assert!(tets(max_local) == reference, "max_local {max_local}");
            }
        }
    }
}
