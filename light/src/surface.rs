//! `_surface` lights: a light entity used as a template, copied over every
//! face with the named texture, one copy per piece of the face after cutting
//! it on the lines of a grid of `spacing` units (as ericw-tools does), placed
//! `offset` units in front of the piece's middle.
//! A template goes only on faces of its own `_surflight_group` (0 when it has
//! none): a brush model's from its entity, and for the world's faces the group
//! the compiler recorded of the entity each came from (worldspawn,
//! `func_detail*`, `func_group`), as ericw-tools' qbsp records it for its light.

use std::collections::HashMap;

use glam::DVec3;
use quake_formats::geom::{Plane, Split, Winding};

use crate::faces::FaceGeom;
use crate::lights::{PointLight, Spot, SurfaceTemplate};

/// Pieces thinner than this along an axis are not cut off.
const MIN_PIECE: f64 = 8.0;

/// Cuts `w` as Quake's warped-surface subdivision does (and ericw-tools places its surface
/// lights by): along each axis, on the line of the `spacing` grid nearest the piece's middle,
/// unless that leaves a part thinner than [`MIN_PIECE`]; then the parts again. Pieces end no
/// wider than `spacing`, and a face across a grid line is cut there however small it is.
fn subdivide(w: Winding, spacing: f64, out: &mut Vec<Winding>) {
    let b = w.bounds();
    for axis in 0..3 {
        let (lo, hi) = (b.mins[axis], b.maxs[axis]);
        let cut = spacing * ((lo + hi) / 2.0 / spacing + 0.5).floor();
        if hi - cut < MIN_PIECE || cut - lo < MIN_PIECE {
            continue;
        }
        let mut normal = DVec3::ZERO;
        normal[axis] = 1.0;
        if let Split::Both { front, back } = w.split(&Plane::new(normal, cut)) {
            subdivide(front, spacing, out);
            subdivide(back, spacing, out);
            return;
        }
    }
    out.push(w);
}

/// Where the faces' `_surflight_group`s come from.
#[derive(Debug, Clone, Copy)]
pub struct SurfaceGroups<'a> {
    /// Brush models with a non-zero group, and that group.
    pub models: &'a HashMap<usize, i64>,
    /// Per face, the group the compiler recorded (`SLIPGATE_SURFGROUP`), if the BSP has them.
    pub faces: Option<&'a [i32]>,
}

impl SurfaceGroups<'_> {
    /// The group of face `f`: its model's, else the compiler's record of it, else none (0).
    fn of(&self, f: &FaceGeom) -> i64 {
        let recorded = || {
            self.faces
                .and_then(|g| g.get(f.index))
                .map(|&g| i64::from(g))
        };
        self.models
            .get(&f.model)
            .copied()
            .or_else(recorded)
            .unwrap_or(0)
    }
}

/// The lights every template puts on the faces using its texture, in its group. A liquid's
/// faces seen from inside it (those `in_liquid` says look into liquid from their middle) get
/// none, as in ericw-tools.
pub fn expand_templates(
    templates: &[SurfaceTemplate],
    faces: &[FaceGeom],
    groups: SurfaceGroups,
    spacing: f64,
    in_liquid: &dyn Fn(DVec3) -> bool,
) -> Vec<PointLight> {
    let underwater_side = |f: &FaceGeom| {
        let middle = || f.points.iter().sum::<DVec3>() / f.points.len().max(1) as f64;
        f.texture.starts_with('*') && in_liquid(middle() + f.plane.normal)
    };
    let mut out = Vec::new();
    for t in templates {
        for f in faces.iter().filter(|f| {
            f.texture.eq_ignore_ascii_case(&t.texture)
                && groups.of(f) == t.group
                && !underwater_side(f)
        }) {
            let mut pieces = Vec::new();
            subdivide(Winding::new(f.points.clone()), spacing, &mut pieces);
            for piece in pieces {
                let mut light = t.light.clone();
                light.origin = piece.center() + f.plane.normal * t.offset;
                if t.spotlight {
                    light.spot = Some(Spot::new(f.plane.normal, t.spot_angle, 0.0));
                }
                out.push(light);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ericw-tools: a template with a `_surflight_group` emits only from brushes with the same
    /// group, and a template without one not from grouped brushes; a brush model's group is its
    /// entity's, a world face's the one the compiler recorded.
    #[test]
    fn templates_go_only_on_faces_of_their_group() {
        let extents = quake_formats::extents::LightmapExtents {
            tex_mins: [0, -64],
            extents: [64, 64],
        };
        let vecs = [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]];
        let face = |index: usize, model: usize| FaceGeom {
            index,
            model,
            kind: crate::faces::FaceKind::Lit,
            texture: "lava1".to_string(),
            points: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(0.0, 64.0, 0.0),
                DVec3::new(64.0, 64.0, 0.0),
                DVec3::new(64.0, 0.0, 0.0),
            ],
            plane: Plane::new(DVec3::Z, 0.0),
            vecs,
            origin: DVec3::ZERO,
            extents,
            continuations: Default::default(),
            outline: None,
            grid: quake_formats::extents::LuxelGrid::vanilla(&extents, &vecs),
            own_grid: None,
        };
        let faces = [face(0, 0), face(1, 1), face(2, 2), face(3, 0)];
        let template = |group: i64| SurfaceTemplate {
            texture: "LAVA1".to_string(),
            light: PointLight {
                entity: 1,
                ..crate::lights::test_light(crate::lights::Falloff::Linear, 300.0)
            },
            offset: 2.0,
            spotlight: false,
            spot_angle: 40.0,
            group,
        };
        let models = HashMap::from([(1, 7)]);
        let recorded = [0, 0, 0, 3];
        let on = |t: SurfaceTemplate, recorded: Option<&[i32]>| {
            let groups = SurfaceGroups {
                models: &models,
                faces: recorded,
            };
            expand_templates(&[t], &faces, groups, 128.0, &|_| false).len()
        };
        assert_eq!(on(template(0), None), 3, "the world's faces and model 2's");
        assert_eq!(on(template(7), None), 1, "model 1's face only");
        assert_eq!(on(template(3), None), 0);
        assert_eq!(on(template(0), Some(&recorded)), 2, "face 0 and model 2's");
        assert_eq!(on(template(3), Some(&recorded)), 1, "the world's face 3");
    }

    /// As ericw-tools' `-surflight_dump` shows: a 64-unit square across the origin is cut into
    /// four on the grid's lines, one off them is not cut.
    #[test]
    fn small_faces_are_cut_where_grid_lines_cross_them() {
        let square = |lo: f64| {
            let hi = lo + 64.0;
            Winding::new(vec![
                DVec3::new(lo, lo, 0.0),
                DVec3::new(lo, hi, 0.0),
                DVec3::new(hi, hi, 0.0),
                DVec3::new(hi, lo, 0.0),
            ])
        };
        let pieces = |w: Winding| {
            let mut out = Vec::new();
            subdivide(w, 128.0, &mut out);
            out
        };
        let across = pieces(square(-32.0));
        assert_eq!(across.len(), 4);
        for p in &across {
            let c = p.center();
            assert_eq!((c.x.abs(), c.y.abs()), (16.0, 16.0));
        }
        assert_eq!(pieces(square(10.0)).len(), 1);
        // 4 units over a grid line: too thin a part to cut off.
        assert_eq!(pieces(square(-4.0)).len(), 1);
    }

    #[test]
    fn a_300_unit_square_is_cut_on_the_128_grid() {
        let sq = Winding::new(vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 300.0, 0.0),
            DVec3::new(300.0, 300.0, 0.0),
            DVec3::new(300.0, 0.0, 0.0),
        ]);
        let mut pieces = Vec::new();
        subdivide(sq, 128.0, &mut pieces);
        assert_eq!(pieces.len(), 9);
        let area: f64 = pieces.iter().map(Winding::area).sum();
        assert!((area - 90000.0).abs() < 1e-6);
        for p in &pieces {
            let b = p.bounds();
            assert!(b.maxs.x - b.mins.x <= 128.0 + 1e-9);
        }
    }
}
