//! Helpers shared by the decompiler's tests: compiling maps, decompiling and measuring how far a
//! recompiled map is from the original.

#![allow(dead_code)] // each test crate uses its own subset

use bsp_compiler::{CompileOptions, CompileOutput, MapSource, Warning, compile};
use decompile::{Decompiled, Options, decompile};
use glam::DVec3;
use quake_formats::Bsp;
use quake_formats::bsp::contents;
use quake_formats::geom::Plane;
use quake_formats::rng::SplitMix64;
use std::path::{Path, PathBuf};

/// The project's `maps/` folder (it holds `slipgate.wad`).
pub fn maps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps")
}

/// Compile `text` as if it were the file `path` (which need not exist: WADs are looked for
/// beside it and in `maps/`).
pub fn compile_text(path: &Path, text: String) -> CompileOutput {
    let options = CompileOptions {
        wad_dirs: vec![maps_dir()],
        ..CompileOptions::default()
    };
    let source = MapSource {
        path: path.to_path_buf(),
        text,
    };
    compile(&source, &options).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Compile the map file at `path`.
pub fn compile_file(path: &Path) -> CompileOutput {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    compile_text(path, text)
}

/// Decompile `bsp` and compile the result again (as a file named `name` in `maps/`), checking
/// that it compiles sealed and with every brush good.
pub fn round_trip(bsp: &Bsp, options: &Options, name: &str) -> (Decompiled, CompileOutput) {
    let decompiled = decompile(bsp, options).expect("decompile");
    let again = compile_text(&maps_dir().join(name), decompiled.text.clone());
    assert!(again.leak.is_none(), "{name}: the decompiled map leaks");
    let bad: Vec<String> = again
        .warnings
        .iter()
        .filter(|w| matches!(w, Warning::BadBrush { .. }))
        .map(|w| w.to_string())
        .collect();
    assert!(
        bad.is_empty() && again.stats.bad_brushes == 0,
        "{name}: bad brushes in the decompiled map: {bad:?}"
    );
    (decompiled, again)
}

/// The contents at `p` in the hull 0 tree below `head`, and how far `p` is from the boundary of
/// its leaf's region (the nearest of the planes on its path: the region is their intersection).
pub fn contents_and_clearance(bsp: &Bsp, head: i32, p: DVec3) -> (i32, f64) {
    let mut node = head;
    let mut clearance = f64::INFINITY;
    while node >= 0 {
        let n = &bsp.nodes[node as usize];
        let plane = &bsp.planes[n.plane as usize];
        let normal = DVec3::from(plane.normal.map(f64::from));
        let d = normal.dot(p) - f64::from(plane.dist);
        clearance = clearance.min(d.abs());
        node = n.children[usize::from(d < 0.0)];
    }
    let leaf = (-(node + 1)) as usize;
    (bsp.leafs[leaf].contents, clearance)
}

/// How two BSPs' hull 0 contents compare at sampled points.
#[derive(Debug, Default, Clone, Copy)]
pub struct Agreement {
    pub samples: usize,
    pub agree: usize,
    /// Disagreements within the tolerance of a leaf boundary in either tree.
    pub near_boundary: usize,
    /// Disagreements further from every boundary.
    pub far: usize,
}

/// Compare the contents of model `model` of `a` and `b` at `samples` points spread through `a`'s
/// bounds of that model (seeded, so every run samples the same points).
pub fn contents_agreement(
    a: &Bsp,
    b: &Bsp,
    model: usize,
    samples: usize,
    tolerance: f64,
) -> Agreement {
    let (ma, mb) = (&a.models[model], &b.models[model]);
    let lo = DVec3::from(ma.mins.map(f64::from));
    let hi = DVec3::from(ma.maxs.map(f64::from));
    let mut rng = SplitMix64::new(0x5eed_dec0);
    let mut out = Agreement {
        samples,
        ..Agreement::default()
    };
    for _ in 0..samples {
        let p = DVec3::new(
            rng.range(lo.x, hi.x),
            rng.range(lo.y, hi.y),
            rng.range(lo.z, hi.z),
        );
        let (ca, da) = contents_and_clearance(a, ma.head_nodes[0], p);
        let (cb, db) = contents_and_clearance(b, mb.head_nodes[0], p);
        if ca == cb {
            out.agree += 1;
        } else if da.min(db) < tolerance {
            out.near_boundary += 1;
        } else {
            out.far += 1;
            eprintln!(
                "  contents differ at {p}: {ca} before, {cb} after ({da:.3} and {db:.3} from a boundary)"
            );
        }
    }
    out
}

/// A face's texture name, texinfo rows, plane (facing the way the face does) and polygon.
pub struct FaceInfo {
    pub texture: String,
    pub rows: [[f64; 4]; 2],
    pub plane: Plane,
    pub points: Vec<DVec3>,
}

/// Every face of model `model`.
pub fn faces(bsp: &Bsp, model: usize) -> Vec<FaceInfo> {
    let m = &bsp.models[model];
    let range = m.first_face as usize..(m.first_face + m.num_faces) as usize;
    bsp.faces[range]
        .iter()
        .map(|f| {
            let p = &bsp.planes[f.plane as usize];
            let mut plane = Plane::new(DVec3::from(p.normal.map(f64::from)), f64::from(p.dist));
            if f.side != 0 {
                plane = plane.flipped();
            }
            let info = &bsp.texinfo[f.texinfo as usize];
            let texture = bsp.textures.textures[info.miptex as usize]
                .as_ref()
                .map(|t| t.name())
                .unwrap_or_default();
            FaceInfo {
                texture,
                rows: info.vecs.map(|r| r.map(f64::from)),
                plane,
                points: bsp
                    .face_vertices(f)
                    .expect("face")
                    .iter()
                    .map(|v| DVec3::from(v.map(f64::from)))
                    .collect(),
            }
        })
        .collect()
}

impl FaceInfo {
    /// The mean of the corners.
    pub fn centre(&self) -> DVec3 {
        self.points.iter().sum::<DVec3>() / self.points.len() as f64
    }

    /// Whether `p` lies on the face (within `eps` of its plane and inside its edges).
    pub fn holds(&self, p: DVec3, eps: f64) -> bool {
        if self.plane.distance(p).abs() > eps {
            return false;
        }
        let n = self.points.len();
        // The corners wind clockwise seen from the front.
        (0..n).all(|i| {
            let (a, b) = (self.points[i], self.points[(i + 1) % n]);
            let inward = (b - a).cross(self.plane.normal);
            let len = inward.length();
            len < 1e-9 || inward.dot(p - a) / len >= -eps
        })
    }
}

/// How the textures of a recompiled model compare with the original's at its faces' centres.
#[derive(Debug, Default, Clone, Copy)]
pub struct TextureAgreement {
    pub faces: usize,
    /// Original faces whose centre lies on no face of the recompiled model facing the same way.
    pub unmatched: usize,
    pub same_texture: usize,
    /// Of those with the same texture: the same projection (axes within 1e-4, offsets within
    /// `offset_tolerance` texels).
    pub same_projection: usize,
}

/// Compare the faces of model `model` of `a` with those of `b` at `a`'s face centres.
pub fn texture_agreement(
    a: &Bsp,
    b: &Bsp,
    model: usize,
    offset_tolerance: f64,
) -> TextureAgreement {
    let (fa, fb) = (faces(a, model), faces(b, model));
    let mut out = TextureAgreement::default();
    for f in &fa {
        out.faces += 1;
        let c = f.centre();
        let Some(g) = fb
            .iter()
            .find(|g| g.plane.normal.dot(f.plane.normal) > 0.999 && g.holds(c, 0.05))
        else {
            out.unmatched += 1;
            eprintln!("  no face at {c} facing {}", f.plane.normal);
            continue;
        };
        if g.texture != f.texture {
            eprintln!(
                "  at {c}: {} became {} ({:?} on {:?})",
                f.texture, g.texture, f.points, g.points
            );
            continue;
        }
        out.same_texture += 1;
        let same = (0..2).all(|i| {
            (0..3).all(|k| (f.rows[i][k] - g.rows[i][k]).abs() < 1e-4)
                && (f.rows[i][3] - g.rows[i][3]).abs() <= offset_tolerance
        });
        if same {
            out.same_projection += 1;
        } else {
            eprintln!(
                "  at {c} ({}): projection {:?} became {:?}",
                f.texture, f.rows, g.rows
            );
        }
    }
    out
}

/// A brush side of a `.map` file: its plane, polygon, texture and texinfo rows.
pub struct MapSideInfo {
    pub texture: String,
    pub rows: [[f64; 4]; 2],
    pub face: FaceInfo,
}

/// The brush sides of entity `entity` of `text`, in the entity's coordinates less `origin`.
pub fn map_sides(text: &str, entity: usize, origin: DVec3) -> Vec<MapSideInfo> {
    let map = bsp_compiler::map::parse_map(Path::new("decompiled.map"), text).expect("parse");
    let mut out = Vec::new();
    for brush in &map.entities[entity].brushes {
        let planes: Vec<Plane> = brush
            .faces
            .iter()
            .map(|f| f.plane(origin).expect("plane"))
            .collect();
        for (i, f) in brush.faces.iter().enumerate() {
            let mut w = Some(quake_formats::geom::Winding::base_for_plane(&planes[i]));
            for (j, other) in planes.iter().enumerate() {
                if i != j {
                    w = w.and_then(|w| w.clip_front(&other.flipped(), false));
                }
            }
            let Some(w) = w else { continue };
            let rows = f.projection.vecs(&planes[i]);
            out.push(MapSideInfo {
                texture: f.texture.clone(),
                rows,
                face: FaceInfo {
                    texture: f.texture.clone(),
                    rows,
                    plane: planes[i],
                    points: w.points,
                },
            });
        }
    }
    out
}

/// How the brush sides of a decompiled map compare with the original BSP's faces they cover.
#[derive(Debug, Default, Clone, Copy)]
pub struct SideAgreement {
    pub faces: usize,
    /// Faces seen from inside a liquid or sky whose back is open space (the underside of a
    /// water surface): no brush has a side there, the compiler makes them from the liquid's.
    pub inside_liquid: usize,
    /// Faces whose centre lies on no brush side facing the same way.
    pub uncovered: usize,
    /// Faces every brush side at whose centre carries the face's texture and projection.
    pub same: usize,
}

/// Compare the faces of model `model` of `bsp` with the brush sides of entity `entity` of the
/// decompiled `text` (written with `origin`) at the faces' centres.
pub fn side_agreement(
    bsp: &Bsp,
    model: usize,
    text: &str,
    entity: usize,
    origin: DVec3,
) -> SideAgreement {
    let sides = map_sides(text, entity, origin);
    let mut out = SideAgreement::default();
    for f in faces(bsp, model) {
        out.faces += 1;
        let c = f.centre();
        let m = &bsp.models[model];
        let (behind, _) = contents_and_clearance(bsp, m.head_nodes[0], c - f.plane.normal * 0.1);
        if behind == contents::EMPTY {
            out.inside_liquid += 1;
            continue;
        }
        let on: Vec<&MapSideInfo> = sides
            .iter()
            .filter(|s| s.face.plane.normal.dot(f.plane.normal) > 0.999 && s.face.holds(c, 0.01))
            .collect();
        if on.is_empty() {
            out.uncovered += 1;
            eprintln!("  no brush side at {c} facing {}", f.plane.normal);
            continue;
        }
        let same = |s: &&MapSideInfo| {
            s.texture == f.texture
                && (0..2).all(|i| {
                    (0..3).all(|k| (f.rows[i][k] - s.rows[i][k]).abs() < 1e-5)
                        && (f.rows[i][3] - s.rows[i][3]).abs() < 1e-3
                })
        };
        if on.iter().all(same) {
            out.same += 1;
        } else {
            let got: Vec<(&str, [[f64; 4]; 2])> =
                on.iter().map(|s| (s.texture.as_str(), s.rows)).collect();
            eprintln!("  at {c}: {} {:?} written as {got:?}", f.texture, f.rows);
        }
    }
    out
}
