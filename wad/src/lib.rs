//! `slipgate wad`: texture WADs (WAD2) from folders of PNG and TGA pictures, and back, as mappers
//! make them with qpakman or TexMex.
//!
//! [`source`] reads a folder (names from file names, `_glow` masks for fullbright colours, holes
//! in `{` and sky textures from alpha); [`picture`] holds true-colour pictures (resampling to
//! multiples of 16, the 2x2 box filter of the mip levels); [`quantise`] picks palette indices by
//! nearest colour or Floyd-Steinberg dithering; [`measure`] is each level's colour error;
//! [`build`] makes the miptex; [`extract`] turns them back into pictures. The file format itself
//! is `quake_formats::wad` and `miptex`.

pub mod build;
pub mod cli;
pub mod extract;
pub mod measure;
pub mod picture;
pub mod quantise;
pub mod source;

pub use build::{BuildOptions, Built, build};

use quake_formats::FormatError;
use std::path::{Path, PathBuf};

/// Everything that can go wrong; every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum WadError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: cannot read the picture: {source}", path.display())]
    Decode {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
    #[error("{}: cannot write the picture: {source}", path.display())]
    Encode {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
    #[error("{}: {detail}", path.display())]
    Name { path: PathBuf, detail: String },
    #[error("{} and {} both make texture \"{name}\"", first.display(), second.display())]
    DuplicateName {
        name: String,
        first: PathBuf,
        second: PathBuf,
    },
    #[error("{}: glow mask for \"{name}\", but there is no picture of that name", path.display())]
    GlowWithoutTexture { path: PathBuf, name: String },
    #[error("{}: {detail}", path.display())]
    Size { path: PathBuf, detail: String },
    #[error("{}: no .png or .tga pictures in this folder", .0.display())]
    NoPictures(PathBuf),
    #[error("{}: {source}", path.display())]
    BadFile {
        path: PathBuf,
        #[source]
        source: FormatError,
    },
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
