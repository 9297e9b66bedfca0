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
    bsp.leafs.push(Leaf {
        contents: contents::SOLID,
        vis_offset: -1,
        mins: [0.0; 3],
        maxs: [0.0; 3],
        first_marksurface: 0,
        num_marksurfaces: 0,
        ambient: [0; 4],
    });
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
        let first_vertex = bsp.vertices.len() as u32;
        for (ca, cb) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let mut v = [0.0f32; 3];
            v[axis] = -normal[axis] * HALF;
            v[a] = ca * HALF;
            v[b] = cb * HALF;
            bsp.vertices.push(v);
        }
        let first_edge = bsp.surfedges.len() as u32;
        for k in 0..4u32 {
            bsp.surfedges.push(bsp.edges.len() as i32);
            bsp.edges
                .push([first_vertex + k, first_vertex + (k + 1) % 4]);
        }
        bsp.texinfo.push(TexInfo {
            vecs: [[s[0], s[1], s[2], 0.0], [t[0], t[1], t[2], 0.0]],
            miptex: 0,
            flags: 0,
        });
        let points: Vec<[f32; 3]> = bsp.vertices[first_vertex as usize..].to_vec();
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
    World::new(bsp, &Palette::slipgate(), PaletteSource::Builtin, None).expect("valid room")
}
