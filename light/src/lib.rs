//! Slipgate's `light`: lightmaps on Quake's 16-texel grid from the map's
//! light entities, with shadows traced by Embree.
//!
//! Pipeline ([`compute_lighting`] then [`apply_lighting`]):
//! 1. [`faces`]: every face as world-space geometry with its lightmap extents
//!    (from the shared `quake_formats::extents`).
//! 2. [`scene`]: one Embree scene of the opaque world (and `_shadow 1` brush
//!    models), sky faces as their own geometry; a small scene per
//!    `_shadowself` model for its own faces' rays.
//! 3. [`lights`]: light entities, suns and sky domes, minlight, switchable
//!    styles; [`surface`] expands `_surface` templates.
//! 4. [`samples`]: sample points per luxel (supersampled with `--extra`),
//!    pulled out of solid. Kept as a structure for a later bounce pass.
//!    [`phong`] gives them smoothed normals where `_phong` asks for it.
//! 5. [`trace`]: each face against the lights that can reach it (range,
//!    plane side and PVS culling from [`visibility`]), 16-ray packets, close
//!    lights supersampled; [`dirt`] occlusion; minlight per sample.
//! 6. [`output`]: `--soft`, scale, clamp, lump and `.lit` bytes.
//!
//! Sky faces block point lights (the sky brush is solid) and are what sun
//! rays look for; liquids (`*` textures) let light through, as in id's tool.

pub mod bench;
pub mod cli;
pub mod dirt;
pub mod embree;
pub mod faces;
pub mod lights;
pub mod output;
pub mod phong;
pub mod samples;
pub mod scene;
pub mod surface;
pub mod trace;
pub mod visibility;

use std::collections::HashMap;
use std::time::Instant;

use quake_formats::Bsp;
use quake_formats::entities::{parse_entities, write_entities};
use quake_formats::geom::{Bounds, Vec3};
use rayon::prelude::*;

use crate::embree::{Device, EmbreeError};
use crate::faces::{FaceKind, face_geometry};
use crate::lights::{GlobalOverrides, parse_lights};
use crate::output::{FaceLightmap, Finish, finish_face};
use crate::samples::{PlacementCounts, face_samples};
use crate::scene::TraceScene;
use crate::trace::{FaceLight, FaceRules, TraceCounts, TraceSetup, light_face};
use crate::visibility::Visibility;

/// Everything that can stop lighting a map.
#[derive(Debug, thiserror::Error)]
pub enum LightError {
    #[error("entity lump: {0}")]
    Entities(#[from] quake_formats::FormatError),
    #[error("entity {index} ({classname}): {detail}")]
    Entity {
        index: usize,
        classname: String,
        detail: String,
    },
    #[error("face {index}: {detail}")]
    BadFace { index: usize, detail: String },
    #[error("more switchable lights (distinct targetnames) than light styles 32..254")]
    TooManySwitchableLights,
    #[error(transparent)]
    Embree(#[from] EmbreeError),
    /// A damaged `SLIPGATE_PHONG` lump (the message names it).
    #[error("{0}")]
    PhongLump(quake_formats::FormatError),
    /// The BSP breaks a rule that would make light read out of bounds ([`quake_formats::check_usable`]).
    #[error(transparent)]
    Unusable(quake_formats::FormatError),
}

/// How much work to spend per luxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Quality {
    /// One sample per luxel.
    Default,
    /// `--extra`: 2x2 samples per luxel.
    Extra,
    /// `--extra4`: 4x4 samples per luxel.
    Extra4,
    /// `--reference`: 16x16 samples per luxel, no light culling.
    Reference,
}

impl Quality {
    pub fn samples_per_axis(self) -> usize {
        match self {
            Quality::Default => 1,
            Quality::Extra => 2,
            Quality::Extra4 => 4,
            Quality::Reference => 16,
        }
    }
}

/// Options of one lighting run.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    pub quality: Quality,
    /// `--soft`: box filter radius over final luxels (0 = off).
    pub soft_radius: usize,
    /// `--gate`: contributions below this many light units count as zero.
    pub gate: f64,
    pub overrides: GlobalOverrides,
    /// Light only these faces (others keep no lightmap); for measurements.
    pub only_faces: Option<Vec<usize>>,
    /// `--no-cull`: consider every light for every face (implied by `Reference`).
    pub no_cull: bool,
    pub progress: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            quality: Quality::Default,
            soft_radius: 0,
            gate: 0.001,
            overrides: GlobalOverrides::default(),
            only_faces: None,
            no_cull: false,
            progress: false,
        }
    }
}

/// Counts and timings of a run (`--stats`).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Stats {
    pub faces: usize,
    pub faces_lit: usize,
    pub luxels: u64,
    pub samples: u64,
    pub scene_triangles: usize,
    pub point_lights: usize,
    pub surface_lights: usize,
    pub sun_directions: usize,
    pub switchable_styles: usize,
    pub coloured: bool,
    /// The map has no light source (light, sun, lit surface or minlight): the lighting lump is
    /// left empty, which engines draw fullbright.
    pub fullbright: bool,
    pub shadow_rays: u64,
    pub sun_rays: u64,
    /// Ambient-occlusion rays (`_dirt`).
    pub dirt_rays: u64,
    pub placement_rays: u64,
    /// Points outside their face moved onto it (inset from its edges).
    pub points_clamped_to_face: u64,
    pub points_pulled_back: u64,
    pub points_moved_to_centre: u64,
    pub face_light_pairs: u64,
    pub face_light_pairs_culled: u64,
    pub faces_with_dropped_styles: u64,
    pub seconds_setup: f64,
    pub seconds_trace: f64,
    pub seconds_total: f64,
    /// All rays cast (shadow + sun + placement) per second of tracing.
    pub rays_per_second: f64,
}

/// The result of lighting: final lightmaps of the lit faces, the entity
/// text with assigned styles, and whether a `.lit` is needed.
#[derive(Debug, Clone)]
pub struct Lighting {
    pub lightmaps: Vec<FaceLightmap>,
    pub entity_text: Option<String>,
    pub coloured: bool,
    pub stats: Stats,
}

/// Everything built before tracing, reusable by later passes and benchmarks.
pub struct Prepared {
    pub faces: Vec<faces::FaceGeom>,
    pub scene: TraceScene,
    pub vis: Visibility,
    pub lights: lights::MapLights,
    /// Entity lights followed by surface-light copies.
    pub point_lights: Vec<lights::PointLight>,
    pub light_leafs: Vec<Option<u32>>,
    pub sun_distance: f32,
    pub surface_lights: usize,
    pub entity_text: Option<String>,
    /// Per face: `_phong` corner normals, for faces of smoothed models.
    pub phong: Vec<Option<Vec<Vec3>>>,
}

impl Prepared {
    /// Whether anything gives light: a light entity, a sun or sky dome, a `_surface` light that
    /// found its texture, or a minlight.
    pub fn has_light_sources(&self) -> bool {
        !self.point_lights.is_empty()
            || !self.lights.suns.is_empty()
            || self.lights.minlight.values().any(|m| m.level > 0.0)
    }

    /// What tracing reads, with lights cut off at `light_reaches` (built with `gate`).
    pub fn trace_setup<'a>(
        &'a self,
        bsp: &'a Bsp,
        light_reaches: &'a [trace::LightReach],
        gate: f64,
        cull: bool,
        adaptive: bool,
    ) -> TraceSetup<'a> {
        TraceSetup {
            bsp,
            faces: &self.faces,
            scene: &self.scene,
            vis: &self.vis,
            lights: &self.point_lights,
            light_leafs: &self.light_leafs,
            light_reaches,
            suns: &self.lights.suns,
            cull,
            gate,
            sun_distance: self.sun_distance,
            dirt: self.lights.uses_dirt().then_some(self.lights.dirt),
            adaptive,
        }
    }
}

/// Reads faces, entities and visibility and builds the Embree scene.
///
/// # Errors
/// Bad entities or faces, or an Embree failure.
pub fn prepare(bsp: &Bsp, options: &Options) -> Result<Prepared, LightError> {
    quake_formats::bsp::check_usable_for(bsp, quake_formats::bsp::TreeUse::IfPresent)
        .map_err(LightError::Unusable)?;
    let mut entities = parse_entities(&bsp.entity_text())?;
    let map_lights = parse_lights(&mut entities, &options.overrides)?;
    let entity_text = (!map_lights.switchable_styles.is_empty()).then(|| write_entities(&entities));
    let origin_of = |m: usize| {
        map_lights
            .model_origins
            .get(&m)
            .copied()
            .unwrap_or(Vec3::ZERO)
    };
    let faces = face_geometry(bsp, origin_of)?;
    // Embree's own threads only build the BVH; rayon does the tracing.
    let device = Device::new(rayon::current_num_threads())?;
    let scene = TraceScene::build(
        &device,
        &faces,
        &map_lights.shadow_models,
        &map_lights.self_shadow_models,
    )?;
    let vis = Visibility::new(bsp, &faces);
    let lump = bsp.phong_faces().map_err(LightError::PhongLump)?;
    let groups = phong::groups(&faces, &map_lights.phong, lump.as_deref());
    let phong = phong::corner_normals(&faces, &groups);
    let surface =
        surface::expand_templates(&map_lights.templates, &faces, surface::DEFAULT_SPACING);
    let surface_lights = surface.len();
    let mut point_lights = map_lights.points.clone();
    point_lights.extend(surface);
    let light_leafs = point_lights
        .iter()
        .map(|l| vis.open_leaf_at(bsp, l.origin))
        .collect();
    let mut bounds = Bounds::EMPTY;
    for p in faces.iter().flat_map(|f| &f.points) {
        bounds.add_point(*p);
    }
    let diagonal = if bounds.is_empty() {
        1.0
    } else {
        (bounds.maxs - bounds.mins).length()
    };
    Ok(Prepared {
        faces,
        scene,
        vis,
        lights: map_lights,
        point_lights,
        light_leafs,
        sun_distance: (diagonal * 2.0 + 1024.0) as f32,
        surface_lights,
        entity_text,
        phong,
    })
}

fn progress_bar(len: usize, show: bool) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::with_draw_target(
        Some(len as u64),
        indicatif::ProgressDrawTarget::stderr(),
    );
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("light {bar:40} {pos}/{len} faces {elapsed}")
    {
        bar.set_style(style);
    }
    bar
}

/// Lightmaps in light units, before the `--soft` filter and the conversion
/// to bytes (so one tracing run can be finished more than one way).
#[derive(Debug, Clone)]
pub struct RawLighting {
    pub faces: Vec<FaceLight>,
    pub entity_text: Option<String>,
    pub coloured: bool,
    pub rangescale: f64,
    pub gamma: f64,
    pub stats: Stats,
}

/// The rules of the faces of brush model `model` (0 = world).
fn face_rules<'a>(lights: &'a lights::MapLights, geom: &faces::FaceGeom) -> FaceRules<'a> {
    // A brush model's own `_minlight` wins; otherwise worldspawn's applies.
    let minlight = lights
        .minlight
        .get(&geom.model)
        .or_else(|| lights.minlight.get(&0))
        .filter(|m| {
            m.exclude_texture
                .as_ref()
                .is_none_or(|t| !t.eq_ignore_ascii_case(&geom.texture))
        });
    FaceRules {
        minlight,
        dirt: !lights.no_dirt_models.contains(&geom.model),
        minlight_only: lights.lightignore_models.contains(&geom.model),
    }
}

/// Traces every lit face of `bsp` (or `options.only_faces`): light units per
/// luxel and style, minlight included.
///
/// # Errors
/// Bad entities or faces, or an Embree failure.
pub fn trace_lighting(bsp: &Bsp, options: &Options) -> Result<RawLighting, LightError> {
    let start = Instant::now();
    let prep = prepare(bsp, options)?;
    let setup_done = Instant::now();
    let light_reaches = trace::light_reaches(&prep.point_lights, options.gate);
    let setup = prep.trace_setup(
        bsp,
        &light_reaches,
        options.gate,
        !options.no_cull && options.quality != Quality::Reference,
        options.quality != Quality::Reference,
    );
    let wanted: Vec<usize> = match &options.only_faces {
        Some(list) => list.clone(),
        None => (0..prep.faces.len()).collect(),
    };
    // With nothing to give light, engines draw a map with an empty lighting lump fullbright
    // (a lump of zeros would be black), as they draw a map never lit.
    let fullbright = !prep.has_light_sources();
    let lit_faces: Vec<usize> = wanted
        .into_iter()
        .filter(|&f| !fullbright && prep.faces.get(f).is_some_and(|g| g.kind == FaceKind::Lit))
        .collect();
    let per_axis = options.quality.samples_per_axis();
    let bar = progress_bar(lit_faces.len(), options.progress);
    let results: Vec<(FaceLight, PlacementCounts, TraceCounts, u64)> = lit_faces
        .par_iter()
        .map(|&f| {
            let geom = &prep.faces[f];
            let (mut samples, placement) = face_samples(geom, per_axis, &prep.scene, bsp);
            if let Some(corners) = &prep.phong[f] {
                samples.normals = samples
                    .points
                    .iter()
                    .map(|&p| phong::interpolate(geom, corners, Vec3::from_f32(p)).to_f32())
                    .collect();
            }
            let rules = face_rules(&prep.lights, geom);
            let (light, counts) = light_face(&setup, &samples, &rules);
            bar.inc(1);
            (light, placement, counts, samples.points.len() as u64)
        })
        .collect();
    bar.finish_and_clear();
    let trace_done = Instant::now();

    let mut placement = PlacementCounts::default();
    let mut counts = TraceCounts::default();
    let mut stats = Stats {
        faces: bsp.faces.len(),
        faces_lit: results.len(),
        scene_triangles: prep.scene.triangles,
        point_lights: prep.lights.points.len(),
        surface_lights: prep.surface_lights,
        sun_directions: prep.lights.suns.len(),
        switchable_styles: prep.lights.switchable_styles.len(),
        coloured: prep.lights.is_coloured(),
        fullbright,
        ..Stats::default()
    };
    let mut faces = Vec::with_capacity(results.len());
    for (light, p, c, samples) in results {
        placement.add(&p);
        counts.add(&c);
        stats.luxels += (light.width * light.height) as u64;
        stats.samples += samples;
        faces.push(light);
    }
    stats.shadow_rays = counts.shadow_rays;
    stats.sun_rays = counts.sun_rays;
    stats.dirt_rays = counts.dirt_rays;
    stats.placement_rays = placement.rays;
    stats.points_clamped_to_face = placement.clamped;
    stats.points_pulled_back = placement.pulled_back;
    stats.points_moved_to_centre = placement.to_centre;
    stats.face_light_pairs = counts.pairs;
    stats.face_light_pairs_culled = counts.pairs_culled;
    stats.seconds_setup = (setup_done - start).as_secs_f64();
    stats.seconds_trace = (trace_done - setup_done).as_secs_f64();
    stats.seconds_total = start.elapsed().as_secs_f64();
    stats.rays_per_second = (counts.rays() + placement.rays) as f64 / stats.seconds_trace.max(1e-9);
    Ok(RawLighting {
        faces,
        entity_text: prep.entity_text,
        coloured: stats.coloured,
        rangescale: prep.lights.rangescale,
        gamma: prep.lights.gamma,
        stats,
    })
}

/// Filters (`soft_radius`, the `--soft` box radius) and converts `raw` to
/// lightmap bytes.
pub fn finish_lighting(raw: &RawLighting, soft_radius: usize) -> Lighting {
    let start = Instant::now();
    let finish = Finish {
        rangescale: raw.rangescale,
        gamma: raw.gamma,
        soft_radius,
    };
    let mut stats = raw.stats.clone();
    let lightmaps = raw
        .faces
        .iter()
        .map(|light| {
            let (map, dropped) = finish_face(light, &finish);
            stats.faces_with_dropped_styles += u64::from(dropped > 0);
            map
        })
        .collect();
    stats.seconds_total += start.elapsed().as_secs_f64();
    Lighting {
        lightmaps,
        entity_text: raw.entity_text.clone(),
        coloured: raw.coloured,
        stats,
    }
}

/// Lights every lit face of `bsp` (or `options.only_faces`).
///
/// # Errors
/// Bad entities or faces, or an Embree failure.
pub fn compute_lighting(bsp: &Bsp, options: &Options) -> Result<Lighting, LightError> {
    let raw = trace_lighting(bsp, options)?;
    Ok(finish_lighting(&raw, options.soft_radius))
}

/// Writes `lighting` into `bsp` (lighting lump, face styles and offsets,
/// entity styles) and returns the `.lit` file bytes when the map is coloured.
pub fn apply_lighting(bsp: &mut Bsp, lighting: &Lighting) -> Option<Vec<u8>> {
    let rgb = output::write_lighting(bsp, &lighting.lightmaps);
    if let Some(text) = &lighting.entity_text {
        bsp.set_entity_text(text);
    }
    lighting
        .coloured
        .then(|| quake_formats::lit::write_lit(&rgb))
}

/// Per-luxel difference between two lightings of the same faces, in 8-bit levels.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct ErrorStats {
    /// Luxels compared (every style of every face both lightings share).
    pub luxels: u64,
    pub rmse: f64,
    pub max: u8,
    /// Luxels that differ by more than 8 levels.
    pub over_8: u64,
}

/// Compares grey lightmaps face by face and style by style (a style only one
/// side has counts against zero).
pub fn compare(a: &Lighting, reference: &Lighting) -> ErrorStats {
    let by_face: HashMap<usize, &FaceLightmap> =
        reference.lightmaps.iter().map(|m| (m.face, m)).collect();
    let mut e = ErrorStats::default();
    let mut sq = 0.0f64;
    for m in &a.lightmaps {
        let Some(r) = by_face.get(&m.face) else {
            continue;
        };
        let mut styles: Vec<u8> = m.styles.clone();
        styles.extend(r.styles.iter().filter(|s| !m.styles.contains(s)));
        let zeros = vec![0u8; m.width * m.height];
        for s in styles {
            let pick = |f: &FaceLightmap| {
                f.styles
                    .iter()
                    .position(|&x| x == s)
                    .map_or(zeros.clone(), |i| f.grey[i].clone())
            };
            for (x, y) in pick(m).iter().zip(pick(r).iter()) {
                let d = x.abs_diff(*y);
                e.luxels += 1;
                sq += f64::from(d) * f64::from(d);
                e.max = e.max.max(d);
                e.over_8 += u64::from(d > 8);
            }
        }
    }
    e.rmse = (sq / e.luxels.max(1) as f64).sqrt();
    e
}

#[cfg(test)]
mod tests;
