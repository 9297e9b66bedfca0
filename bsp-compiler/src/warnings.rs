//! Things wrong with a map that the compiler works around.

use crate::editor::OmittedLayer;
use crate::leak::LeakReport;
use crate::texinfo::FaceContents;
use glam::DVec3;
use quake_formats::bsp::limits::{
    GLQUAKE_MAX_SURFACE_EXTENT, MAX_SURFACE_EXTENT, QUAKESPASM_MAX_SURFACE_EXTENT,
};

use std::path::PathBuf;

/// Something wrong with a map that the compiler works around.
#[derive(Debug, Clone, PartialEq)]
pub enum Warning {
    /// A brush that cannot be built; it is skipped.
    BadBrush {
        /// The entity's index in the map.
        entity: usize,
        /// The brush's index within its entity.
        brush: usize,
        /// The brush's line in the `.map`.
        line: usize,
        /// Why it cannot be built.
        reason: String,
    },
    /// A brush face that cannot be used: it is dropped and the brush built from the others.
    DroppedFace {
        /// The entity's index in the map.
        entity: usize,
        /// The brush's index within its entity.
        brush: usize,
        /// The face's line in the `.map`.
        line: usize,
        /// Why it is dropped.
        reason: DroppedFace,
    },
    /// A brush whose faces' textures give different contents (sky and solid, say): the first
    /// face's are used, as in id's and ericw-tools' compilers. `line` is the first face that
    /// differs.
    MixedContents {
        /// The entity's index in the map.
        entity: usize,
        /// The brush's index within its entity.
        brush: usize,
        /// The line of the first face whose contents differ.
        line: usize,
        /// The contents the brush gets.
        used: FaceContents,
    },
    /// An editor layer marked "Omit From Export": compiled, or left out with everything in it.
    OmittedLayer(OmittedLayer),
    /// A WAD worldspawn names that is nowhere it was looked for (`looked`, in order).
    MissingWad {
        /// The name worldspawn gives.
        name: String,
        /// The paths tried.
        looked: Vec<PathBuf>,
    },
    /// A WAD file that cannot be read or parsed; its textures are not used.
    UnreadableWad {
        /// The WAD file.
        path: PathBuf,
        /// Why it cannot be used.
        reason: String,
    },
    /// A texture that is in no WAD: the face gets a placeholder texture.
    MissingTexture {
        /// The texture's name.
        name: String,
    },
    /// A frame below one the map uses is in no WAD: a placeholder fills the gap, since engines
    /// refuse an animation with a missing frame.
    MissingAnimationFrame {
        /// The missing frame's texture name.
        name: String,
    },
    /// A `+` name whose frame is not `0`-`9` or `a`-`j`: QuakeSpasm refuses to load the map.
    BadAnimationName {
        /// The texture's name.
        name: String,
    },
    /// A brush side whose texture axes meet its plane edge-on (degenerate Valve 220 axes): its
    /// faces get Quake's own projection of the texture instead.
    DegenerateTextureAxes {
        /// The entity's index in the map.
        entity: usize,
        /// The brush's index within its entity.
        brush: usize,
        /// The side's line in the `.map`.
        line: usize,
        /// The side's texture name.
        texture: String,
    },
    /// A point entity whose origin is inside a solid or sky brush (it does not flood).
    EntityInSolid {
        /// The entity's index in the map.
        entity: usize,
        /// The entity's classname.
        classname: String,
        /// The entity's origin.
        origin: DVec3,
        /// The entity's line in the `.map`.
        line: usize,
    },
    /// The map is open to the void.
    Leak(LeakReport),
    /// No point entity lies in open space, so the outside cannot be told from the inside.
    NoEntitiesToFlood,
    /// A brush entity with no usable brushes.
    EmptyBrushEntity {
        /// The entity's index in the map.
        entity: usize,
        /// The entity's classname.
        classname: String,
    },
    /// Faces without `TEX_SPECIAL` wider than WinQuake's limit (only with subdivision off or
    /// coarser than it): `faces` of them, the widest spanning `widest` texels.
    WideFaces {
        /// How many faces are too wide.
        faces: usize,
        /// The widest one's span in texels.
        widest: i32,
    },
    /// An entity key whose value the compiler cannot read: `used` is what it does instead.
    BadKey {
        /// The entity's index in the `.map`.
        entity: usize,
        /// The entity's line in the `.map`.
        line: usize,
        /// The key.
        key: String,
        /// Its value as written.
        value: String,
        /// What the compiler does instead.
        used: String,
    },
    /// Something the compiler does not do yet; the map compiles without it.
    Unsupported {
        /// What is not done.
        what: String,
    },
}

/// Why a brush face is dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DroppedFace {
    /// Its three points are collinear.
    NoPlane,
    /// An earlier face of the brush lies on its plane (facing either way).
    RepeatedPlane,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = |p: &DVec3| format!("({} {} {})", p.x, p.y, p.z);
        match self {
            Warning::BadBrush {
                entity,
                brush,
                line,
                reason,
            } => write!(
                f,
                "line {line}: entity {entity}, brush {brush}: {reason}; brush skipped"
            ),
            Warning::DroppedFace {
                entity,
                brush,
                line,
                reason,
            } => {
                let why = match reason {
                    DroppedFace::NoPlane => "the face's three points lie on one line",
                    DroppedFace::RepeatedPlane => {
                        "the face lies on the plane of an earlier face of the brush"
                    }
                };
                write!(
                    f,
                    "line {line}: entity {entity}, brush {brush}: {why}; face dropped"
                )
            }
            Warning::MixedContents {
                entity,
                brush,
                line,
                used,
            } => write!(
                f,
                "line {line}: entity {entity}, brush {brush}: this face's texture gives other contents than the brush's first face; the brush is {used}"
            ),
            Warning::OmittedLayer(layer) if layer.left_out => write!(
                f,
                "note: layer {:?} (entity {}) is marked Omit From Export: left out with the {} entities in it (--omit-layers)",
                layer.name, layer.entity, layer.entities
            ),
            Warning::OmittedLayer(layer) => write!(
                f,
                "note: layer {:?} (entity {}) is marked Omit From Export: compiled, with the {} entities in it, as ericw-tools compiles it (TrenchBroom's Export, or --omit-layers, leaves it out)",
                layer.name, layer.entity, layer.entities
            ),
            Warning::MissingWad { name, looked } => {
                let looked: Vec<String> = looked
                    .iter()
                    .map(|p| match p.is_relative() {
                        true => format!("{} in the working directory", p.display()),
                        false => p.display().to_string(),
                    })
                    .collect();
                write!(f, "WAD {name} not found; looked for {}", looked.join(", "))
            }
            Warning::UnreadableWad { path, reason } => {
                write!(f, "{}: not a usable WAD: {reason}", path.display())
            }
            Warning::MissingTexture { name } => {
                write!(
                    f,
                    "texture {name} not found in any WAD; using a placeholder"
                )
            }
            Warning::MissingAnimationFrame { name } => write!(
                f,
                "animation frame {name} not found in any WAD; using a placeholder to complete the animation"
            ),
            Warning::BadAnimationName { name } => write!(
                f,
                "texture {name}: a leading + must be followed by a frame 0-9 or a-j; QuakeSpasm refuses to load the map"
            ),
            Warning::DegenerateTextureAxes {
                entity,
                brush,
                line,
                texture,
            } => write!(
                f,
                "line {line}: entity {entity}, brush {brush}: the axes of texture {texture} lie (almost) in the face's plane; using Quake's projection for it"
            ),
            Warning::EntityInSolid {
                entity,
                classname,
                origin,
                line,
            } => write!(
                f,
                "line {line}: entity {entity} ({classname}) at {} is inside a solid brush",
                v(origin)
            ),
            Warning::Leak(report) => write!(
                f,
                "LEAK: {report}; the outside is not filled, see the .pts pointfile"
            ),
            Warning::NoEntitiesToFlood => {
                write!(
                    f,
                    "no point entity in open space: outside filling skipped (the void stays in \
                     the map and its portal file, and vis includes it)"
                )
            }
            Warning::EmptyBrushEntity { entity, classname } => {
                write!(f, "entity {entity} ({classname}) has no usable brushes")
            }
            Warning::WideFaces { faces, widest } => write!(
                f,
                "{faces} faces span more than {MAX_SURFACE_EXTENT} texels (the widest \
                 {widest}): WinQuake refuses the map with \"Bad surface extents\" (GLQuake \
                 above {GLQUAKE_MAX_SURFACE_EXTENT}); QuakeSpasm, vkQuake and Ironwail take up \
                 to {QUAKESPASM_MAX_SURFACE_EXTENT}"
            ),
            Warning::BadKey {
                entity,
                line,
                key,
                value,
                used,
            } => write!(
                f,
                "line {line}: entity {entity}: \"{key}\" \"{value}\" is not a valid value; using {used}"
            ),
            Warning::Unsupported { what } => write!(f, "not supported yet: {what}"),
        }
    }
}
