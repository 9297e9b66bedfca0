//! The sampler on real maps whose PVS was computed by the reference tools: a check of the
//! sampler itself (their PVS should show no, or next to no, sight lines it misses).

use quake_formats::Bsp;
use std::path::{Path, PathBuf};
use vis::read_pvs;
use vis::sample::sample_visibility;

fn corpus_bsp(name: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/corpus/public/bsp/librequake")
        .join(name);
    if path.exists() {
        Some(path)
    } else {
        println!("SKIPPED: {} is absent", path.display());
        None
    }
}

fn sample_stored_pvs(name: &str, pairs: usize) {
    let Some(path) = corpus_bsp(name) else { return };
    let bsp = Bsp::read(&std::fs::read(&path).expect("read")).expect("parse");
    let pvs = read_pvs(&bsp).expect("stored pvs");
    let report = sample_visibility(&bsp, &pvs, pairs, 42).expect("sample");
    println!(
        "{name}: {} leaves, average PVS {:.1}: {report:?}",
        pvs.num_leafs(),
        pvs.average_visible()
    );
    assert_eq!(report.pairs, pairs);
    assert!(report.clear_pairs > 0);
    assert!(report.visible_fraction <= report.pvs_fraction);
    // Reference tools clip with epsilons too: allow a few grazing sight lines, no more.
    assert!(
        report.violations * 10_000 <= report.clear_pairs,
        "{name}: {} of {} clear sight lines missing from the stored PVS: {:?}",
        report.violations,
        report.clear_pairs,
        report.examples
    );
}

#[test]
fn stored_pvs_of_start_passes_the_sampler() {
    sample_stored_pvs("start.bsp", 100_000);
}

#[test]
fn stored_pvs_of_e1m3_passes_the_sampler() {
    sample_stored_pvs("e1m3.bsp", 100_000);
}

#[test]
fn our_vis_on_start_is_never_too_small_and_no_larger_than_the_stored_one() {
    let Some(path) = corpus_bsp("start.bsp") else {
        return;
    };
    let bsp = Bsp::read(&std::fs::read(&path).expect("read")).expect("parse");
    // Portals recovered from the compiled tree (PRT1 orientation: none may face the wrong way).
    let prt = vis::tree_portals::portals_from_bsp(&bsp).expect("portals");
    let graph = vis::PortalGraph::from_prt(&prt).expect("graph");
    assert_eq!(graph.misoriented_portals(), 0);
    let options = vis::VisOptions {
        mode: vis::VisMode::Full { level: 2 },
        threads: None,
        ..Default::default()
    };
    let ours = vis::compute_vis(&prt, &options).expect("vis").pvs;
    let stored = read_pvs(&bsp).expect("stored");
    println!(
        "start: ours {:.1}, stored {:.1}",
        ours.average_visible(),
        stored.average_visible()
    );
    assert!(ours.average_visible() <= stored.average_visible());
    let report = sample_visibility(&bsp, &ours, 100_000, 5).expect("sample");
    assert_eq!(report.violations, 0, "{:?}", report.examples);
}

/// ericw-tools leaves a few open leaves of e1m3 past the world's bounds (on one side): a sealed
/// map all the same, which the void check lets through; only a void all around is a leak.
#[test]
fn sealed_maps_from_ericw_tools_pass_the_void_check() {
    for name in ["start.bsp", "e1m3.bsp"] {
        let Some(path) = corpus_bsp(name) else { return };
        let bsp = Bsp::read(&std::fs::read(&path).expect("read")).expect("parse");
        vis::check_sealed(&bsp).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}
