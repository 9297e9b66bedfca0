//! Speed against tightness on a large synthetic cave world (a benchmark, not a test):
//! `cargo run --release -p slipgate-vis --example synthetic_bench [cells] [seed]`

use std::time::Instant;
use vis::sample::sample_visibility;
use vis::synthetic::VoxelWorld;
use vis::{VisMode, VisOptions, compute_vis};

fn main() {
    let mut args = std::env::args().skip(1);
    let cells: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(3000);
    let seed: u64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(1);
    let world = VoxelWorld::random_caves([48, 48, 8], cells, seed);
    let prt = world.portal_file();
    let bsp = world.bsp();
    println!("{} leaves, {} portals", prt.num_leafs, prt.portals.len());
    println!("mode      seconds  base_s  avg_visible  pvs_frac  sampled_visible  too_small");
    let modes = [("fast", VisMode::Fast)]
        .into_iter()
        .chain((0..=4).map(|level| ("full", VisMode::Full { level })));
    for (name, mode) in modes {
        let options = VisOptions {
            mode,
            threads: None,
            ..Default::default()
        };
        let start = Instant::now();
        let result = compute_vis(&prt, &options).expect("vis");
        let seconds = start.elapsed().as_secs_f64();
        let report = sample_visibility(&bsp, &result.pvs, 1_000_000, seed).expect("sample");
        let level = match mode {
            VisMode::Fast => String::new(),
            VisMode::Full { level } => format!(" {level}"),
        };
        println!(
            "{name:<4}{level:<4} {seconds:>9.3} {:>7.3} {:>12.1} {:>9.4} {:>16.4} {:>10}",
            result.stats.base_seconds,
            result.pvs.average_visible(),
            report.pvs_fraction,
            report.visible_fraction,
            report.violations
        );
    }
}
