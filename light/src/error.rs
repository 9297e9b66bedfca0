//! What can stop lighting a map.

use crate::embree::EmbreeError;

/// Everything that can stop lighting a map.
#[derive(Debug, thiserror::Error)]
pub enum LightError {
    /// The entity lump does not parse.
    #[error("entity lump: {0}")]
    Entities(#[from] quake_formats::FormatError),
    /// A face whose indices run outside the file.
    #[error("face {index}: {detail}")]
    BadFace {
        /// The face's index.
        index: usize,
        /// What is wrong with it.
        detail: String,
    },
    /// More distinct switchable light names than styles to give them.
    #[error(
        "more switchable lights and shadows (distinct targetnames) than light styles {first} to \
         {last} (worldspawn's _compilerstyle_start and _compilerstyle_max; engines other than \
         DarkPlaces and FTE keep styles below 64)"
    )]
    TooManySwitchableLights {
        /// The first style given out.
        first: usize,
        /// The last style that could be given out.
        last: usize,
    },
    /// Embree failed (starting the device or building the scene).
    #[error(transparent)]
    Embree(#[from] EmbreeError),
    /// A damaged BSPX lump light reads: the compiler's `SLIPGATE_PHONG`, `SLIPGATE_FACEFLAGS` or
    /// `SLIPGATE_SURFGROUP`, or a lit BSP's `DECOUPLED_LM`, `LMSHIFT` or `LMOFFSET` (the message
    /// names it).
    #[error("{0}")]
    BspxLump(quake_formats::FormatError),
    /// `--lightgrid_dist` so fine for the map that the grid would hold too many points.
    #[error(
        "the light grid would hold {points} points (at most {most}): give --lightgrid_dist a wider spacing"
    )]
    LightGridTooFine {
        /// Points the spacing gives.
        points: u64,
        /// The most allowed.
        most: u64,
    },
    /// The BSP breaks a rule that would make light read out of bounds ([`quake_formats::check_usable`]).
    #[error(transparent)]
    Unusable(quake_formats::FormatError),
}
