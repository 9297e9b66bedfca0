//! The slow exact bounce of `--reference`: at every sample, the fast method's hemisphere
//! gathering ([`Field::gather`]) with [`STRATA`]² rays, read from every face's `--extra4`
//! direct light. With 256 samples per luxel that is 4096 rays per luxel, none skipped and
//! nothing interpolated.

use super::{BounceCounts, Field, GatherPoint, StyleLuxels, point_key};
use crate::samples::FaceSamples;
use crate::scene::TraceScene;
use glam::Vec3;

/// Strata along each axis of the unit square mapped onto the hemisphere.
const STRATA: usize = 4;

/// Bounced light at every sample of `samples` (per style, per sample), gathered from `field`.
/// `pass` keys the jitter, so passes do not share rays.
pub fn gather(
    field: &Field,
    scene: &TraceScene,
    samples: &FaceSamples,
    model: usize,
    pass: usize,
    counts: &mut BounceCounts,
) -> StyleLuxels {
    let n = samples.points.len();
    let points: Vec<(GatherPoint, usize)> = samples
        .points
        .iter()
        .enumerate()
        .map(|(i, &point)| {
            let at = GatherPoint {
                point: Vec3::from(point).as_dvec3(),
                flat: samples.normal,
                shading: samples.normal_at(i),
                key: point_key(samples.face, i, pass),
                two_sided: samples.two_sided,
            };
            (at, i)
        })
        .collect();
    field.gather(scene, model, &points, STRATA, n, counts)
}
