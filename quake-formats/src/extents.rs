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
        Self::snapped(points, vecs, quakespasm_coord)
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
        let (lo, hi) = grid_lines(points, vecs, coord, LIGHTMAP_SCALE);
        LightmapExtents {
            tex_mins: lo.map(|l| l * LIGHTMAP_SCALE),
            extents: std::array::from_fn(|axis| (hi[axis] - lo[axis]) * LIGHTMAP_SCALE),
        }
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

/// The first and last grid lines (in steps of `scale` texels) around the texture coordinates of
/// `points`, each computed by `coord`; `([0, 0], [0, 0])` for no points.
fn grid_lines(
    points: &[[f32; 3]],
    vecs: &[[f32; 4]; 2],
    coord: impl Fn(&[f32; 3], &[f32; 4]) -> f32,
    scale: i32,
) -> ([i32; 2], [i32; 2]) {
    let mut mins = [f64::INFINITY; 2];
    let mut maxs = [f64::NEG_INFINITY; 2];
    for p in points {
        for axis in 0..2 {
            let val = coord(p, &vecs[axis]) as f64;
            mins[axis] = mins[axis].min(val);
            maxs[axis] = maxs[axis].max(val);
        }
    }
    let mut lo = [0; 2];
    let mut hi = [0; 2];
    if points.is_empty() {
        return (lo, hi);
    }
    let scale = f64::from(scale);
    for axis in 0..2 {
        // Damaged files can hold absurd coordinates; clamping keeps the arithmetic in range
        // (such a face fails every size check downstream anyway).
        lo[axis] = (mins[axis] / scale).floor().clamp(-GRID_CLAMP, GRID_CLAMP) as i32;
        // All-NaN coordinates leave the maximum below the minimum.
        hi[axis] =
            ((maxs[axis] / scale).ceil().clamp(-GRID_CLAMP, GRID_CLAMP) as i32).max(lo[axis]);
    }
    (lo, hi)
}

/// Two unit world axes across the axis `normal` leans on most (the first of equals), ordered so
/// that the first crossed with the second points the way the normal does along that axis.
fn world_axes(normal: [f64; 3]) -> [[f64; 3]; 2] {
    let mut axis = 0;
    for k in 1..3 {
        if normal[k].abs() > normal[axis].abs() {
            axis = k;
        }
    }
    let sign = if normal[axis] > 0.0 { 1.0 } else { -1.0 };
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    // The snapped normal crossed with unit axes a and b.
    let mut first = [0.0; 3];
    first[b] = sign;
    let mut second = [0.0; 3];
    second[a] = -sign;
    // first × second = sign² · (e_b × -e_a) = e_axis, so the pair faces +axis: swap for -axis.
    if sign > 0.0 {
        [first, second]
    } else {
        [second, first]
    }
}

/// The texture coordinate of `p` along axis row `v`, as QuakeSpasm computes it (products summed in
/// `f64`, the sum kept as `f32`).
fn quakespasm_coord(p: &[f32; 3], v: &[f32; 4]) -> f32 {
    (p[0] as f64 * v[0] as f64
        + p[1] as f64 * v[1] as f64
        + p[2] as f64 * v[2] as f64
        + v[3] as f64) as f32
}

/// Where a face's luxels lie, whatever their spacing: luxel (x, y) stands at texture
/// coordinates `mins + scale * (x, y)` of the projection `axes` (`s = axes[0].xyz · p +
/// axes[0].w` for a model-space point `p`). Quake's 16-texel grid is one such grid
/// ([`LuxelGrid::vanilla`]); so are the coarser or finer grids of the BSPX `LMSHIFT` lump
/// ([`LuxelGrid::shifted`]) and the world-space grids of `DECOUPLED_LM`, whose projection is in
/// luxels already (scale 1, minimum 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LuxelGrid {
    /// The projection, in texels per map unit (the texture's own for vanilla and `LMSHIFT`).
    pub axes: [[f64; 4]; 2],
    /// Texels from one luxel to the next.
    pub scale: f64,
    /// Texture coordinates of luxel (0, 0).
    pub mins: [f64; 2],
    /// Luxels across (s) and down (t).
    pub size: [usize; 2],
}

impl LuxelGrid {
    /// Quake's grid: one luxel every 16 texels over `extents` of the texture projection `vecs`.
    pub fn vanilla(extents: &LightmapExtents, vecs: &[[f32; 4]; 2]) -> LuxelGrid {
        LuxelGrid {
            axes: vecs.map(|row| row.map(f64::from)),
            scale: f64::from(LIGHTMAP_SCALE),
            mins: extents.tex_mins.map(f64::from),
            size: extents.luxel_size(),
        }
    }

    /// The grid of a face whose `LMSHIFT` is `shift`: one luxel every `1 << shift` texels, its
    /// extents snapped to that spacing as engines that read the lump snap them (shift 4 is
    /// Quake's grid). `None` for a shift past 30, which no engine's integer arithmetic holds.
    pub fn shifted(points: &[[f32; 3]], vecs: &[[f32; 4]; 2], shift: u8) -> Option<LuxelGrid> {
        if shift > 30 {
            return None;
        }
        let scale = 1i32 << shift;
        let (lo, hi) = grid_lines(points, vecs, quakespasm_coord, scale);
        Some(LuxelGrid {
            axes: vecs.map(|row| row.map(f64::from)),
            scale: f64::from(scale),
            mins: lo.map(|l| f64::from(l) * f64::from(scale)),
            size: std::array::from_fn(|axis| (hi[axis] - lo[axis]) as usize + 1),
        })
    }

    /// A grid whose projection gives luxel coordinates directly (`DECOUPLED_LM`'s
    /// world-to-lightmap rows), `size` luxels.
    pub fn in_luxels(world_to_luxel: &[[f32; 4]; 2], size: [usize; 2]) -> LuxelGrid {
        LuxelGrid {
            axes: world_to_luxel.map(|row| row.map(f64::from)),
            scale: 1.0,
            mins: [0.0; 2],
            size,
        }
    }

    /// The world-aligned grid ericw-tools' `-world_units_per_luxel` gives a face (its
    /// `DECOUPLED_LM` record): one luxel every `units` map units along the two world axes
    /// across the axis `normal` leans on most, turned so that the first row crossed with the
    /// second points along the normal, the projection shifted so the face's smallest luxel
    /// coordinates are whole numbers from 0. Returns the projection (as the lump stores it) and
    /// the grid; `None` for a spacing that is not a positive number or a grid wider than the
    /// lump's 16-bit sizes.
    pub fn world_aligned(
        points: &[[f32; 3]],
        normal: [f64; 3],
        units: f64,
    ) -> Option<([[f32; 4]; 2], LuxelGrid)> {
        if !(units.is_finite() && units > 0.0) || points.is_empty() {
            return None;
        }
        let rows = world_axes(normal).map(|axis| axis.map(|c| (c / units) as f32));
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in points {
            for (axis, row) in rows.iter().enumerate() {
                let v = (0..3)
                    .map(|k| f64::from(row[k]) * f64::from(p[k]))
                    .sum::<f64>();
                lo[axis] = lo[axis].min(v.floor());
                hi[axis] = hi[axis].max(v.ceil());
            }
        }
        let size: [usize; 2] = std::array::from_fn(|axis| (hi[axis] - lo[axis]) as usize + 1);
        if !lo.iter().chain(&hi).all(|v| v.is_finite()) || size.iter().any(|&n| n > 0xffff) {
            return None;
        }
        let world_to_luxel: [[f32; 4]; 2] = std::array::from_fn(|axis| {
            let r = rows[axis];
            [r[0], r[1], r[2], -lo[axis] as f32]
        });
        Some((world_to_luxel, LuxelGrid::in_luxels(&world_to_luxel, size)))
    }

    /// Luxels in one style's lightmap.
    pub fn luxel_count(&self) -> usize {
        self.size[0] * self.size[1]
    }

    /// Texture coordinates (s, t) of luxel (x, y).
    pub fn luxel_st(&self, x: usize, y: usize) -> [f64; 2] {
        [
            self.mins[0] + x as f64 * self.scale,
            self.mins[1] + y as f64 * self.scale,
        ]
    }

    /// Continuous luxel coordinates of model-space point `p` (luxel (x, y) at whole numbers).
    pub fn luxel_at(&self, p: [f64; 3]) -> [f64; 2] {
        std::array::from_fn(|axis| {
            let a = self.axes[axis];
            let st = a[0] * p[0] + a[1] * p[1] + a[2] * p[2] + a[3];
            (st - self.mins[axis]) / self.scale
        })
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

    #[test]
    fn shift_four_is_quakes_grid_and_shift_three_doubles_it() {
        let pts = [[1.5, 0.0, 0.0], [30.25, -17.0, 0.0], [8.0, 3.0, 0.0]];
        let vanilla = LightmapExtents::from_points(&pts, &AXIAL);
        let grid = LuxelGrid::vanilla(&vanilla, &AXIAL);
        assert_eq!(LuxelGrid::shifted(&pts, &AXIAL, 4), Some(grid));
        assert_eq!(grid.luxel_st(1, 2), vanilla.luxel_st(1, 2));
        let fine = LuxelGrid::shifted(&pts, &AXIAL, 3).expect("shift 3");
        assert_eq!(fine.scale, 8.0);
        assert_eq!(fine.mins, [0.0, -8.0]);
        assert_eq!(fine.size, [5, 5]);
        assert_eq!(LuxelGrid::shifted(&pts, &AXIAL, 31), None);
    }

    #[test]
    fn world_aligned_grids_face_their_normal_and_hold_the_face() {
        use glam::DVec3;
        let floor = [
            [8.0, 4.0, 0.0],
            [40.0, 4.0, 0.0],
            [40.0, 20.0, 0.0],
            [8.0, 20.0, 0.0],
        ];
        for (normal, units) in [([0.0, 0.0, 1.0], 8.0), ([0.0, 0.0, -1.0], 4.0)] {
            let (rows, grid) = LuxelGrid::world_aligned(&floor, normal, units).expect("grid");
            let axis = |r: [f32; 4]| DVec3::new(r[0].into(), r[1].into(), r[2].into());
            let facing = axis(rows[0]).cross(axis(rows[1])).dot(DVec3::from(normal));
            assert!(facing > 0.0, "{normal:?}");
            let coords: Vec<[f64; 2]> = floor
                .iter()
                .map(|p| grid.luxel_at(p.map(f64::from)))
                .collect();
            for axis in 0..2 {
                let min = coords.iter().map(|c| c[axis]).fold(f64::INFINITY, f64::min);
                let max = coords
                    .iter()
                    .map(|c| c[axis])
                    .fold(f64::NEG_INFINITY, f64::max);
                // The grid's first and last luxels are the face's, rounded outward.
                let last = (grid.size[axis] - 1) as f64;
                assert!((0.0..1.0).contains(&min), "{normal:?}: {min}");
                assert!(max <= last && max > last - 1.0, "{normal:?}: {max}");
            }
        }
        let (_, grid) = LuxelGrid::world_aligned(&floor, [0.0, 0.0, 1.0], 8.0).expect("grid");
        // The first row runs along y (4..20: 0.5..2.5 luxels, 0..3 snapped), the second along -x.
        assert_eq!(grid.size, [4, 5]);
        assert_eq!(LuxelGrid::world_aligned(&floor, [0.0, 0.0, 1.0], 0.0), None);
        assert_eq!(
            LuxelGrid::world_aligned(&floor, [0.0, 0.0, 1.0], 1e-4),
            None
        );
    }

    #[test]
    fn luxel_at_inverts_luxel_st() {
        let pts = [[0.0, 0.0, 0.0], [64.0, 48.0, 0.0]];
        let grid = LuxelGrid::shifted(&pts, &AXIAL, 3).expect("shift 3");
        let [s, t] = grid.luxel_st(3, 2);
        // AXIAL: s = x, t = -y.
        assert_eq!(grid.luxel_at([s, -t, 7.0]), [3.0, 2.0]);
        let decoupled =
            LuxelGrid::in_luxels(&[[0.125, 0.0, 0.0, 1.0], [0.0, 0.125, 0.0, 0.0]], [9, 7]);
        assert_eq!(decoupled.luxel_at([16.0, 8.0, 0.0]), [3.0, 1.0]);
        assert_eq!(decoupled.luxel_count(), 63);
    }
}
