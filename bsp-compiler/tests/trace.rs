//! Walking the player's box (hull 1) and the shambler's (hull 2) through `maps/test/corridors.map`
//! with engine-style traces over the compiled clip nodes. Coordinates are those documented at the
//! top of the map and in `maps/README.md`.

use bsp_compiler::trace::{HullTrace, hull_point_contents, trace_hull};
use bsp_compiler::{CompileOptions, MapSource, compile};
use quake_formats::Bsp;
use quake_formats::bsp::contents::{EMPTY, SOLID};
use std::path::Path;

const PLAYER: usize = 1;
const SHAMBLER: usize = 2;
/// How high engines let a walking player step up.
const STEP: f32 = 18.0;
/// How far short of a plane traces stop.
const SLACK: f32 = 0.1;

fn corridors() -> Bsp {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps/test/corridors.map");
    let source = MapSource::read(&path).expect("maps/test/corridors.map");
    let out = compile(&source, &CompileOptions::default()).expect("compile");
    assert!(out.leak.is_none(), "{:?}", out.leak);
    out.bsp
}

fn trace(bsp: &Bsp, hull: usize, start: [f32; 3], end: [f32; 3]) -> HullTrace {
    let t = trace_hull(bsp, 0, hull, start, end);
    assert!(!t.start_solid, "trace from {start:?} starts in solid");
    t
}

fn near(a: [f32; 3], b: [f32; 3]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= SLACK)
}

/// Drop straight down until something holds the box.
fn fall(bsp: &Bsp, p: [f32; 3]) -> [f32; 3] {
    let t = trace(bsp, PLAYER, p, [p[0], p[1], p[2] - 1000.0]);
    assert!(t.fraction < 1.0, "fell out of the world from {p:?}");
    t.end
}

/// One walking move towards `to` (same height): straight ahead, else stepping up like engines.
fn walk(bsp: &Bsp, from: [f32; 3], to: [f32; 3]) -> [f32; 3] {
    let flat = trace(bsp, PLAYER, from, to);
    if flat.fraction == 1.0 {
        return fall(bsp, flat.end);
    }
    let up = trace(bsp, PLAYER, from, [from[0], from[1], from[2] + STEP]).end;
    let ahead = trace(bsp, PLAYER, up, [to[0], to[1], up[2]]).end;
    let stepped = fall(bsp, ahead);
    let progress = |p: [f32; 3]| (p[0] - from[0]).hypot(p[1] - from[1]);
    if progress(stepped) > progress(flat.end) {
        stepped
    } else {
        flat.end
    }
}

#[test]
fn the_player_stands_on_floors_and_is_kept_off_walls() {
    let bsp = corridors();
    let at = |x: f32, y: f32, z: f32| hull_point_contents(&bsp, 0, PLAYER, [x, y, z]);
    // Corridor A: the origin stands 24 above the floor, 16 from the walls, 32 below the ceiling.
    assert_eq!(at(100.0, 64.0, 24.5), EMPTY);
    assert_eq!(at(100.0, 64.0, 23.5), SOLID);
    assert_eq!(at(100.0, 16.5, 50.0), EMPTY);
    assert_eq!(at(100.0, 15.5, 50.0), SOLID);
    assert_eq!(at(100.0, 111.5, 50.0), EMPTY);
    assert_eq!(at(100.0, 112.5, 50.0), SOLID);
    assert_eq!(at(100.0, 64.0, 95.5), EMPTY);
    assert_eq!(at(100.0, 64.0, 96.5), SOLID);
    assert_eq!(at(15.5, 64.0, 50.0), SOLID);
    // The pillar, grown by 16, covers x 496..560 for y < 80.
    assert_eq!(at(528.0, 79.5, 50.0), SOLID);
    assert_eq!(at(528.0, 80.5, 50.0), EMPTY);
    assert_eq!(at(495.5, 32.0, 50.0), EMPTY);
    assert_eq!(at(496.5, 32.0, 50.0), SOLID);
    // Corridor B and its platform, 48 up.
    assert_eq!(at(1088.0, 600.0, 72.5), EMPTY);
    assert_eq!(at(1088.0, 600.0, 71.5), SOLID);
    assert_eq!(at(1136.5, 600.0, 80.0), SOLID);
    assert_eq!(at(1135.5, 600.0, 80.0), EMPTY);
    assert_eq!(at(1088.0, 1007.5, 80.0), EMPTY);
    assert_eq!(at(1088.0, 1008.5, 80.0), SOLID);
    // Outside the corridors, everything is solid (the outside was filled).
    for p in [
        [500.0, 500.0, 50.0],
        [-200.0, 64.0, 50.0],
        [100.0, 64.0, -300.0],
        [100.0, 64.0, 400.0],
    ] {
        assert_eq!(hull_point_contents(&bsp, 0, PLAYER, p), SOLID, "{p:?}");
    }
}

#[test]
fn falling_stops_on_the_floor_and_jumping_on_the_ceiling() {
    let bsp = corridors();
    for (x, y, floor) in [
        (100.0, 64.0, 24.0),
        (800.0, 100.0, 24.0),
        (1088.0, 200.0, 24.0),
        (1088.0, 700.0, 72.0),
    ] {
        let t = trace(&bsp, PLAYER, [x, y, 90.0], [x, y, -500.0]);
        assert!(near(t.end, [x, y, floor]), "fell to {:?}", t.end);
        assert_eq!(t.normal, [0.0, 0.0, 1.0]);
    }
    let t = trace(&bsp, PLAYER, [100.0, 64.0, 30.0], [100.0, 64.0, 500.0]);
    assert!(near(t.end, [100.0, 64.0, 96.0]), "jumped to {:?}", t.end);
}

#[test]
fn walls_and_the_pillar_stop_the_player() {
    let bsp = corridors();
    let z = 24.5;
    // North of the pillar the corridor is clear to its far end.
    let t = trace(&bsp, PLAYER, [32.0, 96.0, z], [1000.0, 96.0, z]);
    assert_eq!(t.fraction, 1.0, "stopped at {:?}", t.end);
    // South of it the pillar is in the way.
    let t = trace(&bsp, PLAYER, [32.0, 32.0, z], [1000.0, 32.0, z]);
    assert!(near(t.end, [496.0, 32.0, z]), "stopped at {:?}", t.end);
    assert_eq!(t.normal, [-1.0, 0.0, 0.0]);
    // Side walls, at a slant too.
    let t = trace(&bsp, PLAYER, [100.0, 64.0, z], [100.0, 400.0, z]);
    assert!(near(t.end, [100.0, 112.0, z]), "stopped at {:?}", t.end);
    let t = trace(&bsp, PLAYER, [100.0, 64.0, z], [148.0, 0.0, z]);
    assert!((t.end[1] - 16.0).abs() <= SLACK, "stopped at {:?}", t.end);
    // The end wall of corridor A, and corridor B's far wall.
    let t = trace(&bsp, PLAYER, [100.0, 64.0, z], [-100.0, 64.0, z]);
    assert!(near(t.end, [16.0, 64.0, z]), "stopped at {:?}", t.end);
    let t = trace(&bsp, PLAYER, [1088.0, 64.0, z], [1300.0, 64.0, z]);
    assert!(near(t.end, [1136.0, 64.0, z]), "stopped at {:?}", t.end);
}

#[test]
fn the_player_walks_round_the_corner_and_up_the_steps() {
    let bsp = corridors();
    let mut p = fall(&bsp, [64.0, 96.0, 30.0]);
    // Along corridor A past the pillar, into the corner, then up corridor B.
    for target in [[1088.0, 96.0], [1088.0, 900.0]] {
        for _ in 0..200 {
            let (dx, dy) = (target[0] - p[0], target[1] - p[1]);
            let len = dx.hypot(dy);
            if len < 1.0 {
                break;
            }
            let step = len.min(8.0);
            let next = [p[0] + dx / len * step, p[1] + dy / len * step, p[2]];
            let moved = walk(&bsp, p, next);
            assert!(moved != p, "stuck at {p:?} walking to {target:?}");
            p = moved;
        }
    }
    assert!(near(p, [1088.0, 900.0, 72.0]), "ended at {p:?}");
    // Without stepping, the first step stops the box.
    let t = trace(&bsp, PLAYER, [1088.0, 300.0, 24.5], [1088.0, 600.0, 24.5]);
    assert!(near(t.end, [1088.0, 368.0, 24.5]), "stopped at {:?}", t.end);
}

#[test]
fn the_shambler_box_is_bigger() {
    let bsp = corridors();
    let at = |x: f32, y: f32, z: f32| hull_point_contents(&bsp, 0, SHAMBLER, [x, y, z]);
    // 64 wide and 88 tall: in corridor A its origin has y 32..96 and z 24..64.
    assert_eq!(at(100.0, 64.0, 24.5), EMPTY);
    assert_eq!(at(100.0, 64.0, 23.5), SOLID);
    assert_eq!(at(100.0, 32.5, 40.0), EMPTY);
    assert_eq!(at(100.0, 31.5, 40.0), SOLID);
    assert_eq!(at(100.0, 64.0, 63.5), EMPTY);
    assert_eq!(at(100.0, 64.0, 64.5), SOLID);
    // The 64-unit gap beside the pillar leaves it no room: the pillar stops it at x 480.
    let t = trace_hull(&bsp, 0, SHAMBLER, [100.0, 90.0, 40.0], [1000.0, 90.0, 40.0]);
    assert!(near(t.end, [480.0, 90.0, 40.0]), "stopped at {:?}", t.end);
}
