//! Sample points: where on (just in front of) each face light is measured.
//!
//! One point per luxel (16 texels), or `n x n` per luxel when supersampling,
//! found by inverting the face's texture projection onto its plane. Points
//! are pushed [`SURFACE_OFFSET`] units off the surface; a point that ends up
//! behind a wall (luxels past the face's edge, e.g. under a wall standing on
//! a floor) is pulled back towards the face centre until it is in the open,
//! so light from the far side of the wall does not bleed under it.
//!
//! [`FaceSamples`] is kept as its own structure so later passes (bounce
//! lighting) can reuse the same points.

use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::bsp::limits::LIGHTMAP_SCALE;
use quake_formats::geom::Vec3;

use crate::faces::FaceGeom;
use crate::scene::TraceScene;

/// Distance of sample points in front of their face, in map units.
pub const SURFACE_OFFSET: f64 = 1.0;
/// Clearance kept between a pulled-back point and the wall that blocked it.
const WALL_CLEARANCE: f32 = 1.0;

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
    pub normal: Vec3,
    /// Sample positions, luxel by luxel (row-major), `per_axis²` per luxel.
    pub points: Vec<[f32; 3]>,
}

impl FaceSamples {
    pub fn luxels(&self) -> usize {
        self.width * self.height
    }

    pub fn per_luxel(&self) -> usize {
        self.per_axis * self.per_axis
    }
}

/// Counts from placing sample points.
#[derive(Debug, Clone, Copy, Default)]
pub struct PlacementCounts {
    /// Rays cast from the face centre to check points are in the open.
    pub rays: u64,
    /// Points pulled back because something stood between them and the centre.
    pub pulled_back: u64,
    /// Points still in solid afterwards, moved onto the face centre.
    pub to_centre: u64,
}

impl PlacementCounts {
    pub fn add(&mut self, o: &PlacementCounts) {
        self.rays += o.rays;
        self.pulled_back += o.pulled_back;
        self.to_centre += o.to_centre;
    }
}

/// Solves `[s_axis; t_axis; normal] p = rhs` for model-space `p`: the point
/// on the face plane with texture coordinates (s, t).
struct TextureToWorld {
    inverse: [Vec3; 3],
    s_offset: f64,
    t_offset: f64,
    plane_dist: f64,
}

impl TextureToWorld {
    fn new(face: &FaceGeom) -> Option<TextureToWorld> {
        let axis = |v: [f32; 4]| Vec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
        let (s, t, n) = (axis(face.vecs[0]), axis(face.vecs[1]), face.plane.normal);
        let det = s.dot(t.cross(n));
        if det.abs() < 1e-9 {
            return None; // texture axes parallel to the plane
        }
        // Rows of the inverse's transpose: columns of M^-1 are these / det.
        let c0 = t.cross(n) / det;
        let c1 = n.cross(s) / det;
        let c2 = s.cross(t) / det;
        Some(TextureToWorld {
            inverse: [c0, c1, c2],
            s_offset: f64::from(face.vecs[0][3]),
            t_offset: f64::from(face.vecs[1][3]),
            plane_dist: face.plane.dist - n.dot(face.origin),
        })
    }

    fn point(&self, s: f64, t: f64) -> Vec3 {
        let [c0, c1, c2] = self.inverse;
        c0 * (s - self.s_offset) + c1 * (t - self.t_offset) + c2 * self.plane_dist
    }
}

/// Places the sample points of `face`: `per_axis²` per luxel, spread evenly
/// over the luxel's 16x16-texel square. `bsp` is consulted for world faces to
/// catch points that are still inside solid after the pull-back.
pub fn face_samples(
    face: &FaceGeom,
    per_axis: usize,
    scene: &TraceScene,
    bsp: &Bsp,
) -> (FaceSamples, PlacementCounts) {
    let [width, height] = face.extents.luxel_size();
    let normal = face.plane.normal;
    let lift = normal * SURFACE_OFFSET;
    let centre = face.centroid() + lift;
    let to_world = TextureToWorld::new(face);
    let mut counts = PlacementCounts::default();
    let mut points = Vec::with_capacity(width * height * per_axis * per_axis);
    let step = f64::from(LIGHTMAP_SCALE) / per_axis as f64;
    let first = -f64::from(LIGHTMAP_SCALE) / 2.0 + step / 2.0;
    for y in 0..height {
        for x in 0..width {
            let [s0, t0] = face.extents.luxel_st(x, y);
            for sy in 0..per_axis {
                for sx in 0..per_axis {
                    let (s, t) = if per_axis == 1 {
                        (s0, t0)
                    } else {
                        (s0 + first + step * sx as f64, t0 + first + step * sy as f64)
                    };
                    let p = match &to_world {
                        Some(m) => m.point(s, t) + face.origin + lift,
                        None => centre,
                    };
                    points.push(into_open(
                        p,
                        centre,
                        face.model == 0,
                        scene,
                        bsp,
                        &mut counts,
                    ));
                }
            }
        }
    }
    (
        FaceSamples {
            face: face.index,
            width,
            height,
            per_axis,
            normal,
            points,
        },
        counts,
    )
}

/// `p` if nothing stands between it and `centre`, else pulled back along
/// that line to [`WALL_CLEARANCE`] in front of the obstacle; onto `centre`
/// if it is still in a solid world leaf.
fn into_open(
    p: Vec3,
    centre: Vec3,
    check_leaf: bool,
    scene: &TraceScene,
    bsp: &Bsp,
    counts: &mut PlacementCounts,
) -> [f32; 3] {
    let c = centre.to_f32();
    let d = p - centre;
    let len = d.length();
    let mut out = p.to_f32();
    if len > 1e-3 {
        let dir = (d / len).to_f32();
        counts.rays += 1;
        let reach = len as f32 + WALL_CLEARANCE;
        if let Some(t) = scene.hit_distance(c, dir, reach) {
            let keep = (t - WALL_CLEARANCE).clamp(0.0, len as f32);
            out = [
                c[0] + dir[0] * keep,
                c[1] + dir[1] * keep,
                c[2] + dir[2] * keep,
            ];
            counts.pulled_back += 1;
        }
    }
    if check_leaf
        && bsp
            .leaf_at(out)
            .and_then(|l| bsp.leafs.get(l))
            .is_some_and(|l| l.contents == contents::SOLID)
    {
        counts.to_centre += 1;
        return c;
    }
    out
}
