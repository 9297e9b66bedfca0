//! What `slipgate view --stats FILE.json` writes: one run of the viewer, typed, so that
//! whoever reads the file back (`slipgate report`) reads fields rather than JSON paths.

use std::path::PathBuf;

use crate::flythrough::Flythrough;
use crate::reference::Comparison;
use crate::render::FrameStats;
use crate::world::LoadStats;

/// One run of the viewer: the load, then a picture, a flythrough or a window session.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct ViewSummary {
    /// The BSP drawn.
    pub map: PathBuf,
    /// What the load found.
    pub load: LoadStats,
    /// Seconds to load the map.
    pub load_seconds: f64,
    /// Where the palette came from.
    pub palette: String,
    /// The picture's counts and timings, when one was drawn.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<FrameStats>,
    /// The picture against the reference renderer's, with `--reference`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<Comparison>,
    /// The flythrough benchmark, with `--bench`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bench: Option<Flythrough>,
    /// The interactive session, with `--window`.
    #[cfg(feature = "window")]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<crate::window::WindowSummary>,
}
