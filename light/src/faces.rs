//! The faces of a BSP as geometry the light tool works with: world-space
//! polygon, facing plane, texture projection and lightmap extents.

use std::sync::Arc;

use glam::{DVec3, Vec3};
use quake_formats::Bsp;
use quake_formats::bsp::texinfo_flags;
use quake_formats::extents::{LightmapExtents, LuxelGrid};
use quake_formats::geom::Plane;
use quake_formats::int_hash::IntMap;
use rayon::prelude::*;

use crate::error::LightError;
use crate::outline::{Edges, FaceRegion};

/// What a face is for lighting and shadowing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaceKind {
    /// Has a lightmap and blocks light.
    Lit,
    /// Sky: no lightmap; blocks lights, and sun rays that reach it see the sky.
    Sky,
    /// Water, slime, lava, teleporters (`*` textures) written `TEX_SPECIAL`: no lightmap, and
    /// transparent to light (Quake's own light tool let light through them).
    Liquid,
    /// A liquid the compiler left without `TEX_SPECIAL` (lit water): it has a lightmap, and
    /// is transparent to light like any liquid.
    LitLiquid,
}

impl FaceKind {
    /// Whether light writes a lightmap for faces of this kind.
    pub fn has_lightmap(self) -> bool {
        matches!(self, FaceKind::Lit | FaceKind::LitLiquid)
    }
}

/// One face, ready for sampling.
#[derive(Debug, Clone)]
pub struct FaceGeom {
    pub index: usize,
    /// The brush model it belongs to (0 = world).
    pub model: usize,
    pub kind: FaceKind,
    pub texture: String,
    /// Vertices in world space (the model's `origin` offset applied).
    pub points: Vec<DVec3>,
    /// The plane the face looks out of (the BSP plane flipped for back-side faces), world space.
    pub plane: Plane,
    /// Texture projection `s = vecs[0].xyz · p + vecs[0].w` in model space.
    pub vecs: [[f32; 4]; 2],
    /// Offset from model space to world space.
    pub origin: DVec3,
    pub extents: LightmapExtents,
    /// The lit faces of the same model on the same plane reached from this one across at most
    /// [`CONTINUATION_HOPS`] shared edges: where a luxel past this face's edge finds the surface
    /// it stands over.
    pub continuations: Arc<Continuations>,
    /// Its own outline, as its continuations share it (lit faces, once
    /// [`attach_continuations`] has filled it in).
    pub outline: Option<Arc<FaceRegion>>,
    /// The grid light samples the face on: Quake's 16-texel one over `extents`, or its own.
    pub grid: LuxelGrid,
    /// What its own grid is, when it has one; the lightmap over `extents` is then taken from
    /// that grid.
    pub own_grid: Option<OwnGrid>,
}

impl FaceGeom {
    /// Whether light writes a lightmap for the face: of a kind that has one, and not textured
    /// `trigger` or `skip` (faces of brush models engines never draw, which ericw-tools gives
    /// none either).
    pub fn has_lightmap(&self) -> bool {
        self.kind.has_lightmap()
            && !["trigger", "skip"]
                .iter()
                .any(|t| self.texture.eq_ignore_ascii_case(t))
    }

    /// The face's outline, for telling where on it a point of its plane lies.
    pub fn region(&self) -> FaceRegion {
        FaceRegion::from_points(self.points.clone(), self.plane.normal)
    }

    /// [`FaceGeom::region`], the one [`FaceGeom::outline`] shares when it is there.
    pub fn shared_region(&self) -> Arc<FaceRegion> {
        self.outline
            .clone()
            .unwrap_or_else(|| Arc::new(self.region()))
    }
}

/// The spacing a brush model's faces are lit at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spacing {
    /// Quake's 16 texels.
    Quake,
    /// A world-aligned grid, one luxel every so many map units (`DECOUPLED_LM`).
    WorldUnits(f64),
    /// One luxel every `1 << shift` texels of the face's texture projection (`LMSHIFT`).
    Shift(u8),
}

/// A face's own grid, as the BSP describes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OwnGrid {
    /// World-aligned: the model-space-to-luxel projection of its `DECOUPLED_LM` record.
    Decoupled([[f32; 4]; 2]),
    /// On the texture projection, one luxel every `1 << shift` texels (its `LMSHIFT`).
    Shifted(u8),
}

impl OwnGrid {
    /// The grid `spacing` gives a face with `points` (model space), texture projection `vecs`
    /// and outward `normal`; `None` for Quake's, or a spacing the face cannot take (a grid
    /// past the lump's sizes).
    fn of(
        spacing: Spacing,
        points: &[[f32; 3]],
        vecs: &[[f32; 4]; 2],
        normal: DVec3,
    ) -> Option<(OwnGrid, LuxelGrid)> {
        match spacing {
            // Shift 4 is Quake's 16 texels.
            Spacing::Quake | Spacing::Shift(4) => None,
            Spacing::WorldUnits(units) => {
                let (rows, grid) = LuxelGrid::world_aligned(points, normal.to_array(), units)?;
                Some((OwnGrid::Decoupled(rows), grid))
            }
            Spacing::Shift(shift) => Some((
                OwnGrid::Shifted(shift),
                LuxelGrid::shifted(points, vecs, shift)?,
            )),
        }
    }
}

impl FaceGeom {
    /// A lit face of model `model` with outline `points` on `plane`, without texture axes or
    /// neighbours, for tests.
    #[cfg(test)]
    pub fn for_test(
        index: usize,
        model: usize,
        points: Vec<DVec3>,
        plane: quake_formats::geom::Plane,
    ) -> FaceGeom {
        use quake_formats::extents::{LightmapExtents, LuxelGrid};
        let extents = LightmapExtents::from_points(&[], &[[0.0; 4]; 2]);
        FaceGeom {
            index,
            model,
            kind: FaceKind::Lit,
            texture: String::new(),
            points,
            plane,
            vecs: [[0.0; 4]; 2],
            origin: DVec3::ZERO,
            extents,
            continuations: Arc::default(),
            outline: None,
            grid: LuxelGrid::vanilla(&extents, &[[0.0; 4]; 2]),
            own_grid: None,
        }
    }

    /// Whether its texture is a fence's (a `{` name: its transparent texels let light through).
    pub fn is_fence(&self) -> bool {
        self.texture.starts_with('{')
    }

    /// The mean of the vertices (inside the face: faces are convex).
    pub fn centroid(&self) -> DVec3 {
        quake_formats::geom::polygon_center(&self.points)
    }
}

/// [`unlinked_face_geometry`] with each face's continuations attached.
///
/// # Errors
/// [`LightError::BadFace`] for a face whose indices run outside the file.
#[cfg(test)]
pub fn face_geometry(
    bsp: &Bsp,
    origin_of: impl Fn(usize) -> DVec3 + Sync,
    spacing_of: impl Fn(usize) -> Spacing + Sync,
) -> Result<Vec<FaceGeom>, LightError> {
    let mut faces = unlinked_face_geometry(bsp, origin_of, spacing_of)?;
    let links = continuations(&faces, |_, _| false);
    attach_continuations(&mut faces, links);
    Ok(faces)
}

/// Every face of `bsp` with its model; `origin_of` gives per-model offsets, `spacing_of` the
/// spacing a model's faces are lit at. Their [`FaceGeom::continuations`] are left empty:
/// [`continuations`] finds them and [`attach_continuations`] fills them in, while the faces
/// serve what needs none (the shadow scene is built meanwhile).
///
/// # Errors
/// [`LightError::BadFace`] for a face whose indices run outside the file.
pub fn unlinked_face_geometry(
    bsp: &Bsp,
    origin_of: impl Fn(usize) -> DVec3 + Sync,
    spacing_of: impl Fn(usize) -> Spacing + Sync,
) -> Result<Vec<FaceGeom>, LightError> {
    let mut model_of = vec![0usize; bsp.faces.len()];
    for (m, model) in bsp.models.iter().enumerate() {
        let first = model.first_face as usize;
        let end = (first + model.num_faces as usize).min(bsp.faces.len());
        for slot in model_of.get_mut(first..end).into_iter().flatten() {
            *slot = m;
        }
    }
    let faces: Vec<Result<FaceGeom, LightError>> = bsp
        .faces
        .par_iter()
        .enumerate()
        .map(|(index, face)| {
            let bad = |detail: &str| LightError::BadFace {
                index,
                detail: detail.to_string(),
            };
            let verts = bsp
                .face_vertices(face)
                .filter(|v| v.len() >= 3)
                .ok_or_else(|| bad("edge or vertex index out of range, or fewer than 3 edges"))?;
            let ti = bsp
                .texinfo
                .get(face.texinfo as usize)
                .ok_or_else(|| bad("texinfo index out of range"))?;
            let bp = bsp
                .planes
                .get(face.plane as usize)
                .ok_or_else(|| bad("plane index out of range"))?;
            let texture = bsp
                .textures
                .textures
                .get(ti.miptex as usize)
                .and_then(Option::as_ref)
                .map(quake_formats::miptex::MipTex::name)
                .unwrap_or_default();
            let lower = texture.to_ascii_lowercase();
            let special = ti.flags & texinfo_flags::SPECIAL != 0;
            let kind = match (special, lower.starts_with('*')) {
                (false, false) => FaceKind::Lit,
                (false, true) => FaceKind::LitLiquid,
                (true, _) if lower.starts_with("sky") => FaceKind::Sky,
                (true, _) => FaceKind::Liquid,
            };
            let model = model_of[index];
            let origin = origin_of(model);
            let mut plane = Plane::new(Vec3::from(bp.normal).as_dvec3(), f64::from(bp.dist));
            if face.side != 0 {
                plane = plane.flipped();
            }
            plane.dist += plane.normal.dot(origin);
            let extents = LightmapExtents::from_points(&verts, &ti.vecs);
            let own = OwnGrid::of(spacing_of(model), &verts, &ti.vecs, plane.normal);
            Ok(FaceGeom {
                index,
                model,
                kind,
                texture,
                points: verts
                    .iter()
                    .map(|&v| Vec3::from(v).as_dvec3() + origin)
                    .collect(),
                plane,
                vecs: ti.vecs,
                origin,
                extents,
                continuations: Arc::default(),
                outline: None,
                grid: own.map_or_else(|| LuxelGrid::vanilla(&extents, &ti.vecs), |(_, g)| g),
                own_grid: own.map(|(kind, _)| kind),
            })
        })
        .collect();
    // The first bad face in file order, whichever thread found it.
    faces.into_iter().collect::<Result<Vec<_>, _>>()
}

/// Corners closer than this (units) are the same corner.
const SAME_CORNER: f64 = 0.01;

/// An edge by its two corners' numbers (corners on the [`SAME_CORNER`] grid, numbered as first
/// met), the lesser in the high half.
type EdgeKey = u64;

/// Two faces whose unit normals' dot product is within this of 1 face the same way (with their
/// distances within [`SAME_CORNER`], they lie on one plane).
const SAME_NORMAL: f64 = 1e-6;

/// Whether two planes are one, facing the same way, as far as faces continuing each other go.
pub fn one_plane(a: &Plane, b: &Plane) -> bool {
    a.normal.dot(b.normal) > 1.0 - SAME_NORMAL && (a.dist - b.dist).abs() < SAME_CORNER
}

/// How many shared edges a sample past a face's edge may cross to the faces continuing it on
/// its plane (ericw-tools follows a point across at most three).
pub const CONTINUATION_HOPS: usize = 3;

/// The faces a sample point past a face's edge may walk onto: the face itself (first) and the
/// lit faces of its model on its plane within [`CONTINUATION_HOPS`] shared edges of it, each as
/// its outline and, edge by edge, which of them lies across that edge. A point walks as
/// ericw-tools walks it: across the edge [`FaceRegion::edge_to_cross`] picks, onto the face
/// there, at most [`CONTINUATION_HOPS`] times.
#[derive(Debug, Clone, Default)]
pub struct Continuations {
    /// The face, then the faces it may walk onto in face order: region `k` is face `faces[k]`.
    faces: Vec<u32>,
    /// The outlines of regions whose shared one is seen from a plane whose normal differs in
    /// its last bits from this face's (an outline's inward normals come from its plane).
    own_outlines: Vec<(u32, Arc<FaceRegion>)>,
    /// Whether some region is smoothed with the face (`_phong`) or on another plane.
    smoothed: bool,
    /// What every face's regions look up.
    shared: Arc<SharedRegions>,
}

/// Per face, what the faces continuing it share: its outline (lit faces), its plane and the
/// face across each of its edges, of its model on its plane or smoothed with it.
#[derive(Debug, Default)]
struct SharedRegions {
    outlines: Vec<Option<Arc<FaceRegion>>>,
    planes: Vec<Plane>,
    /// Face `f`'s edges are `across[first_edge[f]..first_edge[f + 1]]`.
    across: Vec<Option<u32>>,
    first_edge: Vec<usize>,
}

impl Continuations {
    /// How many faces continue the face (itself not counted).
    pub fn len(&self) -> usize {
        self.faces.len().saturating_sub(1)
    }

    /// Whether no face continues the face.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Region `k`'s outline (0: the face's own).
    pub fn region(&self, k: usize) -> Option<&FaceRegion> {
        if let Some((_, own)) = self.own_outlines.iter().find(|(at, _)| *at as usize == k) {
            return Some(own);
        }
        let face = *self.faces.get(k)? as usize;
        self.shared.outlines.get(face)?.as_deref()
    }

    /// Whether a point may walk onto a face smoothed with this one (`_phong`): it then stands
    /// on that face, maybe on another plane, and takes its normal.
    pub fn smoothed(&self) -> bool {
        self.smoothed
    }

    /// Region `k`'s face and the plane it looks out of.
    pub fn face(&self, k: usize) -> Option<(usize, &Plane)> {
        let face = *self.faces.get(k)? as usize;
        Some((face, self.shared.planes.get(face)?))
    }

    /// The region a point `p` past region `k` (on its plane) walks onto: the one across the
    /// edge [`FaceRegion::edge_to_cross`] picks, if any.
    pub fn next(&self, k: usize, p: DVec3) -> Option<usize> {
        if self.is_empty() {
            return None;
        }
        self.across(k, self.region(k)?.edge_to_cross(p, Edges::All)?)
    }

    /// The region across edge `edge` of region `k`, if any.
    pub fn across(&self, k: usize, edge: usize) -> Option<usize> {
        let face = *self.faces.get(k)? as usize;
        let shared = &*self.shared;
        let edges = *shared.first_edge.get(face)?..*shared.first_edge.get(face + 1)?;
        let next = shared.across.get(edges)?.get(edge).copied().flatten()?;
        self.region_of(next)
    }

    /// Face `face`'s place among the regions, if it is one.
    fn region_of(&self, face: u32) -> Option<usize> {
        let (&own, others) = self.faces.split_first()?;
        if face == own {
            return Some(0);
        }
        others.binary_search(&face).ok().map(|i| i + 1)
    }
}

/// What [`continuations`] finds: per face, its continuations and its own outline (lit faces
/// only), made once and shared by the faces it continues.
pub struct Links {
    continuations: Vec<Arc<Continuations>>,
    outlines: Vec<Option<Arc<FaceRegion>>>,
}

/// Each lit face's [`FaceGeom::continuations`]: the lit faces reached across at most
/// [`CONTINUATION_HOPS`] shared edges, each of its predecessor's model and plane or `smooths`
/// with it (`_phong`).
pub fn continuations(
    faces: &[FaceGeom],
    smooths: impl Fn(&FaceGeom, &FaceGeom) -> bool + Sync,
) -> Links {
    let key = |p: DVec3| (p / SAME_CORNER).round().as_i64vec3().to_array();
    let lit = |f: &&FaceGeom| f.kind == FaceKind::Lit;
    // Every lit face's edges, sorted by edge: one allocation of the exact size (fresh memory
    // costs more than the keys do to compute). Corners are numbered first, so the sort moves
    // small records and compares one word.
    let edges = faces.iter().filter(lit).map(|f| f.points.len()).sum();
    let mut number: IntMap<[i64; 3], u32> =
        IntMap::with_capacity_and_hasher(edges, Default::default());
    let mut by_edge: Vec<(EdgeKey, u32, u32)> = Vec::with_capacity(edges);
    let mut corners: Vec<u32> = Vec::new();
    for f in faces.iter().filter(lit) {
        corners.clear();
        for &p in &f.points {
            let next = number.len() as u32;
            corners.push(*number.entry(key(p)).or_insert(next));
        }
        for (i, &a) in corners.iter().enumerate() {
            let b = corners[(i + 1) % corners.len()];
            let edge = u64::from(a.min(b)) << 32 | u64::from(a.max(b));
            by_edge.push((edge, f.index as u32, i as u32));
        }
    }
    drop(number);
    by_edge.sort_unstable();
    let same_plane =
        |a: &FaceGeom, b: &FaceGeom| a.model == b.model && one_plane(&a.plane, &b.plane);
    // The faces under one edge are a run of `by_edge`: each is beside the others on its plane,
    // and the first of them (in face order, as ericw-tools finds it) lies across the edge.
    let mut first_edge = Vec::with_capacity(faces.len() + 1);
    first_edge.push(0);
    for f in faces {
        first_edge.push(first_edge.last().copied().unwrap_or(0) + f.points.len());
    }
    let mut across: Vec<Option<u32>> = vec![None; first_edge.last().copied().unwrap_or(0)];
    // As (face, neighbour) pairs, sorted: each face's neighbours are a run of them.
    let mut beside: Vec<(u32, u32)> = Vec::new();
    for run in by_edge.chunk_by(|a, b| a.0 == b.0) {
        for &(_, f, edge) in run {
            let f = f as usize;
            for &(_, g, _) in run {
                let g = g as usize;
                if g != f && (same_plane(&faces[f], &faces[g]) || smooths(&faces[f], &faces[g])) {
                    beside.push((f as u32, g as u32));
                    across[first_edge[f] + edge as usize].get_or_insert(g as u32);
                }
            }
        }
    }
    drop(by_edge);
    beside.sort_unstable();
    beside.dedup();
    // Where each face's run of neighbours starts in `beside` (one past the last face: its end).
    let mut starts = vec![0usize; faces.len() + 1];
    for &(f, _) in &beside {
        starts[f as usize + 1] += 1;
    }
    for f in 0..faces.len() {
        starts[f + 1] += starts[f];
    }
    let neighbours = |f: usize| {
        beside[starts[f]..starts[f + 1]]
            .iter()
            .map(|&(_, g)| g as usize)
    };
    // Each lit face's outline, made once: the faces it continues share it.
    let outlines: Vec<Option<Arc<FaceRegion>>> = faces
        .par_iter()
        .map(|f| (f.kind == FaceKind::Lit).then(|| Arc::new(f.region())))
        .collect();
    let shared = Arc::new(SharedRegions {
        outlines,
        planes: faces.iter().map(|f| f.plane).collect(),
        across,
        first_edge,
    });
    let continuations = (0..faces.len())
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new(), Vec::new()),
            |(reached, ring, next): &mut (Vec<usize>, Vec<usize>, Vec<usize>), f| {
                if shared.outlines[f].is_none() {
                    return Arc::default();
                }
                reached.clear();
                ring.clear();
                ring.push(f);
                for _ in 0..CONTINUATION_HOPS {
                    next.clear();
                    next.extend(ring.iter().flat_map(|&g| neighbours(g)));
                    next.sort_unstable();
                    next.dedup();
                    next.retain(|&g| g != f && !reached.contains(&g));
                    reached.extend_from_slice(next);
                    std::mem::swap(ring, next);
                }
                reached.retain(|&g| shared.outlines[g].is_some());
                reached.sort_unstable();
                // An outline's inward normals come from the plane it is seen on: a continuation
                // on the face's plane whose normal differs in its last bits gets an outline of
                // its own; one on another plane (a smoothed neighbour) keeps its own.
                let normal = faces[f].plane.normal;
                let own_outlines = (reached.iter().enumerate())
                    .filter(|&(_, &g)| {
                        faces[g].plane.normal != normal && same_plane(&faces[f], &faces[g])
                    })
                    .map(|(i, &g)| {
                        let seen = FaceRegion::from_points(faces[g].points.clone(), normal);
                        (i as u32 + 1, Arc::new(seen))
                    })
                    .collect();
                let smoothed = reached
                    .iter()
                    .any(|&g| smooths(&faces[f], &faces[g]) || !same_plane(&faces[f], &faces[g]));
                Arc::new(Continuations {
                    faces: std::iter::once(f)
                        .chain(reached.iter().copied())
                        .map(|g| g as u32)
                        .collect(),
                    own_outlines,
                    smoothed,
                    shared: shared.clone(),
                })
            },
        )
        .collect();
    Links {
        continuations,
        outlines: shared.outlines.clone(),
    }
}

/// Fills each face's [`FaceGeom::continuations`] and [`FaceGeom::outline`] with what
/// [`continuations`] found for it.
pub fn attach_continuations(faces: &mut [FaceGeom], links: Links) {
    let each = links.continuations.into_iter().zip(links.outlines);
    for (face, (continuations, outline)) in faces.iter_mut().zip(each) {
        face.continuations = continuations;
        face.outline = outline;
    }
}
