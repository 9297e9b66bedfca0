use std::path::{Path, PathBuf};

use quake_formats::FormatError;

/// Everything that can go wrong loading a map or writing a picture; messages name the file.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// Reading or writing a file failed (the error names the file).
    #[error(transparent)]
    File(FormatError),
    /// A file (the map, its `.lit`, the palette) could not be parsed.
    #[error("{path}: {error}")]
    Format {
        /// The file that did not parse.
        path: PathBuf,
        /// What was wrong with it.
        error: FormatError,
    },
    /// The map parsed, but cannot be drawn: tools refuse it, its entities do not parse, or its
    /// node tree is not a tree.
    #[error("{path}: {detail}")]
    BadMap {
        /// The BSP file.
        path: PathBuf,
        /// Why it cannot be drawn.
        detail: String,
    },
    /// A frame could not be encoded as PNG.
    #[error("{path}: writing PNG: {error}")]
    Png {
        /// The picture that was to be written.
        path: PathBuf,
        /// The encoder's error.
        error: ::image::ImageError,
    },
    /// The interactive window could not be opened or updated (no display, for instance).
    #[error("window: {0}")]
    Window(String),
}

impl ViewerError {
    /// A quake-formats error about the file at `path`.
    pub fn format(path: &Path, error: FormatError) -> ViewerError {
        match error {
            FormatError::Io { .. } => ViewerError::File(error),
            error => ViewerError::Format {
                path: path.to_path_buf(),
                error,
            },
        }
    }
}

/// A result whose error defaults to [`ViewerError`].
pub type Result<T, E = ViewerError> = std::result::Result<T, E>;
