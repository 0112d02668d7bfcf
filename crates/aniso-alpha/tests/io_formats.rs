//! Readers and writers: round trips, fixtures written here, malformed input.

use std::path::Path;

use crate::common;
use common::TempDir;

use aniso_alpha::io::{
    read_labels, read_pcd_bytes, read_ply_bytes, read_points, read_points_bytes,
    write_labelled_cloud, write_labels, write_obj, write_ply, ClassSet, IoError, Labelled, Mesh,
    PlyEncoding, PointCloud, ReadOptions, ReadWarning,
};

fn tmp_dir(name: &str) -> TempDir {
    TempDir::new("io", name)
}

fn awkward_points() -> Vec<[f64; 3]> {
    vec![
        [0.0, -0.0, 1.0],
        [0.1, 0.2, 0.30000000000000004],
        [1e-300, -1e300, f64::MIN_POSITIVE],
        [f64::MAX, f64::MIN, f64::EPSILON],
        [123456.789, -9.87654321e-5, 2.0f64.sqrt()],
        [5e-324, 1.0 / 3.0, std::f64::consts::PI],
    ]
}

fn bits(p: &[[f64; 3]]) -> Vec<[u64; 3]> {
    p.iter().map(|q| q.map(f64::to_bits)).collect()
}

const NO_LABELS: ReadOptions = ReadOptions {
    label_column: None,
    read_labels: false,
    format: None,
    background_classes: ClassSet::LAS_BACKGROUND,
    attributes: false,
};

#[test]
fn ply_round_trip_ascii_and_binary_exact_bits() {
    let d = tmp_dir("ply-rt");
    let pts = awkward_points();
    let labels: Vec<i64> = vec![-1, 0, 1, 2, i32::MAX as i64, i32::MIN as i64];
    let edges = [[0u32, 1], [4, 5]];
    let faces = [[0u32, 1, 2], [3, 4, 5]];
    let mesh = Mesh {
        labels: Some(&labels),
        edges: &edges,
        faces: &faces,
        ..Mesh::new(&pts)
    };
    for (enc, name) in [
        (PlyEncoding::Ascii, "a.ply"),
        (PlyEncoding::BinaryLittleEndian, "b.PLY"),
    ] {
        let p = d.join(name);
        write_ply(&p, &mesh, enc).unwrap();
        let back = read_points(&p, &ReadOptions::with_labels(3)).unwrap();
        assert_eq!(bits(&back.points), bits(&pts), "{name}");
        assert_eq!(back.labels.as_deref(), Some(&labels[..]), "{name}");
        let plain = read_points(&p, &NO_LABELS).unwrap();
        assert_eq!(plain.labels, None);
    }
    // Without labels or topology.
    let p = d.join("c.ply");
    write_ply(&p, &Mesh::new(&pts), PlyEncoding::Ascii).unwrap();
    let back = read_points(&p, &ReadOptions::with_labels(3)).unwrap();
    assert_eq!(bits(&back.points), bits(&pts));
    assert_eq!(back.labels, None);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn ply_writer_rejects_bad_indices_and_leaves_nothing() {
    let d = tmp_dir("ply-bad");
    let pts = [[0.0; 3]; 3];
    let p = d.join("x.ply");
    let e = write_ply(
        &p,
        &Mesh {
            faces: &[[0, 1, 3]],
            ..Mesh::new(&pts)
        },
        PlyEncoding::Ascii,
    )
    .unwrap_err();
    assert!(e.to_string().contains("x.ply"), "{e}");
    assert!(e.to_string().contains("out of range"), "{e}");
    assert!(!p.exists());
    let e = write_ply(
        &p,
        &Mesh {
            labels: Some(&[1, 2]),
            ..Mesh::new(&pts)
        },
        PlyEncoding::BinaryLittleEndian,
    )
    .unwrap_err();
    assert!(e.to_string().contains("2 labels for 3 points"), "{e}");
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
    let e = write_ply(
        &d.join("missing").join("x.ply"),
        &Mesh::new(&pts),
        PlyEncoding::Ascii,
    )
    .unwrap_err();
    assert!(matches!(e, IoError::MissingFolder { .. }));
    std::fs::remove_dir_all(&d).unwrap();
}

/// A PLY with faces before the vertices, a list property inside the vertex
/// element, extra properties of every scalar type, in big endian.
fn big_endian_fixture(count_lie: Option<usize>) -> Vec<u8> {
    let n = 3usize;
    let mut h = String::from("ply\r\nformat binary_big_endian 1.0\ncomment fixture\n");
    h += "element face 2\nproperty list uint8 int32 vertex_indices\nproperty uchar flag\n";
    h += &format!("element vertex {}\n", count_lie.unwrap_or(n));
    h += "property char c\nproperty ushort us\nproperty float x\nproperty list uchar float normals\n";
    h += "property double y\nproperty short s\nproperty uint u\nproperty int32 z\nproperty int structure\n";
    h += "element extra 1\nproperty float64 v\nend_header\n";
    let mut b = h.into_bytes();
    // faces
    for f in [[0i32, 1, 2], [2, 1, 0]] {
        b.push(3);
        for v in f {
            b.extend_from_slice(&v.to_be_bytes());
        }
        b.push(7);
    }
    for i in 0..n {
        b.push(0xff);
        b.extend_from_slice(&65535u16.to_be_bytes());
        b.extend_from_slice(&(i as f32 + 0.5).to_be_bytes());
        b.push(i as u8); // list of i floats
        for k in 0..i {
            b.extend_from_slice(&(k as f32).to_be_bytes());
        }
        b.extend_from_slice(&(-(i as f64) * 0.25).to_be_bytes());
        b.extend_from_slice(&(-3i16).to_be_bytes());
        b.extend_from_slice(&u32::MAX.to_be_bytes());
        b.extend_from_slice(&(-(i as i32) * 1000).to_be_bytes());
        b.extend_from_slice(&(i as i32 - 1).to_be_bytes());
    }
    b.extend_from_slice(&1.5f64.to_be_bytes());
    b
}

#[test]
fn ply_big_endian_lists_and_extra_elements() {
    let bytes = big_endian_fixture(None);
    let c = read_ply_bytes(Path::new("be.ply"), &bytes, &ReadOptions::with_labels(0)).unwrap();
    assert_eq!(
        c.points,
        vec![[0.5, 0.0, 0.0], [1.5, -0.25, -1000.0], [2.5, -0.5, -2000.0]]
    );
    assert_eq!(c.labels, Some(vec![-1, 0, 1]));
    // Truncated anywhere: an error naming the file, never a panic.
    for cut in 0..bytes.len() {
        let e = read_ply_bytes(Path::new("be.ply"), &bytes[..cut], &NO_LABELS).unwrap_err();
        assert!(e.to_string().starts_with("be.ply"), "{e}");
    }
    let e = read_ply_bytes(
        Path::new("be.ply"),
        &big_endian_fixture(Some(4)),
        &NO_LABELS,
    )
    .unwrap_err();
    assert!(e.to_string().contains("truncated"), "{e}");
}

fn ascii_ply(header_count: usize, rows: &str) -> String {
    format!(
        "ply\nformat ascii 1.0\nelement vertex {header_count}\nproperty float x\nproperty float y\n\
         property float z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\n\
         end_header\n{rows}"
    )
}

#[test]
fn ply_ascii_and_its_errors() {
    let ok = ascii_ply(2, "1 2 3 255\n4 5 6 0\n3 0 1 0\n");
    let c = read_ply_bytes(Path::new("a.ply"), ok.as_bytes(), &NO_LABELS).unwrap();
    assert_eq!(c.points, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
    let cases = [
        (ascii_ply(3, "1 2 3 0\n4 5 6 0\n"), "a.ply:13:"),
        (
            ascii_ply(2, "1 2 3 0\n4 5\n3 0 1 0\n"),
            "a.ply:12: too few values",
        ),
        (
            ascii_ply(2, "1 2 3 0\n4 nan 6 0\n3 0 1 0\n"),
            "a.ply:12: non-finite",
        ),
        (
            ascii_ply(2, "1 2 3 0\n4 5 x 0\n3 0 1 0\n"),
            "a.ply:12: invalid value 'x'",
        ),
        (
            ascii_ply(2, "1 2 3 0\n4 5 6 0\n3 0 1\n"),
            "a.ply:13: too few values",
        ),
        (ascii_ply(0, "3 0 1 2\n"), "a.ply: no points"),
    ];
    for (text, want) in cases {
        let e = read_ply_bytes(Path::new("a.ply"), text.as_bytes(), &NO_LABELS).unwrap_err();
        assert!(e.to_string().starts_with(want), "{e} / {want}");
    }
}

#[test]
fn ply_header_errors() {
    let base = "ply\nformat binary_little_endian 1.0\nelement vertex 1\n";
    let cases = [
        ("plx\n", "not a PLY file"),
        ("ply\nelement vertex 1\nproperty float x\nend_header\n", "no 'format' line"),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n",
            "no 'end_header'",
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n",
            "no property 'z'",
        ),
        (
            "ply\nformat ascii 1.0\nelement face 1\nproperty float x\nend_header\n1\n",
            "no 'vertex' element",
        ),
        ("ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", "invalid count"),
        ("ply\nformat ascii 1.0\nproperty float x\nend_header\n", "property before"),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n", "unknown property type"),
        ("ply\nformat ebcdic 1.0\nend_header\n", "unknown PLY format"),
        ("ply\nformat ascii 1.0\nbogus\nend_header\n", "unexpected PLY header line"),
    ];
    for (text, want) in cases {
        let e = read_ply_bytes(Path::new("h.ply"), text.as_bytes(), &NO_LABELS).unwrap_err();
        let s = e.to_string();
        assert!(s.starts_with("h.ply") && s.contains(want), "{s} / {want}");
    }
    // Binary vertex count lie and a vertex property that is a list.
    let lie =
        format!("{base}property double x\nproperty double y\nproperty double z\nend_header\n");
    let e = read_ply_bytes(Path::new("h.ply"), lie.as_bytes(), &NO_LABELS).unwrap_err();
    assert!(e.to_string().contains("truncated"), "{e}");
    let list = format!(
        "{base}property list uchar float x\nproperty float y\nproperty float z\nend_header\n"
    );
    let e = read_ply_bytes(Path::new("h.ply"), list.as_bytes(), &NO_LABELS).unwrap_err();
    assert!(e.to_string().contains("is a list"), "{e}");
    // Huge counts do not allocate.
    let huge = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nend_header\n",
        usize::MAX
    );
    assert!(read_ply_bytes(Path::new("h.ply"), huge.as_bytes(), &NO_LABELS).is_err());
    let huge_list = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty list uint float n\nproperty double x\nproperty double y\nproperty double z\nend_header\n\x01\x00\x00\x00",
        usize::MAX
    );
    assert!(read_ply_bytes(Path::new("h.ply"), huge_list.as_bytes(), &NO_LABELS).is_err());
}

fn pcd_header(data: &str, points: usize) -> String {
    format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb label\n\
         SIZE 4 8 4 4 4\nTYPE F F F F U\nCOUNT 1 1 1 1 1\nWIDTH {points}\nHEIGHT 1\n\
         VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {points}\nDATA {data}\n"
    )
}

fn pcd_binary_rows() -> Vec<u8> {
    let mut b = Vec::new();
    for i in 0..3u32 {
        b.extend_from_slice(&(i as f32).to_le_bytes());
        b.extend_from_slice(&(i as f64 * 0.5).to_le_bytes());
        b.extend_from_slice(&(-(i as f32)).to_le_bytes());
        b.extend_from_slice(&0f32.to_le_bytes());
        b.extend_from_slice(&(i * 10).to_le_bytes());
    }
    b
}

/// LZF with literals only (valid LZF, no compression).
fn lzf_literals(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    for chunk in data.chunks(32) {
        out.push((chunk.len() - 1) as u8);
        out.extend_from_slice(chunk);
    }
    out
}

#[test]
fn pcd_ascii_binary_compressed() {
    let want = vec![[0.0, 0.0, -0.0], [1.0, 0.5, -1.0], [2.0, 1.0, -2.0]];
    let labels = ReadOptions::with_labels(0);
    let ascii = pcd_header("ascii", 3) + "0 0 -0 0 0\n1 0.5 -1 0 10\n\n2 1 -2 0 20\n";
    let c = read_pcd_bytes(Path::new("c.pcd"), ascii.as_bytes(), &labels).unwrap();
    assert_eq!(c.points, want);
    assert_eq!(c.labels, Some(vec![0, 10, 20]));

    let mut bin = pcd_header("binary", 3).into_bytes();
    bin.extend(pcd_binary_rows());
    let c = read_pcd_bytes(Path::new("c.pcd"), &bin, &labels).unwrap();
    assert_eq!(c.points, want);
    assert_eq!(c.labels, Some(vec![0, 10, 20]));
    for cut in 0..bin.len() {
        assert!(read_pcd_bytes(Path::new("c.pcd"), &bin[..cut], &labels).is_err());
    }

    // Column-major layout for binary_compressed.
    let rows = pcd_binary_rows();
    let sizes = [4usize, 8, 4, 4, 4];
    let mut cols = Vec::new();
    let mut off = 0;
    for s in sizes {
        for i in 0..3 {
            let start = i * 24 + off;
            cols.extend_from_slice(&rows[start..start + s]);
        }
        off += s;
    }
    let comp = lzf_literals(&cols);
    let mut c_bytes = pcd_header("binary_compressed", 3).into_bytes();
    c_bytes.extend_from_slice(&(comp.len() as u32).to_le_bytes());
    c_bytes.extend_from_slice(&(cols.len() as u32).to_le_bytes());
    c_bytes.extend_from_slice(&comp);
    let c = read_pcd_bytes(Path::new("c.pcd"), &c_bytes, &labels).unwrap();
    assert_eq!(c.points, want);
    assert_eq!(c.labels, Some(vec![0, 10, 20]));
    for cut in 0..c_bytes.len() {
        assert!(read_pcd_bytes(Path::new("c.pcd"), &c_bytes[..cut], &labels).is_err());
    }

    let errors = [
        (
            pcd_header("ascii", 4) + "0 0 0 0 0\n",
            "c.pcd:13: PCD file ends early",
        ),
        (
            pcd_header("ascii", 1) + "0 0 0\n",
            "c.pcd:12: expected 5 values, found 3",
        ),
        (
            pcd_header("ascii", 1) + "0 inf 0 0 0\n",
            "c.pcd:12: non-finite",
        ),
        (pcd_header("ascii", 0), "c.pcd: no points"),
        (pcd_header("lzma", 1), "unknown PCD DATA"),
        (
            "FIELDS a b c\nPOINTS 1\nDATA ascii\n1 2 3\n".to_string(),
            "no field 'x'",
        ),
        (
            "FIELDS x y z\nSIZE 4 4\nPOINTS 1\nDATA ascii\n1 2 3\n".to_string(),
            "different lengths",
        ),
        ("FIELDS x y z\nDATA ascii\n1 2 3\n".to_string(), "no POINTS"),
        ("FIELDS x y z\nPOINTS 1\n".to_string(), "no DATA"),
        // Issue 19 §1: a field of COUNT 0 (ascii: index out of bounds;
        // binary: zero stride, 10M points from 12 bytes, or 96 GB reserved).
        (
            "FIELDS x y z i\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 0\nPOINTS 1\nDATA ascii\n1 2 3\n"
                .to_string(),
            "field 'i' has SIZE 4 and COUNT 0",
        ),
        (
            "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 0 0 0\nPOINTS 10000000\nDATA binary\n\0\0\0\0\0\0\0\0\0\0\0\0"
                .to_string(),
            "COUNT 0",
        ),
        (
            "FIELDS x y z\nSIZE 4 4 0\nTYPE F F F\nPOINTS 4000000000\nDATA binary_compressed\n"
                .to_string(),
            "SIZE 0",
        ),
        (
            "FIELDS x y z\nWIDTH 2\nHEIGHT 2\nPOINTS 3\nDATA ascii\n1 2 3\n1 2 3\n1 2 3\n"
                .to_string(),
            "POINTS 3 differs from WIDTH × HEIGHT = 2 × 2 = 4",
        ),
    ];
    for (text, want) in errors {
        let e = read_pcd_bytes(Path::new("c.pcd"), text.as_bytes(), &labels).unwrap_err();
        assert!(
            e.to_string().starts_with("c.pcd") && e.to_string().contains(want),
            "{e} / {want}"
        );
    }
}

/// A PCD header of `width` × `height` points of x y z, `data` ascii or
/// binary.
fn organized_header(data: &str, width: usize, height: usize) -> String {
    format!(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {width}\n\
         HEIGHT {height}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA {data}\n",
        width * height
    )
}

#[test]
fn an_organized_pcd_keeps_its_pixels_without_a_return_as_nan_rows() {
    let none = ReadOptions::default();
    // A 3 × 2 depth image (ascii, as PCL writes it) with two pixels
    // without a return: every row is kept, in file order.
    let ascii =
        organized_header("ascii", 3, 2) + "0 0 1\nnan nan nan\n2 0 1\n0 1 1\n1 1 1\nnan nan nan\n";
    let c = read_pcd_bytes(Path::new("o.pcd"), ascii.as_bytes(), &none).unwrap();
    assert_eq!(c.points.len(), 6);
    assert!(c.points[1].iter().all(|v| v.is_nan()) && c.points[5][2].is_nan());
    assert_eq!(c.points[4], [1.0, 1.0, 1.0]);
    assert_eq!(c.finite_rows(), Some(vec![0, 2, 3, 4]));
    assert_eq!(c.warnings, [ReadWarning::NoReturn { count: 2, of: 6 }]);
    assert_eq!(
        c.warnings[0].to_string(),
        "2 of 6 points of the organized cloud have no return (NaN coordinates)"
    );
    let kept = c.select(&[0, 4]);
    assert_eq!(kept.points, [[0.0, 0.0, 1.0], [1.0, 1.0, 1.0]]);
    assert_eq!(kept.finite_rows(), None);

    // The same image binary: the same rows.
    let mut bin = organized_header("binary", 3, 2).into_bytes();
    for p in &c.points {
        for v in p {
            bin.extend_from_slice(&(*v as f32).to_le_bytes());
        }
    }
    let b = read_pcd_bytes(Path::new("o.pcd"), &bin, &none).unwrap();
    assert_eq!(b.finite_rows(), c.finite_rows());
    assert_eq!(b.points[3], c.points[3]);

    // One row (HEIGHT 1) is no image: NaN stays an input error (SPEC §1),
    // and an image with no return at all is refused.
    let flat = organized_header("ascii", 6, 1) + "0 0 1\nnan nan nan\n2 0 1\n0 1 1\n1 1 1\n1 2 1\n";
    let e = read_pcd_bytes(Path::new("o.pcd"), flat.as_bytes(), &none).unwrap_err();
    assert!(e.to_string().contains("non-finite"), "{e}");
    let empty = organized_header("ascii", 1, 2) + "nan nan nan\nnan nan nan\n";
    let e = read_pcd_bytes(Path::new("o.pcd"), empty.as_bytes(), &none).unwrap_err();
    assert!(
        e.to_string()
            .contains("every point of the organized cloud is NaN"),
        "{e}"
    );
    // Every other reader's cloud is finite: no rows to leave out.
    let t = read_points_bytes(Path::new("t.xyz"), b"0 0 0\n1 0 0\n", &none).unwrap();
    assert_eq!(t.finite_rows(), None);
}

#[test]
fn a_cloud_with_nan_rows_is_written_as_ply_and_refused_as_las() {
    let dir = tmp_dir("nan-rows");
    let cloud = PointCloud {
        points: vec![[0.0, 0.0, 0.0], [f64::NAN; 3], [1.0, 0.0, 0.0]],
        ..PointCloud::default()
    };
    let ids = [0, -1, 0];
    let ply = dir.path("o.ply");
    write_labelled_cloud(&ply, &cloud, &Labelled::new(&ids, &ids)).unwrap();
    let back = read_points(&ply, &ReadOptions::default());
    // The PLY keeps every row, NaN where there was no return (as PCL and
    // CloudCompare write such clouds); a PLY is no organized cloud, so
    // reading it back refuses the NaN (SPEC §1).
    assert!(back.unwrap_err().to_string().contains("non-finite"));
    for name in ["o.las", "o.laz"] {
        let out = dir.path(name);
        let e = write_labelled_cloud(&out, &cloud, &Labelled::new(&ids, &ids)).unwrap_err();
        assert!(
            e.to_string()
                .contains("cannot hold points without a return"),
            "{e}"
        );
        assert!(!out.exists(), "{name}: nothing is written");
    }
}

#[test]
fn extension_dispatch_and_file_errors() {
    let d = tmp_dir("dispatch");
    let p = d.join("pts.TXT");
    std::fs::write(&p, "1 2 3\n1;2;3\n").unwrap();
    let e = read_points(&p, &NO_LABELS).unwrap_err();
    assert!(
        e.to_string().contains("pts.TXT:2: invalid number '1;2;3'"),
        "{e}"
    );
    std::fs::write(&p, "1 2 3\n").unwrap();
    assert_eq!(
        read_points(&p, &NO_LABELS).unwrap().points,
        vec![[1.0, 2.0, 3.0]]
    );
    let e = read_points(&d.join("a.e58"), &NO_LABELS).unwrap_err();
    assert!(matches!(e, IoError::UnknownFormat { .. }));
    let e = read_points(&d.join("missing.xyz"), &NO_LABELS).unwrap_err();
    assert!(matches!(e, IoError::Open { .. }));
    assert!(e.to_string().contains("missing.xyz"));
    let sub = d.join("dir.xyz");
    std::fs::create_dir(&sub).unwrap();
    let e = read_points(&sub, &NO_LABELS).unwrap_err();
    assert!(matches!(e, IoError::IsDirectory { .. }), "{e}");
    let e = read_points_bytes(Path::new("x"), b"1 2 3", &NO_LABELS).unwrap_err();
    assert!(matches!(e, IoError::UnknownFormat { .. }));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn labels_and_obj_files() {
    let d = tmp_dir("labels");
    let p = d.join("l.txt");
    let labels: Vec<i64> = (-5..1000).collect();
    write_labels(&p, &labels).unwrap();
    assert_eq!(read_labels(&p).unwrap(), labels);
    std::fs::write(&p, "1\n2 3\n").unwrap();
    let e = read_labels(&p).unwrap_err();
    assert!(
        e.to_string()
            .ends_with("l.txt:2: expected one integer label, found '2 3'"),
        "{e}"
    );
    let o = d.join("m.obj");
    let pts = [[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [0.0, 1.0, 0.0]];
    write_obj(
        &o,
        &Mesh {
            faces: &[[0, 1, 2]],
            edges: &[[2, 0]],
            ..Mesh::new(&pts)
        },
    )
    .unwrap();
    let text = std::fs::read_to_string(&o).unwrap();
    assert_eq!(
        text,
        "# written by aniso-alpha\nv 0 0 0\nv 1 0.5 0\nv 0 1 0\nf 1 2 3\nl 3 1\n"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[cfg(feature = "las")]
#[test]
fn las_and_laz_round_trip() {
    let d = tmp_dir("las");
    for name in ["p.las", "p.LAZ"] {
        let path = d.join(name);
        let mut builder = las::Builder::from((1, 4));
        builder.transforms = las::Vector {
            x: las::Transform {
                scale: 0.001,
                offset: 1000.0,
            },
            y: las::Transform {
                scale: 0.01,
                offset: -5.0,
            },
            z: las::Transform {
                scale: 0.5,
                offset: 0.0,
            },
        };
        if name.ends_with("LAZ") {
            builder.point_format.is_compressed = true;
        }
        let header = builder.into_header().unwrap();
        let mut w = las::Writer::from_path(&path, header).unwrap();
        for i in 0..5 {
            w.write_point(las::Point {
                x: 1000.0 + i as f64 * 0.125,
                y: -5.0 + i as f64,
                z: i as f64 * 2.0,
                classification: las::point::Classification::new(i as u8 + 1).unwrap(),
                ..Default::default()
            })
            .unwrap();
        }
        w.close().unwrap();
        drop(w);
        let c = read_points(&path, &ReadOptions::with_labels(0)).unwrap();
        assert_eq!(c.points.len(), 5);
        assert_eq!(c.points[2], [1000.25, -3.0, 4.0]);
        // Class 1 (unclassified) is background by default.
        assert_eq!(c.labels, Some(vec![-1, 2, 3, 4, 5]));
        let custom = ReadOptions {
            background_classes: ClassSet::from_classes(&[3, 5]),
            ..ReadOptions::with_labels(0)
        };
        let c = read_points(&path, &custom).unwrap();
        assert_eq!(c.labels, Some(vec![1, 2, -1, 4, -1]));
        let bytes = std::fs::read(&path).unwrap();
        for cut in (0..bytes.len()).step_by(7) {
            let r = aniso_alpha::io::read_las_bytes(&path, &bytes[..cut], &NO_LABELS);
            assert!(r.is_err(), "{name} cut at {cut}");
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// A LAS (or LAZ) file of `n` points in point format `format` with
/// `extra` extra bytes, written by the `las` crate.
#[cfg(feature = "las")]
fn las_file(format: u8, extra: u16, compressed: bool, n: usize) -> Option<Vec<u8>> {
    let mut builder = las::Builder::from((1, 4));
    builder.point_format = las::point::Format::new(format).ok()?;
    builder.point_format.extra_bytes = extra;
    builder.point_format.is_compressed = compressed;
    builder.transforms = las::Vector {
        x: las::Transform {
            scale: 0.01,
            offset: 100.0,
        },
        y: las::Transform {
            scale: 0.01,
            offset: 0.0,
        },
        z: las::Transform {
            scale: 0.001,
            offset: 0.0,
        },
    };
    let header = builder.into_header().ok()?;
    let mut w = las::Writer::new(std::io::Cursor::new(Vec::new()), header).ok()?;
    let f = las::point::Format::new(format).ok()?;
    for i in 0..n {
        let p = las::Point {
            x: 100.0 + (i % 17) as f64 * 0.25,
            y: (i / 17) as f64 * 0.5,
            z: (i % 5) as f64 * 0.125,
            intensity: (i * 37 % 65536) as u16,
            return_number: 1,
            number_of_returns: 1,
            classification: las::point::Classification::new((i % 7) as u8).ok()?,
            gps_time: f.has_gps_time.then_some(i as f64 * 0.001),
            color: f
                .has_color
                .then_some(las::Color::new(i as u16, 2 * i as u16, 3)),
            nir: f.has_nir.then_some(i as u16),
            waveform: f.has_waveform.then(las::raw::point::Waveform::default),
            extra_bytes: (0..extra).map(|k| (i + k as usize) as u8).collect(),
            ..Default::default()
        };
        w.write_point(p).ok()?;
    }
    w.close().ok()?;
    Some(w.into_inner().ok()?.into_inner())
}

/// Byte offset of the laszip VLR's payload in a LAZ file.
#[cfg(feature = "las")]
fn laszip_vlr_at(b: &[u8]) -> usize {
    let header_size = u16::from_le_bytes([b[94], b[95]]) as usize;
    let n = u32::from_le_bytes(b[100..104].try_into().unwrap());
    let mut pos = header_size;
    for _ in 0..n {
        let len = u16::from_le_bytes([b[pos + 20], b[pos + 21]]) as usize;
        if &b[pos + 2..pos + 16] == b"laszip encoded" {
            return pos + 54;
        }
        pos += 54 + len;
    }
    panic!("no laszip VLR");
}

#[cfg(feature = "las")]
#[test]
fn laz_of_every_point_format_reads_like_las() {
    for format in 0..=10u8 {
        for extra in [0u16, 3] {
            let (Some(las), Some(laz)) = (
                las_file(format, extra, false, 300),
                las_file(format, extra, true, 300),
            ) else {
                panic!("format {format}: the las crate could not write it");
            };
            let a =
                read_points_bytes(Path::new("a.las"), &las, &ReadOptions::with_labels(0)).unwrap();
            let b = read_points_bytes(Path::new("a.laz"), &laz, &ReadOptions::with_labels(0))
                .unwrap_or_else(|e| panic!("format {format} extra {extra}: {e}"));
            assert_eq!(a, b, "format {format} extra {extra}");
            assert_eq!(a.points.len(), 300);
            assert_eq!(a.points[18], [100.25, 0.5, 0.375]);
            assert_eq!(a.labels.as_ref().unwrap()[9], 2);
        }
    }
}

/// Hostile LAZ files (issue 19 §1): each is an error naming the file, with
/// no panic and no allocation beyond the file's size.
#[cfg(feature = "las")]
#[test]
fn laz_lies_are_errors() {
    for format in [1u8, 3, 6, 7] {
        let good = las_file(format, 2, true, 2000).unwrap();
        let vlr = laszip_vlr_at(&good);
        let data_start = u32::from_le_bytes(good[96..100].try_into().unwrap()) as usize;
        let table = u64::from_le_bytes(good[data_start..data_start + 8].try_into().unwrap());
        let table = table as usize;
        let mut cases: Vec<(&str, Vec<u8>, &str)> = Vec::new();
        // num_items = 0 (the laz crate panicked in details.rs).
        let mut b = good.clone();
        b[vlr + 32..vlr + 34].copy_from_slice(&0u16.to_le_bytes());
        cases.push(("no items", b, "no items"));
        // An item of the wrong type for the point format.
        let mut b = good.clone();
        b[vlr + 34..vlr + 36].copy_from_slice(&7u16.to_le_bytes());
        cases.push(("wrong item", b, "do not describe point format"));
        // A chunk count patched to 0xFFFFFFFF (35–69 GB allocated, abort).
        let mut b = good.clone();
        b[table + 4..table + 8].copy_from_slice(&u32::MAX.to_le_bytes());
        cases.push(("chunk count", b, "chunks"));
        // A chunk table offset past the end of the file.
        let mut b = good.clone();
        b[data_start..data_start + 8].copy_from_slice(&(1u64 << 40).to_le_bytes());
        cases.push(("table offset", b, "chunk table"));
        // A point count far beyond what the data can hold.
        let mut b = good.clone();
        if format >= 6 {
            b[247..255].copy_from_slice(&(1u64 << 40).to_le_bytes());
        } else {
            b[107..111].copy_from_slice(&u32::MAX.to_le_bytes());
        }
        cases.push(("point count", b, "points"));
        if format >= 6 {
            // A layer size of 4 GB in the first chunk (resized, zero-filled).
            let mut b = good.clone();
            let at = data_start + 8 + b[105] as usize + 4;
            b[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
            cases.push(("layer size", b, "layers"));
        }
        for (what, bytes, want) in cases {
            let e = read_points_bytes(Path::new("bad.laz"), &bytes, &NO_LABELS)
                .expect_err(what)
                .to_string();
            assert!(e.starts_with("bad.laz: "), "{what}: {e}");
            assert!(e.contains(want), "format {format}, {what}: {e}");
        }
        // Every one-byte corruption of the compressed data: points or an
        // error, never a panic or an abort.
        for at in (data_start + 8..table).step_by(13) {
            let mut b = good.clone();
            b[at] ^= 0x5A;
            let _ = read_points_bytes(Path::new("bad.laz"), &b, &NO_LABELS);
        }
    }
}

/// Writes the LAS fuzz target's seeds: LAS and LAZ files of every point
/// format. Run with `--ignored` after a change of the format support.
#[cfg(feature = "las")]
#[test]
#[ignore = "writes fuzz/corpus_seeds/las"]
fn write_fuzz_seeds() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus_seeds/las");
    std::fs::create_dir_all(&dir).unwrap();
    for format in 0..=10u8 {
        for (compressed, ext) in [(false, "las"), (true, "laz")] {
            let b = las_file(format, if format % 3 == 0 { 2 } else { 0 }, compressed, 40).unwrap();
            std::fs::write(dir.join(format!("format{format}.{ext}")), b).unwrap();
        }
    }
}

/// Issue 19 §4: PLY values outside their declared type are errors.
#[test]
fn ply_values_must_fit_their_type() {
    let head = |ty: &str, label: &str| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty {ty} x\nproperty float y\n\
             property float z\nproperty {label} label\nend_header\n"
        )
    };
    let labels = ReadOptions::with_labels(3);
    for (ty, value, want) in [
        ("uchar", "300", "out of range for a uchar"),
        ("uchar", "-5", "out of range for a uchar"),
        ("uchar", "1.5", "not an integer"),
        ("int", "1e20", "not an integer"),
        ("short", "40000", "out of range for a short"),
    ] {
        let text = head(ty, "int") + &format!("{value} 0 0 1\n");
        let e = read_ply_bytes(Path::new("t.ply"), text.as_bytes(), &labels).unwrap_err();
        let e = e.to_string();
        assert!(e.starts_with("t.ply:9: invalid value"), "{ty} {value}: {e}");
        assert!(e.contains(want), "{ty} {value}: {e}");
    }
    let ok = head("uchar", "int") + "255 0 0 -7\n";
    let c = read_ply_bytes(Path::new("t.ply"), ok.as_bytes(), &labels).unwrap();
    assert_eq!((c.points[0][0], c.labels.unwrap()[0]), (255.0, -7));
    // A NaN or fractional float label is an error, not 0 (ascii and binary).
    for v in ["nan", "1.5"] {
        let text = head("float", "float") + &format!("1 0 0 {v}\n");
        let e = read_ply_bytes(Path::new("t.ply"), text.as_bytes(), &labels).unwrap_err();
        assert!(e.to_string().contains("is not an integer"), "{v}: {e}");
    }
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n\
property float y\nproperty float z\nproperty float label\nend_header\n"
        .to_vec();
    for v in [1.0f32, 2.0, 3.0, f32::NAN] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    let e = read_ply_bytes(Path::new("b.ply"), &b, &labels).unwrap_err();
    assert!(e.to_string().contains("label NaN is not an integer"), "{e}");
}
