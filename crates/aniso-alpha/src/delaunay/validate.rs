//! `validate()`: an independent check of every invariant of the structure.

use super::build::{tet_in_conflict, FACE};
use super::{Triangulation, INFINITE};
use crate::geometry::predicates::{orient3d, Filtered, StaticFilter};

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
                if orient3d(p[0], p[1], p[2], p[3]) <= 0 {
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
                if w != INFINITE
                    && tet_in_conflict::<Filtered, _>(
                        &self.pts[..],
                        &v,
                        self.point(w),
                        &StaticFilter::NONE,
                    )
                {
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
