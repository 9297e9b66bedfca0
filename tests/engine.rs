//! End-to-end: maps compiled by Slipgate, played in real engines with real game code.
//!
//! Every project map (`maps/*.map`, `maps/test/`, `maps/leak/sealed.map`, the compiler's test maps, `demo.map` again as
//! BSP2, and the `maps/hard/` maps that compile), LibreQuake's compiled start map decompiled
//! (`slipgate decompile`), and, with `--include-ignored`, every corpus map, goes through `slipgate bsp`, `vis` and `light` (`support/maps.rs`), then into
//! QuakeSpasm and DarkPlaces with LibreQuake's game code from `../shared/engine`
//! (`support/engines.rs`): each engine's dedicated server spawns the map and runs five seconds of
//! game time, then its client plays it from the player start (god mode, every weapon, walking,
//! jumping, turning, firing) and screenshots it. A run fails on a fatal error, a crash, a
//! timeout, a blank screenshot or a player that never fired.
//!
//! The two engines' tests run at once (each plays two maps at a time) and share the compiled
//! maps. Screenshots and logs stay in the scratch directory the tests print.
//! Each engine, its client (which needs `xvfb-run`), `../shared/engine` and `../shared/corpus`
//! skip independently with a `SKIPPED:` line when absent.
#![cfg(unix)]

// Only its `slipgate`: this test keeps its own scratch directory.
#[allow(dead_code)]
#[path = "support/command.rs"]
mod command;
#[path = "support/engines.rs"]
mod engines;
#[path = "support/maps.rs"]
mod maps;
#[path = "support/corpus.rs"]
mod support_corpus;

use engines::{Engine, Kind, Outcome};
use maps::{Case, KnownError, MapSet, NotCompiled};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::ExitStatus;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::Instant;
use support_corpus::corpus;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// This test process's scratch directory.
fn scratch() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("slipgate-engine-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch dir");
        dir
    })
}

fn maps_in(dir: &Path) -> Vec<PathBuf> {
    let mut maps: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "map"))
        .collect();
    maps.sort();
    maps
}

fn project_maps() -> &'static MapSet {
    static SET: OnceLock<MapSet> = OnceLock::new();
    SET.get_or_init(|| {
        let wads = || vec![repo().join("maps")];
        let mut maps = maps_in(&repo().join("maps"));
        maps.extend(maps_in(&repo().join("maps/test")));
        maps.push(repo().join("maps/leak/sealed.map"));
        let mut cases: Vec<Case> = maps.into_iter().map(|m| Case::new(m, wads())).collect();
        // Prefabs (nested, turned, scaled), `_mirrorinside` water and a visblocker.
        cases.push(Case::new(
            repo().join("bsp-compiler/tests/maps/features.map"),
            wads(),
        ));
        // ericw-tools' keys: `_hulls`, `_shadow -1`, `_noambient`, switchable shadows,
        // `*waterskip`, a light on the floor, `_surface` lights on a wall fixture.
        cases.push(Case::new(
            repo().join("bsp-compiler/tests/maps/ericw_keys.map"),
            wads(),
        ));
        cases.push(Case {
            name: "demo_bsp2".to_string(),
            bsp_options: &["--bsp2"],
            ..Case::new(repo().join("maps/demo.map"), wads())
        });
        // RMQ's 2PSB (32-bit indices, 16-bit bounds), which both engines read; a small map.
        cases.push(Case {
            name: "sealed_2psb".to_string(),
            bsp_options: &["--2psb"],
            ..Case::new(repo().join("maps/leak/sealed.map"), wads())
        });
        // LibreQuake's release light settings, with coloured bounce: a `.lit` the engines load.
        cases.push(Case {
            name: "demo_bounce".to_string(),
            light_options: &[
                "--extra4",
                "--soft",
                "--bounce",
                "--dirt",
                "--bouncecolorscale",
                "1",
            ],
            ..Case::new(repo().join("maps/demo.map"), wads())
        });
        cases.extend(
            maps_in(&repo().join("maps/hard"))
                .into_iter()
                .map(|m| Case {
                    may_fail_to_compile: true,
                    known_error: m.ends_with("hard/fan.map").then_some(KnownError {
                        engine: "darkplaces",
                        message: "Mod_Q1BSP_RecursiveNodePortals: portal has same node on both \
                                  sides(1)",
                    }),
                    ..Case::new(m, wads())
                }),
        );
        MapSet::new(cases, scratch().join("project"))
    })
}

/// Every corpus map (`public/maps/**.map`), with its own WADs (`wads/<folder>` for a map under
/// `maps/<folder>/`; the id maps have none: placeholder textures). `None` after saying so when
/// the corpus is absent.
fn corpus_maps() -> Option<&'static MapSet> {
    static SET: OnceLock<Option<MapSet>> = OnceLock::new();
    SET.get_or_init(|| {
        let root = corpus("public/maps")?;
        let wads = corpus("wads")?;
        let mut maps = Vec::new();
        maps_under(&root, &mut maps);
        let cases = maps.into_iter().map(|map| {
            let folder = map.strip_prefix(&root).ok().and_then(|p| p.iter().next());
            let own_wads = folder.map(|folder| wads.join(folder));
            let wad_dirs = own_wads.into_iter().filter(|w| w.is_dir()).collect();
            let empty_view = map.ends_with("ericw-tools/q1_cube.map").then_some(
                "ericw-tools' cube: one brush in the void, below the player start's view, its one \
                 texture missing",
            );
            Case {
                empty_view,
                ..Case::new(map, wad_dirs)
            }
        });
        Some(MapSet::new(cases.collect(), scratch().join("corpus")))
    })
    .as_ref()
}

/// LibreQuake's start map as ericw-tools compiled it (`public/bsp/librequake/start.bsp`),
/// decompiled: compiled back, it must play like any map. `None` after saying so when the corpus
/// is absent.
fn decompiled_maps() -> Option<&'static MapSet> {
    static SET: OnceLock<Option<MapSet>> = OnceLock::new();
    SET.get_or_init(|| {
        let bsp_path = corpus("public/bsp/librequake/start.bsp")?;
        let wads = corpus("wads/librequake")?;
        let bytes = std::fs::read(&bsp_path).expect("read start.bsp");
        let bsp = quake_formats::Bsp::read(&bytes).expect("start.bsp parses");
        let decompiled =
            decompile::decompile(&bsp, &decompile::Options::default()).expect("decompile");
        let dir = scratch().join("decompiled");
        std::fs::create_dir_all(&dir).expect("scratch dir");
        let map = dir.join("start_decompiled.map");
        std::fs::write(&map, decompiled.text).expect("write the decompiled map");
        Some(MapSet::new(vec![Case::new(map, vec![wads])], dir))
    })
    .as_ref()
}

/// The maps in `dir` and below, sorted.
fn maps_under(dir: &Path, maps: &mut Vec<PathBuf>) {
    maps.extend(maps_in(dir));
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let mut folders: Vec<PathBuf> = entries
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.is_dir())
        .collect();
    folders.sort();
    for folder in folders {
        maps_under(&folder, maps);
    }
}

/// A line of the summary: one map in one engine.
struct Row {
    map: String,
    compiled: String,
    server: String,
    client: String,
}

/// Engine runs of one test at once: the two tests together keep a 2-core machine busy even
/// after the faster engine is done.
const RUNS_AT_ONCE: usize = 2;

/// Play every map of `set` in `engine` ([`RUNS_AT_ONCE`] maps at a time; each map's server, then
/// its client), then print a summary and panic listing every failure.
fn play_all(engine: &Engine, set: &'static MapSet) {
    let started = Instant::now();
    let name = engine.kind.name();
    eprintln!("{name}: runs in {}", scratch().display());
    let next = AtomicUsize::new(0);
    let results = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..RUNS_AT_ONCE {
            scope.spawn(|| {
                loop {
                    let index = next.fetch_add(1, Ordering::Relaxed);
                    if index >= set.len() {
                        break;
                    }
                    set.prefetch(index + 1);
                    let result = play(engine, set, index);
                    results.lock().expect("results").push((index, result));
                }
            });
        }
    });
    let mut results = results.into_inner().expect("results");
    results.sort_by_key(|(index, _)| *index);
    let (mut rows, mut failures) = (Vec::new(), Vec::new());
    for (_, (row, failed)) in results {
        rows.extend(row);
        failures.extend(failed);
    }
    eprintln!("\n{name}: {} maps in {:.1?}", rows.len(), started.elapsed());
    eprintln!("| map | compile | {name} server | {name} client |\n|---|---|---|---|");
    for row in &rows {
        eprintln!(
            "| {} | {} | {} | {} |",
            row.map, row.compiled, row.server, row.client
        );
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}

/// Map `index` in `engine`: its summary line (none when it was not compiled) and its failures.
fn play(engine: &Engine, set: &MapSet, index: usize) -> (Option<Row>, Vec<String>) {
    let name = engine.kind.name();
    let map = match set.get(index) {
        Ok(map) => map,
        Err(NotCompiled::Skipped(why)) => {
            eprintln!(
                "note: {} does not compile, not played: {why}",
                set.name(index)
            );
            return (None, Vec::new());
        }
        Err(NotCompiled::Failed(why)) => {
            return (None, vec![format!("{}: {why}", set.name(index))]);
        }
    };
    if let Some(why) = map.empty_view {
        eprintln!("note: {}: its screenshot may be empty: {why}", map.name);
    }
    let mut failures = Vec::new();
    let mut record = |mode: &str, result: Result<Outcome, String>| match result {
        Ok(outcome) => {
            for note in &outcome.notes {
                eprintln!("{name} {mode} {}: note: {note}", map.name);
            }
            if let Some(shot) = &outcome.screenshot {
                eprintln!("{name} {}: screenshot {}", map.name, shot.display());
            }
            summary(&outcome)
        }
        Err(why)
            if map
                .known_error
                .is_some_and(|k| k.engine == name && why.contains(k.message)) =>
        {
            eprintln!(
                "{name} {mode} {}: note: known error, not yet fixed: {why}",
                map.name
            );
            "known error".to_string()
        }
        Err(why) => {
            failures.push(format!("{name} {mode} {}: {why}", map.name));
            "FAILED".to_string()
        }
    };
    let mut row = Row {
        map: map.name.clone(),
        compiled: format!("{:.1} s, vis {}", map.seconds, map.vis),
        server: "-".to_string(),
        client: "-".to_string(),
    };
    if engine.has_server() {
        row.server = record("server", engine.serve(map));
    }
    if engine.has_client() {
        row.client = record("client", engine.play(map));
    }
    eprintln!(
        "{name} {}: server {}; client {}",
        row.map, row.server, row.client
    );
    (Some(row), failures)
}

fn summary(outcome: &Outcome) -> String {
    let mut text = format!("ok {:.1} s", outcome.seconds);
    if let Some(time) = outcome.game_time {
        text += &format!(", game time {time:.1} s");
    }
    if let Some(colours) = outcome.view_colours {
        text += &format!(", {colours} colours");
    }
    text
}

#[test]
fn quakespasm_plays_the_project_maps() {
    if let Some(engine) = Engine::find(Kind::QuakeSpasm, scratch()) {
        play_all(&engine, project_maps());
    }
}

#[test]
fn darkplaces_plays_the_project_maps() {
    if let Some(engine) = Engine::find(Kind::DarkPlaces, scratch()) {
        play_all(&engine, project_maps());
    }
}

#[test]
#[ignore = "slow: compiles and plays every corpus map; run with --release -- --ignored"]
fn quakespasm_plays_the_corpus_maps() {
    if let (Some(engine), Some(set)) = (Engine::find(Kind::QuakeSpasm, scratch()), corpus_maps()) {
        play_all(&engine, set);
    }
}

#[test]
#[ignore = "slow: compiles and plays every corpus map; run with --release -- --ignored"]
fn darkplaces_plays_the_corpus_maps() {
    if let (Some(engine), Some(set)) = (Engine::find(Kind::DarkPlaces, scratch()), corpus_maps()) {
        play_all(&engine, set);
    }
}

#[test]
fn quakespasm_plays_a_decompiled_corpus_bsp() {
    if let (Some(engine), Some(set)) =
        (Engine::find(Kind::QuakeSpasm, scratch()), decompiled_maps())
    {
        play_all(&engine, set);
    }
}

#[test]
fn darkplaces_plays_a_decompiled_corpus_bsp() {
    if let (Some(engine), Some(set)) =
        (Engine::find(Kind::DarkPlaces, scratch()), decompiled_maps())
    {
        play_all(&engine, set);
    }
}

/// Frames of walking forward, at Quake's 200 units a second: long enough for the sealing
/// corridors' 1024 units, with room to spare.
const WALK_FRAMES: usize = 70;
/// The inside of the sealing corridors (`maps/hard/seal_*.map`) along x, and their floor.
const CORRIDOR_X: [f32; 2] = [0.0, 1024.0];
const CORRIDOR_FLOOR: f32 = 0.0;

/// The sealing hard cases (`maps/hard/seal_*.map`) are corridors a player walks end to end in
/// QuakeSpasm: from the start at the west end, the walk must reach the east wall and end
/// standing on the floor (a corridor whose hulls let the player out, or stop it short, fails).
#[test]
fn quakespasm_players_walk_the_sealing_corridors_end_to_end() {
    let Some(engine) = Engine::find(Kind::QuakeSpasm, scratch()) else {
        return;
    };
    if !engine.has_client() {
        eprintln!("SKIPPED: QuakeSpasm's client (or xvfb-run) is absent: the walks need it");
        return;
    }
    let set = project_maps();
    let mut failures = Vec::new();
    let corridors: Vec<usize> = (0..set.len())
        .filter(|&i| set.name(i).starts_with("seal_"))
        .collect();
    assert!(!corridors.is_empty(), "no maps/hard/seal_*.map");
    for index in corridors {
        let map = match set.get(index) {
            Ok(map) => map,
            Err(e) => {
                failures.push(format!(
                    "{}: not compiled: {}",
                    set.name(index),
                    match e {
                        NotCompiled::Skipped(w) | NotCompiled::Failed(w) => w,
                    }
                ));
                continue;
            }
        };
        match engine.walk(map, WALK_FRAMES) {
            // The player's box is 32 wide: its centre stops 16 short of the east wall, and
            // stands 24 above the floor.
            Ok([x, _, z])
                if x > CORRIDOR_X[1] - 24.0 && (z - CORRIDOR_FLOOR - 24.0).abs() < 1.0 =>
            {
                eprintln!("quakespasm walk {}: reached x {x}, z {z}", map.name);
            }
            Ok(origin) => failures.push(format!(
                "{}: the walk east from x {} ended at {origin:?}",
                map.name, CORRIDOR_X[0]
            )),
            Err(e) => failures.push(format!("{}: {e}", map.name)),
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// The demo map compiled against a WAD that `slipgate wad build` makes here from the committed
/// pictures (`maps/textures`: sky holes, a glow mask, liquids), played in QuakeSpasm.
#[test]
fn quakespasm_plays_a_map_with_a_wad_built_from_pictures() {
    let Some(engine) = Engine::find(Kind::QuakeSpasm, scratch()) else {
        return;
    };
    static SET: OnceLock<MapSet> = OnceLock::new();
    let set = SET.get_or_init(|| {
        let dir = scratch().join("wad_from_pictures");
        std::fs::create_dir_all(&dir).expect("scratch dir");
        let wad = dir.join("slipgate.wad");
        let pictures = repo().join("maps/textures");
        let out = command::slipgate(&[
            "wad",
            "build",
            maps::path_str(&pictures),
            maps::path_str(&wad),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let case = Case {
            name: "demo_wad_from_pictures".to_string(),
            ..Case::new(repo().join("maps/demo.map"), vec![dir.clone()])
        };
        MapSet::new(vec![case], dir)
    });
    play_all(&engine, set);
}

/// The check itself: a BSP from another compiler passes both servers, and one with a marksurface
/// pointing past the faces stops both.
#[test]
fn engine_servers_pass_a_known_good_bsp_and_fail_a_damaged_one() {
    let Some(good) = corpus("public/bsp/librequake/start.bsp") else {
        return;
    };
    let dir = scratch().join("check");
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let known_good = maps::Compiled {
        name: "known_good".to_string(),
        bsp: good.clone(),
        lit: None,
        start: None,
        vis: "",
        seconds: 0.0,
        empty_view: None,
        known_error: None,
    };
    let mut bytes = std::fs::read(&good).expect("read");
    let marksurfaces_lump = 4 + 11 * 8;
    let offset = u32::from_le_bytes(
        bytes[marksurfaces_lump..marksurfaces_lump + 4]
            .try_into()
            .expect("4 bytes"),
    ) as usize;
    bytes[offset..offset + 2].copy_from_slice(&60000u16.to_le_bytes());
    let damaged_bsp = dir.join("damaged.bsp");
    std::fs::write(&damaged_bsp, bytes).expect("write");
    let damaged = maps::Compiled {
        name: "damaged".to_string(),
        bsp: damaged_bsp,
        ..known_good.clone()
    };
    for kind in [Kind::QuakeSpasm, Kind::DarkPlaces] {
        let Some(engine) = Engine::find(kind, &dir) else {
            continue;
        };
        if !engine.has_server() {
            continue;
        }
        if let Err(e) = engine.serve(&known_good) {
            panic!("{}: {e}", kind.name());
        }
        let err = engine
            .serve(&damaged)
            .err()
            .unwrap_or_else(|| panic!("{} must reject a damaged BSP", kind.name()));
        assert!(err.contains("bad surface number"), "{err}");
    }
}

/// A crash shows in the exit status, directly or through `xvfb-run`'s shell (128 + signal).
#[test]
fn a_crash_signal_is_a_failure() {
    let segfault = ExitStatus::from_raw(11);
    assert!(engines::exit_problem(segfault).is_some_and(|p| p.contains("SIGSEGV")));
    let through_shell = ExitStatus::from_raw(139 << 8);
    assert!(engines::exit_problem(through_shell).is_some_and(|p| p.contains("SIGSEGV")));
    assert_eq!(engines::exit_problem(ExitStatus::from_raw(0)), None);
}
