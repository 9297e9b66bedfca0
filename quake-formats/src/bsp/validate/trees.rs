//! The hull trees as engines walk them: numbered from each model's head, acyclic, rooted at 0.

use super::{Checker, Rule};
use crate::bsp::contents;
use std::collections::HashSet;

/// The hulls QuakeSpasm traces (0: points, 1: player, 2: shambler); hull 3 is never used.
const TRACED_HULLS: usize = 3;

pub(super) fn check(c: &mut Checker) {
    let bsp = c.bsp;
    if bsp.nodes.is_empty() {
        c.report(
            Rule::NoNodes,
            "nodes",
            0,
            "the file has no nodes".to_string(),
        );
    }
    if let Some(world) = bsp.models.first()
        && world.head_nodes[0] != 0
    {
        let detail = format!("the world's head node is {}, not 0", world.head_nodes[0]);
        c.report(Rule::WorldHeadNode, "models", 0, detail);
    }
    check_numbering(c);
    if let Some(leaf) = bsp.leafs.first()
        && leaf.contents != contents::SOLID
    {
        let detail = format!("leaf 0 has contents {}, not solid", leaf.contents);
        c.report(Rule::LeafZeroSolid, "leafs", 0, detail);
    }
}

/// Walks every model's hulls 0-2 from their heads (QuakeSpasm's `firstclipnode`), reporting
/// nodes numbered below the head and cycles (each cycle once).
fn check_numbering(c: &mut Checker) {
    let bsp = c.bsp;
    let mut nodes = Walker::new(bsp.nodes.len());
    let mut clipnodes = Walker::new(bsp.clipnodes.len());
    let mut cycles = HashSet::new();
    for (i, m) in bsp.models.iter().enumerate() {
        if bsp.clipnodes.is_empty() && m.head_nodes[1..TRACED_HULLS].iter().any(|&h| h >= 0) {
            let detail = "hulls 1 and 2 name head clip nodes, but the file has none".to_string();
            c.report(Rule::ClipHullsMissing, "models", i, detail);
        }
        for hull in 0..TRACED_HULLS {
            let Ok(head) = usize::try_from(m.head_nodes[hull]) else {
                continue; // a leaf or contents: nothing to walk
            };
            let (walk, kind) = if hull == 0 {
                let walk = nodes.walk(head, |n| bsp.nodes[n].children);
                if i == 0 {
                    check_world_children(c, &nodes);
                }
                (walk, "node")
            } else {
                let walk = clipnodes.walk(head, |n| bsp.clipnodes[n].children);
                (walk, "clip node")
            };
            if let Some((parent, child)) = walk.below_head {
                let detail = format!(
                    "hull {hull} reaches {kind} {child} (child of {parent}), below its head {head}"
                );
                c.report(Rule::HullNodeRange, "models", i, detail);
            }
            if let Some((parent, child)) = walk.cycle
                && cycles.insert((hull == 0, parent, child))
            {
                let detail = format!("hull {hull}: {kind} {parent} leads back to {kind} {child}");
                c.report(Rule::TreeCycle, "models", i, detail);
            }
        }
    }
}

/// DarkPlaces builds portals down the world's tree at load and stops at a node whose two
/// children are one.
fn check_world_children(c: &mut Checker, world: &Walker) {
    let bsp = c.bsp;
    for (i, n) in bsp.nodes.iter().enumerate() {
        if world.reached(i) && n.children[0] == n.children[1] {
            let detail = format!("both children are {}", n.children[0]);
            c.report(Rule::NodeSameChildren, "nodes", i, detail);
        }
    }
}

/// What a walk from one head found: the first edge to a node numbered below the head, and the
/// first edge that leads back to a node on the current path (parent, child).
#[derive(Debug, Default, PartialEq)]
struct Walk {
    below_head: Option<(usize, usize)>,
    cycle: Option<(usize, usize)>,
}

/// Depth-first walks over one tree lump; children `>= 0` are nodes, the rest leaves or contents.
/// Stamps instead of cleared flags keep repeated walks linear in the nodes they visit.
struct Walker {
    entered: Vec<u32>,
    finished: Vec<u32>,
    stamp: u32,
}

impl Walker {
    fn new(len: usize) -> Walker {
        Walker {
            entered: vec![0; len],
            finished: vec![0; len],
            stamp: 0,
        }
    }

    /// Whether the last walk reached node `n`.
    fn reached(&self, n: usize) -> bool {
        self.stamp > 0 && self.entered[n] == self.stamp
    }

    /// Walks from `head`; out-of-range children are skipped (`structure` reports them).
    fn walk(&mut self, head: usize, children: impl Fn(usize) -> [i32; 2]) -> Walk {
        let len = self.entered.len();
        let mut found = Walk::default();
        if head >= len {
            return found;
        }
        self.stamp += 1;
        let stamp = self.stamp;
        self.entered[head] = stamp;
        let mut stack = vec![(head, 0)];
        while let Some(top) = stack.last_mut() {
            let (node, side) = *top;
            if side == 2 {
                self.finished[node] = stamp;
                stack.pop();
                continue;
            }
            top.1 += 1;
            let Some(child) = usize::try_from(children(node)[side])
                .ok()
                .filter(|&n| n < len)
            else {
                continue;
            };
            if child < head && found.below_head.is_none() {
                found.below_head = Some((node, child));
            }
            if self.entered[child] == stamp {
                if self.finished[child] != stamp && found.cycle.is_none() {
                    found.cycle = Some((node, child));
                }
                continue;
            }
            self.entered[child] = stamp;
            stack.push((child, 0));
        }
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn walk(tree: &[[i32; 2]], head: usize) -> Walk {
        Walker::new(tree.len()).walk(head, |n| tree[n])
    }

    #[test]
    fn pre_order_trees_walk_clean() {
        // 0 -> (1, 4), 1 -> (2, 3): head first, children after.
        let tree = [[1, 4], [2, 3], [-1, -2], [-1, -2], [-2, -1]];
        assert_eq!(walk(&tree, 0), Walk::default());
        assert_eq!(walk(&tree, 1), Walk::default());
    }

    #[test]
    fn children_first_numbering_is_found_below_the_head() {
        // The compiler's old layout: the head written last.
        let tree = [[-1, -2], [-2, -1], [0, 1]];
        assert_eq!(walk(&tree, 2).below_head, Some((2, 0)));
    }

    #[test]
    fn cycles_are_found_but_shared_subtrees_are_not() {
        let cycle = [[1, -1], [2, -1], [1, -2]];
        assert_eq!(walk(&cycle, 0).cycle, Some((2, 1)));
        let shared = [[1, 2], [3, -1], [3, -1], [-2, -1]];
        assert_eq!(walk(&shared, 0), Walk::default());
    }

    #[test]
    fn out_of_range_children_and_heads_are_left_to_the_structure_check() {
        let tree = [[7, -1]];
        assert_eq!(walk(&tree, 0), Walk::default());
        assert_eq!(walk(&tree, 5), Walk::default());
    }
}
