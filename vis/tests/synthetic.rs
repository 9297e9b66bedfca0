//! Vis on synthetic worlds whose visibility is known.

use quake_formats::Bsp;
use quake_formats::bsp::face_flags::FaceFlags;
use quake_formats::bsp::{Face, TexInfo};
use quake_formats::miptex::MipTex;
use quake_formats::prt::PortalFile;
use vis::sample::sample_visibility;
use vis::synthetic::VoxelWorld;
use vis::{Pvs, VisError, VisMode, VisOptions, compute_vis, read_pvs, write_vis};

fn run(prt: &PortalFile, mode: VisMode) -> Pvs {
    let options = VisOptions {
        mode,
        threads: Some(2),
        ..Default::default()
    };
    compute_vis(prt, &options).expect("vis").pvs
}

const FULL: VisMode = VisMode::Full { level: 4 };

/// A corridor of 6 cells along x, turning into 6 cells along y at x = 5.
fn l_corridor() -> VoxelWorld {
    let mut w = VoxelWorld::new([6, 6, 1], 64.0);
    w.open_box([0, 0, 0], [5, 0, 0])
        .open_box([5, 0, 0], [5, 5, 0]);
    w
}

fn leaf(w: &VoxelWorld, x: usize, y: usize, z: usize) -> usize {
    w.leaf_of([x, y, z]).expect("open cell")
}

#[test]
fn straight_corridor_sees_its_whole_length() {
    let mut w = VoxelWorld::new([10, 1, 1], 64.0);
    w.open_box([0, 0, 0], [9, 0, 0]);
    let pvs = run(&w.portal_file(), FULL);
    for a in 0..10 {
        assert_eq!(pvs.row(a).count(), 10, "leaf {a}");
    }
}

#[test]
fn rooms_around_a_corner_do_not_see_each_other() {
    let w = l_corridor();
    let prt = w.portal_file();
    let full = run(&prt, FULL);
    let fast = run(&prt, VisMode::Fast);
    let start = leaf(&w, 0, 0, 0);
    // Along the first leg and just past the corner: visible.
    for x in 0..6 {
        assert!(full.sees(start, leaf(&w, x, 0, 0)), "x = {x}");
    }
    // Deep in the second leg: hidden by the corner.
    for y in 2..6 {
        let other = leaf(&w, 5, y, 0);
        assert!(!full.sees(start, other), "sees (5, {y})");
        assert!(!full.sees(other, start), "(5, {y}) sees the start");
    }
    // Base vis cannot tell; it sees round the corner.
    assert!(fast.sees(start, leaf(&w, 5, 5, 0)));
    assert!(full.is_subset_of(&fast));
    for a in 0..full.num_leafs() {
        for b in 0..full.num_leafs() {
            assert_eq!(full.sees(a, b), full.sees(b, a), "{a} and {b}");
        }
    }
}

#[test]
fn lower_levels_are_supersets_of_higher_ones() {
    let w = VoxelWorld::random_caves([12, 12, 3], 140, 7);
    let prt = w.portal_file();
    let mut looser = run(&prt, VisMode::Fast);
    for level in 0..=4 {
        let tighter = run(&prt, VisMode::Full { level });
        assert!(tighter.is_subset_of(&looser), "level {level}");
        looser = tighter;
    }
}

#[test]
fn full_vis_is_never_too_small_and_fast_is_a_superset() {
    for seed in 1..=4 {
        let w = VoxelWorld::random_caves([14, 14, 4], 220, seed);
        let prt = w.portal_file();
        let full = run(&prt, FULL);
        let fast = run(&prt, VisMode::Fast);
        assert!(full.is_subset_of(&fast), "seed {seed}");
        let bsp = w.bsp();
        let report = sample_visibility(&bsp, &full, 20_000, seed).expect("sample");
        assert_eq!(report.violations, 0, "seed {seed}: {:?}", report.examples);
        assert!(report.visible_fraction <= report.pvs_fraction);
        assert!(
            full.average_visible() < fast.average_visible(),
            "seed {seed}"
        );
    }
}

#[test]
fn clustered_portals_give_every_leaf_its_clusters_leaves_and_are_never_too_small() {
    for seed in 1..=3 {
        let w = VoxelWorld::random_caves([14, 14, 4], 220, seed);
        let prt = w.paired_portal_file();
        let clusters = prt.clusters.clone().expect("PRT2");
        assert!(
            clusters.len() < prt.num_leafs as usize,
            "seed {seed}: some pairs"
        );
        // Through the text format, as vis reads it.
        let prt = PortalFile::parse(&prt.write()).expect("parse");
        let fast = run(&prt, VisMode::Fast);
        for pvs in [run(&prt, FULL), fast.clone()] {
            assert!(pvs.is_subset_of(&fast), "seed {seed}");
            assert_eq!(pvs.num_leafs(), prt.num_leafs as usize);
            for members in &clusters {
                let first = members[0] as usize;
                for &leaf in members {
                    assert_eq!(pvs.row(leaf as usize), pvs.row(first), "seed {seed}");
                    assert!(pvs.sees(first, leaf as usize), "seed {seed}");
                }
            }
            let report = sample_visibility(&w.bsp(), &pvs, 20_000, seed).expect("sample");
            assert_eq!(report.violations, 0, "seed {seed}: {:?}", report.examples);
        }
    }
}

#[test]
fn pvs_written_into_a_bsp_reads_back_the_same() {
    let w = VoxelWorld::random_caves([10, 10, 3], 90, 3);
    let full = run(&w.portal_file(), FULL);
    let mut bsp = w.bsp();
    let stats = write_vis(&mut bsp, &full).expect("write");
    assert_eq!(stats.vis_leafs, full.num_leafs());
    assert!(stats.unique_rows <= full.num_leafs());
    assert_eq!(bsp.leafs[0].vis_offset, -1);
    let back = Bsp::read(&bsp.write().expect("encode")).expect("decode");
    assert_eq!(read_pvs(&back).expect("read"), full);
}

#[test]
fn identical_rows_are_stored_once() {
    // Every leaf of a straight corridor sees all of it: one row serves all.
    let mut w = VoxelWorld::new([20, 1, 1], 64.0);
    w.open_box([0, 0, 0], [19, 0, 0]);
    let mut bsp = w.bsp();
    let stats = write_vis(&mut bsp, &run(&w.portal_file(), FULL)).expect("write");
    assert_eq!(stats.unique_rows, 1);
    assert!(bsp.leafs[1..].iter().all(|l| l.vis_offset == 0));
}

#[test]
fn the_qbsp_crate_reads_our_rows_as_we_wrote_them() {
    let w = VoxelWorld::random_caves([12, 12, 3], 150, 11);
    let full = run(&w.portal_file(), FULL);
    let mut bsp = w.bsp();
    // qbsp wants a texture lump; engines do not.
    bsp.textures.textures.push(Some(water_texture()));
    write_vis(&mut bsp, &full).expect("write");
    let bytes = bsp.write().expect("encode");
    let data = qbsp::BspData::parse(qbsp::BspParseInput {
        bsp: &bytes,
        lit: None,
        settings: Default::default(),
    })
    .expect("qbsp parses our BSP");
    let n = full.num_leafs();
    for leaf in 1..=n {
        let theirs: Vec<usize> = data
            .potentially_visible_set(leaf)
            .expect("has a row")
            .into_leaf_indices()
            .ok()
            .expect("leaf indices")
            .filter(|&l| l <= n)
            .collect();
        let ours: Vec<usize> = full.row(leaf - 1).iter().map(|l| l + 1).collect();
        assert_eq!(theirs, ours, "leaf {leaf}");
    }
}

#[test]
fn a_portal_file_of_another_map_is_refused() {
    let w = l_corridor();
    let mut other = VoxelWorld::new([3, 1, 1], 64.0);
    other.open_box([0, 0, 0], [2, 0, 0]);
    let pvs = run(&other.portal_file(), FULL);
    let mut bsp = w.bsp();
    let err = write_vis(&mut bsp, &pvs).expect_err("3 leaves against 11");
    assert!(
        matches!(
            err,
            VisError::LeafCountMismatch {
                prt_leafs: 3,
                vis_leafs: 11
            }
        ),
        "{err}"
    );
    assert!(
        err.to_string().contains("does not belong to this BSP"),
        "{err}"
    );
}

#[test]
fn hand_written_prt1_of_three_leaves_in_a_row() {
    // Leaves 0 | 1 | 2 along x, portals at x = 64 and x = 128 (planes facing the first leaf).
    let text = "PRT1\n3\n2\n\
        4 0 1 (64 0 0 ) (64 64 0 ) (64 64 64 ) (64 0 64 )\n\
        4 1 2 (128 0 0 ) (128 64 0 ) (128 64 64 ) (128 0 64 )\n";
    let prt = PortalFile::parse(text).expect("parse");
    let graph = vis::PortalGraph::from_prt(&prt).expect("graph");
    assert_eq!(graph.misoriented_portals(), 0);
    let full = run(&prt, FULL);
    for a in 0..3 {
        assert_eq!(full.row(a).count(), 3);
    }
}

#[test]
fn a_portal_file_written_backwards_is_flagged() {
    let mut prt = l_corridor().portal_file();
    assert_eq!(
        vis::PortalGraph::from_prt(&prt)
            .expect("graph")
            .misoriented_portals(),
        0
    );
    for p in &mut prt.portals {
        p.leafs.swap(0, 1);
    }
    let graph = vis::PortalGraph::from_prt(&prt).expect("graph");
    assert!(graph.misoriented_portals() > graph.portals.len() / 2);
}

fn water_texture() -> MipTex {
    let mips = [0, 1, 2, 3].map(|level| vec![0u8; MipTex::mip_len(16, 16, level)]);
    MipTex::new("*water1", 16, 16, mips)
}

#[test]
fn leaves_that_see_water_hear_it_fading_with_distance() {
    // A corridor of 12 cells with a water surface on the floor of the first cell.
    let mut w = VoxelWorld::new([12, 1, 1], 64.0);
    w.open_box([0, 0, 0], [11, 0, 0]);
    let pvs = run(&w.portal_file(), FULL);
    let mut bsp = w.bsp();
    bsp.textures.textures.push(Some(water_texture()));
    bsp.texinfo.push(TexInfo {
        vecs: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]],
        miptex: 0,
        flags: 1,
    });
    bsp.vertices = vec![
        [0.0, 0.0, 0.0],
        [0.0, 64.0, 0.0],
        [64.0, 64.0, 0.0],
        [64.0, 0.0, 0.0],
    ];
    bsp.edges = vec![[0, 0], [0, 1], [1, 2], [2, 3], [3, 0]];
    bsp.surfedges = vec![1, 2, 3, 4];
    bsp.faces.push(Face {
        plane: 0,
        side: 0,
        first_edge: 0,
        num_edges: 4,
        texinfo: 0,
        styles: [0, 255, 255, 255],
        light_offset: -1,
    });
    bsp.marksurfaces.push(0);
    bsp.leafs[1].num_marksurfaces = 1;
    let hearing =
        vis::ambient::ambient_levels(&mut bsp, &pvs, vis::ambient::Channels::ALL).expect("ambient");
    let water: Vec<u8> = bsp.leafs[1..].iter().map(|l| l.ambient[0]).collect();
    assert_eq!(water[0], 255);
    assert_eq!(water[1], 255, "64 units away");
    assert!(water.windows(2).all(|p| p[0] >= p[1]), "{water:?}");
    assert_eq!(water[11], 0, "640 units away");
    assert_eq!(hearing, water.iter().filter(|&&l| l > 0).count());
    assert!(bsp.leafs.iter().all(|l| l.ambient[1..] == [0, 0, 0]));
    // `-noambientwater` (and `-noambient`) silence the channel.
    let quiet = vis::ambient::Channels::ALL.without(vis::ambient::Ambient::Water);
    let hearing = vis::ambient::ambient_levels(&mut bsp, &pvs, quiet).expect("ambient");
    assert_eq!(hearing, 0);
    assert!(bsp.leafs.iter().all(|l| l.ambient == [0; 4]));
    // A face whose entity has `_noambient 1` (the compiler's face flags) is silent, and so is a
    // liquid leaf it is in.
    let silent = FaceFlags {
        no_ambient: true,
        ..FaceFlags::default()
    };
    bsp.set_face_flags(&[silent]);
    bsp.leafs[1].contents = quake_formats::bsp::contents::WATER;
    let hearing =
        vis::ambient::ambient_levels(&mut bsp, &pvs, vis::ambient::Channels::ALL).expect("ambient");
    assert_eq!(hearing, 0);
}

#[test]
fn leaves_that_see_a_slime_leaf_hear_it_without_any_slime_texture() {
    // A corridor of 12 cells; the first cell is a slime volume with no faces at all.
    let mut w = VoxelWorld::new([12, 1, 1], 64.0);
    w.open_box([0, 0, 0], [11, 0, 0]);
    let pvs = run(&w.portal_file(), FULL);
    let mut bsp = w.bsp();
    bsp.leafs[1].contents = quake_formats::bsp::contents::SLIME;
    vis::ambient::ambient_levels(&mut bsp, &pvs, vis::ambient::Channels::ALL).expect("ambient");
    let slime: Vec<u8> = bsp.leafs[1..].iter().map(|l| l.ambient[2]).collect();
    assert_eq!(slime[0], 255);
    assert_eq!(slime[1], 255, "touching the slime leaf");
    assert!(slime.windows(2).all(|p| p[0] >= p[1]), "{slime:?}");
    assert_eq!(slime[11], 0, "640 units away");
    assert!(bsp.leafs[1..].iter().all(|l| l.ambient[0] == 0));
}

#[test]
fn the_pvs_does_not_depend_on_the_thread_count() {
    let w = VoxelWorld::random_caves([16, 16, 4], 400, 5);
    let prt = w.portal_file();
    let with = |threads| {
        let options = VisOptions {
            mode: FULL,
            threads: Some(threads),
            ..Default::default()
        };
        compute_vis(&prt, &options).expect("vis").pvs
    };
    assert_eq!(with(1), with(3));
}
