//! The library's integration tests, one test binary: each file of this
//! folder is a module here (a binary per file cost a link and a copy of
//! the library's generic code each). `cargo test -p aniso-alpha --test
//! library MODULE::` runs one file's tests. The files that need a cargo
//! feature are test binaries of their own with `required-features`
//! (`io_e57`, `io_fuzz_regressions`), so that without the feature they
//! are not built rather than built empty; `las_range` is a module here
//! only with the `las` feature (the workspace's tests have it).

mod alpha_common;
mod common;

#[path = "alpha_fixtures.rs"]
mod alpha_fixtures;
#[path = "alpha_oracle.rs"]
mod alpha_oracle;
#[path = "alpha_props.rs"]
mod alpha_props;
#[path = "alpha_surface.rs"]
mod alpha_surface;
#[path = "aniso_transform.rs"]
mod aniso_transform;
#[path = "delaunay_fixtures.rs"]
mod delaunay_fixtures;
#[path = "delaunay_props.rs"]
mod delaunay_props;
#[path = "detect_degenerate.rs"]
mod detect_degenerate;
#[path = "detect_no_flag.rs"]
mod detect_no_flag;
#[path = "detect_robustness.rs"]
mod detect_robustness;
#[path = "detect_scenes.rs"]
mod detect_scenes;
#[path = "io_attributes.rs"]
mod io_attributes;
#[path = "io_formats.rs"]
mod io_formats;
#[path = "io_never_panics.rs"]
mod io_never_panics;
#[cfg(feature = "las")]
#[path = "las_range.rs"]
mod las_range;
#[path = "lines_pipeline_bruteforce.rs"]
mod lines_pipeline_bruteforce;
#[path = "normals.rs"]
mod normals;
#[path = "planes_pipeline_bruteforce.rs"]
mod planes_pipeline_bruteforce;
#[path = "readme_examples.rs"]
mod readme_examples;
#[path = "real_scans.rs"]
mod real_scans;
