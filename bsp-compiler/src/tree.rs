//! The BSP tree: brushes are split by their own side planes until every brush fragment in a
//! region fills it, so each leaf is convex and has one contents (the strongest brush in it).
//! This does the CSG implicitly: hidden faces between touching or overlapping brushes never
//! become faces, because faces are only made where leaf contents change (see [`crate::faces`]).

use crate::brush::{Brush, BrushKind, BrushProbe, PlaneProbe};
use crate::planes::{PlaneId, PlaneSet};
use crate::region::{Region, Sliver};
use crate::sides_memo::SidesMemo;
use glam::DVec3;
use quake_formats::bsp::contents;
use quake_formats::geom::{Bounds, ON_EPSILON, Plane};
use rayon::prelude::*;
use std::collections::HashSet;
use std::sync::atomic::{AtomicI64, AtomicUsize, Ordering};

/// How the splitting plane of a node is chosen among the node's unused brush side planes.
///
/// Both first cut nodes larger than `MID_SPLIT_SIZE` by the axial candidate nearest the middle
/// of their longest axis, as Quake's qbsp does, which keeps big maps' trees shallow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub enum SplitHeuristic {
    /// Fewest brushes split; then the most brushes with a side on the plane (fewer nodes and
    /// leaves); then the most even front/back count; then axial planes.
    #[default]
    FewestSplits,
    /// Quake 2's weighting: five times the splits less the brushes facing the plane, plus the
    /// front/back difference, axial planes first on ties.
    Balanced,
}

/// Nodes whose brushes span more than this on some axis are cut near their middle (by default:
/// see [`Splitting::max_node_size`]).
pub const MID_SPLIT_SIZE: f64 = 1024.0;

/// How a tree's nodes are split.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Splitting {
    pub heuristic: SplitHeuristic,
    /// Nodes whose contents span more than this on some axis are cut near their middle first
    /// (ericw-tools' `-maxnodesize`); 0 never does.
    pub max_node_size: f64,
}

impl From<SplitHeuristic> for Splitting {
    fn from(heuristic: SplitHeuristic) -> Splitting {
        Splitting {
            heuristic,
            max_node_size: MID_SPLIT_SIZE,
        }
    }
}

/// What a candidate splitting plane does to the brushes (or surfaces) of a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SplitCounts {
    /// Cut in two.
    pub split: i64,
    /// Lying on the plane (an unused brush side, a surface): one node serves them all.
    pub facing: i64,
    /// Left whole in front and behind.
    pub front: i64,
    pub back: i64,
}

/// How many times `id` occurs in the sorted list `planes`.
pub fn count_sorted(planes: &[PlaneId], id: PlaneId) -> i64 {
    (planes.partition_point(|&p| p <= id) - planes.partition_point(|&p| p < id)) as i64
}

impl SplitHeuristic {
    /// The ranking of a candidate `plane`: lower is better.
    pub fn key(self, plane: &Plane, c: SplitCounts) -> (i64, i64, i64, i64) {
        let imbalance = (c.front - c.back).abs();
        let non_axial = i64::from(plane.axial().is_none());
        match self {
            SplitHeuristic::FewestSplits => (c.split, -c.facing, imbalance, non_axial),
            SplitHeuristic::Balanced => (5 * (c.split - c.facing) + imbalance, non_axial, 0, 0),
        }
    }

    /// A number that orders candidates as the start of [`SplitHeuristic::key`] does, for a
    /// candidate that splits `split` items, lies on `facing` of them and leaves `imbalance`
    /// more whole on one side than on the other: lower is better, and a higher number is a
    /// higher key. With `imbalance` 0 it is the least a candidate still being counted can reach.
    fn key_prefix(self, split: i64, facing: i64, imbalance: i64) -> i64 {
        match self {
            // (split, -facing); facing never reaches 2^31 (one per item).
            SplitHeuristic::FewestSplits => (split << 32) + ((1 << 31) - facing),
            SplitHeuristic::Balanced => 5 * (split - facing) + imbalance,
        }
    }
}

/// The candidate with the lowest [`SplitHeuristic::key`] over a node's `items` (brushes or
/// surfaces), each telling with `sides_of(item, &prepare(plane))` which sides of a plane it
/// reaches (what `prepare` works out of a candidate serves every item). `facing` is the sorted
/// list of planes the items lie on, one entry per item.
///
/// A candidate stops being counted (or is not counted at all) once its key can only come out
/// above the key of some finished candidate, compared on [`SplitHeuristic::key_prefix`]: both
/// heuristics rank splits before all else (the fewest-splits one then the items lying on the
/// plane, which are known before counting), and splits only add up, so it cannot win.
pub fn best_splitter<T: Sync, P>(
    candidates: &[PlaneId],
    items: &[T],
    prepare: impl Fn(PlaneId) -> P + Sync,
    sides_of: impl Fn(&T, &P) -> (bool, bool) + Sync,
    facing: &[PlaneId],
    planes: &PlaneSet,
    heuristic: SplitHeuristic,
) -> Option<PlaneId> {
    let bound = AtomicI64::new(i64::MAX);
    let score = |&(facing, id): &(i64, PlaneId)| {
        let plane = planes.get(id);
        let limit = bound.load(Ordering::Relaxed);
        if heuristic.key_prefix(0, facing, 0) > limit {
            return None;
        }
        let prepared = prepare(id);
        let (mut front, mut back, mut split) = (0i64, 0i64, 0i64);
        for item in items {
            match sides_of(item, &prepared) {
                (true, true) => {
                    split += 1;
                    if heuristic.key_prefix(split, facing, 0) > limit {
                        return None;
                    }
                }
                (true, false) => front += 1,
                (false, true) => back += 1,
                (false, false) => {}
            }
        }
        let counts = SplitCounts {
            split,
            facing,
            front,
            back,
        };
        let key = heuristic.key(plane, counts);
        bound.fetch_min(
            heuristic.key_prefix(split, facing, (front - back).abs()),
            Ordering::Relaxed,
        );
        Some((key, id))
    };
    // Planes many items lie on first: they tend to split few, and the sooner a good candidate
    // is finished, the sooner the others are dropped (the choice does not depend on the order).
    let mut order: Vec<(i64, PlaneId)> = candidates
        .iter()
        .map(|&id| (count_sorted(facing, id), id))
        .collect();
    order.sort_unstable_by_key(|&(facing, id)| (std::cmp::Reverse(facing), id));
    let (first, rest) = order.split_first()?;
    let first = score(first);
    // Scoring is candidates x items; small nodes are not worth a fork.
    let rest = if candidates.len() * items.len() > 20_000 {
        rest.par_iter().filter_map(score).min()
    } else {
        rest.iter().filter_map(score).min()
    };
    first.into_iter().chain(rest).min().map(|(_, id)| id)
}

/// For a node whose contents span `bounds`, larger than `max_size` (not 0): the axial candidate
/// closest to the middle of its longest axis.
pub fn mid_split(
    bounds: &Bounds,
    candidates: &[PlaneId],
    planes: &PlaneSet,
    max_size: f64,
) -> Option<PlaneId> {
    let size = bounds.maxs - bounds.mins;
    let axis = (0..3).max_by(|&a, &b| size[a].total_cmp(&size[b]).then(b.cmp(&a)))?;
    if max_size <= 0.0 || size[axis] <= max_size {
        return None;
    }
    let middle = bounds.center()[axis];
    candidates
        .iter()
        // The set's flag first: most candidates are not axial, and it is kept for each plane.
        .filter(|&&id| planes.is_axial(id) && planes.get(id).axial() == Some(axis))
        .min_by(|&&a, &&b| {
            let da = (planes.get(a).dist - middle).abs();
            let db = (planes.get(b).dist - middle).abs();
            da.total_cmp(&db).then(a.cmp(&b))
        })
        .copied()
}

impl std::str::FromStr for SplitHeuristic {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "fewest-splits" => Ok(SplitHeuristic::FewestSplits),
            "balanced" => Ok(SplitHeuristic::Balanced),
            _ => Err(format!(
                "unknown split heuristic {s:?} (fewest-splits, balanced)"
            )),
        }
    }
}

/// Compiler-only contents of `func_detail_fence` brushes: solid, yet faces behind them stay
/// (fence textures have holes), and vis and face marking look through them. Written as solid.
pub const FENCE: i32 = -100;
/// Compiler-only contents of `func_detail_wall` brushes: solid, yet faces behind them stay whole
/// instead of being cut where the brush touches them (as in ericw-tools). Written as solid.
pub const DETAIL_WALL: i32 = -102;
/// Compiler-only contents of `func_detail_illusionary` brushes: drawn from outside, written as
/// empty.
pub const ILLUSIONARY: i32 = -101;
/// Compiler-only contents of `func_illusionary_visblocker` brushes: drawn from both sides and
/// walked through like water, but vis does not see through them (no portal enters them).
/// Written as empty.
pub const VISBLOCKER: i32 = -103;

/// Compiler-only contents of leaves inside both a `func_detail_illusionary` brush and a liquid:
/// the liquid for engines, but a leaf of its own, so that the illusionary brush's faces are made
/// under the surface too (as in ericw-tools). One for each liquid.
pub const ILLUSIONARY_IN_WATER: i32 = -104;
pub const ILLUSIONARY_IN_SLIME: i32 = -105;
pub const ILLUSIONARY_IN_LAVA: i32 = -106;

/// The contents engines see for a leaf of compiler contents `c`.
pub fn engine_contents(c: i32) -> i32 {
    match c {
        FENCE | DETAIL_WALL => contents::SOLID,
        ILLUSIONARY | VISBLOCKER => contents::EMPTY,
        ILLUSIONARY_IN_WATER => contents::WATER,
        ILLUSIONARY_IN_SLIME => contents::SLIME,
        ILLUSIONARY_IN_LAVA => contents::LAVA,
        c => c,
    }
}

/// Ranking of contents: a region holding several brushes takes the strongest, and owns the faces
/// between them. Sky is opaque as solid is: it owns its faces against a detail wall or a fence,
/// so a sky face behind either is drawn whole. A liquid holding an illusionary brush ranks just
/// above the liquid alone, so that it owns the faces between them.
pub fn contents_priority(c: i32) -> u8 {
    match c {
        contents::SOLID => 18,
        contents::SKY => 17,
        DETAIL_WALL => 16,
        FENCE => 14,
        ILLUSIONARY_IN_LAVA => 11,
        contents::LAVA => 10,
        ILLUSIONARY_IN_SLIME => 9,
        contents::SLIME => 8,
        ILLUSIONARY_IN_WATER => 7,
        contents::WATER => 6,
        VISBLOCKER => 4,
        ILLUSIONARY => 2,
        _ => 0,
    }
}

/// What vis may look between when liquids are opaque (`-notranswater`): leaves of one liquid,
/// or leaves of no liquid.
pub fn vis_class(c: i32) -> i32 {
    let engine = engine_contents(c);
    if contents::is_liquid(engine) {
        engine
    } else {
        contents::EMPTY
    }
}

/// Whether a brush of contents `inner` keeps its sides (and so its faces) inside a brush of the
/// stronger contents `outer`: an illusionary brush is drawn under a liquid's surface, which
/// players see through.
pub fn shows_inside(outer: i32, inner: i32) -> bool {
    inner == ILLUSIONARY && contents::is_liquid(outer)
}

/// The contents of a region whose strongest brush is of contents `strongest`, when
/// `illusionary` brushes lie in it too ([`shows_inside`]).
fn with_illusionary(strongest: i32, illusionary: bool) -> i32 {
    match strongest {
        _ if !illusionary => strongest,
        contents::WATER => ILLUSIONARY_IN_WATER,
        contents::SLIME => ILLUSIONARY_IN_SLIME,
        contents::LAVA => ILLUSIONARY_IN_LAVA,
        c => c,
    }
}

/// Contents that block flooding and are never looked out of.
pub fn is_opaque(c: i32) -> bool {
    c == contents::SOLID || c == contents::SKY
}

/// Whether faces behind leaves of these contents are kept whole: sight passes through them, or
/// (detail walls) they are told not to cut the faces they touch.
pub fn shows_faces_behind(c: i32) -> bool {
    is_see_through(c) || c == DETAIL_WALL || c == VISBLOCKER
}

/// Whether sight passes through leaves of these contents. Liquids count: modern engines draw
/// water translucent, so (like ericw-tools' default "transwater") vis sees through liquid
/// surfaces instead of cutting the world in two at every waterline (with `-notranswater` the
/// portal file keeps liquids apart, see [`vis_class`]). Fences have holes.
pub fn is_see_through(c: i32) -> bool {
    contents::is_liquid(engine_contents(c)) || matches!(c, contents::EMPTY | FENCE | ILLUSIONARY)
}

/// A node of the flattened tree; a leaf has no plane.
#[derive(Debug, Clone, PartialEq)]
pub struct TreeNode {
    pub plane: Option<PlaneId>,
    /// Front and back child (nodes only).
    pub children: [u32; 2],
    /// Leaves only.
    pub contents: i32,
    /// The brush fragments filling a leaf (kept for hull 0, for face textures).
    pub brushes: Vec<Brush>,
    /// Set on the nodes where the structural tree ends (its leaves, the vis clusters): the
    /// contents of the structural brushes there. Detail brushes split the space further below.
    pub cluster: Option<i32>,
}

impl TreeNode {
    pub fn is_leaf(&self) -> bool {
        self.plane.is_none()
    }
}

/// A BSP tree; node 0 is the root.
#[derive(Debug, Clone, PartialEq)]
pub struct Tree {
    pub nodes: Vec<TreeNode>,
    /// How many times a brush was split in two.
    pub splits: usize,
}

impl Tree {
    /// The leaf holding `p` (points on a plane go to the front, as in engines).
    pub fn leaf_at(&self, planes: &PlaneSet, p: DVec3) -> u32 {
        let mut n = 0u32;
        while let Some(id) = self.nodes[n as usize].plane {
            let d = planes.get(id).distance(p);
            n = self.nodes[n as usize].children[usize::from(d < 0.0)];
        }
        n
    }

    /// The structural leaves (vis clusters) whose regions hold `p` or lie within [`ON_EPSILON`]
    /// of it, front sides first: one, unless `p` lies on node planes (a brush face, an edge, a
    /// corner), where it touches the clusters on every side.
    pub fn clusters_touching(&self, planes: &PlaneSet, p: DVec3) -> Vec<u32> {
        self.touching(planes, p, |n| n.cluster.is_some())
    }

    /// The leaves whose regions hold `p` or lie within [`ON_EPSILON`] of it, as
    /// [`Tree::clusters_touching`].
    pub fn leaves_touching(&self, planes: &PlaneSet, p: DVec3) -> Vec<u32> {
        self.touching(planes, p, TreeNode::is_leaf)
    }

    fn touching(&self, planes: &PlaneSet, p: DVec3, stop: impl Fn(&TreeNode) -> bool) -> Vec<u32> {
        let mut found = Vec::new();
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            let Some(id) = node.plane.filter(|_| !stop(node)) else {
                found.push(n);
                continue;
            };
            // Pushed back first, so the front side is searched (and listed) first.
            let d = planes.get(id).distance(p);
            if d < ON_EPSILON {
                stack.push(node.children[1]);
            }
            if d > -ON_EPSILON {
                stack.push(node.children[0]);
            }
        }
        found
    }

    /// The leaves at or below node `n`, in pre-order.
    pub fn leaves_below(&self, n: u32) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack = vec![n];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if node.is_leaf() {
                out.push(n);
            } else {
                stack.push(node.children[1]);
                stack.push(node.children[0]);
            }
        }
        out
    }

    /// For each node, whether everything below it is solid and never looked through (such
    /// subtrees become one leaf).
    pub fn all_solid(&self) -> Vec<bool> {
        let mut solid = vec![false; self.nodes.len()];
        // Children always come after their parent in the flattened order.
        for i in (0..self.nodes.len()).rev() {
            let n = &self.nodes[i];
            solid[i] = match n.plane {
                None => matches!(n.contents, contents::SOLID | DETAIL_WALL),
                Some(_) => solid[n.children[0] as usize] && solid[n.children[1] as usize],
            };
        }
        solid
    }
}

/// A tree under construction; [`flatten`] turns it into a [`Tree`].
pub(crate) enum BuildNode {
    Split {
        plane: PlaneId,
        children: Box<[BuildNode; 2]>,
    },
    Leaf {
        contents: i32,
        brushes: Vec<Brush>,
    },
    /// A structural leaf whose detail brushes split it further.
    Cluster {
        structural_contents: i32,
        detail: Box<BuildNode>,
    },
}

/// Space between the brushes and the box bounding the root's region, so that every brush side
/// crosses it.
const REGION_MARGIN: f64 = 8.0;

/// Subtrees with at least this many brushes are built in parallel.
const PARALLEL_BRUSHES: usize = 64;

/// Brush sides that bound open space once the world's outside is filled, by map brush
/// ([`Brush::source`]) and plane: the sides faces are made on.
pub type VisibleSides = HashSet<(u32, PlaneId)>;

struct Builder<'a> {
    planes: &'a PlaneSet,
    splitting: Splitting,
    keep_brushes: bool,
    /// Every node plane must cut its region cleanly (see [`Region::split_cleanly`]).
    clean_splits: bool,
    /// Split by these sides before any other (hints aside), when known.
    visible: Option<&'a VisibleSides>,
    splits: AtomicUsize,
}

/// Build the tree of `brushes`. `keep_brushes` keeps each leaf's fragments in the result.
///
/// Structural (and hint) brush sides split first; where none is left, the node is a structural
/// leaf, and the detail brushes in it are split in below. Every node plane cuts its region
/// cleanly, for engines that rebuild portals from the tree (DarkPlaces).
pub fn build_tree(
    brushes: Vec<Brush>,
    planes: &PlaneSet,
    splitting: impl Into<Splitting>,
    keep_brushes: bool,
) -> Tree {
    let builder = Builder {
        planes,
        splitting: splitting.into(),
        keep_brushes,
        clean_splits: true,
        visible: None,
        splits: AtomicUsize::new(0),
    };
    builder.tree(brushes)
}

/// Build the world's tree again once its outside is filled, as [`build_tree`] (keeping each
/// leaf's fragments) but splitting by the `visible` sides first, as ericw-tools does: the planes
/// of sides that face the filled void then only cut space that is solid on both sides, which
/// collapses into one solid leaf, instead of sitting above the rooms as nodes of their own.
pub fn rebuild_tree_visible_first(
    brushes: Vec<Brush>,
    planes: &PlaneSet,
    splitting: impl Into<Splitting>,
    visible: &VisibleSides,
) -> Tree {
    let builder = Builder {
        planes,
        splitting: splitting.into(),
        keep_brushes: true,
        clean_splits: true,
        visible: Some(visible),
        splits: AtomicUsize::new(0),
    };
    builder.tree(brushes)
}

/// Build the tree of a clip hull's grown `brushes`. No engine rebuilds portals from clip nodes,
/// so their planes need not cut their regions cleanly: a region too thin for that (between grown
/// sides less than a portal epsilon apart) is split like any other, where [`build_tree`] would
/// fill it as a crack, which in a clip hull is an invisible wall.
pub fn build_clip_hull_tree(
    brushes: Vec<Brush>,
    planes: &PlaneSet,
    splitting: impl Into<Splitting>,
) -> Tree {
    let builder = Builder {
        planes,
        splitting: splitting.into(),
        keep_brushes: false,
        clean_splits: false,
        visible: None,
        splits: AtomicUsize::new(0),
    };
    builder.tree(brushes)
}

pub(crate) fn flatten(node: BuildNode, out: &mut Vec<TreeNode>) -> u32 {
    flatten_in(node, out, false)
}

/// `in_cluster`: the node lies below a structural leaf.
fn flatten_in(node: BuildNode, out: &mut Vec<TreeNode>, in_cluster: bool) -> u32 {
    let index = out.len() as u32;
    match node {
        BuildNode::Leaf { contents, brushes } => out.push(TreeNode {
            plane: None,
            children: [0, 0],
            contents,
            brushes,
            cluster: (!in_cluster).then_some(contents),
        }),
        BuildNode::Split { plane, children } => {
            out.push(TreeNode {
                plane: Some(plane),
                children: [0, 0],
                contents: 0,
                brushes: Vec::new(),
                cluster: None,
            });
            let [front, back] = *children;
            let f = flatten_in(front, out, in_cluster);
            let b = flatten_in(back, out, in_cluster);
            out[index as usize].children = [f, b];
        }
        BuildNode::Cluster {
            structural_contents,
            detail,
        } => {
            debug_assert!(!in_cluster, "clusters do not nest");
            flatten_in(*detail, out, true);
            out[index as usize].cluster = Some(structural_contents);
        }
    }
    index
}

/// Which brush sides may split a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Above the structural leaves: structural and hint sides.
    Structural,
    /// Below a structural leaf: every side.
    Detail,
}

impl Phase {
    fn splits_with(self, b: &Brush) -> bool {
        self == Phase::Detail || !b.is_detail()
    }
}

impl Builder<'_> {
    fn tree(&self, brushes: Vec<Brush>) -> Tree {
        let bounds = brushes
            .iter()
            .fold(Bounds::EMPTY, |acc, b| acc.union(&b.bounds));
        let bounds = if bounds.is_empty() {
            Bounds {
                mins: DVec3::ZERO,
                maxs: DVec3::ZERO,
            }
        } else {
            bounds
        };
        let root = self.build(
            brushes,
            Phase::Structural,
            Region::around(&bounds, REGION_MARGIN),
        );
        let mut nodes = Vec::new();
        flatten(root, &mut nodes);
        Tree {
            nodes,
            splits: self.splits.load(Ordering::Relaxed),
        }
    }

    /// The subtree of the node whose space is `region`, holding `brushes` (parts of them may
    /// lie outside it).
    fn build(&self, brushes: Vec<Brush>, phase: Phase, region: Region) -> BuildNode {
        let mut brushes = self.fit_to_region(brushes, &region);
        let (splitter, filled) = loop {
            if strongest_fills(&brushes, phase) {
                break (None, true);
            }
            let Some(plane) = self.choose_splitter(&brushes, phase) else {
                break (None, false);
            };
            if !self.clean_splits {
                break (Some((plane, region.split(self.planes.get(plane)))), false);
            }
            if let Some(parts) = region.split_cleanly(self.planes.get(plane)) {
                break (Some((plane, parts)), false);
            }
            // Rare: choose again with the sliver given to the rest of the region.
            brushes = self.absorb_sliver(brushes, plane, &region);
        };
        let Some((plane, [front_region, back_region])) = splitter else {
            if phase == Phase::Structural && !filled && brushes.iter().any(Brush::is_detail) {
                let structural_contents =
                    strongest_contents(brushes.iter().filter(|b| !b.is_detail()));
                return BuildNode::Cluster {
                    structural_contents,
                    detail: Box::new(self.build(brushes, Phase::Detail, region)),
                };
            }
            return BuildNode::Leaf {
                contents: strongest_contents(brushes.iter()),
                brushes: if self.keep_brushes {
                    // No plane is scored against them any more.
                    for b in &mut brushes {
                        b.sides_memo = SidesMemo::default();
                    }
                    brushes
                } else {
                    Vec::new()
                },
            };
        };
        let parallel = brushes.len() >= PARALLEL_BRUSHES;
        // Room for every brush on either side: growing by doubling moved each brush again.
        let mut front = Vec::with_capacity(brushes.len());
        let mut back = Vec::with_capacity(brushes.len());
        let mut splits = 0;
        for b in brushes {
            let (f, bk) = b.split(plane, self.planes);
            splits += usize::from(f.is_some() && bk.is_some());
            front.extend(f);
            back.extend(bk);
        }
        self.splits.fetch_add(splits, Ordering::Relaxed);
        for b in front.iter_mut().chain(back.iter_mut()) {
            for s in &mut b.sides {
                if s.plane == plane {
                    s.used = true;
                }
            }
        }
        let (f, b) = if parallel {
            rayon::join(
                || self.build(front, phase, front_region),
                || self.build(back, phase, back_region),
            )
        } else {
            (
                self.build(front, phase, front_region),
                self.build(back, phase, back_region),
            )
        };
        BuildNode::Split {
            plane,
            children: Box::new([f, b]),
        }
    }

    /// The brushes that reach into `region`, each side whose plane misses the region marked
    /// used. Brushes reach past their node's region where a split left one part too thin to
    /// build and kept the brush whole on both sides (see `Brush::split`), and a side may lie
    /// within the epsilon of the region's boundary; inside the region such a side bounds
    /// nothing: as a splitter it would make a node with an empty child, and it must not keep
    /// the brush from filling the region.
    fn fit_to_region(&self, mut brushes: Vec<Brush>, region: &Region) -> Vec<Brush> {
        // A used side lies on a plane above (or was found here to miss a region above), so the
        // region lies inside it.
        let fits = |b: &mut Brush| {
            for s in b.sides.iter_mut().filter(|s| !s.used) {
                let (front, back) = region.sides_of(self.planes.get(s.plane));
                // Whether the region reaches out of the brush past the side, and into it.
                let (outside, inside) = if s.flipped {
                    (back, front)
                } else {
                    (front, back)
                };
                match (outside, inside) {
                    (true, true) => {}
                    (true, false) => return false,
                    (false, _) => s.used = true,
                }
            }
            true
        };
        // Above the parallel subtrees this is on every build's path: spread it too (in place:
        // collecting a filtered parallel iterator joins per-thread vectors).
        if brushes.len() >= PARALLEL_BRUSHES {
            let kept: Vec<bool> = brushes.par_iter_mut().map(fits).collect();
            let mut kept = kept.into_iter();
            brushes.retain(|_| kept.next() == Some(true));
        } else {
            brushes.retain_mut(fits);
        }
        brushes
    }

    /// `brushes` without what lies in the sliver of `region` that the plane `id` cuts off (see
    /// [`Region::split_cleanly`]), the plane's sides marked used: the sliver goes with the rest
    /// of the region instead of becoming a node with a degenerate child. A brush inside the
    /// plane only reaches into the sliver and is left out; one outside it is taken to reach
    /// across the sliver. In a crack every brush is taken to reach across: what seals it stays.
    fn absorb_sliver(&self, brushes: Vec<Brush>, id: PlaneId, region: &Region) -> Vec<Brush> {
        let sliver = region.sliver(self.planes.get(id));
        brushes
            .into_iter()
            .filter_map(|mut b| {
                for s in b.sides.iter_mut().filter(|s| s.plane == id) {
                    // A brush lies behind its side's outward plane: in front of the canonical
                    // plane when the side is flipped.
                    let inside = if s.flipped {
                        Sliver::Front
                    } else {
                        Sliver::Back
                    };
                    if inside == sliver {
                        return None;
                    }
                    s.used = true;
                }
                Some(b)
            })
            .collect()
    }

    /// The best unused side plane, or `None` when every side has been used (a leaf). Big nodes
    /// are cut near their middle first, then hint sides win, then visible sides (when known),
    /// then the heuristic decides.
    fn choose_splitter(&self, brushes: &[Brush], phase: Phase) -> Option<PlaneId> {
        let unused = |kind: Option<BrushKind>, visible: Option<&VisibleSides>| {
            let mut list: Vec<PlaneId> = brushes
                .iter()
                .filter(|b| phase.splits_with(b) && kind.is_none_or(|k| b.kind == k))
                .flat_map(|b| {
                    b.sides
                        .iter()
                        .filter(move |s| {
                            !s.used
                                && !s.buried
                                && visible.is_none_or(|v| v.contains(&(b.source, s.plane)))
                        })
                        .map(|s| s.plane)
                })
                .collect();
            list.sort_unstable();
            list.dedup();
            list
        };
        let candidates = unused(None, None);
        if candidates.is_empty() {
            return None;
        }
        let bounds = brushes
            .iter()
            .fold(Bounds::EMPTY, |acc, b| acc.union(&b.bounds));
        let visible = self
            .visible
            .map(|v| unused(None, Some(v)))
            .unwrap_or_default();
        // Only sides faces are made on cut a big node, when they are known (as in ericw-tools):
        // a hidden side's plane would cut open space where no face asks for it.
        let mid_candidates = if self.visible.is_some() {
            &visible
        } else {
            &candidates
        };
        if let Some(mid) = mid_split(
            &bounds,
            mid_candidates,
            self.planes,
            self.splitting.max_node_size,
        ) {
            return Some(mid);
        }
        let hints = unused(Some(BrushKind::Hint), None);
        let candidates = [hints, visible]
            .into_iter()
            .find(|list| !list.is_empty())
            .unwrap_or(candidates);
        // Each brush's unused side planes, once per brush, sorted: how many brushes a plane
        // would serve as a node (a plane many sides lie on saves nodes and leaves).
        let mut facing_planes: Vec<PlaneId> = Vec::new();
        for b in brushes {
            let mut own: Vec<PlaneId> = b
                .sides
                .iter()
                .filter(|s| !s.used && !s.buried)
                .map(|s| s.plane)
                .collect();
            own.sort_unstable();
            own.dedup();
            facing_planes.extend(own);
        }
        facing_planes.sort_unstable();
        // The largest brushes first: they are the likeliest to be split, so a candidate that
        // cannot win is found out sooner (the counts do not depend on the order).
        let size = |b: &Brush| (b.bounds.maxs - b.bounds.mins).element_sum();
        let mut by_size: Vec<BrushProbe> = brushes.iter().map(BrushProbe::new).collect();
        by_size.sort_by(|a, b| size(b.brush).total_cmp(&size(a.brush)));
        best_splitter(
            &candidates,
            &by_size,
            |id| PlaneProbe::new(id, self.planes),
            BrushProbe::sides_of,
            &facing_planes,
            self.planes,
            self.splitting.heuristic,
        )
    }
}

/// Whether a fragment of the strongest contents fills the region: it decides the region whatever
/// lies inside, and splitting further would only cut up space of one contents. Above the
/// structural leaves only a structural fragment may end the structure. Brushes that keep their
/// sides inside the filler ([`keeps_sides_inside`]) must fill the region too, or their sides
/// split it further.
fn strongest_fills(brushes: &[Brush], phase: Phase) -> bool {
    let strongest = brushes.iter().map(|b| contents_priority(b.contents)).max();
    let Some(filler) = brushes.iter().find(|b| {
        Some(contents_priority(b.contents)) == strongest && b.fills_node() && phase.splits_with(b)
    }) else {
        return false;
    };
    brushes
        .iter()
        .all(|b| !keeps_sides_inside(filler, b) || b.fills_node())
}

/// Whether brush `inner` keeps its sides (and so its faces) inside brush `outer`, stronger or
/// as strong: it shows inside it ([`shows_inside`]), or they are of one contents and either has
/// `_noclipfaces` (treating a junction of such a brush and a plain one as if both had it, as
/// ericw-tools does).
pub fn keeps_sides_inside(outer: &Brush, inner: &Brush) -> bool {
    shows_inside(outer.contents, inner.contents)
        || (outer.contents == inner.contents && (outer.no_clip_faces || inner.no_clip_faces))
}

/// The contents of a region holding `brushes`: the strongest, with any shown inside it
/// ([`with_illusionary`]); empty when there are none.
fn strongest_contents<'a>(brushes: impl Iterator<Item = &'a Brush> + Clone) -> i32 {
    let strongest = brushes
        .clone()
        .map(|b| b.contents)
        .max_by_key(|&c| contents_priority(c))
        .unwrap_or(contents::EMPTY);
    with_illusionary(
        strongest,
        brushes
            .into_iter()
            .any(|b| shows_inside(strongest, b.contents)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::tests::{box_brush, box_planes, solid_cube};

    #[test]
    fn single_box_gives_one_solid_leaf_and_empty_around() {
        let mut planes = PlaneSet::new();
        let b = solid_cube(&mut planes);
        let tree = build_tree(vec![b], &planes, SplitHeuristic::FewestSplits, true);
        let leaves: Vec<_> = tree.nodes.iter().filter(|n| n.is_leaf()).collect();
        assert_eq!(leaves.len(), 7);
        assert_eq!(
            leaves
                .iter()
                .filter(|l| l.contents == contents::SOLID)
                .count(),
            1
        );
        assert_eq!(tree.splits, 0);
    }

    #[test]
    fn overlapping_water_and_solid_take_solid() {
        let mut planes = PlaneSet::new();
        let solid = box_brush(
            &mut planes,
            DVec3::ZERO,
            DVec3::new(64.0, 64.0, 64.0),
            contents::SOLID,
        );
        let water = Brush::from_planes(
            &box_planes(DVec3::new(32.0, 0.0, 0.0), DVec3::new(96.0, 64.0, 64.0)),
            &mut planes,
            contents::WATER,
            1,
        )
        .expect("water");
        let tree = build_tree(vec![water, solid], &planes, SplitHeuristic::Balanced, true);
        let find = |p: DVec3| tree.nodes[tree.leaf_at(&planes, p) as usize].contents;
        assert_eq!(find(DVec3::new(48.0, 32.0, 32.0)), contents::SOLID);
        assert_eq!(find(DVec3::new(80.0, 32.0, 32.0)), contents::WATER);
        assert_eq!(find(DVec3::new(200.0, 32.0, 32.0)), contents::EMPTY);
    }

    fn solid_box(planes: &mut PlaneSet, lo: DVec3, hi: DVec3) -> Brush {
        Brush::from_planes(&box_planes(lo, hi), planes, contents::SOLID, 0).expect("box")
    }

    #[test]
    fn planes_shared_by_many_brushes_split_first() {
        // A row of boxes sharing their floor, top and y planes: one node each for those serves
        // every box, so they go first and the tree needs a single leaf between two boxes.
        let mut planes = PlaneSet::new();
        let brushes: Vec<Brush> = (0..4)
            .map(|i| {
                let x = 128.0 * f64::from(i);
                solid_box(
                    &mut planes,
                    DVec3::new(x, 0.0, 0.0),
                    DVec3::new(x + 64.0, 64.0, 64.0),
                )
            })
            .collect();
        for heuristic in [SplitHeuristic::FewestSplits, SplitHeuristic::Balanced] {
            let tree = build_tree(brushes.clone(), &planes, heuristic, false);
            let leaves = tree.nodes.iter().filter(|n| n.is_leaf()).count();
            assert_eq!(leaves, 4 + 4 + 5, "{heuristic:?}");
        }
    }

    #[test]
    fn hint_sides_split_first() {
        let mut planes = PlaneSet::new();
        let mut brushes = vec![
            solid_box(&mut planes, DVec3::ZERO, DVec3::new(64.0, 64.0, 64.0)),
            solid_box(
                &mut planes,
                DVec3::new(128.0, 0.0, 0.0),
                DVec3::new(192.0, 64.0, 64.0),
            ),
        ];
        let without = build_tree(
            brushes.clone(),
            &planes,
            SplitHeuristic::FewestSplits,
            false,
        );
        let (hint_plane, _) = planes.insert(&Plane::new(DVec3::new(1.0, 0.0, 0.0), 100.0));
        assert_ne!(without.nodes[0].plane, Some(hint_plane));
        let hint = hint_box(
            &mut planes,
            DVec3::new(90.0, -8.0, -8.0),
            DVec3::new(100.0, 72.0, 72.0),
            hint_plane,
        );
        brushes.push(hint);
        let tree = build_tree(brushes, &planes, SplitHeuristic::FewestSplits, false);
        assert_eq!(tree.nodes[0].plane, Some(hint_plane));
        // The hint brush is empty space: neither solid nor a plane of its skip faces.
        let find = |p: DVec3| tree.nodes[tree.leaf_at(&planes, p) as usize].contents;
        assert_eq!(find(DVec3::new(95.0, 32.0, 32.0)), contents::EMPTY);
        let (skip_plane, _) = planes.insert(&Plane::new(DVec3::new(1.0, 0.0, 0.0), 90.0));
        assert!(tree.nodes.iter().all(|n| n.plane != Some(skip_plane)));
    }

    /// An empty box brush of entity 2 whose face on `hint_plane` is a hint; its other faces are
    /// skip.
    fn hint_box(planes: &mut PlaneSet, lo: DVec3, hi: DVec3, hint_plane: PlaneId) -> Brush {
        let mut hint =
            Brush::from_planes(&box_planes(lo, hi), planes, contents::EMPTY, 2).expect("hint");
        hint.kind = BrushKind::Hint;
        for s in &mut hint.sides {
            s.buried = s.plane != hint_plane;
        }
        hint
    }

    /// Walks `tree` from the root with each node's region (the box `bounds` grown as
    /// `build_tree` grows it, cut by the planes above): every node's plane must cut its region
    /// cleanly.
    fn assert_planes_cut_their_regions(tree: &Tree, planes: &PlaneSet, bounds: &Bounds) {
        let mut stack = vec![(0u32, Region::around(bounds, REGION_MARGIN))];
        while let Some((n, region)) = stack.pop() {
            let node = &tree.nodes[n as usize];
            let Some(id) = node.plane else { continue };
            let plane = planes.get(id);
            let Some([front, back]) = region.split_cleanly(plane) else {
                panic!("node {n}: plane {plane:?}");
            };
            stack.push((node.children[0], front));
            stack.push((node.children[1], back));
        }
    }

    /// The cause of DarkPlaces' "new portal was clipped away" on LibreQuake e3m4: a brush
    /// reaching past a split by less than it can be cut is kept whole on both sides, so on the
    /// side it barely reaches its far sides were still candidates, and one became a node whose
    /// plane lies outside the node's region (its back child empty).
    #[test]
    fn brushes_kept_whole_past_a_split_give_no_planes_outside_the_region() {
        let mut planes = PlaneSet::new();
        // Reaches 0.05 above the hint plane z = 0: that part is too small to build.
        let post = solid_box(
            &mut planes,
            DVec3::new(0.0, 0.0, -64.0),
            DVec3::new(1.0, 1.0, 0.05),
        );
        let floor = solid_box(
            &mut planes,
            DVec3::new(-64.0, -64.0, -80.0),
            DVec3::new(64.0, 64.0, -64.0),
        );
        let (hint_plane, _) = planes.insert(&Plane::new(DVec3::new(0.0, 0.0, 1.0), 0.0));
        let hint = hint_box(
            &mut planes,
            DVec3::new(-64.0, -64.0, -8.0),
            DVec3::new(64.0, 64.0, 0.0),
            hint_plane,
        );
        let brushes = vec![post, floor, hint];
        let bounds = brushes
            .iter()
            .fold(Bounds::EMPTY, |acc, b| acc.union(&b.bounds));
        let tree = build_tree(brushes, &planes, SplitHeuristic::FewestSplits, true);
        assert_eq!(tree.nodes[0].plane, Some(hint_plane));
        assert_planes_cut_their_regions(&tree, &planes, &bounds);
        let find = |p: DVec3| tree.nodes[tree.leaf_at(&planes, p) as usize].contents;
        assert_eq!(find(DVec3::new(0.5, 0.5, -32.0)), contents::SOLID);
        assert_eq!(find(DVec3::new(0.5, 0.5, 8.0)), contents::EMPTY);
        assert_eq!(find(DVec3::new(8.0, 0.5, -32.0)), contents::EMPTY);
    }

    #[test]
    fn detail_splits_below_the_structural_leaves() {
        let mut planes = PlaneSet::new();
        let wall = solid_box(&mut planes, DVec3::ZERO, DVec3::new(16.0, 256.0, 256.0));
        let mut pillar = solid_box(
            &mut planes,
            DVec3::new(100.0, 100.0, 0.0),
            DVec3::new(132.0, 132.0, 256.0),
        );
        pillar.kind = BrushKind::Detail;
        let tree = build_tree(
            vec![wall, pillar],
            &planes,
            SplitHeuristic::FewestSplits,
            true,
        );
        // The wall's six planes come first: seven structural leaves, one of them split further.
        let clusters: Vec<usize> = (0..tree.nodes.len())
            .filter(|&i| tree.nodes[i].cluster.is_some())
            .collect();
        assert_eq!(clusters.len(), 7);
        let split = clusters
            .iter()
            .filter(|&&i| !tree.nodes[i].is_leaf())
            .count();
        assert_eq!(split, 1);
        let pillar_cluster = tree.clusters_touching(&planes, DVec3::new(116.0, 116.0, 128.0))[0];
        assert_eq!(
            tree.nodes[pillar_cluster as usize].cluster,
            Some(contents::EMPTY)
        );
        let leaf = tree.leaf_at(&planes, DVec3::new(116.0, 116.0, 128.0));
        assert_eq!(tree.nodes[leaf as usize].contents, contents::SOLID);
        assert!(tree.leaves_below(pillar_cluster).contains(&leaf));
    }

    proptest::proptest! {
        /// Overlapping boxes: every point well inside one lands in a solid leaf, every point
        /// well outside all of them in an empty one.
        #[test]
        fn boxes_give_solid_leaves_exactly_inside(
            boxes in proptest::collection::vec(
                ((-8i32..8, -8i32..8, -8i32..8), (1i32..6, 1i32..6, 1i32..6)),
                1..6,
            ),
            probes in proptest::collection::vec((-80i32..120, -80i32..120, -80i32..120), 40),
        ) {
            let mut planes = PlaneSet::new();
            let boxes: Vec<(DVec3, DVec3)> = boxes
                .iter()
                .map(|&((x, y, z), (w, d, h))| {
                    let lo = DVec3::new(x as f64, y as f64, z as f64) * 8.0;
                    (lo, lo + DVec3::new(w as f64, d as f64, h as f64) * 8.0)
                })
                .collect();
            let brushes: Vec<Brush> = boxes
                .iter()
                .enumerate()
                .map(|(i, &(lo, hi))| {
                    Brush::from_planes(&box_planes(lo, hi), &mut planes, contents::SOLID, i as u32)
                        .expect("box")
                })
                .collect();
            let mut brushes = brushes;
            crate::csg::mark_hidden_sides(&mut brushes, &planes);
            let tree = build_tree(brushes, &planes, SplitHeuristic::FewestSplits, true);
            for &(x, y, z) in &probes {
                // Odd coordinates are never on a box plane (those are multiples of 8).
                let p = DVec3::new(x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5);
                let inside = boxes.iter().any(|&(lo, hi)| Bounds { mins: lo, maxs: hi }.contains(p));
                let leaf = tree.leaf_at(&planes, p) as usize;
                let expected = if inside { contents::SOLID } else { contents::EMPTY };
                proptest::prop_assert_eq!(tree.nodes[leaf].contents, expected, "{:?}", p);
                // Half a unit from every plane: the one leaf it is in, and only that.
                proptest::prop_assert_eq!(tree.leaves_touching(&planes, p), vec![leaf as u32]);
            }
            // A point on the middle of a box's top face touches that box's solid leaf, and an
            // empty one unless boxes fill every octant around it (the boxes' planes are a grid
            // there, so the octants tell which leaves lie within ON_EPSILON).
            let in_a_box = |p: DVec3| {
                boxes.iter().any(|&(lo, hi)| Bounds { mins: lo, maxs: hi }.contains(p))
            };
            for &(lo, hi) in &boxes {
                let top = DVec3::new((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, hi.z);
                let touched = tree.leaves_touching(&planes, top);
                let solid = |l: &u32| tree.nodes[*l as usize].contents == contents::SOLID;
                proptest::prop_assert!(touched.iter().any(solid), "{:?}", top);
                let filled = (0..8).all(|octant| {
                    let sign = |bit: i32| if octant & bit == 0 { -1.0 } else { 1.0 };
                    in_a_box(top + DVec3::new(sign(1), sign(2), sign(4)) * (ON_EPSILON / 2.0))
                });
                proptest::prop_assert_eq!(touched.iter().all(solid), filled, "{:?}", top);
            }
        }

        /// Counting stops early only for candidates that cannot win: the choice is the one
        /// scoring every candidate in full makes, for both heuristics.
        #[test]
        fn best_splitter_chooses_as_scoring_every_candidate_does(
            spans in proptest::collection::vec((-20i32..20, 1i32..12), 1..40),
            cuts in proptest::collection::vec(-24i32..24, 1..16),
            balanced in proptest::bool::ANY,
        ) {
            let mut planes = PlaneSet::new();
            let mut candidates: Vec<PlaneId> = cuts
                .iter()
                .map(|&c| planes.insert(&Plane::new(DVec3::X, f64::from(c))).0)
                .collect();
            candidates.sort_unstable();
            candidates.dedup();
            // Spans of x; one lies on a candidate where it starts there.
            let sides = |&(lo, len): &(i32, i32), id: PlaneId| {
                let p = planes.get(id);
                (f64::from(lo + len) > p.dist, f64::from(lo) < p.dist)
            };
            let mut facing: Vec<PlaneId> = spans
                .iter()
                .filter_map(|&(lo, _)| {
                    candidates.iter().copied().find(|&id| planes.get(id).dist == f64::from(lo))
                })
                .collect();
            facing.sort_unstable();
            let heuristic = if balanced {
                SplitHeuristic::Balanced
            } else {
                SplitHeuristic::FewestSplits
            };
            let exhaustive = candidates
                .iter()
                .map(|&id| {
                    let plane = planes.get(id);
                    let count = |want: (bool, bool)| {
                        spans.iter().filter(|s| sides(s, id) == want).count() as i64
                    };
                    let counts = SplitCounts {
                        split: count((true, true)),
                        facing: count_sorted(&facing, id),
                        front: count((true, false)),
                        back: count((false, true)),
                    };
                    (heuristic.key(plane, counts), id)
                })
                .min()
                .map(|(_, id)| id);
            let chosen = best_splitter(
                &candidates,
                &spans,
                |id| id,
                |span, &id| sides(span, id),
                &facing,
                &planes,
                heuristic,
            );
            proptest::prop_assert_eq!(chosen, exhaustive);
        }
    }
}
