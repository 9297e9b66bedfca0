//! The BSP tree: brushes are split by their own side planes until every brush fragment in a
//! region fills it, so each leaf is convex and has one contents (the strongest brush in it).
//! This does the CSG implicitly: hidden faces between touching or overlapping brushes never
//! become faces, because faces are only made where leaf contents change (see [`crate::faces`]).

use crate::brush::Brush;
use crate::planes::{PlaneId, PlaneSet};
use quake_formats::bsp::contents;
use quake_formats::geom::{Bounds, Plane, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How the splitting plane of a node is chosen among the node's unused brush side planes.
///
/// Both first cut nodes larger than [`MID_SPLIT_SIZE`] by the axial candidate nearest the middle
/// of their longest axis, as Quake's qbsp does, which keeps big maps' trees shallow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub enum SplitHeuristic {
    /// Fewest brushes split; then the most even front/back count; then axial planes.
    #[default]
    FewestSplits,
    /// Quake 2's weighting: five times the splits plus the front/back difference, axial planes
    /// first on ties.
    Balanced,
}

/// Nodes whose brushes span more than this on some axis are cut near their middle.
pub const MID_SPLIT_SIZE: f64 = 1024.0;

impl SplitHeuristic {
    /// The ranking of a candidate `plane` that splits `split` things and leaves `front` and
    /// `back` whole on either side: lower is better.
    pub fn key(self, plane: &Plane, split: i64, front: i64, back: i64) -> (i64, i64, i64) {
        let imbalance = (front - back).abs();
        let non_axial = i64::from(plane.axial().is_none());
        match self {
            SplitHeuristic::FewestSplits => (split, imbalance, non_axial),
            SplitHeuristic::Balanced => (5 * split + imbalance, non_axial, 0),
        }
    }
}

/// For a node whose contents span `bounds`, larger than [`MID_SPLIT_SIZE`]: the axial candidate
/// closest to the middle of its longest axis.
pub fn mid_split(bounds: &Bounds, candidates: &[PlaneId], planes: &PlaneSet) -> Option<PlaneId> {
    let size = bounds.maxs - bounds.mins;
    let axis = (0..3).max_by(|&a, &b| size[a].total_cmp(&size[b]).then(b.cmp(&a)))?;
    if size[axis] <= MID_SPLIT_SIZE {
        return None;
    }
    let middle = bounds.center()[axis];
    candidates
        .iter()
        .filter(|&&id| planes.get(id).axial() == Some(axis))
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

/// Ranking of contents: a region holding several brushes takes the strongest.
pub fn contents_priority(c: i32) -> u8 {
    match c {
        contents::SOLID => 5,
        contents::SKY => 4,
        contents::LAVA => 3,
        contents::SLIME => 2,
        contents::WATER => 1,
        _ => 0,
    }
}

/// Contents that block flooding and are never looked out of.
pub fn is_opaque(c: i32) -> bool {
    c == contents::SOLID || c == contents::SKY
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
    pub fn leaf_at(&self, planes: &PlaneSet, p: Vec3) -> u32 {
        let mut n = 0u32;
        while let Some(id) = self.nodes[n as usize].plane {
            let d = planes.get(id).distance(p);
            n = self.nodes[n as usize].children[usize::from(d < 0.0)];
        }
        n
    }

    /// For each node, whether everything below it is solid (such subtrees become one leaf).
    pub fn all_solid(&self) -> Vec<bool> {
        let mut solid = vec![false; self.nodes.len()];
        // Children always come after their parent in the flattened order.
        for i in (0..self.nodes.len()).rev() {
            let n = &self.nodes[i];
            solid[i] = match n.plane {
                None => n.contents == contents::SOLID,
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
}

/// Subtrees with at least this many brushes are built in parallel.
const PARALLEL_BRUSHES: usize = 64;

struct Builder<'a> {
    planes: &'a PlaneSet,
    heuristic: SplitHeuristic,
    keep_brushes: bool,
    splits: AtomicUsize,
}

/// Build the tree of `brushes`. `keep_brushes` keeps each leaf's fragments in the result.
pub fn build_tree(
    brushes: Vec<Brush>,
    planes: &PlaneSet,
    heuristic: SplitHeuristic,
    keep_brushes: bool,
) -> Tree {
    let builder = Builder {
        planes,
        heuristic,
        keep_brushes,
        splits: AtomicUsize::new(0),
    };
    let root = builder.build(brushes);
    let mut nodes = Vec::new();
    flatten(root, &mut nodes);
    Tree {
        nodes,
        splits: builder.splits.load(Ordering::Relaxed),
    }
}

pub(crate) fn flatten(node: BuildNode, out: &mut Vec<TreeNode>) -> u32 {
    let index = out.len() as u32;
    match node {
        BuildNode::Leaf { contents, brushes } => out.push(TreeNode {
            plane: None,
            children: [0, 0],
            contents,
            brushes,
        }),
        BuildNode::Split { plane, children } => {
            out.push(TreeNode {
                plane: Some(plane),
                children: [0, 0],
                contents: 0,
                brushes: Vec::new(),
            });
            let [front, back] = *children;
            let f = flatten(front, out);
            let b = flatten(back, out);
            out[index as usize].children = [f, b];
        }
    }
    index
}

impl Builder<'_> {
    fn build(&self, brushes: Vec<Brush>) -> BuildNode {
        // A fragment of the strongest contents filling the region decides it whatever lies
        // inside: splitting further would only cut up space of one contents.
        let strongest = brushes.iter().map(|b| contents_priority(b.contents)).max();
        let filled = brushes
            .iter()
            .any(|b| Some(contents_priority(b.contents)) == strongest && b.fills_node());
        let splitter = if filled {
            None
        } else {
            self.choose_splitter(&brushes)
        };
        let Some(plane) = splitter else {
            let contents = brushes
                .iter()
                .map(|b| b.contents)
                .max_by_key(|&c| contents_priority(c))
                .unwrap_or(contents::EMPTY);
            return BuildNode::Leaf {
                contents,
                brushes: if self.keep_brushes {
                    brushes
                } else {
                    Vec::new()
                },
            };
        };
        let parallel = brushes.len() >= PARALLEL_BRUSHES;
        let mut front = Vec::new();
        let mut back = Vec::new();
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
            rayon::join(|| self.build(front), || self.build(back))
        } else {
            (self.build(front), self.build(back))
        };
        BuildNode::Split {
            plane,
            children: Box::new([f, b]),
        }
    }

    /// The best unused side plane, or `None` when every side has been used (a leaf).
    fn choose_splitter(&self, brushes: &[Brush]) -> Option<PlaneId> {
        let mut candidates: Vec<PlaneId> = brushes
            .iter()
            .flat_map(|b| {
                b.sides
                    .iter()
                    .filter(|s| !s.used && !s.buried)
                    .map(|s| s.plane)
            })
            .collect();
        if candidates.is_empty() {
            return None;
        }
        candidates.sort_unstable();
        candidates.dedup();
        let bounds = brushes
            .iter()
            .fold(Bounds::EMPTY, |acc, b| acc.union(&b.bounds));
        if let Some(mid) = mid_split(&bounds, &candidates, self.planes) {
            return Some(mid);
        }
        let score = |&id: &PlaneId| {
            let plane = self.planes.get(id);
            let (mut front, mut back, mut split) = (0i64, 0i64, 0i64);
            for b in brushes {
                match b.sides_of(plane) {
                    (true, true) => split += 1,
                    (true, false) => front += 1,
                    (false, true) => back += 1,
                    (false, false) => {}
                }
            }
            (self.heuristic.key(plane, split, front, back), id)
        };
        let work = candidates.len() * brushes.len();
        if work > 20_000 {
            candidates.par_iter().map(score).min().map(|(_, id)| id)
        } else {
            candidates.iter().map(score).min().map(|(_, id)| id)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::tests::box_planes;

    #[test]
    fn single_box_gives_one_solid_leaf_and_empty_around() {
        let mut planes = PlaneSet::new();
        let b = Brush::from_planes(
            &box_planes(Vec3::ZERO, Vec3::new(64.0, 64.0, 64.0)),
            &mut planes,
            contents::SOLID,
            0,
        )
        .expect("brush");
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
        let solid = Brush::from_planes(
            &box_planes(Vec3::ZERO, Vec3::new(64.0, 64.0, 64.0)),
            &mut planes,
            contents::SOLID,
            0,
        )
        .expect("solid");
        let water = Brush::from_planes(
            &box_planes(Vec3::new(32.0, 0.0, 0.0), Vec3::new(96.0, 64.0, 64.0)),
            &mut planes,
            contents::WATER,
            1,
        )
        .expect("water");
        let tree = build_tree(vec![water, solid], &planes, SplitHeuristic::Balanced, true);
        let find = |p: Vec3| tree.nodes[tree.leaf_at(&planes, p) as usize].contents;
        assert_eq!(find(Vec3::new(48.0, 32.0, 32.0)), contents::SOLID);
        assert_eq!(find(Vec3::new(80.0, 32.0, 32.0)), contents::WATER);
        assert_eq!(find(Vec3::new(200.0, 32.0, 32.0)), contents::EMPTY);
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
            let boxes: Vec<(Vec3, Vec3)> = boxes
                .iter()
                .map(|&((x, y, z), (w, d, h))| {
                    let lo = Vec3::new(x as f64, y as f64, z as f64) * 8.0;
                    (lo, lo + Vec3::new(w as f64, d as f64, h as f64) * 8.0)
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
                let p = Vec3::new(x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5);
                let inside = boxes.iter().any(|&(lo, hi)| Bounds { mins: lo, maxs: hi }.contains(p));
                let leaf = tree.leaf_at(&planes, p) as usize;
                let expected = if inside { contents::SOLID } else { contents::EMPTY };
                proptest::prop_assert_eq!(tree.nodes[leaf].contents, expected, "{:?}", p);
            }
        }
    }
}
