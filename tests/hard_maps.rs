//! Every map in `maps/hard/` through every stage: `bsp`, `vis`, `light`, `view`. A map's header
//! may say what the compiler must make of it (`// expect: refused`, `leaks`, `compiles, BSP2`;
//! without the line: compiles, sealed, BSP29); whatever compiles must then go through vis, light
//! and the viewer, and each BSP a stage writes must have no validation error. A leaking map gets
//! no portal file, and vis refuses it saying it leaks.
//! `maps/hard/README.md` tables what each stage does with each map.

#[path = "support/command.rs"]
mod command;
#[path = "support/hard.rs"]
mod hard;

use command::slipgate;
use hard::{hard_maps, maps_dir};
use quake_formats::{Bsp, BspVersion, Severity, validate};
use std::path::Path;

/// What the compiler must do with a hard map.
#[derive(Debug, Default)]
struct Expect {
    refused: bool,
    leaks: bool,
    bsp2: bool,
}

fn expectation(text: &str) -> Expect {
    let line = text
        .lines()
        .take_while(|l| l.starts_with("//"))
        .find_map(|l| l.strip_prefix("// expect: "))
        .unwrap_or("compiles");
    Expect {
        refused: line.contains("refused"),
        leaks: line.contains("leaks"),
        bsp2: line.contains("BSP2"),
    }
}

/// Runs one stage; its stderr when it fails.
fn stage(args: &[&str]) -> Result<String, String> {
    let out = slipgate(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    if out.status.success() {
        Ok(stderr)
    } else {
        Err(stderr)
    }
}

fn assert_valid(bsp: &Path, after: &str) -> Bsp {
    let parsed = Bsp::read(&std::fs::read(bsp).expect("read bsp")).expect("parse bsp");
    let errors: Vec<String> = validate(&parsed)
        .into_iter()
        .filter(|p| p.severity == Severity::Error)
        .map(|p| p.to_string())
        .collect();
    assert!(
        errors.is_empty(),
        "{} after {after}: {errors:#?}",
        bsp.display()
    );
    parsed
}

/// One map through the stages; panics saying which stage did what.
fn run_map(map: &Path) {
    let name = map.file_stem().and_then(|s| s.to_str()).expect("name");
    let expect = expectation(&std::fs::read_to_string(map).expect("read map"));
    let dir = command::scratch("hard", name);
    std::fs::create_dir_all(&dir).expect("dir");
    let bsp = dir.join(format!("{name}.bsp"));
    let b = bsp.to_str().expect("utf8");
    let wads = maps_dir();
    let compiled = stage(&[
        "bsp",
        map.to_str().expect("utf8"),
        b,
        "--wad-dir",
        wads.to_str().expect("utf8"),
    ]);
    if expect.refused {
        let stderr = compiled.expect_err("the compiler refuses it");
        assert!(stderr.contains(&format!("{name}.map")), "{name}: {stderr}");
        assert!(!bsp.exists(), "{name}: refused but wrote {b}");
        return;
    }
    let stderr = compiled.unwrap_or_else(|e| panic!("{name}: bsp failed: {e}"));
    assert_eq!(stderr.contains("LEAK"), expect.leaks, "{name}: {stderr}");
    assert_eq!(
        bsp.with_extension("pts").exists(),
        expect.leaks,
        "{name}: pointfile"
    );
    let version = assert_valid(&bsp, "bsp").version;
    let wanted = if expect.bsp2 {
        BspVersion::Bsp2
    } else {
        BspVersion::Bsp29
    };
    assert_eq!(version, wanted, "{name}");
    if expect.leaks {
        // No portal file for vis to work through the void with; vis says why.
        assert!(!bsp.with_extension("prt").exists(), "{name}: a .prt");
        let stderr = stage(&["vis", b]).expect_err("vis refuses a leaking map");
        assert!(stderr.contains("the map leaks"), "{name}: {stderr}");
    }
    let stages = if expect.leaks {
        vec![vec!["light", b]]
    } else {
        vec![vec!["vis", b], vec!["light", b]]
    };
    for args in stages {
        if let Err(e) = stage(&args) {
            panic!("{name}: {} failed: {e}", args[0]);
        }
        assert_valid(&bsp, args[0]);
    }
    let png = dir.join(format!("{name}.png"));
    let view = stage(&[
        "view",
        b,
        "--size",
        "64x48",
        "--out",
        png.to_str().expect("utf8"),
    ]);
    if let Err(e) = view {
        panic!("{name}: view failed: {e}");
    }
    assert!(png.exists(), "{name}: no picture");
}

#[test]
fn every_hard_map_goes_through_every_stage() {
    let maps = hard_maps();
    assert!(maps.len() >= 16, "only {} hard maps", maps.len());
    for map in &maps {
        run_map(map);
    }
}

#[test]
fn every_hard_map_is_in_the_readme_table() {
    let readme = std::fs::read_to_string(maps_dir().join("hard/README.md")).expect("README");
    for entry in std::fs::read_dir(maps_dir().join("hard")).expect("maps/hard") {
        let path = entry.expect("entry").path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
            continue;
        };
        if name.ends_with(".map") {
            assert!(
                readme.contains(&format!("| `{name}` |")),
                "README lacks {name}"
            );
        }
    }
}
