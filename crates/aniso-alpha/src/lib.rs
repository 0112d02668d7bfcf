//! # aniso-alpha
//!
//! Exact 3D Delaunay tetrahedralization, alpha-shapes, and the anisotropic
//! alpha-shapes of Bougleux, Melkemi & Elmoataz (2005) for finding lines,
//! planes and polyhedral surfaces in noisy point clouds.
//!
//! The crate is layered (see `ARCHITECTURE.md`):
//!
//! * [`geometry`]: exact, filtered predicates (returning a [`Sign`](geometry::Sign))
//!   with the symbolic perturbation that CGAL uses, circumsphere
//!   constructions, and the small linear algebra the crate shares;
//! * [`delaunay`]: the triangulation (flat `u32` arrays, bulk construction,
//!   queries, `validate()`);
//! * [`io`]: point file readers (text, PLY, LAS/LAZ, PCD), atomic writers
//!   (PLY, OBJ, labels) and their typed errors;
//! * [`aniso`]: the anisotropy Q = diag(e)·R (Euler angles, line and plane
//!   ellipsoids) and the exact point transform;
//! * [`detect`]: orientation samplers, the path filter of non-significant
//!   structures, connected components, least-squares line/plane fits;
//! * [`synth`]: deterministic benchmark scenes with ground truth;
//! * [`eval`]: detection scores (precision/recall/F1, structures found);
//! * [`options`]: a detection's options as the CLI and the Python package
//!   take them, checked and built into a [`Detector`] by one builder;
//! * [`alpha`]: alpha-shape intervals of edges and triangles, `F_α`, the
//!   α-shape surface, and the anisotropic complex of `Q·P`;
//!
//! The main types are at the root: [`Triangulation`], [`AlphaComplex`],
//! [`read_points`].
//!
//! ```
//! use aniso_alpha::Triangulation;
//! let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
//! let tri = Triangulation::new(&pts).unwrap();
//! assert_eq!(tri.dimension(), 3);
//! assert_eq!(tri.num_finite_tets(), 2);
//! tri.validate().unwrap();
//! ```
// `unsafe` is denied everywhere but in the Delaunay build: one
// cache-prefetch hint (`delaunay::cell::prefetch`) and the two calls into
// the x86-64-v3 copies of the hot loops, made after run-time feature
// detection (`delaunay::isa`), each documented and tested where it is.
#![deny(unsafe_code)]
#![deny(missing_docs)]
// Index loops over the 4 vertices / faces of a tetrahedron read better than
// iterator chains in the geometry code.
#![allow(clippy::needless_range_loop)]

pub mod alpha;
pub mod aniso;
pub mod delaunay;
pub mod detect;
pub mod eval;
pub mod geometry;
pub mod io;
pub mod options;
mod par;
#[cfg(feature = "json")]
pub mod report;
pub mod rng;
pub mod synth;
mod unionfind;

pub use alpha::AlphaComplex;
pub use delaunay::{DelaunayError, Triangulation};
pub use detect::StructureKind;
pub use detect::{DetectError, Detection, Detector, Given};
pub use io::{read_points, IoError, PointCloud, ReadOptions};
