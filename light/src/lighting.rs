//! What a lighting run gives back: lightmaps in light units ([`RawLighting`]), in bytes
//! ([`Lighting`]), and the counts and timings of the run ([`Stats`]).

use quake_formats::bsp::lightgrid::LightGrid;

use crate::lightgrid::RawGrid;
use crate::luxels::soften_luxels;
use crate::output::{FaceLightmap, Outputs};
use crate::settings::{ChosenSetting, SettingWarning, SoftRadius};
use crate::trace::FaceLight;

/// Counts and timings of a run (`--stats`).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Stats {
    /// Faces in the BSP.
    pub faces: usize,
    /// Faces given a lightmap.
    pub faces_lit: usize,
    /// Luxels of those lightmaps.
    pub luxels: u64,
    /// Sample points traced for them.
    pub samples: u64,
    /// Triangles in the shadow scene.
    pub scene_triangles: usize,
    /// Point lights from light entities (`_deviance` copies counted).
    pub point_lights: usize,
    /// Copies of `_surface` templates.
    pub surface_lights: usize,
    /// Lights moved out of solid (or off the surface they lay on).
    pub lights_nudged: usize,
    /// Directions of suns and sky domes.
    pub sun_directions: usize,
    /// Switchable styles given out (to switchable lights' names and switchable shadows).
    pub switchable_styles: usize,
    /// Some light is coloured (a `.lit` is written).
    pub coloured: bool,
    /// The map has no light source (light, sun, lit surface or minlight): the lighting lump is
    /// left empty, which engines draw fullbright.
    pub fullbright: bool,
    /// Shadow rays to point lights.
    pub shadow_rays: u64,
    /// Rays towards suns and sky domes.
    pub sun_rays: u64,
    /// Ambient-occlusion rays (`_dirt`).
    pub dirt_rays: u64,
    /// Bounce passes run.
    pub bounce_passes: usize,
    /// Rays cast gathering bounced light.
    pub bounce_rays: u64,
    /// Time gathering bounced light.
    pub seconds_bounce: f64,
    /// Points outside their face moved onto its edge.
    pub points_clamped_to_face: u64,
    /// Points in solid nudged half a unit into the open.
    pub points_nudged: u64,
    /// Points that take no light of their own: in solid however nudged, or far past the
    /// face's edge.
    pub points_occluded: u64,
    /// Face/light pairs looked at.
    pub face_light_pairs: u64,
    /// Of those, the pairs culling skipped.
    pub face_light_pairs_culled: u64,
    /// Faces reached by more than four light styles (the dimmest dropped).
    pub faces_with_dropped_styles: u64,
    /// Light grid points (`--lightgrid`).
    pub grid_points: u64,
    /// Of those, the points in the open.
    pub grid_points_open: u64,
    /// Rays cast sampling the light grid.
    pub grid_rays: u64,
    /// Time sampling the light grid.
    pub seconds_lightgrid: f64,
    /// Time reading the map and building the scene.
    pub seconds_setup: f64,
    /// Time tracing direct light.
    pub seconds_trace: f64,
    /// Time of the whole run.
    pub seconds_total: f64,
    /// All rays cast (shadow, sun, dirt, placement and bounce) per second of tracing.
    pub rays_per_second: f64,
}

/// Lightmaps in light units, before the conversion to bytes (so one tracing run can be
/// finished more than one way).
#[derive(Debug, Clone)]
pub struct RawLighting {
    /// Each lit face's light per luxel and style.
    pub faces: Vec<FaceLight>,
    /// Beside each of `faces`, its light on its own grid and that grid, when it has one
    /// (`--world_units_per_luxel`, `_lmscale`; its light in `faces` is then read from this).
    pub own_grids: Vec<Option<(FaceLight, crate::faces::OwnGrid)>>,
    /// The entity lump with the styles given to switchable lights (`None`: unchanged).
    pub entity_text: Option<String>,
    /// Some light is coloured: a `.lit` is needed.
    pub coloured: bool,
    /// The forms of the lightmaps to write.
    pub outputs: Outputs,
    /// The light grid, when `--lightgrid` asks for it.
    pub grid: Option<RawGrid>,
    /// Lightmap bytes per light unit (`_range`).
    pub rangescale: f64,
    /// Gamma applied to the bytes (`_gamma`).
    pub gamma: f64,
    /// `--soft` as the run was given it (its luxels are blurred already, except the
    /// reference's: [`RawLighting::softened`] blurs those).
    pub soft: SoftRadius,
    /// The settings given a value (on the command line or in worldspawn), and where.
    pub chosen_settings: Vec<ChosenSetting>,
    /// Entity, worldspawn or command-line values light did not take as given.
    pub warnings: Vec<SettingWarning>,
    /// Counts and timings.
    pub stats: Stats,
}

/// The result of lighting: final lightmaps of the lit faces, the entity
/// text with assigned styles, and whether a `.lit` is needed.
#[derive(Debug, Clone)]
pub struct Lighting {
    /// Each lit face's lightmaps, in bytes.
    pub lightmaps: Vec<FaceLightmap>,
    /// The entity lump with the styles given to switchable lights (`None`: unchanged).
    pub entity_text: Option<String>,
    /// Some light is coloured: a `.lit` is needed.
    pub coloured: bool,
    /// The forms of the lightmaps to write.
    pub outputs: Outputs,
    /// The `LIGHTGRID_OCTREE` lump's grid, when `--lightgrid` asks for it.
    pub light_grid: Option<LightGrid>,
    /// The settings given a value (on the command line or in worldspawn), and where.
    pub chosen_settings: Vec<ChosenSetting>,
    /// Entity, worldspawn or command-line values light did not take as given.
    pub warnings: Vec<SettingWarning>,
    /// Counts and timings.
    pub stats: Stats,
}

impl RawLighting {
    /// The faces' light through the `--soft` blur of a run with `per_axis` samples along a
    /// luxel's side (`None` when that run does not blur): to compare such a run with the
    /// reference, which does not.
    pub fn softened(&self, per_axis: usize) -> Option<RawLighting> {
        let radius = self.soft.samples(per_axis);
        if radius == 0 {
            return None;
        }
        let mut soft = self.clone();
        for face in &mut soft.faces {
            for (_, luxels) in &mut face.styles {
                *luxels = soften_luxels(luxels, face.width, per_axis, radius);
            }
        }
        Some(soft)
    }
}
