//! Procedural textures as PNG pictures (`maps/textures/`), and the WAD2 the `slipgate-wad` crate
//! builds from them.
//!
//! Everything is deterministic: a seeded SplitMix64 drives tileable value noise, and only
//! arithmetic whose IEEE results are exact everywhere is used (no `sin`/`exp`), here and in the
//! WAD builder, so the pictures' and the WAD's bytes are the same on every machine.

use image::DynamicImage;
use quake_formats::rng::SplitMix64;
use quake_formats::wad::Wad;
use std::path::Path;
use wad::WadError;
use wad::build::BuildOptions;
use wad::extract::encode_png;

/// Value noise on a grid of `cells` x `cells` that wraps around, so textures tile.
struct Noise {
    cells: usize,
    values: Vec<f64>,
}

impl Noise {
    fn new(rng: &mut SplitMix64, cells: usize) -> Noise {
        Noise {
            cells,
            values: (0..cells * cells).map(|_| rng.unit()).collect(),
        }
    }

    /// Smoothly interpolated value at (u, v) in texture-fraction units [0, 1).
    fn at(&self, u: f64, v: f64) -> f64 {
        let (x, y) = (u * self.cells as f64, v * self.cells as f64);
        let (fx, fy) = (x - x.floor(), y - y.floor());
        let (sx, sy) = (fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy));
        let n = self.cells as i64;
        let cell = |i: f64, j: f64| {
            let (i, j) = ((i as i64).rem_euclid(n), (j as i64).rem_euclid(n));
            self.values[(j * n + i) as usize]
        };
        let (x0, y0) = (x.floor(), y.floor());
        let top = cell(x0, y0) + (cell(x0 + 1.0, y0) - cell(x0, y0)) * sx;
        let bottom = cell(x0, y0 + 1.0) + (cell(x0 + 1.0, y0 + 1.0) - cell(x0, y0 + 1.0)) * sx;
        top + (bottom - top) * sy
    }
}

/// Fractal noise: octaves of 4, 8, 16 and 32 cells, in [0, 1).
struct Fractal(Vec<Noise>);

impl Fractal {
    fn new(seed: u64) -> Fractal {
        let mut rng = SplitMix64::new(seed);
        Fractal([4, 8, 16, 32].map(|c| Noise::new(&mut rng, c)).into())
    }

    fn at(&self, u: f64, v: f64) -> f64 {
        let (mut sum, mut total, mut weight) = (0.0, 0.0, 0.5);
        for octave in &self.0 {
            sum += octave.at(u, v) * weight;
            total += weight;
            weight *= 0.5;
        }
        sum / total
    }
}

/// What a pixel asks of the WAD builder besides its colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Look {
    Plain,
    /// Drawn with a fullbright colour: white in the texture's `_glow` mask.
    Glow,
    /// Transparent (alpha 0): the holes of a sky's front layer.
    Hole,
}

/// An RGB picture (0..255 per channel) with a [`Look`] per pixel.
#[derive(Debug, Clone)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pixels: Vec<([f64; 3], Look)>,
}

impl Image {
    fn from_fn(width: usize, height: usize, f: impl Fn(usize, usize) -> ([f64; 3], Look)) -> Image {
        let pixels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Image {
            width,
            height,
            pixels,
        }
    }

    fn map<P: image::Pixel>(
        &self,
        f: impl Fn([f64; 3], Look) -> P,
    ) -> image::ImageBuffer<P, Vec<P::Subpixel>> {
        image::ImageBuffer::from_fn(self.width as u32, self.height as u32, |x, y| {
            let (rgb, look) = self.pixels[y as usize * self.width + x as usize];
            f(rgb, look)
        })
    }

    /// The picture as the WAD builder reads it: RGBA when it has holes, RGB otherwise.
    pub fn picture(&self) -> DynamicImage {
        let rgb = |c: [f64; 3]| c.map(|v| v.round().clamp(0.0, 255.0) as u8);
        if self.pixels.iter().any(|&(_, look)| look == Look::Hole) {
            DynamicImage::ImageRgba8(self.map(|c, look| {
                let [r, g, b] = rgb(c);
                image::Rgba([r, g, b, if look == Look::Hole { 0 } else { 255 }])
            }))
        } else {
            DynamicImage::ImageRgb8(self.map(|c, _| image::Rgb(rgb(c))))
        }
    }

    /// The `_glow` mask: white where the pixel glows. `None` when none does.
    pub fn glow_mask(&self) -> Option<DynamicImage> {
        let glows = |look: Look| look == Look::Glow;
        self.pixels.iter().any(|&(_, look)| glows(look)).then(|| {
            DynamicImage::ImageLuma8(
                self.map(|_, look| image::Luma([if glows(look) { 255 } else { 0 }])),
            )
        })
    }
}

fn shade(rgb: [f64; 3], factor: f64) -> [f64; 3] {
    rgb.map(|c| c * factor)
}

fn mix(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    std::array::from_fn(|k| a[k] + (b[k] - a[k]) * t)
}

/// Distance from `v` to the nearest multiple of `period` (a triangle wave, 0 on the lines).
fn to_line(v: f64, period: f64) -> f64 {
    let m = v.rem_euclid(period);
    m.min(period - m)
}

/// Raised bevel at the border of a `w` x `h` panel: lighter near the top-left edges, darker near
/// the bottom-right, 1.0 inside.
fn bevel(x: usize, y: usize, w: usize, h: usize, width: usize) -> f64 {
    if x < width || y < width {
        1.25
    } else if x >= w - width || y >= h - width {
        0.7
    } else {
        1.0
    }
}

fn brick(n: &Fractal, rng: &mut SplitMix64) -> Image {
    let tones: Vec<f64> = (0..16).map(|_| 0.8 + 0.35 * rng.unit()).collect();
    Image::from_fn(64, 64, |x, y| {
        let row = y / 16;
        let shifted = x + 16 * (row % 2);
        let grain = n.at(x as f64 / 64.0, y as f64 / 64.0);
        if y % 16 < 2 || shifted % 32 < 2 {
            return (shade([112.0, 106.0, 98.0], 0.7 + 0.5 * grain), Look::Plain);
        }
        let tone = tones[row * 4 + (shifted / 32) % 4];
        (
            shade([150.0, 72.0, 52.0], tone * (0.75 + 0.5 * grain)),
            Look::Plain,
        )
    })
}

fn stone_floor(n: &Fractal, rng: &mut SplitMix64) -> Image {
    let tones: Vec<f64> = (0..4).map(|_| 0.85 + 0.3 * rng.unit()).collect();
    Image::from_fn(64, 64, |x, y| {
        let grain = n.at(x as f64 / 64.0, y as f64 / 64.0);
        let tile = tones[(y / 32) * 2 + x / 32];
        let edge = bevel(x % 32, y % 32, 32, 32, 2);
        let rgb = shade([120.0, 114.0, 102.0], tile * edge * (0.65 + 0.7 * grain));
        (rgb, Look::Plain)
    })
}

fn wood(n: &Fractal, rng: &mut SplitMix64) -> Image {
    let planks: Vec<(f64, usize)> = (0..4)
        .map(|_| (0.8 + 0.35 * rng.unit(), (rng.unit() * 64.0) as usize))
        .collect();
    Image::from_fn(64, 64, |x, y| {
        let (tone, joint) = planks[y / 16];
        if y % 16 == 0 || x == joint {
            return ([58.0, 38.0, 22.0], Look::Plain);
        }
        let warp = n.at(x as f64 / 64.0, y as f64 / 64.0);
        let grain = to_line(y as f64 + 6.0 * warp, 4.0) / 2.0;
        (
            shade([138.0, 94.0, 54.0], tone * (0.75 + 0.3 * grain)),
            Look::Plain,
        )
    })
}

fn metal_panel(n: &Fractal) -> Image {
    Image::from_fn(64, 64, |x, y| {
        let grain = n.at(x as f64 / 64.0, y as f64 / 64.0);
        let rivet = [8, 56].iter().any(|&cx| {
            [8, 56].iter().any(|&cy| {
                let (dx, dy) = (x as i64 - cx, y as i64 - cy);
                dx * dx + dy * dy <= 4
            })
        });
        let light = if rivet { 1.4 } else { bevel(x, y, 64, 64, 3) };
        (
            shade([96.0, 100.0, 118.0], light * (0.85 + 0.3 * grain)),
            Look::Plain,
        )
    })
}

fn door(n: &Fractal) -> Image {
    Image::from_fn(64, 128, |x, y| {
        let grain = n.at(x as f64 / 64.0, y as f64 / 128.0);
        let frame = !(4..60).contains(&x) || !(4..124).contains(&y);
        let band = (20..28).contains(&y) || (100..108).contains(&y);
        if frame || band {
            let light = bevel(x, y % 124, 64, 124, 1);
            return (
                shade([92.0, 96.0, 108.0], light * (0.85 + 0.3 * grain)),
                Look::Plain,
            );
        }
        let seam = (x - 4) % 14 == 0;
        let tone = if seam { 0.45 } else { 0.8 + 0.3 * grain };
        (shade([128.0, 86.0, 48.0], tone), Look::Plain)
    })
}

fn trim(n: &Fractal) -> Image {
    Image::from_fn(64, 16, |x, y| {
        let grain = n.at(x as f64 / 64.0, y as f64 / 16.0);
        let notch = x % 16 == 0 && (4..12).contains(&y);
        let light = if notch { 0.55 } else { bevel(x, y, 64, 16, 2) };
        (
            shade([150.0, 128.0, 84.0], light * (0.85 + 0.3 * grain)),
            Look::Plain,
        )
    })
}

fn light_fixture() -> Image {
    Image::from_fn(32, 32, |x, y| {
        let inner = (6..26).contains(&x) && (6..26).contains(&y);
        if !inner {
            return (
                shade([90.0, 90.0, 96.0], bevel(x, y, 32, 32, 2)),
                Look::Plain,
            );
        }
        // Brightest in the middle of the lamp.
        let d = to_line(x as f64 - 16.0, 64.0).max(to_line(y as f64 - 16.0, 64.0)) / 10.0;
        (
            mix([255.0, 250.0, 215.0], [240.0, 200.0, 140.0], d),
            Look::Glow,
        )
    })
}

/// 256x128: the left half is the front cloud layer (index 0 is transparent), the right half the
/// sky behind it.
fn sky(n: &Fractal, clouds: &Fractal) -> Image {
    Image::from_fn(256, 128, |x, y| {
        let (u, v) = ((x % 128) as f64 / 128.0, y as f64 / 128.0);
        if x >= 128 {
            return (
                mix([28.0, 22.0, 70.0], [90.0, 60.0, 130.0], n.at(u, v)),
                Look::Plain,
            );
        }
        let density = clouds.at(u, v);
        if density < 0.55 {
            return ([0.0; 3], Look::Hole);
        }
        (
            mix([120.0, 120.0, 160.0], [220.0, 215.0, 235.0], density),
            Look::Plain,
        )
    })
}

fn liquid(n: &Fractal, dark: [f64; 3], bright: [f64; 3]) -> Image {
    Image::from_fn(64, 64, |x, y| {
        let t = n.at(x as f64 / 64.0, y as f64 / 64.0);
        let ripple = to_line(8.0 * t, 1.0) * 2.0;
        (mix(dark, bright, 0.6 * t + 0.4 * ripple), Look::Plain)
    })
}

/// Tool textures: a flat colour with a simple line pattern, never seen in game.
fn tool(base: [f64; 3], pattern: fn(usize, usize) -> bool) -> Image {
    Image::from_fn(64, 64, |x, y| {
        let rgb = if pattern(x, y) {
            shade(base, 0.5)
        } else {
            base
        };
        (rgb, Look::Plain)
    })
}

/// Every texture of `slipgate.wad`, in the WAD's order.
pub fn images() -> Vec<(&'static str, Image)> {
    let mut rng = SplitMix64::new(0x5119_6A7E);
    let mut noise = || Fractal::new(rng.next_u64());
    let mut tones = SplitMix64::new(0x7E27_u64);
    vec![
        ("brick1", brick(&noise(), &mut tones)),
        ("floor1", stone_floor(&noise(), &mut tones)),
        ("wood1", wood(&noise(), &mut tones)),
        ("metal1", metal_panel(&noise())),
        ("door1", door(&noise())),
        ("trim1", trim(&noise())),
        ("light1", light_fixture()),
        ("sky1", sky(&noise(), &noise())),
        (
            "*water1",
            liquid(&noise(), [22.0, 40.0, 96.0], [70.0, 110.0, 170.0]),
        ),
        (
            "*lava1",
            liquid(&noise(), [120.0, 24.0, 8.0], [240.0, 140.0, 30.0]),
        ),
        (
            "*slime1",
            liquid(&noise(), [30.0, 70.0, 20.0], [110.0, 170.0, 50.0]),
        ),
        ("clip", tool([150.0, 70.0, 140.0], |x, y| (x + y) % 16 < 2)),
        (
            "trigger",
            tool([220.0, 140.0, 40.0], |x, y| (x + 64 - y) % 16 < 4),
        ),
        (
            "skip",
            tool([150.0, 150.0, 150.0], |x, y| (x / 8 + y / 8) % 2 == 0),
        ),
        (
            "hint",
            tool([70.0, 110.0, 200.0], |x, y| x % 16 == 0 || y % 16 == 0),
        ),
    ]
}

/// Where the pictures go, relative to the maps directory.
pub const PICTURE_DIR: &str = "textures";

/// Every picture file of `textures/`: `(file name, PNG bytes)`, each texture's picture and, for
/// the glowing ones, its `_glow` mask.
pub fn picture_files() -> Result<Vec<(String, Vec<u8>)>, image::ImageError> {
    let mut files = Vec::new();
    for (name, image) in images() {
        let stem = wad::source::file_stem(name);
        files.push((format!("{stem}.png"), encode_png(&image.picture())?));
        if let Some(mask) = image.glow_mask() {
            files.push((format!("{stem}_glow.png"), encode_png(&mask)?));
        }
    }
    Ok(files)
}

/// The texture WAD, built from [`picture_files`] exactly as `slipgate wad build maps/textures
/// maps/slipgate.wad` builds it (Slipgate's palette, dithered).
pub fn wad(pictures: &[(String, Vec<u8>)]) -> Result<Wad, WadError> {
    let files = pictures
        .iter()
        .map(|(name, bytes)| (Path::new(PICTURE_DIR).join(name), bytes.clone()))
        .collect();
    let sources = wad::source::from_files(files)?;
    Ok(wad::build(&sources, &BuildOptions::default(), &|_| {}).wad)
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::palette::FIRST_FULLBRIGHT;

    #[test]
    fn noise_tiles_and_stays_in_range() {
        let n = Fractal::new(3);
        for i in 0..50 {
            let v = i as f64 / 50.0;
            assert!((n.at(0.0, v) - n.at(1.0, v)).abs() < 1e-12);
            assert!((0.0..1.0).contains(&n.at(v, 0.3)));
        }
    }

    fn built_wad() -> Wad {
        wad(&picture_files().expect("PNGs encode")).expect("the WAD builds")
    }

    #[test]
    fn only_the_light_fixture_uses_fullbright_colours() {
        let wad = built_wad();
        for (name, image) in images() {
            let tex = wad.find_miptex(name).expect("every picture is in the WAD");
            assert_eq!(
                (tex.width, tex.height),
                (image.width as u32, image.height as u32)
            );
            let mips = tex.mips.expect("pixels");
            let bright = mips[0].iter().any(|&i| i >= FIRST_FULLBRIGHT);
            assert_eq!(bright, name == "light1", "{name}");
        }
    }

    #[test]
    fn sky_front_layer_has_transparent_holes_and_the_back_has_none() {
        let tex = built_wad().find_miptex("sky1").expect("sky");
        let pixels = &tex.mips.expect("pixels")[0];
        let (front, back): (Vec<_>, Vec<_>) = pixels
            .chunks(256)
            .map(|row| (row[..128].to_vec(), row[128..].to_vec()))
            .unzip();
        let holes = front.concat().iter().filter(|&&i| i == 0).count();
        assert!(holes > 1000 && holes < 128 * 128 - 1000, "{holes} holes");
        assert!(!back.concat().contains(&0));
    }

    #[test]
    fn liquids_are_written_with_a_hash_and_read_back_with_a_star() {
        let files = picture_files().expect("PNGs encode");
        let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        assert!(names.contains(&"#water1.png") && names.contains(&"light1_glow.png"));
        assert!(built_wad().find_miptex("*water1").is_some());
    }
}
