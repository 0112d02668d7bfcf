//! Fuzz target: the LAS/LAZ reader never panics, never allocates beyond
//! what the input's size justifies, and its results are sane.
//!
//! The reader contains panics raised inside the `laz` and `las` crates on
//! corrupt compressed data (they become an error), so the panic hook that
//! libfuzzer-sys installs (abort on any panic) is replaced by one that
//! lets exactly those unwind to the reader's `catch_unwind`; a panic
//! anywhere else still aborts and is reported as a crash.
//!
//! Speed: a LAZ input may declare up to 1000 bytes of records per byte
//! (the reader's bound); decompressing those dominates a run, so inputs
//! declaring more than [`MAX_POINTS`] points, or more than
//! [`MAX_RECORD_BYTES`] of records, are skipped here (the header checks
//! that refuse huge counts are unit-tested in `io::las`). Half the inputs
//! are read with every attribute kept.
//!
//! Seeds: `fuzz/corpus_seeds/las/` (LAS and LAZ files of every point
//! format, written by `cargo test -p aniso-alpha --features las --test
//! io_formats write_fuzz_seeds -- --ignored`).
#![no_main]

use std::path::Path;

use aniso_alpha::io::{read_las_bytes, IoError, PointCloud, ReadOptions};
use libfuzzer_sys::fuzz_target;

/// Inputs declaring more points are skipped (see the module docs).
const MAX_POINTS: u64 = 2048;

/// Inputs declaring more bytes of point records are skipped.
const MAX_RECORD_BYTES: u64 = 256 << 10;

/// The point count the header declares (legacy field, or LAS 1.4's).
fn declared_points(b: &[u8]) -> u64 {
    let u32_at = |o: usize| {
        b.get(o..o + 4)
            .map_or(0, |s| u32::from_le_bytes(s.try_into().unwrap()))
    };
    let u64_at = |o: usize| {
        b.get(o..o + 8)
            .map_or(0, |s| u64::from_le_bytes(s.try_into().unwrap()))
    };
    let v14 = b
        .get(24..26)
        .is_some_and(|v| v[0] > 1 || (v[0] == 1 && v[1] >= 4));
    u64::from(u32_at(107)).max(if v14 { u64_at(247) } else { 0 })
}

fn check(r: Result<PointCloud, IoError>) {
    match r {
        Ok(c) => {
            for a in &c.attributes {
                assert_eq!(a.values.len(), c.points.len());
            }
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
    // The registry's las-0.x/laz-0.x, and the patched laz in vendor/laz.
    [
        "/laz-",
        "/las-",
        "\\laz-",
        "\\las-",
        "vendor/laz/",
        "vendor\\laz\\",
    ]
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
        let points = declared_points(data);
        let record_len = data
            .get(105..107)
            .map_or(0, |s| u64::from(u16::from_le_bytes([s[0], s[1]])));
        if points > MAX_POINTS || points * record_len > MAX_RECORD_BYTES {
            return;
        }
        let name = if data.get(104).is_some_and(|f| f & 0xC0 != 0) {
            "fuzz.laz"
        } else {
            "fuzz.las"
        };
        let options = ReadOptions {
            attributes: data.len() % 2 == 1,
            ..ReadOptions::with_labels(3)
        };
        check(read_las_bytes(Path::new(name), data, &options));
    }
);
