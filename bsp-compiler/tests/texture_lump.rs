//! The texture lump as ericw-tools' qbsp writes it: `skip` first, then every texture the map
//! names on a brush face in the order it first names them, drawn or not; pixels from WADs,
//! names and sizes alone under `-notex` or from `-xwadpath`, absent entries for what no WAD
//! holds (but placeholders where a face shows it). Restates ericw-tools' `notex`,
//! `wadInternal`, `wadExternal`, `looseTextures`, `looseTexturesIgnored`, `wadMapname`,
//! `texturesSearchRelativeToCurrentDirectory`, `missingTexture` and
//! `missingTextureAndMissingTexturesAsZeroSize` on maps of our own.

mod common;

use bsp_compiler::{CompileOptions, MapSource, Warning, compile};
use common::*;
use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::miptex::MipTex;
use quake_formats::wad::{Wad, WadLump};
use std::path::{Path, PathBuf};

/// The folder holding the project's `slipgate.wad`.
fn wad_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps")
}

fn project(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("slipgate-texlump-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("project dir");
    dir
}

/// A lone cuboid in the void, as ericw-tools' `q1_cube.map`: no entities.
fn cube(texture: &str, worldspawn_keys: &str) -> String {
    format!(
        "{{\n\"classname\" \"worldspawn\"\n{worldspawn_keys}{}}}\n",
        box_brush([32.0, -240.0, 80.0], [80.0, -144.0, 112.0], texture)
    )
}

/// The test room with floor1, metal1 (ceiling) and brick1 (walls), then `extra` brushes.
fn textured_room(extra: &str, entities: &str) -> String {
    room_map_with(false, extra, entities)
        .replace("none.wad", "slipgate.wad")
        .replace("floor 0 0 0", "floor1 0 0 0")
        .replace("ceiling 0 0 0", "metal1 0 0 0")
        .replace("wall 0 0 0", "brick1 0 0 0")
}

fn compiled_at(dir: &Path, text: &str, options: &CompileOptions) -> (Bsp, Vec<Warning>) {
    let path = dir.join("map.map");
    std::fs::write(&path, text).expect("write the map");
    let source = MapSource::read(&path).expect("read the map");
    let out = compile(&source, options).expect("compile");
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    (out.bsp, out.warnings)
}

fn with_wads() -> CompileOptions {
    CompileOptions {
        wad_dirs: vec![wad_dir()],
        ..CompileOptions::default()
    }
}

/// Each slot's name, `None` for an absent miptex (offset -1).
fn names(bsp: &Bsp) -> Vec<Option<String>> {
    bsp.textures
        .textures
        .iter()
        .map(|t| t.as_ref().map(MipTex::name))
        .collect()
}

fn named(list: &[&str]) -> Vec<Option<String>> {
    list.iter().map(|n| Some(n.to_string())).collect()
}

fn slot(bsp: &Bsp, i: usize) -> &MipTex {
    bsp.textures.textures[i].as_ref().expect("a miptex")
}

/// The encoded size of each slot's miptex, `None` for an absent one.
fn encoded_sizes(bsp: &Bsp) -> Vec<Option<usize>> {
    let lump = bsp.textures.encode();
    let read = |at: usize| i32::from_le_bytes(lump[at..at + 4].try_into().expect("4 bytes"));
    let count = read(0) as usize;
    let offsets: Vec<i32> = (0..count).map(|i| read(4 + 4 * i)).collect();
    offsets
        .iter()
        .map(|&o| {
            (o >= 0).then(|| {
                let next = offsets.iter().filter(|&&n| n > o).min().copied();
                next.map_or(lump.len(), |n| n as usize) - o as usize
            })
        })
        .collect()
}

/// ericw-tools' `notex`: `skip` (which qbsp lists before reading the map) and the cube's
/// texture, each a 40-byte header with its WAD size and zero offsets.
#[test]
fn notex_writes_skip_and_the_texture_as_headers() {
    let dir = project("notex");
    let options = CompileOptions {
        texture_data: false,
        ..with_wads()
    };
    let (bsp, _) = compiled_at(
        &dir,
        &cube("brick1", "\"wad\" \"slipgate.wad\"\n"),
        &options,
    );
    assert_eq!(names(&bsp), named(&["skip", "brick1"]));
    for i in 0..2 {
        let t = slot(&bsp, i);
        assert_eq!((t.width, t.height), (64, 64));
        assert!(t.mips.is_none());
    }
    assert_eq!(encoded_sizes(&bsp), [Some(40), Some(40)]);
    let lump = bsp.textures.encode();
    // Both headers' four mip offsets are 0.
    for header in [12, 52] {
        assert!(lump[header + 24..header + 40].iter().all(|&b| b == 0));
    }
}

/// ericw-tools' `wadInternal`: skip, then the map's textures in the order it names them, a
/// liquid among them, all with their pixels.
#[test]
fn wad_textures_follow_skip_in_map_order_with_pixels() {
    let dir = project("internal");
    let water = box_brush([-128.0, -128.0, -128.0], [128.0, 128.0, -64.0], "*water1");
    let (bsp, _) = compiled_at(&dir, &textured_room(&water, ""), &with_wads());
    assert_eq!(
        names(&bsp),
        named(&["skip", "floor1", "metal1", "brick1", "*water1"])
    );
    for i in 0..5 {
        assert!(slot(&bsp, i).mips.is_some(), "slot {i}");
    }
}

/// The folder editors write before a texture's name (`base/floor1`) is dropped up to the last
/// `/`, as ericw-tools' qbsp drops it: the bare name is looked up in the WAD and written to the
/// lump. It also decides contents, where ericw-tools keeps the folder: `liquids/*water1` is water.
#[test]
fn texture_folders_are_dropped_from_names() {
    let dir = project("folders");
    let water = box_brush(
        [-128.0, -128.0, -128.0],
        [128.0, 128.0, -64.0],
        "liquids/*water1",
    );
    let text = textured_room(&water, "")
        .replace("floor1 0 0 0", "base/floor1 0 0 0")
        .replace("metal1 0 0 0", "a/b/metal1 0 0 0");
    let (bsp, warnings) = compiled_at(&dir, &text, &with_wads());
    assert_eq!(
        names(&bsp),
        named(&["skip", "floor1", "metal1", "brick1", "*water1"])
    );
    for i in 0..5 {
        assert!(slot(&bsp, i).mips.is_some(), "slot {i}");
    }
    assert!(
        warnings.iter().all(|w| !w.to_string().contains('/')),
        "{warnings:?}"
    );
    let leaf = bsp.leaf_at([0.0, 0.0, -100.0]).expect("a leaf");
    assert_eq!(bsp.leafs[leaf].contents, contents::WATER);
}

/// ericw-tools' `wadExternal`: the same textures from an `-xwadpath` WAD, names and sizes
/// only.
#[test]
fn xwadpath_textures_are_listed_without_pixels() {
    let dir = project("external");
    let water = box_brush([-128.0, -128.0, -128.0], [128.0, 128.0, -64.0], "*water1");
    let options = CompileOptions {
        xwad_dirs: vec![wad_dir()],
        ..CompileOptions::default()
    };
    let (bsp, _) = compiled_at(&dir, &textured_room(&water, ""), &options);
    assert_eq!(
        names(&bsp),
        named(&["skip", "floor1", "metal1", "brick1", "*water1"])
    );
    assert!(encoded_sizes(&bsp).iter().all(|&s| s == Some(40)));
}

/// Writes `textures/NAME.png` of `size` in `dir` for each name.
fn loose_pictures(dir: &Path, names: &[&str], size: u32) {
    std::fs::create_dir_all(dir.join("textures")).expect("textures folder");
    for name in names {
        image::RgbImage::new(size, size)
            .save(dir.join("textures").join(format!("{name}.png")))
            .expect("write a picture");
    }
}

/// ericw-tools' `looseTextures`: under `-notex`, loose pictures in a `-path` folder give the
/// textures no WAD holds their sizes; skip, found nowhere, is an absent entry.
#[test]
fn loose_pictures_size_textures_under_notex() {
    let dir = project("loose");
    loose_pictures(&dir.join("pictures"), &["floor_purple_c", "wall_tan_a"], 64);
    let text = room_map(false, "")
        .replace("floor 0 0 0", "floor_purple_c 0 0 0")
        .replace("ceiling 0 0 0", "wall_tan_a 0 0 0")
        .replace("wall 0 0 0", "wall_tan_a 0 0 0");
    let options = CompileOptions {
        texture_data: false,
        texture_paths: vec![dir.join("pictures")],
        ..CompileOptions::default()
    };
    let (bsp, _) = compiled_at(&dir, &text, &options);
    let mut expected = named(&["", "floor_purple_c", "wall_tan_a"]);
    expected[0] = None;
    assert_eq!(names(&bsp), expected);
    for i in 1..3 {
        let t = slot(&bsp, i);
        assert_eq!((t.width, t.height, t.mips.is_none()), (64, 64, true));
    }
    assert_eq!(encoded_sizes(&bsp), [None, Some(40), Some(40)]);
}

/// ericw-tools' `looseTexturesIgnored`: without `-notex`, textures come from WADs only; a
/// 16x16 picture of brick1 beside them changes nothing.
#[test]
fn loose_pictures_are_ignored_without_notex() {
    let dir = project("loose-ignored");
    loose_pictures(&dir.join("pictures"), &["brick1"], 16);
    let water = box_brush([-128.0, -128.0, -128.0], [128.0, 128.0, -64.0], "*water1");
    let options = CompileOptions {
        texture_paths: vec![dir.join("pictures")],
        ..with_wads()
    };
    let (bsp, _) = compiled_at(&dir, &textured_room(&water, ""), &options);
    assert_eq!(
        names(&bsp),
        named(&["skip", "floor1", "metal1", "brick1", "*water1"])
    );
    for i in 0..5 {
        let t = slot(&bsp, i);
        assert_eq!((t.width, t.height), (64, 64), "slot {i}");
        assert!(t.mips.is_some(), "slot {i}");
    }
}

/// ericw-tools' `wadMapname` (and the texture lump of `texturesSearchRelativeToCurrentDirectory`,
/// whose WAD lookup `wad_lookup`'s tests cover): `MAP.wad` beside the map is read when
/// worldspawn names none; skip, which it lacks, is an absent entry; the cube's texture has its
/// pixels.
#[test]
fn the_maps_own_wad_gives_its_textures_and_skip_is_absent_without_it() {
    let dir = project("mapname");
    let all =
        Wad::read(&std::fs::read(wad_dir().join("slipgate.wad")).expect("the WAD")).expect("a WAD");
    let brick = all.find_miptex("brick1").expect("brick1");
    std::fs::write(
        dir.join("map.wad"),
        Wad::new(vec![WadLump::miptex(brick)]).write(),
    )
    .expect("write the WAD");
    let (bsp, _) = compiled_at(&dir, &cube("brick1", ""), &CompileOptions::default());
    assert_eq!(names(&bsp), vec![None, Some("brick1".to_string())]);
    assert_eq!(encoded_sizes(&bsp)[0], None);
    assert!(encoded_sizes(&bsp)[1].is_some_and(|s| s > 40));
}

/// ericw-tools' `missingTexture`: skip from the WAD, then the missing texture. ericw-tools
/// writes that one absent; Slipgate, since faces show it, a named placeholder with a warning
/// (docs/mapping.md says why).
#[test]
fn a_missing_texture_faces_show_is_a_placeholder_after_skip() {
    let dir = project("missing");
    let (bsp, warnings) = compiled_at(
        &dir,
        &cube("somemissingtexture", "\"wad\" \"slipgate.wad\"\n"),
        &with_wads(),
    );
    assert_eq!(names(&bsp), named(&["skip", "somemissingtext"]));
    let skip = slot(&bsp, 0);
    assert_eq!(
        (skip.width, skip.height, skip.mips.is_some()),
        (64, 64, true)
    );
    let missing = slot(&bsp, 1);
    assert_eq!((missing.width, missing.height), (64, 64));
    assert_eq!(bsp.faces.len(), 6);
    assert!(warnings.contains(&Warning::MissingTexture {
        name: "somemissingtexture".to_string()
    }));
}

/// ericw-tools' `missingTextureAndMissingTexturesAsZeroSize`: the missing texture is a 0x0
/// header with its name, cut to 15 characters.
#[test]
fn missing_textures_as_zero_size_names_the_missing_one_at_0x0() {
    let dir = project("zero-size");
    let options = CompileOptions {
        missing_textures_as_zero_size: true,
        ..with_wads()
    };
    let (bsp, _) = compiled_at(
        &dir,
        &cube("somemissingtexture", "\"wad\" \"slipgate.wad\"\n"),
        &options,
    );
    assert_eq!(names(&bsp), named(&["skip", "somemissingtext"]));
    assert_eq!((slot(&bsp, 0).width, slot(&bsp, 0).height), (64, 64));
    let missing = slot(&bsp, 1);
    assert_eq!((missing.width, missing.height), (0, 0));
    assert_eq!(encoded_sizes(&bsp)[1], Some(40));
    assert_eq!(bsp.faces.len(), 6);
}

/// Textures of faces the BSP does not draw (a liquid's `*waterskip` side, clip, a trigger) are
/// listed where the map first names them, as in ericw-tools (its `q1_liquid_mirrorinside_off`
/// lists skip, `*waterskip`, then the water); texinfos name the slots of the drawn ones.
#[test]
fn textures_of_undrawn_faces_are_listed_in_map_order() {
    let dir = project("undrawn");
    let water = box_brush([-128.0, -128.0, -128.0], [128.0, 128.0, -64.0], "*water1").replacen(
        "*water1",
        "*waterskip",
        1,
    );
    let clip = box_brush([-16.0, -16.0, -64.0], [16.0, 16.0, -32.0], "clip");
    let trigger = brush_entity(
        "trigger_once",
        &box_brush([64.0, 64.0, -64.0], [96.0, 96.0, -32.0], "trigger"),
    );
    let (bsp, _) = compiled_at(
        &dir,
        &textured_room(&(water + &clip), &trigger),
        &with_wads(),
    );
    let mut expected = named(&[
        "skip", "floor1", "metal1", "brick1", "", "*water1", "clip", "trigger",
    ]);
    // No WAD holds *waterskip: absent, as ericw-tools writes a texture it cannot find.
    expected[4] = None;
    assert_eq!(names(&bsp), expected);
    let mut drawn: Vec<String> = (0..bsp.faces.len())
        .map(|f| face_texture(&bsp, f))
        .collect();
    drawn.sort();
    drawn.dedup();
    assert_eq!(drawn, ["*water1", "brick1", "floor1", "metal1"]);
}
