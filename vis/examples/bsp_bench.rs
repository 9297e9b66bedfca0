//! Vis on real compiled maps, with portals recovered from their BSP tree (a benchmark, not a
//! test): `cargo run --release -p slipgate-vis --example bsp_bench -- MAP.bsp [pairs] [levels]`.
//! Prints time, average visible leaves and sampled sight lines for fast and full modes next to
//! the PVS stored in the file.

use quake_formats::Bsp;
use std::time::Instant;
use vis::sample::sample_visibility;
use vis::tree_portals::portals_from_bsp;
use vis::{VisMode, VisOptions, compute_vis, read_pvs};

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .expect("usage: bsp_bench MAP.bsp [pairs] [levels]");
    let pairs: usize = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let levels: Vec<u8> = args
        .next()
        .map(|a| a.split(',').filter_map(|l| l.parse().ok()).collect())
        .unwrap_or_else(|| vec![2, 4]);
    let bsp = Bsp::read(&std::fs::read(&path).expect("read")).expect("parse");
    let start = Instant::now();
    let prt = portals_from_bsp(&bsp).expect("portals");
    println!(
        "{path}: {} leaves, {} portals (recovered in {:.2} s)",
        prt.num_leafs,
        prt.portals.len(),
        start.elapsed().as_secs_f64()
    );
    println!("mode        seconds  base_s  avg_visible  pvs_frac  sampled_visible  too_small");
    let print = |name: &str, seconds: f64, base: f64, pvs: &vis::Pvs| {
        let r = sample_visibility(&bsp, pvs, pairs, 7).expect("sample");
        println!(
            "{name:<10} {seconds:>8.3} {base:>7.3} {:>12.1} {:>9.4} {:>16.4} {:>10}",
            pvs.average_visible(),
            r.pvs_fraction,
            r.visible_fraction,
            r.violations
        );
        if r.violations > 0 {
            println!("  e.g. {:?}", &r.examples[..r.examples.len().min(3)]);
        }
    };
    if let Ok(stored) = read_pvs(&bsp) {
        print("stored", 0.0, 0.0, &stored);
    }
    let modes = [VisMode::Fast]
        .into_iter()
        .chain(levels.into_iter().map(|level| VisMode::Full { level }));
    for mode in modes {
        let options = VisOptions {
            mode,
            threads: None,
            progress: quake_formats::progress::terminal(),
            ..Default::default()
        };
        let start = Instant::now();
        let result = compute_vis(&prt, &options).expect("vis");
        let name = match mode {
            VisMode::Fast => "fast".to_string(),
            VisMode::Full { level } => format!("full {level}"),
        };
        print(
            &name,
            start.elapsed().as_secs_f64(),
            result.stats.base_seconds,
            &result.pvs,
        );
        if result.stats.misoriented_portals > 0 {
            println!(
                "  misoriented portals: {}",
                result.stats.misoriented_portals
            );
        }
    }
}
