//! Text point files: `.xyz`, `.txt`, `.csv`, `.pts`.
//!
//! One point per line, columns separated by runs of whitespace and/or commas
//! (so an empty CSV field does not count as a column). `#` starts a comment
//! that runs to the end of the line. Blank lines are skipped. The first
//! non-blank, non-comment line is a header, and skipped, when its first
//! column is not a number; no other line may be a header. Columns past x, y,
//! z (and the label column) are ignored. A first line holding a single
//! number (the point count that `.pts` files start with) is skipped too.

use std::path::Path;

use super::error::show_token;
use super::{IoError, PointCloud};

#[inline(always)]
fn is_sep(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b',' | b'\r' | b'\x0b' | b'\x0c')
}

#[inline(always)]
fn ends_token(b: u8) -> bool {
    is_sep(b) || b == b'\n' || b == b'#'
}

/// Parses a float token; `None` when it is not a number.
#[inline]
pub(crate) fn parse_f64(tok: &[u8]) -> Option<f64> {
    if let Some(v) = fast_f64(tok) {
        return Some(v);
    }
    std::str::from_utf8(tok).ok()?.parse::<f64>().ok()
}

/// Exact fast path for plain decimals (`-12.345`, at most 19 significant
/// digits, no exponent): the integer mantissa m < 2^53 and the power of ten
/// 10^k with k ≤ 22 are both exact doubles, so m / 10^k is one correctly
/// rounded IEEE division (Clinger's fast path). Anything else returns
/// `None` and goes to the standard library's parser.
#[inline(always)]
fn fast_f64(tok: &[u8]) -> Option<f64> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let (neg, digits) = match tok.first()? {
        b'-' => (true, &tok[1..]),
        b'+' => (false, &tok[1..]),
        _ => (false, tok),
    };
    let mut mantissa: u64 = 0;
    let mut ndigits = 0usize;
    let mut frac_digits = 0usize;
    let mut seen_dot = false;
    for &b in digits {
        match b {
            b'0'..=b'9' => {
                if ndigits >= 19 {
                    return None;
                }
                mantissa = mantissa * 10 + u64::from(b - b'0');
                ndigits += 1;
                if seen_dot {
                    frac_digits += 1;
                }
            }
            b'.' if !seen_dot => seen_dot = true,
            _ => return None,
        }
    }
    if ndigits == 0 || mantissa >= (1u64 << 53) || frac_digits > 22 {
        return None;
    }
    // Leading zeros count as digits above but do not hurt: m is exact.
    let v = mantissa as f64 / POW10[frac_digits];
    Some(if neg { -v } else { v })
}

/// Parses an integer label; accepts an integral float such as `3.0`.
pub(crate) fn parse_label(tok: &[u8]) -> Option<i64> {
    let s = std::str::from_utf8(tok).ok()?;
    if let Ok(v) = s.parse::<i64>() {
        return Some(v);
    }
    let f = s.parse::<f64>().ok()?;
    if f.is_finite() && f.fract() == 0.0 && f.abs() < 9.0e15 {
        Some(f as i64)
    } else {
        None
    }
}

/// Reads a text point file from memory. `path` only names it in errors.
pub(crate) fn read_text(
    path: &Path,
    bytes: &[u8],
    label_column: Option<usize>,
) -> Result<PointCloud, IoError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    // Classic Mac line ends (CR only) would otherwise read as one line.
    let converted: Vec<u8>;
    let bytes = if !bytes.contains(&b'\n') && bytes.contains(&b'\r') {
        converted = bytes
            .iter()
            .map(|&b| if b == b'\r' { b'\n' } else { b })
            .collect();
        &converted[..]
    } else {
        bytes
    };
    let n = bytes.len();
    let needed = match label_column {
        Some(c) => c.max(2).saturating_add(1),
        None => 3,
    };
    let mut points: Vec<[f64; 3]> = Vec::with_capacity(n / 32 + 1);
    let mut labels: Vec<i64> = Vec::new();
    let mut line = 0usize;
    let mut seen_content = false;
    let mut i = 0usize;
    while i < n {
        line += 1;
        let mut col = 0usize;
        let mut xyz = [0.0f64; 3];
        let mut label = 0i64;
        let mut header = false;
        loop {
            while i < n && is_sep(bytes[i]) {
                i += 1;
            }
            if i >= n || bytes[i] == b'\n' || bytes[i] == b'#' {
                break;
            }
            let start = i;
            while i < n && !ends_token(bytes[i]) {
                i += 1;
            }
            let tok = &bytes[start..i];
            if col < 3 {
                match parse_f64(tok) {
                    Some(v) => xyz[col] = v,
                    None if col == 0 && !seen_content => {
                        header = true;
                        break;
                    }
                    None => {
                        return Err(IoError::parse(
                            path,
                            line,
                            format!("invalid number '{}' in column {}", show_token(tok), col + 1),
                        ))
                    }
                }
            }
            if Some(col) == label_column {
                label = parse_label(tok).ok_or_else(|| {
                    IoError::parse(
                        path,
                        line,
                        format!(
                            "invalid label '{}' in column {} (expected an integer)",
                            show_token(tok),
                            col + 1
                        ),
                    )
                })?;
            }
            col += 1;
            if col == needed {
                break;
            }
        }
        // Skip the rest of the line (extra columns, comment).
        while i < n && bytes[i] != b'\n' {
            i += 1;
        }
        i += 1;
        if header {
            seen_content = true;
            continue;
        }
        if col == 0 {
            continue; // blank or comment line
        }
        if col == 1 && !seen_content {
            // A lone number first: the point count line of `.pts` files.
            seen_content = true;
            continue;
        }
        seen_content = true;
        if col < 3 {
            return Err(IoError::parse(
                path,
                line,
                format!("expected 3 numeric columns, found {col}"),
            ));
        }
        if col < needed {
            return Err(IoError::parse(
                path,
                line,
                format!("expected a label in column {needed}, found {col} columns"),
            ));
        }
        if !(xyz[0].is_finite() && xyz[1].is_finite() && xyz[2].is_finite()) {
            return Err(IoError::NonFinite {
                path: path.to_path_buf(),
                line: Some(line),
                index: points.len(),
            });
        }
        points.push(xyz);
        if label_column.is_some() {
            labels.push(label);
        }
    }
    if points.is_empty() {
        return Err(IoError::NoPoints {
            path: path.to_path_buf(),
        });
    }
    Ok(PointCloud {
        points,
        labels: label_column.map(|_| labels),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(s: &str) -> Result<PointCloud, IoError> {
        read_text(Path::new("t.xyz"), s.as_bytes(), None)
    }

    fn err(s: &str) -> String {
        read(s).unwrap_err().to_string()
    }

    #[test]
    fn fast_path_matches_std() {
        for s in [
            "0",
            "-0",
            "1.5",
            "-12.345678",
            "0.1",
            "123456789.123456789",
            "9007199254740993",
            "0.30000000000000004",
            "1.",
            ".5",
            "-.5",
            "+3.25",
            "000.000100",
            "4503599627370497.5",
            "1234567890123456789",
        ] {
            let want: f64 = s.parse().unwrap();
            let got = parse_f64(s.as_bytes()).unwrap();
            assert_eq!(got.to_bits(), want.to_bits(), "{s}");
        }
        for s in ["", "-", ".", "1..2", "1e5x", "abc", "1-2"] {
            assert_eq!(parse_f64(s.as_bytes()), s.parse::<f64>().ok(), "{s}");
        }
    }

    #[test]
    fn separators_comments_header_extra_columns() {
        let c = read(
            "\u{feff}# comment\n\nx,y,z,intensity\n1,2,3,9\n 4\t5 6 # trailing\r\n7, 8 ,9\n#end",
        )
        .unwrap();
        assert_eq!(
            c.points,
            vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]]
        );
        assert_eq!(c.labels, None);
        // Leica PTS: a count line, then x y z intensity r g b.
        let c = read("2\n1 2 3 -1200 10 20 30\n4 5 6 0 1 2 3\n").unwrap();
        assert_eq!(c.points, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert_eq!(
            err("1 2 3\n2\n"),
            "t.xyz:2: expected 3 numeric columns, found 1"
        );
        // CR-only line ends.
        let c = read("x y z\r1 2 3\r4 5 6\r").unwrap();
        assert_eq!(c.points, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert_eq!(
            err("1 2 3\r4 5\r"),
            "t.xyz:2: expected 3 numeric columns, found 2"
        );
        // No trailing newline; exponent and signs.
        let c = read("1e3 -2.5E-1 +0").unwrap();
        assert_eq!(c.points, vec![[1000.0, -0.25, 0.0]]);
    }

    #[test]
    fn labels() {
        let c = read_text(
            Path::new("s.xyz"),
            b"x y z label\n0 0 0 -1\n1 1 1 3.0\n",
            Some(3),
        )
        .unwrap();
        assert_eq!(c.labels, Some(vec![-1, 3]));
        let e = read_text(Path::new("s.xyz"), b"0 0 0 -1\n1 1 1\n", Some(3)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "s.xyz:2: expected a label in column 4, found 3 columns"
        );
        let e = read_text(Path::new("s.xyz"), b"0 0 0 a\n", Some(3)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "s.xyz:1: invalid label 'a' in column 4 (expected an integer)"
        );
    }

    #[test]
    fn huge_label_column_is_an_error_not_an_overflow() {
        let e = read_text(Path::new("s.xyz"), b"0 0 0 1\n", Some(usize::MAX)).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("s.xyz:1: expected a label in column"),
            "{e}"
        );
    }

    #[test]
    fn errors_name_file_and_line() {
        assert_eq!(err(""), "t.xyz: no points in file");
        assert_eq!(err("# only\n\nx y z\n"), "t.xyz: no points in file");
        assert_eq!(
            err("0 0 0\n1 2\n"),
            "t.xyz:2: expected 3 numeric columns, found 2"
        );
        assert_eq!(
            err("x y z\nh2 1 1\n"),
            "t.xyz:2: invalid number 'h2' in column 1"
        );
        assert_eq!(
            err("1 1 1\n1 nan 1\n"),
            "t.xyz:2: non-finite coordinate (NaN or infinity) in point 1"
        );
        assert_eq!(
            err("#c\n1 1 -inf\n"),
            "t.xyz:2: non-finite coordinate (NaN or infinity) in point 0"
        );
        assert_eq!(err("1 2 1e999\n").lines().count(), 1);
        assert!(err("1 1 1\nx y z\n").starts_with("t.xyz:2: invalid number 'x'"));
        assert!(err("1 \u{1} 1\n").contains("'\\u{1}'"));
    }
}
