//! Clip hull queries as engines run them on a written BSP: the contents at a point and a line
//! trace through the clip nodes (the box of the hull moving along the line). In `f32`, with the
//! engine's epsilon, so tests see what a player would.

use quake_formats::Bsp;
use quake_formats::bsp::contents;

/// How far in front of a plane a trace stops, as in engines.
const TRACE_EPSILON: f32 = 0.03125;

/// Where a trace through a clip hull ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HullTrace {
    /// Part of the way travelled: 1 when nothing was hit.
    pub fraction: f32,
    /// Where the box's centre stopped.
    pub end: [f32; 3],
    /// The normal of the plane hit, facing the way the trace came from.
    pub normal: [f32; 3],
    /// The trace started in solid.
    pub start_solid: bool,
    /// The trace never left solid.
    pub all_solid: bool,
}

/// The clip nodes of a BSP.
struct Hull<'a> {
    bsp: &'a Bsp,
}

fn lerp(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

impl Hull<'_> {
    /// Distance of `p` from the plane of clip node `node`, and the plane's normal.
    fn distance(&self, node: i32, p: [f32; 3]) -> (f32, [f32; 3]) {
        let c = &self.bsp.clipnodes[node as usize];
        let plane = &self.bsp.planes[c.plane as usize];
        let d = if plane.kind < 3 {
            p[plane.kind as usize] - plane.dist
        } else {
            plane.normal[0] * p[0] + plane.normal[1] * p[1] + plane.normal[2] * p[2] - plane.dist
        };
        (d, plane.normal)
    }

    fn contents(&self, mut node: i32, p: [f32; 3]) -> i32 {
        while node >= 0 {
            let (d, _) = self.distance(node, p);
            node = self.bsp.clipnodes[node as usize].children[usize::from(d < 0.0)];
        }
        node
    }

    /// Trace from `p1` (at `f1` of the whole move) to `p2` (at `f2`) below `node`; false once
    /// something was hit.
    fn trace(
        &self,
        head: i32,
        node: i32,
        (f1, p1): (f32, [f32; 3]),
        (f2, p2): (f32, [f32; 3]),
        out: &mut HullTrace,
    ) -> bool {
        if node < 0 {
            if node == contents::SOLID {
                out.start_solid = true;
            } else {
                out.all_solid = false;
            }
            return true;
        }
        let (t1, normal) = self.distance(node, p1);
        let (t2, _) = self.distance(node, p2);
        let children = self.bsp.clipnodes[node as usize].children;
        if t1 >= 0.0 && t2 >= 0.0 {
            return self.trace(head, children[0], (f1, p1), (f2, p2), out);
        }
        if t1 < 0.0 && t2 < 0.0 {
            return self.trace(head, children[1], (f1, p1), (f2, p2), out);
        }
        // Crossing: stop a little short of the plane on the near side.
        let mut frac = if t1 < 0.0 {
            (t1 + TRACE_EPSILON) / (t1 - t2)
        } else {
            (t1 - TRACE_EPSILON) / (t1 - t2)
        }
        .clamp(0.0, 1.0);
        let mut fm = f1 + (f2 - f1) * frac;
        let mut mid = lerp(p1, p2, frac);
        let near = usize::from(t1 < 0.0);
        if !self.trace(head, children[near], (f1, p1), (fm, mid), out) {
            return false;
        }
        if self.contents(children[near ^ 1], mid) != contents::SOLID {
            return self.trace(head, children[near ^ 1], (fm, mid), (f2, p2), out);
        }
        if out.all_solid {
            return false;
        }
        out.normal = if near == 0 {
            normal
        } else {
            normal.map(|c| -c)
        };
        // Rounding can leave the stopping point inside solid: back off until it is not.
        while self.contents(head, mid) == contents::SOLID {
            frac -= 0.1;
            if frac < 0.0 {
                break;
            }
            fm = f1 + (f2 - f1) * frac;
            mid = lerp(p1, p2, frac);
        }
        out.fraction = fm;
        out.end = mid;
        false
    }
}

/// The contents of hull `hull` of `model` at `p`: hull 0 (points; its nodes and leaves) or a
/// clip hull (1 player, 2 shambler), where `p` is where the hull box's origin would be.
pub fn hull_point_contents(bsp: &Bsp, model: usize, hull: usize, p: [f32; 3]) -> i32 {
    debug_assert!(hull < 4);
    let head = bsp.models[model].head_nodes[hull];
    if hull > 0 {
        return Hull { bsp }.contents(head, p);
    }
    bsp.leaf_from(head, p)
        .and_then(|leaf| bsp.leafs.get(leaf))
        .map_or(contents::SOLID, |leaf| leaf.contents)
}

/// Move the box of clip hull `hull` (1 or 2) of `model` from `start` to `end`: where it stops.
pub fn trace_hull(
    bsp: &Bsp,
    model: usize,
    hull: usize,
    start: [f32; 3],
    end: [f32; 3],
) -> HullTrace {
    debug_assert!((1..4).contains(&hull));
    let head = bsp.models[model].head_nodes[hull];
    let mut out = HullTrace {
        fraction: 1.0,
        end,
        normal: [0.0; 3],
        start_solid: false,
        all_solid: true,
    };
    Hull { bsp }.trace(head, head, (0.0, start), (1.0, end), &mut out);
    out
}
