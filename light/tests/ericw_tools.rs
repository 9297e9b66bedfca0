//! ericw-tools' `bspinfo` and `bsputil --check` (the tools mappers check BSPs with) accept the
//! demo map lit with every BSPX light lump, and its `light` gives the faces the same
//! `DECOUPLED_LM` grids ours does, its bounced light agrees with ours, and our light reads the
//! `texinfo.json` its `qbsp` writes, when they are present in `../shared/anchors`. Skipped, saying so, when absent.

use std::path::{Path, PathBuf};
use std::process::Command;

use light::{Options, Quality, apply_lighting, compute_lighting};

fn anchor(tool: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/anchors/ericw-tools/bin")
        .join(tool)
}

/// The demo map compiled.
fn demo() -> quake_formats::Bsp {
    let map = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps/demo.map");
    let source = bsp_compiler::MapSource::read(&map).expect("maps/demo.map");
    bsp_compiler::compile(&source, &bsp_compiler::CompileOptions::default())
        .expect("compile")
        .bsp
}

/// The demo map compiled and lit with `--bspxlit --bspxlux --bspxhdr --lightgrid`, written
/// into `dir`.
fn lit_demo(dir: &Path) -> PathBuf {
    let mut bsp = demo();
    let mut options = Options {
        quality: Quality::Default,
        ..Options::default()
    };
    let o = &mut options.overrides;
    (o.bspxlit, o.bspxlux, o.bspxhdr, o.lightgrid) =
        (Some(true), Some(true), Some(true), Some(true));
    let lighting = compute_lighting(&bsp, &options).expect("light");
    apply_lighting(&mut bsp, &lighting);
    let path = dir.join("demo.bsp");
    std::fs::write(&path, bsp.write().expect("BSP encodes")).expect("write");
    path
}

fn run(tool: &Path, args: &[&str], bsp: &Path) -> String {
    let out = Command::new(tool)
        .args(args)
        .arg(bsp)
        .current_dir(bsp.parent().expect("a folder"))
        .output()
        .expect("run the tool");
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{} failed:\n{log}", tool.display());
    log
}

#[test]
fn ericw_tools_accept_the_bspx_light_lumps() {
    let (bspinfo, bsputil) = (anchor("bspinfo"), anchor("bsputil"));
    if !bspinfo.exists() || !bsputil.exists() {
        println!(
            "SKIPPED: no ericw-tools bspinfo and bsputil in {}",
            anchor("").display()
        );
        return;
    }
    let dir = std::env::temp_dir().join(format!("slipgate-light-ericw-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let bsp = lit_demo(&dir);
    let info = run(&bspinfo, &[], &bsp);
    for lump in [
        "RGBLIGHTING",
        "LIGHTINGDIR",
        "LIGHTING_E5BGR9",
        "LIGHTGRID_OCTREE",
    ] {
        assert!(info.contains(lump), "bspinfo does not list {lump}:\n{info}");
    }
    let check = run(&bsputil, &["--check"], &bsp);
    assert!(
        !check.to_lowercase().contains("error"),
        "bsputil --check reports errors:\n{check}"
    );
    println!("bspinfo and bsputil --check accept {}", bsp.display());
    std::fs::remove_dir_all(dir).ok();
}

/// ericw-tools' `light -world_units_per_luxel 8` and ours give every face both light the same
/// `DECOUPLED_LM` size and projection.
#[test]
fn ericw_tools_light_makes_the_same_decoupled_grids() {
    let ericw_light = anchor("light");
    if !ericw_light.exists() {
        println!("SKIPPED: no ericw-tools light in {}", anchor("").display());
        return;
    }
    let dir = std::env::temp_dir().join(format!("slipgate-light-decoupled-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let mut bsp = demo();
    let path = dir.join("demo.bsp");
    std::fs::write(&path, bsp.write().expect("BSP encodes")).expect("write");
    run(&ericw_light, &["-world_units_per_luxel", "8"], &path);
    let theirs = quake_formats::Bsp::read(&std::fs::read(&path).expect("read")).expect("decodes");
    let mut options = Options::default();
    options.overrides.world_units_per_luxel = Some(8.0);
    let lighting = compute_lighting(&bsp, &options).expect("light");
    apply_lighting(&mut bsp, &lighting);
    let records = |bsp: &quake_formats::Bsp| {
        bsp.decoupled_lightmaps()
            .expect("DECOUPLED_LM reads")
            .expect("DECOUPLED_LM")
    };
    let (theirs, ours) = (records(&theirs), records(&bsp));
    assert_eq!(theirs.len(), ours.len());
    let mut compared = 0;
    // ericw-tools leaves faces without light out; compare the faces both lit.
    for (face, (t, o)) in theirs.iter().zip(&ours).enumerate() {
        if t.offset < 0 || o.offset < 0 {
            continue;
        }
        assert_eq!((t.width, t.height), (o.width, o.height), "face {face}");
        assert_eq!(t.world_to_luxel, o.world_to_luxel, "face {face}");
        compared += 1;
    }
    assert!(compared > 300, "{compared} faces compared");
    let (bspinfo, bsputil) = (anchor("bspinfo"), anchor("bsputil"));
    if bspinfo.exists() && bsputil.exists() {
        let mine = dir.join("ours.bsp");
        std::fs::write(&mine, bsp.write().expect("BSP encodes")).expect("write");
        let info = run(&bspinfo, &[], &mine);
        assert!(info.contains("DECOUPLED_LM"), "bspinfo:\n{info}");
        let check = run(&bsputil, &["--check"], &mine);
        assert!(
            !check.to_lowercase().contains("error"),
            "bsputil --check:\n{check}"
        );
    }
    std::fs::remove_dir_all(dir).ok();
}

/// Each face's mean grey style-0 light (`None`: no lightmap).
fn face_means(bsp: &quake_formats::Bsp) -> Vec<Option<f64>> {
    let all: Vec<usize> = (0..bsp.faces.len()).collect();
    let mut out = vec![None; all.len()];
    for map in light::lightmaps_in(bsp, &all).lightmaps {
        if let Some(grey) = map
            .styles
            .iter()
            .position(|&s| s == 0)
            .map(|k| &map.grey[k])
        {
            let sum: u64 = grey.iter().map(|&v| u64::from(v)).sum();
            out[map.face] = Some(sum as f64 / grey.len().max(1) as f64);
        }
    }
    out
}

/// The demo map lit by both tools with one bounce, each at its default `-emissivequality`
/// (`low`: a point per reflecting face): nearly every face within 5 levels of ericw-tools'.
/// `high` (gathered over the surfaces) differs more, which is why it is not the default.
#[test]
fn bounced_light_agrees_with_ericw_tools() {
    let ericw_light = anchor("light");
    if !ericw_light.exists() {
        println!("SKIPPED: no ericw-tools light in {}", anchor("").display());
        return;
    }
    let dir = std::env::temp_dir().join(format!("slipgate-light-bounce-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let bsp = demo();
    let path = dir.join("demo.bsp");
    std::fs::write(&path, bsp.write().expect("BSP encodes")).expect("write");
    run(&ericw_light, &["-bounce"], &path);
    let theirs = face_means(
        &quake_formats::Bsp::read(&std::fs::read(&path).expect("read")).expect("decodes"),
    );
    let agreement = |emission| {
        let mut options = Options::default();
        options.overrides.bounce = Some(1);
        options.overrides.emissive_quality = emission;
        let mut ours = bsp.clone();
        apply_lighting(&mut ours, &compute_lighting(&bsp, &options).expect("light"));
        let pairs: Vec<(f64, f64)> = face_means(&ours)
            .into_iter()
            .zip(&theirs)
            .filter_map(|(a, b)| Some((a?, (*b)?)))
            .collect();
        assert!(pairs.len() > 300, "{} faces lit by both", pairs.len());
        let close = pairs.iter().filter(|(a, b)| (a - b).abs() <= 5.0).count();
        close as f64 / pairs.len() as f64
    };
    let low = agreement(None);
    let high = agreement(Some(light::EmissiveQuality::High));
    assert!(low >= 0.97, "low: {:.1}% of faces", 100.0 * low);
    assert!(low > high, "low {low}, high {high}");
    std::fs::remove_dir_all(dir).ok();
}

/// A box room from ericw-tools' `qbsp` with a `func_group` slab keyed `_lightignore 1` and
/// `_minlight 100` under a light: `slipgate-light` reads the `texinfo.json` ericw-tools wrote
/// beside the BSP, so the slab's top takes its minlight (50) and no light, as with ericw-tools'
/// light, and the BSP it writes carries no lump of those keys.
#[test]
fn light_reads_the_per_face_keys_ericw_tools_qbsp_writes_beside_the_bsp() {
    let qbsp = anchor("qbsp");
    if !qbsp.exists() {
        println!("SKIPPED: no ericw-tools qbsp in {}", anchor("").display());
        return;
    }
    let dir = std::env::temp_dir().join(format!("slipgate-light-texinfo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let map = dir.join("slab.map");
    std::fs::write(&map, slab_map()).expect("write the map");
    let bin = anchor("");
    let out = Command::new(&qbsp)
        .arg(&map)
        .current_dir(&dir)
        .env("LD_LIBRARY_PATH", &bin)
        .output()
        .expect("run qbsp");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bsp_path = dir.join("slab.bsp");
    assert!(dir.join("slab.texinfo.json").is_file());
    let log = run(
        Path::new(env!("CARGO_BIN_EXE_slipgate-light")),
        &[],
        &bsp_path,
    );
    assert!(log.contains("per-face keys"), "{log}");
    let bsp = quake_formats::Bsp::read(&std::fs::read(&bsp_path).expect("read")).expect("BSP");
    assert!(bsp.face_flags().expect("no lump").is_none());
    let top = (0..bsp.faces.len())
        .find(|&f| {
            let verts = bsp.face_vertices(&bsp.faces[f]).unwrap_or_default();
            let plane = &bsp.planes[bsp.faces[f].plane as usize];
            let up = plane.normal[2] * if bsp.faces[f].side == 0 { 1.0 } else { -1.0 };
            up > 0.999 && !verts.is_empty() && verts.iter().all(|v| v[2] == -48.0)
        })
        .expect("the slab's top");
    let at = usize::try_from(bsp.faces[top].light_offset).expect("a lightmap");
    assert_eq!(&bsp.lighting[at..at + 4], &[50; 4], "minlight only");
    std::fs::remove_dir_all(dir).ok();
}

/// A sealed box room (inside -128..128), a light, and the `func_group` slab of
/// [`light_reads_the_per_face_keys_ericw_tools_qbsp_writes_beside_the_bsp`].
fn slab_map() -> String {
    use mapgen::brush::{Brush, Map, MapEntity, MapFormat, aabb};
    use mapgen::level::{Level, Surfaces};
    let room = Level::default()
        .room(aabb([-128.0; 3], [128.0; 3]), Surfaces::all("wall"))
        .brushes();
    let slab = Brush::cuboid(aabb([-32.0, -32.0, -64.0], [32.0, 32.0, -48.0]), "wall");
    let map = Map {
        comment: Vec::new(),
        format: MapFormat::Standard,
        entities: vec![
            MapEntity::new("worldspawn").brushes(room),
            MapEntity::new("func_group")
                .key("_lightignore", "1")
                .key("_minlight", "100")
                .brushes([slab]),
            MapEntity::point("light", [0.0, 0.0, 64.0]),
            MapEntity::point("info_player_start", [-90.0, -90.0, -100.0]),
        ],
    };
    map.to_text()
}

/// A room whose light projects the placeholder picture the compiler made for `floor` straight
/// down, lit by both tools (ours through Quake's palette, which ericw-tools has built in):
/// the same faces lit, every luxel within 2 levels of ericw-tools'.
#[test]
fn a_projected_picture_lands_where_ericw_tools_puts_it() {
    let ericw_light = anchor("light");
    let palette =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus/palette/palette.lmp");
    if !ericw_light.exists() || !palette.exists() {
        println!(
            "SKIPPED: no ericw-tools light in {} or no Quake palette at {}",
            anchor("").display(),
            palette.display()
        );
        return;
    }
    let room = |lo: [i32; 3], hi: [i32; 3], texture: &str| {
        let ([x0, y0, z0], [x1, y1, z1]) = (lo, hi);
        format!(
            "{{\n( {x0} {y0} {z0} ) ( {x0} {} {z0} ) ( {x0} {y0} {} ) {texture} 0 0 0 1 1\n\
             ( {x1} {y0} {z0} ) ( {x1} {y0} {} ) ( {x1} {} {z0} ) {texture} 0 0 0 1 1\n\
             ( {x0} {y0} {z0} ) ( {x0} {y0} {} ) ( {} {y0} {z0} ) {texture} 0 0 0 1 1\n\
             ( {x0} {y1} {z0} ) ( {} {y1} {z0} ) ( {x0} {y1} {} ) {texture} 0 0 0 1 1\n\
             ( {x0} {y0} {z0} ) ( {} {y0} {z0} ) ( {x0} {} {z0} ) {texture} 0 0 0 1 1\n\
             ( {x0} {y0} {z1} ) ( {x0} {} {z1} ) ( {} {y0} {z1} ) {texture} 0 0 0 1 1\n}}\n",
            y0 + 1,
            z0 + 1,
            z0 + 1,
            y0 + 1,
            z0 + 1,
            x0 + 1,
            x0 + 1,
            z0 + 1,
            x0 + 1,
            y0 + 1,
            y0 + 1,
            x0 + 1,
        )
    };
    let (w, h, t) = (256, 256, 16);
    let mut world = room([-w - t, -w - t, -t], [w + t, w + t, 0], "floor");
    world += &room([-w - t, -w - t, h], [w + t, w + t, h + t], "ceil");
    world += &room([-w - t, -w - t, 0], [-w, w + t, h], "wall");
    world += &room([w, -w - t, 0], [w + t, w + t, h], "wall");
    world += &room([-w, -w - t, 0], [w, -w, h], "wall");
    world += &room([-w, w, 0], [w, w + t, h], "wall");
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n{world}}}\n\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"0 0 24\"\n}}\n\
         {{\n\"classname\" \"light\"\n\"origin\" \"0 0 200\"\n\"light\" \"300\"\n\"delay\" \"3\"\n\
         \"_project_texture\" \"floor\"\n\"_project_mangle\" \"30 -70 20\"\n\"_project_fov\" \"100\"\n}}\n"
    );
    let source = bsp_compiler::MapSource {
        path: PathBuf::from("projection.map"),
        text,
    };
    let bsp = bsp_compiler::compile(&source, &bsp_compiler::CompileOptions::default())
        .expect("compile")
        .bsp;
    let dir = std::env::temp_dir().join(format!("slipgate-light-project-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("projection.bsp");
    std::fs::write(&path, bsp.write().expect("BSP encodes")).expect("write");
    run(&ericw_light, &[], &path);
    let theirs = quake_formats::Bsp::read(&std::fs::read(&path).expect("read")).expect("decodes");
    let options = Options {
        palette: Some(
            quake_formats::palette::Palette::from_bytes(&std::fs::read(&palette).expect("read"))
                .expect("a palette"),
        ),
        ..Options::default()
    };
    let mut ours = bsp.clone();
    apply_lighting(&mut ours, &compute_lighting(&bsp, &options).expect("light"));
    let all: Vec<usize> = (0..bsp.faces.len()).collect();
    let style0 = |lit: &quake_formats::Bsp| {
        let mut out = vec![None; all.len()];
        for map in light::lightmaps_in(lit, &all).lightmaps {
            if let Some(k) = map.styles.iter().position(|&s| s == 0) {
                out[map.face] = Some(map.grey[k].clone());
            }
        }
        out
    };
    let (ours, theirs) = (style0(&ours), style0(&theirs));
    let mut worst = 0;
    for (face, (a, b)) in ours.iter().zip(&theirs).enumerate() {
        match (a, b) {
            (Some(a), Some(b)) => {
                for (x, y) in a.iter().zip(b) {
                    worst = worst.max(x.abs_diff(*y));
                }
            }
            (None, None) => {}
            _ => panic!("face {face} lit by one tool only"),
        }
    }
    assert!(
        ours.iter().flatten().count() > 10,
        "the picture lights faces"
    );
    assert!(worst <= 2, "a luxel {worst} levels from ericw-tools'");
    std::fs::remove_dir_all(dir).ok();
}
