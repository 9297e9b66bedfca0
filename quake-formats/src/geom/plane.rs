use super::{DIST_EPSILON, NORMAL_EPSILON, ON_EPSILON};
use crate::geom::DVec3Ext;
use glam::DVec3;

/// A plane `normal · p = dist` with a unit normal; the front side is where the normal points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal, pointing to the front side.
    pub normal: DVec3,
    /// Distance from the origin along `normal`.
    pub dist: f64,
}

/// Where something lies relative to a plane, within [`ON_EPSILON`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlaneSide {
    /// Entirely in front (on the normal's side), or touching the plane from there.
    Front,
    /// Entirely behind, or touching the plane from there.
    Back,
    /// On the plane: every point within [`ON_EPSILON`] of it.
    On,
    /// Partly in front and partly behind.
    Cross,
}

impl PlaneSide {
    /// The side of a point at signed distance `d` from a plane.
    pub fn of_distance(d: f64) -> PlaneSide {
        if d > ON_EPSILON {
            PlaneSide::Front
        } else if d < -ON_EPSILON {
            PlaneSide::Back
        } else {
            PlaneSide::On
        }
    }

    /// The side of a set of points, from whether any is in front and any behind.
    pub fn of_both(front: bool, back: bool) -> PlaneSide {
        match (front, back) {
            (true, true) => PlaneSide::Cross,
            (true, false) => PlaneSide::Front,
            (false, true) => PlaneSide::Back,
            (false, false) => PlaneSide::On,
        }
    }
}

impl Plane {
    /// The plane `normal · p = dist`; `normal` must already be unit length.
    pub fn new(normal: DVec3, dist: f64) -> Self {
        Plane { normal, dist }
    }

    /// The plane through three points, facing so that `a, b, c` wind clockwise seen from the
    /// front (Quake's `.map` convention). `None` when the points are collinear.
    pub fn from_points(a: DVec3, b: DVec3, c: DVec3) -> Option<Plane> {
        let normal = (a - b).cross(c - b).normalized()?;
        Some(Plane::new(normal, normal.dot(b)))
    }

    /// Signed distance of `p` from the plane: positive in front.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.dist
    }

    /// The same plane facing the other way.
    pub fn flipped(&self) -> Plane {
        Plane::new(-self.normal, -self.dist)
    }

    /// Which side `p` is on ([`PlaneSide::Front`], [`PlaneSide::Back`] or [`PlaneSide::On`]).
    pub fn side_of_point(&self, p: DVec3) -> PlaneSide {
        PlaneSide::of_distance(self.distance(p))
    }

    /// Same plane (same facing) within the plane epsilons.
    pub fn same_as(&self, o: &Plane) -> bool {
        self.normal.near(o.normal, NORMAL_EPSILON) && (self.dist - o.dist).abs() < DIST_EPSILON
    }

    /// The axis (0, 1, 2) the normal lies along, within [`NORMAL_EPSILON`] per component: the
    /// same normal as the axis's, as [`Plane::same_as`] compares them. (A test on the axis
    /// component alone, `1 - |n_i| < NORMAL_EPSILON`, would take normals up to 1.4e-3 rad off the
    /// axis, and engines evaluate an axial plane by that one coordinate: such a plane would
    /// turn about the origin, 0.14 units at 100 units out.)
    pub fn axial(&self) -> Option<usize> {
        (0..3).find(|&i| {
            let mut axis = DVec3::ZERO;
            axis[i] = self.normal[i].signum();
            self.normal.near(axis, NORMAL_EPSILON)
        })
    }

    /// `normal` moved onto the axis it lies along ([`Plane::axial`]), or unchanged.
    pub fn snap_normal(normal: DVec3) -> DVec3 {
        match Plane::new(normal, 0.0).axial() {
            Some(i) => {
                let mut axis = DVec3::ZERO;
                axis[i] = normal[i].signum();
                axis
            }
            None => normal,
        }
    }

    /// Quake's plane type: 0..2 axial X/Y/Z, 3..5 mostly X/Y/Z.
    pub fn quake_type(&self) -> i32 {
        if let Some(axis) = self.axial() {
            return axis as i32;
        }
        let a = [
            self.normal.x.abs(),
            self.normal.y.abs(),
            self.normal.z.abs(),
        ];
        if a[0] >= a[1] && a[0] >= a[2] {
            3
        } else if a[1] >= a[0] && a[1] >= a[2] {
            4
        } else {
            5
        }
    }

    /// Snap an axial normal ([`Plane::axial`]) onto its axis, turning the plane about `on` (a
    /// point on it, which stays on it: the plane moves least where it matters), and round a
    /// distance near an integer, so that planes written from integer brush points compare equal.
    pub fn snapped(&self, on: DVec3) -> Plane {
        let normal = Plane::snap_normal(self.normal);
        let mut dist = if normal == self.normal {
            self.dist
        } else {
            normal.dot(on)
        };
        if (dist - dist.round()).abs() < DIST_EPSILON {
            dist = dist.round();
        }
        Plane::new(normal, dist)
    }

    /// Whether the normal and distance hold no NaN or infinity.
    pub fn is_finite(&self) -> bool {
        self.normal.is_finite() && self.dist.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_points_follows_quake_winding() {
        // A floor at z=0 listed as in .map files: normal points up.
        let p = Plane::from_points(
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
        )
        .expect("plane");
        assert!(p.normal.near(DVec3::new(0.0, 0.0, 1.0), 1e-12));
        assert_eq!(p.dist, 0.0);
        assert_eq!(p.quake_type(), 2);
    }

    #[test]
    fn a_normal_a_thousandth_of_a_radian_off_an_axis_is_not_axial() {
        // The edge bevel of a sheared block (generated seed 1007): 0.136 units of lean over
        // 210.8 of height. Taken as axial, snapping and the engines' one-coordinate test of an
        // axial plane flattened it onto the block's axial bevel, and the player hull stopped up
        // to 0.165 units short of the block.
        let n = DVec3::new(0.0, -210.7974, 0.1364).normalized().expect("n");
        assert!(
            (1.0 - n.y.abs()) < NORMAL_EPSILON,
            "the axis component alone looks axial"
        );
        let bevel = Plane::new(n, n.dot(DVec3::new(183.1036, 148.8576, 0.0)));
        assert_eq!(bevel.axial(), None);
        assert_eq!(bevel.quake_type(), 4);
        assert_eq!(bevel.snapped(DVec3::new(183.1036, 148.8576, 0.0)), bevel);
    }

    #[test]
    fn snapping_turns_the_plane_about_the_given_point() {
        // A wall 5e-7 rad off the x axis is axial; snapped, it turns about the point given (on
        // its face, 10000 units out): keeping its distance would move it 0.005 units there.
        let n = DVec3::new(1.0, 5e-7, 0.0).normalized().expect("n");
        let on = DVec3::new(64.0, 10000.0, 0.0);
        let wall = Plane::new(n, n.dot(on));
        assert_eq!(wall.axial(), Some(0));
        let snapped = wall.snapped(on);
        assert_eq!(snapped.normal, DVec3::X);
        assert_eq!(snapped.dist, 64.0);
        assert_eq!(snapped.quake_type(), 0);
    }

    #[test]
    fn collinear_points_have_no_plane() {
        let a = DVec3::new(0.0, 0.0, 0.0);
        assert!(
            Plane::from_points(a, DVec3::new(1.0, 1.0, 1.0), DVec3::new(2.0, 2.0, 2.0)).is_none()
        );
    }
}
