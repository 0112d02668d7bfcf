//! LAS/LAZ files larger than memory: ranges of points read without the
//! rest of the file ([`read_las_range`]) equal the same rows of a whole
//! read, files read from disk equal the same bytes read in memory (the
//! hostile files included), and a labelled copy written a range at a time
//! ([`LasLabelWriter`]) is the file [`write_labelled_cloud`] writes of the
//! whole cloud.

use std::path::{Path, PathBuf};

use crate::common::TempDir;
use aniso_alpha::io::{
    las_point_count, read_las_range, read_points, read_points_bytes, write_labelled_cloud, IoError,
    Labelled, LasLabelWriter, PointCloud, ReadOptions,
};
use aniso_alpha::rng::SplitMix64 as Rng;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/las")
        .join(name)
}

/// Every LAS/LAZ fixture: LAS 1.2–1.4, point formats 0–7, extra bytes,
/// extended VLRs, LAZ with fixed chunks and COPC's 65 chunks of variable
/// size.
const FILES: [&str; 10] = [
    "simple.las",
    "simple.laz",
    "simple.copc.laz",
    "simple1_3.las",
    "1_4_w_evlr.las",
    "1_4_w_evlr.laz",
    "extra.laz",
    "extrabytes.las",
    "autzen.las",
    "urban.las",
];

fn all() -> ReadOptions {
    ReadOptions {
        attributes: true,
        ..ReadOptions::with_labels(3)
    }
}

/// The rows `start..start + count` of a whole read, as a range read gives
/// them: points, labels and records (the attributes are decoded from the
/// records).
fn assert_rows(whole: &PointCloud, part: &PointCloud, start: usize, what: &str) {
    let n = part.points.len();
    assert_eq!(part.points, whole.points[start..start + n], "{what}");
    let labels = whole.labels.as_ref().unwrap();
    assert_eq!(
        part.labels.as_deref(),
        Some(&labels[start..start + n]),
        "{what}"
    );
    let (w, p) = (whole.las.as_ref().unwrap(), part.las.as_ref().unwrap());
    let len = w.record_len;
    assert_eq!(
        p.records,
        w.records[start * len..(start + n) * len],
        "{what}"
    );
    assert_eq!(
        (&p.header, &p.vlrs, &p.padding),
        (&w.header, &w.vlrs, &w.padding),
        "{what}"
    );
    assert_eq!((p.tail_start, &p.tail), (w.tail_start, &w.tail), "{what}");
    assert_eq!(part.attributes.len(), whole.attributes.len(), "{what}");
    for a in &part.attributes {
        assert_eq!(a.values.len(), n, "{what}: {}", a.name);
    }
}

#[test]
fn ranges_equal_the_rows_of_a_whole_read() {
    let mut rng = Rng::new(27);
    for name in FILES {
        let path = fixture(name);
        let whole = read_points(&path, &all()).unwrap();
        let n = whole.points.len();
        assert_eq!(las_point_count(&path).unwrap(), n as u64, "{name}");
        let mut ranges = vec![
            (0, n),
            (0, 1),
            (n - 1, 1),
            (1, n),
            (n / 3, n / 3),
            (7, u64::MAX as usize),
        ];
        for _ in 0..12 {
            let s = rng.below(n as u64) as usize;
            ranges.push((s, 1 + rng.below(n as u64) as usize));
        }
        for (start, count) in ranges {
            let part = read_las_range(&path, start as u64, count as u64, &all()).unwrap();
            assert_eq!(
                part.points.len(),
                count.min(n - start),
                "{name} {start}+{count}"
            );
            assert_rows(&whole, &part, start, &format!("{name} {start}+{count}"));
        }
        // A whole file read a range at a time, the ranges stacked.
        let mut stacked = Vec::new();
        let mut start = 0;
        while start < n {
            let part = read_las_range(&path, start as u64, 100, &ReadOptions::default()).unwrap();
            start += part.points.len();
            stacked.extend(part.points);
        }
        assert_eq!(stacked, whole.points, "{name}");
        let e = read_las_range(&path, n as u64, 1, &ReadOptions::default()).unwrap_err();
        assert!(matches!(e, IoError::Format { .. }), "{e}");
        assert!(
            e.to_string().contains(&format!("the file has {n} points")),
            "{e}"
        );
    }
}

#[test]
fn ranges_cross_the_chunks_of_a_large_laz() {
    // 130,000 points: three LAZ chunks of 50,000 (laz-rs's default) and a
    // last one of 30,000; ranges start inside each and cross the ends.
    let dir = TempDir::new("las-range", "chunks");
    let mut rng = Rng::new(5);
    let cloud = PointCloud {
        points: (0..130_000)
            .map(|_| [rng.uniform() * 100.0, rng.uniform() * 100.0, rng.uniform()])
            .collect(),
        ..PointCloud::default()
    };
    let ids: Vec<i64> = (0..130_000).map(|i| i % 7 - 1).collect();
    let path = dir.path("big.laz");
    write_labelled_cloud(&path, &cloud, &Labelled::new(&ids, &ids)).unwrap();
    let whole = read_points(&path, &all()).unwrap();
    assert_eq!(whole.points.len(), 130_000);
    for (start, count) in [
        (0, 130_000),
        (49_999, 2),
        (50_000, 50_000),
        (73_456, 60_000),
        (129_999, 5),
        (100_001, 1),
    ] {
        let part = read_las_range(&path, start as u64, count as u64, &all()).unwrap();
        assert_eq!(part.points.len(), count.min(130_000 - start));
        assert_rows(&whole, &part, start, &format!("{start}+{count}"));
    }
}

#[test]
fn files_read_from_disk_equal_their_bytes_read_in_memory() {
    let hostile = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    let mut paths: Vec<PathBuf> = FILES.iter().map(|f| fixture(f)).collect();
    for entry in std::fs::read_dir(&hostile).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "las" || e == "laz") {
            paths.push(p);
        }
    }
    assert!(paths.len() >= FILES.len() + 5);
    for path in paths {
        let bytes = std::fs::read(&path).unwrap();
        for options in [all(), ReadOptions::default()] {
            let file = read_points(&path, &options);
            let memory = read_points_bytes(&path, &bytes, &options);
            match (file, memory) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(a.points, b.points, "{path:?}");
                    assert_eq!(a.labels, b.labels, "{path:?}");
                    assert_eq!(a.las, b.las, "{path:?}");
                }
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                (a, b) => panic!("{path:?}: from disk {:?}, in memory {:?}", a.err(), b.err()),
            }
        }
    }
}

#[test]
fn a_copy_written_a_range_at_a_time_is_the_whole_copy() {
    let dir = TempDir::new("las-range", "writer");
    let mut rng = Rng::new(11);
    for name in [
        "simple.las",
        "simple.copc.laz",
        "1_4_w_evlr.las",
        "1_4_w_evlr.laz",
        "extrabytes.las",
    ] {
        let path = fixture(name);
        let whole = read_points(&path, &all()).unwrap();
        let n = whole.points.len();
        let structure: Vec<i64> = (0..n).map(|_| rng.below(4) as i64 - 1).collect();
        let part: Vec<i64> = structure
            .iter()
            .map(|&s| if s < 0 { -1 } else { s * 3 })
            .collect();
        for ext in ["las", "laz"] {
            let reference = dir.path(&format!("whole.{ext}"));
            let labelled = Labelled {
                classify: Some(6),
                ..Labelled::new(&structure, &part)
            };
            write_labelled_cloud(&reference, &whole, &labelled).unwrap();
            let out = dir.path(&format!("ranges.{ext}"));
            let first = read_las_range(&path, 0, 1, &all()).unwrap();
            let src = first.las.as_deref().unwrap();
            let mut w = LasLabelWriter::create(&out, src, n as u64, Some(6)).unwrap();
            let mut start = 0;
            while start < n {
                let count = 1 + rng.below(400) as usize;
                let piece = read_las_range(&path, start as u64, count as u64, &all()).unwrap();
                let k = piece.points.len();
                let records = &piece.las.as_ref().unwrap().records;
                w.append(
                    records,
                    &structure[start..start + k],
                    &part[start..start + k],
                )
                .unwrap();
                start += k;
            }
            w.finish().unwrap();
            assert_eq!(
                std::fs::read(&out).unwrap(),
                std::fs::read(&reference).unwrap(),
                "{name} as {ext}"
            );
        }
    }
}

#[test]
fn an_incomplete_copy_is_an_error_and_leaves_no_file() {
    let dir = TempDir::new("las-range", "incomplete");
    let path = fixture("simple.laz");
    let piece = read_las_range(&path, 0, 10, &all()).unwrap();
    let src = piece.las.as_deref().unwrap();
    let ids = vec![-1i64; 10];
    let out = dir.path("out.laz");
    let mut w = LasLabelWriter::create(&out, src, 1065, None).unwrap();
    w.append(&src.records, &ids, &ids).unwrap();
    let e = w.finish().unwrap_err();
    assert!(
        e.to_string()
            .contains("10 records written, the header declares 1065"),
        "{e}"
    );
    let mut w = LasLabelWriter::create(&out, src, 5, None).unwrap();
    let e = w.append(&src.records, &ids, &ids).unwrap_err();
    assert!(
        e.to_string().contains("past the 5 the header declares"),
        "{e}"
    );
    let e = w.append(&src.records, &ids[..3], &ids).unwrap_err();
    assert!(
        e.to_string().contains("with 3 structure and 10 part ids"),
        "{e}"
    );
    drop(w);
    assert_eq!(std::fs::read_dir(&dir.0).unwrap().count(), 0);
}
