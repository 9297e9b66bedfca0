//! Brush models' lighting keys: which cast shadows (`_shadow`, `_shadowself`), which take no
//! dirt (`_dirt -1`), light (`_lightignore`) or reflect (`_bounce 0`), their own minlight and
//! lightmap spacing (`_world_units_per_luxel`), their `origin` offset, and `_phong` smoothing
//! and `_lmscale` (worldspawn's too, as model 0).

use quake_formats::bsp::phong;
use quake_formats::entities::Entity;

use super::MapLights;
use super::keys::Keys;
use super::worldspawn::Global;
use crate::error::LightError;

/// The brush model an entity names with its `model` key (`*N`), if any.
pub fn model_index(e: &Entity) -> Option<usize> {
    e.get("model")?.strip_prefix('*')?.parse().ok()
}

/// `_phong` and `_phong_angle` (into `out.phong`) and `_lmscale` (into `out.model_lmscale`) of
/// worldspawn (`world`, as model 0) and every brush model.
///
/// # Errors
/// [`LightError::Entity`] for a key that does not read as a number.
pub fn read_world_and_model_keys(
    entities: &[Entity],
    world: Option<usize>,
    out: &mut MapLights,
) -> Result<(), LightError> {
    for (index, e) in entities.iter().enumerate() {
        let model = if Some(index) == world {
            Some(0)
        } else {
            model_index(e).filter(|&m| m > 0)
        };
        if let Some(model) = model {
            let k = Keys { entity: e, index };
            if let Some(scale) = k.float("_lmscale")? {
                out.model_lmscale.insert(model, scale);
            }
            let keys = (k.float("_phong")?, k.float("_phong_angle")?);
            if let Some(angle) = phong::angle_from_keys(keys.0, keys.1) {
                out.phong.insert(model, angle);
            }
        }
    }
    Ok(())
}

/// The lighting keys of every brush model (not the world), into `out`.
///
/// # Errors
/// [`LightError::Entity`] for a key that does not read.
pub fn read_models(
    entities: &[Entity],
    global: &Global,
    out: &mut MapLights,
) -> Result<(), LightError> {
    for (index, e) in entities.iter().enumerate() {
        let Some(model) = model_index(e).filter(|&m| m > 0) else {
            continue;
        };
        let k = Keys { entity: e, index };
        if k.float("_shadow")?.unwrap_or(0.0) == 1.0 {
            out.shadow_models.push(model);
        }
        if k.float_any(&["_shadowself", "_selfshadow"])? == Some(1.0) {
            out.self_shadow_models.push(model);
        }
        if let Some(o) = k.vec3("origin")? {
            out.model_origins.insert(model, o);
        }
        if let Some(group) = k.float("_surflight_group")?.filter(|g| *g != 0.0) {
            out.surflight_groups.insert(model, group as i64);
        }
        if let Some(units) = k.float("_world_units_per_luxel")? {
            out.model_units_per_luxel.insert(model, units);
        }
        if k.float("_dirt")? == Some(-1.0) {
            out.no_dirt_models.push(model);
        }
        if k.float("_lightignore")? == Some(1.0) {
            out.lightignore_models.push(model);
        }
        if k.float("_bounce")?.is_some_and(|b| b <= 0.0) {
            out.no_bounce_models.push(model);
        }
        if let Some(level) = k.float("_minlight")?.filter(|m| *m != 0.0) {
            let color = k.color_any(&["_minlight_color", "_mincolor"])?;
            let exclude = e.get("_minlight_exclude").map(str::to_string);
            out.minlight
                .insert(model, global.minlight(level, color, exclude));
        }
    }
    Ok(())
}
