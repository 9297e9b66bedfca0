//! Suns and sky domes on one face: parallel light that reaches a sample only when its ray
//! meets sky first.
//!
//! A face that sees no sky in the PVS takes none; a direction that meets none of the boxes
//! around the sky the face sees is skipped. In the default mode the many directions of a soft
//! sun or a dome are probed on a grid of luxels and filled in between where the probes agree
//! ([`super::shadows`]); each such direction carries a small part of its source's light.

use glam::DVec3;
use quake_formats::geom::Bounds;

use super::FaceTrace;
use super::arrivals::{Arrival, Source};
use crate::embree::RayPacket16;
use crate::grid::SampleGrid;
use crate::lights::angle_factor;

/// Sky faces closer to a box's edge than this still count as reachable
/// (sample points and rays are f32).
const SKY_BOX_MARGIN: f64 = 1.0;

/// For each box in `sky`, the offsets `q - p` from a point `p` in `samples`
/// to a point `q` in it (the box `sky - samples`, a little wider): a sun
/// ray from a sample can only meet that sky if its direction meets this box.
pub(crate) fn sky_offsets(sky: &[Bounds], samples: &Bounds) -> Vec<Bounds> {
    let margin = DVec3::new(SKY_BOX_MARGIN, SKY_BOX_MARGIN, SKY_BOX_MARGIN);
    sky.iter()
        .map(|b| Bounds {
            mins: b.mins - samples.maxs - margin,
            maxs: b.maxs - samples.mins + margin,
        })
        .collect()
}

/// Whether the ray from the origin along `d` meets any of `boxes`.
pub(crate) fn direction_meets_any(boxes: &[Bounds], d: DVec3) -> bool {
    // Arrays, not DVec3 indexing: glam's Index has a panic arm, which this hot loop pays for.
    let d = d.to_array();
    boxes.iter().any(|b| {
        let (mut near, mut far) = (0.0f64, f64::INFINITY);
        let (mins, maxs) = (b.mins.to_array(), b.maxs.to_array());
        for axis in 0..3 {
            let (lo, hi) = (mins[axis], maxs[axis]);
            if d[axis] == 0.0 {
                if lo > 0.0 || hi < 0.0 {
                    return false;
                }
                continue;
            }
            let (t0, t1) = (lo / d[axis], hi / d[axis]);
            near = near.max(t0.min(t1));
            far = far.min(t0.max(t1));
        }
        near <= far
    })
}

/// Luxels between sunlight probes ([`VisibilityScratch::trace_probed`]).
const SUN_PROBE_STRIDE: usize = 2;

/// Suns and domes spread over at least this many directions are probed in
/// the default mode ([`VisibilityScratch::trace_probed`]).
const SUN_PROBE_DIRECTIONS: usize = 16;

impl FaceTrace<'_> {
    /// Every sun and dome direction the face takes, traced into its arrivals.
    pub(super) fn suns(&mut self) {
        let (setup, face) = (self.setup, self.face);
        if self.suns.is_empty() || (setup.cull && !setup.vis.may_see_sky(face.index)) {
            return;
        }
        let sky_offsets = setup
            .cull
            .then(|| setup.vis.visible_sky_bounds(face.index))
            .flatten()
            .map(|sky| sky_offsets(&sky, &self.bounds));
        let samples = self.samples;
        let probes = (setup.adaptive && samples.per_axis == 1)
            .then(|| SampleGrid::new(samples.width, samples.height, SUN_PROBE_STRIDE));
        for (si, sun) in self.suns.iter().enumerate() {
            if sky_offsets
                .as_ref()
                .is_some_and(|offsets| !direction_meets_any(offsets, sun.to_sun))
            {
                continue;
            }
            self.sun(si, probes.as_ref());
        }
    }

    /// Sun direction `si` on every sample: values, then the rays of those with a value, on the
    /// probe grid `probes` when the direction is one of many.
    fn sun(&mut self, si: usize, probes: Option<&SampleGrid>) {
        let (setup, samples, face) = (self.setup, self.samples, self.face);
        let (lights, suns) = (self.lights, self.suns);
        let sun = &suns[si];
        // A sun of a texture the sky does not have reaches nothing.
        let Some(filter) = setup.scene.sky_filter(sun.sky_texture.as_deref()) else {
            return;
        };
        let dirty = self.takes_dirt(sun.dirt);
        let scratch = &mut *self.scratch;
        let value = &mut scratch.value;
        let dir = sun.to_sun.as_vec3().to_array();
        let sun_value = |i: usize| {
            let v = sun.light * angle_factor(samples.incidence(i, sun.to_sun), sun.anglescale);
            if v.abs() < setup.gate { 0.0 } else { v }
        };
        if samples.normals.is_empty() {
            // A flat face: the same value at every sample (none when the sun is behind it).
            let v = sun_value(0);
            if v == 0.0 {
                return;
            }
            value.fill(v);
        } else {
            for (i, v) in value.iter_mut().enumerate() {
                *v = sun_value(i);
            }
        }
        let ray = |i: usize| (samples.points[i], dir, setup.sun_distance);
        let reaches = |p: &mut RayPacket16| setup.scene.sees_sky16(p, face.model, filter);
        let packet = &mut self.packet;
        let visibility = &mut scratch.visibility;
        self.counts.sun_rays += match probes {
            Some(grid) if sun.directions >= SUN_PROBE_DIRECTIONS => {
                visibility.trace_probed(samples, grid, value, ray, packet, reaches)
            }
            _ => visibility.trace(samples, setup.adaptive, value, ray, packet, reaches),
        };
        for (i, &v) in value.iter().enumerate() {
            if visibility.lit[i] {
                let a = Arrival::new(Source::Sun(si), i, v, dirty);
                scratch
                    .arrivals
                    .add(a, (lights, suns, &samples.points), &mut self.out);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::geom::DVec3Ext;

    fn cube(mins: [f64; 3], maxs: [f64; 3]) -> Bounds {
        Bounds {
            mins: DVec3::new(mins[0], mins[1], mins[2]),
            maxs: DVec3::new(maxs[0], maxs[1], maxs[2]),
        }
    }

    #[test]
    fn sun_directions_are_kept_only_toward_visible_sky() {
        // Samples on a 64x64 floor at z 0, a skylight 128 units above its middle.
        let floor = cube([0.0, 0.0, 0.0], [64.0, 64.0, 0.0]);
        let skylight = cube([16.0, 16.0, 128.0], [48.0, 48.0, 128.0]);
        let offsets = sky_offsets(&[skylight], &floor);
        let up = DVec3::new(0.0, 0.0, 1.0);
        assert!(direction_meets_any(&offsets, up));
        // From the floor's corner (0, 0) to the skylight's far corner (48, 48).
        let steepest_slant = DVec3::new(48.0, 48.0, 128.0).normalized().unwrap();
        assert!(direction_meets_any(&offsets, steepest_slant));
        let too_low = DVec3::new(1.0, 0.0, 0.5).normalized().unwrap();
        assert!(!direction_meets_any(&offsets, too_low));
        assert!(!direction_meets_any(&offsets, -up));
        assert!(!direction_meets_any(&[], up), "no sky in sight");
    }
}
