//! Errors of scene loading: each names the file, and the line and column when known.

use std::path::PathBuf;

/// Why a scene, URDF, mesh or script could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// A file could not be read.
    #[error("{path}: cannot read: {source}{hint}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
        /// Extra advice (e.g. which line referenced the file), possibly empty.
        hint: String,
    },
    /// The TOML or URDF XML is malformed, or a TOML value has the wrong type.
    #[error("{path}:{line}:{column}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// The file is well-formed but its content is invalid (unknown parent, bad value).
    #[error("{path}:{line}:{column}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A URDF file is malformed or inconsistent.
    #[error("{path}: {message}")]
    Urdf {
        /// The URDF file.
        path: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A CoppeliaSim 4.8+ XML scene or model (`.simscene`, `.simmodel`), which gantry
    /// cannot read.
    #[error(
        "'{}' is a CoppeliaSim 4.8+ XML file, which gantry cannot read: save it as .ttt/.ttm in CoppeliaSim, or load a gantry scene (.toml, see docs/scene-format.md) or a robot (.urdf)",
        .0.display()
    )]
    CoppeliaXml(PathBuf),
    /// A CoppeliaSim scene or model file could not be decoded.
    #[error("{path}: {source}")]
    Coppelia {
        /// The file.
        path: PathBuf,
        /// What the reader found wrong, and where.
        source: gantry_coppelia_file::ReadError,
    },
    /// A mesh file could not be found or decoded.
    #[error("{path}: {message}")]
    Mesh {
        /// The mesh file (or the reference that could not be resolved).
        path: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },
}

/// Converts a byte offset of `text` to a 1-based (line, column).
pub(crate) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text.as_bytes()[..offset];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let col = before.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
    (line, col)
}
