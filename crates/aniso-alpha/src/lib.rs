//! # aniso-alpha
//!
//! Exact 3D Delaunay tetrahedralization, alpha-shapes, and the anisotropic
//! alpha-shapes of Bougleux, Melkemi & Elmoataz (2005) for finding lines,
//! planes and polyhedral surfaces in noisy point clouds.
//!
//! The crate is layered (see `ARCHITECTURE.md`):
//!
//! * [`geometry`]: exact, filtered predicates with the symbolic perturbation
//!   that CGAL uses, and circumsphere constructions;
//! * [`delaunay`]: the triangulation (flat `u32` arrays, bulk construction,
//!   queries, `validate()`);
//! * [`alpha`]: alpha-shape intervals of edges and triangles, `F_α`, the
//!   α-shape surface, and the anisotropic complex of `Q·P`;
//!
//! ```
//! use aniso_alpha::delaunay::Triangulation;
//! let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
//! let tri = Triangulation::new(&pts).unwrap();
//! assert_eq!(tri.dimension(), 3);
//! assert_eq!(tri.num_finite_tets(), 2);
//! tri.validate().unwrap();
//! ```
#![forbid(unsafe_code)]
#![deny(missing_docs)]
// Index loops over the 4 vertices / faces of a tetrahedron read better than
// iterator chains in the geometry code.
#![allow(clippy::needless_range_loop)]

pub mod alpha;
pub mod delaunay;
pub mod geometry;
