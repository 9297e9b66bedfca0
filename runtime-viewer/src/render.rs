//! One frame of the fast renderer: visibility, edges, spans, surfaces, raster.

use std::time::Instant;

use crate::camera::{Camera, View};
use crate::edges::{BACKGROUND, EdgeList, EdgeStats, SpanSurface};
use crate::raster::{TexMapping, draw_spans};
use crate::surface_cache::{CacheStats, LightStyles, SurfaceCache, choose_mip};
use crate::textures::{TextureKind, WarpTable, liquid_color, sky_color};
use crate::visibility::{Candidate, VisStats, Visibility};
use crate::world::World;

/// Face id of pixels no surface covers.
pub const NO_FACE: u32 = u32::MAX;

/// A picture (0x00RRGGBB) and the face drawn at each pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<u32>,
    pub faces: Vec<u32>,
}

impl Frame {
    pub fn new(width: usize, height: usize) -> Frame {
        Frame {
            width,
            height,
            pixels: vec![0; width * height],
            faces: vec![NO_FACE; width * height],
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Pixels between exact perspective divides along a span (1 = every pixel).
    pub span_step: u32,
    /// Seconds, for the liquid warp.
    pub time: f64,
    /// Off: the cache is emptied before every frame (to measure what it saves).
    pub use_cache: bool,
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

#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FrameStats {
    pub visibility: VisStats,
    pub edges: EdgeStats,
    pub cache: CacheStats,
    /// Seconds per stage.
    pub time_visibility: f64,
    pub time_edges: f64,
    pub time_spans: f64,
    pub time_surfaces: f64,
    pub time_raster: f64,
}

impl FrameStats {
    pub fn total_time(&self) -> f64 {
        self.time_visibility
            + self.time_edges
            + self.time_spans
            + self.time_surfaces
            + self.time_raster
    }
}

#[derive(Debug)]
pub struct Renderer {
    pub options: RenderOptions,
    pub styles: LightStyles,
    pub cache: SurfaceCache,
    visibility: Visibility,
    candidates: Vec<Candidate>,
    edges: EdgeList,
}

impl Renderer {
    pub fn new(world: &World, options: RenderOptions) -> Renderer {
        Renderer {
            options,
            styles: LightStyles::default(),
            cache: SurfaceCache::new(options.cache_budget),
            visibility: Visibility::new(world),
            candidates: Vec::new(),
            edges: EdgeList::default(),
        }
    }

    pub fn render(&mut self, world: &World, camera: &Camera, frame: &mut Frame) -> FrameStats {
        if frame.width != camera.width || frame.height != camera.height {
            *frame = Frame::new(camera.width, camera.height);
        }
        let view = camera.view();
        let mut stats = FrameStats::default();

        let t = Instant::now();
        stats.visibility = self.visibility.collect(world, &view, &mut self.candidates);
        stats.time_visibility = t.elapsed().as_secs_f64();

        let t = Instant::now();
        self.edges.begin();
        for c in &self.candidates {
            let Some(surface) = &world.surfaces[c.face as usize] else {
                continue;
            };
            let points = match c.fragment {
                Some((leaf, i)) => &world.leaf_fragments[leaf as usize][i as usize].points,
                None => &surface.points,
            };
            let Some(inverse_depth) = view.inverse_depth(&surface.plane) else {
                continue;
            };
            let span_surface = SpanSurface {
                face: c.face,
                key: c.key,
                inverse_depth,
            };
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
        stats.cache = self.cache.stats;
        stats.time_surfaces = stats.cache.build_time.as_secs_f64();
        stats.time_raster = (t.elapsed().saturating_sub(stats.cache.build_time)).as_secs_f64();
        stats
    }

    fn draw_surfaces(&mut self, world: &World, view: &View, frame: &mut Frame) {
        let warp = WarpTable::new(self.options.time);
        let step = self.options.span_step;
        let width = frame.width;
        for (i, ss) in self.edges.surfaces.iter().enumerate() {
            let spans = self.edges.spans_of(i);
            if spans.is_empty() {
                continue;
            }
            for span in spans {
                let row = span.y as usize * width;
                frame.faces[row + span.x0 as usize..row + span.x1 as usize].fill(ss.face);
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
                TextureKind::Lit => {
                    let mip = choose_mip(view, surface);
                    let Some(lit) = self.cache.get(world, ss.face, mip, &self.styles) else {
                        continue;
                    };
                    let map = TexMapping::new(
                        view,
                        surface,
                        ss.inverse_depth,
                        surface.extents.tex_mins,
                        mip,
                        (lit.width, lit.height),
                    );
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::{compare, render_reference};
    use crate::test_room::room;

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
        renderer.styles.values[5] = LightStyles::letter_value(b'a');
        let third = renderer.render(&world, &camera, &mut frame).cache;
        assert_eq!(
            (third.misses, third.style_rebuilds),
            (1, 1),
            "only the style-5 wall"
        );
        assert_ne!(before.pixels, frame.pixels, "the wall ahead went dark");
    }
}
