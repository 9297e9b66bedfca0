//! The `.content.json` file: each BSP leaf's extended content flags, as ericw-tools' qbsp
//! writes them beside the BSP (its light and tests read them).

mod common;

use bsp_compiler::content_flags::ContentFlags;
use common::*;
use quake_formats::bsp::contents;

/// ericw-tools' `detailFence`: the leaf inside a `func_detail_fence` is solid in the BSP, and
/// its extended flags say it is a fence: WINDOW, detail, translucent, mirror-inside decided.
#[test]
fn detail_fence_leaf_is_a_window() {
    let fence = box_brush([-16.0, -64.0, -128.0], [16.0, 64.0, 0.0], "{fence");
    let out = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_detail_fence", &fence),
    ));
    let bsp = &out.bsp;
    assert!(out.leak.is_none(), "{:?}", out.warnings);
    assert_eq!(out.leaf_contents.len(), bsp.leafs.len());
    let leaf = bsp.leaf_at([0.0, 0.0, -64.0]).expect("a leaf");
    assert_ne!(leaf, 0);
    assert_eq!(bsp.leafs[leaf].contents, contents::SOLID);
    assert_eq!(
        out.leaf_contents[leaf].names(),
        ["WINDOW", "MIRROR_INSIDE_SET", "TRANSLUCENT", "DETAIL"]
    );
    // The room's air beside it is empty, and leaf 0 solid.
    let air = bsp.leaf_at([-64.0, 0.0, -64.0]).expect("a leaf");
    assert_eq!(out.leaf_contents[air], ContentFlags::EMPTY);
    assert_eq!(out.leaf_contents[0].names(), ["SOLID"]);
}

/// `_mirrorinside 1` on a fence turns its inside faces on, and the flags say so.
#[test]
fn mirrorinside_fence_leaf_says_mirror_inside() {
    let fence = box_brush([-16.0, -64.0, -128.0], [16.0, 64.0, 0.0], "{fence");
    let entity =
        format!("{{\n\"classname\" \"func_detail_fence\"\n\"_mirrorinside\" \"1\"\n{fence}}}\n");
    let out = compile_text(&room_map_with(false, "", &entity));
    let leaf = out.bsp.leaf_at([0.0, 0.0, -64.0]).expect("a leaf");
    assert_eq!(
        out.leaf_contents[leaf].names(),
        [
            "WINDOW",
            "MIRROR_INSIDE",
            "MIRROR_INSIDE_SET",
            "TRANSLUCENT",
            "DETAIL"
        ]
    );
}

/// Liquids are detail and translucent; an illusionary brush is mist, in the air or in water.
#[test]
fn liquid_and_illusionary_leaves() {
    let water = box_brush([-128.0, -128.0, -128.0], [128.0, 128.0, -64.0], "*water");
    let mist = box_brush([-32.0, -32.0, -96.0], [32.0, 32.0, 32.0], "wall");
    let out = compile_text(&room_map_with(
        false,
        &water,
        &brush_entity("func_detail_illusionary", &mist),
    ));
    let bsp = &out.bsp;
    assert_eq!(out.leaf_contents.len(), bsp.leafs.len());
    let names_at = |p: [f32; 3]| out.leaf_contents[bsp.leaf_at(p).expect("a leaf")].names();
    assert_eq!(
        names_at([96.0, 96.0, -100.0]),
        ["WATER", "TRANSLUCENT", "DETAIL"]
    );
    assert_eq!(
        names_at([0.0, 0.0, 0.0]),
        ["MIST", "MIRROR_INSIDE_SET", "TRANSLUCENT", "DETAIL"]
    );
    assert_eq!(
        names_at([0.0, 0.0, -80.0]),
        [
            "WATER",
            "MIST",
            "MIRROR_INSIDE_SET",
            "TRANSLUCENT",
            "DETAIL"
        ]
    );
    // Every leaf's flags agree with the contents engines read.
    for (leaf, flags) in bsp.leafs.iter().zip(&out.leaf_contents) {
        let expected = match leaf.contents {
            contents::WATER => ContentFlags::WATER,
            contents::SOLID => ContentFlags::SOLID,
            _ => ContentFlags::EMPTY,
        };
        assert!(
            flags.contains(expected),
            "{flags:?} in a leaf of {}",
            leaf.contents
        );
    }
}

/// The file is written beside the BSP, as `MAPNAME.content.json`, one entry per leaf;
/// `-noextendedcontentflags` writes none and removes an old one.
#[test]
fn written_beside_the_bsp_unless_switched_off() {
    use clap::Parser;
    let dir = std::env::temp_dir().join(format!("slipgate-content-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let map = dir.join("room.map");
    std::fs::write(&map, room_map(false, "")).expect("write");
    let map_s = map.to_str().expect("utf-8 path");
    let run = |extra: &[&str]| {
        let words = ["bsp"]
            .iter()
            .chain(extra)
            .chain([&map_s])
            .map(|s| s.to_string());
        let words = quake_formats::cli::normalise_single_dash(words);
        let cli = BspCli::try_parse_from(words).expect("parses");
        bsp_compiler::cli::run(&cli.args).expect("compile");
    };
    run(&[]);
    let json_path = dir.join("room.content.json");
    let text = std::fs::read_to_string(&json_path).expect("content.json written");
    let bsp = quake_formats::Bsp::read(&std::fs::read(dir.join("room.bsp")).expect("bsp"))
        .expect("read bsp");
    let leaves: Vec<Vec<String>> = serde_json::from_str(&text).expect("JSON");
    assert_eq!(leaves.len(), bsp.leafs.len());
    assert_eq!(leaves[0], ["SOLID"]);
    assert!(
        text.starts_with("[\n\t[\n\t\t\"SOLID\"\n\t],\n\t[]"),
        "{text}"
    );
    run(&["-noextendedcontentflags"]);
    assert!(!json_path.exists());
    let _ = std::fs::remove_dir_all(&dir);
}
