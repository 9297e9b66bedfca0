//! Liquids and vis: with transparent water (the default, ericw-tools' `-transwater`) liquids are
//! detail, so a pool does not cut its room into clusters; `-notranswater` makes them structural
//! and opaque to vis. `*waterskip` and its kin are liquids without faces.

mod common;

use bsp_compiler::CompileOptions;
use common::*;
use quake_formats::bsp::contents;
use quake_formats::prt::PortalFile;

/// A room half full of water, with a corridor leaving it below the water line (-x) and one
/// above it (+x), as ericw-tools' `q1_liquid_is_detail`.
fn pool_and_corridors(water: bool) -> String {
    let (a, b) = (-144.0, 144.0);
    let mut world = String::new();
    world += &box_brush([a, a, a], [b, b, -128.0], "floor");
    world += &box_brush([a, a, 128.0], [b, b, b], "ceiling");
    world += &box_brush([-128.0, a, -128.0], [128.0, -128.0, 128.0], "wall");
    world += &box_brush([-128.0, 128.0, -128.0], [128.0, b, 128.0], "wall");
    // The -x wall, open at y -32..32, z -128..-64, and the corridor behind it.
    world += &box_brush([a, a, -128.0], [-128.0, -32.0, 128.0], "wall");
    world += &box_brush([a, 32.0, -128.0], [-128.0, b, 128.0], "wall");
    world += &box_brush([a, -32.0, -64.0], [-128.0, 32.0, 128.0], "wall");
    world += &box_brush([-272.0, -48.0, -144.0], [a, 48.0, -128.0], "floor");
    world += &box_brush([-272.0, -48.0, -64.0], [a, 48.0, -48.0], "ceiling");
    world += &box_brush([-272.0, -48.0, -128.0], [a, -32.0, -64.0], "wall");
    world += &box_brush([-272.0, 32.0, -128.0], [a, 48.0, -64.0], "wall");
    world += &box_brush([-272.0, -32.0, -128.0], [-256.0, 32.0, -64.0], "wall");
    // The +x wall, open at y -32..32, z 32..96, and the corridor behind it.
    world += &box_brush([128.0, a, -128.0], [b, -32.0, 128.0], "wall");
    world += &box_brush([128.0, 32.0, -128.0], [b, b, 128.0], "wall");
    world += &box_brush([128.0, -32.0, -128.0], [b, 32.0, 32.0], "wall");
    world += &box_brush([128.0, -32.0, 96.0], [b, 32.0, 128.0], "wall");
    world += &box_brush([b, -48.0, 16.0], [272.0, 48.0, 32.0], "floor");
    world += &box_brush([b, -48.0, 96.0], [272.0, 48.0, 112.0], "ceiling");
    world += &box_brush([b, -48.0, 32.0], [272.0, -32.0, 96.0], "wall");
    world += &box_brush([b, 32.0, 32.0], [272.0, 48.0, 96.0], "wall");
    world += &box_brush([256.0, -32.0, 32.0], [272.0, 32.0, 96.0], "wall");
    if water {
        world += &box_brush([-128.0, -128.0, -128.0], [128.0, 128.0, 0.0], "*water");
        world += &box_brush([-256.0, -32.0, -128.0], [-128.0, 32.0, -64.0], "*water");
    }
    format!(
        "{{\n\"classname\" \"worldspawn\"\n\"wad\" \"none.wad\"\n{world}}}\n\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"0 0 64\"\n}}\n"
    )
}

const ABOVE: [f32; 3] = [40.0, -100.0, 64.0];
const BELOW: [f32; 3] = [40.0, -100.0, -64.0];
const LOWER: [f32; 3] = [-200.0, 0.0, -96.0];
const UPPER: [f32; 3] = [200.0, 0.0, 64.0];

/// The clusters of `points` in `out`'s portal file, and its portal count.
fn clusters_of(out: &bsp_compiler::CompileOutput, points: [[f32; 3]; 4]) -> (Vec<usize>, usize) {
    let prt = PortalFile::parse(&out.portals.write()).expect("prt");
    let clusters = prt
        .clusters
        .clone()
        .unwrap_or_else(|| (0..prt.num_leafs).map(|l| vec![l]).collect());
    let of = |p: [f32; 3]| {
        let leaf = out.bsp.leaf_at(p).expect("leaf") as u32 - 1;
        clusters
            .iter()
            .position(|c| c.contains(&leaf))
            .expect("a cluster")
    };
    (points.map(of).to_vec(), prt.portals.len())
}

#[test]
fn transparent_water_is_detail_for_vis() {
    let out = compile_text(&pool_and_corridors(true));
    assert!(out.leak.is_none(), "{:?}", out.leak);
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    let (c, portals) = clusters_of(&out, [ABOVE, BELOW, LOWER, UPPER]);
    // The room above and below water is one cluster; each corridor another.
    assert_eq!(c[0], c[1], "{c:?}");
    assert!(c[2] != c[0] && c[3] != c[0] && c[2] != c[3], "{c:?}");
    // The water adds no cluster and no portal.
    let dry = compile_text(&pool_and_corridors(false));
    let (_, dry_portals) = clusters_of(&dry, [ABOVE, BELOW, LOWER, UPPER]);
    assert_eq!(out.stats.clusters, dry.stats.clusters);
    assert_eq!(portals, dry_portals);
    let water = quake_formats::bsp::contents::WATER;
    let contents_at = |p| out.bsp.leafs[out.bsp.leaf_at(p).expect("leaf")].contents;
    assert_eq!((contents_at(BELOW), contents_at(LOWER)), (water, water));
    // As ericw-tools counts it: the shared solid leaf, air and water in the room, a leaf for
    // each corridor; three clusters joined by two portals.
    assert_eq!(out.bsp.leafs.len(), 5);
    assert_eq!((out.stats.clusters, portals), (3, 2));
}

#[test]
fn opaque_water_is_structural_and_closed_to_vis() {
    let options = CompileOptions {
        transwater: false,
        ..CompileOptions::default()
    };
    let out = try_compile_with(&pool_and_corridors(true), &options).expect("compile");
    assert_eq!(errors(&out.bsp), Vec::<String>::new());
    let (c, portals) = clusters_of(&out, [ABOVE, BELOW, LOWER, UPPER]);
    assert_ne!(c[0], c[1], "{c:?}");
    // The same leaves as with transparent water, each its own cluster, and the same two portals.
    assert_eq!(out.bsp.leafs.len(), 5);
    assert_eq!((out.stats.clusters, portals), (4, 2));
    // The lower corridor sees only the water, the upper one only the air above it.
    let prt = PortalFile::parse(&out.portals.write()).expect("prt");
    let joined = |a: usize, b: usize| {
        prt.portals.iter().any(|p| {
            let [x, y] = p.leafs.map(|l| l as usize);
            (x, y) == (a, b) || (x, y) == (b, a)
        })
    };
    assert!(!joined(c[0], c[1]), "air and water share a portal");
    assert!(portals > 0);
    let sees = |from: usize, to: usize| {
        // Connected through portals at all.
        let mut seen = vec![from];
        let mut i = 0;
        while i < seen.len() {
            for p in &prt.portals {
                let [x, y] = p.leafs.map(|l| l as usize);
                for (a, b) in [(x, y), (y, x)] {
                    if a == seen[i] && !seen.contains(&b) {
                        seen.push(b);
                    }
                }
            }
            i += 1;
        }
        seen.contains(&to)
    };
    assert!(sees(c[1], c[2]) && sees(c[0], c[3]));
    assert!(
        !sees(c[2], c[3]),
        "the corridors see each other through the water line"
    );
}

/// ericw-tools' invisible liquids: a `*waterskip` brush is water without faces of its own.
#[test]
fn waterskip_is_water_that_is_not_drawn() {
    let pool = box_brush([-64.0, -64.0, -128.0], [64.0, 64.0, -64.0], "*waterskip");
    let out = compile_text(&room_map(false, &pool));
    let bsp = &out.bsp;
    assert_eq!(errors(bsp), Vec::<String>::new());
    assert!((0..bsp.faces.len()).all(|f| face_texture(bsp, f) != "*waterskip"));
    let leaf = bsp.leaf_at([0.0, 0.0, -96.0]).expect("leaf");
    assert_eq!(bsp.leafs[leaf].contents, contents::WATER);
    // The floor under it is drawn, seen from inside the water.
    assert!(!faces_at(bsp, 0, [0.0, 0.0, -128.0], Some([0.0, 0.0, 1.0])).is_empty());
}
