//! A brush model's solid as polygons, from its hull-0 tree in the BSP. A model whose brushes
//! are all `skip` has no faces, but its tree still holds its brushes: with `_shadow 1` it casts
//! their shadow, as ericw-tools' light makes shadow-casting faces of such a model.

use glam::DVec3;
use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::geom::{Plane, Winding};

/// Nodes walked down at most: a deeper tree (a damaged file) is cut there.
const MAX_DEPTH: usize = 256;

/// The boundary polygons of every solid leaf of `model`'s hull-0 tree, in model space (each
/// convex; which way it faces does not matter to a shadow).
pub fn solid_polygons(bsp: &Bsp, model: usize) -> Vec<Vec<DVec3>> {
    let Some(m) = bsp.models.get(model) else {
        return Vec::new();
    };
    // The model's box (a unit wider) closes leaves the tree leaves open on some side.
    let (lo, hi) = (
        DVec3::from(m.mins.map(f64::from)) - 1.0,
        DVec3::from(m.maxs.map(f64::from)) + 1.0,
    );
    let mut sides: Vec<Plane> = [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .flat_map(|axis| {
            [
                Plane::new(axis, axis.dot(lo)),
                Plane::new(-axis, -axis.dot(hi)),
            ]
        })
        .collect();
    let mut out = Vec::new();
    walk(bsp, m.head_nodes[0], &mut sides, &mut out, 0);
    out
}

/// Adds the polygons of the solid leaves under `node`, whose region is in front of `sides`.
fn walk(bsp: &Bsp, node: i32, sides: &mut Vec<Plane>, out: &mut Vec<Vec<DVec3>>, depth: usize) {
    if node < 0 {
        let leaf = (-(node + 1)) as usize;
        if bsp
            .leafs
            .get(leaf)
            .is_some_and(|l| l.contents == contents::SOLID)
        {
            out.extend(region_polygons(sides));
        }
        return;
    }
    let (Some(n), true) = (bsp.nodes.get(node as usize), depth < MAX_DEPTH) else {
        return;
    };
    let Some(p) = bsp.planes.get(n.plane as usize) else {
        return;
    };
    let plane = Plane::new(DVec3::from(p.normal.map(f64::from)), f64::from(p.dist));
    for (child, side) in [(n.children[0], plane), (n.children[1], plane.flipped())] {
        sides.push(side);
        walk(bsp, child, sides, out, depth + 1);
        sides.pop();
    }
}

/// The faces of the convex region in front of every plane of `sides`.
fn region_polygons(sides: &[Plane]) -> Vec<Vec<DVec3>> {
    sides
        .iter()
        .enumerate()
        .filter_map(|(i, side)| {
            let mut w = Winding::base_for_plane(side);
            for (j, other) in sides.iter().enumerate() {
                if j != i {
                    w = w.clip_front(other, true)?;
                }
            }
            (!w.is_tiny()).then_some(w.points)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_region_has_six_square_faces() {
        let sides: Vec<Plane> = [DVec3::X, DVec3::Y, DVec3::Z]
            .into_iter()
            .flat_map(|a| [Plane::new(a, 0.0), Plane::new(-a, -8.0)])
            .collect();
        let faces = region_polygons(&sides);
        assert_eq!(faces.len(), 6);
        for f in &faces {
            assert_eq!(f.len(), 4);
            assert!(
                f.iter()
                    .all(|p| p.min_element() >= -1e-6 && p.max_element() <= 8.0 + 1e-6)
            );
        }
    }
}
