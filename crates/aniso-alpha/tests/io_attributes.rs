//! Per-point attributes: read from PLY, PCD and LAS/LAZ (real files from
//! laspy's test data and CGAL's `urban.las`, checked against the `las`
//! crate), and kept by `write_labelled_cloud` (LAS/LAZ records byte for
//! byte, PLY properties), with the structure and part ids added.
// Rows of every PLY scalar type, and loops over parallel columns.
#![allow(clippy::type_complexity, clippy::needless_range_loop)]

use std::path::Path;

use crate::common;
use common::TempDir;

use aniso_alpha::io::{
    read_points, read_points_bytes, write_labelled_cloud, Attribute, Labelled, PointCloud,
    ReadOptions, Values,
};

fn tmp_dir(name: &str) -> TempDir {
    TempDir::new("attr", name)
}

const WITH_ATTRS: ReadOptions = ReadOptions {
    label_column: None,
    read_labels: false,
    format: None,
    background_classes: aniso_alpha::io::ClassSet::EMPTY,
    attributes: true,
};

fn attr<'a>(c: &'a PointCloud, name: &str) -> &'a Values {
    &c.attributes
        .iter()
        .find(|a| a.name == name)
        .unwrap_or_else(|| panic!("no attribute {name}"))
        .values
}

fn names(c: &PointCloud) -> Vec<&str> {
    c.attributes.iter().map(|a| a.name.as_str()).collect()
}

#[test]
fn xyz_only_reads_keep_no_attributes() {
    let ply = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
property float z\nproperty uchar red\nend_header\n1 2 3 4\n";
    let c = read_points_bytes(Path::new("a.ply"), ply, &ReadOptions::default()).unwrap();
    assert!(c.attributes.is_empty() && c.las.is_none());
    let c = read_points_bytes(Path::new("a.ply"), ply, &WITH_ATTRS).unwrap();
    assert_eq!(
        c.attributes,
        vec![Attribute::new("red", Values::U8(vec![4]))]
    );
}

/// A PLY vertex element with a property of every type and a list, in
/// ascii, binary little and big endian.
fn ply_every_type(encoding: &str) -> Vec<u8> {
    let header = format!(
        "ply\nformat {encoding} 1.0\nelement vertex 2\nproperty double x\nproperty float y\n\
property int z\nproperty char c\nproperty uchar red\nproperty short s\nproperty ushort us\n\
property int i\nproperty uint ui\nproperty float nx\nproperty double t\n\
property list uchar int idx\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    );
    let rows: [(f64, f32, i32, i8, u8, i16, u16, i32, u32, f32, f64); 2] = [
        (
            0.5,
            1.25,
            3,
            -128,
            255,
            -32768,
            65535,
            i32::MIN,
            u32::MAX,
            0.1,
            1e300,
        ),
        (
            -1.0,
            -0.0,
            -7,
            127,
            0,
            32767,
            0,
            i32::MAX,
            0,
            -3.5e-38,
            -2.5,
        ),
    ];
    let mut out = header.into_bytes();
    for r in rows {
        if encoding == "ascii" {
            out.extend(
                format!(
                    "{} {} {} {} {} {} {} {} {} {} {} 2 0 1\n",
                    r.0, r.1, r.2, r.3, r.4, r.5, r.6, r.7, r.8, r.9, r.10
                )
                .bytes(),
            );
            continue;
        }
        let big = encoding == "binary_big_endian";
        macro_rules! put {
            ($v:expr) => {
                if big {
                    out.extend_from_slice(&$v.to_be_bytes())
                } else {
                    out.extend_from_slice(&$v.to_le_bytes())
                }
            };
        }
        put!(r.0);
        put!(r.1);
        put!(r.2);
        put!(r.3);
        put!(r.4);
        put!(r.5);
        put!(r.6);
        put!(r.7);
        put!(r.8);
        put!(r.9);
        put!(r.10);
        out.push(2);
        put!(0i32);
        put!(1i32);
    }
    if encoding == "ascii" {
        out.extend_from_slice(b"3 0 1 0\n");
    } else {
        let big = encoding == "binary_big_endian";
        out.push(3);
        for v in [0i32, 1, 0] {
            out.extend_from_slice(&if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
    }
    out
}

fn expected_ply_attributes() -> Vec<Attribute> {
    vec![
        Attribute::new("c", Values::I8(vec![-128, 127])),
        Attribute::new("red", Values::U8(vec![255, 0])),
        Attribute::new("s", Values::I16(vec![-32768, 32767])),
        Attribute::new("us", Values::U16(vec![65535, 0])),
        Attribute::new("i", Values::I32(vec![i32::MIN, i32::MAX])),
        Attribute::new("ui", Values::U32(vec![u32::MAX, 0])),
        Attribute::new("nx", Values::F32(vec![0.1, -3.5e-38])),
        Attribute::new("t", Values::F64(vec![1e300, -2.5])),
    ]
}

#[test]
fn ply_keeps_every_scalar_vertex_property_in_its_type() {
    for enc in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let c = read_points_bytes(Path::new("t.ply"), &ply_every_type(enc), &WITH_ATTRS)
            .unwrap_or_else(|e| panic!("{enc}: {e}"));
        assert_eq!(
            c.points,
            vec![[0.5, 1.25, 3.0], [-1.0, -0.0, -7.0]],
            "{enc}"
        );
        assert_eq!(c.attributes, expected_ply_attributes(), "{enc}");
    }
}

#[test]
fn ply_labelled_output_keeps_properties_and_adds_ids() {
    let d = tmp_dir("ply-out");
    for enc in ["ascii", "binary_big_endian"] {
        let c = read_points_bytes(Path::new("t.ply"), &ply_every_type(enc), &WITH_ATTRS).unwrap();
        let out = d.join("o.ply");
        let faces = [[0u32, 1, 0]];
        let l = Labelled {
            faces: &faces,
            element_labels: &[[0, 5]],
            ..Labelled::new(&[0, -1], &[5, -1])
        };
        write_labelled_cloud(&out, &c, &l).unwrap();
        let back = read_points(&out, &WITH_ATTRS).unwrap();
        assert_eq!(back.points, c.points);
        let mut want = vec![
            Attribute::new("structure", Values::I32(vec![0, -1])),
            Attribute::new("part", Values::I32(vec![5, -1])),
        ];
        want.extend(expected_ply_attributes());
        assert_eq!(back.attributes, want, "{enc}");
        let text = std::fs::read(&out).unwrap();
        let head = String::from_utf8_lossy(&text[..text.len().min(800)]).into_owned();
        assert!(
            head.contains("element face 1\nproperty list uchar int vertex_indices\nproperty int structure\nproperty int part\n"),
            "{head}"
        );
        // A second run on its own output: the old ids are kept apart.
        let l2 = Labelled::new(&[1, 1], &[2, 2]);
        write_labelled_cloud(&d.join("o2.ply"), &back, &l2).unwrap();
        let again = read_points(&d.join("o2.ply"), &WITH_ATTRS).unwrap();
        assert_eq!(
            &names(&again)[..4],
            ["structure", "part", "input_structure", "input_part"]
        );
        assert_eq!(attr(&again, "structure"), &Values::I32(vec![1, 1]));
        assert_eq!(attr(&again, "input_structure"), &Values::I32(vec![0, -1]));
    }
}

fn pcd(data: &str, fields: &str, size: &str, ty: &str, count: &str, body: &[u8]) -> Vec<u8> {
    let mut v = format!(
        "VERSION .7\nFIELDS {fields}\nSIZE {size}\nTYPE {ty}\nCOUNT {count}\nWIDTH 2\nHEIGHT 1\n\
VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA {data}\n"
    )
    .into_bytes();
    v.extend_from_slice(body);
    v
}

#[test]
fn pcd_keeps_fields_splits_counts_and_unpacks_rgb() {
    let fields = "x y z rgb intensity h _";
    let size = "4 4 4 4 2 4 1";
    let ty = "F F F F U F U";
    let count = "1 1 1 1 1 2 1";
    // rgb as PCL packs it: 0x00RRGGBB read as a float.
    let rgb = [0x00FF8001u32, 0x00010203];
    let rows: [([f32; 3], u16, [f32; 2]); 2] = [
        ([1.0, 2.0, 3.0], 7, [0.5, -1.5]),
        ([4.0, 5.0, 6.0], 65535, [2.0, 3.0]),
    ];
    let mut bin = Vec::new();
    for (k, (p, i, h)) in rows.iter().enumerate() {
        for v in p {
            bin.extend_from_slice(&v.to_le_bytes());
        }
        bin.extend_from_slice(&rgb[k].to_le_bytes());
        bin.extend_from_slice(&i.to_le_bytes());
        for v in h {
            bin.extend_from_slice(&v.to_le_bytes());
        }
        bin.push(0xAA);
    }
    let mut ascii = String::new();
    for (k, (p, i, h)) in rows.iter().enumerate() {
        ascii += &format!(
            "{} {} {} {:e} {} {} {} 0\n",
            p[0],
            p[1],
            p[2],
            f32::from_bits(rgb[k]),
            i,
            h[0],
            h[1]
        );
    }
    let want = vec![
        Attribute::new("red", Values::U8(vec![0xFF, 1])),
        Attribute::new("green", Values::U8(vec![0x80, 2])),
        Attribute::new("blue", Values::U8(vec![0x01, 3])),
        Attribute::new("intensity", Values::U16(vec![7, 65535])),
        Attribute::new("h_0", Values::F32(vec![0.5, 2.0])),
        Attribute::new("h_1", Values::F32(vec![-1.5, 3.0])),
    ];
    for (name, bytes) in [
        ("binary", pcd("binary", fields, size, ty, count, &bin)),
        (
            "ascii",
            pcd("ascii", fields, size, ty, count, ascii.as_bytes()),
        ),
    ] {
        let c = read_points_bytes(Path::new("c.pcd"), &bytes, &WITH_ATTRS)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(c.points, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], "{name}");
        assert_eq!(c.attributes, want, "{name}");
    }
}

// ------------------------------------------------------------------ LAS

#[cfg(feature = "las")]
const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/las");

/// The real LAS/LAZ files: laspy's test data (formats 1, 3, 4, 6, 7; LAS
/// 1.2 to 1.4; extended VLRs, a COPC file, described and undescribed
/// extra bytes) and CGAL's `urban.las`.
#[cfg(feature = "las")]
const REAL: [&str; 11] = [
    "simple.las",
    "simple.laz",
    "1_4_w_evlr.las",
    "1_4_w_evlr.laz",
    "extrabytes.las",
    "extra.laz",
    "unregistered_extra_bytes.las",
    "autzen.las",
    "simple1_3.las",
    "simple.copc.laz",
    "urban.las",
];

#[cfg(feature = "las")]
mod las_files {
    use super::*;
    use std::path::PathBuf;

    fn fixture(name: &str) -> PathBuf {
        Path::new(FIXTURES).join(name)
    }

    /// The `las` crate's reading of a file, as an independent oracle.
    fn las_points(path: &Path) -> (las::Header, Vec<las::Point>) {
        let mut r = las::Reader::from_path(path).unwrap();
        let h = r.header().clone();
        let pts: Vec<las::Point> = r.read_all().unwrap().points().map(|p| p.unwrap()).collect();
        (h, pts)
    }

    fn u8s(v: &Values) -> Vec<u8> {
        (0..v.len()).map(|i| v.get_f64(i) as u8).collect()
    }

    #[test]
    fn real_files_read_like_the_las_crate() {
        for name in REAL {
            let path = fixture(name);
            let c = read_points(&path, &WITH_ATTRS).unwrap_or_else(|e| panic!("{e}"));
            let (_, pts) = las_points(&path);
            assert_eq!(c.points.len(), pts.len(), "{name}");
            let n = pts.len();
            for (i, p) in pts.iter().enumerate() {
                assert_eq!(c.points[i], [p.x, p.y, p.z], "{name} point {i}");
            }
            let col = |a: &str| attr(&c, a);
            let ints = |a: &str| (0..n).map(|i| col(a).get_f64(i)).collect::<Vec<f64>>();
            let want = |f: &dyn Fn(&las::Point) -> f64| pts.iter().map(f).collect::<Vec<f64>>();
            assert_eq!(
                ints("intensity"),
                want(&|p| f64::from(p.intensity)),
                "{name}"
            );
            assert_eq!(ints("return_number"), want(&|p| f64::from(p.return_number)));
            assert_eq!(
                ints("number_of_returns"),
                want(&|p| f64::from(p.number_of_returns))
            );
            assert_eq!(ints("user_data"), want(&|p| f64::from(p.user_data)));
            assert_eq!(
                ints("point_source_id"),
                want(&|p| f64::from(p.point_source_id))
            );
            assert_eq!(
                ints("withheld"),
                want(&|p| f64::from(u8::from(p.is_withheld)))
            );
            assert_eq!(
                ints("edge_of_flight_line"),
                want(&|p| f64::from(u8::from(p.is_edge_of_flight_line)))
            );
            let classes = u8s(col("classification"));
            for (i, p) in pts.iter().enumerate() {
                // The las crate reads the legacy class 12 as the overlap flag.
                if !(p.is_overlap && classes[i] == 12) {
                    assert_eq!(classes[i], u8::from(p.classification), "{name} {i}");
                }
            }
            if pts[0].gps_time.is_some() {
                assert_eq!(ints("gps_time"), want(&|p| p.gps_time.unwrap_or(f64::NAN)));
            } else {
                assert!(!names(&c).contains(&"gps_time"), "{name}");
            }
            if pts[0].color.is_some() {
                assert_eq!(ints("red"), want(&|p| f64::from(p.color.unwrap().red)));
                assert_eq!(ints("green"), want(&|p| f64::from(p.color.unwrap().green)));
                assert_eq!(ints("blue"), want(&|p| f64::from(p.color.unwrap().blue)));
            }
            // The records kept are the file's (decompressed) records.
            let src = c.las.as_ref().expect("records kept");
            assert_eq!(src.records.len(), n * src.record_len, "{name}");
            for (i, p) in pts.iter().enumerate() {
                let rec = &src.records[i * src.record_len..(i + 1) * src.record_len];
                let extra = &rec[src.record_len - p.extra_bytes.len()..];
                assert_eq!(extra, &p.extra_bytes[..], "{name} {i}");
            }
        }
    }

    #[test]
    fn described_extra_bytes_are_typed_attributes() {
        // extrabytes.las: laspy's file with a field of every extra-bytes type.
        let c = read_points(&fixture("extrabytes.las"), &WITH_ATTRS).unwrap();
        let n = names(&c);
        // Colors: an array of 3 u16; Reserved: 7 undocumented bytes (data
        // type 0); Flags: an array of 2.
        let wanted = [
            "Colors_0",
            "Colors_1",
            "Colors_2",
            "Reserved_0",
            "Reserved_6",
            "Flags_0",
            "Flags_1",
            "Intensity",
            "Time",
        ];
        for want in wanted {
            assert!(n.contains(&want), "{want} not in {n:?}");
        }
        // Undescribed extra bytes are u8 columns by offset.
        let u = read_points(&fixture("unregistered_extra_bytes.las"), &WITH_ATTRS).unwrap();
        let n = names(&u);
        assert!(
            n.contains(&"extra_byte_0") && n.contains(&"extra_byte_3"),
            "{n:?}"
        );
    }

    /// Every byte of input record `i` is the start of output record `i`;
    /// the 8 bytes after it are the two ids (and the classification
    /// changed only where asked).
    fn check_records(
        name: &str,
        input: &PointCloud,
        output: &PointCloud,
        s: &[i64],
        p: &[i64],
        classify: Option<u8>,
    ) {
        let a = input.las.as_ref().unwrap();
        let b = output.las.as_ref().unwrap();
        assert_eq!(b.record_len, a.record_len + 8, "{name}");
        assert_eq!(b.point_format, a.point_format, "{name}");
        let (class_at, mask) = if a.point_format >= 6 {
            (16, 0xFF)
        } else {
            (15, 0x1F)
        };
        for i in 0..input.points.len() {
            let ra = &a.records[i * a.record_len..(i + 1) * a.record_len];
            let rb = &b.records[i * b.record_len..(i + 1) * b.record_len];
            let mut want = ra.to_vec();
            if let (Some(c), true) = (classify, s[i] >= 0) {
                want[class_at] = (want[class_at] & !mask) | c;
            }
            assert_eq!(&rb[..a.record_len], &want[..], "{name} record {i}");
            assert_eq!(
                &rb[a.record_len..a.record_len + 4],
                &(s[i] as i32).to_le_bytes()
            );
            assert_eq!(&rb[a.record_len + 4..], &(p[i] as i32).to_le_bytes());
        }
        // The same header but for what was adjusted.
        let (ha, hb) = (&a.header, &b.header);
        assert_eq!(ha.len(), hb.len(), "{name}");
        for (k, (x, y)) in ha.iter().zip(hb).enumerate() {
            let adjusted = (96..108).contains(&k) || (227..243).contains(&k);
            if !adjusted {
                assert_eq!(x, y, "{name}: header byte {k}");
            }
        }
        // Every VLR kept but laszip's and the extra bytes'.
        let keep =
            |v: &&aniso_alpha::io::Vlr| !v.is(b"laszip encoded", 22204) && !v.is(b"LASF_Spec", 4);
        let va: Vec<_> = a.vlrs.iter().filter(keep).collect();
        let vb: Vec<_> = b.vlrs.iter().filter(keep).collect();
        assert_eq!(va, vb, "{name}");
        assert_eq!(a.padding, b.padding, "{name}");
        assert_eq!(a.tail, b.tail, "{name}: extended VLRs");
        // The extra bytes end with structure and part.
        let eb = &b.vlrs.iter().find(|v| v.is(b"LASF_Spec", 4)).unwrap().data;
        assert_eq!(eb.len() % 192, 0);
        let last = &eb[eb.len() - 384..];
        assert_eq!(&last[2..4], &[6, 0]);
        assert_eq!(&last[4..13], b"structure");
        assert_eq!(&last[192 + 2..192 + 4], &[6, 0]);
        assert_eq!(&last[192 + 4..192 + 8], b"part");
        // And the attributes read back are the input's plus the two.
        let mut want = input.attributes.clone();
        if let Some(c) = classify {
            let cls = want
                .iter_mut()
                .find(|a| a.name == "classification")
                .unwrap();
            let v: Vec<f64> = (0..s.len())
                .map(|i| {
                    if s[i] >= 0 {
                        f64::from(c)
                    } else {
                        cls.values.get_f64(i)
                    }
                })
                .collect();
            cls.values = match &cls.values {
                Values::U8(_) => Values::U8(v.iter().map(|&x| x as u8).collect()),
                other => panic!("{other:?}"),
            };
        }
        let extra_undocumented = |a: &Attribute| a.name.starts_with("extra_byte_");
        let got: Vec<&Attribute> = output.attributes.iter().collect();
        let (ids, rest): (Vec<&Attribute>, Vec<&Attribute>) = got
            .into_iter()
            .partition(|a| a.name == "structure" || a.name == "part");
        assert_eq!(ids.len(), 2, "{name}");
        assert_eq!(
            ids[0].values,
            Values::I32(s.iter().map(|&v| v as i32).collect())
        );
        assert_eq!(
            ids[1].values,
            Values::I32(p.iter().map(|&v| v as i32).collect())
        );
        let rest: Vec<Attribute> = rest.into_iter().cloned().collect();
        // Undescribed bytes become data type 0 entries: same bytes, same names.
        assert_eq!(
            rest.iter().filter(|a| !extra_undocumented(a)).count(),
            want.iter().filter(|a| !extra_undocumented(a)).count(),
            "{name}"
        );
        assert_eq!(rest, want, "{name}");
    }

    fn ids(n: usize) -> (Vec<i64>, Vec<i64>) {
        let s: Vec<i64> = (0..n).map(|i| (i % 5) as i64 - 1).collect();
        let p: Vec<i64> = (0..n)
            .map(|i| if s[i] < 0 { -1 } else { (i % 11) as i64 })
            .collect();
        (s, p)
    }

    #[test]
    fn labelled_las_and_laz_keep_every_record_byte_for_byte() {
        let d = tmp_dir("las-out");
        for name in REAL {
            let input = read_points(&fixture(name), &WITH_ATTRS).unwrap();
            let n = input.points.len();
            let (s, p) = ids(n);
            for (ext, classify) in [("las", None), ("laz", None), ("las", Some(6u8))] {
                let out = d.join(format!("out-{name}.{ext}"));
                let l = Labelled {
                    classify,
                    ..Labelled::new(&s, &p)
                };
                write_labelled_cloud(&out, &input, &l).unwrap_or_else(|e| panic!("{e}"));
                let back = read_points(&out, &WITH_ATTRS).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(back.points, input.points, "{name} -> {ext}");
                check_records(&format!("{name} -> {ext}"), &input, &back, &s, &p, classify);
                // The las crate reads it too, with the ids as extra bytes.
                let (h, pts) = las_points(&out);
                assert_eq!(h.point_format().is_compressed, ext == "laz");
                assert_eq!(pts.len(), n);
                for (i, q) in pts.iter().enumerate() {
                    let e = &q.extra_bytes;
                    assert_eq!(&e[e.len() - 8..e.len() - 4], &(s[i] as i32).to_le_bytes());
                    assert_eq!([q.x, q.y, q.z], input.points[i]);
                }
            }
        }
    }

    #[test]
    fn classify_out_of_range_for_legacy_formats_is_an_error() {
        let d = tmp_dir("las-classify");
        let input = read_points(&fixture("simple.las"), &WITH_ATTRS).unwrap();
        let n = input.points.len();
        let (s, p) = ids(n);
        let out = d.join("o.las");
        let l = Labelled {
            classify: Some(40),
            ..Labelled::new(&s, &p)
        };
        let e = write_labelled_cloud(&out, &input, &l).unwrap_err();
        assert!(e.to_string().contains("0-31"), "{e}");
        assert!(!out.exists());
    }

    #[test]
    fn las_to_ply_keeps_attributes_with_8_bit_colours() {
        let d = tmp_dir("las-ply");
        let input = read_points(&fixture("simple.las"), &WITH_ATTRS).unwrap();
        let n = input.points.len();
        // simple.las's colours are 8-bit values: kept as they are.
        let out = d.join("o8.ply");
        let (s, p) = ids(n);
        write_labelled_cloud(&out, &input, &Labelled::new(&s, &p)).unwrap();
        let back = read_points(&out, &WITH_ATTRS).unwrap();
        let Values::U8(red8) = attr(&back, "red") else {
            panic!("red is not uchar")
        };
        let red16 = attr(&input, "red");
        assert!((0..n).all(|i| f64::from(red8[i]) == red16.get_f64(i)));
        assert!((0..n).any(|i| red16.get_f64(i) > 200.0));
        // The same colours as 16-bit values (x 257): divided back.
        let mut input = input;
        for a in &mut input.attributes {
            if let ("red" | "green" | "blue", Values::U16(v)) = (a.name.as_str(), &mut a.values) {
                v.iter_mut().for_each(|c| *c *= 257);
            }
        }
        let (s, p) = ids(n);
        let out = d.join("o.ply");
        let l = Labelled {
            classify: Some(6),
            ..Labelled::new(&s, &p)
        };
        write_labelled_cloud(&out, &input, &l).unwrap();
        let back = read_points(&out, &WITH_ATTRS).unwrap();
        assert_eq!(back.points, input.points);
        assert_eq!(attr(&back, "structure").len(), n);
        // simple.las has 16-bit colours: divided by 257, as uchar.
        let red16 = attr(&input, "red");
        assert!((0..n).any(|i| red16.get_f64(i) > 255.0));
        let Values::U8(red8) = attr(&back, "red") else {
            panic!("red is not uchar")
        };
        for i in 0..n {
            assert_eq!(f64::from(red8[i]), (red16.get_f64(i) / 257.0).round());
        }
        for a in &input.attributes {
            if matches!(a.name.as_str(), "red" | "green" | "blue" | "classification") {
                continue;
            }
            assert_eq!(attr(&back, &a.name), &a.values, "{}", a.name);
        }
        let cls = attr(&back, "classification");
        let orig = attr(&input, "classification");
        for i in 0..n {
            let want = if s[i] >= 0 { 6.0 } else { orig.get_f64(i) };
            assert_eq!(cls.get_f64(i), want);
        }
    }

    #[test]
    fn other_formats_to_las_quantise_and_keep_attributes_as_extra_bytes() {
        let d = tmp_dir("ply-las");
        let c = read_points_bytes(
            Path::new("t.ply"),
            &ply_every_type("binary_little_endian"),
            &WITH_ATTRS,
        )
        .unwrap();
        for ext in ["las", "laz"] {
            let out = d.join(format!("o.{ext}"));
            write_labelled_cloud(&out, &c, &Labelled::new(&[3, -1], &[0, -1])).unwrap();
            let back = read_points(&out, &WITH_ATTRS).unwrap();
            let src = back.las.as_ref().unwrap();
            let scale = f64::from_le_bytes(src.header[131..139].try_into().unwrap());
            assert!(scale <= 1e-8, "{scale}");
            for (a, b) in back.points.iter().zip(&c.points) {
                for k in 0..3 {
                    assert!((a[k] - b[k]).abs() <= scale, "{a:?} {b:?}");
                }
            }
            for a in &expected_ply_attributes() {
                assert_eq!(attr(&back, &a.name), &a.values, "{ext} {}", a.name);
            }
            assert_eq!(attr(&back, "structure"), &Values::I32(vec![3, -1]));
            assert_eq!(attr(&back, "part"), &Values::I32(vec![0, -1]));
            let (_, pts) = las_points(&out);
            assert_eq!(pts.len(), 2);
        }
    }
}

#[test]
fn normals_from_ply_and_pcd_attributes() {
    // PLY's nx ny nz (any case, any numeric type) and PCD's normal_x
    // normal_y normal_z; a file without them has none, and neither has a
    // read without attributes.
    let ply = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
property float z\nproperty double NX\nproperty double NY\nproperty double NZ\nend_header\n\
0 0 0 0 0 1\n1 0 0 0.6 0.8 0\n";
    let c = read_points_bytes(Path::new("n.ply"), ply, &WITH_ATTRS).unwrap();
    assert_eq!(c.normals(), Some(vec![[0.0, 0.0, 1.0], [0.6, 0.8, 0.0]]));
    let plain = read_points_bytes(Path::new("n.ply"), ply, &ReadOptions::default()).unwrap();
    assert_eq!(plain.normals(), None);
    let ascii = "1 2 3 0 1 0 0.25\n4 5 6 1 0 0 0.5\n";
    let p = pcd(
        "ascii",
        "x y z normal_x normal_y normal_z curvature",
        "4 4 4 4 4 4 4",
        "F F F F F F F",
        "1 1 1 1 1 1 1",
        ascii.as_bytes(),
    );
    let c = read_points_bytes(Path::new("n.pcd"), &p, &WITH_ATTRS).unwrap();
    assert_eq!(c.normals(), Some(vec![[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]));
    let no = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
property float z\nproperty float nx\nend_header\n0 0 0 1\n";
    let c = read_points_bytes(Path::new("n.ply"), no, &WITH_ATTRS).unwrap();
    assert_eq!(c.normals(), None);
}
