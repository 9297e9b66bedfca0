//! From the map's entities to each model's brushes, the first step of a compile.
//!
//! Worldspawn and the entities merged into it (`func_group`, `func_detail*`,
//! `func_illusionary_visblocker`) make model 0; every other brush entity a model of its own, built
//! around its origin. Each map brush becomes a convex [`Brush`] of the contents its textures and
//! its entity give it ([`EntityContext`]), and, when it collides, a grown copy for each clip hull.
//! Point entities become the occupants the outside fill floods from.

use crate::brush::{Brush, BrushKind, BrushPlane, BrushShape};
use crate::brushlist::{self, ListedBrush};
use crate::faces::{MIN_SQUARENESS, projection_squareness};
use crate::hulls::{HULL_BOXES, bevelled_planes, grown_planes};
use crate::leak::MapBrushRef;
use crate::map::{MapBrush, MapEntity, MapFile};
use crate::options::CompileOptions;
use crate::outside::Occupant;
use crate::planes::PlaneSet;
use crate::texinfo::{self, FaceContents, TextureRole};
use crate::tree::{DETAIL_WALL, FENCE, ILLUSIONARY, VISBLOCKER, engine_contents};
use crate::warnings::{DroppedFace, Warning};
use glam::DVec3;
use quake_formats::bsp::contents;
use quake_formats::bsp::face_channels::DEFAULT_CHANNELS;
use quake_formats::bsp::face_flags::FaceFlags;
use quake_formats::bsp::face_minlight::FaceMinlight;
use quake_formats::bsp::face_tone::FaceTone;
use quake_formats::bsp::phong::{self, FacePhong};
use quake_formats::geom::Bounds;
use quake_formats::int_hash::IntMap;
use rayon::prelude::*;

/// Each model's brushes, with what the rest of the compile needs to name them.
pub(crate) struct Gathered {
    pub models: Vec<ModelInput>,
    pub planes: PlaneSet,
    pub table: TexInfoTable,
    /// The world's point entities, for the outside fill.
    pub occupants: Vec<Occupant>,
    /// Per model, when `brush_list` asks for them.
    pub listed: Vec<Vec<ListedBrush>>,
    /// Each entity's first brush in one numbering of every map brush ([`Brush::source`]).
    pub first_source: Vec<u32>,
    /// Map brushes read, and those that could not be built.
    pub brushes: usize,
    pub bad_brushes: usize,
}

/// Build every entity's brushes, but for those `left_out` marks.
pub(crate) fn gather(
    map: &MapFile,
    left_out: &[bool],
    options: &CompileOptions,
    warnings: &mut Vec<Warning>,
) -> Gathered {
    let mut g = Gathered {
        models: vec![ModelInput::new(0)],
        planes: PlaneSet::new(),
        table: TexInfoTable::default(),
        occupants: Vec::new(),
        listed: Vec::new(),
        first_source: map
            .entities
            .iter()
            .scan(0u32, |next, e| {
                let first = *next;
                *next += e.brushes.len() as u32;
                Some(first)
            })
            .collect(),
        brushes: 0,
        bad_brushes: 0,
    };
    let mut skipped_hint = 0;
    let progress = &options.progress;
    progress.start("brushes", map.entities.len());
    for (index, ent) in map.entities.iter().enumerate() {
        progress.advance(1);
        if left_out[index] {
            continue;
        }
        let class = ent.entity.classname();
        if index > 0 && ent.brushes.is_empty() {
            g.occupants.extend(occupant(ent, index));
            continue;
        }
        let brush_class = EntityBrushes::of(index, class);
        warn_partial_numbers(ent, index, brush_class, warnings);
        let origin = match brush_class {
            EntityBrushes::Submodel => submodel_origin(&map.entities, ent, &mut g.planes),
            _ => None,
        };
        let model = if brush_class == EntityBrushes::Submodel {
            g.models.push(ModelInput::new(index));
            g.models.len() - 1
        } else {
            0
        };
        let mut cx = EntityContext {
            entity: index,
            first_source: g.first_source[index],
            class: brush_class,
            origin: origin.unwrap_or(DVec3::ZERO),
            keys: FaceKeys {
                phong: merged_phong(ent, index, brush_class),
                lit_water: lit_water(&map.entities, ent, options.lit_water),
                flags: merged_face_flags(ent, index, brush_class),
                surflight_group: merged_surflight_group(ent, index, brush_class, warnings),
                minlight: merged_minlight(ent, index, brush_class),
                channels: merged_channels(ent, index, brush_class, warnings),
                tone: merged_tone(ent, index, brush_class),
            },
            minlight_exclude: merged_minlight_exclude(ent, index, brush_class),
            transwater: options.transwater,
            bmodel_contents: options.bmodel_contents,
            table: &mut g.table,
            warnings,
        };
        let (built, bad, hints) = cx.build_brushes(ent, &mut g.planes);
        g.brushes += ent.brushes.len();
        g.bad_brushes += bad;
        skipped_hint += hints;
        let hulls = match brush_class {
            EntityBrushes::Submodel => HullMask::of(ent, index, warnings),
            _ => HullMask::ALL,
        };
        g.add(model, built, hulls, options);
    }
    progress.finish();
    if skipped_hint > 0 {
        warnings.push(Warning::Unsupported {
            what: format!("{skipped_hint} hint brushes in brush entities are ignored"),
        });
    }
    g
}

impl Gathered {
    /// Add the brushes `built` (each with whether it is a clip brush) to model `model`, grown
    /// for each clip hull when they collide; clip brushes exist only grown. A hull `hulls`
    /// leaves out gets none of them.
    fn add(
        &mut self,
        model: usize,
        built: Vec<(Brush, bool)>,
        hulls: HullMask,
        options: &CompileOptions,
    ) {
        if options.brush_list {
            self.listed.resize_with(self.models.len(), Vec::new);
            self.listed[model].extend(
                built
                    .iter()
                    .filter_map(|(b, clip)| listed_brush(b, *clip, &self.planes)),
            );
        }
        // Each colliding brush's bevels once, grown by every hull's box and shaped on all
        // cores; the planes are numbered after, in the order one brush after another gives.
        let grows = |brush: &Brush, clip: bool| {
            let collides = matches!(
                engine_contents(brush.contents),
                contents::SOLID | contents::SKY
            );
            options.clip_hulls && (collides || clip)
        };
        let grown: Vec<[Option<BrushShape>; 2]> = built
            .par_iter()
            .map(|(brush, clip)| {
                if !grows(brush, *clip) {
                    return [None, None];
                }
                let bevels = bevelled_planes(brush, &self.planes);
                let mut shapes = HULL_BOXES
                    .map(|(mins, maxs)| BrushShape::of(&grown_planes(&bevels, mins, maxs)).ok());
                for (hull, shape) in shapes.iter_mut().enumerate() {
                    if !hulls.has(hull + 1) {
                        *shape = None;
                    }
                }
                shapes
            })
            .collect();
        let m = &mut self.models[model];
        for ((brush, clip), shapes) in built.into_iter().zip(grown) {
            for (hull, shape) in shapes.into_iter().enumerate() {
                if let Some(g) = shape.and_then(|s| {
                    s.into_brush(&mut self.planes, contents::SOLID, brush.source)
                        .ok()
                }) {
                    m.hull_brushes[hull].push(g);
                }
            }
            if clip || !hulls.has(0) {
                m.clip_bounds = m.clip_bounds.union(&brush.bounds);
            } else {
                m.brushes.push(brush);
            }
        }
    }
}

/// The map brush numbered `source` ([`Brush::source`]) of `map`, whose entities' first brushes
/// are numbered `first_source`.
pub(crate) fn map_brush(map: &MapFile, first_source: &[u32], source: u32) -> Option<MapBrushRef> {
    let entity = first_source
        .partition_point(|&first| first <= source)
        .checked_sub(1)?;
    let brush = (source - first_source[entity]) as usize;
    Some(MapBrushRef {
        entity,
        brush,
        line: map.entities[entity].brushes.get(brush)?.line,
    })
}

/// A map texinfo: projection vectors and texture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapTexInfo {
    pub vecs: [[f64; 4]; 2],
    /// Index into the texture name list.
    pub texture: u32,
    pub role: TextureRole,
    /// The `_phong` group of the world-merged entity the face came from.
    pub phong: FacePhong,
    /// Liquid faces get lightmaps ([`crate::CompileOptions::lit_water`], or the entity's
    /// `_litwater`).
    pub lit_water: bool,
    /// What the world-merged entity's keys say of its faces' shadows and ambient sound.
    pub flags: FaceFlags,
    /// The `_surflight_group` of the world-merged entity (worldspawn included) the face came
    /// from; 0: none.
    pub surflight_group: i32,
    /// The `_minlight` of the world-merged entity the face came from (level 0: none).
    pub minlight: FaceMinlight,
    /// The `_object_channel_mask` of the world-merged entity the face came from (1: the
    /// world's).
    pub channels: u32,
    /// The `_maxlight` and `_lightcolorscale` of the world-merged entity the face came from.
    pub tone: FaceTone,
}

/// What a face's entity says about the face, beyond its brush: one of these per entity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FaceKeys {
    pub phong: FacePhong,
    /// Whether its liquids are lit (only liquids' texinfos carry it).
    pub lit_water: bool,
    pub flags: FaceFlags,
    pub surflight_group: i32,
    pub minlight: FaceMinlight,
    pub channels: u32,
    pub tone: FaceTone,
}

impl MapTexInfo {
    /// Written with `TEX_SPECIAL`: no lightmap, never subdivided.
    pub fn is_special(&self) -> bool {
        self.role.is_special(self.lit_water)
    }

    /// The entity keys it was interned with.
    pub(crate) fn keys(&self) -> FaceKeys {
        FaceKeys {
            phong: self.phong,
            lit_water: self.lit_water,
            flags: self.flags,
            surflight_group: self.surflight_group,
            minlight: self.minlight,
            channels: self.channels,
            tone: self.tone,
        }
    }
}

/// One model's brushes before tree building.
pub(crate) struct ModelInput {
    pub entity: usize,
    pub brushes: Vec<Brush>,
    /// Grown brushes of hulls 1 and 2.
    pub hull_brushes: [Vec<Brush>; 2],
    /// Bounds of the clip brushes, which only exist grown in the hulls.
    pub clip_bounds: Bounds,
}

impl ModelInput {
    /// Brushes of all three trees: the unit of model building progress.
    pub fn work(&self) -> usize {
        self.brushes.len() + self.hull_brushes[0].len() + self.hull_brushes[1].len()
    }

    fn new(entity: usize) -> ModelInput {
        ModelInput {
            entity,
            brushes: Vec::new(),
            hull_brushes: [Vec::new(), Vec::new()],
            clip_bounds: Bounds::EMPTY,
        }
    }
}

/// The hulls a brush entity's brushes are in: its `_hulls` key, bit N for hull N (ericw-tools'
/// convention; 0 or no key: every hull). Without hull 0 the model has no faces and point traces
/// pass through it, like a clip brush; without hull 1 or 2 the player or the large monsters walk
/// through it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct HullMask(u32);

impl HullMask {
    pub(crate) const ALL: HullMask = HullMask(0b111);

    /// Entity `index`'s mask; a value that is not a whole number warns and leaves every hull.
    fn of(ent: &MapEntity, index: usize, warnings: &mut Vec<Warning>) -> HullMask {
        let Some(text) = ent.entity.get("_hulls") else {
            return HullMask::ALL;
        };
        match text.trim().parse::<u32>() {
            Ok(0) => HullMask::ALL,
            Ok(bits) => HullMask(bits & HullMask::ALL.0),
            Err(_) => {
                warnings.push(Warning::BadKey {
                    entity: index,
                    line: ent.line,
                    key: "_hulls".into(),
                    value: text.into(),
                    used: "every hull".into(),
                });
                HullMask::ALL
            }
        }
    }

    fn has(self, hull: usize) -> bool {
        self.0 & (1 << hull) != 0
    }
}

/// How an entity's brushes enter the compile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum EntityBrushes {
    /// Worldspawn and `func_group`.
    World,
    /// `func_detail`: world brushes that do not split the vis structure.
    Detail,
    /// `func_detail_wall`: detail that leaves the faces it touches whole.
    DetailWall,
    /// `func_detail_fence`: detail with see-through (fence) textures.
    Fence,
    /// `func_detail_illusionary`: drawn detail without collision.
    Illusionary,
    /// `func_illusionary_visblocker`: drawn, walked through, and closed to vis.
    VisBlocker,
    /// A brush entity of its own.
    Submodel,
}

impl EntityBrushes {
    pub(crate) fn of(index: usize, classname: &str) -> EntityBrushes {
        match classname {
            _ if index == 0 => EntityBrushes::World,
            "func_group" => EntityBrushes::World,
            "func_detail" => EntityBrushes::Detail,
            "func_detail_wall" => EntityBrushes::DetailWall,
            "func_detail_fence" => EntityBrushes::Fence,
            "func_detail_illusionary" => EntityBrushes::Illusionary,
            "func_illusionary_visblocker" => EntityBrushes::VisBlocker,
            _ => EntityBrushes::Submodel,
        }
    }

    fn kind(self) -> BrushKind {
        match self {
            EntityBrushes::World | EntityBrushes::Submodel | EntityBrushes::VisBlocker => {
                BrushKind::Structural
            }
            _ => BrushKind::Detail,
        }
    }
}

/// What a texinfo is interned by: its projection's bits, texture, phong group, whether it is lit
/// water, its face flags, surface light group, minlight's bits, light channels and tone's bits.
type TexInfoKey = (
    [u64; 8],
    u32,
    u32,
    bool,
    FaceFlags,
    i32,
    [u32; 4],
    u32,
    [u32; 2],
);

/// Texture names and texinfos, interned in first-use order.
#[derive(Default)]
pub(crate) struct TexInfoTable {
    pub names: Vec<String>,
    name_index: IntMap<String, u32>,
    pub infos: Vec<MapTexInfo>,
    info_index: IntMap<TexInfoKey, u32>,
}

impl TexInfoTable {
    /// The texinfo of `name` projected by `vecs` on a face whose entity gives it `keys` (faces
    /// of different phong or surface light groups, lighting or flags never share one, so they
    /// never merge).
    pub(crate) fn intern(&mut self, name: &str, vecs: [[f64; 4]; 2], keys: FaceKeys) -> u32 {
        let FaceKeys {
            phong,
            lit_water,
            flags,
            surflight_group,
            minlight,
            channels,
            tone,
        } = keys;
        let key = name.to_ascii_lowercase();
        let texture = match self.name_index.get(&key) {
            Some(&i) => i,
            None => {
                let i = self.names.len() as u32;
                self.names.push(name.to_string());
                self.name_index.insert(key, i);
                i
            }
        };
        let bits: [u64; 8] = std::array::from_fn(|i| (vecs[i / 4][i % 4] as f32).to_bits() as u64);
        let role = TextureRole::of(name);
        // Only liquids' texinfos depend on it; others stay shared.
        let lit_water = lit_water && matches!(role, TextureRole::Liquid(_));
        let key = (
            bits,
            texture,
            phong.group,
            lit_water,
            flags,
            surflight_group,
            [
                minlight.level,
                minlight.color[0],
                minlight.color[1],
                minlight.color[2],
            ]
            .map(f32::to_bits),
            channels,
            [tone.maxlight, tone.color_scale].map(f32::to_bits),
        );
        if let Some(&i) = self.info_index.get(&key) {
            return i;
        }
        let i = self.infos.len() as u32;
        self.infos.push(MapTexInfo {
            vecs,
            texture,
            role,
            phong,
            lit_water,
            flags,
            surflight_group,
            minlight,
            channels,
            tone,
        });
        self.info_index.insert(key, i);
        i
    }
}

/// A submodel with an origin brush is built around that brush's centre, which becomes its
/// "origin" (what rotating entities turn about); without one, around its origin key.
pub(crate) fn submodel_origin(
    entities: &[MapEntity],
    ent: &MapEntity,
    planes: &mut PlaneSet,
) -> Option<DVec3> {
    origin_brush_centre(ent, planes).or_else(|| key_origin(entities, ent))
}

fn is_origin_brush(mb: &MapBrush) -> bool {
    mb.faces
        .iter()
        .any(|f| TextureRole::of(&f.texture) == TextureRole::Origin)
}

/// The centre of the bounds of an entity's origin brushes, if it has any that can be built.
fn origin_brush_centre(ent: &MapEntity, planes: &mut PlaneSet) -> Option<DVec3> {
    let mut bounds = Bounds::EMPTY;
    for mb in ent.brushes.iter().filter(|mb| is_origin_brush(mb)) {
        let faces: Option<Vec<BrushPlane>> = mb
            .faces
            .iter()
            .map(|f| {
                Some(BrushPlane {
                    plane: f.plane(DVec3::ZERO)?,
                    texinfo: None,
                })
            })
            .collect();
        if let Some(b) = faces.and_then(|f| Brush::from_planes(&f, planes, contents::SOLID, 0).ok())
        {
            bounds = bounds.union(&b.bounds);
        }
    }
    (!bounds.is_empty()).then(|| bounds.center())
}

/// The number keys the compiler reads on every brush entity (worldspawn's `_litwater` too).
const NUMBER_KEYS: &[&str] = &["_litwater", "_splitturb", "_mirrorinside", "_noclipfaces"];

/// The number keys it reads on entities merged into the world only (light reads brush models'
/// own).
const MERGED_NUMBER_KEYS: &[&str] = &[
    "_shadow",
    "_noambient",
    "_dirt",
    "_bounce",
    "_lightignore",
    "_minlight",
    "_phong",
    "_phong_angle",
    "_phong_angle_concave",
];

/// A warning for each number key the compiler reads on `ent` whose value is not wholly a
/// number: it takes the number the value starts with, as ericw-tools' `atof` does (`"150x"` is
/// 150), and a value with none is not set.
fn warn_partial_numbers(
    ent: &MapEntity,
    index: usize,
    class: EntityBrushes,
    warnings: &mut Vec<Warning>,
) {
    let merged = merged_into_world(index, class);
    let keys = NUMBER_KEYS
        .iter()
        .chain(MERGED_NUMBER_KEYS.iter().filter(|_| merged));
    for &key in keys {
        let Some(value) = ent.entity.get(key).filter(|v| !v.trim().is_empty()) else {
            continue;
        };
        let used = match ent.entity.get_leading_float(key) {
            Some((_, true)) => continue,
            Some((v, false)) => format!("{v}, the number it starts with, as ericw-tools reads it"),
            None => "nothing: the key is not set".to_string(),
        };
        warnings.push(Warning::BadKey {
            entity: index,
            line: ent.line,
            key: key.to_string(),
            value: value.to_string(),
            used,
        });
    }
}

/// Whether `ent`'s liquids are lit: its `_litwater` key (or ericw-tools' other name for it,
/// `_splitturb`), else the worldspawn's, else `default`.
fn lit_water(entities: &[MapEntity], ent: &MapEntity, default: bool) -> bool {
    let key = |e: &MapEntity| {
        (e.entity.get_leading_float("_litwater").map(|(v, _)| v))
            .or_else(|| e.entity.get_leading_float("_splitturb").map(|(v, _)| v))
            .map(|v| v != 0.0)
    };
    key(ent)
        .or_else(|| entities.first().and_then(key))
        .unwrap_or(default)
}

/// Whether entity `index` of `class` is merged into the world (`func_detail*`, `func_group`):
/// light reads the keys of worldspawn and brush models from their entities, but those of merged
/// entities only from what the compiler records per face.
fn merged_into_world(index: usize, class: EntityBrushes) -> bool {
    index != 0 && class != EntityBrushes::Submodel
}

/// What the keys of an entity merged into the world say of its faces: `_shadow -1` casts none,
/// and `func_detail_illusionary` casts none unless `_shadow 1` (as in ericw-tools);
/// `_noambient 1` gives no ambient sound; `_dirt -1`, `_bounce 0` and `_lightignore` as on a
/// brush model. Brush models' keys are light's to read.
fn merged_face_flags(ent: &MapEntity, index: usize, class: EntityBrushes) -> FaceFlags {
    if !merged_into_world(index, class) {
        return FaceFlags::default();
    }
    let number = |key| ent.entity.get_leading_float(key).map(|(v, _)| v);
    let shadow = number("_shadow");
    FaceFlags {
        no_shadow: shadow == Some(-1.0)
            || (class == EntityBrushes::Illusionary && shadow != Some(1.0)),
        no_ambient: number("_noambient").is_some_and(|v| v != 0.0),
        no_dirt: number("_dirt") == Some(-1.0),
        no_bounce: number("_bounce").is_some_and(|v| v <= 0.0),
        // A switch, as light reads one: off for 0 and -1, on for any other number.
        light_ignore: number("_lightignore").is_some_and(|v| v != 0.0 && v != -1.0),
        no_minlight: false,
    }
}

/// The `_minlight` (and `_minlight_color` or `_mincolor`, 0–1 or 0–255) of an entity merged
/// into the world, which light reads from the BSP for its faces as it reads a brush model's
/// from its entity.
fn merged_minlight(ent: &MapEntity, index: usize, class: EntityBrushes) -> FaceMinlight {
    let level = ent
        .entity
        .get_leading_float("_minlight")
        .map(|(v, _)| v)
        .unwrap_or(0.0);
    if !merged_into_world(index, class) || level == 0.0 {
        return FaceMinlight::default();
    }
    let color = ["_minlight_color", "_mincolor"]
        .iter()
        .find_map(|key| ent.entity.get_floats::<3>(key))
        .map_or(DVec3::ONE, |c| {
            quake_formats::entities::normalize_color(DVec3::from(c))
        });
    FaceMinlight {
        level: level as f32,
        color: color.as_vec3().to_array(),
    }
}

/// The `_maxlight` and `_lightcolorscale` of an entity merged into the world (light reads
/// worldspawn's and brush models' own keys). Numbers read as ericw-tools reads them, up to the
/// first character that is not part of one.
fn merged_tone(ent: &MapEntity, index: usize, class: EntityBrushes) -> FaceTone {
    if !merged_into_world(index, class) {
        return FaceTone::default();
    }
    let number = |key| ent.entity.get_leading_float(key).map(|(v, _)| v);
    FaceTone::from_keys(number("_maxlight"), number("_lightcolorscale"))
}

/// The `_minlight_exclude` texture of an entity merged into the world: its faces of that
/// texture take no minlight.
fn merged_minlight_exclude(ent: &MapEntity, index: usize, class: EntityBrushes) -> Option<String> {
    if !merged_into_world(index, class) {
        return None;
    }
    ent.entity
        .get("_minlight_exclude")
        .filter(|t| !t.is_empty())
        .map(str::to_string)
}

/// The `_surflight_group` of entity `index` if it is worldspawn or merged into the world (light
/// could not tell their faces apart otherwise; it reads brush models' own keys). A value that is
/// not a whole number warns and leaves no group.
fn merged_surflight_group(
    ent: &MapEntity,
    index: usize,
    class: EntityBrushes,
    warnings: &mut Vec<Warning>,
) -> i32 {
    const KEY: &str = "_surflight_group";
    match ent
        .entity
        .get(KEY)
        .filter(|_| class != EntityBrushes::Submodel)
    {
        Some(text) => parse_or_warn((ent, index), KEY, text, (0, "no group"), warnings),
        None => 0,
    }
}

/// The `_object_channel_mask` of entity `index` if it is merged into the world (light reads
/// brush models' own): the light channels its faces take light on and block light on. A value
/// that is not a whole number from 0 to 2^32 - 1 warns and leaves the world's.
fn merged_channels(
    ent: &MapEntity,
    index: usize,
    class: EntityBrushes,
    warnings: &mut Vec<Warning>,
) -> u32 {
    const KEY: &str = "_object_channel_mask";
    match ent
        .entity
        .get(KEY)
        .filter(|t| merged_into_world(index, class) && !t.trim().is_empty())
    {
        Some(text) => {
            let default = (DEFAULT_CHANNELS, "the world's channel, 1");
            parse_or_warn((ent, index), KEY, text, default, warnings)
        }
        None => DEFAULT_CHANNELS,
    }
}

/// `text`, the value of `key` on entity `index`, parsed whole; a value that does not parse
/// warns and gives `default` (its first), named for the warning by its second.
fn parse_or_warn<T: std::str::FromStr>(
    (ent, index): (&MapEntity, usize),
    key: &str,
    text: &str,
    (default, used): (T, &str),
    warnings: &mut Vec<Warning>,
) -> T {
    text.trim().parse().unwrap_or_else(|_| {
        warnings.push(Warning::BadKey {
            entity: index,
            line: ent.line,
            key: key.into(),
            value: text.into(),
            used: used.into(),
        });
        default
    })
}

/// The `_phong` group of entity `index` if it is merged into the world (its
/// faces could not be told apart from the world's otherwise): its entity
/// index as group id. Worldspawn and brush models get none here; light reads
/// their own keys.
fn merged_phong(ent: &MapEntity, index: usize, class: EntityBrushes) -> FacePhong {
    let merged = merged_into_world(index, class);
    let angle = phong::angle_from_keys(
        ent.entity.get_leading_float("_phong").map(|(v, _)| v),
        ent.entity.get_leading_float("_phong_angle").map(|(v, _)| v),
    );
    match angle.filter(|_| merged) {
        Some(angle) => FacePhong {
            group: index as u32,
            angle: angle as f32,
            concave: phong::concave_from_key(
                ent.entity
                    .get_leading_float("_phong_angle_concave")
                    .map(|(v, _)| v),
            ),
        },
        None => FacePhong::default(),
    }
}

/// The origin a submodel without origin brushes is built around: for Hipnotic's `rotate_*`
/// entities the origin of the entity their `target` names (an `info_rotate`, the pivot), else
/// the submodel's own `origin` key. Engines draw a model moved by its origin, so its brushes must
/// be stored relative to it to appear where the mapper put them.
fn key_origin(entities: &[MapEntity], ent: &MapEntity) -> Option<DVec3> {
    let pivot = ent
        .entity
        .classname()
        .starts_with("rotate_")
        .then(|| ent.entity.get("target"))
        .flatten()
        .and_then(|target| {
            entities
                .iter()
                .find(|e| e.entity.get("targetname") == Some(target))
        });
    let [x, y, z] = pivot.unwrap_or(ent).entity.get_floats::<3>("origin")?;
    Some(DVec3::new(x, y, z))
}

/// The point entity `ent` (number `index`) as an occupant of open space for the flood, where
/// [`quake_formats::entities::Entity::fill_origin`] says it marks one.
pub(crate) fn occupant(ent: &MapEntity, index: usize) -> Option<Occupant> {
    let [x, y, z] = ent.entity.fill_origin()?;
    Some(Occupant {
        entity: index,
        classname: ent.entity.classname().to_string(),
        origin: DVec3::new(x, y, z),
        line: ent.line,
    })
}

/// The faces of a map brush as the compiler takes them: each face's plane (relative to the
/// entity's origin) and texinfo, with its texture's role and its line.
struct BrushFaces {
    planes: Vec<BrushPlane>,
    roles: Vec<TextureRole>,
    lines: Vec<usize>,
    /// Faces of the map brush left out (warned about).
    dropped: usize,
}

/// What an entity's brushes go through to become [`Brush`]es.
struct EntityContext<'a> {
    entity: usize,
    /// The [`Brush::source`] of the entity's first brush.
    first_source: u32,
    class: EntityBrushes,
    origin: DVec3,
    keys: FaceKeys,
    /// Faces of this texture take no minlight (`_minlight_exclude`).
    minlight_exclude: Option<String>,
    /// Liquids are seen through (ericw-tools' `-transwater`): they are detail, which vis does
    /// not cut into clusters; otherwise structural in any entity, as vis's boundaries.
    transwater: bool,
    /// A brush model's liquid brushes keep their contents ([`CompileOptions::bmodel_contents`]).
    bmodel_contents: bool,
    table: &'a mut TexInfoTable,
    warnings: &'a mut Vec<Warning>,
}

impl EntityContext<'_> {
    /// The entity's keys as they apply to a face of `texture`.
    fn face_keys(&self, texture: &str) -> FaceKeys {
        let excluded = self
            .minlight_exclude
            .as_deref()
            .is_some_and(|t| t.eq_ignore_ascii_case(texture));
        if !excluded {
            return self.keys;
        }
        FaceKeys {
            flags: FaceFlags {
                no_minlight: true,
                ..self.keys.flags
            },
            minlight: FaceMinlight::default(),
            ..self.keys
        }
    }

    /// The faces of map brush number `bi`. As in id's and ericw-tools' compilers, a face whose
    /// three points are collinear (no plane) and a face on a plane an earlier face of the brush
    /// already lies on (either way round; id's dm2 has one) are dropped with a warning naming
    /// the face's line, and the brush is built from the rest.
    fn faces(&mut self, mb: &MapBrush, bi: usize) -> BrushFaces {
        let (entity, origin) = (self.entity, self.origin);
        let mut out = BrushFaces {
            planes: Vec::with_capacity(mb.faces.len()),
            roles: Vec::with_capacity(mb.faces.len()),
            lines: Vec::with_capacity(mb.faces.len()),
            dropped: 0,
        };
        for f in &mb.faces {
            let dropped = |reason| Warning::DroppedFace {
                entity,
                brush: bi,
                line: f.line,
                reason,
            };
            let Some(plane) = f.plane(origin) else {
                self.warnings.push(dropped(DroppedFace::NoPlane));
                out.dropped += 1;
                continue;
            };
            let on_plane =
                |b: &BrushPlane| b.plane.same_as(&plane) || b.plane.same_as(&plane.flipped());
            if out.planes.iter().any(on_plane) {
                self.warnings.push(dropped(DroppedFace::RepeatedPlane));
                out.dropped += 1;
                continue;
            }
            // Engines draw the model moved by its origin: shift the texture to match.
            let mut vecs = f.projection.vecs(&plane);
            for row in &mut vecs {
                row[3] += DVec3::new(row[0], row[1], row[2]).dot(origin);
            }
            let role = TextureRole::of(&f.texture);
            if role.is_drawn() && projection_squareness(&vecs, plane.normal) < MIN_SQUARENESS {
                self.warnings.push(Warning::DegenerateTextureAxes {
                    entity,
                    brush: bi,
                    line: f.line,
                    texture: f.texture.clone(),
                });
            }
            let texinfo = self
                .table
                .intern(&f.texture, vecs, self.face_keys(&f.texture));
            out.roles.push(role);
            out.lines.push(f.line);
            out.planes.push(BrushPlane {
                plane,
                texinfo: Some(texinfo),
            });
        }
        out
    }

    /// The contents of a (non-hint) brush of these faces. The texture decides first, as in
    /// ericw-tools: a sky or liquid brush stays one in any detail entity (sky seals the map
    /// wherever it is); only solid brushes take their entity's contents. The brush's first face
    /// that gives contents decides them; a later one giving others is warned about. A brush
    /// model's brushes are solid, unless `-bmodelcontents` lets its liquids be liquid.
    fn contents(&mut self, faces: &BrushFaces, bi: usize) -> (i32, FaceContents) {
        let (textured, conflict) = texinfo::brush_contents(&faces.roles);
        if let Some(i) = conflict {
            self.warnings.push(Warning::MixedContents {
                entity: self.entity,
                brush: bi,
                line: faces.lines[i],
                used: textured,
            });
        }
        let contents = match (self.class, textured) {
            (EntityBrushes::Submodel, FaceContents::Liquid(c)) if self.bmodel_contents => c,
            (EntityBrushes::Submodel, _) => contents::SOLID,
            (EntityBrushes::VisBlocker, _) => VISBLOCKER,
            (_, FaceContents::Sky) => contents::SKY,
            (_, FaceContents::Liquid(c)) => c,
            (EntityBrushes::Fence, _) => FENCE,
            (EntityBrushes::DetailWall, _) => DETAIL_WALL,
            (EntityBrushes::Illusionary, _) => ILLUSIONARY,
            (EntityBrushes::World | EntityBrushes::Detail, _) => contents::SOLID,
        };
        (contents, textured)
    }

    /// Build the entity's brushes, in coordinates relative to its origin, each with whether it
    /// is a clip brush; origin brushes are left out. Brush `i` gets the source `first_source +
    /// i`. Returns the brushes, the number of bad brushes and the number of hint brushes skipped
    /// (outside the world).
    fn build_brushes(
        &mut self,
        ent: &MapEntity,
        planes: &mut PlaneSet,
    ) -> (Vec<(Brush, bool)>, usize, usize) {
        let mut out = Vec::new();
        let (mut bad, mut hints) = (0, 0);
        let mirror_inside = ent
            .entity
            .get_leading_float("_mirrorinside")
            .map(|(v, _)| v)
            .map(|v| v != 0.0);
        let no_clip_faces = ent
            .entity
            .get_leading_float("_noclipfaces")
            .map(|(v, _)| v)
            .is_some_and(|v| v != 0.0);
        for (bi, mb) in ent.brushes.iter().enumerate() {
            if is_origin_brush(mb) {
                continue;
            }
            let faces = self.faces(mb, bi);
            let hint = faces
                .roles
                .iter()
                .any(|r| matches!(r, TextureRole::Hint | TextureRole::HintSkip));
            if hint && self.class == EntityBrushes::Submodel {
                hints += 1;
                continue;
            }
            let (brush_contents, textured) = if hint {
                (contents::EMPTY, FaceContents::Solid)
            } else {
                self.contents(&faces, bi)
            };
            let source = self.first_source + bi as u32;
            match Brush::from_planes(&faces.planes, planes, brush_contents, source) {
                Ok(mut b) => {
                    if hint {
                        b.kind = BrushKind::Hint;
                        // Only the hint faces split; the others (skip, hintskip) are ignored.
                        for s in &mut b.sides {
                            let role = s.texinfo.map(|t| self.table.infos[t as usize].role);
                            s.buried |= role != Some(TextureRole::Hint);
                        }
                    } else if brush_contents == contents::SKY {
                        b.kind = BrushKind::Structural;
                    } else if contents::is_liquid(brush_contents) {
                        b.kind = match self.transwater {
                            true => BrushKind::Detail,
                            false => BrushKind::Structural,
                        };
                    } else {
                        b.kind = self.class.kind();
                    }
                    b.mirror_inside = mirror_inside;
                    b.no_clip_faces = no_clip_faces;
                    out.push((b, textured == FaceContents::Clip));
                }
                Err(e) => {
                    bad += 1;
                    self.warnings.push(Warning::BadBrush {
                        entity: self.entity,
                        brush: bi,
                        line: mb.line,
                        reason: match faces.dropped {
                            0 => e.to_string(),
                            n => format!("{e} once {n} unusable faces are dropped"),
                        },
                    });
                }
            }
        }
        (out, bad, hints)
    }
}

/// A built brush as the `BRUSHLIST` lump stores it: clip brushes as [`brushlist::CLIP`], as
/// ericw-tools writes them; brushes nothing collides with (hint, illusionary) are left out.
fn listed_brush(brush: &Brush, clip: bool, planes: &PlaneSet) -> Option<ListedBrush> {
    let contents = match engine_contents(brush.contents) {
        _ if clip => brushlist::CLIP,
        _ if brush.kind == BrushKind::Hint => return None,
        contents::EMPTY => return None,
        c => c,
    };
    Some(ListedBrush::of(brush, contents, planes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::parse_map;
    use std::path::Path;

    #[test]
    fn phong_groups_only_for_entities_merged_into_the_world() {
        let text = "{ \"classname\" \"worldspawn\" \"_phong\" \"1\" }\n\
                    { \"classname\" \"func_detail\" \"_phong\" \"1\" }\n\
                    { \"classname\" \"func_group\" \"_phong_angle\" \"30\" }\n\
                    { \"classname\" \"func_wall\" \"_phong\" \"1\" }\n\
                    { \"classname\" \"func_detail_wall\" }\n";
        let map = parse_map(Path::new("phong.map"), text).expect("parse");
        let got: Vec<FacePhong> = map
            .entities
            .iter()
            .enumerate()
            .map(|(i, e)| merged_phong(e, i, EntityBrushes::of(i, e.entity.classname())))
            .collect();
        let group = |group, angle| FacePhong {
            group,
            angle,
            concave: 0.0,
        };
        let none = FacePhong::default();
        // Worldspawn and brush models keep their keys for light to read.
        assert_eq!(got, vec![none, group(1, 89.0), group(2, 30.0), none, none]);
    }

    #[test]
    fn faces_of_different_phong_groups_or_flags_get_different_texinfos() {
        let mut table = TexInfoTable::default();
        let vecs = [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]];
        let grouped = FacePhong {
            group: 3,
            angle: 89.0,
            concave: 0.0,
        };
        let keys = |phong, flags| FaceKeys {
            phong,
            lit_water: true,
            flags,
            surflight_group: 0,
            minlight: FaceMinlight::default(),
            channels: DEFAULT_CHANNELS,
            tone: FaceTone::default(),
        };
        let plain = table.intern(
            "wall",
            vecs,
            keys(FacePhong::default(), FaceFlags::default()),
        );
        let a = table.intern("wall", vecs, keys(grouped, FaceFlags::default()));
        assert_ne!(plain, a);
        assert_eq!(
            table.intern("wall", vecs, keys(grouped, FaceFlags::default())),
            a
        );
        let shadowless = FaceFlags {
            no_shadow: true,
            ..FaceFlags::default()
        };
        let b = table.intern("wall", vecs, keys(grouped, shadowless));
        assert_ne!(a, b);
        assert_eq!(table.infos[b as usize].flags, shadowless);
        assert_eq!(table.infos[a as usize].phong, grouped);
        let lit_group = FaceKeys {
            surflight_group: 5,
            ..keys(FacePhong::default(), FaceFlags::default())
        };
        let c = table.intern("wall", vecs, lit_group);
        assert!(![plain, a, b].contains(&c));
        assert_eq!(table.infos[c as usize].surflight_group, 5);
        assert_eq!(table.names.len(), 1, "one texture either way");
    }
}
