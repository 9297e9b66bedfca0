//! Slipgate: portal-flow potentially visible sets.
//!
//! [`compute_vis`] turns a portal file into a [`Pvs`] (base vis alone in fast mode, recursive
//! portal flow in full mode); [`write_vis`] stores it in a BSP; [`ambient::ambient_levels`] fills
//! each leaf's ambient sounds from what it sees; [`sample::sample_visibility`] checks a PVS
//! against sight lines traced through the BSP tree.

pub mod ambient;
pub mod base;
pub mod bitset;
pub mod cli;
pub mod flow;
pub mod lump;
pub mod portals;
pub mod pvs;
pub mod sample;
pub mod synthetic;
pub mod tree_portals;

pub use bitset::BitSet;
pub use lump::{LumpStats, check_portals_match, read_pvs, write_vis};
pub use portals::PortalGraph;
pub use pvs::Pvs;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use quake_formats::prt::PortalFile;
use rayon::prelude::*;
use std::io::IsTerminal;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Everything vis can refuse.
#[derive(Debug, thiserror::Error)]
pub enum VisError {
    #[error(
        "the portal file has {prt_leafs} leaves but the BSP's world model has {vis_leafs} vis \
         leaves: the .prt file does not belong to this BSP (compile the map again)"
    )]
    LeafCountMismatch { prt_leafs: usize, vis_leafs: usize },
    #[error("the BSP has no models, so no world model to compute visibility for")]
    NoWorldModel,
    #[error("the world model claims {vis_leafs} vis leaves but the BSP has {leafs} leaves")]
    BadVisLeafs { vis_leafs: i64, leafs: usize },
    #[error("portal {index} joins leaves {leafs:?}, not both below the leaf count {num_leafs}")]
    PortalLeaf {
        index: usize,
        leafs: [u32; 2],
        num_leafs: usize,
    },
    #[error("portal {index} has a coordinate that is not a finite number")]
    PortalNotFinite { index: usize },
    #[error("leaf {leaf}: vis offset {offset} is outside the {lump_len}-byte visibility lump")]
    BadVisOffset {
        leaf: usize,
        offset: i32,
        lump_len: usize,
    },
    #[error("the compressed visibility data does not fit a 32-bit offset")]
    LumpTooLarge,
    #[error("could not start the worker threads: {0}")]
    Threads(String),
    #[error("the BSP's hull 0 tree is broken: {0}")]
    BadTree(String),
}

/// Which algorithm computes the sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VisMode {
    /// Base vis only: conservative, fast, loose.
    Fast,
    /// Portal flow with separating planes up to `level` (0..=4).
    Full { level: u8 },
}

#[derive(Debug, Clone)]
pub struct VisOptions {
    pub mode: VisMode,
    /// Worker threads; `None` uses every core.
    pub threads: Option<usize>,
    /// Show a progress bar on stderr (only drawn when stderr is a terminal).
    pub progress: bool,
}

impl Default for VisOptions {
    fn default() -> Self {
        VisOptions {
            mode: VisMode::Full { level: 4 },
            threads: None,
            progress: false,
        }
    }
}

/// Counts and timings of one [`compute_vis`] run.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct ComputeStats {
    pub leafs: usize,
    pub portals: usize,
    pub degenerate_portals: usize,
    /// One-way portals whose leaf has another portal in front of them (see
    /// [`PortalGraph::misoriented_portals`]); non-zero means a suspicious portal file.
    pub misoriented_portals: usize,
    pub average_mightsee: f64,
    pub average_portal_vis: f64,
    pub base_seconds: f64,
    pub flow_seconds: f64,
    pub average_visible: f64,
    pub max_visible: usize,
    pub asymmetric_pairs: usize,
}

/// The result of [`compute_vis`].
#[derive(Debug, Clone)]
pub struct VisResult {
    pub pvs: Pvs,
    pub stats: ComputeStats,
}

/// Compute every leaf's potentially visible set from a portal file.
pub fn compute_vis(prt: &PortalFile, options: &VisOptions) -> Result<VisResult, VisError> {
    let graph = PortalGraph::from_prt(prt)?;
    let mut builder = rayon::ThreadPoolBuilder::new().stack_size(64 << 20);
    if let Some(threads) = options.threads {
        builder = builder.num_threads(threads);
    }
    let pool = builder
        .build()
        .map_err(|e| VisError::Threads(e.to_string()))?;
    Ok(pool.install(|| compute_on_graph(&graph, options)))
}

fn compute_on_graph(graph: &PortalGraph, options: &VisOptions) -> VisResult {
    let n = graph.portals.len();
    let start = Instant::now();
    let mightsee: Vec<BitSet> = (0..n)
        .into_par_iter()
        .map(|p| base::mightsee(graph, p))
        .collect();
    let base_seconds = start.elapsed().as_secs_f64();
    let average =
        |sets: &[BitSet]| sets.iter().map(BitSet::count).sum::<usize>() as f64 / n.max(1) as f64;

    let start = Instant::now();
    let (portal_vis, portal_leafs) = match options.mode {
        VisMode::Fast => {
            let leafs = (0..n)
                .into_par_iter()
                .map(|p| Pvs::leafs_behind(graph, p, &mightsee[p]))
                .collect();
            (mightsee.clone(), leafs)
        }
        VisMode::Full { level } => full_flow(graph, &mightsee, level, options.progress),
    };
    let flow_seconds = start.elapsed().as_secs_f64();
    let pvs = Pvs::from_portal_leafs(graph, &portal_leafs);
    let stats = ComputeStats {
        leafs: graph.num_leafs,
        portals: n,
        degenerate_portals: graph.degenerate,
        misoriented_portals: graph.misoriented_portals(),
        average_mightsee: average(&mightsee),
        average_portal_vis: average(&portal_vis),
        base_seconds,
        flow_seconds,
        average_visible: pvs.average_visible(),
        max_visible: pvs.max_visible(),
        asymmetric_pairs: pvs.asymmetric_pairs(),
    };
    VisResult { pvs, stats }
}

/// Run the portal flow for every portal on every worker thread. Portals with the smallest
/// mightsee go first: they finish fast, and their exact sets then bound the bigger ones' flow
/// more tightly than mightsee does.
fn full_flow(
    graph: &PortalGraph,
    mightsee: &[BitSet],
    level: u8,
    progress: bool,
) -> (Vec<BitSet>, Vec<BitSet>) {
    let n = graph.portals.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&p| mightsee[p].count());
    let done: Vec<OnceLock<BitSet>> = (0..n).map(|_| OnceLock::new()).collect();
    let leafs: Vec<OnceLock<BitSet>> = (0..n).map(|_| OnceLock::new()).collect();
    let ctx = flow::FlowContext {
        graph,
        mightsee,
        done: &done,
        level,
    };
    let bar = progress_bar(
        mightsee.iter().map(|m| m.count() as u64 + 1).sum(),
        progress,
    );
    let next = AtomicUsize::new(0);
    rayon::broadcast(|_| {
        let mut ws = flow::Workspace::default();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(&p) = order.get(i) else { break };
            let seen = flow::portal_flow(&ctx, p, &mut ws);
            let _ = done[p].set(flow::done_bound(graph, &mightsee[p], &seen));
            let _ = leafs[p].set(seen);
            bar.inc(mightsee[p].count() as u64 + 1);
        }
    });
    bar.finish_and_clear();
    // Every portal was taken by some worker; the fallbacks only keep this panic-free.
    let portals = done
        .into_iter()
        .zip(mightsee)
        .map(|(d, m)| d.into_inner().unwrap_or_else(|| m.clone()))
        .collect();
    let leafs = leafs
        .into_iter()
        .enumerate()
        .map(|(p, l)| {
            l.into_inner()
                .unwrap_or_else(|| Pvs::leafs_behind(graph, p, &mightsee[p]))
        })
        .collect();
    (portals, leafs)
}

/// A bar with a time estimate on stderr, or a hidden one when stderr is not a terminal.
pub fn progress_bar(len: u64, enabled: bool) -> ProgressBar {
    if !enabled || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{elapsed_precise} [{wide_bar}] {percent}% eta {eta}")
    {
        bar.set_style(style);
    }
    bar
}
