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
pub mod bounce;
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

use glam::{DVec3, Vec3};
use std::collections::HashMap;
use std::time::Instant;

use quake_formats::Bsp;
use quake_formats::entities::{parse_entities, write_entities};
use quake_formats::geom::Bounds;
use rayon::prelude::*;

use crate::bounce::{BounceCounts, StyleLuxels};
use crate::embree::{Device, EmbreeError};
use crate::faces::face_geometry;
use crate::lights::{GlobalOverrides, parse_lights};
use crate::output::{FaceLightmap, Finish, finish_face};
use crate::samples::{FaceSamples, PlacementCounts, face_samples};
use crate::scene::TraceScene;
use crate::trace::{
    FaceLight, FaceRules, SampleLight, TraceCounts, TraceScratch, TraceSetup, trace_face,
};
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
    /// Colours of texture pixels, for `_bouncecolorscale` (default: Slipgate's own palette).
    pub palette: Option<quake_formats::palette::Palette>,
    /// Where and how densely the fast bounce gathers, instead of the quality mode's; for
    /// measurements.
    pub bounce_density: Option<bounce::Density>,
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
            palette: None,
            bounce_density: None,
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
    /// Bounce: passes run, shadow (or, for the reference, gathering) rays cast, and
    /// receiving/emitting face pairs looked at and culled (PVS and facing, then energy).
    pub bounce_passes: usize,
    pub bounce_rays: u64,
    pub seconds_bounce: f64,
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
    pub phong: Vec<Option<Vec<DVec3>>>,
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
        light_reaches: &'a trace::LightReaches,
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
    // Starting Embree (its device and thread pool) takes as long as the check: both at once.
    // Embree's own threads only build the BVH; rayon does the tracing.
    let (usable, device) = rayon::join(
        || quake_formats::bsp::check_usable_for(bsp, quake_formats::bsp::TreeUse::IfPresent),
        || Device::new(rayon::current_num_threads()),
    );
    usable.map_err(LightError::Unusable)?;
    let device = device?;
    let mut entities = parse_entities(&bsp.entity_text())?;
    let map_lights = parse_lights(&mut entities, &options.overrides)?;
    let entity_text = (!map_lights.switchable_styles.is_empty()).then(|| write_entities(&entities));
    let origin_of = |m: usize| {
        map_lights
            .model_origins
            .get(&m)
            .copied()
            .unwrap_or(DVec3::ZERO)
    };
    let faces = face_geometry(bsp, origin_of)?;
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
    let dirt = !lights.no_dirt_models.contains(&geom.model);
    FaceRules {
        minlight,
        dirt,
        minlight_only: lights.lightignore_models.contains(&geom.model),
        bounce_dirt: lights.bounce.dirt.filter(|_| dirt && lights.bounce.is_on()),
    }
}

/// One face after direct light: what later steps need of it.
struct Traced {
    face: usize,
    /// Its light per sample (faces whose lightmap is wanted).
    light: Option<SampleLight>,
    /// Its sample points (kept for the reference's bounce gathering). Boxed, as `receivers`:
    /// most runs keep neither, and every face's record is in one large vector.
    samples: Option<Box<FaceSamples>>,
    /// Where it receives bounced light (when bouncing).
    receivers: Option<Box<bounce::Receivers>>,
    /// The light it reflects (when bouncing and the face reflects).
    reflected: Option<StyleLuxels>,
    placement: PlacementCounts,
    counts: TraceCounts,
    sample_count: u64,
}

/// What a run of [`trace_faces`] keeps of each face.
#[derive(Debug, Clone, Copy)]
struct Keep<'a> {
    wanted: &'a [bool],
    reflectance: &'a [Option<[f32; 3]>],
    bouncing: bool,
    samples: bool,
}

/// Direct light of `faces` at `quality`.
fn trace_faces(
    bsp: &Bsp,
    prep: &Prepared,
    setup: &TraceSetup,
    faces: &[usize],
    quality: Quality,
    keep: Keep,
    bar: &indicatif::ProgressBar,
) -> Vec<Traced> {
    let per_axis = quality.samples_per_axis();
    let styled = prep.lights.bounce.styled;
    faces
        .par_iter()
        .map_init(TraceScratch::default, |reuse, &f| {
            let geom = &prep.faces[f];
            let (mut samples, placement) = face_samples(geom, per_axis, &prep.scene, bsp);
            if let Some(corners) = &prep.phong[f] {
                samples.normals = samples
                    .points
                    .iter()
                    .map(|&p| {
                        phong::interpolate(geom, corners, Vec3::from(p).as_dvec3())
                            .as_vec3()
                            .to_array()
                    })
                    .collect();
            }
            let rules = face_rules(&prep.lights, geom);
            let (light, counts) = trace_face(setup, &samples, &rules, reuse);
            // A hidden bar still takes its lock per call (0.5 % of e1m1's instructions).
            if !bar.is_hidden() {
                bar.inc(1);
            }
            let reflected =
                (keep.bouncing && keep.reflectance[f].is_some()).then(|| light.reflected(styled));
            Traced {
                face: f,
                light: keep.wanted[f].then_some(light),
                receivers: keep
                    .bouncing
                    .then(|| Box::new(bounce::Receivers::new(&samples, geom))),
                reflected,
                placement,
                counts,
                sample_count: samples.points.len() as u64,
                samples: (keep.samples && keep.wanted[f]).then(|| Box::new(samples)),
            }
        })
        .collect()
}

/// Bounced light per face (by index; per luxel, or per sample for the reference), `passes`
/// passes of it, gathered at `density`. `traced` is the direct light of every lit face; with
/// `reference`, `field` is the same at `--extra4` (the reference's emitters) and bounce is
/// gathered at the samples of `traced` by [`bounce::reference::gather`] (the light a pass
/// brings to the faces of `field`, for the next pass, at `density`).
fn bounce_light(
    prep: &Prepared,
    reflectance: &[Option<[f32; 3]>],
    traced: &[Traced],
    field: &[Traced],
    reference: bool,
    density: bounce::Density,
    counts: &mut BounceCounts,
) -> Vec<StyleLuxels> {
    let settings = prep.lights.bounce;
    let n = prep.faces.len();
    let mut light: Vec<Option<StyleLuxels>> = vec![None; n];
    for t in field {
        light[t.face] = t.reflected.clone().filter(|r| !r.is_empty());
    }
    let mut total: Vec<StyleLuxels> = vec![Vec::new(); n];
    for pass in 1..=settings.passes {
        let last = pass == settings.passes;
        let emitting = bounce::Field {
            faces: &prep.faces,
            reflectance,
            light: &light,
            kernel: settings.kernel(),
        };
        if reference {
            let gathered: Vec<(usize, StyleLuxels, BounceCounts)> = traced
                .par_iter()
                .filter_map(|t| Some((t.face, &**t.samples.as_ref()?)))
                .map(|(face, samples)| {
                    let mut c = BounceCounts::default();
                    let model = prep.faces[face].model;
                    let b = bounce::reference::gather(
                        &emitting,
                        &prep.scene,
                        samples,
                        model,
                        pass,
                        &mut c,
                    );
                    (face, b, c)
                })
                .collect();
            for (face, b, c) in gathered {
                bounce::accumulate(&mut total[face], &b);
                counts.add(&c);
            }
            if last {
                break;
            }
        }
        // Wanted faces receive every pass (unless the reference measures them); reflecting ones
        // every pass but the last, for the next.
        let receiving: Vec<&Traced> = field
            .iter()
            .filter(|t| (!reference && t.light.is_some()) || (!last && t.reflected.is_some()))
            .collect();
        let gathered: Vec<(usize, StyleLuxels, BounceCounts)> = receiving
            .par_iter()
            .filter_map(|t| Some((t.face, &**t.receivers.as_ref()?)))
            .map(|(face, r)| {
                let mut c = BounceCounts::default();
                let b = emitting.gather_face(&prep.scene, r, pass, density, &mut c);
                (face, b, c)
            })
            .collect();
        let mut next: Vec<Option<StyleLuxels>> = vec![None; n];
        for (face, b, c) in gathered {
            counts.add(&c);
            if !reference {
                bounce::accumulate(&mut total[face], &b);
            }
            if reflectance[face].is_some() && !b.is_empty() {
                next[face] = Some(b);
            }
        }
        light = next;
    }
    total
}

/// Traces every lit face of `bsp` (or `options.only_faces`): light units per
/// luxel and style, minlight and bounced light included.
///
/// # Errors
/// Bad entities or faces, or an Embree failure.
pub fn trace_lighting(bsp: &Bsp, options: &Options) -> Result<RawLighting, LightError> {
    let start = Instant::now();
    let prep = prepare(bsp, options)?;
    let setup_done = Instant::now();
    let light_reaches = trace::light_reaches(&prep.point_lights, options.gate);
    let reference = options.quality == Quality::Reference;
    let setup = prep.trace_setup(
        bsp,
        &light_reaches,
        options.gate,
        !options.no_cull && !reference,
        !reference,
    );
    let n = prep.faces.len();
    let mut wanted = vec![options.only_faces.is_none(); n];
    for &f in options.only_faces.iter().flatten() {
        if let Some(w) = wanted.get_mut(f) {
            *w = true;
        }
    }
    // With nothing to give light, engines draw a map with an empty lighting lump fullbright
    // (a lump of zeros would be black), as they draw a map never lit.
    let fullbright = !prep.has_light_sources();
    let lit = |f: &usize| !fullbright && prep.faces[*f].kind.has_lightmap();
    let bouncing = prep.lights.bounce.is_on() && !fullbright;
    let palette = options
        .palette
        .clone()
        .unwrap_or_else(quake_formats::palette::Palette::slipgate);
    let reflectance = if bouncing {
        bounce::face_reflectance(bsp, &prep.faces, &prep.lights, &palette)
    } else {
        vec![None; n]
    };
    // Bounce needs every face's direct light (they all reflect, and receive for later passes).
    let to_trace: Vec<usize> = (0..n)
        .filter(lit)
        .filter(|&f| bouncing || wanted[f])
        .collect();
    let bar = progress_bar(to_trace.len(), options.progress);
    let keep = Keep {
        wanted: &wanted,
        reflectance: &reflectance,
        bouncing: bouncing && !reference,
        samples: bouncing && reference,
    };
    let traced = if bouncing && reference {
        let mine: Vec<usize> = to_trace.iter().copied().filter(|&f| wanted[f]).collect();
        trace_faces(bsp, &prep, &setup, &mine, options.quality, keep, &bar)
    } else {
        trace_faces(bsp, &prep, &setup, &to_trace, options.quality, keep, &bar)
    };
    bar.finish_and_clear();
    let trace_done = Instant::now();

    let mut bounce_counts = BounceCounts::default();
    let bounced = if bouncing && reference {
        // The reference's emitters: every face's direct light at --extra4.
        let fine = prep.trace_setup(bsp, &light_reaches, options.gate, true, true);
        let keep = Keep {
            bouncing: true,
            samples: false,
            ..keep
        };
        let hidden = indicatif::ProgressBar::hidden();
        let field = trace_faces(bsp, &prep, &fine, &to_trace, Quality::Extra4, keep, &hidden);
        bounce_light(
            &prep,
            &reflectance,
            &traced,
            &field,
            true,
            bounce::Density::for_quality(Quality::Reference),
            &mut bounce_counts,
        )
    } else if bouncing {
        bounce_light(
            &prep,
            &reflectance,
            &traced,
            &traced,
            false,
            options
                .bounce_density
                .unwrap_or_else(|| bounce::Density::for_quality(options.quality)),
            &mut bounce_counts,
        )
    } else {
        Vec::new()
    };
    let bounce_done = Instant::now();

    let mut placement = PlacementCounts::default();
    let mut counts = TraceCounts::default();
    let mut stats = Stats {
        faces: bsp.faces.len(),
        scene_triangles: prep.scene.triangles,
        point_lights: prep.lights.points.len(),
        surface_lights: prep.surface_lights,
        sun_directions: prep.lights.suns.len(),
        switchable_styles: prep.lights.switchable_styles.len(),
        coloured: prep.lights.is_coloured(),
        fullbright,
        ..Stats::default()
    };
    for t in &traced {
        placement.add(&t.placement);
        counts.add(&t.counts);
        if t.light.is_some() {
            stats.samples += t.sample_count;
        }
    }
    // Gathered first, into room for all, so no vector here grows in steps (each step takes
    // fresh pages) and the parallel collect knows its length.
    let mut lit: Vec<SampleLight> = Vec::with_capacity(traced.len());
    lit.extend(traced.into_iter().filter_map(|t| t.light));
    let faces: Vec<FaceLight> = lit
        .into_par_iter()
        .map(|light| {
            let bounce = bounced.get(light.face).map_or(&[][..], |b| &b[..]);
            light.finish(bounce)
        })
        .collect();
    stats.luxels = faces.iter().map(|l| (l.width * l.height) as u64).sum();
    stats.faces_lit = faces.len();
    if bouncing {
        // Bounced light takes the reflecting texture's colour.
        stats.coloured |= faces.iter().any(|f| {
            f.styles
                .iter()
                .flat_map(|(_, l)| l)
                .any(|c| c[0] != c[1] || c[1] != c[2])
        });
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
    stats.bounce_passes = if bouncing {
        prep.lights.bounce.passes
    } else {
        0
    };
    stats.bounce_rays = bounce_counts.rays;
    stats.seconds_setup = (setup_done - start).as_secs_f64();
    stats.seconds_trace = (trace_done - setup_done).as_secs_f64();
    stats.seconds_bounce = (bounce_done - trace_done).as_secs_f64();
    stats.seconds_total = start.elapsed().as_secs_f64();
    stats.rays_per_second = (counts.rays() + placement.rays + bounce_counts.rays) as f64
        / (stats.seconds_trace + stats.seconds_bounce).max(1e-9);
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
        rgb: raw.coloured,
    };
    let mut stats = raw.stats.clone();
    let (lightmaps, dropped): (Vec<_>, Vec<usize>) = raw
        .faces
        .par_iter()
        .map(|light| finish_face(light, &finish))
        .unzip();
    stats.faces_with_dropped_styles += dropped.iter().filter(|&&d| d > 0).count() as u64;
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
    let rgb = output::write_lighting(bsp, &lighting.lightmaps, lighting.coloured);
    if let Some(text) = &lighting.entity_text {
        bsp.set_entity_text(text);
    }
    rgb.map(|rgb| quake_formats::lit::write_lit(&rgb))
}

/// `--onlyents`: gives switchable lights their styles in the entity lump (the lump `slipgate bsp
/// --onlyents` just replaced) without relighting; the lightmaps stay as they are. Returns how many
/// switchable light names got a style.
///
/// # Errors
/// An entity lump that does not parse, a `style` that is not a number, or more switchable lights
/// than styles.
pub fn update_entities_only(bsp: &mut Bsp) -> Result<usize, LightError> {
    let mut entities = parse_entities(&bsp.entity_text())?;
    let assigned = lights::assign_switchable_styles(&mut entities)?;
    if !assigned.is_empty() {
        bsp.set_entity_text(&write_entities(&entities));
    }
    Ok(assigned.len())
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
    /// Luxels that differ by more than 2 levels.
    pub over_2: u64,
    /// Luxels black (0) here where the reference is not, and where it is above 2 levels.
    pub black: u64,
    pub black_over_2: u64,
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
                e.over_2 += u64::from(d > 2);
                e.black += u64::from(*x == 0 && *y > 0);
                e.black_over_2 += u64::from(*x == 0 && *y > 2);
            }
        }
    }
    e.rmse = (sq / e.luxels.max(1) as f64).sqrt();
    e
}

/// The lightmaps `bsp` already holds for `faces` (grey bytes of every style), as a [`Lighting`]
/// to [`compare`]: how another run or another tool's light is measured against ours. Faces
/// without a lightmap or with indices out of range are left out.
pub fn lightmaps_in(bsp: &Bsp, faces: &[usize]) -> Lighting {
    let mut lightmaps = Vec::new();
    for &f in faces {
        let Some(face) = bsp.faces.get(f) else {
            continue;
        };
        let (Some(verts), Some(ti)) = (
            bsp.face_vertices(face),
            bsp.texinfo.get(face.texinfo as usize),
        ) else {
            continue;
        };
        if face.light_offset < 0 {
            continue;
        }
        let [w, h] =
            quake_formats::extents::LightmapExtents::from_points(&verts, &ti.vecs).luxel_size();
        let styles: Vec<u8> = face.styles.iter().copied().filter(|&s| s != 255).collect();
        let grey = (0..styles.len())
            .map(|k| {
                let at = face.light_offset as usize + k * w * h;
                bsp.lighting
                    .get(at..at + w * h)
                    .map_or(vec![0; w * h], <[u8]>::to_vec)
            })
            .collect();
        lightmaps.push(FaceLightmap {
            face: f,
            width: w,
            height: h,
            styles,
            grey,
            rgb: Vec::new(),
        });
    }
    Lighting {
        lightmaps,
        entity_text: None,
        coloured: false,
        stats: Stats::default(),
    }
}

#[cfg(test)]
mod tests;
