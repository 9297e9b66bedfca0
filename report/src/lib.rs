//! `slipgate report`: for each map and each stage at each quality setting, how long the stage
//! takes (the release `slipgate` binary run as a child process: wall and CPU time, peak memory,
//! best of N) and how far its answer is from the stage's slow exact reference. With an anchor
//! (ericw-tools' `qbsp`, `vis`, `light`), the same maps go through it with matching settings in
//! the same run, interleaved with ours, and are measured against our references the same way.
//!
//! Output: `report.md` (one table per stage), `report.json` (every figure), a time-against-error
//! plot per stage as SVG and PNG, and a self-contained `report.html`.

mod html;
mod machine;
mod markdown;
mod measure;
mod plot;
mod process;
mod run;
mod settings;

use std::path::PathBuf;

pub use machine::Machine;
pub use measure::{BspFigures, LightFigures, ViewFigures, VisFigures};
pub use process::Timing;
pub use run::run;
pub use settings::{Stage, Tool};

/// What to measure and where to write it.
#[derive(Debug, Clone)]
pub struct Options {
    pub maps: Vec<PathBuf>,
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
    pub machine: Machine,
    pub runs: usize,
    pub release: bool,
    pub anchor: Option<PathBuf>,
    pub maps: Vec<PathBuf>,
    /// Per map: every Nth face lit by the light reference, and how long the references took.
    pub light_references: Vec<LightReference>,
    pub rows: Vec<Row>,
}

/// How light's reference was taken on one map.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LightReference {
    pub map: String,
    pub face_stride: usize,
    pub faces: usize,
    pub seconds_direct: f64,
    pub seconds_bounce: Option<f64>,
}

/// One stage at one setting on one map by one tool.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    pub map: String,
    pub stage: Stage,
    pub setting: String,
    pub tool: Tool,
    /// Best of the runs (by wall time); `None` when every run failed.
    pub timing: Option<Timing>,
    pub figures: Option<Figures>,
    /// Why the step or its measurement failed.
    pub failure: Option<String>,
}

/// A stage's answer measured against its reference.
#[derive(Debug, Clone, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Figures {
    Bsp(BspFigures),
    Vis(VisFigures),
    Light(LightFigures),
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

#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {source}", path.display())]
    Format {
        path: PathBuf,
        source: quake_formats::FormatError,
    },
    #[error("`{command}` {status}; last lines of {}:\n{tail}", log.display())]
    CommandFailed {
        command: String,
        status: String,
        log: PathBuf,
        tail: String,
    },
    #[error("{}: {source}", path.display())]
    Vis {
        path: PathBuf,
        source: vis::VisError,
    },
    #[error("{}: {source}", path.display())]
    Light {
        path: PathBuf,
        source: light::LightError,
    },
    #[error("{}: {what}", path.display())]
    Measure { path: PathBuf, what: String },
    #[error("drawing {}: {what}", path.display())]
    Plot { path: PathBuf, what: String },
    #[error("no maps to report on")]
    NoMaps,
}

impl ReportError {
    fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> ReportError {
        let path = path.into();
        move |source| ReportError::Io { path, source }
    }
}
