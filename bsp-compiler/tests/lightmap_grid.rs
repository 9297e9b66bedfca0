//! QuakeSpasm and DarkPlaces must size every lit face's lightmap alike: the compiler nudges
//! texture offsets where their precision would snap a face to different grid lines.

mod common;

use common::*;

use bsp_compiler::lightmap_grid::NUDGE_STEPS;
use bsp_compiler::{CompileOptions, MapSource, compile};
use quake_formats::bsp::Rule;
use quake_formats::{Bsp, validate};
use std::fmt::Write;
use std::path::Path;

const DEGREES: f64 = 10.0;

fn disagreements(bsp: &Bsp) -> Vec<String> {
    validate(bsp)
        .into_iter()
        .filter(|p| p.rule == Rule::LightmapExtentsEnginesDisagree)
        .map(|p| p.to_string())
        .collect()
}

/// A Valve 220 face line through three points with texture axes `u` and `v` (offsets 0).
fn valve_face(points: [[f64; 3]; 3], u: [f64; 3], v: [f64; 3], rotation: f64) -> String {
    let mut s = String::new();
    for p in points {
        write!(s, "( {:?} {:?} {:?} ) ", p[0], p[1], p[2]).expect("write");
    }
    writeln!(
        s,
        "crate [ {:?} {:?} {:?} 0 ] [ {:?} {:?} {:?} 0 ] {rotation} 1 1",
        u[0], u[1], u[2], v[0], v[1], v[2]
    )
    .expect("write");
    s
}

/// A crate turned `DEGREES` about z, textured with the texture turned with it (as an editor's
/// texture lock leaves it): its corners lie on the 16-texel grid in exact arithmetic, so their
/// texture coordinates, computed from `f32` vertices, land within a few `f32` steps of grid
/// lines. `a` and `b` are its corner's texture coordinates, multiples of 16.
fn rotated_crate(a: f64, b: f64, size: f64, height: f64) -> String {
    let (sin, cos) = DEGREES.to_radians().sin_cos();
    let s_axis = [cos, -sin, 0.0];
    let t_axis = [-sin, -cos, 0.0];
    let world = |a: f64, b: f64| [a * s_axis[0] + b * t_axis[0], a * s_axis[1] + b * t_axis[1]];
    let corners = [
        world(a, b),
        world(a + size, b),
        world(a + size, b + size),
        world(a, b + size),
    ];
    let at = |c: [f64; 2], z: f64| [c[0], c[1], z];
    let mut s = String::from("{\n");
    for k in 0..4 {
        let (p, q) = (corners[k], corners[(k + 1) % 4]);
        let len = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
        let along = [(q[0] - p[0]) / len, (q[1] - p[1]) / len, 0.0];
        let points = [at(p, 0.0), at(q, 0.0), at(p, height)];
        s += &valve_face(points, along, [0.0, 0.0, -1.0], 0.0);
    }
    let [c0, c1, c2, _] = corners;
    let top = [at(c0, height), at(c1, height), at(c2, height)];
    s += &valve_face(top, s_axis, t_axis, DEGREES);
    let bottom = [at(c0, 0.0), at(c2, 0.0), at(c1, 0.0)];
    s += &valve_face(bottom, s_axis, t_axis, DEGREES);
    s + "}\n"
}

/// A room far from the origin (where `f32` steps are coarser) holding a field of crates turned
/// 10 degrees, like LibreQuake e1m3's.
fn crate_field_map() -> String {
    let (lo, hi) = ([1536.0, -512.0, 0.0], [3072.0, 1024.0, 256.0]);
    let (a, b) = (
        [lo[0] - 16.0, lo[1] - 16.0, lo[2] - 16.0],
        [hi[0] + 16.0, hi[1] + 16.0, hi[2] + 16.0],
    );
    let mut world = String::new();
    world += &box_brush(a, [b[0], b[1], lo[2]], "floor");
    world += &box_brush([a[0], a[1], hi[2]], b, "ceiling");
    world += &box_brush([a[0], a[1], lo[2]], [lo[0], b[1], hi[2]], "wall");
    world += &box_brush([hi[0], a[1], lo[2]], [b[0], b[1], hi[2]], "wall");
    world += &box_brush([lo[0], a[1], lo[2]], [hi[0], lo[1], hi[2]], "wall");
    world += &box_brush([lo[0], hi[1], lo[2]], [hi[0], b[1], hi[2]], "wall");
    let (sin, cos) = DEGREES.to_radians().sin_cos();
    for i in 0..5 {
        for j in 0..5 {
            let a = 1700.0 + 256.0 * i as f64 + 16.0 * ((i * 7 + j * 3) % 5) as f64;
            // The corner's y (a·(-sin) + b·(-cos)) lands near the row's y.
            let y = -300.0 + 256.0 * j as f64 + 32.0 * ((i + j) % 3) as f64;
            let b = ((y + a * sin) / -cos / 16.0).round() * 16.0;
            let size = 32.0 + 16.0 * ((i * j) % 3) as f64;
            let height = 32.0 + 16.0 * ((i + 2 * j) % 4) as f64;
            world += &rotated_crate(a, b, size, height);
        }
    }
    format!(
        "{{\n\"classname\" \"worldspawn\"\n\"mapversion\" \"220\"\n\"wad\" \"none.wad\"\n{world}}}\n\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"1600 -400 24\"\n}}\n"
    )
}

/// The crates give faces the engines would size differently; after the nudge there are none, and
/// no texture moved by more than the largest step.
#[test]
fn crates_turned_10_degrees_get_offsets_every_engine_agrees_on() {
    let out = compile_text(&crate_field_map());
    let grid = out.stats.lightmap_grid;
    assert!(
        grid.faces_disagreeing > 0,
        "the crates no longer give faces on which the engines disagree: {grid:?}"
    );
    assert!(grid.nudged_texinfos > 0, "{grid:?}");
    assert_eq!(grid.unresolved_faces, 0, "{grid:?}");
    assert_eq!(disagreements(&out.bsp), Vec::<String>::new());
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    // Every texinfo of the map has offsets 0: none may have moved further than the largest step.
    let largest = NUDGE_STEPS.iter().fold(0f32, |m, s| m.max(s.abs()));
    for (i, t) in out.bsp.texinfo.iter().enumerate() {
        for axis in t.vecs {
            assert!(axis[3].abs() <= largest, "texinfo {i}: offset {}", axis[3]);
        }
    }
}

/// Every map of the repository compiles to faces every engine sizes alike.
#[test]
fn repository_maps_have_no_faces_the_engines_size_differently() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).expect("maps/") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|e| e != "map") {
            continue;
        }
        let source = MapSource::read(&path).expect("read");
        let options = CompileOptions {
            wad_dirs: vec![dir.clone()],
            ..CompileOptions::default()
        };
        let out = compile(&source, &options).expect("compile");
        let name = path.display().to_string();
        assert_eq!(disagreements(&out.bsp), Vec::<String>::new(), "{name}");
        assert_eq!(out.stats.lightmap_grid.unresolved_faces, 0, "{name}");
        count += 1;
    }
    assert!(count >= 2, "only {count} maps found");
}
