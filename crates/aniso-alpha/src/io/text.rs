//! Text point files: `.xyz`, `.txt`, `.csv`, `.pts`.
//!
//! One point per line, columns separated by runs of whitespace and/or commas
//! (so an empty CSV field does not count as a column). `#` starts a comment
//! that runs to the end of the line. Blank lines are skipped. Lines end
//! with LF, CRLF or a lone CR (also mixed in one file). The first
//! non-blank, non-comment line is a header, skipped with a
//! [`ReadWarning::HeaderLine`], when none of its first three columns is a
//! number; a first line whose first column is not a number but whose next
//! ones are (`−1 0 0` with a Unicode minus) is an error, as is a non-number
//! on any later line. Columns past x, y, z (and the label column) are
//! ignored. A first line holding a single number (the point count that
//! `.pts` files start with) is skipped too.
//!
//! Commas that would be misread are refused:
//! * a comma between two digits on a line whose columns are separated by
//!   whitespace (`1,5 2,5 3,5`: decimal commas);
//! * a comma-separated line whose field count differs from the first
//!   comma-separated line's (header included), or a field with a leading
//!   zero such as `000.0` (`1,234.5,2,000.0,3.0`: thousands separators).
//!
//! UTF-16 files (a byte-order mark, or NUL bytes) are refused with a clear
//! message. The reader streams: it holds one buffer of the file
//! ([`STREAM_BUFFER`]) and the points, not the whole file.

use std::io::Read;
use std::path::Path;

use super::error::show_token;
use super::{IoError, PointCloud, ReadWarning};

/// Size of the read buffer of the streaming text reader (it grows only for
/// a longer line).
pub(crate) const STREAM_BUFFER: usize = 4 << 20;

#[inline(always)]
fn is_sep(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b',' | b'\x0b' | b'\x0c')
}

#[inline(always)]
fn is_eol(b: u8) -> bool {
    b == b'\n' || b == b'\r'
}

#[inline(always)]
fn ends_token(b: u8) -> bool {
    is_sep(b) || is_eol(b) || b == b'#'
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

/// The state of a text file being parsed, line by line, across buffers.
pub(crate) struct TextParser<'p> {
    path: &'p Path,
    label_column: Option<usize>,
    needed: usize,
    line: usize,
    seen_content: bool,
    /// Field count of the first comma-separated line, and its line number.
    comma_fields: Option<(usize, usize)>,
    /// A CR ended the previous buffer: a LF starting this one is its pair.
    pending_cr: bool,
    first: bool,
    cloud: PointCloud,
}

/// What one line's scan found ([`TextParser::scan_line`]).
#[derive(Default)]
struct LineScan {
    /// Columns seen (counted past those read in a comma-separated file).
    col: usize,
    /// The first three columns.
    xyz: [f64; 3],
    /// The label column's value.
    label: i64,
    /// The first column is not a number on a line before any content.
    header: bool,
    /// Some columns are separated by white space alone.
    ws_sep: bool,
    /// The first comma between two digits with nothing else between them.
    tight_comma: Option<usize>,
    /// Some columns are separated by commas.
    has_comma: bool,
    /// The first field with a leading zero (start, end).
    leading_zero: Option<(usize, usize)>,
}

impl<'p> TextParser<'p> {
    pub(crate) fn new(path: &'p Path, label_column: Option<usize>, size_hint: usize) -> Self {
        let needed = match label_column {
            Some(c) => c.max(2).saturating_add(1),
            None => 3,
        };
        let mut cloud = PointCloud::default();
        cloud.points.reserve(size_hint / 32 + 1);
        if label_column.is_some() {
            cloud.labels = Some(Vec::new());
        }
        TextParser {
            path,
            label_column,
            needed,
            line: 0,
            seen_content: false,
            comma_fields: None,
            pending_cr: false,
            first: true,
            cloud,
        }
    }

    fn err(&self, message: String) -> IoError {
        IoError::parse(self.path, self.line, message)
    }

    /// Checks the start of the file for a BOM and for UTF-16.
    fn check_start<'b>(&self, bytes: &'b [u8]) -> Result<&'b [u8], IoError> {
        if bytes.starts_with(b"\xFF\xFE") || bytes.starts_with(b"\xFE\xFF") {
            return Err(IoError::format(
                self.path,
                "the file is UTF-16 text (it starts with a UTF-16 byte-order mark): \
                 convert it to UTF-8 or ASCII, e.g. iconv -f UTF-16 -t UTF-8",
            ));
        }
        let probe = &bytes[..bytes.len().min(4096)];
        if probe.contains(&0) {
            let hint = if probe.iter().skip(1).step_by(2).filter(|&&b| b == 0).count() * 4
                > probe.len()
                || probe.iter().step_by(2).filter(|&&b| b == 0).count() * 4 > probe.len()
            {
                " (it looks like UTF-16: convert it to UTF-8, e.g. iconv -f UTF-16 -t UTF-8)"
            } else {
                " (a binary file?)"
            };
            return Err(IoError::format(
                self.path,
                format!("NUL bytes in a text point file{hint}"),
            ));
        }
        Ok(bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes))
    }

    /// Parses `bytes`, which ends at a line end unless it is the file's
    /// last piece (a trailing CR may be followed by a LF in the next piece).
    pub(crate) fn feed(&mut self, bytes: &[u8]) -> Result<(), IoError> {
        let bytes = if self.first {
            self.first = false;
            self.check_start(bytes)?
        } else {
            bytes
        };
        let mut i = 0usize;
        if self.pending_cr && bytes.first() == Some(&b'\n') {
            i = 1;
        }
        self.pending_cr = false;
        while i < bytes.len() {
            self.line += 1;
            let line_start = i;
            let scan = self.scan_line(bytes, &mut i)?;
            // Skip the rest of the line (extra columns, comment).
            while i < bytes.len() && !is_eol(bytes[i]) {
                i += 1;
            }
            let line_end = i;
            i = self.past_line_end(bytes, i);
            self.take_line(&scan, bytes, line_start..line_end)?;
        }
        Ok(())
    }

    /// The columns of the line starting at `*i`, read up to what is needed
    /// (all of them in a comma-separated file, to count them); `*i` is left
    /// where the scan stopped.
    #[inline]
    fn scan_line(&self, bytes: &[u8], i: &mut usize) -> Result<LineScan, IoError> {
        let n = bytes.len();
        let mut line = LineScan::default();
        loop {
            let sep_start = *i;
            let mut comma = 0usize;
            while *i < n && is_sep(bytes[*i]) {
                comma += usize::from(bytes[*i] == b',');
                *i += 1;
            }
            if *i >= n || is_eol(bytes[*i]) || bytes[*i] == b'#' {
                break;
            }
            if line.col > 0 {
                if comma == 0 {
                    line.ws_sep = true;
                } else {
                    line.has_comma = true;
                    if *i - sep_start == 1
                        && bytes[sep_start - 1].is_ascii_digit()
                        && bytes[*i].is_ascii_digit()
                    {
                        line.tight_comma.get_or_insert(sep_start);
                    }
                }
            } else if comma > 0 {
                line.has_comma = true;
            }
            let start = *i;
            while *i < n && !ends_token(bytes[*i]) {
                *i += 1;
            }
            let tok = &bytes[start..*i];
            if tok.len() > 1 && tok[0] == b'0' && tok[1].is_ascii_digit() {
                line.leading_zero.get_or_insert((start, *i));
            }
            let col = line.col;
            if col >= self.needed {
                // Past what is read: only counted (comma files).
                line.col += 1;
                continue;
            }
            if col < 3 {
                match parse_f64(tok) {
                    Some(v) => line.xyz[col] = v,
                    None if col == 0 && !self.seen_content => {
                        line.header = true;
                        break;
                    }
                    None => return Err(self.bad_number(tok, col)),
                }
            }
            if Some(col) == self.label_column {
                line.label = parse_label(tok).ok_or_else(|| {
                    self.err(format!(
                        "invalid label '{}' in column {} (expected an integer)",
                        show_token(tok),
                        col + 1
                    ))
                })?;
            }
            line.col += 1;
            if line.col == self.needed && !line.has_comma {
                break;
            }
        }
        Ok(line)
    }

    /// The position after the line end at `i` (CR, LF or CR LF), or `i`
    /// at the end of `bytes`; a CR that ends `bytes` may have its LF in the
    /// next piece.
    #[inline]
    fn past_line_end(&mut self, bytes: &[u8], i: usize) -> usize {
        let n = bytes.len();
        if i >= n {
            return i;
        }
        let mut i = i;
        if bytes[i] == b'\r' {
            if i + 1 < n {
                if bytes[i + 1] == b'\n' {
                    i += 1;
                }
            } else {
                self.pending_cr = true;
            }
        }
        i + 1
    }

    /// The scanned line `bytes[text]`: a header, a blank or comment line,
    /// a `.pts` count line, or a point (and its label) after the checks of
    /// its separators, columns and coordinates.
    #[inline]
    fn take_line(
        &mut self,
        line: &LineScan,
        bytes: &[u8],
        text: std::ops::Range<usize>,
    ) -> Result<(), IoError> {
        let col = line.col;
        if line.header {
            return self.header_line(&bytes[text]);
        }
        if col == 0 {
            return Ok(()); // blank or comment line
        }
        if col == 1 && !self.seen_content {
            // A lone number first: the point count line of `.pts` files.
            self.seen_content = true;
            return Ok(());
        }
        self.seen_content = true;
        if let (true, Some(at)) = (line.ws_sep, line.tight_comma) {
            let tok = token_around(bytes, at, text.start, text.end);
            return Err(self.err(format!(
                "ambiguous comma in '{}': decimal commas are not read (use '.' for decimals, \
                 and commas or spaces between columns)",
                show_token(tok)
            )));
        }
        if line.has_comma {
            self.check_comma_fields(col)?;
            if let Some((a, b)) = line.leading_zero {
                let tok = &bytes[a..b];
                return Err(self.err(format!(
                    "field '{}' has a leading zero: a thousands separator? (write numbers \
                     without digit grouping)",
                    show_token(tok)
                )));
            }
        }
        if col < 3 {
            return Err(self.err(format!("expected 3 numeric columns, found {col}")));
        }
        if col < self.needed {
            return Err(self.err(format!(
                "expected a label in column {}, found {col} columns",
                self.needed
            )));
        }
        let xyz = line.xyz;
        if !(xyz[0].is_finite() && xyz[1].is_finite() && xyz[2].is_finite()) {
            return Err(IoError::NonFinite {
                path: self.path.to_path_buf(),
                line: Some(self.line),
                index: self.cloud.points.len(),
            });
        }
        self.cloud.points.push(xyz);
        if let Some(labels) = self.cloud.labels.as_mut() {
            labels.push(line.label);
        }
        Ok(())
    }

    /// A first line whose first column is not a number: a header when none
    /// of its first three columns is a number, else an error.
    fn header_line(&mut self, text: &[u8]) -> Result<(), IoError> {
        let toks: Vec<&[u8]> = text
            .split(|&b| is_sep(b) || b == b'#')
            .filter(|t| !t.is_empty())
            .take(3)
            .collect();
        let comment_at = text.iter().position(|&b| b == b'#').unwrap_or(text.len());
        let content = &text[..comment_at];
        if toks.len() > 1 && toks[1..].iter().any(|t| parse_f64(t).is_some()) {
            return Err(self.bad_number(toks[0], 0));
        }
        if content.contains(&b',') {
            let fields = content
                .split(|&b| is_sep(b))
                .filter(|t| !t.is_empty())
                .count();
            self.comma_fields = Some((fields, self.line));
        }
        self.seen_content = true;
        self.cloud.warnings.push(ReadWarning::HeaderLine {
            line: self.line,
            text: show_token(content.trim_ascii()),
        });
        Ok(())
    }

    fn check_comma_fields(&mut self, fields: usize) -> Result<(), IoError> {
        match self.comma_fields {
            None => {
                self.comma_fields = Some((fields, self.line));
                Ok(())
            }
            Some((f, _)) if f == fields => Ok(()),
            Some((f, at)) => Err(self.err(format!(
                "{fields} comma-separated fields where line {at} has {f}: a thousands separator \
                 or a decimal comma? (every line of a CSV file needs the same fields)"
            ))),
        }
    }

    fn bad_number(&self, tok: &[u8], col: usize) -> IoError {
        let hint = if std::str::from_utf8(tok)
            .is_ok_and(|s| s.contains(['\u{2212}', '\u{2013}', '\u{2012}', '\u{FE63}', '\u{FF0D}']))
        {
            " (a Unicode minus or dash: use the ASCII '-')"
        } else {
            ""
        };
        self.err(format!(
            "invalid number '{}' in column {}{hint}",
            show_token(tok),
            col + 1
        ))
    }

    /// The points, or [`IoError::NoPoints`].
    pub(crate) fn finish(self) -> Result<PointCloud, IoError> {
        if self.cloud.points.is_empty() {
            return Err(IoError::NoPoints {
                path: self.path.to_path_buf(),
            });
        }
        Ok(self.cloud)
    }
}

/// The whitespace-free token around byte `at` of a line.
fn token_around(bytes: &[u8], at: usize, start: usize, end: usize) -> &[u8] {
    let ws = |b: u8| b.is_ascii_whitespace();
    let a = bytes[start..at]
        .iter()
        .rposition(|&b| ws(b))
        .map_or(start, |k| start + k + 1);
    let b = bytes[at..end]
        .iter()
        .position(|&b| ws(b))
        .map_or(end, |k| at + k);
    &bytes[a..b]
}

/// Reads a text point file from memory. `path` only names it in errors.
pub(crate) fn read_text(
    path: &Path,
    bytes: &[u8],
    label_column: Option<usize>,
) -> Result<PointCloud, IoError> {
    let mut parser = TextParser::new(path, label_column, bytes.len());
    parser.feed(bytes)?;
    parser.finish()
}

/// Reads a text point file from a stream through one bounded buffer,
/// calling `progress(bytes_read)` after each read.
pub(crate) fn read_text_stream(
    path: &Path,
    source: impl Read,
    label_column: Option<usize>,
    size_hint: usize,
    progress: &mut dyn FnMut(u64),
) -> Result<PointCloud, IoError> {
    read_text_stream_with(
        path,
        source,
        label_column,
        size_hint,
        progress,
        STREAM_BUFFER,
    )
}

fn read_text_stream_with(
    path: &Path,
    mut source: impl Read,
    label_column: Option<usize>,
    size_hint: usize,
    progress: &mut dyn FnMut(u64),
    buffer: usize,
) -> Result<PointCloud, IoError> {
    let mut parser = TextParser::new(path, label_column, size_hint);
    let mut buf = vec![0u8; buffer.max(1)];
    let mut filled = 0usize;
    let mut total = 0u64;
    loop {
        if filled == buf.len() {
            // One line longer than the buffer: grow it.
            buf.resize(buf.len() * 2, 0);
        }
        let k = match source.read(&mut buf[filled..]) {
            Ok(k) => k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(source) => {
                return Err(IoError::Open {
                    path: path.to_path_buf(),
                    source,
                })
            }
        };
        total += k as u64;
        progress(total);
        filled += k;
        if k == 0 {
            parser.feed(&buf[..filled])?;
            return parser.finish();
        }
        // Parse up to the last line end; keep the partial line.
        if let Some(last) = buf[..filled].iter().rposition(|&b| is_eol(b)) {
            parser.feed(&buf[..=last])?;
            buf.copy_within(last + 1..filled, 0);
            filled -= last + 1;
        }
    }
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
            "\u{feff}# comment\n\nx,y,z,intensity\n1,2,3,9\n 4\t5 6 # trailing\r\n7, 8 ,9, 0\n#end",
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

    #[test]
    fn misreads_are_errors() {
        assert!(err("1,5 2,5 3,5\n").contains("ambiguous comma in '1,5'"));
        assert!(err("0 0 0\n1,5 2,5 3,5\n").starts_with("t.xyz:2: ambiguous comma"));
        assert_eq!(
            err("x,y,z\n1,234.5,2,000.0,3.0\n"),
            "t.xyz:2: 5 comma-separated fields where line 1 has 3: a thousands separator or a \
             decimal comma? (every line of a CSV file needs the same fields)"
        );
        assert!(err("1,234.5,2,000.0,3.0\n").contains("field '000.0' has a leading zero"));
        assert!(err("1,2,3\n1,2,3,4\n").starts_with("t.xyz:2: 4 comma-separated fields"));
        let e = err("\u{2212}1 0 0\n1 0 0\n");
        assert!(
            e.starts_with("t.xyz:1: invalid number '\u{2212}1' in column 1 (a Unicode minus"),
            "{e}"
        );
        // Comma-space CSV and a header with the same fields stay fine.
        let c = read("x, y, z, i\n1, 2, 3, 4\n-0.5, 0.25, 1e3, 0\n").unwrap();
        assert_eq!(c.points, vec![[1.0, 2.0, 3.0], [-0.5, 0.25, 1000.0]]);
        // 0.5 is not a leading zero.
        assert_eq!(read("0.5,0,0.25\n").unwrap().points, vec![[0.5, 0.0, 0.25]]);
    }

    #[test]
    fn line_ends_and_encodings() {
        // A lone CR inside a LF file ends a line.
        let c = read("1 2 3\r4 5 6\n7 8 9\r\n").unwrap();
        assert_eq!(c.points.len(), 3);
        assert_eq!(
            err("1 2 3\r4 5\n6 7 8\n"),
            "t.xyz:2: expected 3 numeric columns, found 2"
        );
        assert_eq!(
            err("1 2 3\r\n4 5\r\n"),
            "t.xyz:2: expected 3 numeric columns, found 2"
        );
        let e = err("\u{feff}").to_string();
        assert_eq!(e, "t.xyz: no points in file");
        let utf16: Vec<u8> = "\u{feff}1 2 3\n"
            .encode_utf16()
            .flat_map(|u| u.to_le_bytes())
            .collect();
        assert!(read_text(Path::new("t.xyz"), &utf16, None)
            .unwrap_err()
            .to_string()
            .contains("UTF-16"));
        let no_bom: Vec<u8> = "1 2 3\n4 5 6\n"
            .encode_utf16()
            .flat_map(|u| u.to_be_bytes())
            .collect();
        let e = read_text(Path::new("t.xyz"), &no_bom, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("NUL bytes") && e.contains("UTF-16"), "{e}");
    }

    #[test]
    fn header_guess_is_a_warning() {
        let c = read("X Y Z\n1 2 3\n").unwrap();
        assert_eq!(c.warnings.len(), 1);
        assert_eq!(
            c.warnings[0].to_string(),
            "line 1 taken as a header: 'X Y Z'"
        );
        assert!(read("1 2 3\n").unwrap().warnings.is_empty());
        assert!(read("# c\n\n3\n1 2 3\n").unwrap().warnings.is_empty());
    }

    #[test]
    fn streaming_matches_whole_reads_at_every_buffer_size() {
        let text = "# c\r\nx,y,z,l\r\n1,2,3,4\r\n5,6,7,8\r9,10,11,12\n13,14,15,16";
        let whole = read_text(Path::new("t.csv"), text.as_bytes(), Some(3)).unwrap();
        assert_eq!(whole.points.len(), 4);
        for buffer in 1..text.len() + 2 {
            let mut seen = 0;
            let c = read_text_stream_with(
                Path::new("t.csv"),
                text.as_bytes(),
                Some(3),
                0,
                &mut |n| seen = n,
                buffer,
            )
            .unwrap();
            assert_eq!(c, whole, "buffer {buffer}");
            assert_eq!(seen, text.len() as u64);
        }
        // Errors carry the same line numbers.
        let bad = "1 2 3\r\n4 5 6\r\n7 8\r\n";
        for buffer in 1..bad.len() + 2 {
            let e = read_text_stream_with(
                Path::new("t.xyz"),
                bad.as_bytes(),
                None,
                0,
                &mut |_| {},
                buffer,
            )
            .unwrap_err();
            assert_eq!(
                e.to_string(),
                "t.xyz:3: expected 3 numeric columns, found 2"
            );
        }
    }
}
