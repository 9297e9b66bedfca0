//! The Embree scene rays are traced against: every opaque face of the world
//! and of shadow-casting brush models, plus the sky faces as a separate
//! geometry so a ray can tell "reached the sky" from "hit a wall".

use crate::LightError;
use crate::embree::{Device, RayPacket16, Scene, SceneBuilder, sys};
use crate::faces::{FaceGeom, FaceKind};

/// A committed scene and the geometry id of its sky faces.
pub struct TraceScene {
    pub scene: Scene,
    sky_geom: u32,
    /// Triangles in the scene (opaque + sky).
    pub triangles: usize,
}

/// Fan-triangulated faces as Embree buffers.
#[derive(Default)]
struct Mesh {
    vertices: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Mesh {
    fn add(&mut self, face: &FaceGeom) {
        let base = self.vertices.len() as u32;
        self.vertices.extend(face.points.iter().map(|p| p.to_f32()));
        for i in 1..face.points.len() as u32 - 1 {
            self.triangles.push([base, base + i, base + i + 1]);
        }
    }
}

impl TraceScene {
    /// Builds the scene from `faces`: world faces, and faces of the brush
    /// models in `shadow_models`. Liquids are left out (they let light through).
    ///
    /// # Errors
    /// The Embree error if building fails.
    pub fn build(
        device: &Device,
        faces: &[FaceGeom],
        shadow_models: &[usize],
    ) -> Result<TraceScene, LightError> {
        let mut opaque = Mesh::default();
        let mut sky = Mesh::default();
        for f in faces {
            let casts = f.model == 0 || shadow_models.contains(&f.model);
            match f.kind {
                FaceKind::Lit if casts => opaque.add(f),
                FaceKind::Sky if f.model == 0 => sky.add(f),
                _ => {}
            }
        }
        let mut builder = SceneBuilder::new(device)?;
        builder.add_triangle_mesh(&opaque.vertices, &opaque.triangles)?;
        let sky_geom = builder.add_triangle_mesh(&sky.vertices, &sky.triangles)?;
        Ok(TraceScene {
            scene: builder.commit()?,
            sky_geom,
            triangles: opaque.triangles.len() + sky.triangles.len(),
        })
    }

    /// Bit `i` set if lane `i` of `packet` is blocked (sky blocks too).
    pub fn occluded16(&self, packet: &mut RayPacket16) -> u16 {
        self.scene.occluded16(packet, true)
    }

    /// Bit `i` set if lane `i` of `packet` reaches a sky face before anything else.
    pub fn sees_sky16(&self, packet: &mut RayPacket16) -> u16 {
        let ids = self.scene.first_hit_geom16(packet, true);
        (0..16)
            .filter(|&i| ids[i] == self.sky_geom && ids[i] != sys::RTC_INVALID_GEOMETRY_ID)
            .fold(0, |m, i| m | (1 << i))
    }

    /// For each active lane of `packet`, the distance to the first surface
    /// if that is an opaque one (not sky).
    pub fn opaque_hits16(&self, packet: &mut RayPacket16) -> [Option<f32>; 16] {
        let ids = self.scene.first_hit_geom16(packet, true);
        let mut out = [None; 16];
        for (lane, id) in ids.iter().enumerate() {
            if *id != self.sky_geom && *id != sys::RTC_INVALID_GEOMETRY_ID {
                out[lane] = Some(packet.tfar(lane));
            }
        }
        out
    }

    /// Distance along unit `dir` from `org` to the first surface, if any within `max`.
    pub fn hit_distance(&self, org: [f32; 3], dir: [f32; 3], max: f32) -> Option<f32> {
        self.scene.intersect(org, dir, 0.0, max).map(|h| h.t)
    }
}
