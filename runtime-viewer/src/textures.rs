//! Palettes and mip textures as the renderer uses them, plus the two special looks: sky and
//! warped liquids.

use glam::DVec3;
use std::path::{Path, PathBuf};

use quake_formats::miptex::MipTex;
use quake_formats::palette::{FIRST_FULLBRIGHT, Palette};

use crate::error::{Result, ViewerError};

/// Where the palette came from, for the summary line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PaletteSource {
    /// A palette file: the one given, or the game's `gfx/palette.lmp` found near the map.
    File(PathBuf),
    /// Slipgate's own palette, as no file was given or found.
    Builtin,
}

/// `--palette FILE` if given; else `gfx/palette.lmp` in the nearest ancestor of the map's folder
/// that has one (Quake keeps maps in `id1/maps/` and the palette in `id1/gfx/`); else Slipgate's.
pub fn find_palette(map: &Path, explicit: Option<&Path>) -> Result<(Palette, PaletteSource)> {
    let read = |path: &Path| -> Result<(Palette, PaletteSource)> {
        let data = quake_formats::fsutil::read_file(path)
            .map_err(|error| ViewerError::format(path, error))?;
        let palette =
            Palette::from_bytes(&data).map_err(|error| ViewerError::format(path, error))?;
        Ok((palette, PaletteSource::File(path.to_path_buf())))
    };
    if let Some(path) = explicit {
        return read(path);
    }
    let dir = map.parent().unwrap_or(Path::new("."));
    match quake_formats::palette::find_game_palette(dir) {
        Some(found) => read(&found),
        None => Ok((Palette::slipgate(), PaletteSource::Builtin)),
    }
}

/// How a surface is drawn, decided by its texture name and texinfo flags.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureKind {
    /// Lit through the surface cache.
    Lit,
    /// Quake's two-layer sky, looked up by view direction.
    Sky,
    /// Liquids (`*` names): warped, drawn unlit as Quake's software renderer does.
    Liquid,
    /// Fences (`{` names): lit like [`TextureKind::Lit`], but palette index
    /// [`FENCE_TRANSPARENT_INDEX`] is a hole.
    Fence,
}

/// The palette index that fence textures leave see-through.
pub const FENCE_TRANSPARENT_INDEX: u8 = 255;

/// One texture's four mip levels of palette indices.
#[derive(Debug, Clone)]
pub struct Texture {
    /// The miptex name, which decides how it is drawn (see [`Texture::kind`]).
    pub name: String,
    /// Width of mip level 0 in texels.
    pub width: u32,
    /// Height of mip level 0 in texels.
    pub height: u32,
    /// Palette indices of levels 0 to 3, rows top to bottom.
    pub mips: [Vec<u8>; 4],
}

impl Texture {
    /// The BSP's texture, or a checkerboard when the BSP stores none (external textures).
    pub fn from_miptex(mt: Option<&MipTex>) -> Texture {
        match mt {
            Some(MipTex {
                width,
                height,
                mips: Some(mips),
                ..
            }) => Texture {
                name: mt.map(MipTex::name).unwrap_or_default(),
                width: *width,
                height: *height,
                mips: mips.clone(),
            },
            _ => Texture::checker(mt.map(MipTex::name).unwrap_or_default()),
        }
    }

    /// 64x64 checkerboard in two mid greys of the palette's first ramp.
    pub fn checker(name: String) -> Texture {
        let mips = std::array::from_fn(|level| {
            let size = 64usize >> level;
            let cell = 16usize >> level;
            (0..size * size)
                .map(|i| {
                    let (x, y) = (i % size, i / size);
                    if ((x / cell) + (y / cell)).is_multiple_of(2) {
                        6
                    } else {
                        10
                    }
                })
                .collect()
        });
        Texture {
            name,
            width: 64,
            height: 64,
            mips,
        }
    }

    /// How faces with this texture are drawn: by name (`sky`, `*`, `{`, any case), and as a
    /// liquid when the texinfo is `special` (TEX_SPECIAL) but the name is not a sky.
    pub fn kind(&self, special: bool) -> TextureKind {
        let lower = self.name.to_ascii_lowercase();
        if lower.starts_with("sky") {
            TextureKind::Sky
        } else if lower.starts_with('*') || special {
            TextureKind::Liquid
        } else if lower.starts_with('{') {
            TextureKind::Fence
        } else {
            TextureKind::Lit
        }
    }

    /// Width and height of mip level `level` in texels, at least 1.
    pub fn mip_size(&self, level: usize) -> (usize, usize) {
        (
            ((self.width >> level) as usize).max(1),
            ((self.height >> level) as usize).max(1),
        )
    }

    /// Palette index at integer texel (s, t) of `level`, wrapping.
    pub fn index_at(&self, level: usize, s: i32, t: i32) -> u8 {
        let (w, h) = self.mip_size(level);
        let x = s.rem_euclid(w as i32) as usize;
        let y = t.rem_euclid(h as i32) as usize;
        self.mips[level].get(y * w + x).copied().unwrap_or(0)
    }
}

/// Palette colours packed as 0x00RRGGBB, and whether each index is fullbright.
#[derive(Debug, Clone)]
pub struct PackedPalette {
    /// Each index's colour as 0x00RRGGBB.
    pub rgb: [u32; 256],
    /// Each index's colour as RGB bytes.
    pub colors: [[u8; 3]; 256],
}

impl PackedPalette {
    /// Pack `p`'s colours.
    pub fn new(p: &Palette) -> PackedPalette {
        PackedPalette {
            rgb: std::array::from_fn(|i| pack(p.colors[i])),
            colors: p.colors,
        }
    }

    /// Colour of palette index `idx` under light `light` (per channel, 128 = the texture's own
    /// colour, 255 = about twice as bright), clamped. Fullbright indices ignore light.
    #[inline]
    pub fn shade(&self, idx: u8, light: [u32; 3]) -> u32 {
        if idx >= FIRST_FULLBRIGHT {
            return self.rgb[idx as usize];
        }
        let c = self.colors[idx as usize];
        let ch = |k: usize| ((c[k] as u32 * light[k]) >> 7).min(255);
        (ch(0) << 16) | (ch(1) << 8) | ch(2)
    }
}

/// RGB bytes as 0x00RRGGBB, the form of frame pixels.
pub fn pack(c: [u8; 3]) -> u32 {
    ((c[0] as u32) << 16) | ((c[1] as u32) << 8) | c[2] as u32
}

/// A 0x00RRGGBB pixel as RGB bytes.
pub fn unpack(c: u32) -> [u8; 3] {
    [(c >> 16) as u8, (c >> 8) as u8, c as u8]
}

/// Amplitude (texels) and period (texels) of the liquid warp.
const WARP_AMPLITUDE: f64 = 8.0;
const WARP_PERIOD: usize = 128;

/// A sine table for the liquid warp: each coordinate is displaced by a sine of the other one.
#[derive(Debug, Clone)]
pub(crate) struct WarpTable {
    offsets: [i32; WARP_PERIOD],
}

impl WarpTable {
    /// `time` in seconds shifts the phase; 0 gives the still picture tests compare.
    pub fn new(time: f64) -> WarpTable {
        let phase = time * WARP_PERIOD as f64 / (2.0 * std::f64::consts::PI);
        WarpTable {
            offsets: std::array::from_fn(|i| {
                let a = (i as f64 + phase) * 2.0 * std::f64::consts::PI / WARP_PERIOD as f64;
                (a.sin() * WARP_AMPLITUDE).round() as i32
            }),
        }
    }

    /// Mip-0 texel (s, t) of a liquid after warping.
    #[inline]
    pub fn warp(&self, s: i32, t: i32) -> (i32, i32) {
        let mask = WARP_PERIOD as i32 - 1;
        (
            s + self.offsets[(t & mask) as usize],
            t + self.offsets[(s & mask) as usize],
        )
    }
}

/// Colour of a liquid at mip-0 texel (s, t) before warping; liquids are drawn unlit.
#[inline]
pub(crate) fn liquid_color(
    tex: &Texture,
    palette: &PackedPalette,
    warp: &WarpTable,
    s: i32,
    t: i32,
) -> u32 {
    let (ws, wt) = warp.warp(s, t);
    palette.rgb[tex.index_at(0, ws, wt) as usize]
}

/// The sky's colour along view direction `dir`: the front layer (left half of the texture,
/// index 0 transparent) over the back layer (right half), both projected onto a flattened dome.
pub(crate) fn sky_color(tex: &Texture, palette: &PackedPalette, dir: DVec3) -> u32 {
    let flat = DVec3::new(dir.x, dir.y, dir.z * 3.0);
    let len = flat.length().max(1e-9);
    let scale = 6.0 * 63.0 / len;
    let half = (tex.width / 2).max(1) as i32;
    let s = (flat.x * scale).floor() as i32;
    let t = (flat.y * scale).floor() as i32;
    let front = tex.index_at(0, s.rem_euclid(half), t);
    let idx = if front != 0 {
        front
    } else {
        tex.index_at(0, half + s.rem_euclid(half), t)
    };
    palette.rgb[idx as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_128_keeps_the_colour_and_fullbrights_ignore_light() {
        let p = PackedPalette::new(&Palette::slipgate());
        let idx = 20u8;
        assert_eq!(p.shade(idx, [128; 3]), p.rgb[idx as usize]);
        assert_eq!(p.shade(idx, [0; 3]), 0);
        assert_eq!(
            p.shade(FIRST_FULLBRIGHT, [0; 3]),
            p.rgb[FIRST_FULLBRIGHT as usize]
        );
        assert_eq!(unpack(pack([1, 2, 3])), [1, 2, 3]);
    }

    #[test]
    fn kinds_follow_the_name() {
        let kind = |name: &str, special| Texture::checker(name.into()).kind(special);
        assert_eq!(kind("SKY4", false), TextureKind::Sky);
        assert_eq!(kind("*water1", true), TextureKind::Liquid);
        assert_eq!(kind("{grate", false), TextureKind::Fence);
        assert_eq!(kind("brick", true), TextureKind::Liquid);
        assert_eq!(kind("brick", false), TextureKind::Lit);
    }

    #[test]
    fn textures_wrap_in_both_directions() {
        let t = Texture::checker("x".into());
        assert_eq!(t.index_at(0, -1, 0), t.index_at(0, 63, 0));
        assert_eq!(t.index_at(1, 32, 33), t.index_at(1, 0, 1));
    }

    #[test]
    fn missing_palette_falls_back_to_slipgate() {
        let (p, src) = find_palette(Path::new("/nonexistent/maps/x.bsp"), None).expect("fallback");
        assert_eq!(src, PaletteSource::Builtin);
        assert_eq!(p, Palette::slipgate());
    }
}
