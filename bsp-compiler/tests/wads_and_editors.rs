//! A mapper's project as TrenchBroom and ericw-tools leave it: WADs named with folders, in
//! folders beside the map, relative to the working directory or given by `-wadpath` and
//! `-xwadpath`; editor keys and layers omitted from export.

mod common;

use bsp_compiler::{CompileOptions, MapSource, Warning, compile};
use common::*;
use quake_formats::Bsp;
use quake_formats::entities::parse_entities;
use std::path::{Path, PathBuf};

fn project(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("slipgate-wads-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("project dir");
    dir
}

/// The project's texture WAD, copied to `to`.
fn put_wad(to: &Path) {
    std::fs::create_dir_all(to.parent().expect("folder")).expect("folder");
    let wad = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps/slipgate.wad");
    std::fs::copy(wad, to).expect("copy the WAD");
}

/// A sealed room textured brick1, its worldspawn with `keys`, written as `dir/room.map`.
fn room_with(dir: &Path, keys: &str) -> MapSource {
    let text = room_map(false, "")
        .replace("\"wad\" \"none.wad\"\n", keys)
        .replace("wall 0 0 0 1 1", "brick1 0 0 0 1 1");
    let path = dir.join("room.map");
    std::fs::write(&path, &text).expect("write the map");
    MapSource::read(&path).expect("read the map")
}

fn compiled(source: &MapSource, options: &CompileOptions) -> (Bsp, Vec<Warning>) {
    let out = compile(source, options).expect("compile");
    (out.bsp, out.warnings)
}

/// brick1's pixels as the BSP holds them (`None`: name and size only); panics when absent.
fn brick_pixels(bsp: &Bsp) -> Option<usize> {
    let brick = bsp
        .textures
        .textures
        .iter()
        .flatten()
        .find(|t| t.name() == "brick1")
        .expect("brick1 in the texture lump");
    brick.mips.as_ref().map(|m| m[0].len())
}

fn missing_wads(warnings: &[Warning]) -> Vec<String> {
    warnings
        .iter()
        .filter(|w| matches!(w, Warning::MissingWad { .. }))
        .map(|w| w.to_string())
        .collect()
}

#[test]
fn a_wad_named_with_its_folder_is_found_beside_the_map() {
    let dir = project("folder");
    put_wad(&dir.join("deprecated/slipgate.wad"));
    let source = room_with(&dir, "\"wad\" \"deprecated/slipgate.wad\"\n");
    let (bsp, warnings) = compiled(&source, &CompileOptions::default());
    assert_eq!(missing_wads(&warnings), Vec::<String>::new());
    assert_eq!(brick_pixels(&bsp), Some(64 * 64));
}

#[test]
fn a_windows_path_falls_back_to_the_file_name_in_the_wadpath() {
    let dir = project("windows");
    put_wad(&dir.join("wads/slipgate.wad"));
    let source = room_with(&dir, "\"_wad\" \"C:\\quake\\id1\\slipgate.wad\"\n");
    let options = CompileOptions {
        wad_dirs: vec![dir.join("wads")],
        ..CompileOptions::default()
    };
    let (bsp, warnings) = compiled(&source, &options);
    assert_eq!(missing_wads(&warnings), Vec::<String>::new());
    assert_eq!(brick_pixels(&bsp), Some(64 * 64));
}

#[test]
fn the_maps_own_wad_is_read_when_worldspawn_names_none() {
    let dir = project("beside");
    put_wad(&dir.join("room.wad"));
    let source = room_with(&dir, "");
    let (bsp, warnings) = compiled(&source, &CompileOptions::default());
    assert_eq!(missing_wads(&warnings), Vec::<String>::new());
    assert_eq!(brick_pixels(&bsp), Some(64 * 64));
}

#[test]
fn an_xwadpath_wad_gives_sizes_without_pixels() {
    let dir = project("xwad");
    put_wad(&dir.join("external/slipgate.wad"));
    let source = room_with(&dir, "\"wad\" \"slipgate.wad\"\n");
    let options = CompileOptions {
        xwad_dirs: vec![dir.join("external")],
        ..CompileOptions::default()
    };
    let (bsp, warnings) = compiled(&source, &options);
    assert_eq!(missing_wads(&warnings), Vec::<String>::new());
    assert_eq!(brick_pixels(&bsp), None);
}

#[test]
fn a_missing_wad_says_where_it_was_looked_for() {
    let dir = project("missing");
    let source = room_with(&dir, "\"wad\" \"gfx/nowhere.wad\"\n");
    let options = CompileOptions {
        wad_dirs: vec![dir.join("wads")],
        ..CompileOptions::default()
    };
    let (_, warnings) = compiled(&source, &options);
    let missing = missing_wads(&warnings);
    assert_eq!(missing.len(), 1, "{missing:?}");
    let text = &missing[0];
    for looked in [
        dir.join("wads/gfx/nowhere.wad"),
        dir.join("gfx/nowhere.wad"),
        dir.join("wads/nowhere.wad"),
    ] {
        assert!(text.contains(&looked.display().to_string()), "{text}");
    }
    assert!(
        text.contains("gfx/nowhere.wad in the working directory"),
        "{text}"
    );
}

/// TrenchBroom's keys stay out of the entity lump (unless kept). A layer marked Omit From Export
/// is compiled, as ericw-tools compiles it, or with `--omit-layers` left out with its entities
/// as TrenchBroom's Export leaves it; a note says which.
#[test]
fn editor_keys_stay_out_of_the_bsp_and_omitted_layers_compile_as_in_ericw_tools() {
    let layer =
        "{\n\"classname\" \"func_group\"\n\"_tb_type\" \"_tb_layer\"\n\"_tb_name\" \"Notes\"\n\
                 \"_tb_id\" \"4\"\n\"_tb_layer_omit_from_export\" \"1\"\n}\n\
                 {\n\"classname\" \"light\"\n\"origin\" \"0 0 0\"\n\"_tb_layer\" \"4\"\n}\n\
                 {\n\"classname\" \"func_wall\"\n\"_tb_layer\" \"4\"\n"
            .to_string()
            + &box_brush([-8.0; 3], [8.0; 3], "brick1")
            + "}\n";
    let text = room_map_with(false, "", &layer).replace(
        "\"wad\" \"none.wad\"\n",
        "\"wad\" \"none.wad\"\n\"_tb_textures\" \"textures/base\"\n\"_tb_mod\" \"lq\"\n",
    );
    let note = |warnings: &[Warning]| {
        warnings
            .iter()
            .find(|w| matches!(w, Warning::OmittedLayer(_)))
            .map(|w| w.to_string())
    };
    let compiled = try_compile(&text).expect("compile");
    let entities = parse_entities(&compiled.bsp.entity_text()).expect("entities");
    let classes: Vec<&str> = entities.iter().map(|e| e.classname()).collect();
    assert_eq!(
        classes,
        ["worldspawn", "light", "func_wall", "info_player_start"]
    );
    assert_eq!(
        compiled.bsp.models.len(),
        2,
        "the layer's func_wall is a model"
    );
    assert_eq!(
        note(&compiled.warnings).as_deref(),
        Some(
            "note: layer \"Notes\" (entity 1) is marked Omit From Export: compiled, with the 2 \
             entities in it, as ericw-tools compiles it (TrenchBroom's Export, or --omit-layers, \
             leaves it out)"
        )
    );
    let omit = CompileOptions {
        omit_layers: true,
        ..CompileOptions::default()
    };
    let out = try_compile_with(&text, &omit).expect("compile");
    let entities = parse_entities(&out.bsp.entity_text()).expect("entities");
    let classes: Vec<&str> = entities.iter().map(|e| e.classname()).collect();
    assert_eq!(classes, ["worldspawn", "info_player_start"]);
    assert!(
        entities
            .iter()
            .all(|e| e.pairs.iter().all(|(k, _)| !k.starts_with("_tb_")))
    );
    assert_eq!(
        out.bsp.models.len(),
        1,
        "the omitted func_wall has no model"
    );
    assert_eq!(
        note(&out.warnings).as_deref(),
        Some(
            "note: layer \"Notes\" (entity 1) is marked Omit From Export: left out with the 2 \
             entities in it (--omit-layers)"
        )
    );
    let kept = try_compile_with(
        &text,
        &CompileOptions {
            keep_editor_keys: true,
            ..CompileOptions::default()
        },
    )
    .expect("compile");
    let world = &parse_entities(&kept.bsp.entity_text()).expect("entities")[0];
    assert_eq!(world.get("_tb_textures"), Some("textures/base"));
}

/// A map whose hole is closed only by a brush in a layer marked Omit From Export seals, as it
/// does with ericw-tools' qbsp (which compiles such layers); left out as TrenchBroom's Export
/// leaves it, the map leaks.
#[test]
fn a_layer_marked_omit_from_export_still_seals_the_map() {
    let patch =
        "{\n\"classname\" \"func_group\"\n\"_tb_type\" \"_tb_layer\"\n\"_tb_name\" \"seal\"\n\
                 \"_tb_id\" \"5\"\n\"_tb_layer_omit_from_export\" \"1\"\n"
            .to_string()
            + &box_brush([128.0, 0.0, -128.0], [144.0, 32.0, 128.0], "brick1")
            + "}\n";
    let text = room_map_with(true, "", "").replace("wall 0 0 0 1 1", "brick1 0 0 0 1 1");
    let leaky = try_compile(&text).expect("compile");
    assert!(leaky.stats.leaked, "the room has a hole");
    let text = room_map_with(true, "", &patch).replace("wall 0 0 0 1 1", "brick1 0 0 0 1 1");
    let sealed = try_compile(&text).expect("compile");
    assert!(!sealed.stats.leaked, "the layer's brush closes the hole");
    let omit = CompileOptions {
        omit_layers: true,
        ..CompileOptions::default()
    };
    let left_out = try_compile_with(&text, &omit).expect("compile");
    assert!(left_out.stats.leaked, "--omit-layers leaves the seal out");
}
