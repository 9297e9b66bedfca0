//! Diffuse interreflection ("bounce"), with ericw-tools' keys and brightness.
//!
//! The model (what `--reference` computes exactly, see [`reference`]): after direct light, a
//! point `q` of a reflecting face gives off `B(q) = ρ · E(q)`, its direct light `E` (lights and
//! suns; not minlight, not `_bounce 0` lights) times the face's reflectance `ρ` (the texture's
//! mean colour blended with grey by `_bouncecolorscale`). A point `p` receives
//! `scale · ∫ B(q) cosθq cosθp / max(|p − q|, 128)² dA` over every reflecting surface it sees,
//! with `scale` = 0.5 × `_bouncescale`: ericw-tools' bounce kernel (its 128-unit hotspot clamp
//! and factor 0.5), integrated over the surfaces instead of taken at one point per face. Each
//! further pass reflects the light the previous pass brought.
//!
//! The fast method: each reflecting face's lightmap is diced into blocks of
//! [`BLOCK_LUXELS`]² luxels (64 units, ericw-tools' dicing size), each a point emitter with the
//! block's flux (luxel light × the part of the luxel inside the face). A receiving face takes
//! from the faces its leaves' PVS holds, that face it and that it faces; faces whose bound on
//! what they could bring is smallest are dropped while the bounds dropped add up to at most
//! [`CULL_BUDGET_LEVELS`] of a grey level. A face that is small against its distance is gathered
//! from as one point; the others block by block. One shadow ray per luxel and emitter, 16
//! luxels to a packet.

use quake_formats::Bsp;
use quake_formats::bsp::limits::LIGHTMAP_SCALE;
use quake_formats::geom::{Bounds, Plane, Vec3, Winding};
use quake_formats::palette::Palette;

use crate::embree::RayPacket16;
use crate::faces::{FaceGeom, FaceKind};
use crate::lights::{DirtResponse, MapLights};
use crate::samples::FaceSamples;
use crate::scene::TraceScene;
use crate::visibility::Visibility;

pub mod reference;

/// Passes beyond this bring nothing a lightmap byte can show.
pub const MAX_BOUNCE_PASSES: usize = 16;
/// Reflectance of a texture with `_bouncecolorscale 0` (and of a texture without pixels).
pub const GREY_REFLECTANCE: f32 = 127.0 / 255.0;
/// ericw-tools' factor on `_bouncescale` for bounced light.
pub const KERNEL_SCALE: f64 = 0.5;
/// Distances below this count as this (ericw-tools' bounce hotspot clamp).
pub const HOTSPOT_CLAMP: f64 = 128.0;
/// Emitter points stand this far in front of their face.
const EMITTER_LIFT: f64 = 1.0;
/// Luxels along each side of an emitter block.
pub const BLOCK_LUXELS: usize = 4;
/// A face no wider (half-diagonal) than this fraction of its clamped distance from a receiving
/// face is gathered from as one point. Blocks (half-diagonal 45 units) never need splitting:
/// the kernel is flat within the 128-unit clamp.
const ONE_POINT_RATIO: f64 = 1.0;
/// Grey levels (at gamma 1) that culling may take from any luxel, at most.
pub const CULL_BUDGET_LEVELS: f64 = 0.5;
/// A shadow ray is skipped when what it could bring is below this many light units.
const RAY_GATE: f64 = 1e-4;
/// Bounce is measured at every this many luxels along each axis, and between where it is smooth.
pub const GRID_STRIDE: usize = 4;
/// Grey levels (at gamma 1) by which the corners of a grid cell may differ for the luxels
/// inside to be interpolated.
pub const SMOOTH_LEVELS: f64 = 2.0;

/// Worldspawn `_bounce` and its keys (and their command-line overrides).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BounceSettings {
    /// Passes (0 = off).
    pub passes: usize,
    /// `_bouncescale`.
    pub scale: f64,
    /// `_bouncecolorscale`: 0 = grey reflectance, 1 = the texture's mean colour.
    pub color_scale: f64,
    /// `_bouncestyled`: styled (switchable, animated) light bounces too, in its own style.
    pub styled: bool,
    /// How dirt darkens bounced light (worldspawn's dirt, when it is on).
    pub dirt: Option<DirtResponse>,
}

impl Default for BounceSettings {
    fn default() -> Self {
        BounceSettings {
            passes: 0,
            scale: 1.0,
            color_scale: 0.0,
            styled: false,
            dirt: None,
        }
    }
}

impl BounceSettings {
    pub fn is_on(&self) -> bool {
        self.passes > 0 && self.scale > 0.0
    }

    /// The kernel's constant factor.
    pub fn kernel(&self) -> f64 {
        KERNEL_SCALE * self.scale
    }
}

/// Light per style and luxel (row-major) of one face.
pub type StyleLuxels = Vec<(u8, Vec<[f32; 3]>)>;

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

/// Per face, what it reflects (`None`: nothing): faces with a lightmap that are in the shadow
/// scene (the world and `_shadow 1` models) and whose model has no `_bounce 0`. Sky and liquids
/// reflect nothing. The colour is the texture's mean colour blended with
/// [`GREY_REFLECTANCE`] by `color_scale`; a texture without pixels counts as grey.
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
            if f.kind != FaceKind::Lit || !in_scene || lights.no_bounce_models.contains(&f.model) {
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

/// Area and centroid of a convex polygon.
fn area_centroid(points: &[Vec3]) -> (f64, Vec3) {
    let Some(&first) = points.first() else {
        return (0.0, Vec3::ZERO);
    };
    let mut area = 0.0;
    let mut sum = Vec3::ZERO;
    for pair in points[1..].windows(2) {
        let a = (pair[0] - first).cross(pair[1] - first).length() / 2.0;
        area += a;
        sum += (first + pair[0] + pair[1]) * (a / 3.0);
    }
    if area > 0.0 {
        (area, sum / area)
    } else {
        (0.0, first)
    }
}

/// The part of `face` whose texture coordinates lie in `[s0, s1] x [t0, t1]`.
fn clip_to_st(face: &FaceGeom, s: [f64; 2], t: [f64; 2]) -> Option<Winding> {
    let mut w = Some(Winding::new(face.points.clone()));
    for (axis, range) in [(0, s), (1, t)] {
        let v = face.vecs[axis];
        let dir = Vec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
        let len = dir.length();
        if len == 0.0 {
            return None;
        }
        // World point p has coordinate dir · (p − origin) + v[3].
        let offset = f64::from(v[3]) - dir.dot(face.origin);
        let n = dir / len;
        let keep_above = Plane::new(n, (range[0] - offset) / len);
        let keep_below = Plane::new(-n, -(range[1] - offset) / len);
        w = w
            .and_then(|w| w.clip_front(&keep_above, false))
            .and_then(|w| w.clip_front(&keep_below, false));
    }
    w
}

/// One block of an emitter: a point and the luxels whose light it carries.
#[derive(Debug, Clone)]
struct Block {
    point: Vec3,
    /// Luxel index and the area of the luxel inside the face.
    luxels: Vec<(u32, f32)>,
}

/// A reflecting face diced into blocks of its lightmap.
#[derive(Debug, Clone)]
pub struct EmitterGeom {
    pub face: usize,
    normal: Vec3,
    plane: Plane,
    /// Bounds of the face's points.
    bounds: Bounds,
    /// The area-weighted centre, lifted.
    point: Vec3,
    /// Half the bounds' diagonal.
    radius: f64,
    blocks: Vec<Block>,
}

impl EmitterGeom {
    /// `None` for a face with no area.
    pub fn new(face: &FaceGeom) -> Option<EmitterGeom> {
        let [w, h] = face.extents.luxel_size();
        let half = f64::from(LIGHTMAP_SCALE) / 2.0;
        let lift = face.plane.normal * EMITTER_LIFT;
        let mut blocks = Vec::new();
        let (mut total, mut moment) = (0.0, Vec3::ZERO);
        for by in (0..h).step_by(BLOCK_LUXELS) {
            for bx in (0..w).step_by(BLOCK_LUXELS) {
                let (mut area, mut sum) = (0.0, Vec3::ZERO);
                let mut luxels = Vec::new();
                for y in by..(by + BLOCK_LUXELS).min(h) {
                    for x in bx..(bx + BLOCK_LUXELS).min(w) {
                        let [s, t] = face.extents.luxel_st(x, y);
                        let piece = clip_to_st(face, [s - half, s + half], [t - half, t + half]);
                        let (a, c) = piece.map_or((0.0, Vec3::ZERO), |p| area_centroid(&p.points));
                        if a > 0.0 {
                            luxels.push(((y * w + x) as u32, a as f32));
                            area += a;
                            sum += c * a;
                        }
                    }
                }
                if area > 0.0 {
                    total += area;
                    moment += sum;
                    blocks.push(Block {
                        point: sum / area + lift,
                        luxels,
                    });
                }
            }
        }
        if total <= 0.0 {
            return None;
        }
        let mut bounds = Bounds::EMPTY;
        for &p in &face.points {
            bounds.add_point(p);
        }
        Some(EmitterGeom {
            face: face.index,
            normal: face.plane.normal,
            plane: face.plane,
            bounds,
            point: moment / total + lift,
            radius: (bounds.maxs - bounds.mins).length() / 2.0,
            blocks,
        })
    }
}

/// What one emitter gives off in one pass: flux (light × area × reflectance) per style, per
/// block and in total.
#[derive(Debug, Clone)]
pub struct Emission {
    styles: Vec<u8>,
    /// `[block][style]`.
    blocks: Vec<Vec<[f32; 3]>>,
    total: Vec<[f32; 3]>,
    /// Sum over styles of the brightest channel of `total`.
    bound: f64,
}

impl Emission {
    /// `None` when the face gives off nothing.
    pub fn new(geom: &EmitterGeom, reflectance: [f32; 3], light: &StyleLuxels) -> Option<Emission> {
        let styles: Vec<u8> = light.iter().map(|(s, _)| *s).collect();
        let blocks: Vec<Vec<[f32; 3]>> = geom
            .blocks
            .iter()
            .map(|b| {
                light
                    .iter()
                    .map(|(_, luxels)| {
                        let mut flux = [0.0f32; 3];
                        for &(l, area) in &b.luxels {
                            let v = luxels.get(l as usize).copied().unwrap_or_default();
                            for k in 0..3 {
                                flux[k] += v[k] * area * reflectance[k];
                            }
                        }
                        flux
                    })
                    .collect()
            })
            .collect();
        let mut total = vec![[0.0f32; 3]; styles.len()];
        for b in &blocks {
            for (t, f) in total.iter_mut().zip(b) {
                for k in 0..3 {
                    t[k] += f[k];
                }
            }
        }
        let bound: f64 = total
            .iter()
            .map(|t| f64::from(t[0].max(t[1]).max(t[2])))
            .sum();
        (bound > 0.0).then_some(Emission {
            styles,
            blocks,
            total,
            bound,
        })
    }
}

/// Where a face receives bounced light: one point and normal per luxel.
#[derive(Debug, Clone)]
pub struct Receivers {
    pub face: usize,
    pub model: usize,
    pub width: usize,
    pub height: usize,
    pub points: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    plane: Plane,
    bounds: Bounds,
}

impl Receivers {
    /// One sample per luxel of `samples`: its middle one (the probe of supersampled faces).
    pub fn new(samples: &FaceSamples, face: &FaceGeom) -> Receivers {
        let axis = samples.per_axis;
        let pick = (axis / 2) * axis + axis / 2;
        let per = samples.per_luxel();
        let indices = (0..samples.luxels()).map(|l| l * per + pick);
        let points: Vec<[f32; 3]> = indices.clone().map(|i| samples.points[i]).collect();
        let normals = indices.map(|i| samples.normal_at(i).to_f32()).collect();
        let mut bounds = Bounds::EMPTY;
        for &p in &points {
            bounds.add_point(Vec3::from_f32(p));
        }
        Receivers {
            face: samples.face,
            model: face.model,
            width: samples.width,
            height: samples.height,
            points,
            normals,
            plane: face.plane,
            bounds,
        }
    }
}

/// Squared distance between two boxes (0 when they touch).
fn box_gap_squared(a: &Bounds, b: &Bounds) -> f64 {
    (0..3)
        .map(|i| {
            let gap = (a.mins[i] - b.maxs[i]).max(b.mins[i] - a.maxs[i]).max(0.0);
            gap * gap
        })
        .sum()
}

/// True if some corner of `b` is in front of `plane`.
fn in_front(plane: &Plane, b: &Bounds) -> bool {
    (0..8).any(|c| {
        let p = Vec3::new(
            if c & 1 == 0 { b.mins.x } else { b.maxs.x },
            if c & 2 == 0 { b.mins.y } else { b.maxs.y },
            if c & 4 == 0 { b.mins.z } else { b.maxs.z },
        );
        plane.distance(p) > 0.0
    })
}

/// Work done gathering bounced light.
#[derive(Debug, Clone, Copy, Default)]
pub struct BounceCounts {
    pub rays: u64,
    /// Receiving face / emitting face pairs considered, and those culled by PVS or facing, and
    /// by energy.
    pub pairs: u64,
    pub pairs_culled: u64,
    pub pairs_energy_culled: u64,
}

impl BounceCounts {
    pub fn add(&mut self, o: &BounceCounts) {
        self.rays += o.rays;
        self.pairs += o.pairs;
        self.pairs_culled += o.pairs_culled;
        self.pairs_energy_culled += o.pairs_energy_culled;
    }
}

/// Everything a pass of gathering reads.
pub struct Gather<'a> {
    pub scene: &'a TraceScene,
    pub vis: &'a Visibility,
    pub emitters: &'a [EmitterGeom],
    /// This pass's emission of each emitter (same order).
    pub emission: &'a [Option<Emission>],
    /// [`BounceSettings::kernel`].
    pub kernel: f64,
    /// Light units culling may drop per luxel.
    pub budget: f64,
    /// Light units by which a grid cell's corners may differ for its inside to be interpolated.
    pub smooth: f64,
    /// No culling (the reference's passes).
    pub cull: bool,
}

/// One point emitter: where, facing which way, and its flux per style.
struct Element<'a> {
    point: Vec3,
    normal: Vec3,
    flux: &'a [[f32; 3]],
    styles: &'a [u8],
}

impl Gather<'_> {
    /// The emitters `r` takes light from, as point elements, nearest-to-cull last.
    fn elements(&self, r: &Receivers, counts: &mut BounceCounts) -> Vec<Element<'_>> {
        let seen = if self.cull {
            self.vis.leaves_seen_from(r.face)
        } else {
            None
        };
        let mut candidates: Vec<(f64, usize, f64)> = Vec::new();
        for (i, (em, emission)) in self.emitters.iter().zip(self.emission).enumerate() {
            let Some(emission) = emission else {
                continue;
            };
            if em.face == r.face {
                continue;
            }
            counts.pairs += 1;
            let visible = seen.as_ref().is_none_or(|s| self.vis.face_in(s, em.face));
            if !visible || !in_front(&em.plane, &r.bounds) || !in_front(&r.plane, &em.bounds) {
                counts.pairs_culled += 1;
                continue;
            }
            let gap = box_gap_squared(&r.bounds, &em.bounds).sqrt();
            let clamped = gap.max(HOTSPOT_CLAMP);
            candidates.push((self.kernel * emission.bound / (clamped * clamped), i, gap));
        }
        if self.cull {
            // The faces that could bring least go first, while together they stay in budget.
            candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let mut dropped = 0.0;
            let keep_from = candidates
                .iter()
                .position(|c| {
                    dropped += c.0;
                    dropped > self.budget
                })
                .unwrap_or(candidates.len());
            counts.pairs_energy_culled += keep_from as u64;
            candidates.drain(..keep_from);
        }
        let mut elements = Vec::new();
        for (_, i, gap) in candidates {
            let (em, Some(emission)) = (&self.emitters[i], &self.emission[i]) else {
                continue;
            };
            if !self.cull || em.radius > ONE_POINT_RATIO * gap.max(HOTSPOT_CLAMP) {
                for (b, flux) in em.blocks.iter().zip(&emission.blocks) {
                    elements.push(Element {
                        point: b.point,
                        normal: em.normal,
                        flux,
                        styles: &emission.styles,
                    });
                }
            } else {
                elements.push(Element {
                    point: em.point,
                    normal: em.normal,
                    flux: &emission.total,
                    styles: &emission.styles,
                });
            }
        }
        elements
    }

    /// Bounced light at each luxel of `r`, per style: measured on a grid of every
    /// [`GRID_STRIDE`]th luxel (and the last row and column), interpolated bilinearly inside a
    /// grid cell whose corners differ by at most `smooth` light units, measured elsewhere.
    pub fn face(&self, r: &Receivers, counts: &mut BounceCounts) -> StyleLuxels {
        let elements = self.elements(r, counts);
        let n = r.points.len();
        let mut out: StyleLuxels = Vec::new();
        let (w, h) = (r.width, r.height);
        let grid = |size: usize| {
            let mut at: Vec<usize> = (0..size).step_by(GRID_STRIDE).collect();
            if at.last() != Some(&(size - 1)) {
                at.push(size - 1);
            }
            at
        };
        let (xs, ys) = (grid(w), grid(h));
        let corners: Vec<usize> = ys
            .iter()
            .flat_map(|&y| xs.iter().map(move |&x| y * w + x))
            .collect();
        self.measure(r, &elements, &corners, &mut out, counts);
        let mut known = vec![false; n];
        for &i in &corners {
            known[i] = true;
        }
        let cells = |at: &[usize]| -> Vec<(usize, usize)> {
            if at.len() == 1 {
                vec![(at[0], at[0])]
            } else {
                at.windows(2).map(|p| (p[0], p[1])).collect()
            }
        };
        let mut rest = Vec::new();
        for &(y0, y1) in &cells(&ys) {
            for &(x0, x1) in &cells(&xs) {
                let c = [y0 * w + x0, y0 * w + x1, y1 * w + x0, y1 * w + x1];
                let smooth = out.iter().all(|(_, v)| {
                    (0..3).all(|k| {
                        let vals = c.map(|i| v[i][k]);
                        let lo = vals.iter().copied().fold(f32::INFINITY, f32::min);
                        let hi = vals.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                        f64::from(hi - lo) <= self.smooth
                    })
                });
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let i = y * w + x;
                        if known[i] {
                            continue;
                        }
                        known[i] = true;
                        if !smooth {
                            rest.push(i);
                            continue;
                        }
                        let fx = if x1 > x0 {
                            (x - x0) as f32 / (x1 - x0) as f32
                        } else {
                            0.0
                        };
                        let fy = if y1 > y0 {
                            (y - y0) as f32 / (y1 - y0) as f32
                        } else {
                            0.0
                        };
                        for (_, v) in out.iter_mut() {
                            let [a, b, cc, d] = c.map(|k| v[k]);
                            v[i] = std::array::from_fn(|k| {
                                let top = a[k] + (b[k] - a[k]) * fx;
                                let bottom = cc[k] + (d[k] - cc[k]) * fx;
                                top + (bottom - top) * fy
                            });
                        }
                    }
                }
            }
        }
        self.measure(r, &elements, &rest, &mut out, counts);
        out
    }

    /// Gathers from `elements` at the luxels `which` of `r`, adding into `out`.
    fn measure(
        &self,
        r: &Receivers,
        elements: &[Element],
        which: &[usize],
        out: &mut StyleLuxels,
        counts: &mut BounceCounts,
    ) {
        let n = r.points.len();
        let mut packet = RayPacket16::new();
        let mut lane_sample = [0usize; 16];
        let mut lane_weight = [0.0f64; 16];
        for e in elements {
            let brightest = e
                .flux
                .iter()
                .map(|f| f64::from(f[0].max(f[1]).max(f[2])))
                .fold(0.0, f64::max);
            let mut lanes = 0;
            for (k, &i) in which.iter().enumerate() {
                let p = Vec3::from_f32(r.points[i]);
                let to = e.point - p;
                let d = to.length();
                let normal = Vec3::from_f32(r.normals[i]);
                let (cos_r, cos_e) = (normal.dot(to) / d, -e.normal.dot(to) / d);
                let clamped = d.max(HOTSPOT_CLAMP);
                let weight = self.kernel * cos_r * cos_e / (clamped * clamped);
                if d > 0.0 && cos_r > 0.0 && cos_e > 0.0 && weight * brightest >= RAY_GATE {
                    packet.set(lanes, p.to_f32(), (to / d).to_f32(), 0.0, d as f32);
                    lane_sample[lanes] = i;
                    lane_weight[lanes] = weight;
                    lanes += 1;
                }
                if lanes == 0 || (lanes < 16 && k + 1 < which.len()) {
                    continue;
                }
                let active = packet.active_mask();
                counts.rays += u64::from(active.count_ones());
                let through = active & !self.scene.occluded16(&mut packet, r.model);
                for lane in (0..lanes).filter(|l| through & (1 << l) != 0) {
                    add_light(
                        out,
                        n,
                        e.styles,
                        e.flux,
                        lane_sample[lane],
                        lane_weight[lane],
                    );
                }
                packet.clear();
                lanes = 0;
            }
        }
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
        let slot = match out.iter().position(|(s, _)| *s == style) {
            Some(k) => k,
            None => {
                out.push((style, vec![[0.0; 3]; n]));
                out.len() - 1
            }
        };
        let v = &mut out[slot].1[i];
        for k in 0..3 {
            v[k] += (weight * f64::from(f[k])) as f32;
        }
    }
}

/// Adds `b` into `a`, style by style.
pub fn accumulate(a: &mut StyleLuxels, b: &StyleLuxels) {
    for (style, values) in b {
        match a.iter_mut().find(|(s, _)| s == style) {
            Some((_, dst)) => {
                for (d, v) in dst.iter_mut().zip(values) {
                    for k in 0..3 {
                        d[k] += v[k];
                    }
                }
            }
            None => a.push((*style, values.clone())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_and_centroid_of_a_square() {
        let sq = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(4.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let (a, c) = area_centroid(&sq);
        assert!((a - 8.0).abs() < 1e-12);
        assert!(c.near(Vec3::new(2.0, 1.0, 0.0), 1e-12));
    }

    #[test]
    fn texture_mean_goes_through_the_palette() {
        let mut palette = Palette::slipgate();
        palette.colors[1] = [255, 0, 0];
        palette.colors[2] = [0, 0, 255];
        let tex =
            quake_formats::miptex::MipTex::new("t", 2, 1, [vec![1, 2], vec![1], vec![1], vec![1]]);
        assert_eq!(texture_mean(&tex, &palette), Some([0.5, 0.0, 0.5]));
    }
}
