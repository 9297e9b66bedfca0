//! `SLIPGATE_FACEMINLIGHT`: Slipgate's own BSPX lump that carries the `_minlight` and
//! `_minlight_color` of the entities whose brushes the compiler merges into the world
//! (`func_detail*`, `func_group`), which light could not otherwise tell apart from the world's.
//! Brush models' minlight is in their entities, for light to read.
//!
//! Four little-endian `f32` per face, in face order: the level, then the colour's red, green and
//! blue (each 0–1); a level of 0 is no minlight of its own. The lump is left out when no face has
//! one, and engines ignore BSPX lumps they do not know.

use super::Bsp;
use crate::bytes::PutLe;
use crate::error::Result;

/// The lump's BSPX name.
pub const LUMP_NAME: &str = "SLIPGATE_FACEMINLIGHT";
const RECORD_LEN: usize = 16;

/// A face's own minlight: the floor light raises it to, in light units.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FaceMinlight {
    /// 0: none of its own.
    pub level: f32,
    /// Each channel 0–1.
    pub color: [f32; 3],
}

impl Bsp {
    /// The `SLIPGATE_FACEMINLIGHT` records, one per face, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::LumpSize`](crate::FormatError::LumpSize) or
    /// [`FormatError::BadLump`](crate::FormatError::BadLump) when its length does not match the
    /// face count.
    pub fn face_minlights(&self) -> Result<Option<Vec<FaceMinlight>>> {
        self.read_per_face(LUMP_NAME, RECORD_LEN, |r| {
            Ok(FaceMinlight {
                level: r.f32()?,
                color: r.f32x3()?,
            })
        })
    }

    /// Stores `minlights` (one per face) as the `SLIPGATE_FACEMINLIGHT` lump, replacing any
    /// earlier one; with no face at a level of its own the lump is left out.
    pub fn set_face_minlights(&mut self, minlights: &[FaceMinlight]) {
        let unused = |m: &FaceMinlight| m.level == 0.0;
        self.write_per_face(LUMP_NAME, RECORD_LEN, minlights, unused, |data, m| {
            data.put_f32(m.level);
            data.put_f32x3(m.color);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minlights_round_trip_through_the_file() {
        let mut bsp = crate::bsp::bsp_with_faces(3);
        assert_eq!(bsp.face_minlights().expect("no lump"), None);
        let lit = FaceMinlight {
            level: 50.0,
            color: [1.0, 0.5, 0.0],
        };
        let minlights = [FaceMinlight::default(), lit, FaceMinlight::default()];
        bsp.set_face_minlights(&minlights);
        bsp.set_face_minlights(&minlights);
        assert_eq!(bsp.bspx.len(), 1, "replaced, not added");
        let read = Bsp::read(&bsp.write().expect("write")).expect("read");
        assert_eq!(
            read.face_minlights().expect("lump"),
            Some(minlights.to_vec())
        );
        bsp.set_face_minlights(&[FaceMinlight::default(); 3]);
        assert!(bsp.bspx.is_empty(), "no minlight, no lump");
        bsp.set_bspx_lump(LUMP_NAME, vec![0; 20]);
        assert!(
            bsp.face_minlights().is_err(),
            "a record and a bit for 3 faces"
        );
    }
}
