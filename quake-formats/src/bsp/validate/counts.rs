//! Whole-file counts against the tables engines allocate.

use super::{Checker, Rule};
use crate::bsp::BspVersion;
use crate::bsp::limits::{
    ENGINE_MAX_LEAFS, ENGINE_MAX_MODELS, QUAKESPASM_MAX_BSP29_LEAFS, QUAKESPASM_MAX_MODELS,
};

pub(super) fn check(c: &mut Checker) {
    let bsp = c.bsp;
    let leafs = bsp.leafs.len();
    if bsp.version == BspVersion::Bsp29 && leafs > QUAKESPASM_MAX_BSP29_LEAFS {
        let detail = format!("{leafs} leafs, more than {QUAKESPASM_MAX_BSP29_LEAFS}");
        c.report(Rule::LeafCount, "leafs", 0, detail);
    }
    if let Some(world) = bsp.models.first() {
        // Leaf 0 never has a PVS row: rows are for leafs 1..=visleafs.
        let vis_leafs = world.vis_leafs;
        if vis_leafs < 0 || vis_leafs as usize >= leafs.max(1) {
            let detail = format!("the world's visleafs is {vis_leafs}, but it has {leafs} leafs");
            c.report(Rule::VisLeafs, "models", 0, detail);
        } else if vis_leafs as usize > ENGINE_MAX_LEAFS {
            let detail =
                format!("the world's visleafs is {vis_leafs}, more than {ENGINE_MAX_LEAFS}");
            c.report(Rule::VisLeafsVanilla, "models", 0, detail);
        }
    }
    // The model table holds "" (0), the world (1) and every submodel, then the game code's
    // models: at least the player's.
    let needed = bsp.models.len() + 2;
    if needed > QUAKESPASM_MAX_MODELS {
        let detail = format!(
            "{} models leave no room for the game code's in a table of {QUAKESPASM_MAX_MODELS}",
            bsp.models.len()
        );
        c.report(Rule::ModelCount, "models", 0, detail);
    } else if needed > ENGINE_MAX_MODELS {
        let detail = format!(
            "{} models leave no room for the game code's in a table of {ENGINE_MAX_MODELS}",
            bsp.models.len()
        );
        c.report(Rule::ModelCountVanilla, "models", 0, detail);
    }
}
