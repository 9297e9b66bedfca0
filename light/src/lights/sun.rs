//! Suns and sky domes: parallel light from sky faces. Worldspawn's `_sunlight` (spread over
//! `_sunlight_penumbra` degrees), `_sunlight2` and `_sunlight3` (domes from above and below,
//! each spread evenly over its hemisphere), and light entities with `_sun 1`, `_sunlight2 1` or
//! `_sunlight3 1`. A sun or dome spread over many directions is one [`SunLight`] per direction,
//! sharing its light.

use glam::DVec3;

use super::worldspawn::Global;
use crate::directions::{cap_directions, mangle_to_vec};
use crate::dirt::DirtResponse;
use crate::settings::Settings;

/// One direction of sunlight (a sun with a penumbra or a sky dome is many).
#[derive(Debug, Clone, PartialEq)]
pub struct SunLight {
    /// Unit vector pointing towards the sun.
    pub to_sun: DVec3,
    /// Brightness this direction adds at full incidence.
    pub light: f64,
    pub color: DVec3,
    pub style: u8,
    pub anglescale: f64,
    pub dirt: Option<DirtResponse>,
    /// How many directions its sun or dome is spread over (1: a sun without a penumbra).
    pub directions: usize,
}

/// `sun` spread over `degrees` around its direction (a cone's half-angle; 90 for a dome's
/// hemisphere): `sunsamples` directions, each with its share of the light (one direction for
/// no spread).
pub fn spread(sun: SunLight, degrees: f64, sunsamples: usize) -> Vec<SunLight> {
    let dirs = cap_directions(sun.to_sun, degrees, sunsamples);
    let each = sun.light / dirs.len().max(1) as f64;
    let directions = dirs.len();
    dirs.into_iter()
        .map(|to_sun| SunLight {
            to_sun,
            light: each,
            directions,
            ..sun.clone()
        })
        .collect()
}

/// The pole of a sky dome: straight up for `_sunlight2`, down for `_sunlight3`.
pub fn dome_pole(upper: bool) -> DVec3 {
    DVec3::new(0.0, 0.0, if upper { 1.0 } else { -1.0 })
}

/// The sun and domes worldspawn's settings ask for, in that order.
pub fn world_suns(settings: &Settings, global: &Global) -> Vec<SunLight> {
    let mut out = Vec::new();
    if settings.sunlight != 0.0 {
        let mangle = settings.sun_mangle;
        let sun = SunLight {
            to_sun: -mangle_to_vec(mangle.x, mangle.y),
            light: settings.sunlight,
            color: settings.sunlight_color.0,
            style: 0,
            anglescale: global.anglescale,
            dirt: global.dirt_if(settings.sunlight_dirt),
            directions: 1,
        };
        out.extend(spread(sun, settings.sun_penumbra, global.sunsamples));
    }
    let dome_dirt = global.dirt_if(settings.sunlight2_dirt);
    for (light, color, upper) in [
        (settings.sunlight2, settings.sunlight2_color, true),
        (settings.sunlight3, settings.sunlight3_color, false),
    ] {
        if light != 0.0 {
            let dome = SunLight {
                to_sun: dome_pole(upper),
                light,
                color: color.0,
                style: 0,
                anglescale: global.anglescale,
                dirt: dome_dirt,
                directions: 1,
            };
            out.extend(spread(dome, 90.0, global.sunsamples));
        }
    }
    out
}
