//! The result of a detection: structures, their parts with fitted planes
//! or lines, outlines and meshes, per-point labels, and counters.

use super::fit::{LineFit, PlaneFit};
use super::StructureKind;

/// A fitted primitive.
#[derive(Debug, Clone, PartialEq)]
pub enum Primitive {
    /// A least-squares line (k = 1).
    Line(LineFit),
    /// A least-squares plane (k = 2).
    Plane(PlaneFit),
    /// Too few or degenerate points to fit.
    None,
}

impl Primitive {
    /// The RMS distance of the fitted points to the primitive (∞ for none).
    pub fn rms(&self) -> f64 {
        match self {
            Primitive::Line(f) => f.rms_residual,
            Primitive::Plane(f) => f.rms_residual,
            Primitive::None => f64::INFINITY,
        }
    }

    /// The plane as `[a, b, c, d]` with (a, b, c) the unit normal and
    /// a·x + b·y + c·z + d = 0.
    pub fn plane_equation(&self) -> Option<[f64; 4]> {
        match self {
            Primitive::Plane(f) => {
                let n = f.normal;
                let d = -(n[0] * f.centroid[0] + n[1] * f.centroid[1] + n[2] * f.centroid[2]);
                Some([n[0], n[1], n[2], d])
            }
            _ => None,
        }
    }

    /// Distance from `p` to the primitive (∞ for none).
    pub fn distance(&self, p: &[f64; 3]) -> f64 {
        let w = |c: [f64; 3]| [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        match self {
            Primitive::Plane(f) => {
                let w = w(f.centroid);
                (w[0] * f.normal[0] + w[1] * f.normal[1] + w[2] * f.normal[2]).abs()
            }
            Primitive::Line(f) => {
                let w = w(f.centroid);
                let d = f.direction;
                let t = w[0] * d[0] + w[1] * d[1] + w[2] * d[2];
                let r = [w[0] - t * d[0], w[1] - t * d[1], w[2] - t * d[2]];
                (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt()
            }
            Primitive::None => f64::INFINITY,
        }
    }
}

/// A straight or flat piece of a structure: a plane with its outline, or a
/// segment. Parts are disjoint: a point belongs to at most one part.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// Indices into [`Detection::simplices`] (the union of the scanned
    /// anisotropic α-shapes) of the simplices with all their vertices in
    /// this part.
    pub simplices: Vec<u32>,
    /// Input indices of its points, ascending (first occurrences of
    /// duplicated points).
    pub vertices: Vec<u32>,
    /// Its least-squares line or plane (on [`Self::vertices`]).
    pub primitive: Primitive,
    /// A plane part's outline: the boundary of the 2D α-shape of its
    /// points on the plane (outer loop, counter-clockwise seen from the
    /// normal), as points on the plane; a line part's segment: its two end
    /// points (the extreme projections of its points on the line). A
    /// plane found in pieces apart (one wall's window panes) is one part:
    /// its outline is then the largest piece's outer loop, and its
    /// [`Self::mesh`] covers every piece.
    pub outline: Vec<[f64; 3]>,
    /// A plane part's clean mesh: the triangles of that 2D α-shape, over
    /// input point indices (one triangulation of the plane, so no two
    /// triangles overlap and every edge has at most two triangles). Empty
    /// for lines.
    pub mesh: Vec<[u32; 3]>,
    /// log₁₀ of its number of false alarms (see `detect::significance`);
    /// `-inf` when the test was not run.
    pub log10_nfa: f64,
}

impl Part {
    /// The part's plane `[a, b, c, d]` (unit normal), for a plane part.
    pub fn plane(&self) -> Option<[f64; 4]> {
        self.primitive.plane_equation()
    }

    /// The part's segment (two end points), for a line part.
    pub fn segment(&self) -> Option<[[f64; 3]; 2]> {
        match (&self.primitive, self.outline.as_slice()) {
            (Primitive::Line(_), [a, b]) => Some([*a, *b]),
            _ => None,
        }
    }
}

/// A detected structure: a line, a plane, or a polyhedral surface (several
/// flat parts meeting along their boundaries) or polyline.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// Its id (0 = largest), as used in [`Detection::labels`].
    pub id: u32,
    /// Indices into [`Detection::simplices`].
    pub simplices: Vec<u32>,
    /// Input indices of its points, ascending: the union of its parts'.
    pub vertices: Vec<u32>,
    /// Least-squares line (k = 1) or plane (k = 2) of all its points
    /// (meaningful for a single part; a surface's is only indicative).
    pub primitive: Primitive,
    /// Its straight or flat parts, largest first (one for a plain line or
    /// plane; the facets of a polyhedral surface).
    pub parts: Vec<Part>,
    /// log₁₀ of the smallest number of false alarms of its parts.
    pub log10_nfa: f64,
}

impl Structure {
    /// "line", "polyline", "plane" or "surface".
    pub fn kind_name(&self) -> &'static str {
        match (&self.primitive, self.parts.len()) {
            (Primitive::Line(_), 1) => "line",
            (Primitive::Line(_), _) => "polyline",
            (Primitive::Plane(_), 1) => "plane",
            (Primitive::Plane(_), _) => "surface",
            (Primitive::None, _) => "unfitted",
        }
    }
}

/// Counters of a run.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RunStats {
    /// Orientations scanned.
    pub orientations: usize,
    /// Points triangulated, summed over orientations (after pruning, halos
    /// included).
    pub triangulated_points: u64,
    /// Simplices of `F_{k,α,Q}` before the path filter, summed.
    pub raw_simplices: u64,
    /// Simplices after the path filter, summed over orientations.
    pub filtered_simplices: u64,
    /// Distinct simplices in the union.
    pub union_simplices: usize,
    /// Simplices left after the component clean-up.
    pub kept_simplices: usize,
    /// Simplices of the reported structures.
    pub structure_simplices: usize,
    /// Candidate parts rejected by the significance test.
    pub rejected_parts: usize,
    /// Line parts dropped because they lie inside a surface (its sampling
    /// pattern: a scanner's rings at a grazing angle).
    pub surface_lines: usize,
    /// Parts dropped for lacking their shape's proportions at the scale
    /// of their ellipsoid: planes narrower than it is long, lines less
    /// elongated than it.
    pub out_of_proportion: usize,
    /// Points whose nearest claimer made no kept part, joined to the
    /// nearest kept part that claims them (docs/method.md §4 step 6).
    pub reclaimed_points: usize,
    /// Pairs of coplanar planar pieces that would have merged into one
    /// part, kept apart because a solid stands between them: two faces
    /// (docs/method.md §4 step 5, "A solid between them").
    pub faces_apart: usize,
}

/// Simplices with the same number of vertices each (2: edges, k = 1; 3:
/// triangles, k = 2), stored flat: one `Vec<u32>` for all of them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Simplices {
    size: usize,
    vertices: Vec<u32>,
}

impl Simplices {
    /// No simplices, each to have `size` vertices.
    ///
    /// # Panics
    /// If `size` is 0.
    pub fn new(size: usize) -> Self {
        assert!(size >= 1, "a simplex has at least one vertex");
        Simplices {
            size,
            vertices: Vec::new(),
        }
    }

    /// The simplices of `size` vertices each, laid end to end in
    /// `vertices`.
    ///
    /// # Panics
    /// If `size` is 0 or the length of `vertices` is not a multiple of it.
    pub fn from_flat(size: usize, vertices: Vec<u32>) -> Self {
        assert!(size >= 1, "a simplex has at least one vertex");
        assert_eq!(vertices.len() % size, 0, "not whole simplices");
        Simplices { size, vertices }
    }

    /// The number of vertices of each simplex.
    pub fn size(&self) -> usize {
        self.size
    }

    /// The number of simplices.
    pub fn len(&self) -> usize {
        self.vertices.len() / self.size
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// Appends a simplex.
    ///
    /// # Panics
    /// If it does not have [`Self::size`] vertices.
    pub fn push(&mut self, simplex: &[u32]) {
        assert_eq!(simplex.len(), self.size, "a simplex of another size");
        self.vertices.extend_from_slice(simplex);
    }

    /// Simplex `i`, if there is one.
    pub fn get(&self, i: usize) -> Option<&[u32]> {
        self.vertices.get(i * self.size..(i + 1) * self.size)
    }

    /// The simplices in order.
    pub fn iter(&self) -> std::slice::ChunksExact<'_, u32> {
        self.vertices.chunks_exact(self.size)
    }

    /// The simplices in order, to change their vertices.
    pub fn iter_mut(&mut self) -> std::slice::ChunksExactMut<'_, u32> {
        self.vertices.chunks_exact_mut(self.size)
    }

    /// Every vertex of every simplex, simplex after simplex.
    pub fn as_flat(&self) -> &[u32] {
        &self.vertices
    }
}

impl std::ops::Index<usize> for Simplices {
    type Output = [u32];
    fn index(&self, i: usize) -> &[u32] {
        &self.vertices[i * self.size..(i + 1) * self.size]
    }
}

impl<'a> IntoIterator for &'a Simplices {
    type Item = &'a [u32];
    type IntoIter = std::slice::ChunksExact<'a, u32>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

/// The result of [`super::detector::Detector::run`].
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// Lines (k = 1) or planes (k = 2).
    pub kind: StructureKind,
    /// The simplices of the structures (from the union of the scanned
    /// anisotropic α-shapes): vertex index pairs (k = 1) or triples
    /// (k = 2), ascending within each, sorted; flat (a `Vec<u32>` per
    /// simplex took 4–5 times the memory).
    pub simplices: Simplices,
    /// The structure of each simplex.
    pub simplex_structure: Vec<u32>,
    /// The structures, largest first.
    pub structures: Vec<Structure>,
    /// Per input point: the id of its structure, or −1 (background). An
    /// exact duplicate has its first occurrence's.
    pub labels: Vec<i64>,
    /// Per input point: the index of the first input point with the same
    /// coordinates (itself when no earlier point has them). Simplices,
    /// structures and parts list first occurrences only.
    pub first_occurrence: Vec<u32>,
    /// Counters.
    pub stats: RunStats,
}

impl Detection {
    /// Per input point: the global id of its part (parts numbered
    /// structure by structure, largest first, as in the report), or −1.
    /// Parts are disjoint. An exact duplicate has its first occurrence's.
    pub fn part_labels(&self) -> Vec<i64> {
        let mut labels = vec![-1i64; self.labels.len()];
        let mut id = 0i64;
        for st in &self.structures {
            for p in &st.parts {
                for &v in &p.vertices {
                    labels[v as usize] = id;
                }
                id += 1;
            }
        }
        for (i, &f) in self.first_occurrence.iter().enumerate() {
            labels[i] = labels[f as usize];
        }
        labels
    }

    /// Number of parts over all structures.
    pub fn num_parts(&self) -> usize {
        self.structures.iter().map(|s| s.parts.len()).sum()
    }
}

/// A point's position as a sort key: its coordinates' bits, −0 taken as 0
/// (the same point to every step; NaN is refused before).
pub(crate) fn position_key(p: &[f64; 3]) -> [u64; 3] {
    p.map(|c| (c + 0.0).to_bits())
}

/// The number of distinct positions among `points` ([`position_key`]).
pub(crate) fn distinct_count(points: &[[f64; 3]]) -> usize {
    let mut keys: Vec<[u64; 3]> = points.iter().map(position_key).collect();
    crate::par::sort_unstable(&mut keys);
    keys.dedup();
    keys.len()
}

#[cfg(test)]
mod tests {
    use super::Simplices;

    #[test]
    fn simplices_are_read_back_as_pushed() {
        let mut s = Simplices::new(3);
        assert!(s.is_empty());
        s.push(&[0, 1, 2]);
        s.push(&[1, 2, 5]);
        assert_eq!((s.len(), s.size()), (2, 3));
        assert_eq!(&s[1], &[1, 2, 5]);
        assert_eq!(s.get(0), Some(&[0u32, 1, 2][..]));
        assert_eq!(s.get(2), None);
        let all: Vec<&[u32]> = s.iter().collect();
        assert_eq!(all, [&[0, 1, 2][..], &[1, 2, 5][..]]);
        for t in s.iter_mut() {
            t[0] += 10;
        }
        assert_eq!(s.as_flat(), [10, 1, 2, 11, 2, 5]);
        assert_eq!(s, Simplices::from_flat(3, vec![10, 1, 2, 11, 2, 5]));
    }

    #[test]
    #[should_panic(expected = "a simplex of another size")]
    fn a_simplex_of_another_size_is_refused() {
        Simplices::new(2).push(&[0, 1, 2]);
    }

    #[test]
    #[should_panic(expected = "not whole simplices")]
    fn a_flat_list_of_part_of_a_simplex_is_refused() {
        Simplices::from_flat(3, vec![0, 1]);
    }
}
