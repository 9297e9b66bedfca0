//! Diffuse interreflection ("bounce"), with ericw-tools' keys and brightness.
//!
//! The model (what `--reference` computes exactly, see [`reference`]): after direct light, a
//! point `q` of a reflecting face gives off `B(q) = ρ · E(q)`, its direct light `E` (lights and
//! suns; not minlight, not `_bounce 0` lights) times the face's reflectance `ρ` (the texture's
//! mean colour blended with grey by `_bouncecolorscale`). A point `p` receives
//! `scale · ∫ B(q) cosθq cosθp / max(|p − q|, 128)² dA` over every reflecting surface it sees,
//! with `scale` = 0.5 × `_bouncescale`: ericw-tools' bounce kernel (its 128-unit hotspot clamp
//! and factor 0.5), integrated over the surfaces instead of taken at one point per face. A
//! liquid's surface receives as ericw-tools' two-sided receivers do: from both sides, with
//! `cosθp` taken as 1. Each further pass reflects the light the previous pass brought, as the
//! face shows it: times its dirt factor, none from samples inside solid (as ericw-tools).
//!
//! The fast method is a final gather with the reference's estimator: receivers on a grid of
//! every few luxels ([`Density`]) each cast stratified cosine-distributed rays; a ray reads the
//! light of the reflecting face it meets first at the point it meets it (the face's lightmap,
//! bilinear). Its cost is receivers × rays, whatever the number of reflecting faces; the PVS
//! and distance cut nothing by hand, as rays only meet what is in sight. Bounce between
//! receivers is bilinear. Rays are keyed by face, luxel and pass, so results do not depend on
//! threads.

use glam::{DVec3, Vec3};
use quake_formats::Bsp;

use quake_formats::palette::Palette;

use crate::directions::tangent_basis;
use crate::embree::RayPacket16;
use crate::faces::{FaceGeom, FaceKind};
use crate::grid::{cell_of, grid, receiver_grid};
use crate::lights::{BounceSettings, MapLights};
use crate::quality::Quality;
use crate::samples::FaceSamples;
use crate::scene::TraceScene;

pub mod points;
pub mod reference;

/// Reflectance of a texture with `_bouncecolorscale 0` (and of a texture without pixels).
pub const GREY_REFLECTANCE: f32 = 127.0 / 255.0;
/// ericw-tools' factor on `_bouncescale` for bounced light.
pub const KERNEL_SCALE: f64 = 0.5;
/// Distances below this count as this (ericw-tools' bounce hotspot clamp).
pub const HOTSPOT_CLAMP: f64 = 128.0;

/// Where reflecting faces send bounced light from (ericw-tools' `-emissivequality`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EmissiveQuality {
    /// One point in front of each face's middle ([`points`]).
    Low,
    /// That point and each corner ([`points`]).
    Medium,
    /// The whole surface: [`Field`]'s gather.
    High,
}

/// Light per style and luxel (row-major) of one face.
pub type StyleLuxels = Vec<(u8, Vec<[f32; 3]>)>;

/// Light per style at one point.
pub type StyleLight = Vec<(u8, [f32; 3])>;

/// Adds `light` in `style` to `sum`.
pub fn add_style_light(sum: &mut StyleLight, style: u8, light: [f32; 3]) {
    let to = crate::styles::entry(sum, style, || [0.0; 3]);
    to.iter_mut().zip(light).for_each(|(v, a)| *v += a);
}

/// Mean colour (0..1) of a texture's full-size mip through `palette`.
fn texture_mean(tex: &quake_formats::miptex::MipTex, palette: &Palette) -> Option<[f32; 3]> {
    let pixels = tex.mips.as_ref()?.first().filter(|p| !p.is_empty())?;
    let mut sum = [0u64; 3];
    for &i in pixels {
        for (s, c) in sum.iter_mut().zip(palette.colors[usize::from(i)]) {
            *s += u64::from(c);
        }
    }
    Some(sum.map(|s| (s as f64 / pixels.len() as f64 / 255.0) as f32))
}

/// Per face, what it reflects (`None`: nothing): faces with a lightmap that block light outright
/// (of the world and `_shadow 1` models; not shadowless faces, fences or switchable shadows)
/// and whose model has no `_bounce 0`. Sky and liquids reflect nothing. The colour is the
/// texture's mean colour blended with [`GREY_REFLECTANCE`] by `color_scale`; a texture without
/// pixels counts as grey.
pub fn face_reflectance(
    bsp: &Bsp,
    faces: &[FaceGeom],
    lights: &MapLights,
    palette: &Palette,
) -> Vec<Option<[f32; 3]>> {
    let means: Vec<Option<[f32; 3]>> = bsp
        .textures
        .textures
        .iter()
        .map(|t| t.as_ref().and_then(|t| texture_mean(t, palette)))
        .collect();
    let w = lights.bounce.color_scale as f32;
    faces
        .iter()
        .map(|f| {
            let in_scene = f.model == 0 || lights.shadow_models.contains(&f.model);
            let flags = lights.face_flags.get(f.index);
            let merged_no_bounce = flags.is_some_and(|m| m.no_bounce);
            // Only faces that block light outright reflect, as in ericw-tools: not those that
            // cast no shadow (`_shadow -1`, `func_detail_illusionary`), fences (whose texels
            // let light through) or switchable shadows.
            let solid_caster = !flags.is_some_and(|m| m.no_shadow)
                && !f.is_fence()
                && !lights.switchable.shadows.iter().any(|&(m, _)| m == f.model);
            // A face off the world's light channel reflects nothing, as in ericw-tools.
            if f.kind != FaceKind::Lit
                || !in_scene
                || !solid_caster
                || merged_no_bounce
                || lights.no_bounce_models.contains(&f.model)
                || lights.channels_of(f) != 1
            {
                return None;
            }
            let mean = bsp
                .faces
                .get(f.index)
                .and_then(|face| bsp.texinfo.get(face.texinfo as usize))
                .and_then(|ti| means.get(ti.miptex as usize).copied().flatten())
                .unwrap_or([GREY_REFLECTANCE; 3]);
            Some(mean.map(|m| GREY_REFLECTANCE + (m - GREY_REFLECTANCE) * w))
        })
        .collect()
}

/// How densely the fast method gathers: a receiver every `stride` luxels along each axis (and
/// at the last row and column), each casting `strata²` rays.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Density {
    /// Luxels between receivers along each axis.
    pub stride: usize,
    /// Rays per receiver along each axis of the stratified grid.
    pub strata: usize,
    /// A last step of at most half a stride widens the cell before it instead of adding a
    /// row or column of receivers: the default mode's trade.
    pub widen_last: bool,
    /// Receivers' values are smoothed by their neighbours before they
    /// are spread onto the luxels: few rays per receiver, noise averaged over several.
    pub smooth: bool,
}

impl Density {
    /// The density of each quality mode; the reference's later passes gather at every luxel.
    pub fn for_quality(quality: Quality) -> Density {
        match quality {
            // Few rays, smoothed over neighbouring receivers, have the error of more rays
            // unsmoothed (bench/results/light-bounce.md). Where noise is already low,
            // smoothing only adds its bias at corners, so the supersampled modes do not.
            Quality::Default => Density {
                stride: 2,
                strata: 6,
                widen_last: true,
                smooth: true,
            },
            Quality::Extra => Density {
                stride: 2,
                strata: 12,
                widen_last: false,
                smooth: false,
            },
            Quality::Extra4 => Density {
                stride: 2,
                strata: 12,
                widen_last: false,
                smooth: false,
            },
            Quality::Reference => Density {
                stride: 1,
                strata: 16,
                widen_last: false,
                smooth: false,
            },
        }
    }
}

/// A well-mixed 64-bit hash (splitmix64's finaliser).
fn mix(mut x: u64) -> u64 {
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// A number in [0, 1) from the bits of `bits`.
fn unit_of(bits: u64) -> f64 {
    (bits >> 11) as f64 / (1u64 << 53) as f64
}

/// A number in [0, 1) from `key`.
fn unit(key: u64) -> f64 {
    unit_of(mix(key))
}

/// Two numbers in [0, 1) from `key`.
fn jitter(key: u64) -> (f64, f64) {
    let h = mix(key);
    (unit_of(h), unit_of(mix(h ^ 0x9e37_79b9_7f4a_7c15)))
}

/// Sine and cosine of `turns` of a full turn (0 ≤ `turns` < 1), within 1e-10 of `sin_cos`:
/// the nearest quarter turn is exact, and what is left (at most π/4) takes a short series.
/// libm's `sincos` is a large share of what gathering spends outside Embree.
fn sin_cos_turns(turns: f64) -> (f64, f64) {
    debug_assert!((0.0..1.0).contains(&turns), "{turns}");
    let quarter = (turns * 4.0 + 0.5) as u32;
    let x = (turns - f64::from(quarter) * 0.25) * std::f64::consts::TAU;
    let x2 = x * x;
    // Horner forms of the Taylor series to x¹¹ and x¹² (the next terms are below 1e-11).
    let sin = x
        * (1.0
            - x2 / 6.0
                * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0 * (1.0 - x2 / 110.0)))));
    let cos = 1.0
        - x2 / 2.0
            * (1.0
                - x2 / 12.0
                    * (1.0
                        - x2 / 30.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0 * (1.0 - x2 / 132.0)))));
    match quarter % 4 {
        0 => (sin, cos),
        1 => (cos, -sin),
        2 => (-sin, -cos),
        _ => (-cos, sin),
    }
}

/// The jitter key of point `index` of `face` in `pass`: rays depend on nothing else (not on
/// threads or the order faces are gathered in).
pub fn point_key(face: usize, index: usize, pass: usize) -> u64 {
    mix(mix(mix(face as u64) ^ index as u64) ^ pass as u64)
}

/// Where one point gathers: its position, its face's normal (rays are spread around it) and its
/// shading normal (`_phong`; the face normal otherwise), and the key of its rays' jitter.
/// A two-sided point (a liquid's surface) takes light from both sides without a cosine of its
/// own, as ericw-tools' two-sided receivers do: its rays go over the whole sphere.
#[derive(Debug, Clone, Copy)]
pub struct GatherPoint {
    pub point: DVec3,
    pub flat: DVec3,
    pub shading: DVec3,
    pub key: u64,
    pub two_sided: bool,
}

impl GatherPoint {
    /// Ray `r` of `strata²`, in cell (`r / strata`, `r % strata`) of the unit square jittered by
    /// the point's key: cosine-distributed around the face normal, or uniform over the sphere
    /// for a two-sided point.
    fn ray(&self, basis: &[DVec3; 2], r: usize, strata: usize) -> DVec3 {
        let (j1, j2) = jitter(self.key.wrapping_add(r as u64));
        let u1 = ((r / strata) as f64 + j1) / strata as f64;
        let u2 = ((r % strata) as f64 + j2) / strata as f64;
        let (sin, cos) = sin_cos_turns(u2);
        let (across, along) = if self.two_sided {
            let z = 1.0 - 2.0 * u1;
            ((1.0 - z * z).max(0.0).sqrt(), z)
        } else {
            (u1.sqrt(), (1.0 - u1).sqrt())
        };
        basis[0] * (across * cos) + basis[1] * (across * sin) + self.flat * along
    }

    /// The solid angle each ray stands for, over the cosine the estimator divides out: π for
    /// cosine-distributed rays, 4π for the sphere's uniform ones.
    fn ray_measure(&self) -> f64 {
        if self.two_sided {
            4.0 * std::f64::consts::PI
        } else {
            std::f64::consts::PI
        }
    }
}

/// What reflecting surfaces give off: per face, its reflectance and its light per luxel.
pub struct Field<'a> {
    pub faces: &'a [FaceGeom],
    pub reflectance: &'a [Option<[f32; 3]>],
    /// Per face (by index): its light per style and luxel, when it has any.
    pub light: &'a [Option<StyleLuxels>],
    /// The kernel's constant factor: [`KERNEL_SCALE`] × `_bouncescale`.
    pub kernel: f64,
}

impl<'a> Field<'a> {
    /// What `faces` give off with `light`, reflecting as `reflectance` says, at `settings`' scale.
    pub fn new(
        faces: &'a [FaceGeom],
        reflectance: &'a [Option<[f32; 3]>],
        light: &'a [Option<StyleLuxels>],
        settings: &BounceSettings,
    ) -> Field<'a> {
        Field {
            faces,
            reflectance,
            light,
            kernel: KERNEL_SCALE * settings.scale,
        }
    }
}

/// The light of `face` at world point `q`, bilinear between the luxels of its grid.
fn light_at(face: &FaceGeom, luxels: &[[f32; 3]], q: DVec3) -> [f32; 3] {
    crate::resample::bilinear(
        luxels,
        face.grid.size,
        face.grid.luxel_at((q - face.origin).to_array()),
    )
}

/// Rays go no further than this.
const RAY_LENGTH: f32 = 65536.0;

impl Field<'_> {
    /// The light each of `points` receives, in its slot (of `n` per style):
    /// `strata²` cosine-distributed rays around the point's face normal, one per cell of a
    /// stratified grid jittered by the point's key. A ray that first meets the front of a
    /// reflecting face at `q` brings `π · kernel · ρ E(q) · min(1, d²/128²)` (times the
    /// shading/flat cosine ratio), over the number of rays: the model's integral with
    /// `dA = d² dω / cos θq`. A two-sided point's rays are uniform over the sphere and bring
    /// `4π · kernel · ρ E(q) · min(1, d²/128²)`. Rays go 16 to a packet whichever point they leave (a point's
    /// rays need not fill whole packets); each slot takes its rays in order, so the result
    /// does not depend on how they were packed.
    pub fn gather(
        &self,
        scene: &TraceScene,
        model: usize,
        points: &[(GatherPoint, usize)],
        strata: usize,
        n: usize,
        counts: &mut BounceCounts,
    ) -> StyleLuxels {
        let mut out = StyleLuxels::new();
        let rays = strata * strata;
        let scale = self.kernel / rays as f64;
        let mut packet = RayPacket16::new();
        // Per lane: its direction and the point it leaves.
        let mut lanes: Vec<(DVec3, usize)> = Vec::with_capacity(16);
        let all = points.iter().enumerate().flat_map(|(k, (at, _))| {
            let basis = tangent_basis(at.flat);
            (0..rays).map(move |r| (at.ray(&basis, r, strata), k))
        });
        for (dir, k) in all {
            packet.set(
                lanes.len(),
                points[k].0.point.as_vec3().to_array(),
                dir.as_vec3().to_array(),
                crate::trace::RAY_START,
                RAY_LENGTH,
            );
            lanes.push((dir, k));
            if lanes.len() == 16 {
                self.take_hits(
                    scene,
                    model,
                    &mut packet,
                    &lanes,
                    points,
                    scale,
                    &mut out,
                    n,
                );
                counts.rays += 16;
                packet.clear();
                lanes.clear();
            }
        }
        if !lanes.is_empty() {
            self.take_hits(
                scene,
                model,
                &mut packet,
                &lanes,
                points,
                scale,
                &mut out,
                n,
            );
            counts.rays += lanes.len() as u64;
        }
        out
    }

    /// Traces `packet` (its lanes leaving `points` in the directions of `lanes`) and adds what
    /// each ray brings to its point's slot of `out`.
    #[allow(clippy::too_many_arguments)]
    fn take_hits(
        &self,
        scene: &TraceScene,
        model: usize,
        packet: &mut RayPacket16,
        lanes: &[(DVec3, usize)],
        points: &[(GatherPoint, usize)],
        scale: f64,
        out: &mut StyleLuxels,
        n: usize,
    ) {
        let hits = scene.first_faces16(packet, model);
        for (&(dir, k), hit) in lanes.iter().zip(hits) {
            let Some((f, t)) = hit else {
                continue;
            };
            let (Some(face), Some(Some(rho)), Some(Some(light))) = (
                self.faces.get(f),
                self.reflectance.get(f),
                self.light.get(f),
            ) else {
                continue;
            };
            let (at, slot) = &points[k];
            if face.plane.normal.dot(dir) >= 0.0 {
                continue; // the back of a face
            }
            let cosines = if at.two_sided {
                1.0
            } else {
                let cos_flat = at.flat.dot(dir);
                if cos_flat <= 0.0 {
                    continue; // a grazing ray
                }
                at.shading.dot(dir).max(0.0) / cos_flat
            };
            let near = (f64::from(t) / HOTSPOT_CLAMP).min(1.0);
            let weight = scale * at.ray_measure() * cosines * near * near;
            let q = at.point + dir * f64::from(t);
            for (style, luxels) in light {
                let e = light_at(face, luxels, q);
                let flux = std::array::from_fn(|c| e[c] * rho[c]);
                add_light(out, n, &[*style], &[flux], *slot, weight);
            }
        }
    }

    /// Bounced light at each luxel of `r`, per style: gathered at a grid of receivers every
    /// `density.stride` luxels (and the last row and column), bilinear between them.
    pub fn gather_face(
        &self,
        scene: &TraceScene,
        r: &Receivers,
        pass: usize,
        density: Density,
        counts: &mut BounceCounts,
    ) -> StyleLuxels {
        let axis = |size| {
            if density.widen_last {
                receiver_grid(size, density.stride)
            } else {
                grid(size, density.stride)
            }
        };
        let (xs, ys) = (axis(r.width), axis(r.height));
        let cells = xs.len() * ys.len();
        let mut points = Vec::with_capacity(cells);
        for (gy, &y) in ys.iter().enumerate() {
            for (gx, &x) in xs.iter().enumerate() {
                let l = y * r.width + x;
                let at = GatherPoint {
                    point: Vec3::from(r.points[l]).as_dvec3(),
                    flat: r.normal,
                    shading: Vec3::from(r.normals[l]).as_dvec3(),
                    key: point_key(r.face, l, pass),
                    two_sided: r.two_sided,
                };
                points.push((at, gy * xs.len() + gx));
            }
        }
        let mut at_grid = self.gather(scene, r.model, &points, density.strata, cells, counts);
        if density.smooth {
            smooth_receivers(&mut at_grid, xs.len(), ys.len());
        }
        interpolate(&at_grid, &xs, &ys, r.width, r.height)
    }
}

/// Each value of a `w × h` receiver grid (per style) becomes the [1 2 1] / 4 weighted mean of
/// itself and its neighbours along each axis in turn (an edge counts its own value for the
/// missing neighbour): a plane's values stay as they are inside the grid, noise falls.
fn smooth_receivers(grid: &mut StyleLuxels, w: usize, h: usize) {
    let mut src = Vec::new();
    for (_, values) in grid.iter_mut() {
        for (dx, dy) in [(1, 0), (0, 1)] {
            src.clone_from(values);
            for y in 0..h {
                for x in 0..w {
                    let before = src[(y - dy.min(y)) * w + x - dx.min(x)];
                    let after = src[(y + dy).min(h - 1) * w + (x + dx).min(w - 1)];
                    let mid = src[y * w + x];
                    values[y * w + x] =
                        std::array::from_fn(|k| 0.25 * before[k] + 0.5 * mid[k] + 0.25 * after[k]);
                }
            }
        }
    }
}

/// `at_grid` (per style, `xs.len() × ys.len()` values) spread bilinearly onto `w × h` luxels.
fn interpolate(
    at_grid: &StyleLuxels,
    xs: &[usize],
    ys: &[usize],
    w: usize,
    h: usize,
) -> StyleLuxels {
    let (cx, cy) = (cell_of(xs), cell_of(ys));
    let gw = xs.len();
    at_grid
        .iter()
        .map(|(style, values)| {
            let v = |gx: usize, gy: usize| values[gy * gw + gx];
            let mut luxels = Vec::with_capacity(w * h);
            for &(y0, y1, fy) in cy.iter().take(h) {
                for &(x0, x1, fx) in cx.iter().take(w) {
                    let (a, b, c, d) = (v(x0, y0), v(x1, y0), v(x0, y1), v(x1, y1));
                    luxels.push(std::array::from_fn(|k| {
                        let top = a[k] + (b[k] - a[k]) * fx;
                        let bottom = c[k] + (d[k] - c[k]) * fx;
                        top + (bottom - top) * fy
                    }));
                }
            }
            (*style, luxels)
        })
        .collect()
}

/// Where a face receives bounced light: one point and shading normal per luxel.
#[derive(Debug, Clone)]
pub struct Receivers {
    pub face: usize,
    pub model: usize,
    pub width: usize,
    pub height: usize,
    /// The face's normal.
    pub normal: DVec3,
    /// It takes light from both sides (see [`GatherPoint`]).
    pub two_sided: bool,
    pub points: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
}

impl Receivers {
    /// One sample per luxel of `samples`: its middle one (the probe of supersampled faces).
    pub fn new(samples: &FaceSamples, face: &FaceGeom) -> Receivers {
        let indices = (0..samples.luxels()).map(|l| samples.middle_of(l));
        Receivers {
            face: samples.face,
            model: face.model,
            width: samples.width,
            height: samples.height,
            normal: samples.normal,
            two_sided: samples.two_sided,
            points: indices.clone().map(|i| samples.points[i]).collect(),
            normals: indices
                .map(|i| samples.normal_at(i).as_vec3().to_array())
                .collect(),
        }
    }
}

/// Work done gathering bounced light.
#[derive(Debug, Clone, Copy, Default)]
pub struct BounceCounts {
    pub rays: u64,
}

impl BounceCounts {
    pub fn add(&mut self, o: &BounceCounts) {
        self.rays += o.rays;
    }
}

/// Adds `weight × flux` (per style) to luxel `i` of `out` (`n` luxels per style).
pub fn add_light(
    out: &mut StyleLuxels,
    n: usize,
    styles: &[u8],
    flux: &[[f32; 3]],
    i: usize,
    weight: f64,
) {
    for (&style, f) in styles.iter().zip(flux) {
        let v = &mut style_luxels(out, style, n)[i];
        for k in 0..3 {
            v[k] += (weight * f64::from(f[k])) as f32;
        }
    }
}

/// `out`'s luxels of `style` (`n` of them), added dark if it has none yet.
pub fn style_luxels(out: &mut StyleLuxels, style: u8, n: usize) -> &mut [[f32; 3]] {
    crate::styles::entry(out, style, || vec![[0.0; 3]; n]).as_mut_slice()
}

/// Adds `b` into `a`, style by style.
pub fn accumulate(a: &mut StyleLuxels, b: &StyleLuxels) {
    for (style, values) in b {
        let dst = style_luxels(a, *style, values.len());
        for (d, v) in dst.iter_mut().zip(values) {
            for k in 0..3 {
                d[k] += v[k];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_mean_goes_through_the_palette() {
        let mut palette = Palette::slipgate();
        palette.colors[1] = [255, 0, 0];
        palette.colors[2] = [0, 0, 255];
        let tex =
            quake_formats::miptex::MipTex::new("t", 2, 1, [vec![1, 2], vec![1], vec![1], vec![1]]);
        assert_eq!(texture_mean(&tex, &palette), Some([0.5, 0.0, 0.5]));
    }

    #[test]
    fn sin_cos_turns_matches_the_library() {
        for k in 0..100_000 {
            let t = k as f64 / 100_000.0;
            let (s, c) = sin_cos_turns(t);
            let (es, ec) = (std::f64::consts::TAU * t).sin_cos();
            assert!(
                (s - es).abs() < 1e-10 && (c - ec).abs() < 1e-10,
                "{t}: {s} {c}"
            );
        }
    }

    #[test]
    fn smoothing_keeps_planes_inside_and_lowers_noise() {
        let (w, h) = (6, 5);
        let plane = |x: usize, y: usize| 3.0 * x as f32 - 2.0 * y as f32 + 40.0;
        let mut grid = vec![(0, (0..w * h).map(|i| [plane(i % w, i / w); 3]).collect())];
        smooth_receivers(&mut grid, w, h);
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                assert!((grid[0].1[y * w + x][0] - plane(x, y)).abs() < 1e-4);
            }
        }
        // Alternating +-1 noise (the worst case for one pass) vanishes inside.
        let mut noisy = vec![(
            0,
            (0..w * h)
                .map(|i| [if (i % w + i / w) % 2 == 0 { 1.0 } else { -1.0 }; 3])
                .collect(),
        )];
        smooth_receivers(&mut noisy, w, h);
        assert!(noisy[0].1[w + 1][0].abs() < 1e-6);
        // A single receiver grid (a one-luxel face) is left alone.
        let mut one = vec![(0, vec![[5.0; 3]])];
        smooth_receivers(&mut one, 1, 1);
        assert_eq!(one[0].1[0], [5.0; 3]);
    }

    #[test]
    fn jitter_is_in_the_unit_square_and_varies() {
        let a = jitter(1);
        let b = jitter(2);
        assert!((0.0..1.0).contains(&a.0) && (0.0..1.0).contains(&a.1));
        assert_ne!(a, b);
    }

    #[test]
    fn grid_keeps_the_last_row_and_interpolation_is_exact_on_planes() {
        assert_eq!(grid(9, 4), vec![0, 4, 8]);
        assert_eq!(grid(10, 4), vec![0, 4, 8, 9]);
        assert_eq!(grid(1, 4), vec![0]);
        let (w, h) = (10, 3);
        let (xs, ys) = (grid(w, 4), grid(h, 4));
        let plane = |x: usize, y: usize| 2.0 * x as f32 + 5.0 * y as f32 + 1.0;
        let values = ys
            .iter()
            .flat_map(|&y| xs.iter().map(move |&x| [plane(x, y); 3]))
            .collect();
        let out = interpolate(&vec![(0, values)], &xs, &ys, w, h);
        for y in 0..h {
            for x in 0..w {
                let v = out[0].1[y * w + x][0];
                assert!((v - plane(x, y)).abs() < 1e-4, "({x}, {y}): {v}");
            }
        }
    }
}
