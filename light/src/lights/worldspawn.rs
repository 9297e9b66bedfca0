//! What worldspawn's settings (the command line's where it gives them) make of every light:
//! falloff distance and angle scales, the dirt everything takes unless it opts out, the
//! world's minlight, how dirt is measured and how light bounces.

use super::{BounceSettings, Minlight};
use crate::dirt::{DirtResponse, DirtSampling};
use crate::settings::{DirtToggle, Settings};

/// The map-wide values every light entity, sun and brush model is read against.
#[derive(Debug, Clone, Copy)]
pub struct Global {
    /// `_dist`: scales every light's falloff distance.
    pub scaledist: f64,
    /// `_anglescale` of lights and suns without their own.
    pub anglescale: f64,
    /// Directions per sun penumbra and sky dome.
    pub sunsamples: usize,
    /// `_dirt 1` (or `--dirt`): dirt on for everything that does not turn it off.
    pub dirt: bool,
    /// `_dirtscale` and `_dirtgain`: how dirt darkens what sets no response of its own.
    pub response: DirtResponse,
    /// Whether minlight takes dirt, and how.
    pub minlight_dirt: Option<DirtResponse>,
    /// `--addmin`: minlight is added to style 0 instead of raising it.
    pub addmin: bool,
    /// `_spotlightautofalloff`: a targeted spotlight without `_falloff` fades out at its target.
    pub spotlight_autofalloff: bool,
}

impl Global {
    /// The values `settings` give.
    pub fn new(settings: &Settings) -> Global {
        let mut global = Global {
            scaledist: settings.dist,
            anglescale: settings.anglescale,
            sunsamples: settings.sunsamples,
            dirt: settings.dirt,
            response: DirtResponse {
                scale: settings.dirt_scale,
                gain: settings.dirt_gain,
            },
            minlight_dirt: None,
            addmin: settings.addmin,
            spotlight_autofalloff: settings.spotlight_autofalloff,
        };
        global.minlight_dirt = global.dirt_if(settings.minlight_dirt);
        global
    }

    /// How something whose own switch is `toggle` takes dirt, with `response` (`None`: it
    /// takes none).
    pub fn dirt_with(&self, toggle: DirtToggle, response: DirtResponse) -> Option<DirtResponse> {
        toggle.is_on(self.dirt).then_some(response)
    }

    /// [`Global::dirt_with`] the map-wide response.
    pub fn dirt_if(&self, toggle: DirtToggle) -> Option<DirtResponse> {
        self.dirt_with(toggle, self.response)
    }

    /// A minlight of `level` and `color` (a brush model's or the world's).
    pub fn minlight(
        &self,
        level: f64,
        color: glam::DVec3,
        exclude_texture: Option<String>,
    ) -> Minlight {
        Minlight {
            level,
            add: self.addmin,
            color,
            dirt: self.minlight_dirt,
            exclude_texture,
        }
    }
}

/// How dirt occlusion is measured: `_dirtmode`, `_dirtdepth`, `_dirtangle`.
pub fn dirt_sampling(settings: &Settings) -> DirtSampling {
    DirtSampling::new(settings.dirt_mode, settings.dirt_depth, settings.dirt_angle)
}

/// How light bounces: `_bounce` and its keys, bounced light taking worldspawn's dirt.
pub fn bounce(settings: &Settings, global: &Global) -> BounceSettings {
    BounceSettings {
        passes: settings.bounce,
        scale: settings.bounce_scale,
        color_scale: settings.bounce_color_scale,
        styled: settings.bounce_styled,
        dirt: global.dirt.then_some(global.response),
        emission: settings.emissive_quality,
        subdivision: settings.bounce_light_subdivision,
    }
}

/// The world's minlight, when it has one (`_minlight` or `light`, not 0).
pub fn world_minlight(settings: &Settings, global: &Global) -> Option<Minlight> {
    (settings.minlight != 0.0).then(|| {
        global.minlight(
            settings.minlight,
            settings.minlight_color.0,
            settings.minlight_exclude.clone(),
        )
    })
}
