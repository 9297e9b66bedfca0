//! Measuring light against light: the per-luxel difference of two lightings of the same
//! faces, a BSP's own lightmaps as a lighting to compare, and a run against `--reference`.

use std::collections::HashMap;

use quake_formats::Bsp;

use crate::error::LightError;
use crate::lighting::{Lighting, Stats};
use crate::options::Options;
use crate::output::FaceLightmap;
use crate::quality::Quality;
use crate::run::{finish_lighting, trace_lighting};

/// Per-luxel difference between two lightings of the same faces, in 8-bit levels.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct ErrorStats {
    /// Luxels compared (every style of every face both lightings share).
    pub luxels: u64,
    /// Root mean square difference.
    pub rmse: f64,
    /// Largest difference.
    pub max: u8,
    /// Luxels that differ by more than 8 levels.
    pub over_8: u64,
    /// Luxels that differ by more than 2 levels.
    pub over_2: u64,
    /// Luxels black (0) here where the reference is not.
    pub black: u64,
    /// Luxels black here where the reference is above 2 levels.
    pub black_over_2: u64,
}

/// Compares grey lightmaps face by face and style by style (a style only one
/// side has counts against zero).
pub fn compare(a: &Lighting, reference: &Lighting) -> ErrorStats {
    let by_face: HashMap<usize, &FaceLightmap> =
        reference.lightmaps.iter().map(|m| (m.face, m)).collect();
    let mut e = ErrorStats::default();
    let mut sq = 0.0f64;
    for m in &a.lightmaps {
        let Some(r) = by_face.get(&m.face) else {
            continue;
        };
        let mut styles: Vec<u8> = m.styles.clone();
        styles.extend(r.styles.iter().filter(|s| !m.styles.contains(s)));
        let zeros = vec![0u8; m.width * m.height];
        for s in styles {
            let pick = |f: &FaceLightmap| {
                f.styles
                    .iter()
                    .position(|&x| x == s)
                    .map_or(zeros.clone(), |i| f.grey[i].clone())
            };
            for (x, y) in pick(m).iter().zip(pick(r).iter()) {
                let d = x.abs_diff(*y);
                e.luxels += 1;
                sq += f64::from(d) * f64::from(d);
                e.max = e.max.max(d);
                e.over_8 += u64::from(d > 8);
                e.over_2 += u64::from(d > 2);
                e.black += u64::from(*x == 0 && *y > 0);
                e.black_over_2 += u64::from(*x == 0 && *y > 2);
            }
        }
    }
    e.rmse = (sq / e.luxels.max(1) as f64).sqrt();
    e
}

/// The lightmaps `bsp` already holds for `faces` (grey bytes of every style), as a [`Lighting`]
/// to [`compare`]: how another run or another tool's light is measured against ours. Faces
/// without a lightmap or with indices out of range are left out.
pub fn lightmaps_in(bsp: &Bsp, faces: &[usize]) -> Lighting {
    let mut lightmaps = Vec::new();
    for &f in faces {
        let Some(face) = bsp.faces.get(f) else {
            continue;
        };
        let (Some(verts), Some(ti)) = (
            bsp.face_vertices(face),
            bsp.texinfo.get(face.texinfo as usize),
        ) else {
            continue;
        };
        if face.light_offset < 0 {
            continue;
        }
        let [w, h] =
            quake_formats::extents::LightmapExtents::from_points(&verts, &ti.vecs).luxel_size();
        let styles: Vec<u8> = face.styles.iter().copied().filter(|&s| s != 255).collect();
        let grey = (0..styles.len())
            .map(|k| {
                let at = face.light_offset as usize + k * w * h;
                bsp.lighting
                    .get(at..at + w * h)
                    .map_or(vec![0; w * h], <[u8]>::to_vec)
            })
            .collect();
        lightmaps.push(FaceLightmap {
            face: f,
            width: w,
            height: h,
            styles,
            grey,
            rgb: Vec::new(),
            hdr: Vec::new(),
            directions: Vec::new(),
            own_grid: None,
        });
    }
    Lighting {
        lightmaps,
        entity_text: None,
        coloured: false,
        outputs: crate::Outputs::default(),
        light_grid: None,
        warnings: Vec::new(),
        stats: Stats::default(),
    }
}

/// `lighting` with the lightmaps of faces lit on their own grids in place of their 16-texel
/// ones, the other faces left out; `None` when no face has its own grid.
pub fn own_grids(lighting: &Lighting) -> Option<Lighting> {
    let lightmaps: Vec<FaceLightmap> = lighting
        .lightmaps
        .iter()
        .filter_map(|m| {
            let own = m.own_grid.as_deref()?;
            Some(FaceLightmap {
                face: m.face,
                ..own.lightmap.clone()
            })
        })
        .collect();
    (!lightmaps.is_empty()).then(|| Lighting {
        lightmaps,
        ..lighting.clone()
    })
}

/// A lighting against the reference of the same faces (`--compare-reference`).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct ReferenceComparison {
    /// Against the reference.
    pub error: ErrorStats,
    /// Against the reference through the same `--soft` filter (it blurs on purpose), when the
    /// run filters.
    pub error_filtered: Option<ErrorStats>,
    /// Against the reference on the faces' own grids (`--world_units_per_luxel`, `_lmscale`),
    /// when they have them; `error` then measures the 16-texel lightmaps read from those.
    pub error_own_grids: Option<ErrorStats>,
    /// The reference's own time and rays.
    pub reference_seconds: f64,
    /// Rays the reference cast.
    pub reference_rays: u64,
}

/// Lights the faces `lighting` lit from `bsp` with `options` at [`Quality::Reference`] and
/// measures `lighting` against that.
///
/// # Errors
/// As [`trace_lighting`].
pub fn compare_with_reference(
    bsp: &Bsp,
    options: &Options,
    lighting: &Lighting,
) -> Result<ReferenceComparison, LightError> {
    let reference = Options {
        quality: Quality::Reference,
        ..options.clone()
    };
    let raw = trace_lighting(bsp, &reference)?;
    let exact = finish_lighting(&raw, 0);
    let r = &exact.stats;
    Ok(ReferenceComparison {
        error: compare(lighting, &exact),
        error_filtered: (raw.soft_radius > 0)
            .then(|| compare(lighting, &finish_lighting(&raw, raw.soft_radius))),
        error_own_grids: own_grids(lighting)
            .zip(own_grids(&exact))
            .map(|(a, r)| compare(&a, &r)),
        reference_seconds: r.seconds_total,
        reference_rays: r.shadow_rays + r.sun_rays + r.dirt_rays + r.placement_rays,
    })
}
