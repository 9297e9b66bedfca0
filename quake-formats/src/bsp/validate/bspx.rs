//! The BSPX lumps that carry light or what light and vis read, checked as the core lumps are:
//! sizes against the luxel and face counts, lightmaps inside the lighting data, projections
//! finite, the light grid whole.

use super::surfaces::lightmaps_of;
use super::{Checker, Rule};
use crate::bsp::light_lumps::{
    DECOUPLED_LM, HDR_BYTES_PER_LUXEL, LIGHTING_E5BGR9, LIGHTINGDIR, LMOFFSET, LMSHIFT,
    RGB_BYTES_PER_LUXEL, RGBLIGHTING,
};
use crate::bsp::lightgrid::LIGHTGRID_OCTREE;
use crate::bsp::limits::LMSHIFT_MAX_LIGHTMAP_SIZE;
use crate::bsp::{face_flags, phong, surflight_group};
use crate::extents::LuxelGrid;

pub(super) fn check(c: &mut Checker) {
    check_per_luxel_sizes(c);
    check_vanilla_lighting(c);
    check_shifted(c);
    check_decoupled(c);
    if let Err(e) = c.bsp.light_grid() {
        c.report(Rule::LightGrid, LIGHTGRID_OCTREE, 0, e.to_string());
    }
    if let Err(e) = c.bsp.phong_faces() {
        c.report(Rule::BspxFaceRecords, phong::LUMP_NAME, 0, e.to_string());
    }
    if let Err(e) = c.bsp.face_flags() {
        c.report(
            Rule::BspxFaceRecords,
            face_flags::LUMP_NAME,
            0,
            e.to_string(),
        );
    }
    if let Err(e) = c.bsp.surflight_groups() {
        c.report(
            Rule::BspxFaceRecords,
            surflight_group::LUMP_NAME,
            0,
            e.to_string(),
        );
    }
}

/// `RGBLIGHTING`, `LIGHTINGDIR` and `LIGHTING_E5BGR9` hold a record for every luxel.
fn check_per_luxel_sizes(c: &mut Checker) {
    let luxels = c.bsp.luxel_count();
    for (name, per) in [
        (RGBLIGHTING, RGB_BYTES_PER_LUXEL),
        (LIGHTINGDIR, RGB_BYTES_PER_LUXEL),
        (LIGHTING_E5BGR9, HDR_BYTES_PER_LUXEL),
    ] {
        let Some(data) = c.bsp.bspx_lump(name) else {
            continue;
        };
        if data.len() != luxels * per {
            let detail = format!(
                "{} bytes for {luxels} luxels of lighting data ({per} bytes each: {})",
                data.len(),
                luxels * per
            );
            c.report(Rule::BspxLightSize, name, 0, detail);
        }
    }
}

/// Light only in BSPX lumps (`-novanilla`) is drawn fullbright by engines that read the grey lump.
fn check_vanilla_lighting(c: &mut Checker) {
    let bsp = c.bsp;
    if !bsp.lighting.is_empty() || bsp.luxel_count() == 0 {
        return;
    }
    let lit = bsp.faces.iter().filter(|f| f.light_offset >= 0).count();
    let detail = format!(
        "no grey lighting lump beside {} luxels of RGBLIGHTING ({lit} faces with a light offset)",
        bsp.luxel_count()
    );
    c.report(Rule::NoVanillaLighting, "lighting", 0, detail);
}

/// Each `LMSHIFT` face's lightmaps fit the lighting data and the 256-luxel limit.
fn check_shifted(c: &mut Checker) {
    let bsp = c.bsp;
    let shifts = match bsp.lightmap_shifts() {
        Ok(Some(s)) => s,
        Ok(None) => return,
        Err(e) => return c.report(Rule::BspxFaceRecords, LMSHIFT, 0, e.to_string()),
    };
    let offsets = match bsp.lightmap_offsets() {
        Ok(o) => o,
        Err(e) => return c.report(Rule::BspxFaceRecords, LMOFFSET, 0, e.to_string()),
    };
    let luxels = bsp.luxel_count();
    for (i, (f, &shift)) in bsp.faces.iter().zip(&shifts).enumerate() {
        let offset = offsets.as_ref().map_or(f.light_offset, |o| o[i]);
        if offset < 0 {
            continue;
        }
        let (Some(tex), Some(points)) = (bsp.texinfo.get(f.texinfo as usize), bsp.face_vertices(f))
        else {
            continue; // `structure` reports the indices
        };
        let Some(grid) = LuxelGrid::shifted(&points, &tex.vecs, shift) else {
            c.report(
                Rule::ShiftedLightmap,
                LMSHIFT,
                i,
                format!("shift {shift} is past 30"),
            );
            continue;
        };
        if grid.size[0].max(grid.size[1]) > LMSHIFT_MAX_LIGHTMAP_SIZE {
            let detail = format!("{}x{} luxels at shift {shift}", grid.size[0], grid.size[1]);
            c.report(Rule::ShiftedLightmap, LMSHIFT, i, detail);
            continue;
        }
        let needed = grid.luxel_count() * lightmaps_of(f);
        if offset as usize + needed > luxels {
            let detail = format!(
                "lightmap at {offset} ({needed} luxels) runs past the {luxels} luxels of lighting"
            );
            c.report(Rule::ShiftedLightmap, LMSHIFT, i, detail);
        }
    }
}

/// Each `DECOUPLED_LM` record has a finite projection, and its lightmaps fit the lighting data.
fn check_decoupled(c: &mut Checker) {
    let bsp = c.bsp;
    let records = match bsp.decoupled_lightmaps() {
        Ok(Some(r)) => r,
        Ok(None) => return,
        Err(e) => return c.report(Rule::BspxFaceRecords, DECOUPLED_LM, 0, e.to_string()),
    };
    let luxels = bsp.luxel_count();
    for (i, (f, r)) in bsp.faces.iter().zip(&records).enumerate() {
        if r.world_to_luxel.iter().flatten().any(|v| !v.is_finite()) {
            let detail = format!("projection {:?} is not finite", r.world_to_luxel);
            c.report(Rule::DecoupledLightmap, DECOUPLED_LM, i, detail);
            continue;
        }
        if r.offset == -1 {
            continue;
        }
        let count = usize::from(r.width) * usize::from(r.height);
        let needed = count * lightmaps_of(f);
        let problem = if r.offset < 0 {
            Some(format!("offset {} is neither -1 nor a luxel", r.offset))
        } else if count == 0 {
            Some(format!(
                "{}x{} luxels at offset {}",
                r.width, r.height, r.offset
            ))
        } else if r.offset as usize + needed > luxels {
            Some(format!(
                "lightmap at {} ({needed} luxels) runs past the {luxels} luxels of lighting",
                r.offset
            ))
        } else {
            None
        };
        if let Some(detail) = problem {
            c.report(Rule::DecoupledLightmap, DECOUPLED_LM, i, detail);
        }
    }
}
