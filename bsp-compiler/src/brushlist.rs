//! The BSPX `BRUSHLIST` lump (`--wrbrushes`): each model's brushes as bounds, contents and
//! non-axial planes, in ericw-tools' layout, for engines that collide against brushes (FTE) and
//! importers that rebuild collision from them (bevy_trenchbroom, through the `qbsp` crate).
//!
//! Per model, little-endian: `u32` version (1), `u32` model number, `u32` brush count, `u32`
//! plane count over all its brushes; then per brush `f32` mins[3] and maxs[3], `i16` contents,
//! `u16` plane count, and per plane `f32` normal[3] and dist, facing out of the brush. The axial
//! planes are left out: readers take them from the bounds. The others include the brush's
//! bevels ([`crate::hulls::bevelled_planes`]), which readers expanding the planes by a box need.

use crate::brush::Brush;
use crate::hulls::bevelled_planes;
use crate::planes::PlaneSet;
use quake_formats::bsp::BspxLump;
use quake_formats::geom::{Bounds, Plane};

pub const LUMP_NAME: &str = "BRUSHLIST";
const VERSION: u32 = 1;

/// The contents the lump gives clip brushes (BSPX's own, Quake's compile-time clip): they stop
/// players and monsters, not shots, as clip hulls do.
pub const CLIP: i32 = -8;

/// One brush as the lump stores it.
#[derive(Debug, Clone, PartialEq)]
pub struct ListedBrush {
    pub bounds: Bounds,
    /// Engine contents (solid, water, sky...), or [`CLIP`].
    pub contents: i16,
    /// Its non-axial side and bevel planes, facing out.
    pub planes: Vec<Plane>,
}

impl ListedBrush {
    pub fn of(brush: &Brush, contents: i32, planes: &PlaneSet) -> ListedBrush {
        let planes = bevelled_planes(brush, planes)
            .into_iter()
            .filter(|p| p.axial().is_none())
            .collect();
        ListedBrush {
            bounds: brush.bounds,
            contents: contents as i16,
            planes,
        }
    }
}

/// The lump for `models`, each model's brushes in model order.
pub fn brush_list_lump(models: &[Vec<ListedBrush>]) -> BspxLump {
    let mut data = Vec::new();
    let mut put = |bytes: &[u8]| data.extend_from_slice(bytes);
    for (index, brushes) in models.iter().enumerate() {
        let plane_count: usize = brushes.iter().map(|b| b.planes.len()).sum();
        for v in [
            VERSION,
            index as u32,
            brushes.len() as u32,
            plane_count as u32,
        ] {
            put(&v.to_le_bytes());
        }
        for b in brushes {
            for v in b
                .bounds
                .mins
                .as_vec3()
                .to_array()
                .into_iter()
                .chain(b.bounds.maxs.as_vec3().to_array())
            {
                put(&v.to_le_bytes());
            }
            put(&b.contents.to_le_bytes());
            put(&(b.planes.len() as u16).to_le_bytes());
            for p in &b.planes {
                for v in p.normal.as_vec3().to_array() {
                    put(&v.to_le_bytes());
                }
                put(&(p.dist as f32).to_le_bytes());
            }
        }
    }
    let mut raw_name = [0u8; 24];
    raw_name[..LUMP_NAME.len()].copy_from_slice(LUMP_NAME.as_bytes());
    BspxLump { raw_name, data }
}
