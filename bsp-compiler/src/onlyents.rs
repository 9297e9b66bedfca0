//! `--onlyents`: put a `.map`'s entities into a BSP compiled from it before, leaving every other
//! lump (geometry, vis, light) as it is, for edits that move or re-key point entities.
//!
//! The brush entities must still match the BSP's models one for one: the entity lump names
//! models `*1`, `*2`... in order, and a changed count would point entities at the wrong model.

use crate::compile::{CompileError, MapSource, entities_left_out, lump_entities, read_map};
use crate::options::CompileOptions;
use quake_formats::Bsp;
use quake_formats::entities::{Entity, parse_entities, write_entities};

/// Why a BSP's entities could not be replaced.
#[derive(Debug, thiserror::Error)]
pub enum OnlyEntsError {
    /// The `.map` could not be read.
    #[error(transparent)]
    Map(#[from] CompileError),
    /// The `.map`'s brush entities no longer match the BSP's models.
    #[error(
        "--onlyents: the .map has {map} brush entities but the BSP has {bsp} ({detail}); \
         recompile it without --onlyents"
    )]
    ModelsChanged {
        /// Entities of the `.map` that get a model.
        map: usize,
        /// Submodels in the BSP.
        bsp: usize,
        /// The first model whose entity changed, or which models are new or gone.
        detail: String,
    },
}

/// The classname of each entity with a `*N` model, in model order.
fn model_classes(entities: &[Entity]) -> Vec<String> {
    entities
        .iter()
        .filter(|e| e.get("model").is_some_and(|m| m.starts_with('*')))
        .map(|e| e.classname().to_string())
        .collect()
}

/// Replace `bsp`'s entity lump with the entities of `source` as a compile with `options` would
/// write them.
pub fn replace_entities(
    source: &MapSource,
    options: &CompileOptions,
    bsp: &mut Bsp,
) -> Result<(), OnlyEntsError> {
    let map = read_map(source, options)?;
    let (left_out, _) = entities_left_out(&map, options);
    let entities = lump_entities(&map, &left_out, options);
    let submodels = bsp.models.len().saturating_sub(1);
    let new = model_classes(&entities);
    if new.len() != submodels {
        // The old lump says which entity each model was, if it can be read.
        let old = parse_entities(&bsp.entity_text())
            .map(|e| model_classes(&e))
            .unwrap_or_default();
        let detail = match old.iter().zip(&new).position(|(a, b)| a != b) {
            Some(i) => format!(
                "model *{} was a {}, the .map now gives a {}",
                i + 1,
                old[i],
                new[i]
            ),
            None if new.len() > old.len() => {
                format!("new: {}", new[old.len()..].join(", "))
            }
            None => format!(
                "gone: {}",
                old.get(new.len()..).unwrap_or_default().join(", ")
            ),
        };
        return Err(OnlyEntsError::ModelsChanged {
            map: new.len(),
            bsp: submodels,
            detail,
        });
    }
    bsp.set_entity_text(&write_entities(&entities));
    Ok(())
}
