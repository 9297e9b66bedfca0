//! The Embree scene rays are traced against: every opaque face of the world
//! and of shadow-casting brush models, plus the sky faces as a separate
//! geometry so a ray can tell "reached the sky" from "hit a wall".
//! A `_shadowself` model gets a small scene of its own, which only rays
//! from that model's faces are tested against.

use std::collections::HashMap;

use glam::DVec3;

use crate::embree::{Device, RayPacket16, Scene, SceneBuilder, sys};
use crate::error::LightError;
use crate::faces::{FaceGeom, FaceKind};

/// The face of a triangle that blocks light but is no face of the BSP (a faceless model's
/// solid, see [`crate::hull`]).
const NO_FACE: u32 = u32::MAX;

/// Sun rays are tested for blockers up to this fraction of their distance to the sky.
const SKY_HIT_SHORTEN: f32 = 1.0 - 1e-5;

/// A committed scene and the geometry id of its sky faces.
pub struct TraceScene {
    pub scene: Scene,
    sky_geom: u32,
    /// The sky faces alone, to find where a sun ray meets the sky first.
    sky_only: Option<Scene>,
    /// The face of each opaque triangle (by primitive id).
    opaque_faces: Vec<u32>,
    /// Per `_shadowself` model (not already in `scene`): its own faces.
    own: HashMap<usize, Scene>,
    /// Triangles in the scene (opaque + sky) and the `_shadowself` scenes.
    pub triangles: usize,
}

/// Fan-triangulated faces as Embree buffers.
#[derive(Default)]
struct Mesh {
    vertices: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    /// The face each triangle comes from.
    faces: Vec<u32>,
}

impl Mesh {
    /// An empty mesh with room for `faces` without growing: its buffers are the largest the
    /// light tool builds, and each growth of one is a copy into fresh pages.
    fn with_room_for<'a>(faces: impl Iterator<Item = &'a FaceGeom>) -> Mesh {
        let (mut vertices, mut triangles) = (0, 0);
        for f in faces {
            vertices += f.points.len();
            triangles += f.points.len().saturating_sub(2);
        }
        Mesh {
            vertices: Vec::with_capacity(vertices),
            triangles: Vec::with_capacity(triangles),
            faces: Vec::with_capacity(triangles),
        }
    }

    fn add(&mut self, face: &FaceGeom) {
        self.add_polygon(&face.points, face.index as u32);
    }

    /// A convex polygon, fan-triangulated, its triangles marked as `face`'s.
    fn add_polygon(&mut self, points: &[DVec3], face: u32) {
        let base = self.vertices.len() as u32;
        self.vertices
            .extend(points.iter().map(|p| p.as_vec3().to_array()));
        for i in 1..(points.len() as u32).saturating_sub(1) {
            self.triangles.push([base, base + i, base + i + 1]);
            self.faces.push(face);
        }
    }
}

impl TraceScene {
    /// Builds the scene from `faces`: world faces (but those `shadowless` marks, by face
    /// index; it may be empty), and faces of the brush
    /// models in `shadow_models`, and the polygons `solids` (world space: the
    /// solid of shadow-casting models without faces); each model in
    /// `self_shadow_models` that is not also in `shadow_models` gets a scene of
    /// its own faces. Liquids are left out (they let light through).
    ///
    /// # Errors
    /// The Embree error if building fails.
    pub fn build(
        device: &Device,
        faces: &[FaceGeom],
        shadowless: &[bool],
        shadow_models: &[usize],
        self_shadow_models: &[usize],
        solids: &[Vec<DVec3>],
    ) -> Result<TraceScene, LightError> {
        let casts = |f: &FaceGeom| {
            let world = f.model == 0 && !shadowless.get(f.index).copied().unwrap_or(false);
            world || shadow_models.contains(&f.model)
        };
        let mut opaque =
            Mesh::with_room_for(faces.iter().filter(|f| f.kind == FaceKind::Lit && casts(f)));
        let mut sky = Mesh::default();
        let mut own_meshes: HashMap<usize, Mesh> = HashMap::new();
        for f in faces {
            match f.kind {
                FaceKind::Lit if casts(f) => opaque.add(f),
                FaceKind::Lit if self_shadow_models.contains(&f.model) => {
                    own_meshes.entry(f.model).or_default().add(f);
                }
                FaceKind::Sky if f.model == 0 => sky.add(f),
                _ => {}
            }
        }
        for polygon in solids {
            opaque.add_polygon(polygon, NO_FACE);
        }
        let mut triangles = opaque.triangles.len() + sky.triangles.len();
        let mut own = HashMap::with_capacity(own_meshes.len());
        for (model, mesh) in own_meshes {
            let mut builder = SceneBuilder::new(device)?;
            builder.add_triangle_mesh(&mesh.vertices, &mesh.triangles)?;
            triangles += mesh.triangles.len();
            own.insert(model, builder.commit()?);
        }
        let sky_only = if sky.triangles.is_empty() {
            None
        } else {
            let mut builder = SceneBuilder::new(device)?;
            builder.add_triangle_mesh(&sky.vertices, &sky.triangles)?;
            Some(builder.commit()?)
        };
        let mut builder = SceneBuilder::new(device)?;
        builder.add_triangle_mesh(&opaque.vertices, &opaque.triangles)?;
        let sky_geom = builder.add_triangle_mesh(&sky.vertices, &sky.triangles)?;
        Ok(TraceScene {
            scene: builder.commit()?,
            sky_geom,
            sky_only,
            opaque_faces: opaque.faces,
            own,
            triangles,
        })
    }

    /// Bit `i` set if lane `i` of `packet`, cast from a face of brush model
    /// `model`, is blocked (sky blocks too).
    pub fn occluded16(&self, packet: &mut RayPacket16, model: usize) -> u16 {
        let blocked = self.scene.occluded16(packet, true);
        // Embree sets tfar of blocked lanes to -inf, so the second query skips them.
        blocked | self.own_occluded16(packet, model)
    }

    /// Lanes of `packet` (each up to its current `tfar`) that `model`'s own
    /// scene blocks; 0 for a model without one.
    fn own_occluded16(&self, packet: &mut RayPacket16, model: usize) -> u16 {
        self.own
            .get(&model)
            .map_or(0, |own| own.occluded16(packet, true))
    }

    /// Bit `i` set if lane `i` of `packet`, cast from a face of `model`,
    /// reaches a sky face before anything else.
    /// First where each ray meets the sky (sky faces alone, a small scene),
    /// then whether anything blocks it before that: an occlusion query,
    /// which stops at any hit, where one closest-hit query over everything
    /// must rule out every nearer surface.
    pub fn sees_sky16(&self, packet: &mut RayPacket16, model: usize) -> u16 {
        let Some(sky_only) = &self.sky_only else {
            return 0;
        };
        let ids = sky_only.first_hit_geom16(packet, true);
        let sky = (0..16)
            .filter(|&i| ids[i] != sys::RTC_INVALID_GEOMETRY_ID)
            .fold(0, |m, i| m | (1 << i));
        // Just short of the sky hit, so the sky face itself does not block.
        packet.keep_shortened(sky, SKY_HIT_SHORTEN);
        let blocked = self.scene.occluded16(packet, true);
        sky & !blocked & !self.own_occluded16(packet, model)
    }

    /// For each active lane of `packet`, cast from a face of `model`, the
    /// opaque face it meets first and the distance to it (`None`: it meets
    /// nothing, the sky, or `model`'s own `_shadowself` scene first).
    pub fn first_faces16(
        &self,
        packet: &mut RayPacket16,
        model: usize,
    ) -> [Option<(usize, f32)>; 16] {
        let hits = self.scene.first_hits16(packet, false);
        let mut out = [None; 16];
        for (lane, (geom, prim)) in hits.iter().enumerate() {
            if *geom != self.sky_geom && *geom != sys::RTC_INVALID_GEOMETRY_ID {
                out[lane] = self
                    .opaque_faces
                    .get(*prim as usize)
                    .filter(|&&f| f != NO_FACE)
                    .map(|&f| (f as usize, packet.tfar(lane)));
            }
        }
        let own = self.own_occluded16(packet, model);
        for (lane, hit) in out.iter_mut().enumerate() {
            if own & (1 << lane) != 0 {
                *hit = None;
            }
        }
        out
    }

    /// For each active lane of `packet`, cast from a face of `model`, the
    /// distance to the first surface if that is an opaque one (not sky).
    pub fn opaque_hits16(&self, packet: &mut RayPacket16, model: usize) -> [Option<f32>; 16] {
        let ids = self.scene.first_hit_geom16(packet, true);
        let mut out = [None; 16];
        for (lane, id) in ids.iter().enumerate() {
            if *id != self.sky_geom && *id != sys::RTC_INVALID_GEOMETRY_ID {
                out[lane] = Some(packet.tfar(lane));
            }
        }
        if let Some(own) = self.own.get(&model) {
            // tfar ends at the world hit, so any hit here is nearer.
            let own_ids = own.first_hit_geom16(packet, true);
            for (lane, id) in own_ids.iter().enumerate() {
                if *id != sys::RTC_INVALID_GEOMETRY_ID {
                    out[lane] = Some(packet.tfar(lane));
                }
            }
        }
        out
    }
}
