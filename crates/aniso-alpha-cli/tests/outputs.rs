//! Outputs never destroy anything (issue 19 §2): special files, inputs,
//! duplicate outputs, symbolic links, read-only folders, signals.

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use crate::common;
use common::TempDir;

const BIN: &str = env!("CARGO_BIN_EXE_aniso-alpha");

/// The temporary and probe files left in `d` (none, after any run).
fn temps(d: &TempDir) -> Vec<String> {
    std::fs::read_dir(&d.0)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-") || n.contains(".probe-"))
        .collect()
}

const POINTS: &[u8] = b"0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n";

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

fn fails_with(o: &Output, wants: &[&str]) {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    for w in wants {
        assert!(stderr.contains(w), "want {w:?} in {stderr}");
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn an_output_that_is_an_input_is_refused() {
    let d = TempDir::new("out", "same");
    let a = d.file("a.xyz", POINTS);
    let o = run(&["delaunay", s(&a), "--tets", s(&a)]);
    fails_with(&o, &["--tets", "a.xyz", "is the input file"]);
    assert_eq!(std::fs::read(&a).unwrap(), POINTS);
    // Through another spelling and through a hard link.
    let other = d.0.join(".").join("a.xyz");
    fails_with(
        &run(&["delaunay", s(&a), "--tets", s(&other)]),
        &["is the input file"],
    );
    let hard = d.0.join("hard.tets");
    std::fs::hard_link(&a, &hard).unwrap();
    fails_with(
        &run(&["delaunay", s(&a), "--tets", s(&hard)]),
        &["is the input file"],
    );
    assert_eq!(std::fs::read(&a).unwrap(), POINTS);
    assert!(temps(&d).is_empty());
}

#[test]
fn two_outputs_with_one_path_are_refused() {
    let d = TempDir::new("out", "dup");
    let scene = d.0.join("scene.xyz");
    assert_eq!(
        run(&["synth", "lines", "--seed", "1", "--output", s(&scene)])
            .status
            .code(),
        Some(0)
    );
    let out = d.0.join("o.txt");
    let o = run(&[
        "detect",
        s(&scene),
        "--structure",
        "lines",
        "--alpha",
        "1",
        "--lambda3",
        "10",
        "--min-size",
        "4",
        "--labels",
        s(&out),
        "--part-labels",
        s(&d.0.join(".").join("o.txt")),
    ]);
    fails_with(&o, &["--labels and --part-labels name the same file"]);
    assert!(!out.exists());
}

#[cfg(unix)]
#[test]
fn special_files_are_refused_and_kept() {
    use std::os::unix::fs::FileTypeExt;
    let d = TempDir::new("out", "fifo");
    let a = d.file("a.xyz", POINTS);
    let fifo = d.0.join("out.tets");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let o = run(&["delaunay", s(&a), "--tets", s(&fifo)]);
    fails_with(&o, &["out.tets", "FIFO", "not a regular file"]);
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    // Through a symbolic link too.
    let link = d.0.join("link.tets");
    std::os::unix::fs::symlink(&fifo, &link).unwrap();
    fails_with(
        &run(&["delaunay", s(&a), "--tets", s(&link)]),
        &["not a regular file"],
    );
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(temps(&d).is_empty());
}

#[cfg(unix)]
#[test]
fn a_symlinked_output_writes_its_target() {
    let d = TempDir::new("out", "link");
    let a = d.file("a.xyz", POINTS);
    std::fs::create_dir(d.0.join("sub")).unwrap();
    let target = d.0.join("sub").join("real.tets");
    let link = d.0.join("link.tets");
    std::os::unix::fs::symlink("sub/real.tets", &link).unwrap();
    let o = run(&["delaunay", s(&a), "--tets", s(&link)]);
    assert_eq!(o.status.code(), Some(0), "{:?}", o);
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read_to_string(&target).unwrap().lines().count(), 2);
    assert!(temps(&d).is_empty());
}

#[cfg(unix)]
#[test]
fn a_read_only_folder_fails_before_the_work() {
    use std::os::unix::fs::PermissionsExt;
    let d = TempDir::new("out", "ro");
    let ro = d.0.join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root writes into a folder of mode 0555: then take sysfs or procfs,
    // where creating a file is refused even to root (so the check runs in
    // CI's containers too).
    let writable = |dir: &std::path::Path| {
        let probe = dir.join("aniso-alpha-probe");
        let ok = std::fs::write(&probe, b"x").is_ok();
        let _ = std::fs::remove_file(&probe);
        ok
    };
    let folder = if !writable(&ro) {
        ro.clone()
    } else if let Some(p) = ["/sys/kernel", "/proc"]
        .iter()
        .map(std::path::Path::new)
        .find(|p| p.is_dir() && !writable(p))
    {
        p.to_path_buf()
    } else {
        common::tool_missing(
            "a_read_only_folder_fails_before_the_work",
            "no folder here that this user cannot write into",
        );
        return;
    };
    // The input is bad too: the output check must come first.
    let bad = d.file("bad.xyz", b"1 2\n");
    let o = run(&["delaunay", s(&bad), "--tets", s(&folder.join("o.tets"))]);
    let name = folder.file_name().unwrap().to_str().unwrap();
    fails_with(&o, &["cannot write into folder", name]);
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// Starts `synth` with a slow write, waits for its temporary file, sends
/// `signal` and checks that the temporary file is gone.
#[cfg(unix)]
fn interrupted(signal: &str, status: i32) {
    let d = TempDir::new("out", &format!("sig{signal}"));
    let out = d.0.join("scene.xyz");
    let mut child = Command::new(BIN)
        .args(["synth", "lines", "--output", s(&out)])
        .env("ANISO_ALPHA_TEST_WRITE_DELAY_MS", "20000")
        .spawn()
        .unwrap();
    let start = Instant::now();
    while temps(&d).is_empty() {
        assert!(start.elapsed() < Duration::from_secs(60), "no temp file");
        std::thread::sleep(Duration::from_millis(20));
    }
    let killed = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let st = child.wait().unwrap();
    assert_eq!(st.code(), Some(status), "{signal}");
    assert!(temps(&d).is_empty(), "{:?}", temps(&d));
    assert!(!out.exists());
}

#[cfg(unix)]
#[test]
fn sigint_and_sigterm_remove_temporary_files() {
    interrupted("INT", 130);
    interrupted("TERM", 143);
}
