use super::{Bounds, MAX_WORLD_COORD, ON_EPSILON, Plane, PlaneSide};
use crate::geom::DVec3Ext;
use glam::DVec3;

/// A convex polygon, its points in clockwise order seen from the front of its plane (Quake's
/// convention, matching [`Plane::from_points`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Winding {
    /// The corners in order; the last connects back to the first.
    pub points: Vec<DVec3>,
}

/// The result of splitting a winding by a plane.
#[derive(Debug, Clone, PartialEq)]
pub enum Split {
    /// Entirely in front (some points may be on the plane): the winding unchanged.
    Front(Winding),
    /// Entirely behind (some points may be on the plane): the winding unchanged.
    Back(Winding),
    /// Coplanar; `facing_front` tells whether the winding faces the same way as the plane.
    On {
        /// The winding unchanged.
        winding: Winding,
        /// Whether the winding's own normal points the way the plane's does.
        facing_front: bool,
    },
    /// Crossing the plane: cut into two, the new points shared by both halves.
    Both {
        /// The part in front of the plane.
        front: Winding,
        /// The part behind the plane.
        back: Winding,
    },
}

/// Each edge of a winding whose points lie at `dists` from a plane, as (its first point, the
/// next one, their sides of the plane), each point's side worked out once.
fn edge_sides(dists: &[f64]) -> impl Iterator<Item = (usize, usize, PlaneSide, PlaneSide)> + '_ {
    let n = dists.len();
    let first = dists.first().map(|&d| PlaneSide::of_distance(d));
    let mut side_i = first.unwrap_or(PlaneSide::On);
    (0..n).map(move |i| {
        let j = if i + 1 == n { 0 } else { i + 1 };
        let side_j = if j == 0 {
            first.unwrap_or(PlaneSide::On)
        } else {
            PlaneSide::of_distance(dists[j])
        };
        let edge = (i, j, side_i, side_j);
        side_i = side_j;
        edge
    })
}

/// The mean of the convex polygon `points` (the origin for none).
pub fn polygon_center(points: &[DVec3]) -> DVec3 {
    let sum = points.iter().fold(DVec3::ZERO, |acc, &p| acc + p);
    sum / points.len().max(1) as f64
}

/// The area of the convex polygon `points`, in square map units.
pub fn polygon_area(points: &[DVec3]) -> f64 {
    let mut total = DVec3::ZERO;
    for i in 2..points.len() {
        total += (points[i - 1] - points[0]).cross(points[i] - points[0]);
    }
    total.length() * 0.5
}

impl Winding {
    /// A winding of `points`, which must already be convex and in clockwise order.
    pub fn new(points: Vec<DVec3>) -> Self {
        Winding { points }
    }

    /// A huge square on `plane`, spanning the whole world.
    pub fn base_for_plane(plane: &Plane) -> Winding {
        let n = plane.normal;
        // Pick the major axis; "up" is any axis not parallel to it.
        let ax = n.x.abs();
        let ay = n.y.abs();
        let az = n.z.abs();
        let up = if az >= ax && az >= ay {
            DVec3::new(1.0, 0.0, 0.0)
        } else {
            DVec3::new(0.0, 0.0, 1.0)
        };
        let up = (up - n * up.dot(n))
            .normalized()
            .unwrap_or(DVec3::new(0.0, 1.0, 0.0));
        let right = up.cross(n);
        let origin = n * plane.dist;
        let size = MAX_WORLD_COORD * 4.0;
        let up = up * size;
        let right = right * size;
        Winding::new(vec![
            origin - right + up,
            origin + right + up,
            origin + right - up,
            origin - right - up,
        ])
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the winding has no points (clipped away).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The box around the points.
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for &p in &self.points {
            b.add_point(p);
        }
        b
    }

    /// The mean of the points (the origin for an empty winding).
    pub fn center(&self) -> DVec3 {
        polygon_center(&self.points)
    }

    /// Area in square map units.
    pub fn area(&self) -> f64 {
        polygon_area(&self.points)
    }

    /// The plane the winding lies on, from its (clockwise) point order.
    pub fn plane(&self) -> Option<Plane> {
        let n = self.points.len();
        if n < 3 {
            return None;
        }
        // Newell's method: robust for slightly non-planar or near-degenerate polygons.
        let mut normal = DVec3::ZERO;
        for i in 0..n {
            let a = self.points[i];
            let b = self.points[(i + 1) % n];
            normal.x += (a.y - b.y) * (a.z + b.z);
            normal.y += (a.z - b.z) * (a.x + b.x);
            normal.z += (a.x - b.x) * (a.y + b.y);
        }
        // Newell gives the counter-clockwise normal; ours is clockwise-from-front.
        let normal = (-normal).normalized()?;
        Some(Plane::new(normal, normal.dot(self.center())))
    }

    /// The same polygon in the opposite order, facing the other way.
    pub fn reversed(&self) -> Winding {
        Winding::new(self.points.iter().rev().copied().collect())
    }

    /// Classify the winding against a plane without splitting it.
    pub fn side_of(&self, plane: &Plane) -> PlaneSide {
        // Without keeping the distances: the compiler's splitter choice calls this for every
        // candidate plane, and keeping them
        // made its compiles 20 % slower.
        let (mut front, mut back) = (false, false);
        for &p in &self.points {
            match plane.side_of_point(p) {
                PlaneSide::Front => front = true,
                PlaneSide::Back => back = true,
                _ => {}
            }
        }
        PlaneSide::of_both(front, back)
    }

    /// Calls `then` with each point's distance from `plane` and where the whole winding lies
    /// ([`ON_EPSILON`] thick; [`PlaneSide::Cross`] when it has points on both sides). The
    /// distances stay on the stack for windings of up to 16 points: most are that small, and
    /// splitting and clipping run in the compiler's and light's inner loops.
    fn with_distances<R>(&self, plane: &Plane, then: impl FnOnce(&[f64], PlaneSide) -> R) -> R {
        let n = self.points.len();
        let mut inline = [0.0; 16];
        let mut heap = Vec::new();
        let dists: &mut [f64] = if n <= inline.len() {
            &mut inline[..n]
        } else {
            heap.resize(n, 0.0);
            &mut heap
        };
        let (mut front, mut back) = (false, false);
        for (d, &p) in dists.iter_mut().zip(&self.points) {
            *d = plane.distance(p);
            match PlaneSide::of_distance(*d) {
                PlaneSide::Front => front = true,
                PlaneSide::Back => back = true,
                _ => {}
            }
        }
        then(dists, PlaneSide::of_both(front, back))
    }

    /// Where the edge from point `i` to point `j` (on opposite sides) crosses `plane`.
    fn crossing(&self, plane: &Plane, dists: &[f64], i: usize, j: usize) -> DVec3 {
        let t = dists[i] / (dists[i] - dists[j]);
        let mut mid = self.points[i].lerp_monotonic(self.points[j], t);
        // Keep axial coordinates exact so splits by axial planes do not drift.
        for axis in 0..3 {
            if plane.normal[axis] == 1.0 {
                mid[axis] = plane.dist;
            } else if plane.normal[axis] == -1.0 {
                mid[axis] = -plane.dist;
            }
        }
        mid
    }

    /// Split by `plane`; points within [`ON_EPSILON`] of it count as on it.
    pub fn split(&self, plane: &Plane) -> Split {
        self.with_distances(plane, |dists, whole| match whole {
            PlaneSide::On => Split::On {
                winding: self.clone(),
                facing_front: self
                    .plane()
                    .is_some_and(|own| own.normal.dot(plane.normal) > 0.0),
            },
            PlaneSide::Front => Split::Front(self.clone()),
            PlaneSide::Back => Split::Back(self.clone()),
            PlaneSide::Cross => self.split_crossing(plane, dists),
        })
    }

    /// [`Winding::split`] of a winding given away: one wholly on a side (or on the plane) comes
    /// back in its part as it is, without a copy.
    pub fn into_split(self, plane: &Plane) -> Split {
        let crossing = self.with_distances(plane, |dists, whole| match whole {
            PlaneSide::Cross => Ok(self.split_crossing(plane, dists)),
            other => Err(other),
        });
        match crossing {
            Ok(split) => split,
            Err(PlaneSide::Front) => Split::Front(self),
            Err(PlaneSide::Back) => Split::Back(self),
            Err(_) => Split::On {
                facing_front: self
                    .plane()
                    .is_some_and(|own| own.normal.dot(plane.normal) > 0.0),
                winding: self,
            },
        }
    }

    /// [`Winding::split`] of a winding with points on both sides of `plane` at `dists`.
    fn split_crossing(&self, plane: &Plane, dists: &[f64]) -> Split {
        let n = self.points.len();
        let mut front = Vec::with_capacity(n + 2);
        let mut back = Vec::with_capacity(n + 2);
        for (i, j, side_i, side_j) in edge_sides(dists) {
            let p = self.points[i];
            match side_i {
                PlaneSide::On => {
                    front.push(p);
                    back.push(p);
                    continue;
                }
                PlaneSide::Front => front.push(p),
                _ => back.push(p),
            }
            if side_j == PlaneSide::On || side_j == side_i {
                continue;
            }
            let mid = self.crossing(plane, dists, i, j);
            front.push(mid);
            back.push(mid);
        }
        Split::Both {
            front: Winding::new(front),
            back: Winding::new(back),
        }
    }

    /// The part in front of `plane` (on-plane windings are kept when `keep_on` is set): the
    /// front of [`Winding::split`], without building the back.
    pub fn clip_front(&self, plane: &Plane, keep_on: bool) -> Option<Winding> {
        self.with_distances(plane, |dists, whole| match whole {
            PlaneSide::On => keep_on.then(|| self.clone()),
            PlaneSide::Front => Some(self.clone()),
            PlaneSide::Back => None,
            PlaneSide::Cross => Some(self.front_of_crossing(plane, dists)),
        })
    }

    /// The part in front of `plane`, like [`Winding::clip_front`] without `keep_on`, of a winding
    /// given away: one wholly in front comes back as it is, without a copy, and each point's
    /// distance is measured once (classifying first and then clipping measured twice).
    pub fn into_front(self, plane: &Plane) -> Option<Winding> {
        self.into_front_keeping_on(plane, false)
    }

    /// [`Winding::into_front`], and a winding lying on `plane` (within [`ON_EPSILON`]) kept whole
    /// when `keep_on` is set, as [`Winding::clip_front`] keeps it.
    pub fn into_front_keeping_on(self, plane: &Plane, keep_on: bool) -> Option<Winding> {
        let clipped = self.with_distances(plane, |dists, whole| match whole {
            PlaneSide::Front => None,
            PlaneSide::On => (!keep_on).then_some(None),
            PlaneSide::Cross => Some(Some(self.front_of_crossing(plane, dists))),
            PlaneSide::Back => Some(None),
        });
        clipped.unwrap_or(Some(self))
    }

    /// [`Winding::clip_front`] of a winding with points on both sides of `plane` at `dists`.
    fn front_of_crossing(&self, plane: &Plane, dists: &[f64]) -> Winding {
        let mut front = Vec::with_capacity(self.points.len() + 2);
        self.push_front(plane, dists, &mut front);
        Winding::new(front)
    }

    /// Push the points of the part in front of `plane` (this winding's points at `dists` from
    /// it, on both sides) onto `front`.
    fn push_front(&self, plane: &Plane, dists: &[f64], front: &mut Vec<DVec3>) {
        for (i, j, side_i, side_j) in edge_sides(dists) {
            if side_i != PlaneSide::Back {
                front.push(self.points[i]);
            }
            if side_i == PlaneSide::On || side_j == PlaneSide::On || side_j == side_i {
                continue;
            }
            front.push(self.crossing(plane, dists, i, j));
        }
    }

    /// The part in front of every plane of `planes`: [`Winding::into_front`] by each in turn,
    /// with two point buffers taking turns instead of a new winding for every cut.
    pub fn into_front_of_all(self, planes: impl IntoIterator<Item = Plane>) -> Option<Winding> {
        let mut w = self;
        let mut spare = Vec::new();
        for plane in planes {
            let whole = w.with_distances(&plane, |dists, whole| {
                if whole == PlaneSide::Cross {
                    spare.clear();
                    w.push_front(&plane, dists, &mut spare);
                }
                whole
            });
            match whole {
                PlaneSide::Front => {}
                PlaneSide::Cross => std::mem::swap(&mut w.points, &mut spare),
                PlaneSide::Back | PlaneSide::On => return None,
            }
        }
        Some(w)
    }

    /// True when the winding is too small to matter: fewer than three points, or every edge
    /// shorter than [`ON_EPSILON`] apart from at most two.
    pub fn is_tiny(&self) -> bool {
        if self.points.len() < 3 {
            return true;
        }
        let n = self.points.len();
        let long_edges = (0..n)
            .filter(|&i| (self.points[(i + 1) % n] - self.points[i]).length() > ON_EPSILON)
            .count();
        long_edges < 3
    }

    /// Whether every point is free of NaN and infinity.
    pub fn is_finite(&self) -> bool {
        self.points.iter().all(|p| p.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn square(z: f64) -> Winding {
        // Clockwise seen from +Z.
        Winding::new(vec![
            DVec3::new(0.0, 0.0, z),
            DVec3::new(0.0, 64.0, z),
            DVec3::new(64.0, 64.0, z),
            DVec3::new(64.0, 0.0, z),
        ])
    }

    #[test]
    fn plane_of_clockwise_square_faces_up() {
        let p = square(8.0).plane().expect("plane");
        assert!(p.normal.near(DVec3::new(0.0, 0.0, 1.0), 1e-12));
        assert!((p.dist - 8.0).abs() < 1e-12);
    }

    #[test]
    fn base_winding_lies_on_plane_and_faces_it() {
        let plane = Plane::new(DVec3::new(0.6, 0.0, 0.8), 100.0);
        let w = Winding::base_for_plane(&plane);
        for p in &w.points {
            assert!(plane.distance(*p).abs() < 1e-6);
        }
        let own = w.plane().expect("plane");
        assert!(own.normal.near(plane.normal, 1e-9));
    }

    #[test]
    fn split_square_in_half() {
        let plane = Plane::new(DVec3::new(1.0, 0.0, 0.0), 16.0);
        match square(0.0).split(&plane) {
            Split::Both { front, back } => {
                assert!((front.area() - 48.0 * 64.0).abs() < 1e-9);
                assert!((back.area() - 16.0 * 64.0).abs() < 1e-9);
            }
            other => panic!("expected a split, got {other:?}"),
        }
    }

    proptest! {
        /// Clipping gives exactly the front that splitting does (it only skips the back).
        #[test]
        fn clip_front_is_the_front_of_split(
            nx in -1.0f64..1.0, ny in -1.0f64..1.0, nz in -1.0f64..1.0,
            d in -80.0f64..80.0, z in -4.0f64..4.0, keep_on in proptest::bool::ANY,
        ) {
            let Some(normal) = DVec3::new(nx, ny, nz).normalized() else { return Ok(()); };
            let (w, plane) = (square(z), Plane::new(normal, d));
            let front = match w.split(&plane) {
                Split::Both { front, .. } | Split::Front(front) => Some(front),
                Split::On { winding, .. } => keep_on.then_some(winding),
                Split::Back(_) => None,
            };
            prop_assert_eq!(w.clip_front(&plane, keep_on).map(|w| w.points), front.map(|w| w.points));
        }

        /// Clipping by several planes with two buffers in turn gives what clipping by each in
        /// turn does.
        #[test]
        fn into_front_of_all_is_into_front_by_each(
            cuts in proptest::collection::vec(
                (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -80.0f64..80.0),
                0..8,
            ),
        ) {
            let planes: Vec<Plane> = cuts
                .iter()
                .filter_map(|&(x, y, z, d)| Some(Plane::new(DVec3::new(x, y, z).normalized()?, d)))
                .collect();
            let by_each = planes
                .iter()
                .try_fold(square(0.0), |w, plane| w.into_front(plane));
            prop_assert_eq!(square(0.0).into_front_of_all(planes.iter().copied()), by_each);
        }

        /// Giving the winding away changes nothing but the copy.
        #[test]
        fn into_split_is_split(
            nx in -1.0f64..1.0, ny in -1.0f64..1.0, nz in -1.0f64..1.0,
            d in -80.0f64..80.0, z in -4.0f64..4.0,
        ) {
            let Some(normal) = DVec3::new(nx, ny, nz).normalized() else { return Ok(()); };
            let (w, plane) = (square(z), Plane::new(normal, d));
            prop_assert_eq!(w.clone().into_split(&plane), w.split(&plane));
        }

        /// Giving the winding away changes nothing but the copy.
        #[test]
        fn into_front_is_clip_front_without_keep_on(
            nx in -1.0f64..1.0, ny in -1.0f64..1.0, nz in -1.0f64..1.0,
            d in -80.0f64..80.0, z in -4.0f64..4.0,
        ) {
            let Some(normal) = DVec3::new(nx, ny, nz).normalized() else { return Ok(()); };
            let (w, plane) = (square(z), Plane::new(normal, d));
            prop_assert_eq!(w.clone().into_front(&plane), w.clip_front(&plane, false));
        }

        #[test]
        fn split_preserves_area(nx in -1.0f64..1.0, ny in -1.0f64..1.0, nz in -1.0f64..1.0, d in -80.0f64..80.0) {
            let Some(normal) = DVec3::new(nx, ny, nz).normalized() else { return Ok(()); };
            let w = square(3.0);
            let plane = Plane::new(normal, d);
            let total = w.area();
            let parts: f64 = match w.split(&plane) {
                Split::Both { front, back } => {
                    for p in front.points.iter() { prop_assert!(plane.distance(*p) > -ON_EPSILON * 1.01); }
                    for p in back.points.iter() { prop_assert!(plane.distance(*p) < ON_EPSILON * 1.01); }
                    front.area() + back.area()
                }
                Split::Front(f) | Split::Back(f) => f.area(),
                Split::On { winding, .. } => winding.area(),
            };
            // Near-tangent cuts may shave a sliver thinner than ON_EPSILON.
            prop_assert!((parts - total).abs() < 64.0 * ON_EPSILON * 4.0);
        }
    }
}
