//! Light entities (`light*` classnames that are not brush models): point lights and
//! spotlights, `_deviance` copies, `_surface` templates, and the suns and sky domes of
//! `_sun 1`, `_sunlight2 1` and `_sunlight3 1`.

use std::collections::HashMap;

use glam::DVec3;
use quake_formats::entities::Entity;
use quake_formats::geom::DVec3Ext;

use super::keys::Keys;
use super::models::model_index;
use super::point::{DEFAULT_SPOT_ANGLE, Falloff, PointLight, Spot, split_light};
use super::sun::{SunLight, dome, spread};
use super::worldspawn::Global;
use super::{MapLights, SurfaceTemplate};
use crate::directions::mangle_to_vec;
use crate::dirt::DirtResponse;
use crate::error::LightError;
use crate::settings::{DirtToggle, SettingWarning, normalize_color};

/// `light` value of a light entity without one (or with `light 0`, as
/// ericw-tools treats it).
pub const DEFAULT_LIGHT: f64 = 300.0;

/// Lights a `_deviance` light is split into when `_samples` is absent.
pub const DEFAULT_DEVIANCE_SAMPLES: usize = 16;

/// Every light entity of `entities`, into `out` (in entity order).
///
/// # Errors
/// [`LightError::Entity`] for a key that does not read.
pub fn read_lights(
    entities: &[Entity],
    global: &Global,
    out: &mut MapLights,
) -> Result<(), LightError> {
    // Where spotlights aim with `target`.
    let origins: HashMap<&str, DVec3> = entities
        .iter()
        .filter_map(|e| {
            let [x, y, z] = e.get_floats::<3>("origin")?;
            Some((e.get("targetname")?, DVec3::new(x, y, z)))
        })
        .collect();
    for (index, e) in entities.iter().enumerate() {
        if model_index(e).is_some_and(|m| m > 0) || !e.classname().starts_with("light") {
            continue;
        }
        let k = Keys { entity: e, index };
        // A `_switchableshadow_target` light only lends its style to a shadow.
        let shadow_only = e
            .get("_switchableshadow_target")
            .is_some_and(|t| !t.is_empty());
        if shadow_only || k.float("_nostaticlight")? == Some(1.0) {
            continue;
        }
        if k.float("_nonudge")? == Some(1.0) {
            out.no_nudge.push(index);
        }
        read_light(&k, &origins, global, out)?;
    }
    Ok(())
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
    dirt: Option<DirtResponse>,
    deviance: f64,
}

/// One light entity, as a sun, domes, or point lights and templates.
fn read_light(
    k: &Keys,
    origins: &HashMap<&str, DVec3>,
    global: &Global,
    out: &mut MapLights,
) -> Result<(), LightError> {
    let c = common(k, origins, global, &mut out.warnings)?;
    let sun = SunLight {
        to_sun: DVec3::ZERO,
        light: c.light,
        color: c.color,
        style: c.style,
        anglescale: c.anglescale,
        dirt: c.dirt,
        directions: 1,
    };
    if k.float("_sun")? == Some(1.0) {
        let to_sun = -c.aim.unwrap_or(DVec3::new(0.0, 0.0, -1.0));
        let sun = SunLight { to_sun, ..sun };
        out.suns.extend(spread(sun, c.deviance, global.sunsamples));
        return Ok(());
    }
    let mut is_dome = false;
    for (key, upper) in [("_sunlight2", true), ("_sunlight3", false)] {
        if k.float(key)? == Some(1.0) {
            out.suns.extend(dome(sun.clone(), upper, global.sunsamples));
            is_dome = true;
        }
    }
    if is_dome {
        return Ok(());
    }
    point_light(k, c, global, out)
}

/// The keys every light entity reads; values out of range warn (into `warnings`) and take
/// the default.
fn common(
    k: &Keys,
    origins: &HashMap<&str, DVec3>,
    global: &Global,
    warnings: &mut Vec<SettingWarning>,
) -> Result<Common, LightError> {
    let origin = k.vec3("origin")?.unwrap_or(DVec3::ZERO);
    let (light, light_color) = brightness(k, warnings)?;
    // An explicit `_color` wins over the colour of Half-Life's `light` form.
    let color = match (k.vec3("_color")?, light_color) {
        (Some(c), _) => normalize_color(c),
        (None, Some(c)) => c,
        (None, None) => DVec3::ONE,
    };
    let style = k.style()?;
    let anglescale = match k.float_any(&["_anglescale", "_anglesense"])? {
        Some(a) if (0.0..=1.0).contains(&a) => a,
        Some(_) => {
            let key = if k.entity.get("_anglescale").is_some() {
                "_anglescale"
            } else {
                "_anglesense"
            };
            warnings.push(k.warning(key, "expected 0 to 1; the map's anglescale is used"));
            global.anglescale
        }
        None => global.anglescale,
    };
    let aim = match (k.vec3("mangle")?, k.entity.get("target")) {
        (Some(m), _) => Some(mangle_to_vec(m.x, m.y)),
        (None, Some(t)) => origins.get(t).and_then(|&to| (to - origin).normalized()),
        (None, None) => None,
    };
    let toggle = k
        .float("_dirt")?
        .map_or(DirtToggle::AsDirt, DirtToggle::of_number);
    // A light's own `_dirtscale` / `_dirtgain` (non-zero) win over the global ones.
    let response = DirtResponse {
        scale: k
            .float("_dirtscale")?
            .filter(|s| *s > 0.0)
            .unwrap_or(global.response.scale),
        gain: k
            .float("_dirtgain")?
            .filter(|g| *g > 0.0)
            .unwrap_or(global.response.gain),
    };
    Ok(Common {
        origin,
        light,
        color,
        style,
        anglescale,
        aim,
        dirt: global.dirt_with(toggle, response),
        deviance: k.float("_deviance")?.unwrap_or(0.0).max(0.0),
    })
}

/// `light`: a brightness, or Half-Life's `R G B I` (colour in 0..255 or 0..1, then brightness).
/// Absent or 0 is [`DEFAULT_LIGHT`]; another count of numbers warns and takes it too.
fn brightness(
    k: &Keys,
    warnings: &mut Vec<SettingWarning>,
) -> Result<(f64, Option<DVec3>), LightError> {
    let Some(text) = k.entity.get("light").filter(|t| !t.trim().is_empty()) else {
        return Ok((DEFAULT_LIGHT, None));
    };
    let numbers: Option<Vec<f64>> = text
        .split_whitespace()
        .map(|w| w.parse().ok().filter(|v: &f64| v.is_finite()))
        .collect();
    let or_default = |l: f64| if l == 0.0 { DEFAULT_LIGHT } else { l };
    match numbers.as_deref() {
        Some(&[l]) => Ok((or_default(l), None)),
        Some(&[r, g, b, l]) => Ok((or_default(l), Some(normalize_color(DVec3::new(r, g, b))))),
        Some(_) => {
            warnings.push(k.warning(
                "light",
                &format!("expected a brightness or R G B brightness; {DEFAULT_LIGHT} is used"),
            ));
            Ok((DEFAULT_LIGHT, None))
        }
        None => Err(k.bad("light", "numbers")),
    }
}

/// A point light or spotlight: one, `_samples` copies spread over its `_deviance`, or a
/// `_surface` template.
fn point_light(
    k: &Keys,
    c: Common,
    global: &Global,
    out: &mut MapLights,
) -> Result<(), LightError> {
    let delay = k.float("delay")?.unwrap_or(0.0);
    let falloff = Falloff::from_delay(delay as i64)
        .filter(|_| delay.fract() == 0.0)
        .unwrap_or_else(|| {
            let problem = "expected 0, 1, 2, 3, 4 or 5; linear falloff (0) is used";
            out.warnings.push(k.warning("delay", problem));
            Falloff::Linear
        });
    let wait = k.float("wait")?.filter(|w| *w > 0.0).unwrap_or(1.0);
    // `_falloff` (linear only): reaches zero exactly that many units out.
    let atten = match k.float("_falloff")?.filter(|f| *f > 0.0) {
        Some(reach) if falloff == Falloff::Linear => c.light.abs() / reach,
        _ => wait * global.scaledist,
    };
    let angle = k.float("angle")?.unwrap_or(DEFAULT_SPOT_ANGLE);
    let softangle = k.float("_softangle")?.unwrap_or(0.0);
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
        bounce: k.float("_bounce")?.is_none_or(|b| b > 0.0),
        entity: k.index,
    };
    match k.entity.get("_surface").filter(|t| !t.is_empty()) {
        Some(texture) => out.templates.push(SurfaceTemplate {
            texture: texture.to_string(),
            light: PointLight {
                spot: None,
                ..point
            },
            offset: k.float("_surface_offset")?.unwrap_or(2.0),
            spotlight: k.float("_surface_spotlight")? == Some(1.0),
            spot_angle: angle,
            group: k.float("_surflight_group")?.unwrap_or(0.0) as i64,
        }),
        None if c.deviance > 0.0 => {
            let count = k
                .float("_samples")?
                .filter(|n| *n >= 1.0)
                .map_or(DEFAULT_DEVIANCE_SAMPLES, |n| n as usize);
            out.points.extend(split_light(&point, c.deviance, count));
        }
        None => out.points.push(point),
    }
    Ok(())
}
