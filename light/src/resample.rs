//! Light on one luxel grid read at points of another: bounced light reads the light of the
//! faces it meets between their luxels, and a face lit on its own grid
//! (`--world_units_per_luxel`, `_lmscale`) gives engines that read only Quake's 16-texel
//! lightmap that lightmap from its own, as ericw-tools does.

use crate::faces::FaceGeom;
use crate::samples::vanilla_on_own_grid;
use crate::trace::FaceLight;

/// The light at continuous luxel coordinates `at` of a `size` grid of `luxels` (row-major),
/// bilinear between the four luxels around it; coordinates past the grid's edge read its
/// edge.
pub fn bilinear(luxels: &[[f32; 3]], size: [usize; 2], at: [f64; 2]) -> [f32; 3] {
    let [w, h] = size;
    let coord = |f: f64, size: usize| {
        let last = size.saturating_sub(1);
        let f = f.clamp(0.0, last as f64);
        // `f` is clamped at 0, so truncation is the floor (`floor` is a libm call on x86-64).
        let i = (f as usize).min(last);
        (i, (i + 1).min(last), (f - i as f64) as f32)
    };
    let (x0, x1, fx) = coord(at[0], w);
    let (y0, y1, fy) = coord(at[1], h);
    let luxel = |x: usize, y: usize| luxels.get(y * w + x).copied().unwrap_or_default();
    let (a, b, c, d) = (luxel(x0, y0), luxel(x1, y0), luxel(x0, y1), luxel(x1, y1));
    std::array::from_fn(|k| {
        let top = a[k] + (b[k] - a[k]) * fx;
        let bottom = c[k] + (d[k] - c[k]) * fx;
        top + (bottom - top) * fy
    })
}

/// The lightmap over `face`'s 16-texel extents read from `light`, its light on its own grid:
/// every style, and the directions (bilinear, then made unit again).
pub fn vanilla_from_own(face: &FaceGeom, light: &FaceLight) -> FaceLight {
    let at = vanilla_on_own_grid(face);
    let size = [light.width, light.height];
    let read = |luxels: &[[f32; 3]]| -> Vec<[f32; 3]> {
        at.iter().map(|&p| bilinear(luxels, size, p)).collect()
    };
    let [width, height] = face.extents.luxel_size();
    FaceLight {
        face: light.face,
        width,
        height,
        styles: light.styles.iter().map(|(s, l)| (*s, read(l))).collect(),
        directions: light
            .directions
            .iter()
            .map(|(s, d)| (*s, read(d).into_iter().map(unit_or_zero).collect()))
            .collect(),
    }
}

/// `d` scaled to unit length, or zero (no direction) when it has none.
fn unit_or_zero(d: [f32; 3]) -> [f32; 3] {
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if len > 1e-6 {
        d.map(|c| c / len)
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_blends_between_luxels_and_clamps_at_the_edge() {
        let luxels = [[0.0; 3], [10.0; 3], [20.0; 3], [30.0; 3]];
        assert_eq!(bilinear(&luxels, [2, 2], [0.5, 0.5]), [15.0; 3]);
        assert_eq!(bilinear(&luxels, [2, 2], [1.0, 0.0]), [10.0; 3]);
        assert_eq!(bilinear(&luxels, [2, 2], [-3.0, 9.0]), [20.0; 3]);
    }

    #[test]
    fn directions_stay_unit_or_none() {
        assert_eq!(unit_or_zero([0.0, 3.0, 4.0]), [0.0, 0.6, 0.8]);
        assert_eq!(unit_or_zero([0.0; 3]), [0.0; 3]);
    }
}
