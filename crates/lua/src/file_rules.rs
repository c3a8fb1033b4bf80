//! Which folders on disk a script may reach, and the one check every path goes through.
//!
//! Two things read files for scripts: `require` of the user's own modules
//! (`crate::modules`) and the confined `io` library (`crate::script_io`). Both take
//! their folders from a [`Folders`] built per script from the scene's folder and the
//! command line (`--lua-path`, `--allow-files`, carried by [`crate::ScriptLimits`]), and
//! both check paths with [`confine`]: the path is resolved against its folder, made real
//! (symbolic links followed, `..` removed) and must then lie inside one of the allowed
//! folders, themselves made real. Non-goal: a file swapped for a link between the check
//! and the open (the user's own folders are trusted not to change under the script).

use std::path::{Component, Path, PathBuf};

/// The folders the user named on the command line (`--lua-path`, `--allow-files`): the
/// Lua host's state, from which each script's [`Folders`] is made.
pub(crate) struct FileRoots {
    /// `--lua-path` folders.
    pub(crate) lua_path: Vec<PathBuf>,
    /// `--allow-files` folders.
    pub(crate) allow_files: Vec<PathBuf>,
}

/// The folders one script may read modules and files from, and write files into.
#[derive(Debug, Clone, Default)]
pub(crate) struct Folders {
    /// The scene's folder; `None` for a scene embedded in gantry (no folder on disk).
    pub(crate) scene: Option<PathBuf>,
    /// Extra module folders (`--lua-path`), searched after the scene's.
    pub(crate) lua_path: Vec<PathBuf>,
    /// Folders scripts may read and write (`--allow-files`).
    pub(crate) writable: Vec<PathBuf>,
}

impl Folders {
    /// Where modules are searched, in order: the scene's folder, then `--lua-path`.
    pub(crate) fn module_roots(&self) -> Vec<PathBuf> {
        self.scene.iter().chain(&self.lua_path).cloned().collect()
    }

    /// Where files may be read: the scene's folder and the `--allow-files` folders.
    pub(crate) fn readable(&self) -> Vec<PathBuf> {
        self.scene.iter().chain(&self.writable).cloned().collect()
    }
}

/// Why a path was refused.
#[derive(Debug, thiserror::Error)]
pub(crate) enum Refused {
    /// The path (as written or once made real) lies outside every allowed folder.
    #[error("{path} is outside the folders scripts may {what} ({folders})")]
    Outside {
        /// The path as the script gave it.
        path: String,
        /// "read" or "write".
        what: &'static str,
        /// The allowed folders, listed for the message.
        folders: String,
    },
    /// The path cannot be resolved: its folder does not exist or cannot be read.
    #[error("{path}: {reason}")]
    Unresolvable {
        /// The path as the script gave it.
        path: String,
        /// The operating system's reason.
        reason: String,
    },
}

/// The folders of `roots` as a list for messages ("none" when empty).
pub(crate) fn list(roots: &[PathBuf]) -> String {
    if roots.is_empty() {
        return "none".to_owned();
    }
    roots
        .iter()
        .map(|r| r.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The real path of `path` (resolved against `base` when relative) if it lies inside one
/// of `roots`. A path that does not exist yet (a file about to be created) is checked
/// through its parent folder, which must exist; a dangling symbolic link is refused, as
/// creating the file would follow it wherever it points.
///
/// # Errors
/// The path is outside every root, or cannot be resolved.
pub(crate) fn confine(path: &Path, base: &Path, roots: &[PathBuf], what: &'static str) -> Result<PathBuf, Refused> {
    let shown = path.display().to_string();
    let outside = || Refused::Outside {
        path: shown.clone(),
        what,
        folders: list(roots),
    };
    let unresolvable = |e: std::io::Error| Refused::Unresolvable {
        path: shown.clone(),
        reason: e.to_string(),
    };
    let joined = absolute(&base.join(path)).map_err(unresolvable)?;
    let real = match std::fs::symlink_metadata(&joined) {
        Ok(m) if m.file_type().is_symlink() && std::fs::metadata(&joined).is_err() => return Err(outside()),
        Ok(_) => joined.canonicalize().map_err(unresolvable)?,
        Err(_) => {
            // A new file: its name must be a plain name, its parent real and inside.
            let (Some(parent), Some(Component::Normal(name))) = (joined.parent(), joined.components().next_back())
            else {
                return Err(outside());
            };
            parent.canonicalize().map_err(unresolvable)?.join(name)
        }
    };
    let inside = roots
        .iter()
        .filter_map(|r| absolute(r).and_then(|r| r.canonicalize()).ok())
        .any(|r| real.starts_with(r));
    if inside { Ok(real) } else { Err(outside()) }
}

/// `path` made absolute against the current directory (an empty path is `.`).
fn absolute(path: &Path) -> std::io::Result<PathBuf> {
    if path.as_os_str().is_empty() {
        std::path::absolute(".")
    } else {
        std::path::absolute(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_stay_inside_and_dotdot_is_refused() {
        let dir = std::env::temp_dir().join(format!("gantry-file-rules-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let roots = [dir.join("sub")];
        assert!(confine(Path::new("new.csv"), &roots[0], &roots, "write").is_ok());
        assert!(confine(Path::new("../x.csv"), &roots[0], &roots, "write").is_err());
        assert!(confine(Path::new("/etc/passwd"), &roots[0], &roots, "read").is_err());
        assert!(confine(Path::new("x"), &roots[0], &[], "read").is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
