//! Reading the screenshots engines write: uncompressed true-colour TGA (QuakeSpasm's
//! `screenshot tga`, DarkPlaces' `screenshot` with PNG and JPEG turned off).

use std::collections::HashSet;

/// An image as rows of RGB pixels, top row first.
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[u8; 3]>,
}

/// Decode a type 2 (uncompressed true-colour) TGA of 24 or 32 bits per pixel.
pub fn read(bytes: &[u8]) -> Result<Image, String> {
    let header = bytes.get(..18).ok_or("TGA shorter than its header")?;
    let (id_length, colour_map, image_type) = (header[0] as usize, header[1], header[2]);
    if colour_map != 0 || image_type != 2 {
        return Err(format!(
            "TGA colour map {colour_map}, image type {image_type}: only uncompressed true colour (0, 2) is read"
        ));
    }
    let width = u16::from_le_bytes([header[12], header[13]]) as usize;
    let height = u16::from_le_bytes([header[14], header[15]]) as usize;
    let bytes_per_pixel = match header[16] {
        24 => 3,
        32 => 4,
        bits => return Err(format!("TGA of {bits} bits per pixel")),
    };
    // Descriptor bit 5: the first stored row is the top one (otherwise the bottom one).
    let top_first = header[17] & 0x20 != 0;
    let data = bytes
        .get(18 + id_length..18 + id_length + width * height * bytes_per_pixel)
        .ok_or("TGA shorter than its pixels")?;
    let mut pixels = Vec::with_capacity(width * height);
    for row in 0..height {
        let stored = if top_first { row } else { height - 1 - row };
        let line = &data[stored * width * bytes_per_pixel..][..width * bytes_per_pixel];
        pixels.extend(
            line.chunks_exact(bytes_per_pixel)
                .map(|bgr| [bgr[2], bgr[1], bgr[0]]),
        );
    }
    Ok(Image {
        width,
        height,
        pixels,
    })
}

impl Image {
    /// How many distinct colours the image holds.
    pub fn colours(&self) -> usize {
        self.pixels.iter().collect::<HashSet<_>>().len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tga(width: u16, height: u16, descriptor: u8, bgr: &[[u8; 3]]) -> Vec<u8> {
        let mut bytes = vec![0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        bytes.extend(width.to_le_bytes());
        bytes.extend(height.to_le_bytes());
        bytes.extend([24, descriptor]);
        bytes.extend(bgr.iter().flatten());
        bytes
    }

    #[test]
    fn rows_come_out_top_first_whatever_the_stored_order() {
        let stored = [[1, 2, 3], [4, 5, 6]];
        let bottom_first = read(&tga(1, 2, 0, &stored)).expect("read");
        assert_eq!(bottom_first.pixels, [[6, 5, 4], [3, 2, 1]]);
        let top_first = read(&tga(1, 2, 0x20, &stored)).expect("read");
        assert_eq!(top_first.pixels, [[3, 2, 1], [6, 5, 4]]);
        assert_eq!(top_first.colours(), 2);
    }

    #[test]
    fn truncated_or_compressed_files_are_refused() {
        let mut short = tga(2, 2, 0, &[[0; 3]; 3]);
        assert!(read(&short).is_err());
        short[2] = 10;
        assert!(read(&short).is_err());
    }
}
