//! Close lights: a sample so close to a light that its brightness changes a lot across the
//! sample's square (its luxel, or its sub-square when supersampling) takes the mean of what the
//! light adds over `k × k` points spread across the square, each with its own shadow ray,
//! instead of the value at its one point. `k` is chosen so each cell is no wider than a
//! fraction of the light's distance from the square ([`FootprintRule`]), up to the
//! reference's one point per texel. This is what a luxel's value means (the mean over its
//! square), and it matters most for `_surface` copies a few units above their faces, whose
//! 1/x² peak one point either misses or sits on.

use glam::{DVec3, Vec3};
use quake_formats::Bsp;
use quake_formats::geom::DVec3Ext;

use super::LIGHT_CLEARANCE;
use crate::embree::RayPacket16;
use crate::lights::PointLight;
use crate::samples::{FaceSamples, WalkStart, solid_points_from};
use crate::scene::TraceScene;

/// With supersampling, sub-cells per axis are chosen so each is no wider than
/// this fraction of the light's distance from the sample's square (see
/// [`Footprints`]).
const CELL_PER_DISTANCE: f64 = 0.25;

/// [`CELL_PER_DISTANCE`] in the default mode (one sample per luxel), whose
/// error against the reference is dominated by that one sample: finer cells
/// there cast many more shadow rays for an error no lower overall.
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

/// Which lights a face's samples are close enough to for [`Footprints`]: the face's
/// [`FootprintRule`] and its samples' squares.
#[derive(Debug, Clone, Copy)]
pub struct Closeness {
    rule: FootprintRule,
    /// Half-diagonal of a sample's square.
    radius: f64,
    /// Lights at least this far from a sample are one cell away.
    surely_far: f64,
}

impl Closeness {
    /// The rule for the samples of one face.
    pub fn of(samples: &FaceSamples) -> Closeness {
        let radius = samples.map.footprint_radius();
        let rule = FootprintRule::for_samples(samples.per_axis);
        Closeness {
            rule,
            radius,
            surely_far: rule.surely_far(radius),
        }
    }

    /// A squared distance beyond which a light is surely one cell away (see
    /// [`Closeness::cells`]), with room for the rounding of a square and its root.
    pub fn surely_far_squared(&self) -> f64 {
        self.surely_far * self.surely_far * (1.0 + FOOTPRINT_FAR_MARGIN)
    }

    /// Cells per axis for a light at `to_light` (`dist` away) from a sample point on a
    /// surface with unit `normal` (1: the value at the point will do).
    pub fn cells(&self, to_light: DVec3, dist: f64, normal: DVec3) -> usize {
        if dist >= self.surely_far {
            1
        } else {
            self.rule.cells(to_light, normal, self.radius)
        }
    }
}

/// What `light` adds at `p`, unshadowed, on a surface whose cosine of incidence for light
/// arriving along a unit direction is `incidence`.
fn unshadowed(
    light: &PointLight,
    p: DVec3,
    incidence: impl Fn(DVec3) -> f64,
) -> Option<(f64, DVec3, f64)> {
    let to_light = light.origin - p;
    let dist = to_light.length();
    let dir = to_light.normalized()?;
    Some((light.contribution(dist, -dir, incidence(dir)), dir, dist))
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
pub struct Footprints {
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
    pub fn start_face(&mut self) {
        self.clear();
        self.placed.clear();
        self.points.clear();
        self.walk_start = None;
    }

    pub fn clear(&mut self) {
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
    pub fn add(
        &mut self,
        bsp: &Bsp,
        samples: &FaceSamples,
        i: usize,
        cells: usize,
        light: &PointLight,
    ) {
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
            let Some((value, dir, dist)) = unshadowed(light, q, |dir| samples.incidence(i, dir))
            else {
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
    pub fn trace(&mut self, scene: &TraceScene, model: usize, packet: &mut RayPacket16) -> u64 {
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
                    packet.set(lane, org, dir, super::RAY_START, reach);
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
    pub fn means(&self) -> impl Iterator<Item = (usize, f64)> + Clone + '_ {
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
