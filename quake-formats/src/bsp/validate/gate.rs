//! The gate every tool passes a BSP through before it reads the file's indices: the problems that
//! would make a tool read out of bounds, follow a cycle forever, or size an allocation from an
//! unchecked count are refused with the validator's own message.

use super::{Rule, Severity, validate_for_tools};
use crate::bsp::Bsp;
use crate::error::{FormatError, Result};

impl Rule {
    /// Whether a file breaking this rule is refused by Slipgate's tools (vis, light, the viewer,
    /// convert): the structure rules, the trees' shape, and the sizes tools allocate by (surface
    /// extents, visleafs). Rules about what a particular engine or game code accepts are not.
    pub fn refused_by_tools(self) -> bool {
        matches!(
            self,
            Rule::IndexRange
                | Rule::NonFinite
                | Rule::PlaneNormal
                | Rule::FaceEdges
                | Rule::ContentsValue
                | Rule::LightmapRange
                | Rule::NoWorldModel
                | Rule::NoNodes
                | Rule::TreeCycle
                | Rule::SurfaceExtents
                | Rule::VisLeafs
        )
    }
}

/// How many refused problems the error message spells out.
const PROBLEMS_SHOWN: usize = 3;

/// The deepest hull 0 tree tools accept. Real maps stay far below (LibreQuake's lq1m1 is 42 deep,
/// e1m3 38); the file must not decide how deep a tool's recursive walk goes (vis traces sight
/// lines and recovers portals from the tree recursively).
pub const MAX_TREE_DEPTH: usize = 4096;

/// Whether a stage walks the world's hull 0 tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TreeUse {
    /// The stage walks the tree, so a file without nodes is refused.
    Needed,
    /// The stage uses the tree when the file has one (light culls by it) and works from the faces
    /// alone when the nodes lump is empty; a tree that is there must still be sound.
    IfPresent,
}

/// The problems of `bsp` that tools refuse, as [`FormatError::Refused`]; `Ok` when there are
/// none. Every stage's library entry calls this before reading the file's indices.
pub fn check_usable(bsp: &Bsp) -> Result<()> {
    check_usable_for(bsp, TreeUse::Needed)
}

/// [`check_usable`] for a stage that may not need the tree.
pub fn check_usable_for(bsp: &Bsp, tree: TreeUse) -> Result<()> {
    let no_tree_allowed = tree == TreeUse::IfPresent && bsp.nodes.is_empty();
    let refused: Vec<String> = validate_for_tools(bsp)
        .into_iter()
        .filter(|p| p.severity == Severity::Error && p.rule.refused_by_tools())
        .filter(|p| !(no_tree_allowed && is_about_the_missing_tree(p)))
        .map(|p| p.to_string())
        .chain(tree_shape_problem(bsp))
        .collect();
    if refused.is_empty() {
        return Ok(());
    }
    Err(FormatError::Refused {
        count: refused.len(),
        shown: refused[..refused.len().min(PROBLEMS_SHOWN)].join("; "),
    })
}

/// A file without nodes breaks `no-nodes` and, in every model, `index-range` for its head node.
fn is_about_the_missing_tree(p: &super::Problem) -> bool {
    p.rule == Rule::NoNodes
        || (p.rule == Rule::IndexRange && p.lump == "models" && p.detail.starts_with("head node"))
}

/// What engines tolerate but would make a tool's walk exponential or too deep: a hull 0 node
/// reached twice from one model's head (a shared subtree: real compilers write trees), or a
/// tree deeper than [`MAX_TREE_DEPTH`]. Out-of-range children are left to the validator. A
/// model whose head lies in a subtree another model already walked is not walked again, so the
/// check is linear whatever the model count.
fn tree_shape_problem(bsp: &Bsp) -> Option<String> {
    let mut walked_by = vec![0usize; bsp.nodes.len()];
    for (m, model) in bsp.models.iter().enumerate() {
        let stamp = m + 1;
        let Ok(head) = usize::try_from(model.head_nodes[0]) else {
            continue;
        };
        if walked_by.get(head).is_none_or(|&w| w != 0) {
            continue;
        }
        let mut stack = vec![(head, 1usize)];
        walked_by[head] = stamp;
        while let Some((node, depth)) = stack.pop() {
            if depth > MAX_TREE_DEPTH {
                return Some(format!(
                    "error: nodes[{node}]: model {m}'s hull 0 tree is deeper than \
                     {MAX_TREE_DEPTH}, more than tools walk"
                ));
            }
            for child in bsp.nodes[node].children {
                let Some(seen) = usize::try_from(child)
                    .ok()
                    .and_then(|c| walked_by.get_mut(c))
                else {
                    continue;
                };
                if *seen == stamp {
                    return Some(format!(
                        "error: nodes[{node}]: child {child} is reached twice from model {m}'s \
                         hull 0 head (a shared subtree, not a tree)"
                    ));
                }
                if *seen == 0 {
                    *seen = stamp;
                    stack.push((child as usize, depth + 1));
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsp::{BspPlane, BspVersion, Leaf, Model, Node, contents};

    /// One node splitting two empty leaves at x = 0.
    fn one_split() -> Bsp {
        let mut bsp = Bsp::new(BspVersion::Bsp29);
        bsp.set_entity_text("{\n\"classname\" \"worldspawn\"\n}\n");
        bsp.planes = vec![BspPlane {
            normal: [1.0, 0.0, 0.0],
            dist: 0.0,
            kind: 0,
        }];
        bsp.nodes = vec![Node {
            plane: 0,
            children: [-2, -3],
            mins: [-64.0; 3],
            maxs: [64.0; 3],
            first_face: 0,
            num_faces: 0,
        }];
        let empty = Leaf {
            contents: contents::EMPTY,
            ..Leaf::SHARED_SOLID
        };
        bsp.leafs = vec![Leaf::SHARED_SOLID, empty, empty];
        bsp.models = vec![Model {
            mins: [-64.0; 3],
            maxs: [64.0; 3],
            origin: [0.0; 3],
            head_nodes: [0, -1, -1, -1],
            vis_leafs: 2,
            first_face: 0,
            num_faces: 0,
        }];
        bsp
    }

    #[test]
    fn engine_only_rules_are_not_refused() {
        for rule in [
            Rule::ClipHullsMissing,
            Rule::WorldHeadNode,
            Rule::Worldspawn,
            Rule::SkyNameCase,
        ] {
            assert!(!rule.refused_by_tools(), "{}", rule.id());
        }
        for rule in Rule::ALL.into_iter().filter(|r| r.refused_by_tools()) {
            assert_eq!(rule.severity(), Severity::Error, "{}", rule.id());
        }
    }

    /// The gate runs only some rule families: the others must not hold a rule tools refuse.
    #[test]
    fn the_rule_families_the_gate_skips_hold_no_refused_rule() {
        let skipped = [
            include_str!("node_portals.rs"),
            include_str!("textures.rs"),
            include_str!("entities.rs"),
        ];
        for rule in Rule::ALL.into_iter().filter(|r| r.refused_by_tools()) {
            let name = format!("Rule::{rule:?}");
            for source in skipped {
                assert!(
                    !source.contains(&name),
                    "{name} is reported by a family the gate skips"
                );
            }
        }
    }

    #[test]
    fn a_marksurface_past_the_faces_is_refused_with_its_message() {
        let mut bsp = one_split();
        assert!(check_usable(&bsp).is_ok(), "{:?}", check_usable(&bsp));
        bsp.marksurfaces.push(52606);
        let message = check_usable(&bsp).expect_err("refused").to_string();
        assert!(message.contains("marksurfaces["), "{message}");
        assert!(message.contains("52606"), "{message}");
        assert!(message.contains("index-range"), "{message}");
    }

    #[test]
    fn a_cycle_in_the_world_tree_is_refused_but_missing_clip_hulls_are_not() {
        let mut bsp = one_split();
        bsp.models[0].head_nodes[1] = 0;
        assert!(check_usable(&bsp).is_ok(), "{:?}", check_usable(&bsp));
        bsp.nodes[0].children[1] = 0;
        let message = check_usable(&bsp).expect_err("refused").to_string();
        assert!(message.contains("tree-cycle"), "{message}");
    }

    /// `bsp`'s world as a chain of `len` nodes on one plane, each with its back child a leaf.
    fn chain(bsp: &mut Bsp, len: usize) {
        bsp.nodes = (0..len)
            .map(|i| Node {
                children: [if i + 1 < len { i as i32 + 1 } else { -2 }, -3],
                ..bsp.nodes[0]
            })
            .collect();
    }

    #[test]
    fn a_file_without_nodes_passes_only_for_stages_that_can_do_without() {
        let mut bsp = one_split();
        bsp.nodes.clear();
        assert!(check_usable(&bsp).is_err());
        assert!(check_usable_for(&bsp, TreeUse::IfPresent).is_ok());
        bsp.marksurfaces.push(7);
        assert!(check_usable_for(&bsp, TreeUse::IfPresent).is_err());
    }

    #[test]
    fn shared_subtrees_and_deep_chains_are_refused() {
        let mut bsp = one_split();
        chain(&mut bsp, MAX_TREE_DEPTH);
        assert!(check_usable(&bsp).is_ok(), "{:?}", check_usable(&bsp));
        chain(&mut bsp, MAX_TREE_DEPTH + 1);
        let message = check_usable(&bsp).expect_err("too deep").to_string();
        assert!(message.contains("deeper than 4096"), "{message}");
        // Node 1 reached from both sides of node 0, node 2 from both sides of node 1.
        chain(&mut bsp, 3);
        bsp.nodes[0].children = [1, 1];
        let message = check_usable(&bsp).expect_err("shared").to_string();
        assert!(message.contains("reached twice"), "{message}");
        // A brush model whose head is a node of the world's tree is walked once.
        chain(&mut bsp, 3);
        bsp.models.push(Model {
            head_nodes: [2, -1, -1, -1],
            ..bsp.models[0]
        });
        assert!(check_usable(&bsp).is_ok(), "{:?}", check_usable(&bsp));
    }
}
