//! Sealing: maps that are closed must seal, whatever the entities standing on their faces, the
//! entities holding their sky, or the seams between their brushes; maps that leak must say where.

mod common;

use common::*;

use bsp_compiler::outside::FillType;
use bsp_compiler::texinfo::FaceContents;
use bsp_compiler::trace::hull_point_contents;
use bsp_compiler::warnings::DroppedFace;
use bsp_compiler::{CompileOptions, CompileOutput, MapSource, Warning, compile};
use quake_formats::bsp::contents;
use std::path::{Path, PathBuf};

fn maps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps")
}

fn compile_project_map(rel: &str) -> CompileOutput {
    let path = maps_dir().join(rel);
    let source = MapSource::read(&path).expect("read");
    let options = CompileOptions {
        wad_dirs: vec![maps_dir()],
        ..CompileOptions::default()
    };
    compile(&source, &options).expect("compile")
}

fn hull0_contents(out: &CompileOutput, p: [f32; 3]) -> i32 {
    out.bsp.leafs[out.bsp.leaf_at(p).expect("leaf")].contents
}

/// The warnings of `out` other than the missing-texture and missing-WAD kinds.
fn map_warnings(out: &CompileOutput) -> Vec<&Warning> {
    out.warnings
        .iter()
        .filter(|w| {
            !matches!(
                w,
                Warning::MissingTexture { .. } | Warning::MissingWad { .. }
            )
        })
        .collect()
}

/// Every `maps/hard/seal_*.map` corridor seals: the void around it is filled, the corridor is
/// open in every hull, and nothing is warned but what each case is about.
#[test]
fn the_sealing_corridors_seal() {
    let mut names: Vec<String> = std::fs::read_dir(maps_dir().join("hard"))
        .expect("maps/hard")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("seal_") && n.ends_with(".map"))
        .collect();
    names.sort();
    assert!(names.len() >= 5, "{names:?}");
    for name in names {
        let out = compile_project_map(&format!("hard/{name}"));
        assert!(out.leak.is_none(), "{name}: {:?}", out.leak);
        assert!(out.stats.filled_leaves > 0, "{name}: nothing filled");
        // Inside the corridor, and in the void beside it.
        assert_eq!(hull0_contents(&out, [512.0, 64.0, 64.0]), contents::EMPTY);
        assert_eq!(hull0_contents(&out, [512.0, -100.0, 64.0]), contents::SOLID);
        for hull in [1, 2] {
            let inside = hull_point_contents(&out.bsp, 0, hull, [512.0, 64.0, 40.0]);
            assert_eq!(inside, contents::EMPTY, "{name}: hull {hull}");
        }
        assert!(
            !map_warnings(&out)
                .iter()
                .any(|w| matches!(w, Warning::EntityInSolid { .. })),
            "{name}: {:?}",
            out.warnings
        );
    }
}

/// id's dm2 has a brush listing one face twice: the repeat is dropped (named by its line), the
/// brush kept.
#[test]
fn a_face_repeating_its_brushs_plane_is_dropped_and_the_brush_kept() {
    let out = compile_project_map("hard/seal_duplicate_plane.map");
    let warnings = map_warnings(&out);
    assert!(
        matches!(
            warnings[..],
            [Warning::DroppedFace {
                entity: 0,
                brush: 5,
                line: 60,
                reason: DroppedFace::RepeatedPlane,
            }]
        ),
        "{warnings:?}"
    );
    assert_eq!(out.stats.bad_brushes, 0);
}

/// The first face that gives contents decides a brush's (as in id's and ericw-tools' compilers);
/// the first differing face is warned with its line.
#[test]
fn a_brush_of_mixed_contents_takes_its_first_faces() {
    let out = compile_project_map("hard/seal_mixed_contents.map");
    let mixed: Vec<(usize, FaceContents)> = map_warnings(&out)
        .iter()
        .filter_map(|w| match w {
            Warning::MixedContents { brush, used, .. } => Some((*brush, *used)),
            _ => None,
        })
        .collect();
    assert_eq!(
        mixed,
        [(5, FaceContents::Sky), (6, FaceContents::Solid)],
        "{:?}",
        out.warnings
    );
    assert_eq!(hull0_contents(&out, [256.0, 64.0, 136.0]), contents::SKY);
    assert_eq!(hull0_contents(&out, [768.0, 64.0, 136.0]), contents::SOLID);
}

/// Sky is sky in every detail entity: it seals, and its leaves are sky.
#[test]
fn sky_in_any_detail_entity_is_structural_sky() {
    let out = compile_project_map("hard/seal_sky_in_detail.map");
    for x in [80.0, 240.0, 420.0, 600.0, 780.0, 950.0] {
        assert_eq!(
            hull0_contents(&out, [x, 64.0, 136.0]),
            contents::SKY,
            "x {x}"
        );
    }
}

/// An entity exactly on a face between the void and a brush counts on the brush's side in hull
/// 0, so it never leaks; a player start exactly 24 units above the floor (on hull 1's grown
/// floor) still holds the room open in the clip hulls, as ericw-tools' `q1_sealing_hull1_onnode`
/// asks.
#[test]
fn entities_on_node_planes_seal_hull_0_and_keep_the_clip_hulls_open() {
    let out = compile_project_map("hard/seal_entity_on_face.map");
    assert!(out.leak.is_none());
    for hull in [1, 2] {
        let at_start = hull_point_contents(&out.bsp, 0, hull, [64.0, 64.0, 25.0]);
        assert_eq!(at_start, contents::EMPTY, "hull {hull}");
        let far_above = hull_point_contents(&out.bsp, 0, hull, [64.0, 64.0, 1000.0]);
        assert_eq!(
            far_above,
            contents::SOLID,
            "hull {hull}: the void is filled"
        );
    }
}

/// ericw-tools' `q1_sealing_hull1_onnode`: a room whose only entity is a player start exactly 24
/// units above the floor, which is on hull 1's grown floor. In the clip hulls the start counts
/// on the open side, so they are filled around the room as hull 0 is.
#[test]
fn a_player_start_on_the_grown_floor_holds_the_clip_hulls_open() {
    let start = "{\n\"classname\" \"info_player_start\"\n\"origin\" \"-32 -32 -104\"\n}\n";
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n{}}}\n{start}",
        room(-128.0, 128.0, 16.0, false)
    );
    let out = compile_text(&text);
    assert!(out.leak.is_none(), "{:?}", out.leak);
    for hull in [1, 2] {
        let above_start = hull_point_contents(&out.bsp, 0, hull, [-32.0, -32.0, -103.0]);
        assert_eq!(above_start, contents::EMPTY, "hull {hull}");
        let void = hull_point_contents(&out.bsp, 0, hull, [-32.0, -32.0, 1000.0]);
        assert_eq!(void, contents::SOLID, "hull {hull}: its outside is filled");
    }
}

/// An entity inside a solid wall is warned about and is no occupant: the map does not leak
/// through it, even where the wall meets the void.
#[test]
fn an_entity_inside_a_wall_is_warned_and_never_leaks() {
    let light = "{\n\"classname\" \"light\"\n\"origin\" \"136 0 0\"\n}\n";
    let out = compile_text(&room_map_with(false, "", light));
    assert!(out.leak.is_none(), "{:?}", out.leak);
    assert!(
        out.warnings
            .iter()
            .any(|w| matches!(w, Warning::EntityInSolid { entity: 1, .. })),
        "{:?}",
        out.warnings
    );
}

/// `_nofill` lets an entity stand in the void; without it, the same entity leaks.
#[test]
fn an_entity_marked_nofill_may_stand_in_the_void() {
    let outside =
        |nofill: &str| format!("{{\n\"classname\" \"light\"\n\"origin\" \"0 0 400\"\n{nofill}}}\n");
    let out = compile_text(&room_map_with(false, "", &outside("\"_nofill\" \"1\"\n")));
    assert!(out.leak.is_none(), "{:?}", out.leak);
    let out = compile_text(&room_map_with(false, "", &outside("")));
    let leak = out.leak.expect("a light in the void leaks");
    assert_eq!((leak.entity, leak.classname.as_str()), (1, "light"));
}

/// A real leak names its entity with its line, and the brushes around the hole the path leaves
/// the map by: the pinhole's wall pieces above and below it (brushes 7 and 8, lines 73 and 82).
#[test]
fn a_leak_names_the_entity_line_and_the_brushes_around_the_hole() {
    let out = compile_project_map("hard/pinhole.map");
    let leak = out.leak.expect("the pinhole leaks");
    assert_eq!(
        (leak.entity, leak.classname.as_str(), leak.line),
        (1, "info_player_start", 92)
    );
    let around: Vec<(usize, usize)> = leak
        .exit
        .iter()
        .map(|(b, _, _)| (b.brush, b.line))
        .collect();
    assert!(
        around.contains(&(7, 73)) && around.contains(&(8, 82)),
        "{around:?}"
    );
    let text = leak.to_string();
    assert!(
        text.contains("brush 7 of entity 0 (line 73, brick1)"),
        "{text}"
    );
    // The pointfile runs from the entity out through the hole (x 512..528, y 256..257).
    assert_eq!(leak.pointfile[0], glam::DVec3::new(64.0, 64.0, 24.0));
    assert!(
        leak.pointfile
            .iter()
            .any(|p| (512.0..=528.0).contains(&p.x) && (255.0..=258.0).contains(&p.y)),
        "{:?}",
        leak.pointfile
    );
}

/// A leaking entity beyond every brush is named as such, with no brushes: it is what to move.
#[test]
fn a_leaking_entity_beyond_every_brush_says_so() {
    let out = compile_project_map("hard/outside_entity.map");
    let leak = out.leak.expect("the outside light leaks");
    assert!(leak.beyond_brushes && leak.exit.is_empty(), "{leak:?}");
    assert!(leak.to_string().contains("outside every brush"), "{leak}");
}

/// Three rooms in one sealed box: A holds the player start; C is open to A through a slit 8
/// units wide (too narrow for the player's box); B is closed off and holds no entity. With
/// `detail`, A also holds a hollow `func_detail` box (a pocket no entity reaches).
fn three_rooms(detail: bool) -> String {
    let (t, lo, hi) = (16.0, [-512.0, -256.0, 0.0], [512.0, 256.0, 256.0]);
    let mut world = String::new();
    world += &box_brush(
        [lo[0] - t, lo[1] - t, -t],
        [hi[0] + t, hi[1] + t, 0.0],
        "floor",
    );
    world += &box_brush(
        [lo[0] - t, lo[1] - t, 256.0],
        [hi[0] + t, hi[1] + t, 272.0],
        "ceiling",
    );
    world += &box_brush(
        [lo[0] - t, lo[1] - t, 0.0],
        [lo[0], hi[1] + t, 256.0],
        "wall",
    );
    world += &box_brush(
        [hi[0], lo[1] - t, 0.0],
        [hi[0] + t, hi[1] + t, 256.0],
        "wall",
    );
    world += &box_brush([lo[0], lo[1] - t, 0.0], [hi[0], lo[1], 256.0], "wall");
    world += &box_brush([lo[0], hi[1], 0.0], [hi[0], hi[1] + t, 256.0], "wall");
    // A | C through the slit y -4..4; C | B closed.
    world += &box_brush([-128.0, -256.0, 0.0], [-96.0, -4.0, 256.0], "wall");
    world += &box_brush([-128.0, 4.0, 0.0], [-96.0, 256.0, 256.0], "wall");
    world += &box_brush([96.0, -256.0, 0.0], [128.0, 256.0, 256.0], "brick");
    let mut entities = String::new();
    if detail {
        // A 64-unit box of 8-unit plates around (-400, 128, 64).
        let (c, r, w) = ([-400.0, 128.0, 64.0], 32.0, 8.0);
        let mut plates = String::new();
        for axis in 0..3 {
            for side in [-1.0, 1.0] {
                let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
                for i in 0..3 {
                    (a[i], b[i]) = (c[i] - r, c[i] + r);
                }
                if side < 0.0 {
                    b[axis] = a[axis] + w;
                } else {
                    a[axis] = b[axis] - w;
                }
                plates += &box_brush(a, b, "crate");
            }
        }
        entities += &brush_entity("func_detail", &plates);
    }
    format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"none.wad\"\n{world}}}\n{entities}\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"-300 0 24\"\n}}\n"
    )
}

const IN_A: [f32; 3] = [-300.0, 0.0, 60.0];
const IN_C: [f32; 3] = [0.0, 0.0, 60.0];
const IN_B: [f32; 3] = [300.0, 0.0, 60.0];
const IN_POCKET: [f32; 3] = [-400.0, 128.0, 64.0];
const IN_VOID: [f32; 3] = [0.0, 0.0, 1000.0];

/// What hulls 0, 1 and 2 hold at `p`.
fn hulls_at(out: &CompileOutput, p: [f32; 3]) -> [i32; 3] {
    [
        hull0_contents(out, p),
        hull_point_contents(&out.bsp, 0, 1, p),
        hull_point_contents(&out.bsp, 0, 2, p),
    ]
}

/// ericw-tools' default (`-filltype auto`, `-filldetail 1`, its test `sealing`): after the void,
/// every place no entity reaches is filled, in each hull by what reaches there in that hull. Hull
/// 0 fills the closed room B and the pocket inside the detail box, keeping room C, which the
/// slit joins to A; the clip hulls, whose boxes do not pass the slit, fill C too. B's faces go.
#[test]
fn rooms_no_entity_reaches_are_filled() {
    let out = compile_text(&three_rooms(true));
    assert!(out.leak.is_none(), "{:?}", out.leak);
    let (empty, solid) = (contents::EMPTY, contents::SOLID);
    assert_eq!(hulls_at(&out, IN_A), [empty; 3]);
    assert_eq!(hulls_at(&out, IN_C), [empty, solid, solid]);
    assert_eq!(hulls_at(&out, IN_B), [solid; 3]);
    assert_eq!(hulls_at(&out, IN_VOID), [solid; 3]);
    assert_eq!(hull0_contents(&out, IN_POCKET), solid);
    // The wall between C and B is drawn from C only; the pocket's inner faces are gone.
    let brick_facing = |x: f32| {
        let bsp = &out.bsp;
        (0..bsp.faces.len())
            .filter(|&f| face_texture(bsp, f) == "brick" && face_normal(bsp, f)[0] == x)
            .count()
    };
    assert!(brick_facing(-1.0) > 0);
    assert_eq!(brick_facing(1.0), 0);
    let inner = faces_at(&out.bsp, 0, [-400.0, 128.0, 40.0], Some([0.0, 0.0, 1.0]));
    assert!(inner.is_empty(), "{inner:?}");
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
}

/// `-filltype outside` with `-filldetail 0` fills only the void, as before ericw-tools 2.0:
/// every room and the pocket stay open in hull 0, and C and B in the clip hulls.
#[test]
fn filling_from_outside_only_keeps_every_room() {
    let options = CompileOptions {
        fill_type: FillType::Outside,
        fill_detail: false,
        ..CompileOptions::default()
    };
    let out = try_compile_with(&three_rooms(true), &options).expect("compile");
    assert!(out.leak.is_none(), "{:?}", out.leak);
    let (empty, solid) = (contents::EMPTY, contents::SOLID);
    for p in [IN_A, IN_C, IN_B] {
        assert_eq!(hulls_at(&out, p), [empty; 3], "{p:?}");
    }
    assert_eq!(hull0_contents(&out, IN_POCKET), empty);
    assert_eq!(hulls_at(&out, IN_VOID), [solid; 3]);
}

/// `-filltype inside` without `-filldetail` floods by vis clusters, which detail does not split:
/// the rooms are filled as by default, the pocket inside the detail box is not.
#[test]
fn filling_from_inside_without_filldetail_keeps_detail_pockets() {
    let options = CompileOptions {
        fill_type: FillType::Inside,
        fill_detail: false,
        ..CompileOptions::default()
    };
    let out = try_compile_with(&three_rooms(true), &options).expect("compile");
    let (empty, solid) = (contents::EMPTY, contents::SOLID);
    assert_eq!(hulls_at(&out, IN_C), [empty, solid, solid]);
    assert_eq!(hulls_at(&out, IN_B), [solid; 3]);
    assert_eq!(hull0_contents(&out, IN_POCKET), empty);
}
