//! Golden picture: the project's demo map, compiled and lit by Slipgate's own compiler and light
//! tool, rendered from its player start and compared with `tests/golden/demo.png`.
//!
//! The tolerances let small lighting or compiler changes through (a luxel a few levels brighter,
//! a face split elsewhere) but catch a blank or black picture, wrong or missing textures and
//! missing light. When the golden file is missing, or `SLIPGATE_BLESS=1` is set, the test writes
//! it and fails, saying so: look at the new picture before committing it.

use std::path::{Path, PathBuf};

use bsp_compiler::{CompileOptions, MapSource, compile};
use quake_formats::lit::LitData;
use quake_formats::palette::Palette;
use runtime_viewer::textures::PaletteSource;
use runtime_viewer::{
    Camera, Frame, NO_FACE, RenderOptions, Renderer, World, compare, render_reference,
};

const WIDTH: usize = 320;
const HEIGHT: usize = 200;
/// Mean absolute difference per colour channel (0..255) allowed against the golden picture.
/// Measured on the golden picture (mean level 27): all light 5% dimmer is 1.75, 10% dimmer 3.0,
/// the picture shifted by one pixel 2.5; black, unlit or untextured pictures are far beyond.
const MAX_MEAN_DIFF: f64 = 3.0;
/// A pixel "differs" when a channel is off by more than this...
const PIXEL_THRESHOLD: u32 = 16;
/// ...and at most this fraction of the pixels may differ (a one-pixel shift makes about 5%).
const MAX_DIFFERING: f64 = 0.02;

fn maps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps")
}

fn golden_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/demo.png")
}

/// The lit BSP and `.lit` RGB (when coloured) of `maps/demo.map`, computed on `threads` threads
/// and lit with `options`.
fn build_demo(threads: usize, options: &light::Options) -> (Vec<u8>, Option<Vec<u8>>) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let source = MapSource::read(&maps_dir().join("demo.map")).expect("maps/demo.map");
        let compiled = compile(&source, &CompileOptions::default()).expect("demo.map compiles");
        assert!(compiled.leak.is_none(), "demo.map leaks");
        let mut bsp = compiled.bsp;
        let lighting = light::compute_lighting(&bsp, options).expect("demo.map lights");
        let lit = light::apply_lighting(&mut bsp, &lighting);
        let bytes = bsp.write().expect("BSP encodes");
        let rgb = lit
            .lit
            .map(|lit| quake_formats::lit::read_lit(&lit, bsp.lighting.len()).expect("valid .lit"));
        (bytes, rgb)
    })
}

fn render_demo(bsp: &[u8], lit: Option<Vec<u8>>) -> (World, Camera, Frame) {
    let bsp = quake_formats::Bsp::read(bsp).expect("BSP decodes");
    let world = World::new(
        bsp,
        &Palette::slipgate(),
        PaletteSource::Builtin,
        lit.map(LitData::Rgb),
    )
    .expect("the demo loads");
    let (origin, yaw) = world.player_start().expect("demo has a player start");
    let camera = Camera {
        origin,
        angles: [0.0, yaw, 0.0],
        width: WIDTH,
        height: HEIGHT,
        fov_x: 90.0,
    };
    let mut frame = Frame::new(WIDTH, HEIGHT);
    Renderer::new(&world, RenderOptions::default()).render(&world, &camera, &mut frame);
    (world, camera, frame)
}

fn read_png(path: &Path) -> Option<(usize, usize, Vec<[u8; 3]>)> {
    if !path.exists() {
        return None;
    }
    let picture = image::open(path).expect("golden PNG decodes");
    assert_eq!(
        picture.color(),
        image::ColorType::Rgb8,
        "golden PNG is 8-bit RGB"
    );
    let picture = picture.into_rgb8();
    let rgb = picture.pixels().map(|p| p.0).collect();
    Some((picture.width() as usize, picture.height() as usize, rgb))
}

/// Luminance variance, to tell a picture from a flat fill.
fn variance(frame: &Frame) -> f64 {
    let lum: Vec<f64> = frame
        .pixels
        .iter()
        .map(|&c| {
            runtime_viewer::textures::unpack(c)
                .iter()
                .map(|&v| v as f64)
                .sum()
        })
        .collect();
    let mean = lum.iter().sum::<f64>() / lum.len() as f64;
    lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lum.len() as f64
}

/// The mean absolute difference per channel between `frame` and `expected`, and the fraction of
/// pixels with a channel off by more than [`PIXEL_THRESHOLD`].
fn differences(frame: &Frame, expected: &[[u8; 3]]) -> (f64, f64) {
    let (mut total, mut differing) = (0u64, 0usize);
    for (&c, e) in frame.pixels.iter().zip(expected) {
        let got = runtime_viewer::textures::unpack(c);
        let diffs: Vec<u32> = (0..3)
            .map(|k| (got[k] as u32).abs_diff(e[k] as u32))
            .collect();
        total += diffs.iter().sum::<u32>() as u64;
        differing += usize::from(diffs.iter().any(|&d| d > PIXEL_THRESHOLD));
    }
    let pixels = frame.pixels.len();
    (
        total as f64 / (3 * pixels) as f64,
        differing as f64 / pixels as f64,
    )
}

/// The demo lit on grids of its own, world-aligned at 8 units (`DECOUPLED_LM`) and every 8
/// texels (`LMSHIFT`): the viewer draws every lit face from its own grid, and the picture stays
/// close to the one lit on Quake's grid (the same light, sampled twice as finely).
#[test]
fn demo_lit_on_its_own_grids_draws_close_to_quakes_grid() {
    let (quake_bsp, quake_lit) = build_demo(2, &light::Options::default());
    let (_, _, quake) = render_demo(&quake_bsp, quake_lit);
    let quake: Vec<[u8; 3]> = quake
        .pixels
        .iter()
        .map(|&c| runtime_viewer::textures::unpack(c))
        .collect();
    let mut world_units = light::Options::default();
    world_units.overrides.world_units_per_luxel = Some(8.0);
    let mut texels = light::Options::default();
    texels.overrides.lmshift = Some(3);
    for (grid, options) in [("8 units", world_units), ("8 texels", texels)] {
        let (bsp, lit) = build_demo(2, &options);
        let (world, _, frame) = render_demo(&bsp, lit);
        let lit_surfaces = world
            .surfaces
            .iter()
            .flatten()
            .filter(|s| s.light.is_some());
        assert!(lit_surfaces.clone().count() > 0);
        assert!(lit_surfaces.clone().all(|s| s.free_lightmap.is_some()));
        assert!(frame.faces.iter().all(|&f| f != NO_FACE));
        let (mean, fraction) = differences(&frame, &quake);
        println!(
            "{grid} against Quake's grid: mean {mean:.3}, {:.2}% of pixels off",
            fraction * 100.0
        );
        assert!(mean < MAX_MEAN_DIFF, "{grid}: mean difference {mean:.3}");
    }
}

#[test]
fn demo_map_matches_its_golden_picture() {
    // The pipeline must not depend on how many threads run it.
    let options = light::Options::default();
    let (bsp, lit) = build_demo(2, &options);
    let (bsp_single, lit_single) = build_demo(1, &options);
    assert!(
        bsp == bsp_single && lit == lit_single,
        "compiling and lighting on 1 and 2 threads gave different files"
    );
    let (world, camera, frame) = render_demo(&bsp, lit);

    // Checks that hold whatever the golden picture says.
    assert!(
        frame.faces.iter().all(|&f| f != NO_FACE),
        "the start room is closed: no pixel shows the void"
    );
    assert!(variance(&frame) > 100.0, "the picture is nearly flat");
    let reference = render_reference(&world, &camera, &Default::default(), 0.0);
    let against_reference = compare(&frame, &reference);
    assert!(
        against_reference.face_mismatch < 0.01,
        "fast renderer disagrees with the ray caster: {against_reference:?}"
    );

    let golden = golden_path();
    let bless = std::env::var("SLIPGATE_BLESS").is_ok_and(|v| v == "1");
    let expected = if bless { None } else { read_png(&golden) };
    let Some((width, height, expected)) = expected else {
        std::fs::create_dir_all(golden.parent().expect("golden dir")).expect("golden dir");
        runtime_viewer::image::write_png(&frame, &golden).expect("writing golden PNG");
        panic!(
            "wrote {}: maps/demo.map compiled and lit by the workspace's bsp-compiler and light, \
             rendered from info_player_start at {WIDTH}x{HEIGHT} (span step 16, time 0). Look at \
             it, commit it, and run the test again without SLIPGATE_BLESS.",
            golden.display()
        );
    };
    assert_eq!((width, height), (WIDTH, HEIGHT), "golden picture size");
    let (mean, fraction) = differences(&frame, &expected);
    println!(
        "against {}: mean difference {mean:.3} per channel, {:.2}% of pixels off by more than {PIXEL_THRESHOLD}",
        golden.display(),
        fraction * 100.0
    );
    if mean >= MAX_MEAN_DIFF || fraction >= MAX_DIFFERING {
        let actual = Path::new(env!("CARGO_TARGET_TMPDIR")).join("demo.actual.png");
        runtime_viewer::image::write_png(&frame, &actual).expect("writing actual PNG");
        panic!(
            "the demo map's picture changed: mean difference {mean:.3} (limit {MAX_MEAN_DIFF}), \
             {:.2}% of pixels off by more than {PIXEL_THRESHOLD} (limit {:.0}%). This render is in \
             {}; if the change is intended, rerun with SLIPGATE_BLESS=1 to replace the golden file.",
            fraction * 100.0,
            MAX_DIFFERING * 100.0,
            actual.display()
        );
    }
}
