//! `slipgate wad`: texture WADs (WAD2) from folders of PNG and TGA pictures, and back, as mappers
//! make them with qpakman or TexMex.
//!
//! [`source`] reads a folder (names from file names, `_glow` masks for fullbright colours, holes
//! in `{` and sky textures from alpha); `picture` holds true-colour pictures (resampling to
//! multiples of 16, the 2x2 box filter of the mip levels); `quantise` picks palette indices by
//! nearest colour or Floyd-Steinberg dithering; `measure` is each level's colour error
//! ([`LevelError`]); [`build`](mod@build) makes the miptex; [`extract`](mod@extract) turns them
//! back into pictures; [`cli`] is `slipgate wad`. The file format itself is `quake_formats::wad`
//! and `miptex`.

#![warn(missing_docs)]

pub mod build;
#[cfg(feature = "cli")]
pub mod cli;
pub mod extract;
mod measure;
mod picture;
mod quantise;
pub mod source;

pub use build::{BuildOptions, Built, build};
pub use measure::LevelError;
pub use picture::{Picture, Texel};

use quake_formats::FormatError;
use std::path::{Path, PathBuf};

/// Everything that can go wrong; every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum WadError {
    /// Reading a folder or a picture, or making the output folder, failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The folder or file.
        path: PathBuf,
        /// What the OS reported.
        #[source]
        source: std::io::Error,
    },
    /// A picture file could not be decoded.
    #[error("{}: cannot read the picture: {source}", path.display())]
    Decode {
        /// The picture file.
        path: PathBuf,
        /// The decoder's error.
        #[source]
        source: image::ImageError,
    },
    /// A picture could not be encoded as PNG.
    #[error("{}: cannot write the picture: {source}", path.display())]
    Encode {
        /// The picture that was to be written.
        path: PathBuf,
        /// The encoder's error.
        #[source]
        source: image::ImageError,
    },
    /// A file's name makes no texture name: not a picture, not ASCII, or too long.
    #[error("{}: {detail}", path.display())]
    Name {
        /// The picture file.
        path: PathBuf,
        /// What is wrong with the name.
        detail: String,
    },
    /// Two files give the same texture name (names are compared in lower case).
    #[error("{} and {} both make texture \"{name}\"", first.display(), second.display())]
    DuplicateName {
        /// The texture name both give.
        name: String,
        /// The first file of that name.
        first: PathBuf,
        /// The second file of that name.
        second: PathBuf,
    },
    /// A `NAME_glow` mask has no picture `NAME` beside it.
    #[error("{}: glow mask for \"{name}\", but there is no picture of that name", path.display())]
    GlowWithoutTexture {
        /// The mask file.
        path: PathBuf,
        /// The texture name the mask is for.
        name: String,
    },
    /// A picture is too large once rounded up to 16, or a glow mask's size differs from its
    /// picture's.
    #[error("{}: {detail}", path.display())]
    Size {
        /// The picture or mask file.
        path: PathBuf,
        /// The sizes involved.
        detail: String,
    },
    /// The folder holds no `.png` or `.tga` files; holds the folder.
    #[error("{}: no .png or .tga pictures in this folder", .0.display())]
    NoPictures(PathBuf),
    /// A WAD file could not be read as WAD2.
    #[error("{}: {source}", path.display())]
    BadFile {
        /// The WAD file.
        path: PathBuf,
        /// What was wrong with it.
        #[source]
        source: FormatError,
    },
    /// Reading or writing a file failed; the error names the file.
    #[error(transparent)]
    Format(#[from] FormatError),
}

/// Read the pictures in `dir`, build their WAD and write it to `out` (through a temporary file).
pub fn build_folder(
    dir: &Path,
    out: &Path,
    options: &BuildOptions,
    on_texture: &(dyn Fn(&str) + Sync),
) -> Result<Built, WadError> {
    let sources = source::read_folder(dir)?;
    let built = build(&sources, options, on_texture);
    quake_formats::fsutil::write_atomic(out, &built.wad.write())?;
    Ok(built)
}

/// Read the WAD at `path`.
pub fn read_wad(path: &Path) -> Result<quake_formats::wad::Wad, WadError> {
    let bytes = quake_formats::fsutil::read_file(path)?;
    quake_formats::wad::Wad::read(&bytes).map_err(|source| WadError::BadFile {
        path: path.to_path_buf(),
        source,
    })
}

/// The textures at `path`: a WAD's, or a BSP's texture lump as a WAD (the textures it holds
/// with pixels, in lump order; a mapper's way back to a map's textures when the WAD is lost).
pub fn read_textures(path: &Path) -> Result<quake_formats::wad::Wad, WadError> {
    let bytes = quake_formats::fsutil::read_file(path)?;
    if bytes.starts_with(b"WAD2") {
        return read_wad(path);
    }
    let bsp = quake_formats::Bsp::read(&bytes).map_err(|source| WadError::BadFile {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(extract::textures_of(&bsp))
}
