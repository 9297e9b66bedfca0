//! `SLIPGATE_FACEFLAGS`: Slipgate's own BSPX lump that carries what the keys of entities merged
//! into the world (`func_detail*`, `func_group`, worldspawn) say about their faces, which the
//! BSP's core lumps cannot hold: whether a face casts shadows (`_shadow`) and whether it gives
//! ambient sound (`_noambient`). The compiler writes it; light and vis read it.
//!
//! One byte per face, in face order: bit 0 set, the face casts no shadow; bit 1 set, it gives
//! no ambient sound. Other bits are reserved and read as zero. The lump is left out when no face
//! has a flag, and engines ignore BSPX lumps they do not know.

use super::Bsp;
use crate::error::Result;

/// The lump's BSPX name.
pub const LUMP_NAME: &str = "SLIPGATE_FACEFLAGS";
const NO_SHADOW: u8 = 1;
const NO_AMBIENT: u8 = 2;

/// What a face's entity says about it beyond the core lumps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct FaceFlags {
    /// The face blocks no light (`_shadow -1`, or `func_detail_illusionary` without
    /// `_shadow 1`).
    pub no_shadow: bool,
    /// The face gives no ambient sound to the leaves it is in (`_noambient 1`).
    pub no_ambient: bool,
}

impl FaceFlags {
    fn byte(self) -> u8 {
        (u8::from(self.no_shadow) * NO_SHADOW) | (u8::from(self.no_ambient) * NO_AMBIENT)
    }

    fn from_byte(b: u8) -> FaceFlags {
        FaceFlags {
            no_shadow: b & NO_SHADOW != 0,
            no_ambient: b & NO_AMBIENT != 0,
        }
    }
}

impl Bsp {
    /// The `SLIPGATE_FACEFLAGS` records, one per face, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::BadLump`](crate::FormatError::BadLump) when its length is not the face
    /// count.
    pub fn face_flags(&self) -> Result<Option<Vec<FaceFlags>>> {
        let Some(data) = self.bspx_lump(LUMP_NAME) else {
            return Ok(None);
        };
        self.per_face_records(LUMP_NAME, data.len(), 1)?;
        Ok(Some(
            data.iter().map(|&b| FaceFlags::from_byte(b)).collect(),
        ))
    }

    /// Stores `flags` (one per face) as the `SLIPGATE_FACEFLAGS` lump, replacing any earlier
    /// one; with no flag set on any face the lump is left out.
    pub fn set_face_flags(&mut self, flags: &[FaceFlags]) {
        if flags.iter().all(|f| *f == FaceFlags::default()) {
            self.remove_bspx_lump(LUMP_NAME);
            return;
        }
        self.set_bspx_lump(LUMP_NAME, flags.iter().map(|f| f.byte()).collect());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_round_trip_through_the_file() {
        let mut bsp = crate::bsp::bsp_with_faces(3);
        assert_eq!(bsp.face_flags().expect("no lump"), None);
        let flags = [
            FaceFlags::default(),
            FaceFlags {
                no_shadow: true,
                no_ambient: false,
            },
            FaceFlags {
                no_shadow: true,
                no_ambient: true,
            },
        ];
        bsp.set_face_flags(&flags);
        bsp.set_face_flags(&flags);
        assert_eq!(bsp.bspx.len(), 1, "replaced, not added");
        let read = Bsp::read(&bsp.write().expect("write")).expect("read");
        assert_eq!(read.face_flags().expect("lump"), Some(flags.to_vec()));
        bsp.set_face_flags(&[FaceFlags::default(); 3]);
        assert!(bsp.bspx.is_empty(), "no flags, no lump");
    }

    #[test]
    fn a_lump_of_another_length_is_an_error_and_reserved_bits_read_as_zero() {
        let mut bsp = crate::bsp::bsp_with_faces(2);
        bsp.set_bspx_lump(LUMP_NAME, vec![1, 2, 3]);
        assert!(bsp.face_flags().is_err(), "3 records for 2 faces");
        bsp.set_bspx_lump(LUMP_NAME, vec![0xfc, 0xff]);
        let read = bsp.face_flags().expect("lump").expect("present");
        assert_eq!(read[0], FaceFlags::default());
        assert_eq!(
            read[1],
            FaceFlags {
                no_shadow: true,
                no_ambient: true
            }
        );
    }
}
