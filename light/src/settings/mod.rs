//! Light's map-wide settings, each declared once below: its command-line flag (and any other
//! spelling ericw-tools uses), its worldspawn keys, its default, its range and its help text.
//!
//! From that one declaration come the typed [`Settings`] a run resolves, the [`Overrides`] a
//! run is given, the command line's arguments (built from [`TABLE`] by the `cli` feature), the
//! settings table of `docs/mapping.md` ([`markdown_table`]; a test holds the two together) and
//! the reading of worldspawn's keys ([`Settings::resolve`]). A value given on the command line
//! wins over worldspawn's, as in ericw-tools. A worldspawn value that does not read as its type
//! leaves the default; one outside its range is clamped into it or leaves the default, as its
//! [`Range`] says; either way with a warning naming the entity and key, never an error.
//!
//! Adding a setting is one more entry in the `settings!` list below (its type implementing
//! [`SettingValue`]); the code that uses it reads the new field of [`Settings`].

mod declare;
mod resolve;
mod value;

use glam::DVec3;

pub use crate::bounce::EmissiveQuality;
pub use crate::dirt::DirtMode;
pub use declare::Setting;
use declare::{settings, without_underscore};
pub use resolve::{ChosenSetting, Given, SettingWarning, Told, World};
use resolve::{Declared, given, resolve};
pub use value::{Color, DirtToggle, Range, SettingValue, SoftRadius, Spacing, normalize_color};

settings! {
    /// Blur the light over N samples each way before samples are averaged to luxels, as
    /// ericw-tools does (`--soft` alone, or -1: half the samples along a luxel's side, which is
    /// 2 with `--extra4`, 1 with `--extra` and no blur with one sample a luxel).
    soft: SoftRadius = SoftRadius::Samples(0), flag "soft" missing "-1", keys [], range Range::Any;

    /// Light contributions below this many light units count as zero.
    gate: f64 = 0.001, flag "gate", keys [], range Range::Any;

    /// Scales every light's falloff distance.
    dist: f64 = 1.0, flag "dist", keys ["_dist"], range Range::Any;

    /// Lightmap bytes per light unit (scales every light's brightness).
    range: f64 = 0.5, flag "range", keys ["_range"], range Range::Any;

    /// Gamma applied to the lightmaps.
    gamma: f64 = 1.0, keys ["_gamma"], range Range::Above(0.0);

    /// How much a surface's angle to the light matters, 0 (not at all) to 1 (the cosine); lights
    /// without their own `_anglescale` take this.
    anglescale: f64 = 0.5, keys ["_anglescale", "_anglesense"], range Range::Clamp(0.0, 1.0);

    /// Directions per sun penumbra and per sky dome (a dome of 64 is ericw-tools' four rings of
    /// 16 and one straight down).
    sunsamples: usize = 64, flag "sunsamples", keys [], range Range::Clamp(8.0, 2048.0);

    /// Minimum light of the world's faces.
    minlight: f64 = 0.0, keys ["_minlight", "light"], range Range::Any;

    /// Colour of the minimum light.
    minlight_color: Color = Color::WHITE, keys ["_minlight_color", "_mincolor"], range Range::Any;

    /// A texture that does not get the world's minimum light.
    minlight_exclude: Option<String> = None, keys ["_minlight_exclude"], range Range::Any;

    /// `1`: dirt darkens the minimum light too; `-1`: it does not.
    minlight_dirt: DirtToggle = DirtToggle::AsDirt, keys ["_minlight_dirt"], range Range::Any;

    /// Add minlight to every luxel's light instead of raising dark luxels to it.
    addmin: bool = false, flag "addmin", keys [], range Range::Any;

    /// `1`: the minimum light is mottled: a slow noise of 0 to 48 levels, on a lattice of 16
    /// units fixed in the world, is added to it, so a surface lit by nothing else does not read
    /// as one flat wash (Quake II's look; brush models may set their own).
    minlight_mottle: bool = false, keys ["_minlight_mottle", "_minlightMottle"], range Range::Any;

    /// The most light a luxel takes, in levels (0: no cap): a brighter sample is dimmed to it,
    /// its colour kept, as ericw-tools dims it.
    maxlight: f64 = 0.0, keys ["_maxlight"], range Range::Any;

    /// `1`: a spotlight aimed at its `target` (and without `_falloff`) falls off linearly to
    /// zero just past its cone's reach at the target: the distance to it plus the cone's radius
    /// there, as in ericw-tools (linear lights only).
    spotlight_autofalloff: bool = false, keys ["_spotlightautofalloff"], range Range::Any;

    /// First light style given to switchable lights and shadows (styles below are Quake's
    /// animated presets).
    compilerstyle_start: usize = 32, keys ["_compilerstyle_start"], range Range::Clamp(1.0, 254.0);

    /// Switchable styles stay below this one: QuakeSpasm, Ironwail, vkQuake and id's engine
    /// keep 64 light styles (a map with more switchable names than fit is refused, as
    /// ericw-tools refuses it); DarkPlaces and FTE take up to 255.
    compilerstyle_max: usize = 64, keys ["_compilerstyle_max"], range Range::Clamp(1.0, 255.0);

    /// Ignore light entities (their suns, domes and surface lights too): only worldspawn's
    /// sunlight, sky domes and minlight light the map.
    nolights: bool = false, flag "nolights", keys [], range Range::Any;

    /// Sun brightness (light from sky faces).
    sunlight: f64 = 0.0, keys ["_sunlight", "_sun_light"], range Range::Any;

    /// Direction the sunlight travels, `yaw pitch roll` in degrees.
    sun_mangle: DVec3 = DVec3::new(0.0, -90.0, 0.0), keys ["_sun_mangle", "_sunlight_mangle", "_sun_angle"], range Range::Any;

    /// Soft sun: its directions spread over a cone this many degrees wide.
    sun_penumbra: f64 = 0.0, keys ["_sunlight_penumbra"], range Range::Any;

    /// Sun colour.
    sunlight_color: Color = Color::WHITE, keys ["_sunlight_color", "_sun_color"], range Range::Any;

    /// `1`/`-1`: dirt on sunlight on/off.
    sunlight_dirt: DirtToggle = DirtToggle::AsDirt, keys ["_sunlight_dirt"], range Range::Any;

    /// Brightness of a second sun, spread and dirtied as the first.
    sun2: f64 = 0.0, keys ["_sun2"], range Range::Any;

    /// Direction the second sun's light travels, `yaw pitch roll` in degrees.
    sun2_mangle: DVec3 = DVec3::new(0.0, -90.0, 0.0), keys ["_sun2_mangle"], range Range::Any;

    /// Colour of the second sun.
    sun2_color: Color = Color::WHITE, keys ["_sun2_color"], range Range::Any;

    /// Brightness of a sky dome lighting from above: `--sunsamples` directions on rings of equal elevation steps and one straight down, laid out as ericw-tools lays them, so its sky is brighter overhead than at the horizon.
    sunlight2: f64 = 0.0, keys ["_sunlight2"], range Range::Any;

    /// Colour of the upper sky dome.
    sunlight2_color: Color = Color::WHITE, keys ["_sunlight2_color", "_sunlight_color2"], range Range::Any;

    /// `1`/`-1`: dirt on both sky domes on/off.
    sunlight2_dirt: DirtToggle = DirtToggle::AsDirt, keys ["_sunlight2_dirt"], range Range::Any;

    /// Brightness of a sky dome lighting from below.
    sunlight3: f64 = 0.0, keys ["_sunlight3"], range Range::Any;

    /// Colour of the lower sky dome.
    sunlight3_color: Color = Color::WHITE, keys ["_sunlight3_color", "_sunlight_color3"], range Range::Any;

    /// Dirt (ambient occlusion) on every light, sun and minlight (lights with `_dirt -1` still
    /// opt out).
    dirt: bool = false, flag "dirt" alias "dirty", keys ["_dirt", "_dirty"], range Range::Any;

    /// Dirt ray pattern: `0` an ordered cone, `1` random directions per sample.
    dirt_mode: DirtMode = DirtMode::Ordered, flag "dirtmode", keys ["_dirtmode"], range Range::Any;

    /// How far dirt rays look, in units.
    dirt_depth: f64 = 128.0, flag "dirtdepth", keys ["_dirtdepth"], range Range::Above(0.0);

    /// Strength of dirt.
    dirt_scale: f64 = 1.0, flag "dirtscale", keys ["_dirtscale"], range Range::AtLeast(0.0);

    /// Contrast of dirt (the exponent on occlusion).
    dirt_gain: f64 = 1.0, flag "dirtgain", keys ["_dirtgain"], range Range::Above(0.0);

    /// Dirt cone half-angle from the normal, in degrees.
    dirt_angle: f64 = 88.0, flag "dirtangle", keys ["_dirtangle"], range Range::Clamp(1.0, 90.0);

    /// Bounced light: passes of diffuse interreflection (`--bounce` alone: 1). Passes beyond 16
    /// bring nothing a lightmap byte can show.
    bounce: usize = 0, flag "bounce" missing "1", keys ["_bounce"], range Range::Clamp(0.0, 16.0);

    /// Brightness of bounced light.
    bounce_scale: f64 = 1.0, flag "bouncescale", keys ["_bouncescale"], range Range::Clamp(0.0, f64::INFINITY);

    /// How much of a texture's mean colour its reflection takes, 0 (grey) to 1.
    bounce_color_scale: f64 = 0.0, flag "bouncecolorscale", keys ["_bouncecolorscale"], range Range::Clamp(0.0, 1.0);

    /// Light of switchable and animated styles reflects too, in its own style.
    bounce_styled: bool = false, flag "bouncestyled", keys ["_bouncestyled"], range Range::Any;

    /// At `--emissivequality high`, the size in units of the pieces each reflecting face is
    /// diced into (at most 64 along its longest side), each sending its share of the face's
    /// light from its middle, to light the brush models' middles (their autominlight) as
    /// ericw-tools' points do; the faces themselves gather over the whole surfaces.
    bounce_light_subdivision: f64 = 64.0, flag "bouncelightsubdivision", keys ["_bouncelightsubdivision"], range Range::Clamp(1.0, 8192.0);

    /// Where reflecting faces send bounced light from: `low` one point in front of each face's
    /// middle, `medium` that and each corner (both as ericw-tools), `high` the whole surface
    /// (closer to the physics, several times faster on maps lit everywhere, and less like
    /// ericw-tools' look).
    emissive_quality: EmissiveQuality = EmissiveQuality::Low, flag "emissivequality", keys [], range Range::Any;

    /// Write the coloured lightmaps into the BSP as the BSPX `RGBLIGHTING` lump (beside any
    /// `.lit`), for FTE, QuakeSpasm-Spiked and Ironwail.
    bspxlit: bool = false, flag "bspxlit", keys [], range Range::Any;

    /// Leave out the grey lighting lump (implies `--bspxlit`; no `.lit` unless `--lit`): engines
    /// that read only the grey lump (QuakeSpasm 0.95, DarkPlaces, vanilla) draw the map unlit.
    novanilla: bool = false, flag "novanilla", keys [], range Range::Any;

    /// Write a `.lux` deluxemap beside the BSP: per luxel, the light's mean direction in the
    /// face's tangent space (DarkPlaces' `.dlit`, FTE's `.lux`).
    lux: bool = false, flag "lux", keys [], range Range::Any;

    /// Write the deluxemap into the BSP as the BSPX `LIGHTINGDIR` lump.
    bspxlux: bool = false, flag "bspxlux", keys [], range Range::Any;

    /// Write the `.lit` in HDR form (E5BGR9 words, light past 255 kept), for FTE.
    hdr: bool = false, flag "hdr", keys [], range Range::Any;

    /// Write HDR lightmaps into the BSP as the BSPX `LIGHTING_E5BGR9` lump.
    bspxhdr: bool = false, flag "bspxhdr", keys [], range Range::Any;

    /// Sample light through the map's open space into the BSPX `LIGHTGRID_OCTREE` lump, which
    /// FTE, QuakeSpasm-Spiked and Ironwail light models with (direct light and minlight; bounced
    /// light is not in it).
    lightgrid: bool = false, flag "lightgrid", keys ["_lightgrid"], range Range::Any;

    /// Light each face on a world-aligned grid of its own, one luxel every N map units, written
    /// as the BSPX `DECOUPLED_LM` lump (FTE, QuakeSpasm-Spiked), with the 16-texel
    /// lightmaps taken from it for other engines; brush entities may set their own
    /// `_world_units_per_luxel`. 0: off.
    world_units_per_luxel: f64 = 0.0, flag "world_units_per_luxel", keys ["_world_units_per_luxel"], range Range::AtLeast(0.0);

    /// Light every face one luxel every 2^N texels, written as the BSPX `LMSHIFT` and
    /// `LMOFFSET` lumps (FTE, QuakeSpasm-Spiked), with the 16-texel lightmaps taken from those
    /// for other engines; in place of the `_lmscale` of worldspawn and brush entities (a
    /// fraction of 16 texels each). 4 (Quake's 16 texels): each model's `_lmscale`.
    lmshift: usize = 4, flag "lmshift", keys [], range Range::Clamp(0.0, 30.0);

    /// Grid spacing of a `_surface` light's copies over its faces, in units (ericw-tools'
    /// `-surflight_subdivide`).
    surflight_subdivide: f64 = 128.0, flag "surflight_subdivide", keys ["_surflightsubdivision", "_choplight"], range Range::Clamp(1.0, 8192.0);

    /// Light every face at this fraction of Quake's 16 texels (`0.5`: a luxel every 8 texels),
    /// as `--lmshift` does, overriding each model's `_lmscale` (0: unset).
    lightmap_scale: f64 = 0.0, flag "lmscale", keys ["_lightmap_scale"], range Range::AtLeast(0.0);

    /// Map units between light grid points (one number, or one per axis; at least 1).
    lightgrid_dist: Spacing = Spacing::EVEN_32, flag "lightgrid_dist", keys ["_lightgrid_dist"], range Range::Any;
}

/// Whether a default as [`Setting::default`] shows it is words (`white`, `as ...`), not a value.
fn written_in_words(default: &str) -> bool {
    default.starts_with("as ") || default == "white" || default == "—"
}

/// The settings as `docs/mapping.md` tables them: one row per setting, with its worldspawn
/// keys, its flag, its default, its range and its meaning.
pub fn markdown_table() -> String {
    let code = |s: &str| format!("`{s}`");
    let mut out = String::from(
        "| worldspawn key | option | default | range | meaning |\n|---|---|---|---|---|\n",
    );
    for s in TABLE {
        let keys = match s.keys {
            [] => "—".to_string(),
            [key] => code(key),
            [key, others @ ..] => {
                let others: Vec<String> = others.iter().map(|k| code(k)).collect();
                format!("{} ({})", code(key), others.join(", "))
            }
        };
        let value = match (s.switch, s.missing) {
            (true, _) => " [0\\|1]",
            (false, Some(_)) => " [N]",
            (false, None) => " N",
        };
        let flag = match s.alias {
            Some(alias) => format!("`--{}{value}` (`--{alias}`)", s.flag),
            None => format!("`--{}{value}`", s.flag),
        };
        let default = (s.default)();
        let default = if written_in_words(&default) {
            default
        } else {
            code(&default)
        };
        let help = s.help.split_whitespace().collect::<Vec<_>>().join(" ");
        out += &format!(
            "| {keys} | {flag} | {default} | {} | {help} |\n",
            s.range.show()
        );
    }
    out
}

#[cfg(test)]
mod tests;
