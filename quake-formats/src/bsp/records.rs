//! The fixed-size records of the BSP lumps and their per-version encodings.

use super::BspVersion;
use crate::bytes::{PutLe, Reader};
use crate::error::{FormatError, Result};

/// Leaf and clip node contents values: what fills a region of the map.
pub mod contents {
    /// Open space that players and monsters move through.
    pub const EMPTY: i32 = -1;
    /// Inside a wall: nothing moves there and nothing in it is drawn.
    pub const SOLID: i32 = -2;
    /// Water: players swim, and the view is tinted and warped underneath.
    pub const WATER: i32 = -3;
    /// Slime: like water, and it hurts the player.
    pub const SLIME: i32 = -4;
    /// Lava: like water, and it hurts the player more.
    pub const LAVA: i32 = -5;
    /// The inside of sky brushes; faces towards it are drawn as scrolling sky.
    pub const SKY: i32 = -6;

    /// Whether `c` is water, slime or lava.
    pub fn is_liquid(c: i32) -> bool {
        matches!(c, WATER | SLIME | LAVA)
    }
}

/// Texinfo flags.
pub mod texinfo_flags {
    /// Sky or liquid: no lightmap, drawn warped; engines skip its extents check.
    pub const SPECIAL: i32 = 1;
}

/// One record type of a lump, with its size and encoding in each version.
pub(super) trait Record: Sized {
    const LUMP: &'static str;
    fn size(v: BspVersion) -> usize;
    fn read(r: &mut Reader, v: BspVersion) -> Result<Self>;
    fn write(&self, out: &mut Vec<u8>, v: BspVersion) -> Result<()>;
}

/// Narrow a value into a BSP29 16-bit field; `BSP29_*` limits are checked before this, so a
/// failure here means a value (not a count) is out of range.
fn narrow<T: TryFrom<i64>>(value: i64, lump: &'static str, field: &'static str) -> Result<T> {
    T::try_from(value).map_err(|_| FormatError::BadLump {
        lump,
        detail: format!(
            "{field} value {value} does not fit BSP29's 16-bit field; write BSP2 instead (--bsp2)"
        ),
    })
}

/// The BSP's plane record (`f32`), as opposed to [`crate::geom::Plane`] (`f64`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: [f32; 3],
    /// Distance from the origin along `normal`: points `p` on the plane have
    /// `dot(normal, p) == dist`.
    pub dist: f32,
    /// 0..2 axial X/Y/Z, 3..5 mostly X/Y/Z. Engines test a point against an axial plane with
    /// its one coordinate instead of a dot product, so the kind must match the normal.
    pub kind: i32,
}

impl Plane {
    /// How far `p` lies in front of the plane (negative behind), summed as engines' and our
    /// own leaf walks sum it, so every walk puts a point on the same side.
    pub fn distance(&self, p: [f32; 3]) -> f32 {
        self.normal[0] * p[0] + self.normal[1] * p[1] + self.normal[2] * p[2] - self.dist
    }
}

impl Record for Plane {
    const LUMP: &'static str = "planes";
    fn size(_: BspVersion) -> usize {
        20
    }
    fn read(r: &mut Reader, _: BspVersion) -> Result<Self> {
        Ok(Plane {
            normal: r.f32x3()?,
            dist: r.f32()?,
            kind: r.i32()?,
        })
    }
    fn write(&self, out: &mut Vec<u8>, _: BspVersion) -> Result<()> {
        out.put_f32x3(self.normal);
        out.put_f32(self.dist);
        out.put_i32(self.kind);
        Ok(())
    }
}

impl Record for [f32; 3] {
    const LUMP: &'static str = "vertexes";
    fn size(_: BspVersion) -> usize {
        12
    }
    fn read(r: &mut Reader, _: BspVersion) -> Result<Self> {
        r.f32x3()
    }
    fn write(&self, out: &mut Vec<u8>, _: BspVersion) -> Result<()> {
        out.put_f32x3(*self);
        Ok(())
    }
}

/// Which end of a box a bound is, and so which way it is rounded to whole units.
#[derive(Debug, Clone, Copy)]
pub(super) enum BoundEnd {
    /// A `mins` coordinate, rounded down.
    Lower,
    /// A `maxs` coordinate, rounded up.
    Upper,
}

/// `value` rounded outward to the whole units BSP29 and 2PSB store bounds in, so that the box
/// stays conservative; `None` when that does not fit their 16 bits (or is not a number).
pub(super) fn short_bound(value: f32, end: BoundEnd) -> Option<i16> {
    let rounded = match end {
        BoundEnd::Lower => value.floor(),
        BoundEnd::Upper => value.ceil(),
    };
    // NaN fails both comparisons.
    (rounded >= f32::from(i16::MIN) && rounded <= f32::from(i16::MAX)).then_some(rounded as i16)
}

/// Bounds stored as `i16` in BSP29 and 2PSB, `f32` in BSP2.
fn read_bounds(r: &mut Reader, v: BspVersion) -> Result<([f32; 3], [f32; 3])> {
    if v.has_short_bounds() {
        let mut b = [0f32; 6];
        for c in &mut b {
            *c = r.i16()? as f32;
        }
        Ok(([b[0], b[1], b[2]], [b[3], b[4], b[5]]))
    } else {
        Ok((r.f32x3()?, r.f32x3()?))
    }
}

fn write_bounds(
    out: &mut Vec<u8>,
    v: BspVersion,
    mins: [f32; 3],
    maxs: [f32; 3],
    lump: &'static str,
) -> Result<()> {
    if !v.has_short_bounds() {
        out.put_f32x3(mins);
        out.put_f32x3(maxs);
        return Ok(());
    }
    // `Bsp::check_short_bounds` runs before any record is written, so this error is a backstop.
    let corners = mins
        .map(|c| (c, BoundEnd::Lower))
        .into_iter()
        .chain(maxs.map(|c| (c, BoundEnd::Upper)));
    for (c, end) in corners {
        let short = short_bound(c, end).ok_or_else(|| FormatError::BadLump {
            lump,
            detail: format!("bound {c} does not fit {v}'s 16-bit integer bounds; write BSP2"),
        })?;
        out.put_i16(short);
    }
    Ok(())
}

/// Bytes of an index or count: 2 in BSP29, 4 in BSP2 and 2PSB.
fn wide_size(v: BspVersion) -> usize {
    if v.has_wide_indices() { 4 } else { 2 }
}

/// Bytes of one bound coordinate: 2 (`i16`) in BSP29 and 2PSB, 4 (`f32`) in BSP2.
fn bound_size(v: BspVersion) -> usize {
    if v.has_short_bounds() { 2 } else { 4 }
}

/// A 16-bit (BSP29) or 32-bit (BSP2, 2PSB) signed child or index.
fn read_wide_i(r: &mut Reader, v: BspVersion) -> Result<i32> {
    if v.has_wide_indices() {
        r.i32()
    } else {
        Ok(r.i16()? as i32)
    }
}

fn write_wide_i(
    out: &mut Vec<u8>,
    v: BspVersion,
    value: i32,
    lump: &'static str,
    field: &'static str,
) -> Result<()> {
    if v.has_wide_indices() {
        out.put_i32(value);
    } else {
        out.put_i16(narrow(value as i64, lump, field)?);
    }
    Ok(())
}

/// A 16-bit (BSP29) or 32-bit (BSP2, 2PSB) unsigned index.
fn read_wide_u(r: &mut Reader, v: BspVersion) -> Result<u32> {
    if v.has_wide_indices() {
        r.u32()
    } else {
        Ok(r.u16()? as u32)
    }
}

fn write_wide_u(
    out: &mut Vec<u8>,
    v: BspVersion,
    value: u32,
    lump: &'static str,
    field: &'static str,
) -> Result<()> {
    if v.has_wide_indices() {
        out.put_u32(value);
    } else {
        out.put_u16(narrow(value as i64, lump, field)?);
    }
    Ok(())
}

/// An interior node of the hull 0 tree. A child `>= 0` is a node, `< 0` is leaf `-(child + 1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Index of the split plane in the planes lump.
    pub plane: u32,
    /// The front child (on the normal's side of the plane), then the back one.
    pub children: [i32; 2],
    /// Lower corner of the box around everything below the node, for frustum culling (BSP29
    /// stores whole units, rounded outward).
    pub mins: [f32; 3],
    /// Upper corner of the box around everything below the node.
    pub maxs: [f32; 3],
    /// Index of the first of the faces that lie on this node's plane.
    pub first_face: u32,
    /// Number of faces on this node's plane, from `first_face` on.
    pub num_faces: u32,
}

impl Record for Node {
    const LUMP: &'static str = "nodes";
    fn size(v: BspVersion) -> usize {
        // plane, 2 children, 6 bounds, first face, face count.
        4 + 2 * wide_size(v) + 6 * bound_size(v) + 2 * wide_size(v)
    }
    fn read(r: &mut Reader, v: BspVersion) -> Result<Self> {
        let plane = r.u32()?;
        let children = [read_wide_i(r, v)?, read_wide_i(r, v)?];
        let (mins, maxs) = read_bounds(r, v)?;
        Ok(Node {
            plane,
            children,
            mins,
            maxs,
            first_face: read_wide_u(r, v)?,
            num_faces: read_wide_u(r, v)?,
        })
    }
    fn write(&self, out: &mut Vec<u8>, v: BspVersion) -> Result<()> {
        out.put_u32(self.plane);
        for c in self.children {
            write_wide_i(out, v, c, Self::LUMP, "child")?;
        }
        write_bounds(out, v, self.mins, self.maxs, Self::LUMP)?;
        write_wide_u(out, v, self.first_face, Self::LUMP, "first face")?;
        write_wide_u(out, v, self.num_faces, Self::LUMP, "face count")
    }
}

/// A convex region of the hull 0 tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leaf {
    /// What fills the leaf: one of the [`contents`] values.
    pub contents: i32,
    /// Byte offset of this leaf's compressed PVS row, or -1 for none.
    pub vis_offset: i32,
    /// Lower corner of the leaf's box, for frustum culling (BSP29 stores whole units, rounded
    /// outward).
    pub mins: [f32; 3],
    /// Upper corner of the leaf's box.
    pub maxs: [f32; 3],
    /// Index of the leaf's first marksurface: the faces engines draw when the leaf is visible
    /// start there.
    pub first_marksurface: u32,
    /// Number of marksurfaces from `first_marksurface` on.
    pub num_marksurfaces: u32,
    /// Ambient sound levels: water, sky, slime, lava.
    pub ambient: [u8; 4],
}

impl Leaf {
    /// Leaf 0 of every BSP: the one solid leaf all hull 0 trees share, with no PVS row.
    pub const SHARED_SOLID: Leaf = Leaf {
        contents: contents::SOLID,
        vis_offset: -1,
        mins: [0.0; 3],
        maxs: [0.0; 3],
        first_marksurface: 0,
        num_marksurfaces: 0,
        ambient: [0; 4],
    };
}

impl Record for Leaf {
    const LUMP: &'static str = "leafs";
    fn size(v: BspVersion) -> usize {
        // contents, vis offset, 6 bounds, first mark surface, mark surface count, 4 ambients.
        4 + 4 + 6 * bound_size(v) + 2 * wide_size(v) + 4
    }
    fn read(r: &mut Reader, v: BspVersion) -> Result<Self> {
        let contents = r.i32()?;
        let vis_offset = r.i32()?;
        let (mins, maxs) = read_bounds(r, v)?;
        Ok(Leaf {
            contents,
            vis_offset,
            mins,
            maxs,
            first_marksurface: read_wide_u(r, v)?,
            num_marksurfaces: read_wide_u(r, v)?,
            ambient: r.array()?,
        })
    }
    fn write(&self, out: &mut Vec<u8>, v: BspVersion) -> Result<()> {
        out.put_i32(self.contents);
        out.put_i32(self.vis_offset);
        write_bounds(out, v, self.mins, self.maxs, Self::LUMP)?;
        write_wide_u(
            out,
            v,
            self.first_marksurface,
            Self::LUMP,
            "first mark surface",
        )?;
        write_wide_u(
            out,
            v,
            self.num_marksurfaces,
            Self::LUMP,
            "mark surface count",
        )?;
        out.extend_from_slice(&self.ambient);
        Ok(())
    }
}

/// A node of a clipping hull (1 and 2). A child `>= 0` is a clip node, `< 0` is contents.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClipNode {
    /// Index of the split plane in the planes lump.
    pub plane: u32,
    /// The front child (on the normal's side of the plane), then the back one.
    pub children: [i32; 2],
}

impl Record for ClipNode {
    const LUMP: &'static str = "clipnodes";
    fn size(v: BspVersion) -> usize {
        4 + 2 * wide_size(v)
    }
    fn read(r: &mut Reader, v: BspVersion) -> Result<Self> {
        Ok(ClipNode {
            plane: r.u32()?,
            children: [read_wide_i(r, v)?, read_wide_i(r, v)?],
        })
    }
    fn write(&self, out: &mut Vec<u8>, v: BspVersion) -> Result<()> {
        out.put_u32(self.plane);
        for c in self.children {
            if v.has_wide_indices() || c < 0 {
                write_wide_i(out, v, c, Self::LUMP, "child")?;
            } else {
                // Past 32767 a node child is written unsigned (see `widen_bsp29_children`).
                out.put_u16(narrow(c as i64, Self::LUMP, "child")?);
            }
        }
        Ok(())
    }
}

impl ClipNode {
    /// BSP29 clip node children as engines of FitzQuake's line read them
    /// ([`super::limits::BSP29_MAX_CLIPNODES_UNSIGNED`]): the 16 bits unsigned, and a value at or
    /// past `count` contents (less 65536). Children below 32768 read the same either way.
    pub(super) fn widen_bsp29_children(&mut self, count: usize) {
        for c in &mut self.children {
            let unsigned = i32::from(*c as i16 as u16);
            *c = if unsigned as usize >= count {
                unsigned - 65536
            } else {
                unsigned
            };
        }
    }
}

/// Texture projection: `s = dot(p, vecs[0].xyz) + vecs[0].w`, likewise `t` with `vecs[1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TexInfo {
    /// The `s` and `t` axes in texels per map unit, each followed by its offset in texels.
    pub vecs: [[f32; 4]; 2],
    /// Index of the texture in the texture lump.
    pub miptex: u32,
    /// Bits of [`texinfo_flags`].
    pub flags: i32,
}

impl Record for TexInfo {
    const LUMP: &'static str = "texinfo";
    fn size(_: BspVersion) -> usize {
        40
    }
    fn read(r: &mut Reader, _: BspVersion) -> Result<Self> {
        let mut vecs = [[0f32; 4]; 2];
        for row in &mut vecs {
            for c in row.iter_mut() {
                *c = r.f32()?;
            }
        }
        Ok(TexInfo {
            vecs,
            miptex: r.u32()?,
            flags: r.i32()?,
        })
    }
    fn write(&self, out: &mut Vec<u8>, _: BspVersion) -> Result<()> {
        for row in self.vecs {
            for c in row {
                out.put_f32(c);
            }
        }
        out.put_u32(self.miptex);
        out.put_i32(self.flags);
        Ok(())
    }
}

/// A drawable polygon: a run of surfedges on one plane with one texinfo and up to four styles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Face {
    /// Index of the plane the face lies on.
    pub plane: u32,
    /// 1 when the face looks along the plane's back side.
    pub side: u32,
    /// Index of the face's first surfedge.
    pub first_edge: u32,
    /// Number of surfedges from `first_edge` on, which is also its number of vertices.
    pub num_edges: u32,
    /// Index of the texinfo that projects the face's texture and lightmap.
    pub texinfo: u32,
    /// Light styles; 255 marks an empty slot.
    pub styles: [u8; 4],
    /// Byte offset of the first lightmap in the lighting lump, or -1 for none.
    pub light_offset: i32,
}

impl Record for Face {
    const LUMP: &'static str = "faces";
    fn size(v: BspVersion) -> usize {
        // plane, side, first edge (always 32-bit), edge count, texinfo, 4 styles, light offset.
        4 * wide_size(v) + 4 + 4 + 4
    }
    fn read(r: &mut Reader, v: BspVersion) -> Result<Self> {
        Ok(Face {
            plane: read_wide_u(r, v)?,
            side: read_wide_u(r, v)?,
            first_edge: r.u32()?,
            num_edges: read_wide_u(r, v)?,
            texinfo: read_wide_u(r, v)?,
            styles: r.array()?,
            light_offset: r.i32()?,
        })
    }
    fn write(&self, out: &mut Vec<u8>, v: BspVersion) -> Result<()> {
        write_wide_u(out, v, self.plane, Self::LUMP, "plane")?;
        write_wide_u(out, v, self.side, Self::LUMP, "side")?;
        out.put_u32(self.first_edge);
        write_wide_u(out, v, self.num_edges, Self::LUMP, "edge count")?;
        write_wide_u(out, v, self.texinfo, Self::LUMP, "texinfo")?;
        out.extend_from_slice(&self.styles);
        out.put_i32(self.light_offset);
        Ok(())
    }
}

impl Record for u32 {
    const LUMP: &'static str = "marksurfaces";
    fn size(v: BspVersion) -> usize {
        wide_size(v)
    }
    fn read(r: &mut Reader, v: BspVersion) -> Result<Self> {
        read_wide_u(r, v)
    }
    fn write(&self, out: &mut Vec<u8>, v: BspVersion) -> Result<()> {
        write_wide_u(out, v, *self, Self::LUMP, "face")
    }
}

impl Record for [u32; 2] {
    const LUMP: &'static str = "edges";
    fn size(v: BspVersion) -> usize {
        2 * <u32 as Record>::size(v)
    }
    fn read(r: &mut Reader, v: BspVersion) -> Result<Self> {
        Ok([read_wide_u(r, v)?, read_wide_u(r, v)?])
    }
    fn write(&self, out: &mut Vec<u8>, v: BspVersion) -> Result<()> {
        for &i in self {
            write_wide_u(out, v, i, Self::LUMP, "vertex")?;
        }
        Ok(())
    }
}

impl Record for i32 {
    const LUMP: &'static str = "surfedges";
    fn size(_: BspVersion) -> usize {
        4
    }
    fn read(r: &mut Reader, _: BspVersion) -> Result<Self> {
        r.i32()
    }
    fn write(&self, out: &mut Vec<u8>, _: BspVersion) -> Result<()> {
        out.put_i32(*self);
        Ok(())
    }
}

/// A brush model: the world (model 0) or a brush entity, with one head node per hull.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Model {
    /// Lower corner of the model's box, in map units.
    pub mins: [f32; 3],
    /// Upper corner of the model's box.
    pub maxs: [f32; 3],
    /// A point stored with the model that engines do not place it by (the entity's `origin`
    /// key does); Slipgate writes zero.
    pub origin: [f32; 3],
    /// Hull 0 node, then clip node heads of hulls 1..3.
    pub head_nodes: [i32; 4],
    /// Leaves of this model that have PVS rows (the world's count excludes leaf 0).
    pub vis_leafs: i32,
    /// Index of the model's first face; a model's faces are one run.
    pub first_face: u32,
    /// Number of faces from `first_face` on.
    pub num_faces: u32,
}

impl Record for Model {
    const LUMP: &'static str = "models";
    fn size(_: BspVersion) -> usize {
        64
    }
    fn read(r: &mut Reader, _: BspVersion) -> Result<Self> {
        Ok(Model {
            mins: r.f32x3()?,
            maxs: r.f32x3()?,
            origin: r.f32x3()?,
            head_nodes: [r.i32()?, r.i32()?, r.i32()?, r.i32()?],
            vis_leafs: r.i32()?,
            first_face: r.u32()?,
            num_faces: r.u32()?,
        })
    }
    fn write(&self, out: &mut Vec<u8>, _: BspVersion) -> Result<()> {
        out.put_f32x3(self.mins);
        out.put_f32x3(self.maxs);
        out.put_f32x3(self.origin);
        for h in self.head_nodes {
            out.put_i32(h);
        }
        out.put_i32(self.vis_leafs);
        out.put_u32(self.first_face);
        out.put_u32(self.num_faces);
        Ok(())
    }
}
