//! A face's lightmap extents: its texture-space bounds snapped to the 16-texel grid.
//!
//! Computed one way for everyone (compiler, light, viewer, validator), in the precision engines
//! use: vertex and texture-vector components are `f32` in the file and are multiplied and summed
//! in `f64`, as QuakeSpasm and its descendants do, and each sum is then rounded to `f32`, because
//! every engine keeps it in a `float` (QuakeSpasm's `val`, vanilla's x87 result stored to a
//! float) before snapping it to the grid. Without that rounding a coordinate a few millionths
//! below a grid line (common on rotated brushes) snaps one luxel further out than in the engine,
//! and the engine then reads the face's lightmap with the wrong row length.
//!
//! DarkPlaces differs: [`LightmapExtents::from_points_darkplaces`] is its rule. A coordinate
//! within a few `f32` steps of a grid line can snap to different lines under the two rules; the
//! validator's `lightmap-extents-engines-disagree` finds such faces and the compiler nudges
//! texture offsets until there are none.

use crate::bsp::limits::LIGHTMAP_SCALE;

/// Grid lines beyond this (2^25 luxels, far past any real map) are clamped.
const GRID_CLAMP: f64 = (1 << 25) as f64;

/// The lightmap rectangle of a face, in texels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LightmapExtents {
    /// Texture coordinates of luxel (0, 0): the face's minimum s/t rounded down to the grid.
    pub tex_mins: [i32; 2],
    /// Size of the rectangle in texels, a multiple of 16.
    pub extents: [i32; 2],
}

impl LightmapExtents {
    /// The extents QuakeSpasm and its family (and vanilla, and ericw-tools' light) compute.
    pub fn from_points(points: &[[f32; 3]], vecs: &[[f32; 4]; 2]) -> LightmapExtents {
        Self::snapped(points, vecs, |p, v| {
            (p[0] as f64 * v[0] as f64
                + p[1] as f64 * v[1] as f64
                + p[2] as f64 * v[2] as f64
                + v[3] as f64) as f32
        })
    }

    /// The extents DarkPlaces computes. Its vectors are `float` (`vec_t`) and its dot-product
    /// macro multiplies and adds in plain `float` arithmetic, left to right: the x and y
    /// products are added, then the z product, each step rounded to `f32`, and the texture
    /// offset is added last, rounded again. The running minimum and maximum are floats too; only
    /// the division by 16 and the floor/ceil happen in `double`, which is exact for a float and
    /// so matches the other rule's snapping.
    pub fn from_points_darkplaces(points: &[[f32; 3]], vecs: &[[f32; 4]; 2]) -> LightmapExtents {
        Self::snapped(points, vecs, |p, v| {
            (p[0] * v[0] + p[1] * v[1]) + p[2] * v[2] + v[3]
        })
    }

    /// Which axes (s, t) the two engine rules put on different grid lines (either end).
    pub fn engines_disagree(points: &[[f32; 3]], vecs: &[[f32; 4]; 2]) -> [bool; 2] {
        let a = Self::from_points(points, vecs);
        let b = Self::from_points_darkplaces(points, vecs);
        std::array::from_fn(|axis| {
            a.tex_mins[axis] != b.tex_mins[axis] || a.extents[axis] != b.extents[axis]
        })
    }

    /// The texture-space bounds of `points`, each coordinate computed by `coord` from a point
    /// and a texture axis row, snapped outward to the grid.
    fn snapped(
        points: &[[f32; 3]],
        vecs: &[[f32; 4]; 2],
        coord: impl Fn(&[f32; 3], &[f32; 4]) -> f32,
    ) -> LightmapExtents {
        let mut mins = [f64::INFINITY; 2];
        let mut maxs = [f64::NEG_INFINITY; 2];
        for p in points {
            for axis in 0..2 {
                let val = coord(p, &vecs[axis]) as f64;
                mins[axis] = mins[axis].min(val);
                maxs[axis] = maxs[axis].max(val);
            }
        }
        let scale = LIGHTMAP_SCALE as f64;
        let mut tex_mins = [0; 2];
        let mut extents = [0; 2];
        for axis in 0..2 {
            if points.is_empty() {
                break;
            }
            // Damaged files can hold absurd coordinates; clamping keeps the arithmetic in range
            // (such a face fails every size check downstream anyway).
            let lo = (mins[axis] / scale).floor().clamp(-GRID_CLAMP, GRID_CLAMP) as i32;
            let hi = (maxs[axis] / scale).ceil().clamp(-GRID_CLAMP, GRID_CLAMP) as i32;
            tex_mins[axis] = lo * LIGHTMAP_SCALE;
            // All-NaN coordinates leave lo above hi.
            extents[axis] = (hi - lo).max(0) * LIGHTMAP_SCALE;
        }
        LightmapExtents { tex_mins, extents }
    }

    /// Luxels across (s) and down (t): one per grid line, so extent/16 + 1.
    pub fn luxel_size(&self) -> [usize; 2] {
        [
            (self.extents[0] / LIGHTMAP_SCALE) as usize + 1,
            (self.extents[1] / LIGHTMAP_SCALE) as usize + 1,
        ]
    }

    /// Luxels in the whole lightmap: the bytes one style takes in the lighting lump.
    pub fn luxel_count(&self) -> usize {
        let [w, h] = self.luxel_size();
        w * h
    }

    /// Texture coordinates (s, t) of luxel (x, y).
    pub fn luxel_st(&self, x: usize, y: usize) -> [f64; 2] {
        [
            (self.tex_mins[0] + x as i32 * LIGHTMAP_SCALE) as f64,
            (self.tex_mins[1] + y as i32 * LIGHTMAP_SCALE) as f64,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_coordinates_give_an_empty_extent() {
        let pts = [[f32::NAN; 3], [f32::NAN; 3]];
        let e = LightmapExtents::from_points(&pts, &AXIAL);
        assert_eq!(e.extents, [0, 0]);
        assert_eq!(e.luxel_count(), 1);
    }

    #[test]
    fn absurd_coordinates_do_not_overflow() {
        let pts = [[-3.0e38, 0.0, 0.0], [3.0e38, f32::NAN, 0.0]];
        let e = LightmapExtents::from_points(&pts, &AXIAL);
        assert!(e.luxel_count() > 0);
    }

    const AXIAL: [[f32; 4]; 2] = [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]];

    #[test]
    fn a_64_unit_square_has_5x5_luxels() {
        let pts = [
            [0.0, 0.0, 0.0],
            [64.0, 0.0, 0.0],
            [64.0, 64.0, 0.0],
            [0.0, 64.0, 0.0],
        ];
        let e = LightmapExtents::from_points(&pts, &AXIAL);
        assert_eq!(e.tex_mins, [0, -64]);
        assert_eq!(e.extents, [64, 64]);
        assert_eq!(e.luxel_size(), [5, 5]);
    }

    #[test]
    fn off_grid_points_round_outward() {
        let pts = [[1.5, 0.0, 0.0], [30.25, -17.0, 0.0], [8.0, 3.0, 0.0]];
        let e = LightmapExtents::from_points(&pts, &AXIAL);
        assert_eq!(e.tex_mins, [0, -16]);
        assert_eq!(e.extents, [32, 48]);
    }

    /// Face 9288 of our BSP of LibreQuake e1m3 (a brush rotated 10 degrees): its coordinates lie
    /// within 5e-5 texels of grid lines, on either side. Summed in f64 alone they gave 5x4 luxels;
    /// QuakeSpasm, rounding each sum to a float, reads 3x3, so it drew our lightmap skewed.
    #[test]
    fn sums_are_rounded_to_f32_as_engines_store_them() {
        let vecs = ROTATED_10_DEGREES;
        let pts = [
            [2765.9216, 227.831_38, 32.0],
            [2734.4077, 233.388_12, 32.0],
            [2739.9644, 264.901_98, 32.0],
            [2771.4783, 259.345_2, 32.0],
        ];
        let e = LightmapExtents::from_points(&pts, &vecs);
        assert_eq!(e.tex_mins, [2656, -736]);
        assert_eq!(e.luxel_size(), [3, 3]);
    }

    const ROTATED_10_DEGREES: [[f32; 4]; 2] = [
        [0.984_807_7, -0.173_648_18, 0.0, 3.661_621],
        [-0.173_648_18, -0.984_807_7, 0.0, 0.667_358_4],
    ];

    /// A vertex of a face textured at 10 degrees lies on the grid line s = 80 when summed in
    /// f64 (rounded to f32: exactly 80), and one f32 step past it when summed in f32, so
    /// DarkPlaces gives the face one luxel more along s than QuakeSpasm.
    #[test]
    fn darkplaces_sums_in_f32_and_can_snap_to_another_grid_line() {
        let pts = [
            [160.220_55, 469.040_65, 32.0],
            [130.0, 469.040_65, 32.0],
            [130.0, 440.0, 32.0],
        ];
        let qs = LightmapExtents::from_points(&pts, &ROTATED_10_DEGREES);
        let dp = LightmapExtents::from_points_darkplaces(&pts, &ROTATED_10_DEGREES);
        assert_eq!(qs.tex_mins[0], dp.tex_mins[0]);
        assert_eq!((qs.extents[0], dp.extents[0]), (32, 48));
        assert_eq!(qs.extents[1], dp.extents[1]);
        assert_eq!(
            LightmapExtents::engines_disagree(&pts, &ROTATED_10_DEGREES),
            [true, false]
        );
    }

    #[test]
    fn the_rules_agree_away_from_grid_lines() {
        let pts = [[0.0, 0.0, 0.0], [31.5, 7.25, 0.0], [8.0, 3.0, 0.0]];
        assert_eq!(
            LightmapExtents::engines_disagree(&pts, &ROTATED_10_DEGREES),
            [false, false]
        );
        assert_eq!(
            LightmapExtents::engines_disagree(&pts, &AXIAL),
            [false, false]
        );
    }

    #[test]
    fn imprecise_plane_just_below_a_grid_line_stays_on_it() {
        // 31.999998 in f32 sits below 32: the grid must extend to 48, exactly as engines do.
        let pts = [[0.0, 0.0, 0.0], [31.999998, 0.0, 0.0]];
        let e = LightmapExtents::from_points(&pts, &AXIAL);
        assert_eq!(e.extents[0], 32);
        let pts = [[0.0, 0.0, 0.0], [32.000004, 0.0, 0.0]];
        assert_eq!(LightmapExtents::from_points(&pts, &AXIAL).extents[0], 48);
    }
}
