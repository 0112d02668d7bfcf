//! Structure detection (paper §4, docs/method.md §4): [`Detector`] and its
//! result [`Detection`], the split run of [`Plan`] and [`Step`], and the
//! building blocks a user may call alone.
//!
//! Public building blocks:
//!
//! * [`orientations`]: the paper's "box" sampler of rotations and a
//!   near-uniform Fibonacci alternative (docs/method.md §4);
//! * [`filter`]: the path filter (docs/method.md §3) and connected components;
//! * [`fit`]: least-squares lines and planes;
//! * [`parts`]: splitting structures into straight/flat parts, and point
//!   labelling;
//! * [`significance`]: the a-contrario test's numbers of false alarms;
//! * [`local`], [`modes`], [`estimate`]: the local shape of the cloud, the
//!   modes of its normals or directions, and the parameters and data
//!   orientation set estimated from them (method doc §8);
//! * [`quantized`]: coordinates stored in steps coarser than a point's
//!   neighbourhood (a depth camera's), and the points moved within their
//!   step before a run (method doc §8).
//!
//! The pipeline (private; its types are re-exported here):
//!
//! * `detector`: the parameters ([`Detector`], [`DetectError`],
//!   [`OrientationSet`]) and the run that chains the steps;
//! * `regime`: the run-wide modes, decided once per run (lines or planes,
//!   the significance test, orientations from a sampler or the data,
//!   normals gating the claims);
//! * `cloud`: what a run knows of its cloud, worked out once (copies, the
//!   background's volume, the kd-tree of the distinct points);
//! * `scan`: the orientation scan (per orientation `F_{k,α,Q}` with `faces`
//!   after `prune`, tiles with halos, the path filter and its thresholds,
//!   the union);
//! * `assemble`: structures and disjoint parts from the union, stage by
//!   stage, with `outline` (outlines and meshes of planar parts);
//! * `detection`: the result types ([`Detection`], [`Structure`],
//!   [`Part`], [`Primitive`], [`RunStats`]);
//! * `split`: the same run split into per-tile steps that can run
//!   elsewhere (other processes or machines), and the step that gathers
//!   them ([`Plan`], [`Step`], [`SplitJob`], [`Members`], [`Tile`],
//!   [`TileOutput`]).

// The pipeline's types, flat: `aniso_alpha::detect::{Detector, Part, …}`
// (the main ones also at the crate root).
pub use detection::{Detection, Part, Primitive, RunStats, Simplices, Structure};
pub use detector::{DetectError, Detector, Mat3, OrientationSet, LAMBDA_RANGE};
pub use estimate::{Estimate, Given, GivenNormals, Ladder, ModeScan, Param};
pub use fit::{LineFit, PlaneFit};
pub use orientations::{OrientationError, Sampler, MAX_ORIENTATIONS};
pub use split::{Members, Plan, SplitJob, Step, Tile, TileOutput};
pub use stages::Stage;

mod assemble;
mod cloud;
mod detection;
mod detector;
pub mod estimate;
mod faces;
pub mod filter;
pub mod fit;
pub mod local;
pub mod modes;
pub mod orientations;
mod outline;
pub mod parts;
mod prune;
pub mod quantized;
mod regime;
pub mod regions;
mod scan;
pub mod significance;
mod split;
mod stages;

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

    /// What a point of such a structure looks like locally: "planar" or
    /// "linear" (the words of the summary and the warnings).
    pub fn locally(self) -> &'static str {
        match self {
            Self::Lines => "linear",
            Self::Planes => "planar",
        }
    }

    /// The points over which the estimate's shares (structure-like,
    /// explained by the modes) are counted: all of them for planes, those
    /// not on a surface for lines (the words of the warnings).
    pub fn counted_points(self) -> &'static str {
        match self {
            Self::Lines => "the points not on a surface",
            Self::Planes => "the points",
        }
    }
}
