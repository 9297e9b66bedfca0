//! Point lights (entities and `_surface` copies) on one face.
//!
//! Only the lights whose reach may touch the box around the face's samples are looked at
//! ([`crate::reach::LightReaches`]); each is culled when the face's plane turns from it, when
//! it is out of range of the box, or when the PVS says it cannot see the face. A light that
//! remains gets its unshadowed value at every sample, the samples with a value above the gate
//! trace their shadow rays ([`super::shadows`]), and the samples so close that it is averaged
//! over their squares are traced point by point ([`super::footprints`]).

use glam::Vec3;
use quake_formats::geom::DVec3Ext;

use super::footprints::Closeness;
use super::{FaceTrace, LIGHT_CLEARANCE};
use crate::reach::box_distance_squared;

impl FaceTrace<'_> {
    /// Every point light the face takes, traced into its arrivals.
    pub(super) fn point_lights(&mut self) {
        let n = self.samples.points.len();
        self.scratch.to_light.resize(n, ([0.0; 3], 0.0));
        // Only the lights whose reach may touch the samples' box (all of them without culling).
        let mut near_lights = std::mem::take(&mut self.scratch.near_lights);
        near_lights.clear();
        if self.setup.cull && !self.lights.is_empty() {
            self.setup
                .light_reaches
                .near(&self.bounds, &mut near_lights);
        } else {
            near_lights.extend(0..self.lights.len() as u32);
        }
        self.counts.pairs += self.lights.len() as u64;
        self.counts.pairs_culled += (self.lights.len() - near_lights.len()) as u64;
        let closeness = Closeness::of(self.samples);
        for li in near_lights.iter().map(|&li| li as usize) {
            if self.setup.cull && self.culled(li) {
                self.counts.pairs_culled += 1;
                continue;
            }
            self.point_light(li, closeness);
        }
        self.scratch.near_lights = near_lights;
    }

    /// Whether light `li` surely adds nothing to the face: behind its plane, out of range of
    /// its samples' box, or out of its sight in the PVS.
    fn culled(&self, li: usize) -> bool {
        let reach = &self.setup.light_reaches[li];
        // A light behind the plane of a `_phong` face can still be in front of the smoothed
        // normals of some of its samples: only flat faces are culled by their plane.
        let behind =
            self.samples.normals.is_empty() && self.face.plane.distance(reach.origin) <= 0.0;
        behind
            || box_distance_squared(&self.bounds, reach.origin) > reach.range_squared
            || !self
                .setup
                .vis
                .may_reach(self.setup.light_leafs[li], self.face.index)
    }

    /// Light `li` on every sample: values and shadow rays, then the arrivals of those it
    /// reaches.
    fn point_light(&mut self, li: usize, closeness: Closeness) {
        let (setup, samples, face) = (self.setup, self.samples, self.face);
        let light = &self.lights[li];
        let dirty = self.takes_dirt(light.dirt);
        self.unshadowed_values(li, closeness);
        let scratch = &mut *self.scratch;
        let shadow_rays = &scratch.to_light;
        let ray = |i: usize| {
            let (dir, length) = shadow_rays[i];
            (samples.points[i], dir, length)
        };
        self.counts.shadow_rays += scratch.visibility.trace(
            samples,
            setup.adaptive,
            &scratch.value,
            ray,
            &mut self.packet,
            |p| !setup.scene.occluded16(p, face.model),
        );
        let (lit, value) = (&scratch.visibility.lit, &scratch.value);
        let arrived = (0..value.len()).filter(|&i| lit[i]).map(|i| (i, value[i]));
        scratch
            .arrivals
            .add_light(li, light, arrived, (dirty, true), &mut self.out);
        if !scratch.near.is_empty() {
            let footprints = &mut scratch.footprints;
            footprints.clear();
            for &(i, cells) in scratch.near.iter() {
                footprints.add(setup.bsp, samples, i, cells, light);
            }
            self.counts.shadow_rays += footprints.trace(setup.scene, face.model, &mut self.packet);
            scratch.arrivals.add_light(
                li,
                light,
                footprints.means(),
                (dirty, false),
                &mut self.out,
            );
        }
    }

    /// Light `li`'s value at each sample (0 below the gate) and its shadow ray, into the
    /// scratch buffers; samples so close that the light is averaged over their squares go to
    /// `near` instead, with their cell counts.
    fn unshadowed_values(&mut self, li: usize, closeness: Closeness) {
        let samples = self.samples;
        let light = &self.lights[li];
        let scratch = &mut *self.scratch;
        scratch.near.clear();
        for (i, &p) in samples.points.iter().enumerate() {
            scratch.value[i] = 0.0;
            let to_light = light.origin - Vec3::from(p).as_dvec3();
            // One square root per sample and light.
            let Some((dist, dir)) = to_light.length_and_direction() else {
                continue;
            };
            let cells = closeness.cells(to_light, dist, samples.normal);
            if cells > 1 {
                // Traced on its own below, point by point over the square.
                scratch.near.push((i, cells));
                continue;
            }
            // Kept whatever the value: a sample whose `_phong` normal turns from the light may
            // be the first at a point whose others need the ray.
            scratch.to_light[i] = (
                dir.as_vec3().to_array(),
                (dist as f32 - LIGHT_CLEARANCE).max(0.0),
            );
            let v = light.contribution(dist, -dir, samples.normal_at(i).dot(dir));
            if v.abs() >= self.setup.gate {
                scratch.value[i] = v;
            }
        }
    }
}
