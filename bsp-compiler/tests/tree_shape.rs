//! How many nodes and leaves small maps' trees take, as ericw-tools counts them: a sealed box
//! room takes one node per wall, and a box standing in it one more per face it shows, whatever
//! kind of brush it is. Planes that face the filled void must not sit above the room as nodes of
//! their own.

mod common;

use common::{box_brush, brush_entity, compile_text, face_texture, faces_at, room_map_with};
use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::prt::PortalFile;

fn leaf_contents(bsp: &Bsp, p: [f32; 3]) -> i32 {
    bsp.leafs[bsp.leaf_at(p).expect("leaf")].contents
}

/// The room of [`room_map_with`] (inside -128..128 on every axis) with a 64 x 64 box on its
/// floor, 16 high, in an entity of `classname` (the world's brushes for `worldspawn`), reaching
/// `below` units down from the floor's top.
fn room_with_box(classname: &str, below: f64) -> String {
    let block = box_brush([0.0, -96.0, -128.0 - below], [64.0, -32.0, -112.0], "block");
    if classname == "worldspawn" {
        room_map_with(false, &block, "")
    } else {
        room_map_with(false, "", &brush_entity(classname, &block))
    }
}

/// The clusters a portal file gives vis: a PRT1 file's leaves, or a PRT2 file's clusters.
fn vis_clusters(prt: &PortalFile) -> usize {
    prt.clusters
        .as_ref()
        .map_or(prt.num_leafs as usize, Vec::len)
}

#[test]
fn a_box_on_the_floor_adds_a_node_per_face_it_shows() {
    // Kind of box, its leaves (the shared solid leaf and the open ones), vis clusters.
    for (classname, leaves, clusters) in [
        ("worldspawn", 6, 5),
        ("func_detail", 6, 1),
        // Not solid: the room's six leaves stay open around and inside it.
        ("func_detail_illusionary", 7, 1),
    ] {
        let out = compile_text(&room_with_box(classname, 0.0));
        let bsp = &out.bsp;
        assert!(out.leak.is_none(), "{classname}");
        assert_eq!(bsp.nodes.len(), 6 + 5, "{classname}");
        assert_eq!(bsp.leafs.len(), leaves, "{classname}");
        assert_eq!(vis_clusters(&out.portals), clusters, "{classname}");
    }
}

/// The illusionary box reaches through the floor into the void: that part is filled, its faces
/// there dropped; the room keeps one open cluster without portals.
#[test]
fn an_illusionary_box_through_the_floor_is_cut_by_the_fill() {
    let out = compile_text(&room_with_box("func_detail_illusionary", 32.0));
    let bsp = &out.bsp;
    assert_eq!(bsp.nodes.len(), 11);
    assert_eq!(bsp.leafs.len(), 7);
    // The five faces of the box above the floor, and none in the void.
    let block = (0..bsp.faces.len()).filter(|&f| face_texture(bsp, f) == "block");
    assert_eq!(block.count(), 5);
    assert_eq!(leaf_contents(bsp, [32.0, -64.0, -152.0]), contents::SOLID);
    assert!(faces_at(bsp, 0, [0.0, -64.0, -152.0], None).is_empty());
    assert_eq!(vis_clusters(&out.portals), 1);
    assert!(out.portals.portals.is_empty());
}

/// A box room with a sky ceiling: one sky leaf beside the room's, the void past the sky solid
/// (sky does not fill outwards), and no more nodes than two open boxes would take.
#[test]
fn a_sky_ceiling_is_one_leaf_and_the_void_past_it_stays_solid() {
    let text = room_map_with(false, "", "").replace("ceiling", "sky1");
    let out = compile_text(&text);
    let bsp = &out.bsp;
    assert!(out.leak.is_none());
    assert!((7..=11).contains(&bsp.nodes.len()), "{}", bsp.nodes.len());
    assert_eq!(bsp.leafs.len(), 3);
    // Sky faces are not cut for lightmaps: one.
    let sky: Vec<usize> = (0..bsp.faces.len())
        .filter(|&f| face_texture(bsp, f) == "sky1")
        .collect();
    assert_eq!(sky.len(), 1);
    assert_eq!(
        faces_at(bsp, 0, [0.0, 0.0, 128.0], Some([0.0, 0.0, -1.0])),
        sky
    );
    let inside = [-32.0, -32.0, 0.0];
    assert_eq!(leaf_contents(bsp, inside), contents::EMPTY);
    assert_eq!(leaf_contents(bsp, [-32.0, -32.0, 136.0]), contents::SKY);
    for offset in [
        [500.0, 0.0, 0.0],
        [-500.0, 0.0, 0.0],
        [0.0, 500.0, 0.0],
        [0.0, -500.0, 0.0],
        [0.0, 0.0, 500.0],
        [0.0, 0.0, -500.0],
    ] {
        let p = [0, 1, 2].map(|i| inside[i] + offset[i]);
        assert_eq!(leaf_contents(bsp, p), contents::SOLID, "{p:?}");
    }
    assert!(out.portals.portals.is_empty());
    // Each clip hull: the room's six walls.
    assert_eq!(bsp.clipnodes.len(), 12);
}
