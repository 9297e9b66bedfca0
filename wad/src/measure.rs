//! How far a quantised mip level is from the true-colour picture it stands for.
//!
//! Two numbers, both the mean Euclidean distance in RGB (0..=255 per channel) over opaque pixels:
//! `pixel` compares each pixel's palette colour with its true colour, which nearest-colour
//! quantising minimises by construction; `block` compares the mean of each 2x2 block, the colour
//! the eye (or the next mip level, or a distant view) sees, which is what error diffusion keeps.

use crate::picture::Picture;
use crate::quantise::{Class, Quantiser, distance_squared};

/// The colour error of one quantised mip level (see the module comment for the two measures).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct LevelError {
    /// Opaque pixels measured.
    pub pixels: usize,
    /// Mean distance of a pixel's palette colour from its true colour.
    pub pixel: f64,
    /// Mean distance of a 2x2 block's mean palette colour from its mean true colour.
    pub block: f64,
}

impl LevelError {
    pub(crate) fn measure(quantiser: &Quantiser, picture: &Picture, indices: &[u8]) -> LevelError {
        let opaque = |at: usize| quantiser.class(&picture.texels[at]) != Class::Hole;
        let (mut pixel_sum, mut pixels) = (0.0, 0);
        for (at, &index) in indices.iter().enumerate() {
            if opaque(at) {
                let d = distance_squared(quantiser.colour(index), picture.texels[at].rgb);
                pixel_sum += d.sqrt();
                pixels += 1;
            }
        }
        let (mut block_sum, mut blocks) = (0.0, 0);
        for by in 0..picture.height.div_ceil(2) {
            for bx in 0..picture.width.div_ceil(2) {
                let (mut got, mut want, mut n) = ([0.0; 3], [0.0; 3], 0.0);
                for (x, y) in
                    [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| (2 * bx + dx, 2 * by + dy))
                {
                    let at = y * picture.width + x;
                    if x >= picture.width || y >= picture.height || !opaque(at) {
                        continue;
                    }
                    let colour = quantiser.colour(indices[at]);
                    for k in 0..3 {
                        got[k] += colour[k];
                        want[k] += picture.texels[at].rgb[k];
                    }
                    n += 1.0;
                }
                if n > 0.0 {
                    block_sum += distance_squared(got.map(|c| c / n), want.map(|c| c / n)).sqrt();
                    blocks += 1;
                }
            }
        }
        let mean = |sum: f64, count: usize| if count == 0 { 0.0 } else { sum / count as f64 };
        LevelError {
            pixels,
            pixel: mean(pixel_sum, pixels),
            block: mean(block_sum, blocks),
        }
    }

    /// The pixel-weighted mean of several textures' errors at one level.
    pub fn combined<'a>(errors: impl IntoIterator<Item = &'a LevelError>) -> LevelError {
        let mut total = LevelError::default();
        let (mut pixel, mut block) = (0.0, 0.0);
        for e in errors {
            total.pixels += e.pixels;
            pixel += e.pixel * e.pixels as f64;
            block += e.block * e.pixels as f64;
        }
        if total.pixels > 0 {
            total.pixel = pixel / total.pixels as f64;
            total.block = block / total.pixels as f64;
        }
        total
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::picture::Texel;
    use crate::source::Kind;
    use quake_formats::palette::Palette;

    #[test]
    fn dithering_lowers_the_block_error_of_every_mip_of_a_gradient() {
        let palette = Palette::slipgate();
        let q = Quantiser::new(&palette, Kind::Plain);
        // A warm gradient between palette ramps: no palette colour sits on it.
        let mut level = Picture::from_fn(64, 64, |x, y| Texel {
            rgb: [
                60.0 + 2.5 * x as f64,
                50.0 + 1.5 * y as f64,
                70.0 + x as f64,
            ],
            ..Texel::OPAQUE_BLACK
        });
        for mip in 0..4 {
            if mip > 0 {
                level = level.half();
            }
            let nearest = LevelError::measure(&q, &level, &q.quantise(&level, false));
            let dithered = LevelError::measure(&q, &level, &q.quantise(&level, true));
            assert!(
                dithered.block < nearest.block,
                "mip {mip}: {dithered:?} vs {nearest:?}"
            );
            // Nearest colour is the per-pixel optimum, so dithering cannot beat it there.
            assert!(nearest.pixel <= dithered.pixel, "mip {mip}");
        }
    }

    #[test]
    fn an_exact_palette_picture_has_no_error() {
        let palette = Palette::slipgate();
        let q = Quantiser::new(&palette, Kind::Plain);
        let picture = Picture::from_fn(16, 16, |x, y| Texel {
            rgb: palette.colors[(x + 16 * y) % 224].map(f64::from),
            ..Texel::OPAQUE_BLACK
        });
        let e = LevelError::measure(&q, &picture, &q.quantise(&picture, true));
        assert_eq!((e.pixels, e.pixel, e.block), (256, 0.0, 0.0));
    }
}
