//! The command line: `slipgate-bsp [--bsp2 | --2psb] [--wad-dir DIR]... IN.map [OUT.bsp]`.

use crate::content_flags::content_json;
use crate::convert::{MapFormat, convert_map};
use crate::map::parse_map;
use crate::onlyents::replace_entities;
use crate::options::DEFAULT_MAX_EDGES;
use crate::outside::FillType;
use crate::tree::MID_SPLIT_SIZE;
use crate::{CompileOptions, MapSource, SplitHeuristic, compile};
use anyhow::{Context, Result};
use quake_formats::fsutil::write_atomic;
use quake_formats::pts::write_pointfile;
use quake_formats::{Bsp, BspVersion};
use std::path::{Path, PathBuf};

quake_formats::ericw_accepted! {
    /// ericw-tools' qbsp options that Slipgate's compiler accepts without acting on them.
    pub struct EricwOnly with reporting {
        loghulls: bool => "the summary counts every hull's nodes",
        logbmodels: bool => "the summary is the same either way",
        oldaxis: bool => "standard-format texture axes are always id's",
        nooldaxis: bool => "standard-format texture axes are always id's; alignment may differ",
        chop: bool => "brushes are never chopped; CSG happens in the BSP tree",
        nochop: bool => "brushes are never chopped; CSG happens in the BSP tree",
        chopfragment: bool => "brushes are never chopped; CSG happens in the BSP tree",
        forcegoodtree: bool => "the tree is always chosen by the fewest-splits heuristic",
        notjunc: bool => "T-junctions are always welded wherever a crack could show",
        tjunc: Option<String> => "T-junctions are always welded wherever a crack could show",
        splitsky: bool => "sky faces merge like any others",
        splitspecial: bool => "sky and liquid faces merge like any others",
        transsky: bool => "sky is always opaque to vis",
        noskip: bool => "skip faces are always left out",
        nodetail: bool => "detail brushes stay detail",
        nomerge: bool => "faces are always merged",
        noedgereuse: bool => "edges are shared wherever engines allow it",
        leakdist: Option<String> => "the pointfile has one point per leaf crossed",
        allowupgrade: bool => "BSP2 is written by itself when BSP29's limits break",
        noallowupgrade: bool => "BSP2 is written by itself when BSP29's limits break",
        software: bool => "output always suits software renderers",
        nosoftware: bool => "output always suits software renderers",
        epsilon: Option<String> => "one epsilon policy holds everywhere (see ARCHITECTURE.md)",
        microvolume: Option<String> => "one epsilon policy holds everywhere (see ARCHITECTURE.md)",
        worldextent: Option<String> => "the world's extent comes from its brushes",
        forceprt1: bool => "PRT1 is written unless the map has detail",
        objexport: bool => "no OBJ export; `slipgate view` previews the map",
        outsidedebug: bool => "no debug maps are written",
        debugchop: bool => "no debug maps are written",
        debugleak: bool => "the pointfile and the leak message name the hole",
        notriggermodels: bool => "trigger models are written as for every game",
        includeskip: bool => "skip faces are always left out",
        lmscale: Option<String> => "light reads `_lmscale` from the entities; `slipgate light --lmshift N` sets every model's spacing",
        noextendedsurfflags: bool => "Slipgate writes no extended surface flags (ericw-tools' .texinfo.json)",
        nodefaultpaths: bool => "WADs are found as docs/mapping.md says",
        defaultpaths: bool => "WADs are found as docs/mapping.md says",
        gamedir: Option<String> => "WADs are found as docs/mapping.md says",
        basedir: Option<String> => "WADs are found as docs/mapping.md says",
        filepriority: Option<String> => "WADs are found as docs/mapping.md says",
        oldrottex: bool => "rotate_ brushes are textured as docs/mapping.md says",
        midsplitsurffraction: Option<String> => "the tree is always chosen by the fewest-splits heuristic",
        midsplitbrushfraction: Option<String> => "the tree is always chosen by the fewest-splits heuristic",
        aliasdef: Vec<String> => "entity aliases are not read; the map's classnames are kept",
        texturedefs: Option<String> => "texture remaps are not read; the map's texture names are kept",
        debugbspbrushes: bool => "no debug maps are written",
        debugleafvolumes: bool => "no debug maps are written",
    }
}

/// The compiler's command line, shared by `slipgate bsp` and `slipgate-bsp`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// The .map file to compile
    pub input: PathBuf,
    /// The BSP to write (default: the input with .bsp); the .prt, the .content.json (and the .pts
    /// on a leak) go beside it
    pub output: Option<PathBuf>,
    /// Write BSP2 (BSP29 is used unless a limit is exceeded)
    #[arg(long)]
    pub bsp2: bool,
    /// Write 2PSB, RMQ's first BSP2: 32-bit indices, but 16-bit integer node and leaf bounds
    /// (BSP2 is written instead when a bound does not fit them)
    #[arg(long = "2psb", conflicts_with = "bsp2")]
    pub bsp2psb: bool,
    /// A directory to search for the WADs worldspawn names (repeatable; ericw-tools spells it
    /// -wadpath). A WAD named with a path is looked for with that path joined onto each
    /// directory, then by its file name alone; the map's own directory and the working
    /// directory are searched last
    #[arg(long = "wad-dir", visible_alias = "wadpath", value_name = "DIR")]
    pub wad_dirs: Vec<PathBuf>,
    /// Like --wad-dir, but the textures of WADs found there are not embedded: only their names
    /// and sizes, for engines that load them from the WAD (-xwadpath)
    #[arg(long = "xwadpath", value_name = "DIR")]
    pub xwad_dirs: Vec<PathBuf>,
    /// How node planes are chosen: fewest-splits or balanced
    #[arg(long, default_value = "fewest-splits")]
    pub heuristic: SplitHeuristic,
    /// Largest lightmap span of a face in texels before it is cut (0: never cut)
    #[arg(long, default_value_t = 240.0)]
    pub subdivide: f64,
    /// Never cut faces for their lightmaps (--subdivide 0; needs an engine without the 256-texel
    /// surface limit)
    #[arg(long)]
    pub nosubdivide: bool,
    /// Cut nodes larger than this (units, on any axis) near their middle before choosing planes
    /// by the heuristic (0: never)
    #[arg(long, value_name = "N", default_value_t = MID_SPLIT_SIZE)]
    pub maxnodesize: f64,
    /// Cut faces left with more than N edges by T-junction fixing into smaller ones, for engines
    /// that copy faces into fixed buffers (0: never; liquids at most 60 either way but 0)
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_EDGES, value_parser = parse_max_edges)]
    pub maxedges: usize,
    /// Make a leak an error: nothing but the .pts pointfile is written, and the exit status is 1
    #[arg(long)]
    pub leaktest: bool,
    /// Keep the void outside the map instead of filling it (for debugging; leaks are not looked
    /// for)
    #[arg(long)]
    pub nofill: bool,
    /// How a sealed map's space no point entity reaches (a closed room, the inside of a closed
    /// box) is filled after the void: auto or inside fill it, in each hull by what reaches there
    /// in that hull (as ericw-tools does); outside fills only the void
    #[arg(long, value_name = "TYPE", default_value = "auto")]
    pub filltype: FillType,
    /// Fill the space no point entity reaches leaf by leaf, so that pockets closed by detail
    /// brushes are filled too, whatever --filltype says (0 turns it off)
    #[arg(
        long,
        value_name = "N",
        default_value = "1",
        num_args = 0..=1,
        require_equals = true,
        default_missing_value = "1",
        value_parser = clap::value_parser!(u8).range(0..=1)
    )]
    pub filldetail: u8,
    /// Light liquids (1, the default): they get lightmaps and are subdivided like other faces, so
    /// that QuakeSpasm, Ironwail, vkQuake and FTE draw them lit; 0 writes them unlit, drawn
    /// fullbright everywhere. The `_litwater` key of worldspawn or a brush entity overrides it
    #[arg(
        long,
        visible_alias = "splitturb",
        value_name = "N",
        default_value = "1",
        num_args = 0..=1,
        require_equals = true,
        default_missing_value = "1",
        value_parser = clap::value_parser!(u8).range(0..=1)
    )]
    pub litwater: u8,
    /// A brush model's liquid brushes stay liquid (a func_door of water you can swim in, in FTE);
    /// WinQuake-style engines give such a model no collision. Without it they are solid
    #[arg(long)]
    pub bmodelcontents: bool,
    /// Liquids are seen through: vis looks through their surfaces and they do not cut rooms
    /// into clusters (the default)
    #[arg(long, conflicts_with = "notranswater")]
    pub transwater: bool,
    /// Liquids are opaque to vis: their surfaces bound its clusters and it never looks through
    /// them, for engines that draw liquids opaque
    #[arg(long)]
    pub notranswater: bool,
    /// Write the .prt even when the map leaks (vis then works through the void as well, slowly;
    /// without it, a leaking map gets no .prt and an old one is removed)
    #[arg(long)]
    pub keepprt: bool,
    /// Write no MAPNAME.content.json (each leaf's extended content flags, which ericw-tools'
    /// light reads); an old one is removed
    #[arg(long)]
    pub noextendedcontentflags: bool,
    /// Build no clip hulls: players and monsters collide with nothing but point-sized hull 0
    /// (for engines that collide with brushes, with --wrbrushes)
    #[arg(long)]
    pub noclip: bool,
    /// Write textures as names and sizes without pixels, for engines that load them from
    /// elsewhere (FTE, QuakeSpasm-Spiked); the WADs are still read for the sizes
    #[arg(long)]
    pub notex: bool,
    /// A folder searched for loose textures (repeatable): with --notex, a texture no WAD holds
    /// takes its size from textures/NAME.png or .tga there
    #[arg(long = "path", value_name = "DIR")]
    pub texture_paths: Vec<PathBuf>,
    /// Write textures found nowhere as 0x0 miptex with their names, for engines that load them
    /// from elsewhere (others crash on them); by default they are 64x64 placeholders
    #[arg(
        long = "missing-textures-as-zero-size",
        visible_alias = "missing_textures_as_zero_size"
    )]
    pub missing_textures_as_zero_size: bool,
    /// Merge another .map into this one (repeatable): its worldspawn brushes join the world and
    /// its other entities follow; its worldspawn keys are ignored. A relative path not found from
    /// the working directory is looked for beside the input map
    #[arg(long, value_name = "FILE.map")]
    pub add: Vec<PathBuf>,
    /// Leave out func_detail brushes
    #[arg(long)]
    pub omitdetail: bool,
    /// Leave out func_detail_wall brushes
    #[arg(long)]
    pub omitdetailwall: bool,
    /// Leave out func_detail_illusionary brushes
    #[arg(long)]
    pub omitdetailillusionary: bool,
    /// Leave out func_detail_fence brushes
    #[arg(long)]
    pub omitdetailfence: bool,
    /// Keep editor-only keys (TrenchBroom's _tb_textures, _tb_layer...) in the entity lump; by
    /// default they are left out, as they mean nothing to engines and _tb_textures can crash
    /// vanilla clients
    #[arg(long)]
    pub keep_editor_keys: bool,
    /// Leave out TrenchBroom layers marked Omit From Export, with everything in them, as
    /// TrenchBroom's Export step does; by default they are compiled, as ericw-tools compiles
    /// them (a note names each)
    #[arg(long)]
    pub omit_layers: bool,
    /// Write the BSPX BRUSHLIST lump: every model's brushes, for engines and importers that
    /// collide with brushes (FTE, bevy_trenchbroom)
    #[arg(long, alias = "bspx")]
    pub wrbrushes: bool,
    /// --wrbrushes without clip hulls (--noclip): only for engines that collide with brushes
    #[arg(long, alias = "bspxonly")]
    pub wrbrushesonly: bool,
    /// Worker threads (default: one per core); the output is the same for any number
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// ericw-tools' options accepted with a note (hidden from the help).
    #[command(flatten)]
    pub ericw_only: EricwOnly,
    /// Only replace the entities of the existing BSP (OUT.bsp) with the .map's, keeping its
    /// geometry, vis and light; its brush entities must match the BSP's models
    #[arg(long)]
    pub onlyents: bool,
    /// Rewrite the .map with its texture projections in this format, as IN-FORMAT.map beside
    /// it, instead of compiling (to Valve 220 exactly; to Quake as near as Quake can come)
    #[arg(long, value_name = "FORMAT")]
    pub convert: Option<MapFormat>,
    /// Write counts and timings as JSON
    #[arg(long, value_name = "FILE.json")]
    pub stats: Option<PathBuf>,
}

impl Args {
    /// The compile the options ask for.
    pub fn compile_options(&self) -> CompileOptions {
        let omit = [
            (self.omitdetail, "func_detail"),
            (self.omitdetailwall, "func_detail_wall"),
            (self.omitdetailillusionary, "func_detail_illusionary"),
            (self.omitdetailfence, "func_detail_fence"),
        ]
        .into_iter()
        .filter(|(on, _)| *on)
        .map(|(_, class)| class.to_string())
        .collect();
        CompileOptions {
            version: if self.bsp2 {
                BspVersion::Bsp2
            } else if self.bsp2psb {
                BspVersion::Bsp2Psb
            } else {
                BspVersion::Bsp29
            },
            wad_dirs: self.wad_dirs.clone(),
            xwad_dirs: self.xwad_dirs.clone(),
            heuristic: self.heuristic,
            max_node_size: self.maxnodesize,
            subdivide: if self.nosubdivide {
                0.0
            } else {
                self.subdivide
            },
            fill: !self.nofill,
            fill_type: self.filltype,
            fill_detail: self.filldetail != 0,
            transwater: !self.notranswater,
            lit_water: self.litwater != 0,
            bmodel_contents: self.bmodelcontents,
            max_edges: self.maxedges,
            clip_hulls: !(self.noclip || self.wrbrushesonly),
            add: self.add.clone(),
            omit,
            texture_data: !self.notex,
            texture_paths: self.texture_paths.clone(),
            missing_textures_as_zero_size: self.missing_textures_as_zero_size,
            brush_list: self.wrbrushes || self.wrbrushesonly,
            keep_editor_keys: self.keep_editor_keys,
            omit_layers: self.omit_layers,
            progress: quake_formats::progress::terminal(),
        }
    }
}

/// The compiler's options whose value is optional (`-litwater`, `-litwater 0`): a following
/// number is their value, anything else is left as the next argument.
pub fn join_optional_values(args: impl IntoIterator<Item = String>) -> Vec<String> {
    quake_formats::cli::join_optional_values(
        args,
        &[("--filldetail", 1), ("--litwater", 1), ("--splitturb", 1)],
    )
}

/// `--maxedges`: 0 (no limit) or a face of at least a triangle.
fn parse_max_edges(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if n == 0 || n >= 3 => Ok(n),
        _ => Err(format!("{s:?} is neither 0 (no limit) nor 3 or more edges")),
    }
}

fn convert(source: &MapSource, format: MapFormat) -> Result<()> {
    let map = parse_map(&source.path, &source.text)?;
    let (text, approximate) = convert_map(&map, format);
    let stem = source
        .path
        .file_stem()
        .unwrap_or_default()
        .to_string_lossy();
    let out = source
        .path
        .with_file_name(format!("{stem}-{}.map", format.name()));
    // Back to Latin-1, as the map was read.
    let bytes: Vec<u8> = text
        .chars()
        .map(|c| u8::try_from(u32::from(c)).unwrap_or(b'?'))
        .collect();
    write_atomic(&out, &bytes)?;
    println!("wrote {}", out.display());
    if approximate > 0 {
        eprintln!(
            "warning: {approximate} faces have texture axes Quake's format cannot express; \
             their textures are projected as near as it can"
        );
    }
    Ok(())
}

fn only_entities(source: &MapSource, args: &Args, bsp_path: &Path) -> Result<()> {
    let bytes = std::fs::read(bsp_path)
        .with_context(|| format!("--onlyents: reading {}", bsp_path.display()))?;
    let mut bsp = Bsp::read(&bytes).with_context(|| format!("reading {}", bsp_path.display()))?;
    replace_entities(source, &args.compile_options(), &mut bsp)?;
    write_atomic(bsp_path, &bsp.write().context("encoding the BSP")?)?;
    println!(
        "wrote the entities of {} into {}",
        args.input.display(),
        bsp_path.display()
    );
    Ok(())
}

/// Remove a file an earlier compile left that no longer belongs to the map (a pointfile once it
/// seals, a portal file once it leaks, content flags not asked for).
fn remove_stale(path: &Path) -> Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("removing the old {}", path.display()))
        }
        _ => Ok(()),
    }
}

/// Runs `slipgate bsp` with `args`: the compile's counts and timings, or `None` when the
/// options ask for no compile (`--onlyents`, `--convert`).
pub fn run(args: &Args) -> Result<Option<crate::CompileStats>> {
    for note in args.ericw_only.notes() {
        eprintln!("note: {note}");
    }
    match args.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .context("starting the worker threads")?
            .install(|| compile_and_write(args)),
        None => compile_and_write(args),
    }
}

/// [`run`] on the current worker threads.
fn compile_and_write(args: &Args) -> Result<Option<crate::CompileStats>> {
    let source = MapSource::read(&args.input)?;
    let bsp_path = args
        .output
        .clone()
        .unwrap_or_else(|| args.input.with_extension("bsp"));
    if args.onlyents {
        return only_entities(&source, args, &bsp_path).map(|()| None);
    }
    if let Some(format) = args.convert {
        return convert(&source, format).map(|()| None);
    }
    let out = compile(&source, &args.compile_options())?;
    let pts_path = bsp_path.with_extension("pts");
    let prt_path = bsp_path.with_extension("prt");
    let content_path = bsp_path.with_extension("content.json");
    if args.leaktest
        && let Some(leak) = &out.leak
    {
        write_atomic(&pts_path, write_pointfile(&leak.pointfile).as_bytes())?;
        anyhow::bail!(
            "--leaktest: the map leaks: {leak}; nothing written but the pointfile {}",
            pts_path.display()
        );
    }
    // The two files' bytes are made side by side; they are written in order, BSP first.
    let (bytes, prt) = rayon::join(
        || out.bsp.write(),
        || (out.leak.is_none() || args.keepprt).then(|| out.portals.write()),
    );
    write_atomic(&bsp_path, &bytes.context("encoding the BSP")?)?;
    match prt {
        Some(text) => write_atomic(&prt_path, text.as_bytes())?,
        None => remove_stale(&prt_path)?,
    }
    if args.noextendedcontentflags {
        remove_stale(&content_path)?;
    } else {
        write_atomic(&content_path, content_json(&out.leaf_contents).as_bytes())?;
    }
    match &out.leak {
        Some(leak) => write_atomic(&pts_path, write_pointfile(&leak.pointfile).as_bytes())?,
        None => remove_stale(&pts_path)?,
    }

    // Repeated warnings of one kind are summarised after a few.
    let mut shown = std::collections::HashMap::new();
    for w in &out.warnings {
        let kind = std::mem::discriminant(w);
        let n = shown.entry(kind).or_insert(0usize);
        *n += 1;
        if *n <= 10 {
            eprintln!("warning: {w}");
        }
    }
    for w in &out.warnings {
        if let Some(n) = shown.remove(&std::mem::discriminant(w))
            && n > 10
        {
            eprintln!("warning: ... and {} more like the above", n - 10);
        }
    }
    let s = &out.stats;
    println!(
        "{}: {} brushes ({} bad), {} entities, {} models",
        args.input.display(),
        s.brushes,
        s.bad_brushes,
        s.entities,
        s.models
    );
    println!(
        "  {} planes, {} nodes, {} leaves, {} faces, {} splits, {} clipnodes, {} vertices, {} edges",
        s.planes, s.nodes, s.leaves, s.faces, s.splits, s.clipnodes, s.vertices, s.edges
    );
    println!(
        "  {} portals ({} for vis between {} clusters), {} textures, {} texinfo, {} T-junction vertices added",
        s.portals, s.vis_portals, s.clusters, s.textures, s.texinfo, s.tjunction_vertices
    );
    let grid = &s.lightmap_grid;
    if grid.faces_disagreeing > 0 {
        println!(
            "  {} faces sized differently by QuakeSpasm and DarkPlaces: {} texinfos nudged, {} split, {} faces left",
            grid.faces_disagreeing,
            grid.nudged_texinfos,
            grid.split_texinfos,
            grid.unresolved_faces
        );
    }
    for (phase, secs) in &s.timings {
        println!("  {phase:<28} {secs:8.3} s");
    }
    println!("wrote {} ({})", bsp_path.display(), s.version);
    if let Some(leak) = &out.leak {
        let prt = if args.keepprt {
            format!("{} written anyway (--keepprt)", prt_path.display())
        } else {
            "no .prt written: vis needs a sealed map".to_string()
        };
        eprintln!(
            "LEAK: the map is open to the void; the pointfile {} ({} points) leads from entity {} \
             to the void (load it in the editor); {prt}",
            pts_path.display(),
            leak.pointfile.len(),
            leak.entity,
        );
    }
    if let Some(path) = &args.stats {
        let json = serde_json::to_string_pretty(s)?;
        write_atomic(path, json.as_bytes())?;
    }
    Ok(Some(out.stats))
}
