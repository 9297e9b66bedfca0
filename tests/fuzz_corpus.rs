//! Replays the committed fuzz corpora (`fuzz/corpus/TARGET/`: minimized corpora and every input
//! that once crashed a target) through the fuzz targets' own entry points, so CI holds what
//! fuzzing found without nightly or cargo-fuzz.

#[path = "../fuzz/src/lib.rs"]
mod entries;

use std::path::Path;
use std::time::Instant;

/// One target's corpus, each file through `entry`; names the file that fails.
fn replay(target: &str, entry: fn(&[u8])) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("dir entry").path())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "{}: no corpus committed", dir.display());
    let start = Instant::now();
    for file in &files {
        let data = std::fs::read(file).expect("read corpus file");
        let result = std::panic::catch_unwind(|| entry(&data));
        assert!(result.is_ok(), "{target}: {} fails", file.display());
    }
    eprintln!(
        "{target}: {} inputs in {:.2} s",
        files.len(),
        start.elapsed().as_secs_f64()
    );
}

#[test]
fn map_parse_corpus() {
    replay("map_parse", entries::map_parse);
}

#[test]
fn map_compile_corpus() {
    replay("map_compile", entries::map_compile);
}

#[test]
fn bsp_read_corpus() {
    replay("bsp_read", entries::bsp_read);
}

#[test]
fn wad_corpus() {
    replay("wad", entries::wad);
}

#[test]
fn prt_corpus() {
    replay("prt", entries::prt);
}

#[test]
fn lit_corpus() {
    replay("lit", entries::lit);
}

#[test]
fn entities_corpus() {
    replay("entities", entries::entities);
}

#[test]
fn stages_corpus() {
    replay("stages", entries::stages);
}

#[test]
fn pictures_corpus() {
    replay("pictures", entries::pictures);
}
