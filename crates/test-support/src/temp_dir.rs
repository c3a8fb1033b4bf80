//! A temporary folder that cleans up after the test.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A folder under the system temp dir, removed (with everything in it) when dropped.
///
/// Its name holds the caller's tag, the process id and a counter, so tests running in
/// parallel, and concurrent runs of the same test binary, never share one.
#[derive(Debug)]
pub struct TempDir {
    path: PathBuf,
}

impl TempDir {
    /// A fresh, empty folder whose name contains `tag`. A folder left by an earlier run
    /// with the same name is removed first.
    ///
    /// # Panics
    /// If the folder cannot be created.
    pub fn new(tag: &str) -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let path = std::env::temp_dir().join(format!("gantry-test-{tag}-{}-{n}", std::process::id()));
        // A leftover of a crashed run with the same process id; nothing to keep.
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).expect("create the temp dir");
        Self { path }
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes `contents` (text or bytes) to `name` inside the folder and returns the
    /// file's path.
    ///
    /// # Panics
    /// If the file cannot be written (a missing subfolder in `name`, for one).
    pub fn write(&self, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let p = self.path.join(name);
        std::fs::write(&p, contents).expect("write a temp file");
        p
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        // Best effort: a file still open elsewhere must not turn a pass into a panic.
        let _ = std::fs::remove_dir_all(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::TempDir;

    #[test]
    fn folders_are_distinct_written_and_removed_on_drop() {
        let (a, b) = (TempDir::new("same"), TempDir::new("same"));
        assert_ne!(a.path(), b.path());
        let file = a.write("x.txt", "hello");
        assert_eq!(std::fs::read_to_string(&file).expect("written"), "hello");
        let kept = a.path().to_owned();
        drop(a);
        assert!(!kept.exists(), "{} is left behind", kept.display());
        assert!(b.path().is_dir());
    }
}
