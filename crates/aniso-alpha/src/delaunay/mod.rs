//! Exact 3D Delaunay tetrahedralization.
//!
//! [`Triangulation::new`] builds the Delaunay tetrahedralization of a point
//! set with exact predicates and CGAL's symbolic perturbation, so that on
//! degenerate input (grids, cospherical points) the result is the same
//! unique triangulation that CGAL's `Delaunay_triangulation_3` produces,
//! tetrahedron for tetrahedron.
//!
//! # Storage
//!
//! Tetrahedra live in flat arrays indexed by `u32`:
//!
//! * `tets[t]`: the four vertex ids, positively oriented for finite tets;
//! * `adj[t][i]`: the tetrahedron across the face opposite vertex `i`,
//!   packed as `4 * neighbour + j` where `j` is the index of that face in the
//!   neighbour (the *mirror* index), so crossing a face costs nothing.
//!
//! The convex hull is closed by an *infinite vertex* ([`INFINITE`]): each
//! hull facet is the finite face of one infinite tetrahedron, and hull
//! facets are ordinary adjacency. An infinite tet is oriented so that
//! replacing the infinite vertex by a point outside the hull (beyond its
//! facet) gives a positively oriented tetrahedron; its infinite vertex is
//! always at local index 3.
//!
//! Vertex ids are assigned in insertion order (a spatially coherent order);
//! [`Triangulation::input_index`] and [`Triangulation::vertex_of_input`]
//! translate to and from indices into the caller's slice.

//! # Layout
//!
//! The tetrahedron structure is `cell` (cells, the face table [`FACE`],
//! packed neighbours, flags, compaction); the build keeps its cells in a `store`
//! (plain, or shared by threads); one insertion core (`insert`, with the
//! cavity's scratch and linking in `cavity`) is used by the sequential and
//! the parallel build alike (`sequential`, `parallel`); `build` checks the
//! input, orders it (`order`), runs one of them and finishes the
//! [`Triangulation`]. `queries` and `validate` only read it.

mod build;
mod cavity;
mod cell;
mod insert;
mod isa;
mod order;
mod parallel;
mod queries;
mod sequential;
mod store;
#[cfg(test)]
mod test_points;
mod validate;

pub(crate) use cell::EDGES;
pub use cell::FACE;
pub use queries::{Edge, EdgeRing, Triangle};
pub use validate::ValidationError;

use crate::geometry::Point3;

/// The id of the infinite vertex.
pub const INFINITE: u32 = u32::MAX;

/// A vertex of a triangulation: an index into [`Triangulation::points`],
/// in insertion order, as opposed to an index into the caller's input
/// (duplicates share one vertex; [`Triangulation::input_index`] and
/// [`Triangulation::vertex_of_input`] translate). The
/// [`AlphaComplex`](crate::alpha::AlphaComplex) reports both kinds, and
/// gives its vertex ids this type so that the two cannot be mixed up.
///
/// ```
/// use aniso_alpha::AlphaComplex;
/// // The first input point is a duplicate of the third.
/// let pts = [[1.0, 1.0, 1.0], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let ac = AlphaComplex::from_points(&pts)?;
/// let [a, b] = ac.edge_vertices(0);
/// assert!(a < b);
/// let tri = ac.triangulation();
/// assert_eq!(tri.point(a.0), &pts[ac.input_index(a) as usize]);
/// # Ok::<(), aniso_alpha::delaunay::DelaunayError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VertexId(pub u32);

impl From<VertexId> for u32 {
    fn from(v: VertexId) -> u32 {
        v.0
    }
}

/// Error building a triangulation.
#[derive(Debug, Clone, PartialEq)]
pub enum DelaunayError {
    /// The input holds no point.
    Empty,
    /// A coordinate is NaN or infinite.
    NonFinite {
        /// Index of the offending point in the input.
        index: usize,
        /// Which coordinate (0 = x, 1 = y, 2 = z).
        coord: usize,
        /// The value found.
        value: f64,
    },
    /// A coordinate is outside the range where the exact predicates are
    /// guaranteed (see [`COORD_RANGE`]): rescale the data.
    OutOfRange {
        /// Index of the offending point in the input.
        index: usize,
        /// Which coordinate (0 = x, 1 = y, 2 = z).
        coord: usize,
        /// The value found.
        value: f64,
    },
    /// More points than the build accepts ([`MAX_POINTS`]).
    TooManyPoints(usize),
    /// The triangulation of this many points needs more than 2^30
    /// tetrahedra, the most the packed `u32` adjacency can address (uniform
    /// data reaches it near 150 million points).
    TooManyTets(usize),
}

/// The most points a triangulation accepts (duplicates included):
/// 536,870,910 = 2^29 − 2, about 5.4e8.
///
/// Vertex ids are `u32`s that must stay below 2^31: the top bit of a cell's
/// vertex word carries an insertion's flags, and the two largest values
/// stand for the infinite vertex and for an unwritten cell. The build keeps
/// a margin of a factor of 4 below that (`(2^32 − 3) / 8` points are
/// refused). Points in general position reach the 2^30-tetrahedron limit
/// ([`DelaunayError::TooManyTets`]) first, near 150 million points; the
/// point limit matters for inputs with many duplicates or of low dimension.
pub const MAX_POINTS: usize = (u32::MAX as usize - 2) / 8 - 1;

/// The magnitudes a nonzero coordinate may have: `[COORD_RANGE.0,
/// COORD_RANGE.1]` (zero is always fine). Within it, the products of the
/// in-sphere determinant (degree 5 in coordinate differences, and their
/// error terms) neither overflow nor underflow, which is what makes the
/// predicates exact; outside it a result could silently be wrong, so
/// [`Triangulation::new`] refuses it with [`DelaunayError::OutOfRange`].
pub const COORD_RANGE: (f64, f64) = (1e-60, 1e55);

impl std::fmt::Display for DelaunayError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DelaunayError::Empty => write!(f, "no points to triangulate"),
            DelaunayError::NonFinite {
                index,
                coord,
                value,
            } => write!(
                f,
                "point {index} has a non-finite {} coordinate ({value})",
                ["x", "y", "z"][*coord]
            ),
            DelaunayError::OutOfRange {
                index,
                coord,
                value,
            } => write!(
                f,
                "point {index} has {} coordinate {value:e}, outside the range of exact \
                 arithmetic ({:e} to {:e} in magnitude, or 0): rescale the data",
                ["x", "y", "z"][*coord],
                COORD_RANGE.0,
                COORD_RANGE.1
            ),
            DelaunayError::TooManyPoints(n) => {
                write!(
                    f,
                    "{n} points is more than this library can triangulate at once \
                     (at most {MAX_POINTS}): split the data"
                )
            }
            DelaunayError::TooManyTets(n) => write!(
                f,
                "the triangulation of {n} points needs more than 2^30 tetrahedra, \
                 more than this library can index: split the data"
            ),
        }
    }
}

impl std::error::Error for DelaunayError {}

/// A Delaunay tetrahedralization of a finite point set in R³.
///
/// ```
/// use aniso_alpha::delaunay::Triangulation;
/// // The 8 corners of a cube: 5 points cospherical everywhere, settled by
/// // the symbolic perturbation.
/// let pts: Vec<[f64; 3]> = (0..8)
///     .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
///     .collect();
/// let tri = Triangulation::new(&pts)?;
/// assert_eq!(tri.dimension(), 3);
/// assert_eq!(tri.num_finite_tets(), 6);
/// tri.validate()?;
/// // Every tet, with indices into `pts`, positively oriented.
/// for [a, b, c, d] in tri.finite_tets_input() {
///     assert!(a != b && c != d);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct Triangulation {
    /// Vertex id -> coordinates (insertion order).
    pts: Vec<Point3>,
    /// Vertex id -> smallest input index holding that point.
    vert_input: Vec<u32>,
    /// Input index -> vertex id.
    input_vert: Vec<u32>,
    /// Tetrahedra: vertex ids and packed neighbours (`4 * tet + mirror`).
    cells: Vec<cell::Cell>,
    /// Number of finite tetrahedra.
    num_finite: usize,
    /// Vertex id -> one incident tetrahedron.
    vert_tet: Vec<u32>,
    /// Affine dimension of the point set.
    dim: usize,
}

impl Triangulation {
    /// Builds the Delaunay tetrahedralization of `points`.
    ///
    /// Exact duplicates are merged (every input index maps to a vertex, see
    /// [`Self::vertex_of_input`]). If the points span fewer than 3 dimensions
    /// the result has no tetrahedra and [`Self::dimension`] says 0, 1 or 2.
    ///
    /// # Errors
    /// [`DelaunayError::Empty`] for no points, [`DelaunayError::NonFinite`]
    /// for a NaN or infinite coordinate, [`DelaunayError::OutOfRange`] for a
    /// coordinate whose magnitude is outside [`COORD_RANGE`].
    pub fn new(points: &[[f64; 3]]) -> Result<Self, DelaunayError> {
        build::build(points, 1)
    }

    /// [`Self::new`] on `threads` threads (at most 8 are used; 1 is
    /// [`Self::new`] itself). Worth it from about 100,000 points; below
    /// about 16,000 points per thread the build runs on one thread.
    ///
    /// The result has the same tets (the triangulation is unique), the same
    /// vertex ids and the same input mapping as [`Self::new`]'s; only the
    /// numbering of the tets, and where each tet's vertex list starts, may
    /// differ. For a given number of threads it is the same from run to
    /// run: which thread does what depends on the input, never on timing.
    ///
    /// ```
    /// use aniso_alpha::delaunay::Triangulation;
    /// let pts: Vec<[f64; 3]> = (0..1000)
    ///     .map(|i| {
    ///         let t = i as f64;
    ///         [(t * 0.618).fract(), (t * 0.414).fract(), (t * 0.732).fract()]
    ///     })
    ///     .collect();
    /// let one = Triangulation::new(&pts)?;
    /// let two = Triangulation::with_threads(&pts, 2)?;
    /// assert_eq!(one.num_finite_tets(), two.num_finite_tets());
    /// assert_eq!(one.vertex_of_input(17), two.vertex_of_input(17));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn with_threads(points: &[[f64; 3]], threads: usize) -> Result<Self, DelaunayError> {
        build::build(points, threads)
    }

    /// Affine dimension of the input: 0 (one distinct point), 1 (collinear),
    /// 2 (coplanar) or 3. Below 3 there are no tetrahedra.
    pub fn dimension(&self) -> usize {
        self.dim
    }

    /// Number of input points (including duplicates).
    pub fn num_input_points(&self) -> usize {
        self.input_vert.len()
    }

    /// Number of distinct points, i.e. of vertices.
    pub fn num_vertices(&self) -> usize {
        self.pts.len()
    }

    /// Number of input points that were exact duplicates of an earlier one.
    pub fn num_duplicates(&self) -> usize {
        self.input_vert.len() - self.pts.len()
    }

    /// Coordinates of vertex `v`.
    #[inline]
    pub fn point(&self, v: u32) -> &Point3 {
        &self.pts[v as usize]
    }

    /// All vertex coordinates, indexed by vertex id.
    pub fn points(&self) -> &[Point3] {
        &self.pts
    }

    /// The smallest input index whose point is vertex `v`.
    #[inline]
    pub fn input_index(&self, v: u32) -> u32 {
        self.vert_input[v as usize]
    }

    /// The vertex holding input point `i`.
    #[inline]
    pub fn vertex_of_input(&self, i: usize) -> u32 {
        self.input_vert[i]
    }

    /// Number of finite tetrahedra.
    pub fn num_finite_tets(&self) -> usize {
        self.num_finite
    }

    /// Number of tetrahedra including the infinite ones (those incident to
    /// the infinite vertex, one per hull facet).
    pub fn num_tets(&self) -> usize {
        self.cells.len()
    }

    /// The finite tetrahedra as vertex ids, each positively oriented.
    pub fn finite_tets(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        self.cells
            .iter()
            .filter(|c| c.v[3] != INFINITE)
            .map(|c| c.v)
    }

    /// The finite tetrahedra with indices into the input (the smallest
    /// index of a duplicated point), each positively oriented.
    pub fn finite_tets_input(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        self.finite_tets()
            .map(move |t| t.map(|v| self.vert_input[v as usize]))
    }

    /// The four vertices of tetrahedron `t`; for an infinite tet the last
    /// one is [`INFINITE`].
    #[inline]
    pub fn tet(&self, t: u32) -> [u32; 4] {
        self.cells[t as usize].v
    }

    /// Whether tetrahedron `t` is incident to the infinite vertex.
    #[inline]
    pub fn is_infinite(&self, t: u32) -> bool {
        self.cells[t as usize].v[3] == INFINITE
    }

    /// The neighbour of `t` across the face opposite its vertex `i`, and the
    /// index of that shared face in the neighbour (the mirror index).
    #[inline]
    pub fn neighbor(&self, t: u32, i: usize) -> (u32, usize) {
        let p = self.cells[t as usize].n[i];
        (p >> 2, (p & 3) as usize)
    }

    /// One tetrahedron incident to vertex `v` (possibly infinite).
    #[inline]
    pub fn incident_tet(&self, v: u32) -> u32 {
        self.vert_tet[v as usize]
    }
}
