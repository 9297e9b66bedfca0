//! `.map` text: entities with their keys and brushes, in Quake's format or Valve 220.

use crate::brushes::MapSide;
use crate::texture::Projection;
use std::fmt::Write;

/// Append entity number `index` with its key/value pairs and brushes.
pub(crate) fn entity(
    out: &mut String,
    index: usize,
    pairs: &[(String, String)],
    brushes: &[Vec<MapSide>],
) {
    let _ = writeln!(out, "// entity {index}\n{{");
    for (key, value) in pairs {
        let _ = writeln!(out, "\"{key}\" \"{value}\"");
    }
    for (b, sides) in brushes.iter().enumerate() {
        let _ = writeln!(out, "// brush {b}\n{{");
        for side in sides {
            face_line(out, side);
        }
        out.push_str("}\n");
    }
    out.push_str("}\n");
}

/// A number as `.map` files spell it: the shortest decimal that reads back as the same `f64`,
/// never `-0`.
fn num(x: f64) -> String {
    format!("{}", x + 0.0)
}

fn face_line(out: &mut String, side: &MapSide) {
    for p in side.points {
        let _ = write!(out, "( {} {} {} ) ", num(p.x), num(p.y), num(p.z));
    }
    // A name with spaces is quoted, as editors that allow them write it.
    if side.texture.contains(char::is_whitespace) {
        let _ = write!(out, "\"{}\"", side.texture);
    } else {
        out.push_str(&side.texture);
    }
    let _ = match side.projection {
        Projection::Quake {
            shift,
            rotation,
            scale,
        } => writeln!(
            out,
            " {} {} {} {} {}",
            num(shift[0]),
            num(shift[1]),
            num(rotation),
            num(scale[0]),
            num(scale[1])
        ),
        Projection::Valve { axes, scale } => {
            let [u, v] = axes.map(|a| a.map(num));
            writeln!(
                out,
                " [ {} {} {} {} ] [ {} {} {} {} ] 0 {} {}",
                u[0],
                u[1],
                u[2],
                u[3],
                v[0],
                v[1],
                v[2],
                v[3],
                num(scale[0]),
                num(scale[1])
            )
        }
    };
}
