//! Convex brushes: a set of planes with one winding per side, built from a map brush or split
//! from another brush by a node plane.

use crate::planes::{PlaneId, PlaneSet};
use crate::sides_memo::{Sides, SidesMemo};
use glam::DVec3;
use quake_formats::geom::{Bounds, MAX_WORLD_COORD, ON_EPSILON, Plane, PlaneSide, Split, Winding};

/// Brush fragments smaller than this (cubic units) are dropped as numerical slivers.
const MIN_VOLUME: f64 = 0.1;

/// One bounding plane of a brush with the polygon the brush has on it.
#[derive(Debug, Clone, PartialEq)]
pub struct Side {
    pub plane: PlaneId,
    /// The outward normal is the canonical plane's normal negated.
    pub flipped: bool,
    /// Clockwise seen from outside the brush.
    pub winding: Winding,
    /// The map face this side came from (texinfo index), `None` for cuts and bevels.
    pub texinfo: Option<u32>,
    /// Set once a node plane the side lies on splits the space above it.
    pub used: bool,
    /// Wholly inside other brushes (see [`crate::csg`]): never a splitter, yet not a node plane.
    pub buried: bool,
}

/// The part of `w` (a winding on `plane`) behind `other`. A winding lying on `other` (within
/// [`ON_EPSILON`]) and facing the same way marks two sides that are one within the epsilon (a
/// face and a bevel a millionth of a radian apart): the first of them keeps it. Dropping both
/// would leave the brush without that side, bounded further out by its other planes.
fn clip_behind(w: Winding, plane: &Plane, other: &Plane, other_first: bool) -> Option<Winding> {
    let keep_on = !other_first && plane.normal.dot(other.normal) > 0.0;
    w.into_front_keeping_on(&other.flipped(), keep_on)
}

/// What a brush does to the tree's structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BrushKind {
    /// Splits the structural tree, whose leaves are vis clusters, and seals the map.
    #[default]
    Structural,
    /// Split in below the structural leaves only: neither a vis boundary nor a seal.
    Detail,
    /// Empty; its hint sides split the structural tree before any other plane.
    Hint,
}

/// A brush's sides before their planes are numbered: what [`Brush::from_planes`] computes
/// without the [`PlaneSet`], so that many brushes can be shaped at once and numbered after, in
/// their order.
pub struct BrushShape {
    /// The faces with a winding on the brush, in their order.
    sides: Vec<(BrushPlane, Winding)>,
}

impl BrushShape {
    /// The windings `faces` (outward planes) have on the brush they bound.
    pub fn of(faces: &[BrushPlane]) -> Result<BrushShape, BrushError> {
        if faces.len() < 4 {
            return Err(BrushError::TooFewPlanes(faces.len()));
        }
        for (i, a) in faces.iter().enumerate() {
            for (j, b) in faces.iter().enumerate().skip(i + 1) {
                if a.plane.same_as(&b.plane) {
                    return Err(BrushError::DuplicatePlane(i, j));
                }
                if a.plane.same_as(&b.plane.flipped()) {
                    return Err(BrushError::OppositePlanes(i, j));
                }
            }
        }
        let mut sides = Vec::with_capacity(faces.len());
        for (i, face) in faces.iter().enumerate() {
            let mut w = Some(Winding::base_for_plane(&face.plane));
            for (j, other) in faces.iter().enumerate() {
                if i == j {
                    continue;
                }
                w = w.and_then(|w| clip_behind(w, &face.plane, &other.plane, j < i));
            }
            if let Some(w) = w.filter(|w| !w.is_tiny()) {
                sides.push((*face, w));
            }
        }
        Ok(BrushShape { sides })
    }

    /// The brush, its planes numbered in `planes` (even when it turns out too small to keep).
    pub fn into_brush(
        self,
        planes: &mut PlaneSet,
        contents: i32,
        source: u32,
    ) -> Result<Brush, BrushError> {
        let sides = self
            .sides
            .into_iter()
            .map(|(face, winding)| {
                let (plane, flipped) = planes.insert(&face.plane);
                Side {
                    plane,
                    flipped,
                    winding,
                    texinfo: face.texinfo,
                    used: false,
                    buried: false,
                }
            })
            .collect();
        let brush = Brush::with_sides(sides, contents, source, BrushKind::Structural)
            .ok_or(BrushError::NoVolume)?;
        let limit = MAX_WORLD_COORD * 0.5;
        if (0..3).any(|i| brush.bounds.mins[i] < -limit || brush.bounds.maxs[i] > limit) {
            return Err(BrushError::TooLarge);
        }
        Ok(brush)
    }
}

/// A convex volume of one contents type.
#[derive(Debug, Clone, PartialEq)]
pub struct Brush {
    pub sides: Vec<Side>,
    pub bounds: Bounds,
    pub contents: i32,
    /// Index of the map brush this came from, within its model.
    pub source: u32,
    pub kind: BrushKind,
    /// The entity's `_mirrorinside`: whether its faces are also drawn seen from inside it
    /// (`None`: the default for its contents, see [`crate::faces`]).
    pub mirror_inside: Option<bool>,
    /// The entity's `_noclipfaces`: where the brush touches or overlaps brushes of its contents,
    /// the faces of both are kept instead of clipped away (see [`crate::faces`]).
    pub no_clip_faces: bool,
    /// Which sides of a plane its corners reach, for planes its box cannot answer for.
    pub sides_memo: SidesMemo,
}

/// A canonical plane with what [`BrushProbe::sides_of`] needs of it, worked out once for the many
/// brushes a candidate splitter is tested against.
#[derive(Debug, Clone, Copy)]
pub struct PlaneProbe<'a> {
    id: PlaneId,
    plane: &'a Plane,
    /// The normal's components without their signs: how far a box reaches along it.
    abs_normal: DVec3,
    axial: bool,
}

impl<'a> PlaneProbe<'a> {
    pub fn new(id: PlaneId, planes: &'a PlaneSet) -> PlaneProbe<'a> {
        let plane = planes.get(id);
        PlaneProbe {
            id,
            plane,
            abs_normal: plane.normal.abs(),
            axial: planes.is_axial(id),
        }
    }
}

/// A brush with its bounding box's centre and half size, worked out once for the many planes it
/// is tested against.
#[derive(Debug, Clone, Copy)]
pub struct BrushProbe<'a> {
    pub brush: &'a Brush,
    center: DVec3,
    half: DVec3,
}

impl<'a> BrushProbe<'a> {
    pub fn new(brush: &'a Brush) -> BrushProbe<'a> {
        let center = brush.bounds.center();
        BrushProbe {
            brush,
            center,
            half: brush.bounds.maxs - center,
        }
    }

    /// [`Brush::sides_of`]: the box's answer, else the corners' (remembered).
    #[inline(always)]
    pub fn sides_of(&self, plane: &PlaneProbe) -> Sides {
        self.box_sides(plane).unwrap_or_else(|| {
            self.brush
                .sides_memo
                .get_or_insert(plane.id, || self.brush.corner_sides(plane.plane))
        })
    }

    /// What the bounding box tells of the plane's sides: everything, unless the box straddles a
    /// plane that is not axial.
    #[inline(always)]
    fn box_sides(&self, plane: &PlaneProbe) -> Option<Sides> {
        let (n, half) = (plane.abs_normal, self.half);
        let radius = half.x * n.x + half.y * n.y + half.z * n.z;
        let d = plane.plane.distance(self.center);
        if d - radius > -ON_EPSILON {
            return Some((d + radius > ON_EPSILON, false));
        }
        if d + radius < ON_EPSILON {
            return Some((false, d - radius < -ON_EPSILON));
        }
        if plane.axial {
            return Some((d + radius > ON_EPSILON, d - radius < -ON_EPSILON));
        }
        None
    }
}

/// A plane of a brush being built, with the texinfo of its map face.
#[derive(Debug, Clone, Copy)]
pub struct BrushPlane {
    pub plane: Plane,
    pub texinfo: Option<u32>,
}

/// Why a map brush cannot be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BrushError {
    #[error("has {0} planes, fewer than 4")]
    TooFewPlanes(usize),
    #[error("faces {0} and {1} lie on the same plane")]
    DuplicatePlane(usize, usize),
    #[error("faces {0} and {1} face each other on one plane: no volume")]
    OppositePlanes(usize, usize),
    #[error("has no volume")]
    NoVolume,
    #[error("reaches beyond ±{MAX_WORLD_COORD} units")]
    TooLarge,
}

fn outward_plane(planes: &PlaneSet, plane: PlaneId, flipped: bool) -> Plane {
    let p = planes.get(plane);
    if flipped { p.flipped() } else { *p }
}

impl Brush {
    /// The structural brush bounded by `faces` (outward planes). Planes that do not touch the
    /// brush are dropped.
    pub fn from_planes(
        faces: &[BrushPlane],
        planes: &mut PlaneSet,
        contents: i32,
        source: u32,
    ) -> Result<Brush, BrushError> {
        BrushShape::of(faces)?.into_brush(planes, contents, source)
    }

    /// A brush from finished sides, or `None` when it is too small to keep.    /// A brush from finished sides, or `None` when it is too small to keep.
    fn with_sides(sides: Vec<Side>, contents: i32, source: u32, kind: BrushKind) -> Option<Brush> {
        if sides.len() < 4 {
            return None;
        }
        let mut bounds = Bounds::EMPTY;
        for s in &sides {
            for &p in &s.winding.points {
                bounds.add_point(p);
            }
        }
        let brush = Brush {
            sides,
            bounds,
            contents,
            source,
            kind,
            mirror_inside: None,
            no_clip_faces: false,
            sides_memo: SidesMemo::default(),
        };
        (brush.volume() >= MIN_VOLUME).then_some(brush)
    }

    pub fn is_detail(&self) -> bool {
        self.kind == BrushKind::Detail
    }

    pub fn outward(&self, side: &Side, planes: &PlaneSet) -> Plane {
        outward_plane(planes, side.plane, side.flipped)
    }

    /// Whether every side lies on a node plane above: the brush then fills its node's region.
    pub fn fills_node(&self) -> bool {
        self.sides.iter().all(|s| s.used)
    }

    pub fn volume(&self) -> f64 {
        let Some(corner) = self.sides.first().and_then(|s| s.winding.points.first()) else {
            return 0.0;
        };
        self.sides
            .iter()
            .filter_map(|s| {
                let plane = s.winding.plane()?;
                Some(s.winding.area() * -plane.distance(*corner))
            })
            .sum::<f64>()
            / 3.0
    }

    /// Which sides of the canonical plane `id` the brush reaches: (any point in front, any point
    /// behind). The corners' answers are remembered.
    pub fn sides_of(&self, id: PlaneId, planes: &PlaneSet) -> Sides {
        BrushProbe::new(self).sides_of(&PlaneProbe::new(id, planes))
    }

    /// Which sides of `plane` the sides' corners reach.
    fn corner_sides(&self, plane: &Plane) -> Sides {
        let (mut front, mut back) = (false, false);
        for s in &self.sides {
            for &p in &s.winding.points {
                let d = plane.distance(p);
                front |= d > ON_EPSILON;
                back |= d < -ON_EPSILON;
                if front && back {
                    return (true, true);
                }
            }
        }
        (front, back)
    }

    /// Split by the canonical plane `id`: the parts in front and behind. A brush entirely on one
    /// side comes back whole on that side.
    pub fn split(self, id: PlaneId, planes: &PlaneSet) -> (Option<Brush>, Option<Brush>) {
        let plane = *planes.get(id);
        match self.sides_of(id, planes) {
            (true, false) => return (Some(self), None),
            (false, true) => return (None, Some(self)),
            // On the plane within epsilon: a sliver; keep it where its bulk is.
            (false, false) => return (Some(self), None),
            (true, true) => {}
        }
        // The new face: the plane's polygon inside the brush.
        let inside = self.sides.iter().map(|s| self.outward(s, planes).flipped());
        let cut = Winding::base_for_plane(&plane).into_front_of_all(inside);
        let Some(cut) = cut.filter(|w| !w.is_tiny()) else {
            // The plane grazes an edge or a corner: the cut is too thin to build on.
            return self.on_both_sides();
        };
        let mut front_sides = Vec::with_capacity(self.sides.len() + 1);
        let mut back_sides = Vec::with_capacity(self.sides.len() + 1);
        // Classify first: only sides crossing the plane need splitting.
        for s in &self.sides {
            match s.winding.side_of(&plane) {
                PlaneSide::Front => front_sides.push(s.clone()),
                PlaneSide::Back => back_sides.push(s.clone()),
                PlaneSide::On => {}
                PlaneSide::Cross => {
                    let Split::Both { front, back } = s.winding.split(&plane) else {
                        continue;
                    };
                    let part = |winding| Side {
                        winding,
                        plane: s.plane,
                        flipped: s.flipped,
                        texinfo: s.texinfo,
                        used: s.used,
                        buried: s.buried,
                    };
                    if !front.is_tiny() {
                        front_sides.push(part(front));
                    }
                    if !back.is_tiny() {
                        back_sides.push(part(back));
                    }
                }
            }
        }
        // The front part's new face looks back along the plane, the back part's along it.
        front_sides.push(Side {
            plane: id,
            flipped: true,
            winding: cut.reversed(),
            texinfo: None,
            used: true,
            buried: false,
        });
        back_sides.push(Side {
            plane: id,
            flipped: false,
            winding: cut,
            texinfo: None,
            used: true,
            buried: false,
        });
        match (self.part_with(front_sides), self.part_with(back_sides)) {
            (Some(front), Some(back)) => (Some(front), Some(back)),
            _ => self.on_both_sides(),
        }
    }

    /// A part of this brush bounded by `sides`, keeping what the entity said of it.
    fn part_with(&self, sides: Vec<Side>) -> Option<Brush> {
        Brush::with_sides(sides, self.contents, self.source, self.kind).map(|b| Brush {
            mirror_inside: self.mirror_inside,
            no_clip_faces: self.no_clip_faces,
            ..b
        })
    }

    /// The brush reaches past a plane on both sides but one part is too thin to build: each side
    /// keeps the whole brush. Dropping the thin part would leave an uncovered sliver (inside a
    /// wall, a hole the outside flood leaks through); the whole brush is still cut down to its
    /// own sides further down the tree, so no leaf extends past it.
    fn on_both_sides(self) -> (Option<Brush>, Option<Brush>) {
        (Some(self.clone()), Some(self))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use glam::DVec3;
    use quake_formats::geom::DVec3Ext;

    #[test]
    fn a_side_doubled_by_a_plane_a_millionth_of_a_radian_off_is_kept_once() {
        // The +Y side of a 64-unit cube and a plane through its top edge tilted 2e-6 rad: they
        // are not one plane (`same_as`), yet each lies on the other over the cube. Found by
        // tests/generated_maps.rs, where a hull bevel doubled a nearly vertical face this way
        // and dropping both let the hull brush reach units further out.
        let mut faces = box_planes(DVec3::ZERO, DVec3::new(64.0, 64.0, 64.0));
        let n = DVec3::new(0.0, 1.0, 2e-6).normalized().expect("n");
        faces.push(BrushPlane {
            plane: Plane::new(n, n.dot(DVec3::new(0.0, 64.0, 64.0))),
            texinfo: Some(1),
        });
        let mut planes = PlaneSet::new();
        let b = Brush::from_planes(&faces, &mut planes, quake_formats::bsp::contents::SOLID, 0)
            .expect("brush");
        assert!((b.bounds.maxs.y - 64.0).abs() < 0.01, "{:?}", b.bounds);
        let plus_y = b
            .sides
            .iter()
            .filter(|s| b.outward(s, &planes).normal.y > 0.99)
            .count();
        assert_eq!(plus_y, 1, "the first of the two keeps the side");
        assert_eq!(b.sides.len(), 6);
    }

    /// The six outward planes of an axial box.
    pub(crate) fn box_planes(mins: DVec3, maxs: DVec3) -> Vec<BrushPlane> {
        let mut out = Vec::new();
        for axis in 0..3 {
            let mut n = DVec3::ZERO;
            n[axis] = 1.0;
            out.push(BrushPlane {
                plane: Plane::new(n, maxs[axis]),
                texinfo: Some(0),
            });
            out.push(BrushPlane {
                plane: Plane::new(-n, -mins[axis]),
                texinfo: Some(0),
            });
        }
        out
    }

    /// An axial box brush of `contents` in entity 0.
    pub(crate) fn box_brush(
        planes: &mut PlaneSet,
        mins: DVec3,
        maxs: DVec3,
        contents: i32,
    ) -> Brush {
        Brush::from_planes(&box_planes(mins, maxs), planes, contents, 0).expect("box brush")
    }

    /// The solid 64-unit cube at the origin most single-brush tests start from.
    pub(crate) fn solid_cube(planes: &mut PlaneSet) -> Brush {
        box_brush(
            planes,
            DVec3::ZERO,
            DVec3::new(64.0, 64.0, 64.0),
            quake_formats::bsp::contents::SOLID,
        )
    }

    proptest::proptest! {
        /// A tilted plane through a cube whose box it straddles is answered by the corners, then
        /// by the memo: the same answer both times, and for the brush's copy.
        #[test]
        fn remembered_sides_are_the_corners_answer(
            tilt in proptest::collection::vec(-1.0f64..1.0, 3),
            dist in -80.0f64..80.0,
        ) {
            let mut planes = PlaneSet::new();
            let cube = solid_cube(&mut planes);
            let Some(normal) = DVec3::from_slice(&tilt).normalized() else {
                return Ok(());
            };
            let (id, flipped) = planes.insert(&Plane::new(normal, dist));
            let plane = *planes.get(id);
            proptest::prop_assert_eq!(flipped, plane.normal.dot(normal) < 0.0);
            let boxed = BrushProbe::new(&cube).box_sides(&PlaneProbe::new(id, &planes));
            let expected = boxed.unwrap_or_else(|| cube.corner_sides(&plane));
            proptest::prop_assert_eq!(cube.sides_of(id, &planes), expected);
            proptest::prop_assert_eq!(cube.sides_memo.len(), usize::from(boxed.is_none()));
            proptest::prop_assert_eq!(cube.sides_of(id, &planes), expected);
            proptest::prop_assert_eq!(cube.clone().sides_of(id, &planes), expected);
        }
    }

    #[test]
    fn box_brush_has_six_sides_and_volume() {
        let mut planes = PlaneSet::new();
        let b = Brush::from_planes(
            &box_planes(DVec3::new(0.0, 0.0, 0.0), DVec3::new(64.0, 32.0, 16.0)),
            &mut planes,
            -2,
            0,
        )
        .expect("brush");
        assert_eq!(b.sides.len(), 6);
        assert!((b.volume() - 64.0 * 32.0 * 16.0).abs() < 1e-6);
        assert_eq!(planes.len(), 6);
        for s in &b.sides {
            let own = s.winding.plane().expect("plane");
            assert!(own.normal.near(b.outward(s, &planes).normal, 1e-9));
        }
    }

    #[test]
    fn bad_brushes_are_reported() {
        let mut planes = PlaneSet::new();
        let mut faces = box_planes(DVec3::ZERO, DVec3::new(8.0, 8.0, 8.0));
        assert_eq!(
            Brush::from_planes(&faces[..3], &mut planes, -2, 0),
            Err(BrushError::TooFewPlanes(3))
        );
        faces.push(faces[0]);
        assert_eq!(
            Brush::from_planes(&faces, &mut planes, -2, 0),
            Err(BrushError::DuplicatePlane(0, 6))
        );
        // A slab with its top below its bottom has no volume.
        let mut faces = box_planes(DVec3::ZERO, DVec3::new(8.0, 8.0, 8.0));
        faces[4].plane = Plane::new(DVec3::new(0.0, 0.0, 1.0), -4.0);
        assert_eq!(
            Brush::from_planes(&faces, &mut planes, -2, 0),
            Err(BrushError::NoVolume)
        );
    }

    /// A plane cutting a 0.02-deep wedge off the edge of a box (the e3m4 leak: the wedge was
    /// dropped for being too small, leaving an empty sliver inside a wall).
    #[test]
    fn split_keeps_thin_parts_covered() {
        let mut planes = PlaneSet::new();
        let b = solid_cube(&mut planes);
        let n = DVec3::new(1.0, 0.0, 1.0).normalized().expect("n");
        let corner = DVec3::new(64.0, 32.0, 64.0);
        let (cut, flipped) = planes.insert(&Plane::new(n, n.dot(corner) - 0.02));
        assert!(!flipped);
        let (front, back) = b.clone().split(cut, &planes);
        let front = front.expect("the thin wedge keeps a brush");
        assert!(back.is_some());
        assert!(front.bounds.contains(corner));
    }

    #[test]
    fn split_conserves_volume_and_adds_cut_faces() {
        let mut planes = PlaneSet::new();
        let b = solid_cube(&mut planes);
        let (cut, _) = planes.insert(&Plane::new(DVec3::new(0.6, 0.8, 0.0), 40.0));
        let (f, bk) = b.clone().split(cut, &planes);
        let (f, bk) = (f.expect("front"), bk.expect("back"));
        assert!((f.volume() + bk.volume() - b.volume()).abs() < 1e-6);
        assert!(f.sides.iter().any(|s| s.plane == cut && s.used));
        // An axial plane outside the brush leaves it whole.
        let (out, _) = planes.insert(&Plane::new(DVec3::new(1.0, 0.0, 0.0), 100.0));
        let (f, bk) = b.split(out, &planes);
        assert!(f.is_none() && bk.is_some());
    }
}
