//! The pictures a WAD is built from: PNG and TGA files, their texture names, and glow masks.
//!
//! A file's texture name is its file name without the extension, in lower case, with a leading
//! `#` read as `*` (liquids: `*` is not allowed in Windows file names), at most 15 characters.
//! `NAME_glow.png` (or `.tga`) beside `NAME.png` is a glow mask of the same size: where its
//! brightest channel is at least 128 (and it is opaque) the texture's pixel takes a fullbright
//! colour; nowhere else does.

use crate::WadError;
use crate::picture::{Picture, Texel, rounded_side};
use image::{ImageFormat, RgbaImage};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Quake texture names are 16 bytes with a terminating NUL.
pub const MAX_NAME_LEN: usize = 15;

/// The largest side a texture may have once rounded up to 16: what our miptex reader accepts.
pub const MAX_SIDE: usize = 4096;

const GLOW_SUFFIX: &str = "_glow";

/// What a texture's name makes of its transparent pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// Coverage is ignored: every pixel is drawn.
    Plain,
    /// `{` names: engines draw index 255 as a hole.
    Fence,
    /// `sky` names: engines draw index 0 of the front layer (the left half) as a hole.
    Sky,
}

impl Kind {
    /// The kind a texture name makes: `{` names are fences, `sky` names (any case) skies.
    pub fn of(name: &str) -> Kind {
        if name.starts_with('{') {
            Kind::Fence
        } else if name.to_ascii_lowercase().starts_with("sky") {
            Kind::Sky
        } else {
            Kind::Plain
        }
    }

    /// The palette index engines draw as a hole in this kind of texture, if any.
    pub fn transparent_index(self) -> Option<u8> {
        match self {
            Kind::Plain => None,
            Kind::Fence => Some(255),
            Kind::Sky => Some(0),
        }
    }
}

/// One texture's picture, ready to quantise.
#[derive(Debug, Clone)]
pub struct Source {
    /// The texture name the file gives.
    pub name: String,
    /// The picture file.
    pub path: PathBuf,
    /// The picture, its glow mask and (for kinds with holes) its alpha applied.
    pub picture: Picture,
    /// Pixels under half coverage in a texture whose kind has no transparent index (drawn anyway).
    pub ignored_holes: usize,
}

/// The PNG and TGA files directly in `dir` (not below), as textures.
pub fn read_folder(dir: &Path) -> Result<Vec<Source>, WadError> {
    let io = |source| WadError::Io {
        path: dir.to_path_buf(),
        source,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        if path.is_file() && picture_format(&path).is_some() {
            let bytes = std::fs::read(&path).map_err(|source| WadError::Io {
                path: path.clone(),
                source,
            })?;
            files.push((path, bytes));
        }
    }
    if files.is_empty() {
        return Err(WadError::NoPictures(dir.to_path_buf()));
    }
    from_files(files)
}

/// Textures from files already read: `(path, bytes)`, the path giving the name and format.
/// Sorted by texture name.
pub fn from_files(files: Vec<(PathBuf, Vec<u8>)>) -> Result<Vec<Source>, WadError> {
    let mut textures: BTreeMap<String, (PathBuf, RgbaImage)> = BTreeMap::new();
    let mut masks: BTreeMap<String, (PathBuf, RgbaImage)> = BTreeMap::new();
    for (path, bytes) in files {
        let name = texture_name(&path)?;
        let image = decode(&path, &bytes)?;
        let (table, name) = match name.strip_suffix(GLOW_SUFFIX) {
            Some(base) => (&mut masks, base.to_string()),
            None => (&mut textures, name),
        };
        if let Some((first, _)) = table.get(&name) {
            return Err(WadError::DuplicateName {
                name,
                first: first.clone(),
                second: path,
            });
        }
        table.insert(name, (path, image));
    }
    if let Some((name, (path, _))) = masks.iter().find(|(n, _)| !textures.contains_key(*n)) {
        return Err(WadError::GlowWithoutTexture {
            path: path.clone(),
            name: name.clone(),
        });
    }
    textures
        .into_iter()
        .map(|(name, (path, image))| {
            let mask = masks.remove(&name);
            source(name, path, &image, mask)
        })
        .collect()
}

fn source(
    name: String,
    path: PathBuf,
    image: &RgbaImage,
    mask: Option<(PathBuf, RgbaImage)>,
) -> Result<Source, WadError> {
    // Checked before the picture is made: a small file can claim a huge size.
    if [image.width(), image.height()]
        .iter()
        .any(|&side| rounded_side(side as usize) > MAX_SIDE)
    {
        return Err(WadError::Size {
            path,
            detail: format!(
                "{}x{} is larger than {MAX_SIDE} on a side",
                image.width(),
                image.height()
            ),
        });
    }
    if let Some((mask_path, mask)) = &mask
        && mask.dimensions() != image.dimensions()
    {
        return Err(WadError::Size {
            path: mask_path.clone(),
            detail: format!(
                "the glow mask is {}x{} but {} is {}x{}",
                mask.width(),
                mask.height(),
                path.display(),
                image.width(),
                image.height()
            ),
        });
    }
    let keeps_holes = Kind::of(&name).transparent_index().is_some();
    let picture = Picture::from_fn(image.width() as usize, image.height() as usize, |x, y| {
        let [r, g, b, a] = image.get_pixel(x as u32, y as u32).0;
        let glow = mask.as_ref().map_or(0.0, |(_, m)| {
            let [r, g, b, a] = m.get_pixel(x as u32, y as u32).0;
            if r.max(g).max(b) >= 128 && a >= 128 {
                1.0
            } else {
                0.0
            }
        });
        Texel {
            rgb: [r, g, b].map(f64::from),
            alpha: if keeps_holes {
                f64::from(a) / 255.0
            } else {
                1.0
            },
            glow,
        }
    });
    let ignored_holes = if keeps_holes {
        0
    } else {
        image.pixels().filter(|p| p.0[3] < 128).count()
    };
    Ok(Source {
        name,
        path,
        picture,
        ignored_holes,
    })
}

fn picture_format(path: &Path) -> Option<ImageFormat> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "png" => Some(ImageFormat::Png),
        "tga" => Some(ImageFormat::Tga),
        _ => None,
    }
}

fn decode(path: &Path, bytes: &[u8]) -> Result<RgbaImage, WadError> {
    let format = picture_format(path).ok_or_else(|| WadError::Name {
        path: path.to_path_buf(),
        detail: "not a .png or .tga file".to_string(),
    })?;
    image::load_from_memory_with_format(bytes, format)
        .map(|image| image.into_rgba8())
        .map_err(|source| WadError::Decode {
            path: path.to_path_buf(),
            source,
        })
}

/// The texture name a picture file gives (see the module comment), or why it gives none.
pub fn texture_name(path: &Path) -> Result<String, WadError> {
    let bad = |detail: String| WadError::Name {
        path: path.to_path_buf(),
        detail,
    };
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .ok_or_else(|| bad("the file name is not UTF-8".to_string()))?;
    let name = match stem.strip_prefix('#') {
        Some(rest) => format!("*{rest}"),
        None => stem.to_string(),
    }
    .to_ascii_lowercase();
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_graphic()) {
        return Err(bad(format!(
            "\"{name}\" is not a texture name: use ASCII letters, digits and punctuation, no spaces"
        )));
    }
    let texture_part = name.strip_suffix(GLOW_SUFFIX).unwrap_or(&name);
    if texture_part.len() > MAX_NAME_LEN {
        return Err(bad(format!(
            "texture name \"{texture_part}\" is {} characters; Quake allows {MAX_NAME_LEN}",
            texture_part.len()
        )));
    }
    Ok(name)
}

/// The file name (without extension) a texture is extracted to: the reverse of [`texture_name`],
/// with characters no file system takes replaced by `_`.
pub fn file_stem(texture: &str) -> String {
    let stem = match texture.strip_prefix('*') {
        Some(rest) => format!("#{rest}"),
        None => texture.to_string(),
    };
    stem.chars()
        .map(|c| {
            if c.is_ascii_graphic() && !"/\\:*?\"<>|".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encoded(width: u32, height: u32, pixel: [u8; 4], format: ImageFormat) -> Vec<u8> {
        let image = RgbaImage::from_pixel(width, height, image::Rgba(pixel));
        let mut out = std::io::Cursor::new(Vec::new());
        image.write_to(&mut out, format).expect("encode");
        out.into_inner()
    }

    fn png(width: u32, height: u32, pixel: [u8; 4]) -> Vec<u8> {
        encoded(width, height, pixel, ImageFormat::Png)
    }

    #[test]
    fn names_come_from_file_names() {
        let name = |p: &str| texture_name(Path::new(p));
        assert_eq!(name("dir/Brick_1.PNG").expect("ok"), "brick_1");
        assert_eq!(name("#Water1.tga").expect("ok"), "*water1");
        assert_eq!(name("{grate.png").expect("ok"), "{grate");
        assert_eq!(name("exactly15chars_.png").expect("ok"), "exactly15chars_");
        assert_eq!(name("light1_glow.png").expect("ok"), "light1_glow");
        let long = name("sixteen_chars_xx.png").expect_err("16 characters");
        assert!(long.to_string().contains("is 16 characters"), "{long}");
        assert!(name("has space.png").is_err());
        assert_eq!(file_stem("*water1"), "#water1");
        assert_eq!(file_stem("a/b"), "a_b");
    }

    #[test]
    fn duplicate_names_name_both_files() {
        let err = from_files(vec![
            ("a/brick.png".into(), png(16, 16, [1, 2, 3, 255])),
            (
                "a/BRICK.tga".into(),
                encoded(16, 16, [1, 2, 3, 255], ImageFormat::Tga),
            ),
        ])
        .expect_err("duplicate");
        let text = err.to_string();
        assert!(
            text.contains("a/brick.png") && text.contains("a/BRICK.tga"),
            "{text}"
        );
    }

    #[test]
    fn glow_masks_pair_with_their_texture() {
        let sources = from_files(vec![
            ("light.png".into(), png(16, 16, [200, 200, 150, 255])),
            ("light_glow.png".into(), png(16, 16, [255, 255, 255, 255])),
        ])
        .expect("read");
        assert_eq!(sources.len(), 1);
        assert!(sources[0].picture.texels.iter().all(|t| t.glow == 1.0));
        let orphan = from_files(vec![("lamp_glow.png".into(), png(16, 16, [255; 4]))]);
        assert!(matches!(orphan, Err(WadError::GlowWithoutTexture { .. })));
        let wrong_size = from_files(vec![
            ("light.png".into(), png(16, 16, [200, 200, 150, 255])),
            ("light_glow.png".into(), png(8, 8, [255; 4])),
        ]);
        assert!(matches!(wrong_size, Err(WadError::Size { .. })));
    }

    #[test]
    fn holes_count_only_in_fences_and_skies() {
        let clear = png(16, 16, [9, 9, 9, 0]);
        let sources = from_files(vec![
            ("{fence.png".into(), clear.clone()),
            ("wall.png".into(), clear),
        ])
        .expect("read");
        assert_eq!(sources[0].name, "wall");
        assert_eq!(
            (sources[0].ignored_holes, sources[0].picture.texels[0].alpha),
            (256, 1.0)
        );
        assert_eq!(
            (sources[1].ignored_holes, sources[1].picture.texels[0].alpha),
            (0, 0.0)
        );
    }

    #[test]
    fn a_side_over_4096_is_refused_naming_the_file() {
        let err = from_files(vec![("big.png".into(), png(4097, 1, [0; 4]))]).expect_err("big");
        assert!(
            err.to_string().contains("big.png: 4097x1 is larger"),
            "{err}"
        );
    }

    #[test]
    fn an_unreadable_picture_is_named() {
        let err = from_files(vec![("bad.png".into(), b"not a png".to_vec())]).expect_err("bad");
        assert!(err.to_string().contains("bad.png"), "{err}");
    }
}
