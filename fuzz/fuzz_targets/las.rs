//! Fuzz target: the las reader never panics, and its results are sane.
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
        Err(e) => assert!(e.to_string().starts_with("fuzz.")),
    }
}

fuzz_target!(|data: &[u8]| {
    check(read_las_bytes(
        Path::new("fuzz.las"),
        data,
        &ReadOptions::with_labels(3),
    ));
});
