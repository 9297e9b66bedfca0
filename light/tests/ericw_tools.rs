//! ericw-tools' `bspinfo` and `bsputil --check` (the tools mappers check BSPs with) accept the
//! demo map lit with every BSPX light lump, and its `light` gives the faces the same
//! `DECOUPLED_LM` grids ours does, when they are present in `../shared/anchors`. Skipped,
//! saying so, when absent.

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
