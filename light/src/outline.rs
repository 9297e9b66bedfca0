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
    /// Per edge, from each corner to the next.
    lines: Vec<EdgeLine>,
    /// The mean of the corners.
    centre: DVec3,
}

/// One edge of a [`FaceRegion`].
#[derive(Debug, Clone, Copy)]
struct EdgeLine {
    /// Where it starts.
    start: DVec3,
    /// Unit in-plane normal pointing inside.
    inward: DVec3,
    /// The step to its end, and the step's squared length.
    step: DVec3,
    len2: f64,
}

impl EdgeLine {
    /// Inward distance of `p` from the edge's line.
    fn distance(&self, p: DVec3) -> f64 {
        self.inward.dot(p - self.start)
    }
}

/// The edges of a region a question looks at: all of them, or the ones a disc comes near
/// ([`FaceRegion::edges_near_disc`], in order) when asked about a point of the disc.
#[derive(Debug, Clone, Copy)]
pub enum Edges<'a> {
    All,
    Near(&'a [usize]),
}

/// How far past an edge (units) a sample point still counts as inside its face and stays where
/// the grid puts it, as ericw-tools counts it (its `POINT_EQUAL_EPSILON`).
pub const INSIDE_SLACK: f64 = 0.05;

/// Room (units) [`FaceRegion::edges_near_disc`] leaves for rounding: the points it vouches for
/// are computed apart from the disc's centre, each edge distance rounded on its own, at map
/// coordinates where that rounding is below a billionth of a unit.
const DISC_MARGIN: f64 = 1e-6;

impl FaceRegion {
    pub fn from_points(points: Vec<DVec3>, normal: DVec3) -> FaceRegion {
        let centre = points.iter().fold(DVec3::ZERO, |a, &p| a + p) / points.len().max(1) as f64;
        let lines = (0..points.len())
            .map(|i| {
                let (a, b) = (points[i], points[(i + 1) % points.len()]);
                let m = normal.cross(b - a).normalized().unwrap_or(DVec3::ZERO);
                EdgeLine {
                    start: a,
                    inward: if m.dot(centre - a) < 0.0 { -m } else { m },
                    step: b - a,
                    len2: (b - a).dot(b - a),
                }
            })
            .collect();
        FaceRegion { lines, centre }
    }

    /// Mean of the corners (inside: the region is convex).
    pub fn centre(&self) -> DVec3 {
        self.centre
    }

    /// For `p` (a point on the face's plane) inside the region, on its edge or less than
    /// [`INSIDE_SLACK`] past it: whether it lies on the outline ([`FaceRegion::on_edge`]);
    /// `None` for any other point, which [`FaceRegion::nearest`] moves. Of a point of a disc,
    /// the edges the disc comes near give the answer: every other edge holds the disc's points
    /// inside and off the outline.
    pub fn inside_on_edge(&self, p: DVec3, edges: Edges) -> Option<bool> {
        match edges {
            Edges::All => inside_on_edge(p, self.lines.iter().enumerate()),
            Edges::Near(near) => inside_on_edge(p, self.numbered(near)),
        }
    }

    /// The lines of edges `near`, with their numbers.
    fn numbered<'s>(&'s self, near: &'s [usize]) -> impl Iterator<Item = (usize, &'s EdgeLine)> {
        near.iter().filter_map(|&k| Some((k, self.lines.get(k)?)))
    }

    /// Into `near`, the edges that may have a point of the plane within `radius` of `p` (a
    /// point on the face's plane) on, outside or less than [`INSIDE_SLACK`] inside them: each
    /// other edge holds every such point inside and off it, as
    /// [`FaceRegion::inside_on_edge`] measures, and is none that
    /// [`FaceRegion::edge_to_cross`] picks or [`FaceRegion::nearest_on_edge`] moves it onto.
    /// Conservative: `p`'s distance from an edge is held a margin above, for the rounding of
    /// the points' own tests. No edge near: the region holds the disc.
    pub fn edges_near_disc(&self, p: DVec3, radius: f64, near: &mut Vec<usize>) {
        // A point of the disc lies at most `radius` nearer an edge than `p`: it must still be
        // INSIDE_SLACK in (so not crossed) and off the outline.
        let clear = radius + INSIDE_SLACK.max(ON_EDGE) + DISC_MARGIN;
        near.clear();
        // A NaN distance (a broken face) counts as near: its points' own tests decide.
        let is_near = |line: &EdgeLine| {
            let d = line.distance(p);
            d.is_nan() || d <= clear
        };
        let lines = self.lines.iter().enumerate();
        near.extend(lines.filter(|(_, line)| is_near(line)).map(|(k, _)| k));
    }

    /// Whether `p` (a point of the region) lies on its outline (within [`ON_EDGE`]).
    pub fn on_edge(&self, p: DVec3) -> bool {
        self.lines.iter().any(|line| line.distance(p) < ON_EDGE)
    }

    /// `p` (a point on the face's plane) if it is inside, else the nearest
    /// point of the region's outline. Only edges `p` is outside of can hold
    /// that point (or end in it): the region is convex.
    #[cfg(test)]
    pub fn nearest(&self, p: DVec3) -> DVec3 {
        self.nearest_on_edge(p, Edges::All).0
    }

    /// The edge a point `p` past the region (on its plane) crosses to the face beyond, as
    /// ericw-tools picks it: of the edges `p` lies behind (or less than [`INSIDE_SLACK`] in front
    /// of), the one it lies least far past the ends of, measured from the edge's first corner
    /// when past its second (ericw-tools' measure); the first such edge on a tie. Degenerate
    /// edges are passed over. Of a point of a disc, only the edges the disc comes near can be
    /// picked.
    pub fn edge_to_cross(&self, p: DVec3, edges: Edges) -> Option<usize> {
        match edges {
            Edges::All => edge_to_cross(p, self.lines.iter().enumerate()),
            Edges::Near(near) => edge_to_cross(p, self.numbered(near)),
        }
    }

    /// Inward distance of `p` from edge `edge`'s line.
    pub fn distance(&self, edge: usize, p: DVec3) -> f64 {
        self.lines
            .get(edge)
            .map_or(f64::NAN, |line| line.distance(p))
    }

    /// [`FaceRegion::nearest`], and the edge it lies on when `p` moved. Of a point of a disc,
    /// only the edges the disc comes near can hold that point.
    pub fn nearest_on_edge(&self, p: DVec3, edges: Edges) -> (DVec3, Option<usize>) {
        match edges {
            Edges::All => nearest_on_edge(p, self.lines.iter().enumerate()),
            Edges::Near(near) => nearest_on_edge(p, self.numbered(near)),
        }
    }
}

/// [`FaceRegion::inside_on_edge`] over `lines`.
fn inside_on_edge<'a>(
    p: DVec3,
    lines: impl Iterator<Item = (usize, &'a EdgeLine)>,
) -> Option<bool> {
    let mut nearest = f64::INFINITY;
    for (_, line) in lines {
        let d = line.distance(p);
        if d.is_nan() || d < -INSIDE_SLACK {
            return None;
        }
        // Neither is a NaN: a plain comparison is `min`.
        if d < nearest {
            nearest = d;
        }
    }
    Some(nearest < ON_EDGE)
}

/// [`FaceRegion::edge_to_cross`] over `lines`.
fn edge_to_cross<'a>(
    p: DVec3,
    lines: impl Iterator<Item = (usize, &'a EdgeLine)>,
) -> Option<usize> {
    let mut best = None;
    let mut best_past = f64::INFINITY;
    for (edge, line) in lines {
        let (ap, m, ab, len2) = (p - line.start, line.inward, line.step, line.len2);
        if m.dot(ap) >= INSIDE_SLACK || m == DVec3::ZERO || len2 <= 0.0 {
            continue;
        }
        let t = ap.dot(ab) / len2;
        if (0.0..=1.0).contains(&t) {
            // Beside the edge: no other can come out nearer, and the first such one wins.
            return Some(edge);
        }
        let past = t.abs() * len2.sqrt();
        if past < best_past {
            best_past = past;
            best = Some(edge);
        }
    }
    best
}

/// [`FaceRegion::nearest_on_edge`] over `lines`.
fn nearest_on_edge<'a>(
    p: DVec3,
    lines: impl Iterator<Item = (usize, &'a EdgeLine)>,
) -> (DVec3, Option<usize>) {
    let mut best = p;
    let mut best_edge = None;
    let mut best_d2 = f64::INFINITY;
    for (edge, line) in lines {
        let (a, ab, len2) = (line.start, line.step, line.len2);
        if line.distance(p) >= 0.0 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The nearest point of any edge of `region` to `p`, every edge looked at.
    fn nearest_of_every_edge(region: &FaceRegion, p: DVec3) -> DVec3 {
        (region.lines.iter())
            .map(|line| {
                let (a, ab) = (line.start, line.step);
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

    /// The rectangle (0, 0)-(40, 10) on the plane z = 64, its corners counter-clockwise from
    /// the origin: edge 0 along the bottom, 1 up the right side, 2 along the top, 3 down the
    /// left side.
    fn strip() -> FaceRegion {
        let corners = [(0.0, 0.0), (40.0, 0.0), (40.0, 10.0), (0.0, 10.0)];
        let points = corners.map(|(x, y)| DVec3::new(x, y, 64.0)).to_vec();
        FaceRegion::from_points(points, DVec3::Z)
    }

    /// A point less than ericw-tools' `POINT_EQUAL_EPSILON` past an edge stays where it is,
    /// on the edge; one farther past is moved.
    #[test]
    fn a_point_just_past_an_edge_counts_as_inside_on_the_edge() {
        let region = strip();
        assert_eq!(
            region.inside_on_edge(DVec3::new(20.0, -0.04, 64.0), Edges::All),
            Some(true)
        );
        assert_eq!(
            region.inside_on_edge(DVec3::new(20.0, -0.06, 64.0), Edges::All),
            None
        );
        assert_eq!(
            region.inside_on_edge(DVec3::new(20.0, 5.0, 64.0), Edges::All),
            Some(false)
        );
    }

    /// A point past a corner crosses the edge it lies least far past the ends of, measured as
    /// ericw-tools measures it: from the edge's first corner when it lies past the second. Past
    /// the top right corner at (45, 11) that is the top edge (5 units before its first corner),
    /// not the right side (1 unit past its end, but 11 from its first corner).
    #[test]
    fn the_edge_crossed_is_the_one_least_past_its_ends_as_ericw_tools_measures() {
        let region = strip();
        assert_eq!(
            region.edge_to_cross(DVec3::new(20.0, -3.0, 64.0), Edges::All),
            Some(0)
        );
        assert_eq!(
            region.edge_to_cross(DVec3::new(45.0, 11.0, 64.0), Edges::All),
            Some(2)
        );
        assert_eq!(
            region.edge_to_cross(DVec3::new(45.0, -1.0, 64.0), Edges::All),
            Some(1)
        );
        assert_eq!(
            region.edge_to_cross(DVec3::new(20.0, 5.0, 64.0), Edges::All),
            None
        );
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
            let inside = (0..region.lines.len()).all(|k| region.distance(k, p) >= 0.0);
            let got = region.nearest(p);
            if inside {
                prop_assert_eq!(got, p);
            } else {
                let want = nearest_of_every_edge(&region, p);
                prop_assert!(((p - got).length() - (p - want).length()).abs() < 1e-9);
            }
        }

        /// For every point within the radius of a disc, the edges the disc comes near give the
        /// answers all the edges give (inside or not, the edge crossed, the nearest point of
        /// the outline), edges barely far from it too.
        #[test]
        fn the_edges_near_a_disc_judge_its_points_as_all_edges_do(
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
            // Radii at which one edge is only just far, or a little less than INSIDE_SLACK
            // from being so, within a rounding.
            let barely = (0..region.lines.len()).flat_map(|k| {
                let d = region.distance(k, centre) - DISC_MARGIN * 1.5;
                [d - INSIDE_SLACK, d - ON_EDGE]
            });
            let mut near = Vec::new();
            for r in std::iter::once(disc).chain(barely).filter(|&r| r >= 0.0) {
                region.edges_near_disc(centre, r, &mut near);
                // Points at random in the disc, and the ones of its rim nearest each edge.
                let random = at.iter().map(|&(angle, along)| DVec3::new(angle.cos(), angle.sin(), 0.0) * along);
                let nearest = region.lines.iter().map(|line| -line.inward);
                for step in random.chain(nearest) {
                    let p = centre + step * r;
                    prop_assert_eq!(
                        region.inside_on_edge(p, Edges::Near(&near)),
                        region.inside_on_edge(p, Edges::All)
                    );
                    prop_assert_eq!(
                        region.edge_to_cross(p, Edges::Near(&near)),
                        region.edge_to_cross(p, Edges::All)
                    );
                    prop_assert_eq!(
                        region.nearest_on_edge(p, Edges::Near(&near)),
                        region.nearest_on_edge(p, Edges::All)
                    );
                }
            }
        }
    }
}
