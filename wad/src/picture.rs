//! True-colour pictures in floating point: a texture before it is quantised to a palette.

/// One pixel. Colour is 0..=255 per channel, in the file's own (sRGB) values rather than linear
/// light, as Quake's tools averaged; `alpha` is coverage and `glow` how strongly the pixel asks
/// for a fullbright colour, both 0..=1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Texel {
    /// Red, green and blue, 0..=255.
    pub rgb: [f64; 3],
    /// Coverage: 0 for a hole, 1 for an opaque pixel.
    pub alpha: f64,
    /// How strongly the pixel asks for a fullbright colour: 0 not at all, 1 fully.
    pub glow: f64,
}

#[cfg(test)]
impl Texel {
    /// A fully covered black pixel that does not glow, to build test pictures from.
    pub(crate) const OPAQUE_BLACK: Texel = Texel {
        rgb: [0.0; 3],
        alpha: 1.0,
        glow: 0.0,
    };
}

impl Texel {
    /// Colour weighted by coverage, so that a hole's colour does not bleed into its neighbours
    /// when pixels are mixed.
    fn premultiplied(self) -> [f64; 5] {
        let [r, g, b] = self.rgb.map(|c| c * self.alpha);
        [r, g, b, self.alpha, self.glow]
    }

    fn from_premultiplied([r, g, b, alpha, glow]: [f64; 5]) -> Texel {
        let rgb = if alpha > 0.0 {
            [r, g, b].map(|c| c / alpha)
        } else {
            [0.0; 3]
        };
        Texel { rgb, alpha, glow }
    }
}

/// A true-colour picture: a texture, or one of its mip levels, before quantising.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Rows top first.
    pub texels: Vec<Texel>,
}

impl Picture {
    /// A `width` x `height` picture whose pixel (x, y) is `f(x, y)`.
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize, usize) -> Texel) -> Picture {
        let texels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Picture {
            width,
            height,
            texels,
        }
    }

    /// Pixel (x, y); panics outside the picture.
    pub fn at(&self, x: usize, y: usize) -> Texel {
        self.texels[y * self.width + x]
    }

    /// Half the size (rounded down), each pixel the mean of a 2x2 block: the box filter that
    /// makes each mip level from the one above.
    pub fn half(&self) -> Picture {
        Picture::from_fn(self.width / 2, self.height / 2, |x, y| {
            let mut sum = [0.0; 5];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let p = self.at(2 * x + dx, 2 * y + dy).premultiplied();
                for (s, v) in sum.iter_mut().zip(p) {
                    *s += v;
                }
            }
            Texel::from_premultiplied(sum.map(|s| s / 4.0))
        })
    }

    /// Stretched to `width` x `height` by bilinear interpolation between pixel centres, wrapping
    /// around the edges because textures tile.
    pub fn resampled(&self, width: usize, height: usize) -> Picture {
        let source = |x: i64, y: i64| {
            let x = x.rem_euclid(self.width as i64) as usize;
            let y = y.rem_euclid(self.height as i64) as usize;
            self.at(x, y).premultiplied()
        };
        let place = |i: usize, from: usize, to: usize| {
            let s = (i as f64 + 0.5) * from as f64 / to as f64 - 0.5;
            let floor = s.floor();
            (floor as i64, s - floor)
        };
        Picture::from_fn(width, height, |x, y| {
            let (x0, fx) = place(x, self.width, width);
            let (y0, fy) = place(y, self.height, height);
            let mut mixed = [0.0; 5];
            for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
                for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
                    for (m, v) in mixed.iter_mut().zip(source(x0 + dx, y0 + dy)) {
                        *m += v * wx * wy;
                    }
                }
            }
            Texel::from_premultiplied(mixed)
        })
    }
}

/// The size a texture side is stored at: the next multiple of 16 (Quake's surfaces need it).
pub fn rounded_side(side: usize) -> usize {
    side.next_multiple_of(16).max(16)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: f64) -> Texel {
        Texel {
            rgb: [v; 3],
            ..Texel::OPAQUE_BLACK
        }
    }

    #[test]
    fn sides_round_up_to_sixteen() {
        assert_eq!(
            [1, 15, 16, 17, 32, 100].map(rounded_side),
            [16, 16, 16, 32, 32, 112]
        );
    }

    #[test]
    fn the_box_filter_is_the_exact_mean_of_four() {
        // Values chosen so every mean is exact in binary floating point.
        let picture = Picture::from_fn(4, 2, |x, y| grey((x * 10 + y * 100) as f64));
        let half = picture.half();
        assert_eq!((half.width, half.height), (2, 1));
        assert_eq!(half.at(0, 0).rgb, [55.0; 3]);
        assert_eq!(half.at(1, 0).rgb, [75.0; 3]);
        let quarter = Picture::from_fn(4, 4, |x, y| grey((x + 4 * y) as f64))
            .half()
            .half();
        assert_eq!(quarter.at(0, 0).rgb, [7.5; 3]);
    }

    #[test]
    fn a_hole_lends_no_colour_to_the_mean() {
        let hole = Texel {
            rgb: [0.0, 0.0, 255.0],
            alpha: 0.0,
            glow: 0.0,
        };
        let picture = Picture::from_fn(2, 2, |x, _| if x == 0 { hole } else { grey(200.0) });
        let mean = picture.half().at(0, 0);
        assert_eq!((mean.rgb, mean.alpha), ([200.0; 3], 0.5));
    }

    #[test]
    fn resampling_keeps_flat_colour_and_size_and_wraps() {
        let flat = Picture::from_fn(10, 6, |_, _| grey(90.0)).resampled(16, 16);
        assert_eq!((flat.width, flat.height), (16, 16));
        assert!(flat.texels.iter().all(|t| (t.rgb[0] - 90.0).abs() < 1e-9));
        // Doubling a two-pixel stripe: the outer new pixels mix with the far edge (tiling).
        let stripe = Picture::from_fn(2, 1, |x, _| grey(if x == 0 { 0.0 } else { 100.0 }));
        let wide = stripe.resampled(4, 1);
        let values: Vec<f64> = (0..4).map(|x| wide.at(x, 0).rgb[0]).collect();
        assert_eq!(values, [25.0, 25.0, 75.0, 75.0]);
    }
}
