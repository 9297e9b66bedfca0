//! Compile benchmark: each corpus map (or each map named on the command line) is compiled N
//! times; the best time of every phase is printed, with the map's counts.
//!
//! `cargo run --release -p slipgate-bsp --example bench -- [--runs N] [MAP.map ...]`
//!
//! Without maps it takes the corpus maps under `../shared/corpus/public/maps`, largest last.

use bsp_compiler::{CompileOptions, MapSource, compile};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const CORPUS_MAPS: [&str; 6] = [
    "librequake/start.map",
    "id/e1m1.map",
    "ericw-tools/retrojam1_ericw.map",
    "librequake/e1m3.map",
    "librequake/e3m4.map",
    "librequake/e2m4.map",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut runs = 3usize;
    let mut maps: Vec<PathBuf> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        if arg == "--runs" {
            runs = args.next().ok_or("--runs needs a number")?.parse()?;
        } else {
            maps.push(PathBuf::from(arg));
        }
    }
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus");
    if maps.is_empty() {
        if !corpus.is_dir() {
            println!("SKIPPED: no corpus at {}", corpus.display());
            return Ok(());
        }
        maps = CORPUS_MAPS
            .iter()
            .map(|m| corpus.join("public/maps").join(m))
            .collect();
    }
    let options = CompileOptions {
        wad_dirs: vec![
            corpus.join("wads/librequake"),
            corpus.join("wads/ericw-tools"),
        ],
        ..CompileOptions::default()
    };
    for path in &maps {
        let source = MapSource::read(path)?;
        // Phase name to its best time, in the order phases first appear.
        let mut best: BTreeMap<usize, (String, f64)> = BTreeMap::new();
        let mut last = None;
        for _ in 0..runs.max(1) {
            let out = compile(&source, &options)?;
            for (i, (phase, secs)) in out.stats.timings.iter().enumerate() {
                let entry = best.entry(i).or_insert((phase.clone(), f64::INFINITY));
                entry.1 = entry.1.min(*secs);
            }
            last = Some(out.stats);
        }
        let Some(s) = last else { continue };
        println!(
            "{}: {} brushes, {} leaves, {} clusters, {} vis portals, {} faces, {} clipnodes (best of {runs})",
            path.display(),
            s.brushes,
            s.leaves,
            s.clusters,
            s.vis_portals,
            s.faces,
            s.clipnodes
        );
        for (phase, secs) in best.values() {
            println!("  {phase:<28} {secs:8.3} s");
        }
    }
    Ok(())
}
