//! `SLIPGATE_PHONG`: Slipgate's own BSPX lump that says which faces `_phong`
//! smooths together, for entities whose brushes the compiler merges into
//! the world (`func_detail*`, `func_group`), where the light tool could not
//! otherwise tell their faces apart.
//!
//! One 8-byte record per face, in face order (the lump is as long as the face
//! lump has records): `u32` group and `f32` phong angle in degrees,
//! little-endian. Group 0 means "no group" (the angle is then 0); faces with
//! the same non-zero group smooth together, within that group's angle. When a
//! group has an angle of its own for concave joints (`_phong_angle_concave`),
//! `SLIPGATE_PHONGCONCAVE` holds one `f32` per face: that angle, 0 for the
//! phong angle. Engines ignore BSPX lumps they do not know, so the file stays
//! playable.

use super::Bsp;
use crate::bytes::{PutLe, Reader};
use crate::error::{FormatError, Result};

/// The lump's BSPX name.
pub const LUMP_NAME: &str = "SLIPGATE_PHONG";
const RECORD_LEN: usize = 8;
/// The lump of the concave angles, when a face has one.
pub const CONCAVE_LUMP_NAME: &str = "SLIPGATE_PHONGCONCAVE";

/// The phong angle (degrees) when `_phong 1` gives none (ericw-tools' default:
/// a box's 90° edges stay sharp).
pub const DEFAULT_ANGLE: f64 = 89.0;

/// The phong angle an entity's `_phong` and `_phong_angle` values ask for, or
/// `None` if it asks for no smoothing. A positive `_phong_angle` turns
/// smoothing on by itself; angles above 180° mean 180°.
pub fn angle_from_keys(phong: Option<f64>, phong_angle: Option<f64>) -> Option<f64> {
    let angle = phong_angle.filter(|a| *a > 0.0);
    (phong == Some(1.0) || angle.is_some()).then(|| angle.unwrap_or(DEFAULT_ANGLE).min(180.0))
}

/// The concave angle `_phong_angle_concave` asks for: 0 (the phong angle) when unset or not
/// positive, at most 180°.
pub fn concave_from_key(phong_angle_concave: Option<f64>) -> f32 {
    phong_angle_concave
        .filter(|a| *a > 0.0)
        .map_or(0.0, |a| a.min(180.0) as f32)
}

/// One face's record.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FacePhong {
    /// Faces with the same non-zero group smooth together; 0: none.
    pub group: u32,
    /// The group's phong angle in degrees (0 for group 0).
    pub angle: f32,
    /// The group's angle for concave joints (`_phong_angle_concave`; 0: `angle`).
    pub concave: f32,
}

impl Bsp {
    /// The `SLIPGATE_PHONG` records, one per face, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::LumpSize`] or [`FormatError::BadLump`] when the lump's
    /// length does not match the face count or an angle is not a number in
    /// (0, 180] for a grouped face.
    pub fn phong_faces(&self) -> Result<Option<Vec<FacePhong>>> {
        let Some(data) = self.bspx_lump(LUMP_NAME) else {
            return Ok(None);
        };
        let count = self.faces.len();
        self.per_face_records(LUMP_NAME, data.len(), RECORD_LEN)?;
        let concave = self.bspx_lump(CONCAVE_LUMP_NAME);
        if let Some(c) = concave {
            self.per_face_records(CONCAVE_LUMP_NAME, c.len(), 4)?;
        }
        let mut r = Reader::new(data, LUMP_NAME);
        let mut c = concave.map(|c| Reader::new(c, CONCAVE_LUMP_NAME));
        (0..count)
            .map(|i| {
                let record = FacePhong {
                    group: r.u32()?,
                    angle: r.f32()?,
                    concave: c.as_mut().map_or(Ok(0.0), Reader::f32)?,
                };
                let angle_ok = record.angle > 0.0 && record.angle <= 180.0;
                let concave_ok = (0.0..=180.0).contains(&record.concave);
                if record.group != 0 && !(angle_ok && concave_ok) {
                    return Err(FormatError::BadLump {
                        lump: LUMP_NAME,
                        detail: format!(
                            "face {i}: phong angle {} (concave {}) is not in (0, 180]",
                            record.angle, record.concave
                        ),
                    });
                }
                Ok(record)
            })
            .collect::<Result<Vec<_>>>()
            .map(Some)
    }

    /// Stores `records` (one per face) as the `SLIPGATE_PHONG` lump (and their
    /// concave angles as `SLIPGATE_PHONGCONCAVE` when a face has one), replacing
    /// any earlier ones; with no grouped face they are left out.
    pub fn set_phong_faces(&mut self, records: &[FacePhong]) {
        self.write_per_face(
            LUMP_NAME,
            RECORD_LEN,
            records,
            |r| r.group == 0,
            |data, r| {
                data.put_u32(r.group);
                data.put_f32(r.angle);
            },
        );
        // The concave angles only beside the groups, and only when some face has one.
        let ungrouped = records.iter().all(|r| r.group == 0);
        self.write_per_face(
            CONCAVE_LUMP_NAME,
            4,
            records,
            |r| ungrouped || r.concave == 0.0,
            |data, r| data.put_f32(r.concave),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_round_trip_through_the_file() {
        let mut bsp = crate::bsp::bsp_with_faces(3);
        assert_eq!(bsp.phong_faces().expect("no lump"), None);
        let records = [
            FacePhong::default(),
            FacePhong {
                group: 2,
                angle: 60.0,
                concave: 0.0,
            },
            FacePhong {
                group: 2,
                angle: 60.0,
                concave: 0.0,
            },
        ];
        bsp.set_phong_faces(&records);
        bsp.set_phong_faces(&records);
        assert_eq!(bsp.bspx.len(), 1, "replaced, not added");
        let read = Bsp::read(&bsp.write().expect("write")).expect("read");
        assert_eq!(read.phong_faces().expect("lump"), Some(records.to_vec()));
        let mut concave = records;
        concave[1].concave = 10.0;
        bsp.set_phong_faces(&concave);
        assert_eq!(bsp.bspx.len(), 2, "and the concave angles");
        let read = Bsp::read(&bsp.write().expect("write")).expect("read");
        assert_eq!(read.phong_faces().expect("lump"), Some(concave.to_vec()));
        bsp.set_phong_faces(&records);
        assert_eq!(bsp.bspx.len(), 1, "no concave angle, no lump of them");
        bsp.set_phong_faces(&[FacePhong::default(); 3]);
        assert!(bsp.bspx.is_empty(), "no groups, no lump");
    }

    #[test]
    fn damaged_lumps_are_errors() {
        let mut bsp = crate::bsp::bsp_with_faces(2);
        let grouped = FacePhong {
            group: 1,
            angle: 89.0,
            concave: 0.0,
        };
        bsp.set_phong_faces(&[grouped; 3]);
        assert!(bsp.phong_faces().is_err(), "3 records for 2 faces");
        bsp.set_phong_faces(&[
            grouped,
            FacePhong {
                group: 1,
                angle: f32::NAN,
                concave: 0.0,
            },
        ]);
        assert!(bsp.phong_faces().is_err(), "NaN angle");
        bsp.bspx[0].data.pop();
        assert!(bsp.phong_faces().is_err(), "not whole records");
    }

    #[test]
    fn keys_give_the_angle() {
        assert_eq!(angle_from_keys(None, None), None);
        assert_eq!(angle_from_keys(Some(0.0), None), None);
        assert_eq!(angle_from_keys(Some(1.0), None), Some(DEFAULT_ANGLE));
        assert_eq!(angle_from_keys(None, Some(45.0)), Some(45.0));
        assert_eq!(angle_from_keys(Some(1.0), Some(500.0)), Some(180.0));
        assert_eq!(angle_from_keys(None, Some(-5.0)), None);
    }
}
