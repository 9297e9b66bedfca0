//! The whole compile: parse, build brushes, build each model's trees (in parallel), fill the
//! outside, make faces, and emit the BSP and portal file.

use crate::brush::{Brush, BrushKind, BrushPlane};
use crate::brushlist::{ListedBrush, brush_list_lump};
use crate::csg::mark_hidden_sides;
use crate::emit::{EmitInput, emit};
use crate::faces::{
    FaceStats, FaceTexInfo, MIN_SQUARENESS, ModelFace, cut_for_lightmaps, faces_from_portals,
    merge_faces, projection_squareness,
};
use crate::hulls::{HULL_BOXES, expand_brush};
use crate::lightmap_grid::{LightmapGridStats, agree_on_lightmap_grid};
use crate::map::{MapBrush, MapEntity, MapError, MapFile, parse_map, read_map_text};
use crate::outside::{FillOutcome, LeakReport, MapBrushRef, Occupant, OnPlane, fill_outside};
use crate::planes::PlaneSet;
use crate::portals::{Portals, make_cluster_portals, make_portals};
use crate::prefab::{PrefabError, expand_prefabs};
use crate::surface_tree::rebuild_from_surfaces;
use crate::texinfo::{self, FaceContents, Projection, TextureRole};
use crate::tree::{
    DETAIL_WALL, FENCE, ILLUSIONARY, MID_SPLIT_SIZE, SplitHeuristic, Splitting, Tree, VISBLOCKER,
    build_clip_hull_tree, build_tree, engine_contents,
};
use crate::wad_lookup::WadSet;
use crate::warnings::{DroppedFace, Warning};
use glam::DVec3;
use quake_formats::bsp::contents;
use quake_formats::bsp::phong::{self, FacePhong};
use quake_formats::entities::Entity;
use quake_formats::geom::{Bounds, POINT_EPSILON, Plane};
use quake_formats::progress::Progress;
use quake_formats::prt::PortalFile;
use quake_formats::{Bsp, BspVersion, FormatError};
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A `.map` file's text and where it came from (for messages and WAD lookup).
#[derive(Debug, Clone)]
pub struct MapSource {
    pub path: PathBuf,
    pub text: String,
}

impl MapSource {
    pub fn read(path: &Path) -> Result<MapSource, CompileError> {
        let text = read_map_text(path).map_err(|source| CompileError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(MapSource {
            path: path.to_path_buf(),
            text,
        })
    }
}

#[derive(Debug, Clone)]
pub struct CompileOptions {
    /// Write BSP2 even when BSP29 would do.
    pub bsp2: bool,
    /// Directories searched for WADs (the map's own directory is searched last).
    pub wad_dirs: Vec<PathBuf>,
    pub heuristic: SplitHeuristic,
    /// Nodes spanning more than this are cut near their middle first (0: never).
    pub max_node_size: f64,
    /// Largest span of a lit face in texels before it is cut (0: never cut).
    pub subdivide: f64,
    /// Fill the void outside the map (off keeps it, for debugging; leaks are not looked for).
    pub fill: bool,
    /// Build clip hulls 1 and 2 (off: every model is empty to them).
    pub clip_hulls: bool,
    /// Classnames whose brushes are left out of the compile (`--omitdetail` and its kin).
    pub omit: Vec<String>,
    /// Write texture pixels (off: names and sizes only, for engines that have the textures).
    pub texture_data: bool,
    /// Write the BSPX `BRUSHLIST` lump (see [`crate::brushlist`]).
    pub brush_list: bool,
    /// Where the long phases report their progress.
    pub progress: Progress,
}

impl Default for CompileOptions {
    fn default() -> Self {
        CompileOptions {
            bsp2: false,
            wad_dirs: Vec::new(),
            heuristic: SplitHeuristic::default(),
            max_node_size: MID_SPLIT_SIZE,
            subdivide: 240.0,
            fill: true,
            clip_hulls: true,
            omit: Vec::new(),
            texture_data: true,
            brush_list: false,
            progress: Progress::default(),
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum CompileError {
    #[error(transparent)]
    Map(#[from] MapError),
    #[error(transparent)]
    Prefab(#[from] PrefabError),
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: the first entity must be worldspawn, found {found:?}", path.display())]
    NoWorldspawn { path: PathBuf, found: String },
    /// Nothing in the world to draw or see (id's qbsp stopped here too: "Entity with no valid
    /// brushes").
    #[error(
        "{}: worldspawn (entity 0) has no brushes to build{detail}: there is no world to compile",
        path.display()
    )]
    EmptyWorld {
        path: PathBuf,
        /// Why the brushes the map gives it, if any, were left out.
        detail: String,
    },
    #[error("writing the BSP: {0}")]
    Format(#[from] FormatError),
    /// The compiled BSP breaks a rule every later stage refuses (`quake_formats::check_usable`),
    /// e.g. a face whose texture scale makes its lightmap extents huge.
    #[error("{}: the compiled BSP would be {refused}", path.display())]
    Unusable { path: PathBuf, refused: FormatError },
}

/// Counts and timings of one compile.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct CompileStats {
    pub version: String,
    pub heuristic: SplitHeuristic,
    pub entities: usize,
    pub models: usize,
    pub brushes: usize,
    pub bad_brushes: usize,
    pub planes: usize,
    pub nodes: usize,
    pub leaves: usize,
    pub faces: usize,
    pub splits: usize,
    pub clipnodes: usize,
    pub portals: usize,
    pub vis_portals: usize,
    /// Vis clusters (PRT2), or vis leaves when the world has no detail (PRT1).
    pub clusters: usize,
    pub vertices: usize,
    pub edges: usize,
    pub texinfo: usize,
    pub textures: usize,
    pub filled_leaves: usize,
    pub tjunction_vertices: usize,
    pub leaked: bool,
    pub face_stats: FaceStats,
    /// Texture offsets nudged so QuakeSpasm and DarkPlaces size every lightmap alike.
    pub lightmap_grid: LightmapGridStats,
    /// Phase name and seconds; phases run per model are summed over models (CPU time).
    pub timings: Vec<(String, f64)>,
}

/// Everything a compile produces.
#[derive(Debug, Clone)]
pub struct CompileOutput {
    pub bsp: Bsp,
    pub portals: PortalFile,
    pub leak: Option<LeakReport>,
    pub warnings: Vec<Warning>,
    pub stats: CompileStats,
}

/// A map texinfo: projection vectors and texture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapTexInfo {
    pub vecs: [[f64; 4]; 2],
    /// Index into the texture name list.
    pub texture: u32,
    pub role: TextureRole,
    /// The `_phong` group of the world-merged entity the face came from.
    pub phong: FacePhong,
}

/// One model's brushes before tree building.
struct ModelInput {
    entity: usize,
    brushes: Vec<Brush>,
    /// Grown brushes of hulls 1 and 2.
    hull_brushes: [Vec<Brush>; 2],
    /// Bounds of the clip brushes, which only exist grown in the hulls.
    clip_bounds: Bounds,
}

/// Progress units [`build_model`] reports per brush of [`ModelInput::work`]: one for its CSG,
/// one for its tree, one for filling and faces.
const MODEL_WORK_PER_BRUSH: usize = 3;

impl ModelInput {
    /// Brushes of all three trees: the unit of model building progress.
    fn work(&self) -> usize {
        self.brushes.len() + self.hull_brushes[0].len() + self.hull_brushes[1].len()
    }

    fn new(entity: usize) -> ModelInput {
        ModelInput {
            entity,
            brushes: Vec::new(),
            hull_brushes: [Vec::new(), Vec::new()],
            clip_bounds: Bounds::EMPTY,
        }
    }
}

/// One model's trees and faces.
pub(crate) struct ModelOutput {
    pub tree: Tree,
    pub portals: Portals,
    /// Portals between the structural leaves, when detail split some of them.
    pub cluster_portals: Option<Portals>,
    pub faces: Vec<ModelFace>,
    pub hulls: [Tree; 2],
    pub bounds: Bounds,
    pub fill: Option<FillOutcome>,
    pub face_stats: FaceStats,
    pub timings: [f64; 6],
}

const MODEL_PHASES: [&str; 6] = ["tree", "portals", "outside", "faces", "hulls", "csg"];

/// How an entity's brushes enter the compile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum EntityBrushes {
    /// Worldspawn and `func_group`.
    World,
    /// `func_detail`: world brushes that do not split the vis structure.
    Detail,
    /// `func_detail_wall`: detail that leaves the faces it touches whole.
    DetailWall,
    /// `func_detail_fence`: detail with see-through (fence) textures.
    Fence,
    /// `func_detail_illusionary`: drawn detail without collision.
    Illusionary,
    /// `func_illusionary_visblocker`: drawn, walked through, and closed to vis.
    VisBlocker,
    /// A brush entity of its own.
    Submodel,
}

impl EntityBrushes {
    pub(crate) fn of(index: usize, classname: &str) -> EntityBrushes {
        match classname {
            _ if index == 0 => EntityBrushes::World,
            "func_group" => EntityBrushes::World,
            "func_detail" => EntityBrushes::Detail,
            "func_detail_wall" => EntityBrushes::DetailWall,
            "func_detail_fence" => EntityBrushes::Fence,
            "func_detail_illusionary" => EntityBrushes::Illusionary,
            "func_illusionary_visblocker" => EntityBrushes::VisBlocker,
            _ => EntityBrushes::Submodel,
        }
    }

    fn kind(self) -> BrushKind {
        match self {
            EntityBrushes::World | EntityBrushes::Submodel | EntityBrushes::VisBlocker => {
                BrushKind::Structural
            }
            _ => BrushKind::Detail,
        }
    }
}

/// Texture names and texinfos, interned in first-use order.
#[derive(Default)]
struct TexInfoTable {
    names: Vec<String>,
    name_index: HashMap<String, u32>,
    infos: Vec<MapTexInfo>,
    info_index: HashMap<([u64; 8], u32, u32), u32>,
}

impl TexInfoTable {
    /// The texinfo of `name` projected by `vecs` on a face of `phong`'s group
    /// (faces of different groups never share one, so they never merge).
    fn intern(&mut self, name: &str, vecs: [[f64; 4]; 2], phong: FacePhong) -> u32 {
        let key = name.to_ascii_lowercase();
        let texture = match self.name_index.get(&key) {
            Some(&i) => i,
            None => {
                let i = self.names.len() as u32;
                self.names.push(name.to_string());
                self.name_index.insert(key, i);
                i
            }
        };
        let bits: [u64; 8] = std::array::from_fn(|i| (vecs[i / 4][i % 4] as f32).to_bits() as u64);
        if let Some(&i) = self.info_index.get(&(bits, texture, phong.group)) {
            return i;
        }
        let i = self.infos.len() as u32;
        self.infos.push(MapTexInfo {
            vecs,
            texture,
            role: TextureRole::of(name),
            phong,
        });
        self.info_index.insert((bits, texture, phong.group), i);
        i
    }
}

/// Compile a map.
pub fn compile(
    source: &MapSource,
    options: &CompileOptions,
) -> Result<CompileOutput, CompileError> {
    let total = Instant::now();
    let mut timings = Vec::new();
    let mut warnings = Vec::new();
    let mut stats = CompileStats {
        heuristic: options.heuristic,
        ..CompileStats::default()
    };

    let t = Instant::now();
    let map = read_map(source)?;
    stats.entities = map.entities.len();
    timings.push(("parse".to_string(), t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let mut planes = PlaneSet::new();
    let mut table = TexInfoTable::default();
    let mut models: Vec<ModelInput> = vec![ModelInput::new(0)];
    let entities = lump_entities(&map, &options.omit);
    let mut occupants = Vec::new();
    // Each entity's first brush in one numbering of every map brush (`Brush::source`).
    let first_source: Vec<u32> = map
        .entities
        .iter()
        .scan(0u32, |next, e| {
            let first = *next;
            *next += e.brushes.len() as u32;
            Some(first)
        })
        .collect();
    let mut skipped_hint = 0;
    // Per model, when `brush_list` asks for them.
    let mut listed: Vec<Vec<ListedBrush>> = Vec::new();
    let progress = &options.progress;
    progress.start("brushes", map.entities.len());
    for (index, ent) in map.entities.iter().enumerate() {
        progress.advance(1);
        let class = ent.entity.classname();
        if index > 0 && options.omit.iter().any(|c| c == class) {
            continue;
        }
        if index > 0 && ent.brushes.is_empty() {
            occupants.extend(occupant(ent, index));
            continue;
        }
        let brush_class = EntityBrushes::of(index, class);
        let origin = match brush_class {
            EntityBrushes::Submodel => submodel_origin(&map.entities, ent, &mut planes),
            _ => None,
        };
        let model = if brush_class == EntityBrushes::Submodel {
            models.push(ModelInput::new(index));
            models.len() - 1
        } else {
            0
        };
        let mut cx = EntityContext {
            entity: index,
            first_source: first_source[index],
            class: brush_class,
            origin: origin.unwrap_or(DVec3::ZERO),
            phong: merged_phong(ent, index, brush_class),
            table: &mut table,
            warnings: &mut warnings,
        };
        let (built, bad, hints) = cx.build_brushes(ent, &mut planes);
        stats.brushes += ent.brushes.len();
        stats.bad_brushes += bad;
        skipped_hint += hints;
        if options.brush_list {
            listed.resize_with(models.len(), Vec::new);
            listed[model].extend(
                built
                    .iter()
                    .filter_map(|(b, clip)| listed_brush(b, *clip, &planes)),
            );
        }
        let m = &mut models[model];
        for (brush, clip) in built {
            let collides = matches!(
                engine_contents(brush.contents),
                contents::SOLID | contents::SKY
            );
            for (hull, (mins, maxs)) in HULL_BOXES.iter().enumerate() {
                if options.clip_hulls
                    && (collides || clip)
                    && let Some(g) = expand_brush(&brush, &mut planes, *mins, *maxs)
                {
                    m.hull_brushes[hull].push(g);
                }
            }
            if clip {
                m.clip_bounds = m.clip_bounds.union(&brush.bounds);
            } else {
                m.brushes.push(brush);
            }
        }
    }
    progress.finish();
    require_world_brushes(source, &map.entities, &models[0], &warnings)?;
    if skipped_hint > 0 {
        warnings.push(Warning::Unsupported {
            what: format!("{skipped_hint} hint brushes in brush entities are ignored"),
        });
    }
    for m in &models[1..] {
        if m.brushes.is_empty() && m.hull_brushes[0].is_empty() {
            warnings.push(Warning::EmptyBrushEntity {
                entity: m.entity,
                classname: map.entities[m.entity].entity.classname().to_string(),
            });
        }
    }
    timings.push(("brushes".to_string(), t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let face_texinfos: Vec<FaceTexInfo> = table
        .infos
        .iter()
        .map(|i| FaceTexInfo {
            vecs: i.vecs,
            role: i.role,
        })
        .collect();
    progress.start(
        "models",
        models.iter().map(ModelInput::work).sum::<usize>() * MODEL_WORK_PER_BRUSH,
    );
    let results: Vec<(ModelOutput, Vec<Warning>)> = models
        .into_par_iter()
        .enumerate()
        .map(|(i, m)| {
            let occ: &[Occupant] = if i == 0 { &occupants } else { &[] };
            build_model(m, &planes, &face_texinfos, options, occ)
        })
        .collect();
    progress.finish();
    timings.push(("models (wall)".to_string(), t.elapsed().as_secs_f64()));
    let mut outputs = Vec::with_capacity(results.len());
    let mut phase_sums = [0.0; 6];
    let mut leak = None;
    for (out, w) in results {
        warnings.extend(w);
        for (sum, t) in phase_sums.iter_mut().zip(out.timings) {
            *sum += t;
        }
        stats.splits += out.tree.splits;
        stats.portals += out.portals.portals.len();
        let fs = &mut stats.face_stats;
        fs.from_portals += out.face_stats.from_portals;
        fs.untextured += out.face_stats.untextured;
        fs.after_merge += out.face_stats.after_merge;
        match &out.fill {
            Some(FillOutcome::Leaked(l)) => {
                let report = l.report(
                    |source| map_brush(&map, &first_source, source),
                    |texinfo| table.names[table.infos[texinfo as usize].texture as usize].clone(),
                );
                warnings.push(Warning::Leak(report.clone()));
                leak = Some(report);
            }
            Some(FillOutcome::NoOccupants) => warnings.push(Warning::NoEntitiesToFlood),
            Some(FillOutcome::Sealed { filled }) => stats.filled_leaves = *filled,
            None => {}
        }
        outputs.push(out);
    }
    stats.face_stats.squared_up =
        square_up_projections(&mut outputs, &planes, &mut table, options.subdivide);
    stats.face_stats.after_subdivide = outputs.iter().map(|o| o.faces.len()).sum();
    for (name, sum) in MODEL_PHASES.iter().zip(phase_sums) {
        timings.push((format!("  {name} (sum over models)"), sum));
    }
    stats.leaked = leak.is_some();

    let t = Instant::now();
    let wads = WadSet::load(
        map.entities[0].entity.get("wad").unwrap_or(""),
        &wad_search_dirs(source, options),
        &mut warnings,
    );
    let version = if options.bsp2 {
        BspVersion::Bsp2
    } else {
        BspVersion::Bsp29
    };
    let emitted = emit(EmitInput {
        models: &outputs,
        planes: &planes,
        texinfos: &table.infos,
        texture_names: &table.names,
        wads: &wads,
        entities: &entities,
        version,
        warnings: &mut warnings,
    });
    let mut bsp = emitted.bsp;
    stats.lightmap_grid = agree_on_lightmap_grid(&mut bsp);
    if options.brush_list {
        listed.resize_with(bsp.models.len(), Vec::new);
        bsp.bspx.push(brush_list_lump(&listed));
    }
    if !options.texture_data {
        for t in bsp.textures.textures.iter_mut().flatten() {
            t.mips = None;
        }
    }
    if bsp.version == BspVersion::Bsp29
        && let Err(e) = bsp.check_bsp29_limits()
    {
        warnings.push(Warning::Unsupported {
            what: format!("{e}; switching to BSP2 automatically"),
        });
        bsp.version = BspVersion::Bsp2;
    }
    timings.push(("emit".to_string(), t.elapsed().as_secs_f64()));
    timings.push(("total".to_string(), total.elapsed().as_secs_f64()));

    stats.version = bsp.version.to_string();
    stats.models = bsp.models.len();
    stats.planes = bsp.planes.len();
    stats.nodes = bsp.nodes.len();
    stats.leaves = bsp.leafs.len();
    stats.faces = bsp.faces.len();
    stats.clipnodes = bsp.clipnodes.len();
    stats.vertices = bsp.vertices.len();
    stats.edges = bsp.edges.len();
    stats.texinfo = bsp.texinfo.len();
    stats.textures = bsp.textures.textures.len();
    stats.vis_portals = emitted.portals.portals.len();
    stats.clusters = emitted
        .portals
        .clusters
        .as_ref()
        .map_or(emitted.portals.num_leafs as usize, Vec::len);
    stats.tjunction_vertices = emitted.tjunction_vertices;
    stats.timings = timings;
    // The last line of defence: never hand on a BSP every later stage would refuse.
    quake_formats::check_usable(&bsp).map_err(|refused| CompileError::Unusable {
        path: source.path.clone(),
        refused,
    })?;
    Ok(CompileOutput {
        bsp,
        portals: emitted.portals,
        leak,
        warnings,
        stats,
    })
}

/// Parse a map, its prefabs expanded; the first entity must be worldspawn.
/// The folders searched, in order, for the WADs a map names: `options.wad_dirs`, then the map's
/// own folder.
pub fn wad_search_dirs(source: &MapSource, options: &CompileOptions) -> Vec<PathBuf> {
    let mut search = options.wad_dirs.clone();
    if let Some(dir) = source.path.parent() {
        search.push(if dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            dir.to_path_buf()
        });
    }
    search
}

pub(crate) fn read_map(source: &MapSource) -> Result<MapFile, CompileError> {
    let map = expand_prefabs(parse_map(&source.path, &source.text)?, &source.path)?;
    let classname = map
        .entities
        .first()
        .map(|e| e.entity.classname())
        .unwrap_or("");
    if classname != "worldspawn" {
        return Err(CompileError::NoWorldspawn {
            path: source.path.clone(),
            found: classname.to_string(),
        });
    }
    Ok(map)
}

/// The entity lump's entities for `map` (leaving out the classes in `omit`): worldspawn, the
/// point entities, and each brush entity not merged into the world, numbered `*1`, `*2`... in
/// order, with the origin its brushes are built around. Merged entities (`func_group`,
/// `func_detail*`, brushless ones too: they have no spawn function in any game) are left out.
pub(crate) fn lump_entities(map: &MapFile, omit: &[String]) -> Vec<Entity> {
    let mut planes = PlaneSet::new();
    let mut models = 0;
    let mut out = Vec::new();
    for (index, ent) in map.entities.iter().enumerate() {
        let class = ent.entity.classname();
        if index > 0 && omit.iter().any(|c| c == class) {
            continue;
        }
        if index == 0 || EntityBrushes::of(index, class) != EntityBrushes::Submodel {
            if index == 0 {
                out.push(ent.entity.clone());
            }
            continue;
        }
        let mut e = ent.entity.clone();
        if !ent.brushes.is_empty() {
            models += 1;
            e.set("model", format!("*{models}"));
            if let Some(o) = submodel_origin(&map.entities, ent, &mut planes) {
                e.set("origin", format!("{} {} {}", o.x, o.y, o.z));
            }
        }
        out.push(e);
    }
    out
}

/// A submodel with an origin brush is built around that brush's centre, which becomes its
/// "origin" (what rotating entities turn about); without one, around its origin key.
fn submodel_origin(
    entities: &[MapEntity],
    ent: &MapEntity,
    planes: &mut PlaneSet,
) -> Option<DVec3> {
    origin_brush_centre(ent, planes).or_else(|| key_origin(entities, ent))
}

/// Give each face whose texture meets it edge-on (a mapper's degenerate Valve axes, or a sliver
/// the tree left between brushes, textured from a side on another plane) Quake's own projection
/// of that texture for its plane, as ericw-tools' qbsp repairs such sides, then cut it for its
/// lightmap. Returns how many faces it squared up.
fn square_up_projections(
    outputs: &mut [ModelOutput],
    planes: &PlaneSet,
    table: &mut TexInfoTable,
    subdivide: f64,
) -> usize {
    let quake = Projection::Standard {
        shift: [0.0; 2],
        rotation: 0.0,
        scale: [1.0; 2],
    };
    let mut squared = 0;
    for out in outputs {
        let mut faces = Vec::with_capacity(out.faces.len());
        for mut f in std::mem::take(&mut out.faces) {
            let normal = f.normal(planes);
            let info = table.infos[f.texinfo as usize];
            if projection_squareness(&info.vecs, normal) >= MIN_SQUARENESS {
                faces.push(f);
                continue;
            }
            squared += 1;
            let name = table.names[info.texture as usize].clone();
            let vecs = quake.vecs(&Plane::new(normal, 0.0));
            f.texinfo = table.intern(&name, vecs, info.phong);
            let squared_info = FaceTexInfo {
                vecs,
                role: info.role,
            };
            cut_for_lightmaps(f, &squared_info, subdivide, &mut faces);
        }
        out.faces = faces;
    }
    squared
}

/// The world must have brushes to draw or see: without any (nothing given, or only clip, origin
/// or bad brushes), engines would load an empty void, and the world model would have no node to
/// start at but one with the same leaf on both sides, which DarkPlaces rejects ("corrupt node
/// hierarchy").
fn require_world_brushes(
    source: &MapSource,
    entities: &[MapEntity],
    world: &ModelInput,
    warnings: &[Warning],
) -> Result<(), CompileError> {
    if !world.brushes.is_empty() {
        return Ok(());
    }
    let merged =
        |i: usize| EntityBrushes::of(i, entities[i].entity.classname()) != EntityBrushes::Submodel;
    let given: usize = (0..entities.len())
        .filter(|&i| merged(i))
        .map(|i| entities[i].brushes.len())
        .sum();
    let first_bad = warnings.iter().find_map(|w| match w {
        Warning::BadBrush {
            entity,
            line,
            reason,
            ..
        } if merged(*entity) => Some((line, reason)),
        _ => None,
    });
    let detail = match first_bad {
        _ if given == 0 => String::new(),
        Some((line, reason)) => format!(
            " ({given} given: only clip, origin or bad brushes; the first bad one, line {line}: \
             {reason})"
        ),
        None => format!(" ({given} given: only clip or origin brushes)"),
    };
    Err(CompileError::EmptyWorld {
        path: source.path.clone(),
        detail,
    })
}

fn is_origin_brush(mb: &MapBrush) -> bool {
    mb.faces
        .iter()
        .any(|f| TextureRole::of(&f.texture) == TextureRole::Origin)
}

/// The centre of the bounds of an entity's origin brushes, if it has any that can be built.
fn origin_brush_centre(ent: &MapEntity, planes: &mut PlaneSet) -> Option<DVec3> {
    let mut bounds = Bounds::EMPTY;
    for mb in ent.brushes.iter().filter(|mb| is_origin_brush(mb)) {
        let faces: Option<Vec<BrushPlane>> = mb
            .faces
            .iter()
            .map(|f| {
                Some(BrushPlane {
                    plane: f.plane(DVec3::ZERO)?,
                    texinfo: None,
                })
            })
            .collect();
        if let Some(b) = faces.and_then(|f| Brush::from_planes(&f, planes, contents::SOLID, 0).ok())
        {
            bounds = bounds.union(&b.bounds);
        }
    }
    (!bounds.is_empty()).then(|| bounds.center())
}

/// The `_phong` group of entity `index` if it is merged into the world (its
/// faces could not be told apart from the world's otherwise): its entity
/// index as group id. Worldspawn and brush models get none here; light reads
/// their own keys.
fn merged_phong(ent: &MapEntity, index: usize, class: EntityBrushes) -> FacePhong {
    let merged = index != 0 && class != EntityBrushes::Submodel;
    let angle = phong::angle_from_keys(
        ent.entity.get_float("_phong"),
        ent.entity.get_float("_phong_angle"),
    );
    match angle.filter(|_| merged) {
        Some(angle) => FacePhong {
            group: index as u32,
            angle: angle as f32,
        },
        None => FacePhong::default(),
    }
}

/// The origin a submodel without origin brushes is built around: for Hipnotic's `rotate_*`
/// entities the origin of the entity their `target` names (an `info_rotate`, the pivot), else
/// the submodel's own `origin` key. Engines draw a model moved by its origin, so its brushes must
/// be stored relative to it to appear where the mapper put them.
fn key_origin(entities: &[MapEntity], ent: &MapEntity) -> Option<DVec3> {
    let pivot = ent
        .entity
        .classname()
        .starts_with("rotate_")
        .then(|| ent.entity.get("target"))
        .flatten()
        .and_then(|target| {
            entities
                .iter()
                .find(|e| e.entity.get("targetname") == Some(target))
        });
    let [x, y, z] = pivot.unwrap_or(ent).entity.get_floats::<3>("origin")?;
    Some(DVec3::new(x, y, z))
}

/// The point entity `ent` (number `index`) as an occupant of open space for the flood: not
/// when it has no origin, stands at the map's origin (where ericw-tools skips it, taking it for
/// a brush entity), or is marked `_nofill` (or `_lightgrid_hint`) to stand in the void.
fn occupant(ent: &MapEntity, index: usize) -> Option<Occupant> {
    let [x, y, z] = ent.entity.get_floats::<3>("origin")?;
    let origin = DVec3::new(x, y, z);
    let marked = |key| ent.entity.get_float(key).is_some_and(|v| v != 0.0);
    if origin.abs().max_element() < POINT_EPSILON || marked("_nofill") || marked("_lightgrid_hint")
    {
        return None;
    }
    Some(Occupant {
        entity: index,
        classname: ent.entity.classname().to_string(),
        origin,
        line: ent.line,
    })
}

/// The map brush numbered `source` by the numbering of every map brush whose entities start at
/// `first_source`.
fn map_brush(map: &MapFile, first_source: &[u32], source: u32) -> Option<MapBrushRef> {
    let entity = first_source
        .partition_point(|&first| first <= source)
        .checked_sub(1)?;
    let brush = (source - first_source[entity]) as usize;
    Some(MapBrushRef {
        entity,
        brush,
        line: map.entities[entity].brushes.get(brush)?.line,
    })
}

/// The faces of a map brush as the compiler takes them: each face's plane (relative to the
/// entity's origin) and texinfo, with its texture's role and its line.
struct BrushFaces {
    planes: Vec<BrushPlane>,
    roles: Vec<TextureRole>,
    lines: Vec<usize>,
    /// Faces of the map brush left out (warned about).
    dropped: usize,
}

/// What an entity's brushes go through to become [`Brush`]es.
struct EntityContext<'a> {
    entity: usize,
    /// The [`Brush::source`] of the entity's first brush.
    first_source: u32,
    class: EntityBrushes,
    origin: DVec3,
    phong: FacePhong,
    table: &'a mut TexInfoTable,
    warnings: &'a mut Vec<Warning>,
}

impl EntityContext<'_> {
    /// The faces of map brush number `bi`. As in id's and ericw-tools' compilers, a face whose
    /// three points are collinear (no plane) and a face on a plane an earlier face of the brush
    /// already lies on (either way round; id's dm2 has one) are dropped with a warning naming
    /// the face's line, and the brush is built from the rest.
    fn faces(&mut self, mb: &MapBrush, bi: usize) -> BrushFaces {
        let (entity, origin) = (self.entity, self.origin);
        let mut out = BrushFaces {
            planes: Vec::with_capacity(mb.faces.len()),
            roles: Vec::with_capacity(mb.faces.len()),
            lines: Vec::with_capacity(mb.faces.len()),
            dropped: 0,
        };
        for f in &mb.faces {
            let dropped = |reason| Warning::DroppedFace {
                entity,
                brush: bi,
                line: f.line,
                reason,
            };
            let Some(plane) = f.plane(origin) else {
                self.warnings.push(dropped(DroppedFace::NoPlane));
                out.dropped += 1;
                continue;
            };
            let on_plane =
                |b: &BrushPlane| b.plane.same_as(&plane) || b.plane.same_as(&plane.flipped());
            if out.planes.iter().any(on_plane) {
                self.warnings.push(dropped(DroppedFace::RepeatedPlane));
                out.dropped += 1;
                continue;
            }
            // Engines draw the model moved by its origin: shift the texture to match.
            let mut vecs = f.projection.vecs(&plane);
            for row in &mut vecs {
                row[3] += DVec3::new(row[0], row[1], row[2]).dot(origin);
            }
            let role = TextureRole::of(&f.texture);
            if role.is_drawn() && projection_squareness(&vecs, plane.normal) < MIN_SQUARENESS {
                self.warnings.push(Warning::DegenerateTextureAxes {
                    entity,
                    brush: bi,
                    line: f.line,
                    texture: f.texture.clone(),
                });
            }
            let texinfo = self.table.intern(&f.texture, vecs, self.phong);
            out.roles.push(role);
            out.lines.push(f.line);
            out.planes.push(BrushPlane {
                plane,
                texinfo: Some(texinfo),
            });
        }
        out
    }

    /// The contents of a (non-hint) brush of these faces. The texture decides first, as in
    /// ericw-tools: a sky or liquid brush stays one in any detail entity (sky seals the map
    /// wherever it is); only solid brushes take their entity's contents. The brush's first face
    /// that gives contents decides them; a later one giving others is warned about.
    fn contents(&mut self, faces: &BrushFaces, bi: usize) -> (i32, FaceContents) {
        let (textured, conflict) = texinfo::brush_contents(&faces.roles);
        if let Some(i) = conflict {
            self.warnings.push(Warning::MixedContents {
                entity: self.entity,
                brush: bi,
                line: faces.lines[i],
                used: textured,
            });
        }
        let contents = match (self.class, textured) {
            (EntityBrushes::Submodel, _) => contents::SOLID,
            (EntityBrushes::VisBlocker, _) => VISBLOCKER,
            (_, FaceContents::Sky) => contents::SKY,
            (_, FaceContents::Liquid(c)) => c,
            (EntityBrushes::Fence, _) => FENCE,
            (EntityBrushes::DetailWall, _) => DETAIL_WALL,
            (EntityBrushes::Illusionary, _) => ILLUSIONARY,
            (EntityBrushes::World | EntityBrushes::Detail, _) => contents::SOLID,
        };
        (contents, textured)
    }

    /// Build the entity's brushes, in coordinates relative to its origin, each with whether it
    /// is a clip brush; origin brushes are left out. Brush `i` gets the source `first_source +
    /// i`. Returns the brushes, the number of bad brushes and the number of hint brushes skipped
    /// (outside the world).
    fn build_brushes(
        &mut self,
        ent: &MapEntity,
        planes: &mut PlaneSet,
    ) -> (Vec<(Brush, bool)>, usize, usize) {
        let mut out = Vec::new();
        let (mut bad, mut hints) = (0, 0);
        let mirror_inside = ent.entity.get_float("_mirrorinside").map(|v| v != 0.0);
        for (bi, mb) in ent.brushes.iter().enumerate() {
            if is_origin_brush(mb) {
                continue;
            }
            let faces = self.faces(mb, bi);
            let hint = faces
                .roles
                .iter()
                .any(|r| matches!(r, TextureRole::Hint | TextureRole::HintSkip));
            if hint && self.class == EntityBrushes::Submodel {
                hints += 1;
                continue;
            }
            let (brush_contents, textured) = if hint {
                (contents::EMPTY, FaceContents::Solid)
            } else {
                self.contents(&faces, bi)
            };
            let source = self.first_source + bi as u32;
            match Brush::from_planes(&faces.planes, planes, brush_contents, source) {
                Ok(mut b) => {
                    if hint {
                        b.kind = BrushKind::Hint;
                        // Only the hint faces split; the others (skip, hintskip) are ignored.
                        for s in &mut b.sides {
                            let role = s.texinfo.map(|t| self.table.infos[t as usize].role);
                            s.buried |= role != Some(TextureRole::Hint);
                        }
                    } else if brush_contents == contents::SKY {
                        b.kind = BrushKind::Structural;
                    } else {
                        b.kind = self.class.kind();
                    }
                    b.mirror_inside = mirror_inside;
                    out.push((b, textured == FaceContents::Clip));
                }
                Err(e) => {
                    bad += 1;
                    self.warnings.push(Warning::BadBrush {
                        entity: self.entity,
                        brush: bi,
                        line: mb.line,
                        reason: match faces.dropped {
                            0 => e.to_string(),
                            n => format!("{e} once {n} unusable faces are dropped"),
                        },
                    });
                }
            }
        }
        (out, bad, hints)
    }
}

/// A built brush as the `BRUSHLIST` lump stores it: clip brushes collide as solid; brushes
/// nothing collides with (hint, illusionary) are left out.
fn listed_brush(brush: &Brush, clip: bool, planes: &PlaneSet) -> Option<ListedBrush> {
    let contents = match engine_contents(brush.contents) {
        _ if clip => contents::SOLID,
        _ if brush.kind == BrushKind::Hint => return None,
        contents::EMPTY => return None,
        c => c,
    };
    Some(ListedBrush::of(brush, contents, planes))
}

/// Fill the outside of a clip hull's tree, flooding from the world's point entities, and
/// rebuild it from what is left.
fn fill_hull(
    tree: &mut Tree,
    planes: &PlaneSet,
    bounds: &Bounds,
    occupants: &[Occupant],
    heuristic: Splitting,
) {
    if bounds.is_empty() {
        return;
    }
    let portals = make_portals(tree, planes, bounds);
    // Entities near walls are inside the grown brushes; that is expected, not worth a warning.
    let mut ignored = Vec::new();
    if let FillOutcome::Sealed { .. } = fill_outside(
        tree,
        planes,
        &portals,
        occupants,
        OnPlane::Open,
        &mut ignored,
    ) {
        *tree = rebuild_from_surfaces(tree, &portals, planes, heuristic);
    }
}

fn build_model(
    m: ModelInput,
    planes: &PlaneSet,
    texinfos: &[FaceTexInfo],
    options: &CompileOptions,
    occupants: &[Occupant],
) -> (ModelOutput, Vec<Warning>) {
    let mut warnings = Vec::new();
    let mut timings = [0.0; 6];
    // Engines size brush entities from the model bounds (a door's travel, its trigger field),
    // so they hold the map brushes, not the grown ones.
    let mut bounds = m.clip_bounds;
    for b in &m.brushes {
        bounds = bounds.union(&b.bounds);
    }
    if bounds.is_empty() {
        bounds = Bounds {
            mins: DVec3::new(-1.0, -1.0, -1.0),
            maxs: DVec3::new(1.0, 1.0, 1.0),
        };
    }
    let heuristic = Splitting {
        heuristic: options.heuristic,
        max_node_size: options.max_node_size,
    };
    let progress = &options.progress;
    let t = Instant::now();
    let mut brushes = m.brushes;
    let [mut h1, mut h2] = m.hull_brushes;
    let counts = [brushes.len(), h1.len(), h2.len()];
    for list in [&mut brushes, &mut h1, &mut h2] {
        mark_hidden_sides(list, planes);
        progress.advance(list.len());
    }
    let hull_bounds = [&h1, &h2].map(|list| {
        list.iter()
            .fold(Bounds::EMPTY, |acc, b| acc.union(&b.bounds))
    });
    timings[5] = t.elapsed().as_secs_f64();
    let ((mut tree, tree_time), (mut hulls, hull_time)) = rayon::join(
        || {
            let t = Instant::now();
            let tree = build_tree(brushes, planes, heuristic, true);
            progress.advance(counts[0]);
            (tree, t.elapsed().as_secs_f64())
        },
        || {
            let t = Instant::now();
            let (a, b) = rayon::join(
                || {
                    let tree = build_clip_hull_tree(h1, planes, heuristic);
                    progress.advance(counts[1]);
                    tree
                },
                || {
                    let tree = build_clip_hull_tree(h2, planes, heuristic);
                    progress.advance(counts[2]);
                    tree
                },
            );
            ([a, b], t.elapsed().as_secs_f64())
        },
    );
    timings[0] = tree_time;
    timings[4] = hull_time;

    let t = Instant::now();
    let portals = make_portals(&tree, planes, &bounds);
    let cluster_portals = tree
        .nodes
        .iter()
        .any(|n| n.cluster.is_some() && !n.is_leaf())
        .then(|| make_cluster_portals(&tree, planes, &bounds));
    timings[1] = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let is_world = m.entity == 0;
    let fill = (is_world && options.fill).then(|| {
        let flood = cluster_portals.as_ref().unwrap_or(&portals);
        fill_outside(
            &mut tree,
            planes,
            flood,
            occupants,
            OnPlane::Sealing,
            &mut warnings,
        )
    });
    timings[2] = t.elapsed().as_secs_f64();

    // A sealed world's clip hulls are sealed too (grown brushes only close gaps further): fill
    // their outsides as well, so it collapses into one solid leaf instead of many clip nodes.
    let t = Instant::now();
    if matches!(fill, Some(FillOutcome::Sealed { .. })) {
        let [h1, h2] = &mut hulls;
        rayon::join(
            || fill_hull(h1, planes, &hull_bounds[0], occupants, heuristic),
            || fill_hull(h2, planes, &hull_bounds[1], occupants, heuristic),
        );
    }
    progress.advance(counts[1] + counts[2]);
    timings[4] += t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut face_stats = FaceStats::default();
    let raw = faces_from_portals(&tree, &portals, planes, texinfos, &mut face_stats);
    let merged = merge_faces(raw, |f| *planes.get(f.plane));
    face_stats.after_merge = merged.len();
    let mut faces = Vec::with_capacity(merged.len());
    for f in merged {
        let info = &texinfos[f.texinfo as usize];
        if projection_squareness(&info.vecs, f.normal(planes)) < MIN_SQUARENESS {
            // Cut once it has a projection of its own: see `square_up_projections`.
            faces.push(f);
            continue;
        }
        cut_for_lightmaps(f, info, options.subdivide, &mut faces);
    }
    timings[3] = t.elapsed().as_secs_f64();
    progress.advance(counts[0]);

    (
        ModelOutput {
            tree,
            portals,
            cluster_portals,
            faces,
            hulls,
            bounds,
            fill,
            face_stats,
            timings,
        },
        warnings,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phong_groups_only_for_entities_merged_into_the_world() {
        let text = "{ \"classname\" \"worldspawn\" \"_phong\" \"1\" }\n\
                    { \"classname\" \"func_detail\" \"_phong\" \"1\" }\n\
                    { \"classname\" \"func_group\" \"_phong_angle\" \"30\" }\n\
                    { \"classname\" \"func_wall\" \"_phong\" \"1\" }\n\
                    { \"classname\" \"func_detail_wall\" }\n";
        let map = parse_map(Path::new("phong.map"), text).expect("parse");
        let got: Vec<FacePhong> = map
            .entities
            .iter()
            .enumerate()
            .map(|(i, e)| merged_phong(e, i, EntityBrushes::of(i, e.entity.classname())))
            .collect();
        let group = |group, angle| FacePhong { group, angle };
        let none = FacePhong::default();
        // Worldspawn and brush models keep their keys for light to read.
        assert_eq!(got, vec![none, group(1, 89.0), group(2, 30.0), none, none]);
    }

    #[test]
    fn faces_of_different_phong_groups_get_different_texinfos() {
        let mut table = TexInfoTable::default();
        let vecs = [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]];
        let grouped = FacePhong {
            group: 3,
            angle: 89.0,
        };
        let plain = table.intern("wall", vecs, FacePhong::default());
        let a = table.intern("wall", vecs, grouped);
        assert_ne!(plain, a);
        assert_eq!(table.intern("wall", vecs, grouped), a);
        assert_eq!(table.infos[a as usize].phong, grouped);
        assert_eq!(table.names.len(), 1, "one texture either way");
    }
}
