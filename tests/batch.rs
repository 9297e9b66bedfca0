//! End-to-end tests of `slipgate batch`: the cache, shards and `--collect`, a light change, a
//! failing map, and (ignored; release) a few corpus maps.

#[path = "support/command.rs"]
mod command;
#[path = "support/corpus.rs"]
mod support_corpus;

use command::slipgate;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use support_corpus::corpus;

const SMALL_MAPS: [&str; 4] = [
    "demo.map",
    "demo220.map",
    "test/corridors.map",
    "leak/sealed.map",
];

/// A project folder holding copies of `maps` (paths under the repository's `maps/`) and the
/// project's WAD, with a project file building them into `out/`.
fn project(test: &str, maps: &[&str]) -> PathBuf {
    let root = command::scratch("batch", test);
    let _ = std::fs::remove_dir_all(&root);
    let repo_maps = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps");
    for name in maps.iter().chain(&["slipgate.wad"]) {
        let to = root.join(name);
        std::fs::create_dir_all(to.parent().expect("parent")).expect("mkdir");
        std::fs::copy(repo_maps.join(name), &to).expect("copy map");
    }
    let list: Vec<String> = maps.iter().map(|m| format!("{m:?}")).collect();
    std::fs::write(
        root.join("project.toml"),
        format!(
            "maps = [{}]\noutput = \"out\"\n[defaults]\nbsp = \"-wad-dir .\"\npreview = \"--size 80x60\"\n",
            list.join(", ")
        ),
    )
    .expect("project file");
    root
}

fn batch(root: &Path, extra: &[&str]) -> Output {
    let file = root.join("project.toml");
    let mut args = vec!["batch", file.to_str().expect("utf8")];
    args.extend(extra);
    let out = slipgate(&args);
    eprintln!("{}", String::from_utf8_lossy(&out.stdout));
    out
}

fn manifest(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).expect("manifest")).expect("manifest JSON")
}

/// Map -> stage -> cached, from a manifest.
fn stages_cached(manifest: &Value) -> BTreeMap<String, BTreeMap<String, bool>> {
    let built = manifest["built"].as_array().expect("built");
    built
        .iter()
        .map(|m| {
            let stages = m["stages"].as_array().expect("stages");
            let cached = stages
                .iter()
                .map(|s| {
                    let stage = s["stage"].as_str().expect("stage").to_string();
                    (stage, s["cached"].as_bool().expect("cached"))
                })
                .collect();
            (m["map"].as_str().expect("map").to_string(), cached)
        })
        .collect()
}

/// Every file under `dir` but manifests, by relative path.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).expect("read dir") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                walk(root, &path, out);
            } else if !path.to_string_lossy().contains("slipgate-manifest") {
                let rel = path.strip_prefix(root).expect("under root").to_path_buf();
                out.insert(rel, std::fs::read(&path).expect("read"));
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

fn assert_success(out: &Output) {
    assert!(
        out.status.success(),
        "batch failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_second_run_rebuilds_nothing() {
    let root = project("twice", &SMALL_MAPS);
    assert_success(&batch(&root, &["--jobs", "2"]));
    let first = files(&root.join("out"));
    // bsp, prt and png for every map (the demo's coloured light adds a .lit).
    assert!(first.len() >= 3 * SMALL_MAPS.len(), "{:?}", first.keys());
    let ran = stages_cached(&manifest(&root.join("out/slipgate-manifest.json")));
    assert!(ran.values().flat_map(|s| s.values()).all(|cached| !cached));

    assert_success(&batch(&root, &[]));
    let again = stages_cached(&manifest(&root.join("out/slipgate-manifest.json")));
    assert_eq!(again.len(), SMALL_MAPS.len());
    for (map, stages) in &again {
        assert_eq!(stages.len(), 5, "{map}: {stages:?}");
        assert!(stages.values().all(|&cached| cached), "{map}: {stages:?}");
    }
    assert_eq!(
        files(&root.join("out")),
        first,
        "a cached run changes no output"
    );
}

#[test]
fn three_shards_give_the_bytes_of_one_run() {
    let root = project("shards", &SMALL_MAPS);
    assert_success(&batch(&root, &[]));
    let whole = files(&root.join("out"));

    // Three runners with caches of their own and different thread counts, side by side.
    let project_file = root.join("project.toml");
    let runners: Vec<_> = (1..=3)
        .map(|k| {
            Command::new(env!("CARGO_BIN_EXE_slipgate"))
                .args(["batch", project_file.to_str().expect("utf8")])
                .args(["--shard", &format!("{k}/3")])
                .arg("--output")
                .arg(root.join(format!("shard{k}")))
                .arg("--cache")
                .arg(root.join(format!("cache{k}")))
                .env("RAYON_NUM_THREADS", k.to_string())
                .spawn()
                .expect("start a shard")
        })
        .collect();
    for mut runner in runners {
        assert!(runner.wait().expect("shard").success());
    }
    let mut joined = BTreeMap::new();
    for k in 1..=3 {
        let shard = files(&root.join(format!("shard{k}")));
        assert!(!shard.is_empty(), "shard {k} built nothing");
        joined.extend(shard);
    }
    assert_eq!(
        joined, whole,
        "the shards' outputs are the single run's bytes"
    );

    let dir = |k: usize| {
        root.join(format!("shard{k}"))
            .to_string_lossy()
            .into_owned()
    };
    let (d1, d2, d3) = (dir(1), dir(2), dir(3));
    let collected = slipgate(&["batch", "--collect", &d1, &d2, &d3]);
    assert!(
        collected.status.success(),
        "{}",
        String::from_utf8_lossy(&collected.stderr)
    );

    let missing = slipgate(&["batch", "--collect", &d1, &d2]);
    assert_eq!(missing.status.code(), Some(1));
    let shard3 = manifest(&root.join("shard3/slipgate-manifest-3-of-3.json"));
    let lost = shard3["built"][0]["map"]
        .as_str()
        .expect("shard 3 built a map");
    let stderr = String::from_utf8_lossy(&missing.stderr);
    assert!(stderr.contains(&format!("{lost}: missing")), "{stderr}");

    let twice = slipgate(&["batch", "--collect", &d1, &d2, &d3, &d1]);
    assert_eq!(twice.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&twice.stderr).contains("built twice"));

    let bsp = root.join("shard1/demo.bsp");
    std::fs::write(&bsp, b"not the bsp the manifest names").expect("overwrite");
    let damaged = slipgate(&["batch", "--collect", &d1, &d2, &d3]);
    assert_eq!(damaged.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&damaged.stderr).contains("does not match its hash"));
}

#[test]
fn changed_light_keys_rerun_only_ents_and_light() {
    let root = project("light", &["demo.map", "demo220.map"]);
    assert_success(&batch(&root, &[]));
    let map = root.join("demo.map");
    let text = std::fs::read_to_string(&map).expect("map text");
    // A value of another length, so the entity lump changes size.
    let changed = text.replacen("\"light\" \"250\"", "\"light\" \"1250\"", 1);
    assert_ne!(changed, text, "the demo map has a light of 250");
    std::fs::write(&map, changed).expect("edit the map");

    assert_success(&batch(&root, &[]));
    assert_only_light_reran(&root);

    // Light's keys of worldspawn (a sun) are the same kind of change.
    let text = std::fs::read_to_string(&map).expect("map text");
    let sunny = text.replacen(
        "\"classname\" \"worldspawn\"",
        "\"classname\" \"worldspawn\"\n\"_sunlight\" \"150\"\n\"_sun_mangle\" \"30 -60 0\"",
        1,
    );
    assert_ne!(sunny, text, "the demo map's worldspawn");
    std::fs::write(&map, sunny).expect("edit the map");
    assert_success(&batch(&root, &[]));
    assert_only_light_reran(&root);

    // The same bytes as a build from nothing.
    let fresh = root.join("fresh");
    let (out, cache) = (fresh.join("out"), fresh.join("cache"));
    let rebuilt = batch(
        &root,
        &[
            "--output",
            out.to_str().expect("utf8"),
            "--cache",
            cache.to_str().expect("utf8"),
        ],
    );
    assert_success(&rebuilt);
    assert_eq!(files(&out), files(&root.join("out")));
}

/// The demo map's bsp and vis came from the cache, its ents, light and preview ran; the other
/// map was all cached.
fn assert_only_light_reran(root: &Path) {
    let stages = stages_cached(&manifest(&root.join("out/slipgate-manifest.json")));
    let expected: BTreeMap<String, bool> = [
        ("bsp", true),
        ("vis", true),
        ("ents", false),
        ("light", false),
        ("preview", false),
    ]
    .into_iter()
    .map(|(s, c)| (s.to_string(), c))
    .collect();
    assert_eq!(stages["demo.map"], expected);
    assert!(stages["demo220.map"].values().all(|&cached| cached));
}

#[test]
fn a_failing_map_fails_the_batch_and_the_others_finish() {
    let root = project("leak", &["leak/leak.map", "leak/sealed.map", "demo220.map"]);
    let out = batch(&root, &[]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("leak/leak.map failed at bsp"), "{stderr}");
    assert!(!stderr.contains("sealed.map failed"), "{stderr}");
    for built in ["leak/sealed.bsp", "demo220.bsp", "leak/leak.pts"] {
        assert!(root.join("out").join(built).is_file(), "{built}");
    }
    assert!(!root.join("out/leak/leak.bsp").exists());
}

/// A few real maps, twice: the second run takes every stage from the cache.
#[test]
#[ignore = "corpus maps: minutes in a debug build; run with --release -- --ignored"]
fn corpus_maps_build_and_then_come_from_the_cache() {
    let (Some(maps), Some(wads)) = (corpus("public/maps/librequake"), corpus("wads/librequake"))
    else {
        return;
    };
    let root = command::scratch("batch", "corpus");
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&root).expect("mkdir");
    let names = ["start.map", "e1m3.map"];
    for name in names {
        std::fs::copy(maps.join(name), root.join(name)).expect("copy corpus map");
    }
    std::fs::write(
        root.join("project.toml"),
        format!(
            "maps = [\"*.map\"]\noutput = \"out\"\n[defaults]\nbsp = \"-wad-dir {}\"\n",
            wads.display()
        ),
    )
    .expect("project file");
    let timed = |extra: &[&str]| {
        let start = std::time::Instant::now();
        let out = batch(&root, extra);
        assert_success(&out);
        start.elapsed().as_secs_f64()
    };
    let first = timed(&[]);
    let second = timed(&[]);
    eprintln!(
        "corpus batch ({}): first {first:.1} s, cached {second:.1} s",
        names.join(", ")
    );
    let stages = stages_cached(&manifest(&root.join("out/slipgate-manifest.json")));
    assert_eq!(stages.len(), names.len());
    assert!(
        stages
            .values()
            .flat_map(|s| s.values())
            .all(|&cached| cached)
    );
    assert!(
        second < first / 5.0,
        "cached {second:.1} s vs first {first:.1} s"
    );
}

/// A batch stopped while lighting a map left the records of the stages before light: the next
/// run starts at light. (Records are written atomically as stages finish, so removing the last
/// ones is what a kill at that moment leaves.)
#[test]
fn an_interrupted_batch_resumes_after_the_last_finished_stage() {
    let root = project("resume", &["demo220.map", "test/corridors.map"]);
    assert_success(&batch(&root, &[]));
    let whole = files(&root.join("out"));
    let first = manifest(&root.join("out/slipgate-manifest.json"));
    let corridors = first["built"]
        .as_array()
        .expect("built")
        .iter()
        .find(|m| m["map"] == "test/corridors.map")
        .expect("corridors built");
    for stage in corridors["stages"].as_array().expect("stages") {
        if stage["stage"] == "light" || stage["stage"] == "preview" {
            let key = stage["key"].as_str().expect("key");
            let record = root.join(format!(".slipgate-cache/stages/{key}.json"));
            std::fs::remove_file(record).expect("remove a record");
        }
    }
    std::fs::remove_dir_all(root.join("out")).expect("remove outputs");

    assert_success(&batch(&root, &[]));
    let stages = stages_cached(&manifest(&root.join("out/slipgate-manifest.json")));
    let ran: Vec<&String> = stages["test/corridors.map"]
        .iter()
        .filter(|(_, cached)| !**cached)
        .map(|(stage, _)| stage)
        .collect();
    assert_eq!(ran, ["light", "preview"]);
    assert!(stages["demo220.map"].values().all(|&cached| cached));
    assert_eq!(files(&root.join("out")), whole);
}
