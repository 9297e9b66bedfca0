//! A small model of a `.map` file (entities, brushes, faces) and its text writer, in the standard
//! Quake format or Valve 220.

use glam::DVec3;
use quake_formats::geom::{Bounds, Plane};

/// One brush face: three points on its plane, listed so that `(p1 - p2) x (p3 - p2)` points out
/// of the brush (the `.map` convention [`Plane::from_points`] follows).
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    pub points: [DVec3; 3],
    pub texture: String,
}

impl Face {
    pub fn new(points: [DVec3; 3], texture: &str) -> Face {
        Face {
            points: points.map(|p| DVec3::new(snap(p.x), snap(p.y), snap(p.z))),
            texture: texture.to_string(),
        }
    }

    pub fn plane(&self) -> Option<Plane> {
        let [a, b, c] = self.points;
        Plane::from_points(a, b, c)
    }
}

/// A convex brush: the intersection of the half-spaces behind its faces.
#[derive(Debug, Clone, PartialEq)]
pub struct Brush {
    pub faces: Vec<Face>,
}

/// Face order of the six-sided builders: -X, +X, -Y, +Y, -Z, +Z.
pub type SixTextures<'a> = [&'a str; 6];

impl Brush {
    /// An axis-aligned box with one texture.
    pub fn cuboid(b: Bounds, texture: &str) -> Brush {
        Brush::cuboid_faces(b, [texture; 6])
    }

    pub fn cuboid_faces(b: Bounds, textures: SixTextures) -> Brush {
        Brush::hexahedron(box_corners(b), textures)
    }

    /// A six-sided brush from the corners of a (transformed) box: corner `i` has the high X when
    /// bit 0 of `i` is set, high Y for bit 1, high Z for bit 2. The corners of each side must be
    /// coplanar and the transform orientation-preserving (a rotation, shear or translation).
    pub fn hexahedron(corners: [DVec3; 8], textures: SixTextures) -> Brush {
        let mut faces = Vec::with_capacity(6);
        for axis in 0..3 {
            let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
            for high in [false, true] {
                let corner = |ci: usize, cj: usize| {
                    corners[(usize::from(high) << axis) | (ci << i) | (cj << j)]
                };
                // (a - b) x (c - b) = e_i x e_j = +e_axis; swapping a and c faces -e_axis.
                let (a, b, c) = (corner(1, 0), corner(0, 0), corner(0, 1));
                let points = if high { [a, b, c] } else { [c, b, a] };
                faces.push(Face::new(points, textures[2 * axis + usize::from(high)]));
            }
        }
        Brush { faces }
    }

    /// A five-sided wedge: [`Brush::hexahedron`]'s box cut along the diagonal from its low-Z
    /// high-Y edge to its high-Z low-Y edge, keeping the low-Y low-Z half. Textures: -X, +X, -Y,
    /// -Z, the slope.
    pub fn wedge(corners: [DVec3; 8], textures: [&str; 5]) -> Brush {
        let box_faces = Brush::hexahedron(
            corners,
            [
                textures[0],
                textures[1],
                textures[2],
                textures[4],
                textures[3],
                textures[4],
            ],
        )
        .faces;
        let mut faces: Vec<Face> = [0, 1, 2, 4]
            .into_iter()
            .map(|i| box_faces[i].clone())
            .collect();
        faces.push(Face::new([corners[4], corners[2], corners[3]], textures[4]));
        Brush { faces }
    }
}

/// The eight corners of a box in [`Brush::hexahedron`]'s order.
pub fn box_corners(b: Bounds) -> [DVec3; 8] {
    std::array::from_fn(|i| {
        let pick = |bit: usize, axis: usize| {
            if i & bit != 0 {
                b.maxs[axis]
            } else {
                b.mins[axis]
            }
        };
        DVec3::new(pick(1, 0), pick(2, 1), pick(4, 2))
    })
}

/// A box from its low and high corners.
pub fn aabb(lo: [f64; 3], hi: [f64; 3]) -> Bounds {
    Bounds {
        mins: DVec3::new(lo[0], lo[1], lo[2]),
        maxs: DVec3::new(hi[0], hi[1], hi[2]),
    }
}

/// Coordinates are written with at most four decimals; snapping them when the face is built keeps
/// the model identical to what a parser reads back.
fn snap(v: f64) -> f64 {
    (v * 1e4).round() / 1e4 + 0.0
}

/// An entity with its key/value pairs in order and its brushes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MapEntity {
    pub keys: Vec<(String, String)>,
    pub brushes: Vec<Brush>,
}

impl MapEntity {
    pub fn new(classname: &str) -> MapEntity {
        MapEntity::default().key("classname", classname)
    }

    /// A point entity at `origin`.
    pub fn point(classname: &str, origin: [f64; 3]) -> MapEntity {
        let origin = origin.map(|c| c.to_string()).join(" ");
        MapEntity::new(classname).key("origin", &origin)
    }

    pub fn key(mut self, key: &str, value: &str) -> MapEntity {
        self.keys.push((key.to_string(), value.to_string()));
        self
    }

    pub fn brushes(mut self, brushes: impl IntoIterator<Item = Brush>) -> MapEntity {
        self.brushes.extend(brushes);
        self
    }

    pub fn get(&self, key: &str) -> Option<&str> {
        self.keys
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapFormat {
    /// `( p1 ) ( p2 ) ( p3 ) tex xoff yoff rot xscale yscale`
    Standard,
    /// `( p1 ) ( p2 ) ( p3 ) tex [ ux uy uz uoff ] [ vx vy vz voff ] rot xscale yscale`
    Valve220,
}

/// A whole `.map` file: leading `//` comment lines, then the entities (worldspawn first).
#[derive(Debug, Clone, PartialEq)]
pub struct Map {
    pub comment: Vec<String>,
    pub format: MapFormat,
    pub entities: Vec<MapEntity>,
}

impl Map {
    pub fn brush_count(&self) -> usize {
        self.entities.iter().map(|e| e.brushes.len()).sum()
    }

    /// Every texture name the map's faces use, sorted, without repeats.
    pub fn textures(&self) -> Vec<String> {
        let mut names: Vec<String> = self
            .entities
            .iter()
            .flat_map(|e| &e.brushes)
            .flat_map(|b| &b.faces)
            .map(|f| f.texture.clone())
            .collect();
        names.sort();
        names.dedup();
        names
    }

    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for line in &self.comment {
            out.push_str(&format!("// {line}\n"));
        }
        for (index, entity) in self.entities.iter().enumerate() {
            out.push_str(&format!("// entity {index}\n"));
            out.push_str("{\n");
            for (k, v) in &entity.keys {
                out.push_str(&format!("\"{k}\" \"{v}\"\n"));
            }
            for (index, brush) in entity.brushes.iter().enumerate() {
                out.push_str(&format!("// brush {index}\n"));
                out.push_str("{\n");
                for face in &brush.faces {
                    self.write_face(&mut out, face);
                }
                out.push_str("}\n");
            }
            out.push_str("}\n");
        }
        out
    }

    fn write_face(&self, out: &mut String, face: &Face) {
        for p in face.points {
            out.push_str(&format!("( {} {} {} ) ", p.x, p.y, p.z));
        }
        out.push_str(&face.texture);
        match self.format {
            MapFormat::Standard => out.push_str(" 0 0 0 1 1\n"),
            MapFormat::Valve220 => {
                let (u, v) = face
                    .plane()
                    .map_or(BASE_AXES[0], |p| texture_axes(p.normal));
                out.push_str(&format!(
                    " [ {} {} {} 0 ] [ {} {} {} 0 ] 0 1 1\n",
                    u[0], u[1], u[2], v[0], v[1], v[2]
                ));
            }
        }
    }
}

type Axes = ([i8; 3], [i8; 3]);

/// World-aligned texture axes by the face's closest axis (floor/ceiling, X walls, Y walls), the
/// projection the standard format implies, written out explicitly for Valve 220.
const BASE_AXES: [Axes; 3] = [
    ([1, 0, 0], [0, -1, 0]),
    ([0, 1, 0], [0, 0, -1]),
    ([1, 0, 0], [0, 0, -1]),
];

fn texture_axes(normal: DVec3) -> Axes {
    // Ties go to the floor axes first, as in Quake.
    let mut best = 2;
    for axis in [0, 1] {
        if normal[axis].abs() > normal[best].abs() + 1e-9 {
            best = axis;
        }
    }
    BASE_AXES[(best + 1) % 3]
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::geom::DVec3Ext;

    fn faces_point_out(brush: &Brush) -> bool {
        let center = brush
            .faces
            .iter()
            .flat_map(|f| f.points)
            .fold(DVec3::ZERO, |acc, p| acc + p)
            / 18.0;
        brush.faces.iter().all(|f| {
            let plane = f.plane().expect("non-degenerate face");
            plane.distance(center) < 0.0 && f.points.iter().all(|&p| plane.distance(p).abs() < 1e-9)
        })
    }

    #[test]
    fn box_face_normals_point_away_from_the_centre() {
        let b = aabb([-16.0, 8.0, 0.0], [48.0, 72.0, 128.0]);
        let brush = Brush::cuboid(b, "brick1");
        assert!(faces_point_out(&brush));
        let normals: Vec<DVec3> = brush
            .faces
            .iter()
            .map(|f| f.plane().expect("plane").normal)
            .collect();
        let expected = [
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0],
            [0.0, 0.0, 1.0],
        ];
        for (n, e) in normals.iter().zip(expected) {
            assert!(
                n.near(DVec3::new(e[0], e[1], e[2]), 1e-12),
                "{n:?} != {e:?}"
            );
        }
    }

    #[test]
    fn matches_a_face_from_ids_e1m1() {
        // id's e1m1.map writes the -X side of a box spanning x 448..512 like this.
        let id = Face::new(
            [
                DVec3::new(448.0, -320.0, 64.0),
                DVec3::new(448.0, -384.0, 64.0),
                DVec3::new(448.0, -384.0, 0.0),
            ],
            "x",
        );
        let ours = &Brush::cuboid(aabb([448.0, -384.0, 0.0], [512.0, -320.0, 64.0]), "x").faces[0];
        assert!(
            ours.plane()
                .expect("plane")
                .same_as(&id.plane().expect("plane"))
        );
    }

    #[test]
    fn standard_and_valve_faces_are_written_as_parsers_expect() {
        let brush = Brush::cuboid(aabb([0.0, 0.0, 0.0], [64.0, 64.0, 12.5]), "floor1");
        let entity = MapEntity::new("worldspawn").brushes([brush]);
        let mut map = Map {
            comment: vec!["test".into()],
            format: MapFormat::Standard,
            entities: vec![entity],
        };
        let text = map.to_text();
        assert!(text.starts_with("// test\n"));
        assert!(text.contains("( 64 0 12.5 ) ( 0 0 12.5 ) ( 0 64 12.5 ) floor1 0 0 0 1 1\n"));
        map.format = MapFormat::Valve220;
        let text = map.to_text();
        assert!(text.contains("floor1 [ 1 0 0 0 ] [ 0 -1 0 0 ] 0 1 1\n"));
        assert!(text.contains("floor1 [ 0 1 0 0 ] [ 0 0 -1 0 ] 0 1 1\n"));
    }
}
