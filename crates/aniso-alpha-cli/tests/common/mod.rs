//! What the CLI's integration tests share: a scratch folder, the
//! library tests' own (one file, included by path).
// Each test binary compiles this module and uses part of it.
#![allow(dead_code)]

#[path = "../../../aniso-alpha/tests/common/tempdir.rs"]
mod tempdir;
#[allow(unused_imports)]
pub use tempdir::TempDir;

#[path = "../../../aniso-alpha/tests/common/tools.rs"]
mod tools;
#[allow(unused_imports)]
pub use tools::{tool_missing, tools_required};
