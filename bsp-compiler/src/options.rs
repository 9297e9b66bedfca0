//! What a compile is asked to do.

use crate::outside::{FillType, Reach};
use crate::tree::{MID_SPLIT_SIZE, SplitHeuristic};
use quake_formats::BspVersion;
use quake_formats::bsp::limits::QUAKESPASM_MAX_UNLIT_FACE_VERTS;
use quake_formats::progress::Progress;
use std::path::PathBuf;

/// ericw-tools' default `-maxedges` for Quake: the vertex buffer QuakeSpasm and vkQuake copy sky
/// and unlit faces into.
pub const DEFAULT_MAX_EDGES: usize = QUAKESPASM_MAX_UNLIT_FACE_VERTS;

/// What a compile is asked to do.
#[derive(Debug, Clone)]
pub struct CompileOptions {
    /// The BSP version to write: BSP29 (the default), BSP2 (`-bsp2`) or 2PSB (`-2psb`). BSP29
    /// and 2PSB give way to BSP2, with a warning, when the map does not fit them.
    pub version: BspVersion,
    /// Directories searched for WADs (then `xwad_dirs`, the map's own directory and the working
    /// directory; see [`crate::wad_lookup::WadSearch`]).
    pub wad_dirs: Vec<PathBuf>,
    /// Directories searched for WADs whose textures are not embedded: only their names and
    /// sizes go into the BSP, for engines that load them from elsewhere (`-xwadpath`).
    pub xwad_dirs: Vec<PathBuf>,
    /// How the tree's splitting planes are chosen.
    pub heuristic: SplitHeuristic,
    /// Nodes spanning more than this are cut near their middle first (0: never).
    pub max_node_size: f64,
    /// Largest span of a lit face in texels before it is cut (0: never cut).
    pub subdivide: f64,
    /// Fill the void outside the map (off keeps it, for debugging; leaks are not looked for).
    pub fill: bool,
    /// Whether a sealed map's space no point entity reaches is filled too (`-filltype`).
    pub fill_type: FillType,
    /// Fill the space no point entity reaches leaf by leaf, so that pockets closed by detail
    /// brushes are filled too (`-filldetail`), whatever `fill_type` says.
    pub fill_detail: bool,
    /// Liquids are seen through (ericw-tools' `-transwater`, the default): they are detail for
    /// vis and it looks through their surfaces. Off (`-notranswater`): they are structural and
    /// vis stops at their surfaces, for engines that draw them opaque.
    pub transwater: bool,
    /// A brush model's liquid brushes are liquid, as in the world (ericw-tools'
    /// `-bmodelcontents`: a `func_door` of water swims in FTE; engines that collide with brush
    /// models only as solid give it no collision). Off: every brush of a brush model is solid.
    pub bmodel_contents: bool,
    /// Liquids get lightmaps and are subdivided like other faces, for the engines that light
    /// them (ericw-tools' `-litwater`, on by default; the `_litwater` key of worldspawn or a
    /// brush entity overrides it); engines that do not draw them fullbright as before.
    pub lit_water: bool,
    /// Faces left with more edges than this (by T-junction fixing) are cut into smaller ones,
    /// for engines that copy faces into fixed buffers (ericw-tools' `-maxedges`; 0: never).
    pub max_edges: usize,
    /// Build clip hulls 1 and 2 (off: every model is empty to them).
    pub clip_hulls: bool,
    /// Maps whose brushes and entities are merged into the compiled one (ericw-tools' `-add`):
    /// each one's worldspawn brushes join the world, its other entities follow.
    pub add: Vec<PathBuf>,
    /// Classnames whose brushes are left out of the compile (`--omitdetail` and its kin).
    pub omit: Vec<String>,
    /// Write texture pixels (off: names and sizes only, for engines that have the textures).
    pub texture_data: bool,
    /// Folders searched for loose textures (ericw-tools' `-path`): with `texture_data` off, a
    /// texture no WAD holds takes its size from `textures/NAME.png` (or `.tga`) in one.
    pub texture_paths: Vec<PathBuf>,
    /// A texture found nowhere is written as a 0x0 miptex with its name (ericw-tools'
    /// `-missing_textures_as_zero_size`) instead of a placeholder.
    pub missing_textures_as_zero_size: bool,
    /// Write the BSPX `BRUSHLIST` lump (see `crate::brushlist`).
    pub brush_list: bool,
    /// Keep editor-only keys (TrenchBroom's `_tb_*`) in the entity lump ([`crate::editor`]).
    pub keep_editor_keys: bool,
    /// Leave out the editor layers marked "Omit From Export", as TrenchBroom's Export does
    /// ([`crate::editor`]); ericw-tools compiles them.
    pub omit_layers: bool,
    /// Where the long phases report their progress.
    pub progress: Progress,
}

impl CompileOptions {
    /// How a sealed map's space no point entity reaches is filled, if it is.
    pub fn unreached_fill(&self) -> Option<Reach> {
        match (self.fill_type, self.fill_detail) {
            (_, true) => Some(Reach::Leaves),
            (FillType::Outside, false) => None,
            (FillType::Auto | FillType::Inside, false) => Some(Reach::Clusters),
        }
    }
}

impl Default for CompileOptions {
    fn default() -> Self {
        CompileOptions {
            version: BspVersion::Bsp29,
            wad_dirs: Vec::new(),
            xwad_dirs: Vec::new(),
            heuristic: SplitHeuristic::default(),
            max_node_size: MID_SPLIT_SIZE,
            subdivide: 240.0,
            fill: true,
            fill_type: FillType::default(),
            fill_detail: true,
            transwater: true,
            bmodel_contents: false,
            lit_water: true,
            max_edges: DEFAULT_MAX_EDGES,
            clip_hulls: true,
            add: Vec::new(),
            omit: Vec::new(),
            texture_data: true,
            texture_paths: Vec::new(),
            missing_textures_as_zero_size: false,
            brush_list: false,
            keep_editor_keys: false,
            omit_layers: false,
            progress: Progress::default(),
        }
    }
}
