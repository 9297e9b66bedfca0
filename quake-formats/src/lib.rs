//! Quake's file formats and the geometry every Slipgate tool shares.
//!
//! One typed model per format, each with a reader that never panics on bad input and a writer
//! that round-trips byte-for-byte: [`bsp`] (BSP29 and BSP2), [`wad`] (WAD2), [`miptex`],
//! [`palette`], [`entities`], [`prt`] (portal files), [`pts`] (pointfiles), [`lit`] (coloured
//! lightmaps), [`visrle`] (PVS row compression), [`extents`] (lightmap extents of a face) and
//! [`geom`] (f64 vectors, planes, windings and the epsilon policy); [`rng`] is the seeded
//! generator the tools sample with, [`progress`] the one way every stage reports progress, and
//! [`int_hash`] the hasher of maps keyed by small integers.

#![warn(missing_docs)]

pub mod bsp;
mod bsp_version;
mod bytes;
#[cfg(feature = "cli")]
pub mod cli;
pub mod entities;
mod error;
pub mod extents;
pub mod fsutil;
pub mod geom;
pub mod int_hash;
mod layout;
pub mod lit;
pub mod miptex;
pub mod palette;
pub mod progress;
pub mod prt;
pub mod pts;
pub mod rng;
pub mod visrle;
pub mod wad;

pub use bsp::{Bsp, BspVersion, Problem, PvsRow, Severity, check_usable, validate};
pub use bytes::{latin1_to_string, name16_to_string, string_to_latin1, string_to_name16};
pub use error::{FormatError, Result};
