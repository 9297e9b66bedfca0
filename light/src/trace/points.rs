//! Point lights (entities and `_surface` copies) on one face.
//!
//! Only the lights whose reach may touch the box around the face's samples are looked at
//! ([`crate::reach::LightReaches`]); each is culled when the face's plane turns from it, when
//! it is out of range of the box, or when the PVS says it cannot see the face. A light that
//! remains gets its unshadowed value at every sample, and the samples with a value above the gate
//! trace their shadow rays ([`super::shadows`]).

use glam::{DVec3, Vec3};
use quake_formats::geom::DVec3Ext;

use super::{FaceTrace, LIGHT_CLEARANCE};
use crate::lights::Falloff;
use crate::lights::projection::Projector;
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
        for li in near_lights.iter().map(|&li| li as usize) {
            // A light lights only the models on one of its channels.
            if self.lights[li].light_channels & self.rules.channels == 0 {
                continue;
            }
            if self.setup.cull && self.culled(li) {
                self.counts.pairs_culled += 1;
                continue;
            }
            self.point_light(li);
        }
        self.scratch.near_lights = near_lights;
    }

    /// Whether light `li` surely adds nothing to the face: behind its plane, out of range of
    /// its samples' box, or out of its sight in the PVS.
    fn culled(&self, li: usize) -> bool {
        let reach = &self.setup.light_reaches[li];
        // A light behind the plane of a `_phong` face can still be in front of the smoothed
        // normals of some of its samples: only flat one-sided faces are culled by their plane.
        let behind = self.samples.normals.is_empty()
            && !self.samples.two_sided
            && self.face.plane.distance(reach.origin) < 0.0;
        behind
            || box_distance_squared(&self.bounds, reach.origin) > reach.range_squared
            || !self
                .setup
                .vis
                .may_reach(self.setup.light_leafs[li], self.face.index)
    }

    /// Light `li` on every sample: values and shadow rays, then the arrivals of those it
    /// reaches (in a switchable shadow's style where one blocks it).
    fn point_light(&mut self, li: usize) {
        let (setup, samples, face) = (self.setup, self.samples, self.face);
        let light = &self.lights[li];
        let dirty = self.takes_dirt(light.dirt);
        self.unshadowed_values(li);
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
            |p| {
                !setup
                    .scene
                    .occluded16_by(p, face.model, light.shadow_channels)
            },
        );
        let switchable = light.style == 0
            && light.falloff != Falloff::LocalMin
            && setup.scene.switchable_styles().next().is_some();
        let n = scratch.value.len();
        let arrive_in = switchable.then(|| {
            let mut arrive_in = vec![0; n];
            self.switchable_shadows(&mut arrive_in);
            arrive_in
        });
        // The light's own style first, then any switchable shadow's.
        let shadow_styles = arrive_in.as_deref().map_or_else(Vec::new, styles_in);
        let styles = std::iter::once(light.style)
            .chain(shadow_styles.into_iter().filter(|&s| s != light.style));
        let scratch = &mut *self.scratch;
        let (lit, value) = (&scratch.visibility.lit, &scratch.value);
        for style in styles {
            let arrived = (0..value.len())
                .filter(|&i| lit[i] && arrive_in.as_ref().is_none_or(|a| a[i] == style))
                .map(|i| (i, value[i]));
            scratch.arrivals.add_light(
                (li, light, style),
                arrived,
                dirty,
                &samples.points,
                &mut self.out,
            );
        }
    }

    /// For a style-0 light whose shadow rays the world let through (`visibility.lit`): the
    /// samples a switchable shadow blocks take its style in `arrive_in` instead (the first
    /// switchable shadow on the ray, in style order). The face's own switchable shadow is none
    /// of those: it shadows its faces as fixed geometry, which the world's test included.
    fn switchable_shadows(&mut self, arrive_in: &mut [u8]) {
        let (setup, samples) = (self.setup, self.samples);
        let own = setup.scene.own_switchable(self.face.model);
        let styles: Vec<u8> = setup.scene.switchable_styles().collect();
        let scratch = &mut *self.scratch;
        let reached = scratch.visibility.lit.clone();
        let mut open = reached.clone();
        let mut values = scratch.value.clone();
        let shadow_rays = &scratch.to_light;
        let ray = |i: usize| {
            let (dir, length) = shadow_rays[i];
            (samples.points[i], dir, length)
        };
        for (k, &style) in styles.iter().enumerate() {
            if Some(k) == own {
                continue;
            }
            for (v, o) in values.iter_mut().zip(&open) {
                if !o {
                    *v = 0.0;
                }
            }
            self.counts.shadow_rays += scratch.visibility.trace(
                samples,
                setup.adaptive,
                &values,
                ray,
                &mut self.packet,
                |p| !setup.scene.switchable_blocks16(p, k),
            );
            for (i, passes) in scratch.visibility.lit.iter().enumerate() {
                if open[i] && !passes && values[i] != 0.0 {
                    open[i] = false;
                    arrive_in[i] = style;
                }
            }
        }
        // Whatever the world let through arrives, in style 0 or a shadow's.
        scratch.visibility.lit = reached;
    }

    /// Light `li`'s value at each sample (0 below the gate) and its shadow ray, into the
    /// scratch buffers.
    fn unshadowed_values(&mut self, li: usize) {
        let samples = self.samples;
        let light = &self.lights[li];
        // Past its range, a light adds less than the gate at any angle and the sample needs no
        // ray: its square root and divisions are skipped. A sample whose ray stands for others
        // at its point is as far as they are.
        let out_of_reach = if self.setup.cull {
            self.setup.light_reaches[li].range_squared * (1.0 + RANGE_MARGIN)
        } else {
            f64::INFINITY
        };
        let scratch = &mut *self.scratch;
        for (i, &p) in samples.points.iter().enumerate() {
            scratch.value[i] = 0.0;
            let to_light = light.origin - Vec3::from(p).as_dvec3();
            if to_light.length_squared() > out_of_reach {
                continue;
            }
            // One square root per sample and light.
            let Some((dist, dir)) = to_light.length_and_direction() else {
                continue;
            };
            // Kept whatever the value: a sample whose `_phong` normal turns from the light may
            // be the first at a point whose others need the ray.
            scratch.to_light[i] = (
                dir.as_vec3().to_array(),
                (dist as f32 - LIGHT_CLEARANCE).max(0.0),
            );
            let v = light.contribution(dist, -dir, samples.incidence(i, dir));
            // A projected picture lights only the samples it falls on.
            let pictured =
                |picture: &Projector| picture.tint(Vec3::from(p).as_dvec3()) != DVec3::ZERO;
            if v.abs() >= self.setup.gate && light.projector.as_deref().is_none_or(pictured) {
                scratch.value[i] = v;
            }
        }
    }
}

/// Relative margin on a light's squared range before a sample counts as out of its reach:
/// covers the rounding of the range and of the sample's squared distance.
const RANGE_MARGIN: f64 = 1e-9;

/// The distinct styles of `arrive_in`, in first-seen order.
fn styles_in(arrive_in: &[u8]) -> Vec<u8> {
    let mut styles: Vec<u8> = Vec::new();
    for &s in arrive_in {
        if !styles.contains(&s) {
            styles.push(s);
        }
    }
    styles
}
