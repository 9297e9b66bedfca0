//! The viewer on the shared corpus BSPs: every map renders, and the fast renderer agrees with the
//! reference ray caster. Skips (saying so) when the corpus is absent.

use glam::DVec3;
use std::path::{Path, PathBuf};

use runtime_viewer::{
    Camera, Comparison, Frame, NO_FACE, RenderOptions, Renderer, World, compare, render_reference,
};

const MAPS: [&str; 5] = [
    "librequake/start.bsp",
    "librequake/e1m3.bsp",
    "librequake/lq1m1.bsp",
    "ericw-tools/q1_cube.bsp",
    "ericw-tools/q1_detail_fence2.bsp",
];

fn corpus() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus");
    if dir.is_dir() {
        Some(dir)
    } else {
        println!("SKIPPED: corpus not found at {}", dir.display());
        None
    }
}

fn load(corpus: &Path, map: &str) -> World {
    let palette = corpus.join("palette/palette.lmp");
    World::load(&corpus.join("public/bsp").join(map), Some(&palette)).expect(map)
}

fn camera(origin: DVec3, angles: [f64; 3], width: usize, height: usize) -> Camera {
    Camera {
        origin,
        angles,
        width,
        height,
        fov_x: 90.0,
    }
}

fn render(world: &World, cam: &Camera, step: u32) -> Frame {
    let options = RenderOptions {
        span_step: step,
        ..RenderOptions::default()
    };
    let mut frame = Frame::new(cam.width, cam.height);
    Renderer::new(world, options).render(world, cam, &mut frame);
    frame
}

fn variance(frame: &Frame) -> f64 {
    let lum: Vec<f64> = frame
        .pixels
        .iter()
        .map(|&c| ((c >> 16) & 255) as f64 + ((c >> 8) & 255) as f64 + (c & 255) as f64)
        .collect();
    let mean = lum.iter().sum::<f64>() / lum.len() as f64;
    lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lum.len() as f64
}

#[test]
fn every_corpus_bsp_renders_from_its_player_start() {
    let Some(corpus) = corpus() else { return };
    for map in MAPS {
        let world = load(&corpus, map);
        let (origin, yaw) = world.player_start().expect("a player start");
        let level = render(&world, &camera(origin, [0.0, yaw, 0.0], 160, 100), 16);
        // q1_cube's start stands on top of a lone cube in the void: look down to see it.
        let down = render(&world, &camera(origin, [60.0, yaw, 0.0], 160, 100), 16);
        println!(
            "{map}: variance level {:.0}, looking down {:.0}",
            variance(&level),
            variance(&down)
        );
        assert!(variance(&down) > 0.0, "{map}: blank picture");
        assert!(
            down.faces.iter().any(|&f| f != NO_FACE),
            "{map}: no face drawn"
        );
    }
}

/// Fast (span step 16) against reference from the spawn spots of the LibreQuake maps.
#[test]
fn fast_renderer_agrees_with_the_reference() {
    let Some(corpus) = corpus() else { return };
    let mut brush_pixels = 0;
    for map in &MAPS[..3] {
        let world = load(&corpus, map);
        let mut worst: Option<Comparison> = None;
        let spots = world.spots();
        for (origin, yaw) in spots.iter().take(8) {
            let cam = camera(*origin, [10.0, *yaw, 0.0], 160, 100);
            let fast = render(&world, &cam, 16);
            let reference = render_reference(&world, &cam, &Default::default(), 0.0);
            let diff = compare(&fast, &reference);
            brush_pixels += fast
                .faces
                .iter()
                .filter(|f| world.brush_faces.contains(f))
                .count();
            println!("{map} at {origin:?} yaw {yaw}: {diff:?}");
            assert!(diff.face_mismatch < 0.01, "{map} at {origin:?}: {diff:?}");
            assert!(diff.mean_diff < 4.0, "{map} at {origin:?}: {diff:?}");
            if worst.is_none_or(|w| w.mean_diff < diff.mean_diff) {
                worst = Some(diff);
            }
        }
        println!("{map}: worst of {} views {worst:?}", spots.len().min(8));
    }
    println!("{brush_pixels} pixels show brush models");
    assert!(brush_pixels > 0, "no brush model seen");
}

/// The fence map seen through its `{trigger` fences: the letters (index 255) are holes, and the
/// fast renderer agrees with the reference about what shows through them.
#[test]
fn fences_are_see_through() {
    let Some(corpus) = corpus() else { return };
    let world = load(&corpus, "ericw-tools/q1_detail_fence2.bsp");
    assert!(!world.fence_faces.is_empty());
    let cam = camera(DVec3::new(64.0, -200.0, 100.0), [10.0, 80.0, 0.0], 320, 200);
    let options = RenderOptions {
        span_step: 1,
        ..RenderOptions::default()
    };
    let mut fast = Frame::new(cam.width, cam.height);
    let stats = Renderer::new(&world, options).render(&world, &cam, &mut fast);
    assert!(stats.fences > 0, "{stats:?}");
    let reference = render_reference(&world, &cam, &Default::default(), 0.0);
    let diff = compare(&fast, &reference);
    println!("fences: {diff:?}");
    assert!(diff.face_mismatch < 0.005, "{diff:?}");
    let fence_pixels = fast
        .faces
        .iter()
        .filter(|f| world.fence_faces.contains(f))
        .count();
    assert!(fence_pixels > 1000, "{fence_pixels} fence pixels");
}

/// Texture error against the reference for span steps 1, 8, 16 and 32 (run with --nocapture to
/// read the table).
#[test]
fn texture_error_grows_with_the_span_step() {
    let Some(corpus) = corpus() else { return };
    let world = load(&corpus, "librequake/e1m3.bsp");
    let (origin, yaw) = world.player_start().expect("a player start");
    let cam = camera(origin, [15.0, yaw, 0.0], 320, 200);
    let reference = render_reference(&world, &cam, &Default::default(), 0.0);
    let mut errors = Vec::new();
    for step in [1, 8, 16, 32] {
        let diff = compare(&render(&world, &cam, step), &reference);
        println!(
            "span step {step:2}: mean {:.3}, where the face agrees {:.3}, max {}, pixels differing {:.2}%, face mismatch {:.3}%",
            diff.mean_diff,
            diff.mean_diff_same_face,
            diff.max_diff,
            diff.differing_pixels * 100.0,
            diff.face_mismatch * 100.0
        );
        errors.push(diff);
    }
    assert!(errors[0].mean_diff_same_face < 0.5, "{:?}", errors[0]);
    assert!(errors[0].differing_pixels < 0.02, "{:?}", errors[0]);
    assert!(errors[0].differing_pixels <= errors[3].differing_pixels);
    assert!(errors.iter().all(|e| e.face_mismatch < 0.01));
}

/// Damaged indices (nodes, faces, leaves, texinfo, lightmaps) are refused or render: no panic.
#[test]
fn damaged_indices_do_not_panic() {
    let Some(corpus) = corpus() else { return };
    let data = std::fs::read(corpus.join("public/bsp/librequake/start.bsp")).expect("start.bsp");
    let pristine = quake_formats::Bsp::read(&data).expect("parse");
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = |n: usize| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % n.max(1) as u64) as usize
    };
    let mut rendered = 0;
    for round in 0..24 {
        let mut bsp = pristine.clone();
        for _ in 0..40 {
            let wild = next(1 << 20) as i64 - (1 << 19);
            match next(7) {
                0 => {
                    let n = next(bsp.nodes.len());
                    bsp.nodes[n].children[next(2)] = wild as i32;
                }
                1 => {
                    let f = next(bsp.faces.len());
                    bsp.faces[f].first_edge = wild as u32;
                }
                2 => {
                    let f = next(bsp.faces.len());
                    bsp.faces[f].light_offset = wild as i32;
                }
                3 => {
                    let f = next(bsp.faces.len());
                    bsp.faces[f].texinfo = wild as u32;
                }
                4 => {
                    let l = next(bsp.leafs.len());
                    bsp.leafs[l].first_marksurface = wild as u32;
                    bsp.leafs[l].vis_offset = wild as i32;
                }
                5 => {
                    let m = next(bsp.marksurfaces.len());
                    bsp.marksurfaces[m] = wild as u32;
                }
                _ => {
                    let n = next(bsp.nodes.len());
                    bsp.nodes[n].first_face = wild as u32;
                    bsp.nodes[n].num_faces = next(50) as u32;
                }
            }
        }
        let palette = quake_formats::palette::Palette::slipgate();
        let builtin = runtime_viewer::textures::PaletteSource::Builtin;
        let world = match World::new(bsp, &palette, builtin, None) {
            Ok(world) => world,
            Err(e) => {
                assert!(
                    e.contains("refused") || e.contains("node tree is damaged"),
                    "{e}"
                );
                continue;
            }
        };
        let (origin, yaw) = world.player_start().expect("start");
        let cam = camera(origin, [0.0, yaw + 30.0 * round as f64, 0.0], 64, 40);
        render(&world, &cam, 16);
        render_reference(&world, &cam, &Default::default(), 0.0);
        rendered += 1;
    }
    // The gate (quake_formats::check_usable) refuses what the damage breaks; what it lets
    // through renders.
    eprintln!("{rendered} of 24 damaged files rendered");
}
