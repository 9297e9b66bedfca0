//! The whole compile: parse the map ([`read_map`]), gather each model's brushes
//! ([`crate::gather`]), build each model's trees, fill the world's outside and make its faces
//! ([`crate::model`], the models in parallel), then emit the BSP and the portal file.

use crate::brushlist::brush_list_lump;
use crate::content_flags::ContentFlags;
use crate::editor::{OmittedLayer, omitted_layers, without_editor_keys};
use crate::emit::{DrawingInput, DrawnBsp, EmitInput, ModelDrawing, emit, emit_drawing};
use crate::faces::{
    FaceStats, FaceTexInfo, MIN_SQUARENESS, ModelFace, cut_for_lightmaps, projection_squareness,
};
use crate::gather::{
    EntityBrushes, Gathered, ModelInput, TexInfoTable, gather, map_brush, submodel_origin,
};
use crate::leak::LeakReport;
use crate::lightmap_grid::{LightmapGridStats, agree_on_lightmap_grid};
use crate::map::{MapEntity, MapError, MapFile, parse_map, read_map_text};
use crate::model::{
    Clipped, Drawn, MODEL_PHASES, MODEL_WORK_PER_BRUSH, ModelOutput, Written, assemble, split_model,
};
use crate::options::CompileOptions;
use crate::outside::{FillOutcome, Occupant};
use crate::planes::PlaneSet;
use crate::prefab::{PrefabError, expand_prefabs};
use crate::texinfo::Projection;
use crate::tree::SplitHeuristic;
use crate::wad_lookup::{MissingTextures, TextureList, WadSearch, WadSet};
use crate::warnings::Warning;
use quake_formats::bsp::limits::{BSP29_MAX_CLIPNODES, MAX_SURFACE_EXTENT};
use quake_formats::bsp::texinfo_flags;
use quake_formats::entities::Entity;
use quake_formats::extents::LightmapExtents;
use quake_formats::geom::Plane;
use quake_formats::prt::PortalFile;
use quake_formats::{Bsp, BspVersion, FormatError};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A `.map` file's text and where it came from (for messages and WAD lookup).
#[derive(Debug, Clone)]
pub struct MapSource {
    /// The file's path.
    pub path: PathBuf,
    /// The file's text.
    pub text: String,
}

impl MapSource {
    /// Reads the `.map` file at `path`.
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

/// Why a map could not be compiled.
#[derive(Debug, thiserror::Error)]
pub enum CompileError {
    /// The `.map` text does not parse.
    #[error(transparent)]
    Map(#[from] MapError),
    /// A `misc_external_map` prefab could not be spliced in.
    #[error(transparent)]
    Prefab(#[from] PrefabError),
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error reading it.
        #[source]
        source: std::io::Error,
    },
    /// The map's first entity is not `worldspawn`.
    #[error("{}: the first entity must be worldspawn, found {found:?}", path.display())]
    NoWorldspawn {
        /// The `.map` file.
        path: PathBuf,
        /// The first entity's classname.
        found: String,
    },
    /// Nothing in the world to draw or see (id's qbsp stopped here too: "Entity with no valid
    /// brushes").
    #[error(
        "{}: worldspawn (entity 0) has no brushes to build{detail}: there is no world to compile",
        path.display()
    )]
    EmptyWorld {
        /// The `.map` file.
        path: PathBuf,
        /// Why the brushes the map gives it, if any, were left out.
        detail: String,
    },
    /// The BSP could not be encoded.
    #[error("writing the BSP: {0}")]
    Format(#[from] FormatError),
    /// The compiled BSP breaks a rule every later stage refuses (`quake_formats::check_usable`),
    /// e.g. a face whose texture scale makes its lightmap extents huge.
    #[error("{}: the compiled BSP would be {refused}", path.display())]
    Unusable {
        /// The `.map` file.
        path: PathBuf,
        /// The rule the BSP breaks.
        refused: FormatError,
    },
}

/// Counts and timings of one compile.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct CompileStats {
    /// The BSP version written (`BSP29` or `BSP2`).
    pub version: String,
    /// How the tree's splitting planes were chosen.
    pub heuristic: SplitHeuristic,
    /// Entities in the map, prefabs and added maps included.
    pub entities: usize,
    /// Models in the BSP (the world first).
    pub models: usize,
    /// Brushes of the entities compiled.
    pub brushes: usize,
    /// Brushes that could not be built and were skipped.
    pub bad_brushes: usize,
    /// Planes in the BSP.
    pub planes: usize,
    /// Nodes in the BSP.
    pub nodes: usize,
    /// Leaves in the BSP.
    pub leaves: usize,
    /// Faces in the BSP.
    pub faces: usize,
    /// Times a brush was split in two while building the models' trees.
    pub splits: usize,
    /// Clip nodes in the BSP.
    pub clipnodes: usize,
    /// Portals between the models' leaves.
    pub portals: usize,
    /// Portals in the `.prt` file.
    pub vis_portals: usize,
    /// Vis clusters (PRT2), or vis leaves when the world has no detail (PRT1).
    pub clusters: usize,
    /// Vertices in the BSP.
    pub vertices: usize,
    /// Edges in the BSP.
    pub edges: usize,
    /// Texinfos in the BSP.
    pub texinfo: usize,
    /// Textures in the BSP.
    pub textures: usize,
    /// Leaves the outside fill made solid.
    pub filled_leaves: usize,
    /// Vertices added to faces' edges to close T-junctions.
    pub tjunction_vertices: usize,
    /// The world is open to the void.
    pub leaked: bool,
    /// How many faces each face phase made.
    pub face_stats: FaceStats,
    /// Texture offsets nudged so QuakeSpasm and DarkPlaces size every lightmap alike.
    pub lightmap_grid: LightmapGridStats,
    /// Phase name and seconds; phases run per model are summed over models (CPU time).
    pub timings: Vec<(String, f64)>,
}

/// Everything a compile produces.
#[derive(Debug, Clone)]
pub struct CompileOutput {
    /// The compiled BSP.
    pub bsp: Bsp,
    /// The `.prt` file for vis.
    pub portals: PortalFile,
    /// Each BSP leaf's extended content flags, in leaf order (the `.content.json` file).
    pub leaf_contents: Vec<ContentFlags>,
    /// Where the world leaks, if it does.
    pub leak: Option<LeakReport>,
    /// What the compile worked around.
    pub warnings: Vec<Warning>,
    /// Counts and timings.
    pub stats: CompileStats,
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
    let map = read_map(source, options)?;
    stats.entities = map.entities.len();
    timings.push(("parse".to_string(), t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let (left_out, layers) = entities_left_out(&map, options);
    warnings.extend(layers.into_iter().map(Warning::OmittedLayer));
    let Gathered {
        models,
        planes,
        mut table,
        occupants,
        mut listed,
        first_source,
        brushes,
        bad_brushes,
    } = gather(&map, &left_out, options, &mut warnings);
    (stats.brushes, stats.bad_brushes) = (brushes, bad_brushes);
    require_world_brushes(source, &map.entities, &models[0], &warnings)?;
    warn_empty_brush_entities(&map, &models, &mut warnings);
    timings.push(("brushes".to_string(), t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let texture_list = TextureList::of_map(
        map.entities
            .iter()
            .flat_map(|e| &e.brushes)
            .flat_map(|b| &b.faces)
            .map(|f| f.texture.as_str()),
    );
    // The WADs are read while the models are built: reading a map's texture WADs (megabytes
    // each) waits on the disk and on fresh memory, which the models' threads need not. On a
    // thread of its own, not the models' pool: a pool thread reading them would start on the
    // world's clip hulls, the longest job, only when the reading is done.
    let read_wads = || {
        let mut wad_warnings = Vec::new();
        let wads = WadSet::load(
            &map.entities[0].entity,
            &wad_search(source, options),
            &mut wad_warnings,
        );
        (wads, wad_warnings)
    };
    let (built, (wads, wad_warnings)) = std::thread::scope(|scope| {
        // Should no thread start, they are read after the models.
        let reading = std::thread::Builder::new()
            .name("wads".to_string())
            .spawn_scoped(scope, read_wads)
            .ok();
        let built = build_models(
            models,
            &planes,
            &mut table,
            &occupants,
            texture_list,
            options,
        );
        let read = match reading {
            Some(thread) => thread
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
            None => read_wads(),
        };
        (built, read)
    });
    timings.push(("models (wall)".to_string(), t.elapsed().as_secs_f64()));
    let Built {
        models: results,
        drawing,
        table,
        squared_up,
        after_subdivide,
        drawing_time,
    } = built;
    let mut leak = None;
    let mut phase_sums = [0.0; 6];
    let mut outputs = Vec::with_capacity(results.len());
    for (out, w) in results {
        warnings.extend(w);
        for (sum, t) in phase_sums.iter_mut().zip(out.timings) {
            *sum += t;
        }
        stats.add_model(&out);
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
    stats.face_stats.squared_up = squared_up;
    stats.face_stats.after_subdivide = after_subdivide;
    for (name, sum) in MODEL_PHASES.iter().zip(phase_sums) {
        timings.push((format!("  {name} (sum over models)"), sum));
    }
    timings.push(("  hull 0 written".to_string(), drawing_time));
    stats.leaked = leak.is_some();

    let t = Instant::now();
    warnings.extend(wad_warnings);
    let wads = wads.with_missing(MissingTextures {
        loose_dirs: if options.texture_data {
            Vec::new()
        } else {
            options.texture_paths.clone()
        },
        zero_size: options.missing_textures_as_zero_size,
    });
    let emitted = emit(
        drawing,
        EmitInput {
            models: &outputs,
            wads: &wads,
            entities: &lump_entities(&map, &left_out, options),
            warnings: &mut warnings,
        },
    );
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
    // BSP2 holds any map; BSP29 and 2PSB give way to it. BSP29 takes more than 32767 clip nodes
    // only in engines that read their children unsigned, so past that it gives way too.
    let limits = bsp
        .check_version_limits()
        .map_err(|e| e.to_string())
        .and_then(|()| {
            if bsp.version == BspVersion::Bsp29 && bsp.clipnodes.len() > BSP29_MAX_CLIPNODES {
                Err(format!(
                    "{} clip nodes are more than DarkPlaces and the original engine read in BSP29 \
                 ({BSP29_MAX_CLIPNODES})",
                    bsp.clipnodes.len()
                ))
            } else {
                Ok(())
            }
        });
    if let Err(e) = limits {
        warnings.push(Warning::Unsupported {
            what: format!("{e}; switching to BSP2 automatically"),
        });
        bsp.version = BspVersion::Bsp2;
    }
    warnings.extend(wide_faces(&bsp));
    timings.push(("emit".to_string(), t.elapsed().as_secs_f64()));
    timings.push(("total".to_string(), total.elapsed().as_secs_f64()));
    stats.add_output(&bsp, &emitted.portals, emitted.tjunction_vertices);
    stats.timings = timings;
    // The last line of defence: never hand on a BSP every later stage would refuse.
    quake_formats::check_usable(&bsp).map_err(|refused| CompileError::Unusable {
        path: source.path.clone(),
        refused,
    })?;
    drop_in_background((outputs, wads, map));
    Ok(CompileOutput {
        bsp,
        portals: emitted.portals,
        leaf_contents: emitted.leaf_contents,
        leak,
        warnings,
        stats,
    })
}

/// Free `value` on a thread of its own: the models' trees and portals are hundreds of thousands
/// of small blocks, and freeing them need not hold up writing the files.
fn drop_in_background<T: Send + 'static>(value: T) {
    // Should no thread start, the closure and `value` with it are dropped here.
    let _ = std::thread::Builder::new()
        .name("free".to_string())
        .spawn(move || drop(value));
}

/// The faces without `TEX_SPECIAL` wider than WinQuake accepts, when there are any (faces too
/// wide for QuakeSpasm's family are refused by `check_usable` after).
fn wide_faces(bsp: &Bsp) -> Option<Warning> {
    let widths: Vec<i32> = bsp
        .faces
        .iter()
        .filter_map(|f| {
            let tex = bsp.texinfo.get(f.texinfo as usize)?;
            if tex.flags & texinfo_flags::SPECIAL != 0 {
                return None;
            }
            let ext = LightmapExtents::from_points(&bsp.face_vertices(f)?, &tex.vecs);
            Some(ext.extents[0].max(ext.extents[1]))
        })
        .filter(|&w| w > MAX_SURFACE_EXTENT)
        .collect();
    let widest = *widths.iter().max()?;
    Some(Warning::WideFaces {
        faces: widths.len(),
        widest,
    })
}

/// Every model built, its hull 0 and faces written into the BSP ([`emit_drawing`]) while the
/// clip hulls still build: nothing of hull 0's writing needs them, and their trees take longer.
/// The world floods from `occupants`.
fn build_models<'t>(
    models: Vec<ModelInput>,
    planes: &'t PlaneSet,
    table: &'t mut TexInfoTable,
    occupants: &[Occupant],
    texture_list: TextureList,
    options: &CompileOptions,
) -> Built<'t> {
    let face_texinfos = face_texinfos(table);
    let progress = &options.progress;
    progress.start(
        "models",
        models.iter().map(ModelInput::work).sum::<usize>() * MODEL_WORK_PER_BRUSH,
    );
    let occupants_of = |i: usize| if i == 0 { occupants } else { &[] };
    let (jobs, clip_jobs): (Vec<_>, Vec<_>) =
        models.into_iter().map(|m| split_model(m, options)).unzip();
    let (hull_zero, clipped) = rayon::join(
        || {
            let mut drawn: Vec<Drawn> = jobs
                .into_par_iter()
                .enumerate()
                .map(|(i, job)| job.build(planes, &face_texinfos, options, occupants_of(i)))
                .collect();
            let t = Instant::now();
            let squared_up = square_up_projections(
                drawn.iter_mut().map(|d| &mut d.hull.faces),
                planes,
                table,
                options.subdivide,
            );
            let table: &TexInfoTable = table;
            let models: Vec<ModelDrawing> = drawn
                .iter()
                .map(|d| ModelDrawing {
                    tree: &d.hull.tree,
                    portals: &d.hull.portals,
                    cluster_portals: d.hull.cluster_portals.as_ref(),
                    faces: &d.hull.faces,
                    bounds: d.bounds(),
                })
                .collect();
            let drawing = emit_drawing(DrawingInput {
                models: &models,
                planes,
                texinfos: &table.infos,
                texture_names: &table.names,
                texture_list,
                version: options.version,
                max_edges: options.max_edges,
                transwater: options.transwater,
            });
            let face_stats = (squared_up, models.iter().map(|m| m.faces.len()).sum());
            let time = t.elapsed().as_secs_f64();
            drop(models);
            let written: Vec<Written> = drawn.into_iter().map(Drawn::written).collect();
            (written, drawing, table, face_stats, time)
        },
        || {
            clip_jobs
                .into_par_iter()
                .enumerate()
                .map(|(i, job)| job.build(planes, options, occupants_of(i)))
                .collect::<Vec<Clipped>>()
        },
    );
    progress.finish();
    let (written, drawing, table, (squared_up, after_subdivide), drawing_time) = hull_zero;
    Built {
        models: written
            .into_iter()
            .zip(clipped)
            .map(|(d, c)| assemble(d, c))
            .collect(),
        drawing,
        table,
        squared_up,
        after_subdivide,
        drawing_time,
    }
}

/// What [`build_models`] gives back.
struct Built<'t> {
    /// Each model's output and warnings.
    models: Vec<(ModelOutput, Vec<Warning>)>,
    /// The BSP as far as hull 0 writes it.
    drawing: DrawnBsp<'t>,
    /// The texinfo table, with the texinfos of squared-up faces.
    table: &'t TexInfoTable,
    /// Faces whose texture projection was squared up, and the faces after that cut them.
    squared_up: usize,
    after_subdivide: usize,
    /// Seconds spent squaring up and writing hull 0.
    drawing_time: f64,
}

/// What the faces of a model need of each texinfo.
fn face_texinfos(table: &TexInfoTable) -> Vec<FaceTexInfo> {
    table
        .infos
        .iter()
        .map(|i| FaceTexInfo {
            vecs: i.vecs,
            role: i.role,
            special: i.is_special(),
        })
        .collect()
}

/// A warning for each brush entity left without brushes to build.
fn warn_empty_brush_entities(map: &MapFile, models: &[ModelInput], warnings: &mut Vec<Warning>) {
    for m in &models[1..] {
        if m.brushes.is_empty() && m.hull_brushes[0].is_empty() {
            warnings.push(Warning::EmptyBrushEntity {
                entity: m.entity,
                classname: map.entities[m.entity].entity.classname().to_string(),
            });
        }
    }
}

impl CompileStats {
    /// Count what one built model adds.
    fn add_model(&mut self, out: &ModelOutput) {
        self.splits += out.splits;
        self.portals += out.portals;
        let fs = &mut self.face_stats;
        fs.from_portals += out.face_stats.from_portals;
        fs.untextured += out.face_stats.untextured;
        fs.after_merge += out.face_stats.after_merge;
    }

    /// Count what the written BSP and portal file hold.
    fn add_output(&mut self, bsp: &Bsp, portals: &PortalFile, tjunction_vertices: usize) {
        self.version = bsp.version.to_string();
        self.models = bsp.models.len();
        self.planes = bsp.planes.len();
        self.nodes = bsp.nodes.len();
        self.leaves = bsp.leafs.len();
        self.faces = bsp.faces.len();
        self.clipnodes = bsp.clipnodes.len();
        self.vertices = bsp.vertices.len();
        self.edges = bsp.edges.len();
        self.texinfo = bsp.texinfo.len();
        self.textures = bsp.textures.textures.len();
        self.vis_portals = portals.portals.len();
        self.clusters = portals
            .clusters
            .as_ref()
            .map_or(portals.num_leafs as usize, Vec::len);
        self.tjunction_vertices = tjunction_vertices;
    }
}

/// Where the compile of `source` looks for the WADs its map names: the `wad_dirs`, the
/// `xwad_dirs` (not embedded), the map's own folder, then the working directory; `MAP.wad`
/// beside the map when worldspawn names none.
pub fn wad_search(source: &MapSource, options: &CompileOptions) -> WadSearch {
    let map_dir = source.path.parent().unwrap_or(Path::new(""));
    let mut folders: Vec<(PathBuf, bool)> = options
        .wad_dirs
        .iter()
        .map(|d| (d.clone(), true))
        .chain(options.xwad_dirs.iter().map(|d| (d.clone(), false)))
        .collect();
    if !map_dir.as_os_str().is_empty() {
        folders.push((map_dir.to_path_buf(), true));
    }
    folders.push((PathBuf::new(), true));
    WadSearch {
        folders,
        beside_map: source.path.with_extension("wad"),
    }
}

/// The entities of `map` the compile leaves out (worldspawn never): those of the classes
/// `options.omit` names and, with `options.omit_layers`, those in editor layers marked to be
/// omitted from export; and those layers, left out or not.
pub(crate) fn entities_left_out(
    map: &MapFile,
    options: &CompileOptions,
) -> (Vec<bool>, Vec<OmittedLayer>) {
    let (mut left_out, layers) = omitted_layers(map, options.omit_layers);
    for (index, ent) in map.entities.iter().enumerate().skip(1) {
        let class = ent.entity.classname();
        left_out[index] |= options.omit.iter().any(|c| c == class);
    }
    (left_out, layers)
}

/// Parse a map, its prefabs expanded, with the maps `options.add` names merged in; the first
/// entity must be worldspawn.
pub(crate) fn read_map(
    source: &MapSource,
    options: &CompileOptions,
) -> Result<MapFile, CompileError> {
    let mut map = parse_with_worldspawn(source)?;
    for add in &options.add {
        let added = parse_with_worldspawn(&MapSource::read(&added_map_path(source, add))?)?;
        merge_added_map(&mut map, added);
    }
    Ok(map)
}

/// Parse `source`, its prefabs expanded; its first entity must be worldspawn.
fn parse_with_worldspawn(source: &MapSource) -> Result<MapFile, CompileError> {
    let mut map = expand_prefabs(parse_map(&source.path, &source.text)?, &source.path)?;
    map.drop_texture_folders();
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

/// Where `-add`'s `add` is: as written (absolute, or relative to the working directory) when
/// it is there, else beside the map being compiled.
fn added_map_path(source: &MapSource, add: &Path) -> PathBuf {
    if add.is_absolute() || add.exists() {
        return add.to_path_buf();
    }
    source
        .path
        .parent()
        .map_or_else(|| add.to_path_buf(), |dir| dir.join(add))
}

/// Append the map `added` to `map`, as ericw-tools' `-add` does: its worldspawn's brushes join
/// the world (as a `func_group`, which the entity lump leaves out, so that warnings number them
/// apart from the base map's) and its other entities follow; its worldspawn's keys are dropped.
fn merge_added_map(map: &mut MapFile, added: MapFile) {
    let mut entities = added.entities.into_iter();
    if let Some(world) = entities.next() {
        let mut group = Entity::default();
        group.set("classname", "func_group");
        map.entities.push(MapEntity {
            entity: group,
            brushes: world.brushes,
            line: world.line,
        });
    }
    map.entities.extend(entities);
}

/// The entity lump's entities for `map` (leaving out those `left_out` marks, and editor keys
/// unless `options` keeps them): worldspawn, the point entities, and each brush entity not
/// merged into the world, numbered `*1`, `*2`... in
/// order, with the origin its brushes are built around. Merged entities (`func_group`,
/// `func_detail*`, brushless ones too: they have no spawn function in any game) are left out.
pub(crate) fn lump_entities(
    map: &MapFile,
    left_out: &[bool],
    options: &CompileOptions,
) -> Vec<Entity> {
    let mut planes = PlaneSet::new();
    let mut models = 0;
    let mut out = Vec::new();
    let kept = |e: &Entity| match options.keep_editor_keys {
        true => e.clone(),
        false => without_editor_keys(e),
    };
    for (index, ent) in map.entities.iter().enumerate() {
        if left_out[index] {
            continue;
        }
        let class = ent.entity.classname();
        if index == 0 || EntityBrushes::of(index, class) != EntityBrushes::Submodel {
            if index == 0 {
                out.push(kept(&ent.entity));
            }
            continue;
        }
        let mut e = kept(&ent.entity);
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

/// Give each face whose texture meets it edge-on (a mapper's degenerate Valve axes, or a sliver
/// the tree left between brushes, textured from a side on another plane) Quake's own projection
/// of that texture for its plane, as ericw-tools' qbsp repairs such sides, then cut it for its
/// lightmap. Returns how many faces it squared up.
fn square_up_projections<'a>(
    models: impl Iterator<Item = &'a mut Vec<ModelFace>>,
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
    for model_faces in models {
        let mut faces = Vec::with_capacity(model_faces.len());
        for mut f in std::mem::take(model_faces) {
            let normal = f.normal(planes);
            let info = table.infos[f.texinfo as usize];
            if projection_squareness(&info.vecs, normal) >= MIN_SQUARENESS {
                faces.push(f);
                continue;
            }
            squared += 1;
            let name = table.names[info.texture as usize].clone();
            let vecs = quake.vecs(&Plane::new(normal, 0.0));
            f.texinfo = table.intern(&name, vecs, info.keys());
            let squared_info = FaceTexInfo {
                vecs,
                role: info.role,
                special: info.is_special(),
            };
            cut_for_lightmaps(f, &squared_info, subdivide, &mut faces);
        }
        *model_faces = faces;
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
