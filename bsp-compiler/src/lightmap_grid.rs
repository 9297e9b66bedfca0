//! Texture offsets nudged so that every engine gives each lit face the same lightmap.
//!
//! QuakeSpasm's family and DarkPlaces compute a face's texture coordinates in different precision
//! ([`LightmapExtents::from_points`], [`LightmapExtents::from_points_darkplaces`]). A vertex whose
//! coordinate lies within a few `f32` steps of a 16-texel grid line (common on rotated brushes,
//! whose textures are turned with them) can snap to different lines in the two, and one engine
//! then reads the face's lightmap with the wrong row length or origin. Once the final vertices
//! are known (after welding and T-junction fixing), each texinfo with such a face has its offset
//! on the affected axis moved by the first of [`NUDGE_STEPS`] that leaves every face using it
//! agreeing. The texture then moves by that step (plus the rounding of the `f32` offset) and no
//! more: at most 1/8 texel, which no one sees. Faces that need different steps get texinfos of
//! their own while the texinfo limit allows.

use quake_formats::Bsp;
use quake_formats::bsp::limits::{BSP29_MAX_TEXINFO, MAX_SURFACE_EXTENT};
use quake_formats::bsp::texinfo_flags;
use quake_formats::extents::LightmapExtents;
use std::collections::{BTreeMap, HashMap};

/// Offsets tried, in texels, in order (after leaving the offset as it is): the smallest moves
/// first, each in both directions. A coordinate within a few `f32` steps of a grid line ends up
/// 1/32 texel from it, far beyond any rounding, unless another vertex lands near a line then.
pub const NUDGE_STEPS: [f32; 8] = [
    1.0 / 32.0,
    -1.0 / 32.0,
    1.0 / 16.0,
    -1.0 / 16.0,
    3.0 / 32.0,
    -3.0 / 32.0,
    1.0 / 8.0,
    -1.0 / 8.0,
];

/// What `agree_on_lightmap_grid` changed, for the compile summary.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct LightmapGridStats {
    /// Lit faces whose extents the engines computed differently before.
    pub faces_disagreeing: usize,
    /// Texinfos whose offsets were nudged.
    pub nudged_texinfos: usize,
    /// Texinfos added for faces that needed another nudge than the rest of their texinfo.
    pub split_texinfos: usize,
    /// Lit faces the engines still disagree about: no step fixed them, or the texinfo limit
    /// stopped a split.
    pub unresolved_faces: usize,
}

/// A lit face's index and vertices.
struct LitFace {
    index: usize,
    points: Vec<[f32; 3]>,
}

/// Nudge the texture offsets of `bsp` until QuakeSpasm and DarkPlaces agree on every lit face's
/// lightmap extents (see the module documentation).
pub(crate) fn agree_on_lightmap_grid(bsp: &mut Bsp) -> LightmapGridStats {
    let mut stats = LightmapGridStats::default();
    let mut by_texinfo: BTreeMap<u32, Vec<LitFace>> = BTreeMap::new();
    for (index, face) in bsp.faces.iter().enumerate() {
        let Some(tex) = bsp.texinfo.get(face.texinfo as usize) else {
            continue;
        };
        if tex.flags & texinfo_flags::SPECIAL != 0 {
            continue;
        }
        let Some(points) = bsp.face_vertices(face) else {
            continue;
        };
        by_texinfo
            .entry(face.texinfo)
            .or_default()
            .push(LitFace { index, points });
    }
    let limit = if bsp.version.has_wide_indices() || bsp.texinfo.len() > BSP29_MAX_TEXINFO {
        usize::MAX
    } else {
        BSP29_MAX_TEXINFO
    };
    for (texinfo, faces) in by_texinfo {
        let vecs = bsp.texinfo[texinfo as usize].vecs;
        let before = faces
            .iter()
            .filter(|f| LightmapExtents::engines_disagree(&f.points, &vecs) != [false, false])
            .count();
        if before == 0 {
            continue;
        }
        stats.faces_disagreeing += before;
        let plan = [0, 1].map(|axis| plan_axis(&faces, &vecs, axis));
        // Faces grouped by the steps their axes take; the group of the steps most faces share
        // keeps the texinfo.
        let primary = [plan[0].primary, plan[1].primary];
        let mut groups: BTreeMap<[usize; 2], Vec<usize>> = BTreeMap::new();
        for (k, f) in faces.iter().enumerate() {
            let key = [plan[0].steps[k], plan[1].steps[k]];
            groups.entry(key).or_default().push(f.index);
        }
        if primary != [0, 0] {
            stats.nudged_texinfos += 1;
            bsp.texinfo[texinfo as usize].vecs = nudged(&vecs, primary);
        }
        let mut new_index: HashMap<usize, u32> = HashMap::new();
        for (key, members) in groups {
            if key == primary || bsp.texinfo.len() >= limit {
                continue;
            }
            let mut info = bsp.texinfo[texinfo as usize];
            info.vecs = nudged(&vecs, key);
            bsp.texinfo.push(info);
            stats.split_texinfos += 1;
            let id = (bsp.texinfo.len() - 1) as u32;
            for m in members {
                new_index.insert(m, id);
            }
        }
        for f in &faces {
            if let Some(&id) = new_index.get(&f.index) {
                bsp.faces[f.index].texinfo = id;
            }
            let now = bsp.texinfo[bsp.faces[f.index].texinfo as usize].vecs;
            if LightmapExtents::engines_disagree(&f.points, &now) != [false, false] {
                stats.unresolved_faces += 1;
            }
        }
    }
    stats
}

/// For one axis of one texinfo: the step (index into `0 ∪ NUDGE_STEPS`) each face takes, and
/// the step most faces agree under.
struct AxisPlan {
    /// Per face: the primary step when the face agrees under it, else the first step it agrees
    /// under, else (nothing helps) the primary.
    steps: Vec<usize>,
    primary: usize,
}

/// Steps as indices: 0 leaves the offset, `i > 0` adds `NUDGE_STEPS[i - 1]`.
const STEP_COUNT: usize = NUDGE_STEPS.len() + 1;

fn plan_axis(faces: &[LitFace], vecs: &[[f32; 4]; 2], axis: usize) -> AxisPlan {
    // works[k][s]: face k agrees on this axis under step s, and its lightmap grows past neither
    // the size it had nor the vanilla limit subdivision kept it within.
    let works: Vec<[bool; STEP_COUNT]> = faces
        .iter()
        .map(|f| {
            let size = LightmapExtents::from_points(&f.points, vecs).extents[axis];
            let max_size = size.max(MAX_SURFACE_EXTENT);
            std::array::from_fn(|s| {
                let mut v = *vecs;
                v[axis][3] = offset_with_step(v[axis][3], s);
                !LightmapExtents::engines_disagree(&f.points, &v)[axis]
                    && LightmapExtents::from_points(&f.points, &v).extents[axis] <= max_size
            })
        })
        .collect();
    let covered = |s: usize| works.iter().filter(|w| w[s]).count();
    // The earliest of the steps that cover the most faces.
    let primary = (1..STEP_COUNT).fold(
        0,
        |best, s| {
            if covered(s) > covered(best) { s } else { best }
        },
    );
    let steps = works
        .iter()
        .map(|w| {
            if w[primary] {
                primary
            } else {
                (0..STEP_COUNT).find(|&s| w[s]).unwrap_or(primary)
            }
        })
        .collect();
    AxisPlan { steps, primary }
}

fn offset_with_step(offset: f32, step: usize) -> f32 {
    match step {
        0 => offset,
        s => offset + NUDGE_STEPS[s - 1],
    }
}

fn nudged(vecs: &[[f32; 4]; 2], steps: [usize; 2]) -> [[f32; 4]; 2] {
    let mut v = *vecs;
    for axis in 0..2 {
        v[axis][3] = offset_with_step(v[axis][3], steps[axis]);
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::BspVersion;
    use quake_formats::bsp::{Face, TexInfo};

    /// s along a texture turned 10 degrees; t constant (0.5) on the z = 0 plane.
    const VECS: [[f32; 4]; 2] = [
        [0.984_807_7, -0.173_648_18, 0.0, 3.661_621],
        [0.0, 0.0, -1.0, 0.5],
    ];

    fn add_face(bsp: &mut Bsp, points: &[[f32; 3]]) {
        let first_edge = bsp.surfedges.len() as u32;
        let first_vertex = bsp.vertices.len() as u32;
        bsp.vertices.extend_from_slice(points);
        let n = points.len() as u32;
        for k in 0..n {
            bsp.surfedges.push(bsp.edges.len() as i32);
            bsp.edges
                .push([first_vertex + k, first_vertex + (k + 1) % n]);
        }
        bsp.faces.push(Face {
            plane: 0,
            side: 0,
            first_edge,
            num_edges: n,
            texinfo: 0,
            styles: [0, 255, 255, 255],
            light_offset: -1,
        });
    }

    /// Face 0 has a vertex the engines snap to different grid lines, fixed by every step; each
    /// of faces 1-4 agrees as it is but has its extreme vertices where two of the steps make the
    /// engines disagree. No step suits all five: face 0 gets a texinfo of its own, nudged by the
    /// first step, and the rest keep theirs.
    fn conflicting_faces() -> Bsp {
        let mut bsp = Bsp::new(BspVersion::Bsp29);
        bsp.edges.push([0, 0]);
        bsp.texinfo.push(TexInfo {
            vecs: VECS,
            miptex: 0,
            flags: 0,
        });
        let faces: [[[f32; 3]; 3]; 5] = [
            [
                [160.220_55, 469.040_65, 0.0],
                [130.0, 469.040_65, 0.0],
                [130.0, 440.0, 0.0],
            ],
            [
                [1_490.782_7, 275.425_72, 0.0],
                [641.025_15, 155.008_35, 0.0],
                [1_065.903_9, 282.425_72, 0.0],
            ],
            [
                [311.087_04, 311.463_26, 0.0],
                [273.870_97, 468.242_03, 0.0],
                [292.479, 475.242_03, 0.0],
            ],
            [
                [2_350.862, 454.381, 0.0],
                [1_534.156_9, 336.412_54, 0.0],
                [1_942.509_5, 461.381, 0.0],
            ],
            [
                [2_236.942_9, 177.054_69, 0.0],
                [1_977.521_5, 270.749_05, 0.0],
                [2_107.232_2, 277.749_05, 0.0],
            ],
        ];
        for f in &faces {
            add_face(&mut bsp, f);
        }
        bsp
    }

    fn disagreeing(bsp: &Bsp) -> Vec<usize> {
        (0..bsp.faces.len())
            .filter(|&i| {
                let points = bsp.face_vertices(&bsp.faces[i]).expect("face");
                let vecs = bsp.texinfo[bsp.faces[i].texinfo as usize].vecs;
                LightmapExtents::engines_disagree(&points, &vecs) != [false, false]
            })
            .collect()
    }

    #[test]
    fn faces_needing_different_steps_split_their_texinfo() {
        let mut bsp = conflicting_faces();
        assert_eq!(disagreeing(&bsp), [0]);
        let stats = agree_on_lightmap_grid(&mut bsp);
        assert_eq!(
            stats,
            LightmapGridStats {
                faces_disagreeing: 1,
                nudged_texinfos: 0,
                split_texinfos: 1,
                unresolved_faces: 0,
            }
        );
        assert_eq!(disagreeing(&bsp), Vec::<usize>::new());
        assert_eq!(bsp.texinfo.len(), 2);
        assert_eq!(bsp.faces[0].texinfo, 1);
        assert!(bsp.faces[1..].iter().all(|f| f.texinfo == 0));
        assert_eq!(bsp.texinfo[0].vecs, VECS);
        assert_eq!(bsp.texinfo[1].vecs[0][3], VECS[0][3] + NUDGE_STEPS[0]);
        assert_eq!(bsp.texinfo[1].vecs[1], VECS[1]);
    }

    #[test]
    fn a_full_texinfo_table_leaves_the_face_and_counts_it() {
        let mut bsp = conflicting_faces();
        let filler = bsp.texinfo[0];
        bsp.texinfo.resize(BSP29_MAX_TEXINFO, filler);
        let stats = agree_on_lightmap_grid(&mut bsp);
        assert_eq!((stats.split_texinfos, stats.unresolved_faces), (0, 1));
        assert_eq!(bsp.texinfo.len(), BSP29_MAX_TEXINFO);
        assert_eq!(disagreeing(&bsp), [0]);
    }

    #[test]
    fn a_face_alone_is_nudged_in_place() {
        let mut bsp = conflicting_faces();
        bsp.faces.truncate(1);
        let stats = agree_on_lightmap_grid(&mut bsp);
        assert_eq!((stats.nudged_texinfos, stats.split_texinfos), (1, 0));
        assert_eq!(bsp.texinfo[0].vecs[0][3], VECS[0][3] + NUDGE_STEPS[0]);
        assert_eq!(disagreeing(&bsp), Vec::<usize>::new());
    }
}
