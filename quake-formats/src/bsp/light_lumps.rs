//! The BSPX lumps that carry light past what the vanilla lighting lump holds, as ericw-tools
//! writes them and FTE, QuakeSpasm-Spiked, Ironwail and vkQuake read them.
//!
//! Per luxel, in the lighting lump's order (a face's `light_offset` counts luxels in all of
//! them): `RGBLIGHTING` (three bytes, a `.lit` without its header), `LIGHTINGDIR` (three bytes,
//! the deluxemap of a `.lux`) and `LIGHTING_E5BGR9` (one little-endian E5BGR9 word, linear light
//! with 1.0 the texture's own colour, [`crate::lit::pack_e5bgr9`]). With `RGBLIGHTING` the grey
//! lump may be left empty (ericw-tools' `-novanilla`); engines that read only the grey lump then
//! draw the map unlit.
//!
//! Per face: `LMSHIFT` (one byte, the face's lightmap spacing is `1 << shift` texels) with
//! `LMOFFSET` (one `i32`, where the face's lightmap at that spacing starts, so `light_offset` keeps
//! the 16-texel one for other engines), and `DECOUPLED_LM` ([`DecoupledLightmap`], 40 bytes: a
//! lightmap on a grid of its own, sized and projected from world space, with the vanilla
//! lightmap still at `light_offset`).

use super::{Bsp, BspxLump};
use crate::bytes::{PutLe, Reader};
use crate::error::{FormatError, Result};
use crate::extents::LuxelGrid;

/// Coloured light: three bytes per luxel.
pub const RGBLIGHTING: &str = "RGBLIGHTING";
/// Deluxemap: three bytes per luxel, the light's mean direction in the face's tangent space.
pub const LIGHTINGDIR: &str = "LIGHTINGDIR";
/// HDR light: one E5BGR9 word per luxel.
pub const LIGHTING_E5BGR9: &str = "LIGHTING_E5BGR9";
/// Per face, its lightmap's spacing as a power of two texels.
pub const LMSHIFT: &str = "LMSHIFT";
/// Per face, where its `LMSHIFT` lightmap starts (luxels; -1: none).
pub const LMOFFSET: &str = "LMOFFSET";
/// Per face, a lightmap projected from world space on a grid of its own.
pub const DECOUPLED_LM: &str = "DECOUPLED_LM";

/// Bytes per luxel of `RGBLIGHTING` and `LIGHTINGDIR`.
pub const RGB_BYTES_PER_LUXEL: usize = 3;
/// Bytes per luxel of `LIGHTING_E5BGR9`.
pub const HDR_BYTES_PER_LUXEL: usize = 4;
/// Bytes of one `DECOUPLED_LM` record.
pub const DECOUPLED_RECORD_LEN: usize = 40;

/// One face's `DECOUPLED_LM` record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecoupledLightmap {
    /// Luxels across.
    pub width: u16,
    /// Luxels down.
    pub height: u16,
    /// First luxel of the face's lightmaps (one per style, as the face's `styles` list them) in
    /// the lighting data; -1: no lightmap.
    pub offset: i32,
    /// Model space to luxel coordinates: luxel `(x, y)` is where `row · (p, 1)` gives `(x, y)`.
    pub world_to_luxel: [[f32; 4]; 2],
}

impl DecoupledLightmap {
    /// The luxel grid the record describes.
    pub fn grid(&self) -> LuxelGrid {
        LuxelGrid::in_luxels(
            &self.world_to_luxel,
            [usize::from(self.width), usize::from(self.height)],
        )
    }
}

impl Bsp {
    /// The BSPX lump called `name`, if the file has one.
    pub fn bspx_lump(&self, name: &str) -> Option<&[u8]> {
        self.bspx
            .iter()
            .find(|l| l.name() == name)
            .map(|l| l.data.as_slice())
    }

    /// Stores `data` as the BSPX lump `name`, in place of any earlier one (a new lump goes last).
    ///
    /// # Panics
    /// When `name` is longer than the 23 bytes a BSPX name holds (names are the constants of
    /// this crate, not user input).
    pub fn set_bspx_lump(&mut self, name: &str, data: Vec<u8>) {
        assert!(name.len() < 24, "BSPX lump name {name} is too long");
        if let Some(lump) = self.bspx.iter_mut().find(|l| l.name() == name) {
            lump.data = data;
            return;
        }
        let mut raw_name = [0u8; 24];
        raw_name[..name.len()].copy_from_slice(name.as_bytes());
        self.bspx.push(BspxLump { raw_name, data });
    }

    /// Removes the BSPX lump `name`, if there is one.
    pub fn remove_bspx_lump(&mut self, name: &str) {
        self.bspx.retain(|l| l.name() != name);
    }

    /// Luxels the lighting data holds: the grey lump's bytes, or, when it is left empty beside an
    /// `RGBLIGHTING` lump (`-novanilla`), that lump's luxels.
    pub fn luxel_count(&self) -> usize {
        if !self.lighting.is_empty() {
            return self.lighting.len();
        }
        self.bspx_lump(RGBLIGHTING)
            .map_or(0, |rgb| rgb.len() / RGB_BYTES_PER_LUXEL)
    }

    /// The `LMSHIFT` bytes, one per face, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::BadLump`] when it has another length than the face count.
    pub fn lightmap_shifts(&self) -> Result<Option<Vec<u8>>> {
        let Some(data) = self.bspx_lump(LMSHIFT) else {
            return Ok(None);
        };
        self.per_face_records(LMSHIFT, data.len(), 1)?;
        Ok(Some(data.to_vec()))
    }

    /// The `LMOFFSET` values, one per face, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::LumpSize`] or [`FormatError::BadLump`] when its records do not match the
    /// face count.
    pub fn lightmap_offsets(&self) -> Result<Option<Vec<i32>>> {
        self.read_per_face(LMOFFSET, 4, |r| r.i32())
    }

    /// Stores one `LMSHIFT` byte and one `LMOFFSET` value per face.
    pub fn set_shifted_lightmaps(&mut self, shifts: &[u8], offsets: &[i32]) {
        self.set_bspx_lump(LMSHIFT, shifts.to_vec());
        let mut data = Vec::with_capacity(offsets.len() * 4);
        for &o in offsets {
            data.put_i32(o);
        }
        self.set_bspx_lump(LMOFFSET, data);
    }

    /// The `DECOUPLED_LM` records, one per face, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::LumpSize`] or [`FormatError::BadLump`] when its records do not match the
    /// face count.
    pub fn decoupled_lightmaps(&self) -> Result<Option<Vec<DecoupledLightmap>>> {
        let Some(data) = self.bspx_lump(DECOUPLED_LM) else {
            return Ok(None);
        };
        self.per_face_records(DECOUPLED_LM, data.len(), DECOUPLED_RECORD_LEN)?;
        let mut r = Reader::new(data, DECOUPLED_LM);
        let mut read_one = || -> Result<DecoupledLightmap> {
            let width = r.u16()?;
            let height = r.u16()?;
            let offset = r.i32()?;
            let mut world_to_luxel = [[0.0f32; 4]; 2];
            for row in &mut world_to_luxel {
                for v in row.iter_mut() {
                    *v = r.f32()?;
                }
            }
            Ok(DecoupledLightmap {
                width,
                height,
                offset,
                world_to_luxel,
            })
        };
        (0..self.faces.len())
            .map(|_| read_one())
            .collect::<Result<Vec<_>>>()
            .map(Some)
    }

    /// Stores `records` (one per face) as the `DECOUPLED_LM` lump.
    pub fn set_decoupled_lightmaps(&mut self, records: &[DecoupledLightmap]) {
        let mut data = Vec::with_capacity(records.len() * DECOUPLED_RECORD_LEN);
        for r in records {
            data.put_u16(r.width);
            data.put_u16(r.height);
            data.put_i32(r.offset);
            for v in r.world_to_luxel.iter().flatten() {
                data.put_f32(*v);
            }
        }
        self.set_bspx_lump(DECOUPLED_LM, data);
    }

    /// The BSPX lump `lump`, if the file has it, read as one `record`-byte record per face, each
    /// by `read`.
    pub(crate) fn read_per_face<T>(
        &self,
        lump: &'static str,
        record: usize,
        mut read: impl FnMut(&mut Reader) -> Result<T>,
    ) -> Result<Option<Vec<T>>> {
        let Some(data) = self.bspx_lump(lump) else {
            return Ok(None);
        };
        self.per_face_records(lump, data.len(), record)?;
        let mut r = Reader::new(data, lump);
        (0..self.faces.len())
            .map(|_| read(&mut r))
            .collect::<Result<Vec<_>>>()
            .map(Some)
    }

    /// Stores `items` (one per face) as the BSPX lump `lump`, each `record` bytes by `write`,
    /// replacing any earlier one; when every item is `unused` the lump is left out.
    pub(crate) fn write_per_face<T>(
        &mut self,
        lump: &'static str,
        record: usize,
        items: &[T],
        unused: impl Fn(&T) -> bool,
        mut write: impl FnMut(&mut Vec<u8>, &T),
    ) {
        if items.iter().all(unused) {
            self.remove_bspx_lump(lump);
            return;
        }
        let mut data = Vec::with_capacity(items.len() * record);
        for item in items {
            write(&mut data, item);
        }
        self.set_bspx_lump(lump, data);
    }

    /// Checks that a per-face lump of `len` bytes holds one `record`-byte record per face.
    pub(crate) fn per_face_records(
        &self,
        lump: &'static str,
        len: usize,
        record: usize,
    ) -> Result<()> {
        if !len.is_multiple_of(record) {
            return Err(FormatError::LumpSize {
                lump,
                length: len,
                record,
            });
        }
        if len / record != self.faces.len() {
            return Err(FormatError::BadLump {
                lump,
                detail: format!("{} records for {} faces", len / record, self.faces.len()),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn per_face_lumps_round_trip_through_the_file() {
        let mut bsp = crate::bsp::bsp_with_faces(2);
        assert_eq!(bsp.decoupled_lightmaps().expect("none"), None);
        let records = [
            DecoupledLightmap {
                width: 9,
                height: 3,
                offset: 40,
                world_to_luxel: [[0.125, 0.0, 0.0, -2.0], [0.0, 0.0, -0.125, 7.5]],
            },
            DecoupledLightmap {
                width: 0,
                height: 0,
                offset: -1,
                world_to_luxel: [[0.0; 4]; 2],
            },
        ];
        bsp.set_decoupled_lightmaps(&records);
        bsp.set_shifted_lightmaps(&[3, 4], &[0, -1]);
        bsp.set_shifted_lightmaps(&[3, 5], &[0, -1]);
        assert_eq!(bsp.bspx.len(), 3, "replaced, not added");
        let read = Bsp::read(&bsp.write().expect("write")).expect("read");
        assert_eq!(
            read.decoupled_lightmaps().expect("lump"),
            Some(records.to_vec())
        );
        assert_eq!(read.lightmap_shifts().expect("lump"), Some(vec![3, 5]));
        assert_eq!(read.lightmap_offsets().expect("lump"), Some(vec![0, -1]));
        assert_eq!(records[0].grid().luxel_at([16.0, 0.0, 0.0]), [0.0, 7.5]);
    }

    #[test]
    fn per_face_lumps_of_the_wrong_length_are_errors() {
        let mut bsp = crate::bsp::bsp_with_faces(2);
        bsp.set_bspx_lump(LMSHIFT, vec![4; 3]);
        assert!(bsp.lightmap_shifts().is_err());
        bsp.set_bspx_lump(LMOFFSET, vec![0; 7]);
        assert!(bsp.lightmap_offsets().is_err());
        bsp.set_bspx_lump(DECOUPLED_LM, vec![0; DECOUPLED_RECORD_LEN]);
        assert!(
            bsp.decoupled_lightmaps().is_err(),
            "one record for two faces"
        );
    }

    #[test]
    fn without_a_grey_lump_the_luxels_are_rgblighting_s() {
        let mut bsp = crate::bsp::bsp_with_faces(0);
        assert_eq!(bsp.luxel_count(), 0);
        bsp.set_bspx_lump(RGBLIGHTING, vec![0; 30]);
        assert_eq!(bsp.luxel_count(), 10);
        bsp.lighting = vec![0; 10];
        assert_eq!(bsp.luxel_count(), 10);
        bsp.remove_bspx_lump(RGBLIGHTING);
        assert!(bsp.bspx_lump(RGBLIGHTING).is_none());
    }
}
