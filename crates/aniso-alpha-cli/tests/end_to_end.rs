//! The built binary against CGAL's reference fixtures and through the
//! whole synth → detect → eval chain.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common;
use aniso_alpha::rng::SplitMix64;
use common::TempDir;

const BIN: &str = env!("CARGO_BIN_EXE_aniso-alpha");

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../aniso-alpha/tests/fixtures")
        .join(name)
}

fn run_in(dir: Option<&Path>, args: &[&str]) -> Output {
    let mut c = Command::new(BIN);
    c.args(args);
    if let Some(d) = dir {
        c.current_dir(d);
    }
    let o = c.output().unwrap();
    assert!(
        !String::from_utf8_lossy(&o.stderr).contains("panicked"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn ok(args: &[&str]) -> Output {
    let o = run_in(None, args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn canonical(t: [u32; 4]) -> [u32; 4] {
    let m = (0..4).min_by_key(|&i| t[i]).unwrap();
    let [a, b, c, d] = t;
    let s = match m {
        0 => [a, b, c, d],
        1 => [b, a, d, c],
        2 => [c, d, a, b],
        _ => [d, c, b, a],
    };
    let mut r = [s[1], s[2], s[3]];
    while r[0] > r[1] || r[0] > r[2] {
        r = [r[1], r[2], r[0]];
    }
    [s[0], r[0], r[1], r[2]]
}

fn read_tets(p: &Path) -> Vec<[u32; 4]> {
    let mut v: Vec<[u32; 4]> = std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .map(|l| {
            let x: Vec<u32> = l.split(' ').map(|t| t.parse().unwrap()).collect();
            canonical([x[0], x[1], x[2], x[3]])
        })
        .collect();
    v.sort_unstable();
    v
}

#[test]
fn delaunay_equals_cgal_on_every_fixture() {
    let dir = TempDir::new("e2e", "tets");
    for name in [
        "random_500",
        "grid_6",
        "sphere_100",
        "cocircular_plane",
        "duplicates_50",
        "collinear_10",
        "coplanar_30",
    ] {
        let out = dir.path(&format!("{name}.tets"));
        let o = ok(&[
            "delaunay",
            fixture(&format!("{name}.xyz")).to_str().unwrap(),
            "--tets",
            out.to_str().unwrap(),
            "--timings",
        ]);
        let timings: serde_json::Value =
            serde_json::from_str(String::from_utf8_lossy(&o.stderr).trim()).unwrap();
        for key in ["read", "triangulate", "write"] {
            assert!(timings[key].as_f64().is_some(), "{name}: {timings}");
        }
        let want = std::fs::read_to_string(fixture(&format!("{name}.tets"))).unwrap();
        let want: Vec<[u32; 4]> = want
            .lines()
            .map(|l| {
                let x: Vec<u32> = l.split(' ').map(|t| t.parse().unwrap()).collect();
                [x[0], x[1], x[2], x[3]]
            })
            .collect();
        assert_eq!(read_tets(&out), want, "{name}");
    }
}

/// `delaunay` on 2 threads (the parallel build: the set is large enough to
/// share its last rounds) writes the same tets as on 1, up to the rotation
/// of each tet, and the same from run to run.
#[test]
fn delaunay_on_two_threads_equals_one() {
    let dir = TempDir::new("e2e", "threads");
    let input = dir.path("cloud.xyz");
    // 60,000 points: a jittered lattice with exact duplicates and an
    // integer grid block (ties), in a fixed order.
    let mut text = String::new();
    let mut rng = SplitMix64::new(0x9E37_79B9_7F4A_7C15);
    for i in 0..54_000u64 {
        let r = rng.uniform();
        text += &format!("{} {} {}\n", i % 40, i / 40 % 45, (i / 1800) as f64 + r);
    }
    for i in 0..6_000 {
        text += &format!("{} {} {}\n", 50 + i % 20, i / 20 % 20, i / 400);
    }
    text += "0 0 0.5\n0 0 0.5\n";
    std::fs::write(&input, text).unwrap();
    let tets = |threads: &str, name: &str| {
        let out = dir.path(name);
        ok(&[
            "delaunay",
            input.to_str().unwrap(),
            "--tets",
            out.to_str().unwrap(),
            "--threads",
            threads,
        ]);
        read_tets(&out)
    };
    let one = tets("1", "one.tets");
    assert!(one.len() > 300_000, "{}", one.len());
    assert_eq!(tets("2", "two.tets"), one);
    let raw = |name: &str| std::fs::read_to_string(dir.path(name)).unwrap();
    let first = raw("two.tets");
    tets("2", "again.tets");
    assert!(raw("again.tets") == first);
}

fn read_intervals(p: &Path) -> Vec<(String, f64, f64)> {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("dim,v0,v1,v2,alpha_min,alpha_max"));
    let mut v: Vec<(String, f64, f64)> = lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 6, "{l}");
            let key = f[..4].join(",");
            (key, f[4].parse().unwrap(), f[5].parse().unwrap())
        })
        .collect();
    v.sort_by(|a, b| a.0.cmp(&b.0));
    v
}

fn close(a: f64, b: f64) -> bool {
    if a.is_infinite() || b.is_infinite() {
        a == b
    } else {
        (a - b).abs() <= 1e-9 * b.abs().max(1e-300)
    }
}

#[test]
fn alpha_intervals_equal_cgal() {
    let dir = TempDir::new("e2e", "intervals");
    let cases: [(&str, &[&str]); 4] = [
        ("grid_6", &[]),
        ("sphere_100", &[]),
        ("duplicates_50", &[]),
        (
            "grid_6_aniso",
            &["--elongation", "1,0.25,0.125", "--euler=0.3,-0.2,0.5"],
        ),
    ];
    for (name, extra) in cases {
        let out = dir.path(&format!("{name}.csv"));
        let input = fixture(&format!("{name}.xyz"));
        let mut args = vec![
            "alpha",
            input.to_str().unwrap(),
            "--intervals",
            out.to_str().unwrap(),
            "--timings",
        ];
        args.extend_from_slice(extra);
        let o = ok(&args);
        let timings: serde_json::Value =
            serde_json::from_str(String::from_utf8_lossy(&o.stderr).trim()).unwrap();
        assert!(timings["triangulate"].as_f64().is_some());
        assert!(timings["intervals"].as_f64().is_some());
        let ours = read_intervals(&out);
        let theirs = read_intervals(&fixture(&format!("{name}.intervals.csv")));
        assert_eq!(ours.len(), theirs.len(), "{name}");
        for (a, b) in ours.iter().zip(&theirs) {
            assert_eq!(a.0, b.0, "{name}");
            assert!(close(a.1, b.1) && close(a.2, b.2), "{name}: {a:?} vs {b:?}");
        }
    }
}

#[test]
fn alpha_shape_ply_has_faces_and_edges() {
    let dir = TempDir::new("e2e", "shape");
    let out = dir.path("shape.ply");
    ok(&[
        "alpha",
        fixture("random_500.xyz").to_str().unwrap(),
        "--alpha",
        "0.08",
        "--output",
        out.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(&out).unwrap();
    let header = String::from_utf8_lossy(&bytes[..bytes.len().min(1024)]).to_string();
    assert!(header.starts_with("ply\n"), "{header}");
    assert!(header.contains("element vertex 500"), "{header}");
    assert!(header.contains("element face"), "{header}");
    assert!(header.contains("element edge"), "{header}");
    // Readable by our own reader.
    let cloud = aniso_alpha_read(&out);
    assert_eq!(cloud, 500);
}

fn aniso_alpha_read(p: &Path) -> usize {
    // Count vertices via the `delaunay` subcommand's reader path: a PLY
    // input is accepted and every point read.
    let dir = TempDir::new("e2e", "reread");
    let tets = dir.path("t.tets");
    let o = ok(&[
        "delaunay",
        p.to_str().unwrap(),
        "--tets",
        tets.to_str().unwrap(),
    ]);
    let msg = String::from_utf8_lossy(&o.stderr);
    msg.split_whitespace()
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or(0)
}

#[test]
fn synth_detect_eval_chain() {
    let dir = TempDir::new("e2e", "chain");
    let scene = dir.path("lines.xyz");
    let labels = dir.path("labels.txt");
    let report = dir.path("report.json");
    let ply = dir.path("lines.ply");
    ok(&[
        "synth",
        "lines",
        "--seed",
        "2",
        "--output",
        scene.to_str().unwrap(),
    ]);
    let o = ok(&[
        "detect",
        scene.to_str().unwrap(),
        "--structure",
        "lines",
        "--alpha",
        "1",
        "--lambda3",
        "10",
        "--min-size",
        "4",
        "--labels",
        labels.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--output",
        ply.to_str().unwrap(),
        "--threads",
        "2",
    ]);
    let summary = String::from_utf8_lossy(&o.stdout);
    assert!(summary.contains("162 orientations"), "{summary}");
    let n_labels = std::fs::read_to_string(&labels).unwrap().lines().count();
    assert_eq!(n_labels, 1550);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["orientations"], 162);
    assert!(r["structures"].as_array().unwrap().len() >= 5);
    // The report of docs/method.md §7: a line's part is a segment.
    assert_eq!(r["structures"][0]["kind"], "line");
    assert!(r["structures"][0]["rms"].as_f64().is_some());
    let part = &r["structures"][0]["parts"][0];
    assert_eq!(part["segment"].as_array().map(Vec::len), Some(2));
    assert!(part["rms"].as_f64().is_some());
    assert!(r["timings"]["read"].as_f64().is_some());
    assert!(r["timings"]["detect"].as_f64().is_some());
    assert_eq!(r["parameters"]["min_size"]["value"], 4.0);
    let o = ok(&[
        "eval",
        "--truth",
        scene.to_str().unwrap(),
        "--labels",
        labels.to_str().unwrap(),
        "--json",
    ]);
    let ev: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(ev["f1"].as_f64().unwrap() >= 0.85, "{ev}");
    assert_eq!(ev["structures_found"], 5, "{ev}");
}

#[test]
fn detect_without_input_runs_the_example() {
    let dir = TempDir::new("e2e", "example");
    let o = run_in(Some(&dir.0), &["detect"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("aniso-alpha-example"), "{out}");
    assert!(out.contains("structures found 1/1"), "{out}");
    for f in [
        "scene.xyz",
        "labels.txt",
        "parts.txt",
        "structures.ply",
        "report.json",
        "view.html",
    ] {
        assert!(dir.0.join("aniso-alpha-example").join(f).exists(), "{f}");
    }
}

#[test]
fn bad_parameters_are_clean_errors() {
    let dir = TempDir::new("e2e", "badparam");
    let scene = dir.path("s.xyz");
    ok(&["synth", "lines", "--output", scene.to_str().unwrap()]);
    // Out of range at parse time: exit 2 (usage).
    let o = run_in(
        None,
        &[
            "detect",
            scene.to_str().unwrap(),
            "--structure",
            "lines",
            "--alpha",
            "-1",
            "--lambda3",
            "10",
            "--min-size",
            "4",
        ],
    );
    assert_eq!(o.status.code(), Some(2));
    // Semantically bad: exit 1, one line naming the file.
    let o = run_in(
        None,
        &[
            "detect",
            scene.to_str().unwrap(),
            "--structure",
            "lines",
            "--alpha",
            "1",
            "--lambda3",
            "10",
            "--min-size",
            "0",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("--min-size must be between 1 and"), "{err}");
}

fn ply_count(p: &Path, element: &str) -> Option<usize> {
    let bytes = std::fs::read(p).unwrap();
    let header = String::from_utf8_lossy(&bytes[..bytes.len().min(2048)]).to_string();
    header
        .lines()
        .take_while(|l| *l != "end_header")
        .find_map(|l| l.strip_prefix(&format!("element {element} ")))
        .map(|n| n.trim().parse().unwrap())
}

/// `alpha --optimal-alpha` prints the library's optimal alpha; `--surface`
/// writes exactly the regular triangles, and no edges.
#[test]
fn alpha_optimal_and_boundary_surface() {
    use aniso_alpha::alpha::AlphaComplex;
    let input = fixture("random_500.xyz");
    let pts = aniso_alpha::io::read_points(&input, &Default::default())
        .unwrap()
        .points;
    let ac = AlphaComplex::from_points(&pts).unwrap();
    let want = ac.optimal_alpha().unwrap();
    let o = ok(&["alpha", input.to_str().unwrap(), "--optimal-alpha"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stdout),
        format!("optimal alpha {want:?}\n")
    );
    let dir = TempDir::new("e2e", "surface");
    let (all, surf) = (dir.path("all.ply"), dir.path("surf.ply"));
    ok(&[
        "alpha",
        input.to_str().unwrap(),
        "--optimal-alpha",
        "--surface",
        "--output",
        surf.to_str().unwrap(),
    ]);
    ok(&[
        "alpha",
        input.to_str().unwrap(),
        "--alpha",
        &format!("{want:?}"),
        "--output",
        all.to_str().unwrap(),
    ]);
    let n_surface = ac.regular_surface(want).len();
    assert!(n_surface > 0);
    assert_eq!(ply_count(&surf, "face"), Some(n_surface));
    assert!(matches!(ply_count(&surf, "edge"), None | Some(0)));
    // F_alpha holds the boundary and more (interior singular triangles).
    assert_eq!(ply_count(&all, "face"), Some(ac.triangles_at(want).count()));
    assert!(ply_count(&all, "face").unwrap() >= n_surface);
}

/// --quiet means quiet: no messages, no progress, no summary; only what
/// was asked for as the result (eval's scores) still prints.
#[test]
fn quiet_means_quiet() {
    let dir = TempDir::new("e2e", "quiet");
    let silent = |args: &[&str]| {
        let o = run_in(Some(&dir.0), args);
        assert_eq!(o.status.code(), Some(0), "{args:?}");
        assert!(
            o.stdout.is_empty() && o.stderr.is_empty(),
            "{args:?}: {o:?}"
        );
    };
    silent(&[
        "synth", "lines", "--seed", "4", "--output", "l.xyz", "--quiet",
    ]);
    silent(&[
        "detect",
        "l.xyz",
        "--structure",
        "lines",
        "--alpha",
        "1",
        "--lambda3",
        "10",
        "--min-size",
        "4",
        "--labels",
        "labels.txt",
        "--quiet",
    ]);
    silent(&["view", "l.xyz", "--output", "v.html", "--quiet"]);
    silent(&["delaunay", "l.xyz", "--tets", "t.tets", "--quiet"]);
    let o = ok(&[
        "eval",
        "--truth",
        dir.path("l.xyz").to_str().unwrap(),
        "--labels",
        dir.path("labels.txt").to_str().unwrap(),
        "--quiet",
    ]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("F1"));
    // Without --quiet, detect prints its summary.
    let o = run_in(
        Some(&dir.0),
        &[
            "detect",
            "l.xyz",
            "--structure",
            "lines",
            "--alpha",
            "1",
            "--lambda3",
            "10",
            "--min-size",
            "4",
        ],
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("structure(s)"));
}

/// `synth planes --seed 3` in `dir`, the scene both tests below detect on.
fn planes_scene(dir: &TempDir) -> PathBuf {
    let scene = dir.path("planes.xyz");
    ok(&[
        "synth",
        "planes",
        "--seed",
        "3",
        "--output",
        scene.to_str().unwrap(),
    ]);
    scene
}

/// `detect SCENE --structure planes` with `extra` flags, its labels and
/// part labels written as `name.labels` and `name.parts` in `dir`: their
/// texts.
fn planes_labels(dir: &TempDir, scene: &Path, name: &str, extra: &[&str]) -> (String, String) {
    let (labels, parts) = (
        dir.path(&format!("{name}.labels")),
        dir.path(&format!("{name}.parts")),
    );
    let mut args = vec![
        "detect",
        scene.to_str().unwrap(),
        "--structure",
        "planes",
        "--labels",
        labels.to_str().unwrap(),
        "--part-labels",
        parts.to_str().unwrap(),
        "--quiet",
    ];
    args.extend(extra);
    ok(&args);
    (
        std::fs::read_to_string(labels).unwrap(),
        std::fs::read_to_string(parts).unwrap(),
    )
}

#[test]
fn detect_tile_gives_the_untiled_labels() {
    // `detect --tile SIZE` (docs/method.md §8): tiles of side 15, smaller
    // than the scene's planes (20–30 units across at spacing 3, in a
    // 125-unit box; estimated α 0.75, λ 8, so halos of 12), each
    // triangulated with its halo, give the same labels and part labels as
    // one triangulation per orientation.
    let dir = TempDir::new("e2e", "tile");
    let scene = planes_scene(&dir);
    let whole = planes_labels(&dir, &scene, "whole", &[]);
    assert!(whole.0.lines().any(|l| l != "-1"), "no structure found");
    assert_eq!(
        planes_labels(&dir, &scene, "tiled", &["--tile", "15"]),
        whole
    );
}

#[test]
fn detect_uses_the_inputs_normals() {
    // A PLY wall z = 0 with `nx ny nz` and, on it, 100 points of a window
    // frame's sides within 1 cm of the wall but facing along x. `detect`
    // reads the normals: the frame's points stay out of the wall's part,
    // and the report says where the normals came from. With
    // `--ignore-normals` they join it (the check can fail).
    let dir = TempDir::new("e2e", "normals");
    let mut rng = SplitMix64::new(5);
    let mut rows = Vec::new();
    for i in 0..60 {
        for j in 0..60 {
            let x = i as f64 * 0.1 + 0.02 * (rng.uniform() - 0.5);
            let y = j as f64 * 0.1 + 0.02 * (rng.uniform() - 0.5);
            rows.push(format!("{x} {y} {} 0 0 1", 0.01 * (rng.uniform() - 0.5)));
        }
    }
    for k in 0..100 {
        let x = 3.0 + if k % 2 == 0 { -0.01 } else { 0.01 };
        let y = 1.0 + 4.0 * rng.uniform();
        rows.push(format!("{x} {y} {} 1 0 0", 0.015 * (rng.uniform() - 0.5)));
    }
    let ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n{}\n",
        rows.len(),
        rows.join("\n")
    );
    let input = dir.file("wall.ply", ply.as_bytes());
    let run = |extra: &[&str], name: &str| {
        let (parts, report) = (
            dir.path(&format!("{name}.parts")),
            dir.path(&format!("{name}.json")),
        );
        let mut args = vec![
            "detect",
            input.to_str().unwrap(),
            "--structure",
            "planes",
            "--part-labels",
            parts.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
            "--quiet",
        ];
        args.extend(extra);
        ok(&args);
        let parts = common::read_ints(&parts);
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
        // The wall's part: the first wall point's; the frame points in it.
        let wall = parts[0];
        assert!(wall >= 0);
        assert!(parts[..3600].iter().filter(|&&p| p == wall).count() >= 3550);
        let frame_in = parts[3600..].iter().filter(|&&p| p == wall).count();
        (frame_in, report["parameters"]["normals"]["source"].clone())
    };
    let (frame_in, source) = run(&[], "with");
    assert_eq!(frame_in, 0);
    assert_eq!(source, "input");
    let (frame_in, source) = run(&["--ignore-normals"], "without");
    assert!(frame_in >= 80, "{frame_in}");
    assert_eq!(source, "estimated");
}

/// `detect INPUT --structure planes --report REPORT` and `extra`: the
/// run's output and its report, read back.
fn planes_report(input: &Path, report: &Path, extra: &[&str]) -> (Output, serde_json::Value) {
    let mut args = vec![
        "detect",
        input.to_str().unwrap(),
        "--structure",
        "planes",
        "--report",
        report.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = ok(&args);
    let r = serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
    (o, r)
}

/// Three perpendicular walls (a 0.1 m grid, 1 cm of noise), each point
/// with the normal `normal(wall, rng)` (wall 0: z = 0, 1: x = 0, 2: y = 0),
/// written as an ASCII PLY in `dir` and run through `detect --structure
/// planes --report`: the run's output and its report.
fn corner_with_normals(
    dir: &TempDir,
    mut normal: impl FnMut(usize, &mut SplitMix64) -> [f64; 3],
) -> (std::process::Output, serde_json::Value) {
    let mut rng = SplitMix64::new(6);
    let mut rows = Vec::new();
    for i in 1..40 {
        for j in 1..40 {
            let (u, v) = (i as f64 * 0.1, j as f64 * 0.1);
            let mut e = || 0.01 * (rng.uniform() - 0.5);
            let points = [[u, v, e()], [e(), u, v], [u, e(), v]];
            for (w, p) in points.iter().enumerate() {
                let n = normal(w, &mut rng);
                rows.push(format!(
                    "{} {} {} {} {} {}",
                    p[0], p[1], p[2], n[0], n[1], n[2]
                ));
            }
        }
    }
    let ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n{}\n",
        rows.len(),
        rows.join("\n")
    );
    let input = dir.file("corner.ply", ply.as_bytes());
    planes_report(&input, &dir.path("r.json"), &[])
}

#[test]
fn detect_ignores_normals_that_disagree_with_the_points() {
    // Three perpendicular walls whose PLY gives every point the normal
    // 0 0 1 (a placeholder): `detect` warns, estimates the normals, and
    // says so in the report.
    let dir = TempDir::new("e2e", "bad-normals");
    let (o, r) = corner_with_normals(&dir, |_, _| [0.0, 0.0, 1.0]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("normals disagree"), "{stderr}");
    let n = &r["parameters"]["normals"];
    assert_eq!(n["source"], "estimated");
    assert_eq!(n["input_ignored"], true);
    assert!(n["agreement"].as_f64().unwrap() < 0.5);
    assert!(String::from_utf8_lossy(&o.stdout).contains("normals: the input's were ignored"));
}

#[test]
fn detect_takes_the_modes_from_estimated_normals_when_the_given_ones_scatter() {
    // Three perpendicular walls whose PLY gives each point its wall's
    // normal tilted 10-22 degrees at random (normals over too few
    // neighbours): they agree with the points, but their modes explain
    // less of the cloud than the estimated normals' modes, so `detect`
    // warns, scans the estimated normals' modes, still gates the claims
    // with the given normals, and finds the three walls.
    let dir = TempDir::new("e2e", "scattered-normals");
    let (o, r) = corner_with_normals(&dir, |w, rng| {
        let tilt = (10.0 + 12.0 * rng.uniform()).to_radians();
        let turn = std::f64::consts::TAU * rng.uniform();
        let (a, b) = (tilt.sin() * turn.cos(), tilt.sin() * turn.sin());
        match w {
            0 => [a, b, tilt.cos()],
            1 => [tilt.cos(), a, b],
            _ => [a, tilt.cos(), b],
        }
    });
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("do worse than normals estimated"),
        "{stderr}"
    );
    let n = &r["parameters"]["normals"];
    assert_eq!(n["source"], "input");
    assert_eq!(n["modes_from"], "estimated");
    assert_eq!(n["gate"], true);
    let (given, own) = (
        n["explained"]["given"].as_f64().unwrap(),
        n["explained"]["estimated"].as_f64().unwrap(),
    );
    assert!(given < own && own > 0.9, "{n}");
    assert_eq!(r["parameters"]["orientations"]["count"], 3);
    let big = r["structures"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|s| s["parts"].as_array().unwrap())
        .filter(|p| p["points"].as_u64().unwrap() > 1300)
        .count();
    assert_eq!(big, 3, "{}", r["structures"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("normals: the input's were used in part"));
}

#[test]
fn detect_timings_name_every_stage_of_the_run_within_the_detect_phase() {
    // CGAL's ball scan, automatic mode: the stages a run meets, each
    // timed once (no ladder), add up to no more than the detect phase.
    let ball =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../aniso-alpha/tests/fixtures/real/ball.ply");
    let o = ok(&[
        "detect",
        ball.to_str().unwrap(),
        "--structure",
        "planes",
        "--quiet",
        "--timings",
    ]);
    let t: serde_json::Value =
        serde_json::from_str(String::from_utf8_lossy(&o.stderr).trim()).unwrap();
    let stages = t["stages"].as_object().expect("a stages object");
    for key in [
        "scan",
        "union",
        "candidates",
        "widen",
        "claims",
        "significance",
        "merge",
        "proportions",
        "structures",
    ] {
        let s = stages[key].as_f64().unwrap_or(-1.0);
        assert!(s >= 0.0, "{key}: {t}");
    }
    // No scale ladder on this scan: no selection across levels.
    assert!(stages.get("select").is_none(), "{t}");
    let sum: f64 = stages.values().map(|v| v.as_f64().unwrap()).sum();
    let detect = t["detect"].as_f64().unwrap();
    assert!(sum <= detect + 1e-3, "stages {sum} > detect {detect}: {t}");
    assert!(
        sum >= 0.5 * detect,
        "stages {sum} cover little of detect {detect}: {t}"
    );
}

#[test]
fn labels_alone_skip_the_outlines_and_keep_the_labels() {
    // With labels alone no output holds the plane parts' outlines, and the
    // run does not draw them; the labels are those of a run whose report
    // does hold them, a polygon per plane part.
    let dir = TempDir::new("e2e", "outlines");
    let scene = planes_scene(&dir);
    let report = dir.path("report.json");
    let with = planes_labels(
        &dir,
        &scene,
        "with",
        &["--report", report.to_str().unwrap()],
    );
    assert!(with.1.lines().any(|l| l != "-1"), "no part found");
    assert_eq!(planes_labels(&dir, &scene, "without", &[]), with);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let parts: Vec<&serde_json::Value> = r["structures"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|s| s["parts"].as_array().unwrap())
        .collect();
    assert!(!parts.is_empty());
    for p in parts {
        assert!(p["polygon"].as_array().map_or(0, Vec::len) >= 3, "{p}");
        assert!(p["triangles"].as_u64().unwrap_or(0) > 0, "{p}");
    }
}

#[test]
fn detect_labels_an_organized_clouds_pixels_without_a_return_background() {
    // Three perpendicular walls seen as a 117 × 39 depth image (a PCD with
    // HEIGHT > 1, as PCL writes a Kinect frame): every 7th pixel and the
    // image's first column have no return (NaN). `detect` says how many,
    // runs on the others, and writes one label per pixel, -1 for those.
    let dir = TempDir::new("e2e", "organized-pcd");
    let mut rng = SplitMix64::new(7);
    let (width, height) = (117usize, 39usize);
    let mut rows = Vec::new();
    let mut no_return = Vec::new();
    for j in 0..height {
        for i in 0..width {
            let row = rows.len();
            let (w, k) = (i / 39, i % 39);
            let (u, v) = ((k + 1) as f64 * 0.1, (j + 1) as f64 * 0.1);
            let e = 0.01 * (rng.uniform() - 0.5);
            let p = match w {
                0 => [u, v, e],
                1 => [e, u, v],
                _ => [u, e, v],
            };
            if i == 0 || row % 7 == 3 {
                no_return.push(row);
                rows.push("nan nan nan".to_string());
            } else {
                rows.push(format!("{} {} {}", p[0], p[1], p[2]));
            }
        }
    }
    let pcd = format!(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {width}\n\
         HEIGHT {height}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA ascii\n{}\n",
        width * height,
        rows.join("\n")
    );
    let input = dir.file("frame.pcd", pcd.as_bytes());
    let input = input.to_str().unwrap();
    let labels = dir.path("labels.txt");
    let parts = dir.path("parts.txt");
    let ply = dir.path("out.ply");
    let o = ok(&[
        "detect",
        input,
        "--structure",
        "planes",
        "--labels",
        labels.to_str().unwrap(),
        "--part-labels",
        parts.to_str().unwrap(),
        "--output",
        ply.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    let absent = no_return.len();
    assert!(
        stderr.contains(&format!(
            "{absent} of {} points have no return (NaN coordinates of an organized cloud): labelled -1",
            width * height
        )),
        "{stderr}"
    );
    let ids = common::read_ints(&parts);
    assert_eq!(ids.len(), width * height, "one label per pixel");
    assert_eq!(common::read_ints(&labels).len(), width * height);
    assert!(no_return.iter().all(|&r| ids[r] == -1));
    // The three walls: each holds most of its pixels with a return.
    let mut sizes = std::collections::BTreeMap::new();
    for &id in ids.iter().filter(|&&id| id >= 0) {
        *sizes.entry(id).or_insert(0usize) += 1;
    }
    let big = sizes.values().filter(|&&s| s > 1100).count();
    assert_eq!(big, 3, "{sizes:?}");
    // The labelled PLY keeps every row.
    let text = std::fs::read(&ply).unwrap();
    let head = String::from_utf8_lossy(&text[..text.len().min(400)]).into_owned();
    assert!(
        head.contains(&format!("element vertex {}", width * height)),
        "{head}"
    );

    // A labelled LAS cannot hold the NaN rows: refused before the run,
    // nothing written.
    let las = dir.path("out.las");
    let o = run_in(
        None,
        &[
            "detect",
            input,
            "--structure",
            "planes",
            "--output",
            las.to_str().unwrap(),
        ],
    );
    assert_eq!(o.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("cannot hold points without a return"),
        "{stderr}"
    );
    assert!(
        !stderr.contains("structure(s)"),
        "refused before the run: {stderr}"
    );
    assert!(!las.exists());
}

#[test]
fn detect_dithers_depth_quantized_in_steps_coarser_than_a_neighbourhood() {
    // Two faces of a ridge, 30 degrees from level, sampled every 0.01 with
    // their height stored in steps of 0.03 (a depth camera's steps, three
    // spacings): every face is a staircase of flat terraces. Seen as
    // given, each terrace was a plane of its own (no part over 360 of a
    // face's 2,940 points); dithered within their steps, each face's
    // largest part holds 2,000-2,940 of them, depending on the draw (the
    // dithered noise, a step/√12, makes the faces thick planes, which a
    // draw can split in two: the grid shifted by 0 to 0.0007 gave 2,021
    // at worst).
    let dir = TempDir::new("e2e", "quantized");
    let mut rows = Vec::new();
    for j in 0..60 {
        for i in -50..50 {
            let (x, y) = (i as f64 * 0.01, j as f64 * 0.01);
            let z = 1.0 + 0.577 * x.abs();
            rows.push(format!("{x} {y} {}", (z / 0.03).round() * 0.03));
        }
    }
    let input = dir.file("ridge.xyz", rows.join("\n").as_bytes());
    let parts = dir.path("parts.txt");
    let (o, r) = planes_report(
        &input,
        &dir.path("r.json"),
        &["--part-labels", parts.to_str().unwrap()],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("the z coordinates lie on levels 0.0300 apart"),
        "{stderr}"
    );
    let q = &r["parameters"]["quantized"];
    assert_eq!(q.as_array().map(Vec::len), Some(1), "{q}");
    assert_eq!(q[0]["axis"], "z");
    assert!((q[0]["step"].as_f64().unwrap() - 0.03).abs() < 1e-9, "{q}");
    let ids = common::read_ints(&parts);
    // Each face's points mostly in one part of its own.
    for side in [-1.0, 1.0] {
        let mut count = std::collections::BTreeMap::new();
        for (k, &id) in ids.iter().enumerate() {
            let x = (k % 100) as f64 - 50.0;
            if id >= 0 && x * side > 1.0 {
                *count.entry(id).or_insert(0usize) += 1;
            }
        }
        let best = count.values().max().copied().unwrap_or(0);
        assert!(best > 1800, "face {side}: {count:?}");
    }
    // A regular grid's coordinates are levels too, one spacing apart:
    // not quantized, nothing said, nothing in the report.
    let (o, g) = planes_report(&fixture("grid_6.xyz"), &dir.path("g.json"), &[]);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("lie on levels"));
    assert_eq!(g["parameters"]["quantized"], serde_json::json!([]));
    // Three parallel lines 50 apart, 7 between points (the Python
    // `detect` example): y lies on levels far coarser than the spacing,
    // but each is a line of its own, not a terrace. Dithered, they were
    // scattered into nothing.
    let rows: Vec<String> = (0..90)
        .map(|k| format!("{} {} 0", 7 * (k % 30), 50 * (k / 30)))
        .collect();
    let lines = dir.file("lines.xyz", rows.join("\n").as_bytes());
    let o = ok(&[
        "detect",
        lines.to_str().unwrap(),
        "--structure",
        "lines",
        "--alpha",
        "1",
        "--lambda3",
        "10",
        "--min-size",
        "4",
        "--labels",
        dir.path("l.txt").to_str().unwrap(),
    ]);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("lie on levels"));
    let labels = common::read_ints(&dir.path("l.txt"));
    let found: std::collections::BTreeSet<i64> = labels.iter().copied().collect();
    assert_eq!(found, [0, 1, 2].into(), "{labels:?}");
}

#[test]
fn detect_dithers_depth_in_fine_steps_where_a_surface_faces_the_camera() {
    // A wall about 6 degrees from face-on, 3 m from a camera whose pixels
    // are 1/500 rad apart (6 mm there), over a floor, its depth stored in
    // uniform steps of 1/z (a stereo camera's disparity: 4 mm apart at 3
    // m). The steps are finer than a neighbourhood, but the wall is a
    // staircase of terraces 40 mm wide: quantized by the second rule,
    // and the warning and the report say so.
    let dir = TempDir::new("e2e", "fine_steps");
    let q = 4.4e-4;
    let mut rows = Vec::new();
    for i in 0..160 {
        for j in 0..120 {
            let (a, b) = ((i as f64 - 80.0) / 500.0, (j as f64 - 60.0) / 500.0);
            let wall = 3.0 / (1.0 - 0.1 * a);
            let t: f64 = if b > 0.0 { (0.2 / b).min(wall) } else { wall };
            let z = 1.0 / ((1.0 / t / q).round() * q);
            rows.push(format!("{} {} {}", a * z, b * z, z));
        }
    }
    let input = dir.file("frame.xyz", rows.join("\n").as_bytes());
    let (o, r) = planes_report(&input, &dir.path("r.json"), &[]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("the z coordinates lie on levels") && stderr.contains("finer than"),
        "{stderr}"
    );
    let q = &r["parameters"]["quantized"];
    assert_eq!(q.as_array().map(Vec::len), Some(1), "{q}");
    assert_eq!(
        (&q[0]["axis"], &q[0]["coarse"]),
        (&"z".into(), &false.into()),
        "{q}"
    );
    assert!(q[0]["terraced"].as_f64().unwrap() > 0.5, "{q}");
}
