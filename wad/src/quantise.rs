//! Choosing palette indices for a picture: nearest colour, or Floyd-Steinberg error diffusion.
//!
//! Every pixel falls in one of three classes, and each class has its own palette indices: holes
//! (coverage under one half, in textures that have a transparent index) all take that index;
//! pixels that glow take only fullbright colours; all others only the colours that are lit
//! normally. So a fullbright colour never appears where the picture did not ask for one, and the
//! transparent index never appears in an opaque pixel.

use crate::picture::{Picture, Texel};
use crate::source::Kind;
use quake_formats::palette::{FIRST_FULLBRIGHT, Palette};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    Hole,
    Bright,
    Plain,
}

/// A palette and the indices each class of pixel may take, for one kind of texture.
pub struct Quantiser<'a> {
    palette: &'a Palette,
    transparent: Option<u8>,
    /// The indices each class may take, with their colours.
    plain: Vec<(u8, [f64; 3])>,
    bright: Vec<(u8, [f64; 3])>,
}

impl<'a> Quantiser<'a> {
    pub fn new(palette: &'a Palette, kind: Kind) -> Quantiser<'a> {
        let transparent = kind.transparent_index();
        let allowed = |range: std::ops::RangeInclusive<u8>| -> Vec<(u8, [f64; 3])> {
            range
                .filter(|&i| Some(i) != transparent)
                .map(|i| (i, palette.colors[i as usize].map(f64::from)))
                .collect()
        };
        Quantiser {
            palette,
            transparent,
            plain: allowed(0..=FIRST_FULLBRIGHT - 1),
            bright: allowed(FIRST_FULLBRIGHT..=255),
        }
    }

    pub fn class(&self, texel: &Texel) -> Class {
        if self.transparent.is_some() && texel.alpha < 0.5 {
            Class::Hole
        } else if texel.glow >= 0.5 {
            Class::Bright
        } else {
            Class::Plain
        }
    }

    pub fn colour(&self, index: u8) -> [f64; 3] {
        self.palette.colors[index as usize].map(f64::from)
    }

    /// The allowed index of `class` whose colour is nearest `rgb` (squared RGB distance; the
    /// lowest index wins a tie).
    fn nearest(&self, rgb: [f64; 3], class: Class) -> u8 {
        let indices = match class {
            Class::Hole => return self.transparent.unwrap_or(0),
            Class::Bright => &self.bright,
            Class::Plain => &self.plain,
        };
        let mut best = (f64::INFINITY, 0);
        for &(i, colour) in indices {
            let d = distance_squared(colour, rgb);
            if d < best.0 {
                best = (d, i);
            }
        }
        best.1
    }

    /// Palette indices for every pixel of `picture`, rows top first. With `dither`, each pixel's
    /// error is spread to its unvisited neighbours of the same class (Floyd-Steinberg weights
    /// 7, 3, 5, 1 sixteenths), rows walked alternately left to right and right to left.
    pub fn quantise(&self, picture: &Picture, dither: bool) -> Vec<u8> {
        let (w, h) = (picture.width, picture.height);
        let classes: Vec<Class> = picture.texels.iter().map(|t| self.class(t)).collect();
        let mut carried = vec![[0.0; 3]; w * h];
        let mut out = vec![0u8; w * h];
        for y in 0..h {
            let rightward = y % 2 == 0;
            for step in 0..w {
                let x = if rightward { step } else { w - 1 - step };
                let at = y * w + x;
                let class = classes[at];
                let wanted: [f64; 3] = std::array::from_fn(|k| {
                    (picture.texels[at].rgb[k] + carried[at][k]).clamp(0.0, 255.0)
                });
                let index = self.nearest(wanted, class);
                out[at] = index;
                if !dither || class == Class::Hole {
                    continue;
                }
                let got = self.colour(index);
                let error: [f64; 3] = std::array::from_fn(|k| wanted[k] - got[k]);
                let ahead = if rightward { 1 } else { -1 };
                for (dx, dy, weight) in [
                    (ahead, 0, 7.0),
                    (-ahead, 1, 3.0),
                    (0, 1, 5.0),
                    (ahead, 1, 1.0),
                ] {
                    let (nx, ny) = (x as i64 + dx, y + dy);
                    if nx < 0 || nx >= w as i64 || ny >= h {
                        continue;
                    }
                    let next = ny * w + nx as usize;
                    if classes[next] == class {
                        for k in 0..3 {
                            carried[next][k] += error[k] * weight / 16.0;
                        }
                    }
                }
            }
        }
        out
    }
}

pub fn distance_squared(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texel(rgb: [f64; 3], alpha: f64, glow: f64) -> Texel {
        Texel { rgb, alpha, glow }
    }

    #[test]
    fn fullbright_colours_only_where_the_picture_glows() {
        let palette = Palette::slipgate();
        // The brightest fire colour: nearest is a fullbright unless the pixel may not glow.
        let fire = palette.colors[FIRST_FULLBRIGHT as usize + 7].map(f64::from);
        let picture = Picture::from_fn(2, 1, |x, _| texel(fire, 1.0, x as f64));
        let q = Quantiser::new(&palette, Kind::Plain);
        for dither in [false, true] {
            let indices = q.quantise(&picture, dither);
            assert!(indices[0] < FIRST_FULLBRIGHT, "{indices:?}");
            assert_eq!(indices[1], FIRST_FULLBRIGHT + 7);
        }
    }

    #[test]
    fn fence_holes_take_255_and_nothing_else_does() {
        let palette = Palette::slipgate();
        let q = Quantiser::new(&palette, Kind::Fence);
        let picture = Picture::from_fn(16, 16, |x, y| {
            let colour = palette.colors[255].map(f64::from);
            texel(colour, if (x + y) % 3 == 0 { 0.2 } else { 1.0 }, 1.0)
        });
        for dither in [false, true] {
            let indices = q.quantise(&picture, dither);
            for (i, t) in indices.iter().zip(&picture.texels) {
                assert_eq!(*i == 255, t.alpha < 0.5);
            }
        }
    }

    #[test]
    fn sky_holes_take_index_0_and_nothing_else_does() {
        let palette = Palette::slipgate();
        let q = Quantiser::new(&palette, Kind::Sky);
        let black = Picture::from_fn(4, 1, |x, _| texel([0.0; 3], (x % 2) as f64, 0.0));
        // Index 0 is Slipgate's darkest grey; 208 (the darkest brown) is the next nearest black.
        assert_eq!(q.quantise(&black, false), [0, 208, 0, 208]);
    }

    #[test]
    fn dithering_keeps_the_mean_colour_of_a_flat_area() {
        let palette = Palette::slipgate();
        let q = Quantiser::new(&palette, Kind::Plain);
        let colour = [100.0, 77.0, 140.0];
        let picture = Picture::from_fn(32, 32, |_, _| texel(colour, 1.0, 0.0));
        let mean = |indices: &[u8]| -> [f64; 3] {
            let mut sum = [0.0; 3];
            for &i in indices {
                for (s, c) in sum.iter_mut().zip(q.colour(i)) {
                    *s += c / indices.len() as f64;
                }
            }
            sum
        };
        let nearest = distance_squared(mean(&q.quantise(&picture, false)), colour).sqrt();
        let dithered = distance_squared(mean(&q.quantise(&picture, true)), colour).sqrt();
        // Error diffused past the right and bottom edges is lost, so not exactly 0.
        assert!(
            dithered < 2.0 && dithered < nearest / 10.0,
            "{dithered} vs {nearest}"
        );
    }
}
