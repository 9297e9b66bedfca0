//! What one lighting run is asked to do.

use quake_formats::palette::Palette;
use quake_formats::progress::Progress;

use crate::bounce::Density;
use crate::quality::Quality;
use crate::settings::Overrides;

/// Options of one lighting run.
#[derive(Debug, Clone)]
pub struct Options {
    /// How much work to spend per luxel.
    pub quality: Quality,
    /// The settings given to the run; each wins over worldspawn's key.
    pub overrides: Overrides,
    /// Light only these faces (others keep no lightmap); for measurements.
    pub only_faces: Option<Vec<usize>>,
    /// Consider every light for every face (no range, plane-side or PVS culling; implied by
    /// [`Quality::Reference`]); for measurements.
    pub no_cull: bool,
    /// Where progress goes (the faces traced), nowhere by default.
    pub progress: Progress,
    /// Colours of texture pixels, for `_bouncecolorscale` (default: Slipgate's own palette).
    pub palette: Option<Palette>,
    /// Where and how densely the fast bounce gathers at `-emissivequality high`, instead of the
    /// quality mode's; for measurements.
    pub bounce_density: Option<Density>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            quality: Quality::Default,
            overrides: Overrides::default(),
            only_faces: None,
            no_cull: false,
            progress: Progress::default(),
            palette: None,
            bounce_density: None,
        }
    }
}
