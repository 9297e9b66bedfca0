//! PNG output of a frame.

use std::path::Path;

use crate::error::{Result, ViewerError};
use crate::render::Frame;

/// Encode a frame as an 8-bit RGB PNG.
pub fn encode_png(frame: &Frame) -> Result<Vec<u8>, ::image::ImageError> {
    let rgb: Vec<u8> = frame
        .pixels
        .iter()
        .flat_map(|&c| crate::textures::unpack(c))
        .collect();
    let mut out = std::io::Cursor::new(Vec::new());
    ::image::write_buffer_with_format(
        &mut out,
        &rgb,
        frame.width as u32,
        frame.height as u32,
        ::image::ExtendedColorType::Rgb8,
        ::image::ImageFormat::Png,
    )?;
    Ok(out.into_inner())
}

/// Write `frame` to `path` as PNG, atomically.
pub fn write_png(frame: &Frame, path: &Path) -> Result<()> {
    let data = encode_png(frame).map_err(|error| ViewerError::Png {
        path: path.to_path_buf(),
        error,
    })?;
    quake_formats::fsutil::write_atomic(path, &data)
        .map_err(|error| ViewerError::format(path, error))
}
