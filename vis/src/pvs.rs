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

    /// A leaf's set is itself plus the leaves seen through each portal out of it.
    pub fn from_portal_leafs(graph: &PortalGraph, portal_leafs: &[BitSet]) -> Pvs {
        let n = graph.num_leafs;
        let rows = (0..n)
            .map(|leaf| {
                let mut row = BitSet::new(n);
                row.insert(leaf);
                for &p in &graph.leaf_portals[leaf] {
                    row.union_with(&portal_leafs[p as usize]);
                }
                row
            })
            .collect();
        Pvs { rows }
    }

    /// The leaves behind a portal and behind every portal in `portals` (what base vis gives).
    pub fn leafs_behind(graph: &PortalGraph, portal: usize, portals: &BitSet) -> BitSet {
        let mut leafs = BitSet::new(graph.num_leafs);
        leafs.insert(graph.portals[portal].to_leaf as usize);
        for q in portals.iter() {
            leafs.insert(graph.portals[q].to_leaf as usize);
        }
        leafs
    }

    pub fn num_leafs(&self) -> usize {
        self.rows.len()
    }

    /// The set of vis leaf `leaf` (BSP leaf `leaf + 1`).
    pub fn row(&self, leaf: usize) -> &BitSet {
        &self.rows[leaf]
    }

    pub fn rows(&self) -> &[BitSet] {
        &self.rows
    }

    pub fn sees(&self, from: usize, to: usize) -> bool {
        self.rows[from].contains(to)
    }

    pub fn average_visible(&self) -> f64 {
        let total: usize = self.rows.iter().map(BitSet::count).sum();
        total as f64 / self.rows.len().max(1) as f64
    }

    pub fn max_visible(&self) -> usize {
        self.rows.iter().map(BitSet::count).max().unwrap_or(0)
    }

    /// Ordered pairs `(a, b)` where `a` sees `b` but not the other way round. Sight is
    /// symmetric, so these show where the flow's clipping differs by direction.
    pub fn asymmetric_pairs(&self) -> usize {
        self.rows
            .iter()
            .enumerate()
            .map(|(a, row)| row.iter().filter(|&b| !self.rows[b].contains(a)).count())
            .sum()
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
