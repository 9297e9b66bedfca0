//! Light sources read from the entity lump, and the formulas that turn a
//! light and a distance into brightness.
//!
//! Keys follow ericw-tools' documented meanings. Brightness is kept in
//! "light units" (a `light 300` entity gives 300 at its origin with linear
//! falloff); the range scale (`_range`, default 0.5) maps light units to
//! lightmap bytes at the very end.

use glam::DVec3;
use quake_formats::geom::DVec3Ext;
use std::collections::HashMap;

use quake_formats::bsp::phong;
use quake_formats::entities::Entity;

use crate::directions::{ball_points, cap_directions, mangle_to_vec};
use crate::dirt::{DEFAULT_DIRT_ANGLE, DEFAULT_DIRT_DEPTH, DirtMode, DirtResponse, DirtSampling};
use crate::error::LightError;

/// `light` value of a light entity without one (or with `light 0`, as
/// ericw-tools treats it).
pub const DEFAULT_LIGHT: f64 = 300.0;
/// Spotlight cone (full angle, degrees) when `angle` is absent.
pub const DEFAULT_SPOT_ANGLE: f64 = 40.0;
/// Angle-of-incidence weight when `_anglescale` is absent.
pub const DEFAULT_ANGLESCALE: f64 = 0.5;
/// Lightmap bytes per light unit when `_range` is absent.
pub const DEFAULT_RANGESCALE: f64 = 0.5;
/// First style given to switchable lights (styles below are the engine's
/// animated presets).
pub const FIRST_SWITCHABLE_STYLE: u8 = 32;
/// Lights a `_deviance` light is split into when `_samples` is absent.
pub const DEFAULT_DEVIANCE_SAMPLES: usize = 16;
/// Distance (map units) at which the 1/x and 1/x² formulas give `light`.
const FALLOFF_SCALE: f64 = 128.0;

/// How brightness falls off with distance (the `delay` key).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Falloff {
    /// 0: `light - dist * wait`.
    Linear,
    /// 1: `light * 128 / (dist * wait)`.
    Inverse,
    /// 2: `light * 128² / (dist * wait)²` (brighter than `light` within 128 units).
    InverseSquare,
    /// 3: `light` at any distance.
    Constant,
    /// 4: "local minlight": raises what the light sees to `light`, never adds.
    LocalMin,
    /// 5: `light * 128² / (dist * wait + 128)²`: inverse square without the
    /// bright spot near the source.
    InverseSquareSoft,
}

impl Falloff {
    fn from_delay(delay: i64) -> Option<Falloff> {
        Some(match delay {
            0 => Falloff::Linear,
            1 => Falloff::Inverse,
            2 => Falloff::InverseSquare,
            3 => Falloff::Constant,
            4 => Falloff::LocalMin,
            5 => Falloff::InverseSquareSoft,
            _ => return None,
        })
    }
}

/// A spotlight's cone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spot {
    /// Unit direction the light shines in.
    pub dir: DVec3,
    /// Cosine of half the outer cone angle: dimmer than this is dark.
    pub cos_outer: f64,
    /// Cosine of half the inner (`_softangle`) cone: full brightness inside.
    pub cos_inner: f64,
}

impl Spot {
    /// A cone of full angle `angle` degrees (non-positive means the default
    /// 40) with an optional soft inner cone of `softangle` degrees.
    pub fn new(dir: DVec3, angle: f64, softangle: f64) -> Spot {
        let angle = if angle > 0.0 {
            angle.min(360.0)
        } else {
            DEFAULT_SPOT_ANGLE
        };
        let cos_outer = (angle.to_radians() / 2.0).cos();
        let cos_inner = if softangle > 0.0 && softangle < angle {
            (softangle.to_radians() / 2.0).cos()
        } else {
            cos_outer
        };
        Spot {
            dir,
            cos_outer,
            cos_inner,
        }
    }

    /// Brightness factor for a point in unit direction `to_point` from the
    /// light: 1 inside the inner cone, 0 outside the outer one, linear in the
    /// cosine between them.
    pub fn factor(&self, to_point: DVec3) -> f64 {
        let c = self.dir.dot(to_point);
        if c < self.cos_outer {
            0.0
        } else if c >= self.cos_inner {
            1.0
        } else {
            (c - self.cos_outer) / (self.cos_inner - self.cos_outer)
        }
    }
}

/// The angle-of-incidence term: `scale * cos + (1 - scale)` for a surface
/// facing the light (`cos > 0`), else 0.
pub fn angle_factor(cos_incidence: f64, anglescale: f64) -> f64 {
    if cos_incidence <= 0.0 {
        0.0
    } else {
        anglescale * cos_incidence + (1.0 - anglescale)
    }
}

/// A light at a point (an entity, or one copy of a `_surface` template).
#[derive(Debug, Clone, PartialEq)]
pub struct PointLight {
    pub origin: DVec3,
    /// Brightness in light units; negative lights subtract.
    pub light: f64,
    /// Distance scale of the falloff: `wait` times the global `_dist`.
    pub atten: f64,
    pub falloff: Falloff,
    /// Per-channel colour, 1.0 = white.
    pub color: DVec3,
    pub style: u8,
    pub spot: Option<Spot>,
    pub anglescale: f64,
    /// How dirt darkens this light (`None`: it ignores dirt).
    pub dirt: Option<DirtResponse>,
    /// Its light bounces (false for `_bounce 0`).
    pub bounce: bool,
    /// Entity index it came from (for messages).
    pub entity: usize,
}

impl PointLight {
    /// Brightness at `dist` units from the light before angle and cone terms.
    pub fn value_at(&self, dist: f64) -> f64 {
        // Distances under one unit are clamped so 1/x stays finite.
        let scaled = (dist * self.atten).max(1.0);
        match self.falloff {
            Falloff::Linear => {
                if self.light >= 0.0 {
                    (self.light - scaled).max(0.0)
                } else {
                    (self.light + scaled).min(0.0)
                }
            }
            Falloff::Inverse => self.light * FALLOFF_SCALE / scaled,
            Falloff::InverseSquare => self.light * (FALLOFF_SCALE / scaled).powi(2),
            Falloff::Constant | Falloff::LocalMin => self.light,
            Falloff::InverseSquareSoft => {
                self.light * (FALLOFF_SCALE / (dist * self.atten + FALLOFF_SCALE)).powi(2)
            }
        }
    }

    /// Distance beyond which `|value_at|` stays below `gate` light units.
    pub fn range(&self, gate: f64) -> f64 {
        let l = self.light.abs();
        let gate = gate.max(1e-9);
        let r = match self.falloff {
            Falloff::Linear => l,
            Falloff::Inverse => l * FALLOFF_SCALE / gate,
            Falloff::InverseSquare => FALLOFF_SCALE * (l / gate).sqrt(),
            Falloff::InverseSquareSoft => FALLOFF_SCALE * ((l / gate).sqrt() - 1.0).max(0.0),
            Falloff::Constant | Falloff::LocalMin => return f64::INFINITY,
        };
        r / self.atten
    }

    /// Brightness this light adds at a point `dist` away in unit direction
    /// `to_point` (from the light), on a surface whose normal makes cosine
    /// `cos_incidence` with the direction back to the light.
    pub fn contribution(&self, dist: f64, to_point: DVec3, cos_incidence: f64) -> f64 {
        let angle = if self.falloff == Falloff::LocalMin {
            f64::from(u8::from(cos_incidence > 0.0))
        } else {
            angle_factor(cos_incidence, self.anglescale)
        };
        if angle == 0.0 {
            return 0.0;
        }
        let spot = self.spot.map_or(1.0, |s| s.factor(to_point));
        if spot == 0.0 {
            return 0.0;
        }
        self.value_at(dist) * angle * spot
    }
}

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
}

/// Passes beyond this bring nothing a lightmap byte can show.
pub const MAX_BOUNCE_PASSES: usize = 16;

/// Worldspawn `_bounce` and its keys (and their command-line overrides).
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
}

impl Default for BounceSettings {
    fn default() -> Self {
        BounceSettings {
            passes: 0,
            scale: 1.0,
            color_scale: 0.0,
            styled: false,
            dirt: None,
        }
    }
}

impl BounceSettings {
    /// Whether any light bounces.
    pub fn is_on(&self) -> bool {
        self.passes > 0 && self.scale > 0.0
    }
}

/// Settings that command-line options may override.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlobalOverrides {
    /// `--dist`: overrides worldspawn `_dist`.
    pub dist: Option<f64>,
    /// `--range`: overrides worldspawn `_range`.
    pub range: Option<f64>,
    /// `--sunsamples`: directions for a sun penumbra and for each sky dome.
    pub sunsamples: usize,
    /// `--dirt`: dirt on for every light, whatever worldspawn `_dirt` says.
    pub dirt: bool,
    /// `--dirtmode`, `--dirtdepth`, `--dirtscale`, `--dirtgain`, `--dirtangle`:
    /// override the worldspawn keys of the same names.
    pub dirt_mode: Option<f64>,
    pub dirt_depth: Option<f64>,
    pub dirt_scale: Option<f64>,
    pub dirt_gain: Option<f64>,
    pub dirt_angle: Option<f64>,
    /// `--addmin`: minlight is added to style 0 instead of raising it to a floor.
    pub addmin: bool,
    /// `--bounce N`, `--bouncescale`, `--bouncecolorscale`, `--bouncestyled`: override the
    /// worldspawn keys of the same names.
    pub bounce: Option<usize>,
    pub bounce_scale: Option<f64>,
    pub bounce_color_scale: Option<f64>,
    pub bounce_styled: bool,
}

impl Default for GlobalOverrides {
    fn default() -> Self {
        GlobalOverrides {
            dist: None,
            range: None,
            sunsamples: 100,
            dirt: false,
            dirt_mode: None,
            dirt_depth: None,
            dirt_scale: None,
            dirt_gain: None,
            dirt_angle: None,
            addmin: false,
            bounce: None,
            bounce_scale: None,
            bounce_color_scale: None,
            bounce_styled: false,
        }
    }
}

/// Everything the entity lump says about lighting.
#[derive(Debug, Clone, PartialEq)]
pub struct MapLights {
    pub points: Vec<PointLight>,
    pub suns: Vec<SunLight>,
    pub templates: Vec<SurfaceTemplate>,
    /// Minlight per model index (0 = world, from worldspawn).
    pub minlight: HashMap<usize, Minlight>,
    /// Brush models that cast shadows (`_shadow 1`).
    pub shadow_models: Vec<usize>,
    /// Brush models that shadow only their own faces (`_shadowself 1`).
    pub self_shadow_models: Vec<usize>,
    /// Brush models whose faces never take dirt (`_dirt -1`).
    pub no_dirt_models: Vec<usize>,
    /// Brush models whose faces get minlight only (`_lightignore 1`).
    pub lightignore_models: Vec<usize>,
    /// Brush models whose faces do not reflect light (`_bounce 0`).
    pub no_bounce_models: Vec<usize>,
    /// Diffuse interreflection (`_bounce` and its keys).
    pub bounce: BounceSettings,
    /// How dirt occlusion is measured (used only when something takes dirt).
    pub dirt: DirtSampling,
    /// Brush models (0 = world) with `_phong` smoothing, and their angle in degrees.
    pub phong: HashMap<usize, f64>,
    /// Offset of each brush model with an `origin` key (rotating entities).
    pub model_origins: HashMap<usize, DVec3>,
    /// Lightmap bytes per light unit.
    pub rangescale: f64,
    pub gamma: f64,
    /// Styles given to switchable lights (`targetname` -> style), also
    /// written back into the entities as `style`.
    pub switchable_styles: Vec<(String, u8)>,
}

impl MapLights {
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
        self.points.iter().any(|l| grey(&l.color))
            || self.suns.iter().any(|s| grey(&s.color))
            || self.templates.iter().any(|t| grey(&t.light.color))
            || self.minlight.values().any(|m| grey(&m.color))
    }
}

/// Reads a numeric key of entity `index`, naming the entity on failure.
struct Keys<'a> {
    entity: &'a Entity,
    index: usize,
}

impl Keys<'_> {
    fn bad(&self, key: &str, want: &str) -> LightError {
        LightError::Entity {
            index: self.index,
            classname: self.entity.classname().to_string(),
            detail: format!(
                "key \"{key}\" is \"{}\", expected {want}",
                self.entity.get(key).unwrap_or("")
            ),
        }
    }

    fn float(&self, key: &str) -> Result<Option<f64>, LightError> {
        match self.entity.get(key) {
            None => Ok(None),
            Some(v) if v.trim().is_empty() => Ok(None),
            Some(_) => self
                .entity
                .get_float(key)
                .filter(|f| f.is_finite())
                .map(Some)
                .ok_or_else(|| self.bad(key, "a number")),
        }
    }

    /// The first of `keys` that is present.
    fn float_any(&self, keys: &[&str]) -> Result<Option<f64>, LightError> {
        for k in keys {
            if let Some(v) = self.float(k)? {
                return Ok(Some(v));
            }
        }
        Ok(None)
    }

    fn vec3(&self, key: &str) -> Result<Option<DVec3>, LightError> {
        match self.entity.get(key) {
            None => Ok(None),
            Some(v) if v.trim().is_empty() => Ok(None),
            Some(_) => self
                .entity
                .get_floats::<3>(key)
                .filter(|f| f.iter().all(|c| c.is_finite()))
                .map(|[x, y, z]| Some(DVec3::new(x, y, z)))
                .ok_or_else(|| self.bad(key, "three numbers")),
        }
    }

    /// A colour in 0..255 or 0..1 notation, as 1.0 = full channel.
    fn color_any(&self, keys: &[&str]) -> Result<DVec3, LightError> {
        for k in keys {
            if let Some(c) = self.vec3(k)? {
                return Ok(normalize_color(c));
            }
        }
        Ok(DVec3::new(1.0, 1.0, 1.0))
    }

    fn style(&self) -> Result<u8, LightError> {
        match self.float("style")? {
            None => Ok(0),
            Some(s) if s.fract() == 0.0 && (0.0..=254.0).contains(&s) => Ok(s as u8),
            Some(_) => Err(self.bad("style", "a whole number from 0 to 254")),
        }
    }
}

/// ericw-tools' colour rule: components all within 0..1 are fractions,
/// otherwise they are 0..255.
pub fn normalize_color(c: DVec3) -> DVec3 {
    if c.x <= 1.0 && c.y <= 1.0 && c.z <= 1.0 {
        c
    } else {
        c / 255.0
    }
}

/// Splits the light of `sun` evenly over `dirs` (its `to_sun` is replaced).
fn suns_over(dirs: Vec<DVec3>, sun: &SunLight) -> Vec<SunLight> {
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

/// Whether something takes dirt: its own switch (1 on, -1 off), else the
/// global setting.
fn dirt_if(switch: Option<f64>, global_on: bool, response: DirtResponse) -> Option<DirtResponse> {
    let on = match switch {
        Some(1.0) => true,
        Some(-1.0) => false,
        _ => global_on,
    };
    on.then_some(response)
}

fn model_index(e: &Entity) -> Option<usize> {
    e.get("model")?.strip_prefix('*')?.parse().ok()
}

/// Reads every light from `entities` and assigns styles to switchable
/// lights (writing `style` into those entities).
///
/// # Errors
/// [`LightError::Entity`] for a key that does not parse.
pub fn parse_lights(
    entities: &mut [Entity],
    overrides: &GlobalOverrides,
) -> Result<MapLights, LightError> {
    let switchable_styles = assign_switchable_styles(entities)?;
    let world = entities
        .iter()
        .position(|e| e.classname() == "worldspawn")
        .unwrap_or(usize::MAX);
    let empty = Entity::default();
    let wk = Keys {
        entity: entities.get(world).unwrap_or(&empty),
        index: world,
    };
    let scaledist = overrides.dist.or(wk.float("_dist")?).unwrap_or(1.0);
    let rangescale = overrides
        .range
        .or(wk.float("_range")?)
        .unwrap_or(DEFAULT_RANGESCALE);
    let gamma = wk.float("_gamma")?.filter(|g| *g > 0.0).unwrap_or(1.0);
    let global_anglescale = wk
        .float_any(&["_anglescale", "_anglesense"])?
        .unwrap_or(DEFAULT_ANGLESCALE)
        .clamp(0.0, 1.0);
    let sunsamples = overrides.sunsamples.max(1);
    let global_dirt = overrides.dirt || wk.float("_dirt")? == Some(1.0);
    let global_response = DirtResponse {
        scale: overrides
            .dirt_scale
            .or(wk.float("_dirtscale")?)
            .filter(|s| *s >= 0.0)
            .unwrap_or(1.0),
        gain: overrides
            .dirt_gain
            .or(wk.float("_dirtgain")?)
            .filter(|g| *g > 0.0)
            .unwrap_or(1.0),
    };
    let dirt = DirtSampling::new(
        if overrides.dirt_mode.or(wk.float("_dirtmode")?) == Some(1.0) {
            DirtMode::Random
        } else {
            DirtMode::Ordered
        },
        overrides
            .dirt_depth
            .or(wk.float("_dirtdepth")?)
            .filter(|d| *d > 0.0)
            .unwrap_or(DEFAULT_DIRT_DEPTH),
        overrides
            .dirt_angle
            .or(wk.float("_dirtangle")?)
            .unwrap_or(DEFAULT_DIRT_ANGLE)
            .clamp(1.0, 90.0),
    );
    // A light's own `_dirtscale` / `_dirtgain` (non-zero) win over the global ones.
    let response_of = |k: &Keys| -> Result<DirtResponse, LightError> {
        Ok(DirtResponse {
            scale: k
                .float("_dirtscale")?
                .filter(|s| *s > 0.0)
                .unwrap_or(global_response.scale),
            gain: k
                .float("_dirtgain")?
                .filter(|g| *g > 0.0)
                .unwrap_or(global_response.gain),
        })
    };
    let minlight_dirt = dirt_if(wk.float("_minlight_dirt")?, global_dirt, global_response);
    let mut bounce = bounce_settings(&wk, overrides)?;
    bounce.dirt = global_dirt.then_some(global_response);

    let mut out = MapLights {
        points: Vec::new(),
        suns: Vec::new(),
        templates: Vec::new(),
        minlight: HashMap::new(),
        shadow_models: Vec::new(),
        self_shadow_models: Vec::new(),
        no_dirt_models: Vec::new(),
        lightignore_models: Vec::new(),
        no_bounce_models: Vec::new(),
        bounce,
        dirt,
        phong: HashMap::new(),
        model_origins: HashMap::new(),
        rangescale,
        gamma,
        switchable_styles,
    };

    // Worldspawn: minlight, sun, sky domes.
    let world_min = wk.float_any(&["_minlight", "light"])?.unwrap_or(0.0);
    if world_min != 0.0 {
        let color = wk.color_any(&["_minlight_color", "_mincolor"])?;
        out.minlight.insert(
            0,
            Minlight {
                level: world_min,
                add: overrides.addmin,
                color,
                dirt: minlight_dirt,
                exclude_texture: wk.entity.get("_minlight_exclude").map(str::to_string),
            },
        );
    }
    if let Some(sun) = wk.float("_sunlight")?.filter(|s| *s != 0.0) {
        let mangle = wk
            .vec3("_sun_mangle")?
            .or(wk.vec3("_sunlight_mangle")?)
            .unwrap_or(DVec3::new(0.0, -90.0, 0.0));
        let penumbra = wk.float("_sunlight_penumbra")?.unwrap_or(0.0);
        let to_sun = -mangle_to_vec(mangle.x, mangle.y);
        let template = SunLight {
            to_sun,
            light: sun,
            color: wk.color_any(&["_sunlight_color"])?,
            style: 0,
            anglescale: global_anglescale,
            dirt: dirt_if(wk.float("_sunlight_dirt")?, global_dirt, global_response),
            directions: 1,
        };
        let dirs = cap_directions(to_sun, penumbra, sunsamples);
        out.suns.extend(suns_over(dirs, &template));
    }
    let dome_dirt = dirt_if(wk.float("_sunlight2_dirt")?, global_dirt, global_response);
    for (key, colors, up) in [
        ("_sunlight2", ["_sunlight2_color", "_sunlight_color2"], 1.0),
        ("_sunlight3", ["_sunlight3_color", "_sunlight_color3"], -1.0),
    ] {
        if let Some(dome) = wk.float(key)?.filter(|s| *s != 0.0) {
            let up = DVec3::new(0.0, 0.0, up);
            let template = SunLight {
                to_sun: up,
                light: dome,
                color: wk.color_any(&colors)?,
                style: 0,
                anglescale: global_anglescale,
                dirt: dome_dirt,
                directions: 1,
            };
            out.suns
                .extend(suns_over(cap_directions(up, 90.0, sunsamples), &template));
        }
    }

    for (index, e) in entities.iter().enumerate() {
        let model = if index == world {
            Some(0)
        } else {
            model_index(e).filter(|&m| m > 0)
        };
        if let Some(model) = model {
            let k = Keys { entity: e, index };
            let keys = (k.float("_phong")?, k.float("_phong_angle")?);
            if let Some(angle) = phong::angle_from_keys(keys.0, keys.1) {
                out.phong.insert(model, angle);
            }
        }
    }

    let origins: HashMap<&str, DVec3> = entities
        .iter()
        .filter_map(|e| {
            let [x, y, z] = e.get_floats::<3>("origin")?;
            Some((e.get("targetname")?, DVec3::new(x, y, z)))
        })
        .collect();

    for (index, e) in entities.iter().enumerate() {
        let k = Keys { entity: e, index };
        if let Some(model) = model_index(e).filter(|&m| m > 0) {
            if k.float("_shadow")?.unwrap_or(0.0) == 1.0 {
                out.shadow_models.push(model);
            }
            if k.float_any(&["_shadowself", "_selfshadow"])? == Some(1.0) {
                out.self_shadow_models.push(model);
            }
            if let Some(o) = k.vec3("origin")? {
                out.model_origins.insert(model, o);
            }
            if k.float("_dirt")? == Some(-1.0) {
                out.no_dirt_models.push(model);
            }
            if k.float("_lightignore")? == Some(1.0) {
                out.lightignore_models.push(model);
            }
            if k.float("_bounce")?.is_some_and(|b| b <= 0.0) {
                out.no_bounce_models.push(model);
            }
            if let Some(level) = k.float("_minlight")?.filter(|m| *m != 0.0) {
                let color = k.color_any(&["_minlight_color", "_mincolor"])?;
                out.minlight.insert(
                    model,
                    Minlight {
                        level,
                        add: overrides.addmin,
                        color,
                        dirt: minlight_dirt,
                        exclude_texture: e.get("_minlight_exclude").map(str::to_string),
                    },
                );
            }
            continue;
        }
        if !e.classname().starts_with("light") || k.float("_nostaticlight")? == Some(1.0) {
            continue;
        }
        let origin = k.vec3("origin")?.unwrap_or(DVec3::ZERO);
        let light = match k.float("light")? {
            None => DEFAULT_LIGHT,
            Some(0.0) => DEFAULT_LIGHT,
            Some(l) => l,
        };
        let color = k.color_any(&["_color"])?;
        let style = k.style()?;
        let anglescale = k
            .float_any(&["_anglescale", "_anglesense"])?
            .unwrap_or(global_anglescale)
            .clamp(0.0, 1.0);
        // The direction a spotlight (or a `_sun` entity) shines in.
        let aim = match (k.vec3("mangle")?, e.get("target")) {
            (Some(m), _) => Some(mangle_to_vec(m.x, m.y)),
            (None, Some(t)) => origins.get(t).and_then(|&to| (to - origin).normalized()),
            (None, None) => None,
        };
        let dirt = dirt_if(k.float("_dirt")?, global_dirt, response_of(&k)?);
        let deviance = k.float("_deviance")?.unwrap_or(0.0).max(0.0);
        if k.float("_sun")? == Some(1.0) {
            let to_sun = -aim.unwrap_or(DVec3::new(0.0, 0.0, -1.0));
            let template = SunLight {
                to_sun,
                light,
                color,
                style,
                anglescale,
                dirt,
                directions: 1,
            };
            let dirs = cap_directions(to_sun, deviance, sunsamples);
            out.suns.extend(suns_over(dirs, &template));
            continue;
        }
        let mut dome = false;
        for (key, up) in [("_sunlight2", 1.0), ("_sunlight3", -1.0)] {
            if k.float(key)? == Some(1.0) {
                let up = DVec3::new(0.0, 0.0, up);
                let template = SunLight {
                    to_sun: up,
                    light,
                    color,
                    style,
                    anglescale,
                    dirt,
                    directions: 1,
                };
                out.suns
                    .extend(suns_over(cap_directions(up, 90.0, sunsamples), &template));
                dome = true;
            }
        }
        if dome {
            continue;
        }
        let delay = k.float("delay")?.unwrap_or(0.0);
        let falloff = Falloff::from_delay(delay as i64)
            .filter(|_| delay.fract() == 0.0)
            .ok_or_else(|| k.bad("delay", "0, 1, 2, 3, 4 or 5"))?;
        let wait = k.float("wait")?.filter(|w| *w > 0.0).unwrap_or(1.0);
        // `_falloff` (linear only): reaches zero exactly that many units out.
        let atten = match k.float("_falloff")?.filter(|f| *f > 0.0) {
            Some(reach) if falloff == Falloff::Linear => light.abs() / reach,
            _ => wait * scaledist,
        };
        let angle = k.float("angle")?.unwrap_or(DEFAULT_SPOT_ANGLE);
        let softangle = k.float("_softangle")?.unwrap_or(0.0);
        let point = PointLight {
            origin,
            light,
            atten,
            falloff,
            color,
            style,
            spot: aim.map(|dir| Spot::new(dir, angle, softangle)),
            anglescale,
            dirt,
            bounce: k.float("_bounce")?.is_none_or(|b| b > 0.0),
            entity: index,
        };
        match e.get("_surface").filter(|t| !t.is_empty()) {
            Some(texture) => out.templates.push(SurfaceTemplate {
                texture: texture.to_string(),
                light: PointLight {
                    spot: None,
                    ..point
                },
                offset: k.float("_surface_offset")?.unwrap_or(2.0),
                spotlight: k.float("_surface_spotlight")? == Some(1.0),
                spot_angle: angle,
            }),
            None if deviance > 0.0 => {
                let count = k
                    .float("_samples")?
                    .filter(|n| *n >= 1.0)
                    .map_or(DEFAULT_DEVIANCE_SAMPLES, |n| n as usize);
                out.points.extend(split_light(&point, deviance, count));
            }
            None => out.points.push(point),
        }
    }
    Ok(out)
}

/// Worldspawn's `_bounce`, `_bouncescale`, `_bouncecolorscale` and `_bouncestyled`, with the
/// command line's overrides.
fn bounce_settings(wk: &Keys, o: &GlobalOverrides) -> Result<BounceSettings, LightError> {
    let passes = match o.bounce {
        Some(n) => n,
        None => match wk.float("_bounce")? {
            Some(n) if n >= 0.0 && n.fract() == 0.0 => n as usize,
            Some(_) => return Err(wk.bad("_bounce", "a whole number of passes, 0 or more")),
            None => 0,
        },
    };
    Ok(BounceSettings {
        passes: passes.min(MAX_BOUNCE_PASSES),
        scale: o
            .bounce_scale
            .or(wk.float("_bouncescale")?)
            .unwrap_or(1.0)
            .max(0.0),
        color_scale: o
            .bounce_color_scale
            .or(wk.float("_bouncecolorscale")?)
            .unwrap_or(0.0)
            .clamp(0.0, 1.0),
        styled: o.bounce_styled || wk.float("_bouncestyled")? == Some(1.0),
        dirt: None,
    })
}

/// `_deviance`: `light` as `count` lights spread through a ball of `radius`,
/// together as bright as the one light. Linear lights also divide their
/// fade rate, so each copy still reaches as far as the original; local
/// minlight raises to a level rather than adding, so its copies keep it.
pub fn split_light(light: &PointLight, radius: f64, count: usize) -> Vec<PointLight> {
    let n = count.max(1) as f64;
    ball_points(light.origin, radius, count.max(1))
        .into_iter()
        .map(|origin| {
            let mut copy = light.clone();
            copy.origin = origin;
            match light.falloff {
                Falloff::LocalMin => {}
                Falloff::Linear => {
                    copy.light /= n;
                    copy.atten /= n;
                }
                _ => copy.light /= n,
            }
            copy
        })
        .collect()
}

/// Gives each `targetname` of a light entity without an explicit `style` its
/// own style from 32 up (lights sharing a name share it) and writes it into
/// the entity, so the game's switching code finds it.
pub(crate) fn assign_switchable_styles(
    entities: &mut [Entity],
) -> Result<Vec<(String, u8)>, LightError> {
    let mut assigned: Vec<(String, u8)> = Vec::new();
    for (index, e) in entities.iter_mut().enumerate() {
        if !e.classname().starts_with("light") {
            continue;
        }
        let Some(name) = e.get("targetname").filter(|n| !n.is_empty()) else {
            continue;
        };
        let k = Keys { entity: e, index };
        if k.style()? != 0 {
            continue;
        }
        let style = match assigned.iter().find(|(n, _)| n == name) {
            Some(&(_, s)) => s,
            None => {
                let next = FIRST_SWITCHABLE_STYLE as usize + assigned.len();
                let s = u8::try_from(next)
                    .ok()
                    .filter(|s| *s <= quake_formats::bsp::limits::MAX_LIGHTSTYLE)
                    .ok_or(LightError::TooManySwitchableLights)?;
                assigned.push((name.to_string(), s));
                s
            }
        };
        e.set("style", style.to_string());
    }
    Ok(assigned)
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::entities::parse_entities;

    fn light(falloff: Falloff, value: f64, wait: f64) -> PointLight {
        PointLight {
            origin: DVec3::ZERO,
            light: value,
            atten: wait,
            falloff,
            color: DVec3::new(1.0, 1.0, 1.0),
            style: 0,
            spot: None,
            anglescale: 0.5,
            dirt: None,
            bounce: true,
            entity: 0,
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9 * b.abs().max(1.0)
    }

    #[test]
    fn linear_falloff_reaches_zero_at_light_over_wait() {
        let l = light(Falloff::Linear, 300.0, 1.0);
        assert!(close(l.value_at(0.0), 299.0), "clamped to 1 unit");
        assert!(close(l.value_at(100.0), 200.0));
        assert_eq!(l.value_at(400.0), 0.0);
        assert!(close(l.range(0.001), 300.0));
        let l = light(Falloff::Linear, 300.0, 2.0);
        assert!(close(l.value_at(100.0), 100.0));
        assert!(close(l.range(0.001), 150.0));
        let neg = light(Falloff::Linear, -100.0, 1.0);
        assert!(close(neg.value_at(40.0), -60.0));
        assert_eq!(neg.value_at(500.0), 0.0);
    }

    #[test]
    fn inverse_falloffs_equal_light_at_128_units() {
        for f in [Falloff::Inverse, Falloff::InverseSquare] {
            let l = light(f, 200.0, 1.0);
            assert!(close(l.value_at(128.0), 200.0), "{f:?}");
            let at = l.range(0.5);
            assert!(close(l.value_at(at), 0.5), "{f:?} range");
        }
        let inv = light(Falloff::Inverse, 200.0, 1.0);
        assert!(close(inv.value_at(256.0), 100.0));
        let sq = light(Falloff::InverseSquare, 200.0, 1.0);
        assert!(close(sq.value_at(256.0), 50.0));
        assert!(close(sq.value_at(64.0), 800.0), "bright near the source");
        // Wait scales distance.
        let sq2 = light(Falloff::InverseSquare, 200.0, 2.0);
        assert!(close(sq2.value_at(64.0), 200.0));
    }

    #[test]
    fn soft_inverse_square_is_light_at_the_source() {
        let l = light(Falloff::InverseSquareSoft, 300.0, 1.0);
        assert!(close(l.value_at(0.0), 300.0));
        assert!(close(l.value_at(128.0), 75.0));
        assert!(close(l.value_at(l.range(0.25)), 0.25));
    }

    #[test]
    fn constant_and_local_min_ignore_distance() {
        for f in [Falloff::Constant, Falloff::LocalMin] {
            let l = light(f, 50.0, 1.0);
            assert_eq!(l.value_at(1.0e5), 50.0);
            assert_eq!(l.range(0.001), f64::INFINITY);
        }
        // Local minlight has no angle term: any surface facing it gets the full value.
        let l = light(Falloff::LocalMin, 50.0, 1.0);
        assert_eq!(l.contribution(10.0, DVec3::new(1.0, 0.0, 0.0), 0.01), 50.0);
        assert_eq!(l.contribution(10.0, DVec3::new(1.0, 0.0, 0.0), -0.5), 0.0);
    }

    #[test]
    fn angle_factor_blends_cosine() {
        assert_eq!(angle_factor(1.0, 0.5), 1.0);
        assert!(close(angle_factor(0.0001, 0.5), 0.50005));
        assert_eq!(angle_factor(-0.1, 0.5), 0.0);
        assert!(close(angle_factor(0.5, 1.0), 0.5));
        assert_eq!(angle_factor(0.3, 0.0), 1.0);
    }

    #[test]
    fn spotlight_cone_edges() {
        let down = DVec3::new(0.0, 0.0, -1.0);
        let at = |deg: f64| {
            let r = deg.to_radians();
            DVec3::new(r.sin(), 0.0, -r.cos())
        };
        // Default 40 degrees: 20 each side of the axis.
        let s = Spot::new(down, 0.0, 0.0);
        assert_eq!(s.factor(at(0.0)), 1.0);
        assert_eq!(s.factor(at(19.9)), 1.0);
        assert_eq!(s.factor(at(20.1)), 0.0);
        // 60 degree cone with a 20 degree soft inner cone.
        let s = Spot::new(down, 60.0, 20.0);
        assert_eq!(s.factor(at(9.9)), 1.0);
        assert_eq!(s.factor(at(30.1)), 0.0);
        let mid = s.factor(at(20.0));
        let want = (20f64.to_radians().cos() - 30f64.to_radians().cos())
            / (10f64.to_radians().cos() - 30f64.to_radians().cos());
        assert!(close(mid, want) && mid > 0.0 && mid < 1.0, "{mid}");
        // A soft angle wider than the cone is ignored.
        let s = Spot::new(down, 30.0, 50.0);
        assert_eq!(s.cos_inner, s.cos_outer);
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
        let lights = parse_lights(&mut ents, &GlobalOverrides::default()).expect("lights");
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
        assert_eq!(lights.switchable_styles, vec![("door".to_string(), 32)]);
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

    #[test]
    fn bad_numbers_name_the_entity() {
        let mut ents = parse_entities(
            "{ \"classname\" \"worldspawn\" }\n{ \"classname\" \"light\" \"light\" \"bright\" }",
        )
        .expect("parse");
        let err = parse_lights(&mut ents, &GlobalOverrides::default()).expect_err("bad light");
        let msg = err.to_string();
        assert!(
            msg.contains("entity 1") && msg.contains("\"light\""),
            "{msg}"
        );
        let mut ents =
            parse_entities("{ \"classname\" \"light\" \"delay\" \"7\" }").expect("parse");
        assert!(parse_lights(&mut ents, &GlobalOverrides::default()).is_err());
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
        let lights = parse_lights(&mut ents, &GlobalOverrides::default()).expect("lights");
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
        let lights = parse_lights(&mut ents, &GlobalOverrides::default()).expect("lights");
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
        let lights = parse_lights(&mut ents, &GlobalOverrides::default()).expect("lights");
        assert_eq!(lights.points.len(), 5);
        let linear = &lights.points[0];
        assert!(close(linear.value_at(200.0), 100.0), "half way to 400");
        assert_eq!(linear.value_at(400.0), 0.0);
        let total: f64 = lights.points[1..].iter().map(|l| l.light).sum();
        assert!(close(total, 160.0), "copies share the light");
        for l in &lights.points[1..] {
            assert!(l.origin.length() <= 8.0 + 1e-9);
        }
        // Linear copies divide the fade rate too: together as bright, as far-reaching.
        let one = light(Falloff::Linear, 300.0, 1.0);
        let split = split_light(&one, 4.0, 3);
        let sum: f64 = split.iter().map(|l| l.value_at(100.0)).sum();
        assert!(close(sum, one.value_at(100.0)));
        assert!(close(split[0].range(0.001), one.range(0.001)));
    }
}
