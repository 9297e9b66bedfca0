//! Base vis: for each one-way portal, the portals that might be seen through it.
//!
//! A portal `q` can only be seen through `p` when part of `q` lies in front of `p` (beyond it) and
//! part of `p` lies behind `q` (so the line of sight enters `q` from its back). Flooding from
//! `p`'s leaf through portals passing that test gives a conservative set: the fast PVS, and the
//! pruning bound of the full flow.

use crate::bitset::BitSet;
use crate::portals::{OneWayPortal, PortalGraph};
use quake_formats::geom::ON_EPSILON;

/// The plane test of classic vis: could anything seen through `p` be seen through `q` next?
/// Bounding spheres wholly on one side of a plane answer without testing the points.
pub fn may_see_through(p: &OneWayPortal, q: &OneWayPortal) -> bool {
    let q_beyond = match q.sphere_side(&p.plane) {
        Some(front) => front,
        None => q.winding.iter().any(|&v| p.plane.distance(v) > ON_EPSILON),
    };
    let p_behind = || match p.sphere_side(&q.plane) {
        Some(front) => !front,
        None => p.winding.iter().any(|&v| q.plane.distance(v) < -ON_EPSILON),
    };
    q_beyond && p_behind()
}

/// The portals possibly visible through `source` (its "mightsee" set), flooding leaf by leaf
/// through portals that pass [`may_see_through`] against the source. Plane tests run only on
/// portals the flood reaches, which gives the same set as testing every pair first.
pub fn mightsee(graph: &PortalGraph, source: usize) -> BitSet {
    let p = &graph.portals[source];
    let mut seen = BitSet::new(graph.portals.len());
    let mut flooded = BitSet::new(graph.num_clusters);
    let mut stack = vec![p.to_cluster];
    flooded.insert(p.to_cluster as usize);
    while let Some(leaf) = stack.pop() {
        for &q in &graph.cluster_portals[leaf as usize] {
            let portal = &graph.portals[q as usize];
            if q as usize == source || !may_see_through(p, portal) {
                continue;
            }
            seen.insert(q as usize);
            if !flooded.contains(portal.to_cluster as usize) {
                flooded.insert(portal.to_cluster as usize);
                stack.push(portal.to_cluster);
            }
        }
    }
    seen
}
