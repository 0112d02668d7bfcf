//! A scratch folder for integration tests, removed when dropped. Shared by
//! the library's tests (`common/mod.rs`) and the CLI's, which include this
//! file by path.

use std::path::{Path, PathBuf};

/// A fresh folder `aniso-PREFIX-PID-NAME` in the system's temporary
/// folder, removed (with its content) when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    /// Empties and makes the folder; `prefix` names the test binary so that
    /// binaries running at once never share one.
    pub fn new(prefix: &str, name: &str) -> Self {
        let d = std::env::temp_dir().join(format!("aniso-{prefix}-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        TempDir(d)
    }

    /// The path of `name` inside the folder.
    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// Writes `bytes` to `name` inside the folder; its path.
    pub fn file(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
}

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
