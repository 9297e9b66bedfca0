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
