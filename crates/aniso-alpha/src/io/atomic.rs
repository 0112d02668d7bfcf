//! Atomic outputs: complete or absent.

use std::fs::{self, File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::IoError;

/// Size of the write buffer of [`atomic_write`].
const BUFFER: usize = 1 << 20;

/// The folder an output file goes into (`.` for a bare file name).
fn output_folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Checks that `path` can be an output: its folder exists and it is not
/// itself a directory. Call it before long computations so that a typo in
/// an output path fails at once. [`atomic_write`] checks it again.
///
/// ```
/// use aniso_alpha::io::{check_output_path, IoError};
/// use std::path::Path;
/// let err = check_output_path(Path::new("/no/such/folder/out.ply")).unwrap_err();
/// assert!(matches!(err, IoError::MissingFolder { .. }));
/// assert!(err.to_string().contains("/no/such/folder"));
/// ```
pub fn check_output_path(path: &Path) -> Result<(), IoError> {
    let folder = output_folder(path);
    if !folder.is_dir() {
        return Err(IoError::MissingFolder {
            folder,
            path: path.to_path_buf(),
        });
    }
    if path.is_dir() || path.file_name().is_none() {
        return Err(IoError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// Removes the temporary file unless it was renamed.
struct TempGuard {
    path: PathBuf,
    armed: bool,
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if self.armed {
            let _ = fs::remove_file(&self.path);
        }
    }
}

/// Writes `path` atomically: `write` fills a buffered temporary file
/// `.<name>.tmp-<pid>-<n>` in the same folder, which is renamed to `path`
/// only when `write` and the flush succeed. On any error (or a panic in
/// `write`) the temporary file is removed, so `path` is either complete or
/// untouched. A missing folder is an [`IoError::MissingFolder`].
///
/// Every output of the project goes through this function.
///
/// ```
/// use aniso_alpha::io::atomic_write;
/// let path = std::env::temp_dir().join(format!("atomic-doc-{}.txt", std::process::id()));
/// atomic_write(&path, |w| w.write_all(b"hello\n")).unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello\n");
/// // A failing writer leaves the previous content untouched.
/// let err = atomic_write(&path, |w| {
///     w.write_all(b"partial")?;
///     Err(std::io::Error::other("boom"))
/// });
/// assert!(err.is_err());
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello\n");
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn atomic_write<F>(path: &Path, write: F) -> Result<(), IoError>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    check_output_path(path)?;
    let folder = output_folder(path);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = folder.join(format!(".{name}.tmp-{}-{n}", std::process::id()));
    let werr = |source| IoError::Write {
        path: path.to_path_buf(),
        source,
    };
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .map_err(werr)?;
    let mut guard = TempGuard {
        path: tmp,
        armed: true,
    };
    let mut out = BufWriter::with_capacity(BUFFER, file);
    write(&mut out).map_err(werr)?;
    let file: File = out.into_inner().map_err(|e| werr(e.into_error()))?;
    file.sync_all().map_err(werr)?;
    drop(file);
    fs::rename(&guard.path, path).map_err(werr)?;
    guard.armed = false;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("aniso-atomic-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn writes_and_leaves_no_temp() {
        let d = dir("ok");
        let p = d.join("out.txt");
        atomic_write(&p, |w| w.write_all(b"abc")).unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"abc");
        assert_eq!(fs::read_dir(&d).unwrap().count(), 1);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn error_removes_temp_and_output_stays_absent() {
        let d = dir("err");
        let p = d.join("out.txt");
        let r = atomic_write(&p, |w| {
            w.write_all(&[b'x'; 3 << 20])?;
            Err(std::io::Error::other("stop"))
        });
        let msg = r.unwrap_err().to_string();
        assert!(msg.contains("out.txt") && msg.contains("stop"), "{msg}");
        assert!(!p.exists());
        assert_eq!(fs::read_dir(&d).unwrap().count(), 0);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn panic_removes_temp() {
        let d = dir("panic");
        let p = d.join("out.txt");
        let r = std::panic::catch_unwind(|| {
            let _ = atomic_write(&p, |_| panic!("inside writer"));
        });
        assert!(r.is_err());
        assert_eq!(fs::read_dir(&d).unwrap().count(), 0);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn missing_folder_and_directory_target() {
        let d = dir("missing");
        let p = d.join("nope").join("out.txt");
        let e = atomic_write(&p, |w| w.write_all(b"x")).unwrap_err();
        assert!(matches!(e, IoError::MissingFolder { .. }));
        assert!(e.to_string().contains("nope"));
        let e = atomic_write(&d, |w| w.write_all(b"x")).unwrap_err();
        assert!(matches!(e, IoError::IsDirectory { .. }), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }
}
