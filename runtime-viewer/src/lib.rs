//! Slipgate's viewer: a software renderer in the manner of Quake's, for compiled BSPs.
//!
//! A [`World`] is a loaded map; a [`Renderer`] draws it as a [`Camera`] sees it into a [`Frame`].
//! A frame goes through `visibility` (PVS, frustum, BSP order), `edges` (global edge list and
//! sorted spans, so each pixel is drawn once), `surface_cache` (lit texture tiles) and `raster`
//! (perspective span texturing). [`render_reference`] is a slow ray-casting renderer that
//! defines what the fast one should draw, and [`compare`] measures the difference.
//! [`flythrough`] is the speed benchmark; [`ViewSummary`] is a run's counts and timings. With the
//! cargo feature `cli`, the `cli` module is `slipgate view`; [`image`] writes frames as PNG and [`textures`] finds the palette. With the
//! cargo feature `window`, the `window` module shows frames live with noclip flight (`fly`).

#![warn(missing_docs)]

mod camera;
#[cfg(feature = "cli")]
pub mod cli;
mod edges;
mod error;
#[cfg(any(feature = "window", test))]
mod fly;
mod flythrough;
pub mod image;
mod raster;
mod reference;
mod render;
mod summary;
mod surface_cache;
pub mod textures;
mod visibility;
#[cfg(feature = "window")]
mod window;
mod world;

pub use camera::Camera;
pub use edges::EdgeStats;
pub use error::{Result, ViewerError};
pub use flythrough::{Flythrough, flythrough};
pub use reference::{Comparison, compare, render_reference};
pub use render::{Frame, FrameStats, NO_FACE, RenderOptions, Renderer};
pub use summary::ViewSummary;
pub use surface_cache::{CacheStats, LightStyles};
pub use visibility::VisStats;
pub use world::{Fragment, LoadStats, NO_STYLE, Surface, World};
#[cfg(test)]
mod test_room;
