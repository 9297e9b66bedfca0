//! Clip hulls: brushes grown by a monster's box (with bevel planes so the growth is exact), built
//! into their own trees and written as clip nodes.

use crate::brush::{Brush, BrushPlane};
use crate::planes::PlaneSet;
use crate::tree::Tree;
use quake_formats::bsp::{ClipNode, contents};
use quake_formats::geom::{ON_EPSILON, Plane, Vec3};

/// The boxes of hull 1 (player) and hull 2 (shambler), as engines define them.
pub const HULL_BOXES: [(Vec3, Vec3); 2] = [
    (Vec3::new(-16.0, -16.0, -24.0), Vec3::new(16.0, 16.0, 32.0)),
    (Vec3::new(-32.0, -32.0, -24.0), Vec3::new(32.0, 32.0, 64.0)),
];

fn push_unique(list: &mut Vec<Plane>, p: Plane) {
    if !list.iter().any(|q| q.same_as(&p)) {
        list.push(p);
    }
}

/// `brush` grown so that a point outside it is a box (`mins`..`maxs` around the point) clear
/// of the original brush. Solid, untextured.
pub fn expand_brush(brush: &Brush, planes: &mut PlaneSet, mins: Vec3, maxs: Vec3) -> Option<Brush> {
    let mut list: Vec<Plane> = brush
        .sides
        .iter()
        .map(|s| brush.outward(s, planes))
        .collect();
    // Axial bevels: the brush's bounding box.
    for axis in 0..3 {
        let mut n = Vec3::ZERO;
        n[axis] = 1.0;
        push_unique(&mut list, Plane::new(n, brush.bounds.maxs[axis]));
        push_unique(&mut list, Plane::new(-n, -brush.bounds.mins[axis]));
    }
    // Edge bevels: planes through each edge and an axis that have the whole brush behind them.
    let points: Vec<Vec3> = brush
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
                let mut a = Vec3::ZERO;
                a[axis] = 1.0;
                let Some(n) = dir.cross(a).normalized() else {
                    continue;
                };
                for n in [n, -n] {
                    let plane = Plane::new(n, n.dot(p)).snapped();
                    if points.iter().all(|&v| plane.distance(v) <= ON_EPSILON) {
                        push_unique(&mut list, plane);
                    }
                }
            }
        }
    }
    let grown: Vec<BrushPlane> = list
        .iter()
        .map(|p| {
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
            BrushPlane {
                plane: Plane::new(n, p.dist + push),
                texinfo: None,
            }
        })
        .collect();
    Brush::from_planes(&grown, planes, contents::SOLID, brush.source).ok()
}

/// Append the clip nodes of `tree` to `out`; returns the head (a clip node index, or contents
/// when the whole hull is one leaf). Nodes whose children are the same contents collapse.
pub fn emit_clipnodes(
    tree: &Tree,
    plane_index: &mut dyn FnMut(u32) -> u32,
    out: &mut Vec<ClipNode>,
) -> i32 {
    fn walk(
        tree: &Tree,
        node: u32,
        plane_index: &mut dyn FnMut(u32) -> u32,
        out: &mut Vec<ClipNode>,
    ) -> i32 {
        let n = &tree.nodes[node as usize];
        let Some(plane) = n.plane else {
            return if n.contents == contents::SOLID {
                contents::SOLID
            } else {
                contents::EMPTY
            };
        };
        let front = walk(tree, n.children[0], plane_index, out);
        let back = walk(tree, n.children[1], plane_index, out);
        if front == back && front < 0 {
            return front;
        }
        out.push(ClipNode {
            plane: plane_index(plane),
            children: [front, back],
        });
        (out.len() - 1) as i32
    }
    walk(tree, 0, plane_index, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::tests::{box_planes, solid_cube};

    #[test]
    fn box_grows_by_the_hull_size() {
        let mut planes = PlaneSet::new();
        let b = solid_cube(&mut planes);
        let (mins, maxs) = HULL_BOXES[0];
        let g = expand_brush(&b, &mut planes, mins, maxs).expect("grown");
        assert_eq!(g.bounds.mins, Vec3::new(-16.0, -16.0, -32.0));
        assert_eq!(g.bounds.maxs, Vec3::new(80.0, 80.0, 88.0));
        assert_eq!(g.sides.len(), 6);
    }

    #[test]
    fn wedge_gets_bevels() {
        let mut planes = PlaneSet::new();
        let mut faces = box_planes(Vec3::ZERO, Vec3::new(64.0, 64.0, 64.0));
        // Cut the top-front edge with a 45 degree slope.
        let n = Vec3::new(1.0, 0.0, 1.0).normalized().expect("n");
        faces.push(BrushPlane {
            plane: Plane::new(n, n.dot(Vec3::new(64.0, 0.0, 32.0))),
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
        let expected = n.dot(Vec3::new(64.0, 0.0, 32.0)) + (16.0 + 24.0) / 2f64.sqrt();
        assert!((slope.dist - expected).abs() < 1e-6);
    }
}
