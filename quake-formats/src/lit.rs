//! `.lit` files: coloured lightmaps beside a BSP. A header `QLIT` + version 1, then three bytes
//! (RGB) for every byte of the BSP's lighting lump, in the same order.
//!
//! Two variants share the header: the HDR `.lit` (version `0x10001`, ericw-tools' `-hdr`), one
//! little-endian E5BGR9 word per luxel ([`pack_e5bgr9`]), and the `.lux` deluxemap (version 1,
//! three bytes per luxel: the light's mean direction in the face's tangent space, each component
//! `(c + 1) * 128` clamped to a byte), DarkPlaces' `.dlit` and FTE's `.lux`.

use crate::bytes::{PutLe, Reader};
use crate::error::{FormatError, Result};

const LIT_MAGIC: [u8; 4] = *b"QLIT";
const LIT_VERSION: i32 = 1;
/// The HDR `.lit`'s version: E5BGR9 words instead of bytes.
const LIT_VERSION_E5BGR9: i32 = 0x0001_0000 | LIT_VERSION;

/// Bits of each E5BGR9 mantissa.
const E5BGR9_MANTISSA_BITS: i32 = 9;
/// The bias of E5BGR9's shared exponent.
const E5BGR9_EXPONENT_BIAS: i32 = 15;
/// The largest E5BGR9 exponent field.
const E5BGR9_MAX_EXPONENT: i32 = 31;

/// `2^n`, exactly.
fn pow2(n: i32) -> f64 {
    f64::from_bits(((1023 + i64::from(n)) as u64) << 52)
}

/// `rgb` (linear light, 1.0 the texture's own colour) as one E5BGR9 word: a 5-bit shared
/// exponent over three 9-bit mantissas (red in the low bits), as OpenGL's shared-exponent
/// texture format and the `LIGHTING_E5BGR9` lump store it. Negative and NaN channels are 0;
/// values past the format's largest (just under 65536) are clamped to it.
pub fn pack_e5bgr9(rgb: [f32; 3]) -> u32 {
    let n = E5BGR9_MANTISSA_BITS;
    let b = E5BGR9_EXPONENT_BIAS;
    let largest = f64::from((1 << n) - 1) / f64::from(1 << n) * pow2(E5BGR9_MAX_EXPONENT - b);
    // `max` with 0 turns NaN into 0 as well.
    let c = rgb.map(|x| f64::from(x).max(0.0).min(largest));
    let brightest = c[0].max(c[1]).max(c[2]);
    if brightest == 0.0 {
        return 0;
    }
    // floor(log2(brightest)), from the bits of a positive normal f64.
    let log2 = ((brightest.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    let mut exponent = log2.max(-b - 1) + 1 + b;
    if (brightest / pow2(exponent - b - n) + 0.5).floor() >= f64::from(1 << n) {
        exponent += 1;
    }
    let exponent = exponent.clamp(0, E5BGR9_MAX_EXPONENT);
    let step = pow2(exponent - b - n);
    let [r, g, bl] = c.map(|x| ((x / step + 0.5).floor() as u32).min((1 << n) - 1));
    (exponent as u32) << 27 | bl << 18 | g << 9 | r
}

/// The linear light an E5BGR9 word holds, red first.
pub fn unpack_e5bgr9(word: u32) -> [f32; 3] {
    let step = pow2((word >> 27) as i32 - E5BGR9_EXPONENT_BIAS - E5BGR9_MANTISSA_BITS);
    [word & 0x1ff, (word >> 9) & 0x1ff, (word >> 18) & 0x1ff].map(|m| (f64::from(m) * step) as f32)
}

/// A whole HDR `.lit` file: the header with version `0x10001`, then one E5BGR9 word per luxel.
pub fn write_hdr_lit(words: &[u32]) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 + 4 * words.len());
    out.extend_from_slice(&LIT_MAGIC);
    out.put_i32(LIT_VERSION_E5BGR9);
    for &w in words {
        out.put_u32(w);
    }
    out
}

/// A whole `.lux` file: the `.lit` header (version 1), then three direction bytes per luxel.
pub fn write_lux(directions: &[u8]) -> Vec<u8> {
    write_lit(directions)
}

/// What a `.lit` file holds, by its version.
#[derive(Debug, Clone, PartialEq)]
pub enum LitData {
    /// Version 1: three bytes per luxel.
    Rgb(Vec<u8>),
    /// Version `0x10001`: one E5BGR9 word per luxel.
    Hdr(Vec<u32>),
}

/// Either kind of `.lit` for a BSP of `luxels` luxels.
///
/// # Errors
/// A header that is not `QLIT` of a known version, or data of the wrong size.
pub fn read_any_lit(data: &[u8], luxels: usize) -> Result<LitData> {
    let mut r = Reader::new(data, ".lit header");
    let magic = r.array::<4>()?;
    let version = r.i32()?;
    if magic == LIT_MAGIC && version == LIT_VERSION_E5BGR9 {
        let words = &data[8..];
        if words.len() != luxels * 4 {
            return Err(FormatError::BadLump {
                lump: ".lit",
                detail: format!(
                    "{} bytes of HDR colour for {luxels} luxels (expected {})",
                    words.len(),
                    luxels * 4
                ),
            });
        }
        let words = words
            .chunks_exact(4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
            .collect();
        return Ok(LitData::Hdr(words));
    }
    read_lit(data, luxels).map(LitData::Rgb)
}

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

/// The grey lighting lump's byte for a luxel of colour `c`: its brightest channel, as
/// ericw-tools writes it, so coloured light is as bright in engines that read only the grey
/// lump as in those that read the colour.
pub fn grey_level(c: [u8; 3]) -> u8 {
    c[0].max(c[1]).max(c[2])
}

/// How far a luxel's grey may sit outside the span from the mean of its r, g, b to its brightest
/// channel and still be the same light: tools derive the grey lump in their own ways (the mean,
/// the brightest channel, rounding, weights).
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
            let brightest = u32::from(grey_level([c[0], c[1], c[2]]));
            let (grey, tolerance) = (u32::from(**grey), u32::from(LIT_GREY_TOLERANCE));
            grey + tolerance < mean || grey > brightest + tolerance
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grey_is_the_brightest_channel_and_either_convention_agrees() {
        assert_eq!(grey_level([255, 0, 0]), 255);
        assert_eq!(grey_level([10, 200, 30]), 200);
        // A red luxel: ericw-tools' grey (255) and the mean (85) both agree with it.
        let rgb = [255, 0, 0, 255, 0, 0, 255, 0, 0];
        assert_eq!(grey_disagreements(&rgb, &[255, 85, 40]), 1);
        // White: one grey only.
        assert_eq!(grey_disagreements(&[100, 100, 100], &[100]), 0);
        assert_eq!(grey_disagreements(&[100, 100, 100], &[130]), 1);
    }

    #[test]
    fn round_trip_and_size_check() {
        let rgb = vec![1, 2, 3, 4, 5, 6];
        let file = write_lit(&rgb);
        assert_eq!(read_lit(&file, 2).expect("read"), rgb);
        assert!(read_lit(&file, 3).is_err());
    }

    #[test]
    fn e5bgr9_keeps_light_past_one_and_round_trips_within_its_precision() {
        assert_eq!(pack_e5bgr9([0.0; 3]), 0);
        assert_eq!(pack_e5bgr9([-1.0, f32::NAN, 0.0]), 0);
        // 1.0 is 256 * 2^-8: exponent field 8 + 15 + 1 - ... as the OpenGL spec derives it.
        let one = pack_e5bgr9([1.0, 1.0, 1.0]);
        assert_eq!(unpack_e5bgr9(one), [1.0; 3]);
        for rgb in [[3.7f32, 0.25, 0.0], [0.001, 0.5, 0.75], [200.0, 100.0, 1.0]] {
            let back = unpack_e5bgr9(pack_e5bgr9(rgb));
            let brightest = rgb.iter().fold(0.0f32, |a, &b| a.max(b));
            for (a, b) in rgb.iter().zip(back) {
                // Each channel is within half a mantissa step of the shared exponent.
                assert!(
                    (a - b).abs() <= brightest / 512.0 + 1e-9,
                    "{rgb:?} -> {back:?}"
                );
            }
        }
        let huge = unpack_e5bgr9(pack_e5bgr9([1e9, 0.0, 0.0]));
        assert_eq!(huge[0], 65408.0, "clamped to the largest value");
        // The word's layout: red in the low 9 bits, the exponent in the top 5.
        let w = pack_e5bgr9([1.0, 0.0, 0.5]);
        assert_eq!(
            (w & 0x1ff, (w >> 9) & 0x1ff, (w >> 18) & 0x1ff),
            (256, 0, 128)
        );
        assert_eq!(w >> 27, 16);
    }

    #[test]
    fn hdr_lit_reads_back_and_is_told_from_a_plain_one() {
        let words = [pack_e5bgr9([2.0, 1.0, 0.5]), 0];
        let file = write_hdr_lit(&words);
        assert_eq!(
            read_any_lit(&file, 2).expect("hdr"),
            LitData::Hdr(words.to_vec())
        );
        assert!(read_any_lit(&file, 3).is_err());
        let plain = write_lit(&[1, 2, 3]);
        assert_eq!(
            read_any_lit(&plain, 1).expect("rgb"),
            LitData::Rgb(vec![1, 2, 3])
        );
        assert!(
            read_lit(&file, 2).is_err(),
            "a plain reader refuses the HDR version"
        );
    }

    #[test]
    fn grey_disagreement_counts_luxels_far_from_the_lump() {
        let lighting = [100, 100, 0];
        let rgb = [120, 90, 93, 255, 255, 255, 0, 0, 30];
        // 101 vs 100, 255 vs 100, 10 vs 0.
        assert_eq!(grey_disagreements(&rgb, &lighting), 1);
    }
}
