//! Finding the shared test corpus beside the repository.

use std::path::{Path, PathBuf};

/// `../shared/corpus/<rel>`, or `None` after saying the test is skipped.
pub fn corpus(rel: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/corpus")
        .join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!(
            "SKIPPED: {} not found (needs ../shared/corpus)",
            p.display()
        );
        None
    }
}
