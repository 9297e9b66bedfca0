use std::path::{Path, PathBuf};

use quake_formats::FormatError;

/// Everything that can go wrong loading a map or writing a picture; messages name the file.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// Reading or writing a file failed (the error names the file).
    #[error(transparent)]
    File(FormatError),
    #[error("{path}: {error}")]
    Format { path: PathBuf, error: FormatError },
    #[error("{path}: {detail}")]
    BadMap { path: PathBuf, detail: String },
    #[error("{path}: writing PNG: {error}")]
    Png {
        path: PathBuf,
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

pub type Result<T, E = ViewerError> = std::result::Result<T, E>;
