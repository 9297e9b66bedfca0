//! `slipgate report`: for each map and each stage at each quality setting, how long the stage
//! takes (the release `slipgate` binary run as a child process: wall and CPU time, peak memory,
//! best of N) and how far its answer is from the stage's slow exact reference. With an anchor
//! (ericw-tools' `qbsp`, `vis`, `light`), the same maps go through it with matching settings in
//! the same run, interleaved with ours, and are measured against our references the same way.
//!
//! Output: `report.md` (one table per stage), `report.json` (every figure), a time-against-error
//! plot per stage as SVG and PNG, and a self-contained `report.html`.
//!
//! [`independent`] measures both tools' light against a reference computed outside Slipgate.

#![warn(missing_docs)]

mod html;
pub mod independent;
mod machine;
mod markdown;
mod measure;
mod plot;
mod process;
mod run;
mod settings;

use std::path::PathBuf;

pub use machine::Machine;
pub use measure::{BspFigures, GridCost, LightFigures, ViewFigures, VisFigures};
pub use process::Timing;
pub use run::run;
pub use settings::{LightMeasure, Stage, Tool};

/// What to measure and where to write it.
#[derive(Debug, Clone)]
pub struct Options {
    /// The `.map` files to compile and measure.
    pub maps: Vec<PathBuf>,
    /// Where the report, its plots and the maps' work folders go.
    pub out_dir: PathBuf,
    /// Each timed step runs this many times; the best wall time counts.
    pub runs: usize,
    /// ericw-tools' `bin` folder (`qbsp`, `vis`, `light`), measured beside ours.
    pub anchor: Option<PathBuf>,
    /// The `slipgate` binary whose stages are timed.
    pub slipgate: PathBuf,
    /// Folders searched for the WADs maps name (passed to both compilers).
    pub wad_dirs: Vec<PathBuf>,
    /// About how many faces light's reference lights per map (every Nth face).
    pub reference_faces: usize,
    /// Player-box moves traced per BSP to check its clip hull against the map's brushes.
    pub hull_traces: usize,
    /// Sight lines sampled per map to check each PVS.
    pub sample_pairs: usize,
    /// Frames of the viewer's flythrough per span step.
    pub view_frames: usize,
    /// Viewer picture size.
    pub view_size: (usize, usize),
    /// Whether the timed binary is a release build (said in the header).
    pub release: bool,
    /// Draw a progress bar on stderr (only when it is a terminal).
    pub progress: bool,
}

/// Everything one report measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Report {
    /// The machine it ran on.
    pub machine: Machine,
    /// Runs of every timed step; the best counts.
    pub runs: usize,
    /// Whether the timed binary was a release build.
    pub release: bool,
    /// ericw-tools' `bin` folder, when it was measured beside ours.
    pub anchor: Option<PathBuf>,
    /// The maps measured.
    pub maps: Vec<PathBuf>,
    /// Per map: every Nth face lit by light's references, and how long each reference took.
    pub light_references: Vec<LightReference>,
    /// Every stage at every setting on every map, by each tool.
    pub rows: Vec<Row>,
}

/// How light's reference was taken on one map.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LightReference {
    /// The map's name: its file name without extension (numbered when two maps share one).
    pub map: String,
    /// The reference lit every Nth face; this is N.
    pub face_stride: usize,
    /// Faces the reference lit.
    pub faces: usize,
    /// Each reference the settings asked for, and its seconds.
    pub references: Vec<ReferenceSeconds>,
}

/// How long one of light's references took on one map.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ReferenceSeconds {
    /// What the reference computed, as the settings measured against it measure it.
    pub measure: LightMeasure,
    /// Seconds it took.
    pub seconds: f64,
}

/// One stage at one setting on one map by one tool.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// The map's name, as in [`LightReference::map`].
    pub map: String,
    /// The stage measured.
    pub stage: Stage,
    /// The setting's name: Slipgate's options as a mapper writes them (`--extra4 --soft`), or
    /// `default`, `fast`, `full`, `span step N`.
    pub setting: String,
    /// Whose implementation ran.
    pub tool: Tool,
    /// Best of the runs (by wall time); `None` when every run failed.
    pub timing: Option<Timing>,
    /// The answer measured against its reference; `None` when the step or measuring failed.
    pub figures: Option<Figures>,
    /// Why the step or its measurement failed.
    pub failure: Option<String>,
}

/// A stage's answer measured against its reference.
#[derive(Debug, Clone, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Figures {
    /// A compiled BSP's counts, cracks and clip hull agreement.
    Bsp(BspFigures),
    /// A PVS against sampled sight lines.
    Vis(VisFigures),
    /// Lightmaps against light's reference.
    Light(LightFigures),
    /// The viewer's frame rate and its picture against the exact renderer.
    View(ViewFigures),
}

impl Row {
    /// The time a plot shows: whole-process wall seconds, or milliseconds per frame for the viewer.
    pub fn plot_time(&self) -> Option<f64> {
        match &self.figures {
            Some(Figures::View(v)) => (v.fps > 0.0).then(|| 1000.0 / v.fps),
            _ => self.timing.map(|t| t.wall_seconds),
        }
    }

    /// The error a plot shows (see [`Stage::error_name`]).
    pub fn plot_error(&self) -> Option<f64> {
        Some(match self.figures.as_ref()? {
            Figures::Bsp(b) => (b.cracks() + b.hull_disagreements) as f64,
            Figures::Vis(v) => v.pvs_over_sampled,
            Figures::Light(l) => l.rmse,
            Figures::View(v) => v.mean_diff,
        })
    }
}

/// Everything that stops a report; every message names the file or command.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// Reading or writing a file or folder failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What the OS reported.
        source: std::io::Error,
    },
    /// A BSP or portal file could not be read.
    #[error("{}: {source}", path.display())]
    Format {
        /// The BSP or portal file.
        path: PathBuf,
        /// What was wrong with it.
        source: quake_formats::FormatError,
    },
    /// A timed step exited with an error or was killed.
    #[error("`{command}` {status}; last lines of {}:\n{tail}", log.display())]
    CommandFailed {
        /// The command line as run.
        command: String,
        /// How it ended (`exited with status 1`, `was killed by signal 9`).
        status: String,
        /// The file its output went to.
        log: PathBuf,
        /// The log's last lines.
        tail: String,
    },
    /// Measuring a PVS failed in vis' library.
    #[error("{}: {source}", path.display())]
    Vis {
        /// The BSP measured.
        path: PathBuf,
        /// vis' error.
        source: vis::VisError,
    },
    /// Light's reference could not be computed.
    #[error("{}: {source}", path.display())]
    Light {
        /// The BSP lit.
        path: PathBuf,
        /// light's error.
        source: light::LightError,
    },
    /// A measurement could not be made (the hull check, a statistics file, the JSON report).
    #[error("{}: {what}", path.display())]
    Measure {
        /// The file measured or written.
        path: PathBuf,
        /// What went wrong.
        what: String,
    },
    /// A plot could not be drawn.
    #[error("drawing {}: {what}", path.display())]
    Plot {
        /// The picture being drawn.
        path: PathBuf,
        /// What went wrong.
        what: String,
    },
    /// [`Options::maps`] is empty.
    #[error("no maps to report on")]
    NoMaps,
}

impl ReportError {
    fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> ReportError {
        let path = path.into();
        move |source| ReportError::Io { path, source }
    }
}
