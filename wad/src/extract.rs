//! A WAD's textures as pictures, and the listing of a WAD.
//!
//! Each miptex becomes `NAME.png` of its full-size level (`*` written as `#`). Holes (index 255
//! of a `{` texture, index 0 in the front layer of a sky: its left half) get alpha 0, and a
//! texture with fullbright pixels also gets `NAME_glow.png`, white where they are: building the
//! folder again keeps both.

use crate::WadError;
use crate::source::{Kind, file_stem};
use image::{GrayImage, Luma, Rgba, RgbaImage};
use quake_formats::miptex::MipTex;
use quake_formats::palette::{FIRST_FULLBRIGHT, Palette};
use quake_formats::wad::{Wad, WadData, lump_type};
use std::path::{Path, PathBuf};

/// A BSP's textures as a WAD: every texture of its texture lump that holds pixels, once per name
/// (the first, as engines take it), in lump order.
pub fn textures_of(bsp: &quake_formats::Bsp) -> Wad {
    let mut seen = std::collections::HashSet::new();
    let lumps = bsp
        .textures
        .textures
        .iter()
        .flatten()
        .filter(|t| t.mips.is_some() && seen.insert(t.name().to_ascii_lowercase()))
        .map(|t| quake_formats::wad::WadLump::miptex(t.clone()))
        .collect();
    Wad::new(lumps)
}

/// One line of `slipgate wad list`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Entry {
    /// The lump's name as the directory gives it.
    pub name: String,
    /// `miptex`, `palette`, `qpic`, `sound` or the type byte.
    pub kind: String,
    /// Size of the lump's data in bytes.
    pub bytes: usize,
    /// Miptex only: size, and pixels of the full-size level that are fullbright or holes.
    pub size: Option<[u32; 2]>,
    /// Pixels of the full-size level with fullbright colours (0 for other lumps).
    pub fullbright_pixels: usize,
    /// Pixels of the full-size level that engines draw as holes (0 for other lumps).
    pub transparent_pixels: usize,
}

/// One entry per lump, in directory order.
pub fn list(wad: &Wad) -> Vec<Entry> {
    wad.lumps
        .iter()
        .map(|lump| {
            let name = lump.name();
            let tex = miptex_of(wad, lump);
            let (fullbright_pixels, transparent_pixels) = tex
                .as_ref()
                .and_then(|t| Some(counts(&name, t.width, t.mips.as_ref()?[0].as_slice())))
                .unwrap_or((0, 0));
            Entry {
                kind: lump_kind(lump.kind),
                bytes: match &lump.data {
                    WadData::MipTex(t) => t.encoded_len(),
                    WadData::Raw(b) => b.len(),
                },
                size: tex.map(|t| [t.width, t.height]),
                fullbright_pixels,
                transparent_pixels,
                name,
            }
        })
        .collect()
}

fn lump_kind(kind: u8) -> String {
    match kind {
        lump_type::MIPTEX => "miptex".to_string(),
        lump_type::PALETTE => "palette".to_string(),
        lump_type::QPIC => "qpic".to_string(),
        lump_type::SOUND => "sound".to_string(),
        other => format!("type {other:#04x}"),
    }
}

fn miptex_of(wad: &Wad, lump: &quake_formats::wad::WadLump) -> Option<MipTex> {
    match &lump.data {
        WadData::MipTex(t) => Some(t.clone()),
        WadData::Raw(_) if lump.kind == lump_type::MIPTEX => wad.find_miptex(&lump.name()),
        WadData::Raw(_) => None,
    }
}

/// Whether pixel `at` of a full-size level `width` wide is a hole in texture `name`.
fn is_hole(kind: Kind, width: u32, at: usize, index: u8) -> bool {
    match kind {
        Kind::Plain => false,
        Kind::Fence => index == 255,
        Kind::Sky => index == 0 && (at % width as usize) < width as usize / 2,
    }
}

fn counts(name: &str, width: u32, pixels: &[u8]) -> (usize, usize) {
    let kind = Kind::of(name);
    let mut fullbright = 0;
    let mut holes = 0;
    for (at, &index) in pixels.iter().enumerate() {
        if is_hole(kind, width, at, index) {
            holes += 1;
        } else if index >= FIRST_FULLBRIGHT {
            fullbright += 1;
        }
    }
    (fullbright, holes)
}

/// The full-size level of `tex` as a picture, and its glow mask when it has fullbright pixels.
/// `None` for a miptex stored without pixels.
pub fn pictures(tex: &MipTex, palette: &Palette) -> Option<(RgbaImage, Option<GrayImage>)> {
    let pixels = &tex.mips.as_ref()?[0];
    let kind = Kind::of(&tex.name());
    let at = |x: u32, y: u32| (y * tex.width + x) as usize;
    let picture = RgbaImage::from_fn(tex.width, tex.height, |x, y| {
        let index = pixels[at(x, y)];
        let [r, g, b] = palette.colors[index as usize];
        let alpha = if is_hole(kind, tex.width, at(x, y), index) {
            0
        } else {
            255
        };
        Rgba([r, g, b, alpha])
    });
    let (fullbright, _) = counts(&tex.name(), tex.width, pixels);
    let glow = (fullbright > 0).then(|| {
        GrayImage::from_fn(tex.width, tex.height, |x, y| {
            let index = pixels[at(x, y)];
            let bright = index >= FIRST_FULLBRIGHT && !is_hole(kind, tex.width, at(x, y), index);
            Luma([if bright { 255 } else { 0 }])
        })
    });
    Some((picture, glow))
}

/// What `extract` wrote and passed over.
#[derive(Debug, Clone, Default)]
pub struct Extracted {
    /// The pictures and glow masks written.
    pub written: Vec<PathBuf>,
    /// Lumps that are not miptex with pixels, with why.
    pub skipped: Vec<String>,
}

/// Write every miptex of `wad` into `dir` (created if missing) as PNG, each file atomically.
pub fn extract(wad: &Wad, dir: &Path, palette: &Palette) -> Result<Extracted, WadError> {
    std::fs::create_dir_all(dir).map_err(|source| WadError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut done = Extracted::default();
    let mut seen = std::collections::HashSet::new();
    for lump in &wad.lumps {
        let name = lump.name();
        // Compilers take the first texture of a name; a later one would overwrite its picture.
        if lump.kind == lump_type::MIPTEX && !seen.insert(name.to_ascii_lowercase()) {
            done.skipped.push(format!(
                "{name}: a second texture of this name (compilers use the first)"
            ));
            continue;
        }
        let Some(tex) = miptex_of(wad, lump) else {
            done.skipped
                .push(format!("{name}: {} lump", lump_kind(lump.kind)));
            continue;
        };
        let Some((picture, glow)) = pictures(&tex, palette) else {
            done.skipped.push(format!("{name}: miptex without pixels"));
            continue;
        };
        let stem = file_stem(&name);
        let opaque = picture.pixels().all(|p| p.0[3] == 255);
        let picture = if opaque {
            image::DynamicImage::ImageRgba8(picture).into_rgb8().into()
        } else {
            image::DynamicImage::ImageRgba8(picture)
        };
        done.written
            .push(write_png(&picture, &dir.join(format!("{stem}.png")))?);
        if let Some(glow) = glow {
            let path = dir.join(format!("{stem}_glow.png"));
            done.written.push(write_png(&glow.into(), &path)?);
        }
    }
    Ok(done)
}

/// Encode `picture` as PNG bytes.
pub fn encode_png(picture: &image::DynamicImage) -> Result<Vec<u8>, image::ImageError> {
    let mut out = std::io::Cursor::new(Vec::new());
    picture.write_to(&mut out, image::ImageFormat::Png)?;
    Ok(out.into_inner())
}

fn write_png(picture: &image::DynamicImage, path: &Path) -> Result<PathBuf, WadError> {
    let bytes = encode_png(picture).map_err(|source| WadError::Encode {
        path: path.to_path_buf(),
        source,
    })?;
    quake_formats::fsutil::write_atomic(path, &bytes)?;
    Ok(path.to_path_buf())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tex(name: &str, pixels: Vec<u8>) -> MipTex {
        let mips = [pixels, vec![0; 64], vec![0; 16], vec![0; 4]];
        MipTex::new(name, 16, 16, mips)
    }

    #[test]
    fn a_second_texture_of_a_name_is_skipped_not_written_over_the_first() {
        let palette = Palette::slipgate();
        let wad = Wad::new(vec![
            quake_formats::wad::WadLump::miptex(tex("wall", vec![10; 256])),
            quake_formats::wad::WadLump::miptex(tex("WALL", vec![20; 256])),
        ]);
        let dir = std::env::temp_dir().join(format!("slipgate-extract-dup-{}", std::process::id()));
        let done = extract(&wad, &dir, &palette).expect("extract");
        assert_eq!(done.written.len(), 1);
        assert_eq!(done.skipped.len(), 1, "{:?}", done.skipped);
        let written = image::open(&done.written[0]).expect("png").to_rgb8();
        assert_eq!(written.get_pixel(0, 0).0, palette.colors[10]);
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    #[test]
    fn holes_are_clear_and_fullbrights_glow() {
        let palette = Palette::slipgate();
        let pixels: Vec<u8> = (0..256).map(|i| [255, 0, 230, 17][i % 4]).collect();
        let (fence, glow) = pictures(&tex("{grate", pixels.clone()), &palette).expect("pixels");
        assert_eq!(fence.get_pixel(0, 0).0[3], 0);
        assert_eq!(fence.get_pixel(1, 0).0[3], 255);
        let glow = glow.expect("index 230 glows");
        assert_eq!(
            [0, 1, 2, 3].map(|x| glow.get_pixel(x, 0).0[0]),
            [0, 0, 255, 0]
        );
        let (wall, _) = pictures(&tex("wall", pixels.clone()), &palette).expect("pixels");
        assert!(wall.pixels().all(|p| p.0[3] == 255));
        // A sky's index 0 is a hole only in its left half, the front layer.
        let (sky, _) = pictures(&tex("sky4", pixels), &palette).expect("pixels");
        assert_eq!(
            (sky.get_pixel(1, 0).0[3], sky.get_pixel(9, 0).0[3]),
            (0, 255)
        );
    }

    #[test]
    fn listing_counts_pixels() {
        let pixels: Vec<u8> = (0..256).map(|i| [255, 0, 230, 17][i % 4]).collect();
        let wad = Wad::new(vec![quake_formats::wad::WadLump::miptex(tex(
            "{grate", pixels,
        ))]);
        let entries = list(&wad);
        assert_eq!(entries.len(), 1);
        let e = &entries[0];
        assert_eq!((e.kind.as_str(), e.size), ("miptex", Some([16, 16])));
        assert_eq!((e.fullbright_pixels, e.transparent_pixels), (64, 64));
    }
}
