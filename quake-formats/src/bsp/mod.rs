//! BSP29, BSP2 and 2PSB files: one typed model, three on-disk encodings.
//!
//! The model stores every index as `u32`/`i32` and every bound as `f32`, wide enough for every
//! version. Each record type knows its encoding per version (`records::Record`); lumps are
//! read and written by one generic pair of functions. Trailing BSPX lumps are kept as named byte
//! blobs; [`phong`], [`face_flags`], [`face_minlight`], [`face_channels`], [`face_tone`], [`surflight_group`]
//! and [`leaf_flags`] read and write Slipgate's own ones, [`light_lumps`] those that carry light (coloured,
//! directional, HDR, at other spacings) and [`lightgrid`] the light grid.

pub mod face_channels;
pub mod face_flags;
pub mod face_minlight;
pub mod face_tone;
pub mod leaf_flags;
pub mod light_lumps;
pub mod lightgrid;
pub mod limits;
pub mod phong;
mod records;
pub mod surflight_group;
mod validate;

pub use crate::bsp_version::BspVersion;
pub use records::{
    ClipNode, Face, Leaf, Model, Node, Plane as BspPlane, TexInfo, contents, texinfo_flags,
};
pub use validate::{
    DARKPLACES_PORTAL_EPSILON, MAX_TREE_DEPTH, Problem, Rule, RuleInfo, Severity, TreeUse,
    check_usable, check_usable_for, darkplaces_divide, validate,
};

use std::borrow::Cow;

use crate::bytes::{PutLe, Reader};
use crate::error::{FormatError, Result};
use crate::layout::{Layout, place};
use crate::miptex::TextureLump;
use limits::*;
use records::{BoundEnd, Record, short_bound};

const BSP29_MAGIC: [u8; 4] = 29i32.to_le_bytes();
const BSP2_MAGIC: [u8; 4] = *b"BSP2";
/// RMQ's magic: the int `('B' << 24) | ('S' << 16) | ('P' << 8) | '2'`, little-endian.
const BSP2PSB_MAGIC: [u8; 4] = *b"2PSB";
const BSPX_MAGIC: [u8; 4] = *b"BSPX";
const HEADER_LEN: usize = 4 + 15 * 8;
const BSPX_ENTRY_LEN: usize = 24 + 8;

/// The lumps in header order.
pub const LUMP_NAMES: [&str; 15] = [
    "entities",
    "planes",
    "textures",
    "vertexes",
    "visibility",
    "nodes",
    "texinfo",
    "faces",
    "lighting",
    "clipnodes",
    "leafs",
    "marksurfaces",
    "edges",
    "surfedges",
    "models",
];

/// The order lumps are laid out in a freshly written file (the order common compilers use).
const FILE_ORDER: [usize; 15] = [1, 10, 3, 5, 6, 7, 9, 11, 13, 12, 14, 8, 4, 0, 2];

/// A leaf's potentially visible set as stored in a BSP.
#[derive(Debug, Clone, PartialEq)]
pub enum PvsRow {
    /// No row: the leaf sees every leaf.
    All,
    /// A stored row, decompressed.
    Row {
        /// One bit per leaf, leaf 1 in bit 0 of the first byte; as many bytes as the world
        /// model's `vis_leafs` need.
        bits: Vec<u8>,
        /// False when the compressed data ended before the row was full; the rest is zeros.
        complete: bool,
    },
}

/// An extension lump stored after the standard ones (BSPX), kept verbatim.
#[derive(Debug, Clone, PartialEq)]
pub struct BspxLump {
    /// 24-byte NUL-padded name as stored.
    pub raw_name: [u8; 24],
    /// The lump's contents, which only readers that know its name interpret.
    pub data: Vec<u8>,
}

impl BspxLump {
    /// The name up to its first NUL, read as Latin-1 (e.g. `"RGBLIGHTING"`, `"BRUSHLIST"`).
    pub fn name(&self) -> String {
        let end = self.raw_name.iter().position(|&b| b == 0).unwrap_or(24);
        crate::bytes::latin1_to_string(&self.raw_name[..end])
    }
}

/// A whole BSP file.
#[derive(Debug, Clone, PartialEq)]
pub struct Bsp {
    /// The encoding [`Bsp::write`] uses; [`Bsp::read`] sets it from the file's magic.
    pub version: BspVersion,
    /// The entity lump's text as bytes, including its terminating NUL.
    pub entities: Vec<u8>,
    /// Split planes of nodes and clip nodes, and the planes faces lie on.
    pub planes: Vec<BspPlane>,
    /// The miptex lump: the textures texinfos name by index.
    pub textures: TextureLump,
    /// Vertex positions in map units, shared by all faces through `edges`.
    pub vertices: Vec<[f32; 3]>,
    /// Compressed PVS rows; leaves point into it with `vis_offset`.
    pub visibility: Vec<u8>,
    /// Hull 0's BSP nodes for every model; models point at their head node.
    pub nodes: Vec<Node>,
    /// Texture projections; faces point at one each.
    pub texinfo: Vec<TexInfo>,
    /// Drawn polygons of every model.
    pub faces: Vec<Face>,
    /// 8-bit lightmaps; faces point into it with `light_offset`.
    pub lighting: Vec<u8>,
    /// The collision trees of hulls 1 and 2 (the player's box and the large monsters').
    pub clipnodes: Vec<ClipNode>,
    /// Hull 0's leaves; leaf 0 is the shared solid leaf every solid child points at.
    pub leafs: Vec<Leaf>,
    /// Face indices, in runs that leaves point into with `first_marksurface`.
    pub marksurfaces: Vec<u32>,
    /// Vertex indices of each edge's two ends; edge 0 is unused, because surfedges tell the
    /// direction by sign.
    pub edges: Vec<[u32; 2]>,
    /// Edge indices, in runs that faces point into: `i` walks edge `i` from its first vertex to
    /// its second, `-i` from the second to the first.
    pub surfedges: Vec<i32>,
    /// The world (model 0) and each brush entity's model (`*1`, `*2`, ...).
    pub models: Vec<Model>,
    /// Extension lumps after the standard ones, in file order.
    pub bspx: Vec<BspxLump>,
    /// How the file this came from was laid out (for byte-identical rewrites).
    layout: Option<(BspVersion, Layout)>,
}

impl Default for Bsp {
    fn default() -> Self {
        Bsp::new(BspVersion::Bsp29)
    }
}

/// A lump's location in the header.
#[derive(Debug, Clone, Copy)]
struct LumpEntry {
    offset: usize,
    len: usize,
}

impl Bsp {
    /// An empty file in `version`: every lump empty, no layout to keep.
    pub fn new(version: BspVersion) -> Bsp {
        Bsp {
            version,
            entities: Vec::new(),
            planes: Vec::new(),
            textures: TextureLump::default(),
            vertices: Vec::new(),
            visibility: Vec::new(),
            nodes: Vec::new(),
            texinfo: Vec::new(),
            faces: Vec::new(),
            lighting: Vec::new(),
            clipnodes: Vec::new(),
            leafs: Vec::new(),
            marksurfaces: Vec::new(),
            edges: Vec::new(),
            surfedges: Vec::new(),
            models: Vec::new(),
            bspx: Vec::new(),
            layout: None,
        }
    }

    /// Parse a BSP29, BSP2 or 2PSB file. Structural damage (truncation, lumps outside the file,
    /// sizes that are not whole records) is an error; bad indices are left to [`validate`].
    pub fn read(data: &[u8]) -> Result<Bsp> {
        let mut r = Reader::new(data, "BSP header");
        let magic = r.array::<4>()?;
        let version = match magic {
            BSP29_MAGIC => BspVersion::Bsp29,
            BSP2_MAGIC => BspVersion::Bsp2,
            BSP2PSB_MAGIC => BspVersion::Bsp2Psb,
            _ => return Err(FormatError::UnknownBspVersion(u32::from_le_bytes(magic))),
        };
        let mut entries = [LumpEntry { offset: 0, len: 0 }; 15];
        for (i, entry) in entries.iter_mut().enumerate() {
            let offset = r.i32()?;
            let len = r.i32()?;
            if offset < 0 || len < 0 || offset as i64 + len as i64 > data.len() as i64 {
                return Err(FormatError::LumpOutOfFile {
                    lump: LUMP_NAMES[i],
                    offset: offset as i64,
                    length: len as i64,
                    file_len: data.len(),
                });
            }
            *entry = LumpEntry {
                offset: offset as usize,
                len: len as usize,
            };
        }
        let lump = |i: usize| &data[entries[i].offset..entries[i].offset + entries[i].len];
        let mut bsp = Bsp::new(version);
        bsp.entities = lump(0).to_vec();
        bsp.planes = read_records(lump(1), version)?;
        bsp.textures = TextureLump::decode(lump(2))?;
        bsp.vertices = read_records(lump(3), version)?;
        bsp.visibility = lump(4).to_vec();
        bsp.nodes = read_records(lump(5), version)?;
        bsp.texinfo = read_records(lump(6), version)?;
        bsp.faces = read_records(lump(7), version)?;
        bsp.lighting = lump(8).to_vec();
        bsp.clipnodes = read_records(lump(9), version)?;
        if !version.has_wide_indices() {
            let count = bsp.clipnodes.len();
            for c in &mut bsp.clipnodes {
                c.widen_bsp29_children(count);
            }
        }
        bsp.leafs = read_records(lump(10), version)?;
        bsp.marksurfaces = read_records(lump(11), version)?;
        bsp.edges = read_records(lump(12), version)?;
        bsp.surfedges = read_records(lump(13), version)?;
        bsp.models = read_records(lump(14), version)?;

        let mut segments: Vec<(usize, usize)> = FILE_ORDER
            .iter()
            .map(|&i| (entries[i].offset, entries[i].len))
            .collect();
        let lumps_end = entries.iter().map(|e| e.offset + e.len).max().unwrap_or(0);
        if let Some((dir, lumps)) = read_bspx(data, lumps_end)? {
            segments.push(dir);
            for (segment, lump) in lumps {
                segments.push(segment);
                bsp.bspx.push(lump);
            }
        }
        bsp.layout = Some((version, Layout::record(data, HEADER_LEN, segments)));
        Ok(bsp)
    }

    /// Encode in `self.version`. A file read and written back unchanged is byte-identical.
    /// Writing BSP29 fails with [`FormatError::Bsp29Limit`] when the data does not fit it, and
    /// BSP29 or 2PSB with [`FormatError::ShortBound`] when a node or leaf bound does not.
    pub fn write(&self) -> Result<Vec<u8>> {
        let v = self.version;
        self.check_version_limits()?;
        // Lumps held as bytes already are borrowed, not copied.
        let owned = |bytes: Vec<u8>| Cow::Owned(bytes);
        let lumps: [Cow<[u8]>; 15] = [
            Cow::Borrowed(&self.entities),
            owned(write_records(&self.planes, v)?),
            owned(self.textures.encode()),
            owned(write_records(&self.vertices, v)?),
            Cow::Borrowed(&self.visibility),
            owned(write_records(&self.nodes, v)?),
            owned(write_records(&self.texinfo, v)?),
            owned(write_records(&self.faces, v)?),
            Cow::Borrowed(&self.lighting),
            owned(write_records(&self.clipnodes, v)?),
            owned(write_records(&self.leafs, v)?),
            owned(write_records(&self.marksurfaces, v)?),
            owned(write_records(&self.edges, v)?),
            owned(write_records(&self.surfedges, v)?),
            owned(write_records(&self.models, v)?),
        ];

        let mut segments: Vec<&[u8]> = FILE_ORDER.iter().map(|&i| &*lumps[i]).collect();
        let bspx_dir_len = if self.bspx.is_empty() {
            0
        } else {
            8 + BSPX_ENTRY_LEN * self.bspx.len()
        };
        let mut lens: Vec<usize> = segments.iter().map(|s| s.len()).collect();
        if !self.bspx.is_empty() {
            lens.push(bspx_dir_len);
            lens.extend(self.bspx.iter().map(|l| l.data.len()));
        }
        let layout = self
            .layout
            .as_ref()
            .filter(|(lv, _)| *lv == v)
            .map(|(_, l)| l);
        let placement = place(layout, HEADER_LEN, &lens);

        let mut header = Vec::with_capacity(HEADER_LEN);
        header.extend_from_slice(match v {
            BspVersion::Bsp29 => &BSP29_MAGIC,
            BspVersion::Bsp2 => &BSP2_MAGIC,
            BspVersion::Bsp2Psb => &BSP2PSB_MAGIC,
        });
        for (lump, bytes) in lumps.iter().enumerate() {
            let slot = FILE_ORDER.iter().position(|&i| i == lump).unwrap_or(0);
            header.put_i32(placement.offsets[slot] as i32);
            header.put_i32(bytes.len() as i32);
        }
        let mut bspx_dir = Vec::with_capacity(bspx_dir_len);
        if !self.bspx.is_empty() {
            bspx_dir.extend_from_slice(&BSPX_MAGIC);
            bspx_dir.put_u32(self.bspx.len() as u32);
            for (i, l) in self.bspx.iter().enumerate() {
                bspx_dir.extend_from_slice(&l.raw_name);
                bspx_dir.put_u32(placement.offsets[16 + i] as u32);
                bspx_dir.put_u32(l.data.len() as u32);
            }
            segments.push(&bspx_dir);
            segments.extend(self.bspx.iter().map(|l| l.data.as_slice()));
        }
        Ok(placement.assemble(&header, &segments))
    }

    /// Same data in another encoding; fails when the data does not fit it (BSP29's limits, or a
    /// bound outside BSP29's and 2PSB's 16-bit integers).
    pub fn converted(&self, version: BspVersion) -> Result<Bsp> {
        let mut out = self.clone();
        out.version = version;
        out.check_version_limits()?;
        Ok(out)
    }

    /// The limits of `self.version`, checked before any record is narrowed: BSP29's counts and
    /// bounds, 2PSB's bounds; BSP2 has none.
    pub fn check_version_limits(&self) -> Result<()> {
        match self.version {
            BspVersion::Bsp29 => self.check_bsp29_limits(),
            BspVersion::Bsp2Psb => self.check_short_bounds(),
            BspVersion::Bsp2 => Ok(()),
        }
    }

    /// Every BSP29 format limit: its counts, then its bounds ([`Bsp::check_short_bounds`]).
    pub fn check_bsp29_limits(&self) -> Result<()> {
        let counts = [
            ("the node count", self.nodes.len(), BSP29_MAX_NODES),
            ("the leaf count", self.leafs.len(), BSP29_MAX_LEAFS),
            (
                "the clip node count",
                self.clipnodes.len(),
                BSP29_MAX_CLIPNODES_UNSIGNED,
            ),
            ("the plane count", self.planes.len(), BSP29_MAX_PLANES),
            ("the vertex count", self.vertices.len(), BSP29_MAX_VERTICES),
            ("the face count", self.faces.len(), BSP29_MAX_FACES),
            (
                "the mark surface count",
                self.marksurfaces.len(),
                BSP29_MAX_MARKSURFACES,
            ),
            ("the texinfo count", self.texinfo.len(), BSP29_MAX_TEXINFO),
        ];
        for (what, count, max) in counts {
            if count > max {
                return Err(FormatError::Bsp29Limit { what, count, max });
            }
        }
        if let Some(f) = self
            .faces
            .iter()
            .find(|f| f.num_edges as usize > BSP29_MAX_FACE_EDGES)
        {
            return Err(FormatError::Bsp29Limit {
                what: "a face's edge count",
                count: f.num_edges as usize,
                max: BSP29_MAX_FACE_EDGES,
            });
        }
        self.check_short_bounds()
    }

    /// Every node and leaf bound, rounded outward to whole units, fits the 16-bit integers
    /// BSP29 and 2PSB store bounds in.
    pub fn check_short_bounds(&self) -> Result<()> {
        let node = first_long_bound(self.nodes.iter().map(|n| (n.mins, n.maxs)));
        let leaf = || first_long_bound(self.leafs.iter().map(|l| (l.mins, l.maxs)));
        let found = node
            .map(|at| ("node", at))
            .or_else(|| leaf().map(|at| ("leaf", at)));
        match found {
            Some((record, (index, value))) => Err(FormatError::ShortBound {
                version: self.version,
                record,
                index,
                value,
            }),
            None => Ok(()),
        }
    }

    /// The entity lump as text (Quake text is Latin-1, not UTF-8), without the trailing NUL.
    pub fn entity_text(&self) -> String {
        let end = self
            .entities
            .iter()
            .position(|&b| b == 0)
            .unwrap_or(self.entities.len());
        crate::bytes::latin1_to_string(&self.entities[..end])
    }

    /// Replace the entity lump with `text` plus the terminating NUL engines expect.
    pub fn set_entity_text(&mut self, text: &str) {
        self.entities = crate::bytes::string_to_latin1(text);
        self.entities.push(0);
    }

    /// The texture `face` is drawn with, when its texinfo and texture are there.
    pub fn face_texture(&self, face: &Face) -> Option<&crate::miptex::MipTex> {
        let texinfo = self.texinfo.get(face.texinfo as usize)?;
        self.textures
            .textures
            .get(texinfo.miptex as usize)?
            .as_ref()
    }

    /// The vertices of a face in winding order (edges followed by their direction).
    /// Indices are bounds-checked; a broken face yields `None`.
    pub fn face_vertices(&self, face: &Face) -> Option<Vec<[f32; 3]>> {
        self.face_vertex_indices(face)?
            .into_iter()
            .map(|v| self.vertices.get(v as usize).copied())
            .collect()
    }

    /// The vertex indices of `face` in winding order, or `None` when an edge index is out of
    /// range (vertex indices are returned as stored, not checked).
    pub fn face_vertex_indices(&self, face: &Face) -> Option<Vec<u32>> {
        let first = face.first_edge as usize;
        let surfedges = self.surfedges.get(first..first + face.num_edges as usize)?;
        surfedges
            .iter()
            .map(|&se| {
                let edge = self.edges.get(se.unsigned_abs() as usize)?;
                Some(if se >= 0 { edge[0] } else { edge[1] })
            })
            .collect()
    }

    /// Leaf `leaf`'s stored PVS row (bit `i` stands for leaf `i + 1`), read as engines read it:
    /// leaf 0, a vis offset of -1 or a map without visibility data sees everything
    /// ([`PvsRow::All`]). An offset outside the visibility lump is an error.
    pub fn pvs_row(&self, leaf: usize) -> Result<PvsRow> {
        let offset = self.leafs.get(leaf).map_or(-1, |l| l.vis_offset);
        if leaf == 0 || offset < 0 || self.visibility.is_empty() {
            return Ok(PvsRow::All);
        }
        let data = self
            .visibility
            .get(offset as usize..)
            .filter(|d| !d.is_empty())
            .ok_or_else(|| FormatError::BadLump {
                lump: "visibility",
                detail: format!(
                    "leaf {leaf}'s row at offset {offset} is outside the {}-byte lump",
                    self.visibility.len()
                ),
            })?;
        let vis_leafs = self
            .models
            .first()
            .map_or(0, |m| m.vis_leafs.max(0) as usize);
        let (bits, complete) = crate::visrle::decompress_row(data, vis_leafs.div_ceil(8));
        Ok(PvsRow::Row { bits, complete })
    }

    /// The leaf containing `point`, walking the world model's hull 0 tree.
    pub fn leaf_at(&self, point: [f32; 3]) -> Option<usize> {
        self.leaf_from(*self.models.first()?.head_nodes.first()?, point)
    }

    /// The leaf containing `point`, walking down from `node` (a child
    /// index: negative for a leaf), for callers that know the point lies
    /// below it.
    pub fn leaf_from(&self, mut node: i32, point: [f32; 3]) -> Option<usize> {
        let mut steps = 0;
        while node >= 0 {
            let n = self.nodes.get(node as usize)?;
            let plane = self.planes.get(n.plane as usize)?;
            node = n.children[usize::from(plane.distance(point) < 0.0)];
            steps += 1;
            if steps > self.nodes.len() {
                return None; // a cycle in a damaged file
            }
        }
        Some((-(node + 1)) as usize)
    }
}

/// The first box (its index) with a bound (its value) that does not fit a 16-bit integer once
/// rounded outward.
fn first_long_bound(boxes: impl Iterator<Item = ([f32; 3], [f32; 3])>) -> Option<(usize, f32)> {
    boxes.enumerate().find_map(|(index, (mins, maxs))| {
        let lower = mins
            .into_iter()
            .find(|&c| short_bound(c, BoundEnd::Lower).is_none());
        let upper = maxs
            .into_iter()
            .find(|&c| short_bound(c, BoundEnd::Upper).is_none());
        lower.or(upper).map(|value| (index, value))
    })
}

fn read_records<T: Record>(data: &[u8], v: BspVersion) -> Result<Vec<T>> {
    let size = T::size(v);
    if !data.len().is_multiple_of(size) {
        return Err(FormatError::LumpSize {
            lump: T::LUMP,
            length: data.len(),
            record: size,
        });
    }
    let mut r = Reader::new(data, T::LUMP);
    (0..data.len() / size).map(|_| T::read(&mut r, v)).collect()
}

fn write_records<T: Record>(records: &[T], v: BspVersion) -> Result<Vec<u8>> {
    let mut out = Vec::with_capacity(records.len() * T::size(v));
    for rec in records {
        rec.write(&mut out, v)?;
    }
    Ok(out)
}

type BspxSegments = ((usize, usize), Vec<((usize, usize), BspxLump)>);

/// The BSPX directory that may follow the standard lumps (4-byte aligned).
fn read_bspx(data: &[u8], lumps_end: usize) -> Result<Option<BspxSegments>> {
    let dir_ofs = lumps_end.next_multiple_of(4);
    if data.len() < dir_ofs + 8 || data[dir_ofs..dir_ofs + 4] != BSPX_MAGIC {
        return Ok(None);
    }
    let mut r = Reader::at(data, dir_ofs + 4, "BSPX directory");
    let count = r.u32()? as usize;
    if count > data.len() / BSPX_ENTRY_LEN {
        return Err(FormatError::BadLump {
            lump: "BSPX",
            detail: format!("directory claims {count} lumps"),
        });
    }
    let mut lumps = Vec::with_capacity(count);
    for i in 0..count {
        let raw_name = r.array::<24>()?;
        let offset = r.u32()? as usize;
        let len = r.u32()? as usize;
        if offset.checked_add(len).is_none_or(|end| end > data.len()) {
            return Err(FormatError::BadLump {
                lump: "BSPX",
                detail: format!("lump {i}: offset {offset} + length {len} is past the file's end"),
            });
        }
        let lump = BspxLump {
            raw_name,
            data: data[offset..offset + len].to_vec(),
        };
        lumps.push(((offset, len), lump));
    }
    Ok(Some(((dir_ofs, 8 + BSPX_ENTRY_LEN * count), lumps)))
}

/// A BSP of `n` faces without light or geometry, for tests of per-face lumps.
#[cfg(test)]
pub(crate) fn bsp_with_faces(n: usize) -> Bsp {
    let face = Face {
        plane: 0,
        side: 0,
        first_edge: 0,
        num_edges: 0,
        texinfo: 0,
        styles: [255; 4],
        light_offset: -1,
    };
    Bsp {
        faces: vec![face; n],
        ..Bsp::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_bsp_round_trips_in_every_version() {
        for v in [BspVersion::Bsp29, BspVersion::Bsp2, BspVersion::Bsp2Psb] {
            let mut bsp = Bsp::new(v);
            bsp.set_entity_text("{\n\"classname\" \"worldspawn\"\n}\n");
            let bytes = bsp.write().expect("write");
            let back = Bsp::read(&bytes).expect("read");
            assert_eq!(back.version, v);
            assert_eq!(back.entities, bsp.entities);
            assert_eq!(back.write().expect("rewrite"), bytes);
        }
    }

    #[test]
    fn truncated_header_is_an_error_not_a_panic() {
        let bsp = Bsp::new(BspVersion::Bsp29).write().expect("write");
        for len in 0..HEADER_LEN {
            assert!(Bsp::read(&bsp[..len]).is_err());
        }
    }

    #[test]
    fn wrong_version_is_named() {
        let mut bytes = Bsp::new(BspVersion::Bsp29).write().expect("write");
        bytes[0] = 30;
        let err = Bsp::read(&bytes).expect_err("version 30");
        assert!(err.to_string().contains("0x0000001e"), "{err}");
    }

    #[test]
    fn bsp29_limit_says_use_bsp2() {
        let mut bsp = Bsp::new(BspVersion::Bsp29);
        bsp.vertices = vec![[0.0; 3]; BSP29_MAX_VERTICES + 1];
        let err = bsp.write().expect_err("too many vertices");
        assert!(err.to_string().contains("BSP2"), "{err}");
        assert!(
            bsp.converted(BspVersion::Bsp2)
                .expect("bsp2")
                .write()
                .is_ok()
        );
    }

    /// A small tree whose indices need 32 bits and whose bounds are whole units.
    fn wide_bsp(version: BspVersion) -> Bsp {
        let big = 70_000u32;
        let mut bsp = Bsp::new(version);
        bsp.set_entity_text("{\n\"classname\" \"worldspawn\"\n}\n");
        bsp.planes = vec![BspPlane {
            normal: [1.0, 0.0, 0.0],
            dist: 8.0,
            kind: 0,
        }];
        bsp.vertices = vec![[0.0, 0.0, 0.0], [64.0, 0.0, 0.0], [0.0, 64.0, 0.0]];
        bsp.nodes = vec![Node {
            plane: 0,
            children: [-(big as i32), -2],
            mins: [-32768.0, -16.0, 0.0],
            maxs: [32767.0, 16.0, 128.0],
            first_face: big,
            num_faces: 3,
        }];
        bsp.leafs = vec![
            Leaf::SHARED_SOLID,
            Leaf {
                contents: contents::EMPTY,
                vis_offset: -1,
                mins: [-64.0, -16.0, 0.0],
                maxs: [64.0, 16.0, 128.0],
                first_marksurface: big,
                num_marksurfaces: 2,
                ambient: [1, 2, 3, 4],
            },
        ];
        bsp.clipnodes = vec![ClipNode {
            plane: 0,
            children: [big as i32, contents::SOLID],
        }];
        bsp.faces = vec![Face {
            plane: big,
            side: 1,
            first_edge: 0,
            num_edges: 3,
            texinfo: big,
            styles: [0, 255, 255, 255],
            light_offset: -1,
        }];
        bsp.marksurfaces = vec![big, 0];
        bsp.edges = vec![[0, 0], [big, 1], [1, 2]];
        bsp.surfedges = vec![1, 2, -1];
        bsp
    }

    /// Regression: ericw-tools' qbsp writes BSP29 files with more than 32767 clip nodes (a 2025
    /// jam map has 40,000), their children unsigned as FitzQuake's engines read them; every
    /// tool refused such a file, reading those children as bad contents values.
    #[test]
    fn bsp29_clip_node_children_past_32767_read_unsigned_and_write_back() {
        let count = 40_000;
        let mut bsp = Bsp::new(BspVersion::Bsp29);
        bsp.clipnodes = (0..count)
            .map(|i| ClipNode {
                plane: 0,
                children: [
                    if i + 1 < count {
                        i + 1
                    } else {
                        contents::EMPTY
                    },
                    contents::SOLID,
                ],
            })
            .collect();
        let bytes = bsp.write().expect("BSP29 holds 40,000 clip nodes");
        let clip_lump = {
            let at = 4 + 8 * 9;
            i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as usize
        };
        // Node 35000's front child, 35001, is stored as its unsigned 16 bits.
        let child = clip_lump + 35_000 * 8 + 4;
        assert_eq!(u16::from_le_bytes([bytes[child], bytes[child + 1]]), 35_001);
        let read = Bsp::read(&bytes).expect("read");
        assert_eq!(read.clipnodes, bsp.clipnodes);
        assert_eq!(read.write().expect("write again"), bytes);
        let over = Bsp {
            clipnodes: vec![bsp.clipnodes[0]; limits::BSP29_MAX_CLIPNODES_UNSIGNED + 1],
            ..bsp
        };
        assert!(matches!(over.write(), Err(FormatError::Bsp29Limit { .. })));
    }

    #[test]
    fn bsp2psb_round_trips_with_wide_indices_and_short_bounds() {
        let bsp = wide_bsp(BspVersion::Bsp2Psb);
        let bytes = bsp.write().expect("write 2PSB");
        assert_eq!(&bytes[..4], b"2PSB");
        assert_eq!(
            u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
            (u32::from(b'B') << 24)
                | (u32::from(b'S') << 16)
                | (u32::from(b'P') << 8)
                | u32::from(b'2')
        );
        // 32-byte nodes and leaves (BSP2's indices, BSP29's bounds), BSP2's other records.
        let lump_len = |lump: usize| {
            let at = 4 + 8 * lump + 4;
            i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as usize
        };
        assert_eq!(lump_len(5), 32, "one node");
        assert_eq!(lump_len(10), 2 * 32, "two leaves");
        assert_eq!(lump_len(9), 12, "one clip node");
        assert_eq!(lump_len(7), 28, "one face");
        assert_eq!(lump_len(11), 2 * 4, "two mark surfaces");
        assert_eq!(lump_len(12), 3 * 8, "three edges");
        let mut back = Bsp::read(&bytes).expect("read 2PSB");
        assert_eq!(back.write().expect("rewrite"), bytes);
        back.layout = None;
        assert_eq!(back, bsp);
        // The same data converts to the other versions and back unchanged.
        let via_bsp2 = Bsp::read(
            &bsp.converted(BspVersion::Bsp2)
                .expect("to BSP2")
                .write()
                .expect("write BSP2"),
        )
        .expect("read BSP2");
        let mut again = via_bsp2
            .converted(BspVersion::Bsp2Psb)
            .expect("back to 2PSB");
        again.layout = None;
        assert_eq!(again, bsp);
        let bsp29 = bsp.converted(BspVersion::Bsp29).and_then(|b| b.write());
        assert!(bsp29.is_err(), "indices past 16 bits");
    }

    #[test]
    fn bsp2psb_rounds_bounds_outward() {
        let mut bsp = wide_bsp(BspVersion::Bsp2Psb);
        bsp.nodes[0].mins = [-0.5, 1.5, -32767.9];
        bsp.nodes[0].maxs = [0.5, 1.5, 32766.1];
        let back = Bsp::read(&bsp.write().expect("write")).expect("read");
        assert_eq!(back.nodes[0].mins, [-1.0, 1.0, -32768.0]);
        assert_eq!(back.nodes[0].maxs, [1.0, 2.0, 32767.0]);
    }

    #[test]
    fn bound_outside_16_bits_is_an_error_not_a_panic() {
        let cases = [
            (BspVersion::Bsp2Psb, "node 0", 32767.5, f32::NAN),
            (BspVersion::Bsp2Psb, "leaf 1", -32768.5, -40_000.0),
            (BspVersion::Bsp29, "node 0", f32::INFINITY, 1e9),
        ];
        for (version, record, node_max, leaf_min) in cases {
            let mut bsp = wide_bsp(BspVersion::Bsp2);
            bsp.faces.clear();
            bsp.edges.clear();
            bsp.marksurfaces.clear();
            bsp.nodes[0].first_face = 0;
            bsp.leafs[1].first_marksurface = 0;
            if record == "node 0" {
                bsp.nodes[0].maxs[2] = node_max;
            } else {
                bsp.leafs[1].mins[0] = leaf_min;
            }
            assert!(bsp.write().is_ok(), "BSP2 holds float bounds");
            let err = bsp.converted(version).expect_err("bound outside i16");
            assert!(matches!(err, FormatError::ShortBound { .. }), "{err}");
            let text = err.to_string();
            assert!(text.contains(&version.to_string()), "{text}");
            assert!(text.contains(record), "{text}");
            assert!(text.contains("BSP2"), "{text}");
            bsp.version = version;
            assert!(bsp.write().is_err(), "{version}: {record}");
        }
    }

    #[test]
    fn truncated_or_mislabelled_2psb_is_an_error_not_a_panic() {
        let bytes = wide_bsp(BspVersion::Bsp2Psb).write().expect("write");
        for len in 0..bytes.len() {
            let _ = Bsp::read(&bytes[..len]);
        }
        for len in 0..HEADER_LEN {
            assert!(Bsp::read(&bytes[..len]).is_err(), "{len}-byte header");
        }
        // Read as BSP2, its 32-byte nodes are not whole 44-byte records.
        let mut as_bsp2 = bytes.clone();
        as_bsp2[..4].copy_from_slice(b"BSP2");
        let err = Bsp::read(&as_bsp2).expect_err("BSP2 record sizes");
        assert!(matches!(err, FormatError::LumpSize { .. }), "{err}");
    }
}
