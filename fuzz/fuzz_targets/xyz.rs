//! Fuzz target: the xyz reader never panics, and its results are sane.
#![no_main]

use std::path::Path;

use aniso_alpha::io::{read_labels_bytes, read_xyz_bytes, IoError, PointCloud, ReadOptions};
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
    // The first byte picks the options; the rest is the file.
    let (labels, bytes) = match data.split_first() {
        Some((b, rest)) => (*b & 1 == 1, rest),
        None => (false, data),
    };
    let options = if labels {
        ReadOptions::with_labels(3)
    } else {
        ReadOptions::default()
    };
    check(read_xyz_bytes(Path::new("fuzz.xyz"), bytes, &options));
    let _ = read_labels_bytes(Path::new("fuzz.txt"), bytes);
});
