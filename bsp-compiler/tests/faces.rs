//! Which faces a compile makes and where it lists them, in the cases where id's and ericw-tools'
//! compilers settle it: coplanar brush faces, detail in water, edges across contents, fences.

mod common;

use common::*;

const UP: Option<[f32; 3]> = Some([0.0, 0.0, 1.0]);

/// A button set into the floor, its top flush with the floor's: the later brush's face wins, in
/// the world and in a brush entity, as in id's qbsp and ericw-tools (`brushClippingOrder`).
#[test]
fn a_later_brushs_coplanar_face_wins() {
    let button = box_brush([-16.0, -16.0, -136.0], [16.0, 16.0, -128.0], "button");
    let slab = box_brush([32.0, 32.0, -128.0], [96.0, 96.0, -112.0], "slab");
    let wall_button = box_brush([48.0, 48.0, -120.0], [64.0, 64.0, -112.0], "button");
    let text = room_map_with(
        false,
        &button,
        &brush_entity("func_wall", &format!("{slab}{wall_button}")),
    );
    let out = compile_text(&text);
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    for (model, p) in [(0, [0.0, 0.0, -128.0]), (1, [56.0, 56.0, -112.0])] {
        let found = faces_at(bsp, model, p, UP);
        let names: Vec<String> = found.iter().map(|&f| face_texture(bsp, f)).collect();
        assert_eq!(names, ["button"], "model {model}");
    }
    // The rest of the floor and the slab's top keep their own texture.
    let floor = faces_at(bsp, 0, [-64.0, -64.0, -128.0], UP);
    assert_eq!(face_texture(bsp, floor[0]), "floor");
    let top = faces_at(bsp, 1, [88.0, 88.0, -112.0], UP);
    assert_eq!(face_texture(bsp, top[0]), "slab");
}

/// Two brushes side by side with their tops flush, textured differently: each keeps its own
/// texture on its own part of the plane, in the world and in a brush entity (one face does not
/// take one brush's texture across both).
#[test]
fn flush_brushes_keep_their_own_textures() {
    let left = box_brush([-128.0, -128.0, -128.0], [0.0, 128.0, -112.0], "tile_a");
    let right = box_brush([0.0, -128.0, -128.0], [128.0, 128.0, -112.0], "tile_b");
    let step_a = box_brush([-64.0, -64.0, -112.0], [0.0, 0.0, -96.0], "step_a");
    let step_b = box_brush([0.0, -64.0, -112.0], [64.0, 0.0, -96.0], "step_b");
    let text = room_map_with(
        false,
        &format!("{left}{right}"),
        &brush_entity("func_wall", &format!("{step_a}{step_b}")),
    );
    let out = compile_text(&text);
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    for (model, p, name) in [
        (0, [-96.0, 64.0, -112.0], "tile_a"),
        (0, [96.0, 64.0, -112.0], "tile_b"),
        (1, [-32.0, -32.0, -96.0], "step_a"),
        (1, [32.0, -32.0, -96.0], "step_b"),
    ] {
        let found = faces_at(bsp, model, p, UP);
        let names: Vec<String> = found.iter().map(|&f| face_texture(bsp, f)).collect();
        assert_eq!(names, [name], "model {model} at {p:?}");
    }
}

/// A `func_detail_illusionary` block standing in water up through its surface keeps its faces
/// below the water line, outward and (with `_mirrorinside`) inward, and is water inside there, as
/// in ericw-tools (`waterDetailIllusionary`).
#[test]
fn illusionary_detail_keeps_its_faces_under_water() {
    let water = box_brush([-128.0, -128.0, -128.0], [128.0, 128.0, 0.0], "*water");
    let block = box_brush([0.0, 0.0, -128.0], [64.0, 64.0, 128.0], "{vine");
    for mirror in [false, true] {
        let key = if mirror {
            "\"_mirrorinside\" \"1\"\n"
        } else {
            ""
        };
        let entity = format!("{{\n\"classname\" \"func_detail_illusionary\"\n{key}{block}}}\n");
        let out = compile_text(&room_map_with(false, &water, &entity));
        let bsp = &out.bsp;
        assert_eq!(errors(bsp), Vec::<String>::new());
        assert!(out.leak.is_none(), "{:?}", out.warnings);
        let contents_at = |p| bsp.leafs[bsp.leaf_at(p).expect("leaf")].contents;
        assert_eq!(
            contents_at([32.0, 32.0, -64.0]),
            quake_formats::bsp::contents::WATER
        );
        assert_eq!(
            contents_at([32.0, 32.0, 64.0]),
            quake_formats::bsp::contents::EMPTY
        );
        for z in [-64.0, 64.0] {
            let outward = faces_at(bsp, 0, [0.0, 32.0, z], Some([-1.0, 0.0, 0.0]));
            let names: Vec<String> = outward.iter().map(|&f| face_texture(bsp, f)).collect();
            assert_eq!(names, ["{vine"], "z {z}, mirror {mirror}");
            let inward = faces_at(bsp, 0, [0.0, 32.0, z], Some([1.0, 0.0, 0.0]));
            let names: Vec<String> = inward.iter().map(|&f| face_texture(bsp, f)).collect();
            let expected: &[&str] = if mirror { &["{vine"] } else { &[] };
            assert_eq!(names, expected, "z {z}, mirror {mirror}");
        }
        // The water's surface runs on through the block, seen from above and below.
        for normal in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]] {
            let surface = faces_at(bsp, 0, [32.0, 32.0, 0.0], Some(normal));
            let names: Vec<String> = surface.iter().map(|&f| face_texture(bsp, f)).collect();
            assert_eq!(names, ["*water"], "{normal:?}, mirror {mirror}");
        }
    }
}

/// The contents a face of `bsp` is seen from: those just in front of its middle.
fn seen_from(bsp: &quake_formats::Bsp, f: usize) -> i32 {
    let vs = bsp.face_vertices(&bsp.faces[f]).expect("vertices");
    let n = face_normal(bsp, f);
    let mut c = [0.0f32; 3];
    for v in &vs {
        for i in 0..3 {
            c[i] += v[i] / vs.len() as f32;
        }
    }
    let p = [c[0] + n[0] * 0.5, c[1] + n[1] * 0.5, c[2] + n[2] * 0.5];
    bsp.leafs[bsp.leaf_at(p).expect("leaf")].contents
}

/// Software renderers (WinQuake's edge list) draw a face wrongly when it shares an edge with a
/// face seen from other contents (a water surface and its mirror seen from below), or when an
/// edge is used more than once each way. As id's qbsp and ericw-tools (`liquidSoftware`,
/// `edgeSharingSoftware`), edges are shared only between faces seen from the same contents.
#[test]
fn edges_are_shared_only_between_faces_seen_from_the_same_contents() {
    let pool = box_brush([-128.0, -128.0, -128.0], [0.0, 128.0, -64.0], "*water");
    let pillar = box_brush([32.0, 32.0, -128.0], [64.0, 64.0, 128.0], "pillar");
    let out = compile_text(&room_map(false, &format!("{pool}{pillar}")));
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert!(out.leak.is_none() && out.stats.filled_leaves > 0);
    let mut users: std::collections::HashMap<i32, Vec<usize>> = Default::default();
    for (f, face) in bsp.faces.iter().enumerate() {
        let first = face.first_edge as usize;
        for &se in &bsp.surfedges[first..first + face.num_edges as usize] {
            users.entry(se).or_default().push(f);
        }
    }
    let mut shared = 0;
    for (&se, faces) in &users {
        assert_eq!(
            faces.len(),
            1,
            "edge {se} used twice the same way: {faces:?}"
        );
        let Some(back) = users.get(&-se) else {
            continue;
        };
        shared += 1;
        assert_eq!(
            seen_from(bsp, faces[0]),
            seen_from(bsp, back[0]),
            "edge {se} of faces {} and {}",
            faces[0],
            back[0]
        );
    }
    assert!(shared > 0, "no edge is shared at all");
    // The water's surface is drawn from above and below.
    let up = faces_at(bsp, 0, [-64.0, 64.0, -64.0], Some([0.0, 0.0, 1.0]));
    let down = faces_at(bsp, 0, [-64.0, 64.0, -64.0], Some([0.0, 0.0, -1.0]));
    assert_eq!((up.len(), down.len()), (1, 1));
}

/// The BSP leaves whose marksurfaces list face `f`.
fn leaves_listing(bsp: &quake_formats::Bsp, f: usize) -> Vec<usize> {
    (0..bsp.leafs.len())
        .filter(|&l| {
            let leaf = &bsp.leafs[l];
            let first = leaf.first_marksurface as usize;
            bsp.marksurfaces[first..first + leaf.num_marksurfaces as usize].contains(&(f as u32))
        })
        .collect()
}

/// A fence filling a niche in the -x wall, cut in two by a hint: the niche's back wall is seen
/// only from the fence's back leaf, which is solid to engines (they never draw from it) and
/// borders no open leaf. Faces seen from a fence are listed in the open leaves its leaves border
/// (flooding through the fence), which grow to hold them, and not in the fence's own leaves, as
/// in ericw-tools (`detailFence`).
#[test]
fn faces_seen_through_a_fence_are_listed_in_the_open_leaves_around_it() {
    let t = |lo: [f64; 3], hi: [f64; 3], tex: &str| box_brush(lo, hi, tex);
    let (a, b) = (-144.0, 144.0);
    // The room of `room`, its -x wall holding a niche x -192..-128, y -32..32, z -128..-64.
    let mut world = String::new();
    world += &t([a, a, a], [b, b, -128.0], "floor");
    world += &t([a, a, 128.0], [b, b, b], "ceiling");
    world += &t([128.0, a, -128.0], [b, b, 128.0], "wall");
    world += &t([-128.0, a, -128.0], [128.0, -128.0, 128.0], "wall");
    world += &t([-128.0, 128.0, -128.0], [128.0, b, 128.0], "wall");
    world += &t([-208.0, a, -128.0], [-128.0, -32.0, 128.0], "wall");
    world += &t([-208.0, 32.0, -128.0], [-128.0, b, 128.0], "wall");
    world += &t([-208.0, -32.0, -64.0], [-128.0, 32.0, 128.0], "wall");
    world += &t([-208.0, -32.0, -128.0], [-192.0, 32.0, -64.0], "niche");
    world += &t([-208.0, -32.0, -144.0], [-144.0, 32.0, -128.0], "floor");
    // A hint across the niche at x = -160; its other faces do not split.
    world += "{\n( -160 -32 -128 ) ( -160 -32 -64 ) ( -160 32 -128 ) hint 0 0 0 1 1\n\
              ( -176 -32 -128 ) ( -176 32 -128 ) ( -176 -32 -64 ) hintskip 0 0 0 1 1\n\
              ( -176 32 -128 ) ( -160 32 -128 ) ( -176 32 -64 ) hintskip 0 0 0 1 1\n\
              ( -176 -32 -128 ) ( -176 -32 -64 ) ( -160 -32 -128 ) hintskip 0 0 0 1 1\n\
              ( -176 -32 -64 ) ( -176 32 -64 ) ( -160 -32 -64 ) hintskip 0 0 0 1 1\n\
              ( -176 -32 -128 ) ( -160 -32 -128 ) ( -176 32 -128 ) hintskip 0 0 0 1 1\n}\n";
    let fence = t([-192.0, -32.0, -128.0], [-128.0, 32.0, -64.0], "{fence");
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"none.wad\"\n{world}}}\n{}\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"0 0 -100\"\n}}\n",
        brush_entity("func_detail_fence", &fence)
    );
    let out = compile_text(&text);
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert!(out.leak.is_none(), "{:?}", out.warnings);
    let contents = quake_formats::bsp::contents::SOLID;
    // The fence is cut in two, both solid leaves of their own.
    let back = bsp.leaf_at([-176.0, 0.0, -96.0]).expect("leaf");
    let front = bsp.leaf_at([-144.0, 0.0, -96.0]).expect("leaf");
    assert!(back != front && back != 0 && front != 0, "{back} {front}");
    for l in [back, front] {
        assert_eq!(bsp.leafs[l].contents, contents);
        assert_eq!(bsp.leafs[l].num_marksurfaces, 0, "leaf {l}");
    }
    let niche = faces_at(bsp, 0, [-192.0, 0.0, -96.0], Some([1.0, 0.0, 0.0]));
    assert_eq!(niche.len(), 1);
    let listed = leaves_listing(bsp, niche[0]);
    assert!(!listed.is_empty());
    for l in listed {
        let leaf = &bsp.leafs[l];
        assert_ne!(leaf.contents, contents, "leaf {l}");
        // Grown to hold the face, for engines that cull leaves by their bounds.
        assert!(
            leaf.mins[0] <= -192.0 && leaf.maxs[0] >= -128.0,
            "leaf {l}: {leaf:?}"
        );
    }
    // Every face is listed in an open leaf.
    for f in 0..bsp.faces.len() {
        let open = leaves_listing(bsp, f)
            .iter()
            .any(|&l| bsp.leafs[l].contents != contents);
        assert!(open, "face {f} ({})", face_texture(bsp, f));
    }
}

/// A box brush textured `skip` but for its face `face` (0..6: +x, -x, +y, -y, +z, -z), which
/// gets `texture`.
fn box_with_face(mins: [f64; 3], maxs: [f64; 3], face: usize, texture: &str) -> String {
    let mut lines: Vec<String> = box_brush(mins, maxs, "skip")
        .lines()
        .map(String::from)
        .collect();
    // Line 0 is the opening brace.
    lines[face + 1] = lines[face + 1].replace("skip", texture);
    lines.join("\n") + "\n"
}

/// A brush entity of class `classname`, with `_noclipfaces 1` when `no_clip` and the extra keys
/// `keys` (lines of `"key" "value"`), holding `brushes`.
fn entity_with(classname: &str, no_clip: bool, keys: &str, brushes: &str) -> String {
    let key = if no_clip {
        "\"_noclipfaces\" \"1\"\n"
    } else {
        ""
    };
    format!("{{\n\"classname\" \"{classname}\"\n{key}{keys}{brushes}}}\n")
}

/// The faces of model 0 textured `texture`.
fn textured(bsp: &quake_formats::Bsp, texture: &str) -> Vec<usize> {
    (0..bsp.models[0].num_faces as usize)
        .map(|f| f + bsp.models[0].first_face as usize)
        .filter(|&f| face_texture(bsp, f) == texture)
        .collect()
}

const MINUS_Y: Option<[f32; 3]> = Some([0.0, -1.0, 0.0]);

/// `text` compiled, with no BSP errors and no leak (`case` names the case in failures).
fn compile_sealed(text: &str, case: &str) -> bsp_compiler::CompileOutput {
    let out = compile_text(text);
    assert_eq!(errors(&out.bsp), Vec::<String>::new(), "{case}");
    assert!(out.leak.is_none(), "{case}: {:?}", out.warnings);
    out
}

/// The textures of model `model`'s faces holding `p`, seen along `normal` ([`faces_at`]).
fn textures_at(
    bsp: &quake_formats::Bsp,
    model: usize,
    p: [f32; 3],
    normal: [f32; 3],
) -> Vec<String> {
    faces_at(bsp, model, p, Some(normal))
        .iter()
        .map(|&f| face_texture(bsp, f))
        .collect()
}

/// A T of two `func_detail_illusionary` brushes, each with one `{trigger` face (the bar's facing
/// the stem, the stem's at its far end), the rest skip: with `_noclipfaces` the bar's face is
/// kept whole where the stem touches it, one face, as in ericw-tools (`noclipfaces`); with
/// `_mirrorinside` too each face is also drawn from inside (`noclipfacesMirrorinside`). Without
/// the key the stem clips the bar's face around the contact.
#[test]
fn noclipfaces_keeps_the_face_a_brush_of_its_contents_touches() {
    let bar = box_with_face([-64.0, 0.0, -64.0], [64.0, 8.0, 0.0], 3, "{trigger");
    let stem = box_with_face([-4.0, -64.0, -64.0], [4.0, 0.0, 0.0], 3, "{trigger");
    for (no_clip, mirror) in [(true, false), (true, true), (false, false)] {
        let keys = if mirror {
            "\"_mirrorinside\" \"1\"\n"
        } else {
            ""
        };
        let entity = entity_with(
            "func_detail_illusionary",
            no_clip,
            keys,
            &format!("{stem}{bar}"),
        );
        let case = format!("_noclipfaces {no_clip}, _mirrorinside {mirror}");
        let out = compile_sealed(&room_map_with(false, "", &entity), &case);
        let bsp = &out.bsp;
        let contact = faces_at(bsp, 0, [0.0, 0.0, -32.0], MINUS_Y);
        if !no_clip {
            assert_eq!(contact, Vec::<usize>::new(), "{case}");
            continue;
        }
        let expected = if mirror { 4 } else { 2 };
        assert_eq!(textured(bsp, "{trigger").len(), expected, "{case}");
        // Whole: the same face on both sides of the contact and across it.
        assert_eq!(contact.len(), 1, "{case}");
        for x in [-48.0, 48.0] {
            assert_eq!(
                faces_at(bsp, 0, [x, 0.0, -32.0], MINUS_Y),
                contact,
                "{case}"
            );
        }
        let inside = faces_at(bsp, 0, [0.0, 0.0, -32.0], Some([0.0, 1.0, 0.0]));
        assert_eq!(inside.len(), usize::from(mirror), "{case}");
    }
}

/// Two `func_detail_wall` boxes touching, the first with `_noclipfaces`: both faces at the
/// junction are kept, each box's own, as if both had the key (ericw-tools'
/// `noclipfacesJunction`); without the key neither is.
#[test]
fn noclipfaces_keeps_both_faces_where_it_meets_a_plain_entity() {
    let first = box_brush([-64.0, -32.0, -64.0], [0.0, 32.0, 0.0], "{trigger");
    let second = box_brush([0.0, -32.0, -64.0], [64.0, 32.0, 0.0], "blood1");
    for no_clip in [true, false] {
        let entities = entity_with("func_detail_wall", no_clip, "", &first)
            + &entity_with("func_detail_wall", false, "", &second);
        let out = compile_sealed(&room_map_with(false, "", &entities), &no_clip.to_string());
        let bsp = &out.bsp;
        let junction = |normal: [f32; 3]| textures_at(bsp, 0, [0.0, 0.0, -32.0], normal);
        let kept = if no_clip { 6 } else { 5 };
        assert_eq!(textured(bsp, "{trigger").len(), kept, "{no_clip}");
        assert_eq!(textured(bsp, "blood1").len(), kept, "{no_clip}");
        if no_clip {
            assert_eq!(junction([1.0, 0.0, 0.0]), ["{trigger"]);
            assert_eq!(junction([-1.0, 0.0, 0.0]), ["blood1"]);
        } else {
            assert_eq!(junction([1.0, 0.0, 0.0]), Vec::<String>::new());
            assert_eq!(junction([-1.0, 0.0, 0.0]), Vec::<String>::new());
        }
    }
}

/// A cross of two `func_detail_illusionary` brushes overlapping: with `_noclipfaces` each keeps
/// its faces inside the other (ericw-tools' `detailIllusionaryNoclipfacesIntersecting`), without
/// it they are clipped away (`detailIllusionaryIntersecting`); the top where both lie is drawn
/// either way.
#[test]
fn noclipfaces_keeps_faces_inside_an_overlapping_brush() {
    let along_y = box_brush([-4.0, -64.0, -64.0], [4.0, 64.0, 0.0], "{trigger");
    let along_x = box_brush([-64.0, -4.0, -64.0], [64.0, 4.0, 0.0], "{trigger");
    for no_clip in [true, false] {
        let entity = entity_with(
            "func_detail_illusionary",
            no_clip,
            "",
            &format!("{along_y}{along_x}"),
        );
        let out = compile_sealed(&room_map_with(false, "", &entity), &no_clip.to_string());
        let bsp = &out.bsp;
        let interior = faces_at(bsp, 0, [0.0, -4.0, -32.0], MINUS_Y);
        assert_eq!(interior.len(), usize::from(no_clip), "{no_clip}");
        let top = faces_at(bsp, 0, [0.0, 2.0, 0.0], UP).len();
        assert!((1..=2).contains(&top), "{no_clip}: {top} faces on top");
    }
}

/// The panes of a translucent `func_wall` touching end to end, with `_noclipfaces`: the face of
/// each where the other meets it is kept in the entity's model.
#[test]
fn noclipfaces_keeps_faces_between_a_func_walls_panes() {
    let left = box_brush([-64.0, -2.0, -96.0], [0.0, 2.0, -32.0], "glass_a");
    let right = box_brush([0.0, -2.0, -96.0], [64.0, 2.0, -32.0], "glass_b");
    for no_clip in [true, false] {
        let entity = entity_with(
            "func_wall",
            no_clip,
            "\"alpha\" \"0.5\"\n",
            &format!("{left}{right}"),
        );
        let out = compile_sealed(&room_map_with(false, "", &entity), &no_clip.to_string());
        let bsp = &out.bsp;
        for (normal, name) in [([1.0, 0.0, 0.0], "glass_a"), ([-1.0, 0.0, 0.0], "glass_b")] {
            let names = textures_at(bsp, 1, [0.0, 0.0, -64.0], normal);
            let expected: &[&str] = if no_clip { &[name] } else { &[] };
            assert_eq!(names, expected, "{no_clip}");
        }
    }
}
