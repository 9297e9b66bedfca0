//! `slipgate batch [PROJECT] [--jobs N] [--memory-budget SIZE] [--force] [--shard K/N]`, and
//! `slipgate batch --collect DIR...`.

use crate::manifest::{Shard, collect};
use crate::schedule::{default_memory_budget, parse_memory};
use crate::stages::{MapOutcome, STAGES};
use crate::{BatchOptions, Observer, run_batch};
use anyhow::Result;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::Duration;

/// The batch command line, as `slipgate batch` mounts it.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// A project file (TOML), or a folder whose .map files are all built with the default
    /// options (default: the current folder)
    #[arg(conflicts_with = "collect")]
    pub project: Option<PathBuf>,
    /// Maps built at once (default: one per core)
    #[arg(long, short = 'j')]
    pub jobs: Option<usize>,
    /// Memory the maps in flight may take together, e.g. 4G or 512M (default: what the system
    /// has available); each map's need is estimated from the size of its .map
    #[arg(long, value_parser = parse_memory)]
    pub memory_budget: Option<u64>,
    /// Run every stage again, whatever the cache holds
    #[arg(long)]
    pub force: bool,
    /// Build only share K of N (1 <= K <= N): the project's maps dealt round robin in name order
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
    /// Write outputs and the manifest here instead of the project's output folder
    #[arg(long, value_name = "DIR")]
    pub output: Option<PathBuf>,
    /// The cache folder (default: .slipgate-cache beside the project file)
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
    /// Instead of building: join the manifests under these folders and check that every map was
    /// built exactly once and every output matches its hash
    #[arg(long, value_name = "DIR", num_args = 1..)]
    pub collect: Vec<PathBuf>,
}

/// Build the project's maps, or with `--collect` join the manifests; exit code 1 when a map
/// failed or the manifests have problems.
pub fn run(args: &Args) -> Result<ExitCode> {
    if !args.collect.is_empty() {
        return run_collect(args);
    }
    let options = BatchOptions {
        project: args.project.clone().unwrap_or_else(|| PathBuf::from(".")),
        jobs: args.jobs.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
        }),
        memory_budget: args.memory_budget.unwrap_or_else(default_memory_budget),
        force: args.force,
        shard: args.shard,
        output: args.output.clone(),
        cache: args.cache.clone(),
    };
    let bars = Bars::new();
    let report = run_batch(&options, &bars)?;
    bars.multi.clear().ok();
    print!("{}", crate::summary::table(&report.manifest.built));
    println!("manifest: {}", report.manifest_path.display());
    let failures: Vec<&MapOutcome> = report.failures().collect();
    for map in &failures {
        if let Some(failure) = &map.failure {
            eprintln!("error: {} failed at {failure}", map.map);
        }
    }
    Ok(if failures.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn run_collect(args: &Args) -> Result<ExitCode> {
    let collected = collect(&args.collect)?;
    println!(
        "{} manifests, {} maps built",
        collected.manifests.len(),
        collected.maps.len()
    );
    for problem in &collected.problems {
        eprintln!("error: {problem}");
    }
    if collected.problems.is_empty() {
        println!("every map built exactly once; every output matches its hash");
        Ok(ExitCode::SUCCESS)
    } else {
        Ok(ExitCode::from(1))
    }
}

/// A bar per map on a terminal (stages done, the one running); elsewhere (CI logs) a line as each map finishes.
struct Bars {
    multi: MultiProgress,
    terminal: bool,
    bars: Mutex<HashMap<String, ProgressBar>>,
}

impl Bars {
    fn new() -> Bars {
        Bars {
            multi: MultiProgress::with_draw_target(ProgressDrawTarget::stderr()),
            terminal: std::io::stderr().is_terminal(),
            bars: Mutex::new(HashMap::new()),
        }
    }

    fn with_bar(&self, map: &str, f: impl FnOnce(&ProgressBar)) {
        if let Ok(bars) = self.bars.lock()
            && let Some(bar) = bars.get(map)
        {
            f(bar);
        }
    }
}

impl Observer for Bars {
    fn map_started(&self, map: &str) {
        if !self.terminal {
            return;
        }
        let bar = self.multi.add(ProgressBar::new(STAGES.len() as u64));
        if let Ok(style) =
            ProgressStyle::with_template("{spinner} {prefix:30} [{bar:5}] {msg:10} {elapsed}")
        {
            bar.set_style(style);
        }
        bar.set_prefix(map.to_string());
        bar.set_message("cache");
        bar.enable_steady_tick(Duration::from_millis(200));
        if let Ok(mut bars) = self.bars.lock() {
            bars.insert(map.to_string(), bar);
        }
    }

    fn stage_started(&self, map: &str, stage: &str) {
        let done = STAGES.iter().position(|s| *s == stage).unwrap_or(0);
        self.with_bar(map, |bar| {
            bar.set_position(done as u64);
            bar.set_message(stage.to_string());
        });
    }

    fn map_finished(&self, outcome: &MapOutcome) {
        let result = match &outcome.failure {
            Some(failure) => format!("FAILED at {failure}"),
            None => {
                let ran = outcome.stages.iter().filter(|s| !s.cached).count();
                format!("ok ({ran} of {} stages ran)", outcome.stages.len())
            }
        };
        if self.terminal {
            self.with_bar(&outcome.map, |bar| bar.finish_with_message(result));
        } else {
            eprintln!("batch: {}: {result}", outcome.map);
        }
    }
}
