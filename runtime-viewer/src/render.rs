//! One frame of the fast renderer: visibility, edges, spans, surfaces, raster.

use glam::DVec3;
use std::time::Instant;

use crate::camera::{Camera, View};
use crate::edges::{BACKGROUND, EdgeList, EdgeStats, SpanSurface};

use crate::raster::{TexMapping, draw_spans, for_each_segment};
use crate::surface_cache::{CacheStats, LightStyles, SurfaceCache, TRANSPARENT, choose_mip};
use crate::textures::{TextureKind, WarpTable, liquid_color, sky_color};
use crate::visibility::{Candidate, VisStats, Visibility};
use crate::world::{Surface, World};

/// Face id of pixels no surface covers.
pub const NO_FACE: u32 = u32::MAX;

/// A picture (0x00RRGGBB) and the face drawn at each pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Colours as 0x00RRGGBB, row by row from the top left.
    pub pixels: Vec<u32>,
    /// The BSP face shown at each pixel, in the same order; [`NO_FACE`] where none is.
    pub faces: Vec<u32>,
}

impl Frame {
    /// A black frame with no faces drawn.
    pub fn new(width: usize, height: usize) -> Frame {
        Frame {
            width,
            height,
            pixels: vec![0; width * height],
            faces: vec![NO_FACE; width * height],
        }
    }
}

/// How the renderer draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Pixels between exact perspective divides along a span (1 = every pixel).
    pub span_step: u32,
    /// Seconds: animates light styles (10 steps a second) and the liquid warp.
    pub time: f64,
    /// Off: the cache is emptied before every frame (to measure what it saves).
    pub use_cache: bool,
    /// Bytes of lit surfaces the cache keeps before it evicts the least recently used.
    pub cache_budget: usize,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            span_step: 16,
            time: 0.0,
            use_cache: true,
            cache_budget: 64 << 20,
        }
    }
}

/// Counts and timings of one frame.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct FrameStats {
    /// What the PVS, frustum and facing let through.
    pub visibility: VisStats,
    /// What the edge list and span generator did.
    pub edges: EdgeStats,
    /// How the surface cache fared.
    pub cache: CacheStats,
    /// Fence polygons drawn over the opaque picture.
    pub fences: usize,
    /// Seconds spent finding the visible surfaces.
    pub time_visibility: f64,
    /// Seconds spent clipping, projecting and adding polygons to the edge list.
    pub time_edges: f64,
    /// Seconds spent turning edges into sorted spans.
    pub time_spans: f64,
    /// Seconds spent building lit surfaces for the cache.
    pub time_surfaces: f64,
    /// Seconds spent texturing spans and drawing fences, surface building excluded.
    pub time_raster: f64,
}

impl FrameStats {
    /// Seconds of the whole frame: the five stages' sum.
    pub fn total_time(&self) -> f64 {
        self.time_visibility
            + self.time_edges
            + self.time_spans
            + self.time_surfaces
            + self.time_raster
    }
}

/// The fast renderer, with the buffers and surface cache it keeps from frame to frame.
#[derive(Debug)]
pub struct Renderer {
    /// How it draws; may change between frames (`time` animates light styles and liquids).
    pub options: RenderOptions,
    /// The light styles' patterns; their values are set from `options.time` every frame.
    pub styles: LightStyles,
    cache: SurfaceCache,
    visibility: Visibility,
    candidates: Vec<Candidate>,
    edges: EdgeList,
    /// Fences (see [`Renderer::draw_fences`]): this frame's, front to back, and the buffers
    /// drawing them takes.
    fences: Vec<Candidate>,
    fence_edges: EdgeList,
    /// 1/z of the opaque surface at each pixel, filled only on frames with fences.
    depth: Vec<f32>,
}

/// The polygon a candidate draws (its whole face, or a brush model's piece in one leaf) and its
/// surface for the span generator; `None` when the eye lies in its plane.
fn candidate_polygon<'w>(
    world: &'w World,
    view: &View,
    c: &Candidate,
) -> Option<(&'w Surface, &'w [DVec3], SpanSurface)> {
    let surface = world.surfaces.get(c.face as usize)?.as_ref()?;
    let points = match c.fragment {
        Some((leaf, i)) => &world.leaf_fragments[leaf as usize][i as usize].points,
        None => &surface.points,
    };
    let inverse_depth = view.inverse_depth(&surface.plane)?;
    let span_surface = SpanSurface {
        face: c.face,
        key: c.key,
        inverse_depth,
    };
    Some((surface, points, span_surface))
}

impl Renderer {
    /// A renderer for `world`, whose frames are drawn with `options`.
    pub fn new(world: &World, options: RenderOptions) -> Renderer {
        Renderer {
            options,
            styles: LightStyles::default(),
            cache: SurfaceCache::new(options.cache_budget),
            visibility: Visibility::new(world),
            candidates: Vec::new(),
            edges: EdgeList::default(),
            fences: Vec::new(),
            fence_edges: EdgeList::default(),
            depth: Vec::new(),
        }
    }

    /// Draw `world` as `camera` sees it into `frame` (resized to the camera's picture when it
    /// differs).
    pub fn render(&mut self, world: &World, camera: &Camera, frame: &mut Frame) -> FrameStats {
        if frame.width != camera.width || frame.height != camera.height {
            *frame = Frame::new(camera.width, camera.height);
        }
        let view = camera.view();
        let mut stats = FrameStats::default();
        // Surfaces whose styles' values change are rebuilt by the cache; the rest are reused.
        self.styles.animate(self.options.time);

        let t = Instant::now();
        stats.visibility = self.visibility.collect(world, &view, &mut self.candidates);
        stats.time_visibility = t.elapsed().as_secs_f64();

        let t = Instant::now();
        self.edges.begin();
        self.fences.clear();
        for c in &self.candidates {
            let Some((surface, points, span_surface)) = candidate_polygon(world, &view, c) else {
                continue;
            };
            if surface.kind == TextureKind::Fence {
                self.fences.push(*c);
                continue;
            }
            self.edges
                .add_polygon(&view, points, c.clip_flags, span_surface);
        }
        stats.time_edges = t.elapsed().as_secs_f64();

        let t = Instant::now();
        self.edges.scan(frame.width, frame.height);
        stats.time_spans = t.elapsed().as_secs_f64();
        stats.edges = self.edges.stats.clone();

        let t = Instant::now();
        if !self.options.use_cache {
            self.cache.clear();
        }
        self.cache.begin_frame();
        self.draw_surfaces(world, &view, frame);
        stats.fences = self.draw_fences(world, &view, frame);
        stats.cache = self.cache.stats;
        stats.time_surfaces = stats.cache.build_time.as_secs_f64();
        stats.time_raster = (t.elapsed().saturating_sub(stats.cache.build_time)).as_secs_f64();
        stats
    }

    fn draw_surfaces(&mut self, world: &World, view: &View, frame: &mut Frame) {
        let warp = WarpTable::new(self.options.time);
        let step = self.options.span_step;
        let width = frame.width;
        let fill_depth = !self.fences.is_empty();
        if fill_depth {
            self.depth.resize(frame.width * frame.height, 0.0);
        }
        for (i, ss) in self.edges.surfaces.iter().enumerate() {
            let spans = self.edges.spans_of(i);
            if spans.is_empty() {
                continue;
            }
            for span in spans {
                let row = span.y as usize * width;
                frame.faces[row + span.x0 as usize..row + span.x1 as usize].fill(ss.face);
                if fill_depth {
                    let yc = span.y as f64 + 0.5;
                    for x in span.x0..span.x1 {
                        self.depth[row + x as usize] = if i as u32 == BACKGROUND {
                            0.0
                        } else {
                            ss.inverse_depth.at(x as f64 + 0.5, yc) as f32
                        };
                    }
                }
            }
            let surface = match world.surfaces.get(ss.face as usize) {
                Some(Some(s)) if i as u32 != BACKGROUND => s,
                _ => {
                    for span in spans {
                        let row = span.y as usize * width;
                        frame.pixels[row + span.x0 as usize..row + span.x1 as usize].fill(0);
                    }
                    continue;
                }
            };
            let tex = &world.textures[surface.texture];
            match surface.kind {
                // Fences are not in the span list; see `draw_fences`.
                TextureKind::Lit | TextureKind::Fence => {
                    let mip = choose_mip(view, surface);
                    let Some(lit) = self.cache.get(world, ss.face, mip, &self.styles) else {
                        continue;
                    };
                    let map =
                        TexMapping::onto_lit_surface(view, surface, ss.inverse_depth, mip, lit);
                    let (w, texels) = (lit.width, &lit.texels);
                    draw_spans(&mut frame.pixels, width, spans, &map, step, |u, v| {
                        texels[v as usize * w + u as usize]
                    });
                }
                TextureKind::Liquid => {
                    let ext = surface.extents;
                    let size = (
                        ext.extents[0].max(1) as usize,
                        ext.extents[1].max(1) as usize,
                    );
                    let map =
                        TexMapping::new(view, surface, ss.inverse_depth, ext.tex_mins, 0, size);
                    let [s0, t0] = ext.tex_mins;
                    draw_spans(&mut frame.pixels, width, spans, &map, step, |u, v| {
                        liquid_color(tex, &world.palette, &warp, s0 + u, t0 + v)
                    });
                }
                TextureKind::Sky => {
                    for span in spans {
                        let yc = span.y as f64 + 0.5;
                        let row = span.y as usize * width;
                        for x in span.x0..span.x1 {
                            let dir = view.ray(x as f64 + 0.5, yc);
                            frame.pixels[row + x as usize] = sky_color(tex, &world.palette, dir);
                        }
                    }
                }
            }
        }
    }

    /// Fences are left out of the sorted spans (they must not hide what their holes show) and
    /// drawn afterwards, back to front, each pixel tested against the opaque surfaces' 1/z and
    /// skipped where the fence texel is transparent. Returns how many were drawn.
    fn draw_fences(&mut self, world: &World, view: &View, frame: &mut Frame) -> usize {
        let step = self.options.span_step;
        let width = frame.width;
        let mut drawn = 0;
        for c in self.fences.iter().rev() {
            let Some((surface, points, ss)) = candidate_polygon(world, view, c) else {
                continue;
            };
            self.fence_edges.begin();
            if !self.fence_edges.add_polygon(view, points, c.clip_flags, ss) {
                continue;
            }
            self.fence_edges.scan(frame.width, frame.height);
            let mip = choose_mip(view, surface);
            let Some(lit) = self.cache.get(world, c.face, mip, &self.styles) else {
                continue;
            };
            drawn += 1;
            let map = TexMapping::onto_lit_surface(view, surface, ss.inverse_depth, mip, lit);
            let depth = &mut self.depth;
            let spans = self.fence_edges.spans_of(1);
            for_each_segment(spans, &map, step, |seg| {
                let (mut u, mut v) = (seg.u, seg.v);
                let row = seg.y as usize * width;
                let yc = seg.y as f64 + 0.5;
                for x in seg.x..seg.x + seg.len {
                    let texel = lit.texels[(v >> 16) as usize * lit.width + (u >> 16) as usize];
                    let i = row + x as usize;
                    let izi = ss.inverse_depth.at(x as f64 + 0.5, yc) as f32;
                    if texel != TRANSPARENT && izi > depth[i] {
                        frame.pixels[i] = texel;
                        frame.faces[i] = c.face;
                        depth[i] = izi;
                    }
                    u += seg.du;
                    v += seg.dv;
                }
            });
        }
        drawn
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::{compare, render_reference};
    use crate::test_room::{FENCE_FACE, room, room_under_chain, room_with_fence};
    use quake_formats::bsp::MAX_TREE_DEPTH;

    fn start_camera(world: &World, angles: [f64; 3]) -> Camera {
        let (origin, _) = world.player_start().expect("room has a start");
        Camera {
            origin,
            angles,
            width: 96,
            height: 64,
            fov_x: 90.0,
        }
    }

    #[test]
    fn room_matches_the_reference_everywhere() {
        let world = room(0);
        for angles in [[0.0, 0.0, 0.0], [25.0, 40.0, 10.0], [-60.0, 200.0, 0.0]] {
            let camera = start_camera(&world, angles);
            let reference = render_reference(&world, &camera, &LightStyles::default(), 0.0);
            for step in [1, 16] {
                let mut renderer = Renderer::new(
                    &world,
                    RenderOptions {
                        span_step: step,
                        ..RenderOptions::default()
                    },
                );
                let mut frame = Frame::new(96, 64);
                renderer.render(&world, &camera, &mut frame);
                assert!(
                    frame.faces.iter().all(|&f| f != NO_FACE),
                    "a closed room has no gaps"
                );
                let diff = compare(&frame, &reference);
                assert!(
                    diff.face_mismatch < 0.005,
                    "{angles:?} step {step}: {diff:?}"
                );
                // Only the exact step promises the same texels: the room's texture is noise, so
                // the affine error of longer steps on minified side walls shows at full strength.
                if step == 1 {
                    assert!(diff.mean_diff_same_face < 0.2, "{angles:?}: {diff:?}");
                }
            }
        }
    }

    #[test]
    fn cache_reuses_surfaces_and_rebuilds_only_changed_styles() {
        let world = room(5);
        let camera = start_camera(&world, [0.0, 0.0, 0.0]);
        let mut renderer = Renderer::new(&world, RenderOptions::default());
        let mut frame = Frame::new(96, 64);
        let first = renderer.render(&world, &camera, &mut frame).cache;
        assert_eq!(first.hits, 0);
        assert!(
            first.misses >= 4,
            "wall ahead, both sides, floor: {first:?}"
        );
        assert!(first.bytes_built > 0);
        let second = renderer.render(&world, &camera, &mut frame).cache;
        assert_eq!((second.hits, second.misses), (first.misses, 0));
        let before = frame.clone();
        renderer.styles.set_pattern(5, "a");
        let third = renderer.render(&world, &camera, &mut frame).cache;
        assert_eq!(
            (third.misses, third.style_rebuilds),
            (1, 1),
            "only the style-5 wall"
        );
        assert_ne!(before.pixels, frame.pixels, "the wall ahead went dark");
    }

    #[test]
    fn fences_show_what_lies_behind_their_holes() {
        let world = room_with_fence();
        assert_eq!(world.fence_faces, [FENCE_FACE]);
        for angles in [[20.0, 0.0, 0.0], [10.0, 25.0, 0.0]] {
            let camera = start_camera(&world, angles);
            let reference = render_reference(&world, &camera, &LightStyles::default(), 0.0);
            let mut frame = Frame::new(camera.width, camera.height);
            // Exact texture mapping: the holes are 4 texels wide, so the affine error of longer
            // steps would move their edges and blur the comparison.
            let options = RenderOptions {
                span_step: 1,
                ..RenderOptions::default()
            };
            let stats = Renderer::new(&world, options).render(&world, &camera, &mut frame);
            assert_eq!(stats.fences, 1);
            let fence_pixels = |f: &Frame| f.faces.iter().filter(|&&id| id == FENCE_FACE).count();
            // The fence's screen box: where its solid cells are drawn, some wall must show
            // between them.
            let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0, usize::MAX, 0);
            for (i, _) in frame
                .faces
                .iter()
                .enumerate()
                .filter(|&(_, &id)| id == FENCE_FACE)
            {
                let (x, y) = (i % frame.width, i / frame.width);
                (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
            }
            assert!(fence_pixels(&frame) > 50, "{angles:?}: fence not drawn");
            let behind = (y0..=y1)
                .flat_map(|y| (x0..=x1).map(move |x| (x, y)))
                .filter(|&(x, y)| frame.faces[y * frame.width + x] != FENCE_FACE)
                .count();
            assert!(behind > 50, "{angles:?}: nothing seen through the fence");
            let diff = compare(&frame, &reference);
            assert!(diff.face_mismatch < 0.02, "{angles:?}: {diff:?}");
            assert!(
                fence_pixels(&frame).abs_diff(fence_pixels(&reference)) < fence_pixels(&frame) / 10
            );
        }
    }

    #[test]
    fn a_chain_deeper_than_the_gate_allows_is_refused() {
        let Err(error) = room_under_chain(MAX_TREE_DEPTH + 1) else {
            panic!("a chain deeper than the gate allows was accepted");
        };
        assert!(error.contains("deeper than"), "{error}");
    }

    #[test]
    fn a_very_deep_node_chain_renders_without_overflowing_the_stack() {
        // Regression: the visibility walk and the reference trace recursed once per node level.
        let deep = room_under_chain(MAX_TREE_DEPTH - 64).expect("a chain the gate allows");
        let shallow = room(0);
        // Small: every reference ray walks the whole chain.
        let camera = Camera {
            width: 24,
            height: 16,
            ..start_camera(&shallow, [10.0, 30.0, 0.0])
        };
        let expected = render_reference(&shallow, &camera, &LightStyles::default(), 0.0);
        let reference = render_reference(&deep, &camera, &LightStyles::default(), 0.0);
        assert_eq!(reference, expected);
        let mut frame = Frame::new(camera.width, camera.height);
        let stats =
            Renderer::new(&deep, RenderOptions::default()).render(&deep, &camera, &mut frame);
        assert!(stats.visibility.candidates >= 3, "{:?}", stats.visibility);
        let diff = compare(&frame, &expected);
        assert!(diff.face_mismatch < 0.005, "{diff:?}");
    }

    /// Mean of the colour channels over the pixels showing `face`.
    fn brightness(frame: &Frame, face: u32) -> f64 {
        let (sum, n) = frame
            .pixels
            .iter()
            .zip(&frame.faces)
            .filter(|&(_, &f)| f == face)
            .fold((0u64, 0u64), |(sum, n), (&c, _)| {
                let channels = (c >> 16 & 255) + (c >> 8 & 255) + (c & 255);
                (sum + channels as u64, n + 3)
            });
        assert!(n > 0, "face {face} not on screen");
        sum as f64 / n as f64
    }

    #[test]
    fn a_flickering_wall_changes_over_time_and_only_it_is_rebuilt() {
        // Wall 0 (ahead) has style 1, the flicker "mmnmmo..."; the others style 0.
        let world = room(1);
        let camera = start_camera(&world, [0.0, 20.0, 0.0]);
        let mut renderer = Renderer::new(&world, RenderOptions::default());
        let mut frame = Frame::new(96, 64);
        let first = renderer.render(&world, &camera, &mut frame).cache;
        let normal = brightness(&frame, 0);
        let others = frame.pixels.clone();
        // Step 2 is 'n': brighter.
        renderer.options.time = 0.25;
        let brighter = renderer.render(&world, &camera, &mut frame).cache;
        assert_eq!(
            (brighter.misses, brighter.style_rebuilds, brighter.hits),
            (1, 1, first.misses - 1),
            "only the flickering wall is rebuilt"
        );
        assert!(brightness(&frame, 0) > normal + 1.0);
        for ((a, b), &f) in others.iter().zip(&frame.pixels).zip(&frame.faces) {
            if f != 0 {
                assert_eq!(a, b, "walls with style 0 did not change");
            }
        }
        // Still step 2: nothing to rebuild.
        renderer.options.time = 0.29;
        let same = renderer.render(&world, &camera, &mut frame).cache;
        assert_eq!((same.misses, same.hits), (0, first.misses));
        // Step 5 is 'o', step 6 'm' again: back to the first picture.
        renderer.options.time = 0.65;
        renderer.render(&world, &camera, &mut frame);
        assert_eq!(brightness(&frame, 0), normal);
        assert_eq!(frame.pixels, others);
    }
}
