//! `slipgate-vis`: compute the PVS of a compiled map from the `.prt` file beside it; or one
//! shard's part of the full flow (`--shard K/N`), joined later by `--merge`.

use crate::ambient::{Ambient, Channels};
use crate::saved::{InputsHash, SavedFlows, SavedKind};
use crate::shards;
use crate::{BitSet, Checkpoint, KnownFlows, SaveFlows, Shard, VisMode, VisOptions};
use anyhow::{Context, Result};
use quake_formats::Bsp;
use quake_formats::fsutil::{read_file, write_atomic};
use quake_formats::prt::PortalFile;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

quake_formats::ericw_accepted! {
    /// ericw-tools' vis options that Slipgate's vis accepts without acting on them.
    pub struct EricwOnly with reporting {
        nostate: bool => "saved state is read only with --resume",
        noautoclean: bool => "state files are removed once vis finishes",
        phsonly: bool => "Quake maps have no PHS",
        visdist: Option<String> => "the PVS is never cut by distance; it stays exact",
        gamedir: Option<String> => "vis reads only the BSP and its portal file",
        basedir: Option<String> => "vis reads only the BSP and its portal file",
        filepriority: Option<String> => "vis reads only the BSP and its portal file",
        path: Vec<String> => "vis reads only the BSP and its portal file",
        defaultpaths: bool => "vis reads only the BSP and its portal file",
        nodefaultpaths: bool => "vis reads only the BSP and its portal file",
    }
}

/// The vis command line, shared by `slipgate vis` and `slipgate-vis`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// The compiled map; its portal file MAP.prt must lie beside it. Rewritten in place.
    pub bsp: PathBuf,
    /// Base vis only: quick and conservative, but sees more than it needs to
    #[arg(long)]
    pub fast: bool,
    /// Separating-plane testing level of the full flow (0..=4; higher is tighter and slower)
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u8).range(0..=4), conflicts_with = "fast")]
    pub level: u8,
    /// Portal file to read instead of MAP.prt
    #[arg(long)]
    pub prt: Option<PathBuf>,
    /// Worker threads (default: all cores)
    #[arg(long)]
    pub threads: Option<usize>,
    /// ericw-tools' options accepted with a note (hidden from the help).
    #[command(flatten)]
    pub ericw_only: EricwOnly,
    /// After computing, check the PVS against this many random sight lines traced through the map
    #[arg(long, default_value_t = 0)]
    pub sample_pairs: usize,
    /// Write counts and timings as JSON to this file
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Run only shard K of N (for example 2/4) of the full flow, on this or another machine,
    /// into a partial file (MAP.vis.K-of-N beside the BSP); the BSP is not changed
    #[arg(long, value_parser = Shard::parse, conflicts_with_all = ["fast", "merge"])]
    pub shard: Option<Shard>,
    /// With --shard: the partial file to write. With --merge: a partial file to read
    /// (repeatable; default: every MAP.vis.K-of-N beside the BSP)
    #[arg(long)]
    pub partial: Vec<PathBuf>,
    /// Join the partial files of every shard into the BSP: the same bytes as one whole run
    #[arg(long, conflicts_with = "fast")]
    pub merge: bool,
    /// Continue from the state a killed run saved (MAP.vis.state, or the partial's name plus
    /// .state with --shard); a state of other inputs is refused
    #[arg(long)]
    pub resume: bool,
    /// Save the full flow's state every this many seconds (0: never)
    #[arg(long, default_value_t = 300.0)]
    pub save_interval: f64,
    /// No ambient sounds at all (every leaf silent)
    #[arg(long)]
    pub noambient: bool,
    /// No ambient sound from sky (textures named sky*)
    #[arg(long)]
    pub noambientsky: bool,
    /// No ambient sound from water
    #[arg(long)]
    pub noambientwater: bool,
    /// No ambient sound from slime
    #[arg(long)]
    pub noambientslime: bool,
    /// No ambient sound from lava
    #[arg(long)]
    pub noambientlava: bool,
}

/// Runs `slipgate vis` with `args`: the run's report, or `None` for one shard's part.
pub fn run(args: &Args) -> Result<Option<crate::VisReport>> {
    for note in args.ericw_only.notes() {
        eprintln!("note: {note}");
    }
    let total = Instant::now();
    let inputs = Inputs::read(args)?;
    if let Some(shard) = args.shard {
        run_shard(args, &inputs, shard)?;
        return Ok(None);
    }
    let result = if args.merge {
        merge(args, &inputs)?
    } else {
        let options = options(args);
        let state_path = shards::state_path(&args.bsp);
        let known = resume(args, &inputs, Shard::WHOLE, &state_path)?;
        let save = |results: Vec<(usize, &BitSet)>| {
            save_state(
                &state_path,
                shards::state_bytes(inputs.hash, Shard::WHOLE, results),
            );
        };
        let checkpoint = checkpoint(args, &save);
        let result = crate::compute_vis_resuming(&inputs.prt, &options, known, checkpoint.as_ref())
            .with_context(|| format!("{}", inputs.prt_path.display()))?;
        remove_state(&state_path);
        result
    };
    finish(args, inputs, result, total).map(Some)
}

impl Args {
    /// The options these arguments ask for (no progress reported).
    pub fn options(&self) -> VisOptions {
        VisOptions {
            mode: if self.fast {
                VisMode::Fast
            } else {
                VisMode::Full { level: self.level }
            },
            threads: self.threads,
            ambient: self.channels(),
            ..Default::default()
        }
    }

    /// The ambient channels the options leave on.
    fn channels(&self) -> Channels {
        [
            (self.noambientsky, Ambient::Sky),
            (self.noambientwater, Ambient::Water),
            (self.noambientslime, Ambient::Slime),
            (self.noambientlava, Ambient::Lava),
        ]
        .into_iter()
        .filter(|&(off, _)| off || self.noambient)
        .fold(Channels::ALL, |c, (_, channel)| c.without(channel))
    }
}

/// The options of a run from the command line: the arguments', with a progress bar.
fn options(args: &Args) -> VisOptions {
    VisOptions {
        progress: quake_formats::progress::terminal(),
        ..args.options()
    }
}

/// The BSP and portal file every mode reads, checked against each other.
struct Inputs {
    bsp: Bsp,
    prt: PortalFile,
    prt_path: PathBuf,
    hash: InputsHash,
}

impl Inputs {
    fn read(args: &Args) -> Result<Inputs> {
        let bsp_name = args.bsp.display();
        let bsp = Bsp::read(&read_file(&args.bsp)?).with_context(|| format!("{bsp_name}"))?;
        // Before the portal file: a leaking map has none, and this says why.
        let outside = crate::check_sealed(&bsp).with_context(|| format!("{bsp_name}"))?;
        if let crate::Outside::Included { leaf } = outside {
            eprintln!(
                "note: {bsp_name}: no point entity stands in the map's open space, so the \
                 compiler could not tell inside from outside: the outside is included (leaf \
                 {leaf} lies in it)"
            );
        }
        let prt_path = args
            .prt
            .clone()
            .unwrap_or_else(|| args.bsp.with_extension("prt"));
        let prt_text = read_file(&prt_path)
            .context("vis needs the portal file the compiler writes beside the BSP")?;
        let prt = PortalFile::parse(&String::from_utf8_lossy(&prt_text))
            .with_context(|| format!("{}", prt_path.display()))?;
        crate::check_portals_match(&bsp, prt.num_leafs as usize)
            .with_context(|| format!("{} and {bsp_name}", prt_path.display()))?;
        let hash = InputsHash::new(&prt_text, &bsp, args.level);
        Ok(Inputs {
            bsp,
            prt,
            prt_path,
            hash,
        })
    }
}

fn checkpoint<'a>(args: &Args, save: &'a SaveFlows<'a>) -> Option<Checkpoint<'a>> {
    (args.save_interval > 0.0 && !args.fast).then(|| Checkpoint {
        every: Duration::from_secs_f64(args.save_interval),
        save,
    })
}

/// The results the saved state at `path` holds, when `--resume` asks for them.
fn resume(args: &Args, inputs: &Inputs, shard: Shard, path: &Path) -> Result<KnownFlows> {
    if !args.resume || args.fast {
        return Ok(Vec::new());
    }
    if !path.exists() {
        eprintln!(
            "note: no saved state {} to resume from: starting from the beginning",
            path.display()
        );
        return Ok(Vec::new());
    }
    let known = shards::resume_from(path, &read_file(path)?, inputs.hash, shard)
        .context("cannot resume from it (delete it to start over)")?;
    eprintln!(
        "resuming from {}: {} of {} portal flows done",
        path.display(),
        known.iter().flatten().count(),
        known.len()
    );
    Ok(known)
}

/// Write the state atomically; a failure only warns, the run goes on.
fn save_state(path: &Path, bytes: Vec<u8>) {
    if let Err(e) = write_atomic(path, &bytes) {
        eprintln!("warning: could not save the vis state: {e}");
    }
}

fn remove_state(path: &Path) {
    if let Err(e) = std::fs::remove_file(path)
        && e.kind() != std::io::ErrorKind::NotFound
    {
        eprintln!("warning: could not remove {}: {e}", path.display());
    }
}

fn run_shard(args: &Args, inputs: &Inputs, shard: Shard) -> Result<()> {
    let out = args
        .partial
        .first()
        .cloned()
        .unwrap_or_else(|| shards::partial_path(&args.bsp, shard));
    let state_path = shards::shard_state_path(&out);
    let known = resume(args, inputs, shard, &state_path)?;
    let save = |results: Vec<(usize, &BitSet)>| {
        save_state(
            &state_path,
            shards::state_bytes(inputs.hash, shard, results),
        );
    };
    let checkpoint = checkpoint(args, &save);
    let flows = crate::compute_shard(
        &inputs.prt,
        &options(args),
        shard,
        known,
        checkpoint.as_ref(),
    )
    .with_context(|| format!("{}", inputs.prt_path.display()))?;
    let partial = SavedFlows {
        kind: SavedKind::Partial,
        inputs: inputs.hash,
        shard,
        portals: flows.portals,
        results: flows.results,
    };
    write_atomic(&out, &partial.write())?;
    remove_state(&state_path);
    eprintln!(
        "vis shard {shard}: {} of {} one-way portal flows written to {} (the plan has {} final group(s) to share); base vis {:.2} s, flow {:.2} s",
        partial.results.len(),
        flows.portals,
        out.display(),
        flows.groups,
        flows.base_seconds,
        flows.flow_seconds
    );
    Ok(())
}

/// Read every shard's partial file and join their flows into the sets of one whole run.
fn merge(args: &Args, inputs: &Inputs) -> Result<crate::VisResult> {
    let paths = if args.partial.is_empty() {
        shards::find_partials(&args.bsp).with_context(|| format!("{}", args.bsp.display()))?
    } else {
        args.partial.clone()
    };
    let files = paths
        .into_iter()
        .map(|path| Ok((path.clone(), read_file(&path)?)))
        .collect::<Result<Vec<_>>>()?;
    shards::merge_partials(&inputs.prt, files, inputs.hash).with_context(|| {
        format!(
            "joining the partials of {} (--level {})",
            args.bsp.display(),
            args.level
        )
    })
}

/// Write the sets into the BSP and report.
fn finish(
    args: &Args,
    inputs: Inputs,
    result: crate::VisResult,
    total: Instant,
) -> Result<crate::VisReport> {
    let Inputs {
        mut bsp, prt_path, ..
    } = inputs;
    let bsp_name = args.bsp.display();
    let c = &result.stats;
    if c.misoriented_portals > 0 {
        eprintln!(
            "warning: {}: {} of {} one-way portals face the wrong way or bound non-convex leaves",
            prt_path.display(),
            c.misoriented_portals,
            c.portals
        );
    }

    let start = Instant::now();
    let stored = crate::store(&mut bsp, &result.pvs, args.channels())
        .with_context(|| format!("{bsp_name}"))?;
    let (lump, hearing) = (stored.lump, stored.ambient_leafs);
    let bytes = bsp.write().with_context(|| format!("{bsp_name}"))?;
    write_atomic(&args.bsp, &bytes)?;
    let write_seconds = start.elapsed().as_secs_f64();

    let sampling = if args.sample_pairs > 0 {
        Some(crate::sample::sample_visibility(
            &bsp,
            &result.pvs,
            args.sample_pairs,
            1,
        )?)
    } else {
        None
    };

    let n = c.leafs.max(1) as f64;
    eprintln!(
        "vis ({}): {} leaves in {} clusters, {} one-way portals ({} degenerate dropped)",
        if args.fast {
            "fast".to_string()
        } else {
            format!("full, level {}", args.level)
        },
        c.leafs,
        c.clusters,
        c.portals,
        c.degenerate_portals
    );
    eprintln!(
        "  visible leaves per leaf: average {:.1} ({:.1}%), max {}",
        c.average_visible,
        100.0 * c.average_visible / n,
        c.max_visible
    );
    eprintln!(
        "  visibility lump: {} bytes ({} unique rows, {} bytes uncompressed); {hearing} leaves hear ambient sounds",
        lump.compressed_bytes, lump.unique_rows, lump.uncompressed_bytes
    );
    eprintln!(
        "  time: base vis {:.2} s, flow {:.2} s, write {:.2} s, total {:.2} s",
        c.base_seconds,
        c.flow_seconds,
        write_seconds,
        total.elapsed().as_secs_f64()
    );
    if let Some(s) = &sampling {
        eprintln!(
            "  sampling: {} pairs, {:.2}% visible by sight lines vs {:.2}% in the PVS; {} too small",
            s.pairs,
            100.0 * s.visible_fraction,
            100.0 * s.pvs_fraction,
            s.violations
        );
    }
    let report = crate::VisReport {
        mode: if args.fast { "fast" } else { "full" },
        level: args.level,
        compute: result.stats,
        lump,
        ambient_leafs: hearing,
        write_seconds,
        total_seconds: total.elapsed().as_secs_f64(),
        sampling,
    };
    if let Some(path) = &args.stats {
        write_atomic(path, serde_json::to_string_pretty(&report)?.as_bytes())?;
    }
    Ok(report)
}
