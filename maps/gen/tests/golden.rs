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
    let a = mapgen::generate().expect("generate");
    let b = mapgen::generate().expect("generate");
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!(x.path == y.path && x.bytes == y.bytes, "{}", x.path);
    }
}

/// `maps/textures` holds exactly the generated pictures, and `slipgate wad build` of that folder
/// gives the committed WAD byte for byte.
#[test]
fn the_committed_wad_is_the_committed_pictures_built() {
    let maps = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let pictures = maps.join(mapgen::textures::PICTURE_DIR);
    let mut committed: Vec<String> = std::fs::read_dir(&pictures)
        .expect("maps/textures")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    committed.sort();
    let mut generated: Vec<String> = mapgen::textures::picture_files()
        .expect("pictures")
        .into_iter()
        .map(|(name, _)| name)
        .collect();
    generated.sort();
    assert_eq!(
        committed, generated,
        "maps/textures has other files than the generator's"
    );
    let out = std::env::temp_dir().join(format!("slipgate-mapgen-wad-{}.wad", std::process::id()));
    wad::build_folder(&pictures, &out, &wad::BuildOptions::default(), &|_| {}).expect("build");
    let built = std::fs::read(&out).expect("read back");
    let _ = std::fs::remove_file(&out);
    assert!(
        std::fs::read(maps.join("slipgate.wad")).ok() == Some(built),
        "maps/slipgate.wad is not `slipgate wad build maps/textures`: run `cargo run -p slipgate-mapgen`"
    );
}
