//! Which luxels engines draw, and how much of its face each one stands for: the weights of
//! light's error figures ([`crate::compare_drawn`]).
//!
//! Engines filter a lightmap bilinearly between luxel centres, so a point of the face reads the
//! luxels within one luxel of it along both axes of the grid. A luxel no point of the face is
//! that close to (the far corners of a triangle's lightmap, the rim of a sliver's) is stored
//! but never seen. A drawn luxel is weighted by the area of the face within that reach, in
//! square map units: a luxel at the face's edge counts for the part of the face it shows on,
//! and faces count by their size, not by their texture scale.

use std::collections::HashMap;

use glam::DVec3;
use quake_formats::Bsp;
use quake_formats::extents::{LightmapExtents, LuxelGrid};
use quake_formats::geom::{Plane, Winding};

use crate::faces::OwnGrid;
use crate::lighting::Lighting;

/// Units per luxel the face is clipped in: its luxel coordinates scaled so that a luxel spans
/// what it spans on Quake's grid in texels, far above the clipper's epsilon on every grid.
const LUXEL_SPAN: f64 = 16.0;

/// Least area (square [`LUXEL_SPAN`] units) a face shares with a luxel's reach for the luxel
/// to be drawn.
const MIN_SHARED_AREA: f64 = 1e-6;

/// Per face, per luxel of its lightmap (row by row), the area of the face the luxel stands
/// for: 0 for luxels no engine draws. Faces whose texture is fullbright in every texel are
/// left out (engines draw them unlit), as are faces the file cannot place.
#[derive(Debug, Clone, Default)]
pub struct DrawnAreas {
    by_face: HashMap<usize, Vec<f64>>,
}

impl DrawnAreas {
    /// The luxels of `faces`' lightmaps on Quake's 16-texel grid.
    pub fn on_quake_grids(bsp: &Bsp, faces: &[usize]) -> DrawnAreas {
        DrawnAreas::of_faces(bsp, faces.iter().map(|&f| (f, None)))
    }

    /// The luxels of the lightmaps `lighting` lit on the faces' own grids
    /// (`--world_units_per_luxel`, `_lmscale`; what [`crate::own_grids`] compares).
    pub fn on_own_grids(bsp: &Bsp, lighting: &Lighting) -> DrawnAreas {
        let own = lighting.lightmaps.iter().filter_map(|m| {
            let o = m.own_grid.as_deref()?;
            Some((
                m.face,
                Some((o.grid, [o.lightmap.width, o.lightmap.height])),
            ))
        });
        DrawnAreas::of_faces(bsp, own)
    }

    /// Faces with the grid each is lit on: `None` for Quake's, else its own grid and size.
    fn of_faces(
        bsp: &Bsp,
        faces: impl Iterator<Item = (usize, Option<(OwnGrid, [usize; 2])>)>,
    ) -> DrawnAreas {
        let by_face = faces
            .filter_map(|(f, own)| {
                let face = bsp.faces.get(f)?;
                if bsp
                    .face_texture(face)
                    .is_some_and(|t| t.is_all_fullbright())
                {
                    return None;
                }
                let points = bsp.face_vertices(face)?;
                let vecs = bsp.texinfo.get(face.texinfo as usize)?.vecs;
                let grid = match own {
                    None => {
                        LuxelGrid::vanilla(&LightmapExtents::from_points(&points, &vecs), &vecs)
                    }
                    Some((OwnGrid::Decoupled(rows), size)) => LuxelGrid::in_luxels(&rows, size),
                    Some((OwnGrid::Shifted(shift), _)) => {
                        LuxelGrid::shifted(&points, &vecs, shift)?
                    }
                };
                Some((f, drawn_luxel_areas(&points, &grid)))
            })
            .collect();
        DrawnAreas { by_face }
    }

    /// Face `face`'s areas, one per luxel; `None` for a face left out.
    pub fn of(&self, face: usize) -> Option<&[f64]> {
        self.by_face.get(&face).map(Vec::as_slice)
    }
}

/// Per luxel of `grid` (row by row), the area in square map units of the face with
/// model-space corners `points` that lies within one luxel of the luxel's centre along both
/// axes; 0 for a luxel that no point of the face reads.
fn drawn_luxel_areas(points: &[[f32; 3]], grid: &LuxelGrid) -> Vec<f64> {
    let model = |p: &[f32; 3]| p.map(f64::from);
    let face = Winding::new(points.iter().map(|p| DVec3::from(model(p))).collect());
    let flat = Winding::new(
        points
            .iter()
            .map(|p| {
                let [u, v] = grid.luxel_at(model(p));
                DVec3::new(u * LUXEL_SPAN, v * LUXEL_SPAN, 0.0)
            })
            .collect(),
    );
    let flat_area = flat.area();
    let map_units_per_flat = if flat_area > 0.0 {
        face.area() / flat_area
    } else {
        0.0
    };
    let [width, height] = grid.size;
    (0..width * height)
        .map(|i| {
            let centre = [(i % width) as f64, (i / width) as f64].map(|c| c * LUXEL_SPAN);
            let shared = area_within(&flat, centre, LUXEL_SPAN);
            if shared > MIN_SHARED_AREA {
                shared * map_units_per_flat
            } else {
                0.0
            }
        })
        .collect()
}

/// The area the convex `polygon` (in the plane z = 0) shares with the square of half-side
/// `half` around `centre`.
fn area_within(polygon: &Winding, centre: [f64; 2], half: f64) -> f64 {
    let sides = [(DVec3::X, 0), (-DVec3::X, 0), (DVec3::Y, 1), (-DVec3::Y, 1)];
    sides
        .iter()
        .try_fold(polygon.clone(), |w, &(inward, axis)| {
            // The square's side facing `inward`: its front is inside the square.
            let edge = centre[axis] - half * inward[axis];
            w.clip_front(&Plane::new(inward, edge * inward[axis]), false)
        })
        .map_or(0.0, |w| w.area())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Texture axes along world x and y, one texel a unit.
    const AXIAL: [[f32; 4]; 2] = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]];

    fn quake_grid(points: &[[f32; 3]], vecs: &[[f32; 4]; 2]) -> LuxelGrid {
        LuxelGrid::vanilla(&LightmapExtents::from_points(points, vecs), vecs)
    }

    #[test]
    fn a_square_on_the_grid_gives_each_luxel_the_face_within_a_luxel_of_it() {
        // 32 x 32 units: luxels at 0, 16 and 32 each way.
        let points = [
            [0.0, 0.0, 0.0],
            [0.0, 32.0, 0.0],
            [32.0, 32.0, 0.0],
            [32.0, 0.0, 0.0],
        ];
        let areas = drawn_luxel_areas(&points, &quake_grid(&points, &AXIAL));
        // Corners reach a 16 x 16 quarter, edges 32 x 16, the middle all 32 x 32.
        let expected = [
            256.0, 512.0, 256.0, 512.0, 1024.0, 512.0, 256.0, 512.0, 256.0,
        ];
        for (a, e) in areas.iter().zip(expected) {
            assert!((a - e).abs() < 1e-9, "{areas:?}");
        }
    }

    #[test]
    fn the_far_corner_of_a_triangles_lightmap_is_not_drawn() {
        // A right triangle 48 units a side: luxel (3, 3) at (48, 48) is 24√2 from the
        // hypotenuse, further than a luxel along either axis.
        let points = [[0.0, 0.0, 0.0], [0.0, 48.0, 0.0], [48.0, 0.0, 0.0]];
        let grid = quake_grid(&points, &AXIAL);
        assert_eq!(grid.size, [4, 4]);
        let areas = drawn_luxel_areas(&points, &grid);
        assert_eq!(areas[15], 0.0);
        assert!(areas[0] > 0.0 && areas[5] > 0.0);
        // Every point of the face is read with weights summing to four luxels' reach.
        let total: f64 = areas.iter().sum();
        assert!((total - 4.0 * 48.0 * 48.0 / 2.0).abs() < 1e-6, "{total}");
    }

    #[test]
    fn areas_are_map_units_whatever_the_texture_scale() {
        // Textures scaled 2x: half a texel a unit, so the 64-unit square spans 32 texels.
        let half: [[f32; 4]; 2] = [[0.5, 0.0, 0.0, 0.0], [0.0, 0.5, 0.0, 0.0]];
        let points = [
            [0.0, 0.0, 0.0],
            [0.0, 64.0, 0.0],
            [64.0, 64.0, 0.0],
            [64.0, 0.0, 0.0],
        ];
        let areas = drawn_luxel_areas(&points, &quake_grid(&points, &half));
        assert!((areas[4] - 64.0 * 64.0).abs() < 1e-9, "{areas:?}");
        let total: f64 = areas.iter().sum();
        assert!((total - 4.0 * 64.0 * 64.0).abs() < 1e-6, "{total}");
    }
}
