//! The reference renderer: one ray per pixel centre through the BSP tree, exact perspective, the
//! same lit texels and mip choice as the fast renderer. Slow and simple on purpose: it defines
//! what the fast renderer should draw. [`compare`] measures how far a frame is from it.

use glam::DVec3;
use std::collections::HashMap;

use quake_formats::bsp::contents;

use crate::camera::{Camera, NEAR_CLIP, View};
use crate::render::Frame;
use crate::surface_cache::{LightStyles, LitSurface, TRANSPARENT, build_lit_surface, choose_mip};
use crate::textures::{TextureKind, WarpTable, liquid_color, sky_color};
use crate::world::{Surface, World};

/// How far rays go (depth units).
const MAX_DEPTH: f64 = 1.0e6;
/// A hit point this close (map units) outside a polygon's edge still counts as inside.
const EDGE_TOLERANCE: f64 = 1e-4;

enum Trace {
    Miss,
    Hit(u32, f64),
    Blocked,
}

/// Draw `camera`'s view by ray casting; lighting with `styles`, liquids warped at `time`.
/// Fences are seen through where their texels are transparent: the nearest fence texel that is
/// not, in front of the first opaque face, is what a pixel shows.
pub fn render_reference(world: &World, camera: &Camera, styles: &LightStyles, time: f64) -> Frame {
    let view = camera.view();
    let mut shader = Shader {
        world,
        view: &view,
        styles,
        warp: WarpTable::new(time),
        lit: HashMap::new(),
    };
    let mut frame = Frame::new(camera.width, camera.height);
    let mut fences = Vec::new();
    for y in 0..camera.height {
        for x in 0..camera.width {
            let dir = view.ray(x as f64 + 0.5, y as f64 + 0.5);
            let opaque = first_hit(world, &view, dir);
            fence_hits(world, &view, dir, opaque.map(|(_, d)| d), &mut fences);
            let shown = fences
                .iter()
                .copied()
                .chain(opaque)
                .find_map(|(face, depth)| Some((face, shader.color(face, dir, depth)?)));
            if let Some((face, color)) = shown {
                let i = y * camera.width + x;
                frame.faces[i] = face;
                frame.pixels[i] = color;
            }
        }
    }
    frame
}

/// Colours of surface points, with the lit surfaces built so far.
struct Shader<'a> {
    world: &'a World,
    view: &'a View,
    styles: &'a LightStyles,
    warp: WarpTable,
    lit: HashMap<(u32, usize), LitSurface>,
}

impl Shader<'_> {
    /// The colour of `face` where the ray along `dir` meets it at `depth`; `None` for a hole
    /// in a fence.
    fn color(&mut self, face: u32, dir: DVec3, depth: f64) -> Option<u32> {
        let world = self.world;
        let surface = world.surfaces[face as usize].as_ref()?;
        let tex = &world.textures[surface.texture];
        let (s, t) = surface.st(self.view.origin + dir * depth);
        let ext = surface.extents;
        let color = match surface.kind {
            TextureKind::Sky => sky_color(tex, &world.palette, dir),
            TextureKind::Liquid => {
                let texel = |c: f64, axis: usize| {
                    let rel = (c - ext.tex_mins[axis] as f64).floor();
                    rel.clamp(0.0, (ext.extents[axis].max(1) - 1) as f64) as i32
                        + ext.tex_mins[axis]
                };
                liquid_color(tex, &world.palette, &self.warp, texel(s, 0), texel(t, 1))
            }
            TextureKind::Lit | TextureKind::Fence => {
                let mip = choose_mip(self.view, surface);
                let styles = self.styles;
                let ls = self
                    .lit
                    .entry((face, mip))
                    .or_insert_with(|| build_lit_surface(world, surface, mip, styles));
                let texel = |c: f64, axis: usize, size: usize| {
                    let rel = ((c - ext.tex_mins[axis] as f64) / (1 << mip) as f64).floor();
                    rel.clamp(0.0, (size - 1) as f64) as usize
                };
                ls.texels[texel(t, 1, ls.height) * ls.width + texel(s, 0, ls.width)]
            }
        };
        (color != TRANSPARENT).then_some(color)
    }
}

/// Depth at which the ray along `dir` meets the front of `s` inside its polygon.
fn ray_hit(s: &Surface, view: &View, dir: DVec3) -> Option<f64> {
    let eye = s.plane.distance(view.origin);
    let along = s.plane.normal.dot(dir);
    if eye <= 0.0 || along >= 0.0 {
        return None;
    }
    let depth = -eye / along;
    (depth >= NEAR_CLIP && inside(s, view.origin + dir * depth)).then_some(depth)
}

/// The nearest opaque face along `dir` (depth-scaled: the point is `origin + dir * depth`).
fn first_hit(world: &World, view: &View, dir: DVec3) -> Option<(u32, f64)> {
    let world_hit = match world.root() {
        Some(root) => match trace(world, root, view.origin, dir, NEAR_CLIP, MAX_DEPTH) {
            Trace::Hit(f, d) => Some((f, d)),
            Trace::Miss | Trace::Blocked => None,
        },
        None => None,
    };
    let mut best = world_hit;
    for &f in &world.brush_faces {
        let Some(s) = world.surfaces[f as usize].as_ref() else {
            continue;
        };
        if s.kind == TextureKind::Fence {
            continue;
        }
        if let Some(depth) = ray_hit(s, view, dir)
            && best.is_none_or(|(_, d)| depth < d)
        {
            best = Some((f, depth));
        }
    }
    best
}

/// Fence faces the ray along `dir` meets before depth `limit`, nearest first, into `out`.
fn fence_hits(
    world: &World,
    view: &View,
    dir: DVec3,
    limit: Option<f64>,
    out: &mut Vec<(u32, f64)>,
) {
    out.clear();
    for &f in &world.fence_faces {
        let Some(s) = world.surfaces[f as usize].as_ref() else {
            continue;
        };
        if let Some(depth) = ray_hit(s, view, dir)
            && limit.is_none_or(|l| depth < l)
        {
            out.push((f, depth));
        }
    }
    out.sort_by(|a, b| a.1.total_cmp(&b.1));
}

/// Pending work of a ray's walk through the tree.
enum RayStep {
    /// The ray's part from depth `t0` to `t1` through `child`.
    Visit { child: i32, t0: f64, t1: f64 },
    /// The faces of `node` on its `near` side, where the ray crosses its plane at depth `t`.
    Faces { node: usize, near: usize, t: f64 },
}

/// Front-to-back along the ray: the first face hit, or the first solid leaf. An explicit stack
/// keeps a degenerate, very deep tree from overflowing the thread's stack.
fn trace(world: &World, root: i32, o: DVec3, dir: DVec3, t0: f64, t1: f64) -> Trace {
    let bsp = &world.bsp;
    let mut stack = vec![RayStep::Visit {
        child: root,
        t0,
        t1,
    }];
    while let Some(step) = stack.pop() {
        match step {
            RayStep::Visit { child, t0, t1 } => {
                if child < 0 {
                    match bsp.leafs.get((-(child + 1)) as usize) {
                        Some(l) if l.contents != contents::SOLID => continue,
                        _ => return Trace::Blocked,
                    }
                }
                let (Some(node), Some(plane)) = (
                    bsp.nodes.get(child as usize),
                    world.node_plane(child as usize),
                ) else {
                    return Trace::Blocked;
                };
                let d0 = plane.distance(o + dir * t0);
                let d1 = plane.distance(o + dir * t1);
                if (d0 >= 0.0) == (d1 >= 0.0) {
                    let side = usize::from(d0 < 0.0);
                    stack.push(RayStep::Visit {
                        child: node.children[side],
                        t0,
                        t1,
                    });
                    continue;
                }
                let near = usize::from(d0 < 0.0);
                let tm = (t0 + (t1 - t0) * d0 / (d0 - d1)).clamp(t0, t1);
                // Pushed in reverse: the near part, the faces on the plane, the far part.
                stack.push(RayStep::Visit {
                    child: node.children[1 - near],
                    t0: tm,
                    t1,
                });
                stack.push(RayStep::Faces {
                    node: child as usize,
                    near,
                    t: tm,
                });
                stack.push(RayStep::Visit {
                    child: node.children[near],
                    t0,
                    t1: tm,
                });
            }
            RayStep::Faces { node, near, t } => {
                let node = &bsp.nodes[node];
                let p = o + dir * t;
                let first = node.first_face as usize;
                for f in first..first + node.num_faces as usize {
                    let Some(face) = bsp.faces.get(f) else { break };
                    if face.side as usize != near {
                        continue;
                    }
                    // Fences are looked for apart from the tree walk (`fence_hits`).
                    if let Some(s) = world.surfaces[f].as_ref()
                        && s.kind != TextureKind::Fence
                        && inside(s, p)
                    {
                        return Trace::Hit(f as u32, t);
                    }
                }
            }
        }
    }
    Trace::Miss
}

/// Whether `p` (on the surface's plane) lies inside its convex polygon, either winding.
fn inside(s: &Surface, p: DVec3) -> bool {
    let n = s.points.len();
    let (mut pos, mut neg) = (false, false);
    for i in 0..n {
        let (a, b) = (s.points[i], s.points[(i + 1) % n]);
        let edge = b - a;
        let len = edge.length();
        if len < 1e-9 {
            continue;
        }
        let side = edge.cross(p - a).dot(s.plane.normal) / len;
        pos |= side > EDGE_TOLERANCE;
        neg |= side < -EDGE_TOLERANCE;
        if pos && neg {
            return false;
        }
    }
    true
}

/// How two frames differ.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Comparison {
    /// Pixels compared: the frames' width times height.
    pub pixels: usize,
    /// Mean absolute difference per colour channel (0..255) over all pixels.
    pub mean_diff: f64,
    /// The same over pixels where both drew the same face: texture-mapping error alone.
    pub mean_diff_same_face: f64,
    /// Largest difference of one colour channel at one pixel (0..255).
    pub max_diff: u8,
    /// Fraction of pixels whose colour differs at all.
    pub differing_pixels: f64,
    /// Fraction of pixels showing a different face: sorting, clipping or crack errors.
    pub face_mismatch: f64,
}

/// How far `a` is from `b`, pixel by pixel. Panics when the frames differ in size.
pub fn compare(a: &Frame, b: &Frame) -> Comparison {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "frames of different sizes"
    );
    let pixels = a.pixels.len();
    let (mut total, mut same_total, mut same_count) = (0u64, 0u64, 0usize);
    let (mut max_diff, mut differing, mut mismatched) = (0u8, 0usize, 0usize);
    for i in 0..pixels {
        let (ca, cb) = (a.pixels[i], b.pixels[i]);
        let diff: u32 = (0..3)
            .map(|k| ((ca >> (8 * k)) & 255).abs_diff((cb >> (8 * k)) & 255))
            .inspect(|&d| max_diff = max_diff.max(d as u8))
            .sum();
        total += diff as u64;
        differing += usize::from(diff != 0);
        if a.faces[i] == b.faces[i] {
            same_total += diff as u64;
            same_count += 1;
        } else {
            mismatched += 1;
        }
    }
    let frac = |n: usize| n as f64 / pixels.max(1) as f64;
    Comparison {
        pixels,
        mean_diff: total as f64 / (3 * pixels.max(1)) as f64,
        mean_diff_same_face: same_total as f64 / (3 * same_count.max(1)) as f64,
        max_diff,
        differing_pixels: frac(differing),
        face_mismatch: frac(mismatched),
    }
}
