//! Slipgate: portal-flow potentially visible sets.
//!
//! [`compute_vis`] turns a portal file into a [`Pvs`] (base vis alone in fast mode, recursive
//! portal flow in full mode); [`write_vis`] stores it in a BSP; [`ambient::ambient_levels`] fills
//! each leaf's ambient sounds from what it sees; [`sample::sample_visibility`] checks a PVS
//! against sight lines traced through the BSP tree.

#![warn(missing_docs)]

pub mod ambient;
pub mod base;
pub mod bitset;
#[cfg(feature = "cli")]
pub mod cli;
pub mod clusters;
pub mod explored;
pub mod flow;
pub mod lump;
pub mod portals;
pub mod pvs;
pub mod sample;
pub mod saved;
pub mod schedule;
pub mod shards;
pub mod synthetic;
pub mod tree_portals;

pub use ambient::Channels;
pub use bitset::BitSet;
pub use clusters::Clusters;
pub use lump::{LumpStats, Outside, check_portals_match, check_sealed, read_pvs, write_vis};
pub use portals::PortalGraph;
pub use pvs::Pvs;
pub use schedule::{FlowPlan, Grouping, Shard};

use quake_formats::Bsp;
use quake_formats::progress::Progress;
use quake_formats::prt::PortalFile;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

/// Everything vis can refuse.
#[derive(Debug, thiserror::Error)]
pub enum VisError {
    /// The portal file and the BSP disagree on the leaf count: they come from different
    /// compiles.
    #[error(
        "the portal file has {prt_leafs} leaves but the BSP's world model has {vis_leafs} vis \
         leaves: the .prt file does not belong to this BSP (compile the map again)"
    )]
    LeafCountMismatch {
        /// Leaves the portal file declares.
        prt_leafs: usize,
        /// Vis leaves of the BSP's world model.
        vis_leafs: usize,
    },
    /// The world keeps the void outside the map (open leaves past its bounds on every side)
    /// and a point entity stands in its open space: the map leaks.
    #[error(
        "the map leaks: leaf {leaf} reaches past the world's brushes into the void outside the \
         map, which vis would have to work through; fix the leak (the compiler's .pts pointfile \
         leads to it) and compile again"
    )]
    Void {
        /// One open leaf of the void (BSP leaf number).
        leaf: usize,
    },
    /// A shard was asked of fast mode, which has no flow to split.
    #[error("a shard runs a share of the full flow; base vis (fast) has none")]
    FastShard,
    /// The BSP has no world model.
    #[error("the BSP has no models, so no world model to compute visibility for")]
    NoWorldModel,
    /// A damaged `SLIPGATE_FACEFLAGS` lump (the message names it).
    #[error("{0}")]
    FaceFlags(quake_formats::FormatError),
    /// The world model's vis leaf count is negative or beyond the BSP's leaves.
    #[error("the world model claims {vis_leafs} vis leaves but the BSP has {leafs} leaves")]
    BadVisLeafs {
        /// The count the world model claims.
        vis_leafs: i64,
        /// Leaves in the BSP's leaf lump.
        leafs: usize,
    },
    /// A portal names a cluster (or leaf) that does not exist.
    #[error(
        "portal {index} joins clusters {clusters:?}, not both below the cluster count \
         {num_clusters} (in a PRT1 file, the leaf count)"
    )]
    PortalCluster {
        /// The portal's position in the portal file.
        index: usize,
        /// The two clusters it joins, as written.
        clusters: [u32; 2],
        /// Clusters in the file (leaves in a PRT1 file).
        num_clusters: usize,
    },
    /// A PRT2 cluster lists a leaf that does not exist.
    #[error("cluster {cluster} lists leaf {leaf}, not below the leaf count {num_leafs}")]
    ClusterLeaf {
        /// The cluster listing it.
        cluster: usize,
        /// The leaf as written.
        leaf: u32,
        /// Leaves in the file.
        num_leafs: usize,
    },
    /// A PRT2 leaf belongs to two clusters.
    #[error("leaf {leaf} is listed in two clusters, {clusters:?}")]
    LeafInTwoClusters {
        /// The leaf listed twice.
        leaf: u32,
        /// The first and the second cluster listing it.
        clusters: [usize; 2],
    },
    /// A portal's winding has an infinite or NaN coordinate.
    #[error("portal {index} has a coordinate that is not a finite number")]
    PortalNotFinite {
        /// The portal's position in the portal file.
        index: usize,
    },
    /// A leaf's visibility offset points outside the visibility lump.
    #[error("leaf {leaf}: vis offset {offset} is outside the {lump_len}-byte visibility lump")]
    BadVisOffset {
        /// The BSP leaf.
        leaf: usize,
        /// Its offset into the lump, in bytes.
        offset: i32,
        /// The lump's length in bytes.
        lump_len: usize,
    },
    /// The compressed rows are larger than a leaf's 32-bit offset can reach.
    #[error("the compressed visibility data does not fit a 32-bit offset")]
    LumpTooLarge,
    /// The worker thread pool could not be built; holds the reason.
    #[error("could not start the worker threads: {0}")]
    Threads(String),
    /// The portal file's counts would need more set memory than [`MAX_SET_BYTES`].
    #[error(
        "{leafs} leaves and {portals} portals would need {gib} GiB of visibility sets, more than \
         vis allows itself (4 GiB)"
    )]
    TooBig {
        /// Leaves the portal file declares.
        leafs: u64,
        /// Portals in the portal file.
        portals: usize,
        /// The memory the sets would take, in GiB (rounded up).
        gib: u64,
    },
    /// Joined flow results do not cover the portal graph one for one.
    #[error("{flows} portal flow results for {portals} one-way portals")]
    FlowCount {
        /// Flow results given.
        flows: usize,
        /// One-way portals in the graph.
        portals: usize,
    },
    /// The BSP's hull 0 node tree cannot be traced; holds what is wrong.
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
    Full {
        /// How hard the flow tests separating planes: higher is tighter and slower.
        level: u8,
    },
}

/// How [`compute_vis`] runs.
#[derive(Debug, Clone)]
pub struct VisOptions {
    /// Fast base vis or the full flow, and its level.
    pub mode: VisMode,
    /// Worker threads; `None` uses every core.
    pub threads: Option<usize>,
    /// Where the full flow reports its progress (one unit per one-way portal flow).
    pub progress: Progress,
    /// Whether the full flow is planned in groups for shards ([`FlowPlan`]).
    pub grouping: Grouping,
    /// The ambient sound channels [`store`] fills.
    pub ambient: Channels,
}

impl Default for VisOptions {
    fn default() -> Self {
        VisOptions {
            mode: VisMode::Full { level: 4 },
            threads: None,
            progress: Progress::default(),
            grouping: Grouping::Auto,
            ambient: Channels::ALL,
        }
    }
}

/// A vis run as the command line reports it (and writes with `--stats`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct VisReport {
    /// `fast` or `full`.
    pub mode: &'static str,
    /// The full flow's level.
    pub level: u8,
    /// What computing the sets counted.
    pub compute: ComputeStats,
    /// The visibility lump written.
    pub lump: LumpStats,
    /// Leaves that hear an ambient sound.
    pub ambient_leafs: usize,
    /// Seconds storing and writing the BSP took.
    pub write_seconds: f64,
    /// Seconds the whole run took.
    pub total_seconds: f64,
    /// The PVS checked against sight lines, when asked for.
    pub sampling: Option<sample::SamplingReport>,
}

/// What [`store`] wrote into a BSP.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Stored {
    /// The visibility lump.
    pub lump: LumpStats,
    /// Leaves that hear an ambient sound.
    pub ambient_leafs: usize,
}

/// Store `pvs` in `bsp`: the visibility lump ([`write_vis`]) and the ambient sound levels its
/// leaves hear on `channels` ([`ambient::ambient_levels`]).
pub fn store(bsp: &mut Bsp, pvs: &Pvs, channels: Channels) -> Result<Stored, VisError> {
    let lump = write_vis(bsp, pvs)?;
    let ambient_leafs = ambient::ambient_levels(bsp, pvs, channels)?;
    Ok(Stored {
        lump,
        ambient_leafs,
    })
}

/// Counts and timings of one [`compute_vis`] run.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct ComputeStats {
    /// Vis leaves in the PVS (BSP leaves 1..=N).
    pub leafs: usize,
    /// Clusters visibility was computed between (the leaf count for a PRT1 file).
    pub clusters: usize,
    /// One-way portals in the graph: two per portal of the file that was kept.
    pub portals: usize,
    /// Portals of the file dropped as degenerate ([`PortalGraph::degenerate`]).
    pub degenerate_portals: usize,
    /// One-way portals whose leaf has another portal in front of them (see
    /// [`PortalGraph::misoriented_portals`]); non-zero means a suspicious portal file. Only
    /// counted for PRT1 files (clusters need not be convex).
    pub misoriented_portals: usize,
    /// Portals base vis finds each one-way portal might see, on average.
    pub average_mightsee: f64,
    /// Portals each one-way portal sees after the flow (the mightsee in fast mode), on average.
    pub average_portal_vis: f64,
    /// Seconds base vis took.
    pub base_seconds: f64,
    /// Seconds the full flow took (0 in fast mode).
    pub flow_seconds: f64,
    /// Leaves each leaf's set holds, on average.
    pub average_visible: f64,
    /// The most leaves any one leaf's set holds.
    pub max_visible: usize,
    /// One-way cluster pairs dropped because the other side does not see back (see
    /// [`Pvs::intersect_with_transpose`]).
    pub asymmetric_pairs: usize,
}

/// The result of [`compute_vis`].
#[derive(Debug, Clone)]
pub struct VisResult {
    /// Every vis leaf's set.
    pub pvs: Pvs,
    /// What the run counted and how long it took.
    pub stats: ComputeStats,
}

/// Compute every leaf's potentially visible set from a portal file.
pub fn compute_vis(prt: &PortalFile, options: &VisOptions) -> Result<VisResult, VisError> {
    compute_vis_resuming(prt, options, Vec::new(), None)
}

/// Flow results a run starts from: by portal, those a saved state holds (empty: none).
pub type KnownFlows = Vec<Option<BitSet>>;

/// Saves a run's progress: called, from a worker thread, with every result finished so far
/// (by portal, ascending).
pub type SaveFlows<'a> = dyn Fn(Vec<(usize, &BitSet)>) + Sync + 'a;

/// Saving a run's progress now and then, so a killed run can resume.
pub struct Checkpoint<'a> {
    /// The least time between two saves.
    pub every: Duration,
    /// What stores the results.
    pub save: &'a SaveFlows<'a>,
}

/// [`compute_vis`] starting from the results in `known` (a saved state of the same inputs and
/// level; results for other inputs give a wrong PVS) and saving progress through `checkpoint`.
/// The sets are the same as those of one uninterrupted run.
pub fn compute_vis_resuming(
    prt: &PortalFile,
    options: &VisOptions,
    known: KnownFlows,
    checkpoint: Option<&Checkpoint>,
) -> Result<VisResult, VisError> {
    let setup = Setup::new(prt, options.threads)?;
    Ok(setup.pool.install(|| {
        let (mut mightsee, base_seconds) = base_vis(&setup.graph);
        let average_mightsee = average_count(&mightsee);
        let start = Instant::now();
        let portal_vis = match options.mode {
            VisMode::Fast => std::mem::take(&mut mightsee),
            VisMode::Full { level } => {
                let wanted = vec![true; mightsee.len()];
                let plan = FlowPlan::new(&mightsee, options.grouping);
                let job = FlowJob {
                    graph: &setup.graph,
                    plan: &plan,
                    level,
                    progress: &options.progress,
                    wanted: &wanted,
                    checkpoint,
                };
                let done = full_flow(&job, known, &mut mightsee);
                done.into_iter()
                    .zip(std::mem::take(&mut mightsee))
                    .map(|(d, m)| d.unwrap_or(m))
                    .collect()
            }
        };
        let flow_seconds = start.elapsed().as_secs_f64();
        // The portals' sets go before the leaves' rows are made: they are the biggest sets.
        let seen = setup.seen_through(&portal_vis);
        drop(portal_vis);
        let mut result = setup.finish(seen);
        result.stats.average_mightsee = average_mightsee;
        result.stats.base_seconds = base_seconds;
        result.stats.flow_seconds = flow_seconds;
        result
    }))
}

/// One shard's part of the full flow ([`compute_shard`]).
#[derive(Debug, Clone)]
pub struct ShardFlows {
    /// One-way portals in the graph.
    pub portals: usize,
    /// The results the shard hands on ([`FlowPlan::owned`]), by portal, ascending.
    pub results: Vec<(usize, BitSet)>,
    /// Final groups in the plan ([`FlowPlan::groups`]): more shards than this get no final work.
    pub groups: usize,
    /// Seconds base vis took.
    pub base_seconds: f64,
    /// Seconds the shard's flows took.
    pub flow_seconds: f64,
}

/// Run the full flow of `shard`'s share of the portals: the shared ones and the shard's final
/// groups ([`VisOptions::mode`] gives the level; fast mode has no flow to share).
/// [`vis_from_flows`] turns the results of all shards into the same sets [`compute_vis`] gives.
pub fn compute_shard(
    prt: &PortalFile,
    options: &VisOptions,
    shard: Shard,
    known: KnownFlows,
    checkpoint: Option<&Checkpoint>,
) -> Result<ShardFlows, VisError> {
    let VisMode::Full { level } = options.mode else {
        return Err(VisError::FastShard);
    };
    let grouping = options.grouping;
    let setup = Setup::new(prt, options.threads)?;
    Ok(setup.pool.install(|| {
        let (mut mightsee, base_seconds) = base_vis(&setup.graph);
        let start = Instant::now();
        let plan = FlowPlan::new(&mightsee, grouping);
        let wanted = plan.runs(shard);
        let job = FlowJob {
            graph: &setup.graph,
            plan: &plan,
            level,
            progress: &options.progress,
            wanted: &wanted,
            checkpoint,
        };
        let mut done = full_flow(&job, known, &mut mightsee);
        let results: Vec<(usize, BitSet)> = plan
            .owned(shard)
            .into_iter()
            .map(|p| {
                let set = done[p].take();
                (p, set.unwrap_or_else(|| std::mem::take(&mut mightsee[p])))
            })
            .collect();
        ShardFlows {
            portals: mightsee.len(),
            results,
            groups: plan.groups(),
            base_seconds,
            flow_seconds: start.elapsed().as_secs_f64(),
        }
    }))
}

/// The sets from every portal's flow result (by one-way portal, as [`compute_shard`] numbers
/// them; the shards' results joined).
pub fn vis_from_flows(prt: &PortalFile, flows: &[BitSet]) -> Result<VisResult, VisError> {
    let setup = Setup::new(prt, None)?;
    if flows.len() != setup.graph.portals.len() {
        return Err(VisError::FlowCount {
            flows: flows.len(),
            portals: setup.graph.portals.len(),
        });
    }
    Ok(setup
        .pool
        .install(|| setup.finish(setup.seen_through(flows))))
}

/// The clusters seen through each portal, and how many portals each portal saw on average.
struct SeenThrough {
    clusters: Vec<BitSet>,
    average_portal_vis: f64,
}

/// What every entry point builds first.
struct Setup {
    graph: PortalGraph,
    clusters: Option<Clusters>,
    pool: rayon::ThreadPool,
}

impl Setup {
    fn new(prt: &PortalFile, threads: Option<usize>) -> Result<Setup, VisError> {
        check_set_sizes(prt)?;
        let graph = PortalGraph::from_prt(prt)?;
        let clusters = Clusters::from_prt(prt)?;
        let mut builder = rayon::ThreadPoolBuilder::new().stack_size(64 << 20);
        if let Some(threads) = threads {
            builder = builder.num_threads(threads);
        }
        let pool = builder
            .build()
            .map_err(|e| VisError::Threads(e.to_string()))?;
        Ok(Setup {
            graph,
            clusters,
            pool,
        })
    }

    /// The clusters seen through each portal, from the portals seen through it.
    fn seen_through(&self, portal_vis: &[BitSet]) -> SeenThrough {
        let graph = &self.graph;
        SeenThrough {
            clusters: (0..graph.portals.len())
                .into_par_iter()
                .map(|p| Pvs::clusters_behind(graph, p, &portal_vis[p]))
                .collect(),
            average_portal_vis: average_count(portal_vis),
        }
    }

    /// Leaf rows from the clusters seen through each portal (stats without base and flow).
    fn finish(&self, seen: SeenThrough) -> VisResult {
        let graph = &self.graph;
        let mut rows = Pvs::cluster_rows(graph, &seen.clusters);
        drop(seen.clusters);
        let asymmetric_pairs = Pvs::intersect_with_transpose(&mut rows);
        let pvs = match &self.clusters {
            Some(clusters) => clusters.expand(&rows),
            None => Pvs::new(rows),
        };
        let stats = ComputeStats {
            leafs: pvs.num_leafs(),
            clusters: graph.num_clusters,
            portals: graph.portals.len(),
            degenerate_portals: graph.degenerate,
            misoriented_portals: if self.clusters.is_some() {
                0
            } else {
                graph.misoriented_portals()
            },
            average_portal_vis: seen.average_portal_vis,
            average_visible: pvs.average_visible(),
            max_visible: pvs.max_visible(),
            asymmetric_pairs,
            ..ComputeStats::default()
        };
        VisResult { pvs, stats }
    }
}

/// Every portal's mightsee, and the seconds it took.
fn base_vis(graph: &PortalGraph) -> (Vec<BitSet>, f64) {
    let start = Instant::now();
    let mightsee = (0..graph.portals.len())
        .into_par_iter()
        .map(|p| base::mightsee(graph, p))
        .collect();
    (mightsee, start.elapsed().as_secs_f64())
}

fn average_count(sets: &[BitSet]) -> f64 {
    sets.iter().map(BitSet::count).sum::<usize>() as f64 / sets.len().max(1) as f64
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

/// One run of the full flow.
struct FlowJob<'a> {
    graph: &'a PortalGraph,
    plan: &'a FlowPlan,
    level: u8,
    progress: &'a Progress,
    /// By portal: whether to run its flow (a shard skips the other shards' groups).
    wanted: &'a [bool],
    checkpoint: Option<&'a Checkpoint<'a>>,
}

/// Run the portal flows `job` wants, wave by wave ([`FlowPlan`]), on every worker thread,
/// taking results in `known` as they are; returns the portals seen through each (`None` for
/// portals not wanted, or whose worker panicked). A portal's `mightsee` is emptied once its
/// flow is done and no later flow may read it instead of that result, so the finished flows
/// take the place of the mightsee sets rather than adding to them; those of the portals
/// without a result are kept.
fn full_flow(job: &FlowJob, known: KnownFlows, mightsee: &mut [BitSet]) -> Vec<Option<BitSet>> {
    let n = job.graph.portals.len();
    let bar = job.progress;
    bar.start("flow", job.wanted.iter().filter(|&&w| w).count());
    // The plan decides which results a flow may use, so known ones can all go in at once.
    let results: Vec<OnceLock<BitSet>> = (0..n).map(|_| OnceLock::new()).collect();
    for (p, set) in known.into_iter().enumerate().take(n) {
        if let Some(set) = set.filter(|s| job.wanted[p] && s.len() == n) {
            let _ = results[p].set(set);
            bar.advance(1);
        }
    }
    let workspaces: Vec<Mutex<flow::Workspace>> = (0..rayon::current_num_threads())
        .map(|_| Mutex::default())
        .collect();
    let saver = job.checkpoint.map(|c| Saver {
        checkpoint: c,
        last: Mutex::new(Instant::now()),
        busy: AtomicBool::new(false),
    });
    for wave in job.plan.waves() {
        let ctx = flow::FlowContext {
            graph: job.graph,
            mightsee,
            results: &results,
            plan: job.plan,
            level: job.level,
        };
        let todo: Vec<usize> = wave
            .iter()
            .copied()
            .filter(|&p| job.wanted[p] && results[p].get().is_none())
            .collect();
        let next = AtomicUsize::new(0);
        rayon::broadcast(|thread| {
            // A worker that panicked poisons only its own workspace; the portals it would have
            // taken fall back to their mightsee.
            let Ok(mut ws) = workspaces[thread.index()].lock() else {
                return;
            };
            // Largest mightsee first within a wave: the biggest flows start early, so fewer
            // threads wait for a late one at the wave's end (the order changes no result).
            loop {
                let taken = next.fetch_add(1, Ordering::Relaxed);
                let Some(i) = todo.len().checked_sub(taken + 1) else {
                    break;
                };
                let _ = results[todo[i]].set(flow::portal_flow(&ctx, todo[i], &mut ws));
                bar.advance(1);
                if let Some(saver) = &saver {
                    saver.save_if_due(|| {
                        let finished = results.iter().enumerate();
                        finished
                            .filter_map(|(p, r)| r.get().map(|s| (p, s)))
                            .collect()
                    });
                }
            }
        });
        for &p in wave {
            if results[p].get().is_some() && job.plan.bounds_every_later_flow(p) {
                mightsee[p] = BitSet::default();
            }
        }
    }
    bar.finish();
    results.into_iter().map(OnceLock::into_inner).collect()
}

/// Runs a [`Checkpoint`]'s save from whichever worker finds it due, one at a time.
struct Saver<'a> {
    checkpoint: &'a Checkpoint<'a>,
    last: Mutex<Instant>,
    busy: AtomicBool,
}

impl Saver<'_> {
    fn save_if_due<'s>(&self, snapshot: impl FnOnce() -> Vec<(usize, &'s BitSet)>) {
        let due = self
            .last
            .lock()
            .is_ok_and(|last| last.elapsed() >= self.checkpoint.every);
        if !due || self.busy.swap(true, Ordering::Acquire) {
            return;
        }
        (self.checkpoint.save)(snapshot());
        if let Ok(mut last) = self.last.lock() {
            *last = Instant::now();
        }
        self.busy.store(false, Ordering::Release);
    }
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

    fn caves() -> PortalFile {
        synthetic::VoxelWorld::random_caves([12, 12, 3], 160, 17).portal_file()
    }

    #[test]
    fn shards_joined_give_the_sets_of_one_run() {
        let prt = caves();
        let grouped = VisOptions {
            grouping: Grouping::Always,
            ..VisOptions::default()
        };
        let whole = compute_vis(&prt, &grouped).expect("vis");
        let two_threads_grouped = VisOptions {
            threads: Some(2),
            ..grouped
        };
        for count in [1, 2, 3, 16, 17] {
            let mut flows: Vec<Option<BitSet>> = Vec::new();
            for index in 0..count {
                let shard = Shard { index, count };
                let part = compute_shard(&prt, &two_threads_grouped, shard, Vec::new(), None)
                    .expect("shard");
                flows.resize(part.portals, None);
                for (p, set) in part.results {
                    assert!(flows[p].replace(set).is_none(), "portal {p} twice");
                }
            }
            let flows: Vec<BitSet> = flows
                .into_iter()
                .map(|f| f.expect("every portal"))
                .collect();
            let joined = vis_from_flows(&prt, &flows).expect("join");
            assert_eq!(joined.pvs, whole.pvs, "{count} shards");
        }
    }

    #[test]
    fn a_run_resumed_from_saved_results_gives_the_same_sets() {
        let prt = caves();
        let options = VisOptions {
            threads: Some(2),
            grouping: Grouping::Always,
            ..VisOptions::default()
        };
        let whole = compute_vis(&prt, &options).expect("vis");
        // Save after every flow; resume from a snapshot taken part way.
        let saves: Mutex<Vec<KnownFlows>> = Mutex::default();
        let save = |results: Vec<(usize, &BitSet)>| {
            let mut known: KnownFlows = vec![None; results.first().map_or(0, |r| r.1.len())];
            for (p, set) in results {
                known[p] = Some(set.clone());
            }
            saves.lock().expect("lock").push(known);
        };
        let checkpoint = Checkpoint {
            every: Duration::ZERO,
            save: &save,
        };
        let saved = compute_vis_resuming(&prt, &options, Vec::new(), Some(&checkpoint))
            .expect("saving run");
        assert_eq!(saved.pvs, whole.pvs);
        let saves = saves.into_inner().expect("lock");
        assert!(saves.len() > 10, "{} saves", saves.len());
        for known in [&saves[saves.len() / 3], &saves[saves.len() - 1]] {
            let resumed = compute_vis_resuming(&prt, &options, known.clone(), None).expect("vis");
            assert_eq!(resumed.pvs, whole.pvs);
        }
    }
}
