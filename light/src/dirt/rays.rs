//! Dirt rays: the two patterns of directions over the cone, and the occlusion they measure at
//! a face's samples, traced 16 to a packet.

use glam::{DMat3, DVec3, Vec3};

use super::{DirtMode, DirtSampling};
use crate::directions::tangent_basis;
use crate::embree::RayPacket16;
use crate::samples::FaceSamples;
use crate::scene::TraceScene;

/// Directions around the cone's axis (ordered mode).
const AZIMUTH_STEPS: usize = 16;
/// Rings between the axis and the cone's edge (ordered mode).
const ELEVATION_STEPS: usize = 3;
/// Rays per sample point, in both modes.
pub const RAYS_PER_SAMPLE: usize = AZIMUTH_STEPS * ELEVATION_STEPS;

/// The components along `u`, `v` and `n` of a direction `elevation`
/// radians off the axis `n` and `azimuth` around it.
fn cone_components(azimuth: f64, elevation: f64) -> [f64; 3] {
    let (se, ce) = elevation.sin_cos();
    [se * azimuth.cos(), se * azimuth.sin(), ce]
}

/// One cone's ordered pattern: each ray's components along a face's `u`, `v` and `n`.
pub type ConePattern = [[f64; 3]; RAYS_PER_SAMPLE];

/// The ordered pattern in the face's own terms (see [`ordered_directions`]):
/// the same for every sample and face, so the sines and cosines are taken
/// once a run ([`DirtSampling::new`]).
pub fn ordered_components(cone: f64) -> ConePattern {
    let azimuth_step = std::f64::consts::TAU / AZIMUTH_STEPS as f64;
    let elevation_step = cone / ELEVATION_STEPS as f64;
    std::array::from_fn(|k| {
        let (a, e) = (k / ELEVATION_STEPS, k % ELEVATION_STEPS);
        let elevation = elevation_step * (e as f64 + 0.5);
        cone_components(azimuth_step * a as f64, elevation)
    })
}

/// The ordered pattern: rings at evenly spaced elevations, evenly spaced
/// azimuths on each ring (elevations at the middle of their steps).
fn ordered_directions(basis: DMat3, components: &[[f64; 3]]) -> Vec<[f32; 3]> {
    components
        .iter()
        .map(|&c| (basis * DVec3::from(c)).as_vec3().to_array())
        .collect()
}

/// How far (units) dirt rays start from their sample along the face's two
/// tangent directions. The ordered pattern sends rays of axial faces along
/// the axis planes and their diagonals, and from a sample on the luxel grid
/// such a ray meets a grid-aligned edge exactly: a tie that Embree breaks one
/// way or the other with the CPU's vector width and with the other rays in
/// the packet. Moved by these two unequal binary fractions (exact in f32), the
/// ray passes such an edge by at least 1/64 · cos 45° = 0.011 units, over 20
/// f32 steps at coordinates up to 4096. (Turning the azimuths half a step
/// instead avoids the ties too, but moves the pattern away from the one the
/// reference's error was measured with.)
const RAY_START_SHIFT: [f64; 2] = [1.0 / 32.0, 1.0 / 64.0];

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
fn random_directions(basis: DMat3, cone: f64, face: usize, sample: usize) -> Vec<[f32; 3]> {
    let seed = ((face as u64) << 32 ^ sample as u64).wrapping_mul(RAYS_PER_SAMPLE as u64 * 2);
    (0..RAYS_PER_SAMPLE as u64)
        .map(|k| {
            let azimuth = std::f64::consts::TAU * unit_hash(seed + 2 * k);
            let elevation = cone * unit_hash(seed + 2 * k + 1);
            (basis * DVec3::from(cone_components(azimuth, elevation)))
                .as_vec3()
                .to_array()
        })
        .collect()
}

/// `d` if it points in front of a face with unit normal `face_normal`,
/// else its mirror image in the face's plane. A `_phong` normal tilts the
/// dirt cone, and rays it would send behind the flat face (into the face's
/// own polygon, a facet the smooth surface does not have) go back out.
fn in_front(d: [f32; 3], face_normal: DVec3) -> [f32; 3] {
    let v = Vec3::from(d).as_dvec3();
    let below = v.dot(face_normal);
    if below < 0.0 {
        (v - face_normal * (2.0 * below)).as_vec3().to_array()
    } else {
        d
    }
}

/// Which of its dirt rays a sample casts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DirtRays {
    /// All [`RAYS_PER_SAMPLE`].
    All,
    /// Every other azimuth (all elevations): for samples only bounced light
    /// takes dirt at, which is faint and smooth.
    Half,
}

impl DirtRays {
    /// Whether ray `k` of the pattern (azimuth-major) is cast.
    fn casts(self, k: usize) -> bool {
        self == DirtRays::All || (k / ELEVATION_STEPS).is_multiple_of(2)
    }
}

/// Occlusion of the samples `indices` of `samples` (a face of brush model and light channels
/// `from`), in that order: the mean over the dirt rays (`rays` of them),
/// cast in a cone around the sample's shading normal (the `_phong` one where
/// the face has them), of `1 - hit distance / depth` (0 for a ray that
/// reaches no opaque surface within `depth`; sky does not occlude). Returns
/// the values and the number of rays cast.
pub fn occlusion_at(
    samples: &FaceSamples,
    indices: &[usize],
    from: (usize, u32),
    sampling: &DirtSampling,
    rays: DirtRays,
    scene: &TraceScene,
) -> (Vec<f32>, u64) {
    let sample_rays = SampleRays::new(samples, indices, sampling, rays);
    sample_rays.occlusion(scene, from, sampling.depth as f32)
}

/// Where the dirt rays of some samples start and which directions they take.
struct SampleRays {
    /// Per sample, where its rays start.
    starts: Vec<[f32; 3]>,
    /// The ordered pattern around the face's own normal, which every sample without
    /// directions of its own shares.
    flat: Vec<[f32; 3]>,
    /// Per sample, its own directions (empty: `flat`).
    own: Vec<Vec<[f32; 3]>>,
}

impl SampleRays {
    /// The `rays` of the samples `indices` of `samples`, in their patterns turned in front of
    /// the face.
    fn new(
        samples: &FaceSamples,
        indices: &[usize],
        sampling: &DirtSampling,
        rays: DirtRays,
    ) -> SampleRays {
        let cone = sampling.cone_degrees().to_radians();
        let basis_of = |n: DVec3| {
            let [u, v] = tangent_basis(n);
            DMat3::from_cols(u, v, n)
        };
        // Without per-sample normals every sample shares one ordered pattern.
        let flat_basis = basis_of(samples.normal);
        let ordered = sampling.ordered();
        // Each pattern is turned in front of the face once, not per ray.
        let in_front_all = |dirs: Vec<[f32; 3]>| -> Vec<[f32; 3]> {
            dirs.into_iter()
                .enumerate()
                .filter(|&(k, _)| rays.casts(k))
                .map(|(_, d)| in_front(d, samples.normal))
                .collect()
        };
        let shift = flat_basis.x_axis * RAY_START_SHIFT[0] + flat_basis.y_axis * RAY_START_SHIFT[1];
        let starts = indices
            .iter()
            .map(|&i| {
                (Vec3::from(samples.points[i]).as_dvec3() + shift)
                    .as_vec3()
                    .to_array()
            })
            .collect();
        let own = indices
            .iter()
            .map(|&i| match sampling.mode {
                DirtMode::Ordered if samples.normals.is_empty() => Vec::new(),
                DirtMode::Ordered => {
                    in_front_all(ordered_directions(basis_of(samples.normal_at(i)), ordered))
                }
                DirtMode::Random => in_front_all(random_directions(
                    basis_of(samples.normal_at(i)),
                    cone,
                    samples.face,
                    i,
                )),
            })
            .collect();
        SampleRays {
            starts,
            flat: in_front_all(ordered_directions(flat_basis, ordered)),
            own,
        }
    }

    /// Sample `s`'s directions.
    fn directions(&self, s: usize) -> &[[f32; 3]] {
        if self.own[s].is_empty() {
            &self.flat
        } else {
            &self.own[s]
        }
    }

    /// Each sample's occlusion with rays `depth` long, and the rays cast.
    ///
    /// Rays go in pattern order, each direction from every sample in turn, 16 to a packet: a
    /// packet holds one direction from up to 16 neighbouring samples (rays that nearly
    /// coincide, which Embree traverses faster than 16 directions from one point), and no
    /// packet is left part empty while rays remain (a face's few samples fill packets with
    /// their next directions). Each sample sums its rays in pattern order.
    /// `from`: the face's brush model and light channels.
    fn occlusion(&self, scene: &TraceScene, from: (usize, u32), depth: f32) -> (Vec<f32>, u64) {
        let n = self.starts.len();
        let per_sample = self.flat.len();
        let total = n * per_sample;
        let mut gathered = vec![0.0f32; n];
        let mut packet = RayPacket16::new();
        // Direction and sample of the next ray.
        let (mut k, mut s) = (0, 0);
        let mut lane_sample = [0usize; 16];
        for first in (0..total).step_by(16) {
            packet.clear();
            let lanes = (total - first).min(16);
            for (lane, sample) in lane_sample.iter_mut().enumerate().take(lanes) {
                packet.set(
                    lane,
                    self.starts[s],
                    self.directions(s)[k],
                    crate::trace::RAY_START,
                    depth,
                );
                *sample = s;
                s += 1;
                if s == n {
                    (k, s) = (k + 1, 0);
                }
            }
            let hits = scene.opaque_hits16(&mut packet, from);
            for (hit, &sample) in hits.iter().zip(&lane_sample).take(lanes) {
                if let Some(t) = hit {
                    gathered[sample] += 1.0 - (t / depth).min(1.0);
                }
            }
        }
        let values = gathered.iter().map(|g| g / per_sample as f32).collect();
        (values, total as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_stay_inside_the_cone() {
        let n = DVec3::new(0.0, 0.6, 0.8);
        let [u, v] = tangent_basis(n);
        let basis = DMat3::from_cols(u, v, n);
        let cone = 60f64.to_radians();
        let ordered = ordered_directions(basis, &ordered_components(cone));
        let random = random_directions(basis, cone, 3, 7);
        assert_eq!(ordered.len(), RAYS_PER_SAMPLE);
        assert_eq!(random.len(), RAYS_PER_SAMPLE);
        for d in ordered.iter().chain(&random) {
            let d = Vec3::from(*d).as_dvec3();
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert!(d.dot(n) >= cone.cos() - 1e-5, "{d:?}");
        }
        assert_eq!(
            random,
            random_directions(basis, cone, 3, 7),
            "deterministic"
        );
        assert_ne!(random, random_directions(basis, cone, 3, 8));
    }
}
