//! Structure detection building blocks (paper §4): orientation sets,
//! the path filter of non-significant structures, and least-squares fits.
//!
//! * [`orientations`]: the paper's "box" sampler of rotations and a
//!   near-uniform Fibonacci alternative (docs/method.md §4);
//! * [`filter`]: the path filter (docs/method.md §3) and connected components;
//! * [`fit`]: least-squares lines and planes;
//! * [`parts`]: splitting structures into straight/flat parts, and point
//!   labelling;
//! * [`faces`]: `F_{k,α}` at one α straight from a triangulation;
//! * [`prune`]: exact removal of points isolated at distance 2α;
//! * [`local`], [`modes`], [`estimate`]: the local shape of the cloud, the
//!   modes of its normals or directions, and the parameters and data
//!   orientation set estimated from them (method doc §8);
//! * `scan`: the orientation scan (per orientation `F_{k,α,Q}`, tiles with
//!   halos, path filter, union);
//! * `assemble`: structures and disjoint parts from the union, with
//!   [`outline`] (outlines and meshes of planar parts) and [`significance`]
//!   (the a-contrario test);
//! * `detection`: the result types ([`Detection`], [`Structure`],
//!   [`Part`], [`Primitive`], [`RunStats`]);
//! * `detector`: the parameters and the run that chains the steps
//!   ([`Detector`], [`DetectError`], [`OrientationSet`]);
//! * `split`: the same run split into per-tile steps that can run
//!   elsewhere (other processes or machines), and the step that gathers
//!   them ([`Plan`], [`Step`], [`SplitJob`], [`Members`], [`Tile`],
//!   [`TileOutput`]).
//!
//! The pipeline's modules (`detector`, `detection`, `split`, `scan`,
//! `assemble`) are private; their types are re-exported here.

mod assemble;
// The pipeline's types, flat: `aniso_alpha::detect::{Detector, Part, …}`
// (the main ones also at the crate root).
pub use detection::{Detection, Part, Primitive, RunStats, Structure};
pub use detector::{DetectError, Detector, Mat3, OrientationSet, LAMBDA_RANGE};
pub use estimate::{Estimate, Given, GivenNormals, ModeScan, Param};
pub use split::{Members, Plan, SplitJob, Step, Tile, TileOutput};
mod detection;
mod detector;
pub mod estimate;
pub mod faces;
pub mod filter;
pub mod fit;
pub mod local;
pub mod modes;
pub mod orientations;
pub mod outline;
pub mod parts;
pub mod prune;
mod scan;
pub mod significance;
mod split;

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
