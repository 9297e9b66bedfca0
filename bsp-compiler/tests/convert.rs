//! `--convert`: the project's maps rewritten in the other texture format compile to the same
//! texinfo, within the precision of the numbers written.

use bsp_compiler::{CompileOptions, MapSource, compile};
use quake_formats::Bsp;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Texinfo vectors agree to this (texels per unit, and texels for offsets): well under a
/// texel anywhere in a ±32768 world.
const TOLERANCE: f32 = 1e-5;

fn maps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps")
}

fn compile_file(path: &Path) -> Bsp {
    let options = CompileOptions {
        wad_dirs: vec![maps_dir()],
        ..CompileOptions::default()
    };
    compile(&MapSource::read(path).expect("read"), &options)
        .expect("compile")
        .bsp
}

/// A scratch copy of `name` from maps/.
fn scratch_copy(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("slipgate-convert-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let copy = dir.join(name);
    std::fs::copy(maps_dir().join(name), &copy).expect("copy map");
    copy
}

/// `map` converted to `format` by the command: the file it wrote beside it.
fn converted(map: &Path, format: &str) -> PathBuf {
    let out = Command::new(env!("CARGO_BIN_EXE_slipgate-bsp"))
        .args(["--convert", format])
        .arg(map)
        .output()
        .expect("run slipgate-bsp");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stem = map.file_stem().expect("stem").to_string_lossy();
    let result = map.with_file_name(format!("{stem}-{format}.map"));
    assert!(result.exists());
    assert!(
        !map.with_extension("bsp").exists(),
        "converting does not compile"
    );
    result
}

fn assert_same_texinfo(a: &Bsp, b: &Bsp) {
    assert_eq!(a.faces.len(), b.faces.len());
    assert_eq!(a.texinfo.len(), b.texinfo.len());
    for (x, y) in a.texinfo.iter().zip(&b.texinfo) {
        assert_eq!(x.miptex, y.miptex);
        for i in 0..2 {
            for j in 0..4 {
                assert!(
                    (x.vecs[i][j] - y.vecs[i][j]).abs() <= TOLERANCE,
                    "{:?} vs {:?}",
                    x.vecs,
                    y.vecs
                );
            }
        }
    }
}

#[test]
fn quake_maps_convert_to_valve_and_back() {
    let original = scratch_copy("demo.map");
    let valve = converted(&original, "valve");
    let text = std::fs::read_to_string(&valve).expect("read");
    assert!(text.contains("\"mapversion\" \"220\""));
    let before = compile_file(&original);
    assert_same_texinfo(&before, &compile_file(&valve));
    let quake = converted(&valve, "quake");
    assert_same_texinfo(&before, &compile_file(&quake));
}

#[test]
fn valve_maps_convert_to_quake() {
    let original = scratch_copy("demo220.map");
    let quake = converted(&original, "quake");
    let text = std::fs::read_to_string(&quake).expect("read");
    assert!(!text.contains('[') && !text.contains("mapversion"));
    assert_same_texinfo(&compile_file(&original), &compile_file(&quake));
}
