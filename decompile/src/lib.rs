//! A compiled BSP back into a `.map` file, as ericw-tools' `bsputil --decompile` does: the
//! mapper's way back from a lost source.
//!
//! Entities come from the entity lump. Each brush model's hull 0 tree is walked from its head
//! node, cutting the model's box by every node plane (`region`); each leaf that holds
//! something (solid, sky, a liquid) is then a convex region bounded only by the planes that touch
//! it, and becomes a brush (`leaves`). Each side takes the texture of the BSP faces lying on it
//! and facing out of it; a side meeting faces of several textures is cut along their edges first
//! (`faces`). Sides without a face get `skip` (ericw-tools' choice), or a texture of the brush's
//! own kind for sky and liquids so the brush keeps its contents (`brushes`). Three points per
//! side are chosen so the plane reads back as the BSP's within the compiler's epsilons, as round
//! as that allows (`points`); projections are recovered from the texinfo vectors
//! (`texture`) and the text written (`write`).
//!
//! What cannot come back: clip brushes (they live only in the clip hulls), brushes without
//! collision (`func_detail_illusionary`), how the mapper cut the world into brushes (each leaf
//! is a brush of its own), and the mapper's exact three points on planes through no whole
//! points.

#![warn(missing_docs)]

mod brushes;
mod faces;
mod leaves;
mod points;
mod region;
mod texture;
mod write;

use brushes::{KindTextures, ModelContext, model_brushes, origin_brush};
use glam::DVec3;
use quake_formats::entities::parse_entities;
use quake_formats::{Bsp, FormatError, check_usable};

/// The `.map` dialect written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MapFormat {
    /// Quake's own: shift, rotation and scale on axes picked from each face's normal. Texture
    /// axes Quake cannot express (sheared, or off the face's base plane) are written as near as
    /// it comes and counted in [`DecompileStats::approximate_projections`].
    #[default]
    Quake,
    /// Valve 220 (`"mapversion" "220"`): explicit texture axes, so every projection is exact.
    Valve,
}

/// What [`decompile`] is asked to do.
#[derive(Debug, Clone)]
pub struct Options {
    /// The dialect of the text.
    pub format: MapFormat,
    /// Cut a leaf's brush where one of its sides meets faces of different textures, so each
    /// keeps its own (off: the side takes the texture covering most of it).
    pub split_mixed_textures: bool,
    /// Give each brush entity with an origin an origin brush there as well as its `origin` key
    /// (ericw-tools writes the brush), for compilers that build rotating models around one.
    pub origin_brushes: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            format: MapFormat::Quake,
            split_mixed_textures: true,
            origin_brushes: true,
        }
    }
}

/// Counts of what was written and what was lost on the way.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct DecompileStats {
    /// Entities written (worldspawn included).
    pub entities: usize,
    /// Entities written with a model's brushes (worldspawn included).
    pub brush_entities: usize,
    /// Brushes written, origin brushes included.
    pub brushes: usize,
    /// Brush sides that took their texture from a BSP face.
    pub textured_faces: usize,
    /// Brush sides on which no BSP face lies (`skip`, `trigger`, or a texture of the brush's
    /// kind), origin brushes' sides included.
    pub untextured_faces: usize,
    /// Sides whose texture projection Quake's format can only come near (never in Valve 220).
    pub approximate_projections: usize,
    /// Brushes added by cutting leaves whose sides met faces of different textures.
    pub texture_cuts: usize,
    /// Leaves (or parts of cut ones) left out as slivers: less volume than a brush needs.
    pub sliver_leaves: usize,
    /// Leaves of contents this decompiler does not write (neither empty, solid, sky nor liquid).
    pub unknown_contents_leaves: usize,
    /// Sides whose texture was replaced because no side's texture gave the brush its contents.
    pub renamed_for_contents: usize,
    /// Textured sides whose texture the BSP does not hold (an empty slot of its texture lump),
    /// written as `notexture`.
    pub missing_textures: usize,
    /// Untextured sides given the texture of a textured side on the same plane (counted among
    /// the untextured), for compilers that texture a leaf's face from the first brush side on
    /// its plane, where `skip` would drop it.
    pub borrowed_textures: usize,
}

/// Something in the BSP that [`decompile`] passed over.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Warning {
    /// An entity names a model the BSP does not have; it is written without brushes.
    MissingModel {
        /// The entity's index in the entity lump.
        entity: usize,
        /// The `model` key's value.
        model: String,
    },
    /// Brush models no entity names; their brushes are not written.
    UnusedModels {
        /// How many.
        count: usize,
    },
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Warning::MissingModel { entity, model } => write!(
                f,
                "entity {entity} names model {model:?}, which the BSP does not have: written without brushes"
            ),
            Warning::UnusedModels { count } => write!(
                f,
                "{count} brush model(s) no entity names: their brushes are not written"
            ),
        }
    }
}

/// A decompiled map.
#[derive(Debug, Clone)]
pub struct Decompiled {
    /// The `.map` text.
    pub text: String,
    /// What was written.
    pub stats: DecompileStats,
    /// What was passed over.
    pub warnings: Vec<Warning>,
}

/// Why a BSP cannot be decompiled.
#[derive(Debug, thiserror::Error)]
pub enum DecompileError {
    /// The file fails the checks every tool makes before reading a BSP's indices.
    #[error("the BSP is damaged: {0}")]
    Unusable(#[source] FormatError),
    /// The entity lump does not parse.
    #[error("the entity lump does not parse: {0}")]
    Entities(#[source] FormatError),
    /// The first entity is not worldspawn (or there is none): a map needs one first.
    #[error("the entity lump's first entity is {found:?}, not worldspawn")]
    NoWorldspawn {
        /// The first entity's classname (empty when there is no entity or no classname).
        found: String,
    },
}

/// Decompile `bsp` into `.map` text.
pub fn decompile(bsp: &Bsp, options: &Options) -> Result<Decompiled, DecompileError> {
    check_usable(bsp).map_err(DecompileError::Unusable)?;
    let entities = parse_entities(&bsp.entity_text()).map_err(DecompileError::Entities)?;
    let found = entities.first().map_or("", |e| e.classname());
    if found != "worldspawn" {
        return Err(DecompileError::NoWorldspawn {
            found: found.to_string(),
        });
    }
    let kind_textures = KindTextures::of(bsp);
    let mut stats = DecompileStats::default();
    let mut warnings = Vec::new();
    let mut used = vec![false; bsp.models.len()];
    let mut text = String::new();
    for (index, ent) in entities.iter().enumerate() {
        let model = model_of(index, ent, bsp.models.len(), &mut warnings);
        let mut pairs: Vec<(String, String)> = ent
            .pairs
            .iter()
            .filter(|(k, v)| !(k == "model" && v.starts_with('*')))
            .filter(|(k, _)| !(index == 0 && k == "mapversion"))
            .cloned()
            .collect();
        if index == 0 && options.format == MapFormat::Valve {
            pairs.push(("mapversion".to_string(), "220".to_string()));
        }
        let mut brushes = Vec::new();
        if let Some(m) = model {
            used[m] = true;
            // Engines draw a brush model moved by its entity's origin: the model is stored
            // relative to it.
            let origin = match (m, ent.get_floats::<3>("origin")) {
                (1.., Some(o)) if o.iter().all(|c| c.is_finite()) => DVec3::from(o),
                _ => DVec3::ZERO,
            };
            let ctx = ModelContext {
                bsp,
                origin,
                trigger: ent.classname().starts_with("trigger_"),
                format: options.format,
                split: options.split_mixed_textures,
                kind_textures: &kind_textures,
            };
            brushes = model_brushes(&ctx, &bsp.models[m], &mut stats);
            if options.origin_brushes && origin != DVec3::ZERO {
                let origin_brush = origin_brush(origin, options.format);
                stats.untextured_faces += origin_brush.len();
                brushes.push(origin_brush);
            }
            stats.brush_entities += 1;
        }
        stats.brushes += brushes.len();
        write::entity(&mut text, index, &pairs, &brushes);
        stats.entities += 1;
    }
    let unused = used.iter().filter(|u| !**u).count();
    if unused > 0 {
        warnings.push(Warning::UnusedModels { count: unused });
    }
    Ok(Decompiled {
        text,
        stats,
        warnings,
    })
}

/// The model entity `index` takes its brushes from: model 0 for worldspawn, `*N` for a brush
/// entity (a warning when the BSP has no model N).
fn model_of(
    index: usize,
    ent: &quake_formats::entities::Entity,
    models: usize,
    warnings: &mut Vec<Warning>,
) -> Option<usize> {
    if index == 0 {
        return (models > 0).then_some(0);
    }
    let value = ent.get("model")?;
    let number = value.strip_prefix('*')?;
    match number.trim().parse::<usize>() {
        Ok(n) if n > 0 && n < models => Some(n),
        _ => {
            warnings.push(Warning::MissingModel {
                entity: index,
                model: value.to_string(),
            });
            None
        }
    }
}
