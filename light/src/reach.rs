//! Which lights may reach a face, found without looking at every light.
//!
//! Each light has a reach: the distance past which it adds less than the gate
//! ([`PointLight::range`]). [`LightReaches`] lays a grid of cubes over the map and lists in
//! each cube the lights whose reach (the box around its sphere) touches it, so a face looks
//! up the cubes its samples' box overlaps and tests only the lights listed there. Lights that
//! never fade, or whose reach covers too many cubes, are listed as near every box. The list
//! may hold lights that miss the face; the per-face cull ([`box_distance_squared`]) removes
//! them.

use glam::DVec3;
use quake_formats::geom::Bounds;

use crate::bits::ones;
use crate::lights::PointLight;

/// Where a light is and how far it reaches, packed for the per-face cull (a map tests about
/// as many face/light pairs as it has faces times lights).
#[derive(Debug, Clone, Copy)]
pub struct LightReach {
    pub origin: DVec3,
    /// Square of [`PointLight::range`] (infinite for lights that never fade).
    pub range_squared: f64,
}

/// Every light's [`LightReach`], and which lights may reach a box: a grid of
/// cubes, each listing the lights whose reach (the box around its sphere)
/// touches it, so a face looks at the lights near it instead of at all of them
/// (few of a map's lights reach any one face).
pub struct LightReaches {
    each: Vec<LightReach>,
    /// The grid's lowest corner and its cube's side.
    min: DVec3,
    cube: f64,
    dims: [usize; 3],
    /// Per cube (x fastest): the lights reaching into it, in ascending order.
    cubes: Vec<Vec<u32>>,
    /// Lights that never fade, or reach more than [`MAX_CUBES_PER_LIGHT`] cubes: near every box.
    everywhere: Vec<u32>,
}

/// Cubes of the [`LightReaches`] grid along its longest side (fewer when they
/// would be smaller than [`MIN_CUBE`]).
const CUBES_ALONG: f64 = 64.0;

/// Smallest cube side of the [`LightReaches`] grid, in map units.
const MIN_CUBE: f64 = 128.0;

/// A light reaching more cubes than this is listed as near every box instead.
const MAX_CUBES_PER_LIGHT: usize = 4096;

/// Each light's [`LightReach`] at contribution cut-off `gate`.
pub fn light_reaches(lights: &[PointLight], gate: f64) -> LightReaches {
    LightReaches::new(
        lights
            .iter()
            .map(|l| LightReach {
                origin: l.origin,
                range_squared: l.range(gate).powi(2),
            })
            .collect(),
    )
}

impl LightReaches {
    fn new(each: Vec<LightReach>) -> LightReaches {
        let reach_box = |r: &LightReach| {
            let radius = DVec3::splat(r.range_squared.sqrt());
            (r.origin - radius, r.origin + radius)
        };
        let finite = |r: &LightReach| r.range_squared.is_finite();
        let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for r in each.iter().filter(|r| finite(r)) {
            let (lo, hi) = reach_box(r);
            (min, max) = (min.min(lo), max.max(hi));
        }
        let extent = (max - min).max_element();
        let cube = if extent.is_finite() {
            (extent / CUBES_ALONG).max(MIN_CUBE)
        } else {
            MIN_CUBE
        };
        let along = |a: f64| ((a / cube).ceil() as usize).max(1);
        let dims = if extent.is_finite() {
            [
                along(max.x - min.x),
                along(max.y - min.y),
                along(max.z - min.z),
            ]
        } else {
            [1, 1, 1]
        };
        let mut grid = LightReaches {
            each: Vec::new(),
            min,
            cube,
            dims,
            cubes: vec![Vec::new(); dims[0] * dims[1] * dims[2]],
            everywhere: Vec::new(),
        };
        for (li, r) in each.iter().enumerate() {
            let (lo, hi) = reach_box(r);
            // Every finite reach box lies inside the grid.
            match finite(r).then(|| grid.cube_range(lo, hi)).flatten() {
                Some(range)
                    if range.iter().map(|a| a.len()).product::<usize>() <= MAX_CUBES_PER_LIGHT =>
                {
                    for c in grid.cubes_in(range) {
                        grid.cubes[c].push(li as u32);
                    }
                }
                _ => grid.everywhere.push(li as u32),
            }
        }
        grid.each = each;
        grid
    }

    /// The cubes `lo..hi` overlaps, per axis; None when it misses the grid.
    fn cube_range(&self, lo: DVec3, hi: DVec3) -> Option<[std::ops::Range<usize>; 3]> {
        let mut out = [0..0, 0..0, 0..0];
        for a in 0..3 {
            let first = ((lo[a] - self.min[a]) / self.cube).floor();
            let last = ((hi[a] - self.min[a]) / self.cube).floor();
            if last < 0.0 || first >= self.dims[a] as f64 || first.is_nan() || last.is_nan() {
                return None;
            }
            out[a] = first.max(0.0) as usize..(last as usize).min(self.dims[a] - 1) + 1;
        }
        Some(out)
    }

    /// The index in `cubes` of every cube of `range` (x fastest).
    fn cubes_in(&self, range: [std::ops::Range<usize>; 3]) -> impl Iterator<Item = usize> + use<> {
        let [xs, ys, zs] = range;
        let [dx, dy, _] = self.dims;
        zs.flat_map(move |z| {
            let xs = xs.clone();
            ys.clone()
                .flat_map(move |y| xs.clone().map(move |x| (z * dy + y) * dx + x))
        })
    }

    /// Into `out`, in ascending order: every light whose reach may touch `b`. `seen` is
    /// scratch: a bit per light, set as the cubes name it (a light reaching many cubes is named
    /// by each), read in order at the end.
    pub fn near(&self, b: &Bounds, seen: &mut Vec<u64>, out: &mut Vec<u32>) {
        seen.clear();
        seen.resize(self.each.len().div_ceil(64), 0);
        let mut mark = |lights: &[u32]| {
            for &li in lights {
                seen[li as usize / 64] |= 1 << (li % 64);
            }
        };
        mark(&self.everywhere);
        if let Some(range) = self.cube_range(b.mins, b.maxs) {
            for c in self.cubes_in(range) {
                mark(&self.cubes[c]);
            }
        }
        out.clear();
        for (word, &bits) in seen.iter().enumerate() {
            out.extend(ones(bits).map(|k| (word * 64 + k) as u32));
        }
    }
}

impl std::ops::Index<usize> for LightReaches {
    type Output = LightReach;
    fn index(&self, li: usize) -> &LightReach {
        &self.each[li]
    }
}

/// Squared distance from `p` to the box `b` (0 inside).
pub fn box_distance_squared(b: &Bounds, p: DVec3) -> f64 {
    (b.mins - p)
        .max(p - b.maxs)
        .max(DVec3::ZERO)
        .length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// The grid finds every light within reach of a box (it may find more).
        #[test]
        fn light_grid_finds_every_light_within_reach(
            lights in proptest::collection::vec(
                ((-3000.0f64..3000.0, -3000.0f64..3000.0, -500.0f64..500.0), 0.0f64..2000.0, 0u8..8),
                1..40,
            ),
            corner in (-3500.0f64..3500.0, -3500.0f64..3500.0, -900.0f64..900.0),
            size in (0.0f64..600.0, 0.0f64..600.0, 0.0f64..600.0),
        ) {
            let each: Vec<LightReach> = lights
                .iter()
                .map(|&((x, y, z), range, kind)| LightReach {
                    origin: DVec3::new(x, y, z),
                    // Some never fade; some reach nothing.
                    range_squared: match kind {
                        0 => f64::INFINITY,
                        1 => 0.0,
                        _ => range * range,
                    },
                })
                .collect();
            let reaches = LightReaches::new(each);
            let mins = DVec3::new(corner.0, corner.1, corner.2);
            let b = Bounds { mins, maxs: mins + DVec3::new(size.0, size.1, size.2) };
            let mut near = Vec::new();
            reaches.near(&b, &mut Vec::new(), &mut near);
            proptest::prop_assert!(near.windows(2).all(|w| w[0] < w[1]));
            for (li, r) in reaches.each.iter().enumerate() {
                if box_distance_squared(&b, r.origin) <= r.range_squared {
                    proptest::prop_assert!(near.contains(&(li as u32)), "light {} missed", li);
                }
            }
        }
    }
}
