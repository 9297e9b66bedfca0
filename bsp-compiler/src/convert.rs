//! `--convert valve|quake`: rewrite a `.map` with every face's texture projection in the other
//! format, as ericw-tools' `-convert` does.
//!
//! To Valve 220 the conversion is exact: the axes are the texinfo vectors Quake's projection
//! gives the face. To Quake it is exact when a face's Valve axes lie in the plane Quake projects
//! that face onto (what editors write for unrotated, unsheared textures); other axes are
//! projected onto that plane, the nearest Quake can come, and the faces are counted.

use crate::map::{MapFace, MapFile};
use crate::texinfo::{Projection, base_axes};
use glam::DVec3;

use std::fmt::Write;

/// A `.map` dialect, by how faces give their texture projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum MapFormat {
    /// Quake's own: shift, rotation and scale on axes picked from the face's normal.
    Quake,
    /// Valve 220 (`"mapversion" "220"`): explicit texture axes with offsets.
    Valve,
}

impl MapFormat {
    /// The format's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            MapFormat::Quake => "quake",
            MapFormat::Valve => "valve",
        }
    }
}

/// The rewritten map text, and how many faces only came close (see the module comment).
pub fn convert_map(map: &MapFile, to: MapFormat) -> (String, usize) {
    let mut out = String::new();
    let mut approximate = 0;
    for (index, ent) in map.entities.iter().enumerate() {
        let _ = writeln!(out, "// entity {index}\n{{");
        for (key, value) in &ent.entity.pairs {
            if key == "mapversion" {
                continue;
            }
            let _ = writeln!(out, "\"{key}\" \"{value}\"");
        }
        if index == 0 && to == MapFormat::Valve {
            out.push_str("\"mapversion\" \"220\"\n");
        }
        for (bi, brush) in ent.brushes.iter().enumerate() {
            let _ = writeln!(out, "// brush {bi}\n{{");
            for face in &brush.faces {
                let (projection, exact) = converted(face, to);
                approximate += usize::from(!exact);
                write_face(&mut out, face, &projection);
            }
            out.push_str("}\n");
        }
        out.push_str("}\n");
    }
    (out, approximate)
}

fn write_face(out: &mut String, face: &MapFace, projection: &Projection) {
    for p in face.points {
        let _ = write!(out, "( {} {} {} ) ", p.x, p.y, p.z);
    }
    let texture = if face.texture.contains(char::is_whitespace) {
        format!("\"{}\"", face.texture)
    } else {
        face.texture.clone()
    };
    let _ = match *projection {
        Projection::Standard {
            shift,
            rotation,
            scale,
        } => writeln!(
            out,
            "{texture} {} {} {} {} {}",
            shift[0], shift[1], rotation, scale[0], scale[1]
        ),
        Projection::Valve { u, v, scale } => writeln!(
            out,
            "{texture} [ {} {} {} {} ] [ {} {} {} {} ] 0 {} {}",
            u[0], u[1], u[2], u[3], v[0], v[1], v[2], v[3], scale[0], scale[1]
        ),
    };
}

/// `face`'s projection in format `to`, and whether it is exact.
fn converted(face: &MapFace, to: MapFormat) -> (Projection, bool) {
    let Some(plane) = face.plane(DVec3::ZERO) else {
        // No plane, no projection to speak of: the brush is reported as bad when compiled.
        return (face.projection, true);
    };
    let vecs = face.projection.vecs(&plane);
    match to {
        MapFormat::Valve => (to_valve(vecs), true),
        MapFormat::Quake => to_quake(vecs, plane.normal),
    }
}

/// Each texinfo row as a unit axis and a scale (the row is axis / scale).
fn to_valve(vecs: [[f64; 4]; 2]) -> Projection {
    let split = |row: [f64; 4]| {
        let axis = DVec3::new(row[0], row[1], row[2]);
        let len = axis.length();
        if len == 0.0 {
            return (row, 1.0);
        }
        let unit = axis / len;
        ([unit.x, unit.y, unit.z, row[3]], 1.0 / len)
    };
    let (u, su) = split(vecs[0]);
    let (v, sv) = split(vecs[1]);
    Projection::Valve {
        u,
        v,
        scale: [su, sv],
    }
}

/// Angles within this many degrees of a whole number are written whole.
const ROTATION_SNAP: f64 = 1e-6;

/// The Quake projection nearest `vecs` on a face with `normal`: Quake turns the base axes about
/// the two coordinates they use (see [`Projection::vecs`]), so only those components of `vecs`
/// can be kept.
fn to_quake(vecs: [[f64; 4]; 2], normal: DVec3) -> (Projection, bool) {
    let [s0, t0] = base_axes(normal);
    let first_nonzero = |v: DVec3| (0..3).find(|&i| v[i] != 0.0).unwrap_or(2);
    let (p, q) = (first_nonzero(s0), first_nonzero(t0));
    let (s_sign, t_sign) = (s0[p], t0[q]);
    let [r0, r1] = vecs;
    // s axis / scale0 = (cos, sin) * s_sign / scale0 on (p, q).
    let (cos_s, sin_s) = (r0[p] * s_sign, r0[q] * s_sign);
    let len_s = cos_s.hypot(sin_s);
    let mut rotation = sin_s.atan2(cos_s).to_degrees();
    if (rotation - rotation.round()).abs() < ROTATION_SNAP {
        rotation = rotation.round();
    }
    let (sin, cos) = rotation.to_radians().sin_cos();
    // t axis / scale1 = (-sin, cos) * t_sign / scale1 on (p, q).
    let t_len = (-sin * r1[p] + cos * r1[q]) * t_sign;
    let scale = [
        if len_s > 0.0 { 1.0 / len_s } else { 1.0 },
        if t_len != 0.0 { 1.0 / t_len } else { 1.0 },
    ];
    let projection = Projection::Standard {
        shift: [r0[3], r1[3]],
        rotation,
        scale,
    };
    let back = projection.vecs(&quake_formats::geom::Plane::new(normal, 0.0));
    let exact = (0..2).all(|i| (0..3).all(|j| (back[i][j] - vecs[i][j]).abs() < 1e-6));
    (projection, exact)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::parse_map;
    use std::path::Path;

    fn vecs_of(text: &str) -> Vec<[[f64; 4]; 2]> {
        let map = parse_map(Path::new("t.map"), text).expect("parse");
        map.entities[0].brushes[0]
            .faces
            .iter()
            .map(|f| f.projection.vecs(&f.plane(DVec3::ZERO).expect("plane")))
            .collect()
    }

    const BOX: &str = "{\n\"classname\" \"worldspawn\"\n{\n\
        ( 0 0 0 ) ( 0 1 0 ) ( 0 0 1 ) a 3 -7 30 0.5 2\n\
        ( 8 0 0 ) ( 8 0 1 ) ( 8 1 0 ) a 0 0 90 1 1\n\
        ( 0 0 0 ) ( 0 0 1 ) ( 1 0 0 ) a 16 8 -45 2 -1\n\
        ( 0 8 0 ) ( 1 8 0 ) ( 0 8 1 ) a 0 0 0 1 1\n\
        ( 0 0 0 ) ( 1 0 0 ) ( 0 1 0 ) a 5 5 180 0.25 0.25\n\
        ( 0 0 8 ) ( 0 1 8 ) ( 1 0 8 ) a 1 2 270 3 3\n}\n}\n";

    fn close(a: &[[[f64; 4]; 2]], b: &[[[f64; 4]; 2]]) -> bool {
        a.iter()
            .zip(b)
            .all(|(x, y)| (0..2).all(|i| (0..4).all(|j| (x[i][j] - y[i][j]).abs() < 1e-9)))
    }

    #[test]
    fn quake_to_valve_and_back_keeps_every_texinfo() {
        let before = vecs_of(BOX);
        let map = parse_map(Path::new("t.map"), BOX).expect("parse");
        let (valve, approximate) = convert_map(&map, MapFormat::Valve);
        assert_eq!(approximate, 0);
        assert!(valve.contains("\"mapversion\" \"220\"") && valve.contains('['));
        assert!(close(&before, &vecs_of(&valve)));
        let valve_map = parse_map(Path::new("t.map"), &valve).expect("parse");
        let (quake, approximate) = convert_map(&valve_map, MapFormat::Quake);
        assert_eq!(approximate, 0);
        assert!(!quake.contains('[') && !quake.contains("mapversion"));
        assert!(close(&before, &vecs_of(&quake)));
    }

    #[test]
    fn valve_axes_off_the_quake_plane_are_counted() {
        let text = "{\n\"mapversion\" \"220\"\n{\n\
            ( 0 0 8 ) ( 0 1 8 ) ( 1 0 8 ) a [ 1 0 0.5 0 ] [ 0 -1 0 0 ] 0 1 1\n}\n}\n";
        let map = parse_map(Path::new("t.map"), text).expect("parse");
        assert_eq!(convert_map(&map, MapFormat::Quake).1, 1);
    }
}
