//! Atomic outputs: complete or absent, and never in place of something
//! that is not a regular file.
//!
//! * An output is written to a temporary file `.<name>.tmp-<pid>-<n>` in
//!   the target's folder and renamed onto the target when complete.
//! * An existing output that is not a regular file (a device node such as
//!   `/dev/null`, a FIFO, a socket) is refused: a rename would replace it.
//! * A symbolic link is followed deliberately: the file it points to (at
//!   the end of the chain, which may not exist yet) is the one written,
//!   atomically, in its own folder, and the link stays a link. The file's
//!   permissions are kept.
//! * Every temporary file is listed in a process-wide registry while it
//!   exists; [`remove_temp_files`] deletes them (the CLI calls it from its
//!   SIGINT/SIGTERM handler) and refuses new ones from then on.

use std::fs::{self, File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use super::IoError;

/// Size of the write buffer of [`atomic_write`].
const BUFFER: usize = 1 << 20;

/// Symbolic links followed at most (as the kernel's ELOOP limit).
const MAX_LINKS: usize = 40;

/// Temporary files that exist now, and whether new ones are refused.
static TEMPS: Mutex<(Vec<PathBuf>, bool)> = Mutex::new((Vec::new(), false));

/// The folder an output file goes into (`.` for a bare file name).
fn output_folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The file an output path writes: `path` itself, or the end of its chain
/// of symbolic links (which need not exist yet).
///
/// ```
/// use aniso_alpha::io::resolve_output;
/// use std::path::Path;
/// assert_eq!(resolve_output(Path::new("no/such/link")).unwrap(), Path::new("no/such/link"));
/// ```
pub fn resolve_output(path: &Path) -> Result<PathBuf, IoError> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = fs::read_link(&p).map_err(|source| IoError::Write {
                    path: path.to_path_buf(),
                    source,
                })?;
                p = if target.is_absolute() {
                    target
                } else {
                    output_folder(&p).join(target)
                };
            }
            _ => return Ok(p),
        }
    }
    Err(IoError::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other("too many levels of symbolic links"),
    })
}

/// What a non-regular, non-directory file is, for error messages.
fn kind_of(meta: &fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    let _ = meta;
    "a special file"
}

/// Resolves `path` ([`resolve_output`]) and checks the result can be
/// replaced: its folder exists, and it is absent or a regular file.
fn checked_target(path: &Path) -> Result<PathBuf, IoError> {
    if path.file_name().is_none() {
        return Err(IoError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    let target = resolve_output(path)?;
    let folder = output_folder(&target);
    if !folder.is_dir() {
        return Err(IoError::MissingFolder {
            folder,
            path: path.to_path_buf(),
        });
    }
    match fs::metadata(&target) {
        Ok(m) if m.is_dir() => Err(IoError::IsDirectory {
            path: path.to_path_buf(),
        }),
        Ok(m) if !m.is_file() => Err(IoError::NotRegularFile {
            path: target,
            kind: kind_of(&m),
        }),
        _ => Ok(target),
    }
}

/// Checks that `path` can be an output: its folder exists and can be
/// written into (a probe file is created and removed), and it is absent or
/// a regular file (after following symbolic links), not a directory, a
/// device node or a FIFO. Call it before long computations so that a bad
/// output path fails at once. [`atomic_write`] checks it again.
///
/// ```
/// use aniso_alpha::io::{check_output_path, IoError};
/// use std::path::Path;
/// let err = check_output_path(Path::new("/no/such/folder/out.ply")).unwrap_err();
/// assert!(matches!(err, IoError::MissingFolder { .. }));
/// assert!(err.to_string().contains("/no/such/folder"));
/// # #[cfg(unix)]
/// let err = check_output_path(Path::new("/dev/null")).unwrap_err();
/// # #[cfg(unix)]
/// assert!(err.to_string().contains("not a regular file"), "{err}");
/// ```
pub fn check_output_path(path: &Path) -> Result<(), IoError> {
    let target = checked_target(path)?;
    let folder = output_folder(&target);
    let probe = temp_name(&target, "probe");
    match OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(f) => {
            drop(f);
            let _ = fs::remove_file(&probe);
            Ok(())
        }
        Err(source) => Err(IoError::NotWritable {
            folder,
            path: path.to_path_buf(),
            source,
        }),
    }
}

/// Whether `a` and `b` name the same existing file (same device and inode
/// on Unix, same canonical path elsewhere), through links of any kind.
///
/// ```
/// use aniso_alpha::io::same_file;
/// use std::path::Path;
/// let me = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
/// assert!(same_file(&me, &me.parent().unwrap().join(".").join("Cargo.toml")));
/// assert!(!same_file(&me, Path::new("/no/such/file")));
/// ```
pub fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (fs::metadata(a), fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let _ = (&ma, &mb);
        ma.dev() == mb.dev() && ma.ino() == mb.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        matches!((fs::canonicalize(a), fs::canonicalize(b)), (Ok(x), Ok(y)) if x == y)
    }
}

/// The file an output path will write, as one comparable path: symbolic
/// links followed, the folder canonicalized. Two outputs with the same
/// key would overwrite each other.
pub fn output_key(path: &Path) -> PathBuf {
    let target = resolve_output(path).unwrap_or_else(|_| path.to_path_buf());
    let folder = output_folder(&target);
    let folder = fs::canonicalize(&folder).unwrap_or(folder);
    match target.file_name() {
        Some(name) => folder.join(name),
        None => folder,
    }
}

/// Deletes every temporary output file that exists now, and makes every
/// later [`atomic_write`] fail: for a signal handler that then exits. Safe
/// to call from any thread.
pub fn remove_temp_files() {
    let mut temps = TEMPS.lock().unwrap_or_else(|e| e.into_inner());
    for p in temps.0.drain(..) {
        if fs::remove_file(&p).is_err() {
            // A scratch folder ([`ScratchFolder`]) and what it holds.
            let _ = fs::remove_dir_all(p);
        }
    }
    temps.1 = true;
}

/// A hidden scratch folder next to an output (`.aniso-alpha-scratch-<pid>-<n>`),
/// registered as the temporary outputs are: removed with what it holds
/// when dropped, and by [`remove_temp_files`] (a signal handler's) while
/// it exists. For the scratch files of a long run (a region run's part
/// ids), which no interruption should leave behind.
pub struct ScratchFolder {
    path: PathBuf,
}

impl ScratchFolder {
    /// Creates the folder inside `folder`.
    ///
    /// # Errors
    /// [`IoError::Write`] when it cannot be made (or the process is being
    /// interrupted).
    pub fn create(folder: &Path) -> Result<ScratchFolder, IoError> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path = folder.join(format!(".aniso-alpha-scratch-{}-{n}", std::process::id()));
        let err = |source| IoError::Write {
            path: path.clone(),
            source,
        };
        register(&path).map_err(err)?;
        let scratch = ScratchFolder { path: path.clone() };
        fs::create_dir(&path).map_err(err)?;
        Ok(scratch)
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for ScratchFolder {
    fn drop(&mut self) {
        let mut temps = TEMPS.lock().unwrap_or_else(|e| e.into_inner());
        let _ = fs::remove_dir_all(&self.path);
        temps.0.retain(|p| p != &self.path);
    }
}

fn temp_name(target: &Path, tag: &str) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    output_folder(target).join(format!(".{name}.{tag}-{}-{n}", std::process::id()))
}

/// Registers `path` for [`remove_temp_files`] (before it is made, so that
/// a signal handler never misses it); an error once the process is being
/// interrupted.
fn register(path: &Path) -> std::io::Result<()> {
    let mut temps = TEMPS.lock().unwrap_or_else(|e| e.into_inner());
    if temps.1 {
        return Err(std::io::Error::new(
            std::io::ErrorKind::Interrupted,
            "interrupted",
        ));
    }
    temps.0.push(path.to_path_buf());
    Ok(())
}

/// A registered temporary file, removed (and unregistered) unless renamed.
struct TempGuard {
    path: PathBuf,
}

impl TempGuard {
    /// Registers `path` and creates it (registered first, so that a signal
    /// handler never misses a file).
    fn create(path: PathBuf) -> std::io::Result<(TempGuard, File)> {
        register(&path)?;
        let guard = TempGuard { path };
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&guard.path)?;
        Ok((guard, file))
    }

    /// Renames the file onto `target` and unregisters it.
    fn commit(self, target: &Path) -> std::io::Result<()> {
        let mut temps = TEMPS.lock().unwrap_or_else(|e| e.into_inner());
        if temps.1 {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "interrupted",
            ));
        }
        fs::rename(&self.path, target)?;
        temps.0.retain(|p| p != &self.path);
        drop(temps);
        std::mem::forget(self);
        Ok(())
    }
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        let mut temps = TEMPS.lock().unwrap_or_else(|e| e.into_inner());
        let _ = fs::remove_file(&self.path);
        temps.0.retain(|p| p != &self.path);
    }
}

/// Writes `path` atomically: `write` fills a buffered temporary file
/// `.<name>.tmp-<pid>-<n>` in the same folder, which is renamed to `path`
/// only when `write` and the flush succeed. On any error (or a panic in
/// `write`) the temporary file is removed, so `path` is either complete or
/// untouched. A missing folder is an [`IoError::MissingFolder`]; an
/// existing device node, FIFO or socket an [`IoError::NotRegularFile`]; a
/// symbolic link is followed (see the module docs).
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
    atomic_write_file(path, |file| {
        let mut out = BufWriter::with_capacity(BUFFER, file);
        write(&mut out)?;
        out.into_inner().map_err(|e| e.into_error())
    })
}

/// Test hook (CLI tests of the signal handler): holds a temporary file
/// open for `ANISO_ALPHA_TEST_WRITE_DELAY_MS` milliseconds before writing.
fn test_write_delay() {
    if let Some(ms) = std::env::var_os("ANISO_ALPHA_TEST_WRITE_DELAY_MS")
        .and_then(|v| v.to_str().and_then(|s| s.parse::<u64>().ok()))
    {
        std::thread::sleep(std::time::Duration::from_millis(ms));
    }
}

/// [`atomic_write`] handing the temporary [`File`] itself to `write`
/// (for writers that seek), which gives it back when done.
pub(crate) fn atomic_write_file<F>(path: &Path, write: F) -> Result<(), IoError>
where
    F: FnOnce(File) -> std::io::Result<File>,
{
    let (pending, file) = PendingFile::create(path)?;
    test_write_delay();
    let file = write(file).map_err(|source| IoError::Write {
        path: path.to_path_buf(),
        source,
    })?;
    pending.commit(file)
}

/// An output written over several calls, atomically as [`atomic_write`]
/// writes: a temporary file in the output's folder, renamed onto the
/// output by [`PendingFile::commit`], removed if dropped before.
pub(crate) struct PendingFile {
    guard: TempGuard,
    target: PathBuf,
    path: PathBuf,
}

impl PendingFile {
    /// Checks `path` as [`atomic_write`] does and creates the temporary
    /// file (with the permissions of the file it will replace).
    pub(crate) fn create(path: &Path) -> Result<(PendingFile, File), IoError> {
        let target = checked_target(path)?;
        let (guard, file) =
            TempGuard::create(temp_name(&target, "tmp")).map_err(|source| IoError::Write {
                path: path.to_path_buf(),
                source,
            })?;
        if let Ok(meta) = fs::metadata(&target) {
            let _ = fs::set_permissions(&guard.path, meta.permissions());
        }
        let pending = PendingFile {
            guard,
            target,
            path: path.to_path_buf(),
        };
        Ok((pending, file))
    }

    /// Syncs `file` (the temporary file) and renames it onto the output.
    pub(crate) fn commit(self, file: File) -> Result<(), IoError> {
        let werr = |source| IoError::Write {
            path: self.path.clone(),
            source,
        };
        file.sync_all().map_err(werr)?;
        drop(file);
        self.guard.commit(&self.target).map_err(werr)
    }
}

/// An output written over several calls, atomically as [`atomic_write`]
/// writes (a temporary file, renamed onto the output by
/// [`AtomicWriter::finish`], removed when dropped before): for outputs
/// written a piece at a time, such as the labels of a cloud read in
/// pieces.
pub struct AtomicWriter {
    pending: PendingFile,
    out: BufWriter<File>,
}

impl AtomicWriter {
    /// Checks `path` as [`atomic_write`] does and creates the temporary
    /// file.
    ///
    /// # Errors
    /// As [`atomic_write`].
    pub fn create(path: &Path) -> Result<AtomicWriter, IoError> {
        let (pending, file) = PendingFile::create(path)?;
        test_write_delay();
        Ok(AtomicWriter {
            pending,
            out: BufWriter::with_capacity(BUFFER, file),
        })
    }

    /// Writes through `write` (buffered).
    ///
    /// # Errors
    /// [`IoError::Write`] naming the output.
    pub fn write(
        &mut self,
        write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
    ) -> Result<(), IoError> {
        write(&mut self.out).map_err(|source| IoError::Write {
            path: self.pending.path.clone(),
            source,
        })
    }

    /// Flushes, syncs and renames the file onto the output.
    ///
    /// # Errors
    /// [`IoError::Write`] naming the output.
    pub fn finish(self) -> Result<(), IoError> {
        let path = self.pending.path.clone();
        let file = self.out.into_inner().map_err(|e| IoError::Write {
            path,
            source: e.into_error(),
        })?;
        self.pending.commit(file)
    }
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
    fn a_writer_over_several_calls_commits_at_the_end_only() {
        let d = dir("writer");
        let p = d.join("out.txt");
        let mut w = AtomicWriter::create(&p).unwrap();
        w.write(|o| o.write_all(b"ab")).unwrap();
        w.write(|o| o.write_all(b"c")).unwrap();
        assert!(!p.exists());
        w.finish().unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"abc");
        // Dropped before its end: nothing, not even the temporary file.
        let q = d.join("dropped.txt");
        let mut w = AtomicWriter::create(&q).unwrap();
        w.write(|o| o.write_all(&[b'x'; 3 << 20])).unwrap();
        drop(w);
        assert!(!q.exists());
        assert_eq!(fs::read_dir(&d).unwrap().count(), 1);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_scratch_folder_goes_with_its_content_when_dropped() {
        let d = dir("scratch");
        let a = ScratchFolder::create(&d).unwrap();
        fs::write(a.path().join("ids"), b"1234").unwrap();
        assert!(a.path().is_dir() && a.path().starts_with(&d));
        let kept = a.path().to_path_buf();
        drop(a);
        assert!(!kept.exists());
        assert_eq!(fs::read_dir(&d).unwrap().count(), 0);
        fs::remove_dir_all(&d).unwrap();
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

    #[cfg(unix)]
    #[test]
    fn symlinks_are_followed_and_kept() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("link");
        let real = d.join("real.txt");
        fs::write(&real, b"old").unwrap();
        fs::set_permissions(&real, fs::Permissions::from_mode(0o640)).unwrap();
        let link = d.join("link.txt");
        std::os::unix::fs::symlink("real.txt", &link).unwrap();
        atomic_write(&link, |w| w.write_all(b"new")).unwrap();
        assert!(fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(fs::read(&real).unwrap(), b"new");
        let mode = fs::metadata(&real).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
        // A dangling link: its target is created.
        let dangling = d.join("dangling.txt");
        std::os::unix::fs::symlink(d.join("later.txt"), &dangling).unwrap();
        atomic_write(&dangling, |w| w.write_all(b"x")).unwrap();
        assert_eq!(fs::read(d.join("later.txt")).unwrap(), b"x");
        assert_eq!(output_key(&link), output_key(&real));
        // A loop of links is an error, not a hang.
        std::os::unix::fs::symlink("b", d.join("a")).unwrap();
        std::os::unix::fs::symlink("a", d.join("b")).unwrap();
        let e = atomic_write(&d.join("a"), |w| w.write_all(b"x")).unwrap_err();
        assert!(e.to_string().contains("symbolic links"), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn special_files_are_refused() {
        let d = dir("fifo");
        let fifo = d.join("pipe");
        let st = std::process::Command::new("mkfifo").arg(&fifo).status();
        if st.is_ok_and(|s| s.success()) {
            let e = atomic_write(&fifo, |w| w.write_all(b"x")).unwrap_err();
            assert!(matches!(e, IoError::NotRegularFile { .. }), "{e}");
            assert!(e.to_string().contains("FIFO"), "{e}");
            let link = d.join("to-pipe");
            std::os::unix::fs::symlink(&fifo, &link).unwrap();
            assert!(check_output_path(&link).is_err());
            use std::os::unix::fs::FileTypeExt;
            assert!(fs::metadata(&fifo).unwrap().file_type().is_fifo());
        }
        // /dev/null is only checked here, never written.
        let e = check_output_path(Path::new("/dev/null")).unwrap_err();
        assert!(e.to_string().contains("character device"), "{e}");
        assert_eq!(
            fs::read_dir(&d)
                .unwrap()
                .filter(|e| {
                    e.as_ref()
                        .unwrap()
                        .file_name()
                        .to_string_lossy()
                        .contains(".tmp-")
                })
                .count(),
            0
        );
        fs::remove_dir_all(&d).unwrap();
    }
}
