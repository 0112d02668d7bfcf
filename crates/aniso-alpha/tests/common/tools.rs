//! Tests that need a tool the project does not build (a browser, a Python
//! with laspy, a folder this user cannot write into): the rule they all
//! follow. Without the tool, a test says what is missing on stderr and
//! checks nothing more, so that a newcomer's `cargo test --workspace`
//! passes; under `ANISO_ALPHA_CI=1` (set by `.ci/run`, which installs
//! every tool) a missing tool fails the test instead, so that CI never
//! passes a test that checked nothing.

/// Whether a missing tool fails the test: `ANISO_ALPHA_CI` is set and not
/// `0`.
pub fn tools_required() -> bool {
    std::env::var_os("ANISO_ALPHA_CI").is_some_and(|v| !v.is_empty() && v != "0")
}

/// Reports that `test` cannot run because of `why`: a panic under
/// `ANISO_ALPHA_CI`, else a line on stderr. The caller returns after it.
pub fn tool_missing(test: &str, why: &str) {
    assert!(
        !tools_required(),
        "{test}: {why} (ANISO_ALPHA_CI is set: a test whose tool is missing fails)"
    );
    eprintln!("SKIPPED {test}: {why} (under ANISO_ALPHA_CI=1 this fails)");
}
