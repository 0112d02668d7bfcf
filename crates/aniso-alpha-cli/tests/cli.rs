//! The CLI's integration tests, one test binary: each file of this folder
//! is a module here (a binary per file cost a link each). `cargo test -p
//! aniso-alpha-cli --test cli MODULE::` runs one file's tests.

mod common;

#[path = "attributes_roundtrip.rs"]
mod attributes_roundtrip;
#[path = "bad_input.rs"]
mod bad_input;
#[path = "end_to_end.rs"]
mod end_to_end;
#[path = "outputs.rs"]
mod outputs;
#[path = "readme.rs"]
mod readme;
#[path = "regions.rs"]
mod regions;
#[path = "viewer.rs"]
mod viewer;
