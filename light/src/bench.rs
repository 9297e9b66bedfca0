//! The tracer's ceiling: the same kind of shadow rays the lighting pass casts
//! (sample points to the lights that survive culling, 16 neighbouring samples
//! per packet), traced in a bare loop with no lighting arithmetic around it.

use glam::Vec3;
use std::time::Instant;

use quake_formats::Bsp;
use rayon::prelude::*;

use crate::embree::RayPacket16;
use crate::error::LightError;
use crate::options::Options;
use crate::prepare::prepare;
use crate::samples::face_samples;

/// One shadow ray: origin, unit direction, length.
type Ray = ([f32; 3], [f32; 3], f32);

/// Result of [`bare_occlusion`].
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct BareOcclusion {
    /// Rays traced.
    pub rays: u64,
    /// Time tracing them.
    pub seconds: f64,
    /// Their rate.
    pub rays_per_second: f64,
}

/// Collects up to `max_rays` shadow rays of `bsp` lit with `options` (default sampling,
/// plane-side and range culling) and times tracing them in 16-ray packets on all threads.
///
/// # Errors
/// As [`crate::trace_lighting`].
pub fn bare_occlusion(
    bsp: &Bsp,
    options: &Options,
    max_rays: usize,
) -> Result<BareOcclusion, LightError> {
    let prep = prepare(bsp, options)?;
    let gate = prep.lights.settings.gate;
    let mut rays: Vec<Ray> = Vec::new();
    'faces: for face in prep.faces.iter().filter(|f| f.has_lightmap()) {
        let (samples, _) = face_samples(face, 1, bsp);
        for light in &prep.point_lights {
            if face.plane.distance(light.origin) <= 0.0 {
                continue;
            }
            let range = light.range(gate);
            for p in &samples.points {
                let d = light.origin - Vec3::from(*p).as_dvec3();
                let dist = d.length();
                if dist > range || dist < 1e-3 {
                    continue;
                }
                rays.push((*p, (d / dist).as_vec3().to_array(), dist as f32 - 0.1));
                if rays.len() >= max_rays {
                    break 'faces;
                }
            }
        }
    }
    let start = Instant::now();
    let blocked: u64 = rays
        .par_chunks(16)
        .map(|chunk| {
            let mut packet = RayPacket16::new();
            for (lane, &(o, d, t)) in chunk.iter().enumerate() {
                packet.set(lane, o, d, 0.0, t);
            }
            u64::from(prep.scene.occluded16(&mut packet, 0).count_ones())
        })
        .sum();
    let seconds = start.elapsed().as_secs_f64();
    debug_assert!(blocked <= rays.len() as u64);
    Ok(BareOcclusion {
        rays: rays.len() as u64,
        seconds,
        rays_per_second: rays.len() as f64 / seconds.max(1e-9),
    })
}
