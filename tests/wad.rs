//! `slipgate wad`: build, list and extract through the command line, its exit statuses, and a
//! map compiled against a WAD built from pictures.

#[path = "support/command.rs"]
mod command;

use command::{scratch, slipgate};
use image::{ImageFormat, Rgba, RgbaImage};
use quake_formats::Bsp;
use quake_formats::palette::FIRST_FULLBRIGHT;
use quake_formats::wad::Wad;
use std::path::{Path, PathBuf};
use std::process::Output;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

fn arg(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

fn save(picture: &RgbaImage, path: &Path) {
    let format = ImageFormat::from_path(path).expect("known extension");
    picture.save_with_format(path, format).expect("save");
}

/// A folder of pictures that exercises every convention: an odd size, a TGA, a liquid, a fence
/// with holes, a lamp with a glow mask.
fn pictures(dir: &Path) {
    std::fs::create_dir_all(dir).expect("dir");
    let gradient = RgbaImage::from_fn(40, 24, |x, y| {
        Rgba([60 + 4 * x as u8, 80 + 3 * y as u8, 90, 255])
    });
    save(&gradient, &dir.join("Ramp.png"));
    save(&gradient, &dir.join("stone.tga"));
    save(
        &RgbaImage::from_pixel(32, 32, Rgba([40, 70, 150, 255])),
        &dir.join("#water.png"),
    );
    let grate = RgbaImage::from_fn(32, 32, |x, _| {
        Rgba([120, 110, 90, if x % 8 < 4 { 0 } else { 255 }])
    });
    save(&grate, &dir.join("{grate.png"));
    save(
        &RgbaImage::from_pixel(16, 16, Rgba([250, 230, 160, 255])),
        &dir.join("lamp.png"),
    );
    let glow = RgbaImage::from_fn(16, 16, |x, _| {
        let v = if x < 8 { 255 } else { 0 };
        Rgba([v, v, v, 255])
    });
    save(&glow, &dir.join("lamp_glow.png"));
    // Not a picture: passed over.
    std::fs::write(dir.join("notes.txt"), "not a texture").expect("write");
}

fn read_wad(path: &Path) -> Wad {
    Wad::read(&std::fs::read(path).expect("read WAD")).expect("WAD reads")
}

#[test]
fn build_list_extract_and_build_again() {
    let dir = scratch("wad", "pictures");
    pictures(&dir);
    let wad_path = scratch("wad", "built.wad");
    let stats = scratch("wad", "stats.json");
    let out = slipgate(&[
        "wad",
        "build",
        arg(&dir),
        arg(&wad_path),
        "--stats",
        arg(&stats),
    ]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(0), "{log}");
    assert!(
        log.contains("Ramp.png: 40x24 is not a multiple of 16: stretched to 48x32"),
        "{log}"
    );
    assert!(
        log.contains("wad: 5 textures") && log.contains("mip 3"),
        "{log}"
    );

    let wad = read_wad(&wad_path);
    let ramp = wad.find_miptex("ramp").expect("ramp");
    assert_eq!((ramp.width, ramp.height), (48, 32));
    assert!(wad.find_miptex("stone").is_some() && wad.find_miptex("*water").is_some());
    let grate = wad.find_miptex("{grate").expect("fence");
    let holes = grate.mips.expect("pixels")[0]
        .iter()
        .filter(|&&i| i == 255)
        .count();
    assert_eq!(holes, 32 * 16);
    let lamp = wad.find_miptex("lamp").expect("lamp").mips.expect("pixels");
    for (at, &index) in lamp[0].iter().enumerate() {
        assert_eq!(index >= FIRST_FULLBRIGHT, at % 16 < 8, "lamp pixel {at}");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&stats).expect("stats")).expect("JSON");
    assert_eq!(json["textures"].as_array().map(Vec::len), Some(5));
    assert!(
        json["levels"][3]["dithered"]["block"].as_f64().is_some(),
        "{json}"
    );

    let listed = slipgate(&["wad", "list", arg(&wad_path)]);
    let listing = text(&listed);
    assert_eq!(listed.status.code(), Some(0), "{listing}");
    for line in ["*water ", "{grate ", "48x32", "lamp "] {
        assert!(listing.contains(line), "{line}: {listing}");
    }

    let extracted = scratch("wad", "extracted");
    let out = slipgate(&["wad", "extract", arg(&wad_path), arg(&extracted)]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let mut files: Vec<String> = std::fs::read_dir(&extracted)
        .expect("extracted")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let expected = [
        "#water.png",
        "lamp.png",
        "lamp_glow.png",
        "ramp.png",
        "stone.png",
        "{grate.png",
    ];
    assert_eq!(files, expected);
    let grate_png = image::open(extracted.join("{grate.png"))
        .expect("PNG")
        .into_rgba8();
    assert_eq!(
        (
            grate_png.get_pixel(0, 0).0[3],
            grate_png.get_pixel(5, 0).0[3]
        ),
        (0, 255)
    );

    // The extracted pictures are palette colours already: building them again gives the same
    // full-size levels.
    let again = scratch("wad", "again.wad");
    let out = slipgate(&["wad", "build", arg(&extracted), arg(&again)]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let again = read_wad(&again);
    for lump in &wad.lumps {
        let first = wad.find_miptex(&lump.name()).expect("miptex");
        let second = again.find_miptex(&lump.name()).expect("rebuilt");
        assert_eq!(
            first.mips.expect("pixels")[0],
            second.mips.expect("pixels")[0],
            "{}",
            lump.name()
        );
    }
}

#[test]
fn bad_pictures_are_bad_input_naming_the_file() {
    let dir = scratch("wad", "bad");
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(dir.join("broken.png"), b"not a PNG").expect("write");
    let out = slipgate(&["wad", "build", arg(&dir), arg(&scratch("wad", "bad.wad"))]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out).contains("broken.png"), "{}", text(&out));
    assert!(
        !scratch("wad", "bad.wad").exists(),
        "no WAD written on an error"
    );

    let long = scratch("wad", "long");
    std::fs::create_dir_all(&long).expect("dir");
    save(
        &RgbaImage::new(16, 16),
        &long.join("a_much_too_long_name.png"),
    );
    let out = slipgate(&["wad", "build", arg(&long), arg(&scratch("wad", "long.wad"))]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out).contains("a_much_too_long_name.png"),
        "{}",
        text(&out)
    );

    let empty = scratch("wad", "empty");
    std::fs::create_dir_all(&empty).expect("dir");
    let out = slipgate(&[
        "wad",
        "build",
        arg(&empty),
        arg(&scratch("wad", "empty.wad")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out).contains("no .png or .tga pictures"),
        "{}",
        text(&out)
    );

    let out = slipgate(&["wad", "list", arg(&dir.join("broken.png"))]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out).contains("broken.png"), "{}", text(&out));
}

#[test]
fn bad_usage_exits_2() {
    assert_eq!(slipgate(&["wad"]).status.code(), Some(2));
    assert_eq!(
        slipgate(&["wad", "build", "only-one-arg"]).status.code(),
        Some(2)
    );
    assert_eq!(slipgate(&["wad", "frobnicate"]).status.code(), Some(2));
    let help = slipgate(&["wad", "build", "--help"]);
    assert_eq!(help.status.code(), Some(0));
    assert!(
        text(&help).contains("_glow"),
        "the help explains the conventions"
    );
}

/// The demo WAD built into `dir` from `maps/textures` by the command.
fn wad_from_pictures(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).expect("dir");
    let wad = dir.join("slipgate.wad");
    let out = slipgate(&[
        "wad",
        "build",
        arg(&repo().join("maps/textures")),
        arg(&wad),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    wad
}

/// A map compiled against a WAD built from pictures: the compiler embeds its miptex unchanged.
#[test]
fn the_compiler_embeds_a_wad_built_from_pictures() {
    let dir = scratch("wad", "compile");
    let wad = read_wad(&wad_from_pictures(&dir));
    let bsp_path = dir.join("demo220.bsp");
    let map = repo().join("maps/demo220.map");
    let out = slipgate(&["bsp", "--wad-dir", arg(&dir), arg(&map), arg(&bsp_path)]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let bsp = Bsp::read(&std::fs::read(&bsp_path).expect("BSP")).expect("BSP reads");
    let embedded: Vec<_> = bsp.textures.textures.iter().flatten().collect();
    // demo220 uses four textures, listed in the order it names them after skip, as
    // ericw-tools lists them.
    let names: Vec<String> = embedded.iter().map(|t| t.name()).collect();
    assert_eq!(names, ["skip", "floor1", "wood1", "brick1", "metal1"]);
    for tex in embedded {
        let from_wad = wad.find_miptex(&tex.name()).expect("texture from the WAD");
        assert_eq!(tex.mips, from_wad.mips, "{}", tex.name());
    }
}

/// A compiled map's embedded textures come back out: as a WAD holding the very textures of the
/// WAD it was compiled against, and as pictures.
#[test]
fn a_bsps_textures_extract_to_a_wad_and_to_pictures() {
    let dir = scratch("wad", "from-bsp");
    std::fs::create_dir_all(&dir).expect("dir");
    let bsp = dir.join("demo.bsp");
    let maps = repo().join("maps");
    let out = slipgate(&[
        "bsp",
        "--wad-dir",
        arg(&maps),
        arg(&maps.join("demo.map")),
        arg(&bsp),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let extracted = dir.join("demo-textures.wad");
    let out = slipgate(&["wad", "extract", arg(&bsp), arg(&extracted)]);
    assert!(out.status.success(), "{}", text(&out));
    let source = read_wad(&maps.join("slipgate.wad"));
    let wad = read_wad(&extracted);
    assert!(!wad.lumps.is_empty());
    for lump in &wad.lumps {
        let name = lump.name();
        let theirs = source
            .find_miptex(&name)
            .expect("a texture of the source WAD");
        let ours = wad.find_miptex(&name).expect("miptex");
        assert_eq!(
            (ours.width, ours.height),
            (theirs.width, theirs.height),
            "{name}"
        );
        assert_eq!(ours.mips, theirs.mips, "{name}: pixels");
    }
    let pictures = dir.join("pictures");
    let out = slipgate(&["wad", "extract", arg(&bsp), arg(&pictures)]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(pictures.join("brick1.png").exists());
}
