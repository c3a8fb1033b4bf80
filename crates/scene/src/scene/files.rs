//! Where scene files come from: the disk, or the set embedded in the binary.
//!
//! The default scene and its robot and scripts are compiled into the `gantry` binary so
//! that `cargo run --release` works from any directory. The loader reads every file
//! through [`Files`], so embedded and on-disk scenes share one code path.

use std::collections::HashMap;
use std::io;
use std::path::{Path, PathBuf};

/// A read-only file source.
pub trait Files {
    /// Reads a whole file.
    ///
    /// # Errors
    /// The file does not exist or cannot be read.
    fn read(&self, path: &Path) -> io::Result<Vec<u8>>;
    /// Whether `path` is a readable file.
    fn is_file(&self, path: &Path) -> bool;
}

/// The real file system.
#[derive(Debug, Clone, Copy, Default)]
pub struct DiskFiles;

impl Files for DiskFiles {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        std::fs::read(path)
    }
    fn is_file(&self, path: &Path) -> bool {
        path.is_file()
    }
}

/// Files compiled into the binary, addressed by virtual paths such as
/// `/embedded/assets/scenes/showroom.toml`.
#[derive(Debug, Clone, Default)]
pub struct EmbeddedFiles {
    files: HashMap<PathBuf, &'static [u8]>,
}

impl EmbeddedFiles {
    /// The virtual folder every embedded path starts with.
    pub const ROOT: &'static str = "/embedded";

    /// Builds the set from `(path relative to the repository root, bytes)` pairs.
    pub fn new(entries: &[(&str, &'static [u8])]) -> Self {
        let files = entries
            .iter()
            .map(|(p, b)| (Path::new(Self::ROOT).join(p), *b))
            .collect();
        Self { files }
    }

    /// The virtual path of a file given relative to the repository root.
    pub fn path(rel: &str) -> PathBuf {
        Path::new(Self::ROOT).join(rel)
    }
}

impl Files for EmbeddedFiles {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        let key = normalize(path);
        self.files.get(&key).map(|b| b.to_vec()).ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::NotFound,
                format!("{} is not embedded in this binary", path.display()),
            )
        })
    }
    fn is_file(&self, path: &Path) -> bool {
        self.files.contains_key(&normalize(path))
    }
}

/// A file source that keeps a copy of every file it reads through `inner`: what a
/// recording attaches, so that the scene can be loaded again from the recording alone
/// (the scene file, its URDFs, meshes and scripts, as they were when the run began).
pub struct LoggedFiles<'a> {
    inner: &'a dyn Files,
    /// Files read so far, by the path they were read at, first read first.
    read: std::cell::RefCell<Vec<(PathBuf, Vec<u8>)>>,
}

impl<'a> LoggedFiles<'a> {
    /// Reads through `inner`.
    pub fn new(inner: &'a dyn Files) -> Self {
        Self {
            inner,
            read: std::cell::RefCell::new(Vec::new()),
        }
    }

    /// Every file read, once each, by the (normalised) path it was read at.
    pub fn into_read(self) -> Vec<(PathBuf, Vec<u8>)> {
        self.read.into_inner()
    }
}

impl Files for LoggedFiles<'_> {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        let bytes = self.inner.read(path)?;
        let key = normalize(path);
        let mut read = self.read.borrow_mut();
        if !read.iter().any(|(p, _)| *p == key) {
            read.push((key, bytes.clone()));
        }
        Ok(bytes)
    }
    fn is_file(&self, path: &Path) -> bool {
        self.inner.is_file(path)
    }
}

/// Files held in memory, by path: a recording's attachments, from which its scene
/// loads again at the paths it was first read at.
#[derive(Debug, Clone, Default)]
pub struct MapFiles {
    files: HashMap<PathBuf, Vec<u8>>,
}

impl MapFiles {
    /// The files `(path, bytes)`; paths are normalised as [`normalize`] does.
    pub fn new(files: impl IntoIterator<Item = (PathBuf, Vec<u8>)>) -> Self {
        Self {
            files: files.into_iter().map(|(p, b)| (normalize(&p), b)).collect(),
        }
    }
}

impl Files for MapFiles {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self.files.get(&normalize(path)).cloned().ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::NotFound,
                format!("{} is not among the recorded files", path.display()),
            )
        })
    }
    fn is_file(&self, path: &Path) -> bool {
        self.files.contains_key(&normalize(path))
    }
}

/// A file's name without folder and extension: the name of the scene it holds.
pub(super) fn stem(path: &Path) -> String {
    path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene").to_owned()
}

/// `path` with `.` removed and each `..` cancelling the component before it, without
/// touching the disk (embedded paths have no symlinks). A `..` at the root stays at the
/// root, as the OS treats it.
pub fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                out.pop();
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}
