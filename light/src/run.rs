//! One lighting run, stage by stage: prepare the map, trace every face's direct light, gather
//! bounced light, finish each face (bounce added, floors applied, samples averaged to luxels)
//! and count what was done; then turn light units into bytes and write them into the BSP.

use glam::DVec3;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Condvar, Mutex, PoisonError};
use std::time::Instant;

use quake_formats::Bsp;
use quake_formats::bsp::lightgrid::LIGHTGRID_OCTREE;
use quake_formats::entities::{parse_entities, write_entities};
use quake_formats::palette::Palette;
use quake_formats::progress::Progress;
use rayon::prelude::*;

use crate::bounce::points::{Emission, PointField};
use crate::bounce::{
    self, BounceCounts, Density, EmissiveQuality, Field, Receivers, StyleLight, StyleLuxels,
};
use crate::error::LightError;
use crate::faces::{FaceGeom, OwnGrid};
use crate::lightgrid::{GridSources, RawGrid, finish_grid, light_at, trace_grid};
use crate::lighting::{Lighting, RawLighting, Stats};
use crate::lights::{AutoMinlight, StyleRange, assign_switchable_styles};
use crate::luxels::ToLuxels;
use crate::options::Options;
use crate::output::{self, Finish, Outputs, finish_face, finish_face_on_own_grid};
use crate::phong;
use crate::prepare::{Prepared, face_rules, prepare};
use crate::quality::Quality;
use crate::reach::{LightReaches, light_reaches};
use crate::resample;
use crate::samples::{FaceSamples, PlacementCounts, face_samples};
use crate::settings::{Overrides, Settings, World};
use crate::trace::{
    FaceLight, HiddenLuxels, SampleLight, TraceCounts, TraceScratch, TraceSetup, trace_face,
};

/// Lights every lit face of `bsp` (or `options.only_faces`).
///
/// # Errors
/// A BSP light cannot read safely, bad entities or faces, or an Embree failure.
pub fn compute_lighting(bsp: &Bsp, options: &Options) -> Result<Lighting, LightError> {
    let raw = trace_lighting(bsp, options)?;
    let lighting = finish_lighting(&raw);
    drop_in_background(raw);
    Ok(lighting)
}

/// Traces every lit face of `bsp` (or `options.only_faces`): light units per
/// luxel and style, minlight and bounced light included.
///
/// # Errors
/// A BSP light cannot read safely, bad entities or faces, or an Embree failure.
pub fn trace_lighting(bsp: &Bsp, options: &Options) -> Result<RawLighting, LightError> {
    let start = Instant::now();
    let open_fences = crate::fence::with_fence_leaves_open(bsp)?;
    let bsp = open_fences.as_ref();
    let prep = prepare(bsp, options)?;
    let setup_done = Instant::now();
    let plan = Plan::new(bsp, &prep, options);
    let traced = plan.direct_light();
    let trace_done = Instant::now();
    let autominlight = &prep.lights.autominlight;
    // Models whose samples in solid take no light: those that cast shadows, and `-1`.
    let dark_models: Vec<usize> = (prep.lights.shadow_models.iter().copied())
        .chain(
            (autominlight.iter())
                .filter(|(_, a)| **a == AutoMinlight::Off)
                .map(|(&m, _)| m),
        )
        .collect();
    let everywhere: Vec<usize> = (autominlight.iter())
        .filter(|(_, a)| **a == AutoMinlight::Everywhere)
        .map(|(&m, _)| m)
        .collect();
    let centres = plan.model_centres(&buried_models(
        &traced,
        &prep.faces,
        &dark_models,
        &everywhere,
    ));
    let mut bounce_counts = BounceCounts::default();
    let (bounced, centre_bounce) = plan.bounced_light(&traced, &centres, &mut bounce_counts);
    let bounce_done = Instant::now();
    let grid = plan.light_grid()?;
    let grid_done = Instant::now();
    let mut stats = plan.stats(&traced, &bounce_counts);
    if let Some(g) = &grid {
        stats.grid_points = g.points.len() as u64;
        stats.grid_points_open = g.points.iter().flatten().count() as u64;
        stats.grid_rays = g.rays;
        stats.seconds_lightgrid = (grid_done - bounce_done).as_secs_f64();
    }
    let settings = &prep.lights.settings;
    let to_luxels = plan.to_luxels();
    let model_light = plan.model_centre_light(&centres, &centre_bounce);
    let (faces, own_grids) = finish_faces(
        traced,
        &bounced,
        &prep.faces,
        ModelFill {
            dark: &dark_models,
            everywhere: &everywhere,
            light: &model_light,
        },
        to_luxels,
    );
    stats.luxels = faces.iter().map(|l| (l.width * l.height) as u64).sum();
    stats.faces_lit = faces.len();
    if plan.bouncing {
        // Bounced light takes the reflecting texture's colour.
        stats.coloured |= faces.iter().any(|f| {
            f.styles
                .iter()
                .flat_map(|(_, l)| l)
                .any(|c| c[0] != c[1] || c[1] != c[2])
        });
    }
    stats.seconds_setup = (setup_done - start).as_secs_f64();
    stats.seconds_trace = (trace_done - setup_done).as_secs_f64();
    stats.seconds_bounce = (bounce_done - trace_done).as_secs_f64();
    stats.seconds_total = start.elapsed().as_secs_f64();
    let rays = stats.shadow_rays + stats.sun_rays + stats.dirt_rays + stats.bounce_rays;
    stats.rays_per_second = rays as f64 / (stats.seconds_trace + stats.seconds_bounce).max(1e-9);
    let raw = RawLighting {
        faces,
        own_grids,
        entity_text: prep.entity_text.clone(),
        coloured: stats.coloured,
        outputs: Outputs::from_settings(settings),
        grid,
        rangescale: settings.range,
        gamma: settings.gamma,
        soft: settings.soft,
        chosen_settings: prep.lights.chosen_settings.clone(),
        warnings: prep.lights.warnings.clone(),
        stats,
    };
    drop(plan);
    drop_in_background(prep);
    Ok(raw)
}

/// Frees `value` on a worker thread when one is free: what follows need not wait for it (the
/// scene and every face's geometry take milliseconds to free, on one thread).
/// [`wait_for_background_frees`] waits for it.
fn drop_in_background<T: Send + 'static>(value: T) {
    *lock(&BACKGROUND_FREES.count) += 1;
    rayon::spawn(move || {
        drop(value);
        let mut count = lock(&BACKGROUND_FREES.count);
        *count -= 1;
        if *count == 0 {
            BACKGROUND_FREES.done.notify_all();
        }
    });
}

/// How many values [`drop_in_background`] has yet to free, and the signal when none is left.
struct BackgroundFrees {
    count: Mutex<usize>,
    done: Condvar,
}

static BACKGROUND_FREES: BackgroundFrees = BackgroundFrees {
    count: Mutex::new(0),
    done: Condvar::new(),
};

fn lock<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Waits until the values light handed to worker threads to free are freed (most often they
/// already are): a program calls it before it ends, so that no thread is still releasing an
/// Embree scene while the process unloads Embree. Not from a worker of the pool light ran in,
/// which may be the one thread that would free them.
pub fn wait_for_background_frees() {
    let mut count = lock(&BACKGROUND_FREES.count);
    while *count > 0 {
        count = BACKGROUND_FREES
            .done
            .wait(count)
            .unwrap_or_else(PoisonError::into_inner);
    }
}

/// What a run traces, and how.
struct Plan<'a> {
    bsp: &'a Bsp,
    prep: &'a Prepared,
    options: &'a Options,
    /// Each light's reach at the run's gate.
    reaches: LightReaches,
    /// Per face: its lightmap is wanted (every face, or `options.only_faces`).
    wanted: Vec<bool>,
    /// No light source: the lump stays empty, which engines draw fullbright (a lump of zeros
    /// would be black), as they draw a map never lit.
    fullbright: bool,
    /// Bounced light is gathered.
    bouncing: bool,
    /// Per face, what it reflects (when bouncing).
    reflectance: Vec<Option<[f32; 3]>>,
    /// The faces whose direct light is traced: bounce needs every lit face's (they all
    /// reflect, and receive for later passes).
    to_trace: Vec<usize>,
}

impl<'a> Plan<'a> {
    fn new(bsp: &'a Bsp, prep: &'a Prepared, options: &'a Options) -> Plan<'a> {
        let n = prep.faces.len();
        let mut wanted = vec![options.only_faces.is_none(); n];
        for &f in options.only_faces.iter().flatten() {
            if let Some(w) = wanted.get_mut(f) {
                *w = true;
            }
        }
        let fullbright = !prep.has_light_sources();
        let bouncing = prep.lights.bounce.is_on() && !fullbright;
        let reflectance = if bouncing {
            let palette = options.palette.clone().unwrap_or_else(Palette::slipgate);
            bounce::face_reflectance(bsp, &prep.faces, &prep.lights, &palette)
        } else {
            vec![None; n]
        };
        let to_trace = (0..n)
            .filter(|&f| !fullbright && prep.faces[f].has_lightmap())
            .filter(|&f| bouncing || wanted[f])
            .collect();
        Plan {
            bsp,
            prep,
            options,
            reaches: light_reaches(&prep.point_lights, prep.lights.settings.gate),
            wanted,
            fullbright,
            bouncing,
            reflectance,
            to_trace,
        }
    }

    fn reference(&self) -> bool {
        self.options.quality == Quality::Reference
    }

    /// No culling for the reference or with `--no-cull`.
    fn cull(&self) -> bool {
        !self.options.no_cull && !self.reference()
    }

    /// What tracing the run's faces reads: culled as [`Plan::cull`] says, and no adaptive
    /// sampling for the reference.
    fn setup(&self) -> TraceSetup<'_> {
        let gate = self.prep.lights.settings.gate;
        self.prep
            .trace_setup(&self.reaches, gate, self.cull(), !self.reference())
    }

    /// What tracing the reference's bounce emitters reads: culled and adaptive, as `--extra4`.
    fn emitter_setup(&self) -> TraceSetup<'_> {
        let gate = self.prep.lights.settings.gate;
        self.prep.trace_setup(&self.reaches, gate, true, true)
    }

    /// How the run's samples become luxels.
    fn to_luxels(&self) -> ToLuxels {
        match self.options.quality {
            Quality::Reference => ToLuxels::OpenMeans,
            q => ToLuxels::AsEricw {
                soft_radius: self.prep.lights.settings.soft.samples(q.samples_per_axis()),
            },
        }
    }

    /// Each traced face's direct light. The reference's bounce gathers at the samples of the
    /// faces it measures, so only those are traced here when it bounces.
    fn direct_light(&self) -> Vec<Traced> {
        let reference = self.reference();
        let keep = Keep {
            wanted: &self.wanted,
            reflectance: &self.reflectance,
            bouncing: self.bouncing && !reference,
            samples: self.bouncing && reference,
            finish: (!self.bouncing).then(|| self.to_luxels()),
        };
        let faces: Vec<usize> = if self.bouncing && reference {
            let wanted = self.to_trace.iter().copied();
            wanted.filter(|&f| self.wanted[f]).collect()
        } else {
            self.to_trace.clone()
        };
        let progress = &self.options.progress;
        progress.start("light", faces.len());
        let traced = trace_faces(
            self.bsp,
            self.prep,
            &self.setup(),
            &faces,
            self.options.quality,
            keep,
            progress,
        );
        progress.finish();
        traced
    }

    /// Bounced light per face (by index), when bouncing.
    fn bounced_light(
        &self,
        traced: &[Traced],
        centres: &[ModelCentre],
        counts: &mut BounceCounts,
    ) -> (Vec<StyleLuxels>, Vec<StyleLight>) {
        if !self.bouncing {
            return (Vec::new(), vec![Vec::new(); centres.len()]);
        }
        if !self.reference() {
            let density = self
                .options
                .bounce_density
                .unwrap_or_else(|| Density::for_quality(self.options.quality));
            let gathering = Gathering {
                reference: false,
                density,
                progress: &self.options.progress,
            };
            return bounce_light(
                self.prep,
                &self.reflectance,
                (traced, traced),
                centres,
                gathering,
                counts,
            );
        }
        // The reference's emitters: every face's direct light at --extra4.
        let keep = Keep {
            wanted: &self.wanted,
            reflectance: &self.reflectance,
            bouncing: true,
            samples: false,
            finish: None,
        };
        let field = trace_faces(
            self.bsp,
            self.prep,
            &self.emitter_setup(),
            &self.to_trace,
            Quality::Extra4,
            keep,
            &Progress::default(),
        );
        let gathering = Gathering {
            reference: true,
            density: Density::for_quality(Quality::Reference),
            progress: &Progress::default(),
        };
        bounce_light(
            self.prep,
            &self.reflectance,
            (traced, &field),
            centres,
            gathering,
            counts,
        )
    }

    /// The counts of the run so far (luxels and timings are the caller's).
    /// The light grid in light units, when `--lightgrid` asks for it and anything gives light.
    fn light_grid(&self) -> Result<Option<RawGrid>, LightError> {
        let prep = self.prep;
        let settings = &prep.lights.settings;
        if !settings.lightgrid || self.fullbright {
            return Ok(None);
        }
        trace_grid(&self.grid_sources(), settings.lightgrid_dist.0).map(Some)
    }

    /// What lights a point in the open: the grid's sources.
    fn grid_sources(&self) -> GridSources<'_> {
        let prep = self.prep;
        GridSources {
            bsp: self.bsp,
            scene: &prep.scene,
            vis: &prep.vis,
            lights: &prep.point_lights,
            light_leafs: &prep.light_leafs,
            reaches: &self.reaches,
            suns: &prep.lights.suns,
            minlight: prep.lights.minlight.get(&0),
            gate: prep.lights.settings.gate,
            sun_distance: prep.sun_distance,
            cull: self.cull(),
            every_sun_direction: self.reference(),
        }
    }

    /// Where each brush model of `models` takes its estimate of its light (ericw-tools'
    /// "autominlight"): the middle of its box or its `_autominlight_target`, moved out of solid
    /// as a light is (a model whose point no step frees has none).
    fn model_centres(&self, models: &[usize]) -> Vec<ModelCentre> {
        if self.fullbright {
            return Vec::new();
        }
        models
            .iter()
            .filter_map(|&model| {
                let box_of = self.bsp.models.get(model)?;
                let corner = |c: [f32; 3]| DVec3::from(c.map(f64::from));
                let centre = (corner(box_of.mins) + corner(box_of.maxs)) / 2.0;
                let at = self.prep.lights.autominlight_at.get(&model).copied();
                let point = crate::nudge::free_point(self.bsp, at.unwrap_or(centre))?;
                let leaf = self.prep.vis.open_leaf_at(self.bsp, point);
                Some(ModelCentre { model, point, leaf })
            })
            .collect()
    }

    /// Each model's estimate of its light at its centre ([`Plan::model_centres`]): the direct
    /// light there as a grid point takes it, without minlight, and the light `bounce` brings it
    /// (per centre), scaled once more by the range scale as ericw-tools' value is.
    fn model_centre_light(&self, centres: &[ModelCentre], bounce: &[StyleLight]) -> ModelLight {
        let points: Vec<DVec3> = centres.iter().map(|c| c.point).collect();
        let sources = GridSources {
            minlight: None,
            ..self.grid_sources()
        };
        let scale = self.prep.lights.settings.range as f32;
        centres
            .iter()
            .zip(light_at(&sources, &points))
            .zip(bounce)
            .filter_map(|((centre, light), bounce)| {
                let mut light = light?;
                add_styles(&mut light, bounce);
                let light = light.into_iter().map(|(s, c)| (s, c.map(|v| v * scale)));
                Some((centre.model, light.collect()))
            })
            .collect()
    }

    fn stats(&self, traced: &[Traced], bounce: &BounceCounts) -> Stats {
        let prep = self.prep;
        let mut placement = PlacementCounts::default();
        let mut counts = TraceCounts::default();
        let mut samples = 0;
        for t in traced {
            placement.add(&t.placement);
            counts.add(&t.counts);
            if t.light.is_some() {
                samples += t.sample_count;
            }
        }
        Stats {
            faces: self.bsp.faces.len(),
            samples,
            scene_triangles: prep.scene.triangles,
            point_lights: prep.lights.points.len(),
            surface_lights: prep.surface_lights,
            lights_nudged: prep.lights_nudged,
            sun_directions: prep.lights.suns.len(),
            switchable_styles: prep.lights.switchable.count,
            coloured: prep.lights.is_coloured(),
            fullbright: self.fullbright,
            shadow_rays: counts.shadow_rays,
            sun_rays: counts.sun_rays,
            dirt_rays: counts.dirt_rays,
            points_clamped_to_face: placement.clamped,
            points_nudged: placement.nudged,
            points_occluded: placement.occluded,
            face_light_pairs: counts.pairs,
            face_light_pairs_culled: counts.pairs_culled,
            bounce_passes: if self.bouncing {
                prep.lights.bounce.passes
            } else {
                0
            },
            bounce_rays: bounce.rays,
            ..Stats::default()
        }
    }
}

/// Light per style (light units) of some brush models, by model.
type ModelLight = BTreeMap<usize, StyleLight>;

/// Adds `add` to `sum`, style by style.
fn add_styles(sum: &mut StyleLight, add: &[(u8, [f32; 3])]) {
    for &(style, light) in add {
        bounce::add_style_light(sum, style, light);
    }
}

/// Where a brush model takes its estimate of its light ([`Plan::model_centres`]).
struct ModelCentre {
    model: usize,
    point: DVec3,
    /// Its world leaf, when open.
    leaf: Option<u32>,
}

/// The brush models whose samples in solid take their model's light (ericw-tools'
/// autominlight): those with a sample in solid and those `everywhere` names, not the world nor
/// the `dark` ones.
fn buried_models(
    traced: &[Traced],
    geoms: &[FaceGeom],
    dark: &[usize],
    everywhere: &[usize],
) -> Vec<usize> {
    let buried: BTreeSet<usize> = traced
        .iter()
        .filter_map(|t| t.light.as_ref()?.samples())
        .filter(|light| light.has_occluded())
        .map(|light| geoms[light.face].model)
        .chain(everywhere.iter().copied())
        .filter(|&m| m != 0 && !dark.contains(&m))
        .collect();
    buried.into_iter().collect()
}

/// What the samples of brush models take where they are inside solid.
#[derive(Clone, Copy)]
struct ModelFill<'a> {
    /// None: those of models that cast shadows, and of `_autominlight -1`.
    dark: &'a [usize],
    /// Models whose every sample takes at least their light (`_autominlight 1`).
    everywhere: &'a [usize],
    /// The light of the models whose samples in solid take it (ericw-tools' autominlight).
    light: &'a ModelLight,
}

/// Each wanted face's light with its bounced light added, floors applied and samples averaged
/// to luxels: on its 16-texel grid, and beside it the light on its own grid when it was lit
/// there (the 16-texel light is then read from that). The occluded samples of the faces of
/// `models.dark` stay dark; those of other brush models take the light `models.light` gives
/// their model (ericw-tools' autominlight), or if it gives none, as [`fill_hidden_luxels`]
/// says.
fn finish_faces(
    traced: Vec<Traced>,
    bounced: &[StyleLuxels],
    geoms: &[FaceGeom],
    models: ModelFill,
    to_luxels: ToLuxels,
) -> (Vec<FaceLight>, Vec<Option<OwnGridLight>>) {
    let shadow_models = models.dark;
    // Gathered first, into room for all, so no vector here grows in steps (each step takes
    // fresh pages) and the parallel collect knows its length.
    let mut lit: Vec<TracedLight> = Vec::with_capacity(traced.len());
    lit.extend(traced.into_iter().filter_map(|t| t.light));
    // ericw-tools' autominlight: the occluded samples of a brush model's faces take the light
    // of the model's middle, where it has one.
    let model_of = |light: &SampleLight| geoms[light.face].model;
    let centre_light = models.light;
    let lit: Vec<TracedLight> = lit
        .into_iter()
        .map(|traced| match traced {
            TracedLight::Samples(light) => {
                let model = model_of(&light);
                TracedLight::Samples(match centre_light.get(&model) {
                    Some(centre) => {
                        Box::new(light.with_model_light(centre, models.everywhere.contains(&model)))
                    }
                    None => light,
                })
            }
            finished => finished,
        })
        .collect();
    let hidden: Vec<Vec<bool>> = lit
        .iter()
        .map(|t| {
            t.samples()
                .map_or_else(Vec::new, SampleLight::hidden_luxels)
        })
        .collect();
    let mut finished: Vec<FaceLight> = lit
        .into_par_iter()
        .zip(hidden.par_iter())
        .map(|(traced, hidden)| {
            let light = match traced {
                TracedLight::Samples(light) => *light,
                TracedLight::Luxels(light) => return light,
            };
            let bounce = bounced.get(light.face).map_or(&[][..], |b| &b[..]);
            // As in ericw-tools, hidden luxels take their neighbours' light, but a brush
            // model's face with no open luxel at all takes its model's (filled below), and a
            // model that casts shadows gives its samples in solid no light at all.
            let fill = match geoms[light.face].model {
                0 => HiddenLuxels::FromNeighbours,
                m if shadow_models.contains(&m) => HiddenLuxels::Dark,
                _ if !all_hidden(hidden) => HiddenLuxels::FromNeighbours,
                _ => HiddenLuxels::Later,
            };
            light.finish(bounce, fill, to_luxels)
        })
        .collect();
    fill_hidden_luxels(&mut finished, &hidden, geoms, shadow_models);
    finished
        .into_par_iter()
        .map(|light| {
            let geom = &geoms[light.face];
            match geom.own_grid {
                Some(grid) => (
                    resample::vanilla_from_own(geom, &light),
                    Some((light, grid)),
                ),
                None => (light, None),
            }
        })
        .unzip()
}

/// Whether a face's every luxel is hidden ([`SampleLight::hidden_luxels`]).
fn all_hidden(hidden: &[bool]) -> bool {
    !hidden.is_empty() && hidden.iter().all(|&h| h)
}

/// The luxels of a brush model's faces with no open luxel at all (a door's edge or face in
/// the wall it slides into), when the model has no light of its own ([`finish_faces`]: its
/// middle is in solid), take per style the mean of the model's open luxels, all its faces'
/// together (zero where a face has no light of that style): their own rays, traced from
/// inside the wall, say nothing. The faces of `shadow_models` are left dark, as ericw-tools
/// leaves a model that casts shadows.
fn fill_hidden_luxels(
    faces: &mut [FaceLight],
    hidden: &[Vec<bool>],
    geometry: &[FaceGeom],
    shadow_models: &[usize],
) {
    let model_of = |light: &FaceLight| geometry[light.face].model;
    let in_brush_model = |(light, _): &(&FaceLight, &Vec<bool>)| {
        let model = model_of(light);
        model != 0 && !shadow_models.contains(&model)
    };
    if !faces
        .iter()
        .zip(hidden)
        .filter(in_brush_model)
        .any(|(_, h)| h.contains(&true))
    {
        return;
    }
    let mut open_luxels: BTreeMap<usize, usize> = BTreeMap::new();
    let mut sums: BTreeMap<(usize, u8), [f64; 3]> = BTreeMap::new();
    for (light, hidden) in faces.iter().zip(hidden).filter(in_brush_model) {
        let model = model_of(light);
        let open = |i: usize| !hidden.get(i).copied().unwrap_or(false);
        *open_luxels.entry(model).or_default() +=
            (0..light.width * light.height).filter(|&i| open(i)).count();
        for (style, luxels) in &light.styles {
            let sum = sums.entry((model, *style)).or_default();
            for (_, l) in luxels.iter().enumerate().filter(|(i, _)| open(*i)) {
                for k in 0..3 {
                    sum[k] += f64::from(l[k]);
                }
            }
        }
    }
    for (light, hidden) in faces.iter_mut().zip(hidden) {
        let model = model_of(light);
        if model == 0 || shadow_models.contains(&model) || !all_hidden(hidden) {
            continue;
        }
        let count = open_luxels.get(&model).copied().unwrap_or(0);
        if count == 0 {
            continue;
        }
        let n = light.width * light.height;
        for (&(_, style), sum) in sums.range((model, 0)..=(model, u8::MAX)) {
            let value = sum.map(|s| (s / count as f64) as f32);
            let at = light.styles.iter().position(|(s, _)| *s == style);
            let at = at.unwrap_or_else(|| {
                light.styles.push((style, vec![[0.0; 3]; n]));
                light.styles.len() - 1
            });
            for (l, _) in light.styles[at]
                .1
                .iter_mut()
                .zip(hidden)
                .filter(|(_, h)| **h)
            {
                *l = value;
            }
        }
        // Style 0 first, as everywhere.
        light.styles.sort_by_key(|(s, _)| *s != 0);
    }
}

/// A face's direct light: per sample, or (a world face when nothing bounces, whose light
/// nothing else changes) already per luxel.
enum TracedLight {
    Samples(Box<SampleLight>),
    Luxels(FaceLight),
}

impl TracedLight {
    fn samples(&self) -> Option<&SampleLight> {
        match self {
            TracedLight::Samples(light) => Some(light),
            TracedLight::Luxels(_) => None,
        }
    }
}

/// One face after direct light: what later steps need of it.
struct Traced {
    face: usize,
    /// Its light (faces whose lightmap is wanted).
    light: Option<TracedLight>,
    /// Its sample points (kept for the reference's bounce gathering). Boxed, as `receivers`:
    /// most runs keep neither, and every face's record is in one large vector.
    samples: Option<Box<FaceSamples>>,
    /// Where it receives bounced light (when bouncing).
    receivers: Option<Box<Receivers>>,
    /// The light it reflects (when bouncing and the face reflects).
    reflected: Option<StyleLuxels>,
    /// Per luxel, the share of a pass's bounced light it reflects in the next
    /// ([`crate::trace::SampleLight::passed_on`]; `None`: all of it).
    passed_on: Option<Vec<f32>>,
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
    /// When nothing bounces: world faces go to luxels as soon as traced, so their samples'
    /// buffers are freed face by face instead of all held to the end.
    finish: Option<ToLuxels>,
}

/// A face's light on its own grid, and that grid.
type OwnGridLight = (FaceLight, OwnGrid);

/// Direct light of `faces` at `quality`.
fn trace_faces(
    bsp: &Bsp,
    prep: &Prepared,
    setup: &TraceSetup,
    faces: &[usize],
    quality: Quality,
    keep: Keep,
    progress: &Progress,
) -> Vec<Traced> {
    let per_axis = quality.samples_per_axis();
    let styled = prep.lights.bounce.styled;
    let spare = Mutex::new(Vec::new());
    faces
        .par_iter()
        // Small batches, so neither thread is left with a long run of faces while the other has
        // none; each batch borrows a thread's scratch, grown by the faces before it.
        .with_max_len(FACES_PER_BATCH)
        .map_init(
            || Lease::take(&spare),
            |reuse, &f| {
                let geom = &prep.faces[f];
                let (mut samples, placement) = face_samples(geom, per_axis, bsp);
                if let Some(normals) = phong::sample_normals(&samples, &prep.faces, &prep.phong) {
                    samples.normals = normals;
                }
                let rules = face_rules(&prep.lights, geom);
                let (light, counts) = trace_face(setup, &samples, &rules, &mut reuse.scratch);
                progress.advance(1);
                let reflects = keep.bouncing && keep.reflectance[f].is_some();
                let reflected = reflects.then(|| light.reflected(styled));
                // Only a later pass reads what a face passes on.
                let passed_on = (reflects && prep.lights.bounce.passes > 1)
                    .then(|| light.passed_on())
                    .flatten();
                let light = keep.wanted[f].then(|| match keep.finish {
                    Some(to_luxels) if geom.model == 0 => TracedLight::Luxels(light.finish(
                        &[],
                        HiddenLuxels::FromNeighbours,
                        to_luxels,
                    )),
                    _ => TracedLight::Samples(Box::new(light)),
                });
                Traced {
                    face: f,
                    light,
                    receivers: keep
                        .bouncing
                        .then(|| Box::new(Receivers::new(&samples, geom))),
                    reflected,
                    passed_on,
                    placement,
                    counts,
                    sample_count: samples.points.len() as u64,
                    samples: (keep.samples && keep.wanted[f]).then(|| Box::new(samples)),
                }
            },
        )
        .collect()
}

/// The most faces a thread traces before it may take more (see [`trace_faces`]).
const FACES_PER_BATCH: usize = 32;

/// A [`TraceScratch`] lent to one batch of faces, given back to `spare` when the batch is done.
struct Lease<'a> {
    scratch: TraceScratch,
    spare: &'a Mutex<Vec<TraceScratch>>,
}

impl<'a> Lease<'a> {
    fn take(spare: &'a Mutex<Vec<TraceScratch>>) -> Lease<'a> {
        let scratch = lock(spare).pop().unwrap_or_default();
        Lease { scratch, spare }
    }
}

impl Drop for Lease<'_> {
    fn drop(&mut self) {
        lock(self.spare).push(std::mem::take(&mut self.scratch));
    }
}

/// How [`bounce_light`] gathers, and where it counts the faces it has done.
struct Gathering<'p> {
    /// The reference's: at every sample of the faces it measures.
    reference: bool,
    /// Where and how densely the surface gather's receivers are (`-emissivequality high`, and
    /// the reference's passes for the next pass).
    density: Density,
    progress: &'p Progress,
}

/// Bounced light per face (by index; per luxel, or per sample for the reference), `passes`
/// passes of it, gathered as `gathering` says. `traced` is the direct light of every lit face;
/// for the reference, `field` is the same at `--extra4` (the reference's emitters) and bounce is
/// gathered at the samples of `traced` by [`bounce::reference::gather`] (the light a pass
/// brings to the faces of `field`, for the next pass, at its density).
fn bounce_light(
    prep: &Prepared,
    reflectance: &[Option<[f32; 3]>],
    (traced, field): (&[Traced], &[Traced]),
    centres: &[ModelCentre],
    gathering: Gathering,
    counts: &mut BounceCounts,
) -> (Vec<StyleLuxels>, Vec<StyleLight>) {
    let Gathering {
        reference,
        density,
        progress,
    } = gathering;
    let settings = prep.lights.bounce;
    let n = prep.faces.len();
    let mut light: Vec<Option<StyleLuxels>> = vec![None; n];
    let mut shares: Vec<Option<&[f32]>> = vec![None; n];
    for t in field {
        light[t.face] = t.reflected.clone().filter(|r| !r.is_empty());
        shares[t.face] = t.passed_on.as_deref();
    }
    let mut total: Vec<StyleLuxels> = vec![Vec::new(); n];
    let mut at_centres: Vec<StyleLight> = vec![Vec::new(); centres.len()];
    for pass in 1..=settings.passes {
        let last = pass == settings.passes;
        let emitting = Field::new(&prep.faces, reflectance, &light, &settings);
        let emission = match settings.emission {
            EmissiveQuality::Medium => Emission::MiddleAndCorners,
            EmissiveQuality::Low => Emission::Middle,
            EmissiveQuality::High => Emission::Diced(settings.subdivision),
        };
        // Faces gather from points at `low` and `medium`; the reference's passes stay with the
        // surfaces' physics. Brush models' middles take what the points send whatever the faces
        // gather from: ericw-tools' light grid takes points (at `high`, the middles of each face's
        // diced pieces).
        let gathers_from_points = !reference && settings.emission != EmissiveQuality::High;
        let points = (gathers_from_points || !centres.is_empty())
            .then(|| PointField::new(&emitting, &prep.vis, emission));
        // Every pass's emitters light the brush models' centres too (ericw-tools' estimate of
        // a model's light includes bounced light).
        if let Some(points) = &points {
            let lit: Vec<(StyleLight, BounceCounts)> = centres
                .par_iter()
                .map(|c| {
                    let mut n = BounceCounts::default();
                    (points.light_at(&prep.scene, c.leaf, c.point, &mut n), n)
                })
                .collect();
            for (sum, (add, c)) in at_centres.iter_mut().zip(lit) {
                counts.add(&c);
                add_styles(sum, &add);
            }
        }
        if reference {
            // The reference gathers at every sample of the faces it measures.
            let at_samples = gather_faces(traced, |t, c| {
                let (samples, model) = (t.samples.as_deref()?, prep.faces[t.face].model);
                Some(bounce::reference::gather(
                    &emitting,
                    &prep.scene,
                    samples,
                    model,
                    pass,
                    c,
                ))
            });
            for (face, b, c) in at_samples {
                bounce::accumulate(&mut total[face], &b);
                counts.add(&c);
            }
            if last {
                break;
            }
        }
        // Wanted faces receive every pass (unless the reference measures them); reflecting ones
        // every pass but the last, for the next. Bounced light is on channel 1.
        let on_channel_1 = |t: &Traced| prep.lights.channels_of(&prep.faces[t.face]) & 1 != 0;
        let receiving: Vec<&Traced> = field
            .iter()
            .filter(|t| (!reference && t.light.is_some()) || (!last && t.reflected.is_some()))
            .filter(|t| on_channel_1(t))
            .collect();
        let mut next: Vec<Option<StyleLuxels>> = vec![None; n];
        progress.start("bounce", receiving.len());
        let at_receivers = gather_faces(receiving.par_iter().copied(), |t, c| {
            let receivers = t.receivers.as_deref()?;
            progress.advance(1);
            if let Some(points) = points.as_ref().filter(|_| gathers_from_points) {
                return Some(points.gather_face(&prep.scene, receivers, c));
            }
            Some(emitting.gather_face(&prep.scene, receivers, pass, density, c))
        });
        progress.finish();
        for (face, b, c) in at_receivers {
            counts.add(&c);
            if !reference {
                bounce::accumulate(&mut total[face], &b);
            }
            if reflectance[face].is_some() && !b.is_empty() {
                next[face] = Some(passed_on(b, shares[face]));
            }
        }
        light = next;
    }
    (total, at_centres)
}

/// The part of a pass's bounced light `received` that a face reflects in the next: each
/// luxel's times its `share`.
fn passed_on(mut received: StyleLuxels, share: Option<&[f32]>) -> StyleLuxels {
    if let Some(share) = share {
        for (_, luxels) in &mut received {
            for (v, &f) in luxels.iter_mut().zip(share) {
                *v = v.map(|c| c * f);
            }
        }
    }
    received
}

/// One face's light gathered in one pass, and the work it took.
type Gathered = (usize, StyleLuxels, BounceCounts);

/// What `gather` brings each of `faces` (in parallel), for those it has a place for.
fn gather_faces<'t>(
    faces: impl IntoParallelIterator<Item = &'t Traced>,
    gather: impl Fn(&Traced, &mut BounceCounts) -> Option<StyleLuxels> + Sync + Send,
) -> Vec<Gathered> {
    faces
        .into_par_iter()
        .filter_map(|t| {
            let mut counts = BounceCounts::default();
            let light = gather(t, &mut counts)?;
            Some((t.face, light, counts))
        })
        .collect()
}

/// Converts `raw` to lightmap bytes.
pub fn finish_lighting(raw: &RawLighting) -> Lighting {
    let start = Instant::now();
    let outputs = raw.outputs;
    let finish = Finish {
        rangescale: raw.rangescale,
        gamma: raw.gamma,
        rgb: raw.coloured || outputs.rgb_lump,
        hdr: outputs.hdr(),
        directions: outputs.directions(),
    };
    let mut stats = raw.stats.clone();
    let (lightmaps, dropped): (Vec<_>, Vec<usize>) = raw
        .faces
        .par_iter()
        .enumerate()
        .map(
            |(i, light)| match raw.own_grids.get(i).and_then(Option::as_ref) {
                Some((own, grid)) => finish_face_on_own_grid(light, own, *grid, &finish),
                None => finish_face(light, &finish),
            },
        )
        .unzip();
    stats.faces_with_dropped_styles += dropped.iter().filter(|&&d| d > 0).count() as u64;
    stats.seconds_total += start.elapsed().as_secs_f64();
    Lighting {
        lightmaps,
        entity_text: raw.entity_text.clone(),
        coloured: raw.coloured,
        outputs,
        light_grid: raw.grid.as_ref().map(|g| finish_grid(g, &finish)),
        chosen_settings: raw.chosen_settings.clone(),
        warnings: raw.warnings.clone(),
        stats,
    }
}

/// The files beside a lit BSP its light asks for.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LightFiles {
    /// The `.lit`: the HDR one when `--hdr` asks for it, else the coloured one when the light is
    /// coloured and the grey lump is written (with `--novanilla`, `RGBLIGHTING` carries the
    /// colour). `None`: no `.lit` is needed.
    pub lit: Option<Vec<u8>>,
    /// Every luxel's colour as a `.lit` whatever the light (for `--lit`), when it was kept.
    pub rgb_lit: Option<Vec<u8>>,
    /// The `.lux` deluxemap, when `--lux` asks for it.
    pub lux: Option<Vec<u8>>,
}

/// Writes `lighting` into `bsp` (lighting lump and the BSPX lumps asked for, face styles and
/// offsets, entity styles) and returns the files to put beside it.
pub fn apply_lighting(bsp: &mut Bsp, lighting: &Lighting) -> LightFiles {
    let outputs = &lighting.outputs;
    let data = output::write_lighting(bsp, &lighting.lightmaps, outputs);
    if let Some(text) = &lighting.entity_text {
        bsp.set_entity_text(text);
    }
    match &lighting.light_grid {
        Some(grid) => bsp.set_light_grid(grid),
        None => bsp.remove_bspx_lump(LIGHTGRID_OCTREE),
    }
    let rgb_lit = data.rgb.as_deref().map(quake_formats::lit::write_lit);
    let hdr_lit = data
        .hdr
        .as_deref()
        .filter(|_| outputs.hdr_file)
        .map(quake_formats::lit::write_hdr_lit);
    let coloured_lit = rgb_lit
        .clone()
        .filter(|_| lighting.coloured && outputs.grey_lump);
    LightFiles {
        lit: hdr_lit.or(coloured_lit),
        rgb_lit,
        lux: data
            .directions
            .as_deref()
            .filter(|_| outputs.lux_file)
            .map(quake_formats::lit::write_lux),
    }
}

/// `--onlyents`: gives switchable lights and shadows their styles in the entity lump (the lump
/// `slipgate bsp --onlyents` just replaced) without relighting; the lightmaps stay as they are.
/// Returns how many switchable styles were given out.
///
/// # Errors
/// An entity lump that does not parse, or more switchable lights than styles.
pub fn update_entities_only(bsp: &mut Bsp) -> Result<usize, LightError> {
    let mut entities = parse_entities(&bsp.entity_text())?;
    // Keys that do not read are told when the map is lit; here only styles are given out.
    let world = entities.iter().position(|e| e.classname() == "worldspawn");
    let world = world.map(|index| World {
        index,
        entity: &entities[index],
    });
    let range = StyleRange::of(&Settings::resolve(world, &Overrides::default()).0);
    let assigned = assign_switchable_styles(&mut entities, range, &mut Vec::new())?;
    if assigned.count > 0 {
        bsp.set_entity_text(&write_entities(&entities));
    }
    Ok(assigned.count)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What is handed to a worker to free is freed once the wait returns.
    #[test]
    fn waiting_for_background_frees_sees_them_done() {
        use std::sync::Arc;
        use std::sync::atomic::{AtomicUsize, Ordering};
        struct Counted(Arc<AtomicUsize>);
        impl Drop for Counted {
            fn drop(&mut self) {
                // Slow enough that the wait would see it pending.
                std::thread::sleep(std::time::Duration::from_millis(20));
                self.0.fetch_add(1, Ordering::SeqCst);
            }
        }
        let freed = Arc::new(AtomicUsize::new(0));
        for _ in 0..3 {
            drop_in_background(Counted(Arc::clone(&freed)));
        }
        wait_for_background_frees();
        assert_eq!(freed.load(Ordering::SeqCst), 3);
    }

    /// A batch's scratch goes back to the spares when the batch is done, for the next batch to
    /// take; batches at once each get one of their own.
    #[test]
    fn leased_scratch_is_given_back_and_taken_again() {
        let spare = Mutex::new(Vec::new());
        {
            let first = Lease::take(&spare);
            let second = Lease::take(&spare);
            assert!(spare.lock().unwrap().is_empty());
            drop(second);
            assert_eq!(spare.lock().unwrap().len(), 1);
            drop(first);
        }
        assert_eq!(spare.lock().unwrap().len(), 2);
        let _again = Lease::take(&spare);
        assert_eq!(spare.lock().unwrap().len(), 1);
    }
}
