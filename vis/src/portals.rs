//! The portal graph vis works on: every PRT1 portal as two one-way portals.
//!
//! PRT1 convention (the one id's and ericw-tools' qbsp write): the plane of a portal's winding
//! (clockwise seen from the front) faces its first leaf. The one-way portal from the first leaf
//! into the second therefore uses the flipped plane, so that every one-way portal's plane faces
//! into the leaf it leads to: whatever is seen through it lies in front of it.

use crate::VisError;
use quake_formats::geom::{ON_EPSILON, Plane, Vec3};
use quake_formats::prt::PortalFile;

/// A portal seen from one side: looking from `from_leaf` through `winding` into `to_leaf`.
#[derive(Debug, Clone)]
pub struct OneWayPortal {
    pub winding: Vec<Vec3>,
    /// Faces into `to_leaf`.
    pub plane: Plane,
    pub from_leaf: u32,
    pub to_leaf: u32,
    /// A sphere holding the winding, for quick plane tests.
    pub center: Vec3,
    pub radius: f64,
}

impl OneWayPortal {
    fn new(winding: Vec<Vec3>, plane: Plane, from_leaf: u32, to_leaf: u32) -> OneWayPortal {
        let center = winding.iter().fold(Vec3::ZERO, |a, &v| a + v) / winding.len().max(1) as f64;
        let radius = winding
            .iter()
            .map(|&v| (v - center).length())
            .fold(0.0, f64::max);
        OneWayPortal {
            winding,
            plane,
            from_leaf,
            to_leaf,
            center,
            radius,
        }
    }

    /// True when the whole winding lies behind `plane` (by more than [`ON_EPSILON`]).
    #[inline]
    pub fn behind(&self, plane: &Plane) -> bool {
        plane.distance(self.center) < -self.radius - ON_EPSILON
    }
}

/// Leaves (numbered from 0 = BSP leaf 1) and the one-way portals leading out of each.
#[derive(Debug, Clone)]
pub struct PortalGraph {
    pub num_leafs: usize,
    pub portals: Vec<OneWayPortal>,
    /// For each leaf, the one-way portals whose `from_leaf` it is.
    pub leaf_portals: Vec<Vec<u32>>,
    /// PRT portals dropped because their winding has no plane (degenerate, zero area).
    pub degenerate: usize,
}

impl PortalGraph {
    pub fn from_prt(prt: &PortalFile) -> Result<PortalGraph, VisError> {
        let num_leafs = prt.num_leafs as usize;
        let mut portals = Vec::with_capacity(prt.portals.len() * 2);
        let mut degenerate = 0;
        for (index, p) in prt.portals.iter().enumerate() {
            let [a, b] = p.leafs;
            if a as usize >= num_leafs || b as usize >= num_leafs {
                return Err(VisError::PortalLeaf {
                    index,
                    leafs: p.leafs,
                    num_leafs,
                });
            }
            if !p.winding.is_finite() {
                return Err(VisError::PortalNotFinite { index });
            }
            let plane = match p.winding.plane() {
                Some(plane) if !p.winding.is_tiny() && a != b => plane,
                _ => {
                    degenerate += 1;
                    continue;
                }
            };
            portals.push(OneWayPortal::new(
                p.winding.points.clone(),
                plane.flipped(),
                a,
                b,
            ));
            portals.push(OneWayPortal::new(p.winding.reversed().points, plane, b, a));
        }
        let mut leaf_portals = vec![Vec::new(); num_leafs];
        for (i, p) in portals.iter().enumerate() {
            leaf_portals[p.from_leaf as usize].push(i as u32);
        }
        Ok(PortalGraph {
            num_leafs,
            portals,
            leaf_portals,
            degenerate,
        })
    }

    /// The portal going the other way through the same opening (they are stored in pairs).
    pub fn reverse(portal: usize) -> usize {
        portal ^ 1
    }

    /// How many one-way portals of each leaf face out of it the wrong way: another portal of the
    /// same leaf lies in front of the portal's plane (inside the neighbour). A correct portal
    /// file (convex leaves, PRT1 orientation as documented above) gives zero; a file written with
    /// the opposite orientation gives nearly every portal of every leaf with two or more.
    pub fn misoriented_portals(&self) -> usize {
        let mut bad = 0;
        for leaf in &self.leaf_portals {
            for &p in leaf {
                let plane = &self.portals[p as usize].plane;
                let wrong = leaf.iter().filter(|&&q| q != p).any(|&q| {
                    self.portals[q as usize]
                        .winding
                        .iter()
                        .any(|&v| plane.distance(v) > 1.0)
                });
                bad += usize::from(wrong);
            }
        }
        bad
    }
}
