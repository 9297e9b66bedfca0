//! Limits of the BSP29 format and of the engines that load it.
//!
//! BSP29 stores many indices in 16 bits; exceeding these makes the file unwritable (the writer
//! refuses and asks for BSP2). The engine limits below are what the engines that load the file
//! allocate or check, each named after the engine family it belongs to; the validator reports
//! them (see `validate`'s rules), writers do not enforce them.

/// Node children are signed 16-bit; negative values name leaves, so nodes stop at 32767.
pub const BSP29_MAX_NODES: usize = 32767;
/// Leaves are named by a child value `-(leaf + 1)` in a signed 16-bit field.
pub const BSP29_MAX_LEAFS: usize = 32768;
/// Clip node children are 16-bit; read as signed (the original engine, DarkPlaces), negative
/// values are contents, so clip nodes stop at 32767. Slipgate's compiler keeps to this.
pub const BSP29_MAX_CLIPNODES: usize = 32767;
/// FitzQuake's reading, kept by QuakeSpasm, vkQuake, Ironwail and FTE, and written by
/// ericw-tools' qbsp: a child is unsigned 16-bit, and a value at or past the clip node count is
/// contents (the value less 65536). Contents -1..-15 are 65521..65535, so clip nodes stop at
/// 65521. The format limit a BSP29 file is read and written back with.
pub const BSP29_MAX_CLIPNODES_UNSIGNED: usize = 65521;
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

/// Models the original engine can precache (world, brush entities and the game code's models);
/// protocol 15 also sends a model index in one byte.
pub const ENGINE_MAX_MODELS: usize = 256;
/// QuakeSpasm's model precache table (`MAX_MODELS`; vkQuake and Ironwail keep it): the server
/// precaches every submodel into it when the map starts.
pub const QUAKESPASM_MAX_MODELS: usize = 2048;
/// Leaves the original engines can have in a PVS (`MAX_MAP_LEAFS`, their decompression buffer).
pub const ENGINE_MAX_LEAFS: usize = 8192;
/// Leaves QuakeSpasm, vkQuake and Ironwail accept in a BSP29 file ("Mod_LoadLeafs: %i leafs
/// exceeds limit of 32767."), one fewer than the format's 16-bit leaf numbering allows.
pub const QUAKESPASM_MAX_BSP29_LEAFS: usize = 32767;
/// Light styles a face can carry; 255 marks an unused slot.
pub const MAX_LIGHTMAPS: usize = 4;
/// Texels per lightmap sample.
pub const LIGHTMAP_SCALE: i32 = 16;
/// Largest lightmap extent (texels) WinQuake accepts on a face without `TEX_SPECIAL` ("Bad surface
/// extents"); compilers subdivide faces to stay within it.
pub const MAX_SURFACE_EXTENT: i32 = 256;
/// GLQuake's extent limit on faces without `TEX_SPECIAL` ("Bad surface extents").
pub const GLQUAKE_MAX_SURFACE_EXTENT: i32 = 512;
/// QuakeSpasm's, vkQuake's and Ironwail's extent limit on faces without `TEX_SPECIAL` ("Bad
/// surface extents").
pub const QUAKESPASM_MAX_SURFACE_EXTENT: i32 = 2000;
/// Luxels across or down every engine that reads `LMSHIFT` must accept on a face (FTE's BSPX
/// notes); more at a face's shift is refused or drawn wrong.
pub const LMSHIFT_MAX_LIGHTMAP_SIZE: usize = 256;
/// Luxels across or down DarkPlaces accepts on a face it lightmaps ("Bad surface extents").
pub const DARKPLACES_MAX_LIGHTMAP_SIZE: usize = 256;
/// Vertices QuakeSpasm and vkQuake copy into a fixed buffer for a sky or unlit face.
pub const QUAKESPASM_MAX_UNLIT_FACE_VERTS: usize = 64;
/// Vertices QuakeSpasm, vkQuake and GLQuake accept on a liquid face they subdivide ("numverts =
/// %i").
pub const QUAKESPASM_MAX_WARP_FACE_VERTS: usize = 60;
/// Frames of an animated texture sequence: `+0`..`+9`, and alternates `+a`..`+j`.
pub const MAX_ANIMATION_FRAMES: usize = 10;
/// The sky texture size every engine's sky code expects.
pub const SKY_TEXTURE_SIZE: [u32; 2] = [256, 128];
/// The highest light style a face may use; 255 marks an empty style slot.
pub const MAX_LIGHTSTYLE: u8 = 254;
