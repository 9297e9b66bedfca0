//! Geometry in `f64` on glam's `DVec3`: bounds, planes, convex windings and the one epsilon policy every tool uses.
//!
//! # Epsilon policy
//!
//! All geometry is computed in `f64`; values are rounded to `f32` only when written into a file.
//! Three tolerances exist, each with one meaning:
//!
//! - [`ON_EPSILON`]: a point closer than this (in map units) to a plane is *on* it. Used when
//!   classifying or splitting windings, so slivers thinner than this are not created.
//! - [`NORMAL_EPSILON`] and [`DIST_EPSILON`]: two planes are the *same* plane when their normals
//!   differ by less than `NORMAL_EPSILON` per component and their distances by less than
//!   `DIST_EPSILON`. Used when planes are deduplicated. A normal is *axial* when it is the same
//!   as an axis's by that test (`Plane::axial`): snapped onto the axis, turning its plane about a
//!   point on it (`Plane::snapped`), and written with an axial plane type, which engines test by
//!   that one coordinate.
//! - [`POINT_EPSILON`]: two vertices closer than this per component are the same vertex (welding,
//!   shared edges, T-junction detection).
//!
//! Windings never grow past [`MAX_WORLD_COORD`]; a base winding for a plane spans that extent.
//!
//! A few stages need a tolerance with a meaning of their own; each is a named constant beside its
//! use: the engine's clip-hull trace epsilon (`bsp-compiler/src/trace.rs`, 1/32, must match
//! engines), the distance at which a vertex splits another face's edge
//! (`bsp-compiler/src/weld.rs`; the crack checker in `cracks.rs` tests with the same constant),
//! how close a point must be to a face to share its phong normals (`light/src/phong.rs`), how far
//! a group of light sample points must clear a node plane to walk the BSP tree together
//! (`light/src/samples.rs`, `SHARED_WALK_MARGIN`), and how far outside an edge a reference-render
//! ray hit still counts (`runtime-viewer/src/reference.rs`).

mod bounds;
mod direction;
mod plane;
mod winding;

pub use bounds::Bounds;
pub use direction::DVec3Ext;
pub use plane::{Plane, PlaneSide};
pub use winding::{Split, Winding, polygon_area, polygon_center};

/// Distance within which a point lies on a plane.
pub const ON_EPSILON: f64 = 0.01;
/// Per-component tolerance for two plane normals to be equal.
pub const NORMAL_EPSILON: f64 = 1e-6;
/// Tolerance for two plane distances to be equal.
pub const DIST_EPSILON: f64 = 0.001;
/// Per-component tolerance for two vertices to be the same vertex.
pub const POINT_EPSILON: f64 = 0.001;
/// Half-size of the world cube that base windings span. BSP2 stores float coordinates; this leaves
/// room for maps far beyond BSP29's ±32767 while keeping f64 precision well under `ON_EPSILON`.
pub const MAX_WORLD_COORD: f64 = 1.0e6;
