//! The filled leaves of a model's hull 0 tree, each as the convex region the planes on its path
//! bound inside the model's box.

use crate::region::{Region, SideSource};
use glam::DVec3;
use quake_formats::Bsp;
use quake_formats::bsp::{Model, contents};
use quake_formats::geom::{Bounds, Plane};

/// A leaf of the tree that holds something (solid, liquid, sky), as a region.
#[derive(Debug, Clone)]
pub(crate) struct FilledLeaf {
    /// The leaf's contents value (`contents::SOLID`, `WATER`, ...).
    pub contents: i32,
    pub region: Region,
}

/// What walking one model's tree found.
#[derive(Debug, Default)]
pub(crate) struct ModelLeaves {
    pub filled: Vec<FilledLeaf>,
    /// Leaves of a contents value this decompiler does not write (neither empty, solid, sky
    /// nor a liquid).
    pub unknown_contents: usize,
}

/// Whether leaves of `value` become brushes.
pub(crate) fn is_filled(value: i32) -> bool {
    matches!(
        value,
        contents::SOLID | contents::WATER | contents::SLIME | contents::LAVA | contents::SKY
    )
}

/// The model's box: its own bounds and its head node's (the two may differ by the rounding of a
/// BSP29 node's 16-bit bounds), in the model's own coordinates.
fn model_box(bsp: &Bsp, model: &Model) -> Bounds {
    let mut b = Bounds::EMPTY;
    let mut add = |mins: [f32; 3], maxs: [f32; 3]| {
        let (lo, hi) = (
            DVec3::from(mins.map(f64::from)),
            DVec3::from(maxs.map(f64::from)),
        );
        if lo.is_finite() && hi.is_finite() && lo.cmple(hi).all() {
            b.add_point(lo);
            b.add_point(hi);
        }
    };
    add(model.mins, model.maxs);
    if let Some(node) = usize::try_from(model.head_nodes[0])
        .ok()
        .and_then(|i| bsp.nodes.get(i))
    {
        add(node.mins, node.maxs);
    }
    b
}

/// A BSP plane as a unit-normal geometry plane (stored normals are `f32`, a few ulps off unit).
pub(crate) fn bsp_plane(bsp: &Bsp, index: u32) -> Option<Plane> {
    let p = bsp.planes.get(index as usize)?;
    let normal = DVec3::from(p.normal.map(f64::from));
    let len = normal.length();
    (len > 0.5 && len.is_finite()).then(|| Plane::new(normal / len, f64::from(p.dist) / len))
}

/// Walk `model`'s hull 0 tree down from its head node, cutting the model's box by each node's
/// plane, and keep the regions of the leaves that hold something.
pub(crate) fn filled_leaves(bsp: &Bsp, model: &Model) -> ModelLeaves {
    let mut out = ModelLeaves::default();
    let bounds = model_box(bsp, model);
    if bounds.is_empty() {
        return out;
    }
    let Some(start) = Region::from_bounds(&bounds) else {
        return out;
    };
    // Depth first with a stack of its own: the gate bounds the depth, but not to what a thread's
    // stack holds at every region's size.
    let mut stack = vec![(model.head_nodes[0], start)];
    while let Some((child, region)) = stack.pop() {
        if child < 0 {
            let leaf = (-(child + 1)) as usize;
            let Some(value) = bsp.leafs.get(leaf).map(|l| l.contents) else {
                continue;
            };
            if is_filled(value) {
                out.filled.push(FilledLeaf {
                    contents: value,
                    region,
                });
            } else if value != contents::EMPTY {
                out.unknown_contents += 1;
            }
            continue;
        }
        let index = child as usize;
        let Some(node) = bsp.nodes.get(index) else {
            continue;
        };
        let Some(plane) = bsp_plane(bsp, node.plane) else {
            continue;
        };
        let (front, back) = region.split(&plane, SideSource::Node(index));
        // The back child is pushed first so that the front is written first, as the tree lists it.
        if let Some(back) = back {
            stack.push((node.children[1], back));
        }
        if let Some(front) = front {
            stack.push((node.children[0], front));
        }
    }
    out
}
