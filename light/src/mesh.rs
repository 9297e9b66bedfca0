//! Faces fan-triangulated into the buffers Embree takes: the opaque, sky and per-model scenes
//! ([`crate::scene`]) and the fence scene ([`crate::fence`]) are each built from one.

use glam::DVec3;

use crate::embree::{Device, Scene, SceneBuilder};
use crate::error::LightError;
use crate::faces::FaceGeom;

/// Fan-triangulated faces as Embree buffers.
#[derive(Default)]
pub(crate) struct Mesh {
    pub(crate) vertices: Vec<[f32; 3]>,
    pub(crate) triangles: Vec<[u32; 3]>,
    /// The face each triangle comes from.
    pub(crate) faces: Vec<u32>,
}

impl Mesh {
    /// An empty mesh with room for `faces` without growing: its buffers are the largest the
    /// light tool builds, and each growth of one is a copy into fresh pages.
    pub(crate) fn with_room_for<'a>(faces: impl Iterator<Item = &'a FaceGeom>) -> Mesh {
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

    /// A scene of this mesh alone.
    pub(crate) fn commit(&self, device: &Device) -> Result<Scene, LightError> {
        let mut builder = SceneBuilder::new(device)?;
        builder.add_triangle_mesh(&self.vertices, &self.triangles)?;
        Ok(builder.commit()?)
    }

    pub(crate) fn add(&mut self, face: &FaceGeom) {
        self.add_polygon(&face.points, face.index as u32);
    }

    /// A convex polygon, fan-triangulated, its triangles marked as `face`'s.
    pub(crate) fn add_polygon(&mut self, points: &[DVec3], face: u32) {
        let base = self.vertices.len() as u32;
        self.vertices
            .extend(points.iter().map(|p| p.as_vec3().to_array()));
        for i in 1..(points.len() as u32).saturating_sub(1) {
            self.triangles.push([base, base + i, base + i + 1]);
            self.faces.push(face);
        }
    }
}
