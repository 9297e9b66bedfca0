//! Direct lighting of one face's sample points: every light that can reach
//! the face, traced in 16-ray packets (one light, 16 neighbouring samples:
//! coherent rays), then averaged down to luxels.

use glam::{DVec3, Vec3};
use quake_formats::Bsp;
use quake_formats::geom::Bounds;
use quake_formats::geom::DVec3Ext;

use crate::dirt::{DirtFactors, DirtNeed, DirtResponse, DirtSampling, FaceDirt, face_occlusion};
use crate::embree::RayPacket16;
use crate::faces::FaceGeom;
use crate::grid::SampleGrid;
use crate::lights::{Falloff, Minlight, PointLight, SunLight, angle_factor};
use crate::reach::{LightReaches, box_distance_squared};
use crate::samples::{FaceSamples, WalkStart, solid_points_from};
use crate::scene::TraceScene;
use crate::visibility::Visibility;

/// Shadow rays stop this far short of the light, so a light sitting right
/// on a surface is not blocked by it.
const LIGHT_CLEARANCE: f32 = 0.1;

/// With supersampling, sub-cells per axis are chosen so each is no wider than
/// this fraction of the light's distance from the sample's square (see
/// [`Footprints`]).
const CELL_PER_DISTANCE: f64 = 0.25;

/// [`CELL_PER_DISTANCE`] in the default mode (one sample per luxel), whose
/// error against the reference is dominated by that one sample: a quarter cast
/// 33 % more shadow rays on ericw-tools' BSP of e1m1, for an RMSE 0.09 lower on
/// our BSPs of e1m1 and retrojam1 and 0.08 higher on e3m4 (light/README.md,
/// "Close lights").
const CELL_PER_DISTANCE_ONE_SAMPLE: f64 = 1.0;

/// How finely a light's unshadowed brightness is averaged over a sample's
/// square: 1 (the value at the sample point will do) unless the light is so
/// close that brightness changes a lot across the square, e.g. a surface
/// light 2 units above its own face, whose 1/x² peak a single point either
/// misses or sits on.
#[derive(Debug, Clone, Copy)]
struct FootprintRule {
    /// Cells are no wider than this fraction of the light's distance.
    cell_per_distance: f64,
    /// Most cells per axis: the reference's 16x16 texel grid over a luxel.
    max_cells: usize,
}

impl FootprintRule {
    fn for_samples(per_axis: usize) -> FootprintRule {
        FootprintRule {
            cell_per_distance: if per_axis == 1 {
                CELL_PER_DISTANCE_ONE_SAMPLE
            } else {
                CELL_PER_DISTANCE
            },
            max_cells: 16 / per_axis.clamp(1, 16),
        }
    }

    /// Cells per axis for a light at `to_light` from the sample point, over a
    /// square of half-diagonal `radius`.
    fn cells(self, to_light: DVec3, normal: DVec3, radius: f64) -> usize {
        let height = to_light.dot(normal).abs();
        let across = (to_light.dot(to_light) - height * height).max(0.0).sqrt();
        let beyond = (across - radius).max(0.0);
        // Not `hypot`: this runs for every sample and light, and libm's hypot is slow.
        let nearest = (height * height + beyond * beyond).sqrt();
        if nearest >= radius / self.cell_per_distance {
            return 1;
        }
        let cells = radius / (self.cell_per_distance * nearest.max(1e-6));
        (cells.ceil() as usize).clamp(1, self.max_cells)
    }

    /// Distance from a sample point beyond which a light is one cell away from
    /// the sample's square of half-diagonal `radius`: [`FootprintRule::cells`]'
    /// nearest distance is at least the point's distance less `radius`.
    fn surely_far(self, radius: f64) -> f64 {
        radius * (1.0 + 1.0 / self.cell_per_distance) * (1.0 + FOOTPRINT_FAR_MARGIN)
            + FOOTPRINT_FAR_MARGIN
    }
}

/// Relative and absolute margin by which a light must lie beyond
/// [`FootprintRule::surely_far`] before [`FootprintRule::cells`] is skipped:
/// covers the rounding of its own sums.
const FOOTPRINT_FAR_MARGIN: f64 = 1e-9;

/// What `light` adds at `p` on a surface with unit `normal`, unshadowed.
fn unshadowed(light: &PointLight, p: DVec3, normal: DVec3) -> Option<(f64, DVec3, f64)> {
    let to_light = light.origin - p;
    let dist = to_light.length();
    let dir = to_light.normalized()?;
    Some((light.contribution(dist, -dir, normal.dot(dir)), dir, dist))
}

/// A ray's origin, direction and length.
type ShadowRay = ([f32; 3], [f32; 3], f32);

/// Adaptive supersampling of close lights: a sample so close to a light
/// that its value changes a lot across the sample's square takes the mean
/// of what the light adds over `cells x cells` points spread across it,
/// each with its own shadow ray. A point that lands inside solid (the square
/// reaching into a fixture on the wall) counts as the sample point itself.
/// The points of all of one light's footprints on a face share packets
/// (most footprints have fewer than 16 points).
#[derive(Debug, Default)]
struct Footprints {
    /// Per footprint: its sample and its range in `values` and `lit`.
    spans: Vec<(usize, std::ops::Range<usize>)>,
    /// Per point: what the light adds unshadowed (0 at the light itself).
    values: Vec<f64>,
    /// Per point: its shadow ray (origin, direction, length), if it has one.
    rays: Vec<Option<ShadowRay>>,
    /// Per point: its shadow ray got through.
    lit: Vec<bool>,
    /// Per sample (sized at the face's first footprint): the cell count and
    /// range in `points` of its placed points (inside solid: moved onto the
    /// sample), so a sample close to several lights with the same cell
    /// count (the copies of a surface light) places its points once.
    placed: Vec<Option<(usize, std::ops::Range<usize>)>>,
    points: Vec<DVec3>,
    at: Vec<[f32; 3]>,
    /// Where the face's points part ways in the world BSP, found at the
    /// first footprint (the inner None: the BSP has no world model).
    walk_start: Option<Option<WalkStart>>,
}

impl Footprints {
    /// Forgets the last face's placed points.
    fn start_face(&mut self) {
        self.clear();
        self.placed.clear();
        self.points.clear();
        self.walk_start = None;
    }

    fn clear(&mut self) {
        self.spans.clear();
        self.values.clear();
        self.rays.clear();
    }

    /// Places sample `i`'s `cells x cells` points at the end of `points`.
    fn place(
        &mut self,
        bsp: &Bsp,
        samples: &FaceSamples,
        i: usize,
        cells: usize,
    ) -> std::ops::Range<usize> {
        let own = Vec3::from(samples.points[i]).as_dvec3();
        let first = self.points.len();
        self.points.extend(samples.map.footprint_points(i, cells));
        self.at.clear();
        self.at
            .extend(self.points[first..].iter().map(|q| q.as_vec3().to_array()));
        let start = self.walk_start.get_or_insert_with(|| {
            let (lo, hi) = samples.map.bounds();
            WalkStart::for_box(bsp, lo, hi)
        });
        let solid = match start {
            Some(start) => solid_points_from(bsp, start, &self.at),
            None => vec![false; self.at.len()],
        };
        for (q, solid) in self.points[first..].iter_mut().zip(solid) {
            if solid {
                *q = own;
            }
        }
        first..self.points.len()
    }

    /// Adds sample `i`'s `cells x cells` points and their rays to `light`.
    fn add(
        &mut self,
        bsp: &Bsp,
        samples: &FaceSamples,
        i: usize,
        cells: usize,
        light: &PointLight,
    ) {
        let normal = samples.normal_at(i);
        if self.placed.is_empty() {
            self.placed.resize(samples.points.len(), None);
        }
        let placed = match &self.placed[i] {
            Some((c, placed)) if *c == cells => placed.clone(),
            _ => {
                let placed = self.place(bsp, samples, i, cells);
                self.placed[i] = Some((cells, placed.clone()));
                placed
            }
        };
        let first = self.values.len();
        for &q in &self.points[placed] {
            let Some((value, dir, dist)) = unshadowed(light, q, normal) else {
                self.values.push(0.0);
                self.rays.push(None);
                continue;
            };
            let reach = (dist as f32 - LIGHT_CLEARANCE).max(0.0);
            self.values.push(value);
            self.rays.push(Some((
                q.as_vec3().to_array(),
                dir.as_vec3().to_array(),
                reach,
            )));
        }
        self.spans.push((i, first..self.values.len()));
    }

    /// Traces every point's ray, 16 to a packet; returns the rays cast.
    fn trace(&mut self, scene: &TraceScene, model: usize, packet: &mut RayPacket16) -> u64 {
        self.lit.clear();
        self.lit.resize(self.values.len(), false);
        let with_ray: Vec<usize> = (0..self.rays.len())
            .filter(|&k| self.rays[k].is_some())
            .collect();
        let mut rays = 0;
        for chunk in with_ray.chunks(16) {
            packet.clear();
            for (lane, &k) in chunk.iter().enumerate() {
                if let Some((org, dir, reach)) = self.rays[k] {
                    packet.set(lane, org, dir, 0.0, reach);
                }
            }
            let active = packet.active_mask();
            rays += u64::from(active.count_ones());
            let lit = active & !scene.occluded16(packet, model);
            for (lane, &k) in chunk.iter().enumerate() {
                self.lit[k] = lit & (1 << lane) != 0;
            }
        }
        rays
    }

    /// Per footprint in the order added: its sample and mean value. Sums
    /// go 16 points at a time, as one footprint's own packets would.
    fn means(&self) -> impl Iterator<Item = (usize, f64)> + Clone + '_ {
        self.spans.iter().map(|(i, span)| {
            let values = &self.values[span.clone()];
            let lit = &self.lit[span.clone()];
            let mut sum = 0.0;
            for (v, l) in values.chunks(16).zip(lit.chunks(16)) {
                sum += v
                    .iter()
                    .zip(l)
                    .filter(|(_, l)| **l)
                    .map(|(v, _)| *v)
                    .sum::<f64>();
            }
            (*i, sum / values.len() as f64)
        })
    }
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
    /// Each light's cut-off, from [`light_reaches`] with `gate`.
    pub light_reaches: &'a LightReaches,
    pub suns: &'a [SunLight],
    /// Skip lights that cannot reach a face (range, plane side, PVS, sky PVS).
    pub cull: bool,
    /// Contributions below this many light units count as zero.
    pub gate: f64,
    /// Length of sun rays (longer than the map's diagonal).
    pub sun_distance: f32,
    /// How to measure dirt; `None` when no light, sun or minlight takes dirt.
    pub dirt: Option<DirtSampling>,
    /// Supersampled faces trace sub-samples only where luxels disagree
    /// (see `VisibilityScratch::trace`); off for the reference.
    pub adaptive: bool,
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
    /// Bounced light will be added and darkened by dirt this way: dirt is
    /// then measured at every sample (bounce reaches where lights do not).
    pub bounce_dirt: Option<DirtResponse>,
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
#[derive(Debug)]
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

fn sub(a: DVec3, b: [f32; 3]) -> DVec3 {
    a - Vec3::from(b).as_dvec3()
}

/// Sky faces closer to a box's edge than this still count as reachable
/// (sample points and rays are f32).
const SKY_BOX_MARGIN: f64 = 1.0;

/// For each box in `sky`, the offsets `q - p` from a point `p` in `samples`
/// to a point `q` in it (the box `sky - samples`, a little wider): a sun
/// ray from a sample can only meet that sky if its direction meets this box.
fn sky_offsets(sky: &[Bounds], samples: &Bounds) -> Vec<Bounds> {
    let margin = DVec3::new(SKY_BOX_MARGIN, SKY_BOX_MARGIN, SKY_BOX_MARGIN);
    sky.iter()
        .map(|b| Bounds {
            mins: b.mins - samples.maxs - margin,
            maxs: b.maxs - samples.mins + margin,
        })
        .collect()
}

/// Whether the ray from the origin along `d` meets any of `boxes`.
fn direction_meets_any(boxes: &[Bounds], d: DVec3) -> bool {
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

/// What a luxel's probe ray (one sub-sample per luxel) found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Probe {
    /// The probe sample takes nothing from this light (gated, close, off the cone).
    Missing,
    Reaches,
    Blocked,
}

/// Buffers for [`VisibilityScratch::trace`], reused across a face's lights.
#[derive(Debug, Default)]
struct VisibilityScratch {
    /// Per sample: its ray reaches the light (meaningful where `value != 0`).
    lit: Vec<bool>,
    /// Per sample: the first sample at the same point, whose ray stands for both.
    first_at: Vec<usize>,
    /// Per sample: its ray was traced for the current light.
    traced: Vec<bool>,
    todo: Vec<usize>,
    unique: Vec<usize>,
    probes: Vec<Probe>,
}

impl VisibilityScratch {
    /// Ready for a face whose samples' first-at-the-same-point map is `first_at`.
    fn start_face(&mut self, first_at: Vec<usize>) {
        self.first_at = first_at;
    }

    /// Clears what the last light left for a face of `n` samples.
    fn start_light(&mut self, n: usize) {
        self.lit.clear();
        self.lit.resize(n, false);
        self.traced.clear();
        self.traced.resize(n, false);
        self.todo.clear();
    }

    /// Fills `lit` for every sample with a non-zero `value`; returns the
    /// rays cast. `ray(i)` is sample `i`'s (origin, direction, length) and
    /// `reaches` the lanes of a packet whose rays get through.
    ///
    /// `adaptive` (supersampled faces only): first one probe ray per luxel;
    /// a luxel whose probe agrees with the probes of all 8 neighbours takes
    /// that answer for all its sub-samples, the others (penumbrae, shadow
    /// edges, spots where a probe had no ray) trace every sub-sample. A
    /// straight shadow edge through a luxel always separates its probe from
    /// a neighbour's; only shadows thinner than a luxel can slip between.
    /// Moved samples (see [`FaceSamples::moved`]) are always traced.
    fn trace(
        &mut self,
        samples: &FaceSamples,
        adaptive: bool,
        value: &[f64],
        ray: impl Fn(usize) -> ([f32; 3], [f32; 3], f32),
        packet: &mut RayPacket16,
        mut reaches: impl FnMut(&mut RayPacket16) -> u16,
    ) -> u64 {
        let n = value.len();
        self.start_light(n);
        let per = samples.per_luxel();
        if !adaptive || per == 1 {
            self.todo.extend((0..n).filter(|&i| value[i] != 0.0));
            return self.cast(&ray, packet, &mut reaches);
        }
        let axis = samples.per_axis;
        let probe_sub = (axis / 2) * axis + axis / 2;
        let luxels = samples.luxels();
        self.todo.extend(
            (0..luxels)
                .map(|l| l * per + probe_sub)
                .filter(|&i| value[i] != 0.0),
        );
        let mut rays = self.cast(&ray, packet, &mut reaches);
        self.probes.clear();
        self.probes.extend((0..luxels).map(|l| {
            let i = l * per + probe_sub;
            match (value[i] != 0.0, self.lit[i]) {
                (false, _) => Probe::Missing,
                (true, true) => Probe::Reaches,
                (true, false) => Probe::Blocked,
            }
        }));
        self.todo.clear();
        let (w, h) = (samples.width, samples.height);
        for l in 0..luxels {
            let (x, y) = (l % w, l / w);
            let probe = self.probes[l];
            let uniform = !samples.moved[l * per + probe_sub]
                && probe != Probe::Missing
                && (y.saturating_sub(1)..(y + 2).min(h)).all(|ny| {
                    (x.saturating_sub(1)..(x + 2).min(w))
                        .all(|nx| self.probes[ny * w + nx] == probe)
                });
            let first = l * per;
            for (i, &v) in value.iter().enumerate().skip(first).take(per) {
                if v == 0.0 || i == first + probe_sub {
                    continue;
                }
                // Moved points (the luxel overhangs the face, or something
                // rests on it) are off the grid the neighbour test assumes.
                if uniform && !samples.moved[i] {
                    self.lit[i] = probe == Probe::Reaches;
                } else {
                    self.todo.push(i);
                }
            }
        }
        rays += self.cast(&ray, packet, &mut reaches);
        rays
    }

    /// [`VisibilityScratch::trace`] for one of many directions of a sun or
    /// dome, one sample per luxel (the default mode): probes first, at the
    /// positions of `grid` (every [`SUN_PROBE_STRIDE`]-th luxel along each axis
    /// and the last row and column); a luxel between them that was not pulled
    /// back ([`FaceSamples::pulled`]) takes the answer of its cell's probes
    /// when all of them got through or all were blocked; the others are
    /// traced. A shadow narrower than the cell can slip between the probes,
    /// but each direction carries at most 1 / [`SUN_PROBE_DIRECTIONS`] of its
    /// source's light.
    fn trace_probed(
        &mut self,
        samples: &FaceSamples,
        grid: &SampleGrid,
        value: &[f64],
        ray: impl Fn(usize) -> ([f32; 3], [f32; 3], f32),
        packet: &mut RayPacket16,
        mut reaches: impl FnMut(&mut RayPacket16) -> u16,
    ) -> u64 {
        debug_assert_eq!(samples.per_axis, 1);
        let n = value.len();
        self.start_light(n);
        let w = samples.width;
        let probe = |i: usize| value[i] != 0.0 && !samples.pulled[i];
        for &y in &grid.ys {
            self.todo.extend(
                grid.xs
                    .iter()
                    .map(|&x| y * w + x)
                    .filter(|&i| value[i] != 0.0),
            );
        }
        let mut rays = self.cast(&ray, packet, &mut reaches);
        self.todo.clear();
        for i in (0..n).filter(|&i| value[i] != 0.0) {
            let (corners, _, _) = grid.cell(i % w, i / w);
            if corners[0] == (i % w, i / w) {
                continue; // a probe
            }
            let corners = corners.map(|(x, y)| y * w + x);
            let agreed = !samples.pulled[i]
                && corners.iter().all(|&c| probe(c))
                && corners.iter().all(|&c| self.lit[c] == self.lit[corners[0]]);
            if agreed {
                self.lit[i] = self.lit[corners[0]];
            } else {
                self.todo.push(i);
            }
        }
        rays += self.cast(&ray, packet, &mut reaches);
        rays
    }

    /// Traces the samples in `todo`, 16 to a packet, into `lit`; a sample
    /// at the same point as one already traced takes its answer.
    fn cast(
        &mut self,
        ray: &impl Fn(usize) -> ([f32; 3], [f32; 3], f32),
        packet: &mut RayPacket16,
        reaches: &mut impl FnMut(&mut RayPacket16) -> u16,
    ) -> u64 {
        self.unique.clear();
        for &i in &self.todo {
            let first = self.first_at[i];
            if !self.traced[first] {
                self.traced[first] = true;
                self.unique.push(first);
            }
        }
        let mut rays = 0;
        for chunk in self.unique.chunks(16) {
            packet.clear();
            for (lane, &i) in chunk.iter().enumerate() {
                let (org, dir, reach) = ray(i);
                packet.set(lane, org, dir, 0.0, reach);
            }
            let active = packet.active_mask();
            if active == 0 {
                continue;
            }
            rays += u64::from(active.count_ones());
            let through = active & reaches(packet);
            for (lane, &i) in chunk.iter().enumerate() {
                self.lit[i] = through & (1 << lane) != 0;
            }
        }
        for &i in &self.todo {
            self.lit[i] = self.lit[self.first_at[i]];
        }
        rays
    }
}

/// Where light arriving at a sample comes from.
#[derive(Debug, Clone, Copy)]
enum Source {
    Light(usize),
    Sun(usize),
}

/// Light that reached a sample (its shadow ray got through), before dirt.
#[derive(Debug, Clone, Copy)]
struct Arrival {
    source: Source,
    sample: u32,
    value: f64,
    /// The source takes dirt on this face.
    dirty: bool,
    /// Dropped when below the gate once dirt is applied (not for
    /// close-light squares, which are kept whatever their value).
    gated: bool,
}

impl Arrival {
    fn new(source: Source, sample: usize, value: f64, dirty: bool, gated: bool) -> Arrival {
        Arrival {
            source,
            sample: sample as u32,
            value,
            dirty,
            gated,
        }
    }
}

/// Where a face's arrivals go. With dirt measured they wait (dirt is measured
/// after the shadow rays, only where some light that takes it arrives); without,
/// they go straight into the sums, in the same order and so to the same sums
/// (a gated arrival is above the gate already: nothing darkens it).
#[derive(Debug, Default)]
struct Arrivals {
    waiting: Vec<Arrival>,
    wait: bool,
}

impl Arrivals {
    fn start_face(&mut self, wait: bool) {
        self.waiting.clear();
        self.wait = wait;
    }

    fn add(&mut self, a: Arrival, lights: &[PointLight], suns: &[SunLight], out: &mut SampleLight) {
        if self.wait {
            self.waiting.push(a);
        } else {
            settle(&a, a.value, lights, suns, out);
        }
    }

    /// [`Arrivals::add`] for light `li` arriving at each `(sample, value)` of `arrived`, in
    /// one go when nothing waits.
    fn add_light(
        &mut self,
        li: usize,
        light: &PointLight,
        arrived: impl Iterator<Item = (usize, f64)> + Clone,
        (dirty, gated): (bool, bool),
        out: &mut SampleLight,
    ) {
        if self.wait {
            self.waiting
                .extend(arrived.map(|(i, v)| Arrival::new(Source::Light(li), i, v, dirty, gated)));
        } else {
            deposit(light, arrived, out);
        }
    }
}

/// Adds arrival `a` to `out` at `value` (its value after dirt).
fn settle(
    a: &Arrival,
    value: f64,
    lights: &[PointLight],
    suns: &[SunLight],
    out: &mut SampleLight,
) {
    let i = a.sample as usize;
    match a.source {
        Source::Light(li) => deposit(&lights[li], std::iter::once((i, value)), out),
        Source::Sun(si) => {
            let sun = &suns[si];
            let slot = &mut out.sums.get(sun.style)[i];
            for (o, c) in slot.iter_mut().zip(sun.color.to_array()) {
                *o += (value * c) as f32;
            }
        }
    }
}

/// Adds `value` of `light` (its colour) to sample `i` for each `(i, value)`
/// of `arrived`, or for a local minlight raises the sample's floor to it.
/// Light of a `_bounce 0` light is also kept in `no_bounce`, so it can be
/// taken out of what reflects.
fn deposit(
    light: &PointLight,
    arrived: impl Iterator<Item = (usize, f64)> + Clone,
    out: &mut SampleLight,
) {
    let local_min = light.falloff == Falloff::LocalMin;
    let color = light.color.to_array();
    let target = if local_min {
        &mut out.floors
    } else {
        &mut out.sums
    };
    let buffer = target.get(light.style);
    for (i, value) in arrived.clone() {
        for (o, c) in buffer[i].iter_mut().zip(color) {
            let add = (value * c) as f32;
            *o = if local_min { o.max(add) } else { *o + add };
        }
    }
    if !local_min && !light.bounce {
        let len = out.sums.len;
        let kept = out.no_bounce.get_or_insert_with(|| StyleBuffers::new(len));
        let buffer = kept.get(light.style);
        for (i, value) in arrived {
            for (o, c) in buffer[i].iter_mut().zip(color) {
                *o += (value * c) as f32;
            }
        }
    }
}

/// A face's light per sample before minlight floors are applied, so that
/// bounced light can still be added (floors apply to the sum).
#[derive(Debug)]
pub struct SampleLight {
    pub face: usize,
    pub width: usize,
    pub height: usize,
    per_luxel: usize,
    sums: StyleBuffers,
    floors: StyleBuffers,
    /// `--addmin` minlight of style 0, added when finishing (it does not bounce).
    added_minlight: Option<Vec<[f32; 3]>>,
    /// The part of `sums` from `_bounce 0` lights.
    no_bounce: Option<StyleBuffers>,
    /// Per sample, the dirt factor of bounced light (empty: none).
    bounce_dirt: Vec<f32>,
}

/// Luxel means of per-sample values, `per` samples to a luxel (one sample to a luxel, as in
/// the default mode: the values themselves, not copied).
fn luxel_means(values: Vec<[f32; 3]>, per: usize) -> Vec<[f32; 3]> {
    if per == 1 {
        return values;
    }
    values
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
        .collect()
}

impl SampleLight {
    /// Per style, the luxel means of the light that reflects: lights and
    /// suns without minlight or `_bounce 0` lights; style 0 only unless
    /// `styled`. Styles with no light are left out.
    pub fn reflected(&self, styled: bool) -> Vec<(u8, Vec<[f32; 3]>)> {
        let mut out = Vec::new();
        for (style, values) in &self.sums.styles {
            if *style != 0 && !styled {
                continue;
            }
            let mut values = values.clone();
            if let Some(no) = &self.no_bounce
                && let Some((_, minus)) = no.styles.iter().find(|(s, _)| s == style)
            {
                for (v, m) in values.iter_mut().zip(minus) {
                    for k in 0..3 {
                        v[k] = (v[k] - m[k]).max(0.0);
                    }
                }
            }
            if values.iter().any(|v| v.iter().any(|&c| c > 0.0)) {
                out.push((*style, luxel_means(values, self.per_luxel)));
            }
        }
        out
    }

    /// Adds `bounce` (per style, per luxel (given to each of the luxel's
    /// samples) or per sample, times each sample's dirt factor), applies
    /// minlight and the floors, and averages samples to luxels.
    pub fn finish(mut self, bounce: &[(u8, Vec<[f32; 3]>)]) -> FaceLight {
        let per = self.per_luxel;
        if let Some(min) = &self.added_minlight {
            for (s, m) in self.sums.get(0).iter_mut().zip(min) {
                for k in 0..3 {
                    s[k] += m[k];
                }
            }
        }
        for (style, luxels) in bounce {
            let dirt = &self.bounce_dirt;
            let sums = self.sums.get(*style);
            let step = if luxels.len() == sums.len() { 1 } else { per };
            for (i, s) in sums.iter_mut().enumerate() {
                let Some(b) = luxels.get(i / step) else {
                    continue;
                };
                let f = dirt.get(i).copied().unwrap_or(1.0);
                for k in 0..3 {
                    s[k] += b[k] * f;
                }
            }
        }
        for (style, floor) in &self.floors.styles {
            let sum = self.sums.get(*style);
            for (s, f) in sum.iter_mut().zip(floor) {
                for c in 0..3 {
                    s[c] = s[c].max(f[c]);
                }
            }
        }
        let styles = self
            .sums
            .styles
            .into_iter()
            .map(|(style, values)| (style, luxel_means(values, per)))
            .collect();
        FaceLight {
            face: self.face,
            width: self.width,
            height: self.height,
            styles,
        }
    }
}

/// Lights one face's samples and averages them to luxels.
pub fn light_face(
    setup: &TraceSetup,
    samples: &FaceSamples,
    rules: &FaceRules,
) -> (FaceLight, TraceCounts) {
    let (light, counts) = trace_face(setup, samples, rules, &mut TraceScratch::default());
    (light.finish(&[]), counts)
}

/// Working buffers of [`trace_face`] that one thread keeps from face to face: allocating
/// and growing them per face cost about 3 % of e1m1's instructions.
#[derive(Debug, Default)]
pub struct TraceScratch {
    arrivals: Arrivals,
    value: Vec<f64>,
    /// Samples so close to the current light that it is averaged over their squares.
    near: Vec<(usize, usize)>,
    /// Per sample: the direction and length of its shadow ray to the current light.
    to_light: Vec<([f32; 3], f32)>,
    /// The lights that may reach the face ([`LightReaches::near`]).
    near_lights: Vec<u32>,
    footprints: Footprints,
    visibility: VisibilityScratch,
}

/// Lights one face's samples: the light per sample, before floors.
pub fn trace_face(
    setup: &TraceSetup,
    samples: &FaceSamples,
    rules: &FaceRules,
    reuse: &mut TraceScratch,
) -> (SampleLight, TraceCounts) {
    let face = &setup.faces[samples.face];
    let n = samples.points.len();
    let mut counts = TraceCounts::default();
    let mut out = SampleLight {
        face: samples.face,
        width: samples.width,
        height: samples.height,
        per_luxel: samples.per_luxel(),
        sums: StyleBuffers::new(n),
        // Local-minlight (delay 4) lights raise luxels to a floor instead of adding.
        floors: StyleBuffers::new(n),
        added_minlight: None,
        no_bounce: None,
        bounce_dirt: Vec::new(),
    };
    let mut bounds = Bounds::EMPTY;
    for &p in &samples.points {
        bounds.add_point(Vec3::from(p).as_dvec3());
    }
    // Dirt is measured after the shadow rays, only where some light that
    // takes it arrives (half of e3m4's luxels are dark).
    let dirt_sampling = setup.dirt.filter(|_| rules.dirt);
    let takes_dirt = |r: Option<DirtResponse>| r.is_some() && dirt_sampling.is_some();
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
    let TraceScratch {
        arrivals,
        value,
        near,
        to_light: shadow_rays,
        near_lights,
        footprints,
        visibility: scratch,
    } = reuse;
    scratch.start_face(samples.first_at_same_point());
    arrivals.start_face(dirt_sampling.is_some());
    value.clear();
    value.resize(n, 0.0);
    footprints.start_face();
    let radius = samples.map.footprint_radius();
    let footprint = FootprintRule::for_samples(samples.per_axis);
    let surely_far = footprint.surely_far(radius);
    shadow_rays.resize(n, ([0.0; 3], 0.0));
    // Only the lights whose reach may touch the samples' box (all of them without culling).
    near_lights.clear();
    if setup.cull && !lights.is_empty() {
        setup.light_reaches.near(&bounds, near_lights);
    } else {
        near_lights.extend(0..lights.len() as u32);
    }
    counts.pairs += lights.len() as u64;
    counts.pairs_culled += (lights.len() - near_lights.len()) as u64;
    for li in near_lights.iter().map(|&li| li as usize) {
        let light = &lights[li];
        let reach = &setup.light_reaches[li];
        // A light behind the plane of a `_phong` face can still be in front of the smoothed
        // normals of some of its samples: only flat faces are culled by their plane.
        let behind = samples.normals.is_empty() && face.plane.distance(reach.origin) <= 0.0;
        if setup.cull
            && (behind
                || box_distance_squared(&bounds, reach.origin) > reach.range_squared
                || !setup.vis.may_reach(setup.light_leafs[li], face.index))
        {
            counts.pairs_culled += 1;
            continue;
        }
        near.clear();
        for (i, &p) in samples.points.iter().enumerate() {
            value[i] = 0.0;
            let to_light = sub(light.origin, p);
            // One square root per sample and light.
            let Some((dist, dir)) = to_light.length_and_direction() else {
                continue;
            };
            let cells = if dist >= surely_far {
                1
            } else {
                footprint.cells(to_light, samples.normal, radius)
            };
            if cells > 1 {
                // Traced on its own below, point by point over the square.
                near.push((i, cells));
                continue;
            }
            // Kept whatever the value: a sample whose `_phong` normal turns from the light may
            // be the first at a point whose others need the ray.
            shadow_rays[i] = (
                dir.as_vec3().to_array(),
                (dist as f32 - LIGHT_CLEARANCE).max(0.0),
            );
            let v = light.contribution(dist, -dir, samples.normal_at(i).dot(dir));
            if v.abs() >= setup.gate {
                value[i] = v;
            }
        }
        let ray = |i: usize| {
            let (dir, length) = shadow_rays[i];
            (samples.points[i], dir, length)
        };
        counts.shadow_rays +=
            scratch.trace(samples, setup.adaptive, value, ray, &mut packet, |p| {
                !setup.scene.occluded16(p, face.model)
            });
        let dirty = takes_dirt(light.dirt);
        let lit = &scratch.lit;
        let arrived = (0..n).filter(|&i| lit[i]).map(|i| (i, value[i]));
        arrivals.add_light(li, light, arrived, (dirty, true), &mut out);
        if !near.is_empty() {
            footprints.clear();
            for &(i, cells) in near.iter() {
                footprints.add(setup.bsp, samples, i, cells, light);
            }
            counts.shadow_rays += footprints.trace(setup.scene, face.model, &mut packet);
            arrivals.add_light(li, light, footprints.means(), (dirty, false), &mut out);
        }
    }

    if !suns.is_empty() && (!setup.cull || setup.vis.may_see_sky(face.index)) {
        let sky_offsets = setup
            .cull
            .then(|| setup.vis.visible_sky_bounds(face.index))
            .flatten()
            .map(|sky| sky_offsets(&sky, &bounds));
        let sun_probes = (setup.adaptive && samples.per_axis == 1)
            .then(|| SampleGrid::new(samples.width, samples.height, SUN_PROBE_STRIDE));
        for (si, sun) in suns.iter().enumerate() {
            if sky_offsets
                .as_ref()
                .is_some_and(|offsets| !direction_meets_any(offsets, sun.to_sun))
            {
                continue;
            }
            let dir = sun.to_sun.as_vec3().to_array();
            let sun_value = |normal: DVec3| {
                let v = sun.light * angle_factor(normal.dot(sun.to_sun), sun.anglescale);
                if v.abs() < setup.gate { 0.0 } else { v }
            };
            if samples.normals.is_empty() {
                // A flat face: the same value at every sample (none when the sun is behind it).
                let v = sun_value(samples.normal);
                if v == 0.0 {
                    continue;
                }
                value.fill(v);
            } else {
                for (i, v) in value.iter_mut().enumerate() {
                    *v = sun_value(samples.normal_at(i));
                }
            }
            let ray = |i: usize| (samples.points[i], dir, setup.sun_distance);
            let reaches = |p: &mut RayPacket16| setup.scene.sees_sky16(p, face.model);
            counts.sun_rays += match &sun_probes {
                Some(grid) if sun.directions >= SUN_PROBE_DIRECTIONS => {
                    scratch.trace_probed(samples, grid, value, ray, &mut packet, reaches)
                }
                _ => scratch.trace(samples, setup.adaptive, value, ray, &mut packet, reaches),
            };
            let dirty = takes_dirt(sun.dirt);
            for (i, &v) in value.iter().enumerate() {
                if scratch.lit[i] {
                    let a = Arrival::new(Source::Sun(si), i, v, dirty, true);
                    arrivals.add(a, lights, suns, &mut out);
                }
            }
        }
    }

    let occlusion = match dirt_sampling {
        Some(sampling) => {
            let everywhere = if rules.minlight.is_some_and(|m| m.dirt.is_some()) {
                DirtNeed::Light
            } else if rules.bounce_dirt.is_some() {
                DirtNeed::Bounce
            } else {
                DirtNeed::No
            };
            let mut needed = vec![everywhere; n];
            for a in arrivals.waiting.iter().filter(|a| a.dirty) {
                needed[a.sample as usize] = DirtNeed::Light;
            }
            let (values, rays) = face_occlusion(
                FaceDirt {
                    scene: setup.scene,
                    samples,
                    model: face.model,
                    sampling: &sampling,
                    first_at: &scratch.first_at,
                    needed: &needed,
                },
                setup.adaptive,
            );
            counts.dirt_rays += rays;
            values
        }
        None => Vec::new(),
    };
    let mut dirt_factors = DirtFactors::new(&occlusion, n);
    // In the order they were found, so sums come out the same as adding
    // each light as it is traced.
    for a in arrivals.waiting.iter() {
        let i = a.sample as usize;
        let response = match a.source {
            Source::Light(li) => lights[li].dirt,
            Source::Sun(si) => suns[si].dirt,
        };
        let v = a.value * dirt_factors.get(response).map_or(1.0, |d| f64::from(d[i]));
        if a.gated && v.abs() < setup.gate {
            continue;
        }
        settle(a, v, lights, suns, &mut out);
    }

    if let Some(m) = rules.minlight {
        // `--addmin` adds the level to the light; otherwise it is a floor.
        let dirt = dirt_factors.get(m.dirt);
        let values = (0..n).map(|i| {
            let level = m.level * dirt.map_or(1.0, |d| f64::from(d[i]));
            m.color.to_array().map(|c| (level * c) as f32)
        });
        if m.add {
            out.added_minlight = Some(values.collect());
        } else {
            for (f, v) in out.floors.get(0).iter_mut().zip(values) {
                for k in 0..3 {
                    f[k] = f[k].max(v[k]);
                }
            }
        }
    }
    if let Some(d) = dirt_factors.get(rules.bounce_dirt) {
        out.bounce_dirt = d.to_vec();
    }
    (out, counts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(mins: [f64; 3], maxs: [f64; 3]) -> Bounds {
        Bounds {
            mins: DVec3::new(mins[0], mins[1], mins[2]),
            maxs: DVec3::new(maxs[0], maxs[1], maxs[2]),
        }
    }

    proptest::proptest! {
        #[test]
        fn lights_past_the_far_distance_are_one_cell_away(
            radius in 0.01f64..64.0,
            beyond in 0.0f64..4.0,
            theta in 0.0f64..std::f64::consts::PI,
            phi in 0.0f64..std::f64::consts::TAU,
            per_axis in proptest::sample::select(vec![1usize, 2, 4, 16]),
        ) {
            let rule = FootprintRule::for_samples(per_axis);
            let dist = rule.surely_far(radius) * (1.0 + beyond);
            let dir = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            let to_light = dir * dist;
            proptest::prop_assert_eq!(rule.cells(to_light, DVec3::Z, radius), 1, "{:?}", to_light);
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
