//! Convex regions of space as a list of sides (outward plane and polygon), cut in two by planes
//! as a BSP tree is walked down. A region keeps only the planes that touch it, so a leaf's
//! region is already the brush it becomes: no redundant planes to find afterwards.

use glam::DVec3;
use quake_formats::geom::{Bounds, Plane, PlaneSide, Split, Winding};

/// Where a side's plane came from: it decides which BSP faces can lie on the side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SideSource {
    /// One of the six planes of the model's box.
    Bounds,
    /// The plane of this hull 0 node: the node's faces lie on it.
    Node(usize),
    /// A cut made to keep one texture per side: never carries a face.
    Cut,
}

/// One bounding plane of a region and the polygon the region has on it.
#[derive(Debug, Clone)]
pub(crate) struct Side {
    /// Facing out of the region.
    pub plane: Plane,
    /// Clockwise seen from outside (the front of `plane`).
    pub winding: Winding,
    pub source: SideSource,
}

/// A convex region: the intersection of the half-spaces behind its sides' planes.
#[derive(Debug, Clone)]
pub(crate) struct Region {
    pub sides: Vec<Side>,
}

/// The planes of `planes` (outward facing) that touch the region behind all of them, by index,
/// each with the polygon the region has on it (its plane clipped behind every other plane).
pub(crate) fn touching_planes(planes: &[Plane]) -> Vec<(usize, Winding)> {
    let mut out = Vec::with_capacity(planes.len());
    for (i, plane) in planes.iter().enumerate() {
        let mut winding = Some(Winding::base_for_plane(plane));
        for (j, other) in planes.iter().enumerate() {
            if i != j {
                winding = winding.and_then(|w| w.clip_front(&other.flipped(), false));
            }
        }
        if let Some(winding) = winding.filter(|w| !w.is_tiny()) {
            out.push((i, winding));
        }
    }
    out
}

/// The volume of the convex region whose sides are `sides` (outward planes with their polygons),
/// as pyramids from one corner to each side.
pub(crate) fn volume<'a>(sides: impl Iterator<Item = (&'a Plane, &'a Winding)> + Clone) -> f64 {
    let Some(apex) = sides.clone().find_map(|(_, w)| w.points.first().copied()) else {
        return 0.0;
    };
    sides
        .map(|(plane, w)| w.area() * -plane.distance(apex) / 3.0)
        .sum()
}

/// A region needs four sides to hold any volume.
const MIN_SIDES: usize = 4;

impl Region {
    /// The region behind every plane of `planes` (outward facing), each side the part of its
    /// plane the others leave; planes that do not touch the region are left out. `None` when
    /// nothing of volume is left.
    pub fn from_planes(planes: &[(Plane, SideSource)]) -> Option<Region> {
        let bare: Vec<Plane> = planes.iter().map(|p| p.0).collect();
        let sides = touching_planes(&bare)
            .into_iter()
            .map(|(i, winding)| Side {
                plane: planes[i].0,
                winding,
                source: planes[i].1,
            })
            .collect();
        Region::with_sides(sides)
    }

    /// The box `bounds` as a region.
    pub fn from_bounds(bounds: &Bounds) -> Option<Region> {
        let mut planes = Vec::with_capacity(6);
        for axis in 0..3 {
            let mut normal = DVec3::ZERO;
            normal[axis] = 1.0;
            planes.push((Plane::new(normal, bounds.maxs[axis]), SideSource::Bounds));
            planes.push((Plane::new(-normal, -bounds.mins[axis]), SideSource::Bounds));
        }
        Region::from_planes(&planes)
    }

    fn with_sides(sides: Vec<Side>) -> Option<Region> {
        (sides.len() >= MIN_SIDES).then_some(Region { sides })
    }

    /// Cut by `plane`: the part in front of it and the part behind, each `None` when the region
    /// reaches less than [`ON_EPSILON`] into that half. The cut's polygon becomes a side of
    /// both, with `source`.
    pub fn split(&self, plane: &Plane, source: SideSource) -> (Option<Region>, Option<Region>) {
        let (mut front, mut back) = (false, false);
        for p in self.points() {
            match plane.side_of_point(p) {
                PlaneSide::Front => front = true,
                PlaneSide::Back => back = true,
                _ => {}
            }
        }
        match (front, back) {
            (true, true) => {}
            (true, false) => return (Some(self.clone()), None),
            (false, _) => return (None, Some(self.clone())),
        }
        // The cut's polygon: the plane inside every side.
        let cap = self
            .sides
            .iter()
            .try_fold(Winding::base_for_plane(plane), |w, s| {
                w.clip_front(&s.plane.flipped(), false)
            });
        let Some(cap) = cap.filter(|w| !w.is_tiny()) else {
            // The region crosses the plane only in points, not in an area: rounding. The larger
            // reach keeps the whole region.
            return if self.reach(plane) >= self.reach(&plane.flipped()) {
                (Some(self.clone()), None)
            } else {
                (None, Some(self.clone()))
            };
        };
        let mut front_sides = Vec::with_capacity(self.sides.len() + 1);
        let mut back_sides = Vec::with_capacity(self.sides.len() + 1);
        for side in &self.sides {
            let part = |winding: Winding| Side { winding, ..*side };
            match side.winding.split(plane) {
                Split::Front(w) => front_sides.push(part(w)),
                Split::Back(w) => back_sides.push(part(w)),
                // A side on the plane bounds the half its outward normal leaves behind it.
                Split::On {
                    winding,
                    facing_front,
                } => match facing_front {
                    true => back_sides.push(part(winding)),
                    false => front_sides.push(part(winding)),
                },
                Split::Both { front, back } => {
                    if !front.is_tiny() {
                        front_sides.push(part(front));
                    }
                    if !back.is_tiny() {
                        back_sides.push(part(back));
                    }
                }
            }
        }
        front_sides.push(Side {
            plane: plane.flipped(),
            winding: cap.reversed(),
            source,
        });
        back_sides.push(Side {
            plane: *plane,
            winding: cap,
            source,
        });
        (
            Region::with_sides(front_sides),
            Region::with_sides(back_sides),
        )
    }

    /// How far the region reaches in front of `plane`.
    fn reach(&self, plane: &Plane) -> f64 {
        self.points()
            .map(|p| plane.distance(p))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Every corner of every side (corners repeat, once per side they are on).
    pub fn points(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.sides
            .iter()
            .flat_map(|s| s.winding.points.iter().copied())
    }

    /// The volume.
    pub fn volume(&self) -> f64 {
        volume(self.sides.iter().map(|s| (&s.plane, &s.winding)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::geom::ON_EPSILON;

    fn cube(size: f64) -> Region {
        Region::from_bounds(&Bounds {
            mins: DVec3::splat(0.0),
            maxs: DVec3::splat(size),
        })
        .expect("cube")
    }

    #[test]
    fn a_box_has_six_outward_sides() {
        let r = cube(64.0);
        assert_eq!(r.sides.len(), 6);
        for s in &r.sides {
            let own = s.winding.plane().expect("plane");
            assert!(own.normal.dot(s.plane.normal) > 0.999, "{s:?}");
        }
        assert!((r.volume() - 64.0f64.powi(3)).abs() < 1e-6);
    }

    #[test]
    fn a_split_keeps_volume_and_caps_both_halves() {
        let r = cube(64.0);
        let plane = Plane::new(DVec3::new(1.0, 1.0, 0.0).normalize(), 40.0);
        let (front, back) = r.split(&plane, SideSource::Cut);
        let (front, back) = (front.expect("front"), back.expect("back"));
        let lost = front.volume() + back.volume() - r.volume();
        assert!(lost.abs() < 1e-3, "{lost}");
        assert!(
            front
                .sides
                .iter()
                .any(|s| s.plane.same_as(&plane.flipped()))
        );
        assert!(back.sides.iter().any(|s| s.plane.same_as(&plane)));
        for p in back.points() {
            assert!(plane.distance(p) < ON_EPSILON);
        }
    }

    #[test]
    fn a_plane_missing_the_region_leaves_it_whole() {
        let r = cube(64.0);
        let plane = Plane::new(DVec3::X, 100.0);
        let (front, back) = r.split(&plane, SideSource::Cut);
        assert!(front.is_none());
        assert_eq!(back.expect("back").sides.len(), 6);
        // A plane along a side leaves the region whole on the side it lies behind.
        let (front, back) = r.split(&Plane::new(DVec3::X, 64.0), SideSource::Cut);
        assert!(front.is_none() && back.is_some());
    }

    #[test]
    fn planes_that_miss_the_region_are_dropped() {
        let mut planes: Vec<(Plane, SideSource)> = (0..3)
            .flat_map(|axis| {
                let mut n = DVec3::ZERO;
                n[axis] = 1.0;
                [
                    (Plane::new(n, 64.0), SideSource::Bounds),
                    (Plane::new(-n, 0.0), SideSource::Bounds),
                ]
            })
            .collect();
        planes.push((
            Plane::new(DVec3::new(1.0, 1.0, 1.0).normalize(), 1000.0),
            SideSource::Cut,
        ));
        let r = Region::from_planes(&planes).expect("region");
        assert_eq!(r.sides.len(), 6);
    }
}
