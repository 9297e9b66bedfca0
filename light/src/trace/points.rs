//! Point lights (entities and `_surface` copies) on one face.
//!
//! Only the lights whose reach may touch the box around the face's samples are looked at
//! ([`crate::reach::LightReaches`]); each is culled when the face's plane turns from it, when
//! it is out of range of the box, or when the PVS says it cannot see the face. A light that
//! remains gets its unshadowed value at every sample (in vectorised passes: [`Toward`]), and
//! the samples with a value above the gate trace their shadow rays ([`super::shadows`]). The
//! face's faintest lights, together worth less than [`super::TraceSetup::faint_budget`], trace
//! a few probes each instead.

use glam::{DVec3, Vec3};

use super::{FaceTrace, KeptLight, LIGHT_CLEARANCE};
use crate::embree::RayPacket16;
use crate::lights::projection::Projector;
use crate::lights::{Falloff, PointLight};
use crate::reach::box_distance_squared;
use crate::samples::FaceSamples;

impl FaceTrace<'_> {
    /// Every point light the face takes, traced into its arrivals.
    pub(super) fn point_lights(&mut self) {
        // Only the lights whose reach may touch the samples' box (all of them without culling).
        let mut near_lights = std::mem::take(&mut self.scratch.near_lights);
        near_lights.clear();
        if self.setup.cull && !self.lights.is_empty() {
            self.setup.light_reaches.near(
                &self.bounds,
                &mut self.scratch.near_seen,
                &mut near_lights,
            );
        } else {
            near_lights.extend(0..self.lights.len() as u32);
        }
        self.counts.pairs += self.lights.len() as u64;
        self.counts.pairs_culled += (self.lights.len() - near_lights.len()) as u64;
        let mut kept = std::mem::take(&mut self.scratch.kept_lights);
        kept.clear();
        for li in near_lights.iter().map(|&li| li as usize) {
            // A light lights only the models on one of its channels.
            if self.lights[li].light_channels & self.rules.channels == 0 {
                continue;
            }
            if self.setup.cull && self.culled(li) {
                self.counts.pairs_culled += 1;
                continue;
            }
            // The most it adds to any sample, from the distance to the samples' box.
            let light = &self.lights[li];
            let near = box_distance_squared(&self.bounds, light.origin).sqrt();
            kept.push(KeptLight {
                light: li as u32,
                brightest: light.brightest_beyond(near).unwrap_or(f64::INFINITY),
                faint: false,
            });
        }
        if self.floor_hides(&kept) {
            // Style 0 ends at the minlight floor at every sample, lit or not.
            let before = kept.len();
            kept.retain(|k| self.lights[k.light as usize].style != 0);
            self.counts.pairs_culled += (before - kept.len()) as u64;
        }
        self.mark_faint(&mut kept);
        for k in &kept {
            self.point_light(k.light as usize, k.faint);
        }
        self.scratch.near_lights = near_lights;
        self.scratch.kept_lights = kept;
    }

    /// Marks the lights too faint on this face to be worth a shadow ray per sample: weakest
    /// first, as many as fit together in [`super::TraceSetup::faint_budget`], so that however
    /// their probes misjudge their shadows, no sample gains or loses more than the budget.
    /// Off in a map with switchable shadows (their styles need every ray).
    fn mark_faint(&mut self, kept: &mut [KeptLight]) {
        let budget = self.setup.faint_budget;
        if budget <= 0.0 || self.setup.scene.has_switchable() {
            return;
        }
        let order = &mut self.scratch.faintest_first;
        order.clear();
        order.extend(0..kept.len() as u32);
        order.sort_by(|&a, &b| {
            kept[a as usize]
                .brightest
                .total_cmp(&kept[b as usize].brightest)
        });
        let mut spent = 0.0;
        for &k in order.iter() {
            let k = &mut kept[k as usize];
            spent += k.brightest;
            if spent > budget {
                break;
            }
            k.faint = true;
        }
    }

    /// Whether the face's minlight floor is above all the style-0 light the `kept` lights can
    /// bring together, at every sample: then style 0 is the floor whatever their shadows, and
    /// they need no rays. Not when the face may see a sun (suns are style 0 too), when the
    /// floor is darkened by dirt or added rather than a floor, when switchable shadows may move
    /// light to another style, or when light under the floor is read ([`TraceSetup`]'s
    /// `raw_light_read`).
    fn floor_hides(&self, kept: &[KeptLight]) -> bool {
        let setup = self.setup;
        let Some(m) = self.rules.minlight else {
            return false;
        };
        let floor = m.level * m.color.min_element();
        if m.add
            || m.dirt.is_some()
            || floor <= 0.0
            || setup.raw_light_read
            || !(self.suns.is_empty() || (setup.cull && !setup.vis.may_see_sky(self.face.index)))
            || setup.scene.has_switchable()
        {
            return false;
        }
        let brightest: f64 = kept
            .iter()
            .filter(|k| self.lights[k.light as usize].style == 0)
            .map(|k| k.brightest)
            .sum();
        // The margin covers the sums' single precision.
        brightest * (1.0 + FLOOR_MARGIN) < floor
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
    fn point_light(&mut self, li: usize, faint: bool) {
        let (setup, samples, face) = (self.setup, self.samples, self.face);
        let light = &self.lights[li];
        let dirty = self.takes_dirt(light.dirt);
        self.unshadowed_values(li);
        let scratch = &mut *self.scratch;
        let toward = &scratch.toward;
        let ray = |i: usize| {
            let (dir, length) = toward.shadow_ray(i);
            (samples.points[i], dir, length)
        };
        let mut reaches = |p: &mut RayPacket16| {
            !setup
                .scene
                .occluded16_by(p, face.model, light.shadow_channels)
        };
        let (value, visibility) = (&scratch.value, &mut scratch.visibility);
        let (decided, rays) = if faint {
            visibility.probe_faint(samples, value, &ray, &mut self.packet, &mut reaches)
        } else {
            (false, 0)
        };
        self.counts.shadow_rays += rays;
        if !decided {
            self.counts.shadow_rays += visibility.trace(
                samples,
                setup.adaptive,
                value,
                ray,
                &mut self.packet,
                reaches,
            );
        }
        let switchable =
            light.style == 0 && light.falloff != Falloff::LocalMin && setup.scene.has_switchable();
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
            let arrived = lit.iter().zip(value).enumerate();
            let arrived = arrived
                .filter(|&(i, (&lit, _))| lit && arrive_in.as_ref().is_none_or(|a| a[i] == style))
                .map(|(i, (_, &v))| (i, v));
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
        let toward = &scratch.toward;
        let ray = |i: usize| {
            let (dir, length) = toward.shadow_ray(i);
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
        // ray. A sample whose ray stands for others at its point is as far as they are.
        let out_of_reach = if self.setup.cull {
            self.setup.light_reaches[li].range_squared * (1.0 + RANGE_MARGIN)
        } else {
            f64::INFINITY
        };
        let scratch = &mut *self.scratch;
        let toward = &mut scratch.toward;
        toward.measure(&scratch.points, light);
        let gate = self.setup.gate;
        let plain = samples.normals.is_empty()
            && light.spot.is_none()
            && light.projector.is_none()
            && light.falloff != Falloff::LocalMin;
        if plain {
            toward.plain_values(light, samples, (out_of_reach, gate), &mut scratch.value);
            return;
        }
        for (i, &p) in samples.points.iter().enumerate() {
            scratch.value[i] = 0.0;
            let dist = toward.dist[i];
            if toward.squared[i] > out_of_reach || dist <= MIN_DISTANCE {
                continue;
            }
            let dir = toward.direction(i);
            let cos = samples.incidence(i, dir);
            let v = light.contribution_of(toward.falloff[i], -dir, cos);
            // A projected picture lights only the samples it falls on.
            let pictured =
                |picture: &Projector| picture.tint(Vec3::from(p).as_dvec3()) != DVec3::ZERO;
            if v.abs() >= gate && light.projector.as_deref().is_none_or(pictured) {
                scratch.value[i] = v;
            }
        }
    }
}

/// A face's sample points in `f64`, one array per axis, for [`Toward::measure`].
#[derive(Debug, Default)]
pub(super) struct SamplePoints {
    axes: [Vec<f64>; 3],
}

impl SamplePoints {
    pub(super) fn set(&mut self, points: &[[f32; 3]]) {
        for (k, axis) in self.axes.iter_mut().enumerate() {
            axis.clear();
            axis.extend(points.iter().map(|p| f64::from(p[k])));
        }
    }
}

/// Per sample, how a light lies from it: the squared distance, the distance, the unit
/// direction and the light's falloff at that distance ([`PointLight::value_at`]).
#[derive(Debug, Default)]
pub(super) struct Toward {
    squared: Vec<f64>,
    dist: Vec<f64>,
    dir: [Vec<f64>; 3],
    falloff: Vec<f64>,
}

impl Toward {
    /// Measures every sample of `points` against `light`, without a branch, so that the
    /// compiler turns each pass into vector instructions (the square roots and divisions are
    /// most of a light's cost on a face). A sample at the light gets a direction of NaNs,
    /// which [`MIN_DISTANCE`] keeps from use.
    fn measure(&mut self, points: &SamplePoints, light: &PointLight) {
        crate::simd::widest(
            #[inline(always)]
            || self.measure_any(points, light),
        );
    }

    /// [`Toward::measure`] for whatever the build targets.
    #[inline(always)]
    fn measure_any(&mut self, points: &SamplePoints, light: &PointLight) {
        let n = points.axes[0].len();
        for v in [&mut self.squared, &mut self.dist, &mut self.falloff]
            .into_iter()
            .chain(&mut self.dir)
        {
            v.resize(n, 0.0);
        }
        let [px, py, pz] = &points.axes;
        let (px, py, pz) = (&px[..n], &py[..n], &pz[..n]);
        let (squared, dist) = (&mut self.squared[..n], &mut self.dist[..n]);
        let [dx, dy, dz] = &mut self.dir;
        let (dx, dy, dz) = (&mut dx[..n], &mut dy[..n], &mut dz[..n]);
        let o = light.origin;
        for i in 0..n {
            // As `DVec3` computes them: the difference, then x² + y² + z² in that order.
            let (x, y, z) = (o.x - px[i], o.y - py[i], o.z - pz[i]);
            let sq = x * x + y * y + z * z;
            let d = sq.sqrt();
            let inverse = 1.0 / d;
            squared[i] = sq;
            dist[i] = d;
            dx[i] = x * inverse;
            dy[i] = y * inverse;
            dz[i] = z * inverse;
        }
        light.values_at(dist, &mut self.falloff[..n]);
    }

    /// The unit direction from sample `i` to the light.
    fn direction(&self, i: usize) -> DVec3 {
        DVec3::new(self.dir[0][i], self.dir[1][i], self.dir[2][i])
    }

    /// Sample `i`'s shadow ray: its direction, and its length, which stops short of the light.
    fn shadow_ray(&self, i: usize) -> ([f32; 3], f32) {
        let length = (self.dist[i] as f32 - LIGHT_CLEARANCE).max(0.0);
        (self.direction(i).as_vec3().to_array(), length)
    }

    /// Into `value`, `light`'s value at each sample as [`PointLight::contribution`] gives
    /// it (0 out of reach or under the gate), for a flat face and a light without a cone, a
    /// picture or local minlight: then it is the same arithmetic at every sample, with no
    /// branch, and the compiler turns it into vector instructions.
    fn plain_values(
        &self,
        light: &PointLight,
        samples: &FaceSamples,
        bounds: (f64, f64),
        value: &mut [f64],
    ) {
        crate::simd::widest(
            #[inline(always)]
            || self.plain_values_any(light, samples, bounds, value),
        );
    }

    /// [`Toward::plain_values`] for whatever the build targets.
    #[inline(always)]
    fn plain_values_any(
        &self,
        light: &PointLight,
        samples: &FaceSamples,
        (out_of_reach, gate): (f64, f64),
        value: &mut [f64],
    ) {
        let n = value.len();
        let normal = samples.normal;
        let (two_sided, scale) = (samples.two_sided, light.anglescale);
        let [dx, dy, dz] = &self.dir;
        let (dx, dy, dz) = (&dx[..n], &dy[..n], &dz[..n]);
        let (squared, dist, falloff) = (&self.squared[..n], &self.dist[..n], &self.falloff[..n]);
        for i in 0..n {
            // `FaceSamples::incidence`, `angle_factor` and `contribution_of`, term by term.
            let cos = normal.x * dx[i] + normal.y * dy[i] + normal.z * dz[i];
            let cos = if two_sided { cos.abs() } else { cos };
            let facing = scale * cos + (1.0 - scale);
            let angle = if cos < 0.0 { 0.0 } else { facing };
            // Times the cone's factor, 1 without a cone, as `contribution_of` multiplies it.
            let v = falloff[i] * angle * 1.0;
            // `&`, not `&&`: no branch.
            let kept = (squared[i] <= out_of_reach) & (dist[i] > MIN_DISTANCE) & (v.abs() >= gate);
            value[i] = if kept { v } else { 0.0 };
        }
    }
}

/// Relative margin by which the most light the lights can bring must stay under a minlight
/// floor for them to be skipped: more than the rounding of single-precision sums.
const FLOOR_MARGIN: f64 = 1e-4;

/// A sample closer than this to a light has no direction to it, and takes none of its light.
const MIN_DISTANCE: f64 = 1e-12;

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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn light(origin: DVec3, falloff: Falloff, value: f64, anglescale: f64) -> PointLight {
        PointLight {
            origin,
            anglescale,
            ..crate::lights::test_light(falloff, value)
        }
    }

    fn samples(points: Vec<[f32; 3]>, normal: DVec3, two_sided: bool) -> FaceSamples {
        let n = points.len();
        FaceSamples {
            face: 0,
            width: n,
            height: 1,
            per_axis: 1,
            normal,
            points,
            normals: Vec::new(),
            two_sided,
            moved: vec![false; n],
            apart: vec![false; n],
            occluded: Vec::new(),
            landed: Vec::new(),
        }
    }

    const FALLOFFS: [Falloff; 5] = [
        Falloff::Linear,
        Falloff::Inverse,
        Falloff::InverseSquare,
        Falloff::Constant,
        Falloff::InverseSquareSoft,
    ];

    proptest! {
        /// The vectorised measure and values give, bit for bit, what
        /// `PointLight::contribution` gives at each sample's distance and direction, built for
        /// any x86-64 and in the CPU's wider vectors alike.
        #[test]
        fn plain_values_are_the_contribution_bit_for_bit(
            points in prop::collection::vec(prop::array::uniform3(-300.0f32..300.0), 1..40),
            origin in prop::array::uniform3(-300.0f64..300.0),
            normal in prop::array::uniform3(-1.0f64..1.0),
            falloff in 0usize..5,
            value in -300.0f64..300.0,
            anglescale in -1.0f64..2.0,
            two_sided: bool,
            reach in 0.0f64..200_000.0,
            gate in 0.0f64..2.0,
        ) {
            let normal = DVec3::from(normal).normalize_or(DVec3::Z);
            let light = light(DVec3::from(origin), FALLOFFS[falloff], value, anglescale);
            let face = samples(points.clone(), normal, two_sided);
            let mut coords = SamplePoints::default();
            coords.set(&points);
            // The loops as each vector build this CPU runs compiles them.
            let each = crate::simd::builds_here(
                #[inline(always)]
                || {
                    let mut toward = Toward::default();
                    let mut got = vec![f64::NAN; points.len()];
                    toward.measure_any(&coords, &light);
                    toward.plain_values_any(&light, &face, (reach, gate), &mut got);
                    (toward, got)
                },
            );
            for (build, (toward, got)) in each {
                for (i, p) in points.iter().enumerate() {
                    let to_light = light.origin - Vec3::from(*p).as_dvec3();
                    let (sq, dist) = (to_light.length_squared(), to_light.length());
                    let dir = to_light * (1.0 / dist);
                    let want = if sq > reach || dist <= MIN_DISTANCE {
                        0.0
                    } else {
                        let v = light.contribution(dist, -dir, face.incidence(i, dir));
                        if v.abs() >= gate { v } else { 0.0 }
                    };
                    prop_assert_eq!(
                        got[i].to_bits(),
                        want.to_bits(),
                        "sample {}, {:?}",
                        i,
                        build
                    );
                    if want != 0.0 {
                        let (ray, length) = toward.shadow_ray(i);
                        prop_assert_eq!(ray, dir.as_vec3().to_array());
                        prop_assert_eq!(length, (dist as f32 - LIGHT_CLEARANCE).max(0.0));
                    }
                }
            }
        }
    }
}
