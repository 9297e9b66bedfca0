//! Ambient sound levels: each leaf hears the water, sky, slime and lava surfaces it can see,
//! loudest when one is near. Engines read `Leaf::ambient` to fade the ambient loops in and out.

use crate::VisError;
use crate::pvs::Pvs;
use glam::Vec3;
use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::geom::Bounds;
use rayon::prelude::*;

/// Ambient channels in `Leaf::ambient` order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ambient {
    /// Water surfaces (`*water` textures).
    Water = 0,
    /// Sky surfaces (`sky` textures).
    Sky = 1,
    /// Slime surfaces (`*slime` textures).
    Slime = 2,
    /// Lava surfaces (`*lava` textures).
    Lava = 3,
}

/// Full volume up to this distance (map units) from the leaf's box.
const FULL_VOLUME_DISTANCE: f64 = 100.0;
/// Volume lost per map unit beyond that (silent from 500 units on).
const FALLOFF_PER_UNIT: f64 = 0.002;

/// The ambient a texture makes, by its name (case-insensitive): liquids start with `*`.
pub fn ambient_of_texture(name: &str) -> Option<Ambient> {
    let name = name.to_ascii_lowercase();
    if name.starts_with("sky") {
        return Some(Ambient::Sky);
    }
    let liquid = name.strip_prefix('*')?;
    if liquid.contains("slime") {
        Some(Ambient::Slime)
    } else if liquid.contains("lava") {
        Some(Ambient::Lava)
    } else if liquid.contains("water") {
        Some(Ambient::Water)
    } else {
        None
    }
}

/// The ambient a leaf of these contents makes as a whole.
pub fn ambient_of_contents(leaf_contents: i32) -> Option<Ambient> {
    match leaf_contents {
        contents::WATER => Some(Ambient::Water),
        contents::SLIME => Some(Ambient::Slime),
        contents::LAVA => Some(Ambient::Lava),
        contents::SKY => Some(Ambient::Sky),
        _ => None,
    }
}

/// Volume (0..=255) of a surface `distance` units from the listener's box.
pub fn level_at(distance: f64) -> u8 {
    let volume = if distance < FULL_VOLUME_DISTANCE {
        1.0
    } else {
        (1.0 - distance * FALLOFF_PER_UNIT).max(0.0)
    };
    (volume * 255.0) as u8
}

/// The largest per-axis gap between two boxes (0 when they overlap).
fn box_distance(a: &Bounds, b: &Bounds) -> f64 {
    (0..3)
        .map(|i| (b.mins[i] - a.maxs[i]).max(a.mins[i] - b.maxs[i]).max(0.0))
        .fold(0.0, f64::max)
}

fn leaf_bounds(mins: [f32; 3], maxs: [f32; 3]) -> Bounds {
    let mut b = Bounds::EMPTY;
    b.add_point(Vec3::from(mins).as_dvec3());
    b.add_point(Vec3::from(maxs).as_dvec3());
    b
}

/// Which ambient channels a run fills (ericw-tools' `-noambient*` options turn them off); an off
/// channel is silent in every leaf.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Channels(pub [bool; 4]);

impl Channels {
    /// Every channel on: the default.
    pub const ALL: Channels = Channels([true; 4]);

    /// `self` with `channel` off.
    pub fn without(mut self, channel: Ambient) -> Channels {
        self.0[channel as usize] = false;
        self
    }
}

impl Default for Channels {
    fn default() -> Self {
        Channels::ALL
    }
}

/// Per face, whether its entity asked for no ambient sound (`_noambient`, carried in the
/// compiler's `SLIPGATE_FACEFLAGS`); empty when the file has no such lump.
fn silent_faces(bsp: &Bsp) -> Result<Vec<bool>, VisError> {
    let flags = bsp.face_flags().map_err(VisError::FaceFlags)?;
    Ok(flags.map_or_else(Vec::new, |f| f.iter().map(|f| f.no_ambient).collect()))
}

/// The sound sources of leaf `l`: channel and bounds. A liquid or sky leaf sounds as a whole (its
/// surfaces may be named unlike liquids and skies, or be missing), and so does every face in it
/// with a liquid or sky texture; faces `silent` marks make no sound, and a leaf with one is
/// silent as a whole too (it is inside the silenced brushes).
fn leaf_sources(bsp: &Bsp, l: usize, silent: &[bool]) -> Vec<(Ambient, Bounds)> {
    let leaf = &bsp.leafs[l];
    let first = leaf.first_marksurface as usize;
    let marks = bsp
        .marksurfaces
        .get(first..first + leaf.num_marksurfaces as usize)
        .unwrap_or(&[]);
    let is_silent = |f: u32| silent.get(f as usize).copied().unwrap_or(false);
    let volume = ambient_of_contents(leaf.contents)
        .filter(|_| !marks.iter().any(|&f| is_silent(f)))
        .map(|kind| (kind, leaf_bounds(leaf.mins, leaf.maxs)));
    let faces = marks.iter().filter(|&&f| !is_silent(f)).filter_map(|&f| {
        let face = bsp.faces.get(f as usize)?;
        let texinfo = bsp.texinfo.get(face.texinfo as usize)?;
        let tex = bsp
            .textures
            .textures
            .get(texinfo.miptex as usize)?
            .as_ref()?;
        let kind = ambient_of_texture(&tex.name())?;
        let mut b = Bounds::EMPTY;
        for v in bsp.face_vertices(face)? {
            b.add_point(Vec3::from(v).as_dvec3());
        }
        Some((kind, b))
    });
    volume.into_iter().chain(faces).collect()
}

/// Fill `Leaf::ambient` of every vis leaf from the sound surfaces of the leaves it sees, on the
/// channels `channels` has on. Returns how many leaves hear anything.
pub fn ambient_levels(bsp: &mut Bsp, pvs: &Pvs, channels: Channels) -> Result<usize, VisError> {
    crate::lump::check_portals_match(bsp, pvs.num_leafs())?;
    let silent = silent_faces(bsp)?;
    let sources: Vec<Vec<(Ambient, Bounds)>> = (1..=pvs.num_leafs())
        .map(|l| leaf_sources(bsp, l, &silent))
        .collect();
    let levels: Vec<[u8; 4]> = (0..pvs.num_leafs())
        .into_par_iter()
        .map(|i| {
            let leaf = &bsp.leafs[i + 1];
            let here = leaf_bounds(leaf.mins, leaf.maxs);
            let mut nearest = [f64::INFINITY; 4];
            for seen in pvs.row(i).iter() {
                for (kind, b) in &sources[seen] {
                    let d = box_distance(&here, b);
                    let slot = &mut nearest[*kind as usize];
                    *slot = slot.min(d);
                }
            }
            let mut level = nearest.map(level_at);
            for (l, on) in level.iter_mut().zip(channels.0) {
                *l = if on { *l } else { 0 };
            }
            level
        })
        .collect();
    let mut hearing = 0;
    for (i, level) in levels.into_iter().enumerate() {
        hearing += usize::from(level.iter().any(|&l| l > 0));
        bsp.leafs[i + 1].ambient = level;
    }
    Ok(hearing)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_names_map_to_channels() {
        assert_eq!(ambient_of_texture("*water1"), Some(Ambient::Water));
        assert_eq!(ambient_of_texture("*04WATER2"), Some(Ambient::Water));
        assert_eq!(ambient_of_texture("SKY4"), Some(Ambient::Sky));
        assert_eq!(ambient_of_texture("*slime0"), Some(Ambient::Slime));
        assert_eq!(ambient_of_texture("*lava1"), Some(Ambient::Lava));
        assert_eq!(ambient_of_texture("*teleport"), None);
        assert_eq!(ambient_of_texture("city4_6"), None);
    }

    #[test]
    fn liquid_and_sky_contents_map_to_channels() {
        assert_eq!(ambient_of_contents(contents::WATER), Some(Ambient::Water));
        assert_eq!(ambient_of_contents(contents::SLIME), Some(Ambient::Slime));
        assert_eq!(ambient_of_contents(contents::LAVA), Some(Ambient::Lava));
        assert_eq!(ambient_of_contents(contents::SKY), Some(Ambient::Sky));
        assert_eq!(ambient_of_contents(contents::EMPTY), None);
        assert_eq!(ambient_of_contents(contents::SOLID), None);
    }

    #[test]
    fn level_falls_off_with_distance() {
        assert_eq!(level_at(0.0), 255);
        assert_eq!(level_at(99.0), 255);
        assert_eq!(level_at(250.0), 127);
        assert_eq!(level_at(500.0), 0);
        assert_eq!(level_at(f64::INFINITY), 0);
    }
}
