//! Mip textures: the record shared by WAD2 lumps and a BSP's texture lump.

use crate::bytes::{PutLe, Reader, name16_to_string, string_to_name16};
use crate::error::{FormatError, Result};
use crate::palette::FIRST_FULLBRIGHT;

/// Bytes of a miptex header: name, width, height and four mip offsets.
pub const MIPTEX_HEADER_LEN: usize = 40;

/// A texture with its four mip levels of palette indices (level `i` is `width >> i` by
/// `height >> i`). `mips` is `None` for a texture stored without pixels (external to the BSP).
#[derive(Debug, Clone, PartialEq)]
pub struct MipTex {
    /// The raw 16-byte name: bytes after the terminating NUL are kept for exact round trips.
    pub raw_name: [u8; 16],
    /// Width of mip level 0 in texels; engines want a multiple of 16.
    pub width: u32,
    /// Height of mip level 0 in texels; engines want a multiple of 16.
    pub height: u32,
    /// Palette indices of levels 0 to 3, rows top to bottom; `None` when not stored.
    pub mips: Option<[Vec<u8>; 4]>,
}

impl MipTex {
    /// A texture from its four mip levels of palette indices.
    pub fn new(name: &str, width: u32, height: u32, mips: [Vec<u8>; 4]) -> MipTex {
        MipTex {
            raw_name: string_to_name16(name),
            width,
            height,
            mips: Some(mips),
        }
    }

    /// Whether every texel is fullbright (palette index [`FIRST_FULLBRIGHT`] and up), so engines
    /// draw the texture without its face's lightmap (a light fixture's); `false` for a texture
    /// stored without pixels.
    pub fn is_all_fullbright(&self) -> bool {
        self.mips
            .as_ref()
            .is_some_and(|m| !m[0].is_empty() && m[0].iter().all(|&i| i >= FIRST_FULLBRIGHT))
    }

    /// The name up to its first NUL, read as Latin-1.
    pub fn name(&self) -> String {
        name16_to_string(&self.raw_name)
    }

    /// Pixel count of mip level `level`.
    pub fn mip_len(width: u32, height: u32, level: usize) -> usize {
        ((width >> level) as usize) * ((height >> level) as usize)
    }

    /// Decode a miptex that starts at the beginning of `data`.
    pub fn decode(data: &[u8], what: &str) -> Result<MipTex> {
        let mut r = Reader::new(data, what);
        let raw_name = r.array::<16>()?;
        let width = r.u32()?;
        let height = r.u32()?;
        let offsets = [r.u32()?, r.u32()?, r.u32()?, r.u32()?];
        let no_pixels = offsets.iter().all(|&o| o == 0);
        // A name without size or pixels: ericw-tools' `-missing_textures_as_zero_size`.
        let name_only = no_pixels && width == 0 && height == 0;
        if !name_only && (width == 0 || height == 0 || width > 4096 || height > 4096) {
            return Err(FormatError::BadLump {
                lump: "miptex",
                detail: format!(
                    "{what} ({}): implausible size {width}x{height}",
                    name16_to_string(&raw_name)
                ),
            });
        }
        let mips = if no_pixels {
            None
        } else {
            let mut levels: [Vec<u8>; 4] = Default::default();
            for (level, (slot, &ofs)) in levels.iter_mut().zip(&offsets).enumerate() {
                let mut r = Reader::at(data, ofs as usize, what);
                *slot = r.bytes(Self::mip_len(width, height, level))?.to_vec();
            }
            Some(levels)
        };
        Ok(MipTex {
            raw_name,
            width,
            height,
            mips,
        })
    }

    /// Encode with the header followed by the four levels in order.
    pub fn encode(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.raw_name);
        out.put_u32(self.width);
        out.put_u32(self.height);
        match &self.mips {
            Some(mips) => {
                let mut ofs = MIPTEX_HEADER_LEN;
                for m in mips {
                    out.put_u32(ofs as u32);
                    ofs += m.len();
                }
                for m in mips {
                    out.extend_from_slice(m);
                }
            }
            None => {
                for _ in 0..4 {
                    out.put_u32(0);
                }
            }
        }
    }

    /// Bytes [`MipTex::encode`] writes: the header and the levels stored.
    pub fn encoded_len(&self) -> usize {
        MIPTEX_HEADER_LEN
            + self
                .mips
                .as_ref()
                .map_or(0, |m| m.iter().map(Vec::len).sum())
    }
}

/// A BSP's texture lump: a count, an offset per texture (-1 for a missing one), the miptexes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TextureLump {
    /// The texture slots texinfos index, `None` where the lump stores no texture (offset -1).
    pub textures: Vec<Option<MipTex>>,
}

impl TextureLump {
    /// Read the lump; an empty lump has no textures.
    pub fn decode(data: &[u8]) -> Result<TextureLump> {
        if data.is_empty() {
            return Ok(TextureLump::default());
        }
        let mut r = Reader::new(data, "textures lump header");
        let count = r.i32()?;
        if count < 0 || count as usize > data.len() / 4 {
            return Err(FormatError::BadLump {
                lump: "textures",
                detail: format!("texture count {count} does not fit the lump"),
            });
        }
        let mut textures = Vec::with_capacity(count as usize);
        for i in 0..count as usize {
            let ofs = r.i32()?;
            if ofs < 0 {
                textures.push(None);
                continue;
            }
            let start = ofs as usize;
            if start >= data.len() {
                return Err(FormatError::BadLump {
                    lump: "textures",
                    detail: format!("texture {i}: offset {ofs} is past the lump's end"),
                });
            }
            let what = format!("textures lump, texture {i}");
            textures.push(Some(MipTex::decode(&data[start..], &what)?));
        }
        Ok(TextureLump { textures })
    }

    /// Write the lump, each miptex 4-byte aligned; no textures make an empty lump.
    pub fn encode(&self) -> Vec<u8> {
        if self.textures.is_empty() {
            return Vec::new();
        }
        let header = 4 + 4 * self.textures.len();
        let mut out = Vec::with_capacity(header);
        out.put_i32(self.textures.len() as i32);
        // Each miptex starts 4-byte aligned (only sizes that are not multiples of 16 need it).
        let mut ofs = header;
        for t in &self.textures {
            match t {
                Some(t) => {
                    ofs = ofs.next_multiple_of(4);
                    out.put_i32(ofs as i32);
                    ofs += t.encoded_len();
                }
                None => out.put_i32(-1),
            }
        }
        for t in self.textures.iter().flatten() {
            out.resize(out.len().next_multiple_of(4), 0);
            t.encode(&mut out);
        }
        out
    }

    /// The slot of the first texture named `name`, ignoring ASCII case.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.textures.iter().position(|t| {
            t.as_ref()
                .is_some_and(|t| t.name().eq_ignore_ascii_case(name))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_texture_is_all_fullbright_only_when_every_texel_of_its_first_mip_is() {
        let mips = |top: Vec<u8>| [top, vec![0; 4], vec![0], vec![0]];
        let lamp = MipTex::new("light1", 4, 4, mips(vec![FIRST_FULLBRIGHT; 16]));
        assert!(lamp.is_all_fullbright());
        let mut lit = vec![FIRST_FULLBRIGHT; 16];
        lit[5] = FIRST_FULLBRIGHT - 1;
        assert!(!MipTex::new("light2", 4, 4, mips(lit)).is_all_fullbright());
        let external = MipTex { mips: None, ..lamp };
        assert!(!external.is_all_fullbright());
    }

    /// A texture may be a name alone, 0x0 without pixels (ericw-tools'
    /// `-missing_textures_as_zero_size`); a 0x0 one with pixels, or one of a single side 0, is
    /// refused.
    #[test]
    fn a_name_alone_is_a_texture_but_a_zero_side_with_pixels_is_not() {
        let encoded = |width: u32, height: u32, offset: u32| {
            let mut data = Vec::new();
            data.extend_from_slice(&string_to_name16("missing"));
            data.extend_from_slice(&width.to_le_bytes());
            data.extend_from_slice(&height.to_le_bytes());
            for _ in 0..4 {
                data.extend_from_slice(&offset.to_le_bytes());
            }
            data
        };
        let t = MipTex::decode(&encoded(0, 0, 0), "test").expect("name only");
        assert_eq!(
            (t.name(), t.width, t.height, t.mips),
            ("missing".into(), 0, 0, None)
        );
        assert!(MipTex::decode(&encoded(0, 0, 40), "test").is_err());
        assert!(MipTex::decode(&encoded(0, 16, 0), "test").is_err());
    }
}
