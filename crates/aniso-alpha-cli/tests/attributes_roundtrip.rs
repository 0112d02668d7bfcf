//! Attributes survive a `detect --output` round trip (issue 18): the input
//! cloud comes back with every attribute it had and two added fields, the
//! structure and part ids, equal to `--labels` and `--part-labels`.
//! Checked with this project's reader for LAS, LAZ, PLY and E57 inputs,
//! and with laspy (an independent LAS/LAZ reader) when it can be imported:
//! by the Python named by `ANISO_ALPHA_PYTHON` (then it must have laspy and
//! lazrs: `.ci/run` sets it to a virtual environment with both), else by
//! `python3` if it has them (else the laspy half follows the rule of
//! `common::tool_missing`: skipped with a message, a failure under
//! `ANISO_ALPHA_CI=1`).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::TempDir;

use aniso_alpha::io::{read_points, Attribute, PointCloud, ReadOptions, Values};

const BIN: &str = env!("CARGO_BIN_EXE_aniso-alpha");

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../aniso-alpha/tests/fixtures")
        .join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn read_ids(p: &Path) -> Vec<i64> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .map(|l| l.trim().parse().unwrap())
        .collect()
}

/// Runs `detect INPUT --output OUT` with `args`, and returns the structure
/// and part ids it wrote with `--labels` and `--part-labels`.
fn detect(dir: &TempDir, input: &Path, out: &Path, args: &[&str]) -> (Vec<i64>, Vec<i64>) {
    let (labels, parts) = (dir.path("labels.txt"), dir.path("parts.txt"));
    let o = Command::new(BIN)
        .args([
            "detect",
            s(input),
            "--output",
            s(out),
            "--labels",
            s(&labels),
        ])
        .args(["--part-labels", s(&parts), "--quiet", "--threads", "2"])
        .args(args)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{input:?} {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    (read_ids(&labels), read_ids(&parts))
}

fn read_all(p: &Path) -> PointCloud {
    let options = ReadOptions {
        attributes: true,
        ..ReadOptions::default()
    };
    read_points(p, &options).unwrap()
}

fn column<'a>(c: &'a PointCloud, name: &str) -> &'a Values {
    &c.attributes
        .iter()
        .find(|a| a.name == name)
        .unwrap_or_else(|| {
            let names: Vec<_> = c.attributes.iter().map(|a| &a.name).collect();
            panic!("no attribute {name} in {names:?}")
        })
        .values
}

fn as_i64(v: &Values) -> Vec<i64> {
    (0..v.len()).map(|i| v.get_f64(i) as i64).collect()
}

/// Every attribute of `input` is in `output` with the same values (and
/// type, unless `same_type` is false), but `except`; `output` has the
/// structure and part ids.
fn check_kept(
    input: &PointCloud,
    output: &PointCloud,
    ids: &(Vec<i64>, Vec<i64>),
    except: &[&str],
    same_type: bool,
) {
    assert_eq!(output.points.len(), input.points.len());
    assert!(!input.attributes.is_empty());
    for Attribute { name, values } in &input.attributes {
        if except.contains(&name.as_str()) {
            continue;
        }
        let out = column(output, name);
        if same_type {
            assert_eq!(out, values, "{name}");
        } else {
            assert_eq!(out.len(), values.len(), "{name}");
            for i in 0..out.len() {
                assert_eq!(out.get_f64(i), values.get_f64(i), "{name}[{i}]");
            }
        }
    }
    assert_eq!(as_i64(column(output, "structure")), ids.0);
    assert_eq!(as_i64(column(output, "part")), ids.1);
}

/// laspy's verdict on a LAS/LAZ output: `Some(stdout)` when it ran, `None`
/// (with a message) when no Python with laspy and lazrs is available.
fn laspy_check(input: &Path, output: &Path, dir: &TempDir, classify: Option<u8>) -> Option<String> {
    let (python, required) = match std::env::var("ANISO_ALPHA_PYTHON") {
        Ok(p) if !p.is_empty() => (p, true),
        _ => ("python3".to_string(), false),
    };
    let probe = Command::new(&python)
        .args(["-c", "import laspy, lazrs"])
        .output();
    if !probe.as_ref().is_ok_and(|o| o.status.success()) {
        assert!(
            !required,
            "ANISO_ALPHA_PYTHON={python} has no laspy/lazrs: {probe:?}"
        );
        common::tool_missing(
            "the laspy half of the round trip",
            &format!(
                "{python} cannot import laspy and lazrs (set ANISO_ALPHA_PYTHON to a Python \
                 that has them; .ci/run does)"
            ),
        );
        return None;
    }
    let script = r#"
import sys
import laspy
import numpy as np
inp, out, labels, parts, classify = sys.argv[1:6]
a, b = laspy.read(inp), laspy.read(out)
assert a.header.point_format.id == b.header.point_format.id
assert np.allclose(a.header.scales, b.header.scales)
assert np.allclose(a.header.offsets, b.header.offsets)
assert len(a.points) == len(b.points) > 0
s = np.loadtxt(labels, dtype=np.int64, ndmin=1)
p = np.loadtxt(parts, dtype=np.int64, ndmin=1)
kept = 0
for name in a.point_format.dimension_names:
    x, y = np.asarray(a[name]), np.asarray(b[name])
    if name == "classification" and classify != "none":
        c = int(classify)
        assert (y[s >= 0] == c).all(), name
        assert np.array_equal(x[s < 0], y[s < 0]), name
    else:
        assert x.dtype == y.dtype, (name, x.dtype, y.dtype)
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name
    kept += 1
extra = list(b.point_format.extra_dimension_names)
assert extra[-2:] == ["structure", "part"], extra
assert b["structure"].dtype == np.int32 and b["part"].dtype == np.int32
assert np.array_equal(np.asarray(b["structure"]), s)
assert np.array_equal(np.asarray(b["part"]), p)
print(f"laspy: {len(b.points)} points, {kept} dimensions kept, {int((s >= 0).sum())} in structures")
"#;
    let classify = classify.map_or("none".to_string(), |c| c.to_string());
    let o = Command::new(&python)
        .args(["-c", script, s(input), s(output)])
        .args([s(&dir.path("labels.txt")), s(&dir.path("parts.txt"))])
        .arg(&classify)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "laspy check of {output:?} failed: {stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    Some(stdout)
}

/// CGAL's urban.las (an airborne scan of buildings, 13,511 points):
/// planes, every parameter estimated (one orientation; 50 structures).
const URBAN: [&str; 2] = ["--structure", "planes"];

#[test]
fn las_and_laz_outputs_keep_every_field_and_add_the_ids() {
    let dir = TempDir::new("rt", "las");
    let input = fixture("las/urban.las");
    let before = read_all(&input);
    for (out, classify) in [("out.las", None), ("out.laz", Some(6u8))] {
        let out = dir.path(out);
        let mut args = URBAN.to_vec();
        let c = classify.map(|c| format!("planes={c}"));
        if let Some(c) = &c {
            args.extend(["--classify", c]);
        }
        let ids = detect(&dir, &input, &out, &args);
        assert!(
            ids.0.iter().filter(|&&l| l >= 0).count() > 100,
            "urban.las: too few points in structures for a useful check"
        );
        let after = read_all(&out);
        let except: &[&str] = if classify.is_some() {
            &["classification"]
        } else {
            &[]
        };
        check_kept(&before, &after, &ids, except, true);
        if let Some(c) = classify {
            let (cb, ca) = (
                as_i64(column(&before, "classification")),
                as_i64(column(&after, "classification")),
            );
            for i in 0..ids.0.len() {
                let want = if ids.0[i] >= 0 { i64::from(c) } else { cb[i] };
                assert_eq!(ca[i], want, "point {i}");
            }
        }
        if let Some(msg) = laspy_check(&input, &out, &dir, classify) {
            eprintln!("{}", msg.trim());
        }
    }
}

#[test]
fn a_laz_input_round_trips_through_laspy() {
    // A LAS 1.4 file (point format 6, extended VLRs) compressed, with
    // --background-classes: every field still comes back.
    let dir = TempDir::new("rt", "laz14");
    let input = fixture("las/1_4_w_evlr.laz");
    let out = dir.path("out.laz");
    let ids = detect(
        &dir,
        &input,
        &out,
        &["--structure", "planes", "--background-classes", "7,18"],
    );
    check_kept(&read_all(&input), &read_all(&out), &ids, &[], true);
    laspy_check(&input, &out, &dir, None);
}

#[test]
fn ply_and_e57_inputs_keep_their_attributes_in_ply() {
    let dir = TempDir::new("rt", "ply");
    // E57 (libE57's sample, float x/y/z and 8-bit colours) to PLY.
    let e57 = fixture("e57/tinyCartesianFloatRgb.e57");
    let ply = dir.path("from_e57.ply");
    let ids = detect(&dir, &e57, &ply, &["--structure", "planes"]);
    let before = read_all(&e57);
    let after = read_all(&ply);
    check_kept(&before, &after, &ids, &[], true);
    assert_eq!(after.points, before.points);
    assert!(matches!(column(&after, "red"), Values::U8(_)));
    // That PLY (colours, ids) in again: its attributes, the old ids
    // included, survive a second run.
    let again = dir.path("again.ply");
    let ids2 = detect(&dir, &ply, &again, &["--structure", "planes"]);
    let twice = read_all(&again);
    check_kept(&after, &twice, &ids2, &["structure", "part"], true);
    assert!(twice.attributes.len() > after.attributes.len());
    // And LAS to PLY: every LAS field as a property (PLY has no 64-bit
    // integers nor LAS bit fields: compared by value).
    let las = fixture("las/urban.las");
    let from_las = dir.path("from_las.ply");
    let ids = detect(&dir, &las, &from_las, &URBAN);
    check_kept(&read_all(&las), &read_all(&from_las), &ids, &[], false);
}

#[test]
fn e57_to_las_keeps_colours_as_fields() {
    // A cloud that is not LAS goes to a LAS 1.2 file of point format 0,
    // its attributes as typed extra bytes; laspy reads them back.
    let dir = TempDir::new("rt", "e57las");
    let e57 = fixture("e57/tinyCartesianFloatRgb.e57");
    let out = dir.path("out.las");
    let ids = detect(&dir, &e57, &out, &["--structure", "planes"]);
    let before = read_all(&e57);
    let after = read_all(&out);
    check_kept(&before, &after, &ids, &[], true);
    for (p, q) in before.points.iter().zip(&after.points) {
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() <= 1e-6, "{p:?} {q:?}");
        }
    }
}

#[test]
fn detect_help_documents_the_labelled_outputs() {
    let o = Command::new(BIN)
        .args(["detect", "--help"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let help = String::from_utf8_lossy(&o.stdout);
    for want in [
        "--output OUT.las|.laz|.ply writes the input cloud back with every attribute",
        "--classify planes=6",
        "--background-classes 7,18",
        "scan_labelled.laz",
        "e57",
    ] {
        assert!(help.contains(want), "detect --help lacks '{want}':\n{help}");
    }
}

#[test]
fn background_classes_are_left_out_of_the_detection() {
    // urban.las with its most frequent class in structures declared
    // background: every point of that class comes out -1 (structure and
    // part), and without the flag some of them are in structures, so the
    // check can fail.
    let dir = TempDir::new("rt", "bgclass");
    let input = fixture("las/urban.las");
    let class = as_i64(column(&read_all(&input), "classification"));
    let plain = detect(&dir, &input, &dir.path("plain.las"), &URBAN);
    let mut counts = std::collections::BTreeMap::<i64, usize>::new();
    for (c, &l) in class.iter().zip(&plain.0) {
        if l >= 0 {
            *counts.entry(*c).or_default() += 1;
        }
    }
    let (&busiest, &n) = counts.iter().max_by_key(|(_, &n)| n).unwrap();
    assert!(n > 100, "class {busiest}: {n} points in structures");
    let flag = busiest.to_string();
    let mut args = URBAN.to_vec();
    args.extend(["--background-classes", &flag]);
    let left_out = detect(&dir, &input, &dir.path("out.las"), &args);
    let mut others = 0;
    for (i, (&c, (&s, &p))) in class
        .iter()
        .zip(left_out.0.iter().zip(&left_out.1))
        .enumerate()
    {
        if c == busiest {
            assert_eq!((s, p), (-1, -1), "point {i}");
        } else if s >= 0 {
            others += 1;
        }
    }
    eprintln!("class {busiest} left out; {others} points of other classes in structures");
}
