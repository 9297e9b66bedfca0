//! Node, leaf and model bounds as ericw-tools' qbsp writes them (its `cube` and
//! `ClipFuncWallTest` tests, restated on maps of our own): a model's head node spans its brushes
//! grown by 24 units, every node holds its children, leaves and nodes are whole units, and the
//! model's own box is its brushes' a unit inside on every side, which engines widen back by a
//! unit as they load it.

mod common;

use bsp_compiler::CompileOptions;
use common::{box_brush, brush_entity, compile_text, room_map_with, try_compile_with};
use quake_formats::bsp::contents;
use quake_formats::{Bsp, BspVersion};

type Box3 = ([f32; 3], [f32; 3]);

fn grown(b: Box3, by: f32) -> Box3 {
    (b.0.map(|v| v - by), b.1.map(|v| v + by))
}

fn head_node_bounds(bsp: &Bsp, model: usize) -> Box3 {
    let head = bsp.models[model].head_nodes[0];
    let node = &bsp.nodes[usize::try_from(head).expect("a node heads the model")];
    (node.mins, node.maxs)
}

fn model_bounds(bsp: &Bsp, model: usize) -> Box3 {
    (bsp.models[model].mins, bsp.models[model].maxs)
}

fn child_bounds(bsp: &Bsp, child: i32) -> Option<Box3> {
    match child {
        -1 => None, // the shared solid leaf: no box of its own
        c if c < 0 => {
            let leaf = &bsp.leafs[(-c - 1) as usize];
            Some((leaf.mins, leaf.maxs))
        }
        c => Some((bsp.nodes[c as usize].mins, bsp.nodes[c as usize].maxs)),
    }
}

/// Every node's box holds its children's, and every node and leaf box is in whole units.
fn assert_nested_whole_units(bsp: &Bsp) {
    for (i, n) in bsp.nodes.iter().enumerate() {
        for v in n.mins.iter().chain(&n.maxs) {
            assert_eq!(v.fract(), 0.0, "node {i}: {:?} {:?}", n.mins, n.maxs);
        }
        for &c in &n.children {
            if let Some((mins, maxs)) = child_bounds(bsp, c) {
                for a in 0..3 {
                    assert!(
                        mins[a] >= n.mins[a] && maxs[a] <= n.maxs[a],
                        "node {i} {:?} {:?}: child {c} {mins:?} {maxs:?}",
                        n.mins,
                        n.maxs
                    );
                }
            }
        }
    }
    for (i, l) in bsp.leafs.iter().enumerate() {
        for v in l.mins.iter().chain(&l.maxs) {
            assert_eq!(v.fract(), 0.0, "leaf {i}: {:?} {:?}", l.mins, l.maxs);
        }
    }
}

/// A world of one cube and no entity (nothing to fill from), as ericw-tools' `q1_cube.map`.
const CUBE: Box3 = ([32.0, -240.0, 80.0], [80.0, -144.0, 112.0]);

fn cube_map() -> String {
    let [lo, hi] = [CUBE.0, CUBE.1].map(|c| c.map(f64::from));
    format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"none.wad\"\n{}}}\n",
        box_brush(lo, hi, "orangestuff8")
    )
}

#[test]
fn a_lone_cube_has_qbsps_head_node_leaf_and_model_bounds() {
    for version in [BspVersion::Bsp29, BspVersion::Bsp2] {
        let options = CompileOptions {
            version,
            ..CompileOptions::default()
        };
        let out = try_compile_with(&cube_map(), &options).expect("compile");
        let bsp = &out.bsp;
        assert_eq!(bsp.version, version);
        assert_eq!(head_node_bounds(bsp, 0), grown(CUBE, 24.0), "{version:?}");
        assert_eq!(model_bounds(bsp, 0), grown(CUBE, -1.0), "{version:?}");
        // The shared solid leaf has no box; the open leaves around the cube reach the head
        // node's box together.
        assert_eq!((bsp.leafs[0].mins, bsp.leafs[0].maxs), ([0.0; 3], [0.0; 3]));
        let open = &bsp.leafs[1..];
        assert!(!open.is_empty());
        assert!(open.iter().all(|l| l.contents == contents::EMPTY));
        let reach = open
            .iter()
            .fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), l| {
                (
                    std::array::from_fn(|a| lo[a].min(l.mins[a])),
                    std::array::from_fn(|a| hi[a].max(l.maxs[a])),
                )
            });
        assert_eq!(reach, grown(CUBE, 24.0), "{version:?}");
        assert_nested_whole_units(bsp);
    }
}

/// ericw-tools' clip func_wall: a 64 x 64 x 32 clip brush, alone or around a small solid brush.
const CLIP: Box3 = ([64.0, 64.0, 48.0], [128.0, 128.0, 80.0]);

#[test]
fn a_clip_func_wall_is_bounded_by_its_clip_brush() {
    let [lo, hi] = [CLIP.0, CLIP.1].map(|c| c.map(f64::from));
    let clip = box_brush(lo, hi, "clip");
    let solid = box_brush([76.0, 92.0, 68.0], [92.0, 112.0, 72.0], "bolt9");
    for brushes in [clip.clone(), clip + &solid] {
        let out = compile_text(&room_map_with(
            false,
            "",
            &brush_entity("func_wall", &brushes),
        ));
        let bsp = &out.bsp;
        assert!(out.leak.is_none(), "the room is sealed");
        assert_eq!(bsp.models.len(), 2);
        assert_eq!(head_node_bounds(bsp, 1), grown(CLIP, 24.0), "{brushes}");
        assert_eq!(model_bounds(bsp, 1), grown(CLIP, -1.0), "{brushes}");
        assert_nested_whole_units(bsp);
    }
}

#[test]
fn the_box_engines_load_for_a_model_is_its_brushes() {
    // Engines widen the written box by a unit on every side: a door's size, and so its travel,
    // comes out as its brushes'.
    let door = box_brush([-32.0, -8.0, -128.0], [32.0, 8.0, 0.0], "door");
    let out = compile_text(&room_map_with(false, "", &brush_entity("func_door", &door)));
    let (mins, maxs) = model_bounds(&out.bsp, 1);
    let loaded = (mins.map(|v| v - 1.0), maxs.map(|v| v + 1.0));
    assert_eq!(loaded, ([-32.0, -8.0, -128.0], [32.0, 8.0, 0.0]));
}
