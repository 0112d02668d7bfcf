//! Detect lines or planes in a point file and write one label per point,
//! with the library alone:
//!
//!     cargo run --release -p aniso-alpha --example detect_file -- lines.xyz labels.txt lines 2
//!
//! The arguments are the input (any format the library reads), the labels
//! to write, `lines` or `planes`, and the number of threads. The parameters
//! are the paper's (Fig. 12 for lines, Fig. 10 for planes), which suit the
//! scenes of `aniso-alpha synth`; docs/method.md §5 says how to choose them.

use std::error::Error;
use std::path::Path;

use aniso_alpha::detect::{Detection, Detector};
use aniso_alpha::io::{read_points, write_labels, ReadOptions};

/// Reads `input`, finds lines (or planes) on `threads` threads, and writes
/// each point's structure id (or −1, background) to `labels`.
pub fn detect_file(
    input: &Path,
    labels: &Path,
    lines: bool,
    threads: usize,
) -> Result<Detection, Box<dyn Error>> {
    let cloud = read_points(input, &ReadOptions::default())?;
    let detector = if lines {
        Detector::lines(1.0, 10.0, 4) // alpha, lambda3, nb_c
    } else {
        Detector::planes(1.0, 4.0, 8.0, 20) // alpha, lambda2, lambda3, nb_c
    };
    // The orientations are scanned in parallel, on this many threads.
    let detection = detector.threads(threads).run(&cloud.points)?;
    write_labels(labels, &detection.labels)?;
    Ok(detection)
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() != 4 || !["lines", "planes"].contains(&args[2].as_str()) {
        return Err("usage: detect_file INPUT LABELS.txt lines|planes THREADS".into());
    }
    let threads: usize = args[3].parse()?;
    let detection = detect_file(
        Path::new(&args[0]),
        Path::new(&args[1]),
        args[2] == "lines",
        threads,
    )?;
    for s in &detection.structures {
        println!(
            "structure {}: {} points, {} parts",
            s.id,
            s.vertices.len(),
            s.parts.len()
        );
    }
    let background = detection.labels.iter().filter(|&&l| l < 0).count();
    println!(
        "{} structure(s), {background} background point(s); labels -> {}",
        detection.structures.len(),
        args[1]
    );
    Ok(())
}
