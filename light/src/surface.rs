//! `_surface` lights: a light entity used as a template, copied over every
//! face with the named texture, one copy per piece of the face after cutting
//! it on a grid of `spacing` units, placed `offset` units in front of it.
//! A template with a `_surflight_group` only goes on faces of brush models
//! with that group (and one without on faces of models without one).

use std::collections::HashMap;

use glam::DVec3;
use quake_formats::geom::{Plane, Split, Winding};

use crate::faces::FaceGeom;
use crate::lights::{PointLight, Spot, SurfaceTemplate};

/// Default grid spacing of surface light copies (ericw-tools' 128).
pub const DEFAULT_SPACING: f64 = 128.0;

/// Cuts `w` on axial planes until no piece spans more than `spacing` on any axis.
fn subdivide(w: Winding, spacing: f64, out: &mut Vec<Winding>) {
    let b = w.bounds();
    for axis in 0..3 {
        let (lo, hi) = (b.mins[axis], b.maxs[axis]);
        if hi - lo <= spacing {
            continue;
        }
        let mut cut = ((lo / spacing).floor() + 1.0) * spacing;
        if cut <= lo + 1.0 || cut >= hi - 1.0 {
            cut = (lo + hi) / 2.0;
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

/// The lights every template puts on the faces using its texture, in its group (`groups`:
/// brush models with a non-zero `_surflight_group`).
pub fn expand_templates(
    templates: &[SurfaceTemplate],
    faces: &[FaceGeom],
    groups: &HashMap<usize, i64>,
    spacing: f64,
) -> Vec<PointLight> {
    let group_of = |model: usize| groups.get(&model).copied().unwrap_or(0);
    let mut out = Vec::new();
    for t in templates {
        for f in faces
            .iter()
            .filter(|f| f.texture.eq_ignore_ascii_case(&t.texture) && group_of(f.model) == t.group)
        {
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
    /// group, and a template without one not from grouped brushes.
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
            continuations: Vec::new(),
            grid: quake_formats::extents::LuxelGrid::vanilla(&extents, &vecs),
            own_grid: None,
        };
        let faces = [face(0, 0), face(1, 1), face(2, 2)];
        let template = |group: i64| SurfaceTemplate {
            texture: "LAVA1".to_string(),
            light: PointLight {
                origin: DVec3::ZERO,
                light: 300.0,
                atten: 1.0,
                falloff: crate::lights::Falloff::Linear,
                color: DVec3::ONE,
                style: 0,
                spot: None,
                anglescale: 0.5,
                dirt: None,
                bounce: true,
                entity: 1,
            },
            offset: 2.0,
            spotlight: false,
            spot_angle: 40.0,
            group,
        };
        let groups = HashMap::from([(1, 7)]);
        let on = |t: SurfaceTemplate| expand_templates(&[t], &faces, &groups, 128.0).len();
        assert_eq!(on(template(0)), 2, "the world's face and model 2's");
        assert_eq!(on(template(7)), 1, "model 1's face only");
        assert_eq!(on(template(3)), 0);
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
