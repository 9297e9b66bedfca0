//! Entities ericw-tools' users rely on: `_mirrorinside` on brush entities and liquids, and
//! `func_illusionary_visblocker`.

mod common;

use bsp_compiler::CompileOptions;
use bsp_compiler::trace::hull_point_contents;
use common::*;
use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::bsp::face_flags::FaceFlags;
use quake_formats::prt::PortalFile;

/// The centre of the brushes these tests mirror.
const CENTRE: [f32; 3] = [0.0, 0.0, -96.0];

/// Faces with `texture` in model `model`, and how many of them are drawn seen from [`CENTRE`].
fn model_faces(bsp: &Bsp, model: usize, texture: &str) -> (usize, usize) {
    let m = &bsp.models[model];
    let range = m.first_face as usize..(m.first_face + m.num_faces) as usize;
    let mut count = 0;
    let mut inward = 0;
    let centre = CENTRE;
    for f in &bsp.faces[range] {
        let t = bsp.texinfo[f.texinfo as usize].miptex as usize;
        if bsp.textures.textures[t]
            .as_ref()
            .is_none_or(|m| m.name() != texture)
        {
            continue;
        }
        count += 1;
        let plane = &bsp.planes[f.plane as usize];
        let sign = if f.side != 0 { -1.0 } else { 1.0 };
        let d = (0..3).map(|i| plane.normal[i] * centre[i]).sum::<f32>() - plane.dist;
        if sign * d > 0.0 {
            inward += 1;
        }
    }
    (count, inward)
}

fn water_box() -> String {
    box_brush([-64.0, -64.0, -128.0], [64.0, 64.0, -64.0], "*water1")
}

#[test]
fn mirrorinside_gives_brush_entities_faces_seen_from_inside() {
    let bush = box_brush([-32.0, -32.0, -128.0], [32.0, 32.0, -64.0], "leaves");
    let plain = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_illusionary", &bush),
    ))
    .bsp;
    let mirrored_entity =
        format!("{{\n\"classname\" \"func_illusionary\"\n\"_mirrorinside\" \"1\"\n{bush}}}\n");
    let mirrored = compile_text(&room_map_with(false, "", &mirrored_entity)).bsp;
    assert_eq!(errors(&mirrored), Vec::<String>::new());
    assert_eq!(model_faces(&plain, 1, "leaves"), (6, 0));
    assert_eq!(model_faces(&mirrored, 1, "leaves"), (12, 6));
}

#[test]
fn liquids_in_detail_and_groups_mirror_unless_told_not_to() {
    for class in ["func_detail", "func_group"] {
        let default = compile_text(&room_map_with(
            false,
            "",
            &brush_entity(class, &water_box()),
        ));
        let off = format!(
            "{{\n\"classname\" \"{class}\"\n\"_mirrorinside\" \"0\"\n{}}}\n",
            water_box()
        );
        let off = compile_text(&room_map_with(false, "", &off));
        assert_eq!(errors(&off.bsp), Vec::<String>::new());
        // Its five open sides (it stands on the floor): from both sides, or from outside only.
        assert_eq!(model_faces(&default.bsp, 0, "*water1"), (10, 5), "{class}");
        assert_eq!(model_faces(&off.bsp, 0, "*water1"), (5, 0), "{class}");
    }
}

#[test]
fn a_visblocker_blocks_vis_but_not_movement_or_sight_of_its_faces() {
    // A wall of it across the room at x = 0.
    let blocker = brush_entity(
        "func_illusionary_visblocker",
        &box_brush([-8.0, -128.0, -128.0], [8.0, 128.0, 128.0], "*water1"),
    );
    // Unlit liquids, so that its faces are not cut to lightmap size and can be counted.
    let unlit = CompileOptions {
        lit_water: false,
        ..CompileOptions::default()
    };
    let out = try_compile_with(&room_map_with(false, "", &blocker), &unlit).expect("compile");
    let bsp = &out.bsp;
    assert!(out.leak.is_none());
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert!(!bsp.entity_text().contains("visblocker"));
    // Walked through: empty in every hull.
    assert_eq!(
        bsp.leafs[bsp.leaf_at([0.0, 0.0, 0.0]).expect("leaf")].contents,
        contents::EMPTY
    );
    for hull in 1..3 {
        assert_eq!(
            hull_point_contents(bsp, 0, hull, [0.0, 0.0, 0.0]),
            contents::EMPTY,
            "hull {hull}"
        );
    }
    // Drawn from both sides and from within: both faces of each of its two open sides.
    assert_eq!(model_faces(bsp, 0, "*water1").0, 4);
    // No portal enters it: vis sees the room as two halves that cannot see each other.
    let prt = PortalFile::parse(&out.portals.write()).expect("prt");
    let a = bsp.leaf_at([-64.0, 0.0, 0.0]).expect("leaf") as u32 - 1;
    let b = bsp.leaf_at([64.0, 0.0, 0.0]).expect("leaf") as u32 - 1;
    let inside = bsp.leaf_at([0.0, 0.0, 0.0]).expect("leaf") as u32 - 1;
    assert_ne!(a, b);
    for p in &prt.portals {
        assert!(!p.leafs.contains(&inside), "{:?}", p.leafs);
        assert!(p.leafs != [a, b] && p.leafs != [b, a]);
    }
}

/// A brush of `box_brush`'s sides but its top, which slopes from `high` (x, z) down to `low`.
fn ramp(x: [f64; 2], y: [f64; 2], bottom: f64, high: [f64; 2], low: [f64; 2]) -> String {
    let whole = box_brush([x[0], y[0], bottom], [x[1], y[1], high[1]], "ramp");
    let lines: Vec<&str> = whole.lines().collect();
    // The fifth side is the top (+z); the slope's three points turn the same way seen from
    // outside whichever way it falls.
    let (p1, p2, p3) = if high[0] < low[0] {
        (
            [high[0], y[0], high[1]],
            [high[0], y[1], high[1]],
            [low[0], y[0], low[1]],
        )
    } else {
        (
            [high[0], y[0], high[1]],
            [low[0], y[0], low[1]],
            [high[0], y[1], high[1]],
        )
    };
    let point = |p: [f64; 3]| format!("( {} {} {} )", p[0], p[1], p[2]);
    let slope = format!("{} {} {} ramp 0 0 0 1 1", point(p1), point(p2), point(p3));
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    out[5] = slope;
    out.join("\n") + "\n"
}

#[test]
fn a_long_hall_is_cut_in_the_middle_only_by_planes_of_faces() {
    // A hall 2560 units long (over the 1024 above which a node is cut near its middle), closed
    // across by a visblocker 256 units from its middle, with a ramp on each side leaning on it
    // whose steep side, nearer the middle than the visblocker, is hidden in the floor. Only sides faces are made on cut the hall, so each half
    // stays one leaf and no portal is left (ericw-tools' `q1FuncIllusionaryVisblocker`).
    let (y, floor, top) = ([-128.0, 128.0], 0.0, 256.0);
    let mut world = String::new();
    world += &box_brush(
        [-1040.0, y[0] - 16.0, floor - 16.0],
        [1552.0, y[1] + 16.0, floor],
        "floor",
    );
    world += &box_brush(
        [-1040.0, y[0] - 16.0, top],
        [1552.0, y[1] + 16.0, top + 16.0],
        "ceiling",
    );
    world += &box_brush([-1040.0, y[0] - 16.0, floor], [1552.0, y[0], top], "wall");
    world += &box_brush([-1040.0, y[1], floor], [1552.0, y[1] + 16.0, top], "wall");
    world += &box_brush([-1040.0, y[0], floor], [-1024.0, y[1], top], "wall");
    world += &box_brush([1536.0, y[0], floor], [1552.0, y[1], top], "wall");
    // The ramps reach through the walls into the void, where the outside fill makes their
    // buried side's plane no face's.
    let wide = [y[0] - 32.0, y[1] + 32.0];
    world += &ramp([8.0, 40.0], wide, floor - 8.0, [8.0, 16.0], [40.0, floor]);
    world += &ramp(
        [-40.0, -8.0],
        wide,
        floor - 8.0,
        [-8.0, 16.0],
        [-40.0, floor],
    );
    let blocker = brush_entity(
        "func_illusionary_visblocker",
        &box_brush([-8.0, y[0], floor], [8.0, y[1], top], "*water1"),
    );
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"none.wad\"\n{world}}}\n{blocker}\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"-512 0 24\"\n}}\n\
         {{\n\"classname\" \"weapon_nailgun\"\n\"origin\" \"512 0 24\"\n}}\n"
    );
    let out = try_compile(&text).expect("compile");
    assert!(out.leak.is_none());
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    let prt = PortalFile::parse(&out.portals.write()).expect("prt");
    assert_eq!((prt.num_leafs, prt.portals.len()), (3, 0));
}

/// The feature map (`tests/maps/features.map`): prefabs (one nested, turned, scaled), water
/// that mirrors inside (func_detail by default, func_illusionary by `_mirrorinside`) and a
/// visblocker compile without a warning and validate without a problem of any severity.
#[test]
fn the_feature_map_compiles_clean() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let source = bsp_compiler::MapSource::read(&dir.join("tests/maps/features.map")).expect("read");
    let options = bsp_compiler::CompileOptions {
        wad_dirs: vec![dir.join("../maps")],
        ..bsp_compiler::CompileOptions::default()
    };
    let out = bsp_compiler::compile(&source, &options).expect("compile");
    let warnings: Vec<String> = out.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(warnings, Vec::<String>::new());
    let problems: Vec<String> = quake_formats::validate(&out.bsp)
        .iter()
        .map(|p| p.to_string())
        .collect();
    assert_eq!(problems, Vec::<String>::new());
    let bsp = &out.bsp;
    // The world, the func_wall prefab and the func_illusionary water.
    assert_eq!(bsp.models.len(), 3);
    let text = bsp.entity_text();
    assert!(!text.contains("misc_external_map") && !text.contains("visblocker"));
    // The illusionary water is drawn from inside: 6 faces out, 6 in.
    assert_eq!(model_faces(bsp, 2, "*water1").0, 12);
    // The nested prefab's half-size pillar (its cap at 64..72 up) is in the world.
    let cap = bsp.leaf_at([-208.0, 0.0, 68.0]).expect("leaf");
    assert_eq!(bsp.leafs[cap].contents, contents::SOLID);
}

/// A func_wall of one 32-unit box at `centre` with `_hulls` set to `hulls`.
fn wall_in_hulls(centre: [f64; 3], hulls: &str) -> String {
    let [x, y, z] = centre;
    let brush = box_brush(
        [x - 16.0, y - 16.0, z - 16.0],
        [x + 16.0, y + 16.0, z + 16.0],
        "wall",
    );
    format!("{{\n\"classname\" \"func_wall\"\n\"_hulls\" \"{hulls}\"\n{brush}}}\n")
}

#[test]
fn hulls_key_picks_the_hulls_a_brush_model_is_in() {
    // As ericw-tools' `q1_hulls` test: 5 (hulls 0 and 2) stops line traces and shamblers but
    // lets the player through; 6 (hulls 1 and 2) stops the player and shamblers, has no faces
    // and lets point traces through.
    let (a, b) = ([-64.0, 0.0, -64.0], [64.0, 0.0, -64.0]);
    let map = room_map_with(
        false,
        "",
        &(wall_in_hulls(a, "5") + &wall_in_hulls(b, "6") + &wall_in_hulls(b, "0")),
    );
    let out = compile_text(&map);
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    let bsp = &out.bsp;
    let at = |p: [f64; 3]| p.map(|c| c as f32);
    let in_hulls =
        |model: usize, p| [0, 1, 2].map(|hull| hull_point_contents(bsp, model, hull, at(p)));
    let (solid, empty) = (contents::SOLID, contents::EMPTY);
    assert_eq!(in_hulls(1, a), [solid, empty, solid]);
    assert_eq!(in_hulls(2, b), [empty, solid, solid]);
    assert_eq!(in_hulls(3, b), [solid, solid, solid]);
    let faces = |model: usize| bsp.models[model].num_faces;
    assert!(faces(1) > 0 && faces(3) > 0);
    assert_eq!(faces(2), 0);
}

#[test]
fn a_hulls_key_that_is_not_a_number_warns_and_keeps_every_hull() {
    let map = room_map_with(false, "", &wall_in_hulls([0.0; 3], "player"));
    let out = compile_text(&map);
    let warned: Vec<String> = out.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        warned
            .iter()
            .any(|w| w.contains("\"_hulls\" \"player\"") && w.contains("every hull")),
        "{warned:?}"
    );
    assert_eq!(
        [0, 1, 2].map(|hull| hull_point_contents(&out.bsp, 1, hull, [0.0; 3])),
        [contents::SOLID; 3]
    );
}

#[test]
fn merged_entities_keys_for_shadow_and_sound_reach_their_faces() {
    let flagged = |classname: &str, keys: &str| {
        let brush = box_brush([-32.0, -32.0, -128.0], [32.0, 32.0, -64.0], "*water1");
        let entity = format!("{{\n\"classname\" \"{classname}\"\n{keys}\n{brush}}}\n");
        let bsp = compile_text(&room_map_with(false, "", &entity)).bsp;
        let flags = bsp.face_flags().expect("lump").unwrap_or_default();
        let water: Vec<_> = (0..bsp.faces.len())
            .filter(|&f| face_texture(&bsp, f) == "*water1")
            .map(|f| flags.get(f).copied().unwrap_or_default())
            .collect();
        assert!(!water.is_empty());
        assert!(water.windows(2).all(|w| w[0] == w[1]), "{water:?}");
        let others = (0..bsp.faces.len()).filter(|&f| face_texture(&bsp, f) != "*water1");
        assert!(
            others
                .into_iter()
                .all(|f| flags.get(f).is_none_or(|g| *g == FaceFlags::default()))
        );
        water[0]
    };
    let flags = |no_shadow, no_ambient| FaceFlags {
        no_shadow,
        no_ambient,
        ..FaceFlags::default()
    };
    assert_eq!(flagged("func_detail", ""), flags(false, false));
    assert_eq!(
        flagged("func_detail", "\"_noambient\" \"1\""),
        flags(false, true)
    );
    assert_eq!(
        flagged("func_group", "\"_shadow\" \"-1\""),
        flags(true, false)
    );
    assert_eq!(flagged("func_detail_illusionary", ""), flags(true, false));
    assert_eq!(
        flagged("func_detail_illusionary", "\"_shadow\" \"1\""),
        flags(false, false)
    );
    // A brush model's keys are light's to read from its entity.
    assert_eq!(
        flagged("func_wall", "\"_shadow\" \"-1\""),
        flags(false, false)
    );
}

/// A number key of an entity merged into the world reads as ericw-tools' `atof` reads it: the
/// number its value starts with (`"-1x"` is -1), with a warning naming the entity, its line,
/// the key and the value taken; a value that starts with no number is not set, and warns too.
#[test]
fn merged_entities_number_keys_read_as_far_as_the_number_goes() {
    let brush = box_brush([-32.0, -32.0, -128.0], [32.0, 32.0, -64.0], "*water1");
    let entity = format!(
        "{{\n\"classname\" \"func_detail\"\n\"_noambient\" \"1x\"\n\"_shadow\" \"off\"\n{brush}}}\n"
    );
    let out = compile_text(&room_map_with(false, "", &entity));
    let flags = out.bsp.face_flags().expect("lump").unwrap_or_default();
    let water = (0..out.bsp.faces.len())
        .find(|&f| face_texture(&out.bsp, f) == "*water1")
        .expect("a water face");
    let flag = flags.get(water).copied().unwrap_or_default();
    assert!(flag.no_ambient && !flag.no_shadow, "{flag:?}");
    let warned: Vec<String> = out.warnings.iter().map(|w| w.to_string()).collect();
    let about = |key: &str| warned.iter().find(|w| w.contains(key)).cloned();
    let noambient = about("\"_noambient\" \"1x\"").expect("a warning for _noambient");
    assert!(
        noambient.contains("entity 1") && noambient.contains("1, the number it starts with"),
        "{noambient}"
    );
    let shadow = about("\"_shadow\" \"off\"").expect("a warning for _shadow");
    assert!(shadow.contains("not set"), "{shadow}");
}

/// `_object_channel_mask` of an entity merged into the world reaches its faces through
/// `SLIPGATE_FACECHANNELS`; a brush model's stays in its entity for light; every face on
/// channel 1, no lump; a value that is not a whole number warns and leaves channel 1.
#[test]
fn merged_entities_light_channels_reach_their_faces() {
    let channels = |classname: &str, keys: &str| {
        let brush = box_brush([-32.0, -32.0, -128.0], [32.0, 32.0, -64.0], "wall2");
        let entity = format!("{{\n\"classname\" \"{classname}\"\n{keys}\n{brush}}}\n");
        let out = compile_text(&room_map_with(false, "", &entity));
        let masks = out.bsp.face_channels().expect("lump");
        let of_box = masks.map(|m| {
            let mut of: Vec<u32> = (0..out.bsp.faces.len())
                .filter(|&f| face_texture(&out.bsp, f) == "wall2")
                .map(|f| m[f])
                .collect();
            of.dedup();
            of
        });
        let warned = out
            .warnings
            .iter()
            .map(|w| w.to_string())
            .collect::<Vec<_>>();
        (of_box, warned)
    };
    assert_eq!(channels("func_detail", "").0, None);
    assert_eq!(
        channels("func_group", "\"_object_channel_mask\" \"8\"").0,
        Some(vec![8])
    );
    assert_eq!(
        channels("func_wall", "\"_object_channel_mask\" \"8\"").0,
        None,
        "light reads a brush model's own key"
    );
    let (none, warned) = channels("func_detail", "\"_object_channel_mask\" \"two\"");
    assert_eq!(none, None);
    assert!(
        warned
            .iter()
            .any(|w| w.contains("_object_channel_mask") && w.contains("channel, 1")),
        "{warned:?}"
    );
}

/// `_surflight_group` on worldspawn and the entities merged into it reaches their faces through
/// `SLIPGATE_SURFGROUP`; a brush model's stays in its entity for light; no group, no lump.
#[test]
fn merged_entities_surface_light_groups_reach_their_faces() {
    let groups = |world_keys: &str, classname: &str, keys: &str| {
        let brush = box_brush([-32.0, -32.0, -128.0], [32.0, 32.0, -64.0], "wall2");
        let entity = format!("{{\n\"classname\" \"{classname}\"\n{keys}\n{brush}}}\n");
        let out = compile_text(&room_map_with(false, world_keys, &entity));
        let bsp = out.bsp;
        let groups = bsp.surflight_groups().expect("lump")?;
        let of = |box_face: bool| {
            let mut g: Vec<i32> = (0..bsp.faces.len())
                .filter(|&f| (face_texture(&bsp, f) == "wall2") == box_face)
                .map(|f| groups[f])
                .collect();
            g.dedup();
            g
        };
        Some((of(true), of(false)))
    };
    assert_eq!(groups("", "func_detail", ""), None);
    assert_eq!(
        groups("", "func_detail", "\"_surflight_group\" \"3\""),
        Some((vec![3], vec![0]))
    );
    assert_eq!(
        groups(
            "\"_surflight_group\" \"2\"\n",
            "func_group",
            "\"_surflight_group\" \"-4\""
        ),
        Some((vec![-4], vec![2]))
    );
    assert_eq!(groups("", "func_wall", "\"_surflight_group\" \"3\""), None);
}

#[test]
fn a_surface_light_group_that_is_not_a_number_warns_and_leaves_none() {
    let brush = box_brush([-32.0, -32.0, -128.0], [32.0, 32.0, -64.0], "wall2");
    let entity =
        format!("{{\n\"classname\" \"func_group\"\n\"_surflight_group\" \"red\"\n{brush}}}\n");
    let out = compile_text(&room_map_with(false, "", &entity));
    let warned: Vec<String> = out.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        warned
            .iter()
            .any(|w| w.contains("\"_surflight_group\" \"red\"") && w.contains("no group")),
        "{warned:?}"
    );
    assert_eq!(out.bsp.surflight_groups().expect("lump"), None);
}
