//! A loaded map in the shape the renderer wants: per-face surfaces with their texture axes and
//! lightmap rectangles, textures, the palette, lightmaps as RGB, node/leaf parents, and brush
//! models cut into the world's leaves so they sort with the world.

use glam::{DMat3, DVec3, Vec3};
use std::path::Path;

use quake_formats::Bsp;
use quake_formats::bsp::light_lumps::{LIGHTING_E5BGR9, RGBLIGHTING};
use quake_formats::bsp::{contents, limits::MAX_LIGHTMAPS, texinfo_flags};
use quake_formats::entities::{Entity, parse_entities};
use quake_formats::extents::{LightmapExtents, LuxelGrid};
use quake_formats::geom::{Plane, Split, Winding};
use quake_formats::lit::{LitData, unpack_e5bgr9};
use quake_formats::palette::Palette;

use crate::error::{Result, ViewerError};
use crate::textures::{PackedPalette, PaletteSource, Texture, TextureKind, find_palette};

/// Style slot value that marks "no lightmap here".
pub const NO_STYLE: u8 = 255;

/// A face ready to draw, in world space (brush model faces are moved by their entity's origin).
#[derive(Debug, Clone)]
pub struct Surface {
    /// The face's plane, facing the side it is seen from.
    pub plane: Plane,
    /// The polygon's corners in the BSP's winding order.
    pub points: Vec<DVec3>,
    /// Texture coordinates: `s = s_axis · p + s_offset`, likewise t.
    pub s_axis: DVec3,
    /// Offset of `s` in texels, the entity origin's shift included.
    pub s_offset: f64,
    /// The `t` axis in texels per map unit.
    pub t_axis: DVec3,
    /// Offset of `t` in texels, the entity origin's shift included.
    pub t_offset: f64,
    /// Index into [`World::textures`]; faces naming a texture the BSP lacks get the
    /// checkerboard at the end.
    pub texture: usize,
    /// How the surface is drawn.
    pub kind: TextureKind,
    /// The lightmap rectangle, as engines compute it from the face's own (unmoved) vertices.
    pub extents: LightmapExtents,
    /// The face's light styles; [`NO_STYLE`] ends the list.
    pub styles: [u8; MAX_LIGHTMAPS],
    /// First luxel in [`World::light`], when the face has a complete lightmap.
    pub light: Option<usize>,
    /// The lightmap's own grid when it is not Quake's 16 texels over `extents` (`DECOUPLED_LM`,
    /// `LMSHIFT`).
    pub free_lightmap: Option<FreeLightmap>,
}

/// A lightmap on a grid of its own: the grid, and the point of the face's plane (in model space,
/// where the grid's projection works) at texture coordinates (s, t): `at + s * per_s + t * per_t`.
#[derive(Debug, Clone)]
pub struct FreeLightmap {
    pub grid: LuxelGrid,
    pub at: DVec3,
    pub per_s: DVec3,
    pub per_t: DVec3,
}

impl FreeLightmap {
    /// `grid` on a face of texture projection `vecs` and plane `normal · p = dist`; `None` when
    /// the grid is empty or the projection runs along the plane (no point has a texture
    /// coordinate).
    fn new(grid: LuxelGrid, vecs: &[[f32; 4]; 2], normal: DVec3, dist: f64) -> Option<Self> {
        if grid.luxel_count() == 0 {
            return None;
        }
        let row = |v: [f32; 4]| DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
        let rows = DMat3::from_cols(row(vecs[0]), row(vecs[1]), normal).transpose();
        if rows.determinant().abs() < 1e-9 {
            return None;
        }
        let inverse = rows.inverse();
        let offsets = DVec3::new(-f64::from(vecs[0][3]), -f64::from(vecs[1][3]), dist);
        Some(FreeLightmap {
            grid,
            at: inverse * offsets,
            per_s: inverse.x_axis,
            per_t: inverse.y_axis,
        })
    }

    /// Continuous luxel coordinates of texture coordinates (s, t).
    pub fn luxel_at(&self, s: f64, t: f64) -> [f64; 2] {
        self.grid
            .luxel_at((self.at + self.per_s * s + self.per_t * t).to_array())
    }
}

impl Surface {
    /// Texture coordinates (s, t) of world point `p`, in texels.
    pub fn st(&self, p: DVec3) -> (f64, f64) {
        (
            self.s_axis.dot(p) + self.s_offset,
            self.t_axis.dot(p) + self.t_offset,
        )
    }

    /// Luxels across and down its lightmap.
    pub fn luxel_size(&self) -> [usize; 2] {
        self.free_lightmap
            .as_ref()
            .map_or_else(|| self.extents.luxel_size(), |f| f.grid.size)
    }

    /// How many lightmaps the face has: its styles before the first [`NO_STYLE`].
    pub fn style_count(&self) -> usize {
        self.styles.iter().take_while(|&&s| s != NO_STYLE).count()
    }
}

/// A piece of a brush model face lying in one world leaf.
#[derive(Debug, Clone)]
pub struct Fragment {
    /// The BSP face the piece is cut from.
    pub face: u32,
    /// The piece's corners, in world space.
    pub points: Vec<DVec3>,
}

/// Counts for the load summary.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct LoadStats {
    /// Faces in the BSP.
    pub faces: usize,
    /// Faces sound enough to draw.
    pub drawable_faces: usize,
    /// Textures loaded, the fallback checkerboard included.
    pub textures: usize,
    /// Texture slots the BSP stores without pixels (drawn as a checkerboard).
    pub missing_textures: usize,
    /// Brush models that entities show (triggers are not drawn).
    pub brush_models_drawn: usize,
    /// Pieces those models were cut into by the world's leaves.
    pub brush_model_fragments: usize,
    /// Whether the light has colour (a `.lit`, `RGBLIGHTING` or HDR light).
    pub coloured_light: bool,
    /// Where the light came from.
    pub light_source: LightSource,
    /// Why a `.lit` beside the BSP was not used (engines then draw the BSP's own light, grey).
    pub ignored_lit: Option<String>,
}

/// Where a map's light comes from, the first there is of: the BSPX `LIGHTING_E5BGR9` lump,
/// the `RGBLIGHTING` lump, a `.lit` (HDR or not), the lighting lump. As FTE and QuakeSpasm-Spiked
/// choose, engines without BSPX support reading only the last two.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum LightSource {
    /// The grey lighting lump (or none).
    #[default]
    LightingLump,
    /// A `.lit` beside the BSP.
    Lit,
    /// An HDR `.lit` beside the BSP.
    HdrLit,
    /// The `RGBLIGHTING` lump.
    RgbLighting,
    /// The `LIGHTING_E5BGR9` lump.
    HdrLump,
}

/// Light levels of HDR light 1.0 (the texture's own colour), as lightmap bytes stand for it.
const HDR_ONE: f32 = 128.0;

/// Each luxel's light, 128 the texture's own colour, from the best source `bsp` and its `.lit`
/// offer (see [`LightSource`]); a BSPX lump of the wrong size is passed over.
fn choose_light(bsp: &Bsp, lit: Option<LitData>) -> (Vec<[u16; 3]>, LightSource) {
    let luxels = bsp.luxel_count();
    let from_hdr = |words: &mut dyn Iterator<Item = u32>| -> Vec<[u16; 3]> {
        words
            .map(|w| unpack_e5bgr9(w).map(|c| (c * HDR_ONE).round().clamp(0.0, 65535.0) as u16))
            .collect()
    };
    let from_rgb = |rgb: &[u8]| -> Vec<[u16; 3]> {
        rgb.chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]].map(u16::from))
            .collect()
    };
    if let Some(hdr) = bsp
        .bspx_lump(LIGHTING_E5BGR9)
        .filter(|l| l.len() == 4 * luxels)
    {
        let mut words = hdr
            .chunks_exact(4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]));
        return (from_hdr(&mut words), LightSource::HdrLump);
    }
    if let Some(rgb) = bsp.bspx_lump(RGBLIGHTING).filter(|l| l.len() == 3 * luxels) {
        return (from_rgb(rgb), LightSource::RgbLighting);
    }
    match lit {
        Some(LitData::Rgb(rgb)) => (from_rgb(&rgb), LightSource::Lit),
        Some(LitData::Hdr(words)) => (from_hdr(&mut words.into_iter()), LightSource::HdrLit),
        None => (
            bsp.lighting.iter().map(|&l| [u16::from(l); 3]).collect(),
            LightSource::LightingLump,
        ),
    }
}

/// A loaded map, ready to draw.
#[derive(Debug)]
pub struct World {
    /// The map as read.
    pub bsp: Bsp,
    /// The palette textures are drawn through.
    pub palette: PackedPalette,
    /// Where the palette came from.
    pub palette_source: PaletteSource,
    /// One per texture slot of the BSP, then a checkerboard for faces whose texinfo names a slot
    /// past the last.
    pub textures: Vec<Texture>,
    /// One per BSP face; `None` for faces too broken to draw.
    pub surfaces: Vec<Option<Surface>>,
    /// Lightmap samples as RGB, one per luxel (128: the texture's own colour; HDR light may
    /// pass 255).
    pub light: Vec<[u16; 3]>,
    /// Draw the light alone, without textures: a texel shows its light level (128 grey for the
    /// texture's own colour; `--lightmap-only`).
    pub lightmap_only: bool,
    /// Parent node of each node of the world's tree; -1 for the root and unreached nodes.
    pub node_parent: Vec<i32>,
    /// Parent node of each leaf; -1 for leaves the world's tree does not reach.
    pub leaf_parent: Vec<i32>,
    /// Brush model fragments per world leaf.
    pub leaf_fragments: Vec<Vec<Fragment>>,
    /// Faces of the brush models that entities show.
    pub brush_faces: Vec<u32>,
    /// Fence faces of the world and of the brush models shown.
    pub fence_faces: Vec<u32>,
    /// The entity lump, parsed.
    pub entities: Vec<Entity>,
    /// Counts for the summary line.
    pub stats: LoadStats,
}

impl World {
    /// Load `path`, its `.lit` when one sits beside it, and the palette (see [`find_palette`]).
    pub fn load(path: &Path, palette: Option<&Path>) -> Result<World> {
        let format = |path: &Path| {
            let path = path.to_path_buf();
            move |error| ViewerError::format(&path, error)
        };
        let data = quake_formats::fsutil::read_file(path).map_err(format(path))?;
        let bsp = Bsp::read(&data).map_err(format(path))?;
        let lit_path = path.with_extension("lit");
        // As QuakeSpasm and DarkPlaces do, a `.lit` that is not this BSP's is ignored, not fatal.
        let (lit, ignored_lit) = if lit_path.is_file() {
            let data = quake_formats::fsutil::read_file(&lit_path).map_err(format(&lit_path))?;
            match quake_formats::lit::read_any_lit(&data, bsp.luxel_count()) {
                Ok(lit) => (Some(lit), None),
                Err(e) => (None, Some(format!("{}: {e}", lit_path.display()))),
            }
        } else {
            (None, None)
        };
        let (palette, source) = find_palette(path, palette)?;
        let mut world =
            World::new(bsp, &palette, source, lit).map_err(|detail| ViewerError::BadMap {
                path: path.to_path_buf(),
                detail,
            })?;
        world.stats.ignored_lit = ignored_lit;
        Ok(world)
    }

    /// Build from parts; `lit` is the data of a `.lit` file matching the BSP's luxels.
    pub fn new(
        bsp: Bsp,
        palette: &Palette,
        palette_source: PaletteSource,
        lit: Option<LitData>,
    ) -> Result<World, String> {
        quake_formats::check_usable(&bsp).map_err(|e| e.to_string())?;
        let entities = parse_entities(&bsp.entity_text()).map_err(|e| format!("entities: {e}"))?;
        let (light, light_source) = choose_light(&bsp, lit);
        let mut stats = LoadStats {
            faces: bsp.faces.len(),
            coloured_light: light_source != LightSource::LightingLump,
            light_source,
            ..LoadStats::default()
        };
        let mut textures: Vec<Texture> = bsp
            .textures
            .textures
            .iter()
            .map(|t| Texture::from_miptex(t.as_ref()))
            .collect();
        stats.missing_textures = bsp
            .textures
            .textures
            .iter()
            .filter(|t| t.as_ref().is_none_or(|t| t.mips.is_none()))
            .count();
        // Faces naming a texture the lump does not have get a checkerboard at the end.
        let fallback_texture = textures.len();
        textures.push(Texture::checker(String::new()));
        stats.textures = textures.len();

        // Each drawn brush model's entity origin moves its faces.
        let mut model_origin: Vec<Option<DVec3>> = vec![None; bsp.models.len()];
        if let Some(slot) = model_origin.first_mut() {
            *slot = Some(DVec3::ZERO);
        }
        for e in &entities {
            let Some(index) = e.get("model").and_then(|m| m.strip_prefix('*')) else {
                continue;
            };
            let Ok(index) = index.parse::<usize>() else {
                continue;
            };
            // Triggers are invisible in game.
            if index == 0 || e.classname().starts_with("trigger_") {
                continue;
            }
            if let Some(slot) = model_origin.get_mut(index) {
                let o = e.get_floats::<3>("origin").unwrap_or([0.0; 3]);
                *slot = Some(DVec3::new(o[0], o[1], o[2]));
            }
        }
        let mut face_origin: Vec<Option<(usize, DVec3)>> = vec![None; bsp.faces.len()];
        for (m, (model, origin)) in bsp.models.iter().zip(&model_origin).enumerate() {
            let Some(origin) = origin else { continue };
            let first = model.first_face as usize;
            let end = (first + model.num_faces as usize).min(bsp.faces.len());
            for slot in face_origin.get_mut(first..end).unwrap_or_default() {
                *slot = Some((m, *origin));
            }
        }

        let layouts = lightmap_layouts(&bsp);
        let surfaces: Vec<Option<Surface>> = (0..bsp.faces.len())
            .map(|f| {
                let origin = face_origin[f].map_or(DVec3::ZERO, |(_, o)| o);
                let lightmap = Lightmap {
                    layout: layouts.as_ref().and_then(|l| l.get(f).copied().flatten()),
                    luxels: light.len(),
                };
                build_surface(&bsp, f, origin, &textures, fallback_texture, lightmap)
            })
            .collect();
        stats.drawable_faces = surfaces.iter().flatten().count();

        let (node_parent, leaf_parent) = parents(&bsp)?;
        let mut leaf_fragments = vec![Vec::new(); bsp.leafs.len()];
        let mut brush_faces = Vec::new();
        let mut fence_faces = Vec::new();
        for (f, fo) in face_origin.iter().enumerate() {
            let (Some((model, _)), Some(surface)) = (fo, &surfaces[f]) else {
                continue;
            };
            let is_fence = surface.kind == TextureKind::Fence;
            if *model == 0 {
                if is_fence {
                    fence_faces.push(f as u32);
                }
                continue;
            }
            if textures[surface.texture]
                .name
                .eq_ignore_ascii_case("trigger")
            {
                continue;
            }
            if is_fence {
                fence_faces.push(f as u32);
            }
            brush_faces.push(f as u32);
            let winding = Winding::new(surface.points.clone());
            cut_into_leaves(&bsp, f as u32, winding, &mut leaf_fragments);
        }
        stats.brush_models_drawn = model_origin.iter().skip(1).flatten().count();
        stats.brush_model_fragments = leaf_fragments.iter().map(Vec::len).sum();

        Ok(World {
            bsp,
            palette: PackedPalette::new(palette),
            palette_source,
            textures,
            surfaces,
            light,
            lightmap_only: false,
            node_parent,
            leaf_parent,
            leaf_fragments,
            brush_faces,
            fence_faces,
            entities,
            stats,
        })
    }

    /// The world model's root node.
    pub fn root(&self) -> Option<i32> {
        self.bsp.models.first().map(|m| m.head_nodes[0])
    }

    /// The split plane of node `node`; `None` when the node or its plane index is out of range.
    pub fn node_plane(&self, node: usize) -> Option<Plane> {
        let n = self.bsp.nodes.get(node)?;
        let p = self.bsp.planes.get(n.plane as usize)?;
        Some(Plane::new(Vec3::from(p.normal).as_dvec3(), p.dist as f64))
    }

    /// Where the player starts: `info_player_start` (else a deathmatch, coop or intermission
    /// spot), eye height 22 above its origin, and its yaw (`angle`, or `mangle`'s yaw).
    pub fn player_start(&self) -> Option<(DVec3, f64)> {
        const SPOTS: [&str; 4] = [
            "info_player_start",
            "info_player_deathmatch",
            "info_player_coop",
            "info_intermission",
        ];
        SPOTS.iter().find_map(|class| {
            let e = self.entities.iter().find(|e| e.classname() == *class)?;
            let o = e.get_floats::<3>("origin")?;
            let yaw = e
                .get_float("angle")
                .or_else(|| e.get_floats::<3>("mangle").map(|m| m[1]))
                .unwrap_or(0.0);
            let eye = if *class == "info_intermission" {
                0.0
            } else {
                22.0
            };
            Some((DVec3::new(o[0], o[1], o[2] + eye), yaw))
        })
    }

    /// Spawn and intermission spots in entity order, for a flythrough path.
    pub fn spots(&self) -> Vec<(DVec3, f64)> {
        self.entities
            .iter()
            .filter(|e| {
                e.classname().starts_with("info_player") || e.classname() == "info_intermission"
            })
            .filter_map(|e| {
                let o = e.get_floats::<3>("origin")?;
                Some((
                    DVec3::new(o[0], o[1], o[2] + 22.0),
                    e.get_float("angle").unwrap_or(0.0),
                ))
            })
            .collect()
    }
}

/// Per face, the grid and first luxel of its lightmap when the BSP gives it one of its own: from
/// `DECOUPLED_LM`, else from `LMSHIFT` (and `LMOFFSET`, else the face's light offset); `None`
/// when neither lump is there (or reads).
fn lightmap_layouts(bsp: &Bsp) -> Option<Vec<Option<(LuxelGrid, i32)>>> {
    if let Ok(Some(records)) = bsp.decoupled_lightmaps() {
        return Some(records.iter().map(|r| Some((r.grid(), r.offset))).collect());
    }
    let shifts = bsp.lightmap_shifts().ok()??;
    let offsets = bsp.lightmap_offsets().ok()?;
    let layouts = bsp
        .faces
        .iter()
        .zip(&shifts)
        .enumerate()
        .map(|(i, (f, &shift))| {
            let points = bsp.face_vertices(f)?;
            let tex = bsp.texinfo.get(f.texinfo as usize)?;
            let grid = LuxelGrid::shifted(&points, &tex.vecs, shift)?;
            let offset = offsets.as_ref().map_or(f.light_offset, |o| o[i]);
            Some((grid, offset))
        })
        .collect();
    Some(layouts)
}

/// Where a face's lightmap lies: its own grid and first luxel, if the BSP gives it one, and the
/// luxels of light there are.
struct Lightmap {
    layout: Option<(LuxelGrid, i32)>,
    luxels: usize,
}

fn build_surface(
    bsp: &Bsp,
    f: usize,
    origin: DVec3,
    textures: &[Texture],
    fallback_texture: usize,
    lightmap: Lightmap,
) -> Option<Surface> {
    let face = &bsp.faces[f];
    let raw_points = bsp.face_vertices(face)?;
    if raw_points.len() < 3 {
        return None;
    }
    let ti = bsp.texinfo.get(face.texinfo as usize)?;
    let bp = bsp.planes.get(face.plane as usize)?;
    let mut plane = Plane::new(Vec3::from(bp.normal).as_dvec3(), bp.dist as f64);
    if face.side != 0 {
        plane = plane.flipped();
    }
    plane.dist += plane.normal.dot(origin);
    let extents = LightmapExtents::from_points(&raw_points, &ti.vecs);
    let axis = |v: [f32; 4]| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
    let (s_axis, t_axis) = (axis(ti.vecs[0]), axis(ti.vecs[1]));
    let texture = if (ti.miptex as usize) < fallback_texture {
        ti.miptex as usize
    } else {
        fallback_texture
    };
    let kind = textures[texture].kind(ti.flags & texinfo_flags::SPECIAL != 0);
    let styles = face.styles;
    let styles_used = styles.iter().take_while(|&&s| s != NO_STYLE).count();
    let model_normal = Vec3::from(bp.normal).as_dvec3();
    let free_lightmap = lightmap
        .layout
        .as_ref()
        .and_then(|(grid, _)| FreeLightmap::new(*grid, &ti.vecs, model_normal, f64::from(bp.dist)));
    let (offset, count) = match (&lightmap.layout, &free_lightmap) {
        (Some((_, offset)), Some(free)) => (*offset, free.grid.luxel_count()),
        (Some(_), None) => (-1, 0),
        (None, _) => (face.light_offset, extents.luxel_count()),
    };
    let light = usize::try_from(offset)
        .ok()
        .filter(|&ofs| styles_used > 0 && ofs + styles_used * count <= lightmap.luxels);
    Some(Surface {
        plane,
        points: raw_points
            .iter()
            .map(|&p| Vec3::from(p).as_dvec3() + origin)
            .collect(),
        s_axis,
        s_offset: ti.vecs[0][3] as f64 - s_axis.dot(origin),
        t_axis,
        t_offset: ti.vecs[1][3] as f64 - t_axis.dot(origin),
        texture,
        kind,
        extents,
        styles,
        light,
        free_lightmap,
    })
}

/// Parent node of every node and leaf in the world tree (-1 for the root and for anything the
/// world tree does not reach). Fails when a node is reached twice: everything that walks the tree
/// relies on it being a tree.
fn parents(bsp: &Bsp) -> Result<(Vec<i32>, Vec<i32>), String> {
    let mut node_parent = vec![-1; bsp.nodes.len()];
    let mut leaf_parent = vec![-1; bsp.leafs.len()];
    let mut seen = vec![false; bsp.nodes.len()];
    let Some(root) = bsp.models.first().map(|m| m.head_nodes[0]) else {
        return Ok((node_parent, leaf_parent));
    };
    let mut stack = vec![root];
    while let Some(n) = stack.pop() {
        let Some(node) = usize::try_from(n).ok().and_then(|i| bsp.nodes.get(i)) else {
            continue;
        };
        if std::mem::replace(&mut seen[n as usize], true) {
            return Err(format!(
                "node {n} is reached twice from the world's root: the node tree is damaged"
            ));
        }
        for &child in &node.children {
            if child >= 0 {
                if let Some(p) = node_parent.get_mut(child as usize) {
                    *p = n;
                    stack.push(child);
                }
            } else if let Some(p) = leaf_parent.get_mut((-(child + 1)) as usize) {
                *p = n;
            }
        }
    }
    Ok((node_parent, leaf_parent))
}

/// Push a brush model face down the world tree, keeping the pieces in non-solid leaves. A piece
/// lying on a node's plane follows the side it faces.
fn cut_into_leaves(bsp: &Bsp, face: u32, winding: Winding, out: &mut [Vec<Fragment>]) {
    let Some(root) = bsp.models.first().map(|m| m.head_nodes[0]) else {
        return;
    };
    let mut stack = vec![(root, winding)];
    while let Some((n, w)) = stack.pop() {
        if n < 0 {
            let leaf = (-(n + 1)) as usize;
            if let (Some(l), Some(slot)) = (bsp.leafs.get(leaf), out.get_mut(leaf))
                && l.contents != contents::SOLID
            {
                slot.push(Fragment {
                    face,
                    points: w.points,
                });
            }
            continue;
        }
        let Some(node) = bsp.nodes.get(n as usize) else {
            continue;
        };
        let Some(p) = bsp.planes.get(node.plane as usize) else {
            continue;
        };
        let plane = Plane::new(Vec3::from(p.normal).as_dvec3(), p.dist as f64);
        let [front, back] = node.children;
        match w.split(&plane) {
            Split::Front(w) => stack.push((front, w)),
            Split::Back(w) => stack.push((back, w)),
            Split::On {
                winding,
                facing_front,
            } => stack.push((if facing_front { front } else { back }, winding)),
            Split::Both { front: f, back: b } => {
                stack.push((front, f));
                stack.push((back, b));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(bsp: Bsp) -> World {
        World::new(bsp, &Palette::slipgate(), PaletteSource::Builtin, None).expect("room")
    }

    #[test]
    fn bspx_light_lumps_win_over_the_lit_and_the_grey_lump() {
        let mut bsp = crate::test_room::room_bsp(0);
        let luxels = bsp.lighting.len();
        let grey = load(bsp.clone());
        assert_eq!(grey.stats.light_source, LightSource::LightingLump);
        let rgb: Vec<u8> = (0..3 * luxels).map(|i| (i % 251) as u8).collect();
        bsp.set_bspx_lump(RGBLIGHTING, rgb.clone());
        let coloured = load(bsp.clone());
        assert_eq!(coloured.stats.light_source, LightSource::RgbLighting);
        assert_eq!(coloured.light[1], [3, 4, 5]);
        // -novanilla: no grey lump, RGBLIGHTING alone.
        let mut novanilla = bsp.clone();
        novanilla.lighting.clear();
        let world = load(novanilla);
        assert_eq!(world.light, coloured.light);
        assert_eq!(
            world
                .surfaces
                .iter()
                .flatten()
                .filter(|s| s.light.is_some())
                .count(),
            coloured
                .surfaces
                .iter()
                .flatten()
                .filter(|s| s.light.is_some())
                .count(),
            "faces keep their lightmaps"
        );
        // HDR light, twice the texture's own colour in red.
        let word = quake_formats::lit::pack_e5bgr9([2.0, 1.0, 0.0]);
        bsp.set_bspx_lump(LIGHTING_E5BGR9, word.to_le_bytes().repeat(luxels));
        let hdr = load(bsp.clone());
        assert_eq!(hdr.stats.light_source, LightSource::HdrLump);
        assert_eq!(hdr.light[0], [256, 128, 0]);
        // A lump of the wrong size is passed over.
        bsp.set_bspx_lump(LIGHTING_E5BGR9, vec![0; 4]);
        assert_eq!(load(bsp).stats.light_source, LightSource::RgbLighting);
    }

    #[test]
    fn an_hdr_lit_beside_the_bsp_is_read() {
        let bsp = crate::test_room::room_bsp(0);
        let words = vec![quake_formats::lit::pack_e5bgr9([0.5; 3]); bsp.lighting.len()];
        let lit = Some(LitData::Hdr(words));
        let world =
            World::new(bsp, &Palette::slipgate(), PaletteSource::Builtin, lit).expect("room");
        assert_eq!(world.stats.light_source, LightSource::HdrLit);
        assert_eq!(world.light[0], [64; 3]);
    }

    #[test]
    fn a_lit_of_another_bsp_is_ignored_as_engines_do_not_fatal() {
        let dir = std::env::temp_dir().join(format!("slipgate-view-lit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let bsp_path = dir.join("room.bsp");
        let bsp = crate::test_room::room_bsp(0);
        std::fs::write(&bsp_path, bsp.write().expect("room writes")).expect("write bsp");
        // One luxel too many: a .lit written for another BSP.
        let rgb = vec![200u8; 3 * (bsp.lighting.len() + 1)];
        std::fs::write(dir.join("room.lit"), quake_formats::lit::write_lit(&rgb)).expect("lit");
        let world = World::load(&bsp_path, None).expect("loads without the .lit");
        assert!(!world.stats.coloured_light);
        assert!(world.stats.ignored_lit.is_some());
        // The matching size is used.
        let rgb = vec![200u8; 3 * bsp.lighting.len()];
        std::fs::write(dir.join("room.lit"), quake_formats::lit::write_lit(&rgb)).expect("lit");
        let world = World::load(&bsp_path, None).expect("loads with the .lit");
        assert!(world.stats.coloured_light && world.stats.ignored_lit.is_none());
        std::fs::remove_dir_all(&dir).expect("clean up");
    }
}
