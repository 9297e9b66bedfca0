//! `misc_external_map` prefabs: placed, turned and scaled, nested, and refused with a clear error
//! when missing or recursive.

mod common;

use bsp_compiler::{CompileError, CompileOptions, CompileOutput, MapSource, compile};
use common::*;
use std::path::{Path, PathBuf};

/// A fresh directory for one test's map files.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("slipgate-prefab-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("prefabs")).expect("temp dir");
    dir
}

fn write(path: &Path, text: &str) {
    std::fs::write(path, text).expect("write map");
}

fn compile_file(path: &Path) -> Result<CompileOutput, CompileError> {
    compile(&MapSource::read(path)?, &CompileOptions::default())
}

fn prefab_entity(keys: &[(&str, &str)]) -> String {
    let mut s = String::from("{\n\"classname\" \"misc_external_map\"\n");
    for (k, v) in keys {
        s += &format!("\"{k}\" \"{v}\"\n");
    }
    s + "}\n"
}

/// A prefab: one 16x16x32 post standing at the origin, and (optionally) a nested prefab.
fn post_prefab(nested: &str) -> String {
    format!(
        "{{\n\"classname\" \"worldspawn\"\n{}}}\n{{\n\"classname\" \"info_null\"\n\"origin\" \"0 0 0\"\n}}\n{nested}",
        box_brush([0.0, -8.0, 0.0], [16.0, 8.0, 32.0], "post")
    )
}

#[test]
fn a_nested_prefab_is_placed_turned_and_merged() {
    let dir = temp_dir("nested");
    // The cap sits on top of the post, 32 up in the post prefab's own space.
    write(
        &dir.join("prefabs/cap.map"),
        &format!(
            "{{\n\"classname\" \"worldspawn\"\n{}}}\n",
            box_brush([0.0, -8.0, 0.0], [16.0, 8.0, 8.0], "cap")
        ),
    );
    let nested = prefab_entity(&[
        ("_external_map", "cap.map"),
        ("_external_map_classname", "func_group"),
        ("origin", "0 0 32"),
    ]);
    write(&dir.join("prefabs/post.map"), &post_prefab(&nested));
    let placed = prefab_entity(&[
        ("_external_map", "prefabs/post.map"),
        ("_external_map_classname", "func_wall"),
        ("_external_map_angle", "90"),
        ("_external_map_scale", "2"),
        ("targetname", "gate"),
        ("origin", "-64 -64 -128"),
    ]);
    let main = dir.join("main.map");
    write(&main, &room_map_with(false, "", &placed));
    let out = compile_file(&main).expect("compile");
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert_eq!(bsp.models.len(), 2, "the prefab is one func_wall");
    // Scaled by 2 and turned to face +Y: x -16..16, y 0..32, z 0..80, moved by the origin (the
    // model's box is written a unit inside).
    assert_eq!(bsp.models[1].mins, [-79.0, -63.0, -127.0]);
    assert_eq!(bsp.models[1].maxs, [-49.0, -33.0, -49.0]);
    let text = bsp.entity_text();
    assert!(!text.contains("misc_external_map") && !text.contains("_external_map"));
    assert!(text.contains("\"targetname\" \"gate\""), "{text}");
    assert!(
        !text.contains("info_null"),
        "point entities of a prefab are left out"
    );
}

#[test]
fn detail_prefabs_merge_into_the_world() {
    let dir = temp_dir("detail");
    write(&dir.join("prefabs/post.map"), &post_prefab(""));
    let placed = prefab_entity(&[
        ("_external_map", "prefabs/post.map"),
        ("_external_map_classname", "func_detail"),
        ("origin", "0 0 -128"),
    ]);
    let main = dir.join("main.map");
    write(&main, &room_map_with(false, "", &placed));
    let out = compile_file(&main).expect("compile");
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    assert_eq!(out.bsp.models.len(), 1);
    let text = out.bsp.entity_text();
    assert!(!text.contains("func_detail"), "{text}");
}

#[test]
fn a_missing_prefab_names_the_file_line_and_entity() {
    let dir = temp_dir("missing");
    let placed = prefab_entity(&[
        ("_external_map", "prefabs/nowhere.map"),
        ("_external_map_classname", "func_detail"),
    ]);
    let main = dir.join("main.map");
    let text = room_map_with(false, "", &placed);
    write(&main, &text);
    let err = compile_file(&main).expect_err("missing prefab").to_string();
    // The entity's opening brace is on the line before its classname.
    let line = text
        .lines()
        .position(|l| l.contains("misc_external_map"))
        .expect("prefab line");
    assert!(
        err.starts_with(&format!("{}:{}: entity 1", main.display(), line)),
        "{err}"
    );
    assert!(err.contains("nowhere.map"), "{err}");
}

#[test]
fn a_recursive_prefab_is_an_error() {
    let dir = temp_dir("recursive");
    let back = prefab_entity(&[
        ("_external_map", "../main.map"),
        ("_external_map_classname", "func_group"),
    ]);
    write(&dir.join("prefabs/loop.map"), &post_prefab(&back));
    let placed = prefab_entity(&[
        ("_external_map", "prefabs/loop.map"),
        ("_external_map_classname", "func_detail"),
    ]);
    let main = dir.join("main.map");
    write(&main, &room_map_with(false, "", &placed));
    let err = compile_file(&main)
        .expect_err("recursive prefab")
        .to_string();
    assert!(err.contains("recursive prefab"), "{err}");
    assert!(err.contains("loop.map"), "{err}");
}

#[test]
fn a_prefab_without_a_classname_is_an_error() {
    let dir = temp_dir("classless");
    write(&dir.join("prefabs/post.map"), &post_prefab(""));
    let placed = prefab_entity(&[("_external_map", "prefabs/post.map")]);
    let main = dir.join("main.map");
    write(&main, &room_map_with(false, "", &placed));
    let err = compile_file(&main).expect_err("no classname").to_string();
    assert!(err.contains("_external_map_classname"), "{err}");
}
