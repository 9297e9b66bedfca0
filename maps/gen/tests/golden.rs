//! The files committed under `maps/` are exactly what the generator writes.

use std::path::Path;

#[test]
fn committed_files_match_the_generator() {
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = std::env::temp_dir().join(format!("slipgate-mapgen-golden-{}", std::process::id()));
    let files = mapgen::write_all(&out).expect("generate into a temp dir");
    let mut stale = Vec::new();
    for file in &files {
        let fresh = std::fs::read(out.join(&file.path)).expect("read back");
        assert_eq!(fresh, file.bytes, "{}: written bytes differ", file.path);
        if std::fs::read(committed.join(&file.path)).ok().as_ref() != Some(&fresh) {
            stale.push(file.path.clone());
        }
    }
    let _ = std::fs::remove_dir_all(&out);
    assert!(
        stale.is_empty(),
        "maps/ is out of date ({}): run `cargo run -p slipgate-mapgen` to regenerate",
        stale.join(", ")
    );
}

#[test]
fn generation_is_deterministic() {
    let a = mapgen::generate();
    let b = mapgen::generate();
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!(x.path == y.path && x.bytes == y.bytes, "{}", x.path);
    }
}
