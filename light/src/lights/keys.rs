//! The keys light reads from light entities and brush models, each declared once in
//! [`ENTITY_KEYS`] (its spellings, which entities read it, how its value reads, its default and
//! its meaning), and [`Keys`], which reads them from one entity.
//!
//! A value reads as ericw-tools' `light` reads it, so a map lights the same under both: a number
//! is as much of the first word as reads as one (`"150x"` is 150), a whole number the first
//! word's leading digits (`"2.7"` is 2), a switch is off for `0` and `-1` and on for anything
//! else, a vector needs three numbers. A value that does not read at all leaves the key's
//! default. Either way a value not taken exactly as written is a warning naming the entity, its
//! line, the key and the value used instead: a map is never refused over a key.
//!
//! The docs' table of these keys is [`markdown_table`]; a test holds the two together.

use std::cell::RefCell;

use glam::DVec3;
use quake_formats::entities::{Entity, leading_number};

use crate::settings::{Given, SettingWarning, normalize_color};

/// Which entities read a key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum On {
    /// Light entities.
    Lights,
    /// Brush entities (and, for the keys the compiler passes on, `func_detail*` and
    /// `func_group`).
    Models,
    /// Light entities and brush entities.
    LightsAndModels,
    /// Worldspawn and brush entities.
    WorldAndModels,
}

impl On {
    /// How the docs name the entities.
    pub fn show(self) -> &'static str {
        match self {
            On::Lights => "lights",
            On::Models => "brush entities",
            On::LightsAndModels => "lights, brush entities",
            On::WorldAndModels => "worldspawn, brush entities",
        }
    }

    /// Whether a light entity reads the key.
    pub fn lights(self) -> bool {
        matches!(self, On::Lights | On::LightsAndModels)
    }

    /// Whether a brush entity reads the key.
    pub fn models(self) -> bool {
        !matches!(self, On::Lights)
    }
}

/// How a key's value reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A number.
    Number,
    /// A whole number.
    Whole,
    /// A switch: `1` on, `0` or `-1` off.
    Switch,
    /// Three numbers.
    Vector,
    /// A colour: three numbers, 0–255 or 0–1.
    Color,
    /// `light`: a brightness, or Half-Life's `R G B brightness`.
    Brightness,
    /// A name (a texture's, an entity's).
    Text,
}

/// One key light reads from entities.
#[derive(Debug, Clone, Copy)]
pub struct EntityKey {
    /// Its spellings, the first the one the docs use; the first present one is read.
    pub names: &'static [&'static str],
    /// Which entities read it.
    pub on: On,
    /// How its value reads.
    pub kind: Kind,
    /// What light uses when the key is absent, as the docs write it (`—`: nothing).
    pub default: &'static str,
    /// What it does.
    pub meaning: &'static str,
}

impl EntityKey {
    /// What a value that does not read leaves, for a warning.
    fn instead(&self) -> String {
        match self.default {
            "—" => "the key is ignored".to_string(),
            default => format!("{} is used", default.trim_matches('`')),
        }
    }
}

/// Declares the entity keys: each entry
///
/// ```text
/// /// Meaning (the docs' text).
/// CONST: ["_key", "_alias"] on Lights, Number, default "0";
/// ```
///
/// becomes `pub const CONST: EntityKey` and a row of [`ENTITY_KEYS`].
macro_rules! entity_keys {
    ($(
        $(#[doc = $doc:literal])+
        $name:ident: [$($key:literal),+] on $on:ident, $kind:ident, default $default:literal;
    )*) => {
        $(
            $(#[doc = $doc])+
            pub const $name: EntityKey = EntityKey {
                names: &[$($key),+],
                on: On::$on,
                kind: Kind::$kind,
                default: $default,
                meaning: concat!($($doc),+),
            };
        )*

        /// Every key light reads from light entities and brush models, in the docs' order.
        pub static ENTITY_KEYS: &[EntityKey] = &[$($name),*];
    };
}

entity_keys! {
    /// Brightness; or Half-Life's `R G B I`: colour (0–255 or 0–1) and brightness (an explicit
    /// `_color` wins over that colour); three numbers are a colour at the default brightness.
    /// A brightness of `0` lights nothing.
    LIGHT: ["light"] on Lights, Brightness, default "`300`";
    /// Where the light is.
    ORIGIN: ["origin"] on Lights, Vector, default "`0 0 0`";
    /// Colour, `r g b` (0–255, or 0–1); any colour writes a `.lit` file.
    COLOR: ["_color"] on Lights, Color, default "white";
    /// Light style (0 steady, 1–12 Quake's animations, up to 254; clamped into that range).
    STYLE: ["style"] on Lights, Whole, default "`0`";
    /// A switchable light: lights sharing a name get their own style, from worldspawn's
    /// `_compilerstyle_start` (32) up, written into the entity for the game to switch. Also the
    /// name spotlights aim at with `target`.
    TARGETNAME: ["targetname"] on Lights, Text, default "—";
    /// Spotlight: shines towards the entity with this `targetname`.
    TARGET: ["target"] on Lights, Text, default "—";
    /// Spotlight (or `_sun`) direction, `yaw pitch roll` in degrees; wins over `target`.
    MANGLE: ["mangle"] on Lights, Vector, default "—";
    /// Spotlight cone, degrees.
    ANGLE: ["angle"] on Lights, Number, default "`40`";
    /// The light shines a picture, like a slide projector: this texture of the BSP, held in
    /// front of it along `_project_mangle`. A point it reaches takes twice the picture's colour
    /// there times the light's (a mid-grey texel leaves the light as it is); outside the picture
    /// it gives nothing. Ignored, with a warning, when the BSP holds no pixels of that texture;
    /// ignored on `_surface` templates.
    PROJECT_TEXTURE: ["_project_texture"] on Lights, Text, default "—";
    /// Direction of the picture, `yaw pitch roll` in degrees (roll turns the picture); without
    /// it, `mangle`, else the Half-Life `angles` (`pitch yaw roll`, pitch down), else along +x.
    PROJECT_MANGLE: ["_project_mangle"] on Lights, Vector, default "`mangle`";
    /// Field of view of the picture along its longer side, degrees (1–179; other values warn
    /// and take 90).
    PROJECT_FOV: ["_project_fov"] on Lights, Number, default "`90`";
    /// The Half-Life light direction `pitch yaw roll` (pitch positive down), read only for a
    /// projected picture without `_project_mangle` or `mangle`.
    ANGLES: ["angles"] on Lights, Vector, default "—";
    /// Spotlight inner cone with full brightness; the light fades from it to `angle`.
    SOFTANGLE: ["_softangle"] on Lights, Number, default "`0`";
    /// Falloff: `0` linear, `1` 1/x, `2` 1/x², `3` none, `4` local minlight (raises what it sees
    /// to `light`, never adds), `5` 1/(x+128)² (inverse square without the bright spot at the
    /// source). A fraction is cut to its whole part; any other value is a warning and the light
    /// lights nothing, as in ericw-tools.
    DELAY: ["delay"] on Lights, Whole, default "`0`";
    /// Linear falloff rate multiplier (bigger: shorter reach).
    WAIT: ["wait"] on Lights, Number, default "`1`";
    /// Linear lights: the distance at which the light reaches zero (replaces `wait`).
    FALLOFF: ["_falloff"] on Lights, Number, default "—";
    /// How much a surface's angle to this light matters, 0–1 (outside that it warns and takes
    /// worldspawn's).
    ANGLESCALE: ["_anglescale", "_anglesense"] on Lights, Number, default "worldspawn's";
    /// Ambient occlusion: `1` on for this light, `-1` off for this light / this model's faces.
    DIRT: ["_dirt"] on LightsAndModels, Number, default "worldspawn's `_dirt`";
    /// Strength of dirt on this light (0: worldspawn's).
    DIRTSCALE: ["_dirtscale"] on Lights, Number, default "worldspawn's";
    /// Contrast of dirt on this light (0: worldspawn's).
    DIRTGAIN: ["_dirtgain"] on Lights, Number, default "worldspawn's";
    /// `0`: this light's light does not reflect / this model's faces do not reflect.
    BOUNCE: ["_bounce"] on LightsAndModels, Number, default "`1`";
    /// Light channels (a bit mask) this light lights: the faces of brush entities whose
    /// `_object_channel_mask` shares a bit with it (the world is on channel 1).
    LIGHT_CHANNEL_MASK: ["_light_channel_mask"] on Lights, Whole, default "`1`";
    /// Light channels (a bit mask) whose faces block this light's rays: those of brush entities
    /// whose `_object_channel_mask` shares a bit with it (the world is on channel 1).
    SHADOW_CHANNEL_MASK: ["_shadow_channel_mask"] on Lights, Whole, default "its `_light_channel_mask`";
    /// How much of this light bounces (`0`: none, as `_bounce 0`); ericw-tools documents it.
    BOUNCESCALE: ["_bouncescale"] on Lights, Number, default "`1`";
    /// Soft shadows: the light is spread as `_samples` lights in a ball of this radius (for
    /// `_sun` lights: a cone of this many degrees).
    DEVIANCE: ["_deviance"] on Lights, Number, default "`0`";
    /// Lights a `_deviance` light is spread into.
    SAMPLES: ["_samples"] on Lights, Whole, default "`16`";
    /// Surface light template: copies of the light are placed over every face with this texture.
    SURFACE: ["_surface"] on Lights, Text, default "—";
    /// How far off the faces those copies sit.
    SURFACE_OFFSET: ["_surface_offset"] on Lights, Number, default "`2`";
    /// `1`: those copies shine out of their face as spotlights (cone `angle`).
    SURFACE_SPOTLIGHT: ["_surface_spotlight"] on Lights, Switch, default "`0`";
    /// A `_surface` template puts its copies only on faces of its own group: those of brush
    /// entities with the same group, or of worldspawn, `func_detail*` and `func_group` with it
    /// (the compiler records their faces' groups in the BSP for light); a template without one,
    /// only on faces without one.
    SURFLIGHT_GROUP: ["_surflight_group"] on LightsAndModels, Whole, default "`0`";
    /// `1`: the light is a sun (parallel light from sky faces) along `mangle` or towards
    /// `target`.
    SUN: ["_sun"] on Lights, Switch, default "`0`";
    /// `1`: the light is a sky dome from above with its brightness and colour.
    SUNLIGHT2: ["_sunlight2"] on Lights, Switch, default "`0`";
    /// `1`: the light is a sky dome from below with its brightness and colour.
    SUNLIGHT3: ["_sunlight3"] on Lights, Switch, default "`0`";
    /// A `_sun`, `_sunlight2` or `_sunlight3` light shines only through sky faces with this
    /// texture (as in ericw-tools; a texture the BSP does not hold is a warning and the sun
    /// shines through every sky face).
    SUNTEXTURE: ["_suntexture"] on Lights, Text, default "every sky texture";
    /// `1`: the light is ignored by the light tool (left for the game).
    NOSTATICLIGHT: ["_nostaticlight"] on Lights, Switch, default "`0`";
    /// `1`: the light stays where it is. Otherwise a light inside solid, or lying exactly on a
    /// surface, is moved 2 units out along the first axis direction (−x, +x, −y, +y, −z, +z)
    /// that frees it, as in ericw-tools, so a light on a floor or a ceiling lights it; one no
    /// such step frees lights nothing, with a warning.
    NONUDGE: ["_nonudge"] on Lights, Switch, default "`0`";
    /// The `targetname` of brush models whose shadows switch with this light's style (its
    /// `style`, from its own `targetname`); the light itself lights nothing.
    SWITCHABLESHADOW_TARGET: ["_switchableshadow_target"] on Lights, Text, default "—";
    /// Minimum light for that model's faces (instead of the world's).
    MINLIGHT: ["_minlight"] on Models, Number, default "`0`";
    /// Colour of the model's minimum light.
    MINLIGHT_COLOR: ["_minlight_color", "_mincolor"] on Models, Color, default "white";
    /// A texture of the model that does not get its minimum light.
    MINLIGHT_EXCLUDE: ["_minlight_exclude"] on Models, Text, default "—";
    /// `1`: the minimum light of the model's faces (its own or the world's) is mottled, as
    /// worldspawn's `_minlight_mottle` mottles the world's; `0`: not.
    MINLIGHT_MOTTLE: ["_minlight_mottle", "_minlightMottle"] on Models, Switch, default "worldspawn's";
    /// The most light the model's faces take, in levels (instead of the world's `_maxlight`;
    /// on a `func_detail` or `func_group`, its own faces').
    MAXLIGHT: ["_maxlight"] on Models, Number, default "worldspawn's";
    /// `1`: the model casts shadows (the world always does); a model of `skip` brushes, which
    /// has no faces, casts the shadow of its brushes (read from the BSP's tree). `0` or `-1`: a
    /// model casts none. On brushes merged into the world (`func_detail*`, `func_group`, whose
    /// default is the world's shadow), `-1` casts none and `func_detail_illusionary` casts none
    /// unless `1` (the compiler marks their faces in the BSP for light). Faces that cast no shadow
    /// reflect no bounced light either.
    SHADOW: ["_shadow"] on Models, Number, default "`0`";
    /// ericw-tools' autominlight: the model's samples inside solid take the light at the middle
    /// of its box (or at `_autominlight_target`'s entity), direct and, with bounce, bounced,
    /// halved as ericw-tools' is.
    /// `-1`: they take none (they stay dark); `1`: every sample of the model takes at least that
    /// light.
    AUTOMINLIGHT: ["_autominlight"] on Models, Number, default "`0`";
    /// The `targetname` of the entity at whose `origin` the model's autominlight is taken.
    AUTOMINLIGHT_TARGET: ["_autominlight_target"] on Models, Text, default "—";
    /// `1`: the model's shadow can be switched by the game. Style-0 light it blocks goes on a
    /// style of its own (from `_compilerstyle_start` up, shared with the lights and models of the
    /// same `targetname`; a model without one gets its own), written into the entity as
    /// `switchshadstyle`: QuakeC sets that style to `a` to show the shadow and `m` to hide it. The
    /// model casts no fixed shadow (its `_shadow` is ignored) but on itself and the models sharing
    /// its style, which it always shadows; sunlight takes it as a fixed one.
    SWITCHABLESHADOW: ["_switchableshadow"] on Models, Number, default "`0`";
    /// `1`: the model shadows itself only.
    SHADOWSELF: ["_shadowself", "_selfshadow"] on Models, Number, default "`0`";
    /// `1`: the model shadows the world's faces only (not its own, nor other models'); it wins
    /// over `_shadow`.
    SHADOWWORLDONLY: ["_shadowworldonly"] on Models, Number, default "`0`";
    /// Light channels (a bit mask) the entity's faces receive light on and block light on: a
    /// light lights them when the masks share a bit with its `_light_channel_mask`, and they
    /// block the rays of a light whose `_shadow_channel_mask` shares one. Not `1`: they cast
    /// shadows (as `_shadow 1`) and reflect no bounced light; suns, surface lights and bounced
    /// light are on channel 1, and dirt comes from what shares a channel. On `func_detail*` and
    /// `func_group` too (the compiler records it per face).
    OBJECT_CHANNEL_MASK: ["_object_channel_mask"] on Models, Whole, default "`1`";
    /// `1`: the model's faces receive no light but minlight.
    LIGHTIGNORE: ["_lightignore"] on Models, Switch, default "`0`";
    /// The model's faces are lit on a world-aligned grid of one luxel every this many units
    /// (when the map's `_world_units_per_luxel` is set).
    WORLD_UNITS_PER_LUXEL: ["_world_units_per_luxel"] on Models, Number, default "the map's";
    /// How much colour the faces' light keeps: `0` greys it (each luxel takes its brightest
    /// channel in all three), `1` keeps it; between, a mix, as in ericw-tools (on a
    /// `func_detail` or `func_group`, its own faces').
    LIGHTCOLORSCALE: ["_lightcolorscale"] on WorldAndModels, Number, default "`1`";
    /// The model's lightmap spacing as a fraction of Quake's 16 texels, rounded down to a
    /// power of two texels (BSPX `LMSHIFT`).
    LMSCALE: ["_lmscale"] on WorldAndModels, Number, default "`1`";
    /// Smooth normals across the model's faces (see the compiler's table).
    PHONG: ["_phong"] on WorldAndModels, Number, default "off";
    /// The greatest angle between faces `_phong` smooths across, in degrees.
    PHONG_ANGLE: ["_phong_angle"] on WorldAndModels, Number, default "`89`";
    /// The same where two faces meet in a concave joint (`1`: concave joints stay sharp).
    PHONG_ANGLE_CONCAVE: ["_phong_angle_concave"] on WorldAndModels, Number, default "`_phong_angle`";
    /// Where the model is placed, so light finds its faces.
    MODEL_ORIGIN: ["origin"] on Models, Vector, default "`0 0 0`";
}

/// Reads the declared keys of one entity, gathering a warning for each value not taken as
/// written.
pub struct Keys<'a> {
    /// The entity.
    pub entity: &'a Entity,
    /// Its place in the lump.
    pub index: usize,
    warnings: RefCell<Vec<SettingWarning>>,
}

/// A value read from its text, and whether all of the text was taken.
struct Read<T> {
    value: T,
    whole_text: bool,
}

impl<'a> Keys<'a> {
    /// Reads entity `entity`, the `index`th of the lump.
    pub fn new(entity: &'a Entity, index: usize) -> Keys<'a> {
        Keys {
            entity,
            index,
            warnings: RefCell::new(Vec::new()),
        }
    }

    /// The warnings gathered while reading.
    pub fn into_warnings(self) -> Vec<SettingWarning> {
        self.warnings.into_inner()
    }

    /// A warning that `name` (present) is not taken as written: `problem` says why and what is
    /// used instead.
    pub fn warn(&self, name: &'static str, problem: &str) {
        let value = self.entity.get(name).unwrap_or("").to_string();
        self.warnings.borrow_mut().push(SettingWarning {
            given: Given::key(self.index, self.entity, name),
            value,
            problem: problem.to_string(),
        });
    }

    /// The first of `key`'s spellings the entity holds with a value that is not blank.
    fn text_of(&self, key: &EntityKey) -> Option<(&'static str, &'a str)> {
        key.names.iter().find_map(|&name| {
            let text = self.entity.get(name)?;
            (!text.trim().is_empty()).then_some((name, text))
        })
    }

    /// `key`'s value read by `read`; a value that does not read is a warning (`expected` says
    /// what it should be) and `None`, one not read whole a warning naming what it reads as.
    fn read<T: std::fmt::Display>(
        &self,
        key: &EntityKey,
        expected: &str,
        read: impl FnOnce(&str) -> Option<Read<T>>,
    ) -> Option<T> {
        let (name, text) = self.text_of(key)?;
        match read(text) {
            None => {
                self.warn(name, &format!("expected {expected}; {}", key.instead()));
                None
            }
            Some(Read { value, whole_text }) => {
                if !whole_text {
                    self.warn(name, &format!("read as {value}, as ericw-tools reads it"));
                }
                Some(value)
            }
        }
    }

    /// A [`Kind::Number`] key.
    pub fn number(&self, key: &EntityKey) -> Option<f64> {
        debug_assert_eq!(key.kind, Kind::Number, "{:?}", key.names);
        self.read(key, "a number", |text| {
            let mut words = text.split_whitespace();
            let first = words.next()?;
            let (value, used) = leading_number(first)?;
            Some(Read {
                value,
                whole_text: used == first.len() && words.next().is_none(),
            })
        })
    }

    /// A [`Kind::Whole`] key.
    pub fn whole(&self, key: &EntityKey) -> Option<i64> {
        debug_assert_eq!(key.kind, Kind::Whole, "{:?}", key.names);
        self.read(key, "a whole number", |text| {
            let mut words = text.split_whitespace();
            let first = words.next()?;
            let (value, used) = leading_whole(first)?;
            Some(Read {
                value,
                whole_text: used == first.len() && words.next().is_none(),
            })
        })
    }

    /// A [`Kind::Switch`] key: `0` and `-1` are off, `1` on, and so (with a warning) is any
    /// other value, as ericw-tools reads its switches.
    pub fn switch(&self, key: &EntityKey) -> Option<bool> {
        debug_assert_eq!(key.kind, Kind::Switch, "{:?}", key.names);
        let (name, text) = self.text_of(key)?;
        match text.trim() {
            "0" | "-1" => Some(false),
            "1" => Some(true),
            _ => {
                self.warn(
                    name,
                    "read as 1 (on): ericw-tools takes any value but 0 and -1 as on",
                );
                Some(true)
            }
        }
    }

    /// A [`Kind::Vector`] key.
    pub fn vector(&self, key: &EntityKey) -> Option<DVec3> {
        debug_assert_eq!(key.kind, Kind::Vector, "{:?}", key.names);
        self.three_numbers(key)
    }

    /// A [`Kind::Color`] key, as 1.0 = full channel.
    pub fn color(&self, key: &EntityKey) -> Option<DVec3> {
        debug_assert_eq!(key.kind, Kind::Color, "{:?}", key.names);
        self.three_numbers(key).map(normalize_color)
    }

    fn three_numbers(&self, key: &EntityKey) -> Option<DVec3> {
        self.read(key, "three numbers", |text| {
            let (numbers, whole_text) = leading_numbers(text, 3);
            let &[x, y, z] = numbers.as_slice() else {
                return None;
            };
            Some(Read {
                value: ShownVec(DVec3::new(x, y, z)),
                whole_text,
            })
        })
        .map(|v| v.0)
    }

    /// [`LIGHT`]: its brightness, and the colour of Half-Life's form. One number is a
    /// brightness; three a colour (at the default brightness); four a colour and a brightness;
    /// anything else leaves the default, as ericw-tools reads it.
    pub fn brightness(&self) -> (Option<f64>, Option<DVec3>) {
        let Some((name, text)) = self.text_of(&LIGHT) else {
            return (None, None);
        };
        let (numbers, whole_text) = leading_numbers(text, 4);
        let read = match *numbers.as_slice() {
            [l] => (Some(l), None),
            [r, g, b] => (None, Some(DVec3::new(r, g, b))),
            [r, g, b, l] => (Some(l), Some(DVec3::new(r, g, b))),
            _ => {
                let problem = format!(
                    "expected a brightness or R G B brightness; {}",
                    LIGHT.instead()
                );
                self.warn(name, &problem);
                return (None, None);
            }
        };
        if !whole_text {
            let words = numbers.iter().map(ToString::to_string).collect::<Vec<_>>();
            let problem = format!("read as \"{}\", as ericw-tools reads it", words.join(" "));
            self.warn(name, &problem);
        }
        (read.0, read.1.map(normalize_color))
    }

    /// A [`Kind::Text`] key, when it is not blank.
    pub fn text(&self, key: &EntityKey) -> Option<&'a str> {
        debug_assert_eq!(key.kind, Kind::Text, "{:?}", key.names);
        self.text_of(key).map(|(_, text)| text)
    }
}

/// A vector as a warning writes it.
struct ShownVec(DVec3);

impl std::fmt::Display for ShownVec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "\"{} {} {}\"", self.0.x, self.0.y, self.0.z)
    }
}

/// The whole number `word` starts with (a sign and digits), and how many bytes that takes.
fn leading_whole(word: &str) -> Option<(i64, usize)> {
    let bytes = word.as_bytes();
    let sign = usize::from(matches!(bytes.first(), Some(b'+' | b'-')));
    let mut end = sign;
    while bytes.get(end).is_some_and(u8::is_ascii_digit) {
        end += 1;
    }
    if end == sign {
        return None;
    }
    // Past i64 is nothing a key means; saturate rather than refuse.
    let value =
        word[..end]
            .parse::<i64>()
            .unwrap_or(if bytes[0] == b'-' { i64::MIN } else { i64::MAX });
    Some((value, end))
}

/// Up to `most` numbers from the start of `text`, one a word, stopping at the first word that
/// does not start with one; and whether every word was taken whole.
fn leading_numbers(text: &str, most: usize) -> (Vec<f64>, bool) {
    let mut numbers = Vec::new();
    let mut whole_text = true;
    for word in text.split_whitespace() {
        match leading_number(word) {
            Some((n, used)) if numbers.len() < most => {
                numbers.push(n);
                if used < word.len() {
                    whole_text = false;
                    break;
                }
            }
            _ => {
                whole_text = false;
                break;
            }
        }
    }
    (numbers, whole_text)
}

/// The keys as `docs/mapping.md` tables them: one row per key, with the entities that read it,
/// its meaning and its default.
pub fn markdown_table() -> String {
    let mut out = String::from("| key | on | meaning | default |\n|---|---|---|---|\n");
    for key in ENTITY_KEYS {
        let names = match key.names {
            [name, others @ ..] if !others.is_empty() => {
                let others: Vec<String> = others.iter().map(|k| format!("`{k}`")).collect();
                format!("`{name}` ({})", others.join(", "))
            }
            names => format!("`{}`", names.join("`, `")),
        };
        let meaning = key.meaning.split_whitespace().collect::<Vec<_>>().join(" ");
        out += &format!(
            "| {names} | {} | {meaning} | {} |\n",
            key.on.show(),
            key.default
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_as_far_as_they_go() {
        assert_eq!(leading_whole("2.7"), Some((2, 1)));
        assert_eq!(leading_whole("-3"), Some((-3, 2)));
        assert_eq!(leading_whole("abc"), None);
        assert_eq!(leading_numbers("1 0 0x", 3), (vec![1.0, 0.0, 0.0], false));
        assert_eq!(leading_numbers("1 2", 3), (vec![1.0, 2.0], true));
        assert_eq!(leading_numbers("1 x 3", 3), (vec![1.0], false));
    }

    fn entity(pairs: &[(&str, &str)]) -> Entity {
        Entity {
            pairs: pairs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            line: 7,
        }
    }

    #[test]
    fn values_read_as_in_ericw_tools_and_warn_when_not_taken_as_written() {
        let e = entity(&[
            ("classname", "light"),
            ("wait", "2 3"),
            ("angle", "up"),
            ("style", "2.7"),
            ("_sun", "yes"),
            ("_nonudge", "0"),
            ("mangle", "1 2"),
            ("_color", "255 0 0"),
        ]);
        let k = Keys::new(&e, 4);
        assert_eq!(k.number(&WAIT), Some(2.0));
        assert_eq!(k.number(&ANGLE), None);
        assert_eq!(k.whole(&STYLE), Some(2));
        assert_eq!(k.switch(&SUN), Some(true));
        assert_eq!(k.switch(&NONUDGE), Some(false));
        assert_eq!(k.vector(&MANGLE), None);
        assert_eq!(k.color(&COLOR), Some(DVec3::new(1.0, 0.0, 0.0)));
        assert_eq!(k.number(&FALLOFF), None, "absent");
        let told: Vec<String> = k.into_warnings().iter().map(ToString::to_string).collect();
        assert_eq!(told.len(), 5, "{told:?}");
        assert!(told[0].contains("line 7"), "{told:?}");
        assert!(
            told[0].contains("\"wait\" is \"2 3\": read as 2"),
            "{told:?}"
        );
        assert!(told[1].contains("\"angle\" is \"up\": expected a number; 40 is used"));
        assert!(
            told[4].contains("\"mangle\" is \"1 2\": expected three numbers; the key is ignored")
        );
    }

    #[test]
    fn light_reads_one_three_or_four_numbers() {
        let read = |v: &str| {
            let e = entity(&[("classname", "light"), ("light", v)]);
            let k = Keys::new(&e, 1);
            let got = k.brightness();
            (got, k.into_warnings().len())
        };
        assert_eq!(read("200"), ((Some(200.0), None), 0));
        assert_eq!(read("bright"), ((None, None), 1));
        assert_eq!(read("1 2"), ((None, None), 1));
        let orange = Some(DVec3::new(1.0, 127.0 / 255.0, 0.0));
        assert_eq!(read("255 127 0"), ((None, orange), 0));
        assert_eq!(read("255 127 0 200"), ((Some(200.0), orange), 0));
    }

    /// `docs/mapping.md` lists every entity key as declared.
    #[test]
    fn the_docs_list_every_entity_key_as_declared() {
        crate::docs::check_generated_table(
            "light entity keys: generated from light/src/lights/keys.rs",
            "light entity keys",
            &markdown_table(),
        );
    }
}
