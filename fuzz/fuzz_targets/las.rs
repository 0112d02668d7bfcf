//! Fuzz target: the LAS/LAZ reader never panics, never allocates beyond
//! what the input's size justifies, and its results are sane.
//!
//! The reader contains panics raised inside the `laz` and `las` crates on
//! corrupt compressed data (they become an error), so the panic hook that
//! libfuzzer-sys installs (abort on any panic) is replaced by one that
//! lets exactly those unwind to the reader's `catch_unwind`; a panic
//! anywhere else still aborts and is reported as a crash.
//!
//! Seeds: `fuzz/corpus_seeds/las/` (LAS and LAZ files of every point
//! format, written by `cargo test -p aniso-alpha --features las --test
//! io_formats write_fuzz_seeds -- --ignored`).
#![no_main]

use std::path::Path;

use aniso_alpha::io::{read_las_bytes, IoError, PointCloud, ReadOptions};
use libfuzzer_sys::fuzz_target;

fn check(r: Result<PointCloud, IoError>) {
    match r {
        Ok(c) => {
            assert!(!c.points.is_empty());
            assert!(c.points.iter().flatten().all(|v| v.is_finite()));
            if let Some(l) = &c.labels {
                assert_eq!(l.len(), c.points.len());
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz."), "{e}"),
    }
}

fn contained(file: &str) -> bool {
    ["/laz-", "/las-", "\\laz-", "\\las-"]
        .iter()
        .any(|c| file.contains(c))
}

fuzz_target!(
    init: {
        let abort_hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if info.location().is_some_and(|l| contained(l.file())) {
                return; // unwinds to the reader's catch_unwind
            }
            abort_hook(info);
        }));
    },
    |data: &[u8]| {
        let name = if data.get(104).is_some_and(|f| f & 0xC0 != 0) {
            "fuzz.laz"
        } else {
            "fuzz.las"
        };
        check(read_las_bytes(
            Path::new(name),
            data,
            &ReadOptions::with_labels(3),
        ));
    }
);
