//! `--onlyents` on a project map compiled, vis'd and lit: the entities change, every other lump
//! stays byte for byte; a change to the brush entities is refused, saying what changed.

mod common;

use clap::Parser;
use common::{BspCli, LightCli, VisCli};
use quake_formats::Bsp;
use quake_formats::bsp::LUMP_NAMES;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn bsp_stage(args: &[&str]) -> anyhow::Result<()> {
    let cli = BspCli::try_parse_from(std::iter::once("bsp").chain(args.iter().copied()))?;
    bsp_compiler::cli::run(&cli.args).map(drop)
}

/// The raw bytes of each of the 15 BSP29 lumps, from the file's header.
fn lumps(bytes: &[u8]) -> Vec<Vec<u8>> {
    let word = |at: usize| {
        let b: [u8; 4] = bytes[at..at + 4].try_into().expect("header word");
        u32::from_le_bytes(b) as usize
    };
    (0..15)
        .map(|i| {
            let (offset, len) = (word(4 + 8 * i), word(8 + 8 * i));
            bytes[offset..offset + len].to_vec()
        })
        .collect()
}

#[test]
fn onlyents_changes_the_entities_and_nothing_else() {
    let dir = std::env::temp_dir().join(format!("slipgate-onlyents-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let map = dir.join("demo.map");
    let text = std::fs::read_to_string(repo().join("maps/demo.map")).expect("demo.map");
    std::fs::write(&map, &text).expect("write map");
    let wads = repo().join("maps");
    let (map_s, wads_s) = (map.to_str().expect("path"), wads.to_str().expect("path"));
    let bsp_path = map.with_extension("bsp");
    let bsp_s = bsp_path.to_str().expect("path");

    bsp_stage(&[map_s, "--wad-dir", wads_s]).expect("compile");
    let vis = VisCli::try_parse_from(["vis", bsp_s, "--fast"]).expect("vis args");
    vis::cli::run(&vis.args).expect("vis");
    let light = LightCli::try_parse_from(["light", bsp_s]).expect("light args");
    light::cli::run(&light.args).expect("light");
    let before = std::fs::read(&bsp_path).expect("read bsp");
    let lit_before = std::fs::read(map.with_extension("lit")).ok();

    // A light gets a targetname, the player start moves, and a monster is added.
    let edited = text
        .replacen(
            "\"origin\" \"176 176 160\"\n\"light\" \"250\"\n",
            "\"origin\" \"176 176 160\"\n\"light\" \"250\"\n\"targetname\" \"lamp\"\n",
            1,
        )
        .replacen("\"origin\" \"64 256 24\"", "\"origin\" \"96 256 24\"", 1)
        + "{\n\"classname\" \"monster_army\"\n\"origin\" \"640 256 40\"\n}\n";
    assert_ne!(edited, text);
    std::fs::write(&map, &edited).expect("write edited map");
    bsp_stage(&["--onlyents", map_s, "--wad-dir", wads_s]).expect("onlyents");
    let after = std::fs::read(&bsp_path).expect("read bsp");

    let (old, new) = (lumps(&before), lumps(&after));
    for i in 1..15 {
        assert!(old[i] == new[i], "lump {} changed", LUMP_NAMES[i]);
    }
    assert!(
        !old[4].is_empty() && !old[8].is_empty(),
        "vis and light ran"
    );
    let reread = Bsp::read(&after).expect("read");
    assert_eq!(reread.bspx, Bsp::read(&before).expect("read").bspx);
    let entities = reread.entity_text();
    assert!(entities.contains("\"targetname\" \"lamp\""), "{entities}");
    assert!(entities.contains("\"96 256 24\"") && entities.contains("monster_army"));
    assert!(
        entities.contains("\"model\" \"*1\""),
        "the door keeps its model"
    );
    assert_eq!(std::fs::read(map.with_extension("lit")).ok(), lit_before);

    // A new brush entity needs a compile.
    let wall = "{\n\"classname\" \"func_wall\"\n{\n\
        ( 0 0 0 ) ( 0 1 0 ) ( 0 0 1 ) wood1 0 0 0 1 1\n( 8 0 0 ) ( 8 0 1 ) ( 8 1 0 ) wood1 0 0 0 1 1\n\
        ( 0 0 0 ) ( 0 0 1 ) ( 1 0 0 ) wood1 0 0 0 1 1\n( 0 8 0 ) ( 1 8 0 ) ( 0 8 1 ) wood1 0 0 0 1 1\n\
        ( 0 0 0 ) ( 1 0 0 ) ( 0 1 0 ) wood1 0 0 0 1 1\n( 0 0 8 ) ( 0 1 8 ) ( 1 0 8 ) wood1 0 0 0 1 1\n}\n}\n";
    std::fs::write(&map, format!("{edited}{wall}")).expect("write");
    let err = bsp_stage(&["--onlyents", map_s])
        .expect_err("a new brush entity")
        .to_string();
    assert!(err.contains("3 brush entities but the BSP has 2"), "{err}");
    assert!(err.contains("new: func_wall"), "{err}");
    assert_eq!(
        std::fs::read(&bsp_path).expect("read"),
        after,
        "nothing written"
    );
}
