//! PNG output of a frame.

use std::path::Path;

use crate::error::{Result, ViewerError};
use crate::render::Frame;

/// Encode a frame as an 8-bit RGB PNG.
pub fn encode_png(frame: &Frame) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, frame.width as u32, frame.height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    let rgb: Vec<u8> = frame
        .pixels
        .iter()
        .flat_map(|&c| crate::textures::unpack(c))
        .collect();
    writer.write_image_data(&rgb)?;
    writer.finish()?;
    Ok(out)
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
