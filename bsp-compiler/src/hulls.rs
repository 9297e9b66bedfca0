//! Clip hulls: brushes grown by a monster's box (with bevel planes so the growth is exact), built
//! into their own trees and written as clip nodes.

use crate::brush::{Brush, BrushPlane};
use crate::planes::PlaneSet;
use crate::tree::Tree;
use glam::DVec3;
use quake_formats::bsp::{ClipNode, contents};
use quake_formats::geom::DVec3Ext;
use quake_formats::geom::{ON_EPSILON, Plane};

/// The boxes of hull 1 (player) and hull 2 (shambler), as engines define them.
pub const HULL_BOXES: [(DVec3, DVec3); 2] = [
    (
        DVec3::new(-16.0, -16.0, -24.0),
        DVec3::new(16.0, 16.0, 32.0),
    ),
    (
        DVec3::new(-32.0, -32.0, -24.0),
        DVec3::new(32.0, 32.0, 64.0),
    ),
];

fn push_unique(list: &mut Vec<Plane>, p: Plane) {
    if !list.iter().any(|q| q.same_as(&p)) {
        list.push(p);
    }
}

/// The plane with normal `n` that touches `points` with all of them behind it. An edge bevel is
/// placed there rather than through its edge: a plane through an edge with the brush behind it
/// within [`ON_EPSILON`] may cut into the brush that little, and two such near bevels (through
/// two parallel edges of a nearly flat face) lie within the epsilon of each other and of the
/// face, where building the grown brush could let each of the three yield to another and the
/// grown brush lose its side (generated seed 1186: a hull brush open at the top).
pub fn supporting_plane(n: DVec3, points: &[DVec3]) -> Plane {
    let dist = points
        .iter()
        .map(|&v| n.dot(v))
        .fold(f64::NEG_INFINITY, f64::max);
    Plane::new(n, dist)
}

/// The outward planes of `brush` and its bevels, each once: the axial planes of its bounds, and
/// along each edge the planes parallel to an axis that touch the brush there. A box swept
/// against these planes pushed out by its extents stops where it stops against the brush itself
/// (without the bevels it would stop short of a ridge or corner, in the void beside it).
pub fn bevelled_planes(brush: &Brush, planes: &PlaneSet) -> Vec<Plane> {
    let mut list: Vec<Plane> = brush
        .sides
        .iter()
        .map(|s| brush.outward(s, planes))
        .collect();
    // Axial bevels: the brush's bounding box.
    for axis in 0..3 {
        let mut n = DVec3::ZERO;
        n[axis] = 1.0;
        push_unique(&mut list, Plane::new(n, brush.bounds.maxs[axis]));
        push_unique(&mut list, Plane::new(-n, -brush.bounds.mins[axis]));
    }
    // Edge bevels: planes along each edge and an axis that touch the brush at that edge (within
    // the epsilon), the whole brush behind them.
    let points: Vec<DVec3> = brush
        .sides
        .iter()
        .flat_map(|s| s.winding.points.iter().copied())
        .collect();
    for s in &brush.sides {
        let w = &s.winding.points;
        for i in 0..w.len() {
            let (p, q) = (w[i], w[(i + 1) % w.len()]);
            let Some(dir) = (q - p).normalized() else {
                continue;
            };
            for axis in 0..3 {
                let mut a = DVec3::ZERO;
                a[axis] = 1.0;
                let Some(n) = dir.cross(a).normalized() else {
                    continue;
                };
                // Along an axis, the bevel is a side of the bounding box, listed above (its
                // distance is the same extreme of the same points).
                if Plane::new(n, 0.0).axial().is_some() {
                    continue;
                }
                for n in [n, -n] {
                    let bevel = supporting_plane(n, &points);
                    if bevel.distance(p) >= -ON_EPSILON {
                        push_unique(&mut list, bevel);
                    }
                }
            }
        }
    }
    list
}

/// The planes of a brush whose [`bevelled_planes`] are `bevels`, grown by the box
/// `mins`..`maxs`: the brush they bound holds every point where that box, around the point,
/// would touch the brush. Each hull grows the same bevels by its own box.
pub fn grown_planes(bevels: &[Plane], mins: DVec3, maxs: DVec3) -> Vec<BrushPlane> {
    // Planes that differ before growing may be one plane after it (a face and a bevel a
    // millionth of a radian apart, each pushed out by its own support): keep the first, or
    // building the brush refuses the pair and the hull loses the whole brush.
    let mut grown: Vec<Plane> = Vec::with_capacity(bevels.len());
    for p in bevels {
        let n = p.normal;
        let push: f64 = (0..3)
            .map(|i| {
                if n[i] >= 0.0 {
                    -n[i] * mins[i]
                } else {
                    -n[i] * maxs[i]
                }
            })
            .sum();
        push_unique(&mut grown, Plane::new(n, p.dist + push));
    }
    grown
        .into_iter()
        .map(|plane| BrushPlane {
            plane,
            texinfo: None,
        })
        .collect()
}

/// Append the clip nodes of `tree` to `out` in pre-order (each node before its children, so
/// the head comes first and every node of the hull is numbered at or after it, which
/// QuakeSpasm-family engines require); returns the head (a clip node index, or contents when
/// the whole hull is one leaf). Nodes whose children are the same contents collapse.
pub fn emit_clipnodes(
    tree: &Tree,
    plane_index: &mut dyn FnMut(u32) -> u32,
    out: &mut Vec<ClipNode>,
) -> i32 {
    let collapsed = collapsed_contents(tree);
    let mut head = contents::EMPTY;
    // (tree node, where its clip node number goes: None for the head, else (clip node, side)).
    let mut stack = vec![(0u32, None::<(usize, usize)>)];
    while let Some((node, slot)) = stack.pop() {
        let value = match collapsed[node as usize] {
            Some(leaf_contents) => leaf_contents,
            None => {
                let n = &tree.nodes[node as usize];
                let plane = n.plane.expect("a node that does not collapse has a plane");
                let index = out.len();
                out.push(ClipNode {
                    plane: plane_index(plane),
                    children: [0, 0],
                });
                stack.push((n.children[1], Some((index, 1))));
                stack.push((n.children[0], Some((index, 0))));
                index as i32
            }
        };
        match slot {
            Some((parent, side)) => out[parent].children[side] = value,
            None => head = value,
        }
    }
    head
}

/// Per tree node, the one contents its whole subtree holds (solid or empty, as clip hulls
/// know them), or `None` when it needs a clip node.
fn collapsed_contents(tree: &Tree) -> Vec<Option<i32>> {
    let mut collapsed = vec![None; tree.nodes.len()];
    // Children are finished before their parent: visit in reverse of a pre-order walk.
    let mut order = Vec::with_capacity(tree.nodes.len());
    let mut stack = vec![0u32];
    while let Some(n) = stack.pop() {
        order.push(n);
        let node = &tree.nodes[n as usize];
        if node.plane.is_some() {
            stack.extend(node.children);
        }
    }
    for &n in order.iter().rev() {
        let node = &tree.nodes[n as usize];
        collapsed[n as usize] = match node.plane {
            None if node.contents == contents::SOLID => Some(contents::SOLID),
            None => Some(contents::EMPTY),
            Some(_) => {
                let [front, back] = node.children.map(|c| collapsed[c as usize]);
                if front == back { front } else { None }
            }
        };
    }
    collapsed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::tests::{box_planes, solid_cube};

    /// `brush` grown as the compile grows it for a hull with the box `mins`..`maxs`.
    fn expand_brush(
        brush: &Brush,
        planes: &mut PlaneSet,
        mins: DVec3,
        maxs: DVec3,
    ) -> Option<Brush> {
        let faces = grown_planes(&bevelled_planes(brush, planes), mins, maxs);
        Brush::from_planes(&faces, planes, contents::SOLID, brush.source).ok()
    }

    #[test]
    fn box_grows_by_the_hull_size() {
        let mut planes = PlaneSet::new();
        let b = solid_cube(&mut planes);
        let (mins, maxs) = HULL_BOXES[0];
        let g = expand_brush(&b, &mut planes, mins, maxs).expect("grown");
        assert_eq!(g.bounds.mins, DVec3::new(-16.0, -16.0, -32.0));
        assert_eq!(g.bounds.maxs, DVec3::new(80.0, 80.0, 88.0));
        assert_eq!(g.sides.len(), 6);
    }

    /// A solid brush from `.map` face points ("x y z"), its planes snapped as the map's are.
    fn block(faces: &[[&str; 3]], planes: &mut PlaneSet) -> Brush {
        let point = |s: &str| {
            let v: Vec<f64> = s.split(' ').map(|c| c.parse().expect("number")).collect();
            DVec3::new(v[0], v[1], v[2])
        };
        let faces: Vec<BrushPlane> = faces
            .iter()
            .map(|corners| {
                let [a, b, c] = corners.map(point);
                BrushPlane {
                    plane: Plane::from_points(a, b, c)
                        .expect("plane")
                        .snapped((a + b + c) / 3.0),
                    texinfo: Some(0),
                }
            })
            .collect();
        Brush::from_planes(&faces, planes, contents::SOLID, 0).expect("block")
    }

    #[test]
    fn a_bevel_that_grows_onto_a_face_keeps_the_brush() {
        // A rotated, tilted func_detail block (generated seed 1089): one of its faces is 5e-7 rad
        // off vertical; the edge bevel beside it is vertical and 0.001 units further out. They
        // are two planes until hull 2's box pushes them out, when they became one and building
        // the grown brush failed, so hull 2 lost the block.
        let mut planes = PlaneSet::new();
        let b = block(
            &[
                [
                    "-584.0554 643.0143 91.1444",
                    "-606.3677 670.0003 7.7137",
                    "-670.7218 616.7915 7.7137",
                ],
                [
                    "-687.9352 637.6105 7.7137",
                    "-623.5811 690.8193 7.7137",
                    "-601.2688 663.8333 91.1444",
                ],
                [
                    "-623.5811 690.8193 7.7137",
                    "-606.3677 670.0003 7.7137",
                    "-584.0554 643.0143 91.1444",
                ],
                [
                    "-648.4095 589.8055 91.1444",
                    "-670.7218 616.7915 7.7137",
                    "-687.9352 637.6105 7.7137",
                ],
                [
                    "-670.7218 616.7915 7.7137",
                    "-606.3677 670.0003 7.7137",
                    "-623.5811 690.8193 7.7137",
                ],
                [
                    "-601.2688 663.8333 91.1444",
                    "-584.0554 643.0143 91.1444",
                    "-648.4095 589.8055 91.1444",
                ],
            ],
            &mut planes,
        );
        for (mins, maxs) in HULL_BOXES {
            let g = expand_brush(&b, &mut planes, mins, maxs).expect("grown");
            assert!(g.volume() > b.volume());
        }
    }

    #[test]
    fn a_bevel_a_thousandth_of_a_radian_off_an_axis_stays_tilted() {
        // A sheared block (generated seed 1007) leaning 0.136 units along y over its 210.8 of
        // height: the bevel along its slanted edge is 6.5e-4 rad off the -y axis. Taken as
        // axial, it was snapped onto the block's axial bevel, and hull 1 stopped up to 0.165
        // units short of the block near its top.
        let mut planes = PlaneSet::new();
        let b = block(
            &[
                [
                    "171.303 194.2927 210.7974",
                    "183.606 194.1563 0",
                    "183.1036 148.8576 0",
                ],
                [
                    "140.5791 149.3292 0",
                    "141.0815 194.6279 0",
                    "128.7785 194.7644 210.7974",
                ],
                [
                    "141.0815 194.6279 0",
                    "183.606 194.1563 0",
                    "171.303 194.2927 210.7974",
                ],
                [
                    "170.8006 148.994 210.7974",
                    "183.1036 148.8576 0",
                    "140.5791 149.3292 0",
                ],
                [
                    "183.1036 148.8576 0",
                    "183.606 194.1563 0",
                    "141.0815 194.6279 0",
                ],
                [
                    "128.7785 194.7644 210.7974",
                    "171.303 194.2927 210.7974",
                    "170.8006 148.994 210.7974",
                ],
            ],
            &mut planes,
        );
        let lean = DVec3::new(0.0, -210.7974, 0.1364).normalized().expect("n");
        for (mins, maxs) in HULL_BOXES {
            let g = expand_brush(&b, &mut planes, mins, maxs).expect("grown");
            let bevel = g
                .sides
                .iter()
                .map(|s| g.outward(s, &planes))
                .find(|p| p.normal.near(lean, 1e-6))
                .expect("the tilted bevel");
            assert_eq!(bevel.quake_type(), 4);
        }
    }

    #[test]
    fn near_bevels_of_a_nearly_flat_top_leave_the_grown_brush_closed() {
        // A block tilted 6.7e-4 rad (generated seed 1186): the bevels along its top's two long
        // edges are parallel and were placed through their edges, the inner one 0.008 units into
        // the block. With the top, the three lay within ON_EPSILON of each other, and building
        // the grown brush let each give way to another: hull 1's brush had no top, and the hull
        // was solid from the block up to the ceiling.
        let mut planes = PlaneSet::new();
        let b = block(
            &[
                [
                    "85.7001 91.3594 0",
                    "85.6457 91.3826 87.8398",
                    "121.3319 76.1292 87.8659",
                ],
                [
                    "132.3914 102.0035 87.8659",
                    "96.7052 117.2569 87.8398",
                    "96.7596 117.2336 0",
                ],
                [
                    "96.7052 117.2569 87.8398",
                    "85.6457 91.3826 87.8398",
                    "85.7001 91.3594 0",
                ],
                [
                    "121.3862 76.1059 0.0261",
                    "121.3319 76.1292 87.8659",
                    "132.3914 102.0035 87.8659",
                ],
                [
                    "121.3319 76.1292 87.8659",
                    "85.6457 91.3826 87.8398",
                    "96.7052 117.2569 87.8398",
                ],
                [
                    "96.7596 117.2336 0",
                    "85.7001 91.3594 0",
                    "121.3862 76.1059 0.0261",
                ],
            ],
            &mut planes,
        );
        // Hull 2's brush of this block is still open at the bottom (its bottom face and a bevel
        // 3e-4 rad apart cross within the epsilon: the face is dropped, the bevel cut exactly),
        // by 1.5% of its area, where it stands on the floor.
        let (mins, maxs) = HULL_BOXES[0];
        let g = expand_brush(&b, &mut planes, mins, maxs).expect("grown");
        // A closed surface's area-weighted normals sum to zero (here within what sides kept
        // whole on a plane they lie on within the epsilon leave over, a few 1e-6 of the area;
        // the open brush was open by its top, 5% of it).
        let (mut sum, mut area) = (DVec3::ZERO, 0.0);
        for s in &g.sides {
            sum += g.outward(s, &planes).normal * s.winding.area();
            area += s.winding.area();
        }
        assert!(sum.length() < 1e-4 * area, "open by {sum:?} of {area}");
    }

    #[test]
    fn wedge_gets_bevels() {
        let mut planes = PlaneSet::new();
        let mut faces = box_planes(DVec3::ZERO, DVec3::new(64.0, 64.0, 64.0));
        // Cut the top-front edge with a 45 degree slope.
        let n = DVec3::new(1.0, 0.0, 1.0).normalized().expect("n");
        faces.push(BrushPlane {
            plane: Plane::new(n, n.dot(DVec3::new(64.0, 0.0, 32.0))),
            texinfo: Some(0),
        });
        let b = Brush::from_planes(&faces, &mut planes, contents::SOLID, 0).expect("wedge");
        let (mins, maxs) = HULL_BOXES[0];
        let g = expand_brush(&b, &mut planes, mins, maxs).expect("grown");
        // The slope moves out by the box's support along its normal: (16 + 24)/√2.
        let slope = g
            .sides
            .iter()
            .map(|s| g.outward(s, &planes))
            .find(|p| p.normal.near(n, 1e-9))
            .expect("slope");
        let expected = n.dot(DVec3::new(64.0, 0.0, 32.0)) + (16.0 + 24.0) / 2f64.sqrt();
        assert!((slope.dist - expected).abs() < 1e-6);
    }
}
