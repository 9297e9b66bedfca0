use super::{DIST_EPSILON, NORMAL_EPSILON, ON_EPSILON};
use crate::geom::DVec3Ext;
use glam::DVec3;

/// A plane `normal · p = dist` with a unit normal; the front side is where the normal points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    pub normal: DVec3,
    pub dist: f64,
}

/// Where something lies relative to a plane, within [`ON_EPSILON`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlaneSide {
    Front,
    Back,
    On,
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
}

impl Plane {
    pub fn new(normal: DVec3, dist: f64) -> Self {
        Plane { normal, dist }
    }

    /// The plane through three points, facing so that `a, b, c` wind clockwise seen from the
    /// front (Quake's `.map` convention). `None` when the points are collinear.
    pub fn from_points(a: DVec3, b: DVec3, c: DVec3) -> Option<Plane> {
        let normal = (a - b).cross(c - b).normalized()?;
        Some(Plane::new(normal, normal.dot(b)))
    }

    pub fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.dist
    }

    pub fn flipped(&self) -> Plane {
        Plane::new(-self.normal, -self.dist)
    }

    pub fn side_of_point(&self, p: DVec3) -> PlaneSide {
        PlaneSide::of_distance(self.distance(p))
    }

    /// Same plane (same facing) within the plane epsilons.
    pub fn same_as(&self, o: &Plane) -> bool {
        self.normal.near(o.normal, NORMAL_EPSILON) && (self.dist - o.dist).abs() < DIST_EPSILON
    }

    /// The axis (0, 1, 2) the normal is exactly aligned with, if any.
    pub fn axial(&self) -> Option<usize> {
        (0..3).find(|&i| (self.normal[i].abs() - 1.0).abs() < NORMAL_EPSILON)
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

    /// Snap near-axial normals to the axis and round distances near integers, so that planes
    /// written from integer brush points compare equal. Returns the snapped plane.
    pub fn snapped(&self) -> Plane {
        let mut normal = self.normal;
        for i in 0..3 {
            if (normal[i].abs() - 1.0).abs() < NORMAL_EPSILON {
                normal = DVec3::ZERO;
                normal[i] = self.normal[i].signum();
                break;
            }
        }
        let mut dist = self.dist;
        if (dist - dist.round()).abs() < DIST_EPSILON {
            dist = dist.round();
        }
        Plane::new(normal, dist)
    }

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
    fn collinear_points_have_no_plane() {
        let a = DVec3::new(0.0, 0.0, 0.0);
        assert!(
            Plane::from_points(a, DVec3::new(1.0, 1.0, 1.0), DVec3::new(2.0, 2.0, 2.0)).is_none()
        );
    }
}
