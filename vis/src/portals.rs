//! The portal graph vis works on: every portal of a `.prt` file as two one-way portals between
//! clusters. In a PRT1 file each vis leaf is its own cluster; a PRT2 file groups leaves (detail
//! leaves merged with the leaf around them) into clusters and joins clusters by its portals.
//! Clusters need not be convex, so a sight line may enter one more than once.
//!
//! PRT1 convention (PRT2 too) (the one id's and ericw-tools' qbsp write): the plane of a portal's winding
//! (clockwise seen from the front) faces its first leaf. The one-way portal from the first leaf
//! into the second therefore uses the flipped plane, so that every one-way portal's plane faces
//! into the leaf it leads to: whatever is seen through it lies in front of it.

use crate::VisError;
use glam::DVec3;
use quake_formats::geom::{ON_EPSILON, POINT_EPSILON, Plane};
use quake_formats::prt::PortalFile;

/// A portal seen from one side: looking from `from_cluster` through `winding` into `to_cluster`.
#[derive(Debug, Clone)]
pub struct OneWayPortal {
    pub(crate) winding: Vec<DVec3>,
    /// Faces into `to_cluster`.
    pub plane: Plane,
    pub(crate) from_cluster: u32,
    pub(crate) to_cluster: u32,
    /// A sphere holding the winding, for quick plane tests.
    pub center: DVec3,
    pub(crate) radius: f64,
}

impl OneWayPortal {
    pub(crate) fn new(
        winding: Vec<DVec3>,
        plane: Plane,
        from_cluster: u32,
        to_cluster: u32,
    ) -> OneWayPortal {
        let center = winding.iter().fold(DVec3::ZERO, |a, &v| a + v) / winding.len().max(1) as f64;
        let radius = winding
            .iter()
            .map(|&v| (v - center).length())
            .fold(0.0, f64::max);
        OneWayPortal {
            winding,
            plane,
            from_cluster,
            to_cluster,
            center,
            radius,
        }
    }

    /// True when the bounding sphere lies behind `plane` (by more than [`ON_EPSILON`]): a
    /// quick test that the whole winding does.
    #[inline]
    pub fn behind(&self, plane: &Plane) -> bool {
        plane.distance(self.center) < -self.radius - ON_EPSILON
    }

    /// The side of `plane` the bounding sphere lies wholly on, so that every point of the
    /// winding, or of any part of it, does too: `Some(true)` in front by more than
    /// [`ON_EPSILON`], `Some(false)` behind by more, `None` when the sphere reaches closer.
    /// [`POINT_EPSILON`] to spare covers rounding, so point tests agree with the answer.
    #[inline]
    pub fn sphere_side(&self, plane: &Plane) -> Option<bool> {
        let d = plane.distance(self.center);
        let reach = self.radius + ON_EPSILON + POINT_EPSILON;
        if d > reach {
            Some(true)
        } else if d < -reach {
            Some(false)
        } else {
            None
        }
    }

    /// True when every point of the winding lies behind `plane` (by more than [`ON_EPSILON`]).
    #[inline]
    pub fn wholly_behind(&self, plane: &Plane) -> bool {
        let d = plane.distance(self.center);
        d < -self.radius - ON_EPSILON
            || (d < self.radius
                && self
                    .winding
                    .iter()
                    .all(|&v| plane.distance(v) < -ON_EPSILON))
    }
}

/// Clusters (in a PRT1 file, leaves numbered from 0 = BSP leaf 1) and the one-way portals
/// leading out of each.
#[derive(Debug, Clone)]
pub struct PortalGraph {
    pub(crate) num_clusters: usize,
    /// The one-way portals, two per portal of the file that was kept (numbered as flow results
    /// and [`KnownFlows`](crate::KnownFlows) number them).
    pub portals: Vec<OneWayPortal>,
    /// For each cluster, the one-way portals whose `from_cluster` it is.
    pub cluster_portals: Vec<Vec<u32>>,
    /// PRT portals dropped because their winding has no plane (degenerate, zero area).
    pub degenerate: usize,
}

impl PortalGraph {
    /// The graph of a portal file; refuses portals naming clusters that do not exist or with
    /// coordinates that are not finite.
    pub fn from_prt(prt: &PortalFile) -> Result<PortalGraph, VisError> {
        let num_clusters = prt
            .clusters
            .as_ref()
            .map_or(prt.num_leafs as usize, Vec::len);
        let mut portals = Vec::with_capacity(prt.portals.len() * 2);
        let mut degenerate = 0;
        for (index, p) in prt.portals.iter().enumerate() {
            let [a, b] = p.leafs;
            if a as usize >= num_clusters || b as usize >= num_clusters {
                return Err(VisError::PortalCluster {
                    index,
                    clusters: p.leafs,
                    num_clusters,
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
        let mut cluster_portals = vec![Vec::new(); num_clusters];
        for (i, p) in portals.iter().enumerate() {
            cluster_portals[p.from_cluster as usize].push(i as u32);
        }
        Ok(PortalGraph {
            num_clusters,
            portals,
            cluster_portals,
            degenerate,
        })
    }

    /// The portal going the other way through the same opening (they are stored in pairs).
    pub fn reverse(portal: usize) -> usize {
        portal ^ 1
    }

    /// How many one-way portals of each cluster face out of it the wrong way: another portal of
    /// the same cluster lies in front of the portal's plane (inside the neighbour). A correct
    /// PRT1 file (convex leaves, orientation as documented above) gives zero; a file written with
    /// the opposite orientation gives nearly every portal of every leaf with two or more. Only
    /// meaningful for convex clusters (PRT1 leaves).
    pub fn misoriented_portals(&self) -> usize {
        let mut bad = 0;
        for outs in &self.cluster_portals {
            for &p in outs {
                let plane = &self.portals[p as usize].plane;
                let wrong = outs.iter().filter(|&&q| q != p).any(|&q| {
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
