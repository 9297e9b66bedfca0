//! What a setting can hold, how a key's or an argument's text reads as it, and the ranges
//! values are held to.

use glam::DVec3;

use crate::bounce::EmissiveQuality;
use crate::dirt::DirtMode;

/// A type a setting can hold.
pub trait SettingValue: Clone + Sized {
    /// The setting is a switch: its flag takes no value and turns it on.
    const SWITCH: bool = false;

    /// Numbers a flag's value may be given as, each its own argument (ericw-tools'
    /// `-lightgrid_dist 16 16 32`).
    const WORDS: usize = 1;

    /// What `text` (a key's value or a flag's argument) says; `None` for a blank value, which
    /// counts as absent; `Err` names what was expected.
    fn read(text: &str) -> Option<Result<Self, &'static str>>;

    /// How the docs and messages write the value.
    fn show(&self) -> String;

    /// `self` held to `range`: `Ok` inside it, else what to use instead (`None`: the default).
    fn within(self, range: Range) -> Result<Self, Option<Self>> {
        let _ = range;
        Ok(self)
    }
}

/// The values a numeric setting takes, and what light does with one outside them (with a
/// warning either way).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    /// Any value of its type.
    Any,
    /// `min..=max`; a value outside is clamped to the nearer end, as ericw-tools does.
    Clamp(f64, f64),
    /// Above `min`; a value at or below it leaves the default.
    Above(f64),
    /// `min` or more; a value below it leaves the default.
    AtLeast(f64),
}

impl Range {
    /// `x` held to the range: `Ok` inside it, else the value to use (`None`: the default).
    fn hold(self, x: f64) -> Result<f64, Option<f64>> {
        match self {
            Range::Any => Ok(x),
            Range::Clamp(min, _) if x < min => Err(Some(min)),
            Range::Clamp(_, max) if x > max => Err(Some(max)),
            Range::Clamp(..) => Ok(x),
            Range::Above(min) if x > min => Ok(x),
            Range::AtLeast(min) if x >= min => Ok(x),
            Range::Above(_) | Range::AtLeast(_) => Err(None),
        }
    }

    /// How the docs write the range.
    pub fn show(self) -> String {
        let n = |x: f64| {
            if x.is_infinite() {
                "∞".to_string()
            } else {
                x.to_string()
            }
        };
        match self {
            Range::Any => "—".to_string(),
            Range::Clamp(min, max) if max.is_infinite() => format!("≥ {} (clamped)", n(min)),
            Range::Clamp(min, max) => format!("{}–{} (clamped)", n(min), n(max)),
            Range::Above(min) => format!("> {}", n(min)),
            Range::AtLeast(min) => format!("≥ {}", n(min)),
        }
    }
}

/// A number as every numeric key reads (surrounding blanks allowed; `nan` and `inf` are not
/// numbers).
fn number(text: &str) -> Option<Result<f64, &'static str>> {
    let text = text.trim();
    if text.is_empty() {
        return None;
    }
    Some(
        text.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or("a number"),
    )
}

impl SettingValue for f64 {
    fn read(text: &str) -> Option<Result<f64, &'static str>> {
        number(text)
    }

    fn show(&self) -> String {
        self.to_string()
    }

    fn within(self, range: Range) -> Result<f64, Option<f64>> {
        range.hold(self)
    }
}

impl SettingValue for usize {
    fn read(text: &str) -> Option<Result<usize, &'static str>> {
        const WANT: &str = "a whole number, 0 or more";
        Some(number(text)?.map_err(|_| WANT).and_then(|x| {
            (x >= 0.0 && x.fract() == 0.0)
                .then_some(x as usize)
                .ok_or(WANT)
        }))
    }

    fn show(&self) -> String {
        self.to_string()
    }

    fn within(self, range: Range) -> Result<usize, Option<usize>> {
        range
            .hold(self as f64)
            .map(|_| self)
            .map_err(|to| to.map(|x| x as usize))
    }
}

/// A switch: `1` is on, any other number off.
impl SettingValue for bool {
    const SWITCH: bool = true;

    fn read(text: &str) -> Option<Result<bool, &'static str>> {
        Some(number(text)?.map(|x| x == 1.0))
    }

    fn show(&self) -> String {
        u8::from(*self).to_string()
    }
}

/// A texture name (kept as written, even blank).
impl SettingValue for Option<String> {
    fn read(text: &str) -> Option<Result<Option<String>, &'static str>> {
        Some(Ok(Some(text.to_string())))
    }

    fn show(&self) -> String {
        self.clone().unwrap_or_else(|| "—".to_string())
    }
}

/// Three numbers, such as a `mangle` (more after them are ignored).
impl SettingValue for DVec3 {
    const WORDS: usize = 3;

    fn read(text: &str) -> Option<Result<DVec3, &'static str>> {
        if text.trim().is_empty() {
            return None;
        }
        let mut parts = text.split_whitespace();
        let mut xyz = [0.0; 3];
        for c in &mut xyz {
            match parts.next().map(str::parse::<f64>) {
                Some(Ok(x)) if x.is_finite() => *c = x,
                _ => return Some(Err("three numbers")),
            }
        }
        Some(Ok(DVec3::from_array(xyz)))
    }

    fn show(&self) -> String {
        format!("{} {} {}", self.x, self.y, self.z)
    }
}

/// Distances along x, y and z, each at least 1: one number for all three, or three.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spacing(pub DVec3);

impl Spacing {
    /// 32 units on every axis (ericw-tools' light grid spacing).
    pub const EVEN_32: Spacing = Spacing(DVec3::splat(32.0));
}

impl SettingValue for Spacing {
    const WORDS: usize = 3;

    fn read(text: &str) -> Option<Result<Spacing, &'static str>> {
        const WANT: &str = "one or three numbers, each at least 1";
        let parts: Vec<&str> = text.split_whitespace().collect();
        let xyz = match parts[..] {
            [] => return None,
            [one] => DVec3::splat(one.parse().unwrap_or(f64::NAN)),
            [x, y, z] => DVec3::new(
                x.parse().unwrap_or(f64::NAN),
                y.parse().unwrap_or(f64::NAN),
                z.parse().unwrap_or(f64::NAN),
            ),
            _ => return Some(Err(WANT)),
        };
        let usable = xyz.is_finite() && xyz.min_element() >= 1.0;
        Some(usable.then_some(Spacing(xyz)).ok_or(WANT))
    }

    fn show(&self) -> String {
        let v = self.0;
        if v.x == v.y && v.y == v.z {
            v.x.to_string()
        } else {
            v.show()
        }
    }
}

/// A colour, 1.0 a full channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Color(pub DVec3);

impl Color {
    /// Full white.
    pub const WHITE: Color = Color(DVec3::ONE);
}

pub use quake_formats::entities::normalize_color;

/// `r g b`, in 0..255 or all three in 0..1.
impl SettingValue for Color {
    const WORDS: usize = 3;

    fn read(text: &str) -> Option<Result<Color, &'static str>> {
        Some(DVec3::read(text)?.map(|c| Color(normalize_color(c))))
    }

    fn show(&self) -> String {
        if *self == Color::WHITE {
            "white".to_string()
        } else {
            (self.0 * 255.0).show()
        }
    }
}

/// Whether something takes dirt: `1` on, `-1` off, otherwise as worldspawn's `_dirt`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DirtToggle {
    /// `1`.
    On,
    /// `-1`.
    Off,
    /// As worldspawn's `_dirt` (or `--dirt`).
    AsDirt,
}

impl DirtToggle {
    /// The toggle a number says: `1` on, `-1` off, anything else as `_dirt`.
    pub fn of_number(x: f64) -> DirtToggle {
        match x {
            1.0 => DirtToggle::On,
            -1.0 => DirtToggle::Off,
            _ => DirtToggle::AsDirt,
        }
    }

    /// Whether dirt is on, with dirt everywhere `global`.
    pub fn is_on(self, global: bool) -> bool {
        match self {
            DirtToggle::On => true,
            DirtToggle::Off => false,
            DirtToggle::AsDirt => global,
        }
    }
}

impl SettingValue for DirtToggle {
    fn read(text: &str) -> Option<Result<DirtToggle, &'static str>> {
        Some(number(text)?.map(DirtToggle::of_number))
    }

    fn show(&self) -> String {
        match self {
            DirtToggle::On => "1",
            DirtToggle::Off => "-1",
            DirtToggle::AsDirt => "as `_dirt`",
        }
        .to_string()
    }
}

/// The `--soft` blur's radius, in samples of the face's oversampled grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SoftRadius {
    /// This many samples each way (0: no blur).
    Samples(usize),
    /// `-1` (`--soft` alone): half the samples along a luxel's side, as ericw-tools takes it
    /// (`--extra`: 1, `--extra4`: 2, one sample a luxel: no blur).
    HalfLuxel,
}

impl SoftRadius {
    /// The radius in samples with `per_axis` samples along a luxel's side.
    pub fn samples(self, per_axis: usize) -> usize {
        match self {
            SoftRadius::Samples(n) => n,
            SoftRadius::HalfLuxel => per_axis / 2,
        }
    }
}

impl SettingValue for SoftRadius {
    fn read(text: &str) -> Option<Result<SoftRadius, &'static str>> {
        const WANT: &str = "-1 or a whole number, 0 or more";
        Some(number(text)?.map_err(|_| WANT).and_then(|x| match x {
            -1.0 => Ok(SoftRadius::HalfLuxel),
            x if x >= 0.0 && x.fract() == 0.0 => Ok(SoftRadius::Samples(x as usize)),
            _ => Err(WANT),
        }))
    }

    fn show(&self) -> String {
        match self {
            SoftRadius::Samples(n) => n.to_string(),
            SoftRadius::HalfLuxel => "-1 (half a luxel)".to_string(),
        }
    }
}

/// ericw-tools' names, `low`, `medium` and `high` (any case), or `0`, `1`, `2`.
impl SettingValue for EmissiveQuality {
    fn read(text: &str) -> Option<Result<EmissiveQuality, &'static str>> {
        let text = text.trim();
        if text.is_empty() {
            return None;
        }
        Some(match text.to_ascii_lowercase().as_str() {
            "low" | "0" => Ok(EmissiveQuality::Low),
            "medium" | "1" => Ok(EmissiveQuality::Medium),
            "high" | "2" => Ok(EmissiveQuality::High),
            _ => Err("low, medium or high"),
        })
    }

    fn show(&self) -> String {
        match self {
            EmissiveQuality::Low => "low",
            EmissiveQuality::Medium => "medium",
            EmissiveQuality::High => "high",
        }
        .to_string()
    }
}

/// `1` random, any other number ordered.
impl SettingValue for DirtMode {
    fn read(text: &str) -> Option<Result<DirtMode, &'static str>> {
        Some(number(text)?.map(|x| {
            if x == 1.0 {
                DirtMode::Random
            } else {
                DirtMode::Ordered
            }
        }))
    }

    fn show(&self) -> String {
        match self {
            DirtMode::Ordered => "0",
            DirtMode::Random => "1",
        }
        .to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_as_entity_keys_always_did() {
        assert_eq!(f64::read(" 2.5 "), Some(Ok(2.5)));
        assert_eq!(f64::read("  "), None, "blank is absent");
        assert_eq!(f64::read("bright"), Some(Err("a number")));
        assert_eq!(f64::read("nan"), Some(Err("a number")));
        assert_eq!(usize::read("3"), Some(Ok(3)));
        assert!(matches!(usize::read("1.5"), Some(Err(_))));
        assert!(matches!(usize::read("-1"), Some(Err(_))));
        assert_eq!(bool::read("1"), Some(Ok(true)));
        assert_eq!(bool::read("-1"), Some(Ok(false)));
        assert_eq!(DirtToggle::read("-1"), Some(Ok(DirtToggle::Off)));
        assert_eq!(DirtToggle::read("0"), Some(Ok(DirtToggle::AsDirt)));
        assert_eq!(SoftRadius::read("-1"), Some(Ok(SoftRadius::HalfLuxel)));
        assert_eq!(SoftRadius::read("3"), Some(Ok(SoftRadius::Samples(3))));
        assert!(matches!(SoftRadius::read("-2"), Some(Err(_))));
        assert_eq!(SoftRadius::HalfLuxel.samples(4), 2);
        assert_eq!(SoftRadius::HalfLuxel.samples(1), 0);
        assert_eq!(
            Color::read("255 128 0 9"),
            Some(Ok(Color(DVec3::new(1.0, 128.0 / 255.0, 0.0))))
        );
        assert_eq!(
            Color::read("1 0.5 0.5"),
            Some(Ok(Color(DVec3::new(1.0, 0.5, 0.5))))
        );
        assert_eq!(Color::read("1 2"), Some(Err("three numbers")));
        assert_eq!(Option::<String>::read(""), Some(Ok(Some(String::new()))));
        assert_eq!(Spacing::read("16"), Some(Ok(Spacing(DVec3::splat(16.0)))));
        assert_eq!(
            Spacing::read("16 16 32"),
            Some(Ok(Spacing(DVec3::new(16.0, 16.0, 32.0))))
        );
        assert!(matches!(Spacing::read("16 0.5 32"), Some(Err(_))));
        assert!(matches!(Spacing::read("16 16"), Some(Err(_))));
    }

    #[test]
    fn ranges_clamp_or_leave_the_default() {
        assert_eq!(120.0.within(Range::Clamp(1.0, 90.0)), Err(Some(90.0)));
        assert_eq!(45.0.within(Range::Clamp(1.0, 90.0)), Ok(45.0));
        assert_eq!(0.0.within(Range::Above(0.0)), Err(None));
        assert_eq!(0.0.within(Range::AtLeast(0.0)), Ok(0.0));
        assert_eq!((-1.0).within(Range::AtLeast(0.0)), Err(None));
        assert_eq!(
            0usize.within(Range::Clamp(1.0, f64::INFINITY)),
            Err(Some(1))
        );
        assert_eq!(40usize.within(Range::Clamp(0.0, 16.0)), Err(Some(16)));
        assert_eq!(Range::Clamp(1.0, 90.0).show(), "1–90 (clamped)");
        assert_eq!(Range::Clamp(0.0, f64::INFINITY).show(), "≥ 0 (clamped)");
    }
}
