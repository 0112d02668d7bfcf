//! `detect --regions`: the detection region by region, its outputs, the
//! outputs it refuses, and `off`.

use std::path::Path;
use std::process::{Command, Output};

use crate::common;
use aniso_alpha::rng::SplitMix64;
use common::{read_ints as ints, TempDir};

const BIN: &str = env!("CARGO_BIN_EXE_aniso-alpha");

fn run(args: &[&str]) -> Output {
    in_pieces(args, None)
}

/// `run`, reading a LAS/LAZ input of a streamed run in pieces of `piece`
/// points (`None`: the CLI's own size).
fn in_pieces(args: &[&str], piece: Option<usize>) -> Output {
    let mut cmd = Command::new(BIN);
    cmd.args(args);
    if let Some(n) = piece {
        cmd.env("ANISO_ALPHA_TEST_PIECE_POINTS", n.to_string());
    }
    let o = cmd.output().unwrap();
    assert!(
        !String::from_utf8_lossy(&o.stderr).contains("panicked"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// A ground of 100 × 100 points, spacing 1, jittered, with a pitched roof
/// face over 25..55 × 20..35 (across the region border x = 40 of
/// 40-unit regions), written as x y z.
fn scene(path: &Path) -> usize {
    let rows = scene_rows();
    std::fs::write(path, rows.join("\n") + "\n").unwrap();
    rows.len()
}

/// [`scene`] as an ASCII PLY whose every point has the normal `normal`
/// ("nx ny nz").
fn scene_with_normal(path: &Path, normal: &str) {
    let body: Vec<String> = scene_rows()
        .iter()
        .map(|r| format!("{r} {normal}"))
        .collect();
    let ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n{}\n",
        body.len(),
        body.join("\n")
    );
    std::fs::write(path, ply).unwrap();
}

/// [`scene`]'s rows, x y z.
fn scene_rows() -> Vec<String> {
    let mut rng = SplitMix64::new(3);
    let mut rows = Vec::new();
    for iy in 0..100 {
        for ix in 0..100 {
            let (x, y) = (
                ix as f64 + 0.2 * (rng.uniform() - 0.5),
                iy as f64 + 0.2 * (rng.uniform() - 0.5),
            );
            let roof = (25.0..55.0).contains(&x) && (20.0..35.0).contains(&y);
            let z = if roof { 6.0 + 0.4 * (y - 20.0) } else { 0.0 };
            rows.push(format!("{x} {y} {}", z + 0.02 * (rng.uniform() - 0.5)));
        }
    }
    rows
}

/// `detect INPUT --structure planes ARGS…`.
fn detect_planes(input: &Path, args: &[&str]) -> Output {
    let mut all = vec!["detect", input.to_str().unwrap(), "--structure", "planes"];
    all.extend_from_slice(args);
    run(&all)
}

/// `detect --regions 40` on `input` with `args`, writing labels and part
/// labels (files named after `tag` in `d`): the output and both labels.
fn labelled_run(
    d: &TempDir,
    input: &Path,
    tag: &str,
    args: &[&str],
) -> (Output, Vec<i64>, Vec<i64>) {
    let (labels, parts) = (
        d.path(&format!("{tag}-l.txt")),
        d.path(&format!("{tag}-p.txt")),
    );
    let mut all = vec![
        "--regions",
        "40",
        "--labels",
        labels.to_str().unwrap(),
        "--part-labels",
        parts.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    let o = detect_planes(input, &all);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    (o, ints(&labels), ints(&parts))
}

/// Asserts that `o` exited with status 0, showing its stderr if not.
fn succeeded(o: &Output) {
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn regions_label_every_point_and_join_the_ground_across_borders() {
    let d = TempDir::new("regions", "run");
    let input = d.path("scene.xyz");
    let n = scene(&input);
    let report = d.path("r.json");
    let (o, l, p) = labelled_run(
        &d,
        &input,
        "one",
        &["--report", report.to_str().unwrap(), "--threads", "1"],
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("9 region(s) of side 40"), "{out}");
    assert_eq!((l.len(), p.len()), (n, n));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["regions"]["count"], 9);
    let first = &r["parts"][0];
    // The ground: one part of nine pieces, nearly every ground point.
    assert!(first["pieces"].as_u64().unwrap() >= 9, "{first}");
    let ground = p.iter().filter(|&&x| x == 0).count();
    assert!(ground as f64 > 0.9 * (n - 450) as f64, "{ground}");
    assert_eq!(first["points"].as_u64().unwrap() as usize, ground);
    let plane = first["primitive"]["plane"].as_array().unwrap();
    assert!(plane[2].as_f64().unwrap().abs() > 0.999, "{first}");
    // The roof crossing x = 40 is one part too.
    let roof: Vec<i64> = (0..n)
        .filter(|&i| {
            let (x, y) = ((i % 100) as f64, (i / 100) as f64);
            (27.0..53.0).contains(&x) && (22.0..33.0).contains(&y)
        })
        .map(|i| p[i])
        .collect();
    let r0 = roof[0];
    assert!(r0 > 0, "{r0}");
    let same = roof.iter().filter(|&&x| x == r0).count();
    assert!(
        same as f64 > 0.95 * roof.len() as f64,
        "{same} of {}",
        roof.len()
    );
    // Nine regions at once on two threads: the same labels, and a
    // labelled LAS output (refused once, as if it were a mesh) holds them.
    let las = d.path("labelled.las");
    let (_, l2, p2) = labelled_run(
        &d,
        &input,
        "nine",
        &[
            "--region-jobs",
            "9",
            "--threads",
            "2",
            "--output",
            las.to_str().unwrap(),
        ],
    );
    assert_eq!((&l2, &p2), (&l, &p));
    let options = aniso_alpha::io::ReadOptions {
        attributes: true,
        ..Default::default()
    };
    let back = aniso_alpha::io::read_points(&las, &options).unwrap();
    let column = |name: &str| -> Vec<i64> {
        let v = &back
            .attributes
            .iter()
            .find(|a| a.name == name)
            .unwrap()
            .values;
        (0..v.len()).map(|i| v.get_f64(i) as i64).collect()
    };
    assert_eq!((column("structure"), column("part")), (l, p));
}

#[test]
fn regions_refuse_the_outputs_of_a_whole_run_and_off_runs_whole() {
    let d = TempDir::new("regions", "refuse");
    let input = d.path("scene.xyz");
    scene(&input);
    let html = d.path("v.html");
    let o = detect_planes(
        &input,
        &["--regions", "40", "--html", html.to_str().unwrap()],
    );
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--html needs a whole run"), "{err}");
    assert!(!html.exists());
    for bad in ["0", "-3", "nan", "sometimes"] {
        let o = detect_planes(&input, &["--regions", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
    }
    let o = detect_planes(&input, &["--regions", "40", "--region-jobs", "0"]);
    assert_eq!(o.status.code(), Some(2));
    // `off` and a small cloud under `auto`: the whole run's summary.
    for mode in ["off", "auto"] {
        let o = detect_planes(&input, &["--regions", mode, "--threads", "1"]);
        assert_eq!(o.status.code(), Some(0));
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(out.contains("structure  part  kind"), "{mode}: {out}");
        assert!(!out.contains("region(s)"), "{mode}: {out}");
    }
}

#[test]
fn regions_warn_once_for_normals_that_disagree() {
    // Every point given the normal 1 0 0 (a ground and a roof): no region
    // uses them, and one warning says so for all nine.
    let d = TempDir::new("regions", "normals");
    let input = d.path("scene.ply");
    scene_with_normal(&input, "1 0 0");
    let o = detect_planes(&input, &["--regions", "40", "--threads", "1"]);
    assert_eq!(o.status.code(), Some(0));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.matches("normals disagree").count(), 1, "{err}");
    assert!(err.contains("in 9 of 9 region(s)"), "{err}");
    // Normals that agree (0 0 1 on the ground, most of the points): no warning.
    scene_with_normal(&input, "0 0 1");
    let o = detect_planes(&input, &["--regions", "40", "--threads", "1"]);
    assert_eq!(o.status.code(), Some(0));
    assert!(!String::from_utf8_lossy(&o.stderr).contains("normals disagree"));
}

/// The labels of a LAS/LAZ file's `structure` and `part` fields.
fn las_ids(path: &Path) -> (Vec<i64>, Vec<i64>) {
    let options = aniso_alpha::io::ReadOptions {
        attributes: true,
        ..Default::default()
    };
    let cloud = aniso_alpha::io::read_points(path, &options).unwrap();
    let column = |name: &str| -> Vec<i64> {
        let a = cloud
            .attributes
            .iter()
            .find(|a| a.name == name)
            .unwrap_or_else(|| panic!("no {name} field"));
        (0..cloud.points.len())
            .map(|i| a.values.get_f64(i) as i64)
            .collect()
    };
    (column("structure"), column("part"))
}

/// [`scene`] as a LAZ file in `d` (the labelled copy of the text scene),
/// and its number of points.
fn scene_laz(d: &TempDir) -> (std::path::PathBuf, usize) {
    let xyz = d.path("scene.xyz");
    let n = scene(&xyz);
    let laz = d.path("scene.laz");
    let o = detect_planes(
        &xyz,
        &["--regions", "off", "--output", laz.to_str().unwrap()],
    );
    succeeded(&o);
    (laz, n)
}

/// A report without its timing.
fn report_without_seconds(path: &Path) -> serde_json::Value {
    let mut r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    r.as_object_mut().unwrap().remove("seconds");
    r
}

#[test]
fn a_las_input_is_streamed_a_piece_at_a_time_with_the_whole_reads_result() {
    let d = TempDir::new("regions", "streamed");
    let (laz, n) = scene_laz(&d);
    // The whole read: a labelled PLY output needs the cloud in memory.
    let whole_ply = d.path("whole.ply");
    let whole_report = d.path("whole.json");
    let (_, whole_l, whole_p) = labelled_run(
        &d,
        &laz,
        "whole",
        &[
            "--output",
            whole_ply.to_str().unwrap(),
            "--report",
            whole_report.to_str().unwrap(),
        ],
    );
    // Streamed, in pieces of 1,500 points (LAZ chunks of 50,000: each
    // piece starts inside a chunk).
    let out = d.path("out.laz");
    let report = d.path("streamed.json");
    let (labels, parts) = (d.path("s-l.txt"), d.path("s-p.txt"));
    let mut args = vec![
        "detect",
        laz.to_str().unwrap(),
        "--structure",
        "planes",
        "--regions",
        "40",
        "--labels",
        labels.to_str().unwrap(),
        "--part-labels",
        parts.to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--timings",
    ];
    let o = in_pieces(&args, Some(1500));
    succeeded(&o);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains(&format!(
            "streamed from the file: {} piece(s) of at most 1500 points",
            n.div_ceil(1500)
        )),
        "{stdout}"
    );
    let (l, p) = (ints(&labels), ints(&parts));
    assert_eq!(l.len(), n);
    assert_eq!((&l, &p), (&whole_l, &whole_p));
    assert!(p.iter().any(|&x| x > 0), "parts found");
    assert_eq!(las_ids(&out), (l, p));
    assert_eq!(
        report_without_seconds(&report),
        report_without_seconds(&whole_report)
    );
    assert!(hidden(&d).is_empty(), "{:?}", hidden(&d));
    // A file corrupt in its point data: a clear error naming it, no output
    // and no scratch folder left.
    let bad = d.path("bad.laz");
    let mut bytes = std::fs::read(&laz).unwrap();
    let mid = bytes.len() / 2;
    for b in &mut bytes[mid..mid + 2000] {
        *b ^= 0x5a;
    }
    std::fs::write(&bad, bytes).unwrap();
    let (bad_out, bad_labels) = (d.path("bad-out.laz"), d.path("bad-l.txt"));
    let o = in_pieces(
        &[
            "detect",
            bad.to_str().unwrap(),
            "--structure",
            "planes",
            "--regions",
            "40",
            "--labels",
            bad_labels.to_str().unwrap(),
            "--output",
            bad_out.to_str().unwrap(),
        ],
        Some(1500),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_ne!(o.status.code(), Some(0));
    assert!(
        err.contains("bad.laz") && !err.contains("panicked"),
        "{err}"
    );
    assert!(!bad_out.exists() && !bad_labels.exists());
    assert!(hidden(&d).is_empty(), "{:?}", hidden(&d));
    // The oracle can fail: another region side gives other parts.
    args[5] = "25";
    succeeded(&run(&args));
    assert_ne!(
        report_without_seconds(&report),
        report_without_seconds(&whole_report)
    );
}

/// The hidden entries of `d` (temporary outputs, scratch folders).
fn hidden(d: &TempDir) -> Vec<String> {
    std::fs::read_dir(&d.0)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with('.'))
        .collect()
}

#[cfg(unix)]
#[test]
fn an_interrupted_streamed_run_leaves_no_scratch_folder() {
    use std::time::{Duration, Instant};
    let d = TempDir::new("regions", "streamed-int");
    let (laz, _) = scene_laz(&d);
    // The labels' writer waits 20 s once the regions are done: the
    // scratch folder (the part ids) is there until the run ends.
    let labels = d.path("l.txt");
    let mut child = Command::new(BIN)
        .args([
            "detect",
            laz.to_str().unwrap(),
            "--structure",
            "planes",
            "--regions",
            "40",
        ])
        .args(["--labels", labels.to_str().unwrap(), "--quiet"])
        .env("ANISO_ALPHA_TEST_WRITE_DELAY_MS", "20000")
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !hidden(&d).iter().any(|n| n.starts_with(".l.txt.tmp")) {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no temporary labels"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(
        hidden(&d)
            .iter()
            .any(|n| n.starts_with(".aniso-alpha-scratch-")),
        "{:?}",
        hidden(&d)
    );
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    assert_eq!(child.wait().unwrap().code(), Some(130));
    assert!(hidden(&d).is_empty(), "{:?}", hidden(&d));
    assert!(!labels.exists());
}

#[test]
fn a_copc_file_is_streamed_across_its_chunks_with_the_whole_reads_result() {
    // COPC: LAZ 1.4 with chunks of varying sizes (its octree's nodes), in
    // pieces of 100 points that start and end inside them.
    let copc = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../aniso-alpha/tests/fixtures/las/simple.copc.laz");
    let d = TempDir::new("regions", "copc");
    let (streamed, whole) = (d.path("s.txt"), d.path("w.txt"));
    let o = in_pieces(
        &[
            "detect",
            copc.to_str().unwrap(),
            "--structure",
            "planes",
            "--regions",
            "1000",
            "--part-labels",
            streamed.to_str().unwrap(),
        ],
        Some(100),
    );
    succeeded(&o);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("11 piece(s) of at most 100 points"), "{out}");
    let ply = d.path("w.ply");
    let o = detect_planes(
        &copc,
        &[
            "--regions",
            "1000",
            "--part-labels",
            whole.to_str().unwrap(),
            "--output",
            ply.to_str().unwrap(),
        ],
    );
    succeeded(&o);
    let (s, w) = (ints(&streamed), ints(&whole));
    assert_eq!(s.len(), 1065);
    assert!(s.iter().any(|&p| p >= 0));
    assert_eq!(s, w);
}
