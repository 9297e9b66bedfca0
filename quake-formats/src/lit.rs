//! `.lit` files: coloured lightmaps beside a BSP. A header `QLIT` + version 1, then three bytes
//! (RGB) for every byte of the BSP's lighting lump, in the same order.

use crate::bytes::{PutLe, Reader};
use crate::error::{FormatError, Result};

const LIT_MAGIC: [u8; 4] = *b"QLIT";
const LIT_VERSION: i32 = 1;

/// A whole `.lit` file: the header, then `rgb` (three bytes per lighting lump byte).
pub fn write_lit(rgb: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 + rgb.len());
    out.extend_from_slice(&LIT_MAGIC);
    out.put_i32(LIT_VERSION);
    out.extend_from_slice(rgb);
    out
}

/// The RGB data; its length must be three times the lighting lump's.
pub fn read_lit(data: &[u8], lighting_len: usize) -> Result<Vec<u8>> {
    let mut r = Reader::new(data, ".lit header");
    let magic = r.array::<4>()?;
    let version = r.i32()?;
    let bad = |detail: String| FormatError::BadLump {
        lump: ".lit",
        detail,
    };
    if magic != LIT_MAGIC {
        return Err(bad(format!("magic {magic:?} is not QLIT")));
    }
    if version != LIT_VERSION {
        return Err(bad(format!("version {version} is not 1")));
    }
    let rgb = &data[8..];
    if rgb.len() != lighting_len * 3 {
        return Err(bad(format!(
            "{} bytes of colour for a {lighting_len}-byte lighting lump (expected {})",
            rgb.len(),
            lighting_len * 3
        )));
    }
    Ok(rgb.to_vec())
}

/// How far a luxel's grey (the mean of its r, g, b) may sit from the lighting lump's byte and
/// still be the same light: tools derive the grey lump in their own ways (rounding, weights).
pub const LIT_GREY_TOLERANCE: u8 = 24;
/// The share of luxels beyond [`LIT_GREY_TOLERANCE`] above which a `.lit` is another light's.
pub const LIT_MISMATCH_SHARE: f64 = 0.1;

/// How many luxels of `rgb` (as [`read_lit`] returns it) have a grey further than
/// [`LIT_GREY_TOLERANCE`] from `lighting`'s byte: a `.lit` of the right size written for another
/// light of the same BSP (an interrupted or foreign tool run) shows as a large share of them.
pub fn grey_disagreements(rgb: &[u8], lighting: &[u8]) -> usize {
    rgb.chunks_exact(3)
        .zip(lighting)
        .filter(|(c, grey)| {
            let mean = (u32::from(c[0]) + u32::from(c[1]) + u32::from(c[2]) + 1) / 3;
            mean.abs_diff(u32::from(**grey)) > u32::from(LIT_GREY_TOLERANCE)
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_size_check() {
        let rgb = vec![1, 2, 3, 4, 5, 6];
        let file = write_lit(&rgb);
        assert_eq!(read_lit(&file, 2).expect("read"), rgb);
        assert!(read_lit(&file, 3).is_err());
    }

    #[test]
    fn grey_disagreement_counts_luxels_far_from_the_lump() {
        let lighting = [100, 100, 0];
        let rgb = [120, 90, 93, 255, 255, 255, 0, 0, 30];
        // 101 vs 100, 255 vs 100, 10 vs 0.
        assert_eq!(grey_disagreements(&rgb, &lighting), 1);
    }
}
