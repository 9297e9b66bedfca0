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
    compile_with_wads(path, text, vec![maps_dir()])
}

/// Compile `text` as if it were the file `path`, looking for WADs in `wad_dirs`.
pub fn compile_with_wads(path: &Path, text: String, wad_dirs: Vec<PathBuf>) -> CompileOutput {
    let options = CompileOptions {
        wad_dirs,
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
    round_trip_with_wads(bsp, options, name, vec![maps_dir()])
}

/// [`round_trip`], looking for WADs in `wad_dirs`.
pub fn round_trip_with_wads(
    bsp: &Bsp,
    options: &Options,
    name: &str,
    wad_dirs: Vec<PathBuf>,
) -> (Decompiled, CompileOutput) {
    let decompiled = decompile(bsp, options).expect("decompile");
    let again = compile_with_wads(&maps_dir().join(name), decompiled.text.clone(), wad_dirs);
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

/// A face's texture name and size, texinfo rows, plane (facing the way the face does) and
/// polygon.
pub struct FaceInfo {
    pub texture: String,
    pub size: [f64; 2],
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
            let miptex = bsp.textures.textures[info.miptex as usize].as_ref();
            FaceInfo {
                texture: miptex.map_or("notexture".to_string(), |t| t.name()),
                size: miptex.map_or([0.0; 2], |t| [f64::from(t.width), f64::from(t.height)]),
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

    /// Whether `rows` give this face's corners the texture coordinates its own rows do, to
    /// within `tolerance` texels, or coordinates a whole texture further on (which look the
    /// same). Rows that differ by a multiple of the face's normal do that on its plane.
    pub fn same_projection(&self, rows: &[[f64; 4]; 2], tolerance: f64) -> bool {
        let at = |r: &[f64; 4], p: DVec3| DVec3::new(r[0], r[1], r[2]).dot(p) + r[3];
        (0..2).all(|i| {
            let diffs: Vec<f64> = self
                .points
                .iter()
                .map(|&p| at(&self.rows[i], p) - at(&rows[i], p))
                .collect();
            let lo = diffs.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = diffs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let mut d = ((lo + hi) / 2.0).abs();
            if self.size[i] > 0.0 {
                d %= self.size[i];
                d = d.min(self.size[i] - d);
            }
            hi - lo <= tolerance && d <= tolerance
        })
    }
}

/// Where a face of a BSP comes from, as the decompiler sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaceKind {
    /// A side of a filled leaf (solid, liquid, sky) seen from open space or a liquid: a brush
    /// side of the decompiled map lies under it.
    BrushSide,
    /// Open space behind it: the underside of a liquid's surface (the compiler makes it from the
    /// liquid brush's side) or a face of a brush without collision (lost).
    OpenBehind,
    /// Seen only from inside sky, which Slipgate's compiler does not draw (ericw-tools does).
    IntoSky,
    /// The same contents on both sides (ericw-tools writes a few between solid brushes): no
    /// boundary of contents lies there for a brush side to bound.
    NoBoundary,
}

/// What face `f` of model `model` of `bsp` is.
pub fn face_kind(bsp: &Bsp, model: usize, f: &FaceInfo) -> FaceKind {
    let head = bsp.models[model].head_nodes[0];
    let c = f.centre();
    let front = contents_and_clearance(bsp, head, c + f.plane.normal * 0.1).0;
    let behind = contents_and_clearance(bsp, head, c - f.plane.normal * 0.1).0;
    if behind == contents::EMPTY {
        FaceKind::OpenBehind
    } else if front == behind {
        FaceKind::NoBoundary
    } else if front == contents::SKY {
        FaceKind::IntoSky
    } else {
        FaceKind::BrushSide
    }
}

/// How a map's faces compare with the original BSP's brush-side faces ([`FaceKind::BrushSide`])
/// at those faces' centres.
#[derive(Debug, Default, Clone, Copy)]
pub struct TextureAgreement {
    /// Faces of the original.
    pub faces: usize,
    /// Faces of the original that are no brush side (not compared).
    pub open_behind: usize,
    pub into_sky: usize,
    pub no_boundary: usize,
    /// Brush-side faces whose centre lies on nothing facing the same way.
    pub unmatched: usize,
    /// Brush-side faces where everything at the centre has the same texture.
    pub same_texture: usize,
    /// Of those: the same projection too.
    pub same_projection: usize,
}

impl TextureAgreement {
    /// The faces compared.
    pub fn compared(&self) -> usize {
        self.faces - self.open_behind - self.into_sky - self.no_boundary
    }
}

/// Compare the brush-side faces of model `model` of `original` with `candidates` (faces or brush
/// sides, as `FaceInfo`s) at the faces' centres.
fn agreement(
    original: &Bsp,
    model: usize,
    candidates: &[FaceInfo],
    offset_tolerance: f64,
) -> TextureAgreement {
    let mut out = TextureAgreement::default();
    for f in faces(original, model) {
        out.faces += 1;
        match face_kind(original, model, &f) {
            FaceKind::OpenBehind => {
                out.open_behind += 1;
                continue;
            }
            FaceKind::IntoSky => {
                out.into_sky += 1;
                continue;
            }
            FaceKind::NoBoundary => {
                out.no_boundary += 1;
                continue;
            }
            FaceKind::BrushSide => {}
        }
        let c = f.centre();
        // What lies on the face: the candidates through its centre on its plane, or where
        // two planes nearly coincide there (a wedge between two brushes), those on the nearer.
        let gap = |g: &FaceInfo| {
            g.plane.distance(c).abs() + 1000.0 * (1.0 - g.plane.normal.dot(f.plane.normal))
        };
        let through: Vec<&FaceInfo> = candidates
            .iter()
            .filter(|g| g.plane.normal.dot(f.plane.normal) > 0.999 && g.holds(c, 0.05))
            .collect();
        let nearest = through.iter().map(|g| gap(g)).fold(f64::INFINITY, f64::min);
        let on: Vec<&FaceInfo> = through
            .into_iter()
            .filter(|g| gap(g) <= nearest + 1e-3)
            .collect();
        if on.is_empty() {
            out.unmatched += 1;
            eprintln!("  nothing at {c} facing {} ({})", f.plane.normal, f.texture);
            continue;
        }
        if !on.iter().all(|g| g.texture == f.texture) {
            let got: Vec<&str> = on.iter().map(|g| g.texture.as_str()).collect();
            eprintln!("  at {c}: {} became {got:?}", f.texture);
            if std::env::var_os("DECOMPILE_DEBUG").is_some() {
                eprintln!("    face {:?} {:?}", f.plane, f.points);
                for g in &on {
                    eprintln!("    {} {:?} {:?}", g.texture, g.plane, g.points);
                }
            }
            continue;
        }
        out.same_texture += 1;
        if on
            .iter()
            .all(|g| f.same_projection(&g.rows, offset_tolerance))
        {
            out.same_projection += 1;
        } else {
            let got: Vec<_> = on.iter().map(|g| g.rows).collect();
            eprintln!(
                "  at {c} ({}): projection {:?} became {got:?}",
                f.texture, f.rows
            );
        }
    }
    out
}

/// Compare the faces of model `model` of `a` with those of `b` (a recompile) at `a`'s face
/// centres.
pub fn texture_agreement(
    a: &Bsp,
    b: &Bsp,
    model: usize,
    offset_tolerance: f64,
) -> TextureAgreement {
    agreement(a, model, &faces(b, model), offset_tolerance)
}

/// The brush sides of entity `entity` of `text`, in the entity's coordinates less `origin`.
pub fn map_sides(text: &str, entity: usize, origin: DVec3) -> Vec<FaceInfo> {
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
            out.push(FaceInfo {
                texture: f.texture.clone(),
                size: [0.0; 2],
                rows: f.projection.vecs(&planes[i]),
                plane: planes[i],
                points: w.points,
            });
        }
    }
    out
}

/// Compare the faces of model `model` of `bsp` with the brush sides of entity `entity` of the
/// decompiled `text` (written with `origin`) at the faces' centres: every brush side there must
/// carry the face's texture and projection (coordinates within a hundredth of a texel: the
/// rows are `f32`, and the decompiler takes their noise off).
pub fn side_agreement(
    bsp: &Bsp,
    model: usize,
    text: &str,
    entity: usize,
    origin: DVec3,
) -> TextureAgreement {
    agreement(bsp, model, &map_sides(text, entity, origin), 0.01)
}
