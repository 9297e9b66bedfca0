//! `SLIPGATE_FACEFLAGS`: Slipgate's own BSPX lump that carries what the keys of entities merged
//! into the world (`func_detail*`, `func_group`, worldspawn) say about their faces, which the
//! BSP's core lumps cannot hold: whether a face casts shadows (`_shadow`), gives ambient sound
//! (`_noambient`), takes dirt (`_dirt -1`), reflects bounced light (`_bounce 0`), takes light
//! at all (`_lightignore 1`) or takes minlight (`_minlight_exclude`). The compiler writes it;
//! light and vis read it.
//!
//! One byte per face, in face order: bit 0 set, the face casts no shadow; bit 1, it gives no
//! ambient sound; bit 2, it takes no dirt; bit 3, it reflects no bounced light; bit 4, it takes
//! minlight only; bit 5, it takes no minlight. Other bits are reserved and read as zero. The
//! lump is left out when no face has a flag, and engines ignore BSPX lumps they do not know.

use super::Bsp;
use crate::error::Result;

/// The lump's BSPX name.
pub const LUMP_NAME: &str = "SLIPGATE_FACEFLAGS";
const NO_SHADOW: u8 = 1;
const NO_AMBIENT: u8 = 2;
const NO_DIRT: u8 = 4;
const NO_BOUNCE: u8 = 8;
const LIGHT_IGNORE: u8 = 16;
const NO_MINLIGHT: u8 = 32;

/// What a face's entity says about it beyond the core lumps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct FaceFlags {
    /// The face blocks no light (`_shadow -1`, or `func_detail_illusionary` without
    /// `_shadow 1`).
    pub no_shadow: bool,
    /// The face gives no ambient sound to the leaves it is in (`_noambient 1`).
    pub no_ambient: bool,
    /// Dirt does not darken the face (`_dirt -1`).
    pub no_dirt: bool,
    /// The face reflects no bounced light (`_bounce 0` or below).
    pub no_bounce: bool,
    /// The face takes minlight only, no lights or suns (`_lightignore 1`).
    pub light_ignore: bool,
    /// The face takes no minlight, not even the world's (`_minlight_exclude` names its texture).
    pub no_minlight: bool,
}

impl FaceFlags {
    fn byte(self) -> u8 {
        [
            (self.no_shadow, NO_SHADOW),
            (self.no_ambient, NO_AMBIENT),
            (self.no_dirt, NO_DIRT),
            (self.no_bounce, NO_BOUNCE),
            (self.light_ignore, LIGHT_IGNORE),
            (self.no_minlight, NO_MINLIGHT),
        ]
        .iter()
        .fold(0, |b, &(set, bit)| if set { b | bit } else { b })
    }

    fn from_byte(b: u8) -> FaceFlags {
        FaceFlags {
            no_shadow: b & NO_SHADOW != 0,
            no_ambient: b & NO_AMBIENT != 0,
            no_dirt: b & NO_DIRT != 0,
            no_bounce: b & NO_BOUNCE != 0,
            light_ignore: b & LIGHT_IGNORE != 0,
            no_minlight: b & NO_MINLIGHT != 0,
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
        let unused = |f: &FaceFlags| *f == FaceFlags::default();
        self.write_per_face(LUMP_NAME, 1, flags, unused, |data, f| data.push(f.byte()));
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
                no_dirt: true,
                ..FaceFlags::default()
            },
            FaceFlags {
                no_shadow: true,
                no_ambient: true,
                no_bounce: true,
                light_ignore: true,
                no_minlight: true,
                ..FaceFlags::default()
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
        bsp.set_bspx_lump(LUMP_NAME, vec![0xc0, 0xff]);
        let read = bsp.face_flags().expect("lump").expect("present");
        assert_eq!(read[0], FaceFlags::default());
        assert_eq!(read[1].byte(), 0x3f);
    }
}
