//! Finding files in a project's folders.

use std::path::{Path, PathBuf};

/// Every file under `dir` (recursively) that `keep` accepts, in no set order, skipping hidden
/// files and folders (the cache among them). An error names the folder it happened in.
pub(crate) fn files_under(
    dir: &Path,
    keep: &dyn Fn(&Path) -> bool,
    found: &mut Vec<PathBuf>,
) -> Result<(), (PathBuf, std::io::Error)> {
    let io = |source| (dir.to_path_buf(), source);
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        let hidden = path
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'));
        if hidden {
            continue;
        }
        if path.is_dir() {
            files_under(&path, keep, found)?;
        } else if keep(&path) {
            found.push(path);
        }
    }
    Ok(())
}
