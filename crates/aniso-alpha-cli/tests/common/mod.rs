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

/// One integer per line (a `--labels` or `--part-labels` file).
pub fn read_ints(path: &std::path::Path) -> Vec<i64> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect()
}
