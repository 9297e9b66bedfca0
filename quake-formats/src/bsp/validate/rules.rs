//! The named list of rules: what each checks, which engines enforce it and in what words.

use super::Severity;

/// One thing the validator checks. Each rule has a stable short id (printed by `slipgate info`),
/// one severity, the engines that enforce it and, where they print one, their message. The table
/// in `quake-formats/README.md` lists them all.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Rule {
    // Structure: what any reader of the format needs.
    /// `index-range`: an index, offset or range points outside the lump it refers to.
    IndexRange,
    /// `non-finite`: a plane, vertex, bound, texture axis or model origin is NaN or infinite.
    NonFinite,
    /// `plane-normal`: a plane's normal is not of unit length.
    PlaneNormal,
    /// `bsp29-limit`: a BSP29 file's count or bound does not fit its 16-bit field.
    Bsp29Limit,
    /// `entity-text`: the entity lump lacks its NUL or does not parse.
    EntityText,
    /// `face-edges`: a face has fewer than 3 edges.
    FaceEdges,
    /// `contents-value`: a leaf or clip node child holds no valid contents value.
    ContentsValue,
    /// `lightmap-range`: a lit face's lightmaps run past the lighting lump.
    LightmapRange,
    /// `bspx-light-size`: a per-luxel BSPX lump does not hold one record per luxel.
    BspxLightSize,
    /// `bspx-face-records`: a per-face BSPX lump does not hold one record per face.
    BspxFaceRecords,
    /// `decoupled-lightmap`: a `DECOUPLED_LM` lightmap runs past the lighting data or has a
    /// projection that is not finite.
    DecoupledLightmap,
    /// `shifted-lightmap`: an `LMSHIFT` lightmap runs past the lighting data or is too large.
    ShiftedLightmap,
    /// `light-grid`: the `LIGHTGRID_OCTREE` lump does not read.
    LightGrid,
    /// `no-world-model`: the models lump is empty, so there is no world.
    NoWorldModel,
    // What engines enforce when they load or play the file.
    /// `no-nodes`: the nodes lump is empty.
    NoNodes,
    /// `world-head-node`: the world's hull 0 tree does not start at node 0.
    WorldHeadNode,
    /// `hull-node-range`: a hull's tree reaches a node numbered before its head.
    HullNodeRange,
    /// `tree-cycle`: a node or clip node leads back to itself.
    TreeCycle,
    /// `clip-hulls-missing`: models name clip hull heads, but there are no clip nodes.
    ClipHullsMissing,
    /// `node-same-children`: a world node has the same child on both sides.
    NodeSameChildren,
    /// `node-plane-outside-region`: a world node's plane misses the region DarkPlaces gives it.
    NodePlaneOutsideRegion,
    /// `leaf-zero-solid`: leaf 0 is not solid.
    LeafZeroSolid,
    /// `surface-extents`: a lightmapped face is too large for mainstream engines.
    SurfaceExtents,
    /// `surface-extents-vanilla`: a lightmapped face is too large for WinQuake or GLQuake.
    SurfaceExtentsVanilla,
    /// `lightmap-extents-engines-disagree`: QuakeSpasm and DarkPlaces size a face's lightmap differently.
    LightmapExtentsEnginesDisagree,
    /// `no-vanilla-lighting`: lit faces have their light only in BSPX lumps.
    NoVanillaLighting,
    /// `unlit-face-verts`: a liquid, sky or untextured unlit face has more vertices than engines buffer.
    UnlitFaceVerts,
    /// `texture-alignment`: a texture's width or height is not a multiple of 16.
    TextureAlignment,
    /// `animation-name`: a `+` texture's frame character is not 0-9 or a-j.
    AnimationName,
    /// `animation-frames`: an animated sequence misses a frame below its highest.
    AnimationFrames,
    /// `sky-texture-size`: a sky texture is not 256x128.
    SkyTextureSize,
    /// `sky-name-case`: a sky texture's name does not start with lower-case `sky`.
    SkyNameCase,
    /// `texinfo-miptex`: a texinfo names a slot past the texture lump's count.
    TexinfoMiptex,
    /// `texture-missing`: a texinfo names a slot that holds no texture.
    TextureMissing,
    /// `leaf-count`: a BSP29 file has more than 32767 leafs.
    LeafCount,
    /// `vis-leafs`: the world's visleafs exceeds the leafs there are.
    VisLeafs,
    /// `vis-leafs-vanilla`: the world's visleafs exceeds vanilla's 8192.
    VisLeafsVanilla,
    /// `model-count`: the models leave no room for the game code's in a 2048-entry table.
    ModelCount,
    /// `model-count-vanilla`: the models leave no room for the game code's in a 256-entry table.
    ModelCountVanilla,
    /// `worldspawn`: there is no worldspawn entity.
    Worldspawn,
    /// `worldspawn-first`: the first entity is not the worldspawn.
    WorldspawnFirst,
    /// `player-start`: there is no info_player_start.
    PlayerStart,
}

/// What a rule is, for printing and for the documentation table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RuleInfo {
    /// Stable short id, e.g. `hull-node-range`.
    pub id: &'static str,
    /// How bad breaking the rule is.
    pub severity: Severity,
    /// The engine families that enforce the rule.
    pub engines: &'static str,
    /// What those engines print (or do, when they print nothing).
    pub message: &'static str,
    /// What the validator checks.
    pub checks: &'static str,
}

const QS: &str = "QuakeSpasm, vkQuake, Ironwail";

impl Rule {
    /// Every rule, in declaration order (structure first, then what engines enforce).
    pub const ALL: [Rule; 42] = [
        Rule::IndexRange,
        Rule::NonFinite,
        Rule::PlaneNormal,
        Rule::Bsp29Limit,
        Rule::EntityText,
        Rule::FaceEdges,
        Rule::ContentsValue,
        Rule::LightmapRange,
        Rule::BspxLightSize,
        Rule::BspxFaceRecords,
        Rule::DecoupledLightmap,
        Rule::ShiftedLightmap,
        Rule::LightGrid,
        Rule::NoWorldModel,
        Rule::NoNodes,
        Rule::WorldHeadNode,
        Rule::HullNodeRange,
        Rule::TreeCycle,
        Rule::ClipHullsMissing,
        Rule::NodeSameChildren,
        Rule::NodePlaneOutsideRegion,
        Rule::LeafZeroSolid,
        Rule::SurfaceExtents,
        Rule::SurfaceExtentsVanilla,
        Rule::LightmapExtentsEnginesDisagree,
        Rule::NoVanillaLighting,
        Rule::UnlitFaceVerts,
        Rule::TextureAlignment,
        Rule::AnimationName,
        Rule::AnimationFrames,
        Rule::SkyTextureSize,
        Rule::SkyNameCase,
        Rule::TexinfoMiptex,
        Rule::TextureMissing,
        Rule::LeafCount,
        Rule::VisLeafs,
        Rule::VisLeafsVanilla,
        Rule::ModelCount,
        Rule::ModelCountVanilla,
        Rule::Worldspawn,
        Rule::WorldspawnFirst,
        Rule::PlayerStart,
    ];

    /// The rule's stable short id, e.g. `hull-node-range`.
    pub fn id(self) -> &'static str {
        self.info().id
    }

    /// How bad breaking the rule is.
    pub fn severity(self) -> Severity {
        self.info().severity
    }

    /// Everything said about the rule: id, severity, engines, their message and what is checked.
    pub fn info(self) -> RuleInfo {
        use Severity::{Error, Warning};
        let (id, severity, engines, message, checks) = match self {
            Rule::IndexRange => (
                "index-range",
                Error,
                "all engines",
                "reads out of bounds, or a Mod_Load* error such as \"Mod_LoadMarksurfaces: bad \
                 surface number\"",
                "every index, offset and range into another lump lies inside it",
            ),
            Rule::NonFinite => (
                "non-finite",
                Error,
                "all engines",
                "NaN spreads through traces, culling and lightmaps",
                "no plane, vertex, bound, texture axis or model origin holds NaN or infinity",
            ),
            Rule::PlaneNormal => (
                "plane-normal",
                Error,
                "all engines",
                "traces and point tests measure distances with the normal",
                "every plane normal has length 1 (within 0.01)",
            ),
            Rule::Bsp29Limit => (
                "bsp29-limit",
                Error,
                "all engines (the format)",
                "16-bit fields wrap",
                "a BSP29 file's counts and bounds fit its 16-bit fields",
            ),
            Rule::EntityText => (
                "entity-text",
                Error,
                "all engines",
                "\"ED_LoadFromFile: found %s when expecting {\" (Host_Error)",
                "the entity lump is NUL-terminated and parses",
            ),
            Rule::FaceEdges => (
                "face-edges",
                Error,
                "DarkPlaces, Ironwail",
                "a negative triangle count (DarkPlaces); \"surfnum %d: bad numedges %d\" (Ironwail)",
                "every face has at least 3 edges",
            ),
            Rule::ContentsValue => (
                "contents-value",
                Error,
                "all engines",
                "a leaf whose contents is not negative is walked as a node",
                "leaf contents and clip node contents children are -1..-15",
            ),
            Rule::LightmapRange => (
                "lightmap-range",
                Error,
                "QuakeSpasm family, vanilla",
                "reads lightmaps past the lighting lump",
                "a lit face's lightmaps (one per style, sized from its extents) lie inside the \
                 lighting lump (or, without one, the luxels of RGBLIGHTING)",
            ),
            Rule::BspxLightSize => (
                "bspx-light-size",
                Error,
                "FTE, QuakeSpasm-Spiked, Ironwail",
                "the lump is ignored, or lightmaps are read past its end",
                "RGBLIGHTING and LIGHTINGDIR hold 3 bytes and LIGHTING_E5BGR9 4 bytes for every \
                 luxel of the lighting data",
            ),
            Rule::BspxFaceRecords => (
                "bspx-face-records",
                Error,
                "FTE, QuakeSpasm-Spiked, Ironwail",
                "the lump is ignored, or faces read records past its end",
                "LMSHIFT (1 byte), LMOFFSET (4 bytes) and DECOUPLED_LM (40 bytes) hold one whole \
                 record per face",
            ),
            Rule::DecoupledLightmap => (
                "decoupled-lightmap",
                Error,
                "FTE, QuakeSpasm-Spiked, Ironwail",
                "reads lightmaps past the lighting data; NaN texture coordinates",
                "a DECOUPLED_LM face with an offset has a size, its lightmaps (one per style) lie \
                 inside the lighting data, and its projection is finite",
            ),
            Rule::ShiftedLightmap => (
                "shifted-lightmap",
                Error,
                "FTE, QuakeSpasm-Spiked",
                "reads lightmaps past the lighting data; lightmaps over 256 luxels are refused",
                "an LMSHIFT face's lightmaps (at its LMOFFSET, else its light offset; one per \
                 style, sized at 1 << shift texels per luxel) lie inside the lighting data and \
                 span at most 256 luxels per axis",
            ),
            Rule::LightGrid => (
                "light-grid",
                Error,
                "FTE, QuakeSpasm-Spiked, Ironwail",
                "the grid is ignored or walked out of bounds",
                "LIGHTGRID_OCTREE reads whole: its counts fit the lump, its spacing is positive \
                 and finite, its leaves lie inside the grid and every child names a node or leaf \
                 without a cycle",
            ),
            Rule::NoWorldModel => (
                "no-world-model",
                Error,
                "all engines",
                "model 0 is the world",
                "the models lump has at least one model",
            ),
            Rule::NoNodes => (
                "no-nodes",
                Error,
                "DarkPlaces, QuakeSpasm family",
                "\"Mod_Q1BSP_LoadNodes: missing BSP tree in %s\" (DarkPlaces); QuakeSpasm reads node 0",
                "the nodes lump is not empty",
            ),
            Rule::WorldHeadNode => (
                "world-head-node",
                Error,
                QS,
                "\"SV_HullPointContents: bad node number\" (point contents start at node 0)",
                "the world model's hull 0 head is node 0",
            ),
            Rule::HullNodeRange => (
                "hull-node-range",
                Error,
                QS,
                "\"SV_RecursiveHullCheck: bad node number\" (Sys_Error on the first trace)",
                "for every model and hulls 0-2, every node reachable from the head is numbered at \
                 or after the head (a hull spans its head to the lump's last node)",
            ),
            Rule::TreeCycle => (
                "tree-cycle",
                Error,
                "all engines",
                "Mod_SetParent recurses without end; traces never reach a leaf",
                "no node or clip node reachable from a head leads back to itself",
            ),
            Rule::ClipHullsMissing => (
                "clip-hulls-missing",
                Error,
                QS,
                "\"SV_RecursiveHullCheck: bad node number\" once a player or monster moves",
                "a file whose models name clip hull heads has clip nodes",
            ),
            Rule::NodeSameChildren => (
                "node-same-children",
                Error,
                "DarkPlaces (mod_bsp_portalize 1, the default of older builds such as Debian's)",
                "\"Mod_Q1BSP_RecursiveNodePortals: corrupt node hierarchy\" (Host_Error)",
                "no node of the world's tree has the same child on both sides",
            ),
            Rule::NodePlaneOutsideRegion => (
                "node-plane-outside-region",
                Warning,
                "DarkPlaces (mod_bsp_portalize 1, the default of older builds such as Debian's)",
                "\"Mod_Q1BSP_RecursiveNodePortals: WARNING: new portal was clipped away\"; the \
                 node's children get no portal between them, which portal culling and \
                 r_drawportals use",
                "no node of the world's tree has a plane that misses its region, as DarkPlaces \
                 finds it building portals at load (its procedure replayed in its precision)",
            ),
            Rule::LeafZeroSolid => (
                "leaf-zero-solid",
                Warning,
                "all engines",
                "leaf 0 is the shared solid leaf: never drawn, never in a PVS",
                "leaf 0's contents are solid",
            ),
            Rule::SurfaceExtents => (
                "surface-extents",
                Error,
                "QuakeSpasm, vkQuake, Ironwail, DarkPlaces",
                "\"Bad surface extents\" (Sys_Error; Host_Error in DarkPlaces)",
                "a face without TEX_SPECIAL spans at most 2000 texels per axis (QuakeSpasm family); \
                 a face DarkPlaces lightmaps (not TEX_SPECIAL, or lit) at most 256 luxels",
            ),
            Rule::SurfaceExtentsVanilla => (
                "surface-extents-vanilla",
                Warning,
                "WinQuake, GLQuake",
                "\"Bad surface extents\" (Sys_Error)",
                "a face without TEX_SPECIAL spans at most 256 texels per axis (WinQuake; GLQuake \
                 allows 512)",
            ),
            Rule::LightmapExtentsEnginesDisagree => (
                "lightmap-extents-engines-disagree",
                Warning,
                "DarkPlaces vs QuakeSpasm family",
                "one of them reads the face's lightmap with another row length or origin than the \
                 light tool wrote: drawn skewed or shifted (past the lighting lump for the last \
                 face)",
                "a face without TEX_SPECIAL gets the same lightmap extents from QuakeSpasm's rule \
                 (texture coordinates summed in double, kept as float) and DarkPlaces' (summed \
                 in float)",
            ),
            Rule::NoVanillaLighting => (
                "no-vanilla-lighting",
                Warning,
                "QuakeSpasm 0.95, DarkPlaces, vanilla (engines without BSPX RGBLIGHTING)",
                "the map is drawn unlit (fullbright): the grey lighting lump is empty",
                "a map whose faces have lightmaps also has the grey lighting lump (ericw-tools' \
                 -novanilla leaves it out)",
            ),
            Rule::UnlitFaceVerts => (
                "unlit-face-verts",
                Error,
                "QuakeSpasm, vkQuake, GLQuake",
                "\"numverts = %i\" (Sys_Error) for liquids; sky overruns a 64-vertex buffer",
                "liquid (`*`) faces have at most 60 edges; sky faces and unlit faces without a \
                 texture at most 64",
            ),
            Rule::TextureAlignment => (
                "texture-alignment",
                Warning,
                "WinQuake, GLQuake",
                "\"Texture %s is not 16 aligned\" (Sys_Error; newer engines only warn)",
                "texture width and height are multiples of 16",
            ),
            Rule::AnimationName => (
                "animation-name",
                Error,
                "QuakeSpasm family, vanilla, FTE",
                "\"Bad animating texture %s\" (Sys_Error; FTE fails the load; DarkPlaces only \
                 prints it)",
                "a `+` texture's second character is a frame: 0-9 or a-j (either case)",
            ),
            Rule::AnimationFrames => (
                "animation-frames",
                Error,
                "QuakeSpasm family, vanilla, FTE",
                "\"Missing frame %i of %s\" (Sys_Error; FTE fails the load; DarkPlaces only \
                 prints it)",
                "every animated sequence (`+` textures sharing the name after the frame) has all \
                 its frames from 0 (and from a) up to its highest",
            ),
            Rule::SkyTextureSize => (
                "sky-texture-size",
                Warning,
                "QuakeSpasm family, vanilla",
                "\"Sky texture %s is %d x %d, expected 256 x 128\" (QuakeSpasm); vanilla reads \
                 256x128 texels anyway",
                "textures named sky* are 256x128",
            ),
            Rule::SkyNameCase => (
                "sky-name-case",
                Error,
                "DarkPlaces (older builds, e.g. Debian's 0~20180908)",
                "segfaults loading a sky texture whose name is not lower case (current \
                 DarkPlaces lower-cases names first, \"so we don't crash on e2m9\")",
                "a texture whose name starts with sky in any case starts with lower-case sky",
            ),
            Rule::TexinfoMiptex => (
                "texinfo-miptex",
                Warning,
                "WinQuake, GLQuake",
                "\"miptex >= loadmodel->numtextures\" (Sys_Error); newer engines draw no texture",
                "every texinfo names a slot of the texture lump",
            ),
            Rule::TextureMissing => (
                "texture-missing",
                Warning,
                "all engines",
                "drawn with the notexture checkerboard",
                "every texture a texinfo names is stored (its offset is not -1)",
            ),
            Rule::LeafCount => (
                "leaf-count",
                Error,
                QS,
                "\"Mod_LoadLeafs: %i leafs exceeds limit of 32767.\" (Host_Error)",
                "a BSP29 file has at most 32767 leafs",
            ),
            Rule::VisLeafs => (
                "vis-leafs",
                Error,
                "QuakeSpasm family, vanilla",
                "R_MarkLeaves reads leafs past the end",
                "the world model's visleafs is at most the leaf count minus one",
            ),
            Rule::VisLeafsVanilla => (
                "vis-leafs-vanilla",
                Warning,
                "WinQuake, GLQuake",
                "PVS buffers of MAX_MAP_LEAFS (8192) overflow",
                "the world model's visleafs is at most 8192",
            ),
            Rule::ModelCount => (
                "model-count",
                Error,
                QS,
                "\"PF_precache_model: overflow\" (Host_Error): the submodels fill the 2048-entry \
                 model table",
                "the world and submodels leave room in a 2048-entry model table for the game \
                 code's models (at most 2046 models)",
            ),
            Rule::ModelCountVanilla => (
                "model-count-vanilla",
                Warning,
                "WinQuake, GLQuake, protocol 15",
                "\"PF_precache_model: overflow\" in a 256-entry table; protocol 15 sends model \
                 numbers in one byte",
                "the world and submodels leave room in a 256-entry model table (at most 254 models)",
            ),
            Rule::Worldspawn => (
                "worldspawn",
                Error,
                "QuakeSpasm family, vanilla (with id1-style game code)",
                "\"SV_ModelIndex: model progs/player.mdl not precached\" (Sys_Error when the player \
                 spawns: the game code's worldspawn() precaches it)",
                "there is a worldspawn entity",
            ),
            Rule::WorldspawnFirst => (
                "worldspawn-first",
                Warning,
                "all engines",
                "the first entity is spawned as the world (edict 0), whatever its class",
                "the first entity is the worldspawn",
            ),
            Rule::PlayerStart => (
                "player-start",
                Warning,
                "id1 and LibreQuake game code",
                "\"PutClientInServer: no info_player_start on level\" (single player)",
                "there is an info_player_start",
            ),
        };
        RuleInfo {
            id,
            severity,
            engines,
            message,
            checks,
        }
    }
}

impl std::fmt::Display for Rule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.id())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_unique_and_kebab_case() {
        let mut ids: Vec<&str> = Rule::ALL.iter().map(|r| r.id()).collect();
        assert!(ids.iter().all(|id| {
            id.chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
        }));
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), Rule::ALL.len());
    }

    #[test]
    fn all_lists_every_rule_once_in_order() {
        let mut sorted = Rule::ALL;
        sorted.sort();
        assert_eq!(sorted, Rule::ALL);
        assert_eq!(Rule::ALL.first(), Some(&Rule::IndexRange));
        assert_eq!(Rule::ALL.last(), Some(&Rule::PlayerStart));
    }

    /// The README's rule table names every rule with its severity, so the two cannot drift.
    #[test]
    fn readme_documents_every_rule() {
        let readme = include_str!("../../../README.md");
        for rule in Rule::ALL {
            let row = format!("| `{}` | {} |", rule.id(), rule.severity());
            assert!(readme.contains(&row), "README lacks the row {row}");
        }
    }
}
