//! `SLIPGATE_FACECHANNELS`: Slipgate's own BSPX lump that carries the `_object_channel_mask` of
//! the entities whose brushes the compiler merges into the world (`func_detail*`, `func_group`):
//! the light channels their faces take light on and block light on, which light could not
//! otherwise tell apart from the world's. Brush models' masks are in their entities, for light
//! to read.
//!
//! One little-endian `u32` per face, in face order; 1 (the world's channel) is the mask of a face
//! without one of its own. The lump is left out when every face is on channel 1, and engines
//! ignore BSPX lumps they do not know.

use super::Bsp;
use crate::bytes::PutLe;
use crate::error::Result;

/// The lump's BSPX name.
pub const LUMP_NAME: &str = "SLIPGATE_FACECHANNELS";
const RECORD_LEN: usize = 4;

/// The light channels of a face without a mask of its own: the world's.
pub const DEFAULT_CHANNELS: u32 = 1;

impl Bsp {
    /// The `SLIPGATE_FACECHANNELS` masks, one per face, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::LumpSize`](crate::FormatError::LumpSize) or
    /// [`FormatError::BadLump`](crate::FormatError::BadLump) when its length does not match the
    /// face count.
    pub fn face_channels(&self) -> Result<Option<Vec<u32>>> {
        self.read_per_face(LUMP_NAME, RECORD_LEN, |r| r.u32())
    }

    /// Stores `channels` (one mask per face) as the `SLIPGATE_FACECHANNELS` lump, replacing any
    /// earlier one; with every face on channel 1 the lump is left out.
    pub fn set_face_channels(&mut self, channels: &[u32]) {
        let unused = |&c: &u32| c == DEFAULT_CHANNELS;
        self.write_per_face(LUMP_NAME, RECORD_LEN, channels, unused, |data, &c| {
            data.put_u32(c);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_round_trip_through_the_file() {
        let mut bsp = crate::bsp::bsp_with_faces(3);
        assert_eq!(bsp.face_channels().expect("no lump"), None);
        let masks = [1, 8, 3];
        bsp.set_face_channels(&masks);
        bsp.set_face_channels(&masks);
        assert_eq!(bsp.bspx.len(), 1, "replaced, not added");
        let read = Bsp::read(&bsp.write().expect("write")).expect("read");
        assert_eq!(read.face_channels().expect("lump"), Some(masks.to_vec()));
        bsp.set_face_channels(&[DEFAULT_CHANNELS; 3]);
        assert!(bsp.bspx.is_empty(), "every face on channel 1, no lump");
    }

    #[test]
    fn a_lump_of_another_length_is_an_error() {
        let mut bsp = crate::bsp::bsp_with_faces(2);
        bsp.set_bspx_lump(LUMP_NAME, vec![1, 0, 0, 0]);
        assert!(bsp.face_channels().is_err(), "1 record for 2 faces");
    }
}
