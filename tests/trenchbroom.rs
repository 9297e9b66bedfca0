//! The TrenchBroom compile profiles in `docs/trenchbroom/` run as TrenchBroom runs them, on a
//! project laid out as a TrenchBroom user's is: a game folder with a mod, the map in a folder of
//! its own naming its WAD relative to the game folder, TrenchBroom's keys, and a layer marked
//! Omit From Export. Every task of every profile runs with its variables filled in (the tool
//! variables `${qbsp}`, `${vis}` and `${light}` are `slipgate bsp`, `vis` and `light`); the
//! files must come out where the profile says, with the right textures, no editor keys and
//! nothing of the omitted layer, and QuakeSpasm must load and run the map.
#![cfg(unix)]

// Each test binary uses its own part of the shared support.
#[allow(dead_code)]
#[path = "support/command.rs"]
mod command;
#[allow(dead_code)]
#[path = "support/engines.rs"]
mod engines;
#[allow(dead_code)]
#[path = "support/maps.rs"]
mod maps;

use engines::{Engine, Kind};
use quake_formats::Bsp;
use quake_formats::entities::parse_entities;
use serde_json::Value;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// How the layer marked Omit From Export, last in the saved map, begins.
const OMITTED_LAYER_START: &str = "{\n\"classname\" \"func_group\"\n\"_tb_type\" \"_tb_layer\"";

/// A game folder (`game/`, with the mod `mymod`) and a map folder (`src/`) beside it.
struct Project {
    game: PathBuf,
    map: PathBuf,
}

impl Project {
    fn new(root: &Path) -> Project {
        let _ = std::fs::remove_dir_all(root);
        let game = root.join("game");
        let wad = game.join("id1/gfx/slipgate.wad");
        std::fs::create_dir_all(wad.parent().expect("gfx")).expect("game folder");
        std::fs::create_dir_all(game.join("mymod/maps")).expect("mod folder");
        std::fs::copy(repo().join("maps/slipgate.wad"), &wad).expect("WAD");
        let src = root.join("src");
        std::fs::create_dir_all(&src).expect("map folder");
        // The demo map as TrenchBroom saves it: the WAD named relative to the game folder, its
        // own keys, and a layer (with a wall and a light in it) marked Omit From Export.
        let demo = std::fs::read_to_string(repo().join("maps/demo.map")).expect("demo.map");
        let layer = "{\n\"classname\" \"func_group\"\n\"_tb_type\" \"_tb_layer\"\n\
            \"_tb_name\" \"Reference\"\n\"_tb_id\" \"9\"\n\"_tb_layer_omit_from_export\" \"1\"\n}\n\
            {\n\"classname\" \"light\"\n\"origin\" \"64 64 64\"\n\"_tb_layer\" \"9\"\n}\n\
            {\n\"classname\" \"func_wall\"\n\"_tb_layer\" \"9\"\n{\n\
            ( 0 0 0 ) ( 0 1 0 ) ( 0 0 1 ) brick1 0 0 0 1 1\n\
            ( 8 0 0 ) ( 8 0 1 ) ( 8 1 0 ) brick1 0 0 0 1 1\n\
            ( 0 0 0 ) ( 0 0 1 ) ( 1 0 0 ) brick1 0 0 0 1 1\n\
            ( 0 8 0 ) ( 1 8 0 ) ( 0 8 1 ) brick1 0 0 0 1 1\n\
            ( 0 0 0 ) ( 1 0 0 ) ( 0 1 0 ) brick1 0 0 0 1 1\n\
            ( 0 0 8 ) ( 0 1 8 ) ( 1 0 8 ) brick1 0 0 0 1 1\n}\n}\n";
        let text = demo.replacen(
            "\"wad\" \"slipgate.wad\"\n",
            "\"wad\" \"id1/gfx/slipgate.wad\"\n\"_tb_textures\" \"textures\"\n\"_tb_mod\" \"mymod\"\n",
            1,
        ) + layer;
        let map = src.join("demo.map");
        std::fs::write(&map, text).expect("map");
        Project { game, map }
    }

    /// TrenchBroom's variables for this project.
    fn variables(&self) -> HashMap<&'static str, String> {
        let dir = self.map.parent().expect("map folder").display().to_string();
        HashMap::from([
            ("${MAP_DIR_PATH}", dir.clone()),
            ("${WORK_DIR_PATH}", dir),
            ("${MAP_BASE_NAME}", "demo".to_string()),
            ("${MAP_FULL_NAME}", "demo.map".to_string()),
            ("${GAME_DIR_PATH}", self.game.display().to_string()),
            ("${MODS[-1]}", "mymod".to_string()),
        ])
    }
}

fn fill(text: &str, vars: &HashMap<&'static str, String>) -> String {
    let mut out = text.to_string();
    for (k, v) in vars {
        out = out.replace(k, v);
    }
    assert!(!out.contains("${"), "unknown variable in {text}");
    out
}

/// The words of a task's parameters, split as TrenchBroom does (double quotes group words).
fn words(parameters: &str) -> Vec<String> {
    parameters
        .split('"')
        .enumerate()
        .flat_map(|(i, part)| {
            if i % 2 == 1 {
                vec![part.to_string()]
            } else {
                part.split_whitespace().map(str::to_string).collect()
            }
        })
        .collect()
}

/// Run one task of a profile in `workdir`, as TrenchBroom would.
fn run_task(task: &Value, workdir: &Path, vars: &HashMap<&'static str, String>) {
    let field = |name: &str| fill(task[name].as_str().expect(name), vars);
    match task["type"].as_str().expect("type") {
        // TrenchBroom writes the map as it exports it: without the layer marked Omit From
        // Export (the compiler would compile it, as ericw-tools does), which `Project::new`
        // put last.
        "export" => {
            let target = PathBuf::from(field("target"));
            let saved = std::fs::read_to_string(workdir.join("demo.map")).expect("saved map");
            let layer = saved.find(OMITTED_LAYER_START).expect("the omitted layer");
            std::fs::write(&target, &saved[..layer]).expect("export");
        }
        "tool" => {
            let stage = match task["tool"].as_str().expect("tool") {
                "${qbsp}" => "bsp",
                "${vis}" => "vis",
                "${light}" => "light",
                other => panic!("a tool that is not one of TrenchBroom's variables: {other}"),
            };
            assert_eq!(task["treatNonZeroResultCodeAsError"], true);
            let args = words(&field("parameters"));
            let out = Command::new(env!("CARGO_BIN_EXE_slipgate"))
                .arg(stage)
                .args(&args)
                .current_dir(workdir)
                .output()
                .expect("run slipgate");
            assert!(
                out.status.success(),
                "{stage} {args:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        // A copy of a file the compile did not write (a .lit for white light) does nothing.
        "copy" => {
            let source = PathBuf::from(field("source"));
            let target = PathBuf::from(field("target"));
            if source.exists() {
                let name = source.file_name().expect("file name");
                std::fs::copy(&source, target.join(name)).expect("copy");
            }
        }
        other => panic!("unexpected task type {other}"),
    }
}

fn profiles() -> Vec<Value> {
    let text = std::fs::read_to_string(repo().join("docs/trenchbroom/CompilationProfiles.cfg"))
        .expect("profiles");
    let json: Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(json["version"], 1);
    json["profiles"].as_array().expect("profiles").clone()
}

/// The profiles run one after another on one project, as a mapper runs them (entities only
/// needs the BSP an earlier profile compiled).
#[test]
fn every_profile_compiles_a_trenchbroom_project_into_its_mod() {
    let project = Project::new(&command::scratch("trenchbroom", "project"));
    let vars = project.variables();
    for profile in profiles() {
        let name = profile["name"].as_str().expect("name").to_string();
        let workdir = PathBuf::from(fill(profile["workdir"].as_str().expect("workdir"), &vars));
        let tasks = profile["tasks"].as_array().expect("tasks");
        assert_eq!(tasks[0]["type"], "export", "{name}: export first");
        let bsp_path = project.game.join("mymod/maps/demo.bsp");
        let _ = std::fs::remove_file(&bsp_path);
        for task in tasks {
            run_task(task, &workdir, &vars);
        }
        if name.contains("leak test") {
            continue;
        }
        let bsp = Bsp::read(&std::fs::read(&bsp_path).expect("the BSP in the mod")).expect("BSP");
        check_bsp(&name, &bsp);
        assert!(
            workdir.join("demo.prt").exists(),
            "{name}: no .prt for Load Portal File"
        );
        play(&name, &project.game.join("mymod/maps"), &bsp_path);
    }
}

/// The textures the WAD holds, with pixels; no editor keys; nothing of the omitted layer.
fn check_bsp(profile: &str, bsp: &Bsp) {
    let brick = bsp
        .textures
        .textures
        .iter()
        .flatten()
        .find(|t| t.name() == "brick1")
        .expect("brick1");
    assert!(brick.mips.is_some(), "{profile}: brick1 has no pixels");
    let entities = parse_entities(&bsp.entity_text()).expect("entities");
    for e in &entities {
        assert!(
            e.pairs.iter().all(|(k, _)| !k.starts_with("_tb_")),
            "{profile}: editor keys in {e:?}"
        );
        assert_ne!(
            e.get("origin"),
            Some("64 64 64"),
            "{profile}: the omitted light"
        );
    }
    assert!(
        !entities.iter().any(|e| e.classname() == "func_wall"),
        "{profile}: the omitted func_wall"
    );
}

/// QuakeSpasm's dedicated server loads the map from the mod and runs it.
fn play(profile: &str, maps_dir: &Path, bsp: &Path) {
    let Some(engine) = Engine::find(Kind::QuakeSpasm, maps_dir) else {
        return;
    };
    if !engine.has_server() {
        return;
    }
    let compiled = maps::Compiled {
        name: "demo".to_string(),
        bsp: bsp.to_path_buf(),
        lit: Some(bsp.with_extension("lit")).filter(|p| p.exists()),
        start: None,
        vis: "full",
        seconds: 0.0,
        empty_view: None,
        known_error: None,
    };
    if let Err(e) = engine.serve(&compiled) {
        panic!("{profile}: QuakeSpasm: {e}");
    }
}
