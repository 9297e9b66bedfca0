//! The decompiled demo map compiled by ericw-tools' qbsp (the compiler mappers use), when it is
//! present in `../shared/anchors`: sealed, the same contents, and every face's texture back.
//! ericw-tools cuts brush sides against each other before making faces, so where Slipgate's
//! compiler lets one of two flush brushes texture a leaf's face, it keeps both textures.
//! Skipped, saying so, when absent.

mod common;

use common::{compile_file, contents_agreement, maps_dir, texture_agreement};
use decompile::{MapFormat, Options, decompile};
use quake_formats::Bsp;
use std::path::Path;
use std::process::Command;

#[test]
fn ericw_qbsp_compiles_the_decompiled_demo_map_with_every_texture() {
    let qbsp =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/anchors/ericw-tools/bin/qbsp");
    if !qbsp.exists() {
        println!("SKIPPED: no ericw-tools qbsp at {}", qbsp.display());
        return;
    }
    let original = compile_file(&maps_dir().join("demo.map")).bsp;
    let dir = std::env::temp_dir().join(format!("slipgate-decompile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::copy(maps_dir().join("slipgate.wad"), dir.join("slipgate.wad")).expect("wad");
    for format in [MapFormat::Quake, MapFormat::Valve] {
        let options = Options {
            format,
            ..Options::default()
        };
        let text = decompile(&original, &options).expect("decompile").text;
        let map = dir.join("demo-decompiled.map");
        let bsp_path = dir.join("demo-decompiled.bsp");
        std::fs::write(&map, text).expect("write map");
        let out = Command::new(&qbsp)
            .arg(&map)
            .arg(&bsp_path)
            .current_dir(&dir)
            .output()
            .expect("run qbsp");
        let log = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "qbsp failed:\n{log}");
        assert!(
            !log.to_lowercase().contains("leak"),
            "qbsp found a leak:\n{log}"
        );
        let again = Bsp::read(&std::fs::read(&bsp_path).expect("bsp")).expect("parse");
        let contents = contents_agreement(&original, &again, 0, 20_000, 0.05);
        let textures = texture_agreement(&original, &again, 0, 0.25);
        println!(
            "demo.map ({format:?}) through ericw-tools' qbsp:\n  contents {contents:?}\n  textures {textures:?}"
        );
        assert_eq!(contents.far, 0, "contents differ away from leaf boundaries");
        assert_eq!(textures.unmatched, 0, "faces lost");
        assert_eq!(
            textures.same_projection,
            textures.compared(),
            "textures differ"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
