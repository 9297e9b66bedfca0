//! The flythrough benchmark: the renderer's speed along a path through the map's spawn spots,
//! turning as it goes (a full turn on the spot when there is only one), with the clock of a
//! game shown at 60 frames a second so that animated light and liquids cost what they cost.

use std::time::Instant;

use quake_formats::progress::Progress;

use crate::camera::Camera;
use crate::render::{Frame, FrameStats, Renderer};
use crate::surface_cache::CacheStats;
use crate::world::World;

/// Seconds of the map's clock between two frames of the flythrough.
const SECONDS_PER_FRAME: f64 = 1.0 / 60.0;

/// The flythrough's speed and where its time went.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct Flythrough {
    /// Frames drawn.
    pub frames: usize,
    /// Picture width in pixels.
    pub width: usize,
    /// Picture height in pixels.
    pub height: usize,
    /// Frames per second over the whole flythrough.
    pub fps: f64,
    /// Share of surface-cache lookups that found their tile already built.
    pub cache_hit_rate: f64,
    /// The surface cache's counts, summed over every frame.
    pub cache: CacheStats,
    /// The mean frame's time in each step of drawing.
    pub mean_frame: FrameStats,
}

/// Draws `frames` frames from `camera`'s picture size and field of view along the flythrough's
/// path, reporting each frame to `progress`.
pub fn flythrough(
    world: &World,
    renderer: &mut Renderer,
    camera: &Camera,
    frames: usize,
    progress: &Progress,
) -> Flythrough {
    let frames = frames.max(1);
    let mut spots = world.spots();
    if spots.is_empty() {
        spots.push((camera.origin, camera.angles[1]));
    }
    progress.start("frames", frames);
    let start_time = renderer.options.time;
    let mut frame = Frame::new(camera.width, camera.height);
    let mut cache = CacheStats::default();
    let mut sum = FrameStats::default();
    let start = Instant::now();
    for i in 0..frames {
        let along = i as f64 / frames as f64 * spots.len() as f64;
        let a = along.floor() as usize % spots.len();
        let b = (a + 1) % spots.len();
        let origin = if spots.len() > 1 {
            spots[a].0.lerp_monotonic(spots[b].0, along.fract())
        } else {
            spots[0].0
        };
        let cam = Camera {
            origin,
            angles: [0.0, spots[a].1 + 360.0 * i as f64 / frames as f64, 0.0],
            ..*camera
        };
        renderer.options.time = start_time + i as f64 * SECONDS_PER_FRAME;
        let s = renderer.render(world, &cam, &mut frame);
        cache.add(&s.cache);
        sum.time_visibility += s.time_visibility;
        sum.time_edges += s.time_edges;
        sum.time_spans += s.time_spans;
        sum.time_surfaces += s.time_surfaces;
        sum.time_raster += s.time_raster;
        progress.advance(1);
    }
    progress.finish();
    renderer.options.time = start_time;
    let elapsed = start.elapsed().as_secs_f64();
    let n = frames as f64;
    Flythrough {
        frames,
        width: camera.width,
        height: camera.height,
        fps: n / elapsed.max(f64::MIN_POSITIVE),
        cache_hit_rate: cache.hit_rate(),
        cache,
        mean_frame: FrameStats {
            time_visibility: sum.time_visibility / n,
            time_edges: sum.time_edges / n,
            time_spans: sum.time_spans / n,
            time_surfaces: sum.time_surfaces / n,
            time_raster: sum.time_raster / n,
            ..FrameStats::default()
        },
    }
}
