//! Malformed input through the built binary: exit status 1, one line on
//! stderr naming the file (and line for text), no panic, no output file.

use std::path::Path;
use std::process::{Command, Output};

use crate::common;
use common::TempDir;

const BIN: &str = env!("CARGO_BIN_EXE_aniso-alpha");

fn run(args: &[&Path]) -> Output {
    Command::new(BIN)
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .output()
        .unwrap()
}

/// Runs `delaunay input --tets out` and checks the error contract.
/// `wants` are fragments the single stderr line must contain.
fn expect_error(dir: &TempDir, input: &Path, out: &Path, wants: &[&str]) {
    let o = run(&[Path::new("delaunay"), input, Path::new("--tets"), out]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "stderr: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "stderr: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!stderr.contains("internal error"), "{stderr}");
    for w in wants {
        assert!(stderr.contains(w), "want {w:?} in {stderr}");
    }
    assert!(o.stdout.is_empty());
    assert!(!out.exists(), "output {} exists", out.display());
    // No temporary file left behind either.
    let leftovers: Vec<_> = std::fs::read_dir(&dir.0)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

fn ply_header(format: &str, n: usize) -> Vec<u8> {
    format!(
        "ply\nformat {format} 1.0\nelement vertex {n}\nproperty double x\nproperty double y\nproperty double z\nend_header\n"
    )
    .into_bytes()
}

fn binary_ply(header_count: usize, written: usize) -> Vec<u8> {
    let mut b = ply_header("binary_little_endian", header_count);
    for i in 0..written {
        for c in [i as f64, 1.0, 2.0] {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    b
}

#[test]
fn malformed_text_inputs() {
    let d = TempDir::new("cli", "text");
    let out = d.0.join("out.tets");
    let cases: [(&str, &[u8], &[&str]); 7] = [
        ("empty.xyz", b"", &["empty.xyz", "no points"]),
        (
            "comments.xyz",
            b"# only a comment\n\nx y z\n# more\n",
            &["comments.xyz", "no points"],
        ),
        (
            "nan.xyz",
            b"0 0 0\n1 1 1\n1 NaN 0\n",
            &["nan.xyz:3:", "non-finite"],
        ),
        ("inf.csv", b"x,y,z\n0,0,inf\n", &["inf.csv:2:", "non-finite"]),
        (
            "short.txt",
            b"0 0 0\n0 1 0\n# c\n1 1\n",
            &["short.txt:4:", "expected 3 numeric columns, found 2"],
        ),
        (
            "word.pts",
            b"0 0 0\n1 one 0\n",
            &["word.pts:2:", "invalid number 'one'"],
        ),
        (
            "ascii_lie.ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 1 1\n",
            &["ascii_lie.ply:10:", "declares 3 entries, found 2"],
        ),
    ];
    for (name, bytes, wants) in cases {
        let input = d.file(name, bytes);
        expect_error(&d, &input, &out, wants);
    }
}

#[test]
fn malformed_binary_inputs() {
    let d = TempDir::new("cli", "binary");
    let out = d.0.join("out.tets");
    let mut truncated = binary_ply(4, 4);
    truncated.truncate(truncated.len() - 5);
    let cases: Vec<(&str, Vec<u8>, &[&str])> = vec![
        ("truncated.ply", truncated, &["truncated.ply", "truncated"]),
        ("lie.ply", binary_ply(10, 4), &["lie.ply", "declares 10"]),
        (
            "big_lie.ply",
            ply_header("binary_big_endian", 1 << 40),
            &["big_lie.ply", "truncated"],
        ),
        (
            "noz.ply",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n"
                .to_vec(),
            &["noz.ply", "no property 'z'"],
        ),
        ("empty.ply", Vec::new(), &["empty.ply", "not a PLY file"]),
        (
            "empty.pcd",
            b"FIELDS x y z\nPOINTS 2\nDATA binary\n".to_vec(),
            &["empty.pcd", "truncated"],
        ),
        ("junk.las", b"LASF but not really".to_vec(), &["junk.las"]),
    ];
    for (name, bytes, wants) in cases {
        let input = d.file(name, &bytes);
        expect_error(&d, &input, &out, wants);
    }
}

#[test]
fn bad_paths() {
    let d = TempDir::new("cli", "paths");
    let out = d.0.join("out.tets");
    let good = d.file("good.xyz", b"0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
    let unknown = d.file("points.e58", b"0 0 0\n");
    expect_error(
        &d,
        &unknown,
        &out,
        &["points.e58", "unknown file extension"],
    );
    expect_error(
        &d,
        &d.0.join("missing.xyz"),
        &out,
        &["missing.xyz", "cannot read"],
    );
    let sub = d.0.join("folder.xyz");
    std::fs::create_dir(&sub).unwrap();
    expect_error(&d, &sub, &out, &["folder.xyz", "is a directory"]);
    let missing_dir = d.0.join("no_such_dir");
    expect_error(
        &d,
        &good,
        &missing_dir.join("out.tets"),
        &["no_such_dir", "does not exist"],
    );
    assert!(!missing_dir.exists());
    // Output path that is a directory: refused, the directory untouched.
    let o = run(&[Path::new("delaunay"), &good, Path::new("--tets"), &sub]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("folder.xyz: is a directory"), "{stderr}");
    assert!(sub.is_dir());
}

#[test]
fn valid_input_gets_past_reading() {
    let d = TempDir::new("cli", "valid");
    let out = d.0.join("out.tets");
    let input = d.file("good.xyz", b"0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
    let o = run(&[Path::new("delaunay"), &input, Path::new("--tets"), &out]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    // One positively oriented tet: (0, 1, 2, 3) up to an even permutation.
    let tets = std::fs::read_to_string(&out).unwrap();
    let t: Vec<u32> = tets
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(t.len(), 4, "{tets}");
    let inversions = (0..4)
        .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
        .filter(|&(i, j)| t[i] > t[j])
        .count();
    assert_eq!(inversions % 2, 0, "{tets}");
}

#[test]
fn bad_usage_exits_2() {
    for args in [
        &["delaunay", "--no-such-flag"][..],
        &["delaunay", "in.xyz"],
        &["frobnicate"],
        &["detect", "in.xyz", "--alpha", "1"],
        &["detect", "--structure", "circles"],
        &[
            "alpha",
            "in.xyz",
            "--intervals",
            "o.csv",
            "--elongation",
            "1,0,1",
        ],
        &["alpha", "in.xyz", "--output", "s.ply"],
        &["delaunay", "in.xyz", "--tets", "o", "--threads", "0"],
    ] {
        let o = Command::new(BIN).args(args).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}");
    }
    // `alpha --alpha A` alone asks for an output of the shape, nothing else.
    let o = Command::new(BIN)
        .args(["alpha", "in.xyz", "--alpha", "1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    let missing = err.lines().nth(1).unwrap_or_default();
    assert!(
        missing.contains("--output") && missing.contains("--png"),
        "{err}"
    );
    assert!(!missing.contains("--intervals"), "{err}");
    // No --threads where it would do nothing.
    for sub in ["synth", "eval", "view"] {
        let o = Command::new(BIN)
            .args([sub, "--threads", "2", "--help"])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{sub} --threads");
    }
    let o = Command::new(BIN)
        .args(["delaunay", "--help"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&o.stdout).contains("Example"));
}

#[test]
fn timings_are_json_on_success_only() {
    // With an error, stderr keeps its single line even with --timings.
    let d = TempDir::new("cli", "timings");
    let input = d.file("bad.xyz", b"1 2\n");
    let o = run(&[
        Path::new("delaunay"),
        &input,
        Path::new("--tets"),
        &d.0.join("o.tets"),
        Path::new("--timings"),
        Path::new("--quiet"),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&o.stderr).lines().count(), 1);
}

#[test]
fn coordinates_beyond_exact_arithmetic() {
    let d = TempDir::new("cli", "range");
    let out = d.0.join("out.tets");
    let huge = d.file("huge.xyz", b"0 0 0\n1 0 0\n0 1 0\n0 0 1e200\n");
    expect_error(&d, &huge, &out, &["huge.xyz", "point 3", "rescale"]);
    let tiny = d.file(
        "tiny.xyz",
        b"1e-300 0 0\n0 1e-300 0\n0 0 1e-300\n1e-300 1e-300 1e-300\n",
    );
    expect_error(&d, &tiny, &out, &["tiny.xyz", "point 0", "rescale"]);
}

/// Issue 19 §4: text that used to be misread silently.
#[test]
fn misread_text_is_an_error() {
    let d = TempDir::new("cli", "misread");
    let out = d.0.join("out.tets");
    let utf16: Vec<u8> = "\u{feff}0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
        .encode_utf16()
        .flat_map(|u| u.to_le_bytes())
        .collect();
    let cases: Vec<(&str, Vec<u8>, &[&str])> = vec![
        (
            "euro.xyz",
            b"0,0 0,0 0,0\n1,5 2,5 3,5\n".to_vec(),
            &["euro.xyz:1:", "ambiguous comma", "decimal"],
        ),
        (
            "thousands.csv",
            b"x,y,z\n1,234.5,2,000.0,3.0\n".to_vec(),
            &[
                "thousands.csv:2:",
                "5 comma-separated fields where line 1 has 3",
            ],
        ),
        (
            "minus.xyz",
            "\u{2212}1 0 0\n1 0 0\n0 1 0\n0 0 1\n".as_bytes().to_vec(),
            &["minus.xyz:1:", "Unicode minus"],
        ),
        ("utf16.xyz", utf16, &["utf16.xyz", "UTF-16"]),
    ];
    for (name, bytes, wants) in cases {
        let input = d.file(name, &bytes);
        expect_error(&d, &input, &out, wants);
    }
}

#[test]
fn header_guess_warns_unless_quiet() {
    let d = TempDir::new("cli", "header");
    let out = d.0.join("out.tets");
    let input = d.file("h.xyz", b"X Y Z\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
    let o = run(&[Path::new("delaunay"), &input, Path::new("--tets"), &out]);
    assert_eq!(o.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("warning: ") && stderr.contains("h.xyz: line 1 taken as a header: 'X Y Z'"),
        "{stderr}"
    );
    let o = run(&[
        Path::new("delaunay"),
        &input,
        Path::new("--tets"),
        &out,
        Path::new("--quiet"),
    ]);
    assert_eq!(o.status.code(), Some(0));
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn stdin_and_format_override() {
    use std::io::Write;
    let d = TempDir::new("cli", "stdin");
    let out = d.0.join("out.tets");
    let mut child = Command::new(BIN)
        .args(["delaunay", "-", "--tets"])
        .arg(&out)
        .stdin(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(b"0 0 0\n1 0 0\n0 1 0\n0 0 1\n")
        .unwrap();
    let o = child.wait_with_output().unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap().lines().count(), 1);
    // An unknown extension read as text with --format.
    let dat = d.file("points.dat", b"0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
    let o = run(&[Path::new("delaunay"), &dat, Path::new("--tets"), &out]);
    assert_eq!(o.status.code(), Some(1));
    let o = run(&[
        Path::new("delaunay"),
        &dat,
        Path::new("--tets"),
        &out,
        Path::new("--format"),
        Path::new("xyz"),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = Command::new(BIN)
        .args(["delaunay", "x", "--tets", "y", "--format", "e58"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// Issue 19 §3: parameters whose size or range cannot work.
#[test]
fn huge_m2_is_a_clear_error() {
    let d = TempDir::new("cli", "m2");
    let input = d.file("p.xyz", b"0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
    let o = Command::new(BIN)
        .arg("detect")
        .arg(&input)
        .args([
            "--structure",
            "planes",
            "--alpha",
            "1",
            "--lambda3",
            "8",
            "--min-size",
            "20",
            "--m2",
            "100000000",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("--m2 100000000") && stderr.contains("orientations"),
        "{stderr}"
    );
}

/// Regression (issue 19): the triangulation's out-of-range error was
/// swallowed and the run exited 0 with no structure.
#[test]
fn out_of_range_lambda3_names_the_parameter() {
    let d = TempDir::new("cli", "lambda3");
    let scene = d.0.join("s.xyz");
    let o = Command::new(BIN)
        .args(["synth", "lines", "--seed", "1", "--output"])
        .arg(&scene)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    for l3 in ["1e300", "1e-60"] {
        let o = Command::new(BIN)
            .arg("detect")
            .arg(&scene)
            .args([
                "--structure",
                "lines",
                "--alpha",
                "1",
                "--min-size",
                "4",
                "--lambda3",
                l3,
            ])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "--lambda3 {l3}: {stderr}");
        assert!(stderr.contains("lambda3"), "--lambda3 {l3}: {stderr}");
    }
}

/// points × orientations over 2e9: a warning with the estimate before the
/// run (`cmd_detect::warn_if_huge`). 3,000 copies of 3 points and
/// `--m2 6000` (162 × 6,000 = 972,000 orientations, under the limit of
/// 1,000,000): 2.9e9. The run itself would take long: the test stops it
/// once the warning is out.
#[test]
fn huge_run_warns_before_it_starts() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let d = TempDir::new("cli", "huge");
    let input = d.file("dups.xyz", "0 0 0\n1 0 0\n0 1 0\n".repeat(1000).as_bytes());
    let mut child = Command::new(BIN)
        .arg("detect")
        .arg(&input)
        .args([
            "--structure",
            "planes",
            "--alpha",
            "1",
            "--lambda2",
            "4",
            "--lambda3",
            "8",
            "--min-size",
            "20",
            "--m2",
            "6000",
            "--threads",
            "1",
            "--labels",
        ])
        .arg(d.path("labels.txt"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut warning = None;
    let mut seen = Vec::new();
    for line in BufReader::new(child.stderr.take().unwrap()).lines() {
        let line = line.unwrap();
        if line.starts_with("warning: a large run") {
            warning = Some(line);
            break;
        }
        seen.push(line);
        if seen.len() > 50 {
            break;
        }
    }
    // Stops the run (if it is still going: it must not have finished).
    let _ = child.kill();
    let status = child.wait().unwrap();
    let warning = warning.unwrap_or_else(|| panic!("no warning; stderr: {seen:?}"));
    assert!(
        warning.contains("3000 points × 972000 orientations = 2.92e9"),
        "{warning}"
    );
    assert!(warning.contains("(--m1, --m2)"), "{warning}");
    assert!(!status.success());
    // Stopped before the end: no labels file, complete or partial.
    assert!(!d.path("labels.txt").exists());
}
