//! Portals: the polygons where two leaves of a tree touch, found by cutting each node's plane
//! polygon by the portals already bounding the node and then splitting those by the node plane.
//! A box of six portals around the whole tree joins it to an "outside" leaf.

use crate::planes::{PlaneId, PlaneSet};
use crate::tree::{Tree, TreeNode};
use glam::DVec3;
use quake_formats::geom::{Bounds, Plane, Split, Winding};

/// Space left between a model's brushes and the outside box: ericw-tools' qbsp pads its trees
/// by 24 units, and the bounds written for the leaves and nodes along the box reach it (so a
/// model's head node spans its brushes grown by this much, as in the BSPs qbsp writes).
const OUTSIDE_MARGIN: f64 = 24.0;

#[derive(Debug, Clone, PartialEq)]
pub struct Portal {
    /// Faces `nodes[0]`.
    pub plane: Plane,
    /// The node whose plane the portal lies on (`None` for the outside box); its front child side
    /// is `nodes[0]`.
    pub on_node: Option<u32>,
    pub plane_id: Option<PlaneId>,
    pub winding: Winding,
    /// Tree node indices; `Portals::outside` is the outside leaf.
    pub nodes: [u32; 2],
}

#[derive(Debug, Clone, PartialEq)]
pub struct Portals {
    /// Live portals only (every portal separates two leaves).
    pub portals: Vec<Portal>,
    /// Portal indices touching each tree node (the leaves of the portalisation only), plus the
    /// outside leaf last.
    pub leaf_portals: Vec<Vec<u32>>,
    /// Index of the outside leaf (one past the tree's nodes).
    pub outside: u32,
}

impl Portals {
    /// The leaf on the other side of portal `p` from `leaf`.
    pub fn other(&self, p: u32, leaf: u32) -> u32 {
        let nodes = self.portals[p as usize].nodes;
        if nodes[0] == leaf { nodes[1] } else { nodes[0] }
    }

    /// The bounds of a leaf's region: the union of its portals.
    pub fn leaf_bounds(&self, leaf: u32) -> Bounds {
        let mut b = Bounds::EMPTY;
        for &p in &self.leaf_portals[leaf as usize] {
            b = b.union(&self.portals[p as usize].winding.bounds());
        }
        b
    }
}

/// Portalize `tree`, whose contents lie within `bounds`: portals between its leaves.
pub fn make_portals(tree: &Tree, planes: &PlaneSet, bounds: &Bounds) -> Portals {
    portalize(tree, planes, bounds, TreeNode::is_leaf, |_| true)
}

/// Portals between the structural leaves (vis clusters) of `tree`, ignoring the detail below.
pub fn make_cluster_portals(tree: &Tree, planes: &PlaneSet, bounds: &Bounds) -> Portals {
    portalize(
        tree,
        planes,
        bounds,
        |n| n.cluster.is_some() || n.is_leaf(),
        |_| true,
    )
}

/// The portals of a clip hull's `tree` that touch open space: those the outside fill floods
/// through and the hull's rebuilt tree is made from (`surface_tree`). A node with only solid
/// below it makes no portal of its own, whose parts could only part solid from solid; the
/// portals around it are still cut by its plane, so every portal with open space on a side
/// comes out as [`make_portals`] makes it, in the same order.
pub fn make_clip_hull_portals(tree: &Tree, planes: &PlaneSet, bounds: &Bounds) -> Portals {
    let solid = tree.all_solid();
    portalize(tree, planes, bounds, TreeNode::is_leaf, |node| {
        !solid[node as usize]
    })
}

/// Portals between the nodes where `stop` holds, as if they were leaves; only nodes where
/// `own_portal` holds make a portal on their plane.
fn portalize(
    tree: &Tree,
    planes: &PlaneSet,
    bounds: &Bounds,
    stop: impl Fn(&TreeNode) -> bool,
    own_portal: impl Fn(u32) -> bool,
) -> Portals {
    let outside = tree.nodes.len() as u32;
    let mut b = Builder {
        portals: Vec::new(),
        node_portals: vec![Vec::new(); tree.nodes.len() + 1],
    };
    let box_planes = b.outside_box(bounds, outside);
    // The half-spaces bounding each node: the outside box, then the planes above it.
    let mut bounding: Vec<Vec<Plane>> = vec![Vec::new(); tree.nodes.len()];
    bounding[0] = box_planes;
    let mut stack = vec![0u32];
    while let Some(node) = stack.pop() {
        let n = &tree.nodes[node as usize];
        // Taken before anything else: a leaf's list is dropped here, not kept for every leaf.
        let above = std::mem::take(&mut bounding[node as usize]);
        if stop(n) {
            continue;
        }
        let Some(plane_id) = n.plane else { continue };
        let plane = *planes.get(plane_id);
        // The nodes below one that makes no portal make none either: they need no planes.
        if own_portal(node) {
            b.make_node_portal(node, plane_id, &plane, n.children, &above);
            let mut front = above.clone();
            front.push(plane);
            let mut back = above;
            back.push(plane.flipped());
            bounding[n.children[0] as usize] = front;
            bounding[n.children[1] as usize] = back;
        }
        b.split_node_portals(node, &plane, n.children);
        stack.push(n.children[1]);
        stack.push(n.children[0]);
    }
    // Compact in place (a second list would hold every portal twice): drop dead portals and
    // renumber.
    let mut new_index = vec![u32::MAX; b.portals.len()];
    let mut live = 0;
    for (i, p) in b.portals.iter().enumerate() {
        if !p.winding.is_empty() {
            new_index[i] = live;
            live += 1;
        }
    }
    let mut portals = b.portals;
    portals.retain(|p| !p.winding.is_empty());
    let leaf_portals = b
        .node_portals
        .into_iter()
        .map(|list| {
            list.into_iter()
                .map(|p| new_index[p as usize])
                .filter(|&p| p != u32::MAX)
                .collect()
        })
        .collect();
    Portals {
        portals,
        leaf_portals,
        outside,
    }
}

struct Builder {
    portals: Vec<Portal>,
    node_portals: Vec<Vec<u32>>,
}

impl Builder {
    fn add(&mut self, portal: Portal) {
        let id = self.portals.len() as u32;
        self.node_portals[portal.nodes[0] as usize].push(id);
        self.node_portals[portal.nodes[1] as usize].push(id);
        self.portals.push(portal);
    }

    /// The six portals to the outside leaf; returns their (inward-facing) planes.
    fn outside_box(&mut self, bounds: &Bounds, outside: u32) -> Vec<Plane> {
        let mins = bounds.mins - DVec3::new(OUTSIDE_MARGIN, OUTSIDE_MARGIN, OUTSIDE_MARGIN);
        let maxs = bounds.maxs + DVec3::new(OUTSIDE_MARGIN, OUTSIDE_MARGIN, OUTSIDE_MARGIN);
        let mut box_planes = Vec::new();
        for axis in 0..3 {
            let mut n = DVec3::ZERO;
            n[axis] = 1.0;
            // Facing inwards, so the tree (node 0) is in front.
            box_planes.push(Plane::new(n, mins[axis]));
            box_planes.push(Plane::new(-n, -maxs[axis]));
        }
        for (i, plane) in box_planes.iter().enumerate() {
            let others = box_planes.iter().enumerate().filter(|&(j, _)| j != i);
            let w = Winding::base_for_plane(plane).into_front_of_all(others.map(|(_, p)| *p));
            if let Some(w) = w {
                self.add(Portal {
                    plane: *plane,
                    on_node: None,
                    plane_id: None,
                    winding: w,
                    nodes: [0, outside],
                });
            }
        }
        box_planes
    }

    fn make_node_portal(
        &mut self,
        node: u32,
        plane_id: PlaneId,
        plane: &Plane,
        children: [u32; 2],
        above: &[Plane],
    ) {
        let portals = self.node_portals[node as usize].iter().map(|&pid| {
            let p = &self.portals[pid as usize];
            if p.nodes[0] == node {
                p.plane
            } else {
                p.plane.flipped()
            }
        });
        let w =
            Winding::base_for_plane(plane).into_front_of_all(above.iter().copied().chain(portals));
        if let Some(w) = w.filter(|w| !w.is_tiny()) {
            self.add(Portal {
                plane: *plane,
                on_node: Some(node),
                plane_id: Some(plane_id),
                winding: w,
                nodes: children,
            });
        }
    }

    fn split_node_portals(&mut self, node: u32, plane: &Plane, children: [u32; 2]) {
        let list = std::mem::take(&mut self.node_portals[node as usize]);
        for pid in list {
            let p = &mut self.portals[pid as usize];
            let side = usize::from(p.nodes[0] != node);
            let other = p.nodes[1 - side];
            // The winding is replaced by its parts (or left empty), so it moves into the split.
            let split = std::mem::take(&mut p.winding).into_split(plane);
            let old = Portal {
                winding: Winding::default(),
                ..*p
            };
            self.node_portals[other as usize].retain(|&x| x != pid);
            let (front, back) = match split {
                Split::Front(w) => (Some(w), None),
                Split::Back(w) => (None, Some(w)),
                Split::Both { front, back } => (
                    Some(front).filter(|w| !w.is_tiny()),
                    Some(back).filter(|w| !w.is_tiny()),
                ),
                Split::On { .. } => (None, None),
            };
            let place = |this: &mut Builder, winding: Winding, child: u32, reuse: bool| {
                let mut portal = Portal { winding, ..old };
                portal.nodes[side] = child;
                if reuse {
                    this.portals[pid as usize] = portal;
                    this.node_portals[child as usize].push(pid);
                    this.node_portals[other as usize].push(pid);
                } else {
                    this.add(portal);
                }
            };
            match (front, back) {
                (None, None) => {}
                (Some(f), None) => place(self, f, children[0], true),
                (None, Some(b)) => place(self, b, children[1], true),
                (Some(f), Some(b)) => {
                    place(self, f, children[0], true);
                    place(self, b, children[1], false);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::Brush;
    use crate::brush::tests::{box_planes, solid_cube};
    use crate::tree::{SplitHeuristic, build_tree};
    use quake_formats::bsp::contents;

    /// Solid brushes of the boxes `(mins, maxs)`, and the bounds of them all.
    fn solid_boxes(boxes: &[(DVec3, DVec3)], planes: &mut PlaneSet) -> (Vec<Brush>, Bounds) {
        let brushes: Vec<Brush> = boxes
            .iter()
            .enumerate()
            .map(|(i, &(lo, hi))| {
                Brush::from_planes(&box_planes(lo, hi), planes, contents::SOLID, i as u32)
                    .expect("brush")
            })
            .collect();
        let bounds = brushes
            .iter()
            .fold(Bounds::EMPTY, |acc, b| acc.union(&b.bounds));
        (brushes, bounds)
    }

    #[test]
    fn portals_of_a_single_box_close_every_leaf() {
        let mut planes = PlaneSet::new();
        let b = solid_cube(&mut planes);
        let bounds = b.bounds;
        let tree = build_tree(vec![b], &planes, SplitHeuristic::FewestSplits, true);
        let portals = make_portals(&tree, &planes, &bounds);
        // The solid leaf is enclosed by six portals, each a 64x64 square.
        let solid = tree
            .nodes
            .iter()
            .position(|n| n.is_leaf() && n.contents == contents::SOLID)
            .expect("solid leaf") as u32;
        let around = &portals.leaf_portals[solid as usize];
        assert_eq!(around.len(), 6);
        let area: f64 = around
            .iter()
            .map(|&p| portals.portals[p as usize].winding.area())
            .sum();
        assert!((area - 6.0 * 64.0 * 64.0).abs() < 1e-6, "{area}");
        assert_eq!(
            portals.leaf_bounds(solid).maxs,
            DVec3::new(64.0, 64.0, 64.0)
        );
        // Every portal's plane faces its first node.
        for p in &portals.portals {
            let own = p.winding.plane().expect("plane");
            assert!(own.normal.dot(p.plane.normal) > 0.99);
        }
    }

    /// Regression: a node's portal used to be cut only by the portals around the node, not by
    /// the node planes above it, so it could reach past the node's region.
    #[test]
    fn portals_stay_within_their_nodes_regions() {
        let mut planes = PlaneSet::new();
        let boxes = [
            (DVec3::new(0.0, 0.0, 0.0), DVec3::new(64.0, 64.0, 16.0)),
            (DVec3::new(96.0, -32.0, 0.0), DVec3::new(128.0, 96.0, 128.0)),
            (
                DVec3::new(-64.0, 80.0, 32.0),
                DVec3::new(200.0, 112.0, 48.0),
            ),
            (DVec3::new(16.0, 16.0, 64.0), DVec3::new(48.0, 48.0, 200.0)),
        ];
        let (brushes, bounds) = solid_boxes(&boxes, &mut planes);
        let tree = build_tree(brushes, &planes, SplitHeuristic::FewestSplits, true);
        let portals = make_portals(&tree, &planes, &bounds);
        // The half-spaces above each node.
        let mut above: Vec<Vec<Plane>> = vec![Vec::new(); tree.nodes.len()];
        for (i, n) in tree.nodes.iter().enumerate() {
            if let Some(id) = n.plane {
                let p = *planes.get(id);
                for (child, side) in n.children.into_iter().zip([p, p.flipped()]) {
                    let mut list = above[i].clone();
                    list.push(side);
                    above[child as usize] = list;
                }
            }
        }
        for p in &portals.portals {
            let Some(node) = p.on_node else { continue };
            for half in &above[node as usize] {
                for &v in &p.winding.points {
                    assert!(half.distance(v) > -0.1, "{v:?} is outside node {node}");
                }
            }
        }
    }

    /// Overlapping solid boxes (no CSG: their sides inside each other split the tree, as a clip
    /// hull's grown brushes do) make solid subtrees with portals of their own; a clip hull's
    /// portals leave those out and keep every portal touching open space as it is, in order.
    #[test]
    fn clip_hull_portals_are_the_portals_that_touch_open_space() {
        let mut planes = PlaneSet::new();
        let boxes = [
            (DVec3::new(0.0, 0.0, 0.0), DVec3::new(100.0, 100.0, 100.0)),
            (DVec3::new(50.0, 0.0, 0.0), DVec3::new(150.0, 100.0, 100.0)),
            (DVec3::new(0.0, 0.0, 120.0), DVec3::new(40.0, 30.0, 160.0)),
        ];
        let (brushes, bounds) = solid_boxes(&boxes, &mut planes);
        let tree = build_tree(brushes, &planes, SplitHeuristic::FewestSplits, false);
        let all = make_portals(&tree, &planes, &bounds);
        let hull = make_clip_hull_portals(&tree, &planes, &bounds);
        let solid = |n: u32| n != all.outside && tree.nodes[n as usize].contents == contents::SOLID;
        let open = |portals: &Portals| -> Vec<Portal> {
            let touches_open = |p: &&Portal| !p.nodes.iter().all(|&n| solid(n));
            portals
                .portals
                .iter()
                .filter(touches_open)
                .cloned()
                .collect()
        };
        assert!(
            hull.portals.len() < all.portals.len(),
            "no solid subtree left out"
        );
        assert_eq!(open(&hull), open(&all));
    }
}
