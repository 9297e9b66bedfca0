//! `SLIPGATE_SURFGROUP`: Slipgate's own BSPX lump that carries the `_surflight_group` of the
//! entities whose brushes the compiler merges into the world (worldspawn, `func_detail*`,
//! `func_group`), which light could not otherwise tell apart: a `_surface` light template goes
//! only on faces of its own group. Brush models' groups are in their entities, for light to read.
//!
//! One little-endian `i32` per face, in face order; 0 is no group. The lump is left out when no
//! face has a group, and engines ignore BSPX lumps they do not know.

use super::Bsp;
use crate::bytes::PutLe;
use crate::error::Result;

/// The lump's BSPX name.
pub const LUMP_NAME: &str = "SLIPGATE_SURFGROUP";
const RECORD_LEN: usize = 4;

impl Bsp {
    /// The `SLIPGATE_SURFGROUP` groups, one per face, if the file has the lump.
    ///
    /// # Errors
    /// [`FormatError::LumpSize`](crate::FormatError::LumpSize) or
    /// [`FormatError::BadLump`](crate::FormatError::BadLump) when its length does not match the
    /// face count.
    pub fn surflight_groups(&self) -> Result<Option<Vec<i32>>> {
        self.read_per_face(LUMP_NAME, RECORD_LEN, |r| r.i32())
    }

    /// Stores `groups` (one per face) as the `SLIPGATE_SURFGROUP` lump, replacing any earlier
    /// one; with no face in a group the lump is left out.
    pub fn set_surflight_groups(&mut self, groups: &[i32]) {
        self.write_per_face(
            LUMP_NAME,
            RECORD_LEN,
            groups,
            |&g| g == 0,
            |data, &g| {
                data.put_i32(g);
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_round_trip_through_the_file() {
        let mut bsp = crate::bsp::bsp_with_faces(3);
        assert_eq!(bsp.surflight_groups().expect("no lump"), None);
        let groups = [0, 7, -2];
        bsp.set_surflight_groups(&groups);
        bsp.set_surflight_groups(&groups);
        assert_eq!(bsp.bspx.len(), 1, "replaced, not added");
        let read = Bsp::read(&bsp.write().expect("write")).expect("read");
        assert_eq!(
            read.surflight_groups().expect("lump"),
            Some(groups.to_vec())
        );
        bsp.set_surflight_groups(&[0; 3]);
        assert!(bsp.bspx.is_empty(), "no groups, no lump");
    }

    #[test]
    fn a_lump_of_another_length_is_an_error() {
        let mut bsp = crate::bsp::bsp_with_faces(2);
        bsp.set_bspx_lump(LUMP_NAME, vec![1, 0, 0, 0]);
        assert!(bsp.surflight_groups().is_err(), "1 record for 2 faces");
        bsp.set_bspx_lump(LUMP_NAME, vec![1, 0, 0, 0, 2, 0, 0]);
        assert!(bsp.surflight_groups().is_err(), "not whole records");
    }
}
