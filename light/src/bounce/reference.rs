//! The slow exact bounce of `--reference`: at every sample, Monte Carlo gathering over the
//! hemisphere. Each sample casts [`RAYS_PER_SAMPLE`] cosine-distributed rays (one per cell of a
//! stratified grid, jittered by a hash of face, sample and ray, so results are the same on any
//! thread count); a ray that first meets the front of a reflecting face at `q` brings the light
//! the model gives for that direction, with the face's light at `q` read bilinearly from its
//! luxels. No culling, no gate. With 256 samples per luxel that is 4096 rays per luxel.

use quake_formats::bsp::limits::LIGHTMAP_SCALE;
use quake_formats::geom::Vec3;

use super::{BounceCounts, HOTSPOT_CLAMP, StyleLuxels, add_light};
use crate::embree::RayPacket16;
use crate::faces::FaceGeom;
use crate::lights::tangent_basis;
use crate::samples::FaceSamples;
use crate::scene::TraceScene;

/// Strata along each axis of the unit square mapped onto the hemisphere.
const STRATA: usize = 4;
/// Rays per sample (one packet).
pub const RAYS_PER_SAMPLE: usize = STRATA * STRATA;
/// Rays go no further than this.
const RAY_LENGTH: f32 = 65536.0;

/// What reflecting surfaces give off: per face, its reflectance and its light per luxel.
pub struct Field<'a> {
    pub faces: &'a [FaceGeom],
    pub reflectance: &'a [Option<[f32; 3]>],
    /// Per face (by index): its light per style and luxel, when it has any.
    pub light: &'a [Option<StyleLuxels>],
    /// [`super::BounceSettings::kernel`].
    pub kernel: f64,
}

/// A well-mixed 64-bit hash (splitmix64's finaliser).
fn mix(mut x: u64) -> u64 {
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// Two numbers in [0, 1) from `key`.
fn jitter(key: u64) -> (f64, f64) {
    let h = mix(key);
    let unit = |bits: u64| (bits >> 11) as f64 / (1u64 << 53) as f64;
    (unit(h), unit(mix(h ^ 0x9e37_79b9_7f4a_7c15)))
}

/// The light of `face` at world point `q`, bilinear between luxel centres.
fn light_at(face: &FaceGeom, luxels: &[[f32; 3]], q: Vec3) -> [f32; 3] {
    let [w, h] = face.extents.luxel_size();
    let coord = |axis: usize, size: usize| {
        let v = face.vecs[axis];
        let dir = Vec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
        let st = dir.dot(q - face.origin) + f64::from(v[3]);
        let f = ((st - f64::from(face.extents.tex_mins[axis])) / f64::from(LIGHTMAP_SCALE))
            .clamp(0.0, (size - 1) as f64);
        let i = (f.floor() as usize).min(size - 1);
        (i, (i + 1).min(size - 1), (f - i as f64) as f32)
    };
    let (x0, x1, fx) = coord(0, w);
    let (y0, y1, fy) = coord(1, h);
    let at = |x: usize, y: usize| luxels.get(y * w + x).copied().unwrap_or_default();
    let (a, b, c, d) = (at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1));
    std::array::from_fn(|k| {
        let top = a[k] + (b[k] - a[k]) * fx;
        let bottom = c[k] + (d[k] - c[k]) * fx;
        top + (bottom - top) * fy
    })
}

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
    let mut out: StyleLuxels = Vec::new();
    let flat = samples.normal;
    let [t0, t1] = tangent_basis(flat);
    let mut packet = RayPacket16::new();
    let mut dirs = [Vec3::ZERO; RAYS_PER_SAMPLE];
    for i in 0..n {
        let p = Vec3::from_f32(samples.points[i]);
        let shading = samples.normal_at(i);
        packet.clear();
        for (r, dir) in dirs.iter_mut().enumerate() {
            let key = ((samples.face as u64) << 40) ^ ((i as u64) << 8) ^ r as u64;
            let (j1, j2) = jitter(key ^ ((pass as u64) << 60));
            let u1 = ((r / STRATA) as f64 + j1) / STRATA as f64;
            let u2 = ((r % STRATA) as f64 + j2) / STRATA as f64;
            let radius = u1.sqrt();
            let phi = std::f64::consts::TAU * u2;
            *dir = t0 * (radius * phi.cos()) + t1 * (radius * phi.sin()) + flat * (1.0 - u1).sqrt();
            packet.set(r, p.to_f32(), dir.to_f32(), 0.0, RAY_LENGTH);
        }
        counts.rays += u64::from(packet.active_mask().count_ones());
        let hits = scene.first_faces16(&mut packet, model);
        for (r, hit) in hits.iter().enumerate() {
            let Some((f, t)) = *hit else {
                continue;
            };
            let (Some(face), Some(Some(rho)), Some(Some(light))) = (
                field.faces.get(f),
                field.reflectance.get(f),
                field.light.get(f),
            ) else {
                continue;
            };
            let dir = dirs[r];
            let cos_flat = flat.dot(dir);
            if face.plane.normal.dot(dir) >= 0.0 || cos_flat <= 0.0 {
                continue; // the back of a face, or a grazing ray
            }
            let cos_shading = shading.dot(dir).max(0.0);
            let d = f64::from(t);
            let near = (d / HOTSPOT_CLAMP).min(1.0);
            // cos-weighted directions: pdf = cos_flat / π; dA = d² dω / cos at the emitter.
            let weight = field.kernel * std::f64::consts::PI * cos_shading / cos_flat * near * near
                / RAYS_PER_SAMPLE as f64;
            let q = p + dir * d;
            let styles: Vec<u8> = light.iter().map(|(s, _)| *s).collect();
            let flux: Vec<[f32; 3]> = light
                .iter()
                .map(|(_, luxels)| {
                    let e = light_at(face, luxels, q);
                    std::array::from_fn(|k| e[k] * rho[k])
                })
                .collect();
            add_light(&mut out, n, &styles, &flux, i, weight);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jitter_is_in_the_unit_square_and_varies() {
        let a = jitter(1);
        let b = jitter(2);
        assert!((0.0..1.0).contains(&a.0) && (0.0..1.0).contains(&a.1));
        assert_ne!(a, b);
    }
}
