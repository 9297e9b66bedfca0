//! Crack checks ([`bsp_compiler::cracks`]) on compiled maps: the repository's hard cases and demo
//! maps must have none; the corpus maps report their counts.

use bsp_compiler::cracks::find_cracks;
use bsp_compiler::{CompileOptions, MapSource, compile};
use std::path::{Path, PathBuf};

fn compile_file(path: &Path, wad_dirs: Vec<PathBuf>) -> quake_formats::Bsp {
    let source = MapSource::read(path).expect("read");
    let options = CompileOptions {
        wad_dirs,
        ..CompileOptions::default()
    };
    compile(&source, &options).expect("compile").bsp
}

#[test]
fn repository_maps_have_no_cracks() {
    let maps = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps");
    let mut paths = vec![maps.join("demo.map"), maps.join("demo220.map")];
    let mut hard: Vec<PathBuf> = std::fs::read_dir(maps.join("hard"))
        .expect("maps/hard")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "map"))
        // Maps the compiler must refuse (maps/hard/README.md) have nothing to check.
        .filter(|p| {
            let text = std::fs::read_to_string(p).expect("read map");
            !text.contains("\n// expect: refused")
        })
        .collect();
    hard.sort();
    assert!(hard.len() >= 7, "only {} hard maps", hard.len());
    paths.extend(hard);
    let mut failures = Vec::new();
    for path in &paths {
        let report = find_cracks(&compile_file(path, vec![maps.clone()]));
        if !report.is_empty() {
            failures.push(format!("{}: {}", path.display(), report.summary()));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Slow in debug builds: `cargo test -p slipgate-bsp --release --test cracks -- --ignored --nocapture`.
#[test]
#[ignore]
fn corpus_map_crack_counts() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus");
    if !corpus.is_dir() {
        println!("SKIPPED: no corpus at {}", corpus.display());
        return;
    }
    let wads = vec![
        corpus.join("wads/librequake"),
        corpus.join("wads/ericw-tools"),
    ];
    for rel in ["librequake/start.map", "id/e1m1.map"] {
        let bsp = compile_file(&corpus.join("public/maps").join(rel), wads.clone());
        println!("{rel}: {}", find_cracks(&bsp).summary());
    }
}
