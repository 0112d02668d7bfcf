//! The README's library examples (`examples/detect_file.rs`,
//! `examples/alpha_shape.rs`) run as tests: read a file, detect or build
//! the α-shape, write the result.

#[path = "../examples/detect_file.rs"]
#[allow(dead_code)] // its `main` is for `cargo run --example`
mod detect_file;

#[path = "../examples/alpha_shape.rs"]
#[allow(dead_code)]
mod alpha_shape;

use aniso_alpha::alpha::AlphaComplex;
use aniso_alpha::io::{read_labels, read_points, write_scene, ReadOptions};
use aniso_alpha::synth;

struct TempDir(std::path::PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let d = std::env::temp_dir().join(format!("aniso-examples-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        TempDir(d)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn lines_scene(dir: &TempDir) -> (std::path::PathBuf, synth::Scene) {
    let input = dir.0.join("lines.xyz");
    let scene = synth::lines(1);
    write_scene(&input, &scene, false).unwrap();
    (input, scene)
}

#[test]
fn the_detection_example_detects_and_writes_labels() {
    let dir = TempDir::new("detect");
    let (input, scene) = lines_scene(&dir);
    let labels = dir.0.join("labels.txt");
    let det = detect_file::detect_file(&input, &labels, true, 2).unwrap();
    let written = read_labels(&labels).unwrap();
    assert_eq!(written, det.labels);
    assert_eq!(written.len(), scene.points.len());
    // Fig. 12: five lines.
    assert!(det.structures.len() >= 5, "{}", det.structures.len());
    let on_lines = written.iter().filter(|&&l| l >= 0).count();
    assert!((40..=60).contains(&on_lines), "{on_lines}");
    // A missing file is an error, not a panic.
    assert!(detect_file::detect_file(&dir.0.join("nope.xyz"), &labels, true, 2).is_err());
}

#[test]
fn the_alpha_shape_example_writes_the_boundary_surface() {
    let dir = TempDir::new("alpha");
    let (input, scene) = lines_scene(&dir);
    let output = dir.0.join("surface.ply");
    let alpha = alpha_shape::alpha_shape(&input, &output).unwrap();
    let ac = AlphaComplex::from_points(&scene.points).unwrap();
    assert_eq!(Some(alpha), ac.optimal_alpha());
    // The PLY holds every point (and the faces, read back by the header).
    let back = read_points(&output, &ReadOptions::default()).unwrap();
    assert_eq!(back.points.len(), scene.points.len());
    let bytes = std::fs::read(&output).unwrap();
    let header = String::from_utf8_lossy(&bytes[..512]).to_string();
    let want = format!("element face {}", ac.regular_surface(alpha).len());
    assert!(header.contains(&want), "{header}");
}
