//! `SLIPGATE_FACETONE`: Slipgate's own BSPX lump that carries the `_maxlight` and
//! `_lightcolorscale` of the entities whose brushes the compiler merges into the world
//! (`func_detail*`, `func_group`), which light could not otherwise tell apart from the world's.
//! Brush models' keys are in their entities, for light to read.
//!
//! Two little-endian `f32`s per face, in face order: the most light the face's luxels take, in
//! levels (0: the model's or the world's cap), and how much colour its light keeps (a negative
//! value: the model's or the world's). The lump is left out when no face has either, and engines
//! ignore BSPX lumps they do not know.

use super::Bsp;
use crate::bytes::PutLe;
use crate::error::Result;

/// The lump's BSPX name.
pub const LUMP_NAME: &str = "SLIPGATE_FACETONE";
const RECORD_LEN: usize = 8;

/// A face's own light cap and colour scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceTone {
    /// `_maxlight`, in levels; 0: none of its own.
    pub maxlight: f32,
    /// `_lightcolorscale`, 0 to 1; negative: none of its own.
    pub color_scale: f32,
}

impl Default for FaceTone {
    fn default() -> FaceTone {
        FaceTone {
            maxlight: 0.0,
            color_scale: -1.0,
        }
    }
}

impl FaceTone {
    /// From the values of `_maxlight` and `_lightcolorscale` (absent: none of its own; a cap
    /// of 0 or less, a negative scale or a scale of 1 are none either).
    pub fn from_keys(maxlight: Option<f64>, color_scale: Option<f64>) -> FaceTone {
        FaceTone {
            maxlight: maxlight.filter(|&m| m > 0.0).unwrap_or(0.0) as f32,
            color_scale: color_scale
                .filter(|&s| s >= 0.0 && s != 1.0)
                .unwrap_or(-1.0) as f32,
        }
    }

    /// Its cap, if it has one of its own.
    pub fn maxlight(&self) -> Option<f32> {
        (self.maxlight > 0.0).then_some(self.maxlight)
    }

    /// Its colour scale, if it has one of its own.
    pub fn color_scale(&self) -> Option<f32> {
        (self.color_scale >= 0.0).then_some(self.color_scale)
    }
}

impl Bsp {
    /// The `SLIPGATE_FACETONE` records, one per face, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::LumpSize`](crate::FormatError::LumpSize) or
    /// [`FormatError::BadLump`](crate::FormatError::BadLump) when its length does not match the
    /// face count.
    pub fn face_tones(&self) -> Result<Option<Vec<FaceTone>>> {
        self.read_per_face(LUMP_NAME, RECORD_LEN, |r| {
            Ok(FaceTone {
                maxlight: r.f32()?,
                color_scale: r.f32()?,
            })
        })
    }

    /// Stores `tones` (one per face) as the `SLIPGATE_FACETONE` lump, replacing any earlier
    /// one; when no face has either key the lump is left out.
    pub fn set_face_tones(&mut self, tones: &[FaceTone]) {
        let unused = |t: &FaceTone| t.maxlight().is_none() && t.color_scale().is_none();
        self.write_per_face(LUMP_NAME, RECORD_LEN, tones, unused, |data, t| {
            data.put_f32(t.maxlight);
            data.put_f32(t.color_scale);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tones_round_trip_through_the_file() {
        let mut bsp = crate::bsp::bsp_with_faces(3);
        assert_eq!(bsp.face_tones().expect("no lump"), None);
        let capped = FaceTone {
            maxlight: 40.0,
            ..FaceTone::default()
        };
        let grey = FaceTone {
            color_scale: 0.0,
            ..FaceTone::default()
        };
        let tones = [capped, FaceTone::default(), grey];
        bsp.set_face_tones(&tones);
        bsp.set_face_tones(&tones);
        assert_eq!(bsp.bspx.len(), 1, "replaced, not added");
        let read = Bsp::read(&bsp.write().expect("write")).expect("read");
        let back = read.face_tones().expect("lump").expect("present");
        assert_eq!(back, tones.to_vec());
        assert_eq!(
            (back[0].maxlight(), back[0].color_scale()),
            (Some(40.0), None)
        );
        assert_eq!(
            (back[2].maxlight(), back[2].color_scale()),
            (None, Some(0.0))
        );
        bsp.set_face_tones(&[FaceTone::default(); 3]);
        assert!(bsp.bspx.is_empty(), "no face with either key, no lump");
    }

    #[test]
    fn a_lump_of_another_length_is_an_error() {
        let mut bsp = crate::bsp::bsp_with_faces(2);
        bsp.set_bspx_lump(LUMP_NAME, vec![0; 8]);
        assert!(bsp.face_tones().is_err(), "1 record for 2 faces");
    }
}
