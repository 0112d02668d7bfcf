//! The error type of every reader and writer.

use std::fmt;
use std::path::{Path, PathBuf};

/// An error while reading or writing a file.
///
/// Every variant names the file; text parse errors also carry the 1-based
/// line number. `Display` gives one line in the usual
/// `file:line: message` form:
///
/// ```
/// use aniso_alpha::io::{read_points_bytes, ReadOptions};
/// use std::path::Path;
/// let err = read_points_bytes(Path::new("points.xyz"), b"0 0 0\n1 2\n", &ReadOptions::default())
///     .unwrap_err();
/// assert_eq!(err.to_string(), "points.xyz:2: expected 3 numeric columns, found 2");
/// assert_eq!(err.line(), Some(2));
/// ```
#[derive(Debug)]
#[non_exhaustive]
pub enum IoError {
    /// The file could not be opened or read.
    Open {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The path names a directory, not a file.
    IsDirectory {
        /// The path.
        path: PathBuf,
    },
    /// The extension does not name a supported format.
    UnknownFormat {
        /// The file.
        path: PathBuf,
        /// What the reader or writer expected.
        expected: &'static str,
    },
    /// A text line could not be parsed.
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong with the line.
        message: String,
    },
    /// A binary file (or a header) is malformed: bad header, truncated
    /// data, missing property...
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A coordinate is NaN or infinite.
    NonFinite {
        /// The file.
        path: PathBuf,
        /// 1-based line number, for text formats.
        line: Option<usize>,
        /// 0-based index of the point in the file.
        index: usize,
    },
    /// The file holds no point.
    NoPoints {
        /// The file.
        path: PathBuf,
    },
    /// The folder an output should be written into does not exist.
    MissingFolder {
        /// The missing folder.
        folder: PathBuf,
        /// The output file.
        path: PathBuf,
    },
    /// Writing an output failed (disk full, permissions, invalid data...).
    Write {
        /// The output file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// An output path names something that is not a regular file (a
    /// device node, a FIFO, a socket): writing it by rename would replace
    /// it, so it is refused.
    NotRegularFile {
        /// The output path (after following symbolic links).
        path: PathBuf,
        /// What it is ("a character device", "a FIFO", ...).
        kind: &'static str,
    },
    /// The folder of an output cannot be written into.
    NotWritable {
        /// The folder.
        folder: PathBuf,
        /// The output file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The support for this format was not compiled in (LAS/LAZ without
    /// the `las` feature).
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What is missing.
        message: &'static str,
    },
}

impl IoError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            IoError::Open { path, .. }
            | IoError::IsDirectory { path }
            | IoError::UnknownFormat { path, .. }
            | IoError::Parse { path, .. }
            | IoError::Format { path, .. }
            | IoError::NonFinite { path, .. }
            | IoError::NoPoints { path }
            | IoError::MissingFolder { path, .. }
            | IoError::Write { path, .. }
            | IoError::NotRegularFile { path, .. }
            | IoError::NotWritable { path, .. }
            | IoError::Unsupported { path, .. } => path,
        }
    }

    /// The 1-based line number, for errors in text files.
    pub fn line(&self) -> Option<usize> {
        match self {
            IoError::Parse { line, .. } => Some(*line),
            IoError::NonFinite { line, .. } => *line,
            _ => None,
        }
    }

    pub(crate) fn parse(path: &Path, line: usize, message: impl Into<String>) -> Self {
        IoError::Parse {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    pub(crate) fn format(path: &Path, message: impl Into<String>) -> Self {
        IoError::Format {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// Runs `f`, turning a panic inside it (from a decoder crate on corrupt
/// data) into a format error naming the file: "invalid `kind` file: the
/// decoder failed on corrupt data (the panic's message)".
#[cfg(any(feature = "las", feature = "e57"))]
pub(crate) fn contain_decoder<T>(
    path: &Path,
    kind: &str,
    f: impl FnOnce() -> T,
) -> Result<T, IoError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).map_err(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".into());
        IoError::format(
            path,
            format!("invalid {kind} file: the decoder failed on corrupt data ({what})"),
        )
    })
}

impl fmt::Display for IoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IoError::Open { path, source } => {
                write!(f, "cannot read {}: {}", path.display(), source)
            }
            IoError::IsDirectory { path } => {
                write!(f, "{}: is a directory, not a file", path.display())
            }
            IoError::UnknownFormat { path, expected } => write!(
                f,
                "{}: unknown file extension (expected {})",
                path.display(),
                expected
            ),
            IoError::Parse {
                path,
                line,
                message,
            } => write!(f, "{}:{}: {}", path.display(), line, message),
            IoError::Format { path, message } => write!(f, "{}: {}", path.display(), message),
            IoError::NonFinite { path, line, index } => match line {
                Some(line) => write!(
                    f,
                    "{}:{}: non-finite coordinate (NaN or infinity) in point {}",
                    path.display(),
                    line,
                    index
                ),
                None => write!(
                    f,
                    "{}: non-finite coordinate (NaN or infinity) in point {}",
                    path.display(),
                    index
                ),
            },
            IoError::NoPoints { path } => write!(f, "{}: no points in file", path.display()),
            IoError::MissingFolder { folder, path } => write!(
                f,
                "output folder {} does not exist (for {})",
                folder.display(),
                path.display()
            ),
            IoError::Write { path, source } => {
                write!(f, "cannot write {}: {}", path.display(), source)
            }
            IoError::NotRegularFile { path, kind } => write!(
                f,
                "{}: is {kind}, not a regular file: refusing to replace it with an output",
                path.display()
            ),
            IoError::NotWritable {
                folder,
                path,
                source,
            } => write!(
                f,
                "cannot write into folder {} (for {}): {}",
                folder.display(),
                path.display(),
                source
            ),
            IoError::Unsupported { path, message } => {
                write!(f, "{}: {}", path.display(), message)
            }
        }
    }
}

impl std::error::Error for IoError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            IoError::Open { source, .. }
            | IoError::Write { source, .. }
            | IoError::NotWritable { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Shows a token from user data in an error message: lossy UTF-8, control
/// characters escaped, at most 40 characters.
pub(crate) fn show_token(token: &[u8]) -> String {
    let s = String::from_utf8_lossy(token);
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i == 40 {
            out.push('…');
            break;
        }
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(all(test, any(feature = "las", feature = "e57")))]
mod tests {
    use super::*;

    #[test]
    fn a_decoder_s_panic_is_a_format_error_with_its_message() {
        let path = Path::new("scan.laz");
        assert_eq!(contain_decoder(path, "LAS/LAZ", || 7).unwrap(), 7);
        let message = |f: fn()| contain_decoder(path, "LAS/LAZ", f).unwrap_err().to_string();
        assert_eq!(
            message(|| panic!("bad chunk")),
            "scan.laz: invalid LAS/LAZ file: the decoder failed on corrupt data (bad chunk)"
        );
        assert!(message(|| panic!("{} bytes", 3)).ends_with("(3 bytes)"));
        assert!(message(|| std::panic::panic_any(5u8)).ends_with("(unknown cause)"));
    }
}
