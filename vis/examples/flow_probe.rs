//! Per-portal flow cost on a real map (a diagnostic): `flow_probe MAP.bsp [portals] [level]`.

use quake_formats::Bsp;
use std::sync::OnceLock;
use std::time::Instant;
use vis::PortalGraph;
use vis::tree_portals::portals_from_bsp;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("MAP.bsp");
    let count: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(20);
    let level: u8 = args.next().and_then(|a| a.parse().ok()).unwrap_or(2);
    let bsp = Bsp::read(&std::fs::read(&path).expect("read")).expect("parse");
    let graph = PortalGraph::from_prt(&portals_from_bsp(&bsp).expect("portals")).expect("graph");
    let n = graph.portals.len();
    let mightsee: Vec<_> = (0..n).map(|p| vis::base::mightsee(&graph, p)).collect();
    let done: Vec<OnceLock<vis::BitSet>> = (0..n).map(|_| OnceLock::new()).collect();
    let ctx = vis::flow::FlowContext {
        graph: &graph,
        mightsee: &mightsee,
        done: &done,
        level,
    };
    let mut ws = vis::flow::Workspace::default();
    for p in (0..n).step_by(n / count) {
        let before = ws.visits;
        let start = Instant::now();
        let seen = vis::flow::portal_flow(&ctx, p, &mut ws);
        println!(
            "portal {p:>6}: mightsee {:>5} seen {:>5} visits {:>9} {:>8.3} s",
            mightsee[p].count(),
            seen.count(),
            ws.visits - before,
            start.elapsed().as_secs_f64()
        );
    }
}
