//! Potentially-visible-set culling: a light can only reach a world face if
//! one of the leaves that hold the face is in the PVS of the light's leaf, and
//! a face can only see the sky if one of its leaves sees a leaf holding a sky
//! face. Anything without vis data (no vis lump, a leaf without a row, a
//! light in solid, a brush-model face) is treated as visible; a world face that no leaf
//! holds (buried in solid, where ericw-tools' qbsp keeps some detail faces) is seen from no
//! leaf, as ericw-tools' empty PVS for it says. Bounced light from
//! points ([`crate::bounce::points`]) is the exception: it follows ericw-tools'
//! rule, which is not conservative (see [`Visibility::sees_all`]).

use glam::DVec3;
use std::collections::BTreeMap;

use quake_formats::Bsp;
use quake_formats::PvsRow;
use quake_formats::bsp::contents;
use quake_formats::geom::Bounds;

use crate::faces::{FaceGeom, FaceKind};

/// At most this many boxes stand for the sky a face sees (each direction of
/// each face is tested against all of them).
const MAX_SKY_BOXES: usize = 16;

/// Decompressed PVS rows plus which leaves hold each face.
pub struct Visibility {
    /// Row per leaf (bit `j` = leaf `j + 1`), `None` = sees everything.
    rows: Vec<Option<Vec<u8>>>,
    /// World leaves holding each face (empty for brush-model faces).
    face_leafs: Vec<Vec<u32>>,
    /// Per face: a world face no leaf holds, in a map with vis data (buried in solid: seen
    /// from nowhere).
    unheld: Vec<bool>,
    /// Per leaf: its PVS holds a leaf with a sky face.
    leaf_sees_sky: Vec<bool>,
    /// Each leaf that holds sky faces, with the box around them.
    sky_leaf_bounds: Vec<(u32, Bounds)>,
    leaf_contents: Vec<i32>,
}

/// Whether PVS row `row` (bit `j` = leaf `j + 1`) holds `leaf`.
pub fn bit(row: &[u8], leaf: u32) -> bool {
    // Leaf 0 (the shared solid leaf) has no bit.
    leaf > 0
        && row
            .get((leaf as usize - 1) / 8)
            .is_some_and(|b| b & (1 << ((leaf - 1) % 8)) != 0)
}

impl Visibility {
    pub fn new(bsp: &Bsp, faces: &[FaceGeom]) -> Visibility {
        // Damaged or truncated rows count as seeing everything: culling must stay conservative.
        let rows: Vec<Option<Vec<u8>>> = (0..bsp.leafs.len())
            .map(|leaf| match bsp.pvs_row(leaf) {
                Ok(PvsRow::Row {
                    bits,
                    complete: true,
                }) => Some(bits),
                _ => None,
            })
            .collect();
        let mut face_leafs = vec![Vec::new(); faces.len()];
        for (leaf_index, leaf) in bsp.leafs.iter().enumerate() {
            let first = leaf.first_marksurface as usize;
            let marks = bsp
                .marksurfaces
                .get(first..first + leaf.num_marksurfaces as usize)
                .unwrap_or(&[]);
            for &f in marks {
                // Some compilers also mark brush-model faces; those move, so never cull them.
                if faces.get(f as usize).is_some_and(|g| g.model == 0) {
                    face_leafs[f as usize].push(leaf_index as u32);
                }
            }
        }
        let mut sky_boxes: BTreeMap<u32, Bounds> = BTreeMap::new();
        for f in faces.iter().filter(|f| f.kind == FaceKind::Sky) {
            for &leaf in &face_leafs[f.index] {
                let b = sky_boxes.entry(leaf).or_insert(Bounds::EMPTY);
                for &p in &f.points {
                    b.add_point(p);
                }
            }
        }
        let sky_leaf_bounds: Vec<(u32, Bounds)> = sky_boxes.into_iter().collect();
        let sky_leafs: Vec<u32> = sky_leaf_bounds.iter().map(|(l, _)| *l).collect();
        let leaf_sees_sky = rows
            .iter()
            .enumerate()
            .map(|(leaf, row)| match row {
                None => true,
                Some(row) => sky_leafs.iter().any(|&s| s as usize == leaf || bit(row, s)),
            })
            .collect();
        let has_vis = rows.iter().any(Option::is_some);
        let unheld = faces
            .iter()
            .zip(&face_leafs)
            .map(|(f, leafs)| has_vis && f.model == 0 && leafs.is_empty())
            .collect();
        Visibility {
            rows,
            face_leafs,
            unheld,
            leaf_sees_sky,
            sky_leaf_bounds,
            leaf_contents: bsp.leafs.iter().map(|l| l.contents).collect(),
        }
    }

    /// The world leaf containing `p`, unless it is solid (no culling then).
    pub fn open_leaf_at(&self, bsp: &Bsp, p: DVec3) -> Option<u32> {
        let leaf = bsp.leaf_at(p.as_vec3().to_array())?;
        (self.leaf_contents.get(leaf) != Some(&contents::SOLID)).then_some(leaf as u32)
    }

    fn is_liquid(&self, leaf: u32) -> bool {
        self.leaf_contents
            .get(leaf as usize)
            .is_some_and(|&c| contents::is_liquid(c))
    }

    /// False only if vis data proves nothing in `light_leaf` can see `face`.
    /// Light crossing a liquid surface is never culled: some vis tools treat
    /// liquids as opaque, but light passes through them. A world face no leaf holds
    /// ([`Visibility::unheld`]) is seen from no leaf with vis data, as ericw-tools' empty PVS
    /// for it says (a light in solid, sky or a liquid still may reach it).
    pub fn may_reach(&self, light_leaf: Option<u32>, face: usize) -> bool {
        if self.unheld(face) {
            return light_leaf.is_none_or(|l| {
                !matches!(self.rows.get(l as usize), Some(Some(_)))
                    || self.is_liquid(l)
                    || self.leaf_contents.get(l as usize) == Some(&contents::SKY)
            });
        }
        self.may_reach_leafs(light_leaf, &self.face_leafs[face])
    }

    /// Whether `face` is a world face that no leaf holds in a map with vis data: buried in
    /// solid, drawn from nowhere (ericw-tools' qbsp keeps some such detail faces).
    pub fn unheld(&self, face: usize) -> bool {
        self.unheld.get(face).copied().unwrap_or(false)
    }

    /// False only if vis data proves nothing in `light_leaf` can see any of `leafs` (none:
    /// cannot tell).
    pub fn may_reach_leafs(&self, light_leaf: Option<u32>, leafs: &[u32]) -> bool {
        let Some(light_leaf) = light_leaf else {
            return true;
        };
        let Some(Some(row)) = self.rows.get(light_leaf as usize) else {
            return true;
        };
        leafs.is_empty()
            || self.is_liquid(light_leaf)
            || leafs
                .iter()
                .any(|&l| l == light_leaf || bit(row, l) || self.is_liquid(l))
    }

    /// The world leaves holding `face` (empty for brush-model faces: cannot tell).
    pub fn face_leafs(&self, face: usize) -> &[u32] {
        self.face_leafs.get(face).map_or(&[], |l| &l[..])
    }

    /// The union of the PVS rows of `leafs`, with their own bits set: what any of them may see.
    /// `None` when vis data cannot tell (no leaves, a leaf without a row, a liquid leaf).
    pub fn pvs_of(&self, leafs: &[u32]) -> Option<Vec<u8>> {
        if leafs.is_empty() {
            return None;
        }
        let mut union = vec![0u8; self.rows.len().div_ceil(8)];
        for &l in leafs {
            let row = self.rows.get(l as usize)?.as_ref()?;
            if self.is_liquid(l) {
                return None;
            }
            for (u, r) in union.iter_mut().zip(row) {
                *u |= r;
            }
            if l > 0 {
                union[(l as usize - 1) / 8] |= 1 << ((l - 1) % 8);
            }
        }
        Some(union)
    }

    /// Whether `pvs` (from [`Visibility::pvs_of`]) may see every one of `leafs` (liquid leaves
    /// always count as seen; no leaves: cannot tell, seen). Not conservative: bounced light from
    /// a point culls an emitter whose face is only partly in sight, as ericw-tools culls it.
    pub fn sees_all(&self, pvs: &[u8], leafs: &[u32]) -> bool {
        leafs.iter().all(|&l| bit(pvs, l) || self.is_liquid(l))
    }

    /// Whether an emitter on a face held by `leafs` is in sight of `pvs` (from
    /// [`Visibility::pvs_of`]) for bounced light from points: one of its leaves is in the PVS and
    /// [`Visibility::sees_all`] of them (a face no leaf holds, a brush model's: in sight).
    pub fn in_pvs(&self, pvs: &[u8], leafs: &[u32]) -> bool {
        leafs.is_empty() || (leafs.iter().any(|&l| bit(pvs, l)) && self.sees_all(pvs, leafs))
    }

    /// False only if vis data proves `face` cannot see any sky face.
    pub fn may_see_sky(&self, face: usize) -> bool {
        self.leafs_may_see_sky(&self.face_leafs[face])
    }

    /// False only if vis data proves none of `leafs` can see any sky face (none: cannot tell).
    pub fn leafs_may_see_sky(&self, leafs: &[u32]) -> bool {
        leafs.is_empty()
            || leafs
                .iter()
                .any(|&l| self.leaf_sees_sky.get(l as usize).copied().unwrap_or(true))
    }

    /// Boxes around the sky faces `face` may see, one per leaf holding
    /// them; `None` when vis data cannot tell (every direction may reach sky).
    pub fn visible_sky_bounds(&self, face: usize) -> Option<Vec<Bounds>> {
        self.sky_bounds_seen_from(&self.face_leafs[face])
    }

    /// Boxes around the sky faces any of `leafs` may see, one per leaf holding them (merged
    /// down to a few); `None` when vis data cannot tell (every direction may reach sky).
    pub fn sky_bounds_seen_from(&self, leafs: &[u32]) -> Option<Vec<Bounds>> {
        if leafs.is_empty() {
            return None;
        }
        let mut seen = vec![false; self.sky_leaf_bounds.len()];
        for &l in leafs {
            let row = self.rows.get(l as usize)?.as_ref()?;
            for (k, (s, _)) in self.sky_leaf_bounds.iter().enumerate() {
                seen[k] |= *s == l || bit(row, *s);
            }
        }
        let visible: Vec<Bounds> = self
            .sky_leaf_bounds
            .iter()
            .zip(seen)
            .filter(|(_, seen)| *seen)
            .map(|((_, b), _)| *b)
            .collect();
        // Leaves next to each other in the BSP's order are mostly near each
        // other: merging runs of them keeps the per-direction test cheap.
        let run = visible.len().div_ceil(MAX_SKY_BOXES).max(1);
        Some(
            visible
                .chunks(run)
                .map(|c| c.iter().fold(Bounds::EMPTY, |u, b| u.union(b)))
                .collect(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::faces::FaceGeom;
    use quake_formats::bsp::{Leaf, Model};
    use quake_formats::geom::Plane;

    fn face(index: usize, model: usize) -> FaceGeom {
        FaceGeom::for_test(
            index,
            model,
            Vec::new(),
            Plane::new(DVec3::new(0.0, 0.0, 1.0), 0.0),
        )
    }

    /// Leaves 1 and 2 see only themselves; both faces are marked in leaf 2.
    fn two_rooms(leaf2_contents: i32) -> (Bsp, Vec<FaceGeom>) {
        let mut bsp = Bsp::default();
        let leaf = |contents, vis_offset, first| Leaf {
            contents,
            vis_offset,
            mins: [0.0; 3],
            maxs: [0.0; 3],
            first_marksurface: first,
            num_marksurfaces: if first == 0 { 0 } else { 2 },
            ambient: [0; 4],
        };
        bsp.leafs = vec![
            leaf(contents::SOLID, -1, 0),
            leaf(contents::EMPTY, 0, 0),
            leaf(leaf2_contents, 1, 0),
        ];
        bsp.leafs[2].num_marksurfaces = 2;
        bsp.marksurfaces = vec![0, 1];
        bsp.visibility = vec![0b01, 0b10];
        bsp.models = vec![Model {
            mins: [0.0; 3],
            maxs: [0.0; 3],
            origin: [0.0; 3],
            head_nodes: [0; 4],
            vis_leafs: 2,
            first_face: 0,
            num_faces: 1,
        }];
        (bsp, vec![face(0, 0), face(1, 1)])
    }

    #[test]
    fn pvs_culls_world_faces_but_never_brush_model_faces() {
        let (bsp, faces) = two_rooms(contents::EMPTY);
        let vis = Visibility::new(&bsp, &faces);
        assert!(!vis.may_reach(Some(1), 0), "world face in an unseen leaf");
        assert!(vis.may_reach(Some(2), 0));
        // Regression: marksurfaces listing a door's faces made lights skip the door.
        assert!(vis.may_reach(Some(1), 1));
        assert!(vis.may_reach(None, 0), "light in solid: no culling");
    }

    /// A world face no leaf holds (buried in solid) is culled for a light in any leaf with a
    /// PVS row, as ericw-tools' empty PVS for it culls; a light in solid still may reach it, and
    /// without vis data nothing is culled.
    #[test]
    fn a_world_face_no_leaf_holds_is_seen_from_no_leaf() {
        let (bsp, mut faces) = two_rooms(contents::EMPTY);
        faces.push(face(2, 0));
        let vis = Visibility::new(&bsp, &faces);
        assert!(vis.unheld(2) && !vis.unheld(0) && !vis.unheld(1));
        assert!(!vis.may_reach(Some(1), 2) && !vis.may_reach(Some(2), 2));
        assert!(vis.may_reach(None, 2), "light in solid");
        let mut no_vis = bsp.clone();
        no_vis.visibility.clear();
        for leaf in &mut no_vis.leafs {
            leaf.vis_offset = -1;
        }
        let vis = Visibility::new(&no_vis, &faces);
        assert!(!vis.unheld(2) && vis.may_reach(Some(1), 2));
    }

    #[test]
    fn light_into_liquid_is_not_culled() {
        let (bsp, faces) = two_rooms(contents::WATER);
        let vis = Visibility::new(&bsp, &faces);
        assert!(vis.may_reach(Some(1), 0));
    }
}
