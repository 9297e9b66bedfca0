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
