//! Brush models' lighting keys: which cast shadows (`_shadow`, `_shadowself`), their light
//! channels (`_object_channel_mask`), which take no
//! dirt (`_dirt -1`), light (`_lightignore`) or reflect (`_bounce 0`), their own minlight and
//! lightmap spacing (`_world_units_per_luxel`), their `origin` offset, and `_phong` smoothing
//! and `_lmscale` (worldspawn's too, as model 0). The same keys of entities merged into the world
//! (`func_detail*`, `func_group`) come per face, from what the compiler recorded in the BSP.

use quake_formats::Bsp;
use quake_formats::bsp::phong;
use quake_formats::entities::Entity;

use glam::DVec3;

use super::keys::{self, Keys};
use super::worldspawn::Global;
use super::{AutoMinlight, MapLights};

/// The brush model an entity names with its `model` key (`*N`), if any.
pub fn model_index(e: &Entity) -> Option<usize> {
    e.get("model")?.strip_prefix('*')?.parse().ok()
}

/// `_phong`, `_phong_angle` and `_phong_angle_concave` (into `out.phong`), `_lmscale` (into
/// `out.model_lmscale`) and `_lightcolorscale` (into `out.model_lightcolorscale`) of worldspawn
/// (`world`, as model 0) and every brush model, with a warning for each key not taken as
/// written.
pub fn read_world_and_model_keys(entities: &[Entity], world: Option<usize>, out: &mut MapLights) {
    for (index, e) in entities.iter().enumerate() {
        let model = if Some(index) == world {
            Some(0)
        } else {
            model_index(e).filter(|&m| m > 0)
        };
        let Some(model) = model else {
            continue;
        };
        let k = Keys::new(e, index);
        if let Some(scale) = k.number(&keys::LMSCALE) {
            out.model_lmscale.insert(model, scale);
        }
        if let Some(scale) = k.number(&keys::LIGHTCOLORSCALE).filter(|s| *s != 1.0) {
            out.model_lightcolorscale.insert(model, scale);
        }
        let phong = (k.number(&keys::PHONG), k.number(&keys::PHONG_ANGLE));
        if let Some(angle) = phong::angle_from_keys(phong.0, phong.1) {
            let concave = phong::concave_from_key(k.number(&keys::PHONG_ANGLE_CONCAVE));
            let angles = crate::phong::PhongAngles {
                angle,
                concave: f64::from(concave),
            };
            out.phong.insert(model, angles);
        }
        out.warnings.extend(k.into_warnings());
    }
}

/// The lighting keys of every brush model (not the world), into `out`, with a warning for each
/// key not taken as written.
pub fn read_models(entities: &[Entity], global: &Global, out: &mut MapLights) {
    let origins = super::entities::target_origins(entities);
    for (index, e) in entities.iter().enumerate() {
        let Some(model) = model_index(e).filter(|&m| m > 0) else {
            continue;
        };
        let k = Keys::new(e, index);
        if k.number(&keys::SHADOW) == Some(1.0) {
            out.shadow_models.push(model);
        }
        if k.number(&keys::SHADOWSELF) == Some(1.0) {
            out.self_shadow_models.push(model);
        }
        if k.number(&keys::SHADOWWORLDONLY) == Some(1.0) {
            out.world_shadow_models.push(model);
        }
        match super::entities::channel_mask(&k, &keys::OBJECT_CHANNEL_MASK) {
            Some(mask) if mask != 1 => out.channel_models.push((model, mask)),
            _ => {}
        }
        if let Some(o) = k.vector(&keys::MODEL_ORIGIN) {
            out.model_origins.insert(model, o);
        }
        if let Some(group) = k.whole(&keys::SURFLIGHT_GROUP).filter(|g| *g != 0) {
            out.surflight_groups.insert(model, group);
        }
        if let Some(units) = k.number(&keys::WORLD_UNITS_PER_LUXEL) {
            out.model_units_per_luxel.insert(model, units);
        }
        if k.number(&keys::DIRT) == Some(-1.0) {
            out.no_dirt_models.push(model);
        }
        if k.switch(&keys::LIGHTIGNORE) == Some(true) {
            out.lightignore_models.push(model);
        }
        match k.number(&keys::AUTOMINLIGHT) {
            Some(v) if v < 0.0 => {
                out.autominlight.insert(model, AutoMinlight::Off);
            }
            Some(v) if v > 0.0 => {
                out.autominlight.insert(model, AutoMinlight::Everywhere);
            }
            _ => {}
        }
        if let Some(at) = k
            .text(&keys::AUTOMINLIGHT_TARGET)
            .and_then(|t| origins.get(t))
        {
            out.autominlight_at.insert(model, *at);
        }
        if k.number(&keys::BOUNCE).is_some_and(|b| b <= 0.0) {
            out.no_bounce_models.push(model);
        }
        if let Some(level) = k.number(&keys::MAXLIGHT).filter(|m| *m > 0.0) {
            out.model_maxlight.insert(model, level);
        }
        if let Some(mottle) = k.switch(&keys::MINLIGHT_MOTTLE) {
            out.model_minlight_mottle.insert(model, mottle);
        }
        if let Some(level) = k.number(&keys::MINLIGHT).filter(|m| *m != 0.0) {
            let color = k.color(&keys::MINLIGHT_COLOR).unwrap_or(DVec3::ONE);
            let exclude = k.text(&keys::MINLIGHT_EXCLUDE).map(str::to_string);
            out.minlight
                .insert(model, global.minlight(level, color, exclude));
        }
        out.warnings.extend(k.into_warnings());
    }
}

/// What the compiler recorded in `bsp` of the keys of entities merged into the world, per face:
/// their flags (`_dirt -1`, `_bounce 0`, `_lightignore 1`, `_minlight_exclude`, `_shadow`),
/// their own minlight, light channels, `_maxlight` and `_lightcolorscale`, into `out`.
///
/// # Errors
/// A damaged lump of those keys.
pub fn read_merged_faces(
    bsp: &Bsp,
    global: &Global,
    out: &mut MapLights,
) -> Result<(), quake_formats::FormatError> {
    out.face_flags = bsp.face_flags()?.unwrap_or_default();
    out.face_channels = bsp.face_channels()?.unwrap_or_default();
    out.face_tones = bsp.face_tones()?.unwrap_or_default();
    for (face, m) in bsp.face_minlights()?.unwrap_or_default().iter().enumerate() {
        if m.level != 0.0 {
            let color = DVec3::from(m.color.map(f64::from));
            let minlight = global.minlight(f64::from(m.level), color, None);
            out.face_minlight.insert(face, minlight);
        }
    }
    Ok(())
}
