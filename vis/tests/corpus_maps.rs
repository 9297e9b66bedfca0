//! Never too small on every corpus map: each is compiled with the project's compiler, then vis
//! runs fast and full and 1e6 random sight lines are traced through the result. Slow (it
//! compiles and vises six real maps), so ignored by default; run it with
//! `cargo test --release -p slipgate-vis --test corpus_maps -- --ignored --nocapture`.

use bsp_compiler::{CompileOptions, MapSource, compile};
use quake_formats::prt::PortalFile;
use std::path::{Path, PathBuf};
use vis::sample::sample_visibility;
use vis::{VisMode, VisOptions, compute_vis};

const MAPS: [&str; 6] = [
    "librequake/start.map",
    "id/e1m1.map",
    "librequake/e1m3.map",
    "librequake/e2m4.map",
    "librequake/e3m4.map",
    "ericw-tools/retrojam1_ericw.map",
];

fn corpus() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus");
    if dir.exists() {
        Some(dir)
    } else {
        println!("SKIPPED: no corpus at {}", dir.display());
        None
    }
}

fn check_map(corpus: &Path, rel: &str, pairs: usize) {
    let source = MapSource::read(&corpus.join("public/maps").join(rel)).expect("read map");
    let options = CompileOptions {
        wad_dirs: vec![corpus.join("wads/librequake")],
        ..CompileOptions::default()
    };
    let out = compile(&source, &options).expect("compile");
    // Through the text format, as vis reads it.
    let prt = PortalFile::parse(&out.portals.write()).expect("portal file");
    vis::check_portals_match(&out.bsp, prt.num_leafs as usize).expect("portals match");
    let mut fast_pvs = None;
    for mode in [VisMode::Fast, VisMode::Full { level: 4 }] {
        let options = VisOptions {
            mode,
            threads: None,
            ..Default::default()
        };
        let result = compute_vis(&prt, &options).expect("vis");
        let report = sample_visibility(&out.bsp, &result.pvs, pairs, 1).expect("sample");
        println!(
            "{rel} {mode:?}: {} leaves, {} clusters, average visible {:.1}, flow {:.2} s; \
             {:.2}% of sampled pairs visible, {:.2}% in the PVS, {} too small",
            result.stats.leafs,
            result.stats.clusters,
            result.pvs.average_visible(),
            result.stats.flow_seconds,
            100.0 * report.visible_fraction,
            100.0 * report.pvs_fraction,
            report.violations
        );
        assert_eq!(report.pairs, pairs);
        assert!(report.clear_pairs > 0, "{rel}: no clear sight line sampled");
        assert_eq!(
            report.violations, 0,
            "{rel} {mode:?}: too small: {:?}",
            report.examples
        );
        match &fast_pvs {
            None => fast_pvs = Some(result.pvs),
            Some(fast) => {
                assert!(result.pvs.is_subset_of(fast), "{rel}: full beyond fast");
                assert!(result.pvs.average_visible() < fast.average_visible());
            }
        }
    }
}

#[test]
#[ignore = "slow: compiles and vises six real maps; run with --release -- --ignored"]
fn every_corpus_map_is_never_too_small_fast_and_full() {
    let Some(corpus) = corpus() else { return };
    for rel in MAPS {
        check_map(&corpus, rel, 1_000_000);
    }
}
