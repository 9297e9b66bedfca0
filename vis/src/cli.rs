//! `slipgate-vis`: compute the PVS of a compiled map from the `.prt` file beside it; or one
//! shard's part of the full flow (`--shard K/N`), joined later by `--merge`.

use crate::saved::{InputsHash, SavedFlows, SavedKind};
use crate::{BitSet, Checkpoint, KnownFlows, SaveFlows, Shard, VisMode, VisOptions};
use anyhow::{Context, Result, bail};
use quake_formats::Bsp;
use quake_formats::fsutil::{read_file, write_atomic};
use quake_formats::prt::PortalFile;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

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
}

pub fn run(args: &Args) -> Result<()> {
    let total = Instant::now();
    let inputs = Inputs::read(args)?;
    if let Some(shard) = args.shard {
        return run_shard(args, &inputs, shard);
    }
    let result = if args.merge {
        merge(args, &inputs)?
    } else {
        let options = VisOptions {
            mode: if args.fast {
                VisMode::Fast
            } else {
                VisMode::Full { level: args.level }
            },
            threads: args.threads,
            progress: true,
            ..Default::default()
        };
        let state_path = saved_path(&args.bsp, "vis.state");
        let known = resume_state(args, &inputs, Shard::WHOLE, &state_path)?;
        let save = |results: Vec<(usize, &BitSet)>| {
            save_state(&inputs, Shard::WHOLE, &state_path, results);
        };
        let checkpoint = checkpoint(args, &save);
        let result = crate::compute_vis_resuming(&inputs.prt, &options, known, checkpoint.as_ref())
            .with_context(|| format!("{}", inputs.prt_path.display()))?;
        remove_state(&state_path);
        result
    };
    finish(args, inputs, result, total)
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
        crate::check_sealed(&bsp).with_context(|| format!("{bsp_name}"))?;
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

/// `MAP.<suffix>` beside the BSP.
fn saved_path(bsp: &Path, suffix: &str) -> PathBuf {
    bsp.with_extension(suffix)
}

/// Where shard `shard`'s partial goes by default: `MAP.vis.K-of-N`.
pub fn partial_path(bsp: &Path, shard: Shard) -> PathBuf {
    saved_path(bsp, &format!("vis.{}-of-{}", shard.index + 1, shard.count))
}

fn checkpoint<'a>(args: &Args, save: &'a SaveFlows<'a>) -> Option<Checkpoint<'a>> {
    (args.save_interval > 0.0 && !args.fast).then(|| Checkpoint {
        every: Duration::from_secs_f64(args.save_interval),
        save,
    })
}

/// The results a saved state holds, when `--resume` asks for them; a state of other inputs or
/// another shard is refused.
fn resume_state(args: &Args, inputs: &Inputs, shard: Shard, path: &Path) -> Result<KnownFlows> {
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
    let name = path.display();
    let state = SavedFlows::read(&read_file(path)?, SavedKind::State)
        .with_context(|| format!("{name}: cannot resume from it (delete it to start over)"))?;
    if state.inputs != inputs.hash || state.shard != shard {
        bail!(
            "{name}: saved from other inputs (inputs {}, shard {}; this run has inputs {}, shard \
             {shard}): the map, its portal file or --level changed; delete it to start over",
            state.inputs,
            state.shard,
            inputs.hash
        );
    }
    let mut known: KnownFlows = vec![None; state.portals];
    let count = state.results.len();
    for (p, set) in state.results {
        known[p] = Some(set);
    }
    eprintln!(
        "resuming from {name}: {count} of {} portal flows done",
        state.portals
    );
    Ok(known)
}

/// Write the state atomically; a failure only warns, the run goes on.
fn save_state(inputs: &Inputs, shard: Shard, path: &Path, results: Vec<(usize, &BitSet)>) {
    let state = SavedFlows {
        kind: SavedKind::State,
        inputs: inputs.hash,
        shard,
        portals: results.first().map_or(0, |(_, s)| s.len()),
        results: results.into_iter().map(|(p, s)| (p, s.clone())).collect(),
    };
    if let Err(e) = write_atomic(path, &state.write()) {
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
        .unwrap_or_else(|| partial_path(&args.bsp, shard));
    let mut state_name = out.clone().into_os_string();
    state_name.push(".state");
    let state_path = PathBuf::from(state_name);
    let known = resume_state(args, inputs, shard, &state_path)?;
    let save = |results: Vec<(usize, &BitSet)>| save_state(inputs, shard, &state_path, results);
    let checkpoint = checkpoint(args, &save);
    let flows = crate::compute_shard(
        &inputs.prt,
        args.level,
        args.threads,
        crate::Grouping::Auto,
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
        find_partials(&args.bsp)?
    } else {
        args.partial.clone()
    };
    if paths.is_empty() {
        bail!(
            "no partial files {} beside {}: run `vis --shard K/N` for every shard first",
            saved_path(&args.bsp, "vis.K-of-N").display(),
            args.bsp.display()
        );
    }
    let mut partials: Vec<(PathBuf, SavedFlows)> = Vec::new();
    for path in paths {
        let partial = SavedFlows::read(&read_file(&path)?, SavedKind::Partial)
            .with_context(|| format!("{}", path.display()))?;
        if partial.inputs != inputs.hash {
            bail!(
                "{}: computed from other inputs (inputs {}; {} with --level {} has {}): the \
                 partial belongs to another map, portal file or level",
                path.display(),
                partial.inputs,
                args.bsp.display(),
                args.level,
                inputs.hash
            );
        }
        partials.push((path, partial));
    }
    check_shards(&partials)?;
    let portals = partials[0].1.portals;
    let mut flows: Vec<Option<BitSet>> = vec![None; portals];
    for (path, partial) in partials {
        for (p, set) in partial.results {
            if flows[p].replace(set).is_some() {
                bail!("{}: portal {p} is in two partials", path.display());
            }
        }
    }
    let flows: Vec<BitSet> = flows
        .into_iter()
        .enumerate()
        .map(|(p, f)| f.with_context(|| format!("no partial holds portal {p}")))
        .collect::<Result<_>>()?;
    crate::vis_from_flows(&inputs.prt, &flows)
        .with_context(|| format!("{}", inputs.prt_path.display()))
}

/// Every shard of one count exactly once.
fn check_shards(partials: &[(PathBuf, SavedFlows)]) -> Result<()> {
    let (first_path, first) = &partials[0];
    let count = first.shard.count;
    let mut by_shard: Vec<Option<&Path>> = vec![None; count];
    for (path, partial) in partials {
        let shard = partial.shard;
        if shard.count != count {
            bail!(
                "{} is shard {shard} but {} is shard {}: the partials come from runs with \
                 different shard counts",
                path.display(),
                first_path.display(),
                first.shard
            );
        }
        if let Some(other) = by_shard[shard.index].replace(path) {
            bail!(
                "shard {shard} given twice: {} and {}",
                other.display(),
                path.display()
            );
        }
    }
    let missing: Vec<String> = (0..count)
        .filter(|&i| by_shard[i].is_none())
        .map(|index| Shard { index, count }.to_string())
        .collect();
    if !missing.is_empty() {
        let found: Vec<String> = partials
            .iter()
            .map(|(p, _)| p.display().to_string())
            .collect();
        bail!(
            "missing the partial of shard {}; found only {}",
            missing.join(", "),
            found.join(", ")
        );
    }
    Ok(())
}

/// Every `MAP.vis.K-of-N` beside the BSP, sorted by name.
fn find_partials(bsp: &Path) -> Result<Vec<PathBuf>> {
    let dir = match bsp.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let stem = bsp
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!("{stem}.vis.");
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
        let path = entry?.path();
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let is_partial = name
            .as_deref()
            .and_then(|n| n.strip_prefix(&prefix))
            .and_then(|rest| rest.split_once("-of-"))
            .is_some_and(|(k, n)| digits(k) && digits(n));
        if is_partial {
            found.push(path);
        }
    }
    found.sort();
    Ok(found)
}

/// Write the sets into the BSP and report.
fn finish(args: &Args, inputs: Inputs, result: crate::VisResult, total: Instant) -> Result<()> {
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
    let lump = crate::write_vis(&mut bsp, &result.pvs).with_context(|| format!("{bsp_name}"))?;
    let hearing = crate::ambient::ambient_levels(&mut bsp, &result.pvs)?;
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
    if let Some(path) = &args.stats {
        let json = serde_json::json!({
            "mode": if args.fast { "fast" } else { "full" },
            "level": args.level,
            "compute": c,
            "lump": lump,
            "ambient_leafs": hearing,
            "write_seconds": write_seconds,
            "total_seconds": total.elapsed().as_secs_f64(),
            "sampling": sampling,
        });
        write_atomic(path, serde_json::to_string_pretty(&json)?.as_bytes())?;
    }
    Ok(())
}
