//! A synthetic map for unit tests: a 256-unit cube room seen from inside, one wall per node, with
//! a patterned texture and a lightmap gradient per wall, plus an optional light style on a wall.

use quake_formats::bsp::{BspPlane, Face, Leaf, Model, Node, TexInfo, contents};
use quake_formats::extents::LightmapExtents;
use quake_formats::miptex::{MipTex, TextureLump};
use quake_formats::palette::Palette;
use quake_formats::{Bsp, BspVersion};

use crate::textures::PaletteSource;
use crate::world::World;

const HALF: f32 = 128.0;

/// The room; wall 0 (the +x side, facing -x) uses light style `wall0_style`.
pub fn room(wall0_style: u8) -> World {
    World::new(
        room_bsp(wall0_style),
        &Palette::slipgate(),
        PaletteSource::Builtin,
        None,
    )
    .expect("valid room")
}

/// The room's BSP: node i holds wall i, its front child is node i + 1 (the last one's is the
/// room's leaf 1), its back child the solid leaf 0.
pub fn room_bsp(wall0_style: u8) -> Bsp {
    let mut bsp = Bsp::new(BspVersion::Bsp29);
    bsp.set_entity_text(
        "{\n\"classname\" \"worldspawn\"\n}\n{\n\"classname\" \"info_player_start\"\n\"origin\" \"-61.3 7.7 -98.1\"\n\"angle\" \"0\"\n}\n",
    );
    let mips = std::array::from_fn(|level| {
        let size = 16usize >> level;
        (0..size * size)
            .map(|i| (16 + (i % size) * 5 + (i / size) * 3) as u8)
            .collect()
    });
    bsp.textures = TextureLump {
        textures: vec![Some(MipTex::new("wall", 16, 16, mips))],
    };
    // Walls: inward normal, then the axis pair for texture s and t.
    let walls: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
        ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
        ([0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]),
    ];
    let bounds = ([-HALF; 3], [HALF; 3]);
    bsp.leafs.push(Leaf::SHARED_SOLID);
    bsp.leafs.push(Leaf {
        contents: contents::EMPTY,
        vis_offset: -1,
        mins: bounds.0,
        maxs: bounds.1,
        first_marksurface: 0,
        num_marksurfaces: 6,
        ambient: [0; 4],
    });
    for (i, (normal, s, t)) in walls.iter().enumerate() {
        bsp.planes.push(BspPlane {
            normal: *normal,
            dist: -HALF,
            kind: 0,
        });
        // The wall's corners: the two in-plane axes at +-HALF, the normal axis at -normal*HALF.
        let axis = normal.iter().position(|&c| c != 0.0).unwrap_or(0);
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(ca, cb)| {
            let mut v = [0.0f32; 3];
            v[axis] = -normal[axis] * HALF;
            v[a] = ca * HALF;
            v[b] = cb * HALF;
            v
        });
        let first_vertex = bsp.vertices.len();
        let first_edge = push_polygon(&mut bsp, &corners);
        bsp.texinfo.push(TexInfo {
            vecs: [[s[0], s[1], s[2], 0.0], [t[0], t[1], t[2], 0.0]],
            miptex: 0,
            flags: 0,
        });
        let points: Vec<[f32; 3]> = bsp.vertices[first_vertex..].to_vec();
        let extents = LightmapExtents::from_points(&points, &bsp.texinfo[i].vecs);
        let [lw, lh] = extents.luxel_size();
        let light_offset = bsp.lighting.len() as i32;
        for y in 0..lh {
            for x in 0..lw {
                bsp.lighting
                    .push((40 + x * 8 + y * 3 + i * 10).min(255) as u8);
            }
        }
        bsp.faces.push(Face {
            plane: i as u32,
            side: 0,
            first_edge,
            num_edges: 4,
            texinfo: i as u32,
            styles: [if i == 0 { wall0_style } else { 0 }, 255, 255, 255],
            light_offset,
        });
        bsp.marksurfaces.push(i as u32);
        let last = i == walls.len() - 1;
        bsp.nodes.push(Node {
            plane: i as u32,
            children: [if last { -2 } else { i as i32 + 1 }, -1],
            mins: bounds.0,
            maxs: bounds.1,
            first_face: i as u32,
            num_faces: 1,
        });
    }
    bsp.models.push(Model {
        mins: bounds.0,
        maxs: bounds.1,
        origin: [0.0; 3],
        head_nodes: [0, 0, 0, 0],
        vis_leafs: 1,
        first_face: 0,
        num_faces: 6,
    });
    bsp
}

/// Add a polygon's vertices and edges; returns its first surfedge.
fn push_polygon(bsp: &mut Bsp, corners: &[[f32; 3]]) -> u32 {
    let first_vertex = bsp.vertices.len() as u32;
    bsp.vertices.extend_from_slice(corners);
    let first_edge = bsp.surfedges.len() as u32;
    let n = corners.len() as u32;
    for k in 0..n {
        bsp.surfedges.push(bsp.edges.len() as i32);
        bsp.edges
            .push([first_vertex + k, first_vertex + (k + 1) % n]);
    }
    first_edge
}

/// Face index of the fence in [`room_with_fence`].
pub const FENCE_FACE: u32 = 6;

/// The room with a func_wall in front of wall 0: one face at x = 64 facing the start, textured
/// `{grate`, whose 4x4-texel checker cells alternate between a colour and the transparent index.
pub fn room_with_fence() -> World {
    let mut bsp = room_bsp(0);
    let mut text = bsp.entity_text();
    text.push_str("{\n\"classname\" \"func_wall\"\n\"model\" \"*1\"\n}\n");
    bsp.set_entity_text(&text);
    let mips = std::array::from_fn(|level| {
        let (size, cell) = (16usize >> level, 4usize >> level);
        (0..size * size)
            .map(|i| {
                let (x, y) = (i % size / cell.max(1), i / size / cell.max(1));
                if (x + y) % 2 == 0 { 255 } else { 40 }
            })
            .collect()
    });
    bsp.textures
        .textures
        .push(Some(MipTex::new("{grate", 16, 16, mips)));
    let plane = bsp.planes.len() as u32;
    bsp.planes.push(BspPlane {
        normal: [-1.0, 0.0, 0.0],
        dist: -64.0,
        kind: 0,
    });
    let texinfo = bsp.texinfo.len() as u32;
    bsp.texinfo.push(TexInfo {
        vecs: [[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0]],
        miptex: 1,
        flags: 0,
    });
    let corners = [
        (-48.0, -120.0),
        (48.0, -120.0),
        (48.0, -24.0),
        (-48.0, -24.0),
    ]
    .map(|(y, z)| [64.0, y, z]);
    let first_edge = push_polygon(&mut bsp, &corners);
    let face = bsp.faces.len() as u32;
    assert_eq!(face, FENCE_FACE);
    bsp.faces.push(Face {
        plane,
        side: 0,
        first_edge,
        num_edges: 4,
        texinfo,
        styles: [255; 4],
        light_offset: -1,
    });
    bsp.models.push(Model {
        mins: [64.0, -48.0, -120.0],
        maxs: [64.0, 48.0, -24.0],
        origin: [0.0; 3],
        head_nodes: [-1, -1, -1, -1],
        vis_leafs: 0,
        first_face: face,
        num_faces: 1,
    });
    World::new(bsp, &Palette::slipgate(), PaletteSource::Builtin, None).expect("valid room")
}

/// The room below a chain of `depth` extra nodes, each splitting on a plane the room lies in
/// front of, with solid behind: the same picture at the end of a degenerate, very deep tree (or
/// the gate's refusal, when deeper than it allows).
pub fn room_under_chain(depth: usize) -> Result<World, String> {
    let mut bsp = room_bsp(0);
    let plane = bsp.planes.len() as u32;
    bsp.planes.push(BspPlane {
        normal: [1.0, 0.0, 0.0],
        dist: -4.0 * HALF,
        kind: 0,
    });
    let first = bsp.nodes.len() as i32;
    let bounds = (bsp.models[0].mins, bsp.models[0].maxs);
    for k in 0..depth as i32 {
        let next = if k + 1 == depth as i32 {
            0
        } else {
            first + k + 1
        };
        bsp.nodes.push(Node {
            plane,
            children: [next, -1],
            mins: bounds.0,
            maxs: bounds.1,
            first_face: 0,
            num_faces: 0,
        });
    }
    if depth > 0 {
        bsp.models[0].head_nodes[0] = first;
    }
    World::new(bsp, &Palette::slipgate(), PaletteSource::Builtin, None)
}
