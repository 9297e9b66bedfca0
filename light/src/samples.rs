//! Sample points: where on (just in front of) each face light is measured, placed as
//! ericw-tools places them.
//!
//! One point per luxel of the face's grid (Quake's 16 texels, or the face's own:
//! world-aligned, or another power of two texels), or `n x n` per luxel when
//! supersampling, found by inverting the grid's projection onto the face's
//! plane. A point less than 0.05 units past the face's edge counts as inside it. One farther
//! past walks as ericw-tools walks it: across the edge it lies least far past the ends of onto
//! the face continuing the plane there (same model, same plane) or, on a `_phong` face, a face
//! smoothed with it (the point, lifted off its plane, projected onto that face's), and on, at
//! most three times; it stays where it lands inside one, standing on that face. Otherwise (a luxel past the edge, e.g. under a wall
//! standing on a floor) it moves to the nearest point of the outline of the last face it
//! reached, unless that is more than a luxel away (the far corners of a triangle's lightmap,
//! which no pixel shows): such a point is occluded.
//! Points are then lifted [`SURFACE_OFFSET`] units off the surface. One that is then
//! inside the world's solid (on the edge under the wall, behind a fixture on the face)
//! is nudged half a unit along each axis into the open when that frees it, else it is
//! occluded; a point within `ON_PLANE` of a node's plane is in solid when either side
//! is, as in ericw-tools, so one on a solid's surface is nudged off it. An occluded sample
//! takes no light of its own: its luxel takes the mean of its open samples, or else of its
//! neighbours (see `trace::HiddenLuxels`).
//!
//! [`FaceSamples`] is kept as its own structure so later passes (bounce
//! lighting) can reuse the same points.

use std::sync::Arc;

use glam::{DMat3, DVec3, Vec3};
use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::extents::LuxelGrid;
use quake_formats::int_hash::IntMap;

use crate::faces::{CONTINUATION_HOPS, Continuations, FaceGeom, FaceKind, one_plane};
use crate::outline::{Edges, FaceRegion, ON_EDGE};

/// Distance of sample points in front of their face, in map units.
pub const SURFACE_OFFSET: f64 = 1.0;

/// The sample points of one face.
#[derive(Debug, Clone)]
pub struct FaceSamples {
    pub face: usize,
    /// Luxels across (s) and down (t).
    pub width: usize,
    pub height: usize,
    /// Samples per luxel along each axis (1, 2, 4 or 16).
    pub per_axis: usize,
    /// The face's outward unit normal.
    pub normal: DVec3,
    /// Sample positions, luxel by luxel (row-major), `per_axis²` per luxel.
    pub points: Vec<[f32; 3]>,
    /// Per-sample shading normals (`_phong`), or empty: the face normal everywhere.
    pub normals: Vec<[f32; 3]>,
    /// Lit from behind as from in front: a lit liquid's surface, which ericw-tools lights from
    /// both sides (a light under water brightens the surface seen from above).
    pub two_sided: bool,
    /// Per sample: it is not where the texture grid puts it (moved onto the
    /// face, or nudged out of solid: never more than a luxel away).
    pub moved: Vec<bool>,
    /// Per sample: on the face's edge (where a wall may stand on it) or nudged out of solid
    /// beside one, so its neighbours' shadows and dirt do not tell its own.
    pub apart: Vec<bool>,
    /// Per sample: no place to measure light (inside solid, or far past the face's edge), so
    /// its light does not count (empty: no sample is).
    pub occluded: Vec<bool>,
    /// Per sample: the face it stands on, this one unless it walked off onto a face continuing
    /// or smoothed with it (empty: every sample stands on this one).
    pub landed: Vec<u32>,
}

impl FaceSamples {
    pub fn luxels(&self) -> usize {
        self.width * self.height
    }

    pub fn per_luxel(&self) -> usize {
        self.per_axis * self.per_axis
    }

    /// Sample `luxel`'s sub-sample nearest its middle (its probe, on a supersampled face).
    pub fn middle_of(&self, luxel: usize) -> usize {
        let axis = self.per_axis;
        luxel * self.per_luxel() + (axis / 2) * axis + axis / 2
    }

    /// Per sample, the first sample at exactly the same point (itself when
    /// there is none): points moved onto the face often land together, on
    /// an edge or a corner, and need their rays traced only once.
    pub fn first_at_same_point(&self) -> Vec<usize> {
        first_at_same_point(&self.points, &self.moved)
    }

    /// The normal the angle-of-incidence term uses at sample `i`.
    pub fn normal_at(&self, i: usize) -> DVec3 {
        self.normals
            .get(i)
            .map_or(self.normal, |&n| Vec3::from(n).as_dvec3())
    }

    /// The cosine of the angle of incidence of light arriving along unit `to_light` at sample
    /// `i`: negative from behind, but on a two-sided face the light's side counts as the front.
    pub fn incidence(&self, i: usize, to_light: DVec3) -> f64 {
        let cos = self.normal_at(i).dot(to_light);
        if self.two_sided { cos.abs() } else { cos }
    }
}

/// Per point, the first of `points` at exactly the same place (itself when there is none).
/// Points on the texture grid are all distinct: only moved ones (`moved[i]`, true past its
/// end) can meet. Taken in order, the first point of each place is the one its bits are
/// hashed to.
fn first_at_same_point(points: &[[f32; 3]], moved: &[bool]) -> Vec<usize> {
    let mut first: Vec<usize> = (0..points.len()).collect();
    let is_moved = |i: usize| moved.get(i).copied().unwrap_or(true);
    let count = (0..points.len()).filter(|&i| is_moved(i)).count();
    let mut at: IntMap<[u32; 3], usize> =
        IntMap::with_capacity_and_hasher(count, Default::default());
    for i in (0..points.len()).filter(|&i| is_moved(i)) {
        first[i] = *at.entry(points[i].map(f32::to_bits)).or_insert(i);
    }
    first
}

/// Counts from placing sample points.
#[derive(Debug, Clone, Copy, Default)]
pub struct PlacementCounts {
    /// Points outside the face moved onto its edge.
    pub clamped: u64,
    /// Points in solid nudged into the open.
    pub nudged: u64,
    /// Points occluded: in solid however nudged, or too far past the face's edge.
    pub occluded: u64,
}

impl PlacementCounts {
    pub fn add(&mut self, o: &PlacementCounts) {
        self.clamped += o.clamped;
        self.nudged += o.nudged;
        self.occluded += o.occluded;
    }
}

/// Solves `[s_axis; t_axis; normal] p = rhs` for model-space `p`: the point
/// on the face plane with grid coordinates (s, t) of a projection `axes`.
#[derive(Debug, Clone)]
struct TextureToWorld {
    /// Columns: the world-space steps per unit of s, of t and of plane distance.
    inverse: DMat3,
    s_offset: f64,
    t_offset: f64,
    plane_dist: f64,
}

impl TextureToWorld {
    fn new(face: &FaceGeom, axes: &[[f64; 4]; 2]) -> Option<TextureToWorld> {
        let axis = |v: [f64; 4]| DVec3::new(v[0], v[1], v[2]);
        let (s, t, n) = (axis(axes[0]), axis(axes[1]), face.plane.normal);
        let det = s.dot(t.cross(n));
        if det.abs() < 1e-9 {
            return None; // texture axes parallel to the plane
        }
        // The columns of M^-1 are these cross products over det.
        let c0 = t.cross(n) / det;
        let c1 = n.cross(s) / det;
        let c2 = s.cross(t) / det;
        Some(TextureToWorld {
            inverse: DMat3::from_cols(c0, c1, c2),
            s_offset: axes[0][3],
            t_offset: axes[1][3],
            plane_dist: face.plane.dist - n.dot(face.origin),
        })
    }

    fn point(&self, s: f64, t: f64) -> DVec3 {
        self.inverse * DVec3::new(s - self.s_offset, t - self.t_offset, self.plane_dist)
    }
}

/// Where a face's grid coordinates land: the point of the face's plane
/// with those (s, t), moved onto the face's outline when it is outside and
/// lifted [`SURFACE_OFFSET`] off it. Also knows the square of texture space
/// each sample stands for, so later passes can spread points over it.
#[derive(Debug, Clone)]
pub struct SurfaceMap {
    to_world: Option<TextureToWorld>,
    outline: Arc<FaceRegion>,
    /// The faces continuing this one past its edges ([`FaceGeom::continuations`]).
    continuations: Arc<Continuations>,
    origin: DVec3,
    lift: DVec3,
    grid: LuxelGrid,
    per_axis: usize,
    /// Half-diagonal of one sample's square, in world units.
    footprint_radius: f64,
}

/// A sample point as [`SurfaceMap::place`] puts it.
#[derive(Debug, Clone, Copy)]
pub struct Placed {
    /// The point, lifted off the face.
    pub at: DVec3,
    /// It was outside the face and moved onto its edge.
    pub moved: bool,
    /// It lies on the face's edge.
    pub on_edge: bool,
    /// It was more than a luxel outside the face: no pixel shows its light.
    pub beyond: bool,
    /// The face it ended on, when it walked off this one onto another.
    pub face: Option<u32>,
}

impl SurfaceMap {
    pub fn new(face: &FaceGeom, per_axis: usize) -> SurfaceMap {
        let to_world = TextureToWorld::new(face, &face.grid.axes);
        let step = face.grid.scale / per_axis as f64;
        let footprint_radius = to_world.as_ref().map_or(0.0, |m| {
            (m.inverse.x_axis.length() + m.inverse.y_axis.length()) * step / 2.0
        });
        SurfaceMap {
            to_world,
            outline: face.shared_region(),
            continuations: face.continuations.clone(),
            origin: face.origin,
            lift: face.plane.normal * SURFACE_OFFSET,
            grid: face.grid,
            per_axis,
            footprint_radius,
        }
    }

    /// The lifted centre of the face (inside it).
    pub fn centre(&self) -> DVec3 {
        self.outline.centre() + self.lift
    }

    /// Where the sample for grid coordinates (s, t) goes, `near` being the face's edges its
    /// luxel comes near ([`SurfaceMap::edges_near_luxel`]). Without a usable projection: the
    /// centre.
    pub fn place(&self, s: f64, t: f64, near: Edges) -> Placed {
        let Some(m) = &self.to_world else {
            return Placed {
                at: self.centre(),
                moved: false,
                on_edge: false,
                beyond: false,
                face: None,
            };
        };
        let on_plane = m.point(s, t) + self.origin;
        // Most points lie inside the face: then it is where they stay, and one pass over the
        // edges near the luxel tells all (the tests below would each find the same).
        if let Some(on_edge) = self.outline.inside_on_edge(on_plane, near) {
            return Placed {
                at: on_plane + self.lift,
                moved: false,
                on_edge,
                beyond: false,
                face: None,
            };
        }
        // The walk along one plane stays apart from the one across smoothed faces: most points
        // past an edge take it, without the other's planes and faces to keep.
        if self.continuations.smoothed() {
            return self.onto_smoothed_faces(on_plane);
        }
        // Past the edge: across it onto the face continuing the plane there, if one does, and
        // so on; the point stays where it lands inside one, else it moves onto the outline of
        // the last face it reached.
        let mut region = &*self.outline;
        let mut at = 0;
        let hops = if self.continuations.is_empty() {
            0
        } else {
            CONTINUATION_HOPS
        };
        for _ in 0..hops {
            // On the face's own outline (the first region) only the edges near the luxel can
            // be crossed.
            let edge = region.edge_to_cross(on_plane, if at == 0 { near } else { Edges::All });
            let Some((next, beyond_edge)) = edge
                .and_then(|edge| self.continuations.across(at, edge))
                .and_then(|next| Some((next, self.continuations.region(next)?)))
            else {
                break;
            };
            (region, at) = (beyond_edge, next);
            if region.inside_on_edge(on_plane, Edges::All).is_some() {
                return Placed {
                    at: on_plane + self.lift,
                    moved: false,
                    on_edge: false,
                    beyond: false,
                    face: None,
                };
            }
        }
        let onto = region.nearest_on_edge(on_plane, if at == 0 { near } else { Edges::All });
        self.onto_edge(region, on_plane, onto, self.lift, None)
    }

    /// [`SurfaceMap::place`] of a point `on_plane` past the edge of a face smoothed with some of
    /// the faces around it: the walk goes onto those too, the point projected onto each one's
    /// plane (lifted off the plane it leaves, as ericw-tools projects it), and it stands on the
    /// face it ends on.
    fn onto_smoothed_faces(&self, on_plane: DVec3) -> Placed {
        let (mut region, mut at, mut point) = (&*self.outline, 0, on_plane);
        for _ in 0..CONTINUATION_HOPS {
            let Some(next) = self.continuations.next(at, point) else {
                break;
            };
            let (Some(beyond_edge), Some((_, current)), Some((_, next_plane))) = (
                self.continuations.region(next),
                self.continuations.face(at),
                self.continuations.face(next),
            ) else {
                break;
            };
            if !one_plane(current, next_plane) {
                // Onto a smoothed face's plane, as ericw-tools moves it: the point lifted off
                // this plane, projected onto that one.
                let lifted = point + current.normal * SURFACE_OFFSET;
                point = lifted - next_plane.normal * next_plane.distance(lifted);
            }
            (region, at) = (beyond_edge, next);
            if region.inside_on_edge(point, Edges::All).is_some() {
                return Placed {
                    at: point + self.lift_at(at),
                    moved: point != on_plane,
                    on_edge: false,
                    beyond: false,
                    face: self.landed_on(at),
                };
            }
        }
        let onto = region.nearest_on_edge(point, Edges::All);
        let moved = self.onto_edge(region, point, onto, self.lift_at(at), self.landed_on(at));
        Placed {
            moved: moved.moved || point != on_plane,
            ..moved
        }
    }

    /// A point `point` outside `region` (on its plane) moved onto its outline, at the point
    /// and edge [`FaceRegion::nearest_on_edge`] found, and lifted by `lift`: occluded when
    /// that is more than a luxel away.
    fn onto_edge(
        &self,
        region: &FaceRegion,
        point: DVec3,
        (on_face, onto): (DVec3, Option<usize>),
        lift: DVec3,
        face: Option<u32>,
    ) -> Placed {
        let step = on_face - point;
        let along = |axis: [f64; 4]| DVec3::new(axis[0], axis[1], axis[2]).dot(step);
        let [ds, dt] = self.grid.axes.map(along);
        // A point moved onto an edge lies on it: that edge's distance says so without the
        // others'.
        let on_edge = onto.is_some_and(|edge| region.distance(edge, on_face) < ON_EDGE)
            || region.on_edge(on_face);
        Placed {
            at: on_face + lift,
            moved: on_face != point,
            on_edge,
            beyond: longer_than(ds, dt, self.grid.scale),
            face,
        }
    }

    /// The lift off continuation `k`'s face: this face's own on its plane.
    fn lift_at(&self, k: usize) -> DVec3 {
        if k == 0 {
            return self.lift;
        }
        match (self.continuations.face(0), self.continuations.face(k)) {
            (Some((_, own)), Some((_, plane))) if !one_plane(own, plane) => {
                plane.normal * SURFACE_OFFSET
            }
            _ => self.lift,
        }
    }

    /// The face a point that ended on continuation `k` stands on, when not this one.
    fn landed_on(&self, k: usize) -> Option<u32> {
        if k == 0 {
            return None;
        }
        self.continuations.face(k).map(|(f, _)| f as u32)
    }

    /// The edges of the face that the samples of the luxel whose middle is at `[s0, t0]` may
    /// lie on or past ([`FaceRegion::edges_near_disc`], listed in `near`): the only ones
    /// [`SurfaceMap::place`] needs for them. A luxel well inside the face has none.
    fn edges_near_luxel<'a>(&self, [s0, t0]: [f64; 2], near: &'a mut Vec<usize>) -> Edges<'a> {
        let Some(m) = &self.to_world else {
            return Edges::All;
        };
        if self.per_axis == 1 {
            // The one sample: a pass over the edges for the luxel would only precede its own.
            return Edges::All;
        }
        // The samples lie within the luxel's half-diagonal of its middle.
        let radius = self.footprint_radius * self.per_axis as f64;
        self.outline
            .edges_near_disc(m.point(s0, t0) + self.origin, radius, near);
        Edges::Near(near)
    }

    /// Grid units (texels, or luxels of a face's own grid) along each axis one sample stands
    /// for.
    pub fn sample_step(&self) -> f64 {
        self.grid.scale / self.per_axis as f64
    }

    /// Texture coordinates of the sub-samples (row by row) of the luxel whose middle is at
    /// `[s0, t0]`, into `out`.
    fn sub_samples_st(&self, [s0, t0]: [f64; 2], out: &mut Vec<[f64; 2]>) {
        out.clear();
        if self.per_axis == 1 {
            out.push([s0, t0]);
            return;
        }
        let step = self.sample_step();
        let first = -self.grid.scale / 2.0 + step / 2.0;
        let (s_first, t_first) = (s0 + first, t0 + first);
        for row in 0..self.per_axis {
            let t = t_first + step * row as f64;
            out.extend((0..self.per_axis).map(|column| [s_first + step * column as f64, t]));
        }
    }
}

/// Whether the step `(ds, dt)` is longer than `limit`, as `ds.hypot(dt) > limit` says: the
/// sum of squares answers all but the steps within a millionth of the limit.
fn longer_than(ds: f64, dt: f64, limit: f64) -> bool {
    let (squares, limit2) = (ds * ds + dt * dt, limit * limit);
    if limit.is_nan() || limit <= 0.0 {
        ds.hypot(dt) > limit
    } else if squares < limit2 * (1.0 - 1e-6) {
        false
    } else if squares > limit2 * (1.0 + 1e-6) {
        true
    } else {
        ds.hypot(dt) > limit
    }
}

/// Where each luxel of `face`'s 16-texel lightmap lies on its own grid (continuous luxel
/// coordinates, row by row): the point of its plane at the luxel's texture coordinates,
/// projected onto the grid. Without a usable texture projection: the grid's first luxel.
pub fn vanilla_on_own_grid(face: &FaceGeom) -> Vec<[f64; 2]> {
    let [w, h] = face.extents.luxel_size();
    let vecs = face.vecs.map(|row| row.map(f64::from));
    let Some(to_world) = TextureToWorld::new(face, &vecs) else {
        return vec![[0.0; 2]; w * h];
    };
    (0..w * h)
        .map(|i| {
            let [s, t] = face.extents.luxel_st(i % w, i / w);
            face.grid.luxel_at(to_world.point(s, t).to_array())
        })
        .collect()
}

/// Places the sample points of `face`: `per_axis²` per luxel of its grid,
/// spread evenly over the luxel's square; `bsp` tells which are inside solid.
pub fn face_samples(face: &FaceGeom, per_axis: usize, bsp: &Bsp) -> (FaceSamples, PlacementCounts) {
    let [width, height] = face.grid.size;
    let map = SurfaceMap::new(face, per_axis);
    let per_luxel = per_axis * per_axis;
    let count = width * height * per_luxel;
    let mut points: Vec<[f32; 3]> = Vec::with_capacity(count);
    let mut moved: Vec<bool> = Vec::with_capacity(count);
    let mut apart: Vec<bool> = Vec::with_capacity(count);
    let mut beyond: Vec<bool> = Vec::with_capacity(count);
    // Samples that walked off the face, and the face each stands on.
    let mut walked: Vec<(usize, u32)> = Vec::new();
    // Luxel by luxel (row-major), each luxel's samples row by row: the order of
    // [`SurfaceMap::sample_st`].
    let mut sub_st = Vec::with_capacity(per_luxel);
    let mut near = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let middle = face.grid.luxel_st(x, y);
            // With several samples a luxel, one pass over the face's edges for its middle
            // leaves the few its samples need testing against.
            let edges = map.edges_near_luxel(middle, &mut near);
            map.sub_samples_st(middle, &mut sub_st);
            for &[s, t] in &sub_st {
                let placed = map.place(s, t, edges);
                if let Some(other) = placed.face {
                    walked.push((points.len(), other));
                }
                points.push(placed.at.as_vec3().to_array());
                moved.push(placed.moved);
                apart.push(placed.on_edge);
                beyond.push(placed.beyond);
            }
        }
    }
    let mut landed: Vec<u32> = Vec::new();
    if !walked.is_empty() {
        landed = vec![face.index as u32; count];
        for (i, other) in walked {
            landed[i] = other;
        }
    }
    let mut counts = PlacementCounts {
        clamped: moved.iter().filter(|&&m| m).count() as u64,
        ..PlacementCounts::default()
    };
    // A luxel's samples, or a run of a row's luxels with one sample each, lie close together.
    let tile = (per_axis * per_axis).max(16);
    let (tiles, all) = tile_boxes(&points, tile);
    let solid = solid_in_tiles(bsp, &points, tile, &tiles, all);
    let mut occluded = vec![false; count];
    // The nudges of points in solid walk the tree from where a box round all the points, and
    // half a unit more, parts.
    let nudge_start = solid.contains(&true).then(|| {
        let (lo, hi) = all;
        WalkStart::for_box(bsp, lo.map(|c| c - 1.0), hi.map(|c| c + 1.0))
    });
    // Samples moved onto one point (of an edge where a wall stands on the face) are in solid
    // alike, and nudged alike: the first one's nudge serves the rest. Points on the grid are
    // all distinct.
    let mut nudges: IntMap<[u32; 3], Option<[f32; 3]>> = IntMap::default();
    for i in 0..count {
        if beyond[i] {
            occluded[i] = true;
        } else if solid[i] {
            let nudge_of = |p| {
                nudge_start
                    .flatten()
                    .and_then(|start| nudged(bsp, &start, p))
            };
            let nudge = if moved[i] {
                *nudges
                    .entry(points[i].map(f32::to_bits))
                    .or_insert_with(|| nudge_of(points[i]))
            } else {
                nudge_of(points[i])
            };
            match nudge {
                Some(p) => {
                    points[i] = p;
                    moved[i] = true;
                    apart[i] = true;
                    counts.nudged += 1;
                }
                None => occluded[i] = true,
            }
        }
    }
    counts.occluded = occluded.iter().filter(|&&o| o).count() as u64;
    if counts.occluded == 0 {
        occluded.clear();
    }
    (
        FaceSamples {
            face: face.index,
            width,
            height,
            per_axis,
            normal: face.plane.normal,
            points,
            normals: Vec::new(),
            two_sided: face.kind == FaceKind::LitLiquid,
            moved,
            apart,
            occluded,
            landed,
        },
        counts,
    )
}

/// Half a unit along each axis, both ways: where a point inside solid is tried, in turn.
const NUDGES: [[f32; 3]; 8] = [
    [-0.5, -0.5, -0.5],
    [-0.5, -0.5, 0.5],
    [-0.5, 0.5, -0.5],
    [-0.5, 0.5, 0.5],
    [0.5, -0.5, -0.5],
    [0.5, -0.5, 0.5],
    [0.5, 0.5, -0.5],
    [0.5, 0.5, 0.5],
];

/// The first of `p`'s [`NUDGES`] that is in the open, if any; the walks start from `start`
/// when its box holds every nudge.
fn nudged(bsp: &Bsp, start: &WalkStart, p: [f32; 3]) -> Option<[f32; 3]> {
    // The nudges' box: the same sums as the nudges' own.
    let (lo, hi) = (p.map(|c| c - 0.5), p.map(|c| c + 0.5));
    let from = if start.contains(lo, hi) {
        start.node
    } else {
        WalkStart::root(bsp)?.node
    };
    let node = shared_walk(bsp, from, lo, hi);
    NUDGES
        .iter()
        .map(|d| [p[0] + d[0], p[1] + d[1], p[2] + d[2]])
        .find(|&t| !solid_below(bsp, node, t, 0))
}

/// How near a node's plane (units) a point counts as lying on it, and is in solid when the
/// plane's either side is there: ericw-tools' test for a sample point in solid, so a point on
/// a solid's surface (the edge of a floor where a wall stands on it, the front of a fixture a
/// unit thick) is nudged off it.
const ON_PLANE: f32 = 0.1;

/// How far (units) a cluster's bounding box must clear a node's plane for
/// every point to go down one side: beyond [`ON_PLANE`] and far above the f32 rounding of
/// the per-point test, so the shared walk ends where [`solid_at`]'s would.
const SHARED_WALK_MARGIN: f32 = 0.25;

/// A node of the world BSP where the shared walk of [`solid_in_tiles`]
/// arrives for every point inside a box: walks of points inside that box
/// (the nudges of one face's samples in solid) start there instead of at the
/// root, and end where they would have. A box inside another one is on one
/// side of every plane the bigger box is on one side of (the near and far
/// sums are monotonic in the box corners, rounding included).
#[derive(Debug, Clone, Copy)]
struct WalkStart {
    node: i32,
    lo: [f32; 3],
    hi: [f32; 3],
}

impl WalkStart {
    /// The root, for points anywhere (None: the BSP has no world model).
    fn root(bsp: &Bsp) -> Option<WalkStart> {
        let &node = bsp.models.first()?.head_nodes.first()?;
        let (lo, hi) = ([f32::NEG_INFINITY; 3], [f32::INFINITY; 3]);
        Some(WalkStart { node, lo, hi })
    }

    /// Where points inside `lo..hi` part ways.
    fn for_box(bsp: &Bsp, lo: [f32; 3], hi: [f32; 3]) -> Option<WalkStart> {
        let root = WalkStart::root(bsp)?;
        Some(WalkStart {
            node: shared_walk(bsp, root.node, lo, hi),
            lo,
            hi,
        })
    }

    fn contains(&self, lo: [f32; 3], hi: [f32; 3]) -> bool {
        (0..3).all(|a| self.lo[a] <= lo[a] && hi[a] <= self.hi[a])
    }
}

/// Whether `p` is in a solid (or sky) world leaf, a point within [`ON_PLANE`] of a node's
/// plane being in solid when either side of it holds it.
pub fn solid_at(bsp: &Bsp, p: [f32; 3]) -> bool {
    WalkStart::root(bsp).is_some_and(|root| solid_below(bsp, root.node, p, 0))
}

/// [`solid_at`] below `node`; `depth` nodes above it were walked (a broken tree's cycle ends
/// the walk, open).
fn solid_below(bsp: &Bsp, mut node: i32, p: [f32; 3], mut depth: usize) -> bool {
    while node >= 0 && depth <= bsp.nodes.len() {
        let Some(n) = bsp.nodes.get(node as usize) else {
            return false;
        };
        let Some(plane) = bsp.planes.get(n.plane as usize) else {
            return false;
        };
        let d = plane.distance(p);
        depth += 1;
        node = if d > ON_PLANE {
            n.children[0]
        } else if d < -ON_PLANE {
            n.children[1]
        } else {
            return solid_below(bsp, n.children[0], p, depth)
                || solid_below(bsp, n.children[1], p, depth);
        };
    }
    node < 0
        && bsp
            .leafs
            .get((-(node + 1)) as usize)
            .is_some_and(|l| l.contents == contents::SOLID || l.contents == contents::SKY)
}

/// [`solid_in_tiles`] of `points`, boxes and all.
#[cfg(test)]
pub(crate) fn solid_points_in_tiles(bsp: &Bsp, points: &[[f32; 3]], tile: usize) -> Vec<bool> {
    let (tiles, all) = tile_boxes(points, tile);
    solid_in_tiles(bsp, points, tile, &tiles, all)
}

/// Whether each of `points` is in solid ([`solid_at`]), for points that lie in tiles of `tile`
/// consecutive points close together (a luxel's samples), whose boxes are `tiles` and the box
/// of them all `all` ([`tile_boxes`]). The points share the walk from the root down to the
/// first node whose plane passes between them; then each tile shares the walk on down to where
/// its own points part, so a tile inside one leaf costs one walk, not one a point.
fn solid_in_tiles(
    bsp: &Bsp,
    points: &[[f32; 3]],
    tile: usize,
    tiles: &[PointBox],
    (lo, hi): PointBox,
) -> Vec<bool> {
    let Some(root) = WalkStart::root(bsp) else {
        return vec![false; points.len()];
    };
    if points.is_empty() {
        return Vec::new();
    }
    let node = shared_walk(bsp, root.node, lo, hi);
    let mut solid = Vec::with_capacity(points.len());
    for (tile, &(lo, hi)) in points.chunks(tile.max(1)).zip(tiles) {
        let node = shared_walk(bsp, node, lo, hi);
        let mut budget = OPEN_BOX_NODES;
        if box_is_open(bsp, node, lo, hi, &mut budget) == Some(true) {
            solid.extend(std::iter::repeat_n(false, tile.len()));
        } else {
            solid.extend(tile.iter().map(|&p| solid_below(bsp, node, p, 0)));
        }
    }
    solid
}

/// The most nodes [`box_is_open`] looks at before leaving a tile to its points' own walks.
const OPEN_BOX_NODES: usize = 48;

/// Whether every leaf the box `lo..hi` may reach from `node` is open (neither solid nor sky),
/// a node's plane passing within [`SHARED_WALK_MARGIN`] of the box sending it down both sides:
/// then no point of the box is in solid, whatever [`solid_below`] would have walked, since that
/// walk only goes where this one does. `None` when that takes more than `budget` nodes.
fn box_is_open(
    bsp: &Bsp,
    mut node: i32,
    lo: [f32; 3],
    hi: [f32; 3],
    budget: &mut usize,
) -> Option<bool> {
    while node >= 0 {
        *budget = budget.checked_sub(1)?;
        let n = bsp.nodes.get(node as usize)?;
        let plane = bsp.planes.get(n.plane as usize)?;
        let (near, far) = box_distances(plane, lo, hi);
        node = if near >= SHARED_WALK_MARGIN {
            n.children[0]
        } else if far < -SHARED_WALK_MARGIN {
            n.children[1]
        } else {
            if !box_is_open(bsp, n.children[0], lo, hi, budget)? {
                return Some(false);
            }
            n.children[1]
        };
    }
    let leaf = bsp.leafs.get((-(node + 1)) as usize)?;
    Some(leaf.contents != contents::SOLID && leaf.contents != contents::SKY)
}

/// The least and the greatest distance of the box `lo..hi` from `plane`.
fn box_distances(plane: &quake_formats::bsp::BspPlane, lo: [f32; 3], hi: [f32; 3]) -> (f32, f32) {
    let (mut near, mut far) = (-plane.dist, -plane.dist);
    for a in 0..3 {
        let (x, y) = (plane.normal[a] * lo[a], plane.normal[a] * hi[a]);
        near += x.min(y);
        far += x.max(y);
    }
    (near, far)
}

/// A box, `(lo, hi)`.
type PointBox = ([f32; 3], [f32; 3]);

/// The boxes of `points` taken `tile` at a time, in order, and the box of them all: the same
/// box as [`box_of`] of them all, in one pass over the points.
fn tile_boxes(points: &[[f32; 3]], tile: usize) -> (Vec<PointBox>, PointBox) {
    let tiles: Vec<PointBox> = points.chunks(tile.max(1)).map(box_of).collect();
    // Tile by tile in the points' order, the comparisons `box_of` makes point by point.
    let mut all = EMPTY_BOX;
    for &tile in &tiles {
        widen(&mut all, tile);
    }
    (tiles, all)
}

/// The box of no points: lo above hi.
const EMPTY_BOX: PointBox = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);

/// The box of `points` (lo above hi for none).
fn box_of(points: &[[f32; 3]]) -> PointBox {
    let mut b = EMPTY_BOX;
    for &p in points {
        widen(&mut b, (p, p));
    }
    b
}

/// `b` widened to hold the box `lo..hi`: a lesser `lo` or greater `hi` coordinate replaces
/// `b`'s, so of equal ones (0 and -0) the first met stays, and, as `min` and `max` take them,
/// a NaN coordinate changes nothing.
fn widen(b: &mut PointBox, (lo, hi): PointBox) {
    for a in 0..3 {
        if lo[a] < b.0[a] {
            b.0[a] = lo[a];
        }
        if hi[a] > b.1[a] {
            b.1[a] = hi[a];
        }
    }
}

/// From `node` down, the first node whose plane passes between the corners
/// of `lo..hi` (with [`SHARED_WALK_MARGIN`]), or the leaf the box is in.
fn shared_walk(bsp: &Bsp, mut node: i32, lo: [f32; 3], hi: [f32; 3]) -> i32 {
    let mut steps = 0;
    while node >= 0 && steps <= bsp.nodes.len() {
        let Some(n) = bsp.nodes.get(node as usize) else {
            break;
        };
        let Some(plane) = bsp.planes.get(n.plane as usize) else {
            break;
        };
        let (near, far) = box_distances(plane, lo, hi);
        node = if near >= SHARED_WALK_MARGIN {
            n.children[0]
        } else if far < -SHARED_WALK_MARGIN {
            n.children[1]
        } else {
            break;
        };
        steps += 1;
    }
    node
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The sum of squares answers as the hypotenuse does, near the limit too.
        #[test]
        fn longer_than_agrees_with_hypot(
            ds in -40.0f64..40.0,
            dt in -40.0f64..40.0,
            limit in prop_oneof![Just(16.0f64), Just(8.0), Just(0.0), -4.0f64..64.0],
            scale in prop_oneof![Just(1.0f64), Just(1.0 + 1e-9), Just(1.0 - 1e-9), 0.5f64..1.5],
        ) {
            let (ds, dt) = (ds * scale, dt * scale);
            prop_assert_eq!(longer_than(ds, dt, limit), ds.hypot(dt) > limit);
            let on = limit / std::f64::consts::SQRT_2;
            prop_assert_eq!(longer_than(on, on, limit), on.hypot(on) > limit);
            prop_assert_eq!(longer_than(limit, 0.0, limit), limit.hypot(0.0) > limit);
        }

        /// Each moved point's first twin is the lowest-numbered moved point at exactly its place;
        /// points that did not move keep their own.
        #[test]
        fn first_at_same_point_finds_the_first_moved_twin(
            cells in proptest::collection::vec((0u8..4, 0u8..4, any::<bool>()), 0..60),
            moved_len_cut in 0usize..8,
        ) {
            // Few distinct places so twins are common; -0.0 and 0.0 are different bits.
            let points: Vec<[f32; 3]> = cells
                .iter()
                .map(|&(a, b, neg)| [f32::from(a), if neg { -0.0 } else { 0.0 }, f32::from(b)])
                .collect();
            let mut moved: Vec<bool> = cells.iter().map(|&(a, b, _)| (a + b) % 3 != 0).collect();
            moved.truncate(moved.len().saturating_sub(moved_len_cut));
            let is_moved = |i: usize| moved.get(i).copied().unwrap_or(true);
            let bits = |p: &[f32; 3]| p.map(f32::to_bits);
            let got = first_at_same_point(&points, &moved);
            for (i, p) in points.iter().enumerate() {
                let want = if is_moved(i) {
                    (0..=i).find(|&j| is_moved(j) && bits(&points[j]) == bits(p)).unwrap_or(i)
                } else {
                    i
                };
                prop_assert_eq!(got[i], want, "point {}", i);
            }
        }

        /// The box of all the points made from the tiles' boxes is the box of the points, bit
        /// for bit: the first of equal coordinates (0 and -0) kept, NaN coordinates ignored,
        /// tiles of NaN alone included.
        #[test]
        fn the_tiles_boxes_make_the_box_of_all_the_points(
            coords in proptest::collection::vec(
                prop_oneof![Just(0.0f32), Just(-0.0), Just(f32::NAN), -4.0f32..4.0],
                0..120,
            ),
            tile in 1usize..20,
        ) {
            let points: Vec<[f32; 3]> = coords.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            let (tiles, all) = tile_boxes(&points, tile);
            let bits = |(lo, hi): PointBox| (lo.map(f32::to_bits), hi.map(f32::to_bits));
            prop_assert_eq!(bits(all), bits(box_of(&points)));
            prop_assert_eq!(tiles.len(), points.chunks(tile).len());
        }
    }
}
