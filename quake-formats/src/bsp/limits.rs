//! Limits of the BSP29 format and of the engines that load it.
//!
//! BSP29 stores many indices in 16 bits; exceeding these makes the file unwritable (the writer
//! refuses and asks for BSP2). The engine limits below are what vanilla-derived engines allocate;
//! they are reported, not enforced, because modern engines raise them.

/// Node children are signed 16-bit; negative values name leaves, so nodes stop at 32767.
pub const BSP29_MAX_NODES: usize = 32767;
/// Leaves are named by a child value `-(leaf + 1)` in a signed 16-bit field.
pub const BSP29_MAX_LEAFS: usize = 32768;
/// Clip node children are signed 16-bit; negative values are contents.
pub const BSP29_MAX_CLIPNODES: usize = 32767;
/// Faces name their plane with an unsigned 16-bit index.
pub const BSP29_MAX_PLANES: usize = 65536;
/// Edges name their vertices with unsigned 16-bit indices.
pub const BSP29_MAX_VERTICES: usize = 65536;
/// Nodes name their first face and mark surfaces name faces with unsigned 16-bit indices.
pub const BSP29_MAX_FACES: usize = 65536;
/// Leaves name their first mark surface with an unsigned 16-bit index.
pub const BSP29_MAX_MARKSURFACES: usize = 65536;
/// Faces name their texinfo with a signed 16-bit index.
pub const BSP29_MAX_TEXINFO: usize = 32768;
/// Faces store their edge count in a signed 16-bit field.
pub const BSP29_MAX_FACE_EDGES: usize = 32767;
/// Node and leaf bounds are signed 16-bit integers.
pub const BSP29_MAX_COORD: f32 = 32767.0;

/// Models (world + brush entities) the original engine can precache.
pub const ENGINE_MAX_MODELS: usize = 256;
/// Leaves the original software renderer can mark visible.
pub const ENGINE_MAX_LEAFS: usize = 8192;
/// Light styles a face can carry; 255 marks an unused slot.
pub const MAX_LIGHTMAPS: usize = 4;
/// Texels per lightmap sample.
pub const LIGHTMAP_SCALE: i32 = 16;
/// Largest lightmap extent (texels) vanilla engines accept on a lit face ("Bad surface extents").
pub const MAX_SURFACE_EXTENT: i32 = 256;
/// The highest light style a face may use; 255 marks an empty style slot.
pub const MAX_LIGHTSTYLE: u8 = 254;
