//! Slipgate's viewer: a software renderer in the manner of Quake's, for compiled BSPs.
//!
//! A frame goes through [`visibility`] (PVS, frustum, BSP order), [`edges`] (global edge list
//! and sorted spans, so each pixel is drawn once), [`surface_cache`] (lit texture tiles) and
//! [`raster`] (perspective span texturing). [`reference`] is a slow ray-casting renderer that
//! defines what the fast one should draw, and [`reference::compare`] measures the difference.
//! With the cargo feature `window`, the `window` module shows frames live with noclip flight ([`fly`]).

pub mod camera;
pub mod cli;
pub mod edges;
pub mod error;
pub mod fly;
pub mod image;
pub mod raster;
pub mod reference;
pub mod render;
pub mod surface_cache;
pub mod textures;
pub mod visibility;
#[cfg(feature = "window")]
pub mod window;
pub mod world;

pub use camera::Camera;
pub use error::ViewerError;
pub use render::{Frame, FrameStats, RenderOptions, Renderer};
pub use surface_cache::SurfaceCache;
pub use world::World;
#[cfg(test)]
mod test_room;
