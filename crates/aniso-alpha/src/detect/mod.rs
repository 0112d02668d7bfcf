//! Structure detection building blocks (paper §4): orientation sets,
//! the path filter of non-significant structures, and least-squares fits.
//!
//! * [`orientations`]: the paper's "box" sampler of rotations and a
//!   near-uniform Fibonacci alternative (SPEC §4);
//! * [`filter`]: the path filter (SPEC §3) and connected components;
//! * [`fit`]: least-squares lines and planes;
//! * [`parts`]: splitting structures into straight/flat parts, and point
//!   labelling;
//! * [`faces`]: `F_{k,α}` at one α straight from a triangulation;
//! * [`prune`]: exact removal of points isolated at distance 2α;
//! * [`detector`]: the whole §4 pipeline over many orientations.

pub mod detector;
pub mod faces;
pub mod filter;
pub mod fit;
pub mod local;
pub mod modes;
pub mod orientations;
pub mod parts;
pub mod prune;

/// Which structures are sought: k = 1 (lines, edges) or k = 2 (planes,
/// triangles).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StructureKind {
    /// k = 1: linear structures, found as edges; E = (1, 1, 1/λ₃).
    Lines,
    /// k = 2: planar structures, found as triangles; E = (1, 1/λ₂, 1/λ₃).
    Planes,
}

impl StructureKind {
    /// The simplex dimension k (1 or 2).
    pub fn k(self) -> usize {
        match self {
            Self::Lines => 1,
            Self::Planes => 2,
        }
    }
}
