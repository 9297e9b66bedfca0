//! Measuring light against light: the per-luxel difference of two lightings of the same
//! faces (over every luxel, or over the luxels engines draw, each weighted by the area it
//! stands for: [`DrawnAreas`]), a BSP's own lightmaps as a lighting to compare, and a run
//! against `--reference`.

use std::collections::HashMap;

use quake_formats::Bsp;
use quake_formats::bsp::lightgrid::{GridSample, LightGrid};
use quake_formats::extents::{LightmapExtents, LuxelGrid};

use crate::drawn::DrawnAreas;
use crate::error::LightError;
use crate::lighting::{Lighting, Stats};
use crate::options::Options;
use crate::output::{FaceLightmap, QUAKE_SHIFT};
use crate::quality::Quality;
use crate::run::{finish_lighting, trace_lighting};
use quake_formats::lit::grey_level;

/// Per-luxel difference between two lightings of the same faces, in 8-bit levels.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct ErrorStats {
    /// Luxels compared (every style of every face both lightings share; of drawn luxels only,
    /// for [`compare_drawn`]).
    pub luxels: u64,
    /// Root mean square difference; for [`compare_drawn`], each luxel weighted by the area of
    /// the face it stands for.
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

/// [`ErrorStats`] being gathered, one pair of grey levels at a time.
#[derive(Default)]
struct Tally {
    e: ErrorStats,
    squares: f64,
    weights: f64,
}

impl Tally {
    /// One luxel of `weight`: `x` here, `y` in the reference.
    fn add(&mut self, x: u8, y: u8, weight: f64) {
        let d = x.abs_diff(y);
        let e = &mut self.e;
        e.luxels += 1;
        self.squares += weight * f64::from(d) * f64::from(d);
        self.weights += weight;
        e.max = e.max.max(d);
        e.over_8 += u64::from(d > 8);
        e.over_2 += u64::from(d > 2);
        e.black += u64::from(x == 0 && y > 0);
        e.black_over_2 += u64::from(x == 0 && y > 2);
    }

    fn finish(self) -> ErrorStats {
        ErrorStats {
            rmse: if self.weights > 0.0 {
                (self.squares / self.weights).sqrt()
            } else {
                0.0
            },
            ..self.e
        }
    }
}

/// Compares grey lightmaps face by face and style by style over every luxel, those inside
/// solid and past a triangle's corners included (a style only one side has counts against
/// zero). Faces whose lightmaps differ in size are not on the same grid (another tool's own
/// grids) and are left out.
pub fn compare(a: &Lighting, reference: &Lighting) -> ErrorStats {
    compare_over(a, reference, None)
}

/// [`compare`] over the luxels engines draw, each weighted by the area of the face it stands
/// for ([`DrawnAreas`]): what a player sees. Faces `drawn` leaves out are left out.
pub fn compare_drawn(a: &Lighting, reference: &Lighting, drawn: &DrawnAreas) -> ErrorStats {
    compare_over(a, reference, Some(drawn))
}

/// [`compare`], over the luxels `drawn` weighs when given.
fn compare_over(a: &Lighting, reference: &Lighting, drawn: Option<&DrawnAreas>) -> ErrorStats {
    let by_face: HashMap<usize, &FaceLightmap> =
        reference.lightmaps.iter().map(|m| (m.face, m)).collect();
    let mut tally = Tally::default();
    for m in &a.lightmaps {
        let Some(r) = by_face.get(&m.face) else {
            continue;
        };
        if (m.width, m.height) != (r.width, r.height) {
            continue;
        }
        let weights = match drawn.map(|d| d.of(m.face)) {
            None => None,
            Some(Some(w)) if w.len() == m.width * m.height => Some(w),
            Some(_) => continue,
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
            for (i, (x, y)) in pick(m).iter().zip(pick(r).iter()).enumerate() {
                let weight = weights.map_or(1.0, |w| w[i]);
                if weight > 0.0 {
                    tally.add(*x, *y, weight);
                }
            }
        }
    }
    tally.finish()
}

/// Compares two light grids (`LIGHTGRID_OCTREE`) point by point, in grey levels of the points'
/// colours: each style of each point open in both grids counts as one luxel of the
/// [`ErrorStats`] (a style only one side has counts against zero). `None` when the grids'
/// points are not the same (spacing, origin or size differ).
pub fn compare_grids(grid: &LightGrid, reference: &LightGrid) -> Option<ErrorStats> {
    let same_points =
        (grid.spacing, grid.mins, grid.size) == (reference.spacing, reference.mins, reference.size);
    if !same_points {
        return None;
    }
    let [w, h, d] = grid.size;
    let mut tally = Tally::default();
    for index in (0..d).flat_map(|z| (0..h).flat_map(move |y| (0..w).map(move |x| [x, y, z]))) {
        let (Some(Some(a)), Some(Some(r))) = (grid.point(index), reference.point(index)) else {
            continue;
        };
        let grey = |samples: &[GridSample], style: u8| {
            samples
                .iter()
                .find(|s| s.style == style)
                .map_or(0, |s| grey_level(s.rgb))
        };
        let mut styles: Vec<u8> = a.iter().chain(r).map(|s| s.style).collect();
        styles.sort_unstable();
        styles.dedup();
        for style in styles {
            tally.add(grey(a, style), grey(r, style), 1.0);
        }
    }
    Some(tally.finish())
}

/// The lightmaps `bsp` already holds for `faces` (grey bytes of every style), as a [`Lighting`]
/// to [`compare`]: how another run or another tool's light is measured against ours. Faces
/// without a lightmap or with indices out of range are left out.
pub fn lightmaps_in(bsp: &Bsp, faces: &[usize]) -> Lighting {
    let lightmaps = faces.iter().filter_map(|&f| {
        let face = bsp.faces.get(f)?;
        let verts = bsp.face_vertices(face)?;
        let ti = bsp.texinfo.get(face.texinfo as usize)?;
        let size = LightmapExtents::from_points(&verts, &ti.vecs).luxel_size();
        stored_lightmap(bsp, f, face.light_offset, size)
    });
    lighting_of(lightmaps.collect())
}

/// The lightmaps `bsp` holds for `faces` on the faces' own grids, as their `DECOUPLED_LM`
/// records (`--world_units_per_luxel`) or their `LMSHIFT` and `LMOFFSET` (`--lmshift`,
/// `_lmscale`) place and size them, as a [`Lighting`] to [`compare`] with [`own_grids`] of a
/// run. Faces without a lightmap on a grid of their own, or with indices out of range, are
/// left out.
///
/// # Errors
/// [`LightError::BspxLump`] when one of those lumps is damaged.
pub fn own_grid_lightmaps_in(bsp: &Bsp, faces: &[usize]) -> Result<Lighting, LightError> {
    let decoupled = bsp.decoupled_lightmaps().map_err(LightError::BspxLump)?;
    let shifts = bsp.lightmap_shifts().map_err(LightError::BspxLump)?;
    let offsets = bsp.lightmap_offsets().map_err(LightError::BspxLump)?;
    let own_grid = |f: usize| -> Option<(i32, [usize; 2])> {
        if let Some(record) = decoupled.as_ref().and_then(|d| d.get(f)) {
            return Some((record.offset, record.grid().size));
        }
        let shift = *shifts.as_ref()?.get(f)?;
        let offset = *offsets.as_ref()?.get(f)?;
        let face = bsp.faces.get(f)?;
        let verts = bsp.face_vertices(face)?;
        let ti = bsp.texinfo.get(face.texinfo as usize)?;
        // Faces left on Quake's grid keep shift 4 and their 16-texel lightmap.
        (shift != QUAKE_SHIFT).then_some(())?;
        Some((offset, LuxelGrid::shifted(&verts, &ti.vecs, shift)?.size))
    };
    let lightmaps = faces.iter().filter_map(|&f| {
        let (offset, size) = own_grid(f)?;
        stored_lightmap(bsp, f, offset, size)
    });
    Ok(lighting_of(lightmaps.collect()))
}

/// Face `f`'s lightmaps of `size` luxels from `offset` in `bsp`'s lighting data, one per style
/// the face lists; `None` without a lightmap (offset -1) or a style. A lightmap past the data's
/// end reads as black.
fn stored_lightmap(bsp: &Bsp, f: usize, offset: i32, size: [usize; 2]) -> Option<FaceLightmap> {
    let face = bsp.faces.get(f)?;
    let offset = usize::try_from(offset).ok()?;
    let [w, h] = size;
    let styles: Vec<u8> = face.styles.iter().copied().filter(|&s| s != 255).collect();
    let grey = (0..styles.len())
        .map(|k| {
            let at = offset + k * w * h;
            bsp.lighting
                .get(at..at + w * h)
                .map_or(vec![0; w * h], <[u8]>::to_vec)
        })
        .collect();
    Some(FaceLightmap {
        face: f,
        width: w,
        height: h,
        styles,
        grey,
        rgb: Vec::new(),
        hdr: Vec::new(),
        directions: Vec::new(),
        own_grid: None,
    })
}

/// Lightmaps read from a BSP as a [`Lighting`] of nothing else.
fn lighting_of(lightmaps: Vec<FaceLightmap>) -> Lighting {
    Lighting {
        lightmaps,
        entity_text: None,
        coloured: false,
        outputs: crate::Outputs::default(),
        light_grid: None,
        chosen_settings: Vec::new(),
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

/// A lighting against the reference of the same faces (`--compare-reference`), over the luxels
/// engines draw ([`compare_drawn`]) unless said otherwise.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct ReferenceComparison {
    /// Against the reference.
    pub error: ErrorStats,
    /// Against the reference over every luxel of the lightmaps ([`compare`]).
    pub error_whole_lightmaps: ErrorStats,
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
    let exact = finish_lighting(&raw);
    let r = &exact.stats;
    let faces: Vec<usize> = lighting.lightmaps.iter().map(|m| m.face).collect();
    let drawn = DrawnAreas::on_quake_grids(bsp, &faces);
    Ok(ReferenceComparison {
        error: compare_drawn(lighting, &exact, &drawn),
        error_whole_lightmaps: compare(lighting, &exact),
        error_filtered: raw
            .softened(options.quality.samples_per_axis())
            .map(|soft| compare_drawn(lighting, &finish_lighting(&soft), &drawn)),
        error_own_grids: own_grids(lighting)
            .zip(own_grids(&exact))
            .map(|(a, r)| compare_drawn(&a, &r, &DrawnAreas::on_own_grids(bsp, lighting))),
        reference_seconds: r.seconds_total,
        reference_rays: r.shadow_rays + r.sun_rays + r.dirt_rays,
    })
}
