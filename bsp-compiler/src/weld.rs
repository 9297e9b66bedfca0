//! Shared vertices: welding equal points and inserting the vertices that lie on another face's
//! edge (T-junctions), which would otherwise show as cracks.

use quake_formats::geom::{POINT_EPSILON, Vec3};
use std::collections::HashMap;

/// Distance from an edge within which a vertex counts as lying on it.
pub const TJUNCTION_EPSILON: f64 = 0.02;
/// Cell size of the T-junction search grid.
const GRID: f64 = 64.0;

/// Points welded within [`POINT_EPSILON`], numbered in first-seen order.
#[derive(Debug, Default)]
pub struct VertexWelder {
    pub positions: Vec<Vec3>,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

/// A grid cell and the 26 around it: every cell a point within one cell width can fall in.
pub(crate) fn cell_and_neighbours([x, y, z]: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    (-1..=1).flat_map(move |dx| {
        (-1..=1).flat_map(move |dy| (-1..=1).map(move |dz| [x + dx, y + dy, z + dz]))
    })
}

impl VertexWelder {
    fn cell(p: Vec3) -> [i64; 3] {
        // Cells several epsilons wide; neighbours are searched, so the size only affects speed.
        let c = |v: f64| (v / (POINT_EPSILON * 16.0)).floor() as i64;
        [c(p.x), c(p.y), c(p.z)]
    }

    pub fn weld(&mut self, p: Vec3) -> u32 {
        let cell = Self::cell(p);
        let found = cell_and_neighbours(cell)
            .filter_map(|c| self.cells.get(&c))
            .flatten()
            .find(|&&id| self.positions[id as usize].near(p, POINT_EPSILON));
        if let Some(&id) = found {
            return id;
        }
        let id = self.positions.len() as u32;
        self.positions.push(p);
        self.cells.entry(cell).or_default().push(id);
        id
    }
}

/// Insert into each polygon (vertex indices into `positions`) every vertex lying inside one of
/// its edges. Returns how many vertices were inserted.
pub fn fix_tjunctions(positions: &[Vec3], polygons: &mut [Vec<u32>]) -> usize {
    let cell = |p: Vec3| {
        [
            (p.x / GRID).floor() as i64,
            (p.y / GRID).floor() as i64,
            (p.z / GRID).floor() as i64,
        ]
    };
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (i, &p) in positions.iter().enumerate() {
        grid.entry(cell(p)).or_default().push(i as u32);
    }
    let mut inserted = 0;
    let mut on_edge: Vec<(f64, u32)> = Vec::new();
    for poly in polygons.iter_mut() {
        let mut out = Vec::with_capacity(poly.len());
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            out.push(a);
            let (pa, pb) = (positions[a as usize], positions[b as usize]);
            let d = pb - pa;
            let len2 = d.dot(d);
            if len2 < POINT_EPSILON * POINT_EPSILON {
                continue;
            }
            let pad = Vec3::new(TJUNCTION_EPSILON, TJUNCTION_EPSILON, TJUNCTION_EPSILON);
            let (lo, hi) = (cell(pa.min(pb) - pad), cell(pa.max(pb) + pad));
            on_edge.clear();
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        let Some(ids) = grid.get(&[x, y, z]) else {
                            continue;
                        };
                        for &v in ids {
                            if v == a || v == b {
                                continue;
                            }
                            let pv = positions[v as usize];
                            let t = (pv - pa).dot(d) / len2;
                            let along = t * len2.sqrt();
                            if along <= POINT_EPSILON || along >= len2.sqrt() - POINT_EPSILON {
                                continue;
                            }
                            if (pa + d * t - pv).length() < TJUNCTION_EPSILON {
                                on_edge.push((t, v));
                            }
                        }
                    }
                }
            }
            on_edge.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            inserted += on_edge.len();
            out.extend(on_edge.iter().map(|&(_, v)| v));
        }
        *poly = out;
    }
    inserted
}

/// Drop the parts of a welded polygon that its own vertices make degenerate: repeats (`A A`,
/// also around the end) and loops back to a vertex it already visited, keeping the larger of the
/// two loops. A spike (`A B A`, as when a sliver's own vertex lies within [`TJUNCTION_EPSILON`] of
/// its far edge and is inserted there) or a knot of near-coincident vertices inserted on each
/// other's edges would use edges in both directions within one face: zero area that takes an
/// edge's second use from the neighbour that needs it. May leave fewer than three vertices.
pub fn remove_degenerate_vertices(poly: &mut Vec<u32>, positions: &[Vec3]) {
    loop {
        poly.dedup();
        while poly.len() > 1 && poly.first() == poly.last() {
            poly.pop();
        }
        let repeat = (0..poly.len()).find_map(|i| {
            let j = poly[i + 1..].iter().position(|&v| v == poly[i])?;
            Some((i, i + 1 + j))
        });
        let Some((i, j)) = repeat else {
            return;
        };
        let inner = poly[i..j].to_vec();
        let outer: Vec<u32> = poly[j..].iter().chain(&poly[..i]).copied().collect();
        *poly = if area(&inner, positions) > area(&outer, positions) {
            inner
        } else {
            outer
        };
    }
}

/// The area of a closed polygon of vertex indices.
fn area(poly: &[u32], positions: &[Vec3]) -> f64 {
    let point = |k: usize| positions[poly[k % poly.len()] as usize];
    let twice = (0..poly.len()).fold(Vec3::ZERO, |sum, k| sum + point(k).cross(point(k + 1)));
    twice.length() / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn close_points_weld() {
        let mut w = VertexWelder::default();
        let a = w.weld(Vec3::new(64.0, 0.0, 0.0));
        let b = w.weld(Vec3::new(64.0 - POINT_EPSILON * 0.5, 0.0, 0.0));
        let c = w.weld(Vec3::new(64.0 + POINT_EPSILON * 3.0, 0.0, 0.0));
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn vertex_on_an_edge_is_inserted() {
        // A big square next to two small ones: the small ones' shared corner lies on its edge.
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 64.0, 0.0),
            Vec3::new(64.0, 64.0, 0.0),
            Vec3::new(64.0, 0.0, 0.0),
            Vec3::new(64.0, 32.0, 0.0),
        ];
        let mut polys = vec![vec![0, 1, 2, 3]];
        assert_eq!(fix_tjunctions(&positions, &mut polys), 1);
        assert_eq!(polys[0], vec![0, 1, 2, 4, 3]);
    }

    #[test]
    fn repeats_spikes_and_knots_are_removed() {
        // A 64 unit square, a point out on its right, and a knot of points near one corner.
        let mut positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 64.0, 0.0),
            Vec3::new(64.0, 64.0, 0.0),
            Vec3::new(64.0, 0.0, 0.0),
            Vec3::new(96.0, 32.0, 0.0),
        ];
        positions.extend(
            [[0.01, 0.0], [0.01, 0.01], [0.0, 0.01]]
                .map(|[x, y]| Vec3::new(64.0 + x, 64.0 + y, 0.0)),
        );
        let cleaned = |mut poly: Vec<u32>| {
            remove_degenerate_vertices(&mut poly, &positions);
            poly
        };
        assert_eq!(cleaned(vec![0, 1, 1, 2, 3, 0]), vec![0, 1, 2, 3]);
        // Out to 4 and straight back, inside the polygon and around its end.
        assert_eq!(cleaned(vec![0, 1, 2, 4, 2, 3]), vec![2, 3, 0, 1]);
        assert_eq!(cleaned(vec![4, 2, 3, 0, 1, 2]), vec![2, 3, 0, 1]);
        // A knot at corner 2, and a polygon that is nothing but a spike.
        assert_eq!(cleaned(vec![0, 1, 2, 5, 6, 7, 2, 3]), vec![2, 3, 0, 1]);
        assert!(cleaned(vec![0, 1, 2, 1]).len() < 3);
        assert_eq!(cleaned(vec![0, 1, 2, 3]), vec![0, 1, 2, 3]);
    }
}
