//! Alpha-shape intervals, Euclidean and anisotropic alpha-shapes
//! (docs/method.md §1–§2).
//!
//! [`AlphaComplex`] takes a Delaunay [`Triangulation`] and computes, for
//! every finite edge and triangle σ, the interval `[α_min(σ), α_max(σ)]` of
//! radii of the empty open balls whose boundary passes through σ's vertices
//! (the values CGAL's `Alpha_shape_3` in GENERAL mode and GUDHI report), and
//! the circumradius of every tetrahedron. The α-shape of the paper,
//! `F_α = {σ : α_min(σ) ≤ α ≤ α_max(σ)}` (a *closed* interval: on
//! degenerate sets many simplices have `α_min = α_max`), is then a scan.
//!
//! # Definitions
//!
//! * `α_max(σ)`: the largest circumradius of σ's incident tetrahedra, `+∞`
//!   when σ is on the convex hull (incident to an infinite tetrahedron).
//! * `α_min(σ)`: `ρ(σ)` (half the edge length; the triangle's circumradius)
//!   if σ is *Gabriel*, i.e. no vertex of a simplex incident to σ lies
//!   strictly inside σ's smallest circumsphere (decided exactly, see
//!   [`exact`]); otherwise the smallest `α_min` of the simplices one
//!   dimension up (for a triangle: the smallest circumradius of its finite
//!   incident tets; for an edge: the smallest `α_min` of its triangles).
//! * Rounding: a Gabriel simplex's `ρ(σ)` is at most every `α_min` one
//!   dimension up, and equal when a vertex lies on σ's smallest
//!   circumsphere, as on grids. The two are computed by different formulas
//!   and can round one unit apart, so the stored `α_min` of a Gabriel
//!   simplex is the minimum of the two. Every interval is then ordered,
//!   and an edge's contains each of its triangles', exactly.
//!
//! # Algorithm and storage
//!
//! Everything is flat (`Vec`s indexed by `u32`), linear in the number of
//! simplices, without hashing:
//!
//! 1. the finite cells are bucketed by their smallest vertex id (counting
//!    sort). Vertex ids follow the engine's spatially coherent insertion
//!    order while cell ids do not, so the triangle pass (4) visits the
//!    cells in this order (gathering each block of cells first) and its
//!    accesses to points and edges stay local;
//! 2. edges: every finite tet (read in id order) emits its 6 edges
//!    `(a, b)`, `a < b`, bucketed by `a` (counting sort); each bucket is
//!    deduplicated with a per-vertex stamp. The edges are numbered grouped
//!    by `a`, and the per-vertex offsets (CSR) give an `O(degree)` lookup;
//! 3. every cell's circumradius (relative to a vertex; recomputed exactly
//!    and rounded once for slivers, see [`exact`]) and, for each of its
//!    faces, whether its opposite vertex is strictly inside the face's
//!    diametral sphere (exact);
//! 4. a triangle is emitted by the later of its two cells in the order of
//!    (1) (or its finite cell on the hull): Gabriel iff neither apex is
//!    inside. It then pushes its values to its three edges (max of
//!    `α_max`, min of the cofaces' `α_min`, and the edge's own Gabriel test
//!    against the triangle's third vertex: the third vertices of an edge's
//!    triangles are exactly the vertices of its incident tets);
//! 5. each edge's `α_min` is its half length if Gabriel, else the minimum
//!    over its triangles.
//!
//! With the `parallel` feature (default), steps 1 and 3 overlap step 2,
//! and steps 3 and 4 run on rayon's threads: cells are independent;
//! triangles are computed in parallel per block of cells, and one thread
//! applies a block's edge updates, in order, while the others compute the
//! next block's triangles. Ids, order and every bit of the result are the
//! same for any number of threads (tested).
//!
//! Memory: the complex adds about 8 bytes per cell, 20 per triangle and 24
//! per edge to the triangulation (≈ 0.5 GB for 1M uniform points), plus
//! transient buckets of 4 bytes per (tet, edge) incidence during step 2
//! and 4 bytes per cell (position and mask) during steps 3–4.
//!
//! The struct owns the triangulation (get it back with
//! [`AlphaComplex::into_triangulation`]).
//!
//! ```
//! use aniso_alpha::alpha::AlphaComplex;
//! let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
//! let ac = AlphaComplex::from_points(&pts)?;
//! assert_eq!((ac.num_edges(), ac.num_triangles()), (6, 4));
//! // The tet's circumradius is √3/2 ≈ 0.866. The hull triangle (1, 2, 3)
//! // (circumradius √(2/3)) is not Gabriel: the origin is inside its
//! // diametral sphere, so it appears only with the tet's ball.
//! let t = ac.triangles().find(|t| t.vertices == [1, 2, 3]).unwrap();
//! assert!((t.alpha_min - 3f64.sqrt() / 2.0).abs() < 1e-15);
//! assert_eq!(t.alpha_max, f64::INFINITY);
//! // The three triangles through the origin are Gabriel, radius √2/2.
//! assert_eq!(ac.triangles_at(0.85).count(), 3);
//! assert_eq!(ac.regular_surface(0.85).len(), 0);
//! assert_eq!(ac.regular_surface(0.9).len(), 4);
//! # Ok::<(), aniso_alpha::delaunay::DelaunayError>(())
//! ```

pub mod exact;

use crate::delaunay::{DelaunayError, Triangulation, VertexId, EDGES as PAIRS, FACE, INFINITE};
use crate::geometry::{transform_points, Point3};
use crate::unionfind::UnionFind;

/// `Q = diag(e)·R` from a rotation and an elongation (the one definition
/// is [`crate::geometry::q_matrix`]).
pub use crate::geometry::q_matrix;

/// A cell's vertices and `(neighbour, mirror index)` per face.
type GatheredCell = ([u32; 4], [(u32, usize); 4]);

/// An edge of the triangulation with its alpha interval, vertices given as
/// input indices (ascending).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeInterval {
    /// Input indices of the endpoints, ascending (the smallest input index
    /// of a duplicated point).
    pub vertices: [u32; 2],
    /// `α_min` (see the [module docs](self)).
    pub alpha_min: f64,
    /// `α_max`, `+∞` on the convex hull.
    pub alpha_max: f64,
}

/// A triangle of the triangulation with its alpha interval, vertices given
/// as input indices (ascending).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleInterval {
    /// Input indices of the corners, ascending.
    pub vertices: [u32; 3],
    /// `α_min` (see the [module docs](self)).
    pub alpha_min: f64,
    /// `α_max`, `+∞` on the convex hull.
    pub alpha_max: f64,
}

/// The alpha intervals of every edge and triangle of a 3D Delaunay
/// triangulation, and the circumradii of its tetrahedra.
///
/// Ids: edges are numbered `0..num_edges()` grouped by their smaller
/// vertex id, triangles `0..num_triangles()`; cells (tets) use the
/// triangulation's ids. Vertex ids are the triangulation's (insertion
/// order); every query that says *input* maps them to input indices.
///
/// ```
/// use aniso_alpha::alpha::AlphaComplex;
/// // The unit cube's corners: 6 tets, all with circumradius √3/2.
/// let pts: Vec<[f64; 3]> = (0..8)
///     .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
///     .collect();
/// let ac = AlphaComplex::from_points(&pts)?;
/// // The 12 square edges are Gabriel (radius 1/2).
/// assert_eq!(ac.edges().filter(|e| e.alpha_min == 0.5).count(), 12);
/// // The solid appears at once, at α = √3/2.
/// let r = ac.optimal_alpha().unwrap();
/// assert!((r - 3f64.sqrt() / 2.0).abs() < 1e-15);
/// assert_eq!(ac.regular_surface(r).len(), 12);
/// # Ok::<(), aniso_alpha::delaunay::DelaunayError>(())
/// ```
#[derive(Clone, Debug)]
pub struct AlphaComplex {
    tri: Triangulation,
    /// Cell id -> circumradius (`+∞` for infinite cells).
    cell_r: Vec<f64>,
    /// Edge id -> vertex ids `(a, b)`, `a < b`, grouped by `a` (apart from
    /// the intervals: lookups read the one while updates write the other).
    edge_v: Vec<[u32; 2]>,
    /// Edge id -> `[α_min, α_max]`.
    edge_iv: Vec<[f64; 2]>,
    /// Vertex id `a` -> first edge `(a, _)`; `num_vertices + 1` entries.
    edge_start: Vec<u32>,
    /// Triangle id -> owning face, packed `4 * cell + local face`, where
    /// `cell` (always finite) is the one that emitted the triangle.
    tri_face: Vec<u32>,
    /// Triangle id -> `[α_min, α_max]`.
    tri_iv: Vec<[f64; 2]>,
}

impl AlphaComplex {
    /// Computes the intervals of `tri` (which the complex then owns).
    ///
    /// When the triangulation's dimension is below 3 there are no
    /// tetrahedra, and (like CGAL's `Alpha_shape_3`) no edges or triangles
    /// are reported.
    pub fn new(tri: Triangulation) -> Self {
        if tri.dimension() < 3 || tri.num_finite_tets() == 0 {
            let nv = tri.num_vertices();
            return AlphaComplex {
                tri,
                cell_r: Vec::new(),
                edge_v: Vec::new(),
                edge_iv: Vec::new(),
                edge_start: vec![0; nv + 1],
                tri_face: Vec::new(),
                tri_iv: Vec::new(),
            };
        }
        // Steps 1 and 3 (order, then the cells) and step 2 (edges) are
        // independent: with the `parallel` feature they overlap (the edge
        // numbering is sequential and memory-bound).
        let cells = || {
            let order = cells_by_min_vertex(&tri);
            // Per cell: its position in `order` and its Gabriel mask, packed
            // (`pos << 4 | mask`), `u32::MAX` for infinite cells.
            let mut posmask = vec![u32::MAX; tri.num_tets()];
            for (k, &t) in order.iter().enumerate() {
                posmask[t as usize] = (k as u32) << 4;
            }
            let mut cell_r = vec![f64::INFINITY; tri.num_tets()];
            cell_pass(&tri, &mut cell_r, &mut posmask);
            (order, posmask, cell_r)
        };
        let ((order, posmask, cell_r), (edge_v, edge_start, edge_iv)) =
            join(cells, || number_edges(&tri));
        let mut ac = AlphaComplex {
            tri,
            cell_r,
            edge_iv,
            edge_v,
            edge_start,
            tri_face: Vec::new(),
            tri_iv: Vec::new(),
        };
        ac.compute_triangles_edges(&order, &posmask);
        ac
    }

    /// Triangulates `points` and computes the intervals.
    ///
    /// # Errors
    /// As [`Triangulation::new`].
    pub fn from_points(points: &[[f64; 3]]) -> Result<Self, DelaunayError> {
        Ok(Self::new(Triangulation::new(points)?))
    }

    /// The anisotropic complex of docs/method.md §2: transforms every point by the
    /// matrix `Q` given by its rows `q_rows` (`Q = diag(e)·R`, see
    /// [`q_matrix`]), triangulates `Q·P` and computes its intervals. Since
    /// `d_Q(p, q) = |Qp − Qq|`, the result's `F_α` is the anisotropic
    /// `F_{α,Q}(P)`; every query reports indices into `points` (the
    /// triangulation's [`Triangulation::points`] are the transformed ones).
    ///
    /// Each coordinate is computed as `(Q_i1·x + Q_i2·y) + Q_i3·z`, each
    /// operation rounded to double in that order, without fused
    /// multiply-add (numpy's and the project's convention, reproducible bit
    /// for bit). Points that coincide after the transform (exact
    /// duplicates, or distinct points collapsed by rounding) are merged
    /// like duplicates: queries report the smallest input index.
    ///
    /// ```
    /// use aniso_alpha::alpha::{q_matrix, AlphaComplex};
    /// let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    /// let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// // E = (1, 1, 1/8): distances along z count 8 times less.
    /// let q = q_matrix(&id, &[1.0, 1.0, 0.125]);
    /// let ac = AlphaComplex::anisotropic(&pts, &q)?;
    /// assert_eq!(ac.triangulation().point(ac.triangulation().vertex_of_input(3)), &[0.0, 0.0, 0.125]);
    /// let e = ac.edges().find(|e| e.vertices == [0, 3]).unwrap();
    /// assert_eq!(e.alpha_min, 0.0625);
    /// # Ok::<(), aniso_alpha::delaunay::DelaunayError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Triangulation::new`] (a non-finite coordinate after the
    /// transform is reported at its input index).
    pub fn anisotropic(points: &[[f64; 3]], q_rows: &[[f64; 3]; 3]) -> Result<Self, DelaunayError> {
        Self::from_points(&transform_points(q_rows, points))
    }

    /// The triangulation the intervals refer to.
    pub fn triangulation(&self) -> &Triangulation {
        &self.tri
    }

    /// Gives the triangulation back.
    pub fn into_triangulation(self) -> Triangulation {
        self.tri
    }

    /// Number of finite edges.
    pub fn num_edges(&self) -> usize {
        self.edge_v.len()
    }

    /// Number of finite triangles.
    pub fn num_triangles(&self) -> usize {
        self.tri_face.len()
    }

    /// Vertex ids `(a, b)`, `a < b`, of edge `e` (ids of the
    /// triangulation's vertices, not input indices: see
    /// [`Self::input_index`]).
    #[inline]
    pub fn edge_vertices(&self, e: usize) -> [VertexId; 2] {
        self.edge_v[e].map(VertexId)
    }

    /// The smallest input index of vertex `v`.
    #[inline]
    pub fn input_index(&self, v: VertexId) -> u32 {
        self.tri.input_index(v.0)
    }

    /// `(α_min, α_max)` of edge `e`.
    #[inline]
    pub fn edge_interval(&self, e: usize) -> (f64, f64) {
        (self.edge_iv[e][0], self.edge_iv[e][1])
    }

    /// The id of the edge between vertex ids `a` and `b`, if it exists.
    pub fn find_edge(&self, a: VertexId, b: VertexId) -> Option<usize> {
        let (a, b) = (a.0.min(b.0), a.0.max(b.0));
        let s = *self.edge_start.get(a as usize)? as usize;
        let e = *self.edge_start.get(a as usize + 1)? as usize;
        self.edge_v[s..e]
            .iter()
            .position(|x| x[1] == b)
            .map(|k| s + k)
    }

    /// Vertex ids of triangle `f`, ordered so that its normal (right-hand
    /// rule) points into the first of its two cells ([`Self::triangle_cells`]).
    #[inline]
    pub fn triangle_vertices(&self, f: usize) -> [VertexId; 3] {
        self.triangle_vertex_ids(f).map(VertexId)
    }

    /// [`Self::triangle_vertices`] as plain ids.
    #[inline]
    fn triangle_vertex_ids(&self, f: usize) -> [u32; 3] {
        let p = self.tri_face[f];
        let (t, i) = (p >> 2, (p & 3) as usize);
        let v = self.tri.tet(t);
        let fi = FACE[i];
        [v[fi[0]], v[fi[1]], v[fi[2]]]
    }

    /// The two cells on the sides of triangle `f`; the first is always
    /// finite, the second is infinite for a hull triangle.
    #[inline]
    pub fn triangle_cells(&self, f: usize) -> [u32; 2] {
        let p = self.tri_face[f];
        let (t, i) = (p >> 2, (p & 3) as usize);
        [t, self.tri.neighbor(t, i).0]
    }

    /// `(α_min, α_max)` of triangle `f`.
    #[inline]
    pub fn triangle_interval(&self, f: usize) -> (f64, f64) {
        (self.tri_iv[f][0], self.tri_iv[f][1])
    }

    /// Circumradius of cell `t` (`+∞` for an infinite cell).
    #[inline]
    pub fn tet_radius(&self, t: u32) -> f64 {
        self.cell_r[t as usize]
    }

    /// Circumradii of all cells, indexed by cell id (`+∞` for infinite
    /// cells); empty when the dimension is below 3.
    pub fn tet_radii(&self) -> &[f64] {
        &self.cell_r
    }

    /// `[α_min, α_max]` of every triangle, indexed by triangle id.
    pub fn triangle_intervals(&self) -> &[[f64; 2]] {
        &self.tri_iv
    }

    fn input3(&self, v: [u32; 3]) -> [u32; 3] {
        let mut w = v.map(|x| self.tri.input_index(x));
        w.sort_unstable();
        w
    }

    /// Every edge with its interval, vertices as ascending input indices.
    pub fn edges(&self) -> impl Iterator<Item = EdgeInterval> + '_ {
        (0..self.num_edges()).map(move |e| {
            let [a, b] = self.edge_v[e].map(|x| self.tri.input_index(x));
            EdgeInterval {
                vertices: if a < b { [a, b] } else { [b, a] },
                alpha_min: self.edge_iv[e][0],
                alpha_max: self.edge_iv[e][1],
            }
        })
    }

    /// Every triangle with its interval, vertices as ascending input
    /// indices.
    pub fn triangles(&self) -> impl Iterator<Item = TriangleInterval> + '_ {
        (0..self.num_triangles()).map(move |f| TriangleInterval {
            vertices: self.input3(self.triangle_vertex_ids(f)),
            alpha_min: self.tri_iv[f][0],
            alpha_max: self.tri_iv[f][1],
        })
    }

    /// Ids of the edges of `F_{1,α}`: `α_min ≤ α ≤ α_max`.
    pub fn edge_ids_at(&self, alpha: f64) -> impl Iterator<Item = usize> + '_ {
        (0..self.num_edges())
            .filter(move |&e| self.edge_iv[e][0] <= alpha && alpha <= self.edge_iv[e][1])
    }

    /// Ids of the triangles of `F_{2,α}`: `α_min ≤ α ≤ α_max`.
    pub fn triangle_ids_at(&self, alpha: f64) -> impl Iterator<Item = usize> + '_ {
        (0..self.num_triangles())
            .filter(move |&f| self.tri_iv[f][0] <= alpha && alpha <= self.tri_iv[f][1])
    }

    /// `F_{1,α}` as ascending input-index pairs.
    pub fn edges_at(&self, alpha: f64) -> impl Iterator<Item = [u32; 2]> + '_ {
        self.edge_ids_at(alpha).map(move |e| {
            let [a, b] = self.edge_v[e].map(|x| self.tri.input_index(x));
            if a < b {
                [a, b]
            } else {
                [b, a]
            }
        })
    }

    /// `F_{2,α}` as ascending input-index triples.
    pub fn triangles_at(&self, alpha: f64) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.triangle_ids_at(alpha)
            .map(move |f| self.input3(self.triangle_vertex_ids(f)))
    }

    /// The α spectrum: every distinct finite critical value, ascending —
    /// the `α_min` and finite `α_max` of all edges and triangles and the
    /// circumradii of all finite tetrahedra (the values at which the
    /// α-complex or `F_α` changes).
    pub fn spectrum(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self
            .edge_iv
            .iter()
            .chain(&self.tri_iv)
            .flatten()
            .chain(&self.cell_r)
            .copied()
            .filter(|x| x.is_finite())
            .collect();
        v.sort_unstable_by(f64::total_cmp);
        v.dedup();
        v
    }

    /// The boundary of the α-complex's solid part as an oriented triangle
    /// mesh (input indices): the *regular* triangles at `α`, those with
    /// exactly one side a finite tet of circumradius ≤ α (the other side
    /// is a larger tet or outside the hull). Each is oriented so that its
    /// normal (right-hand rule, `(b − a) × (c − a)`) points away from that
    /// interior tet, like the surfaces CGAL and Open3D produce. Singular
    /// triangles (in `F_α` with no solid on either side) are not included;
    /// see [`Self::triangles_at`].
    pub fn regular_surface(&self, alpha: f64) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        for f in 0..self.num_triangles() {
            let [lo, hi] = self.tri_iv[f];
            if !(lo <= alpha && alpha < hi) {
                continue;
            }
            let [t, n] = self.triangle_cells(f);
            let in_t = self.cell_r[t as usize] <= alpha;
            let in_n = self.cell_r[n as usize] <= alpha;
            if in_t == in_n {
                continue;
            }
            let [a, b, c] = self.triangle_vertex_ids(f).map(|x| self.tri.input_index(x));
            // The normal of (a, b, c) points into t.
            out.push(if in_t { [a, c, b] } else { [a, b, c] });
        }
        out
    }

    /// The smallest α at which the α-complex is one solid holding every
    /// point, or `None` when there are no tetrahedra.
    ///
    /// Precisely: the smallest α such that the finite tetrahedra of
    /// circumradius ≤ α (a) have every vertex among their corners and (b)
    /// form a single component when two tets sharing a triangle are joined.
    /// This is CGAL's `find_optimal_alpha(1)` reading of "one solid
    /// component containing all the points". It is always at most the
    /// largest circumradius (at that value every finite tet is in).
    ///
    /// Computed by a union-find over the tets sorted by radius, checking
    /// the two conditions after each group of equal radii.
    pub fn optimal_alpha(&self) -> Option<f64> {
        let nf = self.tri.num_finite_tets();
        if nf == 0 || self.cell_r.is_empty() {
            return None;
        }
        let mut order: Vec<u32> = (0..self.cell_r.len() as u32)
            .filter(|&t| !self.tri.is_infinite(t))
            .collect();
        order
            .sort_unstable_by(|&a, &b| self.cell_r[a as usize].total_cmp(&self.cell_r[b as usize]));
        let mut uf = UnionFind::new(self.cell_r.len());
        let mut added = vec![false; self.cell_r.len()];
        let mut covered = vec![false; self.tri.num_vertices()];
        let mut n_covered = 0usize;
        let mut components = 0usize;
        let nv = self.tri.num_vertices();
        let mut k = 0;
        while k < order.len() {
            let r = self.cell_r[order[k] as usize];
            while k < order.len() && self.cell_r[order[k] as usize] == r {
                let t = order[k];
                k += 1;
                added[t as usize] = true;
                components += 1;
                for &v in &self.tri.tet(t) {
                    if !covered[v as usize] {
                        covered[v as usize] = true;
                        n_covered += 1;
                    }
                }
                for i in 0..4 {
                    let (n, _) = self.tri.neighbor(t, i);
                    if added[n as usize] && uf.union(t, n) {
                        components -= 1;
                    }
                }
            }
            if components == 1 && n_covered == nv {
                return Some(r);
            }
        }
        // Unreachable for a valid triangulation (all finite tets form one
        // face-connected solid), kept total.
        order.last().map(|&t| self.cell_r[t as usize])
    }

    /// Steps 4 and 5 of the algorithm (module docs), after [`cell_pass`]
    /// has stored every cell's circumradius and Gabriel mask. The finite
    /// cells are visited in `order`; a triangle is created by the later of
    /// its two cells in that order (or by its finite cell on the hull), and
    /// pushes its interval to its three edges.
    ///
    /// The work goes by blocks of cells. Within a block, the per-triangle
    /// part (intervals, edge lookups, the edges' Gabriel tests against the
    /// third vertex) only reads shared data and runs in parallel with the
    /// `parallel` feature; the block's triangles are then stored and its
    /// edge updates applied in order on one thread, overlapping the next
    /// block's triangle part, so the result is identical for any number
    /// of threads. (Edge vertex ids and intervals are separate arrays so
    /// that the two can overlap.)
    #[inline(never)]
    fn compute_triangles_edges(&mut self, order: &[u32], posmask: &[u32]) {
        let nt = self.tri.num_triangles();
        let mut tri_face = Vec::with_capacity(nt);
        let mut tri_iv = Vec::with_capacity(nt);
        // During the pass, an edge's `iv` holds [min of its triangles'
        // α_min, max of their α_max], with the sign bit of the first set
        // once a third vertex is found inside its diametral ball.
        const BLOCK: usize = 1 << 14;
        const SUB: usize = 1024;
        let ctx = TriangleCtx {
            tri: &self.tri,
            cell_r: &self.cell_r,
            posmask,
            edge_v: &self.edge_v,
            edge_start: &self.edge_start,
        };
        let edge_iv = &mut self.edge_iv;
        // The triangles of a block, in visiting order.
        let block_triangles = |b: usize, block: &[u32]| -> Vec<Vec<TriangleOut>> {
            let base = b * BLOCK;
            #[cfg(feature = "parallel")]
            {
                use rayon::prelude::*;
                block
                    .par_chunks(SUB)
                    .enumerate()
                    .map(|(k, sub)| ctx.triangles_of(sub, base + k * SUB))
                    .collect()
            }
            #[cfg(not(feature = "parallel"))]
            block
                .chunks(SUB)
                .enumerate()
                .map(|(k, sub)| ctx.triangles_of(sub, base + k * SUB))
                .collect()
        };
        // Stores a block's triangles and applies its edge updates, in order.
        let mut apply = |parts: Vec<Vec<TriangleOut>>| {
            for out in parts.iter().flatten() {
                tri_face.push(out.face);
                tri_iv.push(out.iv);
                for k in 0..3 {
                    update_edge(&mut edge_iv[out.edges[k] as usize], out, k);
                }
            }
        };
        // Pipelined: one thread applies block b while the others compute
        // the triangles of block b + 1 (with the `parallel` feature).
        let mut pending: Option<Vec<Vec<TriangleOut>>> = None;
        for (b, block) in order.chunks(BLOCK).enumerate() {
            let (parts, ()) = join(
                || block_triangles(b, block),
                || {
                    if let Some(p) = pending.take() {
                        apply(p);
                    }
                },
            );
            pending = Some(parts);
        }
        if let Some(p) = pending.take() {
            apply(p);
        }
        let pts = self.tri.points();
        for (&[a, b], slot) in self.edge_v.iter().zip(self.edge_iv.iter_mut()) {
            if slot[0].is_sign_negative() {
                slot[0] = -slot[0];
            } else {
                // Half the length is at most each triangle's α_min (equal
                // when a third vertex is on the diametral sphere); the min
                // keeps that after rounding, and with it the edge's
                // interval containing each of its triangles'.
                let (p, q) = (&pts[a as usize], &pts[b as usize]);
                let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                let half = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                slot[0] = half.min(slot[0]);
            }
        }
        self.tri_face = tri_face;
        self.tri_iv = tri_iv;
    }
}

/// Pushes a triangle's interval and Gabriel refutation of its edge `k` to
/// the edge's `iv`, which keeps [min of α_min, max of α_max] with the sign
/// bit of the first set once refuted.
#[inline(always)]
fn update_edge(slot: &mut [f64; 2], out: &TriangleOut, k: usize) {
    if out.iv[1] > slot[1] {
        slot[1] = out.iv[1];
    }
    let m = slot[0].abs().min(out.iv[0]);
    let refuted = (out.refuted >> k) & 1 == 1;
    slot[0] = if refuted || slot[0].is_sign_negative() {
        -m
    } else {
        m
    };
}

/// Read-only data of the triangle pass.
struct TriangleCtx<'a> {
    tri: &'a Triangulation,
    cell_r: &'a [f64],
    posmask: &'a [u32],
    edge_v: &'a [[u32; 2]],
    edge_start: &'a [u32],
}

/// A triangle found by the triangle pass: its owning face, interval, the
/// ids of its edges (`ab`, `bc`, `ca`) and, per edge, whether the third
/// vertex lies strictly inside the edge's diametral ball.
struct TriangleOut {
    face: u32,
    iv: [f64; 2],
    edges: [u32; 3],
    refuted: u8,
}

impl TriangleCtx<'_> {
    /// The triangles owned by the cells `cells`, which sit at positions
    /// `first..` of the visiting order.
    fn triangles_of(&self, cells: &[u32], first: usize) -> Vec<TriangleOut> {
        let tri = self.tri;
        let pts = tri.points();
        // Cell ids are scattered in memory: gather the cells first
        // (independent loads, so many misses are in flight at once), then
        // work on the gathered copy.
        let gathered: Vec<GatheredCell> = cells
            .iter()
            .map(|&t| (tri.tet(t), [0, 1, 2, 3].map(|i| tri.neighbor(t, i))))
            .collect();
        let mut out = Vec::with_capacity(2 * cells.len() + 8);
        for (k, (&t, (v, nbr))) in cells.iter().zip(&gathered).enumerate() {
            let here = (first + k) as u32;
            let rt = self.cell_r[t as usize];
            let mt = self.posmask[t as usize] & 0xf;
            for i in 0..4 {
                let (n, j) = nbr[i];
                // Owner: the later cell in the order, or the finite one.
                let pm = self.posmask[n as usize];
                let bn = if pm == u32::MAX {
                    0
                } else if pm >> 4 > here {
                    continue;
                } else {
                    pm & 0xf
                };
                let rn = self.cell_r[n as usize];
                let f = FACE[i];
                let (ia, ib, ic) = (v[f[0]], v[f[1]], v[f[2]]);
                let gabriel = (mt >> i) & 1 == 0 && (bn >> j) & 1 == 0;
                let amax = rt.max(rn);
                let amin = if gabriel {
                    // ρ is at most either circumradius, with equality when
                    // an apex lies on the diametral sphere; the two are
                    // computed by different formulas and can round apart,
                    // so the min keeps the interval ordered.
                    triangle_rho_sorted(pts, [ia, ib, ic]).min(rt).min(rn)
                } else {
                    rt.min(rn)
                };
                let mut edges = [0u32; 3];
                let mut refuted = 0u8;
                for (e, (x, y, z)) in [(ia, ib, ic), (ib, ic, ia), (ic, ia, ib)]
                    .into_iter()
                    .enumerate()
                {
                    edges[e] = find_edge_id(self.edge_v, self.edge_start, x, y);
                    let inside = exact::edge_diametral_side(
                        &pts[x as usize],
                        &pts[y as usize],
                        &pts[z as usize],
                    )
                    .is_negative();
                    refuted |= (inside as u8) << e;
                }
                out.push(TriangleOut {
                    face: (t << 2) | i as u32,
                    iv: [amin, amax],
                    edges,
                    refuted,
                });
            }
        }
        out
    }
}

/// The id of edge `(x, y)` (which must exist), by a scan of the smaller
/// vertex's bucket.
#[inline]
fn find_edge_id(edges: &[[u32; 2]], start: &[u32], x: u32, y: u32) -> u32 {
    let (a, b) = if x < y { (x, y) } else { (y, x) };
    let mut e = start[a as usize] as usize;
    while edges[e][1] != b {
        e += 1;
    }
    e as u32
}

/// Step 3 of the algorithm: the circumradius and Gabriel mask (see
/// [`cell_masks`]) of every finite cell, by cell id, into `cell_r` and the
/// low 4 bits of `posmask` (where infinite cells are `u32::MAX` and keep
/// their `+∞` radius). Cells are independent, so with the `parallel`
/// feature they are split across rayon's threads; the values do not depend
/// on the split.
fn cell_pass(tri: &Triangulation, cell_r: &mut [f64], posmask: &mut [u32]) {
    let pts = tri.points();
    let work = |(t, (r, pm)): (usize, (&mut f64, &mut u32))| {
        if *pm != u32::MAX {
            let (rt, mt) = cell_masks(pts, &tri.tet(t as u32));
            *r = rt;
            *pm |= mt as u32;
        }
    };
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        cell_r
            .par_iter_mut()
            .zip(posmask.par_iter_mut())
            .enumerate()
            .with_min_len(1 << 12)
            .for_each(work);
    }
    #[cfg(not(feature = "parallel"))]
    cell_r
        .iter_mut()
        .zip(posmask.iter_mut())
        .enumerate()
        .for_each(work);
}

/// Circumradius of the finite cell with vertices `v`, and its 4-bit
/// Gabriel mask: bit `i` is set when vertex `i` lies strictly inside the
/// diametral sphere of the opposite face (so that face is not Gabriel).
#[inline]
fn cell_masks(pts: &[Point3], v: &[u32; 4]) -> (f64, u8) {
    let (r2, m) = exact::cell_radius2_and_mask(v.map(|k| &pts[k as usize]));
    (r2.sqrt(), m)
}

/// `rayon::join` with the `parallel` feature; otherwise `a` then `b`.
fn join<RA, RB>(a: impl FnOnce() -> RA + Send, b: impl FnOnce() -> RB + Send) -> (RA, RB)
where
    RA: Send,
    RB: Send,
{
    #[cfg(feature = "parallel")]
    return rayon::join(a, b);
    #[cfg(not(feature = "parallel"))]
    (a(), b())
}

/// Edge vertex ids, per-vertex offsets and intervals (see [`AlphaComplex`]).
type EdgeTables = (Vec<[u32; 2]>, Vec<u32>, Vec<[f64; 2]>);

/// Numbers the finite edges `(a, b)`, `a < b` (vertex ids), grouped by
/// `a`: a counting sort of the 6 edges of every finite tet on `a`, then a
/// per-vertex deduplication. Returns the edges, the per-vertex offsets
/// and the edges' initial intervals (allocated here, off the cell pass).
fn number_edges(tri: &Triangulation) -> EdgeTables {
    let nv = tri.num_vertices();
    let mut start = vec![0u32; nv + 1];
    for t in 0..tri.num_tets() as u32 {
        let v = tri.tet(t);
        if v[3] == INFINITE {
            continue;
        }
        for [i, j] in PAIRS {
            start[v[i].min(v[j]) as usize + 1] += 1;
        }
    }
    for k in 0..nv {
        start[k + 1] += start[k];
    }
    let mut fill: Vec<u32> = start[..nv].to_vec();
    let mut buf = vec![0u32; start[nv] as usize];
    for t in 0..tri.num_tets() as u32 {
        let v = tri.tet(t);
        if v[3] == INFINITE {
            continue;
        }
        for [i, j] in PAIRS {
            let (a, b) = if v[i] < v[j] {
                (v[i], v[j])
            } else {
                (v[j], v[i])
            };
            let slot = &mut fill[a as usize];
            buf[*slot as usize] = b;
            *slot += 1;
        }
    }
    drop(fill);
    // Euler: V − E + F − T = 1 for the (ball-shaped) finite complex.
    let nf = tri.num_triangles();
    let ne_guess = (nv + nf).saturating_sub(tri.num_finite_tets() + 1);
    let mut edges: Vec<[u32; 2]> = Vec::with_capacity(ne_guess);
    let mut estart = vec![0u32; nv + 1];
    // Deduplicate each bucket with a stamp per vertex (no sort: within a
    // vertex the edges stay in first-seen order, lookups scan the bucket).
    let mut stamp = vec![u32::MAX; nv];
    for a in 0..nv {
        for &b in &buf[start[a] as usize..start[a + 1] as usize] {
            if stamp[b as usize] != a as u32 {
                stamp[b as usize] = a as u32;
                edges.push([a as u32, b]);
            }
        }
        estart[a + 1] = edges.len() as u32;
    }
    let iv = vec![[f64::INFINITY, 0.0]; edges.len()];
    (edges, estart, iv)
}

/// The finite cells grouped by their smallest vertex id (a counting sort).
/// Vertex ids follow the spatially coherent insertion order while cell ids
/// do not, so visiting cells in this order keeps the accesses to points and
/// edges local.
fn cells_by_min_vertex(tri: &Triangulation) -> Vec<u32> {
    let nv = tri.num_vertices();
    let nc = tri.num_tets() as u32;
    let mut start = vec![0u32; nv + 1];
    for t in 0..nc {
        let v = tri.tet(t);
        if v[3] != INFINITE {
            start[v[0].min(v[1]).min(v[2].min(v[3])) as usize + 1] += 1;
        }
    }
    for k in 0..nv {
        start[k + 1] += start[k];
    }
    let mut order = vec![0u32; start[nv] as usize];
    for t in 0..nc {
        let v = tri.tet(t);
        if v[3] != INFINITE {
            let slot = &mut start[v[0].min(v[1]).min(v[2].min(v[3])) as usize];
            order[*slot as usize] = t;
            *slot += 1;
        }
    }
    order
}

/// Circumradius of the triangle `abc` (radius of its smallest
/// circumsphere), as `|b − a| |c − a| |c − b| / (2 |(b − a) × (c − a)|)`:
/// no cancellation in the numerator, and the cross product is made
/// accurate for nearly collinear triangles.
#[inline]
fn triangle_rho(a: &Point3, b: &Point3, c: &Point3) -> f64 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let d = [c[0] - b[0], c[1] - b[1], c[2] - b[2]];
    let uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    let vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let nn = exact::cross_norm2(a, b, c, &u, &v);
    0.5 * ((uu * vv * dd) / nn).sqrt()
}

/// [`triangle_rho`] of the triangle with vertex ids `f`, evaluated with the
/// ids in ascending order, so that the rounding does not depend on which
/// cell reports the triangle (the detector's `F_α` relies on it).
#[inline]
pub(crate) fn triangle_rho_sorted(pts: &[Point3], mut f: [u32; 3]) -> f64 {
    f.sort_unstable();
    let [a, b, c] = f.map(|v| &pts[v as usize]);
    triangle_rho(a, b, c)
}
