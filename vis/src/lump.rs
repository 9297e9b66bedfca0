//! The BSP's visibility lump: compressed rows, shared when identical, and each leaf's offset.

use crate::VisError;
use crate::bitset::BitSet;
use crate::pvs::Pvs;
use quake_formats::Bsp;
use quake_formats::PvsRow;
use quake_formats::bsp::contents;
use quake_formats::entities::parse_entities;
use quake_formats::visrle::compress_row;
use std::collections::HashMap;

/// What writing the lump produced.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct LumpStats {
    /// Leaves with a row (BSP leaves 1..=N).
    pub vis_leafs: usize,
    /// Distinct compressed rows (identical rows are stored once).
    pub unique_rows: usize,
    /// The lump's size in bytes.
    pub compressed_bytes: usize,
    /// What the rows would take uncompressed and unshared.
    pub uncompressed_bytes: usize,
    /// Leaves each leaf's row holds, on average.
    pub average_visible: f64,
    /// The most leaves any one row holds.
    pub max_visible: usize,
}

/// The world model's vis leaf count (BSP leaves 1..=N have PVS rows).
pub fn world_vis_leafs(bsp: &Bsp) -> Result<usize, VisError> {
    let world = bsp.models.first().ok_or(VisError::NoWorldModel)?;
    let n = usize::try_from(world.vis_leafs).map_err(|_| VisError::BadVisLeafs {
        vis_leafs: world.vis_leafs as i64,
        leafs: bsp.leafs.len(),
    })?;
    if n + 1 > bsp.leafs.len() {
        return Err(VisError::BadVisLeafs {
            vis_leafs: n as i64,
            leafs: bsp.leafs.len(),
        });
    }
    Ok(n)
}

/// Refuse a BSP tools cannot read safely ([`quake_formats::check_usable`]) and a portal file made
/// for another BSP (or another compile of it).
pub fn check_portals_match(bsp: &Bsp, prt_leafs: usize) -> Result<(), VisError> {
    quake_formats::check_usable(bsp)?;
    let vis_leafs = world_vis_leafs(bsp)?;
    if vis_leafs != prt_leafs {
        return Err(VisError::LeafCountMismatch {
            prt_leafs,
            vis_leafs,
        });
    }
    check_sealed(bsp).map(|_| ())
}

/// Whether a BSP's world keeps the void outside the map, which vis then works through too.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outside {
    /// The outside was filled: open leaves lie inside the map's brushes.
    Filled,
    /// No point entity stands in the map's open space, so the compiler could not tell inside
    /// from outside and filled nothing (ericw-tools: "no filling performed"): the void's leaves
    /// are vis leaves like any other. Not a leak.
    Included {
        /// One open leaf of the void (BSP leaf number).
        leaf: usize,
    },
}

/// Refuse a BSP whose world keeps the void of a leaking map: the portals of such a map reach
/// the whole void, and flowing through them is wasted work. A void with no point entity in any
/// open leaf is a map with nothing to flood from (a test room, a prefab), which compilers leave
/// unfilled: vis includes it.
pub fn check_sealed(bsp: &Bsp) -> Result<Outside, VisError> {
    match void_leaf(bsp, world_vis_leafs(bsp)?) {
        None => Ok(Outside::Filled),
        Some(leaf) if entity_in_open_space(bsp) => Err(VisError::Void { leaf }),
        Some(leaf) => Ok(Outside::Included { leaf }),
    }
}

/// Whether a point entity of the entity lump marks open space in the world, as the compiler's
/// outside fill takes them ([`quake_formats::entities::Entity::fill_origin`]). An entity lump
/// that cannot be read says yes: vis cannot tell a map with nothing to flood from.
fn entity_in_open_space(bsp: &Bsp) -> bool {
    let Ok(entities) = parse_entities(&bsp.entity_text()) else {
        return true;
    };
    entities
        .iter()
        .skip(1)
        .filter(|e| !e.get("model").is_some_and(|m| m.starts_with('*')))
        .filter_map(|e| e.fill_origin())
        .any(|origin| {
            bsp.leaf_at(origin.map(|c| c as f32))
                .and_then(|leaf| bsp.leafs.get(leaf))
                .is_some_and(|leaf| leaf.contents != contents::SOLID)
        })
}

/// How far past the world model's bounds a leaf must reach to be the void: more than the
/// rounding of BSP29's whole-unit leaf bounds, less than the margin compilers leave between a
/// map and the box around it.
const VOID_REACH: f32 = 2.0;

/// An open world leaf of a leaking map's void, which compilers keep when they do not fill the
/// outside: open leaves reach past the world model's bounds on all six sides. A sealed map's
/// open leaves lie inside its brushes, but for a few that some compilers leave unfilled at the
/// edge of the map (ericw-tools keeps a leaf whose face also touches open space).
fn void_leaf(bsp: &Bsp, vis_leafs: usize) -> Option<usize> {
    let world = bsp.models.first()?;
    let mut beyond: [Option<usize>; 6] = [None; 6];
    for i in 1..=vis_leafs {
        let leaf = &bsp.leafs[i];
        if leaf.contents == contents::SOLID {
            continue;
        }
        for a in 0..3 {
            if leaf.mins[a] < world.mins[a] - VOID_REACH {
                beyond[2 * a].get_or_insert(i);
            }
            if leaf.maxs[a] > world.maxs[a] + VOID_REACH {
                beyond[2 * a + 1].get_or_insert(i);
            }
        }
    }
    beyond
        .iter()
        .all(Option::is_some)
        .then_some(beyond[0])
        .flatten()
}

/// Store `pvs` in `bsp`: the visibility lump and the vis offset of every leaf. Leaf 0 and the
/// leaves of brush models get -1 (no row), as engines expect.
pub fn write_vis(bsp: &mut Bsp, pvs: &Pvs) -> Result<LumpStats, VisError> {
    check_portals_match(bsp, pvs.num_leafs())?;
    let mut lump = Vec::new();
    let mut offsets: HashMap<Vec<u8>, i32> = HashMap::new();
    let mut uncompressed = 0;
    for leaf in bsp.leafs.iter_mut() {
        leaf.vis_offset = -1;
    }
    for (i, row) in pvs.rows().iter().enumerate() {
        let bytes = row.to_row_bytes();
        uncompressed += bytes.len();
        let packed = compress_row(&bytes);
        let offset = match offsets.get(&packed) {
            Some(&offset) => offset,
            None => {
                let offset = i32::try_from(lump.len()).map_err(|_| VisError::LumpTooLarge)?;
                lump.extend_from_slice(&packed);
                offsets.insert(packed, offset);
                offset
            }
        };
        bsp.leafs[i + 1].vis_offset = offset;
    }
    bsp.visibility = lump;
    Ok(LumpStats {
        vis_leafs: pvs.num_leafs(),
        unique_rows: offsets.len(),
        compressed_bytes: bsp.visibility.len(),
        uncompressed_bytes: uncompressed,
        average_visible: pvs.average_visible(),
        max_visible: pvs.max_visible(),
    })
}

/// The PVS stored in `bsp`, as engines read it. A leaf without a row (offset -1, or no
/// visibility data at all) sees everything, which is what engines do with it.
pub fn read_pvs(bsp: &Bsp) -> Result<Pvs, VisError> {
    let n = world_vis_leafs(bsp)?;
    let rows = (1..=n)
        .map(|leaf| match bsp.pvs_row(leaf) {
            Ok(PvsRow::All) => Ok(BitSet::full(n)),
            Ok(PvsRow::Row { bits, .. }) => Ok(BitSet::from_row_bytes(&bits, n)),
            Err(_) => Err(VisError::BadVisOffset {
                leaf,
                offset: bsp.leafs[leaf].vis_offset,
                lump_len: bsp.visibility.len(),
            }),
        })
        .collect::<Result<Vec<_>, VisError>>()?;
    Ok(Pvs::new(rows))
}
