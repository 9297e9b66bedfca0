//! The convex region of space a tree node stands for, kept as the polygons bounding it while the
//! tree is built. A node's plane must cross its region: otherwise one child is empty space
//! nothing reaches, and engines that rebuild portals from the tree (DarkPlaces) find no portal
//! between the children ("new portal was clipped away").

use glam::DVec3;
use quake_formats::bsp::DARKPLACES_PORTAL_EPSILON;
use quake_formats::geom::{Bounds, ON_EPSILON, Plane, Split, Winding};

/// How far inside a region's faces a node plane's cross-section must reach: DarkPlaces' portal
/// epsilon and a margin for the planes' rounding to `f32` (about 1/1000 unit at BSP29
/// coordinates).
const PORTAL_EPSILON: f64 = DARKPLACES_PORTAL_EPSILON + 1.0 / 128.0;
/// A part of a region is a sliver when nothing of it is left once shrunk by this from every face.
const SLIVER: f64 = 2.0 * DARKPLACES_PORTAL_EPSILON;
/// A region is a crack when nothing of it is left once shrunk by this: less than a unit thick
/// everywhere, too thin for anything but sealing to matter.
const CRACK: f64 = 0.5;

/// Where the sliver a plane cuts off a region lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sliver {
    Front,
    Back,
    /// The whole region is a crack.
    Crack,
}

/// One bounding polygon and the plane it lies on, facing out of the region.
#[derive(Debug, Clone)]
struct Face {
    outward: Plane,
    winding: Winding,
}

#[derive(Debug, Clone)]
pub(crate) struct Region {
    faces: Vec<Face>,
    bounds: Bounds,
}

impl Region {
    /// The box `bounds` grown by `margin` on every side.
    pub(crate) fn around(bounds: &Bounds, margin: f64) -> Region {
        let m = DVec3::new(margin, margin, margin);
        let (mins, maxs) = (bounds.mins - m, bounds.maxs + m);
        let mut planes = Vec::with_capacity(6);
        for axis in 0..3 {
            let mut n = DVec3::ZERO;
            n[axis] = 1.0;
            planes.push(Plane::new(n, maxs[axis]));
            planes.push(Plane::new(-n, -mins[axis]));
        }
        let faces = planes
            .iter()
            .filter_map(|&outward| {
                let winding = clip_inside(Winding::base_for_plane(&outward), &planes, &outward)?;
                Some(Face { outward, winding })
            })
            .collect();
        Region::with_faces(faces)
    }

    fn with_faces(faces: Vec<Face>) -> Region {
        let bounds = faces
            .iter()
            .fold(Bounds::EMPTY, |acc, f| acc.union(&f.winding.bounds()));
        Region { faces, bounds }
    }

    /// Whether some of the region lies in front of `plane`, and some behind, beyond
    /// [`ON_EPSILON`]: (true, true) when the plane crosses it.
    pub(crate) fn sides_of(&self, plane: &Plane) -> (bool, bool) {
        let n = plane.normal;
        let center = self.bounds.center();
        let half = self.bounds.maxs - center;
        let radius = half.x * n.x.abs() + half.y * n.y.abs() + half.z * n.z.abs();
        let d = plane.distance(center);
        if d - radius > -ON_EPSILON || d + radius < ON_EPSILON {
            return (d + radius > ON_EPSILON, d - radius < -ON_EPSILON);
        }
        let (mut front, mut back) = (false, false);
        for p in self.points() {
            let d = plane.distance(*p);
            front |= d > ON_EPSILON;
            back |= d < -ON_EPSILON;
            if front && back {
                break;
            }
        }
        (front, back)
    }

    /// The parts in front of and behind `plane` when it cuts the region cleanly, so that
    /// DarkPlaces keeps the portal it builds on the node's plane: when its cross-section of the
    /// region, shrunk by [`PORTAL_EPSILON`] from every face, is still a polygon. DarkPlaces clips
    /// the plane's polygon by the planes of the portals bounding the region, keeping the points
    /// within its epsilon outside a plane without cutting there (see
    /// [`quake_formats::bsp::darkplaces_divide`]); what lies that far inside every face survives
    /// in whatever order it clips. A plane that misses that (it crosses only a wedge near a face
    /// it almost lies on or near an edge, or a crack) could come out with fewer than three
    /// points: a node DarkPlaces finds no portal for.
    pub(crate) fn split_cleanly(&self, plane: &Plane) -> Option<[Region; 2]> {
        let cut = self.cross_section(plane)?;
        self.faces
            .iter()
            .try_fold(cut.clone(), |w, f| {
                let inner = Plane::new(f.outward.normal, f.outward.dist - PORTAL_EPSILON);
                w.into_front(&inner.flipped())
            })
            .filter(|w| !w.is_tiny())?;
        Some(self.parts(plane, cut))
    }

    /// For a plane that does not cut the region cleanly, the sliver it cuts off: the part with
    /// nothing left once shrunk by [`SLIVER`] (one part always is, as the cross-section is too
    /// thin: were both parts to hold a ball, the cross-section would hold one too); when both
    /// are that thin, the shallower. Unless the whole region is a crack.
    pub(crate) fn sliver(&self, plane: &Plane) -> Sliver {
        if self.shrinks_away(CRACK) {
            return Sliver::Crack;
        }
        let [front, back] = self.split(plane);
        match (front.shrinks_away(SLIVER), back.shrinks_away(SLIVER)) {
            (true, false) => Sliver::Front,
            (false, true) => Sliver::Back,
            _ => {
                let depth = |sign: f64| {
                    self.points()
                        .map(|p| sign * plane.distance(*p))
                        .fold(0.0, f64::max)
                };
                if depth(1.0) < depth(-1.0) {
                    Sliver::Front
                } else {
                    Sliver::Back
                }
            }
        }
    }

    fn points(&self) -> impl Iterator<Item = &DVec3> {
        self.faces.iter().flat_map(|f| &f.winding.points)
    }

    /// Whether nothing is left of the region shrunk by `margin` from every face: were something
    /// left, one of its faces would be a polygon.
    fn shrinks_away(&self, margin: f64) -> bool {
        let shrunk: Vec<Plane> = self
            .faces
            .iter()
            .map(|f| Plane::new(f.outward.normal, f.outward.dist - margin))
            .collect();
        !shrunk
            .iter()
            .any(|p| clip_inside(Winding::base_for_plane(p), &shrunk, p).is_some())
    }

    /// The parts in front of and behind a plane that crosses the region. Should the cut come
    /// out too thin to build on, both parts are the whole region.
    pub(crate) fn split(&self, plane: &Plane) -> [Region; 2] {
        match self.cross_section(plane) {
            Some(cut) => self.parts(plane, cut),
            None => [self.clone(), self.clone()],
        }
    }

    /// The polygon `plane` has inside the region, unless it is too small to build on.
    fn cross_section(&self, plane: &Plane) -> Option<Winding> {
        let planes: Vec<Plane> = self.faces.iter().map(|f| f.outward).collect();
        clip_inside(Winding::base_for_plane(plane), &planes, plane)
    }

    /// The parts of the region on either side of `plane`, whose polygon inside it is `cut`.
    fn parts(&self, plane: &Plane, cut: Winding) -> [Region; 2] {
        let mut front = Vec::with_capacity(self.faces.len() + 1);
        let mut back = Vec::with_capacity(self.faces.len() + 1);
        for f in &self.faces {
            let part = |winding| Face {
                outward: f.outward,
                winding,
            };
            match f.winding.split(plane) {
                Split::Front(w) => front.push(part(w)),
                Split::Back(w) => back.push(part(w)),
                Split::Both { front: a, back: b } => {
                    front.push(part(a));
                    back.push(part(b));
                }
                Split::On { .. } => {}
            }
        }
        front.push(Face {
            outward: plane.flipped(),
            winding: cut.clone(),
        });
        back.push(Face {
            outward: *plane,
            winding: cut,
        });
        [Region::with_faces(front), Region::with_faces(back)]
    }
}

/// `w` (on `own`) cut down to the inside of the other `planes` (outward), if anything is left.
fn clip_inside(w: Winding, planes: &[Plane], own: &Plane) -> Option<Winding> {
    let others = planes
        .iter()
        .filter(|p| !p.same_as(own) && !p.same_as(&own.flipped()));
    w.into_front_of_all(others.map(Plane::flipped))
        .filter(|w| !w.is_tiny())
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::geom::DVec3Ext;

    fn box_region(maxs: DVec3) -> Region {
        Region::around(
            &Bounds {
                mins: DVec3::ZERO,
                maxs,
            },
            0.0,
        )
    }

    fn unit_box() -> Region {
        box_region(DVec3::new(64.0, 64.0, 64.0))
    }

    /// The plane through (x, 0, `z0`) and (x, 64, `z1`) for every x.
    fn tilted(z0: f64, z1: f64) -> Plane {
        let normal = DVec3::new(0.0, z0 - z1, 64.0).normalized().expect("unit");
        Plane::new(normal, normal.dot(DVec3::new(0.0, 0.0, z0)))
    }

    #[test]
    fn planes_through_the_middle_cut_cleanly_and_wedges_off_a_face_do_not() {
        let region = unit_box();
        assert!(region.split_cleanly(&tilted(16.0, 48.0)).is_some());
        // Leaves the box's top 0.02 below it at one end: DarkPlaces keeps only the points near
        // the top face there, too few for a polygon.
        let wedge = tilted(63.98, 64.0);
        assert_eq!(region.sides_of(&wedge), (true, true));
        assert!(region.split_cleanly(&wedge).is_none());
        assert_eq!(region.sliver(&wedge), Sliver::Front);
        assert_eq!(region.sliver(&wedge.flipped()), Sliver::Back);
        // Parallel to the top and as close: DarkPlaces would keep this one, but only a
        // cross-section with room inside every face is safe whatever order it clips in.
        let slab = Plane::new(DVec3::new(0.0, 0.0, 1.0), 63.98);
        assert!(region.split_cleanly(&slab).is_none());
        assert_eq!(region.sliver(&slab), Sliver::Front);
    }

    #[test]
    fn in_a_crack_there_is_no_side_to_give_the_sliver_to() {
        let crack = box_region(DVec3::new(64.0, 0.5, 64.0));
        let x = Plane::new(DVec3::new(1.0, 0.0, 0.0), 32.0);
        assert!(crack.split_cleanly(&x).is_some());
        let y = Plane::new(DVec3::new(0.0, 1.0, 0.0), 0.02);
        assert!(crack.split_cleanly(&y).is_none());
        assert_eq!(crack.sliver(&y), Sliver::Crack);
    }

    #[test]
    fn planes_crossing_a_box_cut_it_and_others_do_not() {
        let region = unit_box();
        let x = DVec3::new(1.0, 0.0, 0.0);
        assert_eq!(region.sides_of(&Plane::new(x, 32.0)), (true, true));
        assert_eq!(region.sides_of(&Plane::new(x, 64.0)), (false, true));
        assert_eq!(region.sides_of(&Plane::new(x, 100.0)), (false, true));
        assert_eq!(region.sides_of(&Plane::new(x, -1.0)), (true, false));
    }

    #[test]
    fn a_split_region_is_cut_where_the_plane_crossed() {
        let diagonal = Plane::new(DVec3::new(1.0, 1.0, 0.0).normalized().expect("unit"), 0.0);
        let x48 = Plane::new(DVec3::new(1.0, 0.0, 0.0), 48.0);
        let [front, back] = unit_box().split_cleanly(&x48).expect("clean");
        assert_eq!(front.bounds.mins.x, 48.0);
        assert_eq!(back.bounds.maxs.x, 48.0);
        // The corner x < 16, y < 16 below the diagonal x + y = 16 is in the back part only.
        let corner = Plane::new(diagonal.normal, 16.0 / 2f64.sqrt());
        assert_eq!(back.sides_of(&corner), (true, true));
        assert_eq!(front.sides_of(&corner), (true, false));
    }
}
