//! `slipgate-view`: render a BSP to PNG, or fly through it and report frame rates.

use glam::DVec3;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::bail;

use quake_formats::progress::terminal;

use crate::camera::Camera;
use crate::flythrough::flythrough;
use crate::image::write_png;
use crate::reference::{compare, render_reference};
use crate::render::{Frame, RenderOptions, Renderer};
use crate::summary::ViewSummary;
use crate::world::World;

/// The viewer's command line, shared by `slipgate view` and `slipgate-view`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// The compiled map (BSP29 or BSP2); a `.lit` beside it is used for coloured light.
    pub map: PathBuf,
    /// PNG to write.
    #[arg(long, default_value = "shot.png")]
    pub out: PathBuf,
    /// Picture size, WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480", value_parser = parse_size)]
    pub size: (usize, usize),
    /// Eye position (default: info_player_start, 22 units above its origin).
    #[arg(long, num_args = 3, value_names = ["X", "Y", "Z"], allow_negative_numbers = true)]
    pub pos: Option<Vec<f64>>,
    /// Pitch (positive looks down), yaw, roll in degrees (default: the start's angle).
    #[arg(long, num_args = 3, value_names = ["P", "Y", "R"], allow_negative_numbers = true)]
    pub angles: Option<Vec<f64>>,
    /// Horizontal field of view in degrees.
    #[arg(long, default_value_t = 90.0)]
    pub fov: f64,
    /// Pixels between exact perspective divides along a span (1 = exact).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub span_step: u32,
    /// Palette (768 bytes); default: gfx/palette.lmp above the map's folder, else Slipgate's.
    #[arg(long)]
    pub palette: Option<PathBuf>,
    /// Seconds on the map's clock: light styles step 10 times a second, liquids warp. The
    /// flythrough advances it 1/60 s per frame, the window follows real time from here.
    #[arg(long, default_value_t = 0.0)]
    pub time: f64,
    /// Surface cache budget in MiB.
    #[arg(long, default_value_t = 64)]
    pub cache_mb: usize,
    /// Also render with the reference ray caster, report the difference and write it beside
    /// the output as NAME.reference.png.
    #[arg(long)]
    pub reference: bool,
    /// Fly through the map for this many frames and report frame rates (no PNG).
    #[arg(long, value_name = "FRAMES")]
    pub bench: Option<usize>,
    /// Open an interactive window instead of writing a PNG: W/A/S/D fly, Q/E or Space/Ctrl go
    /// down/up, Shift is faster, drag with a mouse button or use the arrows to look, Esc quits.
    /// Needs a build with the cargo feature `window`.
    #[arg(long, conflicts_with_all = ["bench", "reference"])]
    pub window: bool,
    /// With --bench: empty the surface cache before every frame.
    #[arg(long)]
    pub no_cache: bool,
    /// Draw the lighting alone, without textures (128 grey is the texture's own colour).
    #[arg(long)]
    pub lightmap_only: bool,
    /// Write counts and timings as JSON.
    #[arg(long, value_name = "FILE.json")]
    pub stats: Option<PathBuf>,
}

impl Args {
    /// How the renderer is to draw, as these arguments ask.
    pub fn render_options(&self) -> RenderOptions {
        RenderOptions {
            span_step: self.span_step,
            use_cache: !self.no_cache,
            cache_budget: self.cache_mb << 20,
            time: self.time,
        }
    }
}

fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size {s:?} is not WIDTHxHEIGHT"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<usize>()
            .ok()
            .filter(|&n| (1..=16384).contains(&n))
            .ok_or_else(|| format!("size {s:?}: {v:?} is not a number from 1 to 16384"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// Load the map and do what `args` ask: write a PNG (and with `--reference` the reference
/// picture), run the flythrough benchmark, or open the window.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let start = Instant::now();
    let mut world = World::load(&args.map, args.palette.as_deref())?;
    world.lightmap_only = args.lightmap_only;
    if let Some(why) = &world.stats.ignored_lit {
        eprintln!("warning: {why}; drawing the BSP's own light in grey, as engines do");
    }
    let load_time = start.elapsed().as_secs_f64();
    let camera = initial_camera(&world, args)?;
    let mut renderer = Renderer::new(&world, args.render_options());
    let mut summary = ViewSummary {
        map: args.map.clone(),
        load: world.stats.clone(),
        load_seconds: load_time,
        palette: format!("{:?}", world.palette_source),
        ..ViewSummary::default()
    };

    if args.window {
        open_window(&world, &mut renderer, camera, args, &mut summary)?;
    } else if let Some(frames) = args.bench {
        let bench = flythrough(&world, &mut renderer, &camera, frames, &terminal());
        eprintln!(
            "{} frames at {}x{}: {:.1} fps, cache hit rate {:.1}%, per frame: visibility {:.2} ms, edges {:.2} ms, spans {:.2} ms, surfaces {:.2} ms, raster {:.2} ms",
            bench.frames,
            bench.width,
            bench.height,
            bench.fps,
            bench.cache_hit_rate * 100.0,
            bench.mean_frame.time_visibility * 1e3,
            bench.mean_frame.time_edges * 1e3,
            bench.mean_frame.time_spans * 1e3,
            bench.mean_frame.time_surfaces * 1e3,
            bench.mean_frame.time_raster * 1e3,
        );
        summary.bench = Some(bench);
    } else {
        let mut frame = Frame::new(camera.width, camera.height);
        let stats = renderer.render(&world, &camera, &mut frame);
        write_png(&frame, &args.out)?;
        eprintln!(
            "{}: {}x{} in {:.1} ms (load {:.0} ms): {} leaves in PVS, {} drawn, {} surfaces, {} spans, cache {} built ({} KiB); wrote {}",
            args.map.display(),
            camera.width,
            camera.height,
            stats.total_time() * 1e3,
            load_time * 1e3,
            stats.visibility.pvs_leaves,
            stats.visibility.drawn_leaves,
            stats.visibility.candidates,
            stats.edges.spans,
            stats.cache.misses,
            stats.cache.bytes_built / 1024,
            args.out.display()
        );
        summary.frame = Some(stats);
        if args.reference {
            let reference = render_reference(&world, &camera, &renderer.styles, args.time);
            let path = args.out.with_extension("reference.png");
            write_png(&reference, &path)?;
            let diff = compare(&frame, &reference);
            eprintln!(
                "reference: mean difference {:.2}/255 ({:.2} where the face agrees), max {}, {:.2}% of pixels show another face; wrote {}",
                diff.mean_diff,
                diff.mean_diff_same_face,
                diff.max_diff,
                diff.face_mismatch * 100.0,
                path.display()
            );
            summary.reference = Some(diff);
        }
    }
    if let Some(path) = &args.stats {
        let text = serde_json::to_string_pretty(&summary)?;
        quake_formats::fsutil::write_atomic(path, text.as_bytes())?;
    }
    Ok(())
}

#[cfg(feature = "window")]
fn open_window(
    world: &World,
    renderer: &mut Renderer,
    camera: Camera,
    args: &Args,
    view: &mut ViewSummary,
) -> anyhow::Result<()> {
    let name = format!("slipgate-view {}", args.map.display());
    let summary = crate::window::run_window(world, renderer, camera, &name)?;
    let [x, y, z] = summary.origin;
    let [p, yaw, r] = summary.angles;
    eprintln!(
        "{} frames in {:.1} s ({:.1} fps); last view: --pos {x:.0} {y:.0} {z:.0} --angles {p:.0} {yaw:.0} {r:.0}",
        summary.frames,
        summary.seconds,
        summary.frames as f64 / summary.seconds.max(1e-9),
    );
    view.window = Some(summary);
    Ok(())
}

#[cfg(not(feature = "window"))]
fn open_window(
    _: &World,
    _: &mut Renderer,
    _: Camera,
    _: &Args,
    _: &mut ViewSummary,
) -> anyhow::Result<()> {
    bail!(
        "--window needs a viewer built with the `window` feature (cargo build --features slipgate-viewer/window)"
    )
}

/// The camera `--pos`, `--angles`, `--fov` and `--size` ask for; by default at the player start.
pub fn initial_camera(world: &World, args: &Args) -> anyhow::Result<Camera> {
    let numbers = args.pos.iter().chain(&args.angles).flatten();
    if numbers.clone().any(|v| !v.is_finite()) || !(1.0..=179.0).contains(&args.fov) {
        bail!("--pos and --angles must be finite numbers and --fov between 1 and 179 degrees");
    }
    if !(args.time.is_finite() && args.time >= 0.0) {
        bail!("--time must be a number of seconds, 0 or more");
    }
    let start = world.player_start();
    let origin = match (&args.pos, start) {
        (Some(p), _) => DVec3::new(p[0], p[1], p[2]),
        (None, Some((o, _))) => o,
        (None, None) => bail!(
            "{}: no info_player_start (or other spawn spot); give --pos X Y Z",
            args.map.display()
        ),
    };
    let angles = match &args.angles {
        Some(a) => [a[0], a[1], a[2]],
        None => [0.0, start.map_or(0.0, |(_, yaw)| yaw), 0.0],
    };
    let (width, height) = args.size;
    Ok(Camera {
        origin,
        angles,
        width,
        height,
        fov_x: args.fov,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("320x200"), Ok((320, 200)));
        assert!(parse_size("320").is_err());
        assert!(parse_size("0x10").is_err());
    }
}
