//! ericw-tools' light keys that Slipgate's light does not implement. A map that sets one is lit
//! without it, with a warning naming the entity, its line and the key, so the difference is not
//! silent.

use quake_formats::entities::Entity;

use crate::settings::{Given, SettingWarning};

/// Which entities a key is read on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Where {
    Worldspawn,
    Lights,
    /// Brush entities, merged into the world or not.
    Brushes,
}

/// Each key, where ericw-tools reads it, and what it does there.
const UNSUPPORTED: &[(&str, Where, &str)] = &[(
    "_bouncelightsubdivision",
    Where::Worldspawn,
    "spacing of bounce emitters",
)];

/// A warning for each key of [`UNSUPPORTED`] an entity of `entities` sets where ericw-tools
/// reads it.
pub fn warnings(entities: &[Entity]) -> Vec<SettingWarning> {
    let mut out = Vec::new();
    for (index, e) in entities.iter().enumerate() {
        let classname = e.classname();
        let here = if classname == "worldspawn" {
            Where::Worldspawn
        } else if classname.starts_with("light") {
            Where::Lights
        } else {
            Where::Brushes
        };
        for &(key, place, what) in UNSUPPORTED {
            let Some(value) = e.get(key).filter(|v| !v.trim().is_empty()) else {
                continue;
            };
            if place == here {
                out.push(SettingWarning {
                    given: Given::key(index, e, key),
                    value: value.to_string(),
                    problem: format!(
                        "ericw-tools' {what}, which Slipgate's light does not implement: ignored"
                    ),
                });
            }
        }
    }
    out
}

/// The keys of [`UNSUPPORTED`] as a Markdown list for docs/mapping.md.
#[cfg(test)]
pub fn markdown_list() -> String {
    let mut out = String::new();
    for (key, place, what) in UNSUPPORTED {
        let on = match place {
            Where::Worldspawn => "worldspawn",
            Where::Lights => "lights",
            Where::Brushes => "brush entities",
        };
        out += &format!("- `{key}` ({on}): {what}\n");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::entities::parse_entities;

    #[test]
    fn each_unsupported_key_warns_where_ericw_tools_reads_it() {
        let text = r#"
{ "classname" "worldspawn" "_bouncelightsubdivision" "2" "_project_texture" "x" }
{ "classname" "light" "origin" "0 0 0" "_project_texture" "window1" }
{ "classname" "func_wall" "model" "*1" "_minlight_mottle" "1" "_lightcolorscale" "0" }
{ "classname" "func_detail" "_lightcolorscale" "0" "_maxlight" "40" }
"#;
        // The merged entity's keys reach light through the compiler's SLIPGATE_FACETONE.
        let entities = parse_entities(text).expect("entities");
        let told: Vec<String> = warnings(&entities)
            .iter()
            .map(ToString::to_string)
            .collect();
        assert_eq!(told.len(), 1, "{told:?}");
        assert!(told[0].contains("\"_bouncelightsubdivision\"") && told[0].contains("bounce"));
    }

    #[test]
    fn the_docs_list_every_unsupported_key() {
        crate::docs::check_generated_table(
            "unsupported light keys: generated from light/src/lights/unsupported.rs",
            "unsupported light keys",
            &markdown_list(),
        );
    }
}
