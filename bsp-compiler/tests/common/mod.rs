//! Helpers shared by the compiler's integration tests: small maps written inline.

#![allow(dead_code)] // each test crate uses its own subset

use bsp_compiler::{CompileError, CompileOptions, CompileOutput, MapSource, compile};
use quake_formats::{Bsp, Severity, validate};
use std::path::PathBuf;

/// A brush face line in the standard format for the axial box face with outward normal along
/// `axis` (0..3) and `positive`.
pub fn box_brush(mins: [f64; 3], maxs: [f64; 3], texture: &str) -> String {
    let (a, b) = (mins, maxs);
    // Three points per plane, clockwise seen from outside.
    let faces = [
        // +x
        [[b[0], a[1], a[2]], [b[0], a[1], b[2]], [b[0], b[1], a[2]]],
        // -x
        [[a[0], a[1], a[2]], [a[0], b[1], a[2]], [a[0], a[1], b[2]]],
        // +y
        [[a[0], b[1], a[2]], [b[0], b[1], a[2]], [a[0], b[1], b[2]]],
        // -y
        [[a[0], a[1], a[2]], [a[0], a[1], b[2]], [b[0], a[1], a[2]]],
        // +z
        [[a[0], a[1], b[2]], [a[0], b[1], b[2]], [b[0], a[1], b[2]]],
        // -z
        [[a[0], a[1], a[2]], [b[0], a[1], a[2]], [a[0], b[1], a[2]]],
    ];
    let mut s = String::from("{\n");
    for f in faces {
        for p in f {
            s.push_str(&format!("( {} {} {} ) ", p[0], p[1], p[2]));
        }
        s.push_str(&format!("{texture} 0 0 0 1 1\n"));
    }
    s.push_str("}\n");
    s
}

/// A closed room: inside `lo..hi`, walls `t` thick. `hole` cuts a gap into the +x wall.
pub fn room(lo: f64, hi: f64, t: f64, hole: bool) -> String {
    let (a, b) = (lo - t, hi + t);
    let mut s = String::new();
    s += &box_brush([a, a, a], [b, b, lo], "floor"); // floor
    s += &box_brush([a, a, hi], [b, b, b], "ceiling"); // ceiling
    s += &box_brush([a, a, lo], [lo, b, hi], "wall"); // -x
    if hole {
        s += &box_brush([hi, a, lo], [b, 0.0, hi], "wall");
        s += &box_brush([hi, 32.0, lo], [b, b, hi], "wall");
    } else {
        s += &box_brush([hi, a, lo], [b, b, hi], "wall"); // +x
    }
    s += &box_brush([lo, a, lo], [hi, lo, hi], "wall"); // -y
    s += &box_brush([lo, hi, lo], [hi, b, hi], "wall"); // +y
    s
}

pub fn room_map(hole: bool, extra: &str) -> String {
    room_map_with(hole, extra, "")
}

/// The room, with `extra` brushes in worldspawn and the entity blocks `entities` after it.
pub fn room_map_with(hole: bool, extra: &str, entities: &str) -> String {
    format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"none.wad\"\n{}{extra}}}\n{entities}{{\n\"classname\" \"info_player_start\"\n\"origin\" \"-32 -32 -100\"\n}}\n",
        room(-128.0, 128.0, 16.0, hole)
    )
}

pub fn brush_entity(classname: &str, brushes: &str) -> String {
    format!("{{\n\"classname\" \"{classname}\"\n{brushes}}}\n")
}

pub fn try_compile(text: &str) -> Result<CompileOutput, CompileError> {
    try_compile_with(text, &CompileOptions::default())
}

pub fn try_compile_with(
    text: &str,
    options: &CompileOptions,
) -> Result<CompileOutput, CompileError> {
    let source = MapSource {
        path: PathBuf::from("inline.map"),
        text: text.to_string(),
    };
    compile(&source, options)
}

pub fn compile_text(text: &str) -> CompileOutput {
    try_compile(text).expect("compile")
}

pub fn errors(bsp: &Bsp) -> Vec<String> {
    validate(bsp)
        .into_iter()
        .filter(|p| p.severity == Severity::Error)
        .map(|p| p.to_string())
        .collect()
}

/// The stage commands' arguments, parsed as the `slipgate` command parses them.
#[derive(clap::Parser)]
pub struct BspCli {
    #[command(flatten)]
    pub args: bsp_compiler::cli::Args,
}

#[derive(clap::Parser)]
pub struct VisCli {
    #[command(flatten)]
    pub args: vis::cli::Args,
}

#[derive(clap::Parser)]
pub struct LightCli {
    #[command(flatten)]
    pub args: light::cli::Args,
}

/// The name of the texture of face `f`.
pub fn face_texture(bsp: &Bsp, f: usize) -> String {
    let info = &bsp.texinfo[bsp.faces[f].texinfo as usize];
    bsp.textures.textures[info.miptex as usize]
        .as_ref()
        .map(|t| t.name())
        .unwrap_or_default()
}

/// The normal of the side face `f` is drawn on.
pub fn face_normal(bsp: &Bsp, f: usize) -> [f32; 3] {
    let face = &bsp.faces[f];
    let n = bsp.planes[face.plane as usize].normal;
    if face.side != 0 { n.map(|c| -c) } else { n }
}

/// The faces of model `model` that hold `p` (within 0.01 of their plane, inside their edges),
/// seen along `normal` when it is given, as ericw-tools' tests look faces up.
pub fn faces_at(bsp: &Bsp, model: usize, p: [f32; 3], normal: Option<[f32; 3]>) -> Vec<usize> {
    let m = &bsp.models[model];
    let first = m.first_face as usize;
    (first..first + m.num_faces as usize)
        .filter(|&f| {
            let n = face_normal(bsp, f);
            if normal.is_some_and(|want| (0..3).any(|i| (want[i] - n[i]).abs() > 1e-3)) {
                return false;
            }
            let vs = bsp.face_vertices(&bsp.faces[f]).expect("vertices");
            let d = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            let dot = |a: [f32; 3], b: [f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            if dot(d(p, vs[0]), n).abs() > 0.01 {
                return false;
            }
            // Inside a convex polygon: on the same side of every edge, whichever way it winds.
            let sides: Vec<f32> = (0..vs.len())
                .map(|i| {
                    let (a, b) = (vs[i], vs[(i + 1) % vs.len()]);
                    let e = d(b, a);
                    let across = [
                        n[1] * e[2] - n[2] * e[1],
                        n[2] * e[0] - n[0] * e[2],
                        n[0] * e[1] - n[1] * e[0],
                    ];
                    dot(d(p, a), across)
                })
                .collect();
            sides.iter().all(|&s| s >= -0.01) || sides.iter().all(|&s| s <= 0.01)
        })
        .collect()
}
