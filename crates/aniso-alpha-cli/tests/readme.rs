//! Every command of the README runs as written.
//!
//! The commands are the lines of the README's ```sh blocks (a trailing
//! `\` continues a line; `#` starts a comment), run in order by `sh` in one
//! temporary folder holding an empty `docs/`, with `aniso-alpha` the binary
//! under test and `cargo run --release --` mapped to it. The commands
//! that build, install or test the project ([`NOT_RUN`], with the reason)
//! are listed as skipped; any other `cargo` command fails the test (it
//! would rebuild or recurse).
//!
//! A ```text block right after `<!-- output of: CMD -->` must be what CMD
//! prints on stdout, seconds (`1.85 s`) aside. A ```rust block right after
//! `<!-- file: PATH -->` must be that file of the repository, verbatim.

use std::path::{Path, PathBuf};

use crate::common;
use common::TempDir;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_aniso-alpha");

/// README commands this test does not run (matched by their start), and
/// why: each is run elsewhere or would rebuild the project.
const NOT_RUN: &[(&str, &str)] = &[
    ("cargo test --workspace", "it is the test suite"),
    (
        "cargo install --locked --path crates/aniso-alpha-cli",
        "installs into ~/.cargo/bin",
    ),
    (
        "cargo run --release -p aniso-alpha --example detect_file",
        "builds the library's examples; tests/readme_examples.rs runs this one",
    ),
    (
        "pip install ./crates/aniso-alpha-py",
        ".ci/run installs the package in a fresh virtual environment, then runs its tests",
    ),
    (
        "python3 -m venv .venv",
        ".ci/run does this in a fresh virtual environment",
    ),
    (
        ".venv/bin/",
        "the Python package's commands: .ci/run runs its tests and its README snippets (tests/test_readme.py)",
    ),
];

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The README's scratch folder: an empty `docs/`, and `aniso-alpha` on
/// the PATH as `.bin/aniso-alpha` (the binary under test).
fn readme_dir(name: &str) -> TempDir {
    let d = TempDir::new("readme", name);
    std::fs::create_dir_all(d.path("docs")).unwrap();
    let bin = d.path(".bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(BIN, bin.join("aniso-alpha")).unwrap();
    d
}

/// A fenced block of the README.
struct Block {
    info: String,
    /// The last non-blank line before the fence.
    before: String,
    body: String,
    line: usize,
}

fn blocks(readme: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut before = String::new();
    let mut open: Option<Block> = None;
    for (i, line) in readme.lines().enumerate() {
        let fence = line.trim_start().starts_with("```");
        match &mut open {
            Some(_) if fence => out.extend(open.take()),
            Some(b) => {
                b.body.push_str(line);
                b.body.push('\n');
            }
            None if fence => {
                open = Some(Block {
                    info: line.trim_start()[3..].trim().to_string(),
                    before: before.clone(),
                    body: String::new(),
                    line: i + 1,
                });
            }
            None => {
                if !line.trim().is_empty() {
                    before = line.trim().to_string();
                }
            }
        }
    }
    assert!(open.is_none(), "README: unclosed code block");
    out
}

/// The commands of a sh block: continuations joined, comments dropped;
/// `Err(reason)` for a command marked as not run.
fn commands(body: &str) -> Vec<Result<String, (String, String)>> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for line in body.lines() {
        let t = line.trim();
        if let Some(head) = t.strip_suffix('\\') {
            cur.push_str(head);
            cur.push(' ');
            continue;
        }
        cur.push_str(t);
        let logical = std::mem::take(&mut cur);
        let logical = logical.trim();
        if logical.is_empty() || logical.starts_with('#') {
            continue;
        }
        let command = match logical.find(" #") {
            Some(k) => logical[..k].trim_end(),
            None => logical,
        };
        match NOT_RUN.iter().find(|(start, _)| command.starts_with(start)) {
            Some((_, why)) => out.push(Err((command.to_string(), why.to_string()))),
            None => out.push(Ok(command.to_string())),
        }
    }
    out
}

/// `cargo run --release --` is the binary; other cargo commands must be
/// marked as not run.
fn map(command: &str) -> Result<String, String> {
    let words: Vec<&str> = command.split_whitespace().collect();
    if words.starts_with(&["cargo", "run", "--release", "--"]) {
        return Ok(format!("aniso-alpha {}", words[4..].join(" ")));
    }
    if words.first() == Some(&"cargo") {
        return Err(format!(
            "README command `{command}` runs cargo: list it in NOT_RUN with why, or use aniso-alpha"
        ));
    }
    Ok(command.to_string())
}

fn sh(dir: &Path, command: &str) -> std::process::Output {
    let path = format!(
        "{}:{}",
        dir.join(".bin").display(),
        std::env::var("PATH").unwrap_or_default()
    );
    Command::new("sh")
        .arg("-c")
        .arg(command)
        .current_dir(dir)
        .env("PATH", path)
        .output()
        .unwrap()
}

/// Seconds are not repeatable: every number directly followed by ` s`
/// becomes `#`.
fn without_seconds(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < chars.len() {
        if chars[i].is_ascii_digit() && (i == 0 || !chars[i - 1].is_alphanumeric()) {
            let mut j = i;
            while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
                j += 1;
            }
            let unit = chars.get(j) == Some(&' ')
                && chars.get(j + 1) == Some(&'s')
                && chars.get(j + 2).is_none_or(|c| !c.is_alphanumeric());
            if unit {
                out.push('#');
                i = j;
                continue;
            }
        }
        out.push(chars[i]);
        i += 1;
    }
    out
}

/// What running a README gave.
#[derive(Debug, Default)]
struct Report {
    run: Vec<String>,
    skipped: Vec<(String, String)>,
    outputs_checked: usize,
    files_checked: usize,
}

/// Runs every command and checks every output and file block of `readme`
/// in `dir`; the first failure is the error.
fn check_readme(readme: &str, dir: &Path) -> Result<Report, String> {
    let mut report = Report::default();
    // What each command run so far printed: an output block of a command
    // already run is checked against that run.
    let mut printed: Vec<(String, std::process::Output)> = Vec::new();
    for b in blocks(readme) {
        match b.info.as_str() {
            "sh" => {
                for c in commands(&b.body) {
                    let command = match c {
                        Ok(c) => c,
                        Err(skip) => {
                            report.skipped.push(skip);
                            continue;
                        }
                    };
                    let mapped = map(&command)?;
                    let o = sh(dir, &mapped);
                    if !o.status.success() {
                        return Err(format!(
                            "README line {}: `{command}` failed ({}):\n{}{}",
                            b.line,
                            o.status,
                            String::from_utf8_lossy(&o.stdout),
                            String::from_utf8_lossy(&o.stderr)
                        ));
                    }
                    report.run.push(command.clone());
                    printed.push((mapped, o));
                }
            }
            "text" => {
                let Some(cmd) = b
                    .before
                    .strip_prefix("<!-- output of:")
                    .and_then(|r| r.strip_suffix("-->"))
                else {
                    continue;
                };
                let cmd = cmd.trim();
                let mapped = map(cmd)?;
                let o = match printed.iter().rev().find(|(c, _)| *c == mapped) {
                    Some((_, o)) => o.clone(),
                    None => sh(dir, &mapped),
                };
                if !o.status.success() {
                    return Err(format!(
                        "README line {}: `{cmd}` failed: {}",
                        b.line,
                        String::from_utf8_lossy(&o.stderr)
                    ));
                }
                let got = without_seconds(&String::from_utf8_lossy(&o.stdout));
                let want = without_seconds(&b.body);
                if got.trim_end() != want.trim_end() {
                    return Err(format!(
                        "README line {}: the output of `{cmd}` differs from the README's block.\n\
--- README\n{want}--- printed\n{got}",
                        b.line
                    ));
                }
                report.outputs_checked += 1;
            }
            _ => {
                let Some(path) = b
                    .before
                    .strip_prefix("<!-- file:")
                    .and_then(|r| r.strip_suffix("-->"))
                else {
                    continue;
                };
                let path = repo().join(path.trim());
                let file = std::fs::read_to_string(&path)
                    .map_err(|e| format!("README line {}: {}: {e}", b.line, path.display()))?;
                if file.trim_end() != b.body.trim_end() {
                    return Err(format!(
                        "README line {}: the block is not {} as it is now",
                        b.line,
                        path.display()
                    ));
                }
                report.files_checked += 1;
            }
        }
    }
    Ok(report)
}

#[test]
fn every_readme_command_runs_as_written() {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let dir = readme_dir("run");
    let report = check_readme(&readme, &dir.0).unwrap_or_else(|e| panic!("{e}"));
    eprintln!(
        "README: {} commands run, {} output block(s) and {} file block(s) checked, {} skipped:",
        report.run.len(),
        report.outputs_checked,
        report.files_checked,
        report.skipped.len()
    );
    for (c, why) in &report.skipped {
        eprintln!("  SKIPPED `{c}`: {why}");
    }
    // The README has a few dozen commands, its sample output and its
    // library example; exceptions stay rare.
    assert!(report.run.len() >= 15, "{report:?}");
    assert!(report.outputs_checked >= 1, "{report:?}");
    assert!(report.files_checked >= 1, "{report:?}");
    assert!(report.skipped.len() <= 8, "{report:?}");
    assert!(report.skipped.iter().all(|(_, why)| !why.is_empty()));
}

/// The checks fail where they should: a failing command, a stale output
/// block, a stale file block, an unmarked cargo command.
#[test]
fn the_readme_check_can_fail() {
    let dir = readme_dir("fail");
    let fence = "```";
    let bad_command = format!("{fence}sh\naniso-alpha synth circles --output x.xyz\n{fence}\n");
    let e = check_readme(&bad_command, &dir.0).unwrap_err();
    assert!(e.contains("synth circles"), "{e}");
    let bad_output = format!(
        "{fence}sh\naniso-alpha synth lines --output l.xyz\n{fence}\n\
<!-- output of: aniso-alpha eval --truth l.xyz --labels l.txt -->\n{fence}text\nnothing\n{fence}\n"
    );
    std::fs::write(dir.0.join("l.txt"), "-1\n".repeat(1550)).unwrap();
    let e = check_readme(&bad_output, &dir.0).unwrap_err();
    assert!(e.contains("differs"), "{e}");
    let bad_file =
        format!("<!-- file: crates/aniso-alpha/examples/detect_file.rs -->\n{fence}rust\nfn main() {{}}\n{fence}\n");
    assert!(check_readme(&bad_file, &dir.0).unwrap_err().contains("not"));
    let cargo = format!("{fence}sh\ncargo build\n{fence}\n");
    assert!(check_readme(&cargo, &dir.0)
        .unwrap_err()
        .contains("runs cargo"));
    let skipped = format!("{fence}sh\ncargo test --workspace   # the tests\n{fence}\n");
    let r = check_readme(&skipped, &dir.0).unwrap();
    assert_eq!(
        r.skipped,
        vec![(
            "cargo test --workspace".to_string(),
            "it is the test suite".to_string()
        )]
    );
    assert_eq!(
        without_seconds("  1944 orientations in 1.85 s; union 3 s\nv2 s"),
        "  1944 orientations in # s; union # s\nv2 s"
    );
}
