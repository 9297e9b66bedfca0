//! The BSP tree: brushes are split by their own side planes until every brush fragment in a
//! region fills it, so each leaf is convex and has one contents (the strongest brush in it).
//! This does the CSG implicitly: hidden faces between touching or overlapping brushes never
//! become faces, because faces are only made where leaf contents change (see [`crate::faces`]).

use crate::brush::Brush;
use crate::planes::{PlaneId, PlaneSet};
use quake_formats::bsp::contents;
use quake_formats::geom::{Bounds, Vec3};
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

enum BuildNode {
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

fn flatten(node: BuildNode, out: &mut Vec<TreeNode>) -> u32 {
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
        let Some(plane) = self.choose_splitter(&brushes) else {
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

    /// For a big node: the axial candidate closest to the middle of its longest axis.
    fn mid_split(&self, brushes: &[Brush], candidates: &[PlaneId]) -> Option<PlaneId> {
        let bounds = brushes
            .iter()
            .fold(Bounds::EMPTY, |acc, b| acc.union(&b.bounds));
        let size = bounds.maxs - bounds.mins;
        let axis = (0..3).max_by(|&a, &b| size[a].total_cmp(&size[b]).then(b.cmp(&a)))?;
        if size[axis] <= MID_SPLIT_SIZE {
            return None;
        }
        let middle = bounds.center()[axis];
        candidates
            .iter()
            .filter(|&&id| self.planes.get(id).axial() == Some(axis))
            .min_by(|&&a, &&b| {
                let da = (self.planes.get(a).dist - middle).abs();
                let db = (self.planes.get(b).dist - middle).abs();
                da.total_cmp(&db).then(a.cmp(&b))
            })
            .copied()
    }

    /// The best unused side plane, or `None` when every side has been used (a leaf).
    fn choose_splitter(&self, brushes: &[Brush]) -> Option<PlaneId> {
        let mut candidates: Vec<PlaneId> = brushes
            .iter()
            .flat_map(|b| b.sides.iter().filter(|s| !s.used).map(|s| s.plane))
            .collect();
        if candidates.is_empty() {
            return None;
        }
        candidates.sort_unstable();
        candidates.dedup();
        if let Some(mid) = self.mid_split(brushes, &candidates) {
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
            let imbalance = (front - back).abs();
            let non_axial = i64::from(plane.axial().is_none());
            let key = match self.heuristic {
                SplitHeuristic::FewestSplits => (split, imbalance, non_axial),
                SplitHeuristic::Balanced => (5 * split + imbalance, non_axial, 0),
            };
            (key, id)
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
}
