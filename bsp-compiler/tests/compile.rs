//! End-to-end compiles of small maps written inline, and of the corpus maps.

mod common;

use common::*;
use glam::{DVec3, Vec3};

use bsp_compiler::faces::{MIN_SQUARENESS, projection_squareness};
use bsp_compiler::{CompileError, CompileOptions, CompileOutput, MapSource, Warning, compile};
use quake_formats::bsp::limits::MAX_SURFACE_EXTENT;
use quake_formats::bsp::{Rule, contents};
use quake_formats::extents::LightmapExtents;

use quake_formats::miptex::MipTex;
use quake_formats::prt::PortalFile;
use quake_formats::wad::{Wad, WadLump};
use quake_formats::{Bsp, validate};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Written and read back, by us and by the independent `qbsp` crate.
fn check_round_trip(bsp: &Bsp) {
    let bytes = bsp.write().expect("write");
    let back = Bsp::read(&bytes).expect("read back");
    assert_eq!(back.faces.len(), bsp.faces.len());
    let theirs = qbsp::BspData::parse(qbsp::BspParseInput {
        bsp: &bytes,
        lit: None,
        settings: Default::default(),
    })
    .expect("qbsp parses our BSP");
    assert_eq!(theirs.planes.len(), bsp.planes.len());
    assert_eq!(theirs.vertices.len(), bsp.vertices.len());
    assert_eq!(theirs.nodes.len(), bsp.nodes.len());
    assert_eq!(theirs.faces.len(), bsp.faces.len());
    assert_eq!(theirs.leaves.len(), bsp.leafs.len());
    assert_eq!(theirs.clip_nodes.len(), bsp.clipnodes.len());
    assert_eq!(theirs.edges.len(), bsp.edges.len());
    assert_eq!(theirs.models.len(), bsp.models.len());
    assert_eq!(theirs.textures.len(), bsp.textures.textures.len());
}

/// Regression: leaves whose portals were all too small to keep had infinite bounds.
fn assert_finite_bounds(bsp: &Bsp, name: &str) {
    let finite = |v: &[f32; 3]| v.iter().all(|c| c.is_finite());
    for (i, l) in bsp.leafs.iter().enumerate() {
        assert!(finite(&l.mins) && finite(&l.maxs), "{name}: leaf {i}");
    }
    for (i, n) in bsp.nodes.iter().enumerate() {
        assert!(finite(&n.mins) && finite(&n.maxs), "{name}: node {i}");
    }
}

/// DarkPlaces builds a portal on every node's plane at load; none may miss its node's region.
fn assert_node_planes_cross_their_regions(bsp: &Bsp, name: &str) {
    let outside: Vec<String> = validate(bsp)
        .into_iter()
        .filter(|p| p.rule == Rule::NodePlaneOutsideRegion)
        .map(|p| p.to_string())
        .collect();
    assert_eq!(outside, Vec::<String>::new(), "{name}");
}

fn leaf_contents(bsp: &Bsp, p: [f32; 3]) -> i32 {
    bsp.leafs[bsp.leaf_at(p).expect("leaf")].contents
}

/// Every face's (outward) normal, from its plane and side.
fn face_normal(bsp: &Bsp, f: &quake_formats::bsp::Face) -> [f32; 3] {
    let n = bsp.planes[f.plane as usize].normal;
    if f.side == 1 { n.map(|c| -c) } else { n }
}

/// Every face's texture projects onto it squarely enough to be mapped back (light tools invert
/// the projection). Regression: ericw-tools' light stopped on e3m4 at a sliver of wall the tree
/// left between brushes, textured with the floor axes of a side on another plane.
fn assert_textures_project_squarely(bsp: &Bsp, name: &str) {
    for (i, f) in bsp.faces.iter().enumerate() {
        let vecs = bsp.texinfo[f.texinfo as usize]
            .vecs
            .map(|row| row.map(f64::from));
        let [x, y, z] = face_normal(bsp, f).map(f64::from);
        let square = projection_squareness(&vecs, DVec3::new(x, y, z));
        assert!(
            square >= MIN_SQUARENESS,
            "{name}: face {i} (texinfo {}) meets its texture at squareness {square}",
            f.texinfo
        );
    }
}

/// No face visits a vertex twice: a spike or a knot of near-coincident vertices would use its own
/// edges in both directions (e3m4 had 94 such faces, q1_mountain 53).
fn assert_faces_are_simple(bsp: &Bsp, name: &str) {
    for (i, f) in bsp.faces.iter().enumerate() {
        let vertices = bsp.face_vertex_indices(f).expect("face vertices");
        let mut distinct = vertices.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert_eq!(
            distinct.len(),
            vertices.len(),
            "{name}: face {i} visits a vertex twice: {vertices:?}"
        );
    }
}

/// A side whose Valve axes meet it edge-on (floor axes on a wall) gets Quake's projection for its
/// plane, and is cut for its lightmap like any other wall.
#[test]
fn edge_on_textures_are_squared_up_and_cut() {
    let pillar = box_brush([-16.0, -500.0, -512.0], [16.0, 500.0, 0.0], "pillar").replacen(
        "pillar 0 0 0 1 1",
        "pillar [ 1 0 0 0 ] [ 0 -1 0 0 ] 0 1 1",
        1,
    );
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n{}{pillar}}}\n{{\n\"classname\" \"info_player_start\"\n\"origin\" \"100 0 -400\"\n}}\n",
        room(-512.0, 512.0, 16.0, false)
    );
    let out = compile_text(&text);
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert!(out.stats.face_stats.squared_up >= 1, "{:?}", out.stats);
    // The mapper is told which side it was.
    let side_line = text[..text.find("pillar [").expect("side")].lines().count();
    assert!(
        out.warnings.iter().any(|w| matches!(w,
            Warning::DegenerateTextureAxes { line, texture, .. }
                if *line == side_line && texture == "pillar")),
        "{:?}",
        out.warnings
    );
    assert_textures_project_squarely(bsp, "pillar");
    let mut pieces = 0;
    for f in &bsp.faces {
        let points = bsp.face_vertices(f).expect("vertices");
        if face_normal(bsp, f) != [1.0, 0.0, 0.0] || points.iter().any(|p| p[0] != 16.0) {
            continue;
        }
        pieces += 1;
        let tex = &bsp.texinfo[f.texinfo as usize];
        let e = LightmapExtents::from_points(&points, &tex.vecs);
        assert!(e.extents.iter().all(|&x| x <= MAX_SURFACE_EXTENT), "{e:?}");
    }
    // 1000 by 512 units: at most 240 texels a piece.
    assert!(pieces >= 5 * 3, "{pieces} pieces");
}

#[test]
fn sealed_room_compiles_to_a_valid_bsp() {
    let out = compile_text(&room_map(false, ""));
    let bsp = &out.bsp;
    assert!(out.leak.is_none(), "{:?}", out.warnings);
    assert_eq!(errors(bsp), Vec::<String>::new());
    check_round_trip(bsp);
    // Six inner faces (cut for lightmaps: the room is 256 wide), nothing facing the void.
    assert_eq!(out.stats.face_stats.after_merge, 6);
    assert_eq!(bsp.faces.len(), 24);
    for f in &bsp.faces {
        let verts = bsp.face_vertices(f).expect("vertices");
        let n = face_normal(bsp, f);
        let c = verts.iter().fold([0.0f32; 3], |acc, v| {
            [acc[0] + v[0], acc[1] + v[1], acc[2] + v[2]]
        });
        let c = c.map(|x| x / verts.len() as f32);
        let probe = [c[0] + n[0], c[1] + n[1], c[2] + n[2]];
        assert_eq!(
            leaf_contents(bsp, probe),
            contents::EMPTY,
            "face looks at {probe:?}"
        );
    }
    // Point in leaf: the room is empty, the walls solid, the outside filled.
    assert_eq!(leaf_contents(bsp, [0.0, 0.0, 0.0]), contents::EMPTY);
    assert_eq!(leaf_contents(bsp, [0.0, 0.0, -136.0]), contents::SOLID);
    assert_eq!(bsp.leaf_at([0.0, 0.0, -136.0]), Some(0));
    assert_eq!(leaf_contents(bsp, [0.0, 0.0, -1000.0]), contents::SOLID);
    // Clip hulls exist; filled from the outside, each is the room's box: six clip nodes.
    assert_eq!(bsp.clipnodes.len(), 12);
    assert!(bsp.models[0].head_nodes[1] >= 0 && bsp.models[0].head_nodes[2] >= 0);
    // The portal file matches the leaves.
    let prt = PortalFile::parse(&out.portals.write()).expect("prt");
    assert_eq!(prt.num_leafs as i32, bsp.models[0].vis_leafs);
    assert_eq!(prt.num_leafs as usize, bsp.leafs.len() - 1);
}

fn hull_contents(bsp: &Bsp, hull: usize, p: [f32; 3]) -> i32 {
    bsp_compiler::trace::hull_point_contents(bsp, 0, hull, p)
}

#[test]
fn clip_hulls_keep_the_player_box_off_the_walls() {
    let out = compile_text(&room_map(false, ""));
    let bsp = &out.bsp;
    // Standing on the floor (z = -128) puts the player origin 24 units up.
    assert_eq!(hull_contents(bsp, 1, [0.0, 0.0, -103.0]), contents::EMPTY);
    assert_eq!(hull_contents(bsp, 1, [0.0, 0.0, -105.0]), contents::SOLID);
    // 16 units from the +x wall at 128.
    assert_eq!(hull_contents(bsp, 1, [111.0, 0.0, 0.0]), contents::EMPTY);
    assert_eq!(hull_contents(bsp, 1, [113.0, 0.0, 0.0]), contents::SOLID);
    // The shambler is 32 wide.
    assert_eq!(hull_contents(bsp, 2, [95.0, 0.0, 0.0]), contents::EMPTY);
    assert_eq!(hull_contents(bsp, 2, [97.0, 0.0, 0.0]), contents::SOLID);
}

#[test]
fn edges_are_shared_once_in_each_direction() {
    // A pillar in the room makes faces meet at T-junctions on the floor and ceiling.
    let pillar = box_brush([-16.0, -16.0, -128.0], [16.0, 16.0, 128.0], "pillar");
    let out = compile_text(&room_map(false, &pillar));
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    let mut uses: HashMap<i32, usize> = HashMap::new();
    for &se in &bsp.surfedges {
        assert_ne!(se, 0);
        *uses.entry(se).or_default() += 1;
    }
    assert!(
        uses.values().all(|&n| n == 1),
        "an edge is used twice in one direction"
    );
    // The room's surface is closed, so every edge is used by exactly two faces.
    for e in 1..bsp.edges.len() as i32 {
        assert_eq!(
            (uses.get(&e).copied(), uses.get(&-e).copied()),
            (Some(1), Some(1)),
            "edge {e} is not shared by two faces"
        );
    }
}

#[test]
fn leaking_room_writes_a_pointfile_to_the_void() {
    let out = compile_text(&room_map(true, ""));
    let leak = out.leak.as_ref().expect("leak");
    assert_eq!(leak.classname, "info_player_start");
    assert_eq!(leak.pointfile[0], DVec3::new(-32.0, -32.0, -100.0));
    let last = *leak.pointfile.last().expect("points");
    assert!(
        [last.x, last.y, last.z].iter().any(|c| c.abs() > 144.0),
        "{last:?} is not outside the map"
    );
    assert!(
        out.warnings
            .iter()
            .any(|w| matches!(w, Warning::Leak { .. }))
    );
    // Still a valid BSP, with the outside kept: faces look into the void too.
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    assert!(out.bsp.faces.len() > 6);
}

/// The leaf numbers each PRT2 cluster lists, checked to cover every vis leaf exactly once.
fn checked_clusters(prt: &PortalFile) -> Vec<Vec<u32>> {
    let clusters = prt.clusters.clone().expect("a PRT2 file");
    let mut seen = vec![0; prt.num_leafs as usize];
    for &leaf in clusters.iter().flatten() {
        seen[leaf as usize] += 1;
    }
    assert!(seen.iter().all(|&n| n == 1), "leaf cover counts {seen:?}");
    clusters
}

#[test]
fn detail_splits_below_the_clusters() {
    let pillar = box_brush([-16.0, -16.0, -128.0], [16.0, 16.0, 128.0], "pillar");
    let structural = compile_text(&room_map(false, &pillar));
    let out = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_detail", &pillar),
    ));
    let bsp = &out.bsp;
    assert!(out.leak.is_none(), "{:?}", out.warnings);
    assert_eq!(errors(bsp), Vec::<String>::new());
    check_round_trip(bsp);
    // Solid where the pillar is, drawn like the structural pillar.
    assert_eq!(leaf_contents(bsp, [0.0, 0.0, 0.0]), contents::SOLID);
    assert_eq!(leaf_contents(bsp, [64.0, 0.0, 0.0]), contents::EMPTY);
    assert_eq!(
        out.stats.face_stats.after_merge,
        structural.stats.face_stats.after_merge
    );
    let prt = PortalFile::parse(&out.portals.write()).expect("prt");
    assert_eq!(prt.num_leafs as i32, bsp.models[0].vis_leafs);
    let clusters = checked_clusters(&prt);
    // The room is one cluster: the pillar does not cut it up for vis.
    assert!(
        clusters.len() < prt.num_leafs as usize,
        "{} clusters, {} leaves",
        clusters.len(),
        prt.num_leafs
    );
    assert_eq!(clusters.len(), 1);
    assert_eq!(out.stats.clusters, 1);
    // The structural pillar gives a leaf per side of it.
    let prt1 = PortalFile::parse(&structural.portals.write()).expect("prt1");
    assert!(prt1.clusters.is_none());
    assert!(prt1.num_leafs >= 4 && !prt1.portals.is_empty());
}

/// Two rooms joined by a doorway with a detail pillar in each: PRT2 portals join the clusters,
/// each facing its first cluster.
#[test]
fn cluster_portals_face_their_first_cluster() {
    let mut world = String::new();
    // The wall between two 256-unit rooms along x, with a doorway at y in -32..32.
    world += &box_brush([-144.0, -144.0, -144.0], [400.0, 144.0, -128.0], "floor");
    world += &box_brush([-144.0, -144.0, 128.0], [400.0, 144.0, 144.0], "ceiling");
    world += &box_brush([-144.0, -144.0, -128.0], [-128.0, 144.0, 128.0], "wall");
    world += &box_brush([384.0, -144.0, -128.0], [400.0, 144.0, 128.0], "wall");
    world += &box_brush([-128.0, -144.0, -128.0], [384.0, -128.0, 128.0], "wall");
    world += &box_brush([-128.0, 128.0, -128.0], [384.0, 144.0, 128.0], "wall");
    world += &box_brush([128.0, -128.0, -128.0], [144.0, -32.0, 128.0], "wall");
    world += &box_brush([128.0, 32.0, -128.0], [144.0, 128.0, 128.0], "wall");
    let pillars = box_brush([-16.0, -16.0, -128.0], [16.0, 16.0, 0.0], "pillar")
        + &box_brush([240.0, 40.0, -128.0], [300.0, 60.0, 128.0], "pillar");
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n{world}}}\n{}{{\n\"classname\" \"info_player_start\"\n\"origin\" \"-32 -32 -100\"\n}}\n",
        brush_entity("func_detail", &pillars)
    );
    let out = compile_text(&text);
    assert!(out.leak.is_none(), "{:?}", out.warnings);
    let bsp = &out.bsp;
    let prt = PortalFile::parse(&out.portals.write()).expect("prt");
    let clusters = checked_clusters(&prt);
    assert!(clusters.len() >= 2 && !prt.portals.is_empty());
    let cluster_of_leaf = |leaf: usize| {
        clusters
            .iter()
            .position(|c| c.contains(&(leaf as u32 - 1)))
            .expect("leaf in a cluster")
    };
    for p in &prt.portals {
        assert_ne!(p.leafs[0], p.leafs[1]);
        let plane = p.winding.plane().expect("plane");
        let c = p.winding.center();
        for (side, cluster) in [(1.0, p.leafs[0]), (-1.0, p.leafs[1])] {
            let probe = c + plane.normal * side;
            let leaf = bsp.leaf_at(probe.as_vec3().to_array()).expect("leaf");
            assert_eq!(cluster_of_leaf(leaf), cluster as usize, "{probe:?}");
        }
    }
}

#[test]
fn detail_does_not_seal() {
    // The gap in the +x wall, filled by a detail brush, then by a structural one.
    let plug = box_brush([128.0, 0.0, -128.0], [144.0, 32.0, 128.0], "wall");
    let out = compile_text(&room_map_with(
        true,
        "",
        &brush_entity("func_detail", &plug),
    ));
    let leak = out.leak.expect("a detail-sealed map leaks");
    assert_eq!(leak.classname, "info_player_start");
    let out = compile_text(&room_map(true, &plug));
    assert!(out.leak.is_none(), "{:?}", out.warnings);
}

#[test]
fn illusionary_detail_is_drawn_and_not_solid() {
    let block = box_brush([-64.0, -64.0, -128.0], [0.0, 0.0, -64.0], "block");
    let out = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_detail_illusionary", &block),
    ));
    let bsp = &out.bsp;
    assert!(out.leak.is_none(), "{:?}", out.warnings);
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert!(
        !out.warnings
            .iter()
            .any(|w| matches!(w, Warning::Unsupported { .. }))
    );
    assert_eq!(bsp.models.len(), 1);
    // Empty inside, for hull 0 and the player's hull.
    assert_eq!(leaf_contents(bsp, [-32.0, -32.0, -96.0]), contents::EMPTY);
    assert_eq!(
        hull_contents(bsp, 1, [-32.0, -32.0, -100.0]),
        contents::EMPTY
    );
    // Its five open sides are drawn from outside (the bottom lies on the floor), and the floor
    // under it is kept.
    let block_faces: Vec<_> = bsp
        .faces
        .iter()
        .filter(|f| {
            let info = &bsp.texinfo[f.texinfo as usize];
            bsp.textures.textures[info.miptex as usize]
                .as_ref()
                .is_some_and(|t| t.name().eq_ignore_ascii_case("block"))
        })
        .collect();
    assert_eq!(block_faces.len(), 5);
    for f in &block_faces {
        let verts = bsp.face_vertices(f).expect("vertices");
        let n = face_normal(bsp, f);
        let c = verts.iter().fold([0.0f32; 3], |acc, v| {
            [acc[0] + v[0], acc[1] + v[1], acc[2] + v[2]]
        });
        let c = c.map(|x| x / verts.len() as f32);
        // Facing out of the block.
        assert!(
            c[0] + n[0] > 0.0
                || c[0] + n[0] < -64.0
                || c[1] + n[1] > 0.0
                || c[1] + n[1] < -64.0
                || c[2] + n[2] > -64.0,
            "{c:?} {n:?}"
        );
    }
    let floor_area: f64 = face_area_with_texture(bsp, "floor");
    assert!((floor_area - 256.0 * 256.0).abs() < 1.0, "{floor_area}");
}

fn face_area_with_texture(bsp: &Bsp, name: &str) -> f64 {
    let mut area = 0.0;
    for f in &bsp.faces {
        let info = &bsp.texinfo[f.texinfo as usize];
        let named = bsp.textures.textures[info.miptex as usize]
            .as_ref()
            .is_some_and(|t| t.name().eq_ignore_ascii_case(name));
        if !named {
            continue;
        }
        let v: Vec<DVec3> = bsp
            .face_vertices(f)
            .expect("vertices")
            .iter()
            .map(|&p| Vec3::from(p).as_dvec3())
            .collect();
        area += quake_formats::geom::Winding::new(v).area();
    }
    area
}

#[test]
fn fence_detail_keeps_the_faces_behind_it() {
    // A fence slab standing on the floor against the -x wall.
    let fence = box_brush([-128.0, -64.0, -128.0], [-120.0, 64.0, 0.0], "{fence");
    let out = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_detail_fence", &fence),
    ));
    let bsp = &out.bsp;
    assert!(out.leak.is_none(), "{:?}", out.warnings);
    assert_eq!(errors(bsp), Vec::<String>::new());
    // Solid for engines and the player, yet a leaf of its own that vis looks through.
    assert_eq!(leaf_contents(bsp, [-124.0, 0.0, -64.0]), contents::SOLID);
    assert_ne!(bsp.leaf_at([-124.0, 0.0, -64.0]), Some(0));
    assert_eq!(hull_contents(bsp, 1, [-110.0, 0.0, -64.0]), contents::SOLID);
    // The wall and floor behind the fence are whole.
    let wall_and_floor = face_area_with_texture(bsp, "wall") + face_area_with_texture(bsp, "floor");
    let plain = compile_text(&room_map(false, ""));
    let plain_area =
        face_area_with_texture(&plain.bsp, "wall") + face_area_with_texture(&plain.bsp, "floor");
    assert!(
        (wall_and_floor - plain_area).abs() < 1.0,
        "{wall_and_floor} vs {plain_area}"
    );
    // Every face is listed in an open leaf, so engines draw the wall seen through the fence.
    let mut listed = vec![false; bsp.faces.len()];
    for leaf in &bsp.leafs[1..] {
        if leaf.contents == contents::SOLID {
            continue;
        }
        let first = leaf.first_marksurface as usize;
        for &m in &bsp.marksurfaces[first..first + leaf.num_marksurfaces as usize] {
            listed[m as usize] = true;
        }
    }
    assert!(listed.iter().all(|&l| l), "{listed:?}");
    let prt = PortalFile::parse(&out.portals.write()).expect("prt");
    checked_clusters(&prt);
}

fn faces_with_texture(bsp: &Bsp, name: &str) -> usize {
    bsp.faces
        .iter()
        .filter(|f| {
            let info = &bsp.texinfo[f.texinfo as usize];
            bsp.textures.textures[info.miptex as usize]
                .as_ref()
                .is_some_and(|t| t.name().eq_ignore_ascii_case(name))
        })
        .count()
}

#[test]
fn detail_walls_do_not_cut_the_faces_they_touch() {
    // A slab standing against the middle of the -x wall.
    let slab = box_brush([-128.0, -40.0, -100.0], [-112.0, 24.0, 60.0], "slab");
    let plain = compile_text(&room_map(false, ""));
    let detail = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_detail", &slab),
    ));
    let wall = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_detail_wall", &slab),
    ));
    assert!(wall.leak.is_none(), "{:?}", wall.warnings);
    assert_eq!(errors(&wall.bsp), Vec::<String>::new());
    assert_eq!(
        leaf_contents(&wall.bsp, [-120.0, 0.0, 0.0]),
        contents::SOLID
    );
    // func_detail cuts the wall around the slab; func_detail_wall leaves it as it was.
    let walls = |out: &CompileOutput| faces_with_texture(&out.bsp, "wall");
    assert!(walls(&detail) > walls(&plain));
    assert_eq!(walls(&wall), walls(&plain));
    assert_eq!(faces_with_texture(&wall.bsp, "slab"), 5);
}

#[test]
fn brush_entities_become_submodels() {
    let door = format!(
        "}}\n{{\n\"classname\" \"func_door\"\n\"angle\" \"90\"\n{}",
        box_brush([-32.0, -8.0, -128.0], [32.0, 8.0, 0.0], "door")
    );
    // `door` closes worldspawn early and opens the door entity, whose '}' the room map supplies.
    let out = compile_text(&room_map(false, &door));
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert_eq!(bsp.models.len(), 2);
    assert_eq!(bsp.models[1].num_faces, 6);
    // The model's box is the door's own a unit inside (engines widen it back as they load it and
    // derive its travel from it), not grown by a hull.
    assert_eq!(bsp.models[1].mins, [-31.0, -7.0, -127.0]);
    assert_eq!(bsp.models[1].maxs, [31.0, 7.0, -1.0]);
    assert!(bsp.entity_text().contains("\"model\" \"*1\""));
    check_round_trip(bsp);
}

/// Every node and clip node a model reaches comes after its parent, so after the model's head:
/// QuakeSpasm rejects a clip node numbered below the head ("SV_RecursiveHullCheck: bad node
/// number") on the first trace.
fn assert_pre_order(bsp: &Bsp) {
    for (m, model) in bsp.models.iter().enumerate() {
        for hull in 0..3 {
            let head = model.head_nodes[hull];
            let mut stack = vec![head];
            while let Some(n) = stack.pop() {
                if n < 0 {
                    continue;
                }
                let children = if hull == 0 {
                    bsp.nodes[n as usize].children
                } else {
                    bsp.clipnodes[n as usize].children
                };
                for c in children.into_iter().filter(|&c| c >= 0) {
                    assert!(c > n, "model {m} hull {hull}: node {n} has child {c}");
                    stack.push(c);
                }
            }
        }
    }
}

#[test]
fn nodes_and_clip_nodes_are_numbered_head_first() {
    let door = format!(
        "}}\n{{\n\"classname\" \"func_door\"\n{}",
        box_brush([-32.0, -8.0, -128.0], [32.0, 8.0, 0.0], "door")
    );
    let pillar = box_brush([40.0, 40.0, -128.0], [72.0, 72.0, 128.0], "wall");
    let out = compile_text(&room_map(false, &format!("{pillar}{door}")));
    assert_eq!(out.bsp.models.len(), 2);
    assert!(out.bsp.models.iter().all(|m| m.head_nodes[1] >= 0));
    assert_pre_order(&out.bsp);
}

/// Each vertex of model `m`'s faces moved by `origin`, with its texture coordinates.
fn model_texels(bsp: &Bsp, m: usize, origin: [f32; 3]) -> Vec<[i64; 5]> {
    let model = &bsp.models[m];
    let mut out = Vec::new();
    for f in &bsp.faces[model.first_face as usize..(model.first_face + model.num_faces) as usize] {
        let info = &bsp.texinfo[f.texinfo as usize];
        for v in bsp.face_vertices(f).expect("vertices") {
            let p = [v[0] + origin[0], v[1] + origin[1], v[2] + origin[2]];
            let st = info
                .vecs
                .map(|r| r[0] * v[0] + r[1] * v[1] + r[2] * v[2] + r[3]);
            let q = |x: f32| (x * 64.0).round() as i64;
            out.push([q(p[0]), q(p[1]), q(p[2]), q(st[0]), q(st[1])]);
        }
    }
    out.sort_unstable();
    out
}

#[test]
fn origin_brushes_set_the_origin_of_their_model() {
    let door = box_brush([32.0, -8.0, -128.0], [96.0, 8.0, 0.0], "door");
    let origin = box_brush([56.0, -8.0, -72.0], [72.0, 8.0, -56.0], "origin");
    let plain = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_rotate_door", &door),
    ));
    let out = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_rotate_door", &(door + &origin)),
    ));
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert!(bsp.entity_text().contains("\"origin\" \"64 0 -64\""));
    // Built around the origin: the engine moves it back into place.
    assert_eq!(bsp.models[1].mins, [-31.0, -7.0, -63.0]);
    assert_eq!(bsp.models[1].maxs, [31.0, 7.0, 63.0]);
    // The origin brush is neither drawn nor solid, and the textures stay where they were.
    assert_eq!(bsp.models[1].num_faces, plain.bsp.models[1].num_faces);
    assert_eq!(
        model_texels(bsp, 1, [64.0, 0.0, -64.0]),
        model_texels(&plain.bsp, 1, [0.0; 3])
    );
}

#[test]
fn origin_keys_and_rotate_targets_set_the_origin_of_their_model() {
    let door = box_brush([32.0, -8.0, -128.0], [96.0, 8.0, 0.0], "door");
    let plain = compile_text(&room_map_with(false, "", &brush_entity("func_wall", &door)));
    let pivot =
        "{\n\"classname\" \"info_rotate\"\n\"targetname\" \"pivot\"\n\"origin\" \"64 0 -64\"\n}\n";
    for entity in [
        // An origin key alone (Quake 2 style)...
        format!("{{\n\"classname\" \"func_wall\"\n\"origin\" \"64 0 -64\"\n{door}}}\n"),
        // ...or Hipnotic's rotate_object turning about the info_rotate it targets.
        format!("{{\n\"classname\" \"rotate_object\"\n\"target\" \"pivot\"\n{door}}}\n{pivot}"),
    ] {
        let out = compile_text(&room_map_with(false, "", &entity));
        let bsp = &out.bsp;
        assert_eq!(errors(bsp), Vec::<String>::new());
        assert!(
            bsp.entity_text().contains("\"origin\" \"64 0 -64\""),
            "{entity}"
        );
        assert_eq!(bsp.models[1].mins, [-31.0, -7.0, -63.0], "{entity}");
        assert_eq!(bsp.models[1].maxs, [31.0, 7.0, 63.0], "{entity}");
        assert_eq!(
            model_texels(bsp, 1, [64.0, 0.0, -64.0]),
            model_texels(&plain.bsp, 1, [0.0; 3])
        );
    }
}

#[test]
fn same_input_gives_the_same_bytes() {
    let pillar = box_brush([-16.0, -20.0, -128.0], [16.0, 16.0, 100.0], "pillar");
    let text = room_map(false, &pillar);
    let a = compile_text(&text).bsp.write().expect("write");
    let b = compile_text(&text).bsp.write().expect("write");
    assert!(a == b);
}

#[test]
fn syntax_errors_name_the_place() {
    let source = MapSource {
        path: PathBuf::from("broken.map"),
        text: "{\n\"classname\" \"worldspawn\"\n{\n( 0 0 0 ) ( 1 0 0 ) oops\n}\n}\n".to_string(),
    };
    let err = compile(&source, &CompileOptions::default()).expect_err("syntax error");
    assert!(err.to_string().starts_with("broken.map:4:"), "{err}");
}

/// Regression (DarkPlaces' "new portal was clipped away" on LibreQuake e3m4): a post reaching
/// past a hint plane by less than it can be cut was kept whole above it too, and its foot became
/// a node plane above the hint, where it crosses nothing.
#[test]
fn a_post_grazing_a_hint_gives_no_node_outside_its_region() {
    let post = box_brush([0.0, 0.0, -128.0], [1.0, 1.0, 0.05], "wall");
    let mut faces: Vec<String> = box_brush([-128.0, -128.0, -8.0], [128.0, 128.0, 0.0], "skip")
        .lines()
        .map(str::to_string)
        .collect();
    // Line 0 is the brace; the +z face comes fifth.
    faces[5] = faces[5].replace("skip", "hint");
    let hint = faces.join("\n") + "\n";
    let out = compile_text(&room_map(false, &(post + &hint)));
    assert_node_planes_cross_their_regions(&out.bsp, "post and hint");
    assert_eq!(leaf_contents(&out.bsp, [0.5, 0.5, -64.0]), contents::SOLID);
    assert_eq!(leaf_contents(&out.bsp, [0.5, 0.5, 16.0]), contents::EMPTY);
}

/// Every map of the repository's `maps/` compiles to a BSP without a problem of any severity and
/// without a compiler warning (but for the hard cases in `maps/hard`); only the leak test leaks.
#[test]
fn repository_maps_compile() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps");
    let mut pending = vec![dir.clone()];
    let mut count = 0;
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d).expect("maps/") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                pending.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "map") {
                continue;
            }
            let source = MapSource::read(&path).expect("read");
            // maps/hard/README.md: a header line says what the compiler must make of a map.
            if source.text.contains("\n// expect: refused") {
                continue;
            }
            let options = CompileOptions {
                wad_dirs: vec![dir.clone()],
                ..CompileOptions::default()
            };
            let out = compile(&source, &options).expect("compile");
            let name = path.display().to_string();
            let problems: Vec<String> = validate(&out.bsp).iter().map(|p| p.to_string()).collect();
            assert_eq!(problems, Vec::<String>::new(), "{name}");
            // The hard cases are hostile on purpose: what they trip must be warned about.
            if !path.starts_with(dir.join("hard")) {
                let warnings: Vec<String> = out
                    .warnings
                    .iter()
                    .filter(|w| !matches!(w, Warning::Leak { .. }))
                    .map(|w| w.to_string())
                    .collect();
                assert_eq!(warnings, Vec::<String>::new(), "{name}");
            }
            assert_finite_bounds(&out.bsp, &name);
            assert_node_planes_cross_their_regions(&out.bsp, &name);
            assert_textures_project_squarely(&out.bsp, &name);
            assert_faces_are_simple(&out.bsp, &name);
            let leaks = name.ends_with("leak.map") || source.text.contains("\n// expect: leaks");
            assert_eq!(out.leak.is_some(), leaks, "{name}");
            count += 1;
        }
    }
    assert!(count >= 12, "only {count} maps found");
}

fn corpus() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus");
    if dir.is_dir() {
        Some(dir)
    } else {
        println!("SKIPPED: no corpus at {}", dir.display());
        None
    }
}

fn compile_corpus_map(rel: &str) -> Option<CompileOutput> {
    let dir = corpus()?;
    let source = MapSource::read(&dir.join("public/maps").join(rel)).expect("read");
    let options = CompileOptions {
        wad_dirs: vec![dir.join("wads/librequake"), dir.join("wads/ericw-tools")],
        ..CompileOptions::default()
    };
    let out = compile(&source, &options).expect("compile");
    assert_eq!(errors(&out.bsp), Vec::<String>::new(), "{rel}");
    // QuakeSpasm and DarkPlaces size every lit face's lightmap alike (LibreQuake e1m3, e3m4 and
    // e2m4 have faces of rotated brushes they would not).
    assert_eq!(out.stats.lightmap_grid.unresolved_faces, 0, "{rel}");
    assert_finite_bounds(&out.bsp, rel);
    assert_node_planes_cross_their_regions(&out.bsp, rel);
    assert_textures_project_squarely(&out.bsp, rel);
    assert_faces_are_simple(&out.bsp, rel);
    check_round_trip(&out.bsp);
    let prt = PortalFile::parse(&out.portals.write()).expect("prt");
    assert_eq!(prt.num_leafs as i32, out.bsp.models[0].vis_leafs, "{rel}");
    if prt.clusters.is_some() {
        checked_clusters(&prt);
    }
    Some(out)
}

#[test]
fn corpus_small_maps_compile() {
    for rel in [
        "ericw-tools/q1_cube.map",
        "ericw-tools/q1_detail_fence2.map",
    ] {
        compile_corpus_map(rel);
    }
    if let Some(out) = compile_corpus_map("librequake/start.map") {
        assert!(out.leak.is_none(), "{:?}", out.leak);
        assert_eq!(
            out.bsp.models.len(),
            53,
            "the reference start.bsp has 53 models"
        );
        assert_eq!(out.stats.bad_brushes, 0);
    }
}

/// Slow in debug builds: `cargo test -p slipgate-bsp --release -- --ignored`.
#[test]
#[ignore]
fn corpus_maps_compile() {
    for rel in [
        "librequake/start.map",
        "id/e1m1.map",
        "ericw-tools/light_general.map",
        "ericw-tools/q1_mountain.map",
        "ericw-tools/retrojam1_ericw.map",
        "librequake/e1m3.map",
        "librequake/e3m4.map",
        "librequake/e2m4.map",
        "id/e1m2.map",
        "id/dm2.map",
        "id/e2m5.map",
    ] {
        if let Some(out) = compile_corpus_map(rel) {
            // q1_mountain leaks on purpose; every other map is sealed (e3m4 once leaked through
            // a sliver a grazing split left uncovered inside a wall; e1m2 and e2m5 through an
            // entity on a brush's outer face, dm2 through a brush dropped for a repeated face).
            assert_eq!(out.leak.is_some(), rel.contains("mountain"), "{rel}");
            println!(
                "{rel}: {} faces, leak {:?}",
                out.bsp.faces.len(),
                out.leak.map(|l| l.entity)
            );
        }
    }
}

const PLAYER_START: &str = "{\n\"classname\" \"info_player_start\"\n\"origin\" \"0 0 32\"\n}\n";

fn world_with(brushes: &str) -> String {
    format!("{{\n\"classname\" \"worldspawn\"\n{brushes}}}\n")
}

/// A world with nothing to draw or see is an error naming the file and worldspawn, never a file
/// (one whose edge 0 named a vertex that did not exist, or whose world node had one leaf on both
/// sides), even when a brush entity has brushes.
#[test]
fn a_world_without_brushes_is_an_error() {
    let door = brush_entity("func_door", &box_brush([0.0; 3], [8.0; 3], "door"));
    let degenerate = "{\n( 0 0 0 ) ( 0 0 0 ) ( 0 0 0 ) wall 0 0 0 1 1\n\
                      ( 0 0 0 ) ( 1 0 0 ) ( 0 1 0 ) wall 0 0 0 1 1\n}\n";
    let clip = box_brush([0.0; 3], [8.0; 3], "clip");
    let origin = box_brush([0.0; 3], [8.0; 3], "origin");
    let clip_and_origin = format!("{clip}{origin}");
    let clip_and_bad = format!("{clip}{degenerate}");
    for (brushes, entities, detail) in [
        ("", PLAYER_START.to_string(), ""),
        ("", format!("{door}{PLAYER_START}"), ""),
        (
            degenerate,
            PLAYER_START.to_string(),
            " (1 given: only clip, origin or bad brushes; the first bad one, line 3: has 1 planes, \
             fewer than 4 once 1 unusable faces are dropped)",
        ),
        (
            clip_and_bad.as_str(),
            PLAYER_START.to_string(),
            " (2 given: only clip, origin or bad brushes; the first bad one, line 11: has 1 planes, \
             fewer than 4 once 1 unusable faces are dropped)",
        ),
        (
            clip_and_origin.as_str(),
            PLAYER_START.to_string(),
            " (2 given: only clip or origin brushes)",
        ),
    ] {
        let text = format!("{}{entities}", world_with(brushes));
        let err = match try_compile(&text) {
            Err(e @ CompileError::EmptyWorld { .. }) => e,
            other => panic!("{text}: {:?}", other.map(|o| o.stats)),
        };
        assert_eq!(
            err.to_string(),
            format!(
                "inline.map: worldspawn (entity 0) has no brushes to build{detail}: there is no \
                 world to compile"
            )
        );
    }
}

/// A world of brushes that are not solid walls (liquid, sky, invisible, hint) is a valid, leaking
/// map with the contents each kind means.
#[test]
fn worlds_without_walls_compile_to_valid_files() {
    let inside = [0.0, 0.0, -32.0];
    // Texture, hull 0 and hull 1 contents inside the brush, and whether it has faces.
    for (texture, hull0, hull1, drawn) in [
        ("*water", contents::WATER, contents::EMPTY, true),
        ("sky1", contents::SKY, contents::SOLID, true),
        ("trigger", contents::SOLID, contents::SOLID, false),
        ("skip", contents::SOLID, contents::SOLID, false),
        ("hint", contents::EMPTY, contents::EMPTY, false),
    ] {
        let brush = box_brush([-64.0, -64.0, -64.0], [64.0, 64.0, 0.0], texture);
        let out = compile_text(&format!("{}{PLAYER_START}", world_with(&brush)));
        let bsp = &out.bsp;
        assert_eq!(errors(bsp), Vec::<String>::new(), "{texture}");
        // Not `check_round_trip`: the `qbsp` crate cannot read the empty texture lump of a world
        // that draws nothing, which engines (and ericw-tools) accept.
        let back = Bsp::read(&bsp.write().expect("write")).expect("read back");
        assert_eq!(errors(&back), Vec::<String>::new(), "{texture}");
        assert!(out.leak.is_some(), "{texture}");
        assert_eq!(!bsp.faces.is_empty(), drawn, "{texture}");
        assert_eq!(leaf_contents(bsp, inside), hull0, "{texture}");
        assert_eq!(hull_contents(bsp, 1, inside), hull1, "{texture}");
    }
}

/// Editor groups merge into the world: none of them reaches the entity lump, even one that holds
/// only point entities (TrenchBroom writes those; e2m4 had 88, each a "no spawn function").
#[test]
fn world_merged_entities_leave_the_entity_lump() {
    let pillar = box_brush([-16.0, -16.0, -128.0], [16.0, 16.0, 0.0], "pillar");
    let entities = format!(
        "{}{}{{\n\"classname\" \"func_group\"\n\"_tb_type\" \"_tb_group\"\n}}\n",
        brush_entity("func_group", &pillar),
        brush_entity("func_detail", ""),
    );
    let out = compile_text(&room_map_with(false, "", &entities));
    let text = out.bsp.entity_text();
    assert!(!text.contains("func_group"), "{text}");
    assert!(!text.contains("func_detail"), "{text}");
    assert!(text.contains("info_player_start"), "{text}");
}

/// Regression: a button using only `+3button` was written with that one frame (QuakeSpasm:
/// "Missing frame 0 of +3BUTNN"), and a placeholder named `SKY4` crashed DarkPlaces 2018, which
/// counts sky textures case-sensitively before it lowercases names.
#[test]
fn animations_are_completed_and_names_lowercased() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("animated_textures");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let frame = |name: &str| {
        let mips = std::array::from_fn(|level| vec![7u8; (32usize >> level).pow(2)]);
        WadLump::miptex(MipTex::new(name, 32, 32, mips))
    };
    let wad = Wad::new(
        ["+0button", "+1button", "+2button", "+3button", "+abutton"]
            .into_iter()
            .map(frame)
            .collect(),
    );
    std::fs::write(dir.join("anim.wad"), wad.write()).expect("write WAD");
    let extra = box_brush([-64.0, 120.0, -64.0], [-32.0, 128.0, -32.0], "+3BUTTON")
        + &box_brush([-32.0, -32.0, 96.0], [32.0, 32.0, 128.0], "SKY4")
        + &box_brush([32.0, -32.0, -128.0], [64.0, 32.0, -96.0], "+1LIFT");
    let source = MapSource {
        path: PathBuf::from("inline.map"),
        text: room_map(false, &extra).replace("none.wad", "anim.wad"),
    };
    let options = CompileOptions {
        wad_dirs: vec![dir],
        ..CompileOptions::default()
    };
    let out = compile(&source, &options).expect("compile");
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    // skip, listed first as ericw-tools lists it, is in no WAD here and no face shows it.
    assert!(out.bsp.textures.textures[0].is_none());
    let mut names: Vec<String> = out
        .bsp
        .textures
        .textures
        .iter()
        .skip(1)
        .map(|t| {
            let t = t.as_ref().expect("every texture is written");
            assert!(t.mips.is_some(), "{} has pixels", t.name());
            t.name()
        })
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "+0button", "+0lift", "+1button", "+1lift", "+2button", "+3button", "+abutton",
            "ceiling", "floor", "sky4", "wall"
        ]
    );
    assert_eq!(faces_with_texture(&out.bsp, "+3button"), 5);
    assert!(
        out.warnings.contains(&Warning::MissingAnimationFrame {
            name: "+0lift".to_string()
        }),
        "{:?}",
        out.warnings
    );
}
