//! Switchable styles, given out from worldspawn's `_compilerstyle_start` (32) up to below its
//! `_compilerstyle_max` (64, the light styles most engines keep) and written into the entities
//! so the game's switching code finds them:
//!
//! - a light with a `targetname` and no `style` of its own gets a style (lights sharing a name
//!   share it), written as its `style`;
//! - a brush model with `_switchableshadow 1` gets one too (shared with every light and model of
//!   its `targetname`; a model without one gets a style of its own), written as
//!   `switchshadstyle`: the light of style 0 its shadow blocks goes on that style, which the game
//!   turns off to show the shadow and on to hide it;
//! - a light with `_switchableshadow_target T` lights nothing itself; the brush models named `T`
//!   cast such a shadow on the light's own style.

use quake_formats::entities::Entity;

use super::entities::style;
use super::keys::{self, Keys};
use super::models::model_index;
use crate::error::LightError;
use crate::settings::SettingWarning;

/// The styles switchable lights and shadows are given: `first` up to below `end`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StyleRange {
    pub first: usize,
    pub end: usize,
}

impl StyleRange {
    /// The range worldspawn's `_compilerstyle_start` and `_compilerstyle_max` give, never past
    /// the last style a BSP can name.
    pub fn of(settings: &crate::settings::Settings) -> StyleRange {
        let last = usize::from(quake_formats::bsp::limits::MAX_LIGHTSTYLE);
        StyleRange {
            first: settings.compilerstyle_start.min(last),
            end: settings.compilerstyle_max.min(last + 1),
        }
    }
}

/// The styles [`assign_switchable_styles`] gave out.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SwitchableStyles {
    /// Each `targetname` that got a style, and the style.
    pub names: Vec<(String, u8)>,
    /// Brush models whose shadow is switchable, and its style.
    pub shadows: Vec<(usize, u8)>,
    /// Styles given out in all (names and models without one).
    pub count: usize,
}

impl SwitchableStyles {
    /// The style of `name` (a new one of `range` for a name not seen yet; a new one every time
    /// for none).
    fn style_for(&mut self, name: Option<&str>, range: StyleRange) -> Result<u8, LightError> {
        if let Some(&(_, s)) = name.and_then(|n| self.names.iter().find(|(m, _)| m == n)) {
            return Ok(s);
        }
        let s = (range.first + self.count < range.end)
            .then(|| u8::try_from(range.first + self.count).ok())
            .flatten()
            .ok_or(LightError::TooManySwitchableLights {
                first: range.first,
                last: range.end.saturating_sub(1),
            })?;
        self.count += 1;
        if let Some(n) = name {
            self.names.push((n.to_string(), s));
        }
        Ok(s)
    }
}

/// Gives out the switchable styles of lights and switchable shadows from `range` (see the
/// module comment) and writes them into the entities; the keys not taken as written are warned
/// about into `warnings`.
///
/// # Errors
/// More switchable names than styles.
pub fn assign_switchable_styles(
    entities: &mut [Entity],
    range: StyleRange,
    warnings: &mut Vec<SettingWarning>,
) -> Result<SwitchableStyles, LightError> {
    let mut out = SwitchableStyles::default();
    let is_light = |e: &Entity| e.classname().starts_with("light") && model_index(e).is_none();
    let name_of = |e: &Entity| Keys::new(e, 0).text(&keys::TARGETNAME).map(String::from);
    for (index, e) in entities.iter_mut().enumerate() {
        let Some(name) = name_of(e).filter(|_| is_light(e)) else {
            continue;
        };
        // Warnings about `style` come when the lights are read.
        if style(&Keys::new(e, index)) == 0 {
            let style = out.style_for(Some(&name), range)?;
            e.set("style", style.to_string());
        }
    }
    for (index, e) in entities.iter_mut().enumerate() {
        let Some(model) = model_index(e).filter(|&m| m > 0) else {
            continue;
        };
        let k = Keys::new(e, index);
        let switchable = k.number(&keys::SWITCHABLESHADOW) == Some(1.0);
        warnings.extend(k.into_warnings());
        if switchable {
            let style = out.style_for(name_of(e).as_deref(), range)?;
            e.set("switchshadstyle", style.to_string());
            out.shadows.push((model, style));
        }
    }
    for index in 0..entities.len() {
        let e = &entities[index];
        let Some(target) = Keys::new(e, index).text(&keys::SWITCHABLESHADOW_TARGET) else {
            continue;
        };
        if !is_light(e) {
            continue;
        }
        let target = target.to_string();
        let style = match style(&Keys::new(e, index)) {
            0 => {
                let style = out.style_for(None, range)?;
                entities[index].set("style", style.to_string());
                style
            }
            s => s,
        };
        for e in entities.iter() {
            let Some(model) = model_index(e).filter(|&m| m > 0) else {
                continue;
            };
            let named = e.get("targetname") == Some(target.as_str());
            if named && !out.shadows.iter().any(|&(m, _)| m == model) {
                out.shadows.push((model, style));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::entities::parse_entities;

    #[test]
    fn shadows_share_their_targetname_s_style_and_targets_take_the_light_s() {
        let text = r#"
{ "classname" "worldspawn" }
{ "classname" "light" "origin" "0 0 0" "targetname" "door" }
{ "classname" "func_door" "model" "*1" "targetname" "door" "_switchableshadow" "1" }
{ "classname" "func_wall" "model" "*2" "_switchableshadow" "1" }
{ "classname" "func_door" "model" "*3" "targetname" "gate" }
{ "classname" "light" "origin" "0 0 0" "targetname" "gate_light" "_switchableshadow_target" "gate" }
{ "classname" "light" "origin" "0 0 0" "_switchableshadow_target" "gate" }
"#;
        let mut ents = parse_entities(text).expect("parse");
        let range = StyleRange::of(&crate::settings::Settings::default());
        let styles = assign_switchable_styles(&mut ents, range, &mut Vec::new()).expect("styles");
        assert_eq!(ents[1].get("style"), Some("32"));
        assert_eq!(ents[2].get("switchshadstyle"), Some("32"), "shares door's");
        assert_eq!(
            ents[3].get("switchshadstyle"),
            Some("34"),
            "unnamed: its own"
        );
        assert_eq!(ents[5].get("style"), Some("33"));
        assert_eq!(
            ents[6].get("style"),
            Some("35"),
            "a target light without a name"
        );
        // The gate takes the first target light's style; the second finds it taken.
        assert_eq!(styles.shadows, vec![(1, 32), (2, 34), (3, 33)]);
        assert_eq!(styles.count, 4);
    }

    /// Styles go from worldspawn's `_compilerstyle_start` to below its `_compilerstyle_max`
    /// (32 and 64: most engines keep 64 styles); one more switchable name than fits is an
    /// error naming the range, as ericw-tools refuses it.
    #[test]
    fn styles_stay_in_the_compiler_style_range() {
        let lights = |n: usize| {
            (0..n)
                .map(|i| format!("{{ \"classname\" \"light\" \"targetname\" \"t{i}\" }}\n"))
                .collect::<String>()
        };
        let default = StyleRange::of(&crate::settings::Settings::default());
        assert_eq!(default, StyleRange { first: 32, end: 64 });
        let mut ents = parse_entities(&lights(32)).expect("parse");
        let styles = assign_switchable_styles(&mut ents, default, &mut Vec::new()).expect("fit");
        assert_eq!(styles.count, 32);
        assert_eq!(ents[31].get("style"), Some("63"));
        let mut ents = parse_entities(&lights(33)).expect("parse");
        let err = assign_switchable_styles(&mut ents, default, &mut Vec::new()).expect_err("full");
        assert!(err.to_string().contains("32 to 63"), "{err}");
        let wide = StyleRange {
            first: 40,
            end: 255,
        };
        let mut ents = parse_entities(&lights(33)).expect("parse");
        let styles = assign_switchable_styles(&mut ents, wide, &mut Vec::new()).expect("fit");
        assert_eq!((styles.count, ents[0].get("style")), (33, Some("40")));
    }
}
