//! What the entity lump says about light: map-wide settings, suns and sky domes, brush
//! models' keys and light entities, read in that order by [`parse_lights`].
//!
//! Keys follow ericw-tools' documented meanings. Worldspawn's map-wide keys are settings
//! ([`crate::settings`]): the command line may override them. The keys of lights and brush
//! models are declared in [`keys`]. A value that does not read, anywhere, is a warning naming
//! the entity and key, never an error.

mod entities;
pub mod keys;
mod models;
pub mod mottle;
mod point;
pub mod projection;
mod styles;
mod sun;
mod worldspawn;

use glam::DVec3;
use std::collections::HashMap;

use quake_formats::bsp::face_channels::DEFAULT_CHANNELS;
use quake_formats::bsp::face_flags::FaceFlags;
use quake_formats::bsp::face_tone::FaceTone;
use quake_formats::entities::Entity;

use crate::bounce::EmissiveQuality;
use crate::dirt::{DirtResponse, DirtSampling};
use crate::error::LightError;
use crate::faces::Spacing;
use crate::settings::{ChosenSetting, Overrides, SettingWarning, Settings, World};
#[cfg(test)]
pub(crate) use point::test_light;
pub use point::{Falloff, PointLight, Spot, angle_factor};
pub use styles::{StyleRange, SwitchableStyles, assign_switchable_styles};
pub use sun::SunLight;
pub use worldspawn::dirt_sampling;

/// A minimum light level: no luxel of style 0 ends up darker than this
/// (times the dirt factor when minlight takes dirt).
#[derive(Debug, Clone, PartialEq)]
pub struct Minlight {
    pub level: f64,
    /// `--addmin`: the level is added to style 0 instead of being a floor.
    pub add: bool,
    pub color: DVec3,
    pub dirt: Option<DirtResponse>,
    /// Faces with this texture get no minlight (`_minlight_exclude`).
    pub exclude_texture: Option<String>,
}

/// A `_surface` light: copied over every face whose texture is `texture`.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceTemplate {
    pub texture: String,
    /// The light each copy starts from (origin and spot are set per copy).
    pub light: PointLight,
    /// Distance of each copy in front of its face (`_surface_offset`).
    pub offset: f64,
    /// Copies shine along the face normal (`_surface_spotlight 1`).
    pub spotlight: bool,
    pub spot_angle: f64,
    /// `_surflight_group`: copies go only on faces of brush models with the same group (the
    /// world and models without the key are group 0).
    pub group: i64,
}

/// How light bounces: worldspawn's `_bounce` and its keys (or the command line's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BounceSettings {
    /// Passes (0 = off).
    pub passes: usize,
    /// `_bouncescale`.
    pub scale: f64,
    /// `_bouncecolorscale`: 0 = grey reflectance, 1 = the texture's mean colour.
    pub color_scale: f64,
    /// `_bouncestyled`: styled (switchable, animated) light bounces too, in its own style.
    pub styled: bool,
    /// How dirt darkens bounced light (worldspawn's dirt, when it is on).
    pub dirt: Option<DirtResponse>,
    /// Where reflecting faces send their light from.
    pub emission: EmissiveQuality,
    /// `_bouncelightsubdivision`: at `high`, the size of the pieces whose middles send a
    /// face's light to the brush models' middles.
    pub subdivision: f64,
}

impl BounceSettings {
    /// Whether any light bounces.
    pub fn is_on(&self) -> bool {
        self.passes > 0 && self.scale > 0.0
    }
}

/// A brush model's `_autominlight` other than the default (its samples in solid take the light
/// at its middle).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AutoMinlight {
    /// `-1`: its samples in solid take no light.
    Off,
    /// `1`: every sample of the model takes at least that light.
    Everywhere,
}

/// Everything the entity lump says about lighting.
#[derive(Debug, Clone, PartialEq)]
pub struct MapLights {
    pub points: Vec<PointLight>,
    pub suns: Vec<SunLight>,
    pub templates: Vec<SurfaceTemplate>,
    /// Minlight per model index (0 = world, from worldspawn).
    pub minlight: HashMap<usize, Minlight>,
    /// Brush models with their own `_minlight_mottle` (else the map's setting).
    pub model_minlight_mottle: HashMap<usize, bool>,
    /// Brush models with their own `_maxlight`, in levels.
    pub model_maxlight: HashMap<usize, f64>,
    /// Worldspawn (model 0) and brush models whose `_lightcolorscale` is not 1.
    pub model_lightcolorscale: HashMap<usize, f64>,
    /// Brush models that cast shadows (`_shadow 1`).
    pub shadow_models: Vec<usize>,
    /// Brush models that shadow only their own faces (`_shadowself 1`).
    pub self_shadow_models: Vec<usize>,
    /// Brush models that shadow only the world's faces (`_shadowworldonly 1`).
    pub world_shadow_models: Vec<usize>,
    /// Brush models on light channels other than 1 (`_object_channel_mask`), and their mask.
    pub channel_models: Vec<(usize, u32)>,
    /// Brush models whose faces never take dirt (`_dirt -1`).
    pub no_dirt_models: Vec<usize>,
    /// Brush models whose faces get minlight only (`_lightignore 1`).
    pub lightignore_models: Vec<usize>,
    /// Brush models whose faces do not reflect light (`_bounce 0`).
    pub no_bounce_models: Vec<usize>,
    /// Per face, what the keys of the entity merged into the world it came from say of it
    /// (the compiler's `SLIPGATE_FACEFLAGS`; empty without that lump).
    pub face_flags: Vec<FaceFlags>,
    /// Faces with a minlight of their own entity's, merged into the world (the compiler's
    /// `SLIPGATE_FACEMINLIGHT`).
    pub face_minlight: HashMap<usize, Minlight>,
    /// Per face, the light channels of the entity merged into the world it came from (the
    /// compiler's `SLIPGATE_FACECHANNELS`; empty without that lump).
    pub face_channels: Vec<u32>,
    /// Per face, the `_maxlight` and `_lightcolorscale` of the entity merged into the world it
    /// came from (the compiler's `SLIPGATE_FACETONE`; empty without that lump).
    pub face_tones: Vec<FaceTone>,
    /// Brush models whose `_autominlight` is not the default (occluded samples only).
    pub autominlight: HashMap<usize, AutoMinlight>,
    /// Brush models whose autominlight is taken at a target's origin (`_autominlight_target`).
    pub autominlight_at: HashMap<usize, DVec3>,
    /// Light entities that stay where they are even in solid (`_nonudge 1`).
    pub no_nudge: Vec<usize>,
    /// Pictures light entities project (`_project_texture`), before the BSP's textures are
    /// looked up ([`MapLights::attach_projections`]).
    pub projections: Vec<projection::ProjectionKeys>,
    /// Diffuse interreflection (`_bounce` and its keys).
    pub bounce: BounceSettings,
    /// How dirt occlusion is measured (used only when something takes dirt).
    pub dirt: DirtSampling,
    /// Brush models (0 = world) with `_phong` smoothing, and their angles.
    pub phong: HashMap<usize, crate::phong::PhongAngles>,
    /// Offset of each brush model with an `origin` key (rotating entities).
    pub model_origins: HashMap<usize, DVec3>,
    /// Brush models with a non-zero `_surflight_group`, and that group.
    pub surflight_groups: HashMap<usize, i64>,
    /// Brush models with their own `_world_units_per_luxel` (used when the map's is set).
    pub model_units_per_luxel: HashMap<usize, f64>,
    /// The world (0) and brush models with their own `_lmscale`.
    pub model_lmscale: HashMap<usize, f64>,
    /// The map-wide settings, resolved (the command line's, else worldspawn's, else the
    /// defaults).
    pub settings: Settings,
    /// The settings given a value, and where.
    pub chosen_settings: Vec<ChosenSetting>,
    /// Values light did not take as given.
    pub warnings: Vec<SettingWarning>,
    /// Styles given to switchable lights and switchable shadows, also written back into the
    /// entities (`style`, `switchshadstyle`).
    pub switchable: SwitchableStyles,
}

impl MapLights {
    /// The light channels of `face`: its merged entity's `_object_channel_mask`, else its brush
    /// model's (1, the world's, by default).
    pub fn channels_of(&self, face: &crate::faces::FaceGeom) -> u32 {
        match self.face_channels.get(face.index) {
            Some(&mask) if mask != DEFAULT_CHANNELS => mask,
            _ => self
                .channel_models
                .iter()
                .find(|(m, _)| *m == face.model)
                .map_or(DEFAULT_CHANNELS, |&(_, mask)| mask),
        }
    }

    /// Every face's light channels ([`MapLights::channels_of`]); empty when all are on
    /// channel 1.
    pub fn face_channel_masks(&self, faces: &[crate::faces::FaceGeom]) -> Vec<u32> {
        if self.channel_models.is_empty() && self.face_channels.is_empty() {
            return Vec::new();
        }
        faces.iter().map(|f| self.channels_of(f)).collect()
    }

    /// The spacing model `model`'s faces are lit at, as in ericw-tools: with the map's
    /// `_world_units_per_luxel` set, world-aligned grids at the model's own
    /// `_world_units_per_luxel`, else the map's; else `-lmshift` for every model when it is
    /// not 4; else the map's `_lightmap_scale` (`-lmscale`) for every model; else the model's
    /// `_lmscale` (fractions of 16 texels, as ericw-tools' qbsp reads them); else Quake's.
    pub fn spacing(&self, model: usize) -> Spacing {
        let map = self.settings.world_units_per_luxel;
        if map > 0.0 {
            let own = self.model_units_per_luxel.get(&model).copied();
            return Spacing::WorldUnits(own.filter(|&u| u > 0.0).unwrap_or(map));
        }
        let map_scale = self.settings.lightmap_scale;
        let shift = match self.settings.lmshift {
            QUAKE_SHIFT if map_scale > 0.0 => shift_of_texels(16.0 * map_scale),
            QUAKE_SHIFT => {
                let scale = self.model_lmscale.get(&model).copied().unwrap_or(0.0);
                shift_of_texels(16.0 * scale)
            }
            // The setting's range holds it to 30.
            shift => u8::try_from(shift).ok(),
        };
        shift.map_or(Spacing::Quake, Spacing::Shift)
    }

    /// True if any light, sun or minlight is darkened by dirt.
    pub fn uses_dirt(&self) -> bool {
        self.points.iter().any(|l| l.dirt.is_some())
            || self.suns.iter().any(|s| s.dirt.is_some())
            || self.templates.iter().any(|t| t.light.dirt.is_some())
            || self.minlight.values().any(|m| m.dirt.is_some())
            || (self.bounce.is_on() && self.bounce.dirt.is_some())
    }

    /// True if any light, sun or minlight is not white (a `.lit` is needed).
    pub fn is_coloured(&self) -> bool {
        let grey = |c: &DVec3| c.x != c.y || c.y != c.z;
        self.points
            .iter()
            .any(|l| grey(&l.color) || l.projector.as_ref().is_some_and(|p| !p.is_grey()))
            || self.suns.iter().any(|s| grey(&s.color))
            || self.templates.iter().any(|t| grey(&t.light.color))
            || self.minlight.values().any(|m| grey(&m.color))
    }
}

/// Reads every light from `entities`, with the map-wide settings resolved against
/// `overrides`, and assigns styles to switchable lights (writing `style` into those
/// entities).
///
/// # Errors
/// [`LightError::TooManySwitchableLights`]: more switchable names than styles.
pub fn parse_lights(
    entities: &mut [Entity],
    overrides: &Overrides,
) -> Result<MapLights, LightError> {
    let world = entities.iter().position(|e| e.classname() == "worldspawn");
    let (settings, told) = Settings::resolve(
        world.map(|index| World {
            index,
            entity: &entities[index],
        }),
        overrides,
    );
    let mut style_warnings = Vec::new();
    let switchable =
        assign_switchable_styles(entities, StyleRange::of(&settings), &mut style_warnings)?;
    let mut warnings = told.warnings;
    warnings.extend(style_warnings);
    let global = worldspawn::Global::new(&settings);
    let mut out = MapLights {
        points: Vec::new(),
        suns: sun::world_suns(&settings, &global),
        templates: Vec::new(),
        minlight: HashMap::new(),
        model_minlight_mottle: HashMap::new(),
        model_maxlight: HashMap::new(),
        model_lightcolorscale: HashMap::new(),
        shadow_models: Vec::new(),
        self_shadow_models: Vec::new(),
        world_shadow_models: Vec::new(),
        channel_models: Vec::new(),
        no_dirt_models: Vec::new(),
        lightignore_models: Vec::new(),
        no_bounce_models: Vec::new(),
        face_flags: Vec::new(),
        face_minlight: HashMap::new(),
        face_channels: Vec::new(),
        face_tones: Vec::new(),
        autominlight: HashMap::new(),
        autominlight_at: HashMap::new(),
        no_nudge: Vec::new(),
        projections: Vec::new(),
        bounce: worldspawn::bounce(&settings, &global),
        dirt: dirt_sampling(&settings),
        phong: HashMap::new(),
        model_origins: HashMap::new(),
        surflight_groups: HashMap::new(),
        model_units_per_luxel: HashMap::new(),
        model_lmscale: HashMap::new(),
        switchable,
        settings,
        chosen_settings: told.chosen,
        warnings,
    };
    if let Some(m) = worldspawn::world_minlight(&out.settings, &global) {
        out.minlight.insert(0, m);
    }
    models::read_world_and_model_keys(entities, world, &mut out);
    models::read_models(entities, &global, &mut out);
    // A switchable shadow is one the game turns on and off, never a fixed one; a world-only
    // shadow falls on the world alone.
    let switchable = &out.switchable.shadows;
    let world_only = &out.world_shadow_models;
    out.shadow_models
        .retain(|m| !switchable.iter().any(|(s, _)| s == m) && !world_only.contains(m));
    if !out.settings.nolights {
        entities::read_lights(entities, &global, &mut out);
    }
    Ok(out)
}

impl MapLights {
    /// Reads what the compiler recorded in `bsp` of the keys of entities merged into the world,
    /// per face ([`MapLights::face_flags`], [`MapLights::face_minlight`],
    /// [`MapLights::face_channels`], [`MapLights::face_tones`]).
    ///
    /// # Errors
    /// A damaged lump of those keys.
    pub fn read_merged_faces(
        &mut self,
        bsp: &quake_formats::Bsp,
    ) -> Result<(), quake_formats::FormatError> {
        let global = worldspawn::Global::new(&self.settings);
        models::read_merged_faces(bsp, &global, self)
    }
}

/// `-lmshift`'s default: Quake's 16 texels, leaving each model its `_lmscale`.
const QUAKE_SHIFT: usize = 4;

/// The `LMSHIFT` of a lightmap spacing of `texels`, as ericw-tools' qbsp takes it: the whole
/// texels, halved down to a power of two. `None` for less than one texel (unset).
fn shift_of_texels(texels: f64) -> Option<u8> {
    // Whole texels as ericw-tools truncates them; past 2^30 no engine's arithmetic holds.
    let mut whole = texels.min(f64::from(1u32 << 30)) as u32;
    if whole == 0 {
        return None;
    }
    let mut shift = 0;
    while whole > 1 {
        whole /= 2;
        shift += 1;
    }
    Some(shift)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dirt::DirtMode;
    use entities::DEFAULT_LIGHT;
    use quake_formats::entities::parse_entities;
    use quake_formats::geom::DVec3Ext;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9 * b.abs().max(1.0)
    }

    #[test]
    fn parses_keys_and_assigns_switchable_styles() {
        let text = r#"
{ "classname" "worldspawn" "light" "20" "_sunlight" "100" "_sun_mangle" "0 -90 0" "_sunlight_color" "255 128 0" }
{ "classname" "light" "origin" "0 0 64" "delay" "2" "wait" "2" "_color" "1 0.5 0.5" }
{ "classname" "light_fluoro" "origin" "0 0 0" "targetname" "door" }
{ "classname" "light" "origin" "8 0 0" "targetname" "door" "light" "200" }
{ "classname" "light" "origin" "8 0 0" "targetname" "other" "style" "5" }
{ "classname" "light" "origin" "0 0 0" "target" "t1" "angle" "60" }
{ "classname" "info_null" "origin" "0 0 -100" "targetname" "t1" }
{ "classname" "light" "_surface" "sky4" "light" "100" }
{ "classname" "func_door" "model" "*1" "_shadow" "1" "_minlight" "10" }
"#;
        let mut ents = parse_entities(text).expect("parse");
        let lights = parse_lights(&mut ents, &Overrides::default()).expect("lights");
        assert_eq!(lights.points.len(), 5);
        let p = &lights.points[0];
        assert_eq!(p.falloff, Falloff::InverseSquare);
        assert_eq!(p.atten, 2.0);
        assert_eq!(p.light, DEFAULT_LIGHT);
        assert_eq!(p.color, DVec3::new(1.0, 0.5, 0.5));
        assert_eq!(lights.points[1].style, 32);
        assert_eq!(lights.points[2].style, 32, "same targetname, same style");
        assert_eq!(lights.points[3].style, 5, "explicit style kept");
        let spot = lights.points[4].spot.expect("spotlight");
        assert!(spot.dir.near(DVec3::new(0.0, 0.0, -1.0), 1e-12));
        assert!(close(spot.cos_outer, 30f64.to_radians().cos()));
        assert_eq!(ents[2].get("style"), Some("32"));
        assert_eq!(ents[4].get("style"), Some("5"));
        assert_eq!(lights.switchable.names, vec![("door".to_string(), 32)]);
        assert_eq!(lights.templates.len(), 1);
        assert_eq!(lights.templates[0].texture, "sky4");
        assert_eq!(lights.suns.len(), 1, "no penumbra: one direction");
        assert!(lights.suns[0].to_sun.near(DVec3::new(0.0, 0.0, 1.0), 1e-12));
        assert!(close(lights.suns[0].color.y, 128.0 / 255.0));
        assert_eq!(lights.minlight[&0].level, 20.0);
        assert_eq!(lights.minlight[&1].level, 10.0);
        assert_eq!(lights.shadow_models, vec![1]);
        assert!(lights.is_coloured());
    }

    /// Regression: a value light could not read stopped the run, where ericw-tools lights the
    /// map; now it is a warning naming the entity, its line and the key, and the value
    /// ericw-tools would use is used.
    #[test]
    fn unreadable_values_warn_and_take_what_ericw_tools_takes() {
        let text = "{ \"classname\" \"worldspawn\" }\n\
                    { \"classname\" \"light\" \"light\" \"bright\" \"_color\" \"%top\" }\n\
                    { \"classname\" \"light\" \"light\" \"150x\" \"style\" \"abc\" }";
        let mut ents = parse_entities(text).expect("parse");
        let lights = parse_lights(&mut ents, &Overrides::default()).expect("lights");
        assert_eq!(lights.points[0].light, DEFAULT_LIGHT);
        assert_eq!(lights.points[0].color, DVec3::ONE);
        assert_eq!(lights.points[1].light, 150.0);
        assert_eq!(lights.points[1].style, 0);
        let told: Vec<String> = lights.warnings.iter().map(ToString::to_string).collect();
        assert_eq!(told.len(), 4, "{told:?}");
        assert!(
            told[0].starts_with(
                "entity 1 (light, line 2 of the entity lump): key \"light\" is \"bright\""
            ),
            "{told:?}"
        );
        assert!(told[2].contains("\"150x\": read as \"150\""), "{told:?}");
    }

    /// Regression: `delay 15` stopped the run, then lit with linear falloff; ericw-tools lights
    /// nothing from it. Half-Life's `light "R G B I"` is a colour and a brightness.
    #[test]
    fn out_of_range_light_keys_warn() {
        let text = r#"
{ "classname" "worldspawn" }
{ "classname" "light" "origin" "0 0 0" "delay" "15" }
{ "classname" "light" "origin" "0 0 0" "light" "255 127 0 200" }
{ "classname" "light" "origin" "0 0 0" "light" "255 127" "_anglescale" "3" }
{ "classname" "light" "origin" "0 0 0" "delay" "2.5" "style" "300" }
"#;
        let mut ents = parse_entities(text).expect("parse");
        let lights = parse_lights(&mut ents, &Overrides::default()).expect("lights");
        assert_eq!(lights.points.len(), 3, "the delay 15 light lights nothing");
        assert_eq!(lights.points[0].light, 200.0);
        assert_eq!(lights.points[0].color, DVec3::new(1.0, 127.0 / 255.0, 0.0));
        assert_eq!(lights.points[1].light, DEFAULT_LIGHT);
        assert_eq!(lights.points[1].color, DVec3::ONE);
        assert_eq!(lights.points[1].anglescale, lights.points[0].anglescale);
        assert_eq!(lights.points[2].falloff, Falloff::InverseSquare);
        assert_eq!(lights.points[2].style, 254);
        let told: Vec<String> = lights.warnings.iter().map(ToString::to_string).collect();
        assert_eq!(told.len(), 5, "{told:?}");
        assert!(
            told[0].starts_with(
                "entity 1 (light, line 3 of the entity lump): key \"delay\" is \"15\""
            ),
            "{told:?}"
        );
        assert!(told[1].contains("(light, line 5"), "{told:?}");
        assert!(told[2].contains("\"_anglescale\" is \"3\""), "{told:?}");
    }

    #[test]
    fn dirt_keys_resolve_per_light() {
        let text = r#"
{ "classname" "worldspawn" "_dirt" "1" "_dirtscale" "1.5" "_dirtgain" "0.5" "_dirtdepth" "64" "_dirtangle" "120" "_dirtmode" "1" "_sunlight" "100" "_sunlight_dirt" "-1" }
{ "classname" "light" "origin" "0 0 0" }
{ "classname" "light" "origin" "0 0 0" "_dirt" "-1" }
{ "classname" "light" "origin" "0 0 0" "_dirtscale" "3" }
{ "classname" "func_wall" "model" "*1" "_dirt" "-1" "_lightignore" "1" "_minlight" "5" "_minlight_exclude" "sky1" }
"#;
        let mut ents = parse_entities(text).expect("parse");
        let lights = parse_lights(&mut ents, &Overrides::default()).expect("lights");
        let global = DirtResponse {
            scale: 1.5,
            gain: 0.5,
        };
        assert_eq!(lights.points[0].dirt, Some(global));
        assert_eq!(lights.points[1].dirt, None);
        assert_eq!(lights.points[2].dirt.map(|d| d.scale), Some(3.0));
        assert_eq!(lights.suns[0].dirt, None, "_sunlight_dirt -1");
        assert_eq!(lights.dirt.mode, DirtMode::Random);
        assert_eq!(lights.dirt.depth, 64.0);
        assert_eq!(lights.dirt.cone_degrees(), 90.0, "clamped to 90");
        assert_eq!(lights.no_dirt_models, vec![1]);
        assert_eq!(lights.lightignore_models, vec![1]);
        assert_eq!(lights.minlight[&1].exclude_texture.as_deref(), Some("sky1"));
        assert!(lights.uses_dirt());
        // Factor: 1 - min(1, scale * occlusion^gain).
        assert!(close(global.factor(0.25), 1.0 - 1.5 * 0.5));
        assert_eq!(global.factor(0.0), 1.0);
        assert_eq!(global.factor(1.0), 0.0);
    }

    #[test]
    fn bounce_keeps_dirt_when_every_light_opts_out() {
        // Regression: dirt was only traced for lights, so bounce lost its dirt here.
        let text = r#"
{ "classname" "worldspawn" "_dirt" "1" "_bounce" "1" }
{ "classname" "light" "origin" "0 0 0" "_dirt" "-1" }
"#;
        let mut ents = parse_entities(text).expect("parse");
        let lights = parse_lights(&mut ents, &Overrides::default()).expect("lights");
        assert_eq!(lights.points[0].dirt, None);
        assert!(lights.bounce.dirt.is_some());
        assert!(lights.uses_dirt());
    }

    #[test]
    fn falloff_key_and_deviance_split() {
        let text = r#"
{ "classname" "light" "origin" "0 0 0" "light" "200" "_falloff" "400" }
{ "classname" "light" "origin" "0 0 0" "light" "160" "delay" "2" "_deviance" "8" "_samples" "4" }
"#;
        let mut ents = parse_entities(text).expect("parse");
        let lights = parse_lights(&mut ents, &Overrides::default()).expect("lights");
        assert_eq!(lights.points.len(), 5);
        let linear = &lights.points[0];
        assert!(close(linear.value_at(200.0), 100.0), "half way to 400");
        assert_eq!(linear.value_at(400.0), 0.0);
        let total: f64 = lights.points[1..].iter().map(|l| l.light).sum();
        assert!(close(total, 160.0), "copies share the light");
        for l in &lights.points[1..] {
            assert!(l.origin.length() <= 8.0 + 1e-9);
        }
    }

    #[test]
    fn lmscale_rounds_down_to_a_power_of_two_texels() {
        assert_eq!(shift_of_texels(16.0), Some(4));
        assert_eq!(shift_of_texels(8.0), Some(3));
        assert_eq!(shift_of_texels(12.0), Some(3));
        assert_eq!(shift_of_texels(16.0 * 0.3), Some(2));
        assert_eq!(shift_of_texels(1.0), Some(0));
        assert_eq!(shift_of_texels(0.5), None);
        assert_eq!(shift_of_texels(-8.0), None);
    }
}
