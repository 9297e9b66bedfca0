//! Faces fan-triangulated into the buffers Embree takes: the opaque, sky and per-model scenes
//! ([`crate::scene`]) and the fence scene ([`crate::fence`]) are each built from one.

use std::collections::HashSet;

use glam::DVec3;
use quake_formats::geom::ON_EPSILON;

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

    /// `faces` (each with the number its triangles are marked with) with their outlines
    /// thinned: a point on a straight run of a face's outline is left out unless it is a corner
    /// of another of `faces`. Such points were put there for faces outside the mesh (a wall
    /// standing on a sky face's edge) and cut the fan into long slivers whose boxes overlap,
    /// which slows every ray through the mesh; the edges the faces share keep the same points
    /// on both sides, so the mesh stays sealed.
    pub(crate) fn thinned(faces: &[(&FaceGeom, u32)]) -> Mesh {
        let key = |p: &DVec3| p.as_vec3().to_array().map(f32::to_bits);
        // Per face, which of its points are its corners: asked once, used twice.
        let own: Vec<Vec<bool>> = faces
            .iter()
            .map(|(f, _)| {
                (0..f.points.len())
                    .map(|i| is_corner(&f.points, i))
                    .collect()
            })
            .collect();
        let corners: HashSet<[u32; 3]> = faces
            .iter()
            .zip(&own)
            .flat_map(|((f, _), own)| f.points.iter().zip(own).filter(|(_, c)| **c))
            .map(|(p, _)| key(p))
            .collect();
        let mut mesh = Mesh::with_room_for(faces.iter().map(|&(f, _)| f));
        let mut kept = Vec::new();
        for (&(f, id), own) in faces.iter().zip(&own) {
            kept.clear();
            kept.extend(
                f.points
                    .iter()
                    .zip(own)
                    .filter(|&(p, &corner)| corner || corners.contains(&key(p)))
                    .map(|(&p, _)| p),
            );
            let outline = if kept.len() >= 3 { &kept } else { &f.points };
            mesh.add_polygon(outline, id);
        }
        mesh
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

/// Whether point `i` of the polygon `points` is a corner: farther than [`ON_EPSILON`] (well
/// above the rounding of a BSP's f32 vertices) off the line through its neighbours.
fn is_corner(points: &[DVec3], i: usize) -> bool {
    let n = points.len();
    if n < 3 {
        return true;
    }
    let (before, at, after) = (points[(i + n - 1) % n], points[i], points[(i + 1) % n]);
    let run = after - before;
    let length = run.length();
    length == 0.0 || run.cross(at - before).length() >= ON_EPSILON * length
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::geom::Plane;

    fn sky(index: usize, points: &[[f64; 2]]) -> FaceGeom {
        let points = points
            .iter()
            .map(|&[x, y]| DVec3::new(x, y, 256.0))
            .collect();
        FaceGeom::for_test(index, 0, points, Plane::new(DVec3::NEG_Z, -256.0))
    }

    /// The outline of `face` in `mesh`, as its triangles' points.
    fn points_of(mesh: &Mesh, face: u32) -> HashSet<[u32; 3]> {
        mesh.triangles
            .iter()
            .zip(&mesh.faces)
            .filter(|&(_, &f)| f == face)
            .flat_map(|(t, _)| {
                t.iter()
                    .map(|&v| mesh.vertices[v as usize].map(f32::to_bits))
            })
            .collect()
    }

    #[test]
    fn thinning_drops_junctions_for_other_meshes_and_keeps_shared_corners() {
        // Face 0 has a point on its east edge for a wall outside the mesh (at y = 40) and one on
        // its north edge that is face 1's corner (at x = 64).
        let big = sky(
            0,
            &[
                [0.0, 0.0],
                [128.0, 0.0],
                [128.0, 40.0],
                [128.0, 128.0],
                [64.0, 128.0],
                [0.0, 128.0],
            ],
        );
        let small = sky(
            1,
            &[[64.0, 128.0], [128.0, 128.0], [128.0, 192.0], [64.0, 192.0]],
        );
        let mesh = Mesh::thinned(&[(&big, 0), (&small, 1)]);
        let key = |x: f32, y: f32| [x, y, 256.0].map(f32::to_bits);
        let outline = points_of(&mesh, 0);
        assert!(
            !outline.contains(&key(128.0, 40.0)),
            "the wall's junction is left out"
        );
        assert!(
            outline.contains(&key(64.0, 128.0)),
            "the other sky face's corner stays"
        );
        assert_eq!(outline.len(), 5);
        assert_eq!(mesh.faces.iter().filter(|&&f| f == 0).count(), 3);
        assert_eq!(points_of(&mesh, 1).len(), 4);
    }

    #[test]
    fn a_face_with_every_point_on_a_run_keeps_its_outline() {
        let flat = sky(0, &[[0.0, 0.0], [64.0, 0.0], [128.0, 0.0]]);
        let mesh = Mesh::thinned(&[(&flat, 0)]);
        assert_eq!(mesh.vertices.len(), 3);
    }
}
