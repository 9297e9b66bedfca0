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

/// `text` compiled with `--wrbrushes`, its `BRUSHLIST` lump as the `qbsp` crate reads it.
fn brush_list_of(text: &str) -> Vec<qbsp::data::bspx::ModelBrushes> {
    let bsp = compile_options(
        text,
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
    parsed.bspx.brush_list.expect("a BRUSHLIST lump")
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
    let list = brush_list_of(&text);
    assert_eq!(list.len(), 2);
    assert_eq!((list[0].model_idx, list[1].model_idx), (0, 1));
    // Six room brushes, the wedge and the clip brush; the hint is left out.
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

/// ericw-tools' `wrbrushesContentTypes`: clip brushes are listed with BSPX's own clip contents
/// (-8), which engines colliding with brushes let shots through, in the world and in brush
/// entities; and `hullExpansionBasic`: a prism's ridge has a bevel (a cap plane) listed beside
/// its sloped sides, or a box sliding along the ridge falls into it.
#[test]
fn wrbrushes_lists_clip_as_clip_and_every_bevel() {
    // A prism along y, sheared: its ridge rises from z -112 at y -64 to z -64 at y 64.
    let prism = "{\n( -16 64 -80 ) ( 0 -64 -112 ) ( -16 -64 -128 ) wall 0 0 0 1 1\n\
                 ( 16 -64 -128 ) ( 0 -64 -112 ) ( 16 64 -80 ) wall 0 0 0 1 1\n\
                 ( -16 -64 -128 ) ( 16 -64 -128 ) ( -16 64 -80 ) wall 0 0 0 1 1\n\
                 ( -16 -64 -128 ) ( 0 -64 -112 ) ( 16 -64 -128 ) wall 0 0 0 1 1\n\
                 ( 16 64 -80 ) ( 0 64 -64 ) ( -16 64 -80 ) wall 0 0 0 1 1\n}\n";
    let clip = box_brush([64.0, 0.0, -128.0], [80.0, 16.0, 0.0], "clip");
    let text = room_map_with(
        false,
        &clip,
        &format!(
            "{}{}",
            brush_entity("func_wall", prism),
            brush_entity("func_wall", &clip)
        ),
    );
    let list = brush_list_of(&text);
    let clip_contents = qbsp::data::nodes::Bsp29LeafContents::Clip;
    let world = &list[0].brushes.inner;
    assert_eq!(world.len(), 7);
    assert_eq!(world[6].contents.0, clip_contents);
    assert_eq!(list[2].brushes.inner[0].contents.0, clip_contents);
    let prism = &list[1].brushes.inner[0];
    let planes: Vec<[f32; 4]> = prism
        .planes
        .inner
        .iter()
        .map(|p| [p.normal.x, p.normal.y, p.normal.z, p.dist])
        .collect();
    assert!(planes.len() >= 3, "{planes:?}");
    // The cap: through the ridge, parallel to x, facing up and back along the rise.
    let rise = (48.0f32).atan2(128.0);
    let cap = [0.0, -rise.sin(), rise.cos()];
    let on_ridge = cap[1] * -64.0 + cap[2] * -112.0;
    assert!(
        planes.iter().any(|p| {
            (0..3).all(|i| (p[i] - cap[i]).abs() < 1e-4) && (p[3] - on_ridge).abs() < 1e-3
        }),
        "no cap plane {cap:?} {on_ridge} in {planes:?}"
    );
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

/// The stage's arguments as the command parses them, ericw-tools' single dashes included.
fn parsed_options(args: &[&str]) -> CompileOptions {
    use clap::Parser;
    let words = ["bsp"].iter().chain(args).map(|s| s.to_string());
    let words =
        bsp_compiler::cli::join_optional_values(quake_formats::cli::normalise_single_dash(words));
    BspCli::try_parse_from(words)
        .expect("parses")
        .args
        .compile_options()
}

#[test]
fn filltype_and_filldetail_take_ericw_tools_spellings() {
    use bsp_compiler::outside::{FillType, Reach};
    let default = parsed_options(&["x.map"]);
    assert_eq!(default.fill_type, FillType::Auto);
    assert_eq!(default.unreached_fill(), Some(Reach::Leaves));
    let outside = parsed_options(&["-filltype", "outside", "-filldetail", "0", "x.map"]);
    assert_eq!(outside.fill_type, FillType::Outside);
    assert_eq!(outside.unreached_fill(), None);
    let inside = parsed_options(&["-filltype", "inside", "-filldetail", "0", "x.map"]);
    assert_eq!(inside.unreached_fill(), Some(Reach::Clusters));
    let bare = parsed_options(&["-filltype", "outside", "-filldetail", "--nofill", "x.map"]);
    assert!(bare.fill_detail && !bare.fill);
}

/// `-add FILE.map` (ericw-tools' `mergeMaps`): the added map's worldspawn brushes join the
/// world and its entities follow the base map's; worldspawn's keys are the base map's. A
/// relative path is found beside the base map too.
#[test]
fn add_merges_a_second_maps_brushes_and_entities() {
    let dir = temp_dir("add");
    let base = dir.join("base.map");
    std::fs::write(&base, room_map(false, "")).expect("write");
    let addition = format!(
        "{{\n\"classname\" \"worldspawn\"\n\"message\" \"not this one\"\n{}}}\n{}",
        box_brush([32.0, 32.0, -128.0], [64.0, 64.0, -96.0], "added"),
        brush_entity(
            "func_wall",
            &box_brush([-96.0, 32.0, -128.0], [-64.0, 64.0, -96.0], "crate")
        ),
    );
    std::fs::write(dir.join("addition.map"), addition).expect("write");
    let options = parsed_options(&["-add", "addition.map", "base.map"]);
    assert_eq!(options.add, [PathBuf::from("addition.map")]);
    let source = bsp_compiler::MapSource::read(&base).expect("read");
    let out = bsp_compiler::compile(&source, &options).expect("compile");
    let bsp = &out.bsp;
    assert!(out.leak.is_none(), "{:?}", out.leak);
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert_eq!(bsp.models.len(), 2);
    let top = faces_at(bsp, 0, [48.0, 48.0, -96.0], Some([0.0, 0.0, 1.0]));
    assert_eq!(top.len(), 1);
    assert_eq!(face_texture(bsp, top[0]), "added");
    let entities = bsp.entity_text();
    assert_eq!(entities.matches("\"classname\"").count(), 3, "{entities}");
    assert!(entities.contains("func_wall") && !entities.contains("not this one"));
    // A missing addition is an error naming it.
    let missing = parsed_options(&["-add", "nowhere.map", "base.map"]);
    let err = bsp_compiler::compile(&source, &missing).expect_err("no such map");
    assert!(err.to_string().contains("nowhere.map"), "{err}");
}

/// A room whose walls are 32 slabs each, of two textures in turn so that they do not merge: every
/// slab's edge meets the sky ceiling's edge, and fixing those T-junctions gives the ceiling 128
/// vertices.
fn room_of_slabs() -> String {
    let mut world = String::new();
    world += &box_brush([-144.0, -144.0, -144.0], [144.0, 144.0, -128.0], "floor");
    world += &box_brush([-144.0, -144.0, 128.0], [144.0, 144.0, 144.0], "sky1");
    for i in 0..32 {
        let (lo, hi) = (-128.0 + 8.0 * f64::from(i), -120.0 + 8.0 * f64::from(i));
        let tex = ["wall", "wall2"][i as usize % 2];
        world += &box_brush([-144.0, lo, -128.0], [-128.0, hi, 128.0], tex);
        world += &box_brush([128.0, lo, -128.0], [144.0, hi, 128.0], tex);
        world += &box_brush([lo, -144.0, -128.0], [hi, -128.0, 128.0], tex);
        world += &box_brush([lo, 128.0, -128.0], [hi, 144.0, 128.0], tex);
    }
    for (x, y) in [
        (-144.0, -144.0),
        (-144.0, 128.0),
        (128.0, -144.0),
        (128.0, 128.0),
    ] {
        world += &box_brush([x, y, -128.0], [x + 16.0, y + 16.0, 128.0], "wall");
    }
    format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"none.wad\"\n{world}}}\n\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"0 0 -100\"\n}}\n"
    )
}

/// `-maxedges N` (ericw-tools' `tjuncManySidedFace` tests): faces whose T-junction fixes give
/// them more than N edges (64 by default, as engines' fixed polygon buffers need) are cut into
/// faces of at most N, none of them without area, and the cracks stay fixed; 0 leaves them whole.
#[test]
fn maxedges_cuts_faces_with_too_many_edges() {
    let text = room_of_slabs();
    let sky_faces = |bsp: &Bsp| -> Vec<usize> {
        (0..bsp.faces.len())
            .filter(|&f| face_texture(bsp, f) == "sky1")
            .collect()
    };
    let area = |bsp: &Bsp, f: usize| {
        let vs: Vec<glam::DVec3> = bsp
            .face_vertices(&bsp.faces[f])
            .expect("vertices")
            .iter()
            .map(|&v| glam::Vec3::from(v).as_dvec3())
            .collect();
        quake_formats::geom::Winding::new(vs).area()
    };
    let capped = compile_options(&text, parsed_options(&["x.map"]));
    assert_eq!(errors(&capped), Vec::<String>::new());
    assert!(bsp_compiler::cracks::find_cracks(&capped).is_empty());
    assert!(capped.faces.iter().all(|f| f.num_edges <= 64));
    let sky = sky_faces(&capped);
    assert!(sky.len() > 1, "{sky:?}");
    let total: f64 = sky.iter().map(|&f| area(&capped, f)).sum();
    assert!((total - 256.0 * 256.0).abs() < 1.0, "{total}");
    assert!(sky.iter().all(|&f| area(&capped, f) > 1.0));
    let small = compile_options(&text, parsed_options(&["-maxedges", "16", "x.map"]));
    assert!(small.faces.iter().all(|f| f.num_edges <= 16));
    assert!(bsp_compiler::cracks::find_cracks(&small).is_empty());
    let whole = compile_options(&text, parsed_options(&["-maxedges", "0", "x.map"]));
    let sky = sky_faces(&whole);
    assert_eq!(sky.len(), 1);
    assert_eq!(whole.faces[sky[0]].num_edges, 128);
}

/// The texinfo flags of the faces textured `name`.
fn flags_of(bsp: &Bsp, name: &str) -> Vec<i32> {
    (0..bsp.faces.len())
        .filter(|&f| face_texture(bsp, f) == name)
        .map(|f| bsp.texinfo[bsp.faces[f].texinfo as usize].flags)
        .collect()
}

/// Lit water (ericw-tools' `-litwater`, alias `-splitturb`, on by default): liquid faces are
/// written without `TEX_SPECIAL`, so light gives them lightmaps, and are cut to lightmap size as
/// other faces are; `-litwater 0` writes them special and whole; the `_litwater` key of
/// worldspawn, and of a brush entity over it, decides for their liquids.
#[test]
fn liquids_are_lit_unless_litwater_is_off() {
    use quake_formats::bsp::texinfo_flags::SPECIAL;
    let pool = box_brush([-128.0, -128.0, -128.0], [128.0, 128.0, -96.0], "*water0");
    let text = room_map(false, &pool);
    let lit = compile_options(&text, parsed_options(&["x.map"]));
    assert_eq!(errors(&lit), Vec::<String>::new());
    let lit_flags = flags_of(&lit, "*water0");
    assert!(lit_flags.iter().all(|f| f & SPECIAL == 0), "{lit_flags:?}");
    let unlit = compile_options(&text, parsed_options(&["-litwater", "0", "x.map"]));
    let unlit_flags = flags_of(&unlit, "*water0");
    assert!(unlit_flags.iter().all(|f| f & SPECIAL != 0));
    // The 256-unit surface, seen from above and below, is cut only when lit.
    assert_eq!(unlit_flags.len(), 2);
    assert!(lit_flags.len() > unlit_flags.len());
    let split = compile_options(&text, parsed_options(&["-splitturb", "x.map"]));
    assert_eq!(flags_of(&split, "*water0"), lit_flags);

    let off_in_world = text.replacen(
        "\"classname\" \"worldspawn\"",
        "\"classname\" \"worldspawn\"\n\"_litwater\" \"0\"",
        1,
    );
    let bsp = compile_options(&off_in_world, parsed_options(&["x.map"]));
    assert!(flags_of(&bsp, "*water0").iter().all(|f| f & SPECIAL != 0));
    let on_in_entity = room_map_with(
        false,
        "",
        &format!("{{\n\"classname\" \"func_group\"\n\"_litwater\" \"1\"\n{pool}}}\n"),
    )
    .replacen(
        "\"classname\" \"worldspawn\"",
        "\"classname\" \"worldspawn\"\n\"_litwater\" \"0\"",
        1,
    );
    let bsp = compile_options(&on_in_entity, parsed_options(&["x.map"]));
    assert!(flags_of(&bsp, "*water0").iter().all(|f| f & SPECIAL == 0));
    // ericw-tools' `litWater` test: `_splitturb 0` on a func_group leaves its liquids unlit.
    let off_by_other_name = room_map_with(
        false,
        "",
        &format!("{{\n\"classname\" \"func_group\"\n\"_splitturb\" \"0\"\n{pool}}}\n"),
    );
    let bsp = compile_options(&off_by_other_name, parsed_options(&["x.map"]));
    assert!(flags_of(&bsp, "*water0").iter().all(|f| f & SPECIAL != 0));
}

/// `-bmodelcontents`: a brush model's water brush is water inside (FTE swims in it), its solid
/// brush still solid; without it, both are solid, as engines that only collide with brush
/// models as solid expect.
#[test]
fn bmodelcontents_keeps_a_brush_models_liquids() {
    let water = box_brush([-64.0, -64.0, -128.0], [0.0, 64.0, -64.0], "*water0");
    let crate_ = box_brush([32.0, -16.0, -128.0], [64.0, 16.0, -96.0], "crate");
    let text = room_map_with(
        false,
        "",
        &brush_entity("func_door", &format!("{water}{crate_}")),
    );
    let contents_at = |bsp: &Bsp, p| {
        let leaf = bsp.leaf_from(bsp.models[1].head_nodes[0], p).expect("leaf");
        bsp.leafs[leaf].contents
    };
    let kept = compile_options(&text, parsed_options(&["-bmodelcontents", "x.map"]));
    assert_eq!(errors(&kept), Vec::<String>::new());
    assert_eq!(contents_at(&kept, [-32.0, 0.0, -96.0]), contents::WATER);
    assert_eq!(contents_at(&kept, [48.0, 0.0, -112.0]), contents::SOLID);
    let solid = compile_options(&text, parsed_options(&["x.map"]));
    assert_eq!(contents_at(&solid, [-32.0, 0.0, -96.0]), contents::SOLID);
    assert_eq!(contents_at(&solid, [48.0, 0.0, -112.0]), contents::SOLID);
}

/// The bsp arguments `args` parse to, spelled as ericw-tools spells them.
fn parsed_args(args: &[&str]) -> bsp_compiler::cli::Args {
    use clap::Parser;
    let words = ["bsp"].iter().chain(args).map(|s| s.to_string());
    let words =
        bsp_compiler::cli::join_optional_values(quake_formats::cli::normalise_single_dash(words));
    BspCli::try_parse_from(words).expect("parses").args
}

/// A compile profile written for ericw-tools' qbsp runs unchanged: its options that change only
/// how qbsp talks, or that Slipgate's compiler has no need of, are accepted, each with a note
/// saying what Slipgate does instead; `-threads N` and `-wrbrushesonly` act.
#[test]
fn ericw_tools_only_options_are_accepted_with_a_note() {
    let args = parsed_args(&[
        "-nopercent",
        "-verbose",
        "-nolog",
        "-tjunc",
        "mwt",
        "-splitsky",
        "-chop",
        "-threads",
        "2",
        "-lowpriority",
        "-gamedir",
        "id1",
        "-aliasdef",
        "a.def",
        "-aliasdef",
        "b.def",
        "x.map",
    ]);
    let notes = args.ericw_only.notes();
    assert_eq!(notes.len(), 9, "{notes:?}");
    for name in [
        "-nopercent",
        "-verbose",
        "-nolog",
        "-tjunc",
        "-splitsky",
        "-chop",
        "-gamedir",
        "-aliasdef",
    ] {
        assert!(
            notes
                .iter()
                .any(|n| n.starts_with(&format!("{name} has no effect"))),
            "{name}: {notes:?}"
        );
    }
    assert_eq!(args.threads, Some(2));
    assert_eq!(args.input, PathBuf::from("x.map"));
    assert!(parsed_args(&["x.map"]).ericw_only.notes().is_empty());

    let only = parsed_args(&["-bspxonly", "x.map"]).compile_options();
    assert!(only.brush_list && !only.clip_hulls);
}

/// `-2psb` (ericw-tools' spelling; `--2psb` too) writes RMQ's 2PSB: its magic leads the file,
/// which reads back as 2PSB, valid, with the faces a BSP29 compile gets.
#[test]
fn two_psb_writes_rmqs_bsp2_variant() {
    use quake_formats::BspVersion;
    assert_eq!(parsed_options(&["x.map"]).version, BspVersion::Bsp29);
    assert_eq!(
        parsed_options(&["-bsp2", "x.map"]).version,
        BspVersion::Bsp2
    );
    for spelling in ["-2psb", "--2psb"] {
        assert_eq!(
            parsed_options(&[spelling, "x.map"]).version,
            BspVersion::Bsp2Psb
        );
    }

    let dir = temp_dir("2psb");
    let map = dir.join("room.map");
    std::fs::write(&map, room_map(false, "")).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_slipgate-bsp"))
        .arg("-2psb")
        .arg(&map)
        .output()
        .expect("run slipgate-bsp");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("(2PSB)"), "{stdout}");
    let bytes = std::fs::read(map.with_extension("bsp")).expect("read the BSP");
    assert_eq!(&bytes[..4], b"2PSB");
    let bsp = Bsp::read(&bytes).expect("2PSB reads back");
    assert_eq!(bsp.version, BspVersion::Bsp2Psb);
    let errors: Vec<_> = validate(&bsp)
        .into_iter()
        .filter(|p| p.severity == Severity::Error)
        .collect();
    assert!(errors.is_empty(), "{errors:?}");
    let bsp29 = compile_options(&room_map(false, ""), CompileOptions::default());
    assert_eq!(bsp29.version, BspVersion::Bsp29);
    assert_eq!(bsp.faces, bsp29.faces);
    assert_eq!(bsp.nodes, bsp29.nodes);
}

/// A 2PSB compile whose node and leaf bounds do not fit its 16-bit integers is written as BSP2,
/// with a warning naming the bound, as BSP29 gives way past its limits.
#[test]
fn two_psb_gives_way_to_bsp2_past_16_bit_bounds() {
    use quake_formats::BspVersion;
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"none.wad\"\n{}}}\n{{\n\"classname\" \"info_player_start\"\n\"origin\" \"32928 32928 32900\"\n}}\n",
        room(32_800.0, 33_056.0, 16.0, false)
    );
    let options = CompileOptions {
        version: BspVersion::Bsp2Psb,
        ..CompileOptions::default()
    };
    let out = try_compile_with(&text, &options).expect("compile");
    assert!(out.leak.is_none(), "{:?}", out.warnings);
    assert_eq!(out.bsp.version, BspVersion::Bsp2);
    let warned = out
        .warnings
        .iter()
        .any(|w| w.to_string().contains("2PSB limit exceeded"));
    assert!(warned, "{:?}", out.warnings);
}

/// The texture of `bsp` named `name`.
fn texture_named(bsp: &Bsp, name: &str) -> quake_formats::miptex::MipTex {
    bsp.textures
        .textures
        .iter()
        .flatten()
        .find(|t| t.name() == name)
        .cloned()
        .unwrap_or_else(|| panic!("no texture {name}"))
}

/// `-path DIR` with `-notex`: a texture no WAD holds takes its name and size from a loose
/// picture, `DIR/textures/NAME.png` or `.tga`, without a warning (ericw-tools' `looseTextures`);
/// without `-notex` textures come from WADs only (`looseTexturesIgnored`), and one found
/// nowhere is a placeholder.
#[test]
fn path_gives_loose_textures_their_sizes_with_notex() {
    let dir = temp_dir("loose");
    std::fs::create_dir_all(dir.join("textures")).expect("textures dir");
    image::RgbImage::new(32, 16)
        .save(dir.join("textures/floor_purple.png"))
        .expect("png");
    image::RgbImage::new(128, 64)
        .save(dir.join("textures/wall_tan.tga"))
        .expect("tga");
    let text = room_map(false, "")
        .replace("floor 0 0 0 1 1", "floor_purple 0 0 0 1 1")
        .replace("wall 0 0 0 1 1", "WALL_TAN 0 0 0 1 1");
    let path = dir.to_str().expect("utf8");
    let out = try_compile_with(&text, &parsed_options(&["-path", path, "-notex", "x.map"]))
        .expect("compile");
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    for (name, size) in [("floor_purple", (32, 16)), ("wall_tan", (128, 64))] {
        let t = texture_named(&out.bsp, name);
        assert_eq!((t.width, t.height), size, "{name}");
        assert!(t.mips.is_none(), "{name}");
    }
    let missing: Vec<String> = out
        .warnings
        .iter()
        .map(|w| w.to_string())
        .filter(|w| w.contains("not found in any WAD"))
        .collect();
    // Only the ceiling's texture is missing.
    assert_eq!(missing.len(), 1, "{missing:?}");

    let embedded =
        try_compile_with(&text, &parsed_options(&["-path", path, "x.map"])).expect("compile");
    let t = texture_named(&embedded.bsp, "floor_purple");
    assert_eq!((t.width, t.height), (64, 64));
    assert!(t.mips.is_some());
}

/// `-missing_textures_as_zero_size`: a texture found nowhere keeps its name with a 0x0 size and
/// no pixels (ericw-tools' `missingTextureAndMissingTexturesAsZeroSize`); one a WAD holds is
/// written whole.
#[test]
fn missing_textures_as_zero_size_writes_them_0x0() {
    let wad = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps");
    let text = room_map(false, "")
        .replace("none.wad", "slipgate.wad")
        .replace("wall 0 0 0 1 1", "brick1 0 0 0 1 1");
    let wad_dir = wad.to_str().expect("utf8");
    let options = parsed_options(&[
        "-wadpath",
        wad_dir,
        "-missing_textures_as_zero_size",
        "x.map",
    ]);
    let bsp = compile_options(&text, options);
    let floor = texture_named(&bsp, "floor");
    assert_eq!((floor.width, floor.height), (0, 0));
    assert!(floor.mips.is_none());
    let brick = texture_named(&bsp, "brick1");
    assert!(brick.width > 0 && brick.mips.is_some());
    let back = Bsp::read(&bsp.write().expect("write")).expect("read back");
    assert_eq!(texture_named(&back, "floor").width, 0);
}

/// ericw-tools' switch for its `.texinfo.json`, which Slipgate does not write, is accepted with
/// a note; the one for the `.content.json` acts (see `content_flags.rs`).
#[test]
fn extended_flag_switches_are_accepted() {
    let args = parsed_args(&["-noextendedcontentflags", "-noextendedsurfflags", "x.map"]);
    let notes = args.ericw_only.notes();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].starts_with("-noextendedsurfflags has no effect"));
    assert!(args.noextendedcontentflags);
}
