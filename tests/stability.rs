//! Numerical stability: every hard map moved by 1e-4 units or turned by 1e-6 radians compiles to
//! the same outcome: the same leak verdict, and the same contents at sampled points (mapped by the
//! same motion) wherever a point lies further than [`PLANE_CLEARANCE`] from every plane it is
//! tested against. ARCHITECTURE.md's epsilon policy names this test.

#[path = "support/hard.rs"]
mod hard;

use bsp_compiler::{CompileOptions, MapSource, compile};
use hard::{hard_maps, maps_dir};
use quake_formats::Bsp;
use std::path::Path;

/// Points closer than this to a node plane on their way down either tree are not compared: there
/// a motion of 1e-4 units (or 1e-6 rad at 33000 units: 0.033) may rightly move them across.
const PLANE_CLEARANCE: f64 = 0.1;
/// Sample points per axis of the world's bounds.
const GRID: usize = 12;

/// A rigid motion: a turn about the z axis, then a shift.
#[derive(Clone, Copy)]
struct Motion {
    yaw: f64,
    shift: [f64; 3],
}

impl Motion {
    fn apply(self, p: [f64; 3]) -> [f64; 3] {
        let (s, c) = self.yaw.sin_cos();
        [
            c * p[0] - s * p[1] + self.shift[0],
            s * p[0] + c * p[1] + self.shift[1],
            p[2] + self.shift[2],
        ]
    }
}

fn fmt(v: f64) -> String {
    format!("{v:.9}")
}

/// `text` with every brush plane point and entity origin moved; texture axes stay as they are.
fn moved_map(text: &str, motion: Motion) -> String {
    let move_triple = |s: &str| -> Option<String> {
        let v: Vec<f64> = s
            .split_whitespace()
            .map(|x| x.parse().ok())
            .collect::<Option<_>>()?;
        let [x, y, z] = v.try_into().ok()?;
        let p = motion.apply([x, y, z]);
        Some(format!("{} {} {}", fmt(p[0]), fmt(p[1]), fmt(p[2])))
    };
    let mut out = String::new();
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("\"origin\" \"") {
            let value = rest.trim_end_matches('"');
            out += &format!("\"origin\" \"{}\"\n", move_triple(value).expect("origin"));
            continue;
        }
        if line.starts_with('(') {
            // ( x y z ) ( x y z ) ( x y z ) texture ...
            let mut rest = line;
            let mut moved = String::new();
            for _ in 0..3 {
                let open = rest.find('(').expect("(");
                let close = rest.find(')').expect(")");
                let point = move_triple(&rest[open + 1..close]).expect("plane point");
                moved += &format!("( {point} ) ");
                rest = &rest[close + 1..];
            }
            out += &format!("{moved}{}\n", rest.trim_start());
            continue;
        }
        out += line;
        out.push('\n');
    }
    out
}

/// The contents at `p` in the world's hull 0, or `None` when `p` passes within
/// [`PLANE_CLEARANCE`] of a node plane on its way down.
fn contents_clear_of_planes(bsp: &Bsp, p: [f64; 3]) -> Option<i32> {
    let mut node = bsp.models[0].head_nodes[0];
    while node >= 0 {
        let n = &bsp.nodes[node as usize];
        let plane = &bsp.planes[n.plane as usize];
        let d = (0..3).map(|i| plane.normal[i] as f64 * p[i]).sum::<f64>() - plane.dist as f64;
        if d.abs() < PLANE_CLEARANCE {
            return None;
        }
        node = n.children[usize::from(d < 0.0)];
    }
    Some(bsp.leafs[(-(node + 1)) as usize].contents)
}

fn compile_text(path: &Path, text: String) -> (Bsp, bool) {
    let source = MapSource {
        path: path.to_path_buf(),
        text,
    };
    let options = CompileOptions {
        wad_dirs: vec![maps_dir()],
        ..CompileOptions::default()
    };
    let out = compile(&source, &options).expect("compile");
    (out.bsp, out.leak.is_some())
}

/// Compares `map` (`original`: its compiled BSP and leak verdict) with it moved by `motion`;
/// returns the points compared.
fn check_motion(
    map: &Path,
    text: &str,
    original: &(Bsp, bool),
    motion: Motion,
    what: &str,
) -> usize {
    let name = map.display();
    let (bsp, leaks) = original;
    let leaks = *leaks;
    let (moved, moved_leaks) = compile_text(map, moved_map(text, motion));
    assert_eq!(leaks, moved_leaks, "{name} {what}: the leak verdict flips");
    let world = &bsp.models[0];
    let mut compared = 0;
    for i in 0..GRID * GRID * GRID {
        let t =
            [i % GRID, i / GRID % GRID, i / (GRID * GRID)].map(|k| (k as f64 + 0.5) / GRID as f64);
        let p: [f64; 3] = std::array::from_fn(|a| {
            world.mins[a] as f64 + t[a] * (world.maxs[a] - world.mins[a]) as f64
        });
        let (Some(before), Some(after)) = (
            contents_clear_of_planes(bsp, p),
            contents_clear_of_planes(&moved, motion.apply(p)),
        ) else {
            continue;
        };
        assert_eq!(before, after, "{name} {what}: contents at {p:?} flip");
        compared += 1;
    }
    compared
}

#[test]
fn tiny_motions_do_not_flip_contents_or_leaks() {
    let maps = hard_maps();
    let motions = [
        (
            Motion {
                yaw: 0.0,
                shift: [1e-4, -1e-4, 1e-4],
            },
            "moved 1e-4",
        ),
        (
            Motion {
                yaw: 1e-6,
                shift: [0.0; 3],
            },
            "turned 1e-6 rad",
        ),
    ];
    for map in &maps {
        let text = std::fs::read_to_string(map).expect("read map");
        if text.contains("\n// expect: refused") {
            continue;
        }
        let original = compile_text(map, text.clone());
        for (motion, what) in motions {
            let compared = check_motion(map, &text, &original, motion, what);
            eprintln!("{}: {what}: {compared} points agree", map.display());
            assert!(
                compared > GRID,
                "{}: only {compared} points compared",
                map.display()
            );
        }
    }
}
