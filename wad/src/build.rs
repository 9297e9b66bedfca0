//! Pictures to miptex: sizes rounded to 16, four mip levels box-filtered in true colour, each
//! quantised (dithered by default) and measured both ways.

use crate::measure::LevelError;
use crate::picture::rounded_side;
use crate::quantise::{Class, Quantiser};
use crate::source::{Kind, Source};
use quake_formats::miptex::MipTex;
use quake_formats::palette::Palette;
use quake_formats::wad::{Wad, WadLump};
use rayon::prelude::*;
use std::path::PathBuf;

/// How pictures become miptex.
#[derive(Debug, Clone)]
pub struct BuildOptions {
    /// The palette colours are quantised to: the game's, or Slipgate's own by default.
    pub palette: Palette,
    /// Floyd-Steinberg error diffusion (otherwise each pixel takes its nearest colour).
    pub dither: bool,
}

impl Default for BuildOptions {
    fn default() -> BuildOptions {
        BuildOptions {
            palette: Palette::slipgate(),
            dither: true,
        }
    }
}

/// One level's error both ways, whichever was written.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct LevelErrors {
    /// The error with Floyd-Steinberg error diffusion.
    pub dithered: LevelError,
    /// The error with each pixel's nearest colour.
    pub nearest: LevelError,
}

/// What became of one picture.
#[derive(Debug, Clone, serde::Serialize)]
pub struct TextureReport {
    /// The texture name, as stored in the WAD.
    pub name: String,
    /// The picture file it was made from.
    pub file: PathBuf,
    /// What its name makes of transparent pixels.
    pub kind: Kind,
    /// The picture's own size, and the size stored (rounded up to multiples of 16).
    pub source_size: [usize; 2],
    /// Width and height stored, multiples of 16.
    pub size: [usize; 2],
    /// Pixels of the full-size level given fullbright colours (where the glow mask is bright).
    pub fullbright_pixels: usize,
    /// Pixels of the full-size level given the transparent index (holes of `{` and sky
    /// textures).
    pub transparent_pixels: usize,
    /// Pixels with coverage under one half in a texture that cannot have holes (drawn opaque).
    pub ignored_holes: usize,
    /// Levels 0 (full size) to 3.
    pub levels: [LevelErrors; 4],
}

impl TextureReport {
    /// Whether the picture was stretched to reach multiples of 16.
    pub fn resized(&self) -> bool {
        self.source_size != self.size
    }
}

/// A built WAD and what became of each picture.
#[derive(Debug, Clone)]
pub struct Built {
    /// The WAD: one miptex lump per picture, in the sources' order.
    pub wad: Wad,
    /// One report per picture, in the same order.
    pub textures: Vec<TextureReport>,
}

impl Built {
    /// Every texture's error at each level, weighted by pixels.
    pub fn level_errors(&self) -> [LevelErrors; 4] {
        std::array::from_fn(|level| LevelErrors {
            dithered: LevelError::combined(self.textures.iter().map(|t| &t.levels[level].dithered)),
            nearest: LevelError::combined(self.textures.iter().map(|t| &t.levels[level].nearest)),
        })
    }
}

/// A WAD of `sources` in their order, textures made in parallel; `on_texture` is called as each
/// one is done.
pub fn build(
    sources: &[Source],
    options: &BuildOptions,
    on_texture: &(dyn Fn(&str) + Sync),
) -> Built {
    let made: Vec<(MipTex, TextureReport)> = sources
        .par_iter()
        .map(|source| {
            let made = miptex(source, options);
            on_texture(&source.name);
            made
        })
        .collect();
    let (lumps, textures) = made
        .into_iter()
        .map(|(tex, report)| (WadLump::miptex(tex), report))
        .unzip();
    Built {
        wad: Wad::new(lumps),
        textures,
    }
}

/// One picture as a miptex, with its report.
pub fn miptex(source: &Source, options: &BuildOptions) -> (MipTex, TextureReport) {
    let picture = &source.picture;
    let size = [rounded_side(picture.width), rounded_side(picture.height)];
    let mut level = if [picture.width, picture.height] == size {
        picture.clone()
    } else {
        picture.resampled(size[0], size[1])
    };
    let kind = Kind::of(&source.name);
    let quantiser = Quantiser::new(&options.palette, kind);
    let mut levels = [LevelErrors::default(); 4];
    let mut mips: [Vec<u8>; 4] = Default::default();
    let (mut fullbright_pixels, mut transparent_pixels) = (0, 0);
    for (i, (errors, mip)) in levels.iter_mut().zip(&mut mips).enumerate() {
        if i > 0 {
            level = level.half();
        }
        let nearest = quantiser.quantise(&level, false);
        let dithered = quantiser.quantise(&level, true);
        errors.nearest = LevelError::measure(&quantiser, &level, &nearest);
        errors.dithered = LevelError::measure(&quantiser, &level, &dithered);
        *mip = if options.dither { dithered } else { nearest };
        if i == 0 {
            for texel in &level.texels {
                match quantiser.class(texel) {
                    Class::Bright => fullbright_pixels += 1,
                    Class::Hole => transparent_pixels += 1,
                    Class::Plain => {}
                }
            }
        }
    }
    let tex = MipTex::new(&source.name, size[0] as u32, size[1] as u32, mips);
    let report = TextureReport {
        name: source.name.clone(),
        file: source.path.clone(),
        kind,
        source_size: [picture.width, picture.height],
        size,
        fullbright_pixels,
        transparent_pixels,
        ignored_holes: source.ignored_holes,
        levels,
    };
    (tex, report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::picture::{Picture, Texel};
    use quake_formats::palette::FIRST_FULLBRIGHT;

    fn source(
        name: &str,
        width: usize,
        height: usize,
        f: impl Fn(usize, usize) -> Texel,
    ) -> Source {
        Source {
            name: name.to_string(),
            path: PathBuf::from(format!("{name}.png")),
            picture: Picture::from_fn(width, height, f),
            ignored_holes: 0,
        }
    }

    fn grey(v: f64) -> Texel {
        Texel {
            rgb: [v; 3],
            ..Texel::OPAQUE_BLACK
        }
    }

    #[test]
    fn odd_sizes_are_resampled_up_to_multiples_of_16() {
        let (tex, report) = miptex(
            &source("odd", 20, 8, |_, _| grey(128.0)),
            &BuildOptions::default(),
        );
        assert_eq!((tex.width, tex.height), (32, 16));
        assert!(report.resized());
        let mips = tex.mips.expect("pixels");
        let lens: Vec<usize> = mips.iter().map(Vec::len).collect();
        assert_eq!(lens, [512, 128, 32, 8]);
    }

    #[test]
    fn no_fullbright_colour_unless_asked_for() {
        let palette = Palette::slipgate();
        let fire = palette.colors[FIRST_FULLBRIGHT as usize + 3].map(f64::from);
        let lamp = |glow: f64| {
            move |_, _| Texel {
                rgb: fire,
                alpha: 1.0,
                glow,
            }
        };
        for dither in [false, true] {
            let options = BuildOptions {
                dither,
                ..BuildOptions::default()
            };
            let (plain, report) = miptex(&source("lamp", 16, 16, lamp(0.0)), &options);
            assert!(
                plain
                    .mips
                    .expect("pixels")
                    .iter()
                    .flatten()
                    .all(|&i| i < FIRST_FULLBRIGHT)
            );
            assert_eq!(report.fullbright_pixels, 0);
            let (lit, report) = miptex(&source("lamp", 16, 16, lamp(1.0)), &options);
            assert!(
                lit.mips
                    .expect("pixels")
                    .iter()
                    .flatten()
                    .all(|&i| i >= FIRST_FULLBRIGHT)
            );
            assert_eq!(report.fullbright_pixels, 256);
        }
    }

    #[test]
    fn fence_holes_are_255_at_every_level() {
        // Left half clear, right half a red that the nearest search would put at index 255 if
        // it could (the last fullbright): glowing, so only fullbrights are allowed.
        let palette = Palette::slipgate();
        let red = palette.colors[255].map(f64::from);
        let fence = source("{grate", 32, 32, |x, _| Texel {
            rgb: red,
            alpha: if x < 16 { 0.0 } else { 1.0 },
            glow: 1.0,
        });
        let (tex, report) = miptex(&fence, &BuildOptions::default());
        assert_eq!(report.transparent_pixels, 512);
        for (level, mip) in tex.mips.expect("pixels").iter().enumerate() {
            let width = 32 >> level;
            for (at, &index) in mip.iter().enumerate() {
                assert_eq!(
                    index == 255,
                    at % width < width / 2,
                    "level {level} pixel {at}"
                );
            }
        }
    }

    #[test]
    fn measured_errors_cover_both_quantisings() {
        let gradient = source("ramp", 64, 64, |x, y| Texel {
            rgb: [40.0 + 3.0 * x as f64, 90.0, 30.0 + 2.0 * y as f64],
            ..Texel::OPAQUE_BLACK
        });
        let built = build(&[gradient], &BuildOptions::default(), &|_| {});
        for (level, e) in built.level_errors().iter().enumerate() {
            assert_eq!(e.dithered.pixels, 4096 >> (2 * level));
            assert!(e.dithered.block < e.nearest.block, "level {level}: {e:?}");
        }
    }
}
