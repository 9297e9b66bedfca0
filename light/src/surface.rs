//! `_surface` lights: a light entity used as a template, copied over every
//! face with the named texture, one copy per piece of the face after cutting
//! it on a grid of `spacing` units, placed `offset` units in front of it.

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

/// The lights every template puts on the faces using its texture.
pub fn expand_templates(
    templates: &[SurfaceTemplate],
    faces: &[FaceGeom],
    spacing: f64,
) -> Vec<PointLight> {
    let mut out = Vec::new();
    for t in templates {
        for f in faces
            .iter()
            .filter(|f| f.texture.eq_ignore_ascii_case(&t.texture))
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
