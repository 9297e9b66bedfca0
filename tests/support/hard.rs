//! Where the repository's maps are, and the hard cases among them (`maps/hard/*.map`).

use std::path::{Path, PathBuf};

pub fn maps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("maps")
}

/// Every `.map` in `maps/hard/`, sorted by name.
pub fn hard_maps() -> Vec<PathBuf> {
    let mut maps: Vec<PathBuf> = std::fs::read_dir(maps_dir().join("hard"))
        .expect("maps/hard")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "map"))
        .collect();
    maps.sort();
    maps
}
