//! Per-portal flow cost on a real map (a diagnostic): `flow_probe MAP.prt|MAP.bsp [level] [seconds]`
//! runs the flow of every portal on one thread in the order vis uses (a BSP without its portal
//! file gets portals recovered from its tree), stops after `seconds`, and lists the slowest.

use quake_formats::Bsp;
use quake_formats::prt::PortalFile;
use std::sync::OnceLock;
use std::time::Instant;
use vis::tree_portals::portals_from_bsp;
use vis::{FlowPlan, PortalGraph};

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("MAP.prt or MAP.bsp");
    let level: u8 = args.next().and_then(|a| a.parse().ok()).unwrap_or(4);
    let budget: f64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(60.0);
    let bytes = std::fs::read(&path).expect("read");
    let prt = if path.ends_with(".prt") {
        PortalFile::parse(&String::from_utf8_lossy(&bytes)).expect("parse")
    } else {
        portals_from_bsp(&Bsp::read(&bytes).expect("parse")).expect("portals")
    };
    let graph = PortalGraph::from_prt(&prt).expect("graph");
    let n = graph.portals.len();
    let mightsee: Vec<_> = (0..n).map(|p| vis::base::mightsee(&graph, p)).collect();
    let results: Vec<OnceLock<vis::BitSet>> = (0..n).map(|_| OnceLock::new()).collect();
    let plan = FlowPlan::new(&mightsee, vis::Grouping::Auto);
    let order: Vec<usize> = plan.waves().flatten().copied().collect();
    let mut ws = vis::flow::Workspace::default();
    let mut costs = Vec::new();
    let all = Instant::now();
    for (i, &p) in order.iter().enumerate() {
        if all.elapsed().as_secs_f64() > budget {
            println!("stopped after {i} of {n} portals");
            break;
        }
        let before = ws.visits;
        let start = Instant::now();
        let ctx = vis::flow::FlowContext {
            graph: &graph,
            mightsee: &mightsee,
            results: &results,
            plan: &plan,
            level,
        };
        let seen = vis::flow::portal_flow(&ctx, p, &mut ws);
        costs.push((
            start.elapsed().as_secs_f64(),
            p,
            i,
            ws.visits - before,
            seen.count(),
        ));
        let _ = results[p].set(seen);
    }
    let seen: usize = costs.iter().map(|c| c.4).sum();
    println!(
        "{} portals in {:.2} s, {} leaf visits, {} covered walks skipped, {:.1} portals seen per portal",
        costs.len(),
        all.elapsed().as_secs_f64(),
        ws.visits,
        ws.covered,
        seen as f64 / costs.len().max(1) as f64
    );
    costs.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (seconds, p, i, visits, seen) in costs.iter().take(15) {
        println!(
            "portal {p:>6} (#{i:>6}): mightsee {:>5} seen {seen:>5} visits {visits:>9} {seconds:>8.3} s",
            mightsee[*p].count()
        );
    }
}
