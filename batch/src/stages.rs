//! One map through the stages, each looked up in the cache by the key of its inputs first.
//!
//! | stage | key: the content of | makes |
//! |---|---|---|
//! | `bsp` | the map's geometry view (below), the WADs it names as the compiler finds them, the bsp options | BSP, `.prt` |
//! | `vis` | bsp's BSP and `.prt`, the vis options | BSP with visibility |
//! | `ents` | vis's BSP, the whole `.map` text, the bsp options | that BSP with the map's entity lump (`bsp --onlyents`) |
//! | `light` | ents' BSP, the light options, the palette light finds | lit BSP (and `.lit`) |
//! | `preview` | light's BSP and `.lit`, the view options, the palette the viewer finds | PNG |
//!
//! Every key also holds the tool's identity (version and the hash of the running program). The
//! geometry view is the map after prefabs are spliced in, without line numbers, with every point
//! entity whose classname starts with `light` cut down to its `classname`, `origin` and
//! `targetname`, and worldspawn to the keys the compiler reads of it ([`WORLDSPAWN_KEYS_COMPILED`]).
//! So a map whose lights changed only their other keys (`light`, `_color`, `wait`, `style`, ...),
//! or whose worldspawn changed only light's keys (`_sunlight`, `_dirt`, ...), keeps its bsp and
//! vis, and re-runs only the cheap entity replacement, light and the preview; moving a light
//! re-runs everything.
//! The ents step puts the same entity lump into the BSP as a full compile would, so the result
//! is byte-identical to a build from scratch.

use crate::cache::{Cache, StageRecord};
use crate::hash::KeyHasher;
use crate::options::{parse_stage, stage_words};
use crate::project::MapJob;
use bsp_compiler::map::{MapFile, parse_map};
use bsp_compiler::prefab::expand_prefabs;
use bsp_compiler::wad_lookup::WadSet;
use bsp_compiler::{CompileOptions, MapSource, Progress, compile, wad_search};
use quake_formats::Bsp;
use quake_formats::fsutil::write_atomic;
use quake_formats::prt::PortalFile;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The stages in the order they run.
pub const STAGES: [&str; 5] = ["bsp", "vis", "ents", "light", "preview"];

/// What one stage did for one map.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct StageRun {
    pub stage: String,
    pub key: String,
    /// Taken from the cache (`seconds` is then the time the stage took when it ran).
    pub cached: bool,
    pub seconds: f64,
    pub counts: String,
    /// The hash of each output the stage made (`bsp`, `prt`, `lit`, `png`).
    pub outputs: BTreeMap<String, String>,
}

/// Why a map failed: the stage and the error.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Failure {
    pub stage: String,
    pub message: String,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.stage, self.message)
    }
}

/// One map's result.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct MapOutcome {
    pub map: String,
    pub stages: Vec<StageRun>,
    /// Output path (relative to the output folder) and the hash of its bytes.
    pub outputs: BTreeMap<String, String>,
    pub failure: Option<Failure>,
}

/// What every map's stages share.
pub struct Context<'a> {
    pub cache: &'a Cache,
    /// The tool's identity, part of every key.
    pub tool: &'a str,
    /// Run every stage, whatever the cache holds (the results are stored again).
    pub force: bool,
    pub project_root: &'a Path,
    pub output_dir: &'a Path,
    /// Told the name of each stage as it starts.
    pub on_stage: &'a (dyn Fn(&str) + Sync),
}

/// What a stage made: named outputs and what it counted.
struct Product {
    outputs: Vec<(&'static str, Vec<u8>)>,
    counts: String,
}

type StageResult<T> = Result<T, Failure>;

fn fail(stage: &str) -> impl Fn(String) -> Failure + '_ {
    move |message| Failure {
        stage: stage.to_string(),
        message,
    }
}

/// One map through every stage; a failing stage ends the map and is named in its outcome.
pub fn build_map(ctx: &Context, job: &MapJob) -> MapOutcome {
    let mut outcome = MapOutcome {
        map: job.name.clone(),
        stages: Vec::new(),
        outputs: BTreeMap::new(),
        failure: None,
    };
    if let Err(failure) = run_stages(ctx, job, &mut outcome) {
        outcome.failure = Some(failure);
    }
    outcome
}

fn run_stages(ctx: &Context, job: &MapJob, outcome: &mut MapOutcome) -> StageResult<()> {
    let source = MapSource::read(&job.path).map_err(|e| fail("bsp")(e.to_string()))?;
    let runs = &mut outcome.stages;
    let (compiled, omit_words) = bsp_stage(ctx, job, &source, runs)?;
    let visible = vis_stage(ctx, job, &compiled, runs)?;
    let with_entities = ents_stage(ctx, &source, &omit_words, &visible, runs)?;
    let lit = light_stage(ctx, job, &with_entities, runs)?;

    let bsp_bytes = blob(ctx, "light", &lit, "bsp")?;
    let mut outputs = vec![
        ("bsp", bsp_bytes),
        ("prt", blob(ctx, "bsp", &compiled, "prt")?),
    ];
    // Light's companion files: each written when light made it, else an old one removed.
    for extension in ["lit", "lux"] {
        if lit.outputs.contains_key(extension) {
            outputs.push((extension, blob(ctx, "light", &lit, extension)?));
        } else {
            remove_stale(&job.output(ctx.output_dir, extension)).map_err(fail("light"))?;
        }
    }
    for (extension, bytes) in &outputs {
        put_output(ctx, job, extension, bytes, &mut outcome.outputs).map_err(fail("light"))?;
    }
    if let Some(preview) = &job.options.preview {
        let picture = preview_stage(ctx, job, preview, &lit, &mut outcome.stages)?;
        let png = blob(ctx, "preview", &picture, "png")?;
        put_output(ctx, job, "png", &png, &mut outcome.outputs).map_err(fail("preview"))?;
    }
    Ok(())
}

/// Look the stage up by `key`, or run it and store what it made.
fn cached_stage(
    ctx: &Context,
    stage: &'static str,
    key: String,
    runs: &mut Vec<StageRun>,
    work: impl FnOnce() -> Result<Product, String>,
) -> StageResult<StageRecord> {
    if !ctx.force
        && let Some(record) = ctx.cache.record(&key)
    {
        runs.push(StageRun {
            stage: stage.into(),
            key,
            cached: true,
            seconds: record.seconds,
            counts: record.counts.clone(),
            outputs: record.outputs.clone(),
        });
        return Ok(record);
    }
    (ctx.on_stage)(stage);
    let start = Instant::now();
    let product = work().map_err(fail(stage))?;
    let mut outputs = BTreeMap::new();
    for (name, bytes) in &product.outputs {
        let hash = ctx
            .cache
            .put_blob(bytes)
            .map_err(|e| fail(stage)(e.to_string()))?;
        outputs.insert(name.to_string(), hash);
    }
    let record = StageRecord {
        outputs,
        counts: product.counts,
        seconds: start.elapsed().as_secs_f64(),
    };
    ctx.cache
        .put_record(&key, &record)
        .map_err(|e| fail(stage)(e.to_string()))?;
    runs.push(StageRun {
        stage: stage.into(),
        key,
        cached: false,
        seconds: record.seconds,
        counts: record.counts.clone(),
        outputs: record.outputs.clone(),
    });
    Ok(record)
}

fn blob(ctx: &Context, stage: &str, record: &StageRecord, name: &str) -> StageResult<Vec<u8>> {
    let hash = record
        .outputs
        .get(name)
        .ok_or_else(|| fail(stage)(format!("the cached stage has no {name} output")))?;
    ctx.cache.blob(hash).map_err(|e| fail(stage)(e.to_string()))
}

fn output_hash<'r>(record: &'r StageRecord, name: &str) -> &'r str {
    record.outputs.get(name).map_or("none", String::as_str)
}

/// Write an output unless the file already holds these bytes, and note its hash.
fn put_output(
    ctx: &Context,
    job: &MapJob,
    extension: &str,
    bytes: &[u8],
    outputs: &mut BTreeMap<String, String>,
) -> Result<(), String> {
    let path = job.output(ctx.output_dir, extension);
    if std::fs::read(&path).ok().as_deref() != Some(bytes) {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        write_atomic(&path, bytes).map_err(|e| e.to_string())?;
    }
    outputs.insert(job.output_name(extension), crate::hash::hash_bytes(bytes));
    Ok(())
}

/// Engines would load a `.lit` left from an earlier build over the new lightmaps.
fn remove_stale(path: &Path) -> Result<(), String> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(format!("removing stale {}: {e}", path.display()))
        }
        _ => Ok(()),
    }
}

fn key_with_options(ctx: &Context, stage: &str, words: &[String]) -> KeyHasher {
    let mut key = KeyHasher::new(stage);
    key.field("tool", ctx.tool.as_bytes())
        .field("options", words.join("\0").as_bytes());
    key
}

/// The stage's options parsed by its own command line, with `first` as its positional argument.
fn stage_args<A: clap::Args + clap::FromArgMatches>(
    stage: &'static str,
    first: &Path,
    words: &[String],
) -> StageResult<A> {
    let mut argv = vec![first.to_string_lossy().into_owned()];
    argv.extend(words.iter().cloned());
    parse_stage(stage, &argv).map_err(|e| fail(stage)(format!("options: {e}")))
}

/// Returns the bsp stage's record and its option words (the ents step leaves out what it does).
fn bsp_stage(
    ctx: &Context,
    job: &MapJob,
    source: &MapSource,
    runs: &mut Vec<StageRun>,
) -> StageResult<(StageRecord, Vec<String>)> {
    let words = stage_words(&job.options.bsp);
    let args: bsp_compiler::cli::Args = stage_args("bsp", &job.path, &words)?;
    if args.onlyents || args.convert.is_some() {
        return Err(fail("bsp")(
            "--onlyents and --convert are not batch options".into(),
        ));
    }
    let mut options = args.compile_options();
    options.progress = Progress::default();
    for dir in options.wad_dirs.iter_mut().chain(&mut options.xwad_dirs) {
        *dir = ctx.project_root.join(&*dir);
    }
    let mut key = key_with_options(ctx, "bsp", &words);
    let map = geometry_view(source).map_err(fail("bsp"))?;
    key.debug_field("geometry", &map);
    for (path, bytes) in wads_used(source, &map, &options).map_err(fail("bsp"))? {
        key.field("wad", path.to_string_lossy().as_bytes())
            .field("wad bytes", &bytes);
    }
    let record = cached_stage(ctx, "bsp", key.finish(), runs, || {
        compile_map(ctx, job, source, &options)
    })?;
    Ok((record, words))
}

fn compile_map(
    ctx: &Context,
    job: &MapJob,
    source: &MapSource,
    options: &CompileOptions,
) -> Result<Product, String> {
    let out = compile(source, options).map_err(|e| e.to_string())?;
    if let Some(leak) = &out.leak {
        let pts = job.output(ctx.output_dir, "pts");
        let text = quake_formats::pts::write_pointfile(&leak.pointfile);
        if let Some(dir) = pts.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        write_atomic(&pts, text.as_bytes()).map_err(|e| e.to_string())?;
        return Err(format!(
            "the map leaks: {leak}; pointfile {}",
            pts.display()
        ));
    }
    let s = &out.stats;
    Ok(Product {
        outputs: vec![
            ("bsp", out.bsp.write().map_err(|e| e.to_string())?),
            ("prt", out.portals.write().into_bytes()),
        ],
        counts: format!(
            "{} faces, {} leaves, {} warnings",
            s.faces,
            s.leaves,
            out.warnings.len()
        ),
    })
}

/// What the compiler reads of the map (see the module comment): lights' other keys and every
/// line number left out.
fn geometry_view(source: &MapSource) -> Result<MapFile, String> {
    let parsed = parse_map(&source.path, &source.text).map_err(|e| e.to_string())?;
    let mut map = expand_prefabs(parsed, &source.path).map_err(|e| e.to_string())?;
    for entity in &mut map.entities {
        entity.line = 0;
        for brush in &mut entity.brushes {
            brush.line = 0;
            for face in &mut brush.faces {
                face.line = 0;
            }
        }
    }
    for (index, entity) in map.entities.iter_mut().enumerate() {
        let read = if index == 0 {
            WORLDSPAWN_KEYS_COMPILED.as_slice()
        } else if entity.brushes.is_empty() && entity.entity.classname().starts_with("light") {
            LIGHT_KEYS_COMPILED.as_slice()
        } else {
            continue;
        };
        entity
            .entity
            .pairs
            .retain(|(k, _)| read.contains(&k.as_str()));
    }
    Ok(map)
}

/// The keys of a light the compiler reads: `origin` decides what the outside fill floods, and a
/// `targetname` could name a rotating entity's pivot.
const LIGHT_KEYS_COMPILED: [&str; 3] = ["classname", "origin", "targetname"];

/// The keys of worldspawn the compiler reads (its others, `_sunlight`, `light`, `_dirt`,
/// `_bounce`..., are light's). A new key the compiler reads must be added here.
const WORLDSPAWN_KEYS_COMPILED: [&str; 9] = [
    "classname",
    "wad",
    "_phong",
    "_phong_angle",
    "_mirrorinside",
    "_noclipfaces",
    "_litwater",
    "origin",
    "targetname",
];

/// The WADs the compile will read, found as the compiler finds them, with their bytes.
fn wads_used(
    source: &MapSource,
    map: &MapFile,
    options: &CompileOptions,
) -> Result<Vec<(PathBuf, Vec<u8>)>, String> {
    let Some(world) = map.entities.first() else {
        return Ok(Vec::new());
    };
    let wads = WadSet::load(&world.entity, &wad_search(source, options), &mut Vec::new());
    wads.paths()
        .map(|path| {
            let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
            Ok((path.to_path_buf(), bytes))
        })
        .collect()
}

fn vis_stage(
    ctx: &Context,
    job: &MapJob,
    compiled: &StageRecord,
    runs: &mut Vec<StageRun>,
) -> StageResult<StageRecord> {
    let words = stage_words(&job.options.vis);
    let args: vis::cli::Args = stage_args("vis", &job.output(ctx.output_dir, "bsp"), &words)?;
    let mut key = key_with_options(ctx, "vis", &words);
    key.field("bsp", output_hash(compiled, "bsp").as_bytes())
        .field("prt", output_hash(compiled, "prt").as_bytes());
    cached_stage(ctx, "vis", key.finish(), runs, || {
        let mut bsp = read_bsp(&blob(ctx, "bsp", compiled, "bsp").map_err(|f| f.message)?)?;
        let prt_bytes = blob(ctx, "bsp", compiled, "prt").map_err(|f| f.message)?;
        let prt = PortalFile::parse(&String::from_utf8_lossy(&prt_bytes))
            .map_err(|e| format!("the portal file: {e}"))?;
        vis::check_portals_match(&bsp, prt.num_leafs as usize).map_err(|e| e.to_string())?;
        let options = args.options();
        let result = vis::compute_vis(&prt, &options).map_err(|e| e.to_string())?;
        vis::store(&mut bsp, &result.pvs, options.ambient).map_err(|e| e.to_string())?;
        let c = &result.stats;
        Ok(Product {
            outputs: vec![("bsp", bsp.write().map_err(|e| e.to_string())?)],
            counts: format!(
                "{:.1} of {} leaves visible on average",
                c.average_visible, c.leafs
            ),
        })
    })
}

fn read_bsp(bytes: &[u8]) -> Result<Bsp, String> {
    Bsp::read(bytes).map_err(|e| e.to_string())
}

fn ents_stage(
    ctx: &Context,
    source: &MapSource,
    bsp_words: &[String],
    visible: &StageRecord,
    runs: &mut Vec<StageRun>,
) -> StageResult<StageRecord> {
    let args: bsp_compiler::cli::Args = stage_args("bsp", &source.path, bsp_words)?;
    let mut key = key_with_options(ctx, "ents", bsp_words);
    key.field("bsp", output_hash(visible, "bsp").as_bytes())
        .field("map", source.text.as_bytes());
    cached_stage(ctx, "ents", key.finish(), runs, || {
        let mut bsp = read_bsp(&blob(ctx, "vis", visible, "bsp").map_err(|f| f.message)?)?;
        bsp_compiler::onlyents::replace_entities(source, &args.compile_options(), &mut bsp)
            .map_err(|e| e.to_string())?;
        let entities =
            quake_formats::entities::parse_entities(&bsp.entity_text()).map_or(0, |e| e.len());
        Ok(Product {
            outputs: vec![("bsp", bsp.write().map_err(|e| e.to_string())?)],
            counts: format!("{entities} entities"),
        })
    })
}

fn light_stage(
    ctx: &Context,
    job: &MapJob,
    with_entities: &StageRecord,
    runs: &mut Vec<StageRun>,
) -> StageResult<StageRecord> {
    let words = stage_words(&job.options.light);
    let args: light::cli::Args = stage_args("light", &job.output(ctx.output_dir, "bsp"), &words)?;
    let options = args
        .lighting_options()
        .map_err(|e| fail("light")(format!("{e:#}")))?;
    let mut key = key_with_options(ctx, "light", &words);
    key.field("bsp", output_hash(with_entities, "bsp").as_bytes());
    if let Some(palette) = &options.palette {
        key.field("palette", &palette.to_bytes());
    }
    cached_stage(ctx, "light", key.finish(), runs, || {
        let mut bsp = read_bsp(&blob(ctx, "ents", with_entities, "bsp").map_err(|f| f.message)?)?;
        let lighting = match args.threads {
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(usize::from(n))
                .build()
                .map_err(|e| format!("starting the worker threads: {e}"))?
                .install(|| light::compute_lighting(&bsp, &options)),
            None => light::compute_lighting(&bsp, &options),
        }
        .map_err(|e| e.to_string())?;
        let files = light::apply_lighting(&mut bsp, &lighting);
        let companions = args.companion_files(&bsp, files);
        let mut outputs = vec![("bsp", bsp.write().map_err(|e| e.to_string())?)];
        outputs.extend(
            companions
                .by_extension()
                .into_iter()
                .filter_map(|(extension, bytes)| Some((extension, bytes?))),
        );
        let s = &lighting.stats;
        Ok(Product {
            outputs,
            counts: format!(
                "{} luxels, {} lights",
                s.luxels,
                s.point_lights + s.surface_lights
            ),
        })
    })
}

fn preview_stage(
    ctx: &Context,
    job: &MapJob,
    preview: &str,
    lit: &StageRecord,
    runs: &mut Vec<StageRun>,
) -> StageResult<StageRecord> {
    use runtime_viewer::{Frame, Renderer, World, cli::initial_camera};
    let words = stage_words(preview);
    let args: runtime_viewer::cli::Args =
        stage_args("preview", &job.output(ctx.output_dir, "bsp"), &words)?;
    let (palette, _) = runtime_viewer::textures::find_palette(&args.map, args.palette.as_deref())
        .map_err(|e| fail("preview")(e.to_string()))?;
    let mut key = key_with_options(ctx, "preview", &words);
    key.field("bsp", output_hash(lit, "bsp").as_bytes())
        .field("lit", output_hash(lit, "lit").as_bytes())
        .field("palette", &palette.to_bytes());
    cached_stage(ctx, "preview", key.finish(), runs, || {
        // The lit BSP and its `.lit` are already written where the viewer reads them.
        let world = World::load(&args.map, args.palette.as_deref()).map_err(|e| e.to_string())?;
        let camera = initial_camera(&world, &args).map_err(|e| format!("{e:#}"))?;
        let mut renderer = Renderer::new(&world, args.render_options());
        let mut frame = Frame::new(camera.width, camera.height);
        renderer.render(&world, &camera, &mut frame);
        let png = runtime_viewer::image::encode_png(&frame).map_err(|e| e.to_string())?;
        Ok(Product {
            outputs: vec![("png", png)],
            counts: format!("{}x{}", camera.width, camera.height),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(text: &str) -> String {
        let source = MapSource {
            path: PathBuf::from("test.map"),
            text: text.to_string(),
        };
        let mut key = KeyHasher::new("view");
        key.debug_field("geometry", &geometry_view(&source).expect("parses"));
        key.finish()
    }

    const BOX: &str = "( 0 0 0 ) ( 0 1 0 ) ( 1 0 0 ) floor1 0 0 0 1 1\n\
                       ( 0 0 8 ) ( 1 0 8 ) ( 0 1 8 ) floor1 0 0 0 1 1\n\
                       ( 0 0 0 ) ( 0 0 1 ) ( 0 1 0 ) floor1 0 0 0 1 1\n\
                       ( 8 0 0 ) ( 8 1 0 ) ( 8 0 1 ) floor1 0 0 0 1 1\n\
                       ( 0 0 0 ) ( 1 0 0 ) ( 0 0 1 ) floor1 0 0 0 1 1\n\
                       ( 0 8 0 ) ( 0 8 1 ) ( 1 8 0 ) floor1 0 0 0 1 1\n";

    fn map(world_keys: &str, light: &str, comment: &str) -> String {
        format!(
            "{comment}{{\n\"classname\" \"worldspawn\"\n{world_keys}{{\n{BOX}}}\n}}\n\
             {{\n\"classname\" \"light\"\n{light}}}\n\
             {{\n\"classname\" \"info_player_start\"\n\"origin\" \"4 4 4\"\n}}\n"
        )
    }

    #[test]
    fn the_geometry_view_leaves_out_what_only_light_reads() {
        let base = view(&map("\"wad\" \"a.wad\"\n", "\"origin\" \"2 2 2\"\n", ""));
        let same = [
            // A light's brightness and colour, and lines moved by a comment.
            map(
                "\"wad\" \"a.wad\"\n",
                "\"origin\" \"2 2 2\"\n\"light\" \"300\"\n\"_color\" \"1 0 0\"\n",
                "// moved\n// down\n",
            ),
            // Worldspawn's sun.
            map(
                "\"wad\" \"a.wad\"\n\"_sunlight\" \"200\"\n",
                "\"origin\" \"2 2 2\"\n",
                "",
            ),
        ];
        for text in &same {
            assert_eq!(view(text), base, "{text}");
        }
        let different = [
            map("\"wad\" \"a.wad\"\n", "\"origin\" \"2 2 3\"\n", ""),
            map("\"wad\" \"b.wad\"\n", "\"origin\" \"2 2 2\"\n", ""),
            map(
                "\"wad\" \"a.wad\"\n\"_phong\" \"1\"\n",
                "\"origin\" \"2 2 2\"\n",
                "",
            ),
            // Regression: worldspawn's `_litwater` decides which liquids get lightmaps.
            map(
                "\"wad\" \"a.wad\"\n\"_litwater\" \"0\"\n",
                "\"origin\" \"2 2 2\"\n",
                "",
            ),
            // Worldspawn's `_noclipfaces` keeps faces between its brushes.
            map(
                "\"wad\" \"a.wad\"\n\"_noclipfaces\" \"1\"\n",
                "\"origin\" \"2 2 2\"\n",
                "",
            ),
        ];
        for text in &different {
            assert_ne!(view(text), base, "{text}");
        }
    }
}
