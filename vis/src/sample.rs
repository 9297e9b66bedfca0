//! Checking a PVS against sight lines: random point pairs in open leaves, traced through the
//! BSP's hull 0 tree. Where nothing opaque lies between two points, each point's leaf must be in
//! the other's PVS (a PVS that is too small shows on screen as missing walls).

use crate::VisError;
use crate::pvs::Pvs;
use glam::DVec3;
use quake_formats::Bsp;
use quake_formats::bsp::{Leaf, contents};
use quake_formats::geom::Plane;
use quake_formats::rng::SplitMix64;
use rayon::prelude::*;

/// Whether sight passes through a leaf of these contents. Sky leaves are opaque: they lie inside
/// sky brushes, and compilers write no portals into them.
pub fn is_open(leaf_contents: i32) -> bool {
    matches!(
        leaf_contents,
        contents::EMPTY | contents::WATER | contents::SLIME | contents::LAVA
    )
}

/// The world's hull 0 tree in `f64`, checked once so tracing needs no error handling.
pub struct Hull0 {
    nodes: Vec<(Plane, [i32; 2])>,
    leaf_contents: Vec<i32>,
    head: i32,
}

impl Hull0 {
    /// The world model's hull 0 tree of `bsp`; refuses a tree that names missing planes,
    /// nodes or leaves, or reaches a node twice.
    pub fn new(bsp: &Bsp) -> Result<Hull0, VisError> {
        let bad = |s: String| VisError::BadTree(s);
        let world = bsp.models.first().ok_or(VisError::NoWorldModel)?;
        let leaf_contents: Vec<i32> = bsp.leafs.iter().map(|l| l.contents).collect();
        let nodes = bsp
            .nodes
            .iter()
            .enumerate()
            .map(|(i, n)| {
                let p = bsp
                    .planes
                    .get(n.plane as usize)
                    .ok_or_else(|| bad(format!("node {i} names missing plane {}", n.plane)))?;
                for c in n.children {
                    let ok = if c >= 0 {
                        (c as usize) < bsp.nodes.len()
                    } else {
                        ((-(c + 1)) as usize) < bsp.leafs.len()
                    };
                    if !ok {
                        return Err(bad(format!("node {i} has child {c} outside the tree")));
                    }
                }
                let normal = DVec3::new(p.normal[0] as f64, p.normal[1] as f64, p.normal[2] as f64);
                Ok((Plane::new(normal, p.dist as f64), n.children))
            })
            .collect::<Result<Vec<_>, VisError>>()?;
        let hull = Hull0 {
            nodes,
            leaf_contents,
            head: world.head_nodes[0],
        };
        hull.check_is_tree()?;
        Ok(hull)
    }

    /// Every node reachable once from the head: no cycles, so recursion ends.
    fn check_is_tree(&self) -> Result<(), VisError> {
        let mut seen = vec![false; self.nodes.len()];
        let mut stack = vec![self.head];
        while let Some(n) = stack.pop() {
            if n < 0 {
                if (-(n + 1)) as usize >= self.leaf_contents.len() {
                    return Err(VisError::BadTree(format!(
                        "head names missing leaf {}",
                        -(n + 1)
                    )));
                }
                continue;
            }
            let Some(node) = self.nodes.get(n as usize) else {
                return Err(VisError::BadTree(format!("head names missing node {n}")));
            };
            if std::mem::replace(&mut seen[n as usize], true) {
                return Err(VisError::BadTree(format!("node {n} is reached twice")));
            }
            stack.extend(node.1);
        }
        Ok(())
    }

    /// The BSP leaf holding point `p`.
    pub fn leaf_at(&self, p: DVec3) -> usize {
        let mut n = self.head;
        while n >= 0 {
            let (plane, children) = &self.nodes[n as usize];
            n = children[usize::from(plane.distance(p) < 0.0)];
        }
        (-(n + 1)) as usize
    }

    /// True when the segment from `a` to `b` passes only through open leaves.
    pub fn segment_is_open(&self, a: DVec3, b: DVec3) -> bool {
        self.open_below(self.head, a, b)
    }

    fn open_below(&self, node: i32, a: DVec3, b: DVec3) -> bool {
        if node < 0 {
            return is_open(self.leaf_contents[(-(node + 1)) as usize]);
        }
        let (plane, children) = &self.nodes[node as usize];
        let da = plane.distance(a);
        let db = plane.distance(b);
        if da >= 0.0 && db >= 0.0 {
            return self.open_below(children[0], a, b);
        }
        if da < 0.0 && db < 0.0 {
            return self.open_below(children[1], a, b);
        }
        let mid = a.lerp_monotonic(b, da / (da - db));
        let near = usize::from(da < 0.0);
        self.open_below(children[near], a, mid) && self.open_below(children[1 - near], mid, b)
    }
}

/// What sampling found.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SamplingReport {
    /// Point pairs sampled, each point in a random open vis leaf.
    pub pairs: usize,
    /// Pairs whose segment crosses nothing opaque.
    pub clear_pairs: usize,
    /// Clear pairs where one leaf is missing from the other's PVS: the PVS is too small.
    pub violations: usize,
    /// `clear_pairs / pairs`: the share of leaf pairs sampling shows to be visible.
    pub visible_fraction: f64,
    /// Share of sampled pairs whose second leaf is in the first one's PVS; the excess over
    /// `visible_fraction` measures how loose the PVS is.
    pub pvs_fraction: f64,
    /// The first few violations: points and their BSP leaf numbers.
    pub examples: Vec<([f64; 3], [f64; 3], [usize; 2])>,
}

/// Sample `n_pairs` pairs of points, each in a random open vis leaf (uniform over leaves, then
/// uniform within the leaf), and check `pvs` against sight lines through hull 0.
pub fn sample_visibility(
    bsp: &Bsp,
    pvs: &Pvs,
    n_pairs: usize,
    seed: u64,
) -> Result<SamplingReport, VisError> {
    crate::lump::check_portals_match(bsp, pvs.num_leafs())?;
    let hull = Hull0::new(bsp)?;
    // Leaves where a first point is found; random draws in them then end quickly.
    let open_leafs: Vec<usize> = (1..=pvs.num_leafs())
        .filter(|&l| {
            let leaf = &bsp.leafs[l];
            let mut rng = SplitMix64::new(seed ^ l as u64);
            is_open(leaf.contents)
                && (0..3).all(|i| leaf.maxs[i] > leaf.mins[i])
                && (0..32).any(|_| hull.leaf_at(point_in_box(leaf, &mut rng)) == l)
        })
        .collect();
    if open_leafs.is_empty() || n_pairs == 0 {
        return Ok(SamplingReport::default());
    }
    const CHUNK: usize = 4096;
    let chunks: Vec<SamplingReport> = (0..n_pairs.div_ceil(CHUNK))
        .into_par_iter()
        .map(|chunk| {
            let mut rng =
                SplitMix64::new(seed ^ (chunk as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
            let pairs = CHUNK.min(n_pairs - chunk * CHUNK);
            let mut report = SamplingReport::default();
            let mut in_pvs = 0;
            for _ in 0..pairs {
                let (a, la) = random_point(bsp, &hull, &open_leafs, &mut rng);
                let (b, lb) = random_point(bsp, &hull, &open_leafs, &mut rng);
                report.pairs += 1;
                let ab = pvs.sees(la - 1, lb - 1);
                in_pvs += usize::from(ab);
                if !hull.segment_is_open(a, b) {
                    continue;
                }
                report.clear_pairs += 1;
                if !ab || !pvs.sees(lb - 1, la - 1) {
                    report.violations += 1;
                    if report.examples.len() < 10 {
                        report.examples.push((a.to_array(), b.to_array(), [la, lb]));
                    }
                }
            }
            report.pvs_fraction = in_pvs as f64;
            report
        })
        .collect();
    let mut total = SamplingReport::default();
    let mut in_pvs = 0.0;
    for c in chunks {
        total.pairs += c.pairs;
        total.clear_pairs += c.clear_pairs;
        total.violations += c.violations;
        in_pvs += c.pvs_fraction;
        let room = 10 - total.examples.len().min(10);
        total.examples.extend(c.examples.into_iter().take(room));
    }
    total.visible_fraction = total.clear_pairs as f64 / total.pairs as f64;
    total.pvs_fraction = in_pvs / total.pairs as f64;
    Ok(total)
}

/// A point in a random open leaf: a random point of the leaf's box that the tree places in that
/// leaf (the box may reach into neighbours). Leaves where that keeps failing are redrawn.
fn random_point(bsp: &Bsp, hull: &Hull0, open: &[usize], rng: &mut SplitMix64) -> (DVec3, usize) {
    loop {
        let leaf = open[rng.below(open.len())];
        for _ in 0..32 {
            let p = point_in_box(&bsp.leafs[leaf], rng);
            if hull.leaf_at(p) == leaf {
                return (p, leaf);
            }
        }
    }
}

fn point_in_box(leaf: &Leaf, rng: &mut SplitMix64) -> DVec3 {
    let mut p = DVec3::ZERO;
    for i in 0..3 {
        p[i] = leaf.mins[i] as f64 + rng.unit() * (leaf.maxs[i] - leaf.mins[i]) as f64;
    }
    p
}
