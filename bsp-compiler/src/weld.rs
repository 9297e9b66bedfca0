//! Shared vertices: welding equal points and inserting the vertices that lie on another face's
//! edge (T-junctions), which would otherwise show as cracks.

use crate::int_hash::IntMap;
use glam::DVec3;
use quake_formats::geom::DVec3Ext;
use quake_formats::geom::{Bounds, ON_EPSILON, POINT_EPSILON};

/// Distance from an edge within which a vertex counts as lying on it.
pub const TJUNCTION_EPSILON: f64 = 0.02;
/// Cell size of the T-junction search grid.
const GRID: f64 = 64.0;

/// Points welded within [`POINT_EPSILON`], numbered in first-seen order.
#[derive(Debug, Default)]
pub struct VertexWelder {
    pub positions: Vec<DVec3>,
    cells: IntMap<[i64; 3], Vec<u32>>,
}

/// A grid cell and the 26 around it: every cell a point within one cell width can fall in.
pub(crate) fn cell_and_neighbours([x, y, z]: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    (-1..=1).flat_map(move |dx| {
        (-1..=1).flat_map(move |dy| (-1..=1).map(move |dz| [x + dx, y + dy, z + dz]))
    })
}

impl VertexWelder {
    fn cell(p: DVec3) -> [i64; 3] {
        // Cells several epsilons wide; neighbours are searched, so the size only affects speed.
        let c = |v: f64| (v / (POINT_EPSILON * 16.0)).floor() as i64;
        [c(p.x), c(p.y), c(p.z)]
    }

    pub fn weld(&mut self, p: DVec3) -> u32 {
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

/// Passes of T-junction fixing before giving up on a polygon set that keeps changing.
const MAX_TJUNCTION_PASSES: usize = 16;

/// Insert into each polygon (vertex indices into `positions`) every vertex lying inside one of
/// its edges, then drop the degenerate parts that makes ([`remove_degenerate_vertices`]), and
/// repeat until nothing changes: an insertion makes new, shorter edges that a third vertex of a
/// knot of near-coincident ones (where several planes meet) may lie on. Polygons may be left with
/// fewer than three vertices. Returns how many vertices were inserted.
pub fn fix_tjunctions(positions: &[DVec3], polygons: &mut [Vec<u32>]) -> usize {
    let mut grid = TJunctionGrid::new(positions);
    let mut inserted = 0;
    for _ in 0..MAX_TJUNCTION_PASSES {
        let collapsed = collapse_short_edges(positions, polygons);
        // A vertex made one with another is no longer anywhere to insert.
        for &v in &collapsed {
            grid.remove(v);
        }
        let mut changed = !collapsed.is_empty();
        for poly in polygons.iter_mut() {
            let before = poly.clone();
            let added = grid.insert_edge_vertices(poly);
            if added == 0 {
                continue;
            }
            remove_degenerate_vertices(poly, positions);
            // A vertex inserted and then dropped again (a spike) is no change.
            if *poly != before {
                inserted += added;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    inserted
}

/// Make the two ends of every polygon edge shorter than [`TJUNCTION_EPSILON`] one vertex (the
/// lower-numbered one, when its position is that close to the other's). Such an edge is a knot
/// of near-coincident vertices where several planes meet: each lies within the T-junction
/// distance of the others' edges, so no insertion can fix them (a sliver triangle of three of
/// them has each vertex on its opposite edge).
/// Returns the vertices collapsed into others.
fn collapse_short_edges(positions: &[DVec3], polygons: &mut [Vec<u32>]) -> Vec<u32> {
    let mut same: IntMap<u32, u32> = IntMap::default();
    let root = |same: &IntMap<u32, u32>, mut v: u32| {
        while let Some(&r) = same.get(&v) {
            v = r;
        }
        v
    };
    for poly in polygons.iter() {
        for k in 0..poly.len() {
            let (a, b) = (
                root(&same, poly[k]),
                root(&same, poly[(k + 1) % poly.len()]),
            );
            if a != b && positions[a as usize].near(positions[b as usize], TJUNCTION_EPSILON) {
                same.insert(a.max(b), a.min(b));
            }
        }
    }
    if same.is_empty() {
        return Vec::new();
    }
    for poly in polygons.iter_mut() {
        for v in poly.iter_mut() {
            *v = root(&same, *v);
        }
        remove_degenerate_vertices(poly, positions);
    }
    same.into_keys().collect()
}

/// Vertices bucketed by position, for finding those near an edge.
struct TJunctionGrid<'a> {
    positions: &'a [DVec3],
    cells: IntMap<[i64; 3], Vec<u32>>,
}

impl<'a> TJunctionGrid<'a> {
    fn cell(p: DVec3) -> [i64; 3] {
        let c = |v: f64| (v / GRID).floor() as i64;
        [c(p.x), c(p.y), c(p.z)]
    }

    fn new(positions: &'a [DVec3]) -> Self {
        let mut cells: IntMap<[i64; 3], Vec<u32>> = IntMap::default();
        for (i, &p) in positions.iter().enumerate() {
            cells.entry(Self::cell(p)).or_default().push(i as u32);
        }
        Self { positions, cells }
    }

    fn remove(&mut self, v: u32) {
        let cell = Self::cell(self.positions[v as usize]);
        if let Some(ids) = self.cells.get_mut(&cell) {
            ids.retain(|&id| id != v);
        }
    }

    /// Insert into `poly` every vertex lying inside one of its edges; how many were inserted.
    fn insert_edge_vertices(&self, poly: &mut Vec<u32>) -> usize {
        let mut inserted = 0;
        let mut out = Vec::with_capacity(poly.len());
        let mut on_edge: Vec<(f64, u32)> = Vec::new();
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            out.push(a);
            self.vertices_inside(a, b, &mut on_edge);
            inserted += on_edge.len();
            out.extend(on_edge.iter().map(|&(_, v)| v));
        }
        *poly = out;
        inserted
    }

    /// The vertices inside edge `a`→`b` (within [`TJUNCTION_EPSILON`] of it, more than
    /// [`POINT_EPSILON`] from its ends), with their fraction along it, in order along it.
    fn vertices_inside(&self, a: u32, b: u32, on_edge: &mut Vec<(f64, u32)>) {
        on_edge.clear();
        let (pa, pb) = (self.positions[a as usize], self.positions[b as usize]);
        let d = pb - pa;
        let len2 = d.dot(d);
        if len2 < POINT_EPSILON * POINT_EPSILON {
            return;
        }
        let len = len2.sqrt();
        let pad = DVec3::new(TJUNCTION_EPSILON, TJUNCTION_EPSILON, TJUNCTION_EPSILON);
        let (lo, hi) = (Self::cell(pa.min(pb) - pad), Self::cell(pa.max(pb) + pad));
        // A long slanted edge's box spans many cells the edge passes far from: a cell whose
        // centre is farther from the edge than its half-diagonal (and a unit of slack for
        // points rounded into it) and the epsilon holds no vertex on the edge.
        let reach = GRID * 3f64.sqrt() / 2.0 + 1.0 + TJUNCTION_EPSILON;
        // Every point within the epsilon of the edge lies in its box grown by the epsilon (and
        // a millionth for rounding): most vertices of the cells fail this first, cheaper test.
        let slack = DVec3::splat(TJUNCTION_EPSILON + 1e-6);
        let near_box = Bounds {
            mins: pa.min(pb) - slack,
            maxs: pa.max(pb) + slack,
        };
        let far = |c: [i64; 3]| {
            let centre = (DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) + 0.5) * GRID;
            let t = ((centre - pa).dot(d) / len2).clamp(0.0, 1.0);
            (pa + d * t - centre).length() > reach
        };
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    if far([x, y, z]) {
                        continue;
                    }
                    for &v in self.cells.get(&[x, y, z]).into_iter().flatten() {
                        if v == a || v == b {
                            continue;
                        }
                        let pv = self.positions[v as usize];
                        if !near_box.contains(pv) {
                            continue;
                        }
                        let t = (pv - pa).dot(d) / len2;
                        let along = t * len;
                        if along <= POINT_EPSILON || along >= len - POINT_EPSILON {
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
    }
}

/// Drop the parts of a welded polygon that its own vertices make degenerate: repeats (`A A`,
/// also around the end) and loops back to a vertex it already visited, keeping the larger of the
/// two loops. A spike (`A B A`, as when a sliver's own vertex lies within [`TJUNCTION_EPSILON`] of
/// its far edge and is inserted there) or a knot of near-coincident vertices inserted on each
/// other's edges would use edges in both directions within one face: zero area that takes an
/// edge's second use from the neighbour that needs it. May leave fewer than three vertices.
pub fn remove_degenerate_vertices(poly: &mut Vec<u32>, positions: &[DVec3]) {
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

/// Cut `poly`, a convex polygon of vertex indices into `positions` whose edges carry the vertices
/// T-junction fixing put on them, into polygons of at most `max` (at least 3) vertices, for
/// engines that copy a face into a fixed buffer. Each cut is a chord between two of its
/// vertices, so the pieces share their new edge whole and no T-junction appears; a chord is
/// taken only where both sides have area (some vertex more than [`ON_EPSILON`] off it), never
/// along a run of vertices on one edge. A polygon no chord cuts that way is left whole.
pub fn cut_to_max_vertices(poly: Vec<u32>, max: usize, positions: &[DVec3]) -> Vec<Vec<u32>> {
    let has_area = |part: &[u32]| {
        let (Some(&a), Some(&b)) = (part.first(), part.last()) else {
            return false;
        };
        let (pa, pb) = (positions[a as usize], positions[b as usize]);
        let Some(dir) = (pb - pa).normalized() else {
            return false;
        };
        part.iter().any(|&v| {
            let d = positions[v as usize] - pa;
            (d - dir * d.dot(dir)).length() > ON_EPSILON
        })
    };
    let mut pieces = Vec::new();
    let mut rest = poly;
    while max >= 3 && rest.len() > max {
        let n = rest.len();
        let cut = (0..n).find_map(|i| {
            let piece: Vec<u32> = (0..max).map(|k| rest[(i + k) % n]).collect();
            let remainder: Vec<u32> = (max - 1..=n).map(|k| rest[(i + k) % n]).collect();
            (has_area(&piece) && has_area(&remainder)).then_some((piece, remainder))
        });
        let Some((piece, remainder)) = cut else {
            break;
        };
        pieces.push(piece);
        rest = remainder;
    }
    pieces.push(rest);
    pieces
}

/// The area of a closed polygon of vertex indices.
fn area(poly: &[u32], positions: &[DVec3]) -> f64 {
    let point = |k: usize| positions[poly[k % poly.len()] as usize];
    let twice = (0..poly.len()).fold(DVec3::ZERO, |sum, k| sum + point(k).cross(point(k + 1)));
    twice.length() / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn close_points_weld() {
        let mut w = VertexWelder::default();
        let a = w.weld(DVec3::new(64.0, 0.0, 0.0));
        let b = w.weld(DVec3::new(64.0 - POINT_EPSILON * 0.5, 0.0, 0.0));
        let c = w.weld(DVec3::new(64.0 + POINT_EPSILON * 3.0, 0.0, 0.0));
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn vertex_on_an_edge_is_inserted() {
        // A big square next to two small ones: the small ones' shared corner lies on its edge.
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 64.0, 0.0),
            DVec3::new(64.0, 64.0, 0.0),
            DVec3::new(64.0, 0.0, 0.0),
            DVec3::new(64.0, 32.0, 0.0),
        ];
        let mut polys = vec![vec![0, 1, 2, 3]];
        assert_eq!(fix_tjunctions(&positions, &mut polys), 1);
        assert_eq!(polys[0], vec![0, 1, 2, 4, 3]);
    }

    #[test]
    fn repeats_spikes_and_knots_are_removed() {
        // A 64 unit square, a point out on its right, and a knot of points near one corner.
        let mut positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 64.0, 0.0),
            DVec3::new(64.0, 64.0, 0.0),
            DVec3::new(64.0, 0.0, 0.0),
            DVec3::new(96.0, 32.0, 0.0),
        ];
        positions.extend(
            [[0.01, 0.0], [0.01, 0.01], [0.0, 0.01]]
                .map(|[x, y]| DVec3::new(64.0 + x, 64.0 + y, 0.0)),
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
