//! Everything built before tracing: faces, the shadow scene, the PVS, the lights (with
//! `_surface` copies and their leaves) and `_phong` normals, and the rules each face takes.

use std::sync::Arc;

use glam::DVec3;
use quake_formats::Bsp;
use quake_formats::entities::{Entity, parse_entities, write_entities};
use quake_formats::geom::Bounds;
use quake_formats::palette::Palette;

use crate::embree::Device;
use crate::error::LightError;
use crate::faces::{
    FaceGeom, FaceKind, attach_continuations, continuations, unlinked_face_geometry,
};
use crate::fence::fence_masks;
use crate::hull;
use crate::lights::projection::Projector;
use crate::lights::{MapLights, PointLight, parse_lights};
use crate::nudge;
use crate::options::Options;
use crate::phong;
use crate::reach::LightReaches;
use crate::scene::{Casters, TraceScene};
use crate::settings::{Given, SettingWarning, Settings};
use crate::surface;
use crate::trace::{FaceRules, TraceSetup};
use crate::visibility::Visibility;

/// Everything built before tracing, reusable by later passes and benchmarks.
pub struct Prepared {
    /// Every face as geometry.
    pub faces: Vec<FaceGeom>,
    /// The shadow scene.
    pub scene: TraceScene,
    /// The PVS, for culling.
    pub vis: Visibility,
    /// What the entity lump says about light.
    pub lights: MapLights,
    /// Entity lights followed by surface-light copies.
    pub point_lights: Vec<PointLight>,
    /// Each point light's world leaf (`None`: in solid or outside).
    pub light_leafs: Vec<Option<u32>>,
    /// Length of sun rays (longer than the map's diagonal).
    pub sun_distance: f32,
    /// How many of `point_lights` are surface-light copies.
    pub surface_lights: usize,
    /// Lights moved out of solid ([`nudge`]).
    pub lights_nudged: usize,
    /// The entity lump with switchable lights' styles (`None`: unchanged).
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
        light_reaches: &'a LightReaches,
        gate: f64,
        cull: bool,
        adaptive: bool,
    ) -> TraceSetup<'a> {
        let directions = crate::output::Outputs::from_settings(&self.lights.settings).directions();
        TraceSetup {
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
            directions,
            raw_light_read: directions || self.lights.bounce.is_on(),
            faint_budget: if adaptive {
                faint_budget(&self.lights.settings)
            } else {
                0.0
            },
        }
    }
}

/// Lightmap levels by which the probes of a face's faint lights may misjudge a sample,
/// together: half a level, so no byte moves by more than one.
const FAINT_LEVELS: f64 = 0.5;

/// [`TraceSetup::faint_budget`] for the map's settings: [`FAINT_LEVELS`] in light units; none
/// under a gamma, which raises faint light steeply.
fn faint_budget(settings: &Settings) -> f64 {
    if settings.gamma != 1.0 || settings.range <= 0.0 {
        0.0
    } else {
        FAINT_LEVELS / settings.range
    }
}

/// The solid (from the BSP's tree, world space) of each model of `shadow_models` without a lit
/// face: a model of `skip` brushes casts its shadow from its brushes.
fn faceless_solids(
    bsp: &Bsp,
    faces: &[FaceGeom],
    shadow_models: &[usize],
    origin_of: impl Fn(usize) -> DVec3,
) -> Vec<Vec<DVec3>> {
    let faceless = |m: usize| {
        !faces
            .iter()
            .any(|f| f.model == m && f.kind == FaceKind::Lit)
    };
    let mut out = Vec::new();
    for &m in shadow_models.iter().filter(|&&m| faceless(m)) {
        let offset = origin_of(m);
        for polygon in hull::solid_polygons(bsp, m) {
            out.push(polygon.into_iter().map(|p| p + offset).collect());
        }
    }
    out
}

/// A `_suntexture` the BSP has no texture of filters nothing (as in ericw-tools): each sun
/// naming one shines through every sky face, with a warning naming its entity.
fn drop_unknown_sun_textures(bsp: &Bsp, entities: &[Entity], lights: &mut MapLights) {
    let known = |name: &str| {
        bsp.textures
            .textures
            .iter()
            .flatten()
            .any(|t| t.name().eq_ignore_ascii_case(name))
    };
    let key = "_suntexture";
    let named_by_a_sun = |name: &str| {
        lights
            .suns
            .iter()
            .any(|s| s.sky_texture.as_deref() == Some(name))
    };
    for (index, e) in entities.iter().enumerate() {
        match e.get(key) {
            Some(name) if named_by_a_sun(name) && !known(name) => {
                lights.warnings.push(SettingWarning {
                    given: Given::key(index, e, key),
                    value: name.to_string(),
                    problem: "the map has no such texture; the sun shines through every sky face"
                        .to_string(),
                });
            }
            _ => {}
        }
    }
    for sun in &mut lights.suns {
        if sun.sky_texture.as_deref().is_some_and(|name| !known(name)) {
            sun.sky_texture = None;
        }
    }
}

/// Gives each light whose entity projects a picture its [`Projector`]; a picture the BSP has
/// no pixels of is a warning naming the entity, and the light shines unprojected (as in
/// ericw-tools).
fn attach_projections(bsp: &Bsp, entities: &[Entity], palette: &Palette, lights: &mut MapLights) {
    for keys in std::mem::take(&mut lights.projections) {
        let texture = bsp
            .textures
            .textures
            .iter()
            .flatten()
            .find(|t| t.name().eq_ignore_ascii_case(&keys.texture));
        match texture.and_then(|t| Projector::new(&keys, t, palette)) {
            Some(projector) => {
                let projector = Arc::new(projector);
                for light in lights.points.iter_mut().filter(|l| l.entity == keys.entity) {
                    light.projector = Some(Arc::clone(&projector));
                }
            }
            None => {
                let Some(e) = entities.get(keys.entity) else {
                    continue;
                };
                lights.warnings.push(SettingWarning {
                    given: Given::key(keys.entity, e, "_project_texture"),
                    value: keys.texture.clone(),
                    problem: "the BSP holds no pixels of that texture; the light is not projected"
                        .to_string(),
                });
            }
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
    let mut map_lights = parse_lights(&mut entities, &options.overrides)?;
    map_lights
        .read_merged_faces(bsp)
        .map_err(LightError::BspxLump)?;
    let entity_text = (map_lights.switchable.count > 0).then(|| write_entities(&entities));
    drop_unknown_sun_textures(bsp, &entities, &mut map_lights);
    let palette = options.palette.clone().unwrap_or_else(Palette::slipgate);
    attach_projections(bsp, &entities, &palette, &mut map_lights);
    let origin_of = |m: usize| {
        map_lights
            .model_origins
            .get(&m)
            .copied()
            .unwrap_or(DVec3::ZERO)
    };
    let mut faces = unlinked_face_geometry(bsp, origin_of, |m| map_lights.spacing(m))?;
    let solids = faceless_solids(bsp, &faces, &map_lights.shadow_models, origin_of);
    let shadowless: Vec<bool> = map_lights.face_flags.iter().map(|f| f.no_shadow).collect();
    let fences = fence_masks(bsp, &faces);
    let face_channels = map_lights.face_channel_masks(&faces);
    let casters = Casters {
        shadowless: &shadowless,
        models: &map_lights.shadow_models,
        self_shadow_models: &map_lights.self_shadow_models,
        world_shadow_models: &map_lights.world_shadow_models,
        solids: &solids,
        switchable: &map_lights.switchable.shadows,
        fences: &fences,
        channels: &face_channels,
    };
    let lump = bsp.phong_faces().map_err(LightError::BspxLump)?;
    let groups = phong::groups(&faces, &map_lights.phong, lump.as_deref());
    // Bounce's and dirt's rays may go through an unsealed copy of the shared faces; the
    // reference traces every ray against the sealed scene.
    let unsealed = (map_lights.bounce.is_on() || map_lights.uses_dirt())
        && options.quality != crate::quality::Quality::Reference;
    // Embree builds its tree on its own threads while ours link the faces, the longer job; the
    // visibility tables are read while they link.
    let ((scene, vis), links) = rayon::join(
        || {
            let for_suns = !map_lights.suns.is_empty();
            let scene = TraceScene::build(&device, &faces, &casters, unsealed, for_suns);
            (scene, Visibility::new(bsp, &faces))
        },
        || continuations(&faces, |f, g| groups.smooths(f, g)),
    );
    let scene = scene?;
    attach_continuations(&mut faces, links);
    let phong = phong::corner_normals(&faces, &groups);
    let in_liquid = |p: DVec3| {
        let leaf = bsp.leaf_at(p.as_vec3().to_array());
        leaf.and_then(|l| bsp.leafs.get(l))
            .is_some_and(|l| quake_formats::bsp::contents::is_liquid(l.contents))
    };
    let recorded_groups = bsp.surflight_groups().map_err(LightError::BspxLump)?;
    let groups = surface::SurfaceGroups {
        models: &map_lights.surflight_groups,
        faces: recorded_groups.as_deref(),
    };
    let surface = surface::expand_templates(
        &map_lights.templates,
        &faces,
        groups,
        map_lights.settings.surflight_subdivide,
        &in_liquid,
    );
    let surface_lights = surface.len();
    let mut point_lights = map_lights.points.clone();
    point_lights.extend(surface);
    let nudges = nudge::nudge_out_of_solid(bsp, &mut point_lights, &map_lights.no_nudge);
    for &entity in &nudges.stuck {
        let Some(e) = entities.get(entity) else {
            continue;
        };
        map_lights.warnings.push(SettingWarning {
            given: Given::key(entity, e, "origin"),
            value: e.get("origin").unwrap_or("").to_string(),
            problem: format!(
                "the light is in solid and no step of {} units frees it; it lights nothing",
                nudge::NUDGE
            ),
        });
    }
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
        lights_nudged: nudges.moved,
        entity_text,
        phong,
    })
}

/// The rules of the faces of brush model `model` (0 = world).
pub fn face_rules<'a>(lights: &'a MapLights, geom: &FaceGeom) -> FaceRules<'a> {
    let merged = lights
        .face_flags
        .get(geom.index)
        .copied()
        .unwrap_or_default();
    let tone = lights
        .face_tones
        .get(geom.index)
        .copied()
        .unwrap_or_default();
    // The face's own merged entity's `_minlight` wins, then its brush model's, then
    // worldspawn's.
    let minlight = lights
        .face_minlight
        .get(&geom.index)
        .or_else(|| lights.minlight.get(&geom.model))
        .or_else(|| lights.minlight.get(&0))
        .filter(|m| {
            !merged.no_minlight
                && m.exclude_texture
                    .as_ref()
                    .is_none_or(|t| !t.eq_ignore_ascii_case(&geom.texture))
        });
    // A liquid's surface takes no dirt, as in ericw-tools.
    let dirt = !merged.no_dirt
        && !lights.no_dirt_models.contains(&geom.model)
        && geom.kind != FaceKind::LitLiquid;
    FaceRules {
        minlight,
        minlight_mottle: (lights.model_minlight_mottle.get(&geom.model))
            .copied()
            .unwrap_or(lights.settings.minlight_mottle),
        dirt,
        minlight_only: merged.light_ignore || lights.lightignore_models.contains(&geom.model),
        channels: lights.channels_of(geom),
        // The face's own merged entity's keys win, then its brush model's, then worldspawn's.
        color_scale: tone.color_scale().or_else(|| {
            lights
                .model_lightcolorscale
                .get(&geom.model)
                .map(|&s| s as f32)
        }),
        maxlight: tone
            .maxlight()
            .map(f64::from)
            .or_else(|| lights.model_maxlight.get(&geom.model).copied())
            .or(Some(lights.settings.maxlight))
            .filter(|&m| m > 0.0),
        bounce_dirt: lights.bounce.dirt.filter(|_| dirt && lights.bounce.is_on()),
    }
}
