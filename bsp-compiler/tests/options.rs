//! The compile options mappers' profiles use (ericw-tools' names): each does what it says, and
//! the BSP stays valid.

mod common;

use bsp_compiler::CompileOptions;
use common::*;
use quake_formats::bsp::contents;
use quake_formats::{Bsp, Severity, validate};
use std::path::{Path, PathBuf};
use std::process::Command;

fn compile_options(text: &str, options: CompileOptions) -> Bsp {
    try_compile_with(text, &options).expect("compile").bsp
}

fn faces_with_texture(bsp: &Bsp, name: &str) -> usize {
    bsp.faces
        .iter()
        .filter(|f| {
            let t = bsp.texinfo[f.texinfo as usize].miptex as usize;
            bsp.textures.textures[t]
                .as_ref()
                .is_some_and(|m| m.name() == name)
        })
        .count()
}

#[test]
fn nofill_keeps_the_outside() {
    let text = room_map(false, "");
    let filled = compile_text(&text).bsp;
    let kept = compile_options(
        &text,
        CompileOptions {
            fill: false,
            ..CompileOptions::default()
        },
    );
    assert_eq!(errors(&kept), Vec::<String>::new());
    // The walls' outer faces are drawn too: twice the faces of the sealed room.
    assert!(
        kept.faces.len() >= 2 * filled.faces.len(),
        "{} vs {}",
        kept.faces.len(),
        filled.faces.len()
    );
}

#[test]
fn noclip_leaves_the_clip_hulls_empty() {
    let text = room_map_with(
        false,
        "",
        &brush_entity(
            "func_wall",
            &box_brush([-16.0, -16.0, -128.0], [16.0, 16.0, -96.0], "crate"),
        ),
    );
    let bsp = compile_options(
        &text,
        CompileOptions {
            clip_hulls: false,
            ..CompileOptions::default()
        },
    );
    assert!(bsp.clipnodes.is_empty());
    for m in &bsp.models {
        assert_eq!(&m.head_nodes[1..3], &[contents::EMPTY, contents::EMPTY]);
    }
    let problems: Vec<String> = validate(&bsp)
        .iter()
        .filter(|p| p.severity == Severity::Error)
        .map(|p| p.to_string())
        .collect();
    assert_eq!(problems, Vec::<String>::new());
}

#[test]
fn notex_keeps_names_and_sizes_without_pixels() {
    let wad = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps");
    let text = room_map(false, "")
        .replace("none.wad", "slipgate.wad")
        .replace("wall 0 0 0 1 1", "brick1 0 0 0 1 1");
    let with = |texture_data| {
        compile_options(
            &text,
            CompileOptions {
                texture_data,
                wad_dirs: vec![wad.clone()],
                ..CompileOptions::default()
            },
        )
    };
    let (full, bare) = (with(true), with(false));
    assert_eq!(errors(&bare), Vec::<String>::new());
    let brick = |bsp: &Bsp| {
        bsp.textures
            .textures
            .iter()
            .flatten()
            .find(|t| t.name() == "brick1")
            .cloned()
            .expect("brick1")
    };
    let (a, b) = (brick(&full), brick(&bare));
    assert!(a.mips.is_some() && b.mips.is_none());
    assert_eq!((a.width, a.height), (b.width, b.height));
    let bytes = bare.write().expect("write");
    let back = Bsp::read(&bytes).expect("read back");
    assert!(
        back.textures
            .textures
            .iter()
            .flatten()
            .all(|t| t.mips.is_none())
    );
    assert!(bytes.len() < full.write().expect("write").len());
}

#[test]
fn omitdetail_leaves_out_func_detail_only() {
    let text = room_map_with(
        false,
        "",
        &(brush_entity(
            "func_detail",
            &box_brush([-16.0, -16.0, -128.0], [16.0, 16.0, -96.0], "crate"),
        ) + &brush_entity(
            "func_detail_wall",
            &box_brush([64.0, -16.0, -128.0], [96.0, 16.0, -96.0], "panel"),
        )),
    );
    let bsp = compile_options(
        &text,
        CompileOptions {
            omit: vec!["func_detail".into()],
            ..CompileOptions::default()
        },
    );
    assert_eq!(errors(&bsp), Vec::<String>::new());
    assert_eq!(faces_with_texture(&bsp, "crate"), 0);
    assert!(faces_with_texture(&bsp, "panel") > 0);
}

#[test]
fn subdivide_zero_leaves_faces_whole() {
    // A 1024-unit floor: cut into 240-texel pieces by default, one face without subdivision.
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n{}{}}}\n{{\n\"classname\" \"info_player_start\"\n\"origin\" \"0 0 32\"\n}}\n",
        box_brush([-512.0, -512.0, -16.0], [512.0, 512.0, 0.0], "floor"),
        box_brush([-512.0, -512.0, 128.0], [512.0, 512.0, 144.0], "ceiling"),
    );
    let cut = compile_options(&text, CompileOptions::default());
    let whole = compile_options(
        &text,
        CompileOptions {
            subdivide: 0.0,
            fill: false,
            ..CompileOptions::default()
        },
    );
    assert!(faces_with_texture(&cut, "floor") > 2);
    let wide = |out: &[bsp_compiler::Warning]| {
        out.iter()
            .filter(|w| matches!(w, bsp_compiler::Warning::WideFaces { .. }))
            .map(ToString::to_string)
            .collect::<Vec<_>>()
    };
    assert!(wide(&compile_text(&text).warnings).is_empty());
    let unsubdivided = try_compile_with(
        &text,
        &CompileOptions {
            subdivide: 0.0,
            fill: false,
            ..CompileOptions::default()
        },
    )
    .expect("compiles");
    let said = wide(&unsubdivided.warnings);
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(
        said[0].contains("widest 1024") && said[0].contains("WinQuake"),
        "{}",
        said[0]
    );
    // Top and bottom of the floor, each side, one face each.
    assert!(
        faces_with_texture(&whole, "floor") <= 6,
        "{}",
        faces_with_texture(&whole, "floor")
    );
}

#[test]
fn nosubdivide_refuses_a_face_too_wide_for_quakespasm_naming_the_engines() {
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n{}{}}}\n{{\n\"classname\" \"info_player_start\"\n\"origin\" \"0 0 32\"\n}}\n",
        box_brush([-1536.0, -64.0, -16.0], [1536.0, 64.0, 0.0], "floor"),
        box_brush([-1536.0, -64.0, 128.0], [1536.0, 64.0, 144.0], "ceiling"),
    );
    let options = CompileOptions {
        subdivide: 0.0,
        fill: false,
        ..CompileOptions::default()
    };
    let refused = try_compile_with(&text, &options)
        .expect_err("a 3072-texel face is refused")
        .to_string();
    assert!(
        refused.contains("surface-extents")
            && refused.contains("3072")
            && refused.contains("QuakeSpasm"),
        "{refused}"
    );
}

#[test]
fn maxnodesize_changes_where_big_nodes_are_cut() {
    let pillar = box_brush([-100.0, -16.0, -128.0], [-60.0, 16.0, 0.0], "pillar");
    let text = room_map(false, &pillar);
    let default = compile_text(&text).bsp;
    let small = compile_options(
        &text,
        CompileOptions {
            max_node_size: 64.0,
            ..CompileOptions::default()
        },
    );
    assert_eq!(errors(&small), Vec::<String>::new());
    assert_ne!(small.nodes.len(), default.nodes.len());
}

#[test]
fn wrbrushes_lists_every_model_brush_for_the_qbsp_crate() {
    // A wedge (one sloped side) in the world, a crate in a func_wall, a clip brush, a hint.
    let wedge = "{\n( -64 -64 -128 ) ( -64 -63 -128 ) ( -64 -64 -127 ) wall 0 0 0 1 1\n\
                 ( -32 -64 -128 ) ( -32 -64 -127 ) ( -31 -64 -128 ) wall 0 0 0 1 1\n\
                 ( -64 -64 -128 ) ( -63 -64 -128 ) ( -64 -63 -128 ) wall 0 0 0 1 1\n\
                 ( -64 32 -128 ) ( -63 32 -128 ) ( -64 32 -127 ) wall 0 0 0 1 1\n\
                 ( -64 -64 -64 ) ( -64 -63 -64 ) ( -32 -64 -128 ) wall 0 0 0 1 1\n}\n";
    let extra = format!(
        "{wedge}{}{}",
        box_brush([0.0, 0.0, -128.0], [16.0, 16.0, 0.0], "clip"),
        box_brush([32.0, -128.0, -128.0], [33.0, 128.0, 128.0], "hint"),
    );
    let text = room_map_with(
        false,
        &extra,
        &brush_entity(
            "func_wall",
            &box_brush([64.0, 64.0, -128.0], [96.0, 96.0, -96.0], "crate"),
        ),
    );
    let bsp = compile_options(
        &text,
        CompileOptions {
            brush_list: true,
            ..CompileOptions::default()
        },
    );
    assert_eq!(errors(&bsp), Vec::<String>::new());
    let bytes = bsp.write().expect("write");
    let parsed = qbsp::BspData::parse(qbsp::BspParseInput {
        bsp: &bytes,
        lit: None,
        settings: Default::default(),
    })
    .expect("qbsp parses the BSP");
    let list = parsed.bspx.brush_list.expect("a BRUSHLIST lump");
    assert_eq!(list.len(), 2);
    assert_eq!((list[0].model_idx, list[1].model_idx), (0, 1));
    // Six room brushes, the wedge and the clip brush (solid); the hint is left out.
    let world = &list[0].brushes.inner;
    assert_eq!(world.len(), 8);
    let sloped: Vec<_> = world
        .iter()
        .filter(|b| !b.planes.inner.is_empty())
        .collect();
    assert_eq!(sloped.len(), 1, "only the wedge has a non-axial plane");
    let plane = sloped[0].planes.inner[0];
    // Facing out of the wedge: up and towards +x.
    assert!(plane.normal.x > 0.0 && plane.normal.z > 0.0, "{plane:?}");
    let crate_brush = &list[1].brushes.inner[0];
    assert_eq!(crate_brush.bound.min.to_array(), [64.0, 64.0, -128.0]);
    assert_eq!(crate_brush.bound.max.to_array(), [96.0, 96.0, -96.0]);
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("slipgate-opts-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

#[test]
fn leaktest_writes_nothing_but_the_pointfile_and_fails() {
    let dir = temp_dir("leaktest");
    let map = dir.join("leaky.map");
    std::fs::write(&map, room_map(true, "")).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_slipgate-bsp"))
        .arg("--leaktest")
        .arg(&map)
        .output()
        .expect("run slipgate-bsp");
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("leaks"), "{stderr}");
    assert!(!map.with_extension("bsp").exists());
    assert!(!map.with_extension("prt").exists());
    assert!(map.with_extension("pts").exists());
    // Sealed, it compiles as usual.
    std::fs::write(&map, room_map(false, "")).expect("write");
    let status = Command::new(env!("CARGO_BIN_EXE_slipgate-bsp"))
        .arg("--leaktest")
        .arg(&map)
        .output()
        .expect("run slipgate-bsp")
        .status;
    assert!(status.success());
    assert!(map.with_extension("bsp").exists());
}
