//! `_phong` smoothing: shading normals that turn smoothly across the faces
//! of one brush entity (worldspawn for the world, or a `func_detail` /
//! `func_group` the compiler recorded in the `SLIPGATE_PHONG` lump), so a
//! column made of flat faces is lit like a round one. Each face corner gets the mean of the
//! normals of the entity's faces that meet there and lie within the phong
//! angle of the face, each weighted by the angle it spans at that corner times its area.
//! Inside a face the corner normals are blended by barycentric coordinates over a fan of
//! triangles from its first corner (mean value coordinates for a point nudged off the face),
//! both as ericw-tools does. A sample past a face's edge walks onto the faces smoothed with it
//! and takes the normal of the one it stands on (`samples.rs`). Only the angle-of-incidence
//! term uses them; shadows and culling keep the flat face.

use glam::{DVec3, Vec3};
use quake_formats::geom::DVec3Ext;
use std::collections::HashMap;

use quake_formats::bsp::phong::FacePhong;
use quake_formats::geom::{Bounds, polygon_area};

use crate::faces::{FaceGeom, FaceKind};
use crate::outline::INSIDE_SLACK;
use crate::samples::FaceSamples;

/// A point this close to a face (plane and outline) touches it.
const TOUCH_EPSILON: f64 = 0.05;
/// Two faces whose normals' angle is the smoothing angle to within this much of its cosine are
/// within it (the rounding of a cosine of degrees).
const ANGLE_SLACK: f64 = 1e-9;
/// Grid cell size of the lookup of faces near a point.
const CELL: f64 = 64.0;

fn cell_of(p: DVec3) -> [i64; 3] {
    [p.x, p.y, p.z].map(|c| (c / CELL).floor() as i64)
}

/// The angle the polygon `points` spans at `p` if `p` is one of its corners,
/// π if `p` lies on one of its edges, and 2π inside it; `None` if `p` is
/// not on the polygon.
fn angle_at(points: &[DVec3], normal: DVec3, plane_dist: f64, p: DVec3) -> Option<f64> {
    if (normal.dot(p) - plane_dist).abs() > TOUCH_EPSILON {
        return None;
    }
    let n = points.len();
    let mut inside = true;
    for i in 0..n {
        let a = points[i];
        let b = points[(i + 1) % n];
        if (p - a).length() <= TOUCH_EPSILON {
            let prev = points[(i + n - 1) % n];
            let (u, v) = ((prev - a).normalized()?, (b - a).normalized()?);
            return Some(u.dot(v).clamp(-1.0, 1.0).acos());
        }
        let edge = b - a;
        let len = edge.length();
        let along = (p - a).dot(edge) / len.max(1e-12);
        let off = (p - a - edge * (along / len.max(1e-12))).length();
        if off <= TOUCH_EPSILON && along > 0.0 && along < len {
            return Some(std::f64::consts::PI);
        }
        // Faces are clockwise seen from the front.
        if normal.dot((p - a).cross(edge)) < 0.0 {
            inside = false;
        }
    }
    inside.then_some(std::f64::consts::TAU)
}

/// A group's smoothing angles, in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhongAngles {
    /// Faces whose normals are at most this far apart smooth together (`_phong_angle`).
    pub angle: f64,
    /// The same where they meet in a concave joint (`_phong_angle_concave`; 0: `angle`).
    pub concave: f64,
}

impl PhongAngles {
    /// One angle for every joint.
    #[cfg(test)]
    pub fn of(angle: f64) -> PhongAngles {
        PhongAngles {
            angle,
            concave: 0.0,
        }
    }

    /// The angle for a joint, concave or not.
    fn for_joint(self, concave: bool) -> f64 {
        if concave && self.concave > 0.0 {
            self.concave
        } else {
            self.angle
        }
    }
}

/// Which faces smooth together.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PhongGroups {
    /// Per face: its group (an index into `angles`), or `None`.
    pub of_face: Vec<Option<usize>>,
    /// Per group: its smoothing angles.
    pub angles: Vec<PhongAngles>,
}

/// Where a group comes from: a brush model's (or worldspawn's) own keys, or
/// a group the compiler recorded in the `SLIPGATE_PHONG` lump.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum GroupKey {
    Model(usize),
    Lump(u32),
}

/// The phong groups of the lit faces: a face the `lump` (one record per
/// face, from the compiler) puts in a group smooths with that group;
/// otherwise a face of a brush model in `model_angles` (model index ->
/// angle in degrees; 0 = worldspawn) smooths with its model's faces.
pub fn groups(
    faces: &[FaceGeom],
    model_angles: &HashMap<usize, PhongAngles>,
    lump: Option<&[FacePhong]>,
) -> PhongGroups {
    let mut ids: HashMap<GroupKey, usize> = HashMap::new();
    let mut out = PhongGroups {
        of_face: vec![None; faces.len()],
        angles: Vec::new(),
    };
    for f in faces {
        if f.kind != FaceKind::Lit || f.points.len() < 3 {
            continue;
        }
        let recorded = lump
            .and_then(|l| l.get(f.index))
            .filter(|r| r.group != 0)
            .map(|r| {
                let angles = PhongAngles {
                    angle: f64::from(r.angle),
                    concave: f64::from(r.concave),
                };
                (GroupKey::Lump(r.group), angles)
            });
        let own = || {
            model_angles
                .get(&f.model)
                .map(|&a| (GroupKey::Model(f.model), a))
        };
        let Some((key, angle)) = recorded.or_else(own) else {
            continue;
        };
        let id = *ids.entry(key).or_insert_with(|| {
            out.angles.push(angle);
            out.angles.len() - 1
        });
        out.of_face[f.index] = Some(id);
    }
    out
}

/// Corner normals of every face in a phong group; `None` for the others.
pub fn corner_normals(faces: &[FaceGeom], groups: &PhongGroups) -> Vec<Option<Vec<DVec3>>> {
    let mut out: Vec<Option<Vec<DVec3>>> = vec![None; faces.len()];
    let mut members: Vec<Vec<&FaceGeom>> = vec![Vec::new(); groups.angles.len()];
    for f in faces {
        if let Some(Some(g)) = groups.of_face.get(f.index) {
            members[*g].push(f);
        }
    }
    for (members, &angles) in members.iter().zip(&groups.angles) {
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (m, f) in members.iter().enumerate() {
            let mut bounds = Bounds::EMPTY;
            for &p in &f.points {
                bounds.add_point(p);
            }
            let margin = DVec3::new(1.0, 1.0, 1.0) * TOUCH_EPSILON;
            let (lo, hi) = (cell_of(bounds.mins - margin), cell_of(bounds.maxs + margin));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        grid.entry([x, y, z]).or_default().push(m);
                    }
                }
            }
        }
        let areas: Vec<f64> = members.iter().map(|g| polygon_area(&g.points)).collect();
        for f in members {
            let normal = f.plane.normal;
            let corners = f
                .points
                .iter()
                .map(|&p| {
                    let mut sum = DVec3::ZERO;
                    for &m in grid.get(&cell_of(p)).into_iter().flatten() {
                        let g = members[m];
                        if !within_angle(f, g, angles) {
                            continue;
                        }
                        if let Some(w) = angle_at(&g.points, g.plane.normal, g.plane.dist, p) {
                            sum += g.plane.normal * (w * areas[m]);
                        }
                    }
                    sum.normalized().unwrap_or(normal)
                })
                .collect();
            out[f.index] = Some(corners);
        }
    }
    out
}

/// Whether face `g`'s normal is within the smoothing angle of `f`'s (the concave one where `g`
/// rises in front of `f`).
fn within_angle(f: &FaceGeom, g: &FaceGeom, angles: PhongAngles) -> bool {
    let concave = f.plane.distance(g.centroid()) > TOUCH_EPSILON;
    let cos_limit = angles.for_joint(concave).to_radians().cos();
    g.plane.normal.dot(f.plane.normal) >= cos_limit - ANGLE_SLACK
}

impl PhongGroups {
    /// Whether faces `f` and `g` are smoothed together: in one group, their normals within its
    /// angle.
    pub fn smooths(&self, f: &FaceGeom, g: &FaceGeom) -> bool {
        let group = |face: &FaceGeom| self.of_face.get(face.index).copied().flatten();
        match (group(f), group(g)) {
            (Some(a), Some(b)) if a == b => self
                .angles
                .get(a)
                .is_some_and(|&angles| within_angle(f, g, angles)),
            _ => false,
        }
    }
}

/// The `_phong` normal at each of `samples` (of `faces[samples.face]`), from the corner normals
/// of the face each stands on; `None` for a face not smoothed.
pub fn sample_normals(
    samples: &FaceSamples,
    faces: &[FaceGeom],
    corner_normals: &[Option<Vec<DVec3>>],
) -> Option<Vec<[f32; 3]>> {
    let corners_of = |f: usize| corner_normals.get(f).and_then(Option::as_ref);
    let own = corners_of(samples.face)?;
    let geom = faces.get(samples.face)?;
    let normals = samples.points.iter().enumerate().map(|(i, &p)| {
        // A sample on a face without normals of its own (a continuing face outside the group)
        // takes this face's.
        let (geom, corners) = samples
            .landed
            .get(i)
            .map(|&f| f as usize)
            .filter(|&f| f != samples.face)
            .and_then(|f| Some((faces.get(f)?, corners_of(f)?)))
            .unwrap_or((geom, own));
        interpolate(geom, corners, Vec3::from(p).as_dvec3())
            .as_vec3()
            .to_array()
    });
    Some(normals.collect())
}

/// The smooth normal at `p` (on or just off the face) from the face's
/// `corners` normals, as ericw-tools blends them: the face cut into a fan of triangles from
/// its first corner, and `p` (projected onto the face's plane) blended by its barycentric
/// coordinates in the first triangle holding it (within [`INSIDE_SLACK`] of its edges). A point
/// no triangle holds (one nudged off the face) takes mean value coordinates, which blend
/// smoothly outside the face too.
pub fn interpolate(face: &FaceGeom, corners: &[DVec3], p: DVec3) -> DVec3 {
    let n = face.plane.normal;
    let q = p - n * face.plane.distance(p);
    fan_blend(&face.points, corners, n, q).unwrap_or_else(|| mean_value_blend(face, corners, q))
}

/// The blend of `corners` at `q` (on the plane of `points`, whose normal is `n`) by the
/// barycentric coordinates of the first triangle of the fan from `points[0]` that holds it.
/// Degenerate triangles are passed over.
fn fan_blend(points: &[DVec3], corners: &[DVec3], n: DVec3, q: DVec3) -> Option<DVec3> {
    let (&a, &na) = (points.first()?, corners.first()?);
    for i in 2..points.len().min(corners.len()) {
        let (b, c) = (points[i - 1], points[i]);
        let centre = (a + b + c) / 3.0;
        let holds = [(a, b), (b, c), (c, a)].iter().all(|&(from, to)| {
            n.cross(to - from).normalized().is_some_and(|m| {
                let inward = if m.dot(centre - from) < 0.0 { -m } else { m };
                inward.dot(q - from) >= -INSIDE_SLACK
            })
        });
        if !holds {
            continue;
        }
        let (ab, ac, aq) = (b - a, c - a, q - a);
        let (d00, d01, d11) = (ab.dot(ab), ab.dot(ac), ac.dot(ac));
        let (d20, d21) = (aq.dot(ab), aq.dot(ac));
        let denom = d00 * d11 - d01 * d01;
        let v = (d11 * d20 - d01 * d21) / denom;
        let w = (d00 * d21 - d01 * d20) / denom;
        let u = 1.0 - v - w;
        if !(u.is_finite() && v.is_finite() && w.is_finite()) {
            continue;
        }
        let blend = na * u + corners[i - 1] * v + corners[i] * w;
        return Some(blend.normalized().unwrap_or(n));
    }
    None
}

/// The blend of `corners` at `q` (on the face's plane) by mean value coordinates (a point
/// outside the face takes the nearest edge's blend).
fn mean_value_blend(face: &FaceGeom, corners: &[DVec3], q: DVec3) -> DVec3 {
    let n = face.plane.normal;
    let pts = &face.points;
    let count = pts.len();
    let spokes: Vec<DVec3> = pts.iter().map(|&v| v - q).collect();
    let lengths: Vec<f64> = spokes.iter().map(|s| s.length()).collect();
    if let Some(i) = lengths.iter().position(|&r| r < 1e-6) {
        return corners[i];
    }
    // tan(half the angle between spokes i and i+1), signed so points
    // outside the face get negative weights on the edges they are beyond.
    let mut half_tan = Vec::with_capacity(count);
    for i in 0..count {
        let j = (i + 1) % count;
        let cross = spokes[j].cross(spokes[i]).dot(n);
        let dot = spokes[i].dot(spokes[j]);
        let denom = lengths[i] * lengths[j] + dot;
        if denom.abs() < 1e-9 || (cross.abs() < 1e-9 && dot < 0.0) {
            // On the edge i..j: blend its two corners.
            let t = lengths[i] / (lengths[i] + lengths[j]);
            return (corners[i] * (1.0 - t) + corners[j] * t)
                .normalized()
                .unwrap_or(n);
        }
        half_tan.push(cross / denom);
    }
    let mut sum = DVec3::ZERO;
    for i in 0..count {
        let w = (half_tan[(i + count - 1) % count] + half_tan[i]) / lengths[i];
        sum += corners[i] * w;
    }
    match sum.normalized() {
        Some(s) if s.dot(n) > 0.0 => s,
        _ => n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::geom::Plane;

    fn square() -> FaceGeom {
        // Clockwise seen from above (+z).
        let points = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 10.0, 0.0),
            DVec3::new(10.0, 10.0, 0.0),
            DVec3::new(10.0, 0.0, 0.0),
        ];
        FaceGeom::for_test(0, 0, points, Plane::new(DVec3::new(0.0, 0.0, 1.0), 0.0))
    }

    #[test]
    fn interpolation_hits_corners_edges_and_blends_inside() {
        let f = square();
        let tilt = |x: f64| DVec3::new(x, 0.0, 1.0).normalized().expect("unit");
        // Normals lean -x on the x = 0 side and +x on the x = 10 side.
        let corners = [tilt(-0.5), tilt(-0.5), tilt(0.5), tilt(0.5)];
        assert!(interpolate(&f, &corners, DVec3::new(0.0, 0.0, 1.0)).near(corners[0], 1e-12));
        let edge = interpolate(&f, &corners, DVec3::new(5.0, 10.0, 1.0));
        assert!(edge.near(DVec3::new(0.0, 0.0, 1.0), 1e-9), "{edge:?}");
        let mid = interpolate(&f, &corners, DVec3::new(5.0, 3.0, 0.0));
        assert!(mid.near(DVec3::new(0.0, 0.0, 1.0), 1e-9), "{mid:?}");
        let left = interpolate(&f, &corners, DVec3::new(2.0, 5.0, 0.0));
        assert!(left.x < 0.0 && left.x > tilt(-0.5).x, "{left:?}");
    }

    /// As ericw-tools blends them: over the fan of triangles from the first corner, so inside
    /// the first triangle (corners 0, 1, 2) the fourth corner's normal plays no part.
    #[test]
    fn interpolation_blends_over_a_fan_from_the_first_corner() {
        let f = square();
        let up = DVec3::Z;
        let odd = DVec3::new(1.0, 0.0, 1.0).normalized().expect("unit");
        let corners = [up, up, up, odd];
        // (2, 8) lies in the triangle (0, 0), (0, 10), (10, 10).
        let inside_first = interpolate(&f, &corners, DVec3::new(2.0, 8.0, 1.0));
        assert!(inside_first.near(up, 1e-12), "{inside_first:?}");
        let inside_second = interpolate(&f, &corners, DVec3::new(8.0, 2.0, 1.0));
        assert!(inside_second.x > 0.0, "{inside_second:?}");
    }

    #[test]
    fn lump_groups_take_precedence_over_model_keys() {
        let faces: Vec<FaceGeom> = (0..4)
            .map(|index| FaceGeom {
                index,
                model: usize::from(index == 3),
                ..square()
            })
            .collect();
        let group = |g: u32, angle: f32| FacePhong {
            group: g,
            angle,
            concave: 0.0,
        };
        // Face 1 is in a compiler group; faces 0 and 2 follow worldspawn's
        // `_phong`; face 3 belongs to model 1, which has no key.
        let lump = [group(0, 0.0), group(7, 45.0), group(0, 0.0), group(0, 0.0)];
        let world = HashMap::from([(0, PhongAngles::of(60.0))]);
        let g = groups(&faces, &world, Some(&lump));
        assert_eq!(g.of_face, vec![Some(0), Some(1), Some(0), None]);
        assert_eq!(g.angles, vec![PhongAngles::of(60.0), PhongAngles::of(45.0)]);
        let g = groups(&faces, &HashMap::new(), Some(&lump));
        assert_eq!(g.of_face, vec![None, Some(0), None, None]);
        assert_eq!(
            groups(&faces, &HashMap::new(), None),
            PhongGroups {
                of_face: vec![None; 4],
                angles: Vec::new(),
            }
        );
    }

    #[test]
    fn corners_of_a_lone_face_keep_its_normal() {
        let f = square();
        let angles = HashMap::from([(0, PhongAngles::of(89.0))]);
        let groups = groups(std::slice::from_ref(&f), &angles, None);
        let normals = corner_normals(std::slice::from_ref(&f), &groups);
        let c = normals[0].as_ref().expect("phong face");
        assert!(c.iter().all(|n| n.near(f.plane.normal, 1e-12)));
    }

    /// `_phong_angle_concave`: the square and a face leaning 45° off its x = 0 edge smooth
    /// within `_phong_angle 89` whichever way the other leans; with a concave angle of 1 the
    /// trough (the other face rising in front of the square) stays sharp, the ridge does not.
    #[test]
    fn a_concave_angle_keeps_troughs_sharp_and_smooths_ridges() {
        let lean = |rise: f64| {
            let points = vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(-10.0, 0.0, rise),
                DVec3::new(-10.0, 10.0, rise),
                DVec3::new(0.0, 10.0, 0.0),
            ];
            let normal = DVec3::new(rise.signum(), 0.0, 1.0)
                .normalized()
                .expect("unit");
            FaceGeom {
                index: 1,
                points,
                plane: Plane::new(normal, 0.0),
                ..square()
            }
        };
        let corner = |other: FaceGeom, angles: PhongAngles| {
            let faces = [square(), other];
            let groups = groups(&faces, &HashMap::from([(0, angles)]), None);
            corner_normals(&faces, &groups)[0]
                .as_ref()
                .expect("smoothed")[0]
        };
        let up = DVec3::Z;
        let (trough, ridge) = (lean(10.0), lean(-10.0));
        assert!(!corner(trough.clone(), PhongAngles::of(89.0)).near(up, 1e-6));
        assert!(!corner(ridge.clone(), PhongAngles::of(89.0)).near(up, 1e-6));
        let concave_sharp = PhongAngles {
            angle: 89.0,
            concave: 1.0,
        };
        assert!(corner(trough, concave_sharp).near(up, 1e-12));
        assert!(!corner(ridge, concave_sharp).near(up, 1e-6));
    }
}
