//! Suns and sky domes: parallel light from sky faces. Worldspawn's `_sunlight` (spread over
//! `_sunlight_penumbra` degrees), `_sunlight2` and `_sunlight3` (domes from above and below,
//! laid out in rings as ericw-tools lays them: see [`dome`]), and light entities with `_sun 1`,
//! `_sunlight2 1` or `_sunlight3 1`. A sun or dome spread over many directions is one
//! [`SunLight`] per direction, sharing its light.

use std::sync::Arc;

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
    /// `_suntexture`: the only sky texture it shines through (`None`: every sky face).
    pub sky_texture: Option<Arc<str>>,
}

/// `sun` spread over `degrees` around its direction (a cone's half-angle): `sunsamples`
/// directions, each with its share of the light (one direction for no spread).
pub fn spread(sun: SunLight, degrees: f64, sunsamples: usize) -> Vec<SunLight> {
    let dirs = cap_directions(sun.to_sun, degrees, sunsamples);
    shared_out(&sun, dirs)
}

/// One copy of `sun` towards each of `dirs`, each with an even share of its light.
fn shared_out(sun: &SunLight, dirs: Vec<DVec3>) -> Vec<SunLight> {
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

/// A sky dome (`_sunlight2` when `upper`, else `_sunlight3`): `sun`'s light shared by
/// directions on rings of equal elevation steps, each ring with as many directions, and one
/// at the pole, as ericw-tools (after q3map2) lays its dome out, about `sunsamples` in all.
/// Rings crowd towards the pole, so the dome's sky is brighter overhead than at the horizon
/// (a courtyard's floor takes more of it than an even sky would give): maps lit with
/// ericw-tools are tuned to that.
pub fn dome(sun: SunLight, upper: bool, sunsamples: usize) -> Vec<SunLight> {
    let rings = ((sunsamples.saturating_sub(1) as f64 / 4.0).sqrt().round() as usize).max(1);
    let per_ring = rings * 4;
    let step = std::f64::consts::FRAC_PI_2 / (rings + 1) as f64;
    let azimuth_step = std::f64::consts::TAU / per_ring as f64;
    let up = if upper { 1.0 } else { -1.0 };
    let mut dirs = Vec::with_capacity(rings * per_ring + 1);
    for ring in 0..rings {
        let elevation = step * (ring as f64 + 0.5);
        // Each ring turns a little further, so directions do not line up ring over ring.
        let turn = azimuth_step * ring as f64 / rings as f64;
        let (rise, flat) = elevation.sin_cos();
        for k in 0..per_ring {
            let (s, c) = (azimuth_step * k as f64 + turn).sin_cos();
            dirs.push(DVec3::new(c * flat, s * flat, up * rise));
        }
    }
    dirs.push(DVec3::new(0.0, 0.0, up));
    shared_out(&sun, dirs)
}

/// The suns (`_sunlight`, `_sun2`) and domes worldspawn's settings ask for, in that order.
pub fn world_suns(settings: &Settings, global: &Global) -> Vec<SunLight> {
    let mut out = Vec::new();
    for (light, mangle, color) in [
        (
            settings.sunlight,
            settings.sun_mangle,
            settings.sunlight_color,
        ),
        (settings.sun2, settings.sun2_mangle, settings.sun2_color),
    ] {
        if light == 0.0 {
            continue;
        }
        let sun = SunLight {
            to_sun: -mangle_to_vec(mangle.x, mangle.y),
            light,
            color: color.0,
            style: 0,
            anglescale: global.anglescale,
            dirt: global.dirt_if(settings.sunlight_dirt),
            directions: 1,
            sky_texture: None,
        };
        out.extend(spread(sun, settings.sun_penumbra, global.sunsamples));
    }
    let dome_dirt = global.dirt_if(settings.sunlight2_dirt);
    for (light, color, upper) in [
        (settings.sunlight2, settings.sunlight2_color, true),
        (settings.sunlight3, settings.sunlight3_color, false),
    ] {
        if light != 0.0 {
            let sky = SunLight {
                to_sun: DVec3::ZERO,
                light,
                color: color.0,
                style: 0,
                anglescale: global.anglescale,
                dirt: dome_dirt,
                directions: 1,
                sky_texture: None,
            };
            out.extend(dome(sky, upper, global.sunsamples));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sky(light: f64) -> SunLight {
        SunLight {
            to_sun: DVec3::ZERO,
            light,
            color: DVec3::ONE,
            style: 0,
            anglescale: 0.5,
            dirt: None,
            directions: 1,
            sky_texture: None,
        }
    }

    /// ericw-tools' layout for its default of 64 samples: 4 rings of 16 directions, 18 degrees
    /// apart from 9 degrees up, and the pole; each takes an even share. 100 samples are 5 rings
    /// of 20, 15 degrees apart from 7.5 degrees up.
    #[test]
    fn a_dome_has_rings_of_equal_elevation_steps_and_its_pole() {
        for (samples, rings, first, step) in [(64, 4, 9.0, 18.0), (100, 5, 7.5, 15.0)] {
            let per_ring = 4 * rings;
            let count = rings * per_ring + 1;
            let suns = dome(sky(count as f64), true, samples);
            assert_eq!(suns.len(), count);
            for s in &suns {
                assert!((s.light - 1.0).abs() < 1e-12 && s.directions == count);
                assert!((s.to_sun.length() - 1.0).abs() < 1e-12);
            }
            let elevation = |s: &SunLight| s.to_sun.z.asin().to_degrees();
            for (ring, chunk) in suns[..count - 1].chunks(per_ring).enumerate() {
                let want = first + step * ring as f64;
                assert!(chunk.iter().all(|s| (elevation(s) - want).abs() < 1e-9));
            }
            assert_eq!(suns[count - 1].to_sun, DVec3::Z);
            let lower = dome(sky(1.0), false, samples);
            for (a, b) in suns.iter().zip(&lower) {
                assert_eq!(a.to_sun.truncate(), b.to_sun.truncate());
                assert_eq!(a.to_sun.z, -b.to_sun.z);
            }
        }
    }

    /// Rings crowd towards the pole: more of the dome's light comes from within 30 degrees of
    /// it than an even sky's 13% (1 - sin 60°), so a courtyard's floor, which sees only the
    /// high sky, takes more of it.
    #[test]
    fn a_dome_is_brighter_overhead_than_an_even_sky() {
        for samples in [64, 100, 300] {
            let suns = dome(sky(1.0), true, samples);
            let high: f64 = suns
                .iter()
                .filter(|s| s.to_sun.z > 60f64.to_radians().sin())
                .map(|s| s.light)
                .sum();
            assert!(high > 0.18, "{samples}: {high}");
            let total: f64 = suns.iter().map(|s| s.light).sum();
            assert!((total - 1.0).abs() < 1e-12);
        }
    }

    /// worldspawn's `_sun2`: a second sun beside `_sunlight`, with its own direction and colour.
    #[test]
    fn a_second_sun_shines_beside_the_first() {
        let settings = Settings {
            sunlight: 200.0,
            sun2: 100.0,
            sun2_mangle: DVec3::new(0.0, -45.0, 0.0),
            sun2_color: crate::settings::Color(DVec3::new(1.0, 0.0, 0.0)),
            ..Settings::default()
        };
        let suns = world_suns(&settings, &Global::new(&settings));
        assert_eq!(suns.len(), 2);
        assert_eq!((suns[0].light, suns[0].color), (200.0, DVec3::ONE));
        assert!((suns[0].to_sun - DVec3::Z).length() < 1e-9);
        assert_eq!((suns[1].light, suns[1].color), (100.0, DVec3::X));
        let half = std::f64::consts::FRAC_1_SQRT_2;
        assert!(
            (suns[1].to_sun - DVec3::new(-half, 0.0, half)).length() < 1e-9,
            "{:?}",
            suns[1].to_sun
        );
    }
}
