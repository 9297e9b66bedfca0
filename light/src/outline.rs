//! A face's outline as half-planes: whether a point of its plane lies inside, on the edge or
//! outside, and the nearest point of the outline to one outside. Sample placement
//! ([`crate::samples`]) asks these of a face and of the faces continuing it.

use glam::DVec3;
use quake_formats::geom::DVec3Ext;

/// How near a face's edge (units) a sample point lies on it: a point moved onto the edge,
/// or one the grid puts there, where a wall standing on the face begins.
pub const ON_EDGE: f64 = 1e-3;

/// A convex face polygon as half-planes: a point is inside when it is in
/// front of every edge's inward plane.
#[derive(Debug, Clone)]
pub struct FaceRegion {
    pub points: Vec<DVec3>,
    /// Per edge (from `points[i]` to the next): unit in-plane normal pointing inside.
    inward: Vec<DVec3>,
    /// Per edge: the step from `points[i]` to the next and its squared length.
    edges: Vec<(DVec3, f64)>,
    /// The mean of the corners, and the square of a distance from it past which no point is
    /// [`FaceRegion::contains`]'s (infinite when the corners' angles are too sharp to say).
    centre: DVec3,
    reach2: f64,
}

/// How far outside an edge (units) a point still counts as inside ([`FaceRegion::contains`]).
const CONTAINS_SLACK: f64 = 1e-6;

/// Room (units) [`FaceRegion::holds_disc`] leaves for rounding: the points it vouches for are
/// computed apart from the disc's centre, each edge distance rounded on its own, at map
/// coordinates where that rounding is below a billionth of a unit.
const DISC_MARGIN: f64 = 1e-6;

/// The square of a distance from `centre` beyond which no point is within [`CONTAINS_SLACK`]
/// (and the rounding of the edge test) of every edge's inner side: the farthest corner, plus
/// how far pushing each edge out that much moves a corner (more at a sharper corner), plus room
/// for rounding. Infinite for a degenerate edge or a corner sharper than a thousandth of a
/// radian, where no such bound is worth having.
fn reach2(points: &[DVec3], inward: &[DVec3], centre: DVec3) -> f64 {
    let n = points.len();
    if n < 3 || inward.contains(&DVec3::ZERO) {
        return f64::INFINITY;
    }
    // The sharpest corner, by the square of half its angle's sine: at points[i], between edge
    // i - 1 and edge i.
    let mut sharpest2 = f64::INFINITY;
    for i in 0..n {
        let (before, after) = (inward[(i + n - 1) % n], inward[i]);
        sharpest2 = sharpest2.min((1.0 + before.dot(after)) / 2.0);
    }
    if sharpest2.is_nan() || sharpest2 <= 1e-6 {
        return f64::INFINITY;
    }
    let farthest2 = points
        .iter()
        .map(|p| p.distance_squared(centre))
        .fold(0.0, f64::max);
    let reach = farthest2.sqrt() + 2.0 * CONTAINS_SLACK / sharpest2.sqrt() + 1e-3;
    reach * reach
}

impl FaceRegion {
    pub fn from_points(points: Vec<DVec3>, normal: DVec3) -> FaceRegion {
        let centre = points.iter().fold(DVec3::ZERO, |a, &p| a + p) / points.len().max(1) as f64;
        let inward: Vec<DVec3> = (0..points.len())
            .map(|i| {
                let a = points[i];
                let b = points[(i + 1) % points.len()];
                let m = normal.cross(b - a).normalized().unwrap_or(DVec3::ZERO);
                if m.dot(centre - a) < 0.0 { -m } else { m }
            })
            .collect();
        let edges = (0..points.len())
            .map(|i| {
                let ab = points[(i + 1) % points.len()] - points[i];
                (ab, ab.dot(ab))
            })
            .collect();
        let reach2 = reach2(&points, &inward, centre);
        FaceRegion {
            points,
            inward,
            edges,
            centre,
            reach2,
        }
    }

    /// Mean of the corners (inside: the region is convex).
    pub fn centre(&self) -> DVec3 {
        self.centre
    }

    /// Whether `p` (a point on the face's plane) is inside the region or on its edge.
    pub fn contains(&self, p: DVec3) -> bool {
        // Far from the region, no edge need be looked at.
        p.distance_squared(self.centre) <= self.reach2
            && (self.points.iter().zip(&self.inward)).all(|(&a, m)| m.dot(p - a) >= -CONTAINS_SLACK)
    }

    /// For `p` (a point on the face's plane) inside the region or on its edge, no edge's
    /// inward distance negative: whether it lies on the outline ([`FaceRegion::on_edge`]);
    /// `None` for any other point, which [`FaceRegion::nearest`] moves.
    pub fn inside_on_edge(&self, p: DVec3) -> Option<bool> {
        let mut nearest = f64::INFINITY;
        for (&a, m) in self.points.iter().zip(&self.inward) {
            let d = m.dot(p - a);
            if d.is_nan() || d < 0.0 {
                return None;
            }
            // Neither is a NaN: a plain comparison is `min`.
            if d < nearest {
                nearest = d;
            }
        }
        Some(nearest < ON_EDGE)
    }

    /// Whether every point of the plane within `radius` of `p` (a point on the face's plane)
    /// is inside the region and off its outline: [`FaceRegion::inside_on_edge`] would say
    /// `Some(false)` of each. Conservative: `p`'s distances from the edges are held a margin
    /// above `radius`, for the rounding of the points' own tests.
    pub fn holds_disc(&self, p: DVec3, radius: f64) -> bool {
        let clear = radius + ON_EDGE + DISC_MARGIN;
        (self.points.iter().zip(&self.inward)).all(|(&a, m)| m.dot(p - a) > clear)
    }

    /// Whether `p` (a point of the region) lies on its outline (within [`ON_EDGE`]).
    pub fn on_edge(&self, p: DVec3) -> bool {
        (self.points.iter().zip(&self.inward)).any(|(&a, m)| m.dot(p - a) < ON_EDGE)
    }

    /// `p` (a point on the face's plane) if it is inside, else the nearest
    /// point of the region's outline. Only edges `p` is outside of can hold
    /// that point (or end in it): the region is convex.
    #[cfg(test)]
    pub fn nearest(&self, p: DVec3) -> DVec3 {
        self.nearest_on_edge(p).0
    }

    /// Inward distance of `p` from edge `edge`'s line.
    pub fn distance(&self, edge: usize, p: DVec3) -> f64 {
        self.inward[edge].dot(p - self.points[edge])
    }

    /// [`FaceRegion::nearest`], and the edge it lies on when `p` moved.
    pub fn nearest_on_edge(&self, p: DVec3) -> (DVec3, Option<usize>) {
        let mut best = p;
        let mut best_edge = None;
        let mut best_d2 = f64::INFINITY;
        let edges = self.points.iter().zip(&self.inward).zip(&self.edges);
        for (edge, ((&a, m), &(ab, len2))) in edges.enumerate() {
            if m.dot(p - a) >= 0.0 {
                continue;
            }
            let t = if len2 > 0.0 {
                ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let q = a + ab * t;
            let d = p - q;
            if d.dot(d) < best_d2 {
                best_d2 = d.dot(d);
                best = q;
                best_edge = Some(edge);
            }
        }
        (best, best_edge)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The nearest point of any edge of `region` to `p`, every edge looked at.
    fn nearest_of_every_edge(region: &FaceRegion, p: DVec3) -> DVec3 {
        let n = region.points.len();
        (0..n)
            .map(|i| {
                let (a, b) = (region.points[i], region.points[(i + 1) % n]);
                let ab = b - a;
                a + ab * ((p - a).dot(ab) / ab.dot(ab)).clamp(0.0, 1.0)
            })
            .min_by(|q, r| (p - *q).length().total_cmp(&(p - *r).length()))
            .unwrap_or(p)
    }

    /// A convex region on the plane z = 64: corners on a circle of `radius` at `angles`
    /// (radians), sorted and thinned to no two closer than `min_gap`; `None` when fewer than
    /// three remain.
    fn circle_region(mut angles: Vec<f64>, radius: f64, min_gap: f64) -> Option<FaceRegion> {
        angles.sort_by(f64::total_cmp);
        angles.dedup_by(|a, b| (*a - *b).abs() < min_gap);
        (angles.len() >= 3).then(|| {
            let points = angles
                .iter()
                .map(|a| DVec3::new(radius * a.cos(), radius * a.sin(), 64.0))
                .collect();
            FaceRegion::from_points(points, DVec3::Z)
        })
    }

    proptest! {
        /// Looking only at the edges a point is outside of finds the same nearest point.
        #[test]
        fn nearest_looks_only_at_edges_the_point_is_outside_of(
            angles in proptest::collection::vec(0.0f64..std::f64::consts::TAU, 3..9),
            radius in 1.0f64..500.0,
            x in -800.0f64..800.0,
            y in -800.0f64..800.0,
        ) {
            let region = circle_region(angles, radius, 0.05);
            prop_assume!(region.is_some());
            let region = region.expect("assumed");
            let p = DVec3::new(x, y, 64.0);
            let inside = (region.points.iter().zip(&region.inward)).all(|(&a, m)| m.dot(p - a) >= 0.0);
            let got = region.nearest(p);
            if inside {
                prop_assert_eq!(got, p);
            } else {
                let want = nearest_of_every_edge(&region, p);
                prop_assert!(((p - got).length() - (p - want).length()).abs() < 1e-9);
            }
        }

        /// The distance bound never turns away a point the edges take, near the outline too.
        #[test]
        fn contains_takes_what_every_edge_takes(
            angles in proptest::collection::vec(0.0f64..std::f64::consts::TAU, 3..9),
            radius in 1.0f64..500.0,
            x in -800.0f64..800.0,
            y in -800.0f64..800.0,
            toward in 0usize..9,
            nudge in -1e-5f64..1e-5,
        ) {
            let region = circle_region(angles, radius, 0.01);
            prop_assume!(region.is_some());
            let region = region.expect("assumed");
            // A point anywhere, and one just off a corner.
            let corner = region.points[toward % region.points.len()];
            for p in [DVec3::new(x, y, 64.0), corner + DVec3::new(nudge, -nudge, 0.0)] {
                let by_edges = (region.points.iter().zip(&region.inward))
                    .all(|(&a, m)| m.dot(p - a) >= -CONTAINS_SLACK);
                prop_assert_eq!(region.contains(p), by_edges);
            }
        }

        /// Every point within the radius of a disc the region holds is inside it and off its
        /// outline, by the test each sample point takes, discs barely held too.
        #[test]
        fn a_held_disc_holds_each_of_its_points(
            angles in proptest::collection::vec(0.0f64..std::f64::consts::TAU, 3..9),
            radius in 1.0f64..500.0,
            x in -400.0f64..400.0,
            y in -400.0f64..400.0,
            disc in 0.0f64..40.0,
            at in proptest::collection::vec((0.0f64..std::f64::consts::TAU, 0.0f64..=1.0), 16),
        ) {
            let region = circle_region(angles, radius, 0.05);
            prop_assume!(region.is_some());
            let region = region.expect("assumed");
            let centre = DVec3::new(x, y, 64.0);
            // The largest disc it holds, within a rounding: the nearest edge minus the margins.
            let nearest = (region.points.iter().zip(&region.inward))
                .map(|(&a, m)| m.dot(centre - a))
                .fold(f64::INFINITY, f64::min);
            for r in [disc, nearest - ON_EDGE - DISC_MARGIN * 1.5] {
                if r < 0.0 || !region.holds_disc(centre, r) {
                    continue;
                }
                for &(angle, along) in &at {
                    let p = centre + DVec3::new(angle.cos(), angle.sin(), 0.0) * r * along;
                    prop_assert_eq!(region.inside_on_edge(p), Some(false));
                }
            }
        }
    }
}
