//! Faces as engines build surfaces from them: lightmap extents, lightmap data, polygon buffers.

use super::{Checker, Rule};
use crate::bsp::limits::{
    DARKPLACES_MAX_LIGHTMAP_SIZE, GLQUAKE_MAX_SURFACE_EXTENT, MAX_SURFACE_EXTENT,
    QUAKESPASM_MAX_SURFACE_EXTENT, QUAKESPASM_MAX_UNLIT_FACE_VERTS, QUAKESPASM_MAX_WARP_FACE_VERTS,
};
use crate::bsp::records::texinfo_flags;
use crate::bsp::{Face, TexInfo};
use crate::extents::LightmapExtents;

pub(super) fn check(c: &mut Checker) {
    let bsp = c.bsp;
    for (i, f) in bsp.faces.iter().enumerate() {
        let Some(tex) = bsp.texinfo.get(f.texinfo as usize) else {
            continue; // `structure` reports the index
        };
        check_polygon_buffers(c, i, f, tex);
        let Some(points) = bsp.face_vertices(f) else {
            continue;
        };
        let ext = LightmapExtents::from_points(&points, &tex.vecs);
        check_extents(c, i, f, tex, &ext);
        check_engines_agree(c, i, tex, &points, &ext);
        check_lightmap_data(c, i, f, tex, &ext);
    }
}

/// QuakeSpasm refuses non-special faces over 2000 texels and DarkPlaces faces it lightmaps over
/// 256 luxels; WinQuake refuses non-special faces over 256 texels, GLQuake over 512.
fn check_extents(c: &mut Checker, i: usize, f: &Face, tex: &TexInfo, ext: &LightmapExtents) {
    let special = tex.flags & texinfo_flags::SPECIAL != 0;
    let lightmapped_by_darkplaces = !special || f.light_offset != -1;
    let widest = ext.extents[0].max(ext.extents[1]);
    let luxels = ext.luxel_size();
    // Formatted only for a problem: every face passes here.
    let detail = || {
        format!(
            "spans {}x{} texels ({}x{} luxels){}",
            ext.extents[0],
            ext.extents[1],
            luxels[0],
            luxels[1],
            if special { ", TEX_SPECIAL" } else { "" }
        )
    };
    if (!special && widest > QUAKESPASM_MAX_SURFACE_EXTENT)
        || (lightmapped_by_darkplaces && luxels[0].max(luxels[1]) > DARKPLACES_MAX_LIGHTMAP_SIZE)
    {
        c.report(Rule::SurfaceExtents, "faces", i, detail());
    } else if !special && widest > MAX_SURFACE_EXTENT {
        let which = if widest > GLQUAKE_MAX_SURFACE_EXTENT {
            "WinQuake and GLQuake"
        } else {
            "WinQuake"
        };
        c.report(
            Rule::SurfaceExtentsVanilla,
            "faces",
            i,
            format!("{}: {which} refuse it", detail()),
        );
    }
}

/// A lit face's lightmap must have one size and origin in every engine: QuakeSpasm's family and
/// DarkPlaces compute texture coordinates in different precision, which near a grid line can
/// snap them to different lines.
fn check_engines_agree(
    c: &mut Checker,
    i: usize,
    tex: &TexInfo,
    points: &[[f32; 3]],
    ext: &LightmapExtents,
) {
    if tex.flags & texinfo_flags::SPECIAL != 0 {
        return;
    }
    let disagree = LightmapExtents::engines_disagree(points, &tex.vecs);
    if disagree == [false, false] {
        return;
    }
    let dp = LightmapExtents::from_points_darkplaces(points, &tex.vecs);
    let axes = match disagree {
        [true, true] => "s and t",
        [true, false] => "s",
        _ => "t",
    };
    let detail = format!(
        "lightmap along {axes}: QuakeSpasm family {:?} from texel {:?}, DarkPlaces {:?} from \
         texel {:?}",
        ext.luxel_size(),
        ext.tex_mins,
        dp.luxel_size(),
        dp.tex_mins
    );
    c.report(Rule::LightmapExtentsEnginesDisagree, "faces", i, detail);
}

/// How many lightmaps (styles) a lit face has: its styles that are not 255, at least one.
pub(super) fn lightmaps_of(f: &Face) -> usize {
    f.styles.iter().filter(|&&s| s != 255).count().max(1)
}

/// A lit face's lightmaps (one per style) must lie inside the lighting lump.
fn check_lightmap_data(c: &mut Checker, i: usize, f: &Face, tex: &TexInfo, ext: &LightmapExtents) {
    if f.light_offset < 0 || tex.flags & texinfo_flags::SPECIAL != 0 {
        return;
    }
    let styles = lightmaps_of(f);
    let needed = ext.luxel_count() * styles;
    let offset = f.light_offset as usize;
    let luxels = c.bsp.luxel_count();
    if offset + needed > luxels {
        let detail = format!(
            "lightmap at {offset} ({needed} luxels for {styles} style(s)) runs past the {luxels} \
             luxels of lighting data"
        );
        c.report(Rule::LightmapRange, "faces", i, detail);
    }
}

/// QuakeSpasm and vkQuake copy sky, liquid and unlit untextured faces into a 64-vertex buffer
/// and subdivide liquids from a 60-vertex one.
fn check_polygon_buffers(c: &mut Checker, i: usize, f: &Face, tex: &TexInfo) {
    let bsp = c.bsp;
    let texture = bsp
        .textures
        .textures
        .get(tex.miptex as usize)
        .and_then(Option::as_ref);
    let name = texture.map(|t| t.name());
    let (kind, max) = match name.as_deref() {
        Some(n) if n.starts_with('*') => ("liquid", QUAKESPASM_MAX_WARP_FACE_VERTS),
        Some(n) if n.get(..3).is_some_and(|p| p.eq_ignore_ascii_case("sky")) => {
            ("sky", QUAKESPASM_MAX_UNLIT_FACE_VERTS)
        }
        None if f.light_offset == -1 => ("unlit untextured", QUAKESPASM_MAX_UNLIT_FACE_VERTS),
        _ => return,
    };
    if f.num_edges as usize > max {
        let detail = format!("{kind} face has {} edges, more than {max}", f.num_edges);
        c.report(Rule::UnlitFaceVerts, "faces", i, detail);
    }
}
