//! The TrenchBroom compile profiles in `docs/trenchbroom/` are TrenchBroom's format (version 1)
//! and run stage commands whose arguments the stages accept.

mod common;

use clap::Parser;
use common::{BspCli, LightCli, VisCli};
use serde_json::Value;
use std::path::Path;

/// The parameters with TrenchBroom's variables filled in, split as a shell would (quotes
/// group words).
fn words(parameters: &str) -> Vec<String> {
    let filled = parameters
        .replace("${MAP_DIR_PATH}", "/maps")
        .replace("${MAP_FULL_NAME}", "start.map")
        .replace("${MAP_BASE_NAME}", "start");
    assert!(!filled.contains("${"), "unknown variable in {parameters}");
    filled
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

#[test]
fn compile_profiles_run_commands_the_stages_accept() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/trenchbroom/CompilationProfiles.cfg");
    let text = std::fs::read_to_string(&path).expect("profiles");
    let json: Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(json["version"], 1);
    let profiles = json["profiles"].as_array().expect("profiles");
    assert!(profiles.len() >= 4);
    let mut stages_seen = Vec::new();
    for profile in profiles {
        assert!(profile["name"].is_string() && profile["workdir"].is_string());
        for task in profile["tasks"].as_array().expect("tasks") {
            match task["type"].as_str().expect("type") {
                "copy" => assert!(task["source"].is_string() && task["target"].is_string()),
                "tool" => {
                    assert_eq!(task["tool"], "slipgate");
                    assert_eq!(task["treatNonZeroResultCodeAsError"], true);
                    let argv = words(task["parameters"].as_str().expect("parameters"));
                    let stage = argv[0].clone();
                    let parsed = match stage.as_str() {
                        "bsp" => BspCli::try_parse_from(&argv).map(|_| ()),
                        "vis" => VisCli::try_parse_from(&argv).map(|_| ()),
                        "light" => LightCli::try_parse_from(&argv).map(|_| ()),
                        // `build` is the command's own (src/build.rs): its map comes last.
                        "build" => {
                            assert!(argv.last().is_some_and(|a| a.ends_with(".map")));
                            Ok(())
                        }
                        other => panic!("unknown stage {other}"),
                    };
                    parsed.unwrap_or_else(|e| panic!("{argv:?}: {e}"));
                    stages_seen.push(stage);
                }
                other => panic!("unexpected task type {other}"),
            }
        }
    }
    for stage in ["build", "bsp", "vis", "light"] {
        assert!(
            stages_seen.iter().any(|s| s == stage),
            "no profile runs {stage}"
        );
    }
}
