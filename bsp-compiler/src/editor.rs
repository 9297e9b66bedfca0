//! What a level editor writes into a `.map` for itself: TrenchBroom's `_tb_*` keys (texture
//! collections, mod folders, layers and groups) and its layers marked "Omit From Export".
//!
//! TrenchBroom keeps layers and groups as `func_group` entities with `_tb_type` `_tb_layer` or
//! `_tb_group` and an `_tb_id`; an entity in a layer or group names it by `_tb_layer` or
//! `_tb_group`, and a group names its own layer or parent group the same way. Its Export step
//! leaves out the layers whose `_tb_layer_omit_from_export` is `1`, with everything in them.
//! Compiling the saved map keeps them, as ericw-tools' qbsp does (a map sealed only by such a
//! layer seals the same with both tools), unless `--omit-layers` asks for what Export does; a
//! note names each such layer either way. Editor keys are left out of the entity lump (as
//! ericw-tools does: `_tb_textures` alone can be long enough to crash vanilla clients) unless
//! asked to keep them.

use crate::map::MapFile;
use quake_formats::entities::Entity;
use std::collections::HashMap;

/// Whether `key` is one only an editor reads.
pub(crate) fn is_editor_key(key: &str) -> bool {
    key.starts_with("_tb_")
}

/// `entity` without its editor keys.
pub(crate) fn without_editor_keys(entity: &Entity) -> Entity {
    Entity {
        pairs: entity
            .pairs
            .iter()
            .filter(|(k, _)| !is_editor_key(k))
            .cloned()
            .collect(),
        line: entity.line,
    }
}

/// A layer marked "Omit From Export".
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OmittedLayer {
    /// Its name in the editor (`_tb_name`).
    pub name: String,
    /// The entity that is the layer.
    pub entity: usize,
    /// Entities in it (the layer's own entity not counted).
    pub entities: usize,
    /// It was left out of the compile with everything in it (`--omit-layers`).
    pub left_out: bool,
}

/// The entities of `map` in layers marked "Omit From Export" (by entity index), and those layers,
/// which are left out of the compile when `omit` says so.
pub(crate) fn omitted_layers(map: &MapFile, omit: bool) -> (Vec<bool>, Vec<OmittedLayer>) {
    let entities = &map.entities;
    let id_of = |kind: &str| -> HashMap<&str, usize> {
        entities
            .iter()
            .enumerate()
            .filter(|(_, e)| e.entity.get("_tb_type") == Some(kind))
            .filter_map(|(i, e)| Some((e.entity.get("_tb_id")?, i)))
            .collect()
    };
    let (layers, groups) = (id_of("_tb_layer"), id_of("_tb_group"));
    let omits = |i: usize| entities[i].entity.get("_tb_layer_omit_from_export") == Some("1");
    // The layer an entity is in: its own key, or that of the group holding it (groups nest).
    let layer_of = |mut i: usize| -> Option<usize> {
        for _ in 0..=entities.len() {
            let e = &entities[i].entity;
            if let Some(&layer) = e.get("_tb_layer").and_then(|id| layers.get(id)) {
                return Some(layer);
            }
            i = *e.get("_tb_group").and_then(|id| groups.get(id))?;
        }
        None
    };
    let mut left_out = vec![false; entities.len()];
    let mut omitted: Vec<OmittedLayer> = Vec::new();
    for (i, out) in left_out.iter_mut().enumerate().skip(1) {
        let layer = if layers.values().any(|&l| l == i) {
            Some(i)
        } else {
            layer_of(i)
        };
        let Some(layer) = layer.filter(|&l| omits(l)) else {
            continue;
        };
        *out = true;
        let found = omitted.iter_mut().find(|o| o.entity == layer);
        match found {
            Some(o) => o.entities += usize::from(i != layer),
            None => omitted.push(OmittedLayer {
                name: entities[layer]
                    .entity
                    .get("_tb_name")
                    .unwrap_or("")
                    .to_string(),
                entity: layer,
                entities: usize::from(i != layer),
                left_out: omit,
            }),
        }
    }
    omitted.sort_by_key(|o| o.entity);
    if !omit {
        left_out.fill(false);
    }
    (left_out, omitted)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::parse_map;
    use std::path::Path;

    #[test]
    fn an_omitted_layer_takes_its_groups_and_entities_with_it() {
        let text = "{\n\"classname\" \"worldspawn\"\n\"_tb_textures\" \"textures/a\"\n}\n\
            {\n\"classname\" \"func_group\"\n\"_tb_type\" \"_tb_layer\"\n\"_tb_name\" \"Notes\"\n\
            \"_tb_id\" \"2\"\n\"_tb_layer_omit_from_export\" \"1\"\n}\n\
            {\n\"classname\" \"func_group\"\n\"_tb_type\" \"_tb_group\"\n\"_tb_id\" \"7\"\n\
            \"_tb_layer\" \"2\"\n}\n\
            {\n\"classname\" \"light\"\n\"origin\" \"0 0 0\"\n\"_tb_group\" \"7\"\n}\n\
            {\n\"classname\" \"info_null\"\n\"_tb_layer\" \"2\"\n}\n\
            {\n\"classname\" \"func_group\"\n\"_tb_type\" \"_tb_layer\"\n\"_tb_name\" \"Kept\"\n\
            \"_tb_id\" \"3\"\n}\n\
            {\n\"classname\" \"light\"\n\"_tb_layer\" \"3\"\n}\n\
            {\n\"classname\" \"info_player_start\"\n}\n";
        let map = parse_map(Path::new("layers.map"), text).expect("parse");
        let (left_out, layers) = omitted_layers(&map, true);
        assert_eq!(
            left_out,
            [false, true, true, true, true, false, false, false]
        );
        assert_eq!(
            layers,
            [OmittedLayer {
                name: "Notes".to_string(),
                entity: 1,
                entities: 3,
                left_out: true,
            }]
        );
        let world = without_editor_keys(&map.entities[0].entity);
        assert_eq!(world.get("_tb_textures"), None);
        assert_eq!(world.classname(), "worldspawn");
    }
}
