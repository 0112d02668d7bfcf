//! The HTML viewer (`view`, `detect --html`) loaded in headless Chromium:
//! it renders without console errors, the canvas is not blank and shows
//! the structures' colours, and the legend lists every structure.
//! Also the PNG pictures (`detect --png`, `alpha --png`).
//!
//! Chromium is Debian's `chromium` (`.ci/run` installs it); set
//! `ANISO_CHROMIUM` to use another binary. Without one, the browser test
//! follows the rule of `common::tool_missing`: it says so and checks
//! nothing, or fails under `ANISO_ALPHA_CI=1` (the PNG tests always run).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common;
use aniso_alpha::rng::SplitMix64;
use common::TempDir;

use tiny_skia::Pixmap;

const BIN: &str = env!("CARGO_BIN_EXE_aniso-alpha");

fn ok(dir: &Path, args: &[&str]) -> Output {
    let o = Command::new(BIN)
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("ANISO_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    for dir in std::env::split_paths(&path) {
        for name in ["chromium", "chromium-browser"] {
            let p = dir.join(name);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// What one headless load of a page gave.
struct Load {
    dom: String,
    console: Vec<String>,
    screenshot: Pixmap,
}

const WIDTH: u32 = 1000;
const HEIGHT: u32 = 700;
/// The legend panel's width (the page's CSS): the canvas is the rest.
const PANEL: u32 = 340;

/// Loads `page` in headless Chromium: the DOM after the scripts ran, the
/// console messages (Chromium's log on stderr), a screenshot.
fn load(browser: &Path, page: &Path, dir: &TempDir) -> Load {
    let shot = dir.path("shot.png");
    let profile = dir.path(&format!(
        "profile-{}",
        page.file_stem().unwrap().to_string_lossy()
    ));
    let _ = std::fs::remove_file(&shot);
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            // WebGL without a GPU: ANGLE on SwiftShader (software).
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--enable-logging=stderr",
            "--v=0",
            "--hide-scrollbars",
            &format!("--user-data-dir={}", profile.display()),
            &format!("--window-size={WIDTH},{HEIGHT}"),
            &format!("--screenshot={}", shot.display()),
            "--dump-dom",
        ])
        .arg(format!("file://{}", page.display()))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start chromium");
    // Read both pipes on threads (a full pipe would block the browser).
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let t_out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let t_err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!(
                "chromium did not finish loading {} in 120 s",
                page.display()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let dom = t_out.join().unwrap();
    let log = t_err.join().unwrap();
    assert!(
        status.success(),
        "chromium failed on {}: {log}",
        page.display()
    );
    let console = log
        .lines()
        .filter(|l| l.contains(":CONSOLE"))
        // SwiftShader's note that the screenshot read the pixels back.
        .filter(|l| !l.contains("GL Driver Message (OpenGL, Performance"))
        .map(str::to_string)
        .collect();
    let screenshot = Pixmap::load_png(&shot).expect("screenshot");
    Load {
        dom,
        console,
        screenshot,
    }
}

/// Mean squared deviation of the canvas pixels' luminance, and the number
/// of saturated (coloured, not grey) pixels.
fn canvas_stats(p: &Pixmap) -> (f64, usize) {
    let w = p.width().min(WIDTH - PANEL);
    let mut lum = Vec::new();
    let mut coloured = 0;
    for y in 0..p.height() {
        for x in 0..w {
            let c = p.pixel(x, y).unwrap();
            let (r, g, b) = (c.red() as f64, c.green() as f64, c.blue() as f64);
            lum.push(0.299 * r + 0.587 * g + 0.114 * b);
            let (mx, mn) = (r.max(g).max(b), r.min(g).min(b));
            if mx - mn > 60.0 {
                coloured += 1;
            }
        }
    }
    let mean = lum.iter().sum::<f64>() / lum.len() as f64;
    let var = lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lum.len() as f64;
    (var, coloured)
}

/// The `<body …>` tag of the dumped DOM: the page's script sets
/// `data-drawn` there after each frame and `data-error` on a failure.
fn body_tag(dom: &str) -> &str {
    let start = dom.find("<body").expect("a body");
    &dom[start..start + dom[start..].find('>').unwrap() + 1]
}

fn legend_items(dom: &str) -> usize {
    dom.matches("<li class=\"st\"").count()
}

/// A scene with known structures: two planar facets of a box corner
/// (z = 0 and x = 0, one structure in two parts), a straight line and
/// uniform background.
fn scene(dir: &TempDir) -> (PathBuf, PathBuf, PathBuf, PathBuf) {
    let mut pts = String::new();
    let mut labels = String::new();
    let mut parts = String::new();
    let mut add = |p: [f64; 3], l: i64, q: i64| {
        pts.push_str(&format!("{} {} {}\n", p[0], p[1], p[2]));
        labels.push_str(&format!("{l}\n"));
        parts.push_str(&format!("{q}\n"));
    };
    for i in 1..=10 {
        for j in 0..=10 {
            add([i as f64, j as f64, 0.0], 0, 0);
            add([0.0, j as f64, i as f64], 0, 1);
        }
    }
    for i in 0..=30 {
        add([4.0 + i as f64 * 0.5, 4.0, 8.0], 1, 2);
    }
    let mut rng = SplitMix64::new(7);
    let mut rnd = || rng.uniform();
    for _ in 0..400 {
        add(
            [rnd() * 24.0 - 4.0, rnd() * 14.0 - 2.0, rnd() * 14.0 - 2.0],
            -1,
            -1,
        );
    }
    let report = serde_json::json!({
        "structures": [
            {"id": 0, "kind": "surface", "points": 220, "rms": 0.0, "nfa": 3.2e-41, "parts": [
                {"id": 0, "points": 110, "rms": 0.0, "plane": [0.0, 0.0, 1.0, 0.0],
                 "polygon": [[1.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0], [1.0, 10.0, 0.0]]},
                {"id": 1, "points": 110, "rms": 0.0, "plane": [1.0, 0.0, 0.0, 0.0],
                 "polygon": [[0.0, 0.0, 1.0], [0.0, 10.0, 1.0], [0.0, 10.0, 10.0], [0.0, 0.0, 10.0]]}
            ]},
            {"id": 1, "kind": "line", "points": 31, "rms": 0.0, "parts": [
                {"id": 2, "points": 31, "rms": 0.0, "segment": [[4.0, 4.0, 8.0], [19.0, 4.0, 8.0]]}
            ]}
        ],
        "parameters": {"structure": "planes", "alpha": 1.0}
    });
    let files = (
        dir.path("scene.xyz"),
        dir.path("labels.txt"),
        dir.path("parts.txt"),
        dir.path("report.json"),
    );
    std::fs::write(&files.0, pts).unwrap();
    std::fs::write(&files.1, labels).unwrap();
    std::fs::write(&files.2, parts).unwrap();
    std::fs::write(&files.3, report.to_string()).unwrap();
    files
}

#[test]
fn viewer_renders_in_headless_chromium() {
    let Some(browser) = chromium() else {
        common::tool_missing(
            "viewer_renders_in_headless_chromium",
            "no chromium on PATH (apt-get install chromium; .ci/run installs it), nor ANISO_CHROMIUM",
        );
        return;
    };
    let dir = TempDir::new("view", "chromium");

    // The checks can fail: a page with a script error is caught, and a
    // page whose canvas stays empty has no variance.
    let bad = dir.path("bad.html");
    std::fs::write(
        &bad,
        "<!DOCTYPE html><html><body style=\"margin:0;background:#111\">\
<canvas width=\"10\" height=\"10\"></canvas><script>notAFunction();</script></body></html>",
    )
    .unwrap();
    let l = load(&browser, &bad, &dir);
    assert!(
        l.console.iter().any(|c| c.contains("notAFunction")),
        "the console check sees no error: {:?}",
        l.console
    );
    assert!(canvas_stats(&l.screenshot).0 < 1.0);

    // `view` on a scene with a report in the current schema (planes,
    // polygons, a segment, NFA).
    let (scene, labels, parts, report) = scene(&dir);
    let page = dir.path("view.html");
    ok(
        &dir.0,
        &[
            "view",
            scene.to_str().unwrap(),
            "--labels",
            labels.to_str().unwrap(),
            "--part-labels",
            parts.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
            "--output",
            page.to_str().unwrap(),
        ],
    );
    let l = load(&browser, &page, &dir);
    assert!(l.console.is_empty(), "console: {:?}", l.console);
    assert!(
        !body_tag(&l.dom).contains("data-error"),
        "{}",
        body_tag(&l.dom)
    );
    assert!(
        body_tag(&l.dom).contains("data-drawn=\""),
        "the page never drew"
    );
    assert_eq!(legend_items(&l.dom), 2);
    assert!(l
        .dom
        .contains("<b>#0</b> surface · 220 pts · rms 0 · NFA 3.20e-41"));
    assert!(l.dom.contains("<b>#1</b> line · 31 pts"));
    assert!(l.dom.contains("0x + 0y + 1z + 0 = 0"), "plane of part 0");
    assert!(l.dom.contains("1x + 0y + 0z + 0 = 0"), "plane of part 1");
    assert!(l.dom.contains("(4, 4, 8) → (19, 4, 8), length 15"));
    let (var, coloured) = canvas_stats(&l.screenshot);
    assert!(var > 20.0, "blank canvas? luminance variance {var}");
    assert!(
        coloured > 500,
        "structures not drawn? {coloured} coloured pixels"
    );

    // A plain point cloud: no labels, no report.
    let plain = dir.path("plain.html");
    ok(
        &dir.0,
        &[
            "view",
            scene.to_str().unwrap(),
            "--output",
            plain.to_str().unwrap(),
        ],
    );
    let l = load(&browser, &plain, &dir);
    assert!(l.console.is_empty(), "console: {:?}", l.console);
    assert_eq!(legend_items(&l.dom), 0);
    let (var, coloured) = canvas_stats(&l.screenshot);
    assert!(var > 5.0, "blank canvas? luminance variance {var}");
    assert!(coloured < 50, "{coloured} coloured pixels without labels");

    // `detect --html` (the report of today's detect, outlines from the
    // points' hulls).
    ok(
        &dir.0,
        &["synth", "lines", "--seed", "3", "--output", "lines.xyz"],
    );
    ok(
        &dir.0,
        &[
            "detect",
            "lines.xyz",
            "--structure",
            "lines",
            "--alpha",
            "1",
            "--lambda3",
            "10",
            "--min-size",
            "4",
            "--html",
            "lines.html",
            "--report",
            "lines.json",
        ],
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path("lines.json")).unwrap()).unwrap();
    let n = report["structures"].as_array().unwrap().len();
    assert!(n >= 5);
    let l = load(&browser, &dir.path("lines.html"), &dir);
    assert!(l.console.is_empty(), "console: {:?}", l.console);
    assert!(!body_tag(&l.dom).contains("data-error"));
    assert_eq!(legend_items(&l.dom), n);
    assert!(l.dom.matches("line · ").count() >= 5, "{}", l.dom);
    let (var, coloured) = canvas_stats(&l.screenshot);
    assert!(var > 5.0 && coloured > 100, "{var} {coloured}");
}

/// The points of a PNG whose colour is close to `c`.
fn count_color(p: &Pixmap, c: [u8; 3], tol: i32) -> usize {
    p.pixels()
        .iter()
        .filter(|q| {
            (q.red() as i32 - c[0] as i32).abs() <= tol
                && (q.green() as i32 - c[1] as i32).abs() <= tol
                && (q.blue() as i32 - c[2] as i32).abs() <= tol
        })
        .count()
}

#[test]
fn pictures_of_detection_and_shape() {
    let dir = TempDir::new("view", "png");
    let (scene, ..) = scene(&dir);
    ok(
        &dir.0,
        &["synth", "lines", "--seed", "3", "--output", "lines.xyz"],
    );
    let args = [
        "detect",
        "lines.xyz",
        "--structure",
        "lines",
        "--alpha",
        "1",
        "--lambda3",
        "10",
        "--min-size",
        "4",
        "--png",
        "a.png",
    ];
    ok(&dir.0, &args);
    let mut again = args;
    again[args.len() - 1] = "b.png";
    ok(&dir.0, &again);
    let a = std::fs::read(dir.path("a.png")).unwrap();
    assert_eq!(
        a,
        std::fs::read(dir.path("b.png")).unwrap(),
        "not deterministic"
    );
    let p = Pixmap::decode_png(&a).unwrap();
    assert_eq!((p.width(), p.height()), (1200, 900));
    let white = count_color(&p, [255, 255, 255], 0);
    assert!(white > 1200 * 900 / 2, "mostly white background: {white}");
    let coloured = p
        .pixels()
        .iter()
        .filter(|q| {
            let (r, g, b) = (q.red() as i32, q.green() as i32, q.blue() as i32);
            r.max(g).max(b) - r.min(g).min(b) > 60
        })
        .count();
    assert!(coloured > 2000, "structures drawn in colour: {coloured}");

    // The alpha-shape: every face, and the boundary surface.
    ok(
        &dir.0,
        &[
            "alpha",
            scene.to_str().unwrap(),
            "--alpha",
            "2",
            "--png",
            "shape.png",
        ],
    );
    let p = Pixmap::load_png(dir.path("shape.png")).unwrap();
    let blue = p
        .pixels()
        .iter()
        .filter(|q| q.blue() as i32 > q.red() as i32 + 40)
        .count();
    assert!(blue > 10_000, "shaded triangles: {blue}");
}
