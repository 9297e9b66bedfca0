//! Crack finding on a written BSP: places where faces that meet do not share their edges, so an
//! engine's rasteriser can leave pixel gaps between them.
//!
//! Within each model it reports T-junctions (a face vertex on the open interior of another face's
//! edge), directed edges used by more than two faces and not as often as their reverse, and
//! distinct vertex indices at the same position. Faces of every kind count (sky, liquids,
//! fences): engines draw them all, so a T-junction between water and a wall shows as a crack like
//! any other. A vertex counts on an edge only when the edge's face welds with a face the vertex
//! belongs to ([`WeldClass`]): the compiler leaves the vertices of fences and illusionary brushes
//! out of solid faces' edges on purpose, as ericw-tools does, since no crack shows there. A face's
//! class is read from the BSP ([`face_class`]). Indices the validator would reject are skipped,
//! never trusted.

use crate::weld::{TJUNCTION_EPSILON, WeldClass, cell_and_neighbours};
use glam::{DVec3, Vec3};
use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::geom::DVec3Ext;
use quake_formats::geom::POINT_EPSILON;
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// Cell size of the vertex search grid.
const GRID: f64 = 64.0;

/// A vertex lying inside another face's edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TJunction {
    /// The model whose faces these are.
    pub model: usize,
    /// The face whose edge the vertex splits.
    pub face: usize,
    /// The edge's vertex indices, in the face's winding order.
    pub edge: [u32; 2],
    /// The vertex lying inside the edge.
    pub vertex: u32,
    /// That vertex's position.
    pub position: [f32; 3],
}

/// Everything [`find_cracks`] found.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct CrackReport {
    /// Vertices lying inside another face's edge.
    pub tjunctions: Vec<TJunction>,
    /// `(model, [from, to], faces)`: a directed edge used by more than two faces, and by more
    /// or fewer than its reverse.
    pub overused_edges: Vec<(usize, [u32; 2], usize)>,
    /// `(model, a, b)`: two vertex indices used by one model within [`POINT_EPSILON`].
    pub duplicate_vertices: Vec<(usize, u32, u32)>,
}

impl CrackReport {
    /// Nothing was found.
    pub fn is_empty(&self) -> bool {
        self.tjunctions.is_empty()
            && self.overused_edges.is_empty()
            && self.duplicate_vertices.is_empty()
    }

    /// One line of counts, with the first T-junction as an example.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "{} T-junctions, {} overused edges, {} duplicate vertices",
            self.tjunctions.len(),
            self.overused_edges.len(),
            self.duplicate_vertices.len()
        );
        if let Some(t) = self.tjunctions.first() {
            s += &format!(
                "; first: vertex {} {:?} inside edge {:?} of face {} (model {})",
                t.vertex, t.position, t.edge, t.face, t.model
            );
        }
        s
    }
}

/// The vertex indices of face `f` in winding order, or `None` when an index is out of range.
fn face_vertices(bsp: &Bsp, f: usize) -> Option<Vec<u32>> {
    let vs = bsp.face_vertex_indices(bsp.faces.get(f)?)?;
    vs.iter()
        .all(|&v| (v as usize) < bsp.vertices.len())
        .then_some(vs)
}

fn cell(p: DVec3) -> [i64; 3] {
    let c = |v: f64| (v / GRID).floor() as i64;
    [c(p.x), c(p.y), c(p.z)]
}

/// The grid cells within reach of segment `a..b`: those around points sampled along it.
fn cells_along(a: DVec3, b: DVec3, out: &mut BTreeSet<[i64; 3]>) {
    out.clear();
    let steps = ((b - a).length() / (GRID * 0.5)).ceil().max(1.0) as usize;
    for i in 0..=steps {
        out.extend(cell_and_neighbours(cell(
            a.lerp_monotonic(b, i as f64 / steps as f64),
        )));
    }
}

/// Find the cracks of every model of `bsp`.
pub fn find_cracks(bsp: &Bsp) -> CrackReport {
    let mut report = CrackReport::default();
    for (mi, model) in bsp.models.iter().enumerate() {
        let first = model.first_face as usize;
        let faces: Vec<(usize, Vec<u32>)> = (first..first.saturating_add(model.num_faces as usize))
            .filter_map(|f| Some((f, face_vertices(bsp, f)?)))
            .collect();
        check_model(bsp, mi, &faces, &mut report);
    }
    report
}

/// How far behind a face its back leaf is looked up: less than the thinnest brush mappers make
/// (1/16 unit), more than `f32` rounding of coordinates in the map's range.
const BEHIND: f32 = 1.0 / 64.0;

/// What face `f` of model `model` is made of, as far as a BSP tells, as the compiler classes it
/// ([`WeldClass::of`]): a liquid or a fence by its texture, an illusionary brush's by the open
/// leaf behind it; otherwise solid or sky (a `func_detail_wall`'s faces cannot be told from
/// those of solid brushes).
pub fn face_class(bsp: &Bsp, model: usize, f: usize) -> WeldClass {
    let Some(face) = bsp.faces.get(f) else {
        return WeldClass::Opaque;
    };
    let name = bsp.face_texture(face).map(|t| t.name()).unwrap_or_default();
    if name.starts_with('*') {
        return WeldClass::Liquid;
    }
    if name.starts_with('{') {
        return WeldClass::SeeThrough;
    }
    let (Some(vertices), Some(plane)) =
        (bsp.face_vertices(face), bsp.planes.get(face.plane as usize))
    else {
        return WeldClass::Opaque;
    };
    let sign = if face.side != 0 { -1.0 } else { 1.0 };
    let centre = vertices
        .iter()
        .fold(Vec3::ZERO, |sum, &v| sum + Vec3::from(v))
        / vertices.len().max(1) as f32;
    let behind = centre - Vec3::from(plane.normal) * sign * BEHIND;
    let leaf = bsp
        .models
        .get(model)
        .and_then(|m| bsp.leaf_from(m.head_nodes[0], behind.to_array()))
        .and_then(|l| bsp.leafs.get(l));
    match leaf.map(|l| l.contents) {
        Some(contents::SOLID | contents::SKY) | None => WeldClass::Opaque,
        Some(_) => WeldClass::SeeThrough,
    }
}

fn check_model(bsp: &Bsp, model: usize, faces: &[(usize, Vec<u32>)], report: &mut CrackReport) {
    let pos = |v: u32| Vec3::from(bsp.vertices[v as usize]).as_dvec3();
    let used: BTreeSet<u32> = faces
        .iter()
        .flat_map(|(_, vs)| vs.iter().copied())
        .collect();
    // The classes of the faces each vertex belongs to.
    let mut owners: HashMap<u32, Vec<WeldClass>> = HashMap::new();
    let classes: Vec<WeldClass> = faces
        .iter()
        .map(|&(f, _)| face_class(bsp, model, f))
        .collect();
    for ((_, vs), &class) in faces.iter().zip(&classes) {
        for &v in vs {
            let list = owners.entry(v).or_default();
            if !list.contains(&class) {
                list.push(class);
            }
        }
    }
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for &v in &used {
        grid.entry(cell(pos(v))).or_default().push(v);
    }

    for &v in &used {
        for c in cell_and_neighbours(cell(pos(v))) {
            for &w in grid.get(&c).into_iter().flatten() {
                if w > v && pos(w).near(pos(v), POINT_EPSILON) {
                    report.duplicate_vertices.push((model, v, w));
                }
            }
        }
    }

    let mut directed: BTreeMap<[u32; 2], usize> = BTreeMap::new();
    let mut cells = BTreeSet::new();
    for ((f, vs), &class) in faces.iter().zip(&classes) {
        let welds = |v: &u32| {
            owners
                .get(v)
                .is_some_and(|list| list.iter().any(|&o| class.welds_with(o)))
        };
        for k in 0..vs.len() {
            let (a, b) = (vs[k], vs[(k + 1) % vs.len()]);
            *directed.entry([a, b]).or_default() += 1;
            let (pa, pb) = (pos(a), pos(b));
            let d = pb - pa;
            let len = d.length();
            if len < POINT_EPSILON {
                continue;
            }
            cells_along(pa, pb, &mut cells);
            for &v in cells.iter().filter_map(|c| grid.get(c)).flatten() {
                let pv = pos(v);
                let along = (pv - pa).dot(d) / len;
                if v == a
                    || v == b
                    || !welds(&v)
                    || along <= POINT_EPSILON
                    || along >= len - POINT_EPSILON
                    || (pa + d * (along / len) - pv).length() >= TJUNCTION_EPSILON
                {
                    continue;
                }
                report.tjunctions.push(TJunction {
                    model,
                    face: *f,
                    edge: [a, b],
                    vertex: v,
                    position: bsp.vertices[v as usize],
                });
            }
        }
    }
    // Around an edge, each open sector (air, liquid) is bounded by two faces that run along the
    // edge opposite ways, and a two-sided liquid surface gives two sectors a face each: an edge
    // where more than two open sectors meet (a brush's edge lying on a liquid surface: three)
    // is used more than twice each way. Only an edge used more often one way than the other
    // has a face without its neighbour.
    let reverse_uses = |[a, b]: [u32; 2]| directed.get(&[b, a]).copied().unwrap_or(0);
    let overused: Vec<_> = directed
        .iter()
        .filter(|&(&e, &n)| n > 2 && n != reverse_uses(e))
        .map(|(&e, &n)| (model, e, n))
        .collect();
    report.overused_edges.extend(overused);
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::bsp::{BspVersion, Face, Model};

    /// A BSP with one model whose faces are the given vertex loops.
    fn bsp_of(vertices: &[[f32; 3]], loops: &[&[u32]]) -> Bsp {
        let mut bsp = Bsp::new(BspVersion::Bsp29);
        bsp.vertices = vertices.to_vec();
        bsp.edges.push([0, 0]);
        for l in loops {
            let first_edge = bsp.surfedges.len() as u32;
            for k in 0..l.len() {
                bsp.surfedges.push(bsp.edges.len() as i32);
                bsp.edges.push([l[k], l[(k + 1) % l.len()]]);
            }
            bsp.faces.push(Face {
                plane: 0,
                side: 0,
                first_edge,
                num_edges: l.len() as u32,
                texinfo: 0,
                styles: [255; 4],
                light_offset: -1,
            });
        }
        bsp.models.push(Model {
            mins: [0.0; 3],
            maxs: [0.0; 3],
            origin: [0.0; 3],
            head_nodes: [0; 4],
            vis_leafs: 0,
            first_face: 0,
            num_faces: loops.len() as u32,
        });
        bsp
    }

    const SQUARE_AND_HALVES: [[f32; 3]; 6] = [
        [0.0, 0.0, 0.0],
        [64.0, 0.0, 0.0],
        [64.0, 64.0, 0.0],
        [0.0, 64.0, 0.0],
        [128.0, 0.0, 0.0],
        [128.0, 64.0, 0.0],
    ];

    #[test]
    fn a_vertex_inside_a_neighbours_edge_is_a_tjunction() {
        // The right square is cut in two at y 32; its cut point lies inside the left one's edge.
        let mut vertices = SQUARE_AND_HALVES.to_vec();
        vertices.extend([[64.0, 32.0, 0.0], [128.0, 32.0, 0.0]]);
        let bsp = bsp_of(&vertices, &[&[0, 1, 2, 3], &[1, 4, 7, 6], &[6, 7, 5, 2]]);
        let report = find_cracks(&bsp);
        assert_eq!(report.tjunctions.len(), 1, "{}", report.summary());
        assert_eq!(
            (report.tjunctions[0].face, report.tjunctions[0].vertex),
            (0, 6)
        );

        // With the vertex inserted into the left square the edge is shared and nothing is left.
        let fixed = bsp_of(&vertices, &[&[0, 1, 6, 2, 3], &[1, 4, 7, 6], &[6, 7, 5, 2]]);
        assert!(find_cracks(&fixed).is_empty());
    }

    #[test]
    fn duplicate_positions_and_overused_edges_are_reported() {
        let mut vertices = SQUARE_AND_HALVES.to_vec();
        vertices.push([64.0, 64.0005, 0.0]);
        let bsp = bsp_of(&vertices, &[&[0, 1, 2, 3], &[1, 4, 5, 6]]);
        assert_eq!(find_cracks(&bsp).duplicate_vertices, vec![(0, 2, 6)]);

        let bsp = bsp_of(&vertices, &[&[0, 1, 2], &[0, 1, 3], &[0, 1, 5]]);
        assert_eq!(find_cracks(&bsp).overused_edges, vec![(0, [0, 1], 3)]);
    }

    #[test]
    fn an_edge_where_three_open_sectors_meet_is_no_crack() {
        // A wedge's edge lying on a two-sided water surface (generated seed 1012): the water's
        // top and bottom on both sides of the edge and the wedge's two faces all end there,
        // three faces running along the edge each way. Every vertex is shared: no crack.
        let vertices = [
            [0.0, 0.0, 0.0],
            [64.0, 0.0, 0.0],
            [64.0, -32.0, 0.0],
            [0.0, -32.0, 0.0],
            [64.0, 32.0, 0.0],
            [0.0, 32.0, 0.0],
            [64.0, -16.0, 16.0],
            [0.0, -16.0, 16.0],
            [64.0, 16.0, 16.0],
            [0.0, 16.0, 16.0],
        ];
        let water_top = [&[0, 1, 2, 3][..], &[1, 0, 5, 4]];
        let water_bottom = [&[3, 2, 1, 0][..], &[4, 5, 0, 1]];
        let wedge = [&[0, 1, 6, 7][..], &[1, 0, 9, 8]];
        let loops: Vec<&[u32]> = water_top
            .into_iter()
            .chain(water_bottom)
            .chain(wedge)
            .collect();
        let report = find_cracks(&bsp_of(&vertices, &loops));
        assert!(report.is_empty(), "{}", report.summary());

        // Without one of the water's top faces the edge is used more one way than the other.
        let report = find_cracks(&bsp_of(&vertices, &loops[1..]));
        assert_eq!(report.overused_edges, vec![(0, [1, 0], 3)]);
    }

    #[test]
    fn out_of_range_indices_are_skipped() {
        let mut bsp = bsp_of(&SQUARE_AND_HALVES, &[&[0, 1, 2, 3]]);
        bsp.surfedges[2] = 99;
        bsp.models[0].num_faces = 5;
        assert!(find_cracks(&bsp).is_empty());
    }
}
