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
pub mod clusters;
pub mod explored;
pub mod flow;
pub mod lump;
pub mod portals;
pub mod pvs;
pub mod sample;
pub mod synthetic;
pub mod tree_portals;

pub use bitset::BitSet;
pub use clusters::Clusters;
pub use lump::{LumpStats, check_portals_match, read_pvs, write_vis};
pub use portals::PortalGraph;
pub use pvs::Pvs;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use quake_formats::prt::PortalFile;
use rayon::prelude::*;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
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
    #[error(
        "portal {index} joins clusters {clusters:?}, not both below the cluster count \
         {num_clusters} (in a PRT1 file, the leaf count)"
    )]
    PortalCluster {
        index: usize,
        clusters: [u32; 2],
        num_clusters: usize,
    },
    #[error("cluster {cluster} lists leaf {leaf}, not below the leaf count {num_leafs}")]
    ClusterLeaf {
        cluster: usize,
        leaf: u32,
        num_leafs: usize,
    },
    #[error("leaf {leaf} is listed in two clusters, {clusters:?}")]
    LeafInTwoClusters { leaf: u32, clusters: [usize; 2] },
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
    #[error(
        "{leafs} leaves and {portals} portals would need {gib} GiB of visibility sets, more than \
         vis allows itself (4 GiB)"
    )]
    TooBig {
        leafs: u64,
        portals: usize,
        gib: u64,
    },
    #[error("the BSP's hull 0 tree is broken: {0}")]
    BadTree(String),
    /// The BSP breaks a rule that would make vis read out of bounds ([`quake_formats::check_usable`]).
    #[error(transparent)]
    Unusable(#[from] quake_formats::FormatError),
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
    /// Clusters visibility was computed between (the leaf count for a PRT1 file).
    pub clusters: usize,
    pub portals: usize,
    pub degenerate_portals: usize,
    /// One-way portals whose leaf has another portal in front of them (see
    /// [`PortalGraph::misoriented_portals`]); non-zero means a suspicious portal file. Only
    /// counted for PRT1 files (clusters need not be convex).
    pub misoriented_portals: usize,
    pub average_mightsee: f64,
    pub average_portal_vis: f64,
    pub base_seconds: f64,
    pub flow_seconds: f64,
    pub average_visible: f64,
    pub max_visible: usize,
    /// One-way cluster pairs dropped because the other side does not see back (see
    /// [`Pvs::intersect_with_transpose`]).
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
    check_set_sizes(prt)?;
    let graph = PortalGraph::from_prt(prt)?;
    let clusters = Clusters::from_prt(prt)?;
    let mut builder = rayon::ThreadPoolBuilder::new().stack_size(64 << 20);
    if let Some(threads) = options.threads {
        builder = builder.num_threads(threads);
    }
    let pool = builder
        .build()
        .map_err(|e| VisError::Threads(e.to_string()))?;
    Ok(pool.install(|| compute_on_graph(&graph, clusters.as_ref(), options)))
}

/// The most memory vis lets its bit sets take ([`set_bytes`]). The biggest real maps need far
/// less; a portal file whose counts ask for more is refused before anything is allocated.
pub const MAX_SET_BYTES: u64 = 4 << 30;

/// What the bit sets for `prt` take: one set per one-way portal over the portals, and one per
/// leaf (and cluster) over the leaves.
pub fn set_bytes(prt: &PortalFile) -> u64 {
    let square = |n: u64| n * n.div_ceil(8);
    let one_way = 2 * prt.portals.len() as u64;
    let leafs = u64::from(prt.num_leafs);
    let clusters = prt.clusters.as_ref().map_or(leafs, |c| c.len() as u64);
    square(one_way) + square(leafs) + square(clusters)
}

fn check_set_sizes(prt: &PortalFile) -> Result<(), VisError> {
    let bytes = set_bytes(prt);
    if bytes > MAX_SET_BYTES {
        return Err(VisError::TooBig {
            leafs: u64::from(prt.num_leafs),
            portals: prt.portals.len(),
            gib: bytes.div_ceil(1 << 30),
        });
    }
    Ok(())
}

fn compute_on_graph(
    graph: &PortalGraph,
    clusters: Option<&Clusters>,
    options: &VisOptions,
) -> VisResult {
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
    let portal_vis = match options.mode {
        VisMode::Fast => mightsee.clone(),
        VisMode::Full { level } => full_flow(graph, &mightsee, level, options.progress),
    };
    let flow_seconds = start.elapsed().as_secs_f64();
    let seen_through: Vec<BitSet> = (0..n)
        .into_par_iter()
        .map(|p| Pvs::clusters_behind(graph, p, &portal_vis[p]))
        .collect();
    let mut rows = Pvs::cluster_rows(graph, &seen_through);
    let asymmetric_pairs = Pvs::intersect_with_transpose(&mut rows);
    let pvs = match clusters {
        Some(clusters) => clusters.expand(&rows),
        None => Pvs::new(rows),
    };
    let stats = ComputeStats {
        leafs: pvs.num_leafs(),
        clusters: graph.num_clusters,
        portals: n,
        degenerate_portals: graph.degenerate,
        misoriented_portals: if clusters.is_some() {
            0
        } else {
            graph.misoriented_portals()
        },
        average_mightsee: average(&mightsee),
        average_portal_vis: average(&portal_vis),
        base_seconds,
        flow_seconds,
        average_visible: pvs.average_visible(),
        max_visible: pvs.max_visible(),
        asymmetric_pairs,
    };
    VisResult { pvs, stats }
}

/// Portal flows run in this many waves (fewer when there are few portals): each wave's flows
/// run in parallel, bounded by the results of the waves before. Fixing the waves by the portal
/// count alone makes the result the same whatever the thread count and timing.
const FLOW_WAVES: usize = 200;
const MIN_WAVE_PORTALS: usize = 16;

/// Run the portal flow for every portal on every worker thread; returns the portals seen
/// through each. Portals with the smallest mightsee go first: they finish fast, and their
/// results then bound the bigger ones' flows more tightly than mightsee does.
fn full_flow(graph: &PortalGraph, mightsee: &[BitSet], level: u8, progress: bool) -> Vec<BitSet> {
    let n = graph.portals.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&p| (mightsee[p].count(), p));
    let mut done: Vec<Option<BitSet>> = vec![None; n];
    let bar = progress_bar(n as u64, progress);
    let workspaces: Vec<Mutex<flow::Workspace>> = (0..rayon::current_num_threads())
        .map(|_| Mutex::default())
        .collect();
    let wave_len = n.div_ceil(FLOW_WAVES).max(MIN_WAVE_PORTALS);
    for wave in order.chunks(wave_len) {
        let results: Vec<OnceLock<BitSet>> = wave.iter().map(|_| OnceLock::new()).collect();
        let ctx = flow::FlowContext {
            graph,
            mightsee,
            done: &done,
            level,
        };
        let next = AtomicUsize::new(0);
        rayon::broadcast(|thread| {
            // A worker that panicked poisons only its own workspace; the portals it would have
            // taken fall back to their mightsee below.
            let Ok(mut ws) = workspaces[thread.index()].lock() else {
                return;
            };
            // Largest mightsee first within a wave: the biggest flows start early, so fewer
            // threads wait for a late one at the wave's end (the order changes no result).
            loop {
                let taken = next.fetch_add(1, Ordering::Relaxed);
                let Some(i) = wave.len().checked_sub(taken + 1) else {
                    break;
                };
                let _ = results[i].set(flow::portal_flow(&ctx, wave[i], &mut ws));
                bar.inc(1);
            }
        });
        for (&p, result) in wave.iter().zip(results) {
            done[p] = result.into_inner();
        }
    }
    bar.finish_and_clear();
    done.into_iter()
        .zip(mightsee)
        .map(|(d, m)| d.unwrap_or_else(|| m.clone()))
        .collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_portal_file_claiming_billions_of_leaves_is_refused_before_allocating() {
        // Found by fuzzing: compute_vis allocated 96 GB for this file and aborted, and 3 GB in
        // 10 s for a 38-byte PRT2 file claiming 224314 leaves.
        let text = "PRT1\n4000000000\n1\n3 0 1 (0 0 0 ) (0 64 0 ) (0 0 64 )\n";
        let prt = PortalFile::parse(text).expect("parse");
        let err = compute_vis(&prt, &VisOptions::default()).expect_err("refused");
        assert!(err.to_string().contains("4000000000 leaves"), "{err}");
        let prt = PortalFile::parse("PRT2\n224314\n0\n0\n").expect("parse");
        assert!(compute_vis(&prt, &VisOptions::default()).is_err());
    }
}
