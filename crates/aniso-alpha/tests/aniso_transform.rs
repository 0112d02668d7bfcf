//! Q·P must reproduce CGAL's fixture `grid_6_aniso.transformed.xyz` bit for
//! bit from `grid_6_aniso.xyz` and the R rows of `grid_6_aniso.transform.txt`.

use aniso_alpha::aniso::Anisotropy;
use std::path::PathBuf;

fn fixture(name: &str) -> String {
    let p: PathBuf = [env!("CARGO_MANIFEST_DIR"), "tests", "fixtures", name]
        .iter()
        .collect();
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn numbers(line: &str) -> Vec<f64> {
    line.split_whitespace()
        .map(|t| t.parse::<f64>().unwrap_or_else(|e| panic!("{t:?}: {e}")))
        .collect()
}

fn points(text: &str) -> Vec<[f64; 3]> {
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let v = numbers(l);
            assert_eq!(v.len(), 3, "{l}");
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn grid_6_aniso_transform_is_bit_exact() {
    let spec = fixture("grid_6_aniso.transform.txt");
    let mut rows = Vec::new();
    let mut e = None;
    let mut euler = None;
    for line in spec.lines() {
        if let Some(rest) = line.strip_prefix("R ") {
            let v = numbers(rest);
            rows.push([v[0], v[1], v[2]]);
        } else if let Some(rest) = line.strip_prefix("e ") {
            let v = numbers(rest);
            e = Some([v[0], v[1], v[2]]);
        } else if let Some(rest) = line.strip_prefix("euler ") {
            let v = numbers(rest);
            euler = Some([v[0], v[1], v[2]]);
        }
    }
    assert_eq!(rows.len(), 3);
    let r = [rows[0], rows[1], rows[2]];
    let e = e.expect("e line");
    let a = Anisotropy::from_matrix_rows(r, e).expect("fixture R is a rotation");

    let input = points(&fixture("grid_6_aniso.xyz"));
    let expected = points(&fixture("grid_6_aniso.transformed.xyz"));
    assert_eq!(input.len(), 216);
    assert_eq!(expected.len(), input.len());
    let got = a.transform(&input);
    let mut mismatches = 0;
    for (i, (g, x)) in got.iter().zip(&expected).enumerate() {
        for c in 0..3 {
            if g[c].to_bits() != x[c].to_bits() {
                mismatches += 1;
                eprintln!("point {i} coord {c}: got {:e}, want {:e}", g[c], x[c]);
            }
        }
    }
    assert_eq!(mismatches, 0);

    // The Euler angles give the fixture's R bit for bit (same matrix
    // product as numpy's rz @ rx @ ry, same sin/cos), hence the same points.
    let [t, p, f] = euler.expect("euler line");
    let b = Anisotropy::from_euler(t, p, f, e).unwrap();
    for (i, (got, want)) in b.rotation().iter().zip(&r).enumerate() {
        for (j, (g, w)) in got.iter().zip(want).enumerate() {
            assert_eq!(g.to_bits(), w.to_bits(), "R[{i}][{j}]");
        }
    }
    let from_angles = b.transform(&input);
    assert!(from_angles
        .iter()
        .zip(&expected)
        .all(|(g, x)| (0..3).all(|c| g[c].to_bits() == x[c].to_bits())));
}
