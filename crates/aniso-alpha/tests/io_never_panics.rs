//! Byte-fuzz properties: no reader panics on arbitrary input, and mutated
//! valid files give either points or an error naming the file.

use std::path::Path;

use aniso_alpha::io::{read_labels_bytes, read_points_bytes, ReadOptions};
use proptest::prelude::*;

const NAMES: [&str; 5] = ["f.xyz", "f.ply", "f.pcd", "f.las", "f.laz"];

fn opts(labels: bool) -> ReadOptions {
    // Attributes are kept on the label runs: both paths are fuzzed.
    if labels {
        ReadOptions {
            attributes: true,
            ..ReadOptions::with_labels(3)
        }
    } else {
        ReadOptions::default()
    }
}

fn check(name: &str, bytes: &[u8], labels: bool) {
    match read_points_bytes(Path::new(name), bytes, &opts(labels)) {
        Ok(c) => {
            assert!(!c.points.is_empty());
            assert!(c.points.iter().flatten().all(|v| v.is_finite()));
            if let Some(l) = &c.labels {
                assert_eq!(l.len(), c.points.len());
            }
            for a in &c.attributes {
                assert_eq!(a.values.len(), c.points.len(), "{}", a.name);
            }
        }
        Err(e) => {
            let s = e.to_string();
            assert!(s.contains(name), "{s}");
            assert_eq!(s.lines().count(), 1, "{s}");
        }
    }
}

const PLY_SEED: &[u8] = b"ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uchar int vertex_indices\nelement vertex 2\nproperty float x\nproperty double y\nproperty short z\nproperty int label\nend_header\n\x03\x00\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x00\xf0\x3f\x02\x00\x05\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x00\xf0\x3f\x02\x00\x05\x00\x00\x00";
const PLY_ASCII_SEED: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty list uchar int l\nend_header\n1 2 3 2 0 1\n4 5 6 0\n";
const PCD_SEED: &[u8] = b"VERSION .7\nFIELDS x y z label\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary_compressed\n\x1c\x00\x00\x00\x20\x00\x00\x00\x0f\x00\x00\x80\x3f\x00\x00\x00\x40\x00\x00\x40\x40\x00\x00\x80\x40\xc0\x0f\x07\x05\x00\x00\x00\x06\x00\x00\x00";
const XYZ_SEED: &[u8] = b"# c\nx y z l\n1 2 3 4\n-1.5e3,2,3,-1 # t\n\n";

fn mutate(seed: &[u8], edits: &[(usize, u8)], cut: usize) -> Vec<u8> {
    let mut b = seed.to_vec();
    for &(i, v) in edits {
        if !b.is_empty() {
            let k = i % b.len();
            b[k] = v;
        }
    }
    b.truncate(cut % (b.len() + 1));
    b
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512), labels: bool) {
        for name in NAMES {
            check(name, &bytes, labels);
        }
        let _ = read_labels_bytes(Path::new("l.txt"), &bytes);
    }

    #[test]
    fn arbitrary_text_never_panics(text in "[0-9a-z .,#eE+\\-\n\r\t]{0,300}", labels: bool) {
        check("f.xyz", text.as_bytes(), labels);
        let _ = read_labels_bytes(Path::new("l.txt"), text.as_bytes());
    }

    #[test]
    fn mutated_seeds_never_panic(
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 0..6),
        cut in any::<usize>(),
        labels: bool,
    ) {
        check("f.ply", &mutate(PLY_SEED, &edits, cut), labels);
        check("f.ply", &mutate(PLY_ASCII_SEED, &edits, cut), labels);
        check("f.pcd", &mutate(PCD_SEED, &edits, cut), labels);
        check("f.xyz", &mutate(XYZ_SEED, &edits, cut), labels);
    }
}

#[test]
fn seeds_are_valid() {
    let o = ReadOptions::with_labels(3);
    let c = read_points_bytes(Path::new("s.ply"), PLY_SEED, &o).unwrap();
    assert_eq!(c.points, vec![[1.0, 1.0, 2.0], [1.0, 1.0, 2.0]]);
    assert_eq!(c.labels, Some(vec![5, 5]));
    let c = read_points_bytes(Path::new("s.ply"), PLY_ASCII_SEED, &o).unwrap();
    assert_eq!(c.points.len(), 2);
    let c = read_points_bytes(Path::new("s.pcd"), PCD_SEED, &o).unwrap();
    assert_eq!(c.points, vec![[1.0, 3.0, 1.0], [2.0, 4.0, 2.0]]);
    assert_eq!(c.labels, Some(vec![5, 6]));
    let c = read_points_bytes(Path::new("s.xyz"), XYZ_SEED, &o).unwrap();
    assert_eq!(c.labels, Some(vec![4, -1]));
}
