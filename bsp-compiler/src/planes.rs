//! Deduplicated planes in canonical orientation.
//!
//! Engines take a fast path for axial planes that assumes the normal points along +axis, so every
//! plane is stored with its largest normal component positive; users keep a `flipped` flag.

use quake_formats::geom::{DIST_EPSILON, Plane};
use quake_formats::int_hash::IntMap;

pub type PlaneId = u32;

#[derive(Debug, Clone, Default)]
pub struct PlaneSet {
    planes: Vec<Plane>,
    /// Whether each plane is axial ([`Plane::axial`]): asked of every plane a brush is tested
    /// against while choosing splitters.
    axial: Vec<bool>,
    /// Planes by their distance rounded down, for lookups within [`DIST_EPSILON`].
    by_dist: IntMap<i64, Vec<PlaneId>>,
}

/// `plane` with its largest normal component positive, and whether that flipped it.
pub fn canonical(plane: &Plane) -> (Plane, bool) {
    let n = plane.normal;
    let axis = match plane.axial() {
        Some(a) => a,
        None => {
            let a = [n.x.abs(), n.y.abs(), n.z.abs()];
            if a[0] >= a[1] && a[0] >= a[2] {
                0
            } else if a[1] >= a[2] {
                1
            } else {
                2
            }
        }
    };
    if n[axis] < 0.0 {
        (plane.flipped(), true)
    } else {
        (*plane, false)
    }
}

impl PlaneSet {
    pub fn new() -> PlaneSet {
        PlaneSet::default()
    }

    pub fn get(&self, id: PlaneId) -> &Plane {
        &self.planes[id as usize]
    }

    pub fn is_axial(&self, id: PlaneId) -> bool {
        self.axial[id as usize]
    }

    pub fn len(&self) -> usize {
        self.planes.len()
    }

    /// The id of `plane`'s canonical form, and whether `plane` faces the other way.
    pub fn insert(&mut self, plane: &Plane) -> (PlaneId, bool) {
        let (canon, flipped) = canonical(plane);
        let key = canon.dist.floor() as i64;
        for k in [key, key - 1, key + 1] {
            if let Some(ids) = self.by_dist.get(&k)
                && let Some(&id) = ids
                    .iter()
                    .find(|&&id| self.planes[id as usize].same_as(&canon))
            {
                return (id, flipped);
            }
        }
        debug_assert!(canon.dist.is_finite() && DIST_EPSILON < 1.0);
        let id = self.planes.len() as PlaneId;
        self.planes.push(canon);
        self.axial.push(canon.axial().is_some());
        self.by_dist.entry(key).or_default().push(id);
        (id, flipped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn opposite_planes_share_an_id() {
        let mut set = PlaneSet::new();
        let p = Plane::new(DVec3::new(0.0, 0.0, -1.0), -64.0);
        let (a, fa) = set.insert(&p);
        let (b, fb) = set.insert(&p.flipped());
        assert_eq!(a, b);
        assert!(fa && !fb);
        assert_eq!(set.get(a).normal, DVec3::new(0.0, 0.0, 1.0));
        assert_eq!(set.get(a).dist, 64.0);
    }

    #[test]
    fn near_equal_distances_across_integer_boundaries_match() {
        let mut set = PlaneSet::new();
        let n = DVec3::new(0.6, 0.8, 0.0);
        let (a, _) = set.insert(&Plane::new(n, 15.99999999));
        let (b, _) = set.insert(&Plane::new(n, 16.0000001));
        assert_eq!(a, b);
        assert_eq!(set.len(), 1);
    }
}
