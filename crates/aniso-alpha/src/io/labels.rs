//! Plain label files: one integer per line.

use std::path::Path;

use super::error::show_token;
use super::{atomic_write, read_file, IoError};

/// Reads a label file: one integer per line (`#` comments and blank lines
/// are skipped). Errors name the file and the line.
///
/// ```no_run
/// let labels = aniso_alpha::io::read_labels("labels.txt".as_ref())?;
/// # Ok::<(), aniso_alpha::io::IoError>(())
/// ```
pub fn read_labels(path: &Path) -> Result<Vec<i64>, IoError> {
    let bytes = read_file(path, &mut |_, _| {})?;
    read_labels_bytes(path, &bytes)
}

/// [`read_labels`] on bytes in memory; `name` only names them in errors.
///
/// ```
/// use aniso_alpha::io::read_labels_bytes;
/// assert_eq!(read_labels_bytes("l.txt".as_ref(), b"3\n-1\n\n0\n").unwrap(), vec![3, -1, 0]);
/// let e = read_labels_bytes("l.txt".as_ref(), b"3\nx\n").unwrap_err();
/// assert_eq!(e.to_string(), "l.txt:2: expected one integer label, found 'x'");
/// ```
pub fn read_labels_bytes(name: &Path, bytes: &[u8]) -> Result<Vec<i64>, IoError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut out = Vec::with_capacity(bytes.len() / 3);
    for (k, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let content = raw.split(|&b| b == b'#').next().unwrap_or(raw);
        let tok = content.trim_ascii();
        if tok.is_empty() {
            continue;
        }
        let v = std::str::from_utf8(tok)
            .ok()
            .and_then(|s| s.parse::<i64>().ok())
            .ok_or_else(|| {
                IoError::parse(
                    name,
                    k + 1,
                    format!("expected one integer label, found '{}'", show_token(tok)),
                )
            })?;
        out.push(v);
    }
    Ok(out)
}

/// Writes labels, one integer per line, atomically.
///
/// ```
/// use aniso_alpha::io::{read_labels, write_labels};
/// let path = std::env::temp_dir().join(format!("labels-doc-{}.txt", std::process::id()));
/// write_labels(&path, &[2, -1, 0]).unwrap();
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "2\n-1\n0\n");
/// assert_eq!(read_labels(&path).unwrap(), vec![2, -1, 0]);
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn write_labels(path: &Path, labels: &[i64]) -> Result<(), IoError> {
    atomic_write(path, |w| {
        let mut buf = Vec::with_capacity(4096 * 21);
        for chunk in labels.chunks(4096) {
            buf.clear();
            for &v in chunk {
                push_i64(&mut buf, v);
                buf.push(b'\n');
            }
            w.write_all(&buf)?;
        }
        Ok(())
    })
}

/// Appends the decimal form of `v` (no allocation).
fn push_i64(buf: &mut Vec<u8>, v: i64) {
    if v < 0 {
        buf.push(b'-');
    }
    let mut m = v.unsigned_abs();
    let mut tmp = [0u8; 20];
    let mut i = tmp.len();
    loop {
        i -= 1;
        tmp[i] = b'0' + (m % 10) as u8;
        m /= 10;
        if m == 0 {
            break;
        }
    }
    buf.extend_from_slice(&tmp[i..]);
}

#[cfg(test)]
mod tests {
    #[test]
    fn integers() {
        let mut b = Vec::new();
        for v in [0, -1, 42, i64::MIN, i64::MAX] {
            super::push_i64(&mut b, v);
            b.push(b' ');
        }
        assert_eq!(
            String::from_utf8(b).unwrap(),
            "0 -1 42 -9223372036854775808 9223372036854775807 "
        );
    }
}
