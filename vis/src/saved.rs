//! Flow results kept in files: a shard's partial results (`--shard`, joined by `--merge`) and a
//! long run's saved state (`--resume`). Both hold some portals' flow results and the hash of
//! the inputs they were computed from, and are never used for other inputs.
//!
//! Layout (little-endian): the magic `SGVISFLO`, a format version (u32), the kind (u32: 0 state,
//! 1 partial), the inputs hash (16 bytes), shard index and count (u32 each), the one-way portal
//! count (u32), the number of results (u32), then per result its portal (u32), the length of
//! its row (u32) and the row: the portal set as a PVS row in Quake's zero-run compression.

use crate::bitset::BitSet;
use crate::schedule::Shard;
use quake_formats::Bsp;
use quake_formats::visrle::{compress_row, decompress_row};

const MAGIC: &[u8; 8] = b"SGVISFLO";
const VERSION: u32 = 1;

/// Why a saved file cannot be used.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum SavedError {
    /// The file lacks the magic or names an unknown kind.
    #[error("not a Slipgate vis flow file (no SGVISFLO magic)")]
    NotFlowFile,
    /// Another format version wrote the file; holds that version.
    #[error("written by format version {0}; this vis reads version {VERSION}")]
    Version(u32),
    /// A state was read where a partial was expected, or the other way round.
    #[error("is a {found}, not a {expected}")]
    Kind {
        /// What the file is.
        found: &'static str,
        /// What the reader wanted.
        expected: &'static str,
    },
    /// The data ends inside a field or a row, or goes on after the last result.
    #[error("ends early or has bytes after its last result")]
    Truncated,
    /// A result names a portal the graph does not have.
    #[error("result for portal {portal}, but the file covers {portals} one-way portals")]
    PortalOutOfRange {
        /// The portal named.
        portal: u32,
        /// One-way portals the file covers.
        portals: u32,
    },
    /// Results out of ascending portal order (a portal twice); holds the portal.
    #[error("holds portal {0} twice")]
    DuplicatePortal(u32),
    /// The shard index is not below a non-zero count.
    #[error("shard {index} of {count} is not a valid shard")]
    BadShard {
        /// The shard index, 0-based.
        index: u32,
        /// The shard count.
        count: u32,
    },
}

/// What a saved file is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SavedKind {
    /// A run's progress, to resume from.
    State,
    /// One shard's results, to merge.
    Partial,
}

impl SavedKind {
    fn code(self) -> u32 {
        match self {
            SavedKind::State => 0,
            SavedKind::Partial => 1,
        }
    }

    fn name(self) -> &'static str {
        match self {
            SavedKind::State => "vis state file",
            SavedKind::Partial => "vis partial file",
        }
    }
}

/// Flow results of some portals, with what they were computed from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SavedFlows {
    /// A state to resume from or a partial to merge.
    pub kind: SavedKind,
    /// What the results were computed from; other inputs refuse them.
    pub inputs: InputsHash,
    /// The shard that computed them ([`Shard::WHOLE`] for a whole run).
    pub shard: Shard,
    /// One-way portals in the graph (each result's length).
    pub portals: usize,
    /// Results by portal, ascending.
    pub results: Vec<(usize, BitSet)>,
}

impl SavedFlows {
    /// The file's bytes; [`SavedFlows::read`] reads them back.
    pub fn write(&self) -> Vec<u8> {
        let mut out = Vec::new();
        out.extend_from_slice(MAGIC);
        for word in [VERSION, self.kind.code()] {
            out.extend_from_slice(&word.to_le_bytes());
        }
        out.extend_from_slice(&self.inputs.0.to_le_bytes());
        let counts = [
            self.shard.index,
            self.shard.count,
            self.portals,
            self.results.len(),
        ];
        for count in counts {
            out.extend_from_slice(&(count as u32).to_le_bytes());
        }
        for (portal, set) in &self.results {
            let row = compress_row(&set.to_row_bytes());
            out.extend_from_slice(&(*portal as u32).to_le_bytes());
            out.extend_from_slice(&(row.len() as u32).to_le_bytes());
            out.extend_from_slice(&row);
        }
        out
    }

    /// Read a file that must be of `kind`; every count and index is checked.
    pub fn read(bytes: &[u8], kind: SavedKind) -> Result<SavedFlows, SavedError> {
        let mut r = Reader { bytes, at: 0 };
        if r.take(MAGIC.len())? != MAGIC {
            return Err(SavedError::NotFlowFile);
        }
        let version = r.u32()?;
        if version != VERSION {
            return Err(SavedError::Version(version));
        }
        let found = match r.u32()? {
            0 => SavedKind::State,
            1 => SavedKind::Partial,
            _ => return Err(SavedError::NotFlowFile),
        };
        if found != kind {
            return Err(SavedError::Kind {
                found: found.name(),
                expected: kind.name(),
            });
        }
        let inputs = InputsHash(u128::from_le_bytes(
            r.take(16)?.try_into().map_err(|_| SavedError::Truncated)?,
        ));
        let (index, count) = (r.u32()?, r.u32()?);
        if index >= count {
            return Err(SavedError::BadShard { index, count });
        }
        let portals = r.u32()?;
        let entries = r.u32()?;
        let row_len = (portals as usize).div_ceil(8);
        let mut results: Vec<(usize, BitSet)> = Vec::new();
        for _ in 0..entries {
            let portal = r.u32()?;
            if portal >= portals {
                return Err(SavedError::PortalOutOfRange { portal, portals });
            }
            if results
                .last()
                .is_some_and(|&(last, _)| last >= portal as usize)
            {
                return Err(SavedError::DuplicatePortal(portal));
            }
            let len = r.u32()? as usize;
            let (row, complete) = decompress_row(r.take(len)?, row_len);
            if !complete {
                return Err(SavedError::Truncated);
            }
            results.push((
                portal as usize,
                BitSet::from_row_bytes(&row, portals as usize),
            ));
        }
        if r.at != bytes.len() {
            return Err(SavedError::Truncated);
        }
        Ok(SavedFlows {
            kind,
            inputs,
            shard: Shard {
                index: index as usize,
                count: count as usize,
            },
            portals: portals as usize,
            results,
        })
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], SavedError> {
        let end = self.at.checked_add(n).ok_or(SavedError::Truncated)?;
        let slice = self.bytes.get(self.at..end).ok_or(SavedError::Truncated)?;
        self.at = end;
        Ok(slice)
    }

    fn u32(&mut self) -> Result<u32, SavedError> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
}

/// A 128-bit FNV-1a hash of everything a flow result depends on: the portal file, the BSP's
/// tree (planes, nodes, leaves without their vis fields, the world model) and the flow level.
/// It tells files of different maps or options apart; it is not meant to resist forgery.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InputsHash(pub u128);

impl std::fmt::Display for InputsHash {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "{:032x}", self.0)
    }
}

impl InputsHash {
    /// The hash of a portal file's text, the BSP it belongs to and the flow level.
    pub fn new(prt_text: &[u8], bsp: &Bsp, level: u8) -> InputsHash {
        let mut h = Fnv128::default();
        h.field(b"prt", prt_text);
        h.field(b"level", &[level]);
        let mut tree = Vec::new();
        for p in &bsp.planes {
            floats(&mut tree, &p.normal);
            floats(&mut tree, &[p.dist]);
            tree.extend_from_slice(&p.kind.to_le_bytes());
        }
        h.field(b"planes", &tree);
        tree.clear();
        for n in &bsp.nodes {
            tree.extend_from_slice(&n.plane.to_le_bytes());
            n.children
                .iter()
                .for_each(|c| tree.extend_from_slice(&c.to_le_bytes()));
        }
        h.field(b"nodes", &tree);
        tree.clear();
        // Vis writes each leaf's vis offset and ambient levels; the rest is the map's.
        for l in &bsp.leafs {
            tree.extend_from_slice(&l.contents.to_le_bytes());
            floats(&mut tree, &l.mins);
            floats(&mut tree, &l.maxs);
        }
        h.field(b"leafs", &tree);
        tree.clear();
        if let Some(world) = bsp.models.first() {
            world
                .head_nodes
                .iter()
                .for_each(|n| tree.extend_from_slice(&n.to_le_bytes()));
            tree.extend_from_slice(&world.vis_leafs.to_le_bytes());
        }
        h.field(b"world", &tree);
        InputsHash(h.0)
    }
}

fn floats(out: &mut Vec<u8>, values: &[f32]) {
    values
        .iter()
        .for_each(|v| out.extend_from_slice(&v.to_bits().to_le_bytes()));
}

struct Fnv128(u128);

impl Default for Fnv128 {
    fn default() -> Self {
        Fnv128(0x6c62272e07bb014262b821756295c58d)
    }
}

impl Fnv128 {
    const PRIME: u128 = 0x0000000001000000000000000000013B;

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u128::from(b);
            self.0 = self.0.wrapping_mul(Self::PRIME);
        }
    }

    /// A named, length-prefixed field, so no two different inputs give the same byte stream.
    fn field(&mut self, name: &[u8], bytes: &[u8]) {
        self.bytes(name);
        self.bytes(&(bytes.len() as u64).to_le_bytes());
        self.bytes(bytes);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> SavedFlows {
        let mut a = BitSet::new(70);
        [0, 5, 64, 69].iter().for_each(|&i| a.insert(i));
        SavedFlows {
            kind: SavedKind::Partial,
            inputs: InputsHash(0x1234_5678_9abc_def0_0fed_cba9_8765_4321),
            shard: Shard { index: 1, count: 3 },
            portals: 70,
            results: vec![(2, a), (9, BitSet::new(70)), (69, BitSet::full(70))],
        }
    }

    #[test]
    fn flows_round_trip() {
        let saved = sample();
        let bytes = saved.write();
        assert_eq!(SavedFlows::read(&bytes, SavedKind::Partial), Ok(saved));
    }

    #[test]
    fn damaged_files_are_refused_without_panicking() {
        let bytes = sample().write();
        for cut in 0..bytes.len() {
            assert!(
                SavedFlows::read(&bytes[..cut], SavedKind::Partial).is_err(),
                "{cut}"
            );
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert_eq!(
            SavedFlows::read(&longer, SavedKind::Partial),
            Err(SavedError::Truncated)
        );
        let mut version = bytes.clone();
        version[8] = 9;
        assert_eq!(
            SavedFlows::read(&version, SavedKind::Partial),
            Err(SavedError::Version(9))
        );
        assert!(matches!(
            SavedFlows::read(&bytes, SavedKind::State),
            Err(SavedError::Kind { .. })
        ));
        let mut state = sample();
        state.results.swap(0, 1);
        assert_eq!(
            SavedFlows::read(&state.write(), SavedKind::Partial),
            Err(SavedError::DuplicatePortal(2))
        );
        state.results[0].0 = 70;
        assert!(matches!(
            SavedFlows::read(&state.write(), SavedKind::Partial),
            Err(SavedError::PortalOutOfRange { portal: 70, .. })
        ));
        assert_eq!(
            SavedFlows::read(b"SGVISFLX", SavedKind::Partial),
            Err(SavedError::NotFlowFile)
        );
    }

    #[test]
    fn the_inputs_hash_tells_portals_trees_and_levels_apart() {
        let bsp = Bsp::default();
        let base = InputsHash::new(b"PRT1\n1\n0\n", &bsp, 4);
        assert_eq!(base, InputsHash::new(b"PRT1\n1\n0\n", &bsp, 4));
        assert_ne!(base, InputsHash::new(b"PRT1\n2\n0\n", &bsp, 4));
        assert_ne!(base, InputsHash::new(b"PRT1\n1\n0\n", &bsp, 3));
        let mut other = bsp.clone();
        other.leafs.push(quake_formats::bsp::Leaf::SHARED_SOLID);
        assert_ne!(base, InputsHash::new(b"PRT1\n1\n0\n", &other, 4));
        let mut vised = other.clone();
        vised.leafs[0].vis_offset = 7;
        vised.leafs[0].ambient = [1, 2, 3, 4];
        assert_eq!(
            InputsHash::new(b"x", &other, 4),
            InputsHash::new(b"x", &vised, 4)
        );
    }
}
