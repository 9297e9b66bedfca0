//! Full vis split across runs: a saved state a killed run resumes from, and the partial results
//! of shards (run on this or other machines) joined into the sets of one whole run.
//!
//! Both are [`SavedFlows`] files tied by an [`InputsHash`] to the map, portal file and level they
//! were computed from; results of other inputs would give a wrong PVS, so they are refused. The
//! files sit beside the BSP: `MAP.vis.state` for a whole run, `MAP.vis.K-of-N` for shard K of N
//! (and its own state, `MAP.vis.K-of-N.state`).

use crate::bitset::BitSet;
use crate::saved::{InputsHash, SavedError, SavedFlows, SavedKind};
use crate::schedule::Shard;
use crate::{KnownFlows, VisError, VisResult, vis_from_flows};
use quake_formats::prt::PortalFile;
use std::path::{Path, PathBuf};

/// Why saved flows cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ShardError {
    /// A file is not a usable flow file of the kind wanted.
    #[error("{}: {source}", path.display())]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        #[source]
        source: SavedError,
    },
    /// A saved state belongs to other inputs or another shard.
    #[error(
        "{}: saved from other inputs (inputs {found}, shard {found_shard}; this run has inputs \
         {inputs}, shard {shard}): the map, its portal file or the level changed; delete it to \
         start over",
        path.display()
    )]
    OtherState {
        /// The state file.
        path: PathBuf,
        /// The inputs it was saved from.
        found: InputsHash,
        /// The shard that saved it.
        found_shard: Shard,
        /// This run's inputs.
        inputs: InputsHash,
        /// This run's shard.
        shard: Shard,
    },
    /// A partial belongs to other inputs.
    #[error(
        "{}: computed from other inputs (inputs {found}; this run has {inputs}): the partial \
         belongs to another map, portal file or level",
        path.display()
    )]
    OtherPartial {
        /// The partial file.
        path: PathBuf,
        /// The inputs it was computed from.
        found: InputsHash,
        /// This run's inputs.
        inputs: InputsHash,
    },
    /// A merge was given no partial files.
    #[error("no partial files: run `vis --shard K/N` for every shard first")]
    NoPartials,
    /// Two partials come from runs with different shard counts.
    #[error(
        "{} is shard {shard} but {} is shard {first_shard}: the partials come from runs with \
         different shard counts",
        path.display(),
        first.display()
    )]
    ShardCounts {
        /// The partial that disagrees with the first.
        path: PathBuf,
        /// Its shard.
        shard: Shard,
        /// The first partial.
        first: PathBuf,
        /// The first partial's shard.
        first_shard: Shard,
    },
    /// Two partials are of the same shard.
    #[error("shard {shard} given twice: {} and {}", first.display(), second.display())]
    ShardTwice {
        /// The shard.
        shard: Shard,
        /// The partial read first.
        first: PathBuf,
        /// The partial read second.
        second: PathBuf,
    },
    /// Some shards have no partial.
    #[error("missing the partial of shard {missing}; found only {found}")]
    MissingShards {
        /// The shards missing, as `K/N`, comma-separated.
        missing: String,
        /// The partial files given, comma-separated.
        found: String,
    },
    /// Two partials hold a result for the same portal.
    #[error("{}: portal {portal} is in two partials", path.display())]
    PortalTwice {
        /// The partial read second.
        path: PathBuf,
        /// The one-way portal.
        portal: usize,
    },
    /// No partial holds a result for a portal; holds the one-way portal.
    #[error("no partial holds portal {0}")]
    PortalMissing(usize),
    /// Joining the results failed.
    #[error(transparent)]
    Vis(#[from] VisError),
}

/// Where a whole run saves its state: `MAP.vis.state`.
pub fn state_path(bsp: &Path) -> PathBuf {
    bsp.with_extension("vis.state")
}

/// Where shard `shard`'s partial goes by default: `MAP.vis.K-of-N`.
pub fn partial_path(bsp: &Path, shard: Shard) -> PathBuf {
    bsp.with_extension(format!("vis.{}-of-{}", shard.index + 1, shard.count))
}

/// Where a shard writing its partial to `partial` saves its state: the partial's name plus
/// `.state`.
pub fn shard_state_path(partial: &Path) -> PathBuf {
    let mut name = partial.as_os_str().to_owned();
    name.push(".state");
    PathBuf::from(name)
}

/// The flow results a saved state (`bytes`, read from `path`) holds for a run of `inputs` and
/// `shard`; a state of other inputs or another shard is refused.
pub fn resume_from(
    path: &Path,
    bytes: &[u8],
    inputs: InputsHash,
    shard: Shard,
) -> Result<KnownFlows, ShardError> {
    let state =
        SavedFlows::read(bytes, SavedKind::State).map_err(|source| ShardError::Unreadable {
            path: path.to_path_buf(),
            source,
        })?;
    if state.inputs != inputs || state.shard != shard {
        return Err(ShardError::OtherState {
            path: path.to_path_buf(),
            found: state.inputs,
            found_shard: state.shard,
            inputs,
            shard,
        });
    }
    let mut known: KnownFlows = vec![None; state.portals];
    for (p, set) in state.results {
        known[p] = Some(set);
    }
    Ok(known)
}

/// The bytes of a saved state holding `results` (every result finished so far, by portal).
pub fn state_bytes(inputs: InputsHash, shard: Shard, results: Vec<(usize, &BitSet)>) -> Vec<u8> {
    SavedFlows {
        kind: SavedKind::State,
        inputs,
        shard,
        portals: results.first().map_or(0, |(_, s)| s.len()),
        results: results.into_iter().map(|(p, s)| (p, s.clone())).collect(),
    }
    .write()
}

/// Join the partial files of every shard (`(path, bytes)`, each read from its path) into the
/// sets of one whole run of `prt` with `inputs`.
pub fn merge_partials(
    prt: &PortalFile,
    files: Vec<(PathBuf, Vec<u8>)>,
    inputs: InputsHash,
) -> Result<VisResult, ShardError> {
    if files.is_empty() {
        return Err(ShardError::NoPartials);
    }
    let mut partials = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        let partial = SavedFlows::read(&bytes, SavedKind::Partial).map_err(|source| {
            ShardError::Unreadable {
                path: path.clone(),
                source,
            }
        })?;
        if partial.inputs != inputs {
            return Err(ShardError::OtherPartial {
                path,
                found: partial.inputs,
                inputs,
            });
        }
        partials.push((path, partial));
    }
    check_shards(&partials)?;
    let portals = partials[0].1.portals;
    let mut flows: Vec<Option<BitSet>> = vec![None; portals];
    for (path, partial) in partials {
        for (portal, set) in partial.results {
            if flows[portal].replace(set).is_some() {
                return Err(ShardError::PortalTwice { path, portal });
            }
        }
    }
    let flows: Vec<BitSet> = flows
        .into_iter()
        .enumerate()
        .map(|(p, f)| f.ok_or(ShardError::PortalMissing(p)))
        .collect::<Result<_, _>>()?;
    Ok(vis_from_flows(prt, &flows)?)
}

/// Every shard of one count exactly once.
fn check_shards(partials: &[(PathBuf, SavedFlows)]) -> Result<(), ShardError> {
    let (first_path, first) = &partials[0];
    let count = first.shard.count;
    let mut by_shard: Vec<Option<&Path>> = vec![None; count];
    for (path, partial) in partials {
        let shard = partial.shard;
        if shard.count != count {
            return Err(ShardError::ShardCounts {
                path: path.clone(),
                shard,
                first: first_path.clone(),
                first_shard: first.shard,
            });
        }
        if let Some(other) = by_shard[shard.index].replace(path) {
            return Err(ShardError::ShardTwice {
                shard,
                first: other.to_path_buf(),
                second: path.clone(),
            });
        }
    }
    let missing: Vec<String> = (0..count)
        .filter(|&i| by_shard[i].is_none())
        .map(|index| Shard { index, count }.to_string())
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    let found: Vec<String> = partials
        .iter()
        .map(|(p, _)| p.display().to_string())
        .collect();
    Err(ShardError::MissingShards {
        missing: missing.join(", "),
        found: found.join(", "),
    })
}

/// Every `MAP.vis.K-of-N` beside the BSP, sorted by name.
pub fn find_partials(bsp: &Path) -> std::io::Result<Vec<PathBuf>> {
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
    for entry in std::fs::read_dir(dir)? {
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
