//! A model's filled leaves as `.map` brushes: three points per side, a texture and its
//! projection, in an order that gives the brush the leaf's contents.

use crate::faces::{ModelFaces, SideFace, TexturedRegion, texture_region};
use crate::leaves::{FilledLeaf, filled_leaves};
use crate::points::{read_back, three_points};
use crate::region::{Region, touching_planes, volume};
use crate::texture::{Gives, Projection, default_name, gives, plain, to_quake, to_valve};
use crate::{DecompileStats, MapFormat};
use glam::DVec3;
use quake_formats::Bsp;
use quake_formats::bsp::{Model, contents};
use quake_formats::geom::{Bounds, ON_EPSILON, Plane, Winding};
use std::collections::HashMap;

/// A region holding less than this (cubic units) is a sliver between planes, not a brush: the
/// compiler refuses brushes under 0.1, and the margin covers the difference between its volume
/// of the planes read back and ours. (At 0.5, forty wedges of trim a unit long went from
/// LibreQuake's lq1m1.)
const MIN_VOLUME: f64 = 0.15;

/// Half the size of the origin brush written for an entity with an origin.
const ORIGIN_BRUSH_HALF: f64 = 8.0;

/// One side of a brush as a `.map` face line gives it.
#[derive(Debug, Clone)]
pub(crate) struct MapSide {
    pub points: [DVec3; 3],
    pub texture: String,
    pub projection: Projection,
}

/// What the brushes of one model are written with.
pub(crate) struct ModelContext<'a> {
    pub bsp: &'a Bsp,
    /// The entity's origin: the model's coordinates are relative to it.
    pub origin: DVec3,
    /// The entity is a trigger: untextured sides of its brushes get `trigger`, not `skip`.
    pub trigger: bool,
    pub format: MapFormat,
    pub split: bool,
    /// For each contents value of sky and the liquids, a texture of the BSP that gives it.
    pub kind_textures: &'a KindTextures,
}

/// A texture name of the BSP for each contents value a texture can give (sky, the liquids), for
/// the untextured sides of brushes of those contents.
#[derive(Debug, Default)]
pub(crate) struct KindTextures(Vec<(i32, String)>);

impl KindTextures {
    pub fn of(bsp: &Bsp) -> KindTextures {
        let mut found: Vec<(i32, String)> = Vec::new();
        for tex in bsp.textures.textures.iter().flatten() {
            let name = tex.name();
            if let Gives::Contents(value) = gives(&name)
                && value != contents::SOLID
                && !found.iter().any(|(v, _)| *v == value)
            {
                found.push((value, name));
            }
        }
        KindTextures(found)
    }

    fn get(&self, value: i32) -> Option<&str> {
        self.0
            .iter()
            .find(|(v, _)| *v == value)
            .map(|(_, n)| n.as_str())
    }
}

/// The brushes of `model`, in map coordinates.
pub(crate) fn model_brushes(
    ctx: &ModelContext,
    model: &Model,
    stats: &mut DecompileStats,
) -> Vec<Vec<MapSide>> {
    let leaves = filled_leaves(ctx.bsp, model);
    stats.unknown_contents_leaves += leaves.unknown_contents;
    let faces = ModelFaces::new(ctx.bsp, model);
    let mut drafts = Vec::new();
    for FilledLeaf { contents, region } in leaves.filled {
        if region.volume() < MIN_VOLUME {
            stats.sliver_leaves += 1;
            continue;
        }
        let pieces = texture_region(&faces, region, ctx.split);
        stats.texture_cuts += pieces.len() - 1;
        for piece in pieces {
            match draft(ctx, &piece, contents) {
                Some(b) => drafts.push(b),
                None => stats.sliver_leaves += 1,
            }
        }
    }
    borrow_textures(&mut drafts, stats);
    drafts.into_iter().map(|d| finish(ctx, d, stats)).collect()
}

/// A brush side before its texture is settled: the plane the compiler will read from its points
/// (in the model's coordinates), and the texture of the face on it, if any.
struct DraftSide {
    points: [DVec3; 3],
    plane: Plane,
    /// The box around the side's polygon.
    bounds: Bounds,
    texture: Option<SideTexture>,
    /// The texture is another side's (see [`borrow_textures`]).
    borrowed: bool,
}

/// A texture name and its texinfo rows, in the entity's map coordinates.
#[derive(Debug, Clone)]
struct SideTexture {
    name: String,
    rows: [[f64; 4]; 2],
}

struct DraftBrush {
    contents: i32,
    sides: Vec<DraftSide>,
}

/// The brush of one textured region of `value` contents; `None` when the planes written for it
/// bound too little to be a brush.
fn draft(ctx: &ModelContext, piece: &TexturedRegion, value: i32) -> Option<DraftBrush> {
    let sides = &piece.region.sides;
    // A side whose points read back as no plane at all (not found in practice) would leave the
    // brush open: the brush goes.
    let mut written: Vec<Option<(DraftSide, f64)>> = sides
        .iter()
        .zip(&piece.faces)
        .map(|(side, face)| {
            let face_polygon = face.and_then(|f| face_winding(ctx.bsp, f));
            let mut polygons = vec![&side.winding];
            polygons.extend(face_polygon.as_ref());
            let points = three_points(&side.plane, &polygons, ctx.origin);
            let draft = DraftSide {
                points,
                plane: read_back(points, ctx.origin)?,
                bounds: side.winding.bounds(),
                texture: face.and_then(|f| texinfo_of(ctx, f.texinfo)),
                borrowed: false,
            };
            Some(Some((draft, side.winding.area())))
        })
        .collect::<Option<_>>()?;
    // Two sides read back as one plane would make the compiler refuse the brush; the smaller one
    // goes (it was within the plane epsilons of the other).
    for i in 0..written.len() {
        for j in i + 1..written.len() {
            let (Some((a, area_a)), Some((b, area_b))) = (&written[i], &written[j]) else {
                continue;
            };
            if a.plane.same_as(&b.plane.flipped()) {
                return None;
            }
            if a.plane.same_as(&b.plane) {
                let smaller = if area_a < area_b { i } else { j };
                written[smaller] = None;
            }
        }
    }
    let mut kept: Vec<Option<DraftSide>> = written
        .into_iter()
        .flatten()
        .map(|(d, _)| Some(d))
        .collect();
    let planes: Vec<Plane> = kept.iter().flatten().map(|d| d.plane).collect();
    let touching = touching_planes(&planes);
    let bounded = volume(touching.iter().map(|(i, w)| (&planes[*i], w)));
    if touching.len() < 4 || bounded < MIN_VOLUME {
        return None;
    }
    Some(DraftBrush {
        contents: value,
        sides: touching
            .iter()
            .filter_map(|&(i, _)| kept[i].take())
            .collect(),
    })
}

/// Give each side without a face of its own the texture of a textured side of a brush of the
/// same contents lying on the same plane and facing the same way: one it touches, else the
/// nearest. Such a side is hidden where it is, but a compiler that textures each leaf's face
/// from the first brush side it finds on the face's plane (Slipgate's does) may take it for a
/// visible face of the leaf: `skip` there would drop the face.
fn borrow_textures(drafts: &mut [DraftBrush], stats: &mut DecompileStats) {
    let mut textured: HashMap<PlaneKey, Vec<(Plane, Bounds, SideTexture)>> = HashMap::new();
    for b in drafts.iter() {
        for s in &b.sides {
            if let Some(texture) = &s.texture {
                textured
                    .entry(PlaneKey::of(b.contents, &s.plane, 0))
                    .or_default()
                    .push((s.plane, s.bounds, texture.clone()));
            }
        }
    }
    for b in drafts.iter_mut() {
        for s in b.sides.iter_mut().filter(|s| s.texture.is_none()) {
            // A side this one touches first (the compiler's leaf holds both), else the nearest:
            // leaves of flush brushes reach far. The planes within the epsilons of this one are
            // in its key's bucket or, where the distance sits near a bucket's edge, the next.
            let touching = |bounds: &Bounds| {
                let pad = DVec3::splat(ON_EPSILON);
                bounds.intersects(&Bounds {
                    mins: s.bounds.mins - pad,
                    maxs: s.bounds.maxs + pad,
                })
            };
            let nearest = [-1, 0, 1]
                .into_iter()
                .filter_map(|step| textured.get(&PlaneKey::of(b.contents, &s.plane, step)))
                .flatten()
                .filter(|(plane, _, _)| plane.same_as(&s.plane))
                .min_by(|x, y| {
                    let gap = |b: &Bounds| (b.center() - s.bounds.center()).length_squared();
                    touching(&y.1)
                        .cmp(&touching(&x.1))
                        .then(gap(&x.1).total_cmp(&gap(&y.1)))
                });
            if let Some((_, _, texture)) = nearest {
                s.texture = Some(texture.clone());
                s.borrowed = true;
                stats.borrowed_textures += 1;
            }
        }
    }
}

/// A bucket of planes near one another, for brushes of one contents: the normal to a
/// thousandth, the distance to a unit (`step` buckets further on).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct PlaneKey {
    contents: i32,
    normal: [i64; 3],
    dist: i64,
}

impl PlaneKey {
    fn of(contents: i32, plane: &Plane, step: i64) -> PlaneKey {
        PlaneKey {
            contents,
            normal: (plane.normal * 1000.0).round().as_i64vec3().to_array(),
            dist: plane.dist.round() as i64 + step,
        }
    }
}

/// The brush's sides as written: names, projections, and an order that gives it its contents.
fn finish(ctx: &ModelContext, brush: DraftBrush, stats: &mut DecompileStats) -> Vec<MapSide> {
    let mut out: Vec<(MapSide, bool)> = brush
        .sides
        .iter()
        .map(|d| side(ctx, d, brush.contents, stats))
        .collect();
    give_contents(ctx, &mut out, brush.contents, stats);
    for (_, textured) in &out {
        match textured {
            true => stats.textured_faces += 1,
            false => stats.untextured_faces += 1,
        }
    }
    out.into_iter().map(|(s, _)| s).collect()
}

/// The polygon of BSP face `f`.
fn face_winding(bsp: &Bsp, f: SideFace) -> Option<Winding> {
    let face = bsp.faces.get(f.face)?;
    let points = bsp.face_vertices(face)?;
    Some(Winding::new(
        points
            .iter()
            .map(|p| DVec3::from(p.map(f64::from)))
            .collect(),
    ))
}

/// The name written for a face whose texture the BSP does not hold (a slot of the texture lump
/// left empty): the name engines give the checkerboard they draw such faces with. Writing
/// `skip` instead (as ericw-tools does) would drop the face from the map.
pub(crate) const MISSING_TEXTURE: &str = "notexture";

/// A texinfo's name and rows, in the entity's map coordinates.
fn texinfo_of(ctx: &ModelContext, texinfo: u32) -> Option<SideTexture> {
    let info = ctx.bsp.texinfo.get(texinfo as usize)?;
    let name = ctx
        .bsp
        .textures
        .textures
        .get(info.miptex as usize)
        .and_then(|t| t.as_ref())
        .map(|t| t.name())
        .filter(|n| !n.is_empty())
        .unwrap_or_else(|| MISSING_TEXTURE.to_string());
    let mut rows = info.vecs.map(|r| r.map(f64::from));
    // The compiler added each axis's reach to the origin to the offset, so the texture stays
    // where the mapper put it when the engine moves the model by its origin.
    for row in &mut rows {
        row[3] -= DVec3::new(row[0], row[1], row[2]).dot(ctx.origin);
    }
    Some(SideTexture { name, rows })
}

/// One side's texture and projection, and whether it came from a face on the side.
fn side(
    ctx: &ModelContext,
    draft: &DraftSide,
    value: i32,
    stats: &mut DecompileStats,
) -> (MapSide, bool) {
    let normal = draft.plane.normal;
    let valve = ctx.format == MapFormat::Valve;
    let (texture, projection) = match &draft.texture {
        Some(t) => {
            let projection = if valve {
                to_valve(t.rows, normal)
            } else {
                // The rows are in map coordinates: so is the plane they are fitted on.
                let plane = Plane::new(normal, draft.plane.dist + normal.dot(ctx.origin));
                let (projection, exact) = to_quake(t.rows, &plane);
                stats.approximate_projections += usize::from(!exact);
                projection
            };
            stats.missing_textures += usize::from(t.name == MISSING_TEXTURE);
            (t.name.clone(), projection)
        }
        None => (
            untextured_name(ctx, value).to_string(),
            plain(normal, valve),
        ),
    };
    (
        MapSide {
            points: draft.points,
            texture,
            projection,
        },
        draft.texture.is_some() && !draft.borrowed,
    )
}

/// The texture an untextured side of a brush of `value` gets.
fn untextured_name<'a>(ctx: &'a ModelContext, value: i32) -> &'a str {
    match value {
        contents::SOLID if ctx.trigger => "trigger",
        contents::SOLID => default_name(value),
        _ => ctx
            .kind_textures
            .get(value)
            .unwrap_or_else(|| default_name(value)),
    }
}

/// Put a side whose texture gives the brush `value` contents first among the sides that give
/// any (compilers take the first), or rename the first such side when none does.
fn give_contents(
    ctx: &ModelContext,
    sides: &mut [(MapSide, bool)],
    value: i32,
    stats: &mut DecompileStats,
) {
    let giving = |s: &(MapSide, bool)| gives(&s.0.texture);
    let Some(first) = sides.iter().position(|s| giving(s) != Gives::Nothing) else {
        return;
    };
    if giving(&sides[first]) == Gives::Contents(value) {
        return;
    }
    match sides
        .iter()
        .position(|s| giving(s) == Gives::Contents(value))
    {
        Some(right) => sides.swap(first, right),
        None => {
            // Every side's texture gives other contents (a mapper's sky texture on the faces
            // of a solid brush): one loses its texture so the brush keeps its contents.
            stats.renamed_for_contents += 1;
            let (side, textured) = &mut sides[first];
            side.texture = untextured_name(ctx, value).to_string();
            *textured = false;
        }
    }
}

/// The origin brush of an entity at `origin`: what Quake compilers that know origin brushes
/// build the entity's model around.
pub(crate) fn origin_brush(origin: DVec3, format: MapFormat) -> Vec<MapSide> {
    let half = DVec3::splat(ORIGIN_BRUSH_HALF);
    let Some(region) = Region::from_bounds(&Bounds {
        mins: origin - half,
        maxs: origin + half,
    }) else {
        return Vec::new();
    };
    region
        .sides
        .iter()
        .map(|s| MapSide {
            points: three_points(&s.plane, &[&s.winding], DVec3::ZERO),
            texture: "origin".to_string(),
            projection: plain(s.plane.normal, format == MapFormat::Valve),
        })
        .collect()
}
