//! Dirt (ambient occlusion, after q3map2 and ericw-tools): how enclosed each
//! sample point is, measured with rays in a cone around the face normal.
//! Lights that take dirt are scaled by [`crate::lights::DirtResponse::factor`]
//! of this occlusion.

use quake_formats::geom::Vec3;

use crate::embree::RayPacket16;
use crate::lights::{DirtMode, DirtSampling, tangent_basis};
use crate::scene::TraceScene;

/// Directions around the cone's axis (ordered mode).
const AZIMUTH_STEPS: usize = 16;
/// Rings between the axis and the cone's edge (ordered mode).
const ELEVATION_STEPS: usize = 3;
/// Rays per sample point, in both modes.
pub const RAYS_PER_SAMPLE: usize = AZIMUTH_STEPS * ELEVATION_STEPS;

/// A direction `elevation` radians off the axis `n` and `azimuth` around it.
fn cone_direction(basis: [Vec3; 3], azimuth: f64, elevation: f64) -> Vec3 {
    let [u, v, n] = basis;
    let (se, ce) = elevation.sin_cos();
    u * (se * azimuth.cos()) + v * (se * azimuth.sin()) + n * ce
}

/// The ordered pattern: rings at evenly spaced elevations, evenly spaced
/// azimuths on each ring (elevations at the middle of their steps).
fn ordered_directions(basis: [Vec3; 3], cone: f64) -> Vec<[f32; 3]> {
    let azimuth_step = std::f64::consts::TAU / AZIMUTH_STEPS as f64;
    let elevation_step = cone / ELEVATION_STEPS as f64;
    (0..AZIMUTH_STEPS)
        .flat_map(|a| {
            (0..ELEVATION_STEPS).map(move |e| {
                let elevation = elevation_step * (e as f64 + 0.5);
                cone_direction(basis, azimuth_step * a as f64, elevation).to_f32()
            })
        })
        .collect()
}

/// A uniform value in [0, 1) from a 64-bit key (SplitMix64 finaliser):
/// deterministic, so results do not depend on thread scheduling.
fn unit_hash(key: u64) -> f64 {
    let mut z = key.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// The random pattern for sample `sample` of face `face`: azimuth and
/// elevation each uniform, as in the ordered pattern.
fn random_directions(basis: [Vec3; 3], cone: f64, face: usize, sample: usize) -> Vec<[f32; 3]> {
    let seed = ((face as u64) << 32 ^ sample as u64).wrapping_mul(RAYS_PER_SAMPLE as u64 * 2);
    (0..RAYS_PER_SAMPLE as u64)
        .map(|k| {
            let azimuth = std::f64::consts::TAU * unit_hash(seed + 2 * k);
            let elevation = cone * unit_hash(seed + 2 * k + 1);
            cone_direction(basis, azimuth, elevation).to_f32()
        })
        .collect()
}

/// Occlusion of each of `points` (in front of a face with unit `normal`):
/// the mean over the dirt rays of `1 - hit distance / depth` (0 for a ray
/// that reaches no opaque surface within `depth`; sky does not occlude).
/// Returns the values and the number of rays cast.
pub fn occlusion(
    points: &[[f32; 3]],
    normal: Vec3,
    face: usize,
    sampling: &DirtSampling,
    scene: &TraceScene,
) -> (Vec<f32>, u64) {
    let [u, v] = tangent_basis(normal);
    let basis = [u, v, normal];
    let cone = sampling.cone_degrees.to_radians();
    let ordered = ordered_directions(basis, cone);
    let depth = sampling.depth as f32;
    let mut packet = RayPacket16::new();
    let mut rays = 0u64;
    let values = points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let random;
            let dirs = match sampling.mode {
                DirtMode::Ordered => &ordered,
                DirtMode::Random => {
                    random = random_directions(basis, cone, face, i);
                    &random
                }
            };
            let mut gathered = 0.0f32;
            for chunk in dirs.chunks(16) {
                packet.clear();
                for (lane, &d) in chunk.iter().enumerate() {
                    packet.set(lane, p, d, 0.0, depth);
                }
                rays += chunk.len() as u64;
                for t in scene.opaque_hits16(&mut packet).into_iter().flatten() {
                    gathered += 1.0 - (t / depth).min(1.0);
                }
            }
            gathered / dirs.len() as f32
        })
        .collect();
    (values, rays)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_stay_inside_the_cone() {
        let n = Vec3::new(0.0, 0.6, 0.8);
        let [u, v] = tangent_basis(n);
        let cone = 60f64.to_radians();
        let ordered = ordered_directions([u, v, n], cone);
        let random = random_directions([u, v, n], cone, 3, 7);
        assert_eq!(ordered.len(), RAYS_PER_SAMPLE);
        assert_eq!(random.len(), RAYS_PER_SAMPLE);
        for d in ordered.iter().chain(&random) {
            let d = Vec3::from_f32(*d);
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert!(d.dot(n) >= cone.cos() - 1e-5, "{d:?}");
        }
        assert_eq!(
            random,
            random_directions([u, v, n], cone, 3, 7),
            "deterministic"
        );
        assert_ne!(random, random_directions([u, v, n], cone, 3, 8));
    }
}
