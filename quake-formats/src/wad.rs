//! WAD2 texture archives: a header, lump data, and a directory of 32-byte entries.

use crate::bytes::{PutLe, Reader, name16_to_string, string_to_name16};
use crate::error::{FormatError, Result};
use crate::layout::{Layout, place};
use crate::miptex::MipTex;

const WAD2_MAGIC: [u8; 4] = *b"WAD2";
const HEADER_LEN: usize = 12;
const ENTRY_LEN: usize = 32;

/// Lump types used by Quake's WADs.
pub mod lump_type {
    /// A 768-byte palette (`gfx.wad`'s `PALETTE`).
    pub const PALETTE: u8 = 0x40;
    /// `TYP_QTEX` of Quake's source; Slipgate reads and writes no such lump.
    pub const QTEX: u8 = 0x41;
    /// A status bar or menu picture: width, height, then palette indices (`gfx.wad`).
    pub const QPIC: u8 = 0x42;
    /// `TYP_SOUND` of Quake's source; kept as raw bytes.
    pub const SOUND: u8 = 0x43;
    /// A mip texture ([`MipTex`](crate::miptex::MipTex)): what texture WADs hold.
    pub const MIPTEX: u8 = 0x44;
}

/// A lump's payload: decoded miptex, or bytes kept as they are.
#[derive(Debug, Clone, PartialEq)]
pub enum WadData {
    /// An uncompressed miptex lump whose bytes are exactly what [`MipTex::encode`] writes.
    MipTex(MipTex),
    /// Any other lump, or a miptex with unusual padding or offsets, as stored.
    Raw(Vec<u8>),
}

/// One directory entry and its data.
#[derive(Debug, Clone, PartialEq)]
pub struct WadLump {
    /// The raw 16-byte name: bytes after the terminating NUL are kept for exact round trips.
    pub raw_name: [u8; 16],
    /// The lump's type, one of [`lump_type`].
    pub kind: u8,
    /// The entry's compression byte; Quake's WADs use 0 (none), and nothing decompresses
    /// others.
    pub compression: u8,
    /// The two padding bytes of the entry, kept for exact round trips.
    pub pad: [u8; 2],
    /// The entry's uncompressed `size` field when it differs from the stored length.
    pub declared_size: Option<u32>,
    /// The lump's bytes, decoded where they are a miptex.
    pub data: WadData,
}

impl WadLump {
    /// An uncompressed miptex lump named after the texture.
    pub fn miptex(tex: MipTex) -> WadLump {
        WadLump {
            raw_name: string_to_name16(&tex.name()),
            kind: lump_type::MIPTEX,
            compression: 0,
            pad: [0; 2],
            declared_size: None,
            data: WadData::MipTex(tex),
        }
    }

    /// The name up to its first NUL, read as Latin-1.
    pub fn name(&self) -> String {
        name16_to_string(&self.raw_name)
    }

    fn encode(&self) -> Vec<u8> {
        match &self.data {
            WadData::MipTex(t) => {
                let mut out = Vec::with_capacity(t.encoded_len());
                t.encode(&mut out);
                out
            }
            WadData::Raw(b) => b.clone(),
        }
    }
}

/// A WAD2 file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Wad {
    /// The directory's entries in order, each with its data.
    pub lumps: Vec<WadLump>,
    layout: Option<Layout>,
}

impl Wad {
    /// A WAD of `lumps`, laid out afresh when written.
    pub fn new(lumps: Vec<WadLump>) -> Wad {
        Wad {
            lumps,
            layout: None,
        }
    }

    /// Parse a WAD2 file; a directory or lump outside the file is an error.
    pub fn read(data: &[u8]) -> Result<Wad> {
        let mut r = Reader::new(data, "WAD header");
        let magic = r.array::<4>()?;
        if magic != WAD2_MAGIC {
            return Err(FormatError::NotWad2(magic));
        }
        let count = r.i32()?;
        let dir_ofs = r.i32()?;
        // The directory must lie inside the file even when empty: the writer puts it back
        // where it was, so an offset past the end would size the rewritten file.
        let dir_fits = |count: usize, ofs: usize| {
            count <= data.len() / ENTRY_LEN && ofs <= data.len() - count * ENTRY_LEN
        };
        if count < 0 || dir_ofs < 0 || !dir_fits(count as usize, dir_ofs as usize) {
            return Err(FormatError::BadLump {
                lump: "WAD directory",
                detail: format!("{count} entries at offset {dir_ofs} do not fit the file"),
            });
        }
        let mut r = Reader::at(data, dir_ofs as usize, "WAD directory");
        let mut lumps = Vec::with_capacity(count as usize);
        let mut segments = Vec::with_capacity(count as usize + 1);
        for index in 0..count as usize {
            let file_pos = r.i32()?;
            let disk_size = r.i32()?;
            let size = r.i32()?;
            let kind = r.u8()?;
            let compression = r.u8()?;
            let pad = r.array::<2>()?;
            let raw_name = r.array::<16>()?;
            let bad = |detail: String| FormatError::BadWadLump {
                index,
                name: name16_to_string(&raw_name),
                detail,
            };
            if file_pos < 0 || disk_size < 0 || file_pos as usize + disk_size as usize > data.len()
            {
                return Err(bad(format!(
                    "data at {file_pos}+{disk_size} is outside the {}-byte file",
                    data.len()
                )));
            }
            let bytes = &data[file_pos as usize..(file_pos + disk_size) as usize];
            let payload = if kind == lump_type::MIPTEX && compression == 0 {
                let tex = MipTex::decode(bytes, "WAD miptex").map_err(|e| bad(e.to_string()))?;
                let mut check = Vec::new();
                tex.encode(&mut check);
                // Keep unusual encodings (padding, odd offsets) byte-exact as raw data.
                if check == bytes {
                    WadData::MipTex(tex)
                } else {
                    WadData::Raw(bytes.to_vec())
                }
            } else {
                WadData::Raw(bytes.to_vec())
            };
            lumps.push(WadLump {
                raw_name,
                kind,
                compression,
                pad,
                declared_size: (size != disk_size).then_some(size as u32),
                data: payload,
            });
            segments.push((file_pos as usize, disk_size as usize));
        }
        segments.push((dir_ofs as usize, count as usize * ENTRY_LEN));
        Ok(Wad {
            lumps,
            layout: Some(Layout::record(data, HEADER_LEN, segments)),
        })
    }

    /// Encode the file. A file read and written back unchanged is byte-identical.
    pub fn write(&self) -> Vec<u8> {
        let encoded: Vec<Vec<u8>> = self.lumps.iter().map(WadLump::encode).collect();
        let mut lens: Vec<usize> = encoded.iter().map(Vec::len).collect();
        lens.push(self.lumps.len() * ENTRY_LEN);
        let placement = place(self.layout.as_ref(), HEADER_LEN, &lens);
        let dir_ofs = placement.offsets[self.lumps.len()];
        let mut header = Vec::with_capacity(HEADER_LEN);
        header.extend_from_slice(&WAD2_MAGIC);
        header.put_i32(self.lumps.len() as i32);
        header.put_i32(dir_ofs as i32);
        let mut dir = Vec::with_capacity(lens[self.lumps.len()]);
        for (i, (lump, bytes)) in self.lumps.iter().zip(&encoded).enumerate() {
            dir.put_i32(placement.offsets[i] as i32);
            dir.put_i32(bytes.len() as i32);
            dir.put_i32(lump.declared_size.unwrap_or(bytes.len() as u32) as i32);
            dir.put_u8(lump.kind);
            dir.put_u8(lump.compression);
            dir.extend_from_slice(&lump.pad);
            dir.extend_from_slice(&lump.raw_name);
        }
        let mut segments: Vec<&[u8]> = encoded.iter().map(Vec::as_slice).collect();
        segments.push(&dir);
        placement.assemble(&header, &segments)
    }

    /// The miptex named `name` (case-insensitive, as Quake's texture names are).
    pub fn find_miptex(&self, name: &str) -> Option<MipTex> {
        self.lumps.iter().find_map(|l| {
            if !l.name().eq_ignore_ascii_case(name) || l.kind != lump_type::MIPTEX {
                return None;
            }
            match &l.data {
                WadData::MipTex(t) => Some(t.clone()),
                WadData::Raw(b) => MipTex::decode(b, "WAD miptex").ok(),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_wad_reads_back() {
        let mips = [vec![1u8; 256], vec![2u8; 64], vec![3u8; 16], vec![4u8; 4]];
        let wad = Wad::new(vec![WadLump::miptex(MipTex::new("brick1", 16, 16, mips))]);
        let bytes = wad.write();
        let back = Wad::read(&bytes).expect("read");
        assert_eq!(back.lumps.len(), 1);
        let tex = back.find_miptex("BRICK1").expect("case-insensitive lookup");
        assert_eq!(tex.width, 16);
        assert_eq!(back.write(), bytes);
    }

    #[test]
    fn truncated_directory_is_an_error() {
        let mips = [vec![0u8; 256], vec![0u8; 64], vec![0u8; 16], vec![0u8; 4]];
        let bytes = Wad::new(vec![WadLump::miptex(MipTex::new("a", 16, 16, mips))]).write();
        for cut in [4, 11, bytes.len() - 1] {
            assert!(Wad::read(&bytes[..cut]).is_err());
        }
    }

    #[test]
    fn an_empty_directory_past_the_end_is_an_error() {
        // Found by fuzzing: an 18-byte WAD naming no lumps in a directory at offset 721 million
        // was read, and rewriting it padded the file out to that offset (a 700 MB allocation).
        let mut bytes = b"WAD2".to_vec();
        bytes.extend(0i32.to_le_bytes());
        bytes.extend(0x2b00_0000i32.to_le_bytes());
        let err = Wad::read(&bytes).expect_err("directory past the end");
        assert!(err.to_string().contains("do not fit"), "{err}");
        let empty = Wad::new(Vec::new()).write();
        assert!(Wad::read(&empty).is_ok());
    }
}
