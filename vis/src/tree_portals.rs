//! Portals recovered from a compiled BSP's hull 0 tree, for re-running vis on a BSP without its
//! `.prt` file (and for measuring vis on real maps before our compiler writes portal files).
//!
//! Every node's plane, clipped to the node's region, is pushed down the front subtree and each
//! piece then down the back subtree: every final piece lies between a front leaf and a back leaf.
//! Pieces between two open leaves are the portals.

use crate::VisError;
use crate::lump::world_vis_leafs;
use crate::sample::is_open;
use glam::{DVec3, Vec3};
use quake_formats::Bsp;
use quake_formats::geom::{Plane, Winding};
use quake_formats::prt::{PortalFile, PrtPortal};

struct Tree<'a> {
    bsp: &'a Bsp,
    planes: Vec<Plane>,
    vis_leafs: usize,
}

/// PRT1 portals between the open leaves of the world model.
pub fn portals_from_bsp(bsp: &Bsp) -> Result<PortalFile, VisError> {
    quake_formats::check_usable(bsp)?;
    // Checks node and leaf references once; the walk below relies on them.
    crate::sample::Hull0::new(bsp)?;
    let vis_leafs = world_vis_leafs(bsp)?;
    let world = &bsp.models[0];
    let planes = bsp
        .planes
        .iter()
        .map(|p| Plane::new(Vec3::from(p.normal).as_dvec3(), p.dist as f64))
        .collect();
    let tree = Tree {
        bsp,
        planes,
        vis_leafs,
    };
    // The world's box, a little larger, bounds every node region.
    let mut bounds = Vec::new();
    for axis in 0..3 {
        let mut normal = DVec3::ZERO;
        normal[axis] = 1.0;
        bounds.push(Plane::new(normal, world.mins[axis] as f64 - 64.0));
        bounds.push(Plane::new(-normal, -(world.maxs[axis] as f64 + 64.0)));
    }
    let mut portals = Vec::new();
    tree.node_portals(world.head_nodes[0], &mut bounds, &mut portals);
    Ok(PortalFile {
        num_leafs: vis_leafs as u32,
        portals,
        clusters: None,
    })
}

impl Tree<'_> {
    /// `region`: planes whose front side holds the node.
    fn node_portals(&self, node: i32, region: &mut Vec<Plane>, out: &mut Vec<PrtPortal>) {
        if node < 0 {
            return;
        }
        let n = &self.bsp.nodes[node as usize];
        let plane = self.planes[n.plane as usize];
        let mut winding = Some(Winding::base_for_plane(&plane));
        for bound in region.iter() {
            winding = winding.and_then(|w| w.clip_front(bound, false));
        }
        if let Some(w) = winding {
            let mut front_pieces = Vec::new();
            self.filter(n.children[0], w, &mut front_pieces);
            for (front_leaf, piece) in front_pieces {
                let mut pieces = Vec::new();
                self.filter(n.children[1], piece, &mut pieces);
                for (back_leaf, piece) in pieces {
                    if !piece.is_tiny() {
                        // The winding faces the front leaf, which PRT1 lists first.
                        out.push(PrtPortal {
                            leafs: [front_leaf as u32 - 1, back_leaf as u32 - 1],
                            winding: piece,
                        });
                    }
                }
            }
        }
        for (child, side) in [(n.children[0], plane), (n.children[1], plane.flipped())] {
            region.push(side);
            self.node_portals(child, region, out);
            region.pop();
        }
    }

    /// Split `w` down the subtree at `node`; keep the pieces that reach open vis leaves.
    fn filter(&self, node: i32, w: Winding, out: &mut Vec<(usize, Winding)>) {
        if node < 0 {
            let leaf = (-(node + 1)) as usize;
            if (1..=self.vis_leafs).contains(&leaf) && is_open(self.bsp.leafs[leaf].contents) {
                out.push((leaf, w));
            }
            return;
        }
        let n = &self.bsp.nodes[node as usize];
        let plane = &self.planes[n.plane as usize];
        if let Some(front) = w.clip_front(plane, true) {
            self.filter(n.children[0], front, out);
        }
        if let Some(back) = w.clip_front(&plane.flipped(), false) {
            self.filter(n.children[1], back, out);
        }
    }
}
