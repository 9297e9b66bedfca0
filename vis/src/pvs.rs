//! Per-leaf potentially visible sets.

use crate::bitset::BitSet;
use crate::portals::PortalGraph;

/// One row per vis leaf: row `i` is BSP leaf `i + 1`, and bit `j` of a row stands for BSP leaf
/// `j + 1` (leaf 0, the outside, has no row and no bit).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pvs {
    rows: Vec<BitSet>,
}

impl Pvs {
    /// Rows must all cover `rows.len()` leaves.
    pub fn new(rows: Vec<BitSet>) -> Pvs {
        debug_assert!(rows.iter().all(|r| r.len() == rows.len()));
        Pvs { rows }
    }

    /// Each cluster's set: itself plus the clusters seen through each portal out of it.
    pub fn cluster_rows(graph: &PortalGraph, seen_through: &[BitSet]) -> Vec<BitSet> {
        let n = graph.num_clusters;
        (0..n)
            .map(|cluster| {
                let mut row = BitSet::new(n);
                row.insert(cluster);
                for &p in &graph.cluster_portals[cluster] {
                    row.union_with(&seen_through[p as usize]);
                }
                row
            })
            .collect()
    }

    /// The clusters behind a portal and behind every portal in `portals` (what base vis gives).
    pub fn clusters_behind(graph: &PortalGraph, portal: usize, portals: &BitSet) -> BitSet {
        let mut clusters = BitSet::new(graph.num_clusters);
        clusters.insert(graph.portals[portal].to_cluster as usize);
        for q in portals.iter() {
            clusters.insert(graph.portals[q].to_cluster as usize);
        }
        clusters
    }

    /// Keep only the pairs seen both ways; returns how many one-way pairs were dropped. Sight is
    /// symmetric and both rows are conservative, so when one side does not see the other,
    /// neither truly does.
    pub fn intersect_with_transpose(rows: &mut [BitSet]) -> usize {
        let mut dropped = 0;
        for a in 0..rows.len() {
            let lonely: Vec<usize> = rows[a].iter().filter(|&b| !rows[b].contains(a)).collect();
            dropped += lonely.len();
            for b in lonely {
                rows[a].remove(b);
            }
        }
        dropped
    }

    /// Vis leaves (rows), BSP leaves 1..=N.
    pub fn num_leafs(&self) -> usize {
        self.rows.len()
    }

    /// The set of vis leaf `leaf` (BSP leaf `leaf + 1`).
    pub fn row(&self, leaf: usize) -> &BitSet {
        &self.rows[leaf]
    }

    pub(crate) fn rows(&self) -> &[BitSet] {
        &self.rows
    }

    /// Whether vis leaf `from` may see vis leaf `to` (both BSP leaf - 1).
    pub fn sees(&self, from: usize, to: usize) -> bool {
        self.rows[from].contains(to)
    }

    /// Leaves each leaf's set holds, on average.
    pub fn average_visible(&self) -> f64 {
        let total: usize = self.rows.iter().map(BitSet::count).sum();
        total as f64 / self.rows.len().max(1) as f64
    }

    pub(crate) fn max_visible(&self) -> usize {
        self.rows.iter().map(BitSet::count).max().unwrap_or(0)
    }

    /// True when every leaf's set holds this one's (for checking one mode against another).
    pub fn is_subset_of(&self, other: &Pvs) -> bool {
        self.rows.len() == other.rows.len()
            && self
                .rows
                .iter()
                .zip(&other.rows)
                .all(|(a, b)| a.is_subset(b))
    }
}
