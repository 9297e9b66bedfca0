//! Brush entities come back as brush entities: a door, and a rotating entity built around an
//! origin brush, keep their keys, their shapes and their textures.

mod common;

use common::{compile_text, contents_agreement, maps_dir, round_trip, side_agreement};
use decompile::{MapFormat, Options};
use glam::DVec3;
use quake_formats::entities::{Entity, parse_entities};

/// A box brush from `lo` to `hi`, every face `texture` (standard format).
fn block(lo: [i32; 3], hi: [i32; 3], texture: &str) -> String {
    let mut out = String::from("{\n");
    for axis in 0..3 {
        // On the face across `axis`: a corner and the corners along the next two axes, which
        // wind clockwise seen from outside in one order on the high face, the other on the low.
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for high in [true, false] {
            let mut corner = lo;
            corner[axis] = if high { hi[axis] } else { lo[axis] };
            let (mut along_u, mut along_v) = (corner, corner);
            along_u[u] = hi[u];
            along_v[v] = hi[v];
            let points = if high {
                [along_u, corner, along_v]
            } else {
                [along_v, corner, along_u]
            };
            for [x, y, z] in points {
                out += &format!("( {x} {y} {z} ) ");
            }
            out += &format!("{texture} 0 0 0 1 1\n");
        }
    }
    out + "}\n"
}

/// A closed room 512 x 256 x 192 with a door in a wall across it and a spinning block.
fn map() -> String {
    let mut world = String::new();
    world += &block([-16, -16, -16], [528, 272, 0], "floor1");
    world += &block([-16, -16, 192], [528, 272, 208], "wood1");
    world += &block([-16, -16, 0], [0, 272, 192], "brick1");
    world += &block([512, -16, 0], [528, 272, 192], "brick1");
    world += &block([0, -16, 0], [512, 0, 192], "brick1");
    world += &block([0, 256, 0], [512, 272, 192], "brick1");
    // A wall across the room with a doorway from y 96 to 160.
    world += &block([248, 0, 0], [264, 96, 192], "metal1");
    world += &block([248, 160, 0], [264, 256, 192], "metal1");
    world += &block([248, 96, 128], [264, 160, 192], "metal1");
    let door = block([252, 96, 0], [260, 160, 128], "door1");
    let spinner = block([352, 96, 32], [416, 160, 96], "metal1")
        + &block([376, 120, 56], [392, 136, 72], "origin");
    format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"slipgate.wad\"\n{world}}}\n\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"64 128 24\"\n}}\n\
         {{\n\"classname\" \"func_door\"\n\"angle\" \"-1\"\n\"speed\" \"120\"\n\"targetname\" \"gate\"\n{door}}}\n\
         {{\n\"classname\" \"rotate_object\"\n\"targetname\" \"spin\"\n\"rotate\" \"0 90 0\"\n{spinner}}}\n"
    )
}

fn entity_with<'a>(entities: &'a [Entity], classname: &str) -> (usize, &'a Entity) {
    entities
        .iter()
        .enumerate()
        .find(|(_, e)| e.classname() == classname)
        .unwrap_or_else(|| panic!("no {classname}"))
}

#[test]
fn a_door_and_a_rotating_entity_come_back_with_their_keys() {
    let original = compile_text(&maps_dir().join("decompile_entities.map"), map());
    let before = parse_entities(&original.bsp.entity_text()).expect("entities");
    for format in [MapFormat::Quake, MapFormat::Valve] {
        let options = Options {
            format,
            ..Options::default()
        };
        let (decompiled, again) =
            round_trip(&original.bsp, &options, "decompile_entities-decompiled.map");
        let map =
            bsp_compiler::map::parse_map(std::path::Path::new("decompiled.map"), &decompiled.text)
                .expect("the decompiled map parses");
        let after = parse_entities(&again.bsp.entity_text()).expect("entities");
        for classname in ["func_door", "rotate_object"] {
            let (index, was) = entity_with(&before, classname);
            let (_, now) = entity_with(&after, classname);
            // The decompiled entity: its keys, without the compiler's model number, and brushes.
            let written = &map.entities[index];
            assert_eq!(written.entity.classname(), classname);
            for (key, value) in &was.pairs {
                match key.as_str() {
                    "model" => assert_eq!(written.entity.get("model"), None),
                    _ => assert_eq!(
                        written.entity.get(key),
                        Some(value.as_str()),
                        "{classname} {key}"
                    ),
                }
            }
            assert!(!written.brushes.is_empty(), "{classname} has no brushes");
            // Recompiled: the same keys (the compiler may put `model` elsewhere), and a model of
            // the same contents.
            let sorted = |e: &Entity| {
                let mut pairs = e.pairs.clone();
                pairs.sort();
                pairs
            };
            assert_eq!(sorted(was), sorted(now), "{classname}'s keys changed");
            let model: usize = now
                .get("model")
                .and_then(|m| m[1..].parse().ok())
                .expect("model");
            let contents = contents_agreement(&original.bsp, &again.bsp, model, 5_000, 0.05);
            let origin = DVec3::from(now.get_floats::<3>("origin").unwrap_or([0.0; 3]));
            let sides = side_agreement(&original.bsp, model, &decompiled.text, index, origin);
            eprintln!("{classname} ({format:?}): contents {contents:?}\n  brush sides {sides:?}");
            assert_eq!(contents.far, 0, "{classname}: contents differ");
            assert_eq!(
                sides.same_projection,
                sides.compared(),
                "{classname}: textures differ"
            );
        }
        // The rotating entity is built around its origin brush, at the centre of which the
        // compiler put its origin; the decompiled map has one there.
        let (index, spinner) = entity_with(&before, "rotate_object");
        assert_eq!(spinner.get("origin"), Some("384 128 64"));
        let origin_brushes: Vec<_> = map.entities[index]
            .brushes
            .iter()
            .filter(|b| b.faces.iter().all(|f| f.texture == "origin"))
            .collect();
        assert_eq!(origin_brushes.len(), 1, "one origin brush");
        assert_eq!(decompiled.stats.brush_entities, 3);
    }
}
