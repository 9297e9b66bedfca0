//! Direct lighting of one face's sample points: every light that can reach
//! the face, traced in 16-ray packets (one light, 16 neighbouring samples:
//! coherent rays), then averaged down to luxels.

use quake_formats::Bsp;
use quake_formats::geom::{Bounds, Vec3};

use crate::dirt;
use crate::embree::RayPacket16;
use crate::faces::FaceGeom;
use crate::lights::{
    DirtResponse, DirtSampling, Falloff, Minlight, PointLight, SunLight, angle_factor,
};
use crate::samples::FaceSamples;
use crate::scene::TraceScene;
use crate::visibility::Visibility;

/// Shadow rays stop this far short of the light, so a light sitting right
/// on a surface is not blocked by it.
const LIGHT_CLEARANCE: f32 = 0.1;

/// Sub-cells per axis are chosen so each is no wider than this fraction of
/// the light's distance from the sample's square (see [`footprint_cells`]).
const CELL_PER_DISTANCE: f64 = 0.25;

/// How finely to average a light's unshadowed brightness over a sample's
/// square: 1 (the value at the sample point will do) unless the light is so
/// close that brightness changes a lot across the square, e.g. a surface
/// light 2 units above its own face, whose 1/x² peak a single point either
/// misses or sits on. `to_light` runs from the sample point to the light;
/// `radius` is the square's half-diagonal; `max_cells` per axis gives the
/// reference's 16x16 texel grid over a luxel.
fn footprint_cells(to_light: Vec3, normal: Vec3, radius: f64, max_cells: usize) -> usize {
    let height = to_light.dot(normal).abs();
    let across = (to_light.dot(to_light) - height * height).max(0.0).sqrt();
    let beyond = (across - radius).max(0.0);
    // Not `hypot`: this runs for every sample and light, and libm's hypot is slow.
    let nearest = (height * height + beyond * beyond).sqrt();
    if nearest >= radius / CELL_PER_DISTANCE {
        return 1;
    }
    let cells = radius / (CELL_PER_DISTANCE * nearest.max(1e-6));
    (cells.ceil() as usize).clamp(1, max_cells)
}

/// What `light` adds at `p` on a surface with unit `normal`, unshadowed.
fn unshadowed(light: &PointLight, p: Vec3, normal: Vec3) -> Option<(f64, Vec3, f64)> {
    let to_light = light.origin - p;
    let dist = to_light.length();
    let dir = to_light.normalized()?;
    Some((light.contribution(dist, -dir, normal.dot(dir)), dir, dist))
}

/// Adaptive supersampling of one close light: the mean of what `light` adds
/// over `cells x cells` points spread across sample `i`'s square, each with
/// its own shadow ray. A point that lands inside solid (the square reaching
/// into a fixture on the wall) counts as the sample point itself.
fn footprint_light(
    setup: &TraceSetup,
    samples: &FaceSamples,
    i: usize,
    cells: usize,
    light: &PointLight,
    packet: &mut RayPacket16,
    counts: &mut TraceCounts,
) -> f64 {
    let normal = samples.normal_at(i);
    let in_solid = |q: Vec3| {
        setup
            .bsp
            .leaf_at(q.to_f32())
            .and_then(|l| setup.bsp.leafs.get(l))
            .is_some_and(|l| l.contents == quake_formats::bsp::contents::SOLID)
    };
    let own = Vec3::from_f32(samples.points[i]);
    let points: Vec<Vec3> = samples
        .map
        .footprint_points(i, cells)
        .map(|q| if in_solid(q) { own } else { q })
        .collect();
    let mut lane_value = [0.0f64; 16];
    let mut sum = 0.0;
    for chunk in points.chunks(16) {
        packet.clear();
        for (lane, &q) in chunk.iter().enumerate() {
            let Some((value, dir, dist)) = unshadowed(light, q, normal) else {
                continue;
            };
            lane_value[lane] = value;
            let reach = (dist as f32 - LIGHT_CLEARANCE).max(0.0);
            packet.set(lane, q.to_f32(), dir.to_f32(), 0.0, reach);
        }
        let active = packet.active_mask();
        counts.shadow_rays += u64::from(active.count_ones());
        let lit = active & !setup.scene.occluded16(packet);
        sum += (0..16)
            .filter(|l| lit & (1 << l) != 0)
            .map(|l| lane_value[l])
            .sum::<f64>();
    }
    sum / points.len() as f64
}

/// Everything shared by all faces while tracing.
pub struct TraceSetup<'a> {
    pub bsp: &'a Bsp,
    pub faces: &'a [FaceGeom],
    pub scene: &'a TraceScene,
    pub vis: &'a Visibility,
    /// Entity lights and surface-light copies.
    pub lights: &'a [PointLight],
    /// World leaf of each light (None: in solid or outside; no PVS culling).
    pub light_leafs: &'a [Option<u32>],
    pub suns: &'a [SunLight],
    /// Skip lights that cannot reach a face (range, plane side, PVS, sky PVS).
    pub cull: bool,
    /// Contributions below this many light units count as zero.
    pub gate: f64,
    /// Length of sun rays (longer than the map's diagonal).
    pub sun_distance: f32,
    /// How to measure dirt; `None` when no light, sun or minlight takes dirt.
    pub dirt: Option<DirtSampling>,
}

/// What one face takes from the lights (set per brush model).
#[derive(Debug, Clone, Copy, Default)]
pub struct FaceRules<'a> {
    /// The floor for style 0 (none for a face its model's `_minlight_exclude` names).
    pub minlight: Option<&'a Minlight>,
    /// Dirt may darken this face (false for models with `_dirt -1`).
    pub dirt: bool,
    /// `_lightignore`: minlight only, no lights or suns.
    pub minlight_only: bool,
}

/// Per-luxel colour of each style a face receives, in light units.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceLight {
    pub face: usize,
    pub width: usize,
    pub height: usize,
    /// Style and its luxels (row-major), style 0 first.
    pub styles: Vec<(u8, Vec<[f32; 3]>)>,
}

/// Work done lighting one face.
#[derive(Debug, Clone, Copy, Default)]
pub struct TraceCounts {
    pub shadow_rays: u64,
    pub sun_rays: u64,
    pub dirt_rays: u64,
    /// Face/light pairs looked at, and how many of them culling skipped.
    pub pairs: u64,
    pub pairs_culled: u64,
}

impl TraceCounts {
    pub fn add(&mut self, o: &TraceCounts) {
        self.shadow_rays += o.shadow_rays;
        self.sun_rays += o.sun_rays;
        self.dirt_rays += o.dirt_rays;
        self.pairs += o.pairs;
        self.pairs_culled += o.pairs_culled;
    }

    pub fn rays(&self) -> u64 {
        self.shadow_rays + self.sun_rays + self.dirt_rays
    }
}

/// Per-sample buffers, one per style (style 0 always present and first).
struct StyleBuffers {
    len: usize,
    styles: Vec<(u8, Vec<[f32; 3]>)>,
}

impl StyleBuffers {
    fn new(len: usize) -> StyleBuffers {
        StyleBuffers {
            len,
            styles: vec![(0, vec![[0.0; 3]; len])],
        }
    }

    fn get(&mut self, style: u8) -> &mut Vec<[f32; 3]> {
        let i = match self.styles.iter().position(|(s, _)| *s == style) {
            Some(i) => i,
            None => {
                self.styles.push((style, vec![[0.0; 3]; self.len]));
                self.styles.len() - 1
            }
        };
        &mut self.styles[i].1
    }
}

fn sub(a: Vec3, b: [f32; 3]) -> Vec3 {
    a - Vec3::from_f32(b)
}

/// Distance from `p` to the box `b` (0 inside).
fn box_distance(b: &Bounds, p: Vec3) -> f64 {
    let mut d2 = 0.0;
    for axis in 0..3 {
        let excess = (b.mins[axis] - p[axis])
            .max(p[axis] - b.maxs[axis])
            .max(0.0);
        d2 += excess * excess;
    }
    d2.sqrt()
}

/// The dirt factor of `response` at sample `i` (1 without occlusion data).
fn dirt_factor(response: Option<DirtResponse>, occlusion: &[f32], i: usize) -> f64 {
    match (response, occlusion.get(i)) {
        (Some(r), Some(&occ)) => r.factor(f64::from(occ)),
        _ => 1.0,
    }
}

/// Adds `value` of `light` (its colour) to sample `i`, or for a local
/// minlight raises the sample's floor to it.
fn deposit(
    light: &PointLight,
    value: f64,
    i: usize,
    sums: &mut StyleBuffers,
    floors: &mut StyleBuffers,
) {
    let local_min = light.falloff == Falloff::LocalMin;
    let target = if local_min { floors } else { sums };
    let out = &mut target.get(light.style)[i];
    for (o, c) in out.iter_mut().zip(light.color.to_array()) {
        let add = (value * c) as f32;
        *o = if local_min { o.max(add) } else { *o + add };
    }
}

/// Lights one face's samples and averages them to luxels.
pub fn light_face(
    setup: &TraceSetup,
    samples: &FaceSamples,
    rules: &FaceRules,
) -> (FaceLight, TraceCounts) {
    let face = &setup.faces[samples.face];
    let n = samples.points.len();
    let mut counts = TraceCounts::default();
    let mut sums = StyleBuffers::new(n);
    // Local-minlight (delay 4) lights raise luxels to a floor instead of adding.
    let mut floors = StyleBuffers::new(n);
    let mut bounds = Bounds::EMPTY;
    for &p in &samples.points {
        bounds.add_point(Vec3::from_f32(p));
    }
    let occlusion = match setup.dirt.filter(|_| rules.dirt) {
        Some(sampling) => {
            let (values, rays) = dirt::occlusion(
                &samples.points,
                samples.normal,
                face.index,
                &sampling,
                setup.scene,
            );
            counts.dirt_rays += rays;
            values
        }
        None => Vec::new(),
    };
    let lights = if rules.minlight_only {
        &[][..]
    } else {
        setup.lights
    };
    let suns = if rules.minlight_only {
        &[][..]
    } else {
        setup.suns
    };

    let mut packet = RayPacket16::new();
    let mut lane_value = [0.0f64; 16];
    let radius = samples.map.footprint_radius();
    let max_cells = 16 / samples.per_axis.min(16);
    // Samples so close to the current light that it is averaged over their squares.
    let mut near: Vec<(usize, usize)> = Vec::new();
    for (li, light) in lights.iter().enumerate() {
        counts.pairs += 1;
        if setup.cull
            && (face.plane.distance(light.origin) <= 0.0
                || box_distance(&bounds, light.origin) > light.range(setup.gate)
                || !setup.vis.may_reach(setup.light_leafs[li], face.index))
        {
            counts.pairs_culled += 1;
            continue;
        }
        near.clear();
        for (chunk_index, chunk) in samples.points.chunks(16).enumerate() {
            let base = chunk_index * 16;
            packet.clear();
            for (lane, &p) in chunk.iter().enumerate() {
                let to_light = sub(light.origin, p);
                let dist = to_light.length();
                let Some(dir) = to_light.normalized() else {
                    continue;
                };
                let normal = samples.normal_at(base + lane);
                let dirt = dirt_factor(light.dirt, &occlusion, base + lane);
                let cells = footprint_cells(to_light, samples.normal, radius, max_cells);
                if cells > 1 {
                    // Traced on its own below, point by point over the square.
                    near.push((base + lane, cells));
                    continue;
                }
                let value = light.contribution(dist, -dir, normal.dot(dir)) * dirt;
                if value.abs() < setup.gate {
                    continue;
                }
                lane_value[lane] = value;
                let reach = (dist as f32 - LIGHT_CLEARANCE).max(0.0);
                packet.set(lane, p, dir.to_f32(), 0.0, reach);
            }
            let active = packet.active_mask();
            if active == 0 {
                continue;
            }
            counts.shadow_rays += u64::from(active.count_ones());
            let lit = active & !setup.scene.occluded16(&mut packet);
            for lane in (0..16).filter(|l| lit & (1 << l) != 0) {
                deposit(light, lane_value[lane], base + lane, &mut sums, &mut floors);
            }
        }
        for &(i, cells) in &near {
            let v = footprint_light(setup, samples, i, cells, light, &mut packet, &mut counts)
                * dirt_factor(light.dirt, &occlusion, i);
            deposit(light, v, i, &mut sums, &mut floors);
        }
    }

    if !setup.cull || setup.vis.may_see_sky(face.index) {
        for sun in suns {
            let dir = sun.to_sun.to_f32();
            let target = sums.get(sun.style);
            for (chunk_index, chunk) in samples.points.chunks(16).enumerate() {
                let base = chunk_index * 16;
                packet.clear();
                for (lane, &p) in chunk.iter().enumerate() {
                    let cos = samples.normal_at(base + lane).dot(sun.to_sun);
                    let value = sun.light
                        * angle_factor(cos, sun.anglescale)
                        * dirt_factor(sun.dirt, &occlusion, base + lane);
                    if value.abs() < setup.gate {
                        continue;
                    }
                    lane_value[lane] = value;
                    packet.set(lane, p, dir, 0.0, setup.sun_distance);
                }
                let active = packet.active_mask();
                if active == 0 {
                    continue;
                }
                counts.sun_rays += u64::from(active.count_ones());
                let lit = setup.scene.sees_sky16(&mut packet);
                for lane in (0..16).filter(|l| lit & (1 << l) != 0) {
                    let v = lane_value[lane];
                    for (out, c) in target[base + lane].iter_mut().zip(sun.color.to_array()) {
                        *out += (v * c) as f32;
                    }
                }
            }
        }
    }

    if let Some(m) = rules.minlight {
        let floor = floors.get(0);
        for (i, f) in floor.iter_mut().enumerate() {
            let level = m.level * dirt_factor(m.dirt, &occlusion, i);
            for (out, c) in f.iter_mut().zip(m.color.to_array()) {
                *out = out.max((level * c) as f32);
            }
        }
    }
    for (style, floor) in &floors.styles {
        let sum = sums.get(*style);
        for (s, f) in sum.iter_mut().zip(floor) {
            for c in 0..3 {
                s[c] = s[c].max(f[c]);
            }
        }
    }

    let per = samples.per_luxel();
    let styles = sums
        .styles
        .into_iter()
        .map(|(style, values)| {
            let luxels = values
                .chunks(per)
                .map(|c| {
                    let mut acc = [0.0f32; 3];
                    for v in c {
                        for k in 0..3 {
                            acc[k] += v[k];
                        }
                    }
                    acc.map(|a| a / per as f32)
                })
                .collect();
            (style, luxels)
        })
        .collect();
    (
        FaceLight {
            face: samples.face,
            width: samples.width,
            height: samples.height,
            styles,
        },
        counts,
    )
}
