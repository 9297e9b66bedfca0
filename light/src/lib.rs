//! Slipgate's `light`: lightmaps on Quake's 16-texel grid (and on faces' own grids) from a
//! BSP's light entities, with shadows traced by Embree.
//!
//! [`compute_lighting`] reads a BSP and returns its lightmaps; [`apply_lighting`] writes them
//! into it (the grey lump and the BSPX lumps asked for) and gives the files beside it (`.lit`,
//! `.lux`). In between, stage by stage:
//!
//! 1. Settings ([`settings`]): each map-wide setting from the command line, else worldspawn,
//!    else its default; values that do not read warn and fall back.
//! 2. Preparation (`prepare`): faces as world-space geometry with their lightmap extents and
//!    the grid they are lit on, Quake's or their own (`--world_units_per_luxel`, `_lmscale`)
//!    (`faces`);
//!    the Embree scene of everything opaque, sky faces as their own geometry and a small scene
//!    per `_shadowself` model (`scene`); lights, suns, sky domes, minlight and
//!    switchable styles from the entity lump (`lights`), `_surface` templates copied over
//!    their faces (`surface`); the PVS for culling (`visibility`); `_phong` normals (`phong`).
//! 3. Direct light (`trace`), face by face in parallel: sample points per luxel (`--extra`:
//!    2×2, `--extra4`: 4×4, `--reference`: 16×16), nudged out of solid (`samples`); the lights
//!    that may reach the face (`reach`, culled by plane, range and PVS) traced in 16-ray
//!    packets, close lights averaged over each sample's square; suns and domes towards the sky
//!    the face sees; dirt measured where light that takes it arrived (`dirt`); minlight.
//! 4. Bounced light (`bounce`), when asked for: each pass gathers, at a grid of receivers per
//!    face, what the light of the pass before gives off from the faces it sees.
//! 5. Finishing: bounce added, floors applied, samples turned into luxels with occluded samples
//!    filled and the `--soft` blur (`luxels`; a face lit on its own grid gets its 16-texel
//!    lightmap read from that one, `resample`); range scale, gamma and clamping to bytes, at
//!    most four styles a face (`output`).
//!
//! Sky faces block point lights (the sky brush is solid) and are what sun rays look for;
//! liquids (`*` textures) let light through, as in id's tool. Results depend on neither the
//! number of threads nor the CPU's vector width.
//!
//! The command line (`slipgate light`, `slipgate-light`) is the `cli` feature's module.

#![warn(missing_docs)]

mod bench;
mod bits;
mod bounce;
#[cfg(feature = "cli")]
pub mod cli;
mod compare;
mod directions;
mod dirt;
#[cfg(test)]
mod docs;
mod drawn;
mod embree;
#[cfg(feature = "cli")]
pub mod ericw_texinfo;
mod error;
mod faces;
mod fence;
mod grid;
mod hull;
mod lightgrid;
mod lighting;
mod lights;
mod luxels;
mod mesh;
mod nudge;
mod options;
mod outline;
mod output;
mod phong;
mod prepare;
mod quality;
mod reach;
mod resample;
mod run;
mod samples;
mod scene;
pub mod settings;
mod simd;
mod styles;
mod surface;
mod trace;
mod visibility;

pub use bench::{BareOcclusion, bare_occlusion};
pub use bounce::Density as BounceDensity;
pub use bounce::EmissiveQuality;
pub use compare::{
    ErrorStats, ReferenceComparison, compare, compare_drawn, compare_grids, compare_with_reference,
    lightmaps_in, own_grid_lightmaps_in, own_grids,
};
pub use drawn::DrawnAreas;
pub use embree::CONFIG_ENV as EMBREE_CONFIG_ENV;
pub use error::LightError;
pub use lighting::{Lighting, RawLighting, Stats};
pub use lights::keys as entity_keys;
pub use options::Options;
pub use output::{FaceLightmap, Outputs, grey_lit};
pub use quality::Quality;
pub use run::{
    LightFiles, apply_lighting, compute_lighting, finish_lighting, trace_lighting,
    update_entities_only, wait_for_background_frees,
};
pub use trace::FaceLight;

#[cfg(test)]
mod tests;
