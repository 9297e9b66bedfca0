//! Maps compiled, decompiled and compiled again: the second BSP must be sealed, built from good
//! brushes, hold the same contents as the first (away from leaf boundaries) and show the same
//! textures.

mod common;

use common::{
    compile_file, contents_agreement, maps_dir, round_trip, side_agreement, texture_agreement,
};
use decompile::{MapFormat, Options};
use glam::DVec3;

/// Points sampled through the world's bounds.
const SAMPLES: usize = 20_000;

/// A disagreement this close to a leaf boundary of either tree is the planes' rounding: the
/// written planes are the BSP's within the compiler's epsilons (0.001 in distance, 1e-6 per
/// normal component, so a few thousandths across a large map).
const BOUNDARY_TOLERANCE: f64 = 0.05;

/// Texture offsets may move by the compiler's lightmap-grid nudges (an eighth of a texel at
/// most) each time a map is compiled.
const OFFSET_TOLERANCE: f64 = 0.25;

/// The share of the recompiled map's faces that must show the original's texture and projection.
/// The decompiled brush sides carry every face's texture exactly (checked above); the compiler
/// textures each leaf's face on a plane from the first brush side it finds there, so where two
/// flush brushes of one leaf show different textures on one plane one of them wins.
const MIN_RECOMPILED_TEXTURES: f64 = 0.9;

fn check(map: &str, format: MapFormat) {
    let path = maps_dir().join(map);
    let original = compile_file(&path);
    let options = Options {
        format,
        ..Options::default()
    };
    let name = format!(
        "{}-decompiled.map",
        map.replace('/', "_").trim_end_matches(".map")
    );
    let (decompiled, again) = round_trip(&original.bsp, &options, &name);
    let agreement = contents_agreement(&original.bsp, &again.bsp, 0, SAMPLES, BOUNDARY_TOLERANCE);
    let sides = side_agreement(&original.bsp, 0, &decompiled.text, 0, DVec3::ZERO);
    let textures = texture_agreement(&original.bsp, &again.bsp, 0, OFFSET_TOLERANCE);
    eprintln!(
        "{map} ({format:?}): {:?}\n  contents: {agreement:?}\n  brush sides: {sides:?}\n  recompiled textures: {textures:?}",
        decompiled.stats
    );
    assert_eq!(
        agreement.far, 0,
        "{map}: contents differ away from boundaries"
    );
    assert_eq!(
        sides.same_projection,
        sides.compared(),
        "{map}: brush sides do not carry their faces' textures"
    );
    assert_eq!(textures.unmatched, 0, "{map}: faces lost");
    assert!(
        textures.same_projection as f64 >= MIN_RECOMPILED_TEXTURES * textures.compared() as f64,
        "{map}: too few recompiled faces keep their texture"
    );
}

#[test]
fn demo_map_round_trips() {
    check("demo.map", MapFormat::Quake);
}

#[test]
fn demo_map_round_trips_in_valve_220() {
    check("demo.map", MapFormat::Valve);
}

#[test]
fn seal_seams_round_trips() {
    check("hard/seal_seams.map", MapFormat::Quake);
}

/// A box brush from `lo` to `hi` in the standard format, every face `texture` with the given
/// offsets, rotation and scales.
fn textured_block(lo: [i32; 3], hi: [i32; 3], texture: &str) -> String {
    let [a, b, c] = lo;
    let [x, y, z] = hi;
    let planes = [
        [[a, b, c], [a, y, c], [a, b, z]],
        [[x, b, c], [x, b, z], [x, y, c]],
        [[a, b, c], [a, b, z], [x, b, c]],
        [[a, y, c], [x, y, c], [a, y, z]],
        [[a, b, c], [x, b, c], [a, y, c]],
        [[a, b, z], [a, y, z], [x, b, z]],
    ];
    let mut out = String::from("{\n");
    for points in planes {
        for [px, py, pz] in points {
            out += &format!("( {px} {py} {pz} ) ");
        }
        out += &format!("{texture}\n");
    }
    out + "}\n"
}

/// ericw-tools' `q1DecompilerTest`, restated on a room of our own whose floor is two brushes of
/// different textures and projections, and whose walls overlap unevenly (one reaches below the
/// floor and past the far wall, another down into the floor): the decompiled map has a brush
/// for each wall, the ceiling and each floor brush, and compiles back to the same models,
/// leaves and nodes (ericw-tools: 6 nodes, 2 leaves), every world face found again at its
/// centre with the same texture axes.
#[test]
fn a_room_decompiles_to_its_brushes_and_compiles_back_the_same() {
    let world = [
        textured_block([-144, -128, -32], [-128, 144, 128], "brick1 0 0 0 1 1"),
        textured_block([128, -128, 0], [144, 128, 128], "brick1 8 0 0 1 1"),
        textured_block([-128, -144, 0], [128, -128, 128], "brick1 0 0 45 1 1"),
        textured_block([-128, 128, -8], [144, 144, 128], "brick1 0 0 0 0.5 1"),
        textured_block([-128, -128, 128], [128, 128, 136], "metal1 0 0 0 1 1"),
        textured_block([-128, -128, -16], [128, 0, 0], "floor1 16 8 90 2 2"),
        textured_block([-128, 0, -16], [128, 128, 0], "wood1 0 0 0 1 0.5"),
    ]
    .concat();
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"slipgate.wad\"\n{world}}}\n\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"-64 -64 24\"\n}}\n\
         {{\n\"classname\" \"light\"\n\"origin\" \"64 64 96\"\n}}\n"
    );
    let original = common::compile_text(&maps_dir().join("decompiler-room.map"), text);
    let bsp = &original.bsp;
    let (decompiled, again) =
        round_trip(bsp, &Options::default(), "decompiler-room-decompiled.map");
    assert_eq!(decompiled.stats.brushes, 7, "{}", decompiled.text);
    let back = &again.bsp;
    assert_eq!((bsp.nodes.len(), bsp.leafs.len()), (6, 2));
    assert_eq!(
        (back.models.len(), back.leafs.len(), back.nodes.len()),
        (bsp.models.len(), bsp.leafs.len(), bsp.nodes.len())
    );
    let recompiled = common::faces(back, 0);
    for face in common::faces(bsp, 0) {
        let centre = face.centre();
        let found = recompiled
            .iter()
            .find(|f| f.plane.normal.dot(face.plane.normal) > 0.999 && f.holds(centre, 0.01))
            .unwrap_or_else(|| panic!("no face at {centre} facing {}", face.plane.normal));
        assert_eq!(found.texture, face.texture, "at {centre}");
        let axes = |rows: &[[f64; 4]; 2]| rows.map(|r| [r[0], r[1], r[2]]);
        assert_eq!(axes(&found.rows), axes(&face.rows), "at {centre}");
    }
}
