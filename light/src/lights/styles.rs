//! Switchable lights: a light with a `targetname` and no `style` of its own gets a style from
//! [`FIRST_SWITCHABLE_STYLE`] up (lights sharing a name share it), written into the entity so
//! the game's switching code finds it.

use quake_formats::entities::Entity;

use super::keys::Keys;
use crate::error::LightError;

/// Gives each `targetname` of a light entity without an explicit `style` its
/// own style from 32 up (lights sharing a name share it) and writes it into
/// the entity, so the game's switching code finds it.
pub fn assign_switchable_styles(entities: &mut [Entity]) -> Result<Vec<(String, u8)>, LightError> {
    let mut assigned: Vec<(String, u8)> = Vec::new();
    for (index, e) in entities.iter_mut().enumerate() {
        if !e.classname().starts_with("light") {
            continue;
        }
        let Some(name) = e.get("targetname").filter(|n| !n.is_empty()) else {
            continue;
        };
        let k = Keys { entity: e, index };
        if k.style()? != 0 {
            continue;
        }
        let style = match assigned.iter().find(|(n, _)| n == name) {
            Some(&(_, s)) => s,
            None => {
                let next = FIRST_SWITCHABLE_STYLE as usize + assigned.len();
                let s = u8::try_from(next)
                    .ok()
                    .filter(|s| *s <= quake_formats::bsp::limits::MAX_LIGHTSTYLE)
                    .ok_or(LightError::TooManySwitchableLights)?;
                assigned.push((name.to_string(), s));
                s
            }
        };
        e.set("style", style.to_string());
    }
    Ok(assigned)
}

/// First style given to switchable lights (styles below are the engine's
/// animated presets).
pub const FIRST_SWITCHABLE_STYLE: u8 = 32;
