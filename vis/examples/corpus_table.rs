//! The speed-against-error table of vis/README.md (a benchmark, not a test):
//! `cargo run --release -p slipgate-vis --example corpus_table -- [MAP.map ...]`
//! (default: the corpus maps). Each map is compiled with the project's compiler; then vis runs
//! fast and full (levels 2 and 4) on its portals (best of three runs), and 1e6 random sight
//! lines traced through the BSP measure how much the PVS over-estimates what is visible and
//! whether it is too small.

use bsp_compiler::{CompileOptions, MapSource, compile};
use std::path::{Path, PathBuf};
use std::time::Instant;
use vis::sample::sample_visibility;
use vis::{VisMode, VisOptions, compute_vis};

const PAIRS: usize = 1_000_000;
const RUNS: usize = 3;

fn main() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus");
    let mut maps: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if maps.is_empty() {
        maps = [
            "librequake/start.map",
            "id/e1m1.map",
            "librequake/e1m3.map",
            "librequake/e2m4.map",
            "librequake/e3m4.map",
            "ericw-tools/retrojam1_ericw.map",
        ]
        .iter()
        .map(|m| corpus.join("public/maps").join(m))
        .collect();
    }
    println!(
        "| map | leaves / clusters / portals | mode | seconds | avg visible leaves | sampled visible | in PVS | over-estimate | too small |"
    );
    println!("|---|---|---|---:|---:|---:|---:|---:|---:|");
    for path in maps {
        let source = MapSource::read(&path).expect("read map");
        let options = CompileOptions {
            wad_dirs: vec![corpus.join("wads/librequake")],
            ..CompileOptions::default()
        };
        let out = compile(&source, &options).expect("compile");
        let name = path
            .file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned());
        for (mode_name, mode) in [
            ("fast", VisMode::Fast),
            ("full 2", VisMode::Full { level: 2 }),
            ("full 4", VisMode::Full { level: 4 }),
        ] {
            let options = VisOptions {
                mode,
                threads: None,
                ..Default::default()
            };
            // Best of `RUNS`: the machine is shared, and every run gives the same sets.
            let mut seconds = f64::INFINITY;
            let mut result = None;
            for _ in 0..RUNS {
                let start = Instant::now();
                result = Some(compute_vis(&out.portals, &options).expect("vis"));
                seconds = seconds.min(start.elapsed().as_secs_f64());
            }
            let result = result.expect("at least one run");
            let r = sample_visibility(&out.bsp, &result.pvs, PAIRS, 1).expect("sample");
            let s = &result.stats;
            println!(
                "| {name} | {} / {} / {} | {mode_name} | {seconds:.2} | {:.1} | {:.2}% | {:.2}% | {:.2}x | {} |",
                s.leafs,
                s.clusters,
                s.portals / 2,
                result.pvs.average_visible(),
                100.0 * r.visible_fraction,
                100.0 * r.pvs_fraction,
                r.pvs_fraction / r.visible_fraction.max(f64::MIN_POSITIVE),
                r.violations
            );
        }
    }
}
