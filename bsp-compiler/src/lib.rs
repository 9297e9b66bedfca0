//! Slipgate: .map to BSP29/BSP2 compiler.
//!
//! Stages, each a module with typed input and output: [`map`] (parsing), [`texinfo`] and
//! [`wad_lookup`] (textures), `brush` (brush windings), `csg` (hidden sides), `tree` (the
//! BSP tree: structural brushes first, its leaves the vis clusters, then detail below them),
//! `portals`, [`outside`] (filling and leaks), [`faces`] (faces from portals,
//! merging, subdivision), `hulls` (clip hulls) and `surface_tree` (their trees rebuilt after
//! filling), `weld` (shared vertices, T-junctions), `emit` and [`lightmap_grid`] (texture
//! offsets nudged so engines agree on lightmap sizes). [`compile()`] runs them all;
//! [`cracks`] checks a written BSP for T-junctions and unshared edges;
//! [`trace`] moves a hull's box through a written BSP as engines do, and [`hull_check`] measures
//! whether those moves stop where the map's brushes say.

#![warn(missing_docs)]

mod bounds_tree;
mod brush;
mod brushlist;
#[cfg(feature = "cli")]
pub mod cli;
mod compile;
pub mod content_flags;
pub mod convert;
pub mod cracks;
mod csg;
pub mod editor;
mod emit;
pub mod faces;
mod gather;
pub mod hull_check;
mod hulls;
pub mod leak;
pub mod lightmap_grid;
pub mod map;
mod model;
pub mod onlyents;
mod options;
pub mod outside;
mod planes;
mod portals;
pub mod prefab;
mod region;
mod sides_memo;
mod surface_tree;
pub mod texinfo;
pub mod trace;
mod tree;
pub mod wad_lookup;
pub mod warnings;
mod weld;

pub use compile::{CompileError, CompileOutput, CompileStats, MapSource, compile, wad_search};
pub use options::CompileOptions;
pub use quake_formats::progress::{Progress, ProgressEvent};
pub use tree::SplitHeuristic;
pub use warnings::Warning;
