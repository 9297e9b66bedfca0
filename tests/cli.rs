//! End-to-end tests of the `slipgate` command: exit codes, `info`, `convert`.

#[path = "support/command.rs"]
mod command;
#[path = "support/corpus.rs"]
mod support_corpus;

use command::slipgate;
use std::path::{Path, PathBuf};
use support_corpus::corpus;

fn scratch(name: &str) -> PathBuf {
    command::scratch("cli", name)
}

#[test]
fn bad_usage_exits_2_and_bad_input_exits_1() {
    assert_eq!(slipgate(&["no-such-command"]).status.code(), Some(2));
    assert_eq!(slipgate(&["info"]).status.code(), Some(2));
    let missing = slipgate(&["info", "/nonexistent/x.bsp"]);
    assert_eq!(missing.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("/nonexistent/x.bsp"));

    let junk = scratch("junk.bsp");
    std::fs::write(&junk, b"this is not a bsp file at all").expect("write");
    let out = slipgate(&["info", junk.to_str().expect("utf8")]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("junk.bsp"));
}

#[test]
fn info_counts_and_validates_a_corpus_bsp() {
    let Some(bsp) = corpus("public/bsp/librequake/start.bsp") else {
        return;
    };
    let out = slipgate(&["info", bsp.to_str().expect("utf8")]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("BSP29"));
    assert!(text.contains("faces              1620"), "{text}");
    assert!(text.contains("valid: no problems found"));
}

#[test]
fn info_exits_1_on_a_damaged_bsp() {
    let Some(bsp) = corpus("public/bsp/librequake/start.bsp") else {
        return;
    };
    let mut bytes = std::fs::read(bsp).expect("read");
    // Point marksurface 0 at face 60000.
    let ofs = i32::from_le_bytes(bytes[4 + 11 * 8..4 + 11 * 8 + 4].try_into().expect("4")) as usize;
    bytes[ofs..ofs + 2].copy_from_slice(&60000u16.to_le_bytes());
    let damaged = scratch("damaged.bsp");
    std::fs::write(&damaged, bytes).expect("write");
    let out = slipgate(&["info", damaged.to_str().expect("utf8")]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("marksurfaces[0]: face 60000 is out of range"),
        "{text}"
    );
}

#[test]
fn convert_round_trips_and_accepts_ericw_spelling() {
    let Some(bsp) = corpus("public/bsp/librequake/start.bsp") else {
        return;
    };
    let original = std::fs::read(&bsp).expect("read");
    let same = scratch("same.bsp");
    let v2 = scratch("v2.bsp");
    let back = scratch("back.bsp");
    let s = |p: &Path| p.to_str().expect("utf8").to_string();
    assert!(slipgate(&["convert", &s(&bsp), &s(&same)]).status.success());
    assert!(
        std::fs::read(&same).expect("read") == original,
        "same-version rewrite differs"
    );
    assert!(
        slipgate(&["convert", &s(&bsp), &s(&v2), "-bsp2"])
            .status
            .success()
    );
    assert!(std::fs::read(&v2).expect("read").starts_with(b"BSP2"));
    assert!(
        slipgate(&["convert", &s(&v2), &s(&back), "--bsp29"])
            .status
            .success()
    );
    let out = slipgate(&["info", &s(&back)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}

#[test]
fn build_runs_the_whole_pipeline_on_the_demo_map() {
    let maps = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps");
    let dir = scratch("build");
    std::fs::create_dir_all(&dir).expect("dir");
    for f in ["demo.map", "slipgate.wad"] {
        std::fs::copy(maps.join(f), dir.join(f)).expect("copy");
    }
    let map = dir.join("demo.map");
    let out = slipgate(&[
        "build",
        map.to_str().expect("utf8"),
        "--size",
        "160x100",
        "-extra",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for ext in ["bsp", "prt", "png"] {
        assert!(map.with_extension(ext).exists(), "no .{ext} written");
    }
    assert!(
        !map.with_extension("pts").exists(),
        "the demo map is sealed"
    );
    let info = slipgate(&["info", map.with_extension("bsp").to_str().expect("utf8")]);
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(info.status.success(), "{text}");
    assert!(text.contains("valid: no problems found"), "{text}");
    let lighting: usize = text
        .lines()
        .find(|l| l.trim_start().starts_with("lighting"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|n| n.parse().ok())
        .expect("lighting line");
    assert!(lighting > 0, "the build left the map unlit");
}

/// Sight lines between random points must never find a leaf missing from the other's PVS; this
/// failed on every waterline before the compiler wrote portals through liquid surfaces.
#[test]
fn vis_of_the_demo_map_is_never_too_small() {
    let maps = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps");
    let dir = scratch("vis");
    std::fs::create_dir_all(&dir).expect("dir");
    for f in ["demo.map", "slipgate.wad"] {
        std::fs::copy(maps.join(f), dir.join(f)).expect("copy");
    }
    let map = dir.join("demo.map");
    let bsp = map.with_extension("bsp");
    assert!(
        slipgate(&["bsp", map.to_str().expect("utf8")])
            .status
            .success()
    );
    let mut in_pvs = Vec::new();
    for mode in [&["-fast"][..], &[][..]] {
        let mut args = vec!["vis", "--sample-pairs", "100000"];
        args.extend_from_slice(mode);
        args.push(bsp.to_str().expect("utf8"));
        let out = slipgate(&args);
        let text = String::from_utf8_lossy(&out.stdout).to_string()
            + &String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{text}");
        let line = text
            .lines()
            .find(|l| l.contains("sampling:"))
            .expect("sampling line");
        assert!(line.ends_with("0 too small"), "{line}");
        let share: f64 = line
            .split(" vs ")
            .nth(1)
            .and_then(|s| s.split('%').next())
            .and_then(|s| s.parse().ok())
            .expect("PVS share");
        in_pvs.push(share);
    }
    assert!(
        in_pvs[1] <= in_pvs[0],
        "full vis {} is larger than fast {}",
        in_pvs[1],
        in_pvs[0]
    );
}

/// A map whose worldspawn has no brushes stops `bsp` and `build` with exit 1, an error naming the
/// file and worldspawn, and no files written (the BSP it used to write failed `info`).
#[test]
fn a_world_without_brushes_is_an_error_and_writes_nothing() {
    let dir = scratch("empty-world");
    std::fs::create_dir_all(&dir).expect("dir");
    let map = dir.join("empty.map");
    std::fs::write(
        &map,
        "{\n\"classname\" \"worldspawn\"\n}\n\
         {\n\"classname\" \"info_player_start\"\n\"origin\" \"0 0 32\"\n}\n",
    )
    .expect("write map");
    let map_arg = map.to_str().expect("utf8");
    for command in ["bsp", "build"] {
        let out = slipgate(&[command, map_arg]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{command}: {stderr}");
        assert!(
            stderr.contains(&format!(
                "{map_arg}: worldspawn (entity 0) has no brushes to build"
            )),
            "{command}: {stderr}"
        );
        for ext in ["bsp", "prt", "pts", "png"] {
            assert!(
                !map.with_extension(ext).exists(),
                "{command} wrote a .{ext}"
            );
        }
    }
}

#[test]
fn info_says_whether_the_lit_beside_a_bsp_is_its_own() {
    let Some(bsp) = corpus("public/bsp/librequake/start.bsp") else {
        return;
    };
    let copy = scratch("lit-check.bsp");
    std::fs::copy(bsp, &copy).expect("copy");
    let lighting = quake_formats::Bsp::read(&std::fs::read(&copy).expect("read"))
        .expect("corpus BSP reads")
        .lighting;
    let lit = copy.with_extension("lit");
    let info = || {
        String::from_utf8_lossy(&slipgate(&["info", copy.to_str().expect("utf8")]).stdout)
            .into_owned()
    };
    let own: Vec<u8> = lighting.iter().flat_map(|&g| [g, g, g]).collect();
    std::fs::write(&lit, quake_formats::lit::write_lit(&own)).expect("write");
    assert!(
        info().contains("grey agrees with the lighting lump"),
        "{}",
        info()
    );
    let foreign: Vec<u8> = lighting.iter().flat_map(|&g| [255 - g; 3]).collect();
    std::fs::write(&lit, quake_formats::lit::write_lit(&foreign)).expect("write");
    assert!(
        info().contains("the colours of another light run"),
        "{}",
        info()
    );
    std::fs::write(&lit, quake_formats::lit::write_lit(&own[3..])).expect("write");
    assert!(info().contains("engines ignore it"), "{}", info());
}

/// A leaking map gets its pointfile and no `.prt` (an old one is removed), so vis never flows
/// through the void; `--keepprt` writes it anyway, and vis then refuses it, saying the map
/// leaks. Once the map seals, the old pointfile goes.
#[test]
fn a_leak_writes_a_pointfile_and_no_portal_file_and_vis_refuses_the_void() {
    let dir = scratch("leak-outputs");
    std::fs::create_dir_all(&dir).expect("dir");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let map = dir.join("pinhole.map");
    std::fs::copy(repo.join("maps/hard/pinhole.map"), &map).expect("copy");
    let (prt, pts) = (map.with_extension("prt"), map.with_extension("pts"));
    std::fs::write(&prt, "an old portal file").expect("write");
    let map_arg = map.to_str().expect("utf8");

    let out = slipgate(&["bsp", map_arg]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("LEAK: entity 1 (info_player_start, line 92)"),
        "{stderr}"
    );
    assert!(
        stderr.contains("brush 7 of entity 0 (line 73, brick1)"),
        "{stderr}"
    );
    assert!(pts.exists() && !prt.exists(), "{stderr}");

    let out = slipgate(&["bsp", "-keepprt", map_arg]);
    assert!(out.status.success() && prt.exists());
    let bsp = map.with_extension("bsp");
    let out = slipgate(&["vis", bsp.to_str().expect("utf8")]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("the map leaks"), "{stderr}");

    // Sealed: the same room without its pinhole brushes' gap.
    std::fs::copy(repo.join("maps/leak/sealed.map"), &map).expect("copy");
    let out = slipgate(&["bsp", map_arg]);
    assert!(out.status.success());
    assert!(prt.exists() && !pts.exists());
}

/// A map with no point entity in its open space does not leak: the compiler fills nothing and
/// writes the `.prt` of the whole tree, and vis says that the outside is included and runs.
#[test]
fn a_map_without_entities_still_vis() {
    let dir = scratch("no-entities");
    std::fs::create_dir_all(&dir).expect("dir");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sealed = std::fs::read_to_string(repo.join("maps/leak/sealed.map")).expect("read");
    // Worldspawn alone: everything up to the line that closes it.
    let end = sealed.find("\n}\n// entity 1").expect("worldspawn's end");
    let map = dir.join("blockout.map");
    std::fs::write(&map, format!("{}\n}}\n", &sealed[..end])).expect("write");

    let out = slipgate(&["bsp", map.to_str().expect("utf8")]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("outside filling skipped"), "{stderr}");
    assert!(map.with_extension("prt").exists() && !map.with_extension("pts").exists());

    let out = slipgate(&["vis", map.with_extension("bsp").to_str().expect("utf8")]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("the outside is included"), "{stderr}");
}

/// `slipgate decompile` writes a `.map` that compiles again, sealed, with brushes and textures.
#[test]
fn a_decompiled_bsp_compiles_again() {
    let dir = scratch("decompile");
    std::fs::create_dir_all(&dir).expect("dir");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let maps = repo.join("maps");
    let bsp = dir.join("demo.bsp");
    let arg = |p: &Path| p.to_str().expect("utf8").to_string();
    let out = slipgate(&[
        "bsp",
        "--wad-dir",
        &arg(&maps),
        &arg(&maps.join("demo.map")),
        &arg(&bsp),
    ]);
    assert!(out.status.success());
    let out = slipgate(&["decompile", &arg(&bsp)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let map = dir.join("demo-decompile.map");
    assert!(stderr.contains("brushes"), "{stderr}");
    let again = dir.join("again.bsp");
    let out = slipgate(&["bsp", "--wad-dir", &arg(&maps), &arg(&map), &arg(&again)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("LEAK"), "{stderr}");
}

/// A listing piped into a reader that stops early (`slipgate wad list X.wad | head -1`) ends
/// the command quietly, as other tools end, instead of a panic on the closed pipe.
#[test]
fn a_reader_that_stops_early_ends_the_listing_quietly() {
    use quake_formats::wad::Wad;
    use std::io::{BufRead, BufReader};
    use std::process::{Command, Stdio};
    // A listing longer than a pipe holds, so the command is still writing when the reader goes.
    let demo = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("maps/slipgate.wad"))
        .expect("maps/slipgate.wad");
    let lumps = Wad::read(&demo).expect("a WAD").lumps;
    let many: Vec<_> = lumps
        .iter()
        .cycle()
        .take(lumps.len() * 200)
        .cloned()
        .collect();
    let wad = scratch("many.wad");
    std::fs::write(&wad, Wad::new(many).write()).expect("write");
    let mut child = Command::new(env!("CARGO_BIN_EXE_slipgate"))
        .args(["wad", "list", wad.to_str().expect("utf8")])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run slipgate");
    let mut first = String::new();
    let mut reader = BufReader::new(child.stdout.take().expect("stdout"));
    reader.read_line(&mut first).expect("the first line");
    drop(reader);
    let out = child.wait_with_output().expect("wait");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(first.starts_with("name"), "{first}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}
