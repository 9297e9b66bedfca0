//! Light entities (`light*` classnames that are not brush models): point lights and
//! spotlights, `_deviance` copies, `_surface` templates, and the suns and sky domes of
//! `_sun 1`, `_sunlight2 1` and `_sunlight3 1`.

use std::collections::HashMap;
use std::sync::Arc;

use glam::DVec3;
use quake_formats::entities::Entity;
use quake_formats::geom::DVec3Ext;

use super::keys::{self, Keys};
use super::models::model_index;
use super::point::{DEFAULT_SPOT_ANGLE, Falloff, PointLight, Spot, split_light};
use super::projection::{self, ProjectionKeys};
use super::sun::{SunLight, dome, spread};
use super::worldspawn::Global;
use super::{MapLights, SurfaceTemplate};
use crate::directions::mangle_to_vec;
use crate::dirt::DirtResponse;
use crate::settings::DirtToggle;

/// `light` value of a light entity without one.
pub const DEFAULT_LIGHT: f64 = 300.0;

/// Lights a `_deviance` light is split into when `_samples` is absent.
pub const DEFAULT_DEVIANCE_SAMPLES: usize = 16;

/// The most lights one `_deviance` light is split into: more adds nothing a lightmap byte shows
/// and only costs time and memory.
pub const MAX_DEVIANCE_SAMPLES: usize = 4096;

/// The `origin` of each entity with a `targetname`, by that name.
pub fn target_origins(entities: &[Entity]) -> HashMap<&str, DVec3> {
    entities
        .iter()
        .filter_map(|e| {
            let [x, y, z] = e.get_floats::<3>("origin")?;
            Some((e.get("targetname")?, DVec3::new(x, y, z)))
        })
        .collect()
}

/// Every light entity of `entities`, into `out` (in entity order), with a warning for each key
/// not taken as written.
pub fn read_lights(entities: &[Entity], global: &Global, out: &mut MapLights) {
    // Where spotlights aim with `target`.
    let origins = target_origins(entities);
    for (index, e) in entities.iter().enumerate() {
        if model_index(e).is_some_and(|m| m > 0) || !e.classname().starts_with("light") {
            continue;
        }
        let k = Keys::new(e, index);
        // A `_switchableshadow_target` light only lends its style to a shadow.
        let shadow_only = k.text(&keys::SWITCHABLESHADOW_TARGET).is_some();
        if !shadow_only && k.switch(&keys::NOSTATICLIGHT) != Some(true) {
            if k.switch(&keys::NONUDGE) == Some(true) {
                out.no_nudge.push(index);
            }
            read_light(&k, &origins, global, out);
        }
        out.warnings.extend(k.into_warnings());
    }
}

/// What every kind of light entity reads alike.
struct Common {
    origin: DVec3,
    light: f64,
    color: DVec3,
    style: u8,
    anglescale: f64,
    /// The direction a spotlight (or a `_sun` entity) shines in.
    aim: Option<DVec3>,
    /// How far the `target` it aims at is (`None`: aimed by `mangle`, or not at all).
    target_distance: Option<f64>,
    dirt: Option<DirtResponse>,
    deviance: f64,
}

/// One light entity, as a sun, domes, or point lights and templates.
fn read_light(k: &Keys, origins: &HashMap<&str, DVec3>, global: &Global, out: &mut MapLights) {
    let c = common(k, origins, global);
    if c.light == 0.0 {
        return;
    }
    let sun = SunLight {
        to_sun: DVec3::ZERO,
        light: c.light,
        color: c.color,
        style: c.style,
        anglescale: c.anglescale,
        dirt: c.dirt,
        directions: 1,
        sky_texture: k
            .text(&keys::SUNTEXTURE)
            .filter(|t| !t.is_empty())
            .map(Arc::from),
    };
    if k.switch(&keys::SUN) == Some(true) {
        let to_sun = -c.aim.unwrap_or(DVec3::new(0.0, 0.0, -1.0));
        let sun = SunLight { to_sun, ..sun };
        out.suns.extend(spread(sun, c.deviance, global.sunsamples));
        return;
    }
    let mut is_dome = false;
    for (key, upper) in [(&keys::SUNLIGHT2, true), (&keys::SUNLIGHT3, false)] {
        if k.switch(key) == Some(true) {
            out.suns.extend(dome(sun.clone(), upper, global.sunsamples));
            is_dome = true;
        }
    }
    if !is_dome {
        point_light(k, c, global, out);
    }
}

/// The keys every light entity reads; values out of range warn and take the default.
fn common(k: &Keys, origins: &HashMap<&str, DVec3>, global: &Global) -> Common {
    let origin = k.vector(&keys::ORIGIN).unwrap_or(DVec3::ZERO);
    let (light, light_color) = k.brightness();
    // A `light` of 0 (in either form) lights nothing, as in ericw-tools 2.0.
    let light = light.unwrap_or(DEFAULT_LIGHT);
    // An explicit `_color` wins over the colour of Half-Life's `light` form.
    let color = k.color(&keys::COLOR).or(light_color).unwrap_or(DVec3::ONE);
    let style = style(k);
    let anglescale = match k.number(&keys::ANGLESCALE) {
        Some(a) if (0.0..=1.0).contains(&a) => a,
        Some(_) => {
            let key = if k.entity.get("_anglescale").is_some() {
                "_anglescale"
            } else {
                "_anglesense"
            };
            k.warn(key, "expected 0 to 1; the map's anglescale is used");
            global.anglescale
        }
        None => global.anglescale,
    };
    let target = k.text(&keys::TARGET).and_then(|t| origins.get(t));
    let (aim, target_distance) = match (k.vector(&keys::MANGLE), target) {
        (Some(m), _) => (Some(mangle_to_vec(m.x, m.y)), None),
        (None, Some(&to)) => ((to - origin).normalized(), Some((to - origin).length())),
        (None, None) => (None, None),
    };
    let toggle = k
        .number(&keys::DIRT)
        .map_or(DirtToggle::AsDirt, DirtToggle::of_number);
    // A light's own `_dirtscale` / `_dirtgain` (non-zero) win over the global ones.
    let response = DirtResponse {
        scale: k
            .number(&keys::DIRTSCALE)
            .filter(|s| *s > 0.0)
            .unwrap_or(global.response.scale),
        gain: k
            .number(&keys::DIRTGAIN)
            .filter(|g| *g > 0.0)
            .unwrap_or(global.response.gain),
    };
    Common {
        origin,
        light,
        color,
        style,
        anglescale,
        aim,
        target_distance,
        dirt: global.dirt_with(toggle, response),
        deviance: k.number(&keys::DEVIANCE).unwrap_or(0.0).max(0.0),
    }
}

/// A light-channel mask key (`_light_channel_mask` and the like): its bits, `None` when unset;
/// a value outside 32 bits is a warning and `None`.
pub(super) fn channel_mask(k: &Keys, key: &keys::EntityKey) -> Option<u32> {
    let value = k.whole(key)?;
    u32::try_from(value).ok().or_else(|| {
        k.warn(key.names[0], "not a mask of 32 bits; the default is used");
        None
    })
}

/// `style`, held to the styles a lightmap can name (with a warning outside them).
pub(super) fn style(k: &Keys) -> u8 {
    let most = quake_formats::bsp::limits::MAX_LIGHTSTYLE;
    match k.whole(&keys::STYLE) {
        None => 0,
        Some(s) => u8::try_from(s)
            .ok()
            .filter(|s| *s <= most)
            .unwrap_or_else(|| {
                let held = if s < 0 { 0 } else { most };
                k.warn("style", &format!("outside 0–{most}; {held} is used"));
                held
            }),
    }
}

/// A point light or spotlight: one, `_samples` copies spread over its `_deviance`, or a
/// `_surface` template.
fn point_light(k: &Keys, c: Common, global: &Global, out: &mut MapLights) {
    let delay = k.whole(&keys::DELAY).unwrap_or(0);
    let Some(falloff) = Falloff::from_delay(delay) else {
        k.warn(
            "delay",
            "names no falloff (0 to 5); the light lights nothing, as in ericw-tools",
        );
        return;
    };
    let wait = k.number(&keys::WAIT).filter(|w| *w > 0.0).unwrap_or(1.0);
    let angle = k.number(&keys::ANGLE).unwrap_or(DEFAULT_SPOT_ANGLE);
    // `_spotlightautofalloff`: a targeted spotlight reaches just past its cone at the target.
    let auto_reach = c
        .target_distance
        .filter(|d| global.spotlight_autofalloff && *d > 0.0)
        .map(|d| {
            let cone = if angle > 0.0 {
                angle
            } else {
                DEFAULT_SPOT_ANGLE
            };
            d + d * (cone / 2.0).to_radians().tan()
        });
    // `_falloff` (linear only): reaches zero exactly that many units out.
    let reach = k.number(&keys::FALLOFF).filter(|f| *f > 0.0).or(auto_reach);
    let atten = match reach {
        Some(reach) if falloff == Falloff::Linear => c.light.abs() / reach,
        _ => wait * global.scaledist,
    };
    let softangle = k.number(&keys::SOFTANGLE).unwrap_or(0.0);
    let light_channels = channel_mask(k, &keys::LIGHT_CHANNEL_MASK).unwrap_or(1);
    let point = PointLight {
        origin: c.origin,
        light: c.light,
        atten,
        falloff,
        color: c.color,
        style: c.style,
        spot: c.aim.map(|dir| Spot::new(dir, angle, softangle)),
        anglescale: c.anglescale,
        dirt: c.dirt,
        bounce: if k.number(&keys::BOUNCE).is_none_or(|b| b > 0.0) {
            k.number(&keys::BOUNCESCALE)
                .map_or(1.0, |s| s.max(0.0) as f32)
        } else {
            0.0
        },
        light_channels,
        shadow_channels: channel_mask(k, &keys::SHADOW_CHANNEL_MASK).unwrap_or(light_channels),
        entity: k.index,
        projector: None,
    };
    let surface = k.text(&keys::SURFACE);
    if surface.is_none() {
        out.projections.extend(projection(k, c.origin));
    }
    match surface {
        // Surface lights are on channel 1, as in ericw-tools.
        Some(texture) => out.templates.push(SurfaceTemplate {
            texture: texture.to_string(),
            light: PointLight {
                spot: None,
                light_channels: 1,
                shadow_channels: 1,
                ..point
            },
            offset: k.number(&keys::SURFACE_OFFSET).unwrap_or(2.0),
            spotlight: k.switch(&keys::SURFACE_SPOTLIGHT) == Some(true),
            spot_angle: angle,
            group: k.whole(&keys::SURFLIGHT_GROUP).unwrap_or(0),
        }),
        None if c.deviance > 0.0 => {
            let count = match k.whole(&keys::SAMPLES) {
                Some(n) if n > MAX_DEVIANCE_SAMPLES as i64 => {
                    let problem = format!("more than {MAX_DEVIANCE_SAMPLES}; that many are used");
                    k.warn("_samples", &problem);
                    MAX_DEVIANCE_SAMPLES
                }
                Some(n) if n >= 1 => n as usize,
                _ => DEFAULT_DEVIANCE_SAMPLES,
            };
            out.points.extend(split_light(&point, c.deviance, count));
        }
        None => out.points.push(point),
    }
}

/// The picture a light projects (`_project_texture`), if it names one: its direction from
/// `_project_mangle`, else `mangle`, else the Half-Life `angles`; a field of view outside
/// 1–179 degrees is a warning and 90.
fn projection(k: &Keys, origin: DVec3) -> Option<ProjectionKeys> {
    let texture = k.text(&keys::PROJECT_TEXTURE).filter(|t| !t.is_empty())?;
    let angles = k
        .vector(&keys::PROJECT_MANGLE)
        .or_else(|| k.vector(&keys::MANGLE))
        .or_else(|| k.vector(&keys::ANGLES).map(|a| DVec3::new(a.y, -a.x, a.z)))
        .unwrap_or(DVec3::ZERO);
    let fov = match k.number(&keys::PROJECT_FOV) {
        Some(fov) if projection::FOV_RANGE.contains(&fov) => fov,
        Some(_) => {
            k.warn("_project_fov", "expected 1 to 179 degrees; 90 is used");
            projection::DEFAULT_FOV
        }
        None => projection::DEFAULT_FOV,
    };
    Some(ProjectionKeys {
        entity: k.index,
        origin,
        texture: texture.to_string(),
        angles,
        fov,
    })
}
