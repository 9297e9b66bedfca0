//! Which BSP faces lie on each side of a leaf's region, and the texture each side takes from
//! them. A side that meets faces of different textures (a leaf the tree did not split where two
//! map brushes met on one plane) is cut along one of those faces' edges until each side has one.

use crate::leaves::bsp_plane;
use crate::region::{Region, SideSource};
use quake_formats::Bsp;
use quake_formats::bsp::Model;
use quake_formats::geom::{ON_EPSILON, Plane, PlaneSide, Winding};
use std::collections::HashMap;

/// A face piece smaller than this (square units) is a touch along an edge, not a face on the side.
const MIN_PIECE_AREA: f64 = 0.01;

/// Two texinfos of one texture whose axes differ by less than this per component, and whose
/// offsets by less than [`SAME_OFFSET`] texels (modulo the texture's size), look the same: the
/// compiler nudges offsets by fractions of a texel so engines agree on lightmap sizes.
const SAME_AXIS: f64 = 1e-4;
const SAME_OFFSET: f64 = 0.25;

/// How many pieces one leaf may be cut into to give each side one texture: a bound on the work a
/// damaged or pathological file can ask for (real leaves take a few).
const MAX_PIECES: usize = 64;

/// The faces of one model, by the index of the plane they lie on.
pub(crate) struct ModelFaces<'a> {
    bsp: &'a Bsp,
    by_plane: HashMap<u32, Vec<usize>>,
}

impl<'a> ModelFaces<'a> {
    pub fn new(bsp: &'a Bsp, model: &Model) -> ModelFaces<'a> {
        let mut by_plane: HashMap<u32, Vec<usize>> = HashMap::new();
        let first = model.first_face as usize;
        let end = first
            .saturating_add(model.num_faces as usize)
            .min(bsp.faces.len());
        for i in first..end {
            by_plane.entry(bsp.faces[i].plane).or_default().push(i);
        }
        ModelFaces { bsp, by_plane }
    }
}

/// The part of a BSP face that lies on a side.
#[derive(Debug, Clone)]
pub(crate) struct FacePiece {
    pub face: usize,
    pub texinfo: u32,
    pub winding: Winding,
}

/// The faces on each side of `region` that face out of it, clipped to the side.
pub(crate) fn side_faces(faces: &ModelFaces, region: &Region) -> Vec<Vec<FacePiece>> {
    region
        .sides
        .iter()
        .enumerate()
        .map(|(i, side)| {
            let SideSource::Node(node) = side.source else {
                return Vec::new();
            };
            let Some(plane_index) = faces.bsp.nodes.get(node).map(|n| n.plane) else {
                return Vec::new();
            };
            let mut side_box = side.winding.bounds();
            side_box.mins -= ON_EPSILON;
            side_box.maxs += ON_EPSILON;
            let candidates = faces.by_plane.get(&plane_index).map_or(&[][..], |v| v);
            candidates
                .iter()
                .filter_map(|&f| {
                    let face = faces.bsp.faces.get(f)?;
                    let plane = bsp_plane(faces.bsp, face.plane)?;
                    let facing = if face.side != 0 {
                        plane.flipped()
                    } else {
                        plane
                    };
                    if facing.normal.dot(side.plane.normal) < 0.99 {
                        return None;
                    }
                    let points = faces.bsp.face_vertices(face)?;
                    let mut w = Winding::new(
                        points
                            .iter()
                            .map(|p| glam::DVec3::from(p.map(f64::from)))
                            .collect(),
                    );
                    if !w.is_finite() || !w.bounds().intersects(&side_box) {
                        return None;
                    }
                    for (j, other) in region.sides.iter().enumerate() {
                        if j != i {
                            w = w.clip_front(&other.plane.flipped(), false)?;
                        }
                    }
                    (!w.is_tiny() && w.area() > MIN_PIECE_AREA).then_some(FacePiece {
                        face: f,
                        texinfo: face.texinfo,
                        winding: w,
                    })
                })
                .collect()
        })
        .collect()
}

/// Whether faces of texinfos `a` and `b` show the same texture the same way.
pub(crate) fn same_look(bsp: &Bsp, a: u32, b: u32) -> bool {
    if a == b {
        return true;
    }
    let (Some(ta), Some(tb)) = (bsp.texinfo.get(a as usize), bsp.texinfo.get(b as usize)) else {
        return false;
    };
    if ta.miptex != tb.miptex {
        return false;
    }
    let size = bsp
        .textures
        .textures
        .get(ta.miptex as usize)
        .and_then(|t| t.as_ref())
        .map(|t| [f64::from(t.width), f64::from(t.height)]);
    (0..2).all(|row| {
        let axes_close = (0..3)
            .all(|k| (f64::from(ta.vecs[row][k]) - f64::from(tb.vecs[row][k])).abs() < SAME_AXIS);
        let mut d = (f64::from(ta.vecs[row][3]) - f64::from(tb.vecs[row][3])).abs();
        if let Some(size) = size.map(|s| s[row]).filter(|&s| s > 0.0) {
            d %= size;
            d = d.min(size - d);
        }
        axes_close && d < SAME_OFFSET
    })
}

/// The face a side takes its texture from: the largest piece of the look covering most of the
/// side. `None` when no face lies on it.
pub(crate) fn side_face(bsp: &Bsp, pieces: &[FacePiece]) -> Option<SideFace> {
    // Per look: its largest piece and the look's total area.
    let mut looks: Vec<(&FacePiece, f64, f64)> = Vec::new();
    for piece in pieces {
        let area = piece.winding.area();
        match looks
            .iter_mut()
            .find(|l| same_look(bsp, l.0.texinfo, piece.texinfo))
        {
            Some(look) => {
                look.2 += area;
                if area > look.1 {
                    (look.0, look.1) = (piece, area);
                }
            }
            None => looks.push((piece, area, area)),
        }
    }
    looks
        .into_iter()
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .map(|l| SideFace {
            face: l.0.face,
            texinfo: l.0.texinfo,
        })
}

/// The BSP face a side takes its texture from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SideFace {
    pub face: usize,
    pub texinfo: u32,
}

/// A region with the faces on each of its sides.
#[derive(Debug, Clone)]
pub(crate) struct TexturedRegion {
    pub region: Region,
    /// Per side, the face it takes its texture from.
    pub faces: Vec<Option<SideFace>>,
}

/// `region` with a texinfo per side; when `split` is set, first cut where one side meets faces
/// of different looks. Returns the pieces.
pub(crate) fn texture_region(
    faces: &ModelFaces,
    region: Region,
    split: bool,
) -> Vec<TexturedRegion> {
    let mut out = Vec::new();
    let mut work = vec![region];
    while let Some(region) = work.pop() {
        let pieces = side_faces(faces, &region);
        if split && out.len() + work.len() + 2 <= MAX_PIECES {
            // The first side of mixed looks that a cut separates.
            let halves = pieces
                .iter()
                .zip(&region.sides)
                .filter(|(p, _)| mixed(faces.bsp, p))
                .filter_map(|(p, side)| best_cut(faces.bsp, p, &side.plane))
                .find_map(|cut| match region.split(&cut, SideSource::Cut) {
                    (Some(front), Some(back)) => Some((front, back)),
                    _ => None,
                });
            if let Some((front, back)) = halves {
                work.push(back);
                work.push(front);
                continue;
            }
        }
        let chosen = pieces.iter().map(|p| side_face(faces.bsp, p)).collect();
        out.push(TexturedRegion {
            region,
            faces: chosen,
        });
    }
    out
}

/// Whether the pieces on one side show more than one look.
fn mixed(bsp: &Bsp, pieces: &[FacePiece]) -> bool {
    pieces
        .iter()
        .any(|p| !same_look(bsp, p.texinfo, pieces[0].texinfo))
}

/// The plane through an edge of one of the pieces, square to the side, that best separates the
/// pieces of different looks: it has a piece of one look wholly in front and one of another
/// wholly behind, and cuts the fewest pieces. Axial planes and whole distances are snapped, so
/// the cut's points can be written as whole numbers.
fn best_cut(bsp: &Bsp, pieces: &[FacePiece], side_plane: &Plane) -> Option<Plane> {
    let mut best: Option<(usize, Plane)> = None;
    for piece in pieces {
        let points = &piece.winding.points;
        let inside = piece.winding.center();
        for (i, &a) in points.iter().enumerate() {
            let b = points[(i + 1) % points.len()];
            let Some(normal) = (b - a).cross(side_plane.normal).try_normalize() else {
                continue;
            };
            let mut cut = Plane::new(normal, normal.dot(a)).snapped((a + b) * 0.5);
            if cut.distance(inside) > 0.0 {
                cut = cut.flipped();
            }
            let sides: Vec<PlaneSide> = pieces.iter().map(|p| p.winding.side_of(&cut)).collect();
            let front = pieces
                .iter()
                .zip(&sides)
                .find(|(_, s)| **s == PlaneSide::Front);
            let back = pieces
                .iter()
                .zip(&sides)
                .find(|(_, s)| **s == PlaneSide::Back);
            let separates = match (front, back) {
                (Some((f, _)), Some(_)) => pieces
                    .iter()
                    .zip(&sides)
                    .any(|(p, s)| *s == PlaneSide::Back && !same_look(bsp, p.texinfo, f.texinfo)),
                _ => false,
            };
            if !separates {
                continue;
            }
            let crossed = sides.iter().filter(|s| **s == PlaneSide::Cross).count();
            if best.is_none_or(|(c, _)| crossed < c) {
                best = Some((crossed, cut));
            }
        }
    }
    best.map(|(_, cut)| cut)
}
