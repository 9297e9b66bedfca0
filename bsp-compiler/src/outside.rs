//! Outside filling: flood from the void through open portals; if that reaches a point entity the
//! map leaks (report it with a path to the void), otherwise every flooded leaf becomes solid.
//!
//! The flood runs over the structural leaves (vis clusters) with their structural contents:
//! detail brushes never seal a map, as in ericw-tools.

use crate::planes::PlaneSet;
use crate::portals::Portals;
use crate::tree::{Tree, TreeNode, engine_contents, is_opaque};
use crate::warnings::Warning;
use glam::DVec3;
use quake_formats::bsp::contents;

use std::cmp::Ordering;
use std::collections::{BinaryHeap, VecDeque};

/// A point entity that marks open space.
#[derive(Debug, Clone, PartialEq)]
pub struct Occupant {
    pub entity: usize,
    pub classname: String,
    pub origin: DVec3,
}

/// A map open to the void.
#[derive(Debug, Clone, PartialEq)]
pub struct Leak {
    pub entity: usize,
    pub classname: String,
    pub origin: DVec3,
    /// From the entity through portal centres to the outside box (what the `.pts` file holds).
    pub pointfile: Vec<DVec3>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum FillOutcome {
    /// The outside was filled; this many leaves became solid.
    Sealed {
        filled: usize,
    },
    Leaked(Leak),
    /// No entity in open space: nothing can be told inside from outside.
    NoOccupants,
}

/// Flood `tree` from the outside and fill it unless an occupant is reached. `portals` are its
/// cluster portals ([`crate::portals::make_cluster_portals`]).
pub fn fill_outside(
    tree: &mut Tree,
    planes: &PlaneSet,
    portals: &Portals,
    occupants: &[Occupant],
    warnings: &mut Vec<Warning>,
) -> FillOutcome {
    let leaf_count = portals.leaf_portals.len();
    let mut occupant_of: Vec<Option<usize>> = vec![None; leaf_count];
    let cluster_contents = |node: &TreeNode| node.cluster.unwrap_or(node.contents);
    for (i, o) in occupants.iter().enumerate() {
        let cluster = tree.cluster_at(planes, o.origin) as usize;
        let leaf = &tree.nodes[tree.leaf_at(planes, o.origin) as usize];
        let sealed_in = is_opaque(cluster_contents(&tree.nodes[cluster]));
        if sealed_in || engine_contents(leaf.contents) == contents::SOLID {
            warnings.push(Warning::EntityInSolid {
                entity: o.entity,
                classname: o.classname.clone(),
                origin: o.origin,
            });
        }
        if !sealed_in && occupant_of[cluster].is_none() {
            occupant_of[cluster] = Some(i);
        }
    }
    if occupant_of.iter().all(Option::is_none) {
        return FillOutcome::NoOccupants;
    }
    let contents_of = |cluster: u32| {
        if cluster == portals.outside {
            contents::EMPTY
        } else {
            cluster_contents(&tree.nodes[cluster as usize])
        }
    };
    let mut reached = vec![false; leaf_count];
    reached[portals.outside as usize] = true;
    let mut queue = VecDeque::from([portals.outside]);
    while let Some(leaf) = queue.pop_front() {
        for &p in &portals.leaf_portals[leaf as usize] {
            let next = portals.other(p, leaf);
            if !reached[next as usize] && !is_opaque(contents_of(next)) {
                reached[next as usize] = true;
                queue.push_back(next);
            }
        }
    }
    let leaking = (0..leaf_count)
        .filter(|&l| reached[l])
        .filter_map(|l| occupant_of[l].map(|o| (o, l as u32)))
        .min();
    if let Some((o, leaf)) = leaking {
        let o = &occupants[o];
        let mut pointfile = vec![o.origin];
        pointfile.extend(path_to_outside(portals, &contents_of, leaf, o.origin));
        return FillOutcome::Leaked(Leak {
            entity: o.entity,
            classname: o.classname.clone(),
            origin: o.origin,
            pointfile,
        });
    }
    let mut filled = 0;
    for (cluster, &r) in reached.iter().enumerate().take(tree.nodes.len()) {
        if r && tree.nodes[cluster].cluster.is_some() {
            tree.nodes[cluster].cluster = Some(contents::SOLID);
            for leaf in tree.leaves_below(cluster as u32) {
                tree.nodes[leaf as usize].contents = contents::SOLID;
                filled += 1;
            }
        }
    }
    FillOutcome::Sealed { filled }
}

#[derive(PartialEq)]
struct Visit {
    dist: f64,
    portal: u32,
}

impl Eq for Visit {}

impl Ord for Visit {
    fn cmp(&self, o: &Self) -> Ordering {
        // Min-heap on distance, ties by portal index for a deterministic path.
        o.dist
            .total_cmp(&self.dist)
            .then_with(|| o.portal.cmp(&self.portal))
    }
}

impl PartialOrd for Visit {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// The shortest path through portal centres from `origin` in `start` to the outside box.
fn path_to_outside(
    portals: &Portals,
    contents_of: &dyn Fn(u32) -> i32,
    start: u32,
    origin: DVec3,
) -> Vec<DVec3> {
    let n = portals.portals.len();
    let centre: Vec<DVec3> = portals.portals.iter().map(|p| p.winding.center()).collect();
    let mut dist = vec![f64::INFINITY; n];
    let mut prev = vec![u32::MAX; n];
    let mut heap = BinaryHeap::new();
    for &p in &portals.leaf_portals[start as usize] {
        let d = (centre[p as usize] - origin).length();
        if d < dist[p as usize] && !is_opaque(contents_of(portals.other(p, start))) {
            dist[p as usize] = d;
            heap.push(Visit { dist: d, portal: p });
        }
    }
    while let Some(Visit { dist: d, portal }) = heap.pop() {
        if d > dist[portal as usize] {
            continue;
        }
        let nodes = portals.portals[portal as usize].nodes;
        if nodes.contains(&portals.outside) {
            let mut path = Vec::new();
            let mut p = portal;
            while p != u32::MAX {
                path.push(centre[p as usize]);
                p = prev[p as usize];
            }
            path.reverse();
            return path;
        }
        for leaf in nodes {
            if is_opaque(contents_of(leaf)) {
                continue;
            }
            for &q in &portals.leaf_portals[leaf as usize] {
                let nd = d + (centre[q as usize] - centre[portal as usize]).length();
                if nd < dist[q as usize] && !is_opaque(contents_of(portals.other(q, leaf))) {
                    dist[q as usize] = nd;
                    prev[q as usize] = portal;
                    heap.push(Visit {
                        dist: nd,
                        portal: q,
                    });
                }
            }
        }
    }
    Vec::new()
}
