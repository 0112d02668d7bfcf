//! `validate()`: an independent check of every invariant of the structure.
//!
//! Independent of the build: the local Delaunay test here has its own
//! exact predicates (straight calls to `robust`'s adaptive arithmetic,
//! without the build's static filters, integer stages or grid keys) and its
//! own statement of CGAL's symbolic perturbation (a full lexicographic sort
//! of the points, where the build runs a tournament or compares keys). It
//! shares only the face table with the build.

use super::cell::FACE;
use super::{Triangulation, INFINITE};
use crate::geometry::Point3;
use robust::{Coord, Coord3D};
use std::cmp::Ordering;

/// A broken invariant found by [`Triangulation::validate`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ValidationError {
    /// A neighbour link is not symmetric, or the shared face's vertices
    /// differ on the two sides.
    Adjacency {
        /// The tetrahedron.
        tet: u32,
        /// The local face index.
        face: usize,
    },
    /// A finite tetrahedron is not positively oriented, or an infinite one
    /// is malformed, or finite and infinite tets are not numbered in order.
    Orientation {
        /// The tetrahedron.
        tet: u32,
    },
    /// The vertex across `face` of `tet` is in (perturbed) conflict with
    /// `tet`: the triangulation is not Delaunay (or the hull not convex).
    NotDelaunay {
        /// The tetrahedron.
        tet: u32,
        /// The local face index.
        face: usize,
    },
    /// V − E + F − T of the finite complex is not 1.
    Euler {
        /// The value found.
        chi: i64,
    },
    /// A vertex is in no tetrahedron, or an input index maps to no vertex
    /// (or to a vertex with other coordinates).
    Vertex {
        /// The vertex or input index.
        index: usize,
    },
}

impl std::fmt::Display for ValidationError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ValidationError::Adjacency { tet, face } => {
                write!(f, "adjacency of tet {tet} face {face} is not symmetric")
            }
            ValidationError::Orientation { tet } => write!(f, "tet {tet} is badly oriented"),
            ValidationError::NotDelaunay { tet, face } => {
                write!(f, "facet {face} of tet {tet} is not locally Delaunay")
            }
            ValidationError::Euler { chi } => {
                write!(
                    f,
                    "Euler characteristic of the finite complex is {chi}, not 1"
                )
            }
            ValidationError::Vertex { index } => write!(f, "vertex/input {index} is missing"),
        }
    }
}

impl std::error::Error for ValidationError {}

fn sorted_face(v: &[u32; 4], i: usize) -> [u32; 3] {
    let f = FACE[i];
    let mut s = [v[f[0]], v[f[1]], v[f[2]]];
    s.sort_unstable();
    s
}

impl Triangulation {
    /// Checks every invariant with exact predicates: neighbour symmetry,
    /// positive orientation of finite tets, local Delaunay (with the
    /// perturbation) on every facet including hull convexity, the Euler
    /// characteristic of the finite complex, and that every vertex is used
    /// and every input index maps to a vertex.
    ///
    /// Costs about as much as the construction; meant for tests.
    pub fn validate(&self) -> Result<(), ValidationError> {
        let nt = self.cells.len();
        for (i, &v) in self.input_vert.iter().enumerate() {
            if v as usize >= self.pts.len() || self.vert_input[v as usize] as usize > i {
                return Err(ValidationError::Vertex { index: i });
            }
        }
        for (v, &i) in self.vert_input.iter().enumerate() {
            if self.input_vert.get(i as usize) != Some(&(v as u32)) {
                return Err(ValidationError::Vertex { index: v });
            }
        }
        if self.dim < 3 {
            if nt != 0 {
                return Err(ValidationError::Orientation { tet: 0 });
            }
            return Ok(());
        }
        let mut used = vec![false; self.pts.len()];
        for t in 0..nt as u32 {
            let v = self.cells[t as usize].v;
            let infs = v.iter().filter(|&&x| x == INFINITE).count();
            if infs > 1 || (infs == 1 && v[3] != INFINITE) {
                return Err(ValidationError::Orientation { tet: t });
            }
            for &w in &v {
                if w != INFINITE {
                    if w as usize >= self.pts.len() {
                        return Err(ValidationError::Vertex { index: w as usize });
                    }
                    used[w as usize] = true;
                }
            }
            if infs == 0 {
                let p = v.map(|w| self.point(w));
                if orient(p[0], p[1], p[2], p[3]) <= 0 {
                    return Err(ValidationError::Orientation { tet: t });
                }
            }
            for i in 0..4 {
                let (n, j) = self.neighbor(t, i);
                if n as usize >= nt || n == t || self.neighbor(n, j) != (t, i) {
                    return Err(ValidationError::Adjacency { tet: t, face: i });
                }
                if sorted_face(&v, i) != sorted_face(&self.cells[n as usize].v, j) {
                    return Err(ValidationError::Adjacency { tet: t, face: i });
                }
                let w = self.cells[n as usize].v[j];
                if w != INFINITE && self.conflicts(&v, self.point(w)) {
                    return Err(ValidationError::NotDelaunay { tet: t, face: i });
                }
            }
        }
        if let Some(v) = used.iter().position(|&u| !u) {
            return Err(ValidationError::Vertex { index: v });
        }
        // Euler characteristic of the finite complex (a 3-ball): 1.
        let mut edges: Vec<u64> = Vec::with_capacity(6 * self.num_finite);
        for v in self.finite_tets() {
            for a in 0..4 {
                for b in a + 1..4 {
                    let (x, y) = (v[a].min(v[b]), v[a].max(v[b]));
                    edges.push(((x as u64) << 32) | y as u64);
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let chi = self.pts.len() as i64 - edges.len() as i64 + self.num_triangles() as i64
            - self.num_finite as i64;
        if chi != 1 {
            return Err(ValidationError::Euler { chi });
        }
        Ok(())
    }

    /// [`Self::validate`], and also that every input point's vertex has the
    /// input point's coordinates. `points` must be the slice the
    /// triangulation was built from.
    pub fn validate_with_input(&self, points: &[[f64; 3]]) -> Result<(), ValidationError> {
        if points.len() != self.input_vert.len() {
            return Err(ValidationError::Vertex {
                index: points.len(),
            });
        }
        for (i, p) in points.iter().enumerate() {
            if self.point(self.input_vert[i]) != p {
                return Err(ValidationError::Vertex { index: i });
            }
        }
        self.validate()
    }
}

impl Triangulation {
    /// Whether point `q` destroys the tet with vertices `v` under CGAL's
    /// symbolic perturbation: inside the circumsphere of a finite tet;
    /// strictly beyond the hull facet of an infinite one, or in its plane
    /// and inside its circumcircle.
    fn conflicts(&self, v: &[u32; 4], q: &Point3) -> bool {
        let p = |k: usize| self.point(v[k]);
        if v[3] == INFINITE {
            match orient(p(0), p(1), p(2), q) {
                0 => coplanar_incircle(p(0), p(1), p(2), q),
                o => o > 0,
            }
        } else {
            insphere_perturbed(&[p(0), p(1), p(2), p(3), q])
        }
    }
}

/// The sign of `x`.
fn sign(x: f64) -> i32 {
    (x > 0.0) as i32 - (x < 0.0) as i32
}

fn c3(p: &Point3) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Exact sign of `det[b − a, c − a, d − a]` (`robust`'s orient3d has the
/// opposite sign).
fn orient(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> i32 {
    -sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
}

/// Exact in-sphere sign: positive when `e` is strictly inside the
/// circumsphere of the positively oriented `(a, b, c, d)`.
fn insphere(a: &Point3, b: &Point3, c: &Point3, d: &Point3, e: &Point3) -> i32 {
    -sign(robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)))
}

/// The lexicographic order of points (x, then y, then z), CGAL's
/// perturbation order.
fn lex(a: &Point3, b: &Point3) -> Ordering {
    a[0].total_cmp(&b[0])
        .then(a[1].total_cmp(&b[1]))
        .then(a[2].total_cmp(&b[2]))
}

/// CGAL's perturbed in-sphere test for the positively oriented tet
/// `p[0..4]` and the query `p[4]`: on an exact tie, the points are taken
/// from the lexicographically largest down; the query itself means
/// outside, a tet vertex means the sign of the tet with that vertex
/// replaced by the query, unless it is zero.
fn insphere_perturbed(p: &[&Point3; 5]) -> bool {
    let s = insphere(p[0], p[1], p[2], p[3], p[4]);
    if s != 0 {
        return s > 0;
    }
    let mut idx = [0, 1, 2, 3, 4];
    idx.sort_by(|&i, &j| lex(p[j], p[i]));
    for i in idx {
        if i == 4 {
            return false;
        }
        let mut q = [p[0], p[1], p[2], p[3]];
        q[i] = p[4];
        let o = orient(q[0], q[1], q[2], q[3]);
        if o != 0 {
            return o > 0;
        }
    }
    false
}

/// The orientation of `a, b, c` projected onto coordinates `(i, j)`.
fn orient2(a: &Point3, b: &Point3, c: &Point3, i: usize, j: usize) -> i32 {
    let q = |p: &Point3| Coord { x: p[i], y: p[j] };
    sign(robust::orient2d(q(a), q(b), q(c)))
}

/// CGAL's orientation of three coplanar points: in the first of the
/// projections xy, yz, xz where they are not collinear.
fn coplanar_orientation(a: &Point3, b: &Point3, c: &Point3) -> i32 {
    [(0, 1), (1, 2), (0, 2)]
        .iter()
        .map(|&(i, j)| orient2(a, b, c, i, j))
        .find(|&o| o != 0)
        .unwrap_or(0)
}

/// CGAL's perturbed coplanar in-circle test: whether `q`, in the plane of
/// the triangle `(a, b, c)`, is inside its circumcircle. The circle is cut
/// by any sphere through it: the one through `a, b, c` and `a` moved off
/// the plane along an axis the plane is not parallel to. On an exact tie,
/// the points from the lexicographically largest down: the query means
/// outside, a triangle vertex means the orientation of the triangle with it
/// replaced by the query, relative to the triangle's own.
fn coplanar_incircle(a: &Point3, b: &Point3, c: &Point3, q: &Point3) -> bool {
    let axis = [(0, 1, 2), (1, 2, 0), (0, 2, 1)]
        .iter()
        .find(|&&(i, j, _)| orient2(a, b, c, i, j) != 0)
        .map_or(2, |&(_, _, k)| k);
    let mut x = *a;
    x[axis] += a[axis].abs().max(1.0);
    let s = insphere(a, b, c, &x, q) * orient(a, b, c, &x);
    if s != 0 {
        return s > 0;
    }
    let p = [a, b, c, q];
    let mut idx = [0, 1, 2, 3];
    idx.sort_by(|&i, &j| lex(p[j], p[i]));
    let own = coplanar_orientation(a, b, c);
    for i in idx {
        if i == 3 {
            return false;
        }
        let mut t = [a, b, c];
        t[i] = q;
        let o = coplanar_orientation(t[0], t[1], t[2]);
        if o != 0 {
            return o * own > 0;
        }
    }
    false
}

/// Each invariant that `validate()` checks is broken on purpose here, and
/// the check must name it: an oracle that cannot fail proves nothing.
#[cfg(test)]
mod tests {
    use super::super::cell::{link_by_faces, pack, unpack, Cell, FACE, FRESH};
    use super::super::test_points::{int_grid, uniform_points};
    use super::super::{Triangulation, INFINITE};
    use super::{orient, ValidationError};

    /// The triangulation made of the finite tets `tets` (vertex ids into
    /// `pts`, either orientation) and, on each face that no other tet
    /// shares, an infinite tet; linked by brute force. No check that this
    /// is a triangulation at all: that is `validate()`'s job.
    fn from_tets(pts: &[[f64; 3]], tets: &[[u32; 4]]) -> Triangulation {
        let mut cells: Vec<Cell> = tets
            .iter()
            .map(|&t| {
                let p = t.map(|w| &pts[w as usize]);
                let mut v = t;
                if orient(p[0], p[1], p[2], p[3]) < 0 {
                    v.swap(0, 1);
                }
                Cell { v, ..FRESH }
            })
            .collect();
        let key = |c: &Cell, i: usize| {
            let mut f = FACE[i].map(|k| c.v[k]);
            f.sort_unstable();
            f
        };
        let mut hull = Vec::new();
        for c in &cells {
            for i in 0..4 {
                let shared = cells
                    .iter()
                    .filter(|d| (0..4).any(|j| key(d, j) == key(c, i)))
                    .count();
                if shared == 1 {
                    // Face i reversed: the infinite vertex on its outer side.
                    let f = FACE[i].map(|k| c.v[k]);
                    hull.push(Cell {
                        v: [f[1], f[0], f[2], INFINITE],
                        ..FRESH
                    });
                }
            }
        }
        let num_finite = cells.len();
        cells.extend(hull);
        let ids: Vec<u32> = (0..cells.len() as u32).collect();
        link_by_faces(&mut cells, &ids);
        let mut vert_tet = vec![u32::MAX; pts.len()];
        for (t, c) in cells.iter().enumerate() {
            for &w in &c.v {
                if w != INFINITE {
                    vert_tet[w as usize] = t as u32;
                }
            }
        }
        Triangulation {
            pts: pts.to_vec(),
            vert_input: (0..pts.len() as u32).collect(),
            input_vert: (0..pts.len() as u32).collect(),
            cells,
            num_finite,
            vert_tet,
            dim: 3,
        }
    }

    /// Uniform points and a grid (ties everywhere), built, and rebuilt by
    /// [`from_tets`] from their finite tets: both pass.
    fn valid_cases() -> Vec<Triangulation> {
        let mut out = Vec::new();
        for pts in [uniform_points(3, 300), int_grid(5)] {
            let tri = Triangulation::new(&pts).unwrap();
            tri.validate_with_input(&pts).unwrap();
            let tets: Vec<[u32; 4]> = tri.finite_tets().collect();
            let again = from_tets(tri.points(), &tets);
            again.validate().unwrap();
            out.push(tri);
        }
        out
    }

    /// Exchanges tets `a` and `b` (ids, and every neighbour word that
    /// points at them): the same triangulation, numbered otherwise.
    fn swap_tets(tri: &mut Triangulation, a: u32, b: u32) {
        if a == b {
            return;
        }
        let rename = |t: u32| {
            if t == a {
                b
            } else if t == b {
                a
            } else {
                t
            }
        };
        tri.cells.swap(a as usize, b as usize);
        for c in tri.cells.iter_mut() {
            for p in c.n.iter_mut() {
                let (t, i) = unpack(*p);
                *p = pack(rename(t), i);
            }
        }
    }

    #[test]
    fn a_broken_neighbour_link_is_an_adjacency_error() {
        for mut tri in valid_cases() {
            // Tet 0's neighbours across faces 0 and 1 exchanged: the links
            // are no longer symmetric.
            tri.cells[0].n.swap(0, 1);
            assert!(
                matches!(tri.validate(), Err(ValidationError::Adjacency { .. })),
                "{:?}",
                tri.validate()
            );
        }
    }

    #[test]
    fn mismatched_shared_faces_are_an_adjacency_error() {
        for mut tri in valid_cases() {
            // Two finite tets that are not neighbours linked to each other
            // symmetrically: the links agree, the faces do not.
            let finite: Vec<u32> = (0..tri.num_tets() as u32)
                .filter(|&t| !tri.is_infinite(t))
                .collect();
            let (a, b) = (finite[0], *finite.last().unwrap());
            assert!((0..4).all(|i| tri.neighbor(a, i).0 != b));
            let (na, ia) = unpack(tri.cells[a as usize].n[0]);
            let (nb, ib) = unpack(tri.cells[b as usize].n[0]);
            tri.cells[a as usize].n[0] = pack(b, 0);
            tri.cells[b as usize].n[0] = pack(a, 0);
            tri.cells[na as usize].n[ia] = pack(nb, ib);
            tri.cells[nb as usize].n[ib] = pack(na, ia);
            assert!(
                matches!(tri.validate(), Err(ValidationError::Adjacency { .. })),
                "{:?}",
                tri.validate()
            );
        }
    }

    #[test]
    fn a_negatively_oriented_tet_is_an_orientation_error() {
        for mut tri in valid_cases() {
            // A finite tet moved to id 0 (checked first), then mirrored:
            // vertices 0 and 1 exchanged with their faces' neighbours, so
            // every link and face still agrees and only the orientation
            // is wrong.
            let t = (0..tri.num_tets() as u32)
                .find(|&t| !tri.is_infinite(t))
                .unwrap();
            swap_tets(&mut tri, 0, t);
            tri.validate().unwrap();
            let c = &mut tri.cells[0];
            c.v.swap(0, 1);
            c.n.swap(0, 1);
            for i in 0..2 {
                let (n, j) = unpack(tri.cells[0].n[i]);
                tri.cells[n as usize].n[j] = pack(0, i);
            }
            assert_eq!(tri.validate(), Err(ValidationError::Orientation { tet: 0 }));
        }
    }

    #[test]
    fn a_malformed_infinite_tet_is_an_orientation_error() {
        for mut tri in valid_cases() {
            let t = (0..tri.num_tets() as u32)
                .find(|&t| tri.is_infinite(t))
                .unwrap();
            swap_tets(&mut tri, 0, t);
            tri.validate().unwrap();
            // The infinite vertex must be at index 3.
            tri.cells[0].v.swap(2, 3);
            assert_eq!(tri.validate(), Err(ValidationError::Orientation { tet: 0 }));
        }
    }

    /// Two tets on the triangle of a bipyramid whose apexes lie inside
    /// each other's circumsphere: the Delaunay triangulation of these five
    /// points is the three tets around the apexes' edge.
    #[test]
    fn a_non_delaunay_facet_is_reported() {
        let h = 0.75f64.sqrt();
        let pts = [
            [1.0, 0.0, 0.0],
            [-0.5, h, 0.0],
            [-0.5, -h, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -0.5],
        ];
        let delaunay = from_tets(&pts, &[[0, 1, 3, 4], [1, 2, 3, 4], [2, 0, 3, 4]]);
        delaunay.validate().unwrap();
        let flipped = from_tets(&pts, &[[0, 1, 2, 3], [0, 1, 2, 4]]);
        assert!(
            matches!(flipped.validate(), Err(ValidationError::NotDelaunay { .. })),
            "{:?}",
            flipped.validate()
        );
    }

    /// A tie: the cube's corners are cospherical, and only the perturbation
    /// decides which diagonals are Delaunay. The triangulation with the
    /// opposite choice on one face pair is reported.
    #[test]
    fn the_perturbation_decides_ties_in_validation() {
        let pts: Vec<[f64; 3]> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let tri = Triangulation::new(&pts).unwrap();
        tri.validate().unwrap();
        // The cube split into 5 tets (a corner-cut decomposition) instead
        // of CGAL's 6: every facet is a tie, and some diagonal of it is
        // not the perturbation's choice.
        let five = from_tets(
            &pts,
            &[
                [0, 1, 2, 4],
                [1, 2, 3, 7],
                [1, 4, 5, 7],
                [2, 4, 6, 7],
                [1, 2, 4, 7],
            ],
        );
        assert!(
            matches!(five.validate(), Err(ValidationError::NotDelaunay { .. })),
            "{:?}",
            five.validate()
        );
    }

    /// Two disjoint triangulations side by side pass every local check,
    /// but their Euler characteristic is 2.
    #[test]
    fn two_components_fail_the_euler_check() {
        let a = uniform_points(5, 40);
        let b: Vec<[f64; 3]> = uniform_points(6, 40)
            .iter()
            .map(|p| [p[0] + 10.0, p[1], p[2]])
            .collect();
        let n = a.len() as u32;
        let mut tets = Vec::new();
        for (pts, offset) in [(&a, 0), (&b, n)] {
            let tri = Triangulation::new(pts).unwrap();
            tets.extend(
                tri.finite_tets()
                    .map(|t| t.map(|w| tri.input_index(w) + offset)),
            );
        }
        let pts: Vec<[f64; 3]> = a.iter().chain(&b).copied().collect();
        let two = from_tets(&pts, &tets);
        assert_eq!(two.validate(), Err(ValidationError::Euler { chi: 2 }));
    }

    #[test]
    fn broken_vertex_maps_are_vertex_errors() {
        for tri in valid_cases() {
            let nv = tri.num_vertices();
            // An input index mapped to no vertex.
            let mut t = tri.clone();
            t.input_vert[7] = nv as u32;
            assert_eq!(t.validate(), Err(ValidationError::Vertex { index: 7 }));
            // A vertex standing for an input that maps elsewhere.
            let mut t = tri.clone();
            t.vert_input.swap(2, 3);
            assert!(matches!(t.validate(), Err(ValidationError::Vertex { .. })));
            // A vertex in no tetrahedron.
            let mut t = tri.clone();
            t.pts.push([9.0, 9.0, 9.0]);
            t.vert_input.push(t.input_vert.len() as u32);
            t.input_vert.push(nv as u32);
            assert_eq!(t.validate(), Err(ValidationError::Vertex { index: nv }));
            // The input's coordinates differ from its vertex's.
            let i = tri.input_index(0) as usize;
            let mut input: Vec<[f64; 3]> = (0..tri.num_input_points())
                .map(|k| *tri.point(tri.vertex_of_input(k)))
                .collect();
            tri.validate_with_input(&input).unwrap();
            input[i][0] += 0.5;
            assert_eq!(
                tri.validate_with_input(&input),
                Err(ValidationError::Vertex { index: i })
            );
        }
    }
}
