//! The entry points the fuzz targets drive, one per reader or stage. Each takes any bytes and
//! must return without a panic, a hang or an allocation sized by an unchecked count; where a
//! step succeeds, what it produces must read back (and a BSP a stage writes must pass the gate).
//! `tests/fuzz_corpus.rs` replays the committed corpora through these same functions on stable.

use quake_formats::bsp::BspVersion;
use quake_formats::{Bsp, check_usable};
use std::path::Path;

/// Quake text is Latin-1: each byte is the char of the same value.
fn latin1(data: &[u8]) -> String {
    data.iter().map(|&b| b as char).collect()
}

/// The `.map` parser alone.
pub fn map_parse(data: &[u8]) {
    let _ = bsp_compiler::map::parse_map(Path::new("fuzz.map"), &latin1(data));
}

/// The whole compiler on a `.map`; a BSP it writes must pass the gate and read back.
pub fn map_compile(data: &[u8]) {
    let source = bsp_compiler::MapSource {
        path: "fuzz.map".into(),
        text: latin1(data),
    };
    let Ok(out) = bsp_compiler::compile(&source, &bsp_compiler::CompileOptions::default()) else {
        return;
    };
    if let Err(e) = check_usable(&out.bsp) {
        panic!("the compiler wrote a BSP tools refuse: {e}");
    }
    let bytes = out.bsp.write().expect("a compiled BSP encodes");
    Bsp::read(&bytes).expect("a compiled BSP reads back");
}

/// The BSP reader, the validator and the gate; a file that reads rewrites and reads back, and a
/// usable one converts to either version.
pub fn bsp_read(data: &[u8]) {
    let Ok(bsp) = Bsp::read(data) else {
        return;
    };
    let _ = quake_formats::validate(&bsp);
    let usable = check_usable(&bsp).is_ok();
    if let Ok(bytes) = bsp.write() {
        Bsp::read(&bytes).expect("a BSP that was read rewrites readably");
    }
    if usable {
        for version in [BspVersion::Bsp29, BspVersion::Bsp2, BspVersion::Bsp2Psb] {
            if let Ok(converted) = bsp.converted(version) {
                let _ = converted.write();
            }
        }
    }
}

/// The WAD2 reader; a WAD that reads rewrites readably, and its textures decode or fail cleanly.
pub fn wad(data: &[u8]) {
    let Ok(wad) = quake_formats::wad::Wad::read(data) else {
        return;
    };
    for lump in &wad.lumps {
        let _ = wad.find_miptex(&lump.name());
    }
    quake_formats::wad::Wad::read(&wad.write()).expect("a WAD that was read rewrites readably");
}

/// Pixels the fuzzer lets a picture have; larger ones are refused only past 4096 on a side (with
/// its unit test), and building them would only be slow.
const FUZZ_PICTURE_PIXELS: u64 = 1 << 16;

/// The WAD builder on one picture: the bytes as a PNG and as a TGA `{` texture (so holes count)
/// with themselves as its glow mask; a WAD that builds reads back with that one texture.
pub fn pictures(data: &[u8]) {
    for (format, ext) in [
        (image::ImageFormat::Png, "png"),
        (image::ImageFormat::Tga, "tga"),
    ] {
        let reader = image::ImageReader::with_format(std::io::Cursor::new(data), format);
        match reader.into_dimensions() {
            Ok((w, h)) if u64::from(w) * u64::from(h) <= FUZZ_PICTURE_PIXELS => {}
            _ => continue,
        }
        let files = vec![
            (format!("{{fuzz.{ext}").into(), data.to_vec()),
            (format!("{{fuzz_glow.{ext}").into(), data.to_vec()),
        ];
        let Ok(sources) = wad::source::from_files(files) else {
            continue;
        };
        let built = wad::build(&sources, &wad::BuildOptions::default(), &|_| {});
        let read = quake_formats::wad::Wad::read(&built.wad.write()).expect("a built WAD reads");
        assert!(
            read.find_miptex("{fuzz").is_some(),
            "the texture is in the WAD"
        );
    }
}

/// What the fuzzer lets base vis spend on its sets; past it vis's own limit
/// ([`vis::MAX_SET_BYTES`], with its unit test) is what refuses, and a run that large would only
/// be slow.
const FUZZ_SET_BYTES: u64 = 64 << 20;

/// The `.prt` reader, then base vis on what it read (vis sizes its sets from the file's counts).
pub fn prt(data: &[u8]) {
    let Ok(prt) = quake_formats::prt::PortalFile::parse(&latin1(data)) else {
        return;
    };
    quake_formats::prt::PortalFile::parse(&prt.write()).expect("a portal file rewrites readably");
    let options = vis::VisOptions {
        mode: vis::VisMode::Fast,
        threads: Some(1),
        ..Default::default()
    };
    let bytes = vis::set_bytes(&prt);
    if bytes > vis::MAX_SET_BYTES {
        assert!(
            vis::compute_vis(&prt, &options).is_err(),
            "vis takes {bytes} bytes"
        );
    }
    if bytes > FUZZ_SET_BYTES {
        return;
    }
    let _ = vis::compute_vis(&prt, &options);
}

/// The `.lit` reader; the first two bytes say how long the BSP's lighting lump is.
pub fn lit(data: &[u8]) {
    let (len, rest) = match data {
        [a, b, rest @ ..] => (u16::from_le_bytes([*a, *b]) as usize, rest),
        _ => return,
    };
    let _ = quake_formats::lit::read_lit(rest, len);
}

/// The entity lump reader; what it reads writes and reads back to as many entities.
pub fn entities(data: &[u8]) {
    let Ok(entities) = quake_formats::entities::parse_entities(&latin1(data)) else {
        return;
    };
    let text = quake_formats::entities::write_entities(&entities);
    let again = quake_formats::entities::parse_entities(&text).expect("written entities parse");
    assert_eq!(again.len(), entities.len());
}

/// A BSP that passes the gate through vis (portals from its tree, base vis), light and the viewer;
/// the BSP vis and light write must pass the gate too.
pub fn stages(data: &[u8]) {
    let Ok(mut bsp) = Bsp::read(data) else {
        return;
    };
    if check_usable(&bsp).is_err() {
        return;
    }
    run_vis(&mut bsp);
    run_light(&mut bsp);
    let bytes = bsp.write();
    if let Ok(bytes) = bytes {
        let back = Bsp::read(&bytes).expect("a BSP vis and light wrote reads back");
        if let Err(e) = check_usable(&back) {
            panic!("vis and light wrote a BSP tools refuse: {e}");
        }
    }
    run_viewer(bsp);
}

fn run_vis(bsp: &mut Bsp) {
    let Ok(prt) = vis::tree_portals::portals_from_bsp(bsp) else {
        return;
    };
    let options = vis::VisOptions {
        mode: vis::VisMode::Fast,
        threads: Some(1),
        ..Default::default()
    };
    let Ok(result) = vis::compute_vis(&prt, &options) else {
        return;
    };
    if vis::write_vis(bsp, &result.pvs).is_ok() {
        let _ = vis::ambient::ambient_levels(bsp, &result.pvs, vis::ambient::Channels::ALL);
    }
}

fn run_light(bsp: &mut Bsp) {
    if let Ok(lighting) = light::compute_lighting(bsp, &light::Options::default()) {
        light::apply_lighting(bsp, &lighting);
    }
}

fn run_viewer(bsp: Bsp) {
    let palette = quake_formats::palette::Palette::slipgate();
    let source = runtime_viewer::textures::PaletteSource::Builtin;
    let Ok(world) = runtime_viewer::World::new(bsp, &palette, source, None) else {
        return;
    };
    let (origin, yaw) = world.player_start().unwrap_or_default();
    let camera = runtime_viewer::Camera {
        origin,
        angles: [0.0, yaw, 0.0],
        width: 32,
        height: 24,
        fov_x: 90.0,
    };
    let mut renderer =
        runtime_viewer::Renderer::new(&world, runtime_viewer::RenderOptions::default());
    let mut frame = runtime_viewer::Frame::new(camera.width, camera.height);
    renderer.render(&world, &camera, &mut frame);
}
