//! Writing output files so a crash or error never leaves a half-written file behind.

use crate::error::{FormatError, Result};
use std::path::{Path, PathBuf};

/// Write `bytes` to a temporary file beside `path`, then rename it into place.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    Staged::write(path, bytes)?.commit()
}

/// A whole file written under a temporary name beside its destination, not yet in place: for
/// outputs that must arrive in a chosen order (a BSP and its `.lit`). Dropped without
/// [`Staged::commit`], the temporary is removed.
#[derive(Debug)]
pub struct Staged {
    tmp: PathBuf,
    path: PathBuf,
    committed: bool,
}

impl Staged {
    /// Write `bytes` to a temporary file beside `path` (in the same folder, so the rename stays
    /// on one file system), leaving `path` untouched until [`Staged::commit`].
    pub fn write(path: &Path, bytes: &[u8]) -> Result<Self> {
        let file_name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".to_string());
        let tmp = path.with_file_name(format!(".{file_name}.tmp{}", std::process::id()));
        let staged = Staged {
            tmp,
            path: path.to_path_buf(),
            committed: false,
        };
        std::fs::write(&staged.tmp, bytes).map_err(|e| staged.io(e))?;
        Ok(staged)
    }

    /// Where the file goes.
    pub fn target(&self) -> &Path {
        &self.path
    }

    /// Renames the temporary into place (atomic within one file system).
    pub fn commit(mut self) -> Result<()> {
        std::fs::rename(&self.tmp, &self.path).map_err(|e| self.io(e))?;
        self.committed = true;
        Ok(())
    }

    fn io(&self, source: std::io::Error) -> FormatError {
        FormatError::Io {
            path: self.path.clone(),
            source,
        }
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Read a whole file, naming it on failure.
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|source| FormatError::Io {
        path: path.to_path_buf(),
        source,
    })
}
