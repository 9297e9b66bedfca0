//! The corners of each luxel's samples, for shadow rays on supersampled faces.
//!
//! A point light's shadow on a plane is bounded by straight lines (the outlines of occluders,
//! projected from the light). If every corner of the convex hull of a luxel's samples is
//! lit, no such line crosses the hull, so every sample inside it is lit too; likewise when
//! every corner is blocked by one straight-edged shadow. Only a shadow narrower than the hull
//! (a thin bar, the tip of a wedge) can slip between the corners. [`LuxelHulls`] finds, once
//! per face and only for the luxels that ask, which samples are corners and which lie inside.
//!
//! Only samples in the plane the face's grid samples lie in (its plane, lifted by
//! [`crate::samples::SURFACE_OFFSET`]) take part: a sample nudged off it out of solid, or an
//! occluded one, is neither a corner nor inside, and is always traced.

use glam::DVec3;

use crate::samples::FaceSamples;

/// How far (units) a sample may lie from the plane of the grid's samples and still count as in
/// it: f32 coordinates of a few thousand units carry about a thousandth.
const IN_PLANE: f64 = 0.01;

/// A turn of three hull points this small (the cross product of their steps, in square units)
/// counts as straight on: the middle point is left out of the corners. Sample spacings are a
/// unit or more, so real turns are far larger.
const STRAIGHT: f64 = 1e-6;

/// A luxel whose hull is not worked out yet.
const NOT_YET: u32 = u32::MAX;

/// Per luxel of one face: the sub-samples at the corners of its samples' hull.
#[derive(Debug, Default)]
pub struct LuxelHulls {
    /// Per luxel: where its corners start in `corners` (`NOT_YET` until asked), and how many.
    start: Vec<u32>,
    count: Vec<u8>,
    /// Sub-sample indices (within the luxel) of every asked luxel's corners.
    corners: Vec<u8>,
    /// Per luxel, a bit a sample: in the plane, inside the hull (on an edge included), not a
    /// corner.
    inside: Vec<u64>,
    /// The grid samples' plane (normal, distance) and the two coordinates its points are told
    /// apart by; `None` when the face has no sample on the grid to find it from (then no luxel
    /// has corners).
    plane: Option<(DVec3, f64, [usize; 2])>,
    /// Scratch: one luxel's samples in the plane, as (u, v, sub-sample).
    points: Vec<(f64, f64, u8)>,
    hull: Vec<(f64, f64, u8)>,
}

impl LuxelHulls {
    /// Ready for `samples`' face: no luxel asked yet.
    pub fn start_face(&mut self, samples: &FaceSamples) {
        let luxels = samples.luxels();
        self.start.clear();
        self.start.resize(luxels, NOT_YET);
        self.count.clear();
        self.count.resize(luxels, 0);
        self.corners.clear();
        self.inside.clear();
        self.inside.resize(luxels, 0);
        let normal = samples.normal;
        self.plane = samples.moved.iter().position(|&m| !m).map(|i| {
            let distance = normal.dot(point(samples, i));
            // Dropping the normal's largest coordinate maps the plane onto the other two
            // without folding it, and keeps hulls hulls.
            let drop = normal.abs().max_position();
            let axes = [(drop + 1) % 3, (drop + 2) % 3];
            (normal, distance, axes)
        });
    }

    /// Works out `luxel`'s hull, the first time it is asked for; `on_grid`: all its samples
    /// lie on the grid, in the open.
    pub fn ask(&mut self, samples: &FaceSamples, luxel: usize, on_grid: bool) {
        if self.start[luxel] == NOT_YET {
            self.work_out(samples, luxel, on_grid);
        }
    }

    /// The sub-samples at the corners of asked `luxel`'s hull (none when the face has no plane
    /// to work in).
    pub fn corners(&self, luxel: usize) -> &[u8] {
        let start = self.start[luxel] as usize;
        &self.corners[start..start + usize::from(self.count[luxel])]
    }

    /// The samples inside asked `luxel`'s hull, a bit each.
    pub fn inside(&self, luxel: usize) -> u64 {
        self.inside[luxel]
    }

    fn work_out(&mut self, samples: &FaceSamples, luxel: usize, on_grid: bool) {
        let per = samples.per_luxel();
        let first = luxel * per;
        let start = self.corners.len();
        let Some((normal, distance, axes)) = self.plane else {
            self.start[luxel] = start as u32;
            return;
        };
        if on_grid {
            // A square grid: its four corners.
            let axis = samples.per_axis;
            let square = [0, axis - 1, axis * (axis - 1), per - 1];
            self.corners.extend(square.map(|k| k as u8));
            self.inside[luxel] = square
                .iter()
                .fold(every_sample(per), |bits, &k| bits & !(1 << k));
        } else {
            let [a, b] = axes;
            let occluded = |i: usize| samples.occluded.get(i).copied().unwrap_or(false);
            self.points.clear();
            // Samples moved onto an edge often land together, one after another: a repeat of
            // the last point is inside whatever the hull (it has that point's answer).
            let mut repeats = 0u64;
            let mut last = None;
            for k in 0..per {
                let i = first + k;
                let p = samples.points[i];
                // Samples on the grid lie in the plane; a moved one may have left it.
                let in_plane = !samples.moved[i]
                    || (normal.dot(point(samples, i)) - distance).abs() <= IN_PLANE;
                if !in_plane || occluded(i) {
                    continue;
                }
                if last == Some(p) {
                    repeats |= 1 << k;
                    continue;
                }
                last = Some(p);
                self.points
                    .push((f64::from(p[a]), f64::from(p[b]), k as u8));
            }
            convex_hull(&mut self.points, &mut self.hull);
            self.corners.extend(self.hull.iter().map(|&(_, _, k)| k));
            let bits = |points: &[(f64, f64, u8)]| points.iter().fold(0u64, |b, p| b | 1 << p.2);
            self.inside[luxel] = (bits(&self.points) | repeats) & !bits(&self.hull);
        }
        self.start[luxel] = start as u32;
        self.count[luxel] = (self.corners.len() - start) as u8;
    }
}

/// One bit for each of a luxel's `per` samples (at most 64).
pub(super) fn every_sample(per: usize) -> u64 {
    u64::MAX >> (64 - per)
}

fn point(samples: &FaceSamples, i: usize) -> DVec3 {
    glam::Vec3::from(samples.points[i]).as_dvec3()
}

/// The corners of the convex hull of `points` into `hull` (Andrew's monotone chain): points
/// on an edge, and repeats of a corner, are left out. Sorts `points`.
fn convex_hull(points: &mut [(f64, f64, u8)], hull: &mut Vec<(f64, f64, u8)>) {
    hull.clear();
    // By x, then y: an insertion sort, as a luxel has a few samples, often in order already
    // (coordinates are finite: sample points).
    for j in 1..points.len() {
        let p = points[j];
        let mut k = j;
        while k > 0 && (points[k - 1].0, points[k - 1].1) > (p.0, p.1) {
            points[k] = points[k - 1];
            k -= 1;
        }
        points[k] = p;
    }
    let same = |p: &(f64, f64, u8), q: &(f64, f64, u8)| (p.0, p.1) == (q.0, q.1);
    if points.windows(2).all(|w| same(&w[0], &w[1])) {
        hull.extend(points.first().copied());
        return;
    }
    let turn = |o: (f64, f64, u8), a: (f64, f64, u8), b: (f64, f64, u8)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    // Lower chain left to right, then upper chain right to left.
    for &p in points.iter() {
        if hull.last().is_some_and(|q| same(q, &p)) {
            continue;
        }
        while hull.len() >= 2 && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= STRAIGHT {
            hull.pop();
        }
        hull.push(p);
    }
    let upper_start = hull.len();
    for &p in points.iter().rev().skip(1) {
        if hull.last().is_some_and(|q| same(q, &p)) {
            continue;
        }
        while hull.len() > upper_start
            && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= STRAIGHT
        {
            hull.pop();
        }
        hull.push(p);
    }
    // The last point pushed is the first again.
    hull.pop();
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A floor face one luxel across (16 units) at `per_axis`² samples, one unit above z = 0:
    /// samples with x past `edge` are moved onto the line x = `edge`, as light places those
    /// of a luxel overhanging the face's edge.
    pub(in crate::trace) fn luxel_over_edge(per_axis: usize, edge: f32) -> FaceSamples {
        let step = 16.0 / per_axis as f32;
        let mut points = Vec::new();
        let mut moved = Vec::new();
        for y in 0..per_axis {
            for x in 0..per_axis {
                let at = [(x as f32 + 0.5) * step, (y as f32 + 0.5) * step, 1.0];
                moved.push(at[0] > edge);
                points.push([at[0].min(edge), at[1], at[2]]);
            }
        }
        let n = points.len();
        FaceSamples {
            face: 0,
            width: 1,
            height: 1,
            per_axis,
            normal: DVec3::Z,
            points,
            normals: Vec::new(),
            two_sided: false,
            moved,
            apart: vec![false; n],
            occluded: Vec::new(),
            landed: Vec::new(),
        }
    }

    fn asked(samples: &FaceSamples) -> (Vec<u8>, Vec<bool>) {
        let mut hulls = LuxelHulls::default();
        hulls.start_face(samples);
        let on_grid = samples.moved.iter().all(|&m| !m) && !samples.occluded.contains(&true);
        hulls.ask(samples, 0, on_grid);
        let mut corners = hulls.corners(0).to_vec();
        corners.sort_unstable();
        let inside = (0..samples.points.len())
            .map(|k| hulls.inside(0) >> k & 1 != 0)
            .collect();
        (corners, inside)
    }

    #[test]
    fn a_luxel_on_the_grid_has_the_four_corners_of_its_square() {
        let (corners, inside) = asked(&luxel_over_edge(4, 100.0));
        assert_eq!(corners, [0, 3, 12, 15]);
        assert_eq!(inside.iter().filter(|&&i| i).count(), 12);
    }

    #[test]
    fn samples_moved_onto_an_edge_are_corners_only_at_its_ends() {
        // Columns at x = 2, 6, 10, 14; the last two moved onto x = 8.
        let samples = luxel_over_edge(4, 8.0);
        let (corners, inside) = asked(&samples);
        // The hull: x = 2 and x = 8 (where two moved samples land together), at y = 2 and 14.
        assert_eq!(corners.len(), 4, "{corners:?}");
        for &k in &corners {
            let [x, y, _] = samples.points[usize::from(k)];
            assert!(x == 2.0 || x == 8.0, "{x}");
            assert!(y == 2.0 || y == 14.0, "{y}");
        }
        assert_eq!(inside.iter().filter(|&&i| i).count(), 12);
    }

    #[test]
    fn samples_off_the_plane_or_occluded_are_neither_corners_nor_inside() {
        let mut samples = luxel_over_edge(4, 100.0);
        // Nudged up out of solid, and one in solid.
        samples.points[5][2] += 0.5;
        samples.moved[5] = true;
        samples.occluded = vec![false; 16];
        samples.occluded[0] = true;
        let (corners, inside) = asked(&samples);
        assert!(!corners.contains(&5) && !inside[5]);
        assert!(!corners.contains(&0) && !inside[0]);
        // Sample 0's corner is cut off: 1 and 4 take its place.
        assert_eq!(corners, [1, 3, 4, 12, 15]);
    }

    #[test]
    fn a_face_without_samples_on_the_grid_has_no_corners() {
        let mut samples = luxel_over_edge(4, 100.0);
        samples.moved = vec![true; 16];
        let (corners, inside) = asked(&samples);
        assert!(corners.is_empty());
        assert!(!inside.contains(&true));
    }

    proptest! {
        /// Every point is a corner or lies in the hull (on an edge included); corners turn
        /// one way, each by more than the straight-on margin, and appear once.
        #[test]
        fn the_hull_holds_every_point(
            cells in prop::collection::vec((0u8..5, 0u8..5), 1..20),
        ) {
            let mut points: Vec<(f64, f64, u8)> = cells
                .iter()
                .enumerate()
                .map(|(k, &(x, y))| (f64::from(x) * 4.0, f64::from(y) * 4.0, k as u8))
                .collect();
            let mut hull = Vec::new();
            convex_hull(&mut points, &mut hull);
            prop_assert!(!hull.is_empty());
            let turn = |o: (f64, f64, u8), a: (f64, f64, u8), b: (f64, f64, u8)| {
                (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
            };
            let n = hull.len();
            if n >= 3 {
                for k in 0..n {
                    prop_assert!(turn(hull[k], hull[(k + 1) % n], hull[(k + 2) % n]) > 0.0);
                }
            }
            for &p in &points {
                if n >= 3 {
                    for k in 0..n {
                        prop_assert!(turn(hull[k], hull[(k + 1) % n], p) >= 0.0);
                    }
                } else if n == 2 {
                    prop_assert!(turn(hull[0], hull[1], p) == 0.0);
                } else {
                    prop_assert!((p.0, p.1) == (hull[0].0, hull[0].1));
                }
            }
            for (k, c) in hull.iter().enumerate() {
                prop_assert!(hull[k + 1..].iter().all(|d| (d.0, d.1) != (c.0, c.1)));
            }
        }
    }
}
