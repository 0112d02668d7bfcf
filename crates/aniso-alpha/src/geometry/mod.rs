//! Geometry: exact predicates (with the symbolic perturbation that settles
//! ties) and floating-point constructions (circumspheres).
//!
//! Nothing here knows about triangulation topology.

pub mod circum;
pub mod predicates;

pub use predicates::Point3;
