//! The surface cache: each visible surface's texture tiled over its lightmap rectangle and lit,
//! built once per (face, mip level) and reused until its light styles change. A byte budget with
//! least-recently-used eviction bounds it.
//!
//! Shading is done in RGB rather than through an 8-bit colormap: a texel's palette colour is
//! multiplied by light / 128 and clamped (128 = the texture's own colour, as the middle row of
//! Quake's colormap; fullbright palette entries stay unlit). That keeps `.lit` colour exact.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use quake_formats::bsp::limits::MAX_LIGHTMAPS;

use crate::camera::{NEAR_CLIP, View};
use crate::textures::{FENCE_TRANSPARENT_INDEX, TextureKind, pack};
use crate::world::{Surface, World};

/// Light value of every face of a map without lighting data: engines draw it fully lit. (In a
/// map with lighting data, a face without a lightmap is dark, as in engines.)
const UNLIT_MAP_LIGHT: u32 = 255;
/// Light levels above this shade every palette colour to white (a channel of 1 times it /
/// 128 is already past 255).
const MAX_SHADED_LIGHT: u32 = 255 * 128;
/// Style value for normal light ('m').
pub const NORMAL_STYLE: u32 = 256;

/// Quake's standard light style patterns, which the game sets when a level starts: one letter
/// per step, 'a' dark, 'm' normal, 'z' double. Styles past these (the switchable lights from 32
/// on) stay 'm'.
pub const STANDARD_STYLES: [&str; 12] = [
    // 0 normal
    "m",
    // 1 flicker
    "mmnmmommommnonmmonqnmmo",
    // 2 slow strong pulse
    "abcdefghijklmnopqrstuvwxyzyxwvutsrqponmlkjihgfedcba",
    // 3 candle
    "mmmmmaaaaammmmmaaaaaabcdefgabcdefg",
    // 4 fast strobe
    "mamamamamama",
    // 5 gentle pulse
    "jklmnopqrstuvwxyzyxwvutsrqponmlkj",
    // 6 other flicker
    "nmonqnmomnmomomno",
    // 7 candle
    "mmmaaaabcdefgmmmmaaaammmaamm",
    // 8 candle
    "mmmaaammmaaammmabcdefaaaammmmabcdefmmmaaaa",
    // 9 slow strobe
    "aaaaaaaazzzzzzzz",
    // 10 fluorescent flicker
    "mmamammmmammamamaaamammma",
    // 11 slow pulse, not fading to black
    "abcdefghijklmnopqrrqponmlkjihgfedcba",
];

/// Light style steps per second.
pub const STYLE_STEPS_PER_SECOND: f64 = 10.0;

/// The 256 light styles: each one's pattern and its brightness at the current time
/// (`NORMAL_STYLE` is unchanged light).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LightStyles {
    patterns: Vec<Vec<u8>>,
    /// Each style's brightness now: 256 for 'm' (normal light), 0 for 'a', 533 for 'z'.
    pub values: [u32; 256],
}

impl Default for LightStyles {
    /// The standard patterns at time 0.
    fn default() -> Self {
        let mut styles = LightStyles {
            patterns: vec![b"m".to_vec(); 256],
            values: [NORMAL_STYLE; 256],
        };
        for (style, pattern) in STANDARD_STYLES.iter().enumerate() {
            styles.set_pattern(style as u8, pattern);
        }
        styles
    }
}

impl LightStyles {
    /// Quake's pattern letters: 'a' is dark, 'm' normal, 'z' double.
    pub fn letter_value(c: u8) -> u32 {
        (c.clamp(b'a', b'z') - b'a') as u32 * NORMAL_STYLE / 12
    }

    /// Give `style` a new pattern (as the game's `lightstyle` does; an empty one means 'm').
    /// Its value is that of the pattern's first letter until the next [`LightStyles::animate`].
    pub fn set_pattern(&mut self, style: u8, pattern: &str) {
        let letters = if pattern.is_empty() {
            b"m".to_vec()
        } else {
            pattern.as_bytes().to_vec()
        };
        self.values[style as usize] = Self::letter_value(letters[0]);
        self.patterns[style as usize] = letters;
    }

    /// Set every style's value for `time` seconds: the pattern's letter at step
    /// `floor(time * 10)`, wrapping around.
    pub fn animate(&mut self, time: f64) {
        let step = (time.max(0.0) * STYLE_STEPS_PER_SECOND) as u64;
        for (value, pattern) in self.values.iter_mut().zip(&self.patterns) {
            *value = Self::letter_value(pattern[(step % pattern.len() as u64) as usize]);
        }
    }

    fn of(&self, surface: &Surface) -> [u32; MAX_LIGHTMAPS] {
        std::array::from_fn(|i| match surface.styles[i] {
            crate::world::NO_STYLE => 0,
            s => self.values[s as usize],
        })
    }
}

/// A lit texel of a fence that shows what lies behind (real colours are 0x00RRGGBB).
pub const TRANSPARENT: u32 = 0xFF00_0000;

/// Largest cached surface side in texels; bigger surfaces use a coarser mip level.
pub const MAX_CACHE_EXTENT: i32 = 2048;

/// Mip level for a surface: from the texels per pixel at its nearest point (its nearest vertex,
/// no nearer than the near clip plane), one level per doubling, coarser when the surface would
/// not fit [`MAX_CACHE_EXTENT`]. Shared with the reference renderer.
pub fn choose_mip(view: &View, surface: &Surface) -> usize {
    let nearest = surface
        .points
        .iter()
        .map(|&p| view.depth(p))
        .fold(f64::INFINITY, f64::min)
        .max(NEAR_CLIP);
    let texels_per_unit = surface.s_axis.length().max(surface.t_axis.length());
    let texels_per_pixel = nearest * texels_per_unit / view.scale;
    let mut mip = match texels_per_pixel {
        t if t <= 1.0 => 0,
        t if t <= 2.0 => 1,
        t if t <= 4.0 => 2,
        _ => 3,
    };
    let widest = surface.extents.extents[0].max(surface.extents.extents[1]);
    while mip < 3 && widest >> mip > MAX_CACHE_EXTENT {
        mip += 1;
    }
    mip
}

/// A lit surface at one mip level: `width` x `height` texels, 0x00RRGGBB or [`TRANSPARENT`].
/// Texel (u, v) shows texture coordinates (tex_mins + (u, v) * 2^mip).
#[derive(Debug, Clone)]
pub struct LitSurface {
    pub width: usize,
    pub height: usize,
    pub texels: Vec<u32>,
}

/// Light and texture a surface at `mip`: each texel's light is the bilinear blend of the four
/// luxels around its corner, the styles summed with their current values. With
/// [`World::lightmap_only`] the texture is left out: a texel shows its light (128 grey for the
/// texture's own colour).
pub fn build_lit_surface(
    world: &World,
    surface: &Surface,
    mip: usize,
    styles: &LightStyles,
) -> LitSurface {
    let ext = surface.extents;
    let width = ((ext.extents[0] >> mip) as usize).max(1);
    let height = ((ext.extents[1] >> mip) as usize).max(1);
    let [lw, lh] = surface.luxel_size();
    let count = lw * lh;
    let mut block = vec![[0u32; 3]; count];
    match surface.light {
        Some(ofs) => {
            let values = styles.of(surface);
            for (style, &value) in values.iter().enumerate().take(surface.style_count()) {
                let map = &world.light[ofs + style * count..ofs + (style + 1) * count];
                for (b, l) in block.iter_mut().zip(map) {
                    for c in 0..3 {
                        b[c] += l[c] as u32 * value;
                    }
                }
            }
        }
        None if world.light.is_empty() => block.fill([UNLIT_MAP_LIGHT * NORMAL_STYLE; 3]),
        None => {}
    }
    let tex = &world.textures[surface.texture];
    let holes = surface.kind == TextureKind::Fence;
    let (s0, t0) = (ext.tex_mins[0] >> mip, ext.tex_mins[1] >> mip);
    let mut texels = Vec::with_capacity(width * height);
    for v in 0..height {
        let pv = v << mip;
        let (ly, fy) = ((pv >> 4).min(lh - 1), (pv & 15) as u32);
        let ly1 = (ly + 1).min(lh - 1);
        for u in 0..width {
            let pu = u << mip;
            let (lx, fx) = ((pu >> 4).min(lw - 1), (pu & 15) as u32);
            let lx1 = (lx + 1).min(lw - 1);
            let light = match &surface.free_lightmap {
                // Quake's grid: luxels 16 texels apart, blended in 1/16 steps as engines do.
                None => {
                    let (a, b) = (block[ly * lw + lx], block[ly * lw + lx1]);
                    let (c, d) = (block[ly1 * lw + lx], block[ly1 * lw + lx1]);
                    std::array::from_fn(|k| {
                        let top = a[k] * (16 - fx) + b[k] * fx;
                        let bottom = c[k] * (16 - fx) + d[k] * fx;
                        ((top as u64 * (16 - fy) as u64 + bottom as u64 * fy as u64) >> 16) as u32
                    })
                }
                Some(free) => {
                    let s = f64::from(ext.tex_mins[0] + (pu as i32));
                    let t = f64::from(ext.tex_mins[1] + (pv as i32));
                    free_light(&block, [lw, lh], free.luxel_at(s, t))
                }
            };
            // HDR light passes 255; past this every channel is white anyway.
            let light = light.map(|l| l.min(MAX_SHADED_LIGHT));
            if world.lightmap_only {
                texels.push(pack(light.map(|l| l.min(255) as u8)));
                continue;
            }
            let idx = tex.index_at(mip, s0 + u as i32, t0 + v as i32);
            texels.push(if holes && idx == FENCE_TRANSPARENT_INDEX {
                TRANSPARENT
            } else {
                world.palette.shade(idx, light)
            });
        }
    }
    LitSurface {
        width,
        height,
        texels,
    }
}

/// The light of `block` (`size` luxels, each summed over styles at [`NORMAL_STYLE`] per unit) at
/// continuous luxel coordinates `at`, blended between the four luxels around it and held to the
/// lightmap's edge.
fn free_light(block: &[[u32; 3]], size: [usize; 2], at: [f64; 2]) -> [u32; 3] {
    let [lw, lh] = size;
    let split = |c: f64, n: usize| {
        let c = c.clamp(0.0, (n - 1) as f64);
        let i = (c.floor() as usize).min(n - 1);
        (i, (i + 1).min(n - 1), c - i as f64)
    };
    let ((x0, x1, fx), (y0, y1, fy)) = (split(at[0], lw), split(at[1], lh));
    std::array::from_fn(|k| {
        let at = |x: usize, y: usize| f64::from(block[y * lw + x][k]);
        let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
        let bottom = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
        ((top * (1.0 - fy) + bottom * fy) / f64::from(NORMAL_STYLE)).round() as u32
    })
}

/// How the surface cache fared over one frame (or, added up, over many).
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
pub struct CacheStats {
    /// Surfaces found in the cache, lit by current style values.
    pub hits: u64,
    /// Surfaces built, because they were absent or lit by old style values.
    pub misses: u64,
    /// Misses caused by a light style changing under a cached surface.
    pub style_rebuilds: u64,
    /// Bytes of lit surfaces built.
    pub bytes_built: u64,
    /// Surfaces dropped to stay within the budget.
    pub evictions: u64,
    /// Bytes the cache holds at the end.
    pub bytes_resident: u64,
    /// Time spent building lit surfaces.
    #[serde(skip)]
    pub build_time: Duration,
}

impl CacheStats {
    /// Hits over all look-ups; 1 when there were none.
    pub fn hit_rate(&self) -> f64 {
        let total = self.hits + self.misses;
        if total == 0 {
            1.0
        } else {
            self.hits as f64 / total as f64
        }
    }

    /// Add another frame's counts and time; `bytes_resident` becomes the later frame's.
    pub fn add(&mut self, o: &CacheStats) {
        self.hits += o.hits;
        self.misses += o.misses;
        self.style_rebuilds += o.style_rebuilds;
        self.bytes_built += o.bytes_built;
        self.evictions += o.evictions;
        self.bytes_resident = o.bytes_resident;
        self.build_time += o.build_time;
    }
}

#[derive(Debug)]
struct Entry {
    surface: LitSurface,
    styles: [u32; MAX_LIGHTMAPS],
    last_used: u64,
}

impl Entry {
    fn bytes(&self) -> usize {
        self.surface.texels.len() * 4
    }
}

#[derive(Debug)]
pub struct SurfaceCache {
    entries: HashMap<(u32, u8), Entry>,
    bytes: usize,
    budget: usize,
    frame: u64,
    /// This frame's statistics (reset by [`SurfaceCache::begin_frame`]).
    pub stats: CacheStats,
}

impl SurfaceCache {
    pub fn new(budget_bytes: usize) -> SurfaceCache {
        SurfaceCache {
            entries: HashMap::new(),
            bytes: 0,
            budget: budget_bytes,
            frame: 0,
            stats: CacheStats::default(),
        }
    }

    pub fn begin_frame(&mut self) {
        self.frame += 1;
        self.stats = CacheStats {
            bytes_resident: self.bytes as u64,
            ..CacheStats::default()
        };
    }

    pub fn clear(&mut self) {
        self.entries.clear();
        self.bytes = 0;
    }

    /// The lit surface for `face` at `mip`, built now if absent or lit by old style values.
    pub fn get(
        &mut self,
        world: &World,
        face: u32,
        mip: usize,
        styles: &LightStyles,
    ) -> Option<&LitSurface> {
        let surface = world.surfaces.get(face as usize)?.as_ref()?;
        let key = (face, mip as u8);
        let current = styles.of(surface);
        let fresh = match self.entries.get_mut(&key) {
            Some(e) if e.styles == current => {
                e.last_used = self.frame;
                self.stats.hits += 1;
                false
            }
            Some(_) => {
                self.stats.style_rebuilds += 1;
                true
            }
            None => true,
        };
        if fresh {
            self.stats.misses += 1;
            let start = Instant::now();
            let entry = Entry {
                surface: build_lit_surface(world, surface, mip, styles),
                styles: current,
                last_used: self.frame,
            };
            self.stats.build_time += start.elapsed();
            self.stats.bytes_built += entry.bytes() as u64;
            self.bytes += entry.bytes();
            if let Some(old) = self.entries.insert(key, entry) {
                self.bytes -= old.bytes();
            }
            if self.bytes > self.budget {
                self.evict();
            }
            self.stats.bytes_resident = self.bytes as u64;
        }
        self.entries.get(&key).map(|e| &e.surface)
    }

    /// Drop least recently used entries (never this frame's) until 3/4 of the budget is used.
    fn evict(&mut self) {
        let mut old: Vec<(u64, (u32, u8))> = self
            .entries
            .iter()
            .filter(|(_, e)| e.last_used < self.frame)
            .map(|(k, e)| (e.last_used, *k))
            .collect();
        old.sort_unstable();
        let target = self.budget / 4 * 3;
        for (_, key) in old {
            if self.bytes <= target {
                break;
            }
            if let Some(e) = self.entries.remove(&key) {
                self.bytes -= e.bytes();
                self.stats.evictions += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_room::{room, room_bsp};
    use crate::textures::PaletteSource;
    use quake_formats::Bsp;
    use quake_formats::palette::Palette;

    #[test]
    fn least_recently_used_surfaces_go_first() {
        let world = room(0);
        let styles = LightStyles::default();
        let one = build_lit_surface(
            &world,
            world.surfaces[0].as_ref().expect("wall"),
            0,
            &styles,
        );
        let size = one.texels.len() * 4;
        // Over budget, entries not used this frame go oldest first until 3/4 of it is used.
        let mut cache = SurfaceCache::new(size * 9 / 2);
        cache.begin_frame();
        for face in [0, 1, 2] {
            cache.get(&world, face, 0, &styles);
        }
        cache.begin_frame();
        cache.get(&world, 0, 0, &styles);
        cache.get(&world, 3, 0, &styles);
        cache.begin_frame();
        cache.get(&world, 4, 0, &styles);
        assert_eq!(cache.stats.evictions, 2);
        assert!(cache.bytes <= size * 9 / 2 / 4 * 3);
        cache.begin_frame();
        for face in [0, 3, 4] {
            cache.get(&world, face, 0, &styles);
        }
        assert_eq!((cache.stats.hits, cache.stats.misses), (3, 0));
        cache.get(&world, 1, 0, &styles);
        assert_eq!(cache.stats.misses, 1, "face 1 was evicted");
    }

    /// As engines: a map without lighting data is fully lit; in a lit map, a face without a
    /// lightmap is dark.
    #[test]
    fn faces_without_lightmaps_are_dark_unless_the_map_has_no_light() {
        let texel = |bsp: Bsp, face: usize| {
            let world =
                World::new(bsp, &Palette::slipgate(), PaletteSource::Builtin, None).expect("room");
            let s = world.surfaces[face].as_ref().expect("wall");
            let lit = build_lit_surface(&world, s, 0, &LightStyles::default());
            let idx = world.textures[0].index_at(0, s.extents.tex_mins[0], s.extents.tex_mins[1]);
            (lit.texels[0], idx, world.palette.clone())
        };
        let mut unlit_face = room_bsp(0);
        unlit_face.faces[1].light_offset = -1;
        let (dark, idx, palette) = texel(unlit_face, 1);
        assert_eq!(dark, palette.shade(idx, [0; 3]));
        let mut unlit_map = room_bsp(0);
        unlit_map.lighting.clear();
        for f in &mut unlit_map.faces {
            f.light_offset = -1;
        }
        let (bright, idx, palette) = texel(unlit_map, 1);
        assert_eq!(bright, palette.shade(idx, [UNLIT_MAP_LIGHT; 3]));
    }

    /// A `DECOUPLED_LM` record per face describing its own 16-texel grid: drawn through the
    /// free-grid path, every texel matches Quake's path within rounding.
    #[test]
    fn a_decoupled_lightmap_on_quakes_grid_draws_as_quakes() {
        use quake_formats::bsp::light_lumps::DecoupledLightmap;
        use quake_formats::extents::LightmapExtents;
        let mut bsp = room_bsp(0);
        let records: Vec<DecoupledLightmap> = bsp
            .faces
            .iter()
            .map(|f| {
                let vecs = bsp.texinfo[f.texinfo as usize].vecs;
                let points = bsp.face_vertices(f).expect("face");
                let ext = LightmapExtents::from_points(&points, &vecs);
                let [w, h] = ext.luxel_size();
                let row = |axis: usize| {
                    let v = vecs[axis];
                    let mins = ext.tex_mins[axis] as f32;
                    [v[0] / 16.0, v[1] / 16.0, v[2] / 16.0, (v[3] - mins) / 16.0]
                };
                DecoupledLightmap {
                    width: w as u16,
                    height: h as u16,
                    offset: f.light_offset,
                    world_to_luxel: [row(0), row(1)],
                }
            })
            .collect();
        let quake = World::new(
            bsp.clone(),
            &Palette::slipgate(),
            PaletteSource::Builtin,
            None,
        )
        .expect("room");
        // A face without a lightmap, as ericw-tools writes it: no luxels, no offset.
        let mut empty = records.clone();
        (empty[1].width, empty[1].height, empty[1].offset) = (0, 0, -1);
        bsp.set_decoupled_lightmaps(&empty);
        let world = World::new(
            bsp.clone(),
            &Palette::slipgate(),
            PaletteSource::Builtin,
            None,
        )
        .expect("room");
        let unlit = world.surfaces[1].as_ref().expect("wall");
        assert!(unlit.free_lightmap.is_none() && unlit.light.is_none());
        build_lit_surface(&world, unlit, 0, &LightStyles::default());
        bsp.set_decoupled_lightmaps(&records);
        let decoupled =
            World::new(bsp, &Palette::slipgate(), PaletteSource::Builtin, None).expect("room");
        let mut compared = 0;
        for (q, d) in quake.surfaces.iter().zip(&decoupled.surfaces) {
            let (Some(q), Some(d)) = (q, d) else { continue };
            assert!(d.free_lightmap.is_some() && d.light == q.light);
            let styles = LightStyles::default();
            let a = build_lit_surface(&quake, q, 0, &styles);
            let b = build_lit_surface(&decoupled, d, 0, &styles);
            for (x, y) in a.texels.iter().zip(&b.texels) {
                let (x, y) = (crate::textures::unpack(*x), crate::textures::unpack(*y));
                assert!(
                    x.iter().zip(y).all(|(p, q)| p.abs_diff(q) <= 2),
                    "{x:?} {y:?}"
                );
                compared += 1;
            }
        }
        assert!(compared > 1000);
    }

    #[test]
    fn lightmap_only_shows_the_light_without_the_texture() {
        let mut world = room(0);
        world.lightmap_only = true;
        let s = world.surfaces[2].as_ref().expect("wall");
        let lit = build_lit_surface(&world, s, 0, &LightStyles::default());
        let l0 = world.light[s.light.expect("lit")][0] as u8;
        assert_eq!(lit.texels[0], pack([l0; 3]));
    }

    #[test]
    fn hdr_light_past_255_shades_to_white_without_overflow() {
        let mut world = room(0);
        let s = world.surfaces[2].clone().expect("wall");
        let ofs = s.light.expect("lit");
        world.light[ofs] = [u16::MAX; 3];
        let lit = build_lit_surface(&world, &s, 0, &LightStyles::default());
        let idx = world.textures[0].index_at(0, s.extents.tex_mins[0], s.extents.tex_mins[1]);
        assert_eq!(
            lit.texels[0],
            world.palette.shade(idx, [MAX_SHADED_LIGHT; 3])
        );
    }

    #[test]
    fn lightmap_is_bilinear_between_luxels() {
        let world = room(0);
        let s = world.surfaces[2].as_ref().expect("wall");
        let lit = build_lit_surface(&world, s, 0, &LightStyles::default());
        let ofs = s.light.expect("lit");
        let tex = &world.textures[0];
        let [lw, _] = s.extents.luxel_size();
        let expect = |u: usize, light: u32| {
            let idx = tex.index_at(0, s.extents.tex_mins[0] + u as i32, s.extents.tex_mins[1]);
            world.palette.shade(idx, [light; 3])
        };
        let (l0, l1) = (world.light[ofs][0] as u32, world.light[ofs + 1][0] as u32);
        assert!(lw > 2 && l0 != l1);
        assert_eq!(lit.texels[0], expect(0, l0));
        assert_eq!(lit.texels[16], expect(16, l1));
        assert_eq!(lit.texels[8], expect(8, (l0 + l1) / 2));
    }

    #[test]
    fn styles_follow_their_patterns_at_ten_steps_a_second() {
        let mut styles = LightStyles::default();
        let flicker = STANDARD_STYLES[1].as_bytes();
        for (time, step) in [(0.0, 0), (0.25, 2), (0.55, 5), (2.35, 0), (2.45, 1)] {
            styles.animate(time);
            assert_eq!(
                styles.values[1],
                LightStyles::letter_value(flicker[step]),
                "time {time}"
            );
            assert_eq!(styles.values[0], NORMAL_STYLE);
            assert_eq!(styles.values[32], NORMAL_STYLE, "switchable styles stay on");
        }
        styles.animate(0.85);
        assert_eq!(styles.values[9], LightStyles::letter_value(b'z'));
        styles.set_pattern(40, "a");
        styles.set_pattern(41, "");
        styles.animate(100.0);
        assert_eq!((styles.values[40], styles.values[41]), (0, NORMAL_STYLE));
    }

    #[test]
    fn style_letters() {
        assert_eq!(LightStyles::letter_value(b'a'), 0);
        assert_eq!(LightStyles::letter_value(b'm'), NORMAL_STYLE);
        assert_eq!(LightStyles::letter_value(b'z'), NORMAL_STYLE * 25 / 12);
    }
}
