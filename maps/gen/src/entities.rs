//! What every generated map shares: worldspawn naming the project's WAD, lights, the player
//! start, and the standard-format map holding them.

use crate::brush::{Map, MapEntity, MapFormat};

/// The WAD every generated map names, beside `demo.map`.
pub const WAD_NAME: &str = "slipgate.wad";

pub(crate) fn worldspawn(message: &str) -> MapEntity {
    MapEntity::new("worldspawn")
        .key("message", message)
        .key("wad", WAD_NAME)
}

pub(crate) fn light(origin: [f64; 3], level: u32) -> MapEntity {
    MapEntity::point("light", origin).key("light", &level.to_string())
}

pub(crate) fn player_start(origin: [f64; 3], angle: u32) -> MapEntity {
    MapEntity::point("info_player_start", origin).key("angle", &angle.to_string())
}

pub(crate) fn standard(comment: &[&str], entities: Vec<MapEntity>) -> Map {
    Map {
        comment: comment.iter().map(|s| s.to_string()).collect(),
        format: MapFormat::Standard,
        entities,
    }
}
