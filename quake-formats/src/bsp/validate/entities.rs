//! The entity lump as the server spawns it.

use super::{Checker, Rule};
use crate::entities::parse_entities;

pub(super) fn check(c: &mut Checker) {
    let bsp = c.bsp;
    if bsp.entities.last() != Some(&0) {
        let detail = "text is not NUL-terminated".to_string();
        c.report(Rule::EntityText, "entities", 0, detail);
    }
    let entities = match parse_entities(&bsp.entity_text()) {
        Ok(entities) => entities,
        Err(e) => {
            c.report(Rule::EntityText, "entities", 0, e.to_string());
            return;
        }
    };
    match entities.iter().position(|e| e.classname() == "worldspawn") {
        Some(0) => {}
        Some(at) => {
            let first = entities[0].classname();
            let detail = format!("the worldspawn is entity {at}; the first is \"{first}\"");
            c.report(Rule::WorldspawnFirst, "entities", 0, detail);
        }
        None => {
            let detail = "there is no worldspawn entity".to_string();
            c.report(Rule::Worldspawn, "entities", 0, detail);
        }
    }
    if !entities
        .iter()
        .any(|e| e.classname() == "info_player_start")
    {
        let detail = "there is no info_player_start".to_string();
        c.report(Rule::PlayerStart, "entities", 0, detail);
    }
}
