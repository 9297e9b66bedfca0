//! DarkPlaces' portals from the world's tree (`model_brush.c` `Mod_Q1BSP_MakePortals`), built at
//! load: going down from the head, each node's plane gets a huge quad, clipped by the portals
//! that bound the node's region so far; what is left becomes the portal between its children,
//! and the region's portals are split between the children. When nothing is left, the node's
//! plane does not cross its region and DarkPlaces warns "new portal was clipped away". This
//! replays that procedure in its own precision: `f32` planes, `f64` points, a 1/32 unit epsilon,
//! its list order and its quirks (a clipped-away portal still clips the children's quads but is
//! not handed further down).

use super::{Checker, Rule};
use crate::bsp::Bsp;

/// DarkPlaces' `PORTAL_DIST_EPSILON`: points this close to a plane are on it.
pub const DARKPLACES_PORTAL_EPSILON: f64 = 1.0 / 32.0;
/// Half the side of the quad each node's portal starts from.
const QUAD_SIZE: f64 = 1024.0 * 1024.0 * 1024.0;
/// DarkPlaces' `MAX_PORTALPOINTS`: a node portal with this many points is dropped too.
const MAX_POINTS: usize = 64;
/// Portal clips and splits the replay may spend per node of the world's tree before it gives up
/// and reports what it found so far. Real maps spend about 30 per node (LibreQuake's lq1m1 and
/// e1m3 30, start 22); a file built so every portal bounds every deeper node (a chain of nodes on
/// one plane) costs time and memory quadratic in its depth, in DarkPlaces as here.
const WORK_PER_NODE: usize = 256;
/// Work the replay may always spend, whatever the node count.
const WORK_MIN: usize = 1 << 16;
/// The most portals one node's region may have before the replay gives up: real maps reach 228
/// (e1m3; lq1m1 184), the chain above one more per level.
const MAX_BOUNDING: usize = 1024;

type Point = [f64; 3];

/// A plane as DarkPlaces holds it: the file's `f32` values, used in `f64` arithmetic.
#[derive(Clone, Copy)]
struct PlaneD {
    normal: Point,
    dist: f64,
}

impl PlaneD {
    fn flipped(self) -> PlaneD {
        PlaneD {
            normal: self.normal.map(|v| -v),
            dist: -self.dist,
        }
    }

    fn divide(self, points: &[Point]) -> (Vec<Point>, Vec<Point>) {
        darkplaces_divide(points, self.normal, self.dist, DARKPLACES_PORTAL_EPSILON)
    }
}

/// One side of a portal: a node of the tree, or a leaf (leaves are never clipped further, so
/// their portal lists are not kept).
#[derive(Clone, Copy, PartialEq)]
enum Region {
    Node(usize),
    Leaf,
}

struct Portal {
    plane: PlaneD,
    points: Vec<Point>,
    /// Front and back region of `plane`.
    sides: [Region; 2],
}

/// Nodes of the world's tree whose plane DarkPlaces finds outside their region, in the order it
/// warns. Stops quietly at trees it cannot walk (bad indices, shared nodes, cycles: other rules
/// report those).
pub(super) fn clipped_away_nodes(bsp: &Bsp) -> Vec<usize> {
    let Some(head) = bsp
        .models
        .first()
        .and_then(|m| usize::try_from(m.head_nodes[0]).ok())
    else {
        return Vec::new();
    };
    let mut walk = Portalizer {
        bsp,
        portals: Vec::new(),
        lists: vec![Vec::new(); bsp.nodes.len()],
        visited: vec![false; bsp.nodes.len()],
        clipped_away: Vec::new(),
        work_left: WORK_MIN + WORK_PER_NODE * bsp.nodes.len(),
    };
    let mut stack = vec![head];
    while let Some(node) = stack.pop() {
        let Some(children) = walk.cut(node) else {
            break;
        };
        // Front first, as DarkPlaces recurses.
        stack.extend(children.into_iter().rev().filter_map(|c| match c {
            Region::Node(n) => Some(n),
            Region::Leaf => None,
        }));
    }
    walk.clipped_away
}

fn child_region(bsp: &Bsp, child: i32) -> Option<Region> {
    match usize::try_from(child) {
        Ok(n) if n < bsp.nodes.len() => Some(Region::Node(n)),
        Ok(_) => None,
        Err(_) => Some(Region::Leaf),
    }
}

struct Portalizer<'a> {
    bsp: &'a Bsp,
    portals: Vec<Portal>,
    /// Per node, the portals bounding its region; the last is the head of DarkPlaces' list.
    lists: Vec<Vec<usize>>,
    visited: Vec<bool>,
    clipped_away: Vec<usize>,
    /// What is left of the replay's budget (see [`WORK_PER_NODE`]).
    work_left: usize,
}

impl Portalizer<'_> {
    /// Makes `node`'s portal and hands its region's portals to its children, which it returns
    /// (front, back); `None` where the tree cannot be walked.
    fn cut(&mut self, node: usize) -> Option<[Region; 2]> {
        let n = self.bsp.nodes.get(node)?;
        if std::mem::replace(self.visited.get_mut(node)?, true) {
            return None;
        }
        let p = self.bsp.planes.get(usize::try_from(n.plane).ok()?)?;
        let plane = PlaneD {
            normal: p.normal.map(f64::from),
            dist: f64::from(p.dist),
        };
        let children = [
            child_region(self.bsp, n.children[0])?,
            child_region(self.bsp, n.children[1])?,
        ];
        if n.children[0] == n.children[1] {
            return None; // DarkPlaces stops: `node-same-children`
        }
        let bounding: Vec<usize> = std::mem::take(&mut self.lists[node])
            .into_iter()
            .rev()
            .collect();
        if bounding.len() > MAX_BOUNDING {
            return None;
        }
        // Each bounding portal is clipped against once and split once.
        self.work_left = self.work_left.checked_sub(1 + 2 * bounding.len())?;
        let points = self.node_portal(node, plane, &bounding);
        self.add(Portal {
            plane,
            points,
            sides: children,
        });
        for &id in &bounding {
            self.split(node, id, plane, children);
        }
        Some(children)
    }

    /// The node plane's quad clipped by the planes of the portals bounding its region (facing
    /// into it); empty when clipped away or past the point limit.
    fn node_portal(&mut self, node: usize, plane: PlaneD, bounding: &[usize]) -> Vec<Point> {
        let mut points = quad_for_plane(plane);
        for &id in bounding {
            let portal = &self.portals[id];
            let inward = if portal.sides[0] == Region::Node(node) {
                portal.plane
            } else {
                portal.plane.flipped()
            };
            points = inward.divide(&points).0;
            if points.is_empty() || points.len() >= MAX_POINTS {
                break;
            }
        }
        if points.len() < 3 {
            self.clipped_away.push(node);
            points.clear();
        } else if points.len() >= MAX_POINTS {
            points.clear();
        }
        points
    }

    /// Links a new portal into the lists of the nodes on its sides.
    fn add(&mut self, portal: Portal) {
        let id = self.portals.len();
        for side in portal.sides {
            if let Region::Node(n) = side {
                self.lists[n].push(id);
            }
        }
        self.portals.push(portal);
    }

    /// Hands one portal of `node`'s region to the child (or children, split) it lies in.
    /// Portals with no points stay behind, as in DarkPlaces.
    fn split(&mut self, node: usize, id: usize, plane: PlaneD, children: [Region; 2]) {
        if self.portals[id].points.is_empty() {
            return;
        }
        let side = usize::from(self.portals[id].sides[0] != Region::Node(node));
        let other = self.portals[id].sides[1 - side];
        if let Region::Node(o) = other
            && let Some(at) = self.lists[o].iter().rposition(|&p| p == id)
        {
            self.lists[o].remove(at);
        }
        let (front, back) = plane.divide(&self.portals[id].points);
        let with = |child: Region| {
            let mut sides = [other; 2];
            sides[side] = child;
            sides
        };
        let original = &mut self.portals[id];
        let moved_whole = if front.is_empty() {
            Some(children[1])
        } else if back.is_empty() {
            Some(children[0])
        } else {
            None
        };
        if let Some(child) = moved_whole {
            original.sides = with(child);
            self.relink(id);
            return;
        }
        let split_plane = original.plane;
        original.points = front;
        original.sides = with(children[0]);
        self.relink(id);
        self.add(Portal {
            plane: split_plane,
            points: back,
            sides: with(children[1]),
        });
    }

    fn relink(&mut self, id: usize) {
        for side in self.portals[id].sides {
            if let Region::Node(n) = side {
                self.lists[n].push(id);
            }
        }
    }
}

/// DarkPlaces' `PolygonD_QuadForPlane`, operation for operation.
fn quad_for_plane(plane: PlaneD) -> Vec<Point> {
    let [nx, ny, nz] = plane.normal;
    let mut up = if nz.abs() > nx.abs() && nz.abs() > ny.abs() {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let d = -(up[0] * nx + up[1] * ny + up[2] * nz);
    up = [up[0] + d * nx, up[1] + d * ny, up[2] + d * nz];
    let scale = 1.0 / (up[0] * up[0] + up[1] * up[1] + up[2] * up[2]).sqrt();
    up = up.map(|v| v * scale);
    let right = [
        up[1] * nz - up[2] * ny,
        up[2] * nx - up[0] * nz,
        up[0] * ny - up[1] * nx,
    ];
    let corner = |r: f64, u: f64| -> Point {
        std::array::from_fn(|i| {
            plane.dist * plane.normal[i] + r * QUAD_SIZE * right[i] + u * QUAD_SIZE * up[i]
        })
    };
    vec![
        corner(-1.0, 1.0),
        corner(1.0, 1.0),
        corner(1.0, -1.0),
        corner(-1.0, -1.0),
    ]
}

/// DarkPlaces' polygon split (`PolygonD_Divide`, operation for operation): the part of a convex
/// polygon on or in front of the plane `normal`·p = `dist`, and the part on or behind it. Points
/// within `epsilon` of the plane go to both parts and edges are cut only where they run from
/// beyond `epsilon` on one side to beyond it on the other, so a polygon reaching less than
/// `epsilon` past the plane keeps just its points near the plane there (and a polygon lying on
/// the plane goes whole to both sides).
pub fn darkplaces_divide(
    points: &[[f64; 3]],
    normal: [f64; 3],
    dist: f64,
    epsilon: f64,
) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let distance = |p: &Point| p[0] * normal[0] + p[1] * normal[1] + p[2] * normal[2] - dist;
    let mut front = Vec::with_capacity(points.len() + 1);
    let mut back = Vec::with_capacity(points.len() + 1);
    for (i, p) in points.iter().enumerate() {
        let n = &points[(i + 1) % points.len()];
        let pdist = distance(p);
        let ndist = distance(n);
        if pdist >= -epsilon {
            front.push(*p);
        }
        if pdist <= epsilon {
            back.push(*p);
        }
        if (pdist > epsilon && ndist < -epsilon) || (pdist < -epsilon && ndist > epsilon) {
            let frac = pdist / (pdist - ndist);
            let mid = std::array::from_fn(|k| p[k] + frac * (n[k] - p[k]));
            front.push(mid);
            back.push(mid);
        }
    }
    (front, back)
}

pub(super) fn check(c: &mut Checker) {
    for node in clipped_away_nodes(c.bsp) {
        let n = &c.bsp.nodes[node];
        let detail = format!(
            "plane {} does not cross the node's region (node box {:?} to {:?}): its children get \
             no portal between them",
            n.plane, n.mins, n.maxs
        );
        c.report(Rule::NodePlaneOutsideRegion, "nodes", node, detail);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsp::{BspPlane as Plane, BspVersion, Leaf, Model, Node, contents};

    fn plane(normal: [f32; 3], dist: f32) -> Plane {
        Plane {
            normal,
            dist,
            kind: 0,
        }
    }

    fn node(plane: u32, children: [i32; 2]) -> Node {
        Node {
            plane,
            children,
            mins: [0.0; 3],
            maxs: [0.0; 3],
            first_face: 0,
            num_faces: 0,
        }
    }

    /// A world whose head node splits at x = 0 and whose front child splits again at
    /// x = `second`, every child a leaf.
    fn two_splits(second: f32) -> Bsp {
        let mut bsp = Bsp::new(BspVersion::Bsp29);
        bsp.planes = vec![plane([1.0, 0.0, 0.0], 0.0), plane([1.0, 0.0, 0.0], second)];
        bsp.nodes = vec![node(0, [1, -2]), node(1, [-3, -4])];
        let empty = Leaf {
            contents: contents::EMPTY,
            ..Leaf::SHARED_SOLID
        };
        bsp.leafs = vec![Leaf::SHARED_SOLID, empty, empty, empty];
        bsp.models = vec![Model {
            mins: [-64.0; 3],
            maxs: [64.0; 3],
            origin: [0.0; 3],
            head_nodes: [0, -1, -1, -1],
            vis_leafs: 3,
            first_face: 0,
            num_faces: 0,
        }];
        bsp
    }

    #[test]
    fn a_plane_inside_its_region_keeps_its_portal() {
        assert_eq!(clipped_away_nodes(&two_splits(32.0)), Vec::<usize>::new());
        // Within DarkPlaces' epsilon of the region's boundary still counts as inside.
        assert_eq!(clipped_away_nodes(&two_splits(-0.02)), Vec::<usize>::new());
    }

    #[test]
    fn a_plane_behind_its_region_is_clipped_away() {
        assert_eq!(clipped_away_nodes(&two_splits(-16.0)), vec![1]);
    }

    #[test]
    fn a_polygon_reaching_less_than_the_epsilon_past_a_plane_keeps_only_its_near_points() {
        // A triangle whose corner at x = 0.02 pokes past x = 0; the plane is not cut there.
        let triangle = [[-10.0, 0.0, 0.0], [0.02, 5.0, 0.0], [-10.0, 10.0, 0.0]];
        let (front, back) = darkplaces_divide(&triangle, [1.0, 0.0, 0.0], 0.0, 1.0 / 32.0);
        assert_eq!(front, vec![[0.02, 5.0, 0.0]]);
        assert_eq!(back.len(), 3);
        // Past the epsilon it is cut where the edges cross.
        let triangle = [[-10.0, 0.0, 0.0], [10.0, 5.0, 0.0], [-10.0, 10.0, 0.0]];
        let (front, _) = darkplaces_divide(&triangle, [1.0, 0.0, 0.0], 0.0, 1.0 / 32.0);
        assert_eq!(front.len(), 3);
    }

    #[test]
    fn a_deep_chain_on_one_plane_is_given_up_in_bounded_work() {
        // Every node's portal lies on the one plane, so each bounds every deeper node.
        let mut bsp = two_splits(0.0);
        let depth: i32 = 100_000;
        bsp.planes[1] = bsp.planes[0];
        bsp.nodes = (0..depth)
            .map(|i| node(0, [if i + 1 < depth { i + 1 } else { -2 }, -3]))
            .collect();
        let start = std::time::Instant::now();
        clipped_away_nodes(&bsp);
        let seconds = start.elapsed().as_secs_f64();
        assert!(seconds < 5.0, "{seconds} s");
    }

    #[test]
    fn walks_stop_where_the_tree_breaks() {
        let mut bsp = two_splits(-16.0);
        // A cycle: the walk ends where it comes back.
        bsp.nodes[1].children = [1, -4];
        assert_eq!(clipped_away_nodes(&bsp), vec![1]);
        bsp.nodes[1].plane = 7;
        assert_eq!(clipped_away_nodes(&bsp), Vec::<usize>::new());
    }
}
