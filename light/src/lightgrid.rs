//! `--lightgrid`: light sampled on a regular grid through the map's open space, which engines
//! light models with (the BSPX `LIGHTGRID_OCTREE` lump).
//!
//! A grid point takes what a surface there facing each light would: the direct light of every
//! light and sun whose ray reaches it, without the angle term, and the world's minlight as a
//! floor under style 0. Bounced light and dirt are not gathered. Points inside solid or sky
//! are marked occluded; engines then use their neighbours. As for faces, the PVS culls lights
//! and sun directions that cannot reach a point's leaf. The reference (`--reference`) samples
//! the same points without that culling and through every direction of every sun.

use glam::DVec3;
use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::bsp::lightgrid::{GridPoint, GridSample, LightGrid};
use quake_formats::bsp::limits::MAX_LIGHTMAPS;
use quake_formats::geom::{Bounds, DVec3Ext};
use rayon::prelude::*;
use std::sync::OnceLock;

use crate::embree::RayPacket16;
use crate::error::LightError;
use crate::lights::{Falloff, Minlight, PointLight, SunLight};
use crate::output::{Finish, levels_to_bytes, to_levels};
use crate::reach::LightReaches;
use crate::scene::TraceScene;
use crate::trace::suns::{direction_meets_any, sky_offsets};
use crate::visibility::Visibility;

/// A spacing fine enough to give more points than this is refused: the grid would take more
/// memory and time than the lightmaps.
const MAX_GRID_POINTS: u64 = 1 << 24;

/// Grid points sit this far off the whole-unit positions axial brush planes take, so none lies
/// on a floor or wall, where which side it is on (and which rays it casts) would be a toss-up.
const OFF_PLANE: f64 = 0.5;

/// Light per style at a grid point, in light units, by style number; `None` inside solid.
pub type RawPoint = Option<Vec<(u8, [f32; 3])>>;

/// The grid in light units, before bytes.
#[derive(Debug, Clone, PartialEq)]
pub struct RawGrid {
    /// Map units between points along each axis.
    pub spacing: DVec3,
    /// Where point (0, 0, 0) is.
    pub mins: DVec3,
    /// Points along each axis.
    pub size: [i32; 3],
    /// Every point, z then y then x.
    pub points: Vec<RawPoint>,
    /// Shadow and sun rays cast.
    pub rays: u64,
}

/// What lights the grid.
#[derive(Clone, Copy)]
pub struct GridSources<'a> {
    pub bsp: &'a Bsp,
    pub scene: &'a TraceScene,
    pub vis: &'a Visibility,
    pub lights: &'a [PointLight],
    /// Each light's world leaf (`None`: no culling).
    pub light_leafs: &'a [Option<u32>],
    pub reaches: &'a LightReaches,
    pub suns: &'a [SunLight],
    /// The world's minlight.
    pub minlight: Option<&'a Minlight>,
    /// Contributions below this many light units count as zero.
    pub gate: f64,
    /// Length of sun rays.
    pub sun_distance: f32,
    /// Skip lights and sun directions the PVS says cannot reach a point (off for the reference
    /// and `--no-cull`).
    pub cull: bool,
    /// Trace every direction of a soft sun or sky dome, not [`GRID_SUN_DIRECTIONS`] of them
    /// (the reference).
    pub every_sun_direction: bool,
}

/// Points of a grid row traced together (a packet of rays).
const RUN: i32 = 16;

/// A soft sun or sky dome is sampled in at most this many of its directions at each grid point
/// (each carrying the light of those skipped): models lit from the grid show no penumbrae.
const GRID_SUN_DIRECTIONS: usize = 16;

/// `suns` as the grid samples them: of each sun or dome spread over many directions (a run of
/// `directions` entries), evenly spaced ones, at most [`GRID_SUN_DIRECTIONS`], together as
/// bright as the whole.
fn grid_suns(suns: &[SunLight]) -> Vec<SunLight> {
    let mut out = Vec::new();
    let mut rest = suns;
    while let Some(first) = rest.first() {
        let (run, after) = rest.split_at(first.directions.clamp(1, rest.len()));
        let stride = run.len().div_ceil(GRID_SUN_DIRECTIONS);
        let taken = run.len().div_ceil(stride);
        let scale = run.len() as f64 / taken as f64;
        out.extend(run.iter().step_by(stride).map(|s| SunLight {
            light: s.light * scale,
            ..s.clone()
        }));
        rest = after;
    }
    out
}

/// The first point and the point counts of a grid of `spacing` over `bounds`.
fn frame(bounds: &Bounds, spacing: DVec3) -> (DVec3, [i32; 3]) {
    let mins = (bounds.mins / spacing).floor() * spacing + OFF_PLANE;
    let counts = ((bounds.maxs - mins) / spacing).floor() + 1.0;
    let size = counts.max(DVec3::ZERO).to_array().map(|c| c as i32);
    (mins, size)
}

/// Samples the light of `sources` at every point of a grid of `spacing` over the world
/// model's box.
///
/// # Errors
/// A spacing that gives more than [`MAX_GRID_POINTS`] points.
pub fn trace_grid(sources: &GridSources, spacing: DVec3) -> Result<RawGrid, LightError> {
    let bounds = sources
        .bsp
        .models
        .first()
        .map_or(Bounds::EMPTY, |m| Bounds {
            mins: DVec3::from(m.mins.map(f64::from)),
            maxs: DVec3::from(m.maxs.map(f64::from)),
        });
    let (mins, size) = if bounds.is_empty() {
        (DVec3::ZERO, [0; 3])
    } else {
        frame(&bounds, spacing)
    };
    let count: u64 = size.iter().map(|&s| s as u64).product();
    if count > MAX_GRID_POINTS {
        return Err(LightError::LightGridTooFine {
            points: count,
            most: MAX_GRID_POINTS,
        });
    }
    let [w, h, d] = size;
    // A run of a row along x at a time: its points share the lights that may reach them and
    // fill packets of rays.
    let runs_per_row = (w + RUN - 1) / RUN;
    let runs: Vec<(Vec<RawPoint>, u64)> = with_grid_suns(sources, |sources, sky| {
        (0..h * d * runs_per_row)
            .into_par_iter()
            .map(|k| {
                let (run, row) = (k % runs_per_row, k / runs_per_row);
                let (y, z) = (row % h, row / h);
                let points: Vec<DVec3> = (run * RUN..(run * RUN + RUN).min(w))
                    .map(|x| mins + DVec3::new(f64::from(x), f64::from(y), f64::from(z)) * spacing)
                    .collect();
                trace_run(sources, sky, &points)
            })
            .collect()
    });
    let rays = runs.iter().map(|(_, r)| r).sum();
    Ok(RawGrid {
        spacing,
        mins,
        size,
        points: runs.into_iter().flat_map(|(p, _)| p).collect(),
        rays,
    })
}

/// The light at each of `points` (anywhere, apart from each other) as a grid point there would
/// take it; `None` for a point inside solid or sky.
pub fn light_at(sources: &GridSources, points: &[DVec3]) -> Vec<RawPoint> {
    with_grid_suns(sources, |sources, sky| {
        // One point to a run: the leaf walk takes a run's points as one straight row.
        points
            .par_iter()
            .flat_map_iter(|p| trace_run(sources, sky, std::slice::from_ref(p)).0)
            .collect()
    })
}

/// `f` with `sources` whose suns are sampled as grid points sample them ([`grid_suns`], or all
/// of them for the reference), and the sky each leaf sees of those.
fn with_grid_suns<R>(sources: &GridSources, f: impl FnOnce(&GridSources, &LeafSky) -> R) -> R {
    let suns = if sources.every_sun_direction {
        sources.suns.to_vec()
    } else {
        grid_suns(sources.suns)
    };
    let sources = &GridSources {
        suns: &suns,
        ..*sources
    };
    f(sources, &LeafSky::new(sources.bsp, sources.suns))
}

/// Deeper than this no walk of a sound world tree goes.
const MAX_TREE_DEPTH: usize = 4096;

/// The world leaf of each of `points`, which lie evenly spaced along a line (a grid row), as
/// [`Bsp::leaf_at`] finds it: one walk down the tree, the row split where it crosses a node's
/// plane (at most once, a row being straight). `None` where the tree cannot tell (no tree, or a
/// damaged one).
pub(crate) fn leaves_along(bsp: &Bsp, points: &[DVec3]) -> Vec<Option<usize>> {
    let mut out = vec![None; points.len()];
    if let Some(&head) = bsp.models.first().and_then(|m| m.head_nodes.first()) {
        let points: Vec<[f32; 3]> = points.iter().map(|p| p.as_vec3().to_array()).collect();
        walk_row(bsp, head, &points, &mut out, 0);
    }
    out
}

/// [`leaves_along`] below `node` for `points`, into `out` (as long as `points`).
fn walk_row(bsp: &Bsp, node: i32, points: &[[f32; 3]], out: &mut [Option<usize>], depth: usize) {
    if points.is_empty() {
        return;
    }
    if node < 0 {
        out.fill(Some((-(node + 1)) as usize));
        return;
    }
    let n = bsp.nodes.get(node as usize);
    let Some((n, plane)) = n.and_then(|n| Some((n, bsp.planes.get(n.plane as usize)?))) else {
        return;
    };
    if depth == MAX_TREE_DEPTH {
        return;
    }
    // The same sum as `leaf_at`'s, so both put a point on the same side.
    let behind = |p: &[f32; 3]| plane.distance(*p) < 0.0;
    let first_behind = behind(&points[0]);
    let split = points.partition_point(|p| behind(p) == first_behind);
    let (near, far) = points.split_at(split);
    let (near_out, far_out) = out.split_at_mut(split);
    let child = |behind: bool| n.children[usize::from(behind)];
    walk_row(bsp, child(first_behind), near, near_out, depth + 1);
    walk_row(bsp, child(!first_behind), far, far_out, depth + 1);
}

/// Where each of `points` (along a grid row) is: `None` inside solid or sky, else the world leaf
/// holding it (`Some(None)`: the BSP's tree cannot tell).
fn places(bsp: &Bsp, points: &[DVec3]) -> Vec<Option<Option<u32>>> {
    leaves_along(bsp, points)
        .into_iter()
        .map(|leaf| {
            let Some(leaf) = leaf else {
                return Some(None);
            };
            match bsp.leafs.get(leaf).map(|l| l.contents) {
                Some(contents::SOLID | contents::SKY) => None,
                _ => Some(Some(leaf as u32)),
            }
        })
        .collect()
}

/// Per world leaf, which of the grid's sun directions may reach sky from somewhere in it (the
/// PVS and the boxes around the sky it sees; see [`Visibility::sky_bounds_seen_from`]), found
/// once per leaf for the whole grid.
struct LeafSky<'a> {
    suns: &'a [SunLight],
    leaves: Vec<OnceLock<Vec<bool>>>,
    /// For points whose leaf the tree cannot tell: every direction.
    all: Vec<bool>,
}

impl<'a> LeafSky<'a> {
    fn new(bsp: &Bsp, suns: &'a [SunLight]) -> LeafSky<'a> {
        LeafSky {
            suns,
            leaves: (0..bsp.leafs.len()).map(|_| OnceLock::new()).collect(),
            all: vec![true; suns.len()],
        }
    }

    /// Per sun direction, whether it may reach sky from `leaf`.
    fn directions(&self, bsp: &Bsp, vis: &Visibility, leaf: Option<u32>) -> &[bool] {
        let Some((leaf, cell)) = leaf.and_then(|l| Some((l, self.leaves.get(l as usize)?))) else {
            return &self.all;
        };
        cell.get_or_init(|| {
            if !vis.leafs_may_see_sky(&[leaf]) {
                return vec![false; self.suns.len()];
            }
            let Some(sky) = vis.sky_bounds_seen_from(&[leaf]) else {
                return self.all.clone();
            };
            let l = &bsp.leafs[leaf as usize];
            let inside = Bounds {
                mins: DVec3::from(l.mins.map(f64::from)),
                maxs: DVec3::from(l.maxs.map(f64::from)),
            };
            let offsets = sky_offsets(&sky, &inside);
            self.suns
                .iter()
                .map(|s| direction_meets_any(&offsets, s.to_sun))
                .collect()
        })
    }
}

/// Light per style, summed or raised to a floor.
#[derive(Debug, Default)]
struct StyleSums(Vec<(u8, [f64; 3])>);

impl StyleSums {
    fn slot(&mut self, style: u8) -> &mut [f64; 3] {
        crate::styles::entry(&mut self.0, style, || [0.0; 3])
    }

    fn add(&mut self, style: u8, value: f64, color: DVec3) {
        let slot = self.slot(style);
        for (s, c) in slot.iter_mut().zip(color.to_array()) {
            *s += value * c;
        }
    }

    fn raise(&mut self, style: u8, value: f64, color: DVec3) {
        let slot = self.slot(style);
        for (s, c) in slot.iter_mut().zip(color.to_array()) {
            *s = s.max(value * c);
        }
    }
}

/// One open point's light while its run is traced.
#[derive(Debug, Default)]
struct PointSums {
    sums: StyleSums,
    floors: StyleSums,
}

impl PointSums {
    /// `light`'s `value` reached the point, in `color` (the light's there).
    fn add_light(&mut self, light: &PointLight, value: f64, color: DVec3) {
        if light.falloff == Falloff::LocalMin {
            self.floors.raise(light.style, value, color);
        } else {
            self.sums.add(light.style, value, color);
        }
    }

    /// The light per style, floors applied, by style number.
    fn finish(mut self) -> Vec<(u8, [f32; 3])> {
        for &(style, floor) in &self.floors.0 {
            let sum = self.sums.slot(style);
            for (s, f) in sum.iter_mut().zip(floor) {
                *s = s.max(f);
            }
        }
        let mut out: Vec<(u8, [f32; 3])> = self
            .sums
            .0
            .into_iter()
            .map(|(s, v)| (s, v.map(|c| c as f32)))
            .collect();
        out.sort_by_key(|&(s, _)| s);
        out
    }
}

/// Casts the rays `lanes` (point index, direction, length) sixteen at a time and calls `reached`
/// with the index of each point whose ray `through` lets pass; returns the rays cast.
fn cast(
    points: &[DVec3],
    lanes: &[(usize, DVec3, f32)],
    through: impl Fn(&mut RayPacket16) -> u16,
    mut reached: impl FnMut(usize),
) -> u64 {
    let mut packet = RayPacket16::new();
    for chunk in lanes.chunks(16) {
        packet.clear();
        for (lane, &(i, dir, length)) in chunk.iter().enumerate() {
            let org = points[i].as_vec3().to_array();
            packet.set(lane, org, dir.as_vec3().to_array(), 0.0, length);
        }
        let passed = through(&mut packet);
        for (lane, &(i, _, _)) in chunk.iter().enumerate() {
            if passed & (1 << lane) != 0 {
                reached(i);
            }
        }
    }
    lanes.len() as u64
}

/// The light at each of `points` (a run of a grid row), and the rays cast.
fn trace_run(src: &GridSources, sky: &LeafSky, points: &[DVec3]) -> (Vec<RawPoint>, u64) {
    let places = places(src.bsp, points);
    let open: Vec<bool> = places.iter().map(Option::is_some).collect();
    let mut sums: Vec<PointSums> = points.iter().map(|_| PointSums::default()).collect();
    let mut bounds = Bounds::EMPTY;
    for (p, _) in points.iter().zip(&open).filter(|(_, o)| **o) {
        bounds.add_point(*p);
    }
    let mut rays = 0;
    let mut lanes = Vec::with_capacity(points.len());
    if !bounds.is_empty() {
        let mut near = Vec::new();
        src.reaches.near(&bounds, &mut Vec::new(), &mut near);
        for &li in &near {
            let light = &src.lights[li as usize];
            let light_leaf = src.light_leafs[li as usize];
            lanes.clear();
            let mut values = vec![0.0; points.len()];
            for (i, &p) in points.iter().enumerate() {
                let Some(leaf) = places[i] else {
                    continue;
                };
                if src.cull && !src.vis.may_reach_leafs(light_leaf, leaf.as_slice()) {
                    continue;
                }
                let Some((dist, dir)) = (light.origin - p).length_and_direction() else {
                    continue;
                };
                let value = light.contribution(dist, -dir, 1.0);
                if value.abs() >= src.gate {
                    values[i] = value;
                    let length = (dist as f32 - crate::trace::LIGHT_CLEARANCE).max(0.0);
                    lanes.push((i, dir, length));
                }
            }
            rays += cast(
                points,
                &lanes,
                |p| !src.scene.occluded16(p, 0),
                |i| sums[i].add_light(light, values[i], light.color_at(points[i])),
            );
        }
        let directions: Vec<Option<&[bool]>> = places
            .iter()
            .map(|place| {
                place.map(|leaf| {
                    if src.cull {
                        sky.directions(src.bsp, src.vis, leaf)
                    } else {
                        &sky.all
                    }
                })
            })
            .collect();
        for (si, sun) in src.suns.iter().enumerate() {
            let Some(filter) = src.scene.sky_filter(sun.sky_texture.as_deref()) else {
                continue;
            };
            lanes.clear();
            lanes.extend(
                directions
                    .iter()
                    .enumerate()
                    .filter(|(_, d)| d.is_some_and(|d| d[si]))
                    .map(|(i, _)| (i, sun.to_sun, src.sun_distance)),
            );
            rays += cast(
                points,
                &lanes,
                |p| src.scene.sees_sky16(p, 0, filter),
                |i| sums[i].sums.add(sun.style, sun.light, sun.color),
            );
        }
    }
    let out = sums
        .into_iter()
        .zip(&open)
        .map(|(mut s, &open)| {
            open.then(|| {
                if let Some(m) = src.minlight {
                    if m.add {
                        s.sums.add(0, m.level, m.color);
                    } else {
                        s.floors.raise(0, m.level, m.color);
                    }
                }
                s.finish()
            })
        })
        .collect();
    (out, rays)
}

/// The grid in lightmap bytes, as engines read it: range scale and gamma as the lightmaps
/// take them, styles dark at the point left out, and at most four (style 0, then the
/// brightest).
pub fn finish_grid(raw: &RawGrid, finish: &Finish) -> LightGrid {
    let points: Vec<GridPoint> = raw
        .points
        .iter()
        .map(|p| p.as_ref().map(|styles| point_bytes(styles, finish)))
        .collect();
    LightGrid::build(
        raw.spacing.as_vec3().to_array(),
        raw.mins.as_vec3().to_array(),
        raw.size,
        &points,
    )
}

/// One point's styles as bytes (see [`finish_grid`]).
fn point_bytes(styles: &[(u8, [f32; 3])], finish: &Finish) -> Vec<GridSample> {
    let mut samples: Vec<GridSample> = styles
        .iter()
        .map(|&(style, c)| GridSample {
            style,
            rgb: levels_to_bytes(to_levels(c, finish)),
        })
        .filter(|s| s.rgb != [0; 3])
        .collect();
    let energy = |s: &GridSample| s.rgb.iter().map(|&b| u32::from(b)).sum::<u32>();
    // Style 0 first, then the brightest; ties by style number, so the order is the same on
    // every run.
    samples.sort_by_key(|s| (s.style != 0, std::cmp::Reverse(energy(s)), s.style));
    samples.truncate(MAX_LIGHTMAPS);
    samples
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dome_is_thinned_to_sixteen_directions_as_bright_as_all() {
        let sun = |light: f64, directions: usize| SunLight {
            to_sun: DVec3::Z,
            light,
            color: DVec3::ONE,
            style: 0,
            anglescale: 0.5,
            dirt: None,
            directions,
            sky_texture: None,
        };
        let mut suns = vec![sun(300.0, 1)];
        suns.extend((0..100).map(|_| sun(0.5, 100)));
        let thinned = grid_suns(&suns);
        // The single sun, then every seventh of the dome's 100 directions: 15 of them.
        assert_eq!(thinned.len(), 1 + 15);
        assert_eq!(thinned[0], suns[0]);
        let dome: f64 = thinned[1..].iter().map(|s| s.light).sum();
        assert!((dome - 50.0).abs() < 1e-9, "{dome}");
    }

    #[test]
    fn the_frame_covers_the_box_off_the_whole_units() {
        let bounds = Bounds {
            mins: DVec3::new(-40.0, 0.0, 8.0),
            maxs: DVec3::new(100.0, 31.0, 8.0),
        };
        let (mins, size) = frame(&bounds, DVec3::splat(32.0));
        assert_eq!(mins, DVec3::new(-63.5, 0.5, 0.5));
        // x: -63.5 .. 96.5 (six points); y: only 0.5; z: 0.5 alone.
        assert_eq!(size, [6, 1, 1]);
    }

    #[test]
    fn a_point_keeps_style_0_and_its_three_brightest_others() {
        let finish = Finish {
            rangescale: 1.0,
            gamma: 1.0,
            rgb: true,
            hdr: false,
            directions: false,
        };
        let styles = [
            (0, [0.0; 3]),
            (1, [10.0; 3]),
            (2, [30.0; 3]),
            (3, [20.0; 3]),
            (4, [40.0; 3]),
            (5, [5.0, 0.0, 0.0]),
        ];
        let got: Vec<u8> = point_bytes(&styles, &finish)
            .iter()
            .map(|s| s.style)
            .collect();
        assert_eq!(got, vec![4, 2, 3, 1], "dark style 0 is left out");
        let lit0 = [(3, [300.0, 0.0, 0.0]), (0, [1.0; 3])];
        let got = point_bytes(&lit0, &finish);
        assert_eq!(
            got[0],
            GridSample {
                style: 0,
                rgb: [1; 3]
            }
        );
        assert_eq!(
            got[1],
            GridSample {
                style: 3,
                rgb: [255, 0, 0]
            }
        );
    }
}
