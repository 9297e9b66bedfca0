//! Slipgate batch: many maps through bsp, vis, light and a preview in one run, each stage cached
//! by the content of its inputs, maps side by side within a memory budget, and the work dealt
//! out to shards whose manifests are joined and checked afterwards. `docs/batch.md` is the
//! user's guide.
//!
//! Modules: `project` (the project file, or a folder of maps), `stages` (one map through the
//! stages, and what each stage's cache key holds), `cache` (blobs and stage records),
//! `schedule` (the memory budget), `manifest` (shards, manifests, `--collect`), `options`
//! (option strings to stage arguments), `summary` (the table) and [`cli`], the one public
//! module: the command line `slipgate batch` mounts.

#![warn(missing_docs)]

mod cache;
pub mod cli;
mod hash;
mod manifest;
mod options;
mod project;
mod schedule;
mod stages;
mod summary;
mod walk;

pub use options::command_words;

use cache::Cache;
use manifest::{Manifest, ManifestError, Shard};
use project::{MapJob, Project, ProjectError};
use stages::{Context, MapOutcome};
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub(crate) enum BatchError {
    #[error(transparent)]
    Project(#[from] ProjectError),
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// How to run a batch.
#[derive(Debug, Clone)]
pub(crate) struct BatchOptions {
    /// A project file, or a folder whose `.map` files are built with the defaults.
    pub project: PathBuf,
    /// Maps in flight at once.
    pub jobs: usize,
    /// Bytes the maps in flight may take together (by [`schedule::estimate_memory`]).
    pub memory_budget: u64,
    /// Run every stage whatever the cache holds.
    pub force: bool,
    pub shard: Option<Shard>,
    /// Where outputs and the manifest go instead of the project's output folder.
    pub output: Option<PathBuf>,
    /// Where the cache is instead of the project's.
    pub cache: Option<PathBuf>,
}

/// Told as maps start, change stage and finish.
pub(crate) trait Observer: Sync {
    fn map_started(&self, map: &str);
    fn stage_started(&self, map: &str, stage: &str);
    fn map_finished(&self, outcome: &MapOutcome);
}

/// What a batch did.
#[derive(Debug)]
pub(crate) struct BatchReport {
    pub manifest: Manifest,
    pub manifest_path: PathBuf,
}

impl BatchReport {
    pub fn failures(&self) -> impl Iterator<Item = &MapOutcome> {
        self.manifest.built.iter().filter(|m| m.failure.is_some())
    }
}

/// Who made the outputs: the version and the hash of the running program, so a rebuilt tool
/// never takes a stale stage from the cache.
fn tool_identity() -> Result<String, BatchError> {
    let exe = std::env::current_exe().map_err(|source| BatchError::Io {
        path: PathBuf::from("(the running program)"),
        source,
    })?;
    let bytes = std::fs::read(&exe).map_err(|source| BatchError::Io {
        path: exe.clone(),
        source,
    })?;
    Ok(format!(
        "slipgate {} {}",
        env!("CARGO_PKG_VERSION"),
        hash::hash_bytes(&bytes)
    ))
}

/// Build the project's maps (this shard's share of them).
pub(crate) fn run_batch(
    options: &BatchOptions,
    observer: &dyn Observer,
) -> Result<BatchReport, BatchError> {
    let mut project = Project::load(&options.project)?;
    if let Some(dir) = &options.output {
        project.output_dir = dir.clone();
    }
    if let Some(dir) = &options.cache {
        project.cache_dir = dir.clone();
    }
    let project_maps: Vec<String> = project.maps.iter().map(|m| m.name.clone()).collect();
    let mine: Vec<(u64, &MapJob)> = project
        .maps
        .iter()
        .enumerate()
        .filter(|(i, _)| options.shard.is_none_or(|s| s.takes(*i)))
        .map(|(_, job)| (schedule::estimate_memory(file_size(&job.path)), job))
        .collect();
    let tool = tool_identity()?;
    let cache = Cache::new(&project.cache_dir);
    let built = schedule::run_within_budget(&mine, options.jobs, options.memory_budget, |job| {
        observer.map_started(&job.name);
        let on_stage = |stage: &str| observer.stage_started(&job.name, stage);
        let ctx = Context {
            cache: &cache,
            tool: &tool,
            force: options.force,
            project_root: &project.root,
            output_dir: &project.output_dir,
            on_stage: &on_stage,
        };
        let outcome = stages::build_map(&ctx, job);
        observer.map_finished(&outcome);
        outcome
    });
    let manifest = Manifest {
        version: env!("CARGO_PKG_VERSION").into(),
        shard: options.shard,
        project_maps,
        built,
    };
    std::fs::create_dir_all(&project.output_dir).map_err(|source| BatchError::Io {
        path: project.output_dir.clone(),
        source,
    })?;
    let manifest_path = project.output_dir.join(Shard::manifest_name(options.shard));
    manifest.write(&manifest_path)?;
    Ok(BatchReport {
        manifest,
        manifest_path,
    })
}

/// A missing file estimates as empty: reading it fails later, naming it.
fn file_size(path: &Path) -> u64 {
    std::fs::metadata(path).map_or(0, |m| m.len())
}
