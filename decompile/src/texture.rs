//! Texture projections back from texinfo vectors, and what a texture name makes of a brush.
//!
//! A texinfo row is `s = p · axis + offset`. Valve 220 writes the axis as a unit vector with a
//! scale (the axis is `unit / scale`), so it recovers every texinfo. Quake's own format only
//! rotates and scales the axes of the base direction nearest the face's normal, so it recovers
//! a texinfo when its axes lie in that base plane (what Quake-format maps compile to) and comes
//! as close as it can otherwise.

use glam::DVec3;
use quake_formats::bsp::contents;
use quake_formats::geom::Plane;

/// A texture projection as a `.map` face line gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Projection {
    /// Quake's format: shift, rotation (degrees) and scale.
    Quake {
        shift: [f64; 2],
        rotation: f64,
        scale: [f64; 2],
    },
    /// Valve 220: unit axes with their offsets, and scales.
    Valve {
        axes: [[f64; 4]; 2],
        scale: [f64; 2],
    },
}

/// Quake's base directions, in the order it tries them (the first of equally near wins), each
/// with the texture's s and t axes on faces nearest it.
const BASES: [(DVec3, DVec3, DVec3); 6] = [
    (DVec3::Z, DVec3::X, DVec3::NEG_Y),
    (DVec3::NEG_Z, DVec3::X, DVec3::NEG_Y),
    (DVec3::X, DVec3::Y, DVec3::NEG_Z),
    (DVec3::NEG_X, DVec3::Y, DVec3::NEG_Z),
    (DVec3::Y, DVec3::X, DVec3::NEG_Z),
    (DVec3::NEG_Y, DVec3::X, DVec3::NEG_Z),
];

/// The unrotated s and t axes Quake projects a face of `normal` with.
pub(crate) fn quake_axes(normal: DVec3) -> (DVec3, DVec3) {
    let mut best = (0, 0.0);
    for (i, base) in BASES.iter().enumerate() {
        let d = normal.dot(base.0);
        if d > best.1 {
            best = (i, d);
        }
    }
    (BASES[best.0].1, BASES[best.0].2)
}

/// The coordinate an unrotated axis runs along (each is a signed unit vector on one axis).
fn axis_index(v: DVec3) -> usize {
    v.abs().max_position()
}

/// Texinfo rows Quake's projection gives a face of `normal`: the base axes turned by `rotation`
/// within the two coordinates they run along, then divided by the scales.
pub(crate) fn quake_rows(
    normal: DVec3,
    shift: [f64; 2],
    rotation: f64,
    scale: [f64; 2],
) -> [[f64; 4]; 2] {
    let (s, t) = quake_axes(normal);
    let (p, q) = (axis_index(s), axis_index(t));
    // Compilers take right angles exactly; here the rows only measure how close a fit came,
    // and sin_cos is within 1e-16 of those.
    let (sin, cos) = rotation.to_radians().sin_cos();
    let turn = |v: DVec3| {
        let mut out = v;
        out[p] = cos * v[p] - sin * v[q];
        out[q] = sin * v[p] + cos * v[q];
        out
    };
    let row = |axis: DVec3, scale: f64, shift: f64| {
        let a = turn(axis) / if scale == 0.0 { 1.0 } else { scale };
        [a.x, a.y, a.z, shift]
    };
    [row(s, scale[0], shift[0]), row(t, scale[1], shift[1])]
}

/// `rows` as Valve 220 axes and scales (exact).
pub(crate) fn to_valve(rows: [[f64; 4]; 2], normal: DVec3) -> Projection {
    let (base_s, base_t) = quake_axes(normal);
    let mut axes = [[0.0; 4]; 2];
    let mut scale = [1.0; 2];
    for (i, base) in [base_s, base_t].into_iter().enumerate() {
        let axis = DVec3::new(rows[i][0], rows[i][1], rows[i][2]);
        let len = axis.length();
        // A row without a direction has no projection to keep: Quake's unrotated axis.
        let unit = if len > 1e-9 { axis / len } else { base };
        axes[i] = [tidy(unit.x), tidy(unit.y), tidy(unit.z), tidy(rows[i][3])];
        scale[i] = if len > 1e-9 { tidy(1.0 / len) } else { 1.0 };
    }
    Projection::Valve { axes, scale }
}

/// The Quake projection nearest `rows` on a face of `plane` (in map coordinates), and whether it
/// gives the face the same texture coordinates.
///
/// On the face's plane a row and the row plus any multiple of the plane's normal (with the
/// offset moved to match) map every point alike, so each row is first moved along the normal
/// into the two coordinates Quake's base axes for the plane run along: a Valve 220 projection
/// on a slope becomes the Quake one that looks the same. What is left is exact unless the two
/// rows are sheared against each other, which Quake's one rotation for both cannot express.
pub(crate) fn to_quake(rows: [[f64; 4]; 2], plane: &Plane) -> (Projection, bool) {
    let normal = plane.normal;
    let (s, t) = quake_axes(normal);
    let (p, q) = (axis_index(s), axis_index(t));
    let dropped = 3 - p - q;
    let mut rows = rows;
    if normal[dropped].abs() > 1e-9 {
        for row in &mut rows {
            let k = -row[dropped] / normal[dropped];
            for (axis, component) in row.iter_mut().take(3).enumerate() {
                *component += k * normal[axis];
            }
            row[dropped] = 0.0;
            row[3] -= k * plane.dist;
        }
    }
    let (s_sign, t_sign) = (s[p], t[q]);
    let (cos_s, sin_s) = (rows[0][p] * s_sign, rows[0][q] * s_sign);
    let s_len = cos_s.hypot(sin_s);
    let rotation = if s_len > 1e-9 {
        tidy_within(sin_s.atan2(cos_s).to_degrees(), ROTATION_NOISE)
    } else {
        0.0
    };
    let (sin, cos) = rotation.to_radians().sin_cos();
    let t_len = (cos * rows[1][q] - sin * rows[1][p]) * t_sign;
    let scale = [
        if s_len > 1e-9 { tidy(1.0 / s_len) } else { 1.0 },
        if t_len.abs() > 1e-9 {
            tidy(1.0 / t_len)
        } else {
            1.0
        },
    ];
    let shift = [tidy(rows[0][3]), tidy(rows[1][3])];
    let back = quake_rows(normal, shift, rotation, scale);
    let exact = (0..2).all(|i| {
        (0..3).all(|k| (back[i][k] - rows[i][k]).abs() < 1e-5)
            && (back[i][3] - rows[i][3]).abs() < 1e-3
    });
    (
        Projection::Quake {
            shift,
            rotation,
            scale,
        },
        exact,
    )
}

/// The projection an untextured side gets: Quake's unrotated axes.
pub(crate) fn plain(normal: DVec3, valve: bool) -> Projection {
    let shift = [0.0; 2];
    let scale = [1.0; 2];
    if valve {
        to_valve(quake_rows(normal, shift, 0.0, scale), normal)
    } else {
        Projection::Quake {
            shift,
            rotation: 0.0,
            scale,
        }
    }
}

/// How far a value read from `f32` fields may be from the number it stood for, per unit of
/// its size: four `f32` steps (texinfo rows are sums and quotients of a few `f32` values).
const F32_NOISE: f64 = 4.8e-7;

/// How far a rotation recovered from `f32` axes may be from the angle it stood for, in degrees.
const ROTATION_NOISE: f64 = 1e-5;

/// The most decimals a tidied number keeps: few enough that a number read from `f32` is seldom
/// within the noise of one by chance.
const TIDY_DECIMALS: i32 = 5;

/// `x` read from `f32` data, with the noise taken off: the number of at most five decimals
/// within `F32_NOISE` of it (relative to its size, at least 1), when there is one: a scale of
/// 0.49999997 is 0.5, one of -1.0000004 is -1. Otherwise `x`.
pub(crate) fn tidy(x: f64) -> f64 {
    tidy_within(x, F32_NOISE * x.abs().max(1.0))
}

/// `x` with at most five decimals when that moves it by `noise` at most.
fn tidy_within(x: f64, noise: f64) -> f64 {
    for digits in 0..=TIDY_DECIMALS {
        let m = 10f64.powi(digits);
        let r = (x * m).round() / m;
        if (r - x).abs() <= noise {
            return r + 0.0;
        }
    }
    x + 0.0
}

/// What a face's texture makes of its brush in Quake compilers (the first face that gives any
/// contents decides them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Gives {
    /// This contents value.
    Contents(i32),
    /// Only the clip hulls (`clip`).
    Clip,
    /// Nothing (`hint`, `hintskip`, `origin`).
    Nothing,
}

/// What a texture named `name` gives its brush.
pub(crate) fn gives(name: &str) -> Gives {
    let lower = name.to_ascii_lowercase();
    if lower.starts_with("sky") {
        Gives::Contents(contents::SKY)
    } else if let Some(liquid) = lower.strip_prefix('*') {
        Gives::Contents(liquid_contents(liquid))
    } else {
        match lower.as_str() {
            "clip" => Gives::Clip,
            "hint" | "hintskip" | "origin" => Gives::Nothing,
            _ => Gives::Contents(contents::SOLID),
        }
    }
}

/// A liquid's contents from its name after the `*`.
fn liquid_contents(name: &str) -> i32 {
    if name.contains("lava") {
        contents::LAVA
    } else if name.contains("slime") {
        contents::SLIME
    } else {
        contents::WATER
    }
}

/// The name an untextured side of a brush of `value` gets when no texture of the brush's own
/// kind is at hand: `skip` for solid (ericw-tools' choice), and ericw-tools' names of skipped
/// liquid and sky faces otherwise, which still give their brush its contents.
pub(crate) fn default_name(value: i32) -> &'static str {
    match value {
        contents::WATER => "*waterskip",
        contents::SLIME => "*slimeskip",
        contents::LAVA => "*lavaskip",
        contents::SKY => "skyskip",
        _ => "skip",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [[f64; 4]; 2], b: [[f64; 4]; 2]) -> bool {
        (0..2).all(|i| (0..4).all(|k| (a[i][k] - b[i][k]).abs() < 1e-9))
    }

    #[test]
    fn quake_projections_come_back_exactly() {
        let normals = [
            DVec3::Z,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::new(0.6, 0.0, 0.8),
            DVec3::new(0.0, -0.8, 0.6),
        ];
        for normal in normals {
            for (shift, rotation, scale) in [
                ([0.0, 0.0], 0.0, [1.0, 1.0]),
                ([16.0, -8.0], 30.0, [0.5, 2.0]),
                ([3.0, 5.0], 90.0, [-1.0, 1.0]),
                ([1.0, 2.0], -45.0, [1.0, -0.25]),
                ([7.0, 0.0], 180.0, [2.0, 2.0]),
            ] {
                let rows = quake_rows(normal, shift, rotation, scale);
                let (back, exact) = to_quake(rows, &Plane::new(normal, 40.0));
                assert!(exact, "{normal} {shift:?} {rotation} {scale:?}: {back:?}");
                let Projection::Quake {
                    shift: s,
                    rotation: r,
                    scale: sc,
                } = back
                else {
                    panic!("quake projection expected");
                };
                assert!(close(quake_rows(normal, s, r, sc), rows));
            }
        }
    }

    #[test]
    fn a_valve_projection_on_a_slope_is_exact_in_quake_format() {
        // A texture laid along a 30 degree ramp in Valve 220: its t axis runs up the slope.
        let normal = DVec3::new(0.0, -0.5, 0.866_025_403_784_438_6);
        let plane = Plane::new(normal, 100.0);
        let up_slope = DVec3::new(0.0, 0.866_025_403_784_438_6, 0.5);
        let rows = [
            [1.0, 0.0, 0.0, 3.0],
            [-up_slope.x, -up_slope.y, -up_slope.z, 5.0],
        ];
        let (quake, exact) = to_quake(rows, &plane);
        assert!(exact, "{quake:?}");
        let Projection::Quake {
            shift,
            rotation,
            scale,
        } = quake
        else {
            panic!("quake projection expected");
        };
        // Every point of the plane gets the texture coordinates the Valve rows give it.
        let back = quake_rows(normal, shift, rotation, scale);
        for p in [
            normal * 100.0,
            normal * 100.0 + DVec3::X * 17.0 + up_slope * 40.0,
        ] {
            for i in 0..2 {
                let want = DVec3::new(rows[i][0], rows[i][1], rows[i][2]).dot(p) + rows[i][3];
                let got = DVec3::new(back[i][0], back[i][1], back[i][2]).dot(p) + back[i][3];
                // Within what taking the f32 noise off the offsets may move them.
                assert!((want - got).abs() < 1e-4, "{want} {got}");
            }
        }
    }

    #[test]
    fn sheared_axes_are_inexact_in_quake_format() {
        let rows = [[1.0, 0.5, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]];
        assert!(!to_quake(rows, &Plane::new(DVec3::Z, 0.0)).1);
        let Projection::Valve { axes, scale } = to_valve(rows, DVec3::Z) else {
            panic!("valve projection expected");
        };
        let len = 1.25f64.sqrt();
        assert!((scale[0] - 1.0 / len).abs() < 1e-6);
        assert!((axes[0][1] - 0.5 / len).abs() < 1e-6);
    }

    #[test]
    fn tidy_removes_f32_noise_only() {
        assert_eq!(tidy(f64::from(0.5f32 - f32::EPSILON / 4.0)), 0.5);
        assert_eq!(tidy(29.999_998), 30.0);
        assert_eq!(tidy(12.031_25), 12.031_25);
        assert_eq!(tidy(-0.0), 0.0);
        assert_eq!(tidy(-1.000_000_357_627_996_6), -1.0);
        let irrational = f64::from(std::f32::consts::FRAC_1_SQRT_2);
        assert_eq!(tidy(irrational), irrational);
    }

    #[test]
    fn names_give_their_contents() {
        assert_eq!(gives("SKY4"), Gives::Contents(contents::SKY));
        assert_eq!(gives("*lava1"), Gives::Contents(contents::LAVA));
        assert_eq!(gives("*slime0"), Gives::Contents(contents::SLIME));
        assert_eq!(gives("*04water"), Gives::Contents(contents::WATER));
        assert_eq!(gives("skip"), Gives::Contents(contents::SOLID));
        assert_eq!(gives("clip"), Gives::Clip);
        assert_eq!(gives("hint"), Gives::Nothing);
        for value in [
            contents::WATER,
            contents::SLIME,
            contents::LAVA,
            contents::SKY,
            contents::SOLID,
        ] {
            assert_eq!(gives(default_name(value)), Gives::Contents(value));
        }
    }
}
