//! Direct lighting of one face's sample points: every light that can reach
//! the face, traced in 16-ray packets (one light, 16 neighbouring samples:
//! coherent rays), then averaged down to luxels.

use quake_formats::Bsp;
use quake_formats::geom::{Bounds, Vec3};

use crate::embree::RayPacket16;
use crate::faces::FaceGeom;
use crate::lights::{Falloff, PointLight, SunLight, angle_factor};
use crate::samples::FaceSamples;
use crate::scene::TraceScene;
use crate::visibility::Visibility;

/// Shadow rays stop this far short of the light, so a light sitting right
/// on a surface is not blocked by it.
const LIGHT_CLEARANCE: f32 = 0.1;

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
    /// Face/light pairs looked at, and how many of them culling skipped.
    pub pairs: u64,
    pub pairs_culled: u64,
}

impl TraceCounts {
    pub fn add(&mut self, o: &TraceCounts) {
        self.shadow_rays += o.shadow_rays;
        self.sun_rays += o.sun_rays;
        self.pairs += o.pairs;
        self.pairs_culled += o.pairs_culled;
    }

    pub fn rays(&self) -> u64 {
        self.shadow_rays + self.sun_rays
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

/// Lights one face's samples and averages them to luxels.
pub fn light_face(setup: &TraceSetup, samples: &FaceSamples) -> (FaceLight, TraceCounts) {
    let face = &setup.faces[samples.face];
    let normal = samples.normal;
    let n = samples.points.len();
    let mut counts = TraceCounts::default();
    let mut sums = StyleBuffers::new(n);
    // Local-minlight (delay 4) lights raise luxels to a floor instead of adding.
    let mut floors = StyleBuffers::new(n);
    let mut bounds = Bounds::EMPTY;
    for &p in &samples.points {
        bounds.add_point(Vec3::from_f32(p));
    }

    let mut packet = RayPacket16::new();
    let mut lane_value = [0.0f64; 16];
    for (li, light) in setup.lights.iter().enumerate() {
        counts.pairs += 1;
        if setup.cull
            && (face.plane.distance(light.origin) <= 0.0
                || box_distance(&bounds, light.origin) > light.range(setup.gate)
                || !setup.vis.may_reach(setup.light_leafs[li], face.index))
        {
            counts.pairs_culled += 1;
            continue;
        }
        let color = light.color;
        for (chunk_index, chunk) in samples.points.chunks(16).enumerate() {
            packet.clear();
            for (lane, &p) in chunk.iter().enumerate() {
                let to_light = sub(light.origin, p);
                let dist = to_light.length();
                let Some(dir) = to_light.normalized() else {
                    continue;
                };
                let value = light.contribution(dist, -dir, normal.dot(dir));
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
            let base = chunk_index * 16;
            let target = if light.falloff == Falloff::LocalMin {
                floors.get(light.style)
            } else {
                sums.get(light.style)
            };
            for lane in (0..16).filter(|l| lit & (1 << l) != 0) {
                let v = lane_value[lane];
                let out = &mut target[base + lane];
                for c in 0..3 {
                    let add = (v * color[c]) as f32;
                    if light.falloff == Falloff::LocalMin {
                        out[c] = out[c].max(add);
                    } else {
                        out[c] += add;
                    }
                }
            }
        }
    }

    if !setup.cull || setup.vis.may_see_sky(face.index) {
        for sun in setup.suns {
            let cos = normal.dot(sun.to_sun);
            let value = sun.light * angle_factor(cos, sun.anglescale);
            if value.abs() < setup.gate {
                continue;
            }
            let dir = sun.to_sun.to_f32();
            let target = sums.get(sun.style);
            for (chunk_index, chunk) in samples.points.chunks(16).enumerate() {
                packet.clear();
                for (lane, &p) in chunk.iter().enumerate() {
                    packet.set(lane, p, dir, 0.0, setup.sun_distance);
                }
                counts.sun_rays += chunk.len() as u64;
                let lit = setup.scene.sees_sky16(&mut packet);
                let base = chunk_index * 16;
                let add = [0, 1, 2].map(|c| (value * sun.color[c]) as f32);
                for lane in (0..16).filter(|l| lit & (1 << l) != 0) {
                    for (out, a) in target[base + lane].iter_mut().zip(add) {
                        *out += a;
                    }
                }
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
