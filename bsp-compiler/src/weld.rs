//! Shared vertices: welding equal points and inserting the vertices that lie on another face's
//! edge (T-junctions), which would otherwise show as cracks.

use crate::tree::{DETAIL_WALL, engine_contents};
use glam::DVec3;
use quake_formats::bsp::contents;
use quake_formats::geom::DVec3Ext;
use quake_formats::geom::{Bounds, ON_EPSILON, POINT_EPSILON};
use quake_formats::int_hash::IntMap;
use rayon::prelude::*;

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
        // Cells several epsilons wide; the cells a point's epsilon box reaches are searched, so
        // the size only affects speed.
        let c = |v: f64| (v / (POINT_EPSILON * 16.0)).floor() as i64;
        [c(p.x), c(p.y), c(p.z)]
    }

    pub fn weld(&mut self, p: DVec3) -> u32 {
        // Every point within the epsilon lies in a cell its box (doubled against rounding)
        // reaches: one cell mostly, at most eight, searched in the order of the 27 around it.
        let reach = DVec3::splat(2.0 * POINT_EPSILON);
        let (lo, hi) = (Self::cell(p - reach), Self::cell(p + reach));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let Some(ids) = self.cells.get(&[x, y, z]) else {
                        continue;
                    };
                    let positions = &self.positions;
                    if let Some(&id) = ids
                        .iter()
                        .find(|&&id| positions[id as usize].near(p, POINT_EPSILON))
                    {
                        return id;
                    }
                }
            }
        }
        let cell = Self::cell(p);
        let id = self.positions.len() as u32;
        self.positions.push(p);
        self.cells.entry(cell).or_default().push(id);
        id
    }
}

/// Passes of T-junction fixing before giving up on a polygon set that keeps changing.
const MAX_TJUNCTION_PASSES: usize = 16;

/// What a face is made of, for T-junctions: which other faces' vertices go into its edges. As in
/// ericw-tools, solid, sky and liquid faces give their vertices to every face; a solid or sky face
/// takes no others, a detail wall's face takes those of detail walls too, and a see-through face
/// (fence, illusionary) or a liquid's takes every vertex. Detail walls, fences and illusionary
/// brushes are there to leave the world's faces alone, and a crack along their edge on a wall
/// behind them does not show through them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeldClass {
    Opaque,
    DetailWall,
    SeeThrough,
    Liquid,
}

impl WeldClass {
    /// The class of a face painted from a leaf of compiler contents `c` with the texture
    /// `texture`. A liquid's texture makes a liquid's face whatever leaf it is painted from (a
    /// water surface inside an illusionary brush), and a fence's (`{`) a see-through one, as a
    /// BSP shows them to the crack check ([`crate::cracks::face_class`]).
    pub fn of(c: i32, texture: &str) -> WeldClass {
        if texture.starts_with('*') {
            return WeldClass::Liquid;
        }
        if texture.starts_with('{') {
            return WeldClass::SeeThrough;
        }
        match c {
            contents::SOLID | contents::SKY => WeldClass::Opaque,
            DETAIL_WALL => WeldClass::DetailWall,
            c if contents::is_liquid(engine_contents(c)) && c == engine_contents(c) => {
                WeldClass::Liquid
            }
            _ => WeldClass::SeeThrough,
        }
    }

    fn bit(self) -> u8 {
        1 << self as u8
    }

    /// Whether a face of this class takes the vertices of faces of class `other`.
    pub fn welds_with(self, other: WeldClass) -> bool {
        self.takes() & other.bit() != 0
    }

    /// The classes (bits) whose faces' vertices a face of this class takes.
    fn takes(self) -> u8 {
        let always = WeldClass::Opaque.bit() | WeldClass::Liquid.bit();
        match self {
            WeldClass::Opaque => always,
            WeldClass::DetailWall => always | WeldClass::DetailWall.bit(),
            WeldClass::SeeThrough | WeldClass::Liquid => u8::MAX,
        }
    }
}

/// Insert into each polygon (vertex indices into `positions`) every vertex lying inside one of
/// its edges that it takes by its [`WeldClass`] (`classes`, one per polygon: a vertex belongs to
/// the classes of the polygons it starts in and of those it is inserted into), then drop the degenerate parts that makes
/// ([`remove_degenerate_vertices`]), and repeat until nothing changes: an insertion makes new,
/// shorter edges that a third vertex of a knot of near-coincident ones (where several planes
/// meet) may lie on. Only the polygons' own vertices are inserted: call it once per model.
/// Polygons may be left with fewer than three vertices. Returns how many vertices were inserted.
pub fn fix_tjunctions(
    positions: &[DVec3],
    polygons: &mut [Vec<u32>],
    classes: &[WeldClass],
) -> usize {
    let mut owners: IntMap<u32, u8> = IntMap::default();
    for (poly, class) in polygons.iter().zip(classes) {
        for &v in poly {
            *owners.entry(v).or_default() |= class.bit();
        }
    }
    let mut grid = TJunctionGrid::new(positions, owners);
    let mut inserted = 0;
    for _ in 0..MAX_TJUNCTION_PASSES {
        let collapsed = collapse_short_edges(positions, polygons);
        // A vertex made one with another is no longer anywhere to insert; the one it became
        // belongs to its faces too.
        for &(v, into) in &collapsed {
            grid.merge(v, into);
        }
        let mut changed = !collapsed.is_empty();
        // What lies inside each edge depends only on the positions and the grid, which the
        // insertions below leave alone: found for every polygon at once, then inserted in order
        // (an insertion gives the vertex its polygon's class, which later polygons may take).
        let inside: Vec<Vec<EdgeVertex>> = polygons
            .par_iter()
            .map(|poly| grid.inside_edges(poly))
            .collect();
        for ((poly, &class), inside) in polygons.iter_mut().zip(classes).zip(inside) {
            if inside.is_empty() {
                continue;
            }
            let before = poly.clone();
            let added = grid.insert_edge_vertices(poly, class, &inside);
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
/// Returns the vertices collapsed into others, each with the one it became.
fn collapse_short_edges(positions: &[DVec3], polygons: &mut [Vec<u32>]) -> Vec<(u32, u32)> {
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
    same.keys().map(|&v| (v, root(&same, v))).collect()
}

/// A vertex found inside edge `edge` (from corner `edge` to the next) of a polygon.
#[derive(Debug, Clone, Copy)]
struct EdgeVertex {
    edge: usize,
    vertex: u32,
}

/// The vertices of a set of polygons bucketed by position, for finding those near an edge, each
/// with the [`WeldClass`] bits of the polygons it belongs to.
struct TJunctionGrid<'a> {
    positions: &'a [DVec3],
    cells: IntMap<[i64; 3], Vec<u32>>,
    owners: IntMap<u32, u8>,
}

impl<'a> TJunctionGrid<'a> {
    fn cell(p: DVec3) -> [i64; 3] {
        let c = |v: f64| (v / GRID).floor() as i64;
        [c(p.x), c(p.y), c(p.z)]
    }

    fn new(positions: &'a [DVec3], owners: IntMap<u32, u8>) -> Self {
        let mut cells: IntMap<[i64; 3], Vec<u32>> = IntMap::default();
        for &v in owners.keys() {
            cells
                .entry(Self::cell(positions[v as usize]))
                .or_default()
                .push(v);
        }
        // Hash order must not decide the order vertices are found in.
        for ids in cells.values_mut() {
            ids.sort_unstable();
        }
        Self {
            positions,
            cells,
            owners,
        }
    }

    /// Vertex `v` became `into`: it is gone, and `into` belongs to its polygons too.
    fn merge(&mut self, v: u32, into: u32) {
        let cell = Self::cell(self.positions[v as usize]);
        if let Some(ids) = self.cells.get_mut(&cell) {
            ids.retain(|&id| id != v);
        }
        let bits = self.owners.remove(&v).unwrap_or(0);
        *self.owners.entry(into).or_default() |= bits;
    }

    /// Every vertex inside one of `poly`'s edges ([`TJunctionGrid::vertices_inside`]), edge by
    /// edge, each edge's in order along it.
    fn inside_edges(&self, poly: &[u32]) -> Vec<EdgeVertex> {
        let mut found = Vec::new();
        let mut on_edge = Vec::new();
        for k in 0..poly.len() {
            self.vertices_inside(poly[k], poly[(k + 1) % poly.len()], &mut on_edge);
            found.extend(
                on_edge
                    .iter()
                    .map(|&(_, vertex)| EdgeVertex { edge: k, vertex }),
            );
        }
        found
    }

    /// Insert into `poly`, a polygon of `class`, every vertex of `inside` (its
    /// [`TJunctionGrid::inside_edges`]) that belongs to a class it takes; how many were
    /// inserted. An inserted vertex belongs to `class` from then on: a face that welds with this
    /// polygon meets it there too.
    fn insert_edge_vertices(
        &mut self,
        poly: &mut Vec<u32>,
        class: WeldClass,
        inside: &[EdgeVertex],
    ) -> usize {
        let takes = class.takes();
        let mut inserted = 0;
        let mut out = Vec::with_capacity(poly.len() + inside.len());
        let mut rest = inside;
        for (k, &a) in poly.iter().enumerate() {
            out.push(a);
            let on_edge = rest.partition_point(|e| e.edge == k);
            // An edge lists a vertex once, so marking each as it is taken tests the others
            // as they were.
            for e in &rest[..on_edge] {
                if let Some(bits) = self.owners.get_mut(&e.vertex)
                    && *bits & takes != 0
                {
                    *bits |= class.bit();
                    out.push(e.vertex);
                    inserted += 1;
                }
            }
            rest = &rest[on_edge..];
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

    /// A big square and a small one beside it, whose corner 4 lies on the big one's edge.
    fn square_and_neighbour() -> (Vec<DVec3>, Vec<Vec<u32>>) {
        let positions = [
            [0.0, 0.0],
            [0.0, 64.0],
            [64.0, 64.0],
            [64.0, 0.0],
            [64.0, 32.0],
            [96.0, 0.0],
            [96.0, 32.0],
        ]
        .map(|[x, y]| DVec3::new(x, y, 0.0))
        .to_vec();
        (positions, vec![vec![0, 1, 2, 3], vec![4, 3, 5, 6]])
    }

    #[test]
    fn vertex_on_an_edge_is_inserted() {
        let (positions, mut polys) = square_and_neighbour();
        let classes = [WeldClass::Opaque; 2];
        assert_eq!(fix_tjunctions(&positions, &mut polys, &classes), 1);
        assert_eq!(polys[0], vec![0, 1, 2, 4, 3]);
    }

    /// Which faces take which faces' vertices, as ericw-tools decides (its `tjuncMatrix` test):
    /// rows are the big face's class, columns the small one's.
    #[test]
    fn faces_take_the_vertices_of_the_classes_they_weld_with() {
        use WeldClass::*;
        let all = [Opaque, DetailWall, SeeThrough, Liquid];
        let takes = [
            (Opaque, [true, false, false, true]),
            (DetailWall, [true, true, false, true]),
            (SeeThrough, [true, true, true, true]),
            (Liquid, [true, true, true, true]),
        ];
        for (big, row) in takes {
            for (small, expected) in all.into_iter().zip(row) {
                let (positions, mut polys) = square_and_neighbour();
                let inserted = fix_tjunctions(&positions, &mut polys, &[big, small]);
                assert_eq!(inserted == 1, expected, "{big:?} taking from {small:?}");
            }
        }
        // Only the polygons given are looked at: another model's vertex goes into no edge.
        let (positions, mut polys) = square_and_neighbour();
        assert_eq!(fix_tjunctions(&positions, &mut polys[..1], &[Opaque]), 0);
    }

    /// A see-through face's corner on the shared edge of a liquid face and a solid one: the
    /// liquid takes it, and then the solid face, which meets the liquid there, takes it too, or
    /// the two would crack along that edge.
    #[test]
    fn a_vertex_goes_on_to_the_faces_that_weld_with_a_face_it_went_into() {
        use WeldClass::*;
        let positions = [
            [0.0, 0.0],
            [64.0, 0.0],
            [64.0, 32.0],
            [0.0, 32.0],
            [0.0, -64.0],
            [64.0, -64.0],
            [32.0, 0.0],
            [32.0, -16.0],
            [48.0, -16.0],
        ]
        .map(|[x, y]| DVec3::new(x, y, 0.0))
        .to_vec();
        let mut polys = vec![vec![1, 0, 4, 5], vec![0, 1, 2, 3], vec![6, 7, 8]];
        let inserted = fix_tjunctions(&positions, &mut polys, &[Opaque, Liquid, SeeThrough]);
        assert_eq!(inserted, 2);
        assert!(polys[0].contains(&6) && polys[1].contains(&6), "{polys:?}");
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
