//! `report`: speed against error for every stage (the `report` crate does the work).

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
pub struct ReportArgs {
    /// Maps to measure (default: the project's maps, and corpus maps when ../shared/corpus is
    /// present; run from the project's root)
    maps: Vec<PathBuf>,
    /// Where report.md, report.json, report.html and the plots go
    #[arg(long, default_value = "report")]
    out_dir: PathBuf,
    /// Runs of every timed step; the best counts
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    runs: u32,
    /// ericw-tools' bin folder (qbsp, vis, light): run the same steps with it, interleaved
    #[arg(long, value_name = "DIR")]
    anchor: Option<PathBuf>,
    /// Extra folders to search for the WADs the maps name
    #[arg(long = "wad-dir", value_name = "DIR")]
    wad_dirs: Vec<PathBuf>,
    /// About how many faces per map light's reference lights (every Nth face)
    #[arg(long, default_value_t = 96)]
    reference_faces: usize,
    /// Sight lines sampled per map to check each PVS
    #[arg(long, default_value_t = 200_000)]
    sample_pairs: usize,
    /// Player-box moves traced per BSP to check its clip hull against the map's brushes
    #[arg(long, default_value_t = 2000)]
    hull_traces: usize,
    /// Frames of the viewer's flythrough per span step
    #[arg(long, default_value_t = 120)]
    view_frames: usize,
    /// Print report.json to stdout when done
    #[arg(long)]
    stats: bool,
    /// Light only, both tools against an independent reference (Python 3 with Mitsuba 3 and
    /// numpy): benchmark forms of the maps, compiled by the anchor (default
    /// ../shared/anchors/ericw-tools/bin), lit by both tools at default and -extra4 -soft
    #[arg(long)]
    independent: bool,
    /// With --independent: the folder holding benchmark_map.py and reference.py
    #[arg(long, value_name = "DIR", default_value = "bench/independent")]
    scripts: PathBuf,
    /// With --independent: the Python 3 interpreter that runs them
    #[arg(long, value_name = "PYTHON", default_value = "python3")]
    python: PathBuf,
}

const PROJECT_MAPS: [&str; 2] = ["maps/demo.map", "maps/test/corridors.map"];
const CORPUS: &str = "../shared/corpus";
const CORPUS_MAPS: [&str; 2] = ["public/maps/id/e1m1.map", "public/maps/librequake/e3m4.map"];
const CORPUS_WADS: &str = "wads/librequake";
/// The corpus maps `--independent` measures by default.
const INDEPENDENT_MAPS: [&str; 3] = [
    "public/maps/id/e1m1.map",
    "public/maps/librequake/start.map",
    "public/maps/librequake/e1m3.map",
];
/// ericw-tools beside the project, where `--independent` looks when no --anchor is given.
const SHARED_ANCHOR: &str = "../shared/anchors/ericw-tools/bin";

/// The project's maps, and the corpus maps when the corpus is beside the project.
fn default_maps() -> Vec<PathBuf> {
    let corpus = Path::new(CORPUS);
    PROJECT_MAPS
        .iter()
        .map(PathBuf::from)
        .chain(CORPUS_MAPS.iter().map(|m| corpus.join(m)))
        .filter(|p| p.is_file())
        .collect()
}

pub fn report(args: &ReportArgs) -> Result<()> {
    if args.independent {
        return independent(args);
    }
    let maps = if args.maps.is_empty() {
        default_maps()
    } else {
        args.maps.clone()
    };
    anyhow::ensure!(
        !maps.is_empty(),
        "no maps given, and none of {} found here (run from the project's root)",
        PROJECT_MAPS.join(", ")
    );
    let wad_dirs = wad_dirs(args);
    let options = report::Options {
        maps,
        out_dir: args.out_dir.clone(),
        runs: args.runs as usize,
        anchor: args.anchor.clone(),
        slipgate: std::env::current_exe().context("finding the slipgate binary to time")?,
        wad_dirs,
        reference_faces: args.reference_faces,
        sample_pairs: args.sample_pairs,
        hull_traces: args.hull_traces,
        view_frames: args.view_frames,
        view_size: (320, 240),
        release: !cfg!(debug_assertions),
        progress: true,
    };
    let result = report::run(&options)?;
    let failed = result.rows.iter().filter(|r| r.failure.is_some()).count();
    eprintln!(
        "report: {} rows ({failed} failed) in {}",
        result.rows.len(),
        args.out_dir.join("report.md").display()
    );
    if args.stats {
        println!("{}", serde_json::to_string_pretty(&result)?);
    }
    Ok(())
}

/// The WAD folders given, and the corpus' when it is beside the project.
fn wad_dirs(args: &ReportArgs) -> Vec<PathBuf> {
    let mut wad_dirs = args.wad_dirs.clone();
    let corpus_wads = Path::new(CORPUS).join(CORPUS_WADS);
    if corpus_wads.is_dir() && !wad_dirs.contains(&corpus_wads) {
        wad_dirs.push(corpus_wads);
    }
    wad_dirs
}

/// `report --independent`: both tools' light against the independent reference.
fn independent(args: &ReportArgs) -> Result<()> {
    let maps = if args.maps.is_empty() {
        let corpus = Path::new(CORPUS);
        INDEPENDENT_MAPS
            .iter()
            .map(|m| corpus.join(m))
            .filter(|p| p.is_file())
            .collect()
    } else {
        args.maps.clone()
    };
    anyhow::ensure!(
        !maps.is_empty(),
        "no maps given, and none of the corpus maps ({}) found under {CORPUS}",
        INDEPENDENT_MAPS.join(", ")
    );
    let anchor = match &args.anchor {
        Some(a) => a.clone(),
        None if Path::new(SHARED_ANCHOR).join("light").is_file() => PathBuf::from(SHARED_ANCHOR),
        None => anyhow::bail!(
            "--independent measures ericw-tools' light beside ours: give its bin folder with \
             --anchor DIR (none at {SHARED_ANCHOR})"
        ),
    };
    let options = report::independent::IndependentOptions {
        maps,
        out_dir: args.out_dir.clone(),
        runs: args.runs as usize,
        anchor,
        slipgate: std::env::current_exe().context("finding the slipgate binary to time")?,
        wad_dirs: wad_dirs(args),
        scripts: args.scripts.clone(),
        python: args.python.clone(),
        release: !cfg!(debug_assertions),
        progress: true,
    };
    let result = report::independent::run(&options)?;
    let failed = result.rows.iter().filter(|r| r.failure.is_some()).count();
    eprintln!(
        "report: {} rows ({failed} failed) in {}",
        result.rows.len(),
        args.out_dir.join("independent.md").display()
    );
    if args.stats {
        println!("{}", serde_json::to_string_pretty(&result)?);
    }
    Ok(())
}
