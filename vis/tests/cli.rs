//! The command line on a synthetic map written to a temporary directory.

use quake_formats::Bsp;
use std::path::PathBuf;
use vis::cli::{Args, EricwOnly, run};
use vis::synthetic::VoxelWorld;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("slipgate-vis-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn args(bsp: PathBuf) -> Args {
    Args {
        bsp,
        fast: false,
        level: 4,
        prt: None,
        threads: Some(1),
        sample_pairs: 1000,
        stats: None,
        shard: None,
        partial: Vec::new(),
        merge: false,
        resume: false,
        save_interval: 0.0,
        noambient: false,
        noambientsky: false,
        noambientwater: false,
        noambientslime: false,
        noambientlava: false,
        ericw_only: EricwOnly::default(),
    }
}

#[derive(clap::Parser)]
struct VisCli {
    #[command(flatten)]
    args: Args,
}

/// A profile written for ericw-tools' vis runs unchanged: its options that only change how vis
/// reports, or that Slipgate's vis has no need of, are accepted, each with a note.
#[test]
fn ericw_tools_only_options_are_accepted_with_a_note() {
    use clap::Parser;
    let words = [
        "vis",
        "-nopercent",
        "-visdist",
        "2000",
        "-level",
        "2",
        "-path",
        "a",
        "-path",
        "b",
        "-nodefaultpaths",
        "x.bsp",
    ];
    let words = quake_formats::cli::normalise_single_dash(words.iter().map(|s| s.to_string()));
    let cli = VisCli::try_parse_from(words).expect("parses");
    let notes = cli.args.ericw_only.notes();
    assert_eq!(notes.len(), 4, "{notes:?}");
    assert!(notes[1].starts_with("-visdist has no effect"), "{notes:?}");
    assert_eq!(cli.args.level, 2);
}

#[test]
fn vis_writes_the_pvs_into_the_bsp_and_stats_json() {
    let dir = temp_dir("ok");
    let world = VoxelWorld::random_caves([8, 8, 2], 50, 2);
    let bsp_path = dir.join("map.bsp");
    std::fs::write(&bsp_path, world.bsp().write().expect("bsp")).expect("write bsp");
    std::fs::write(dir.join("map.prt"), world.portal_file().write()).expect("write prt");
    let mut a = args(bsp_path.clone());
    a.stats = Some(dir.join("stats.json"));
    run(&a).expect("vis");
    let bsp = Bsp::read(&std::fs::read(&bsp_path).expect("read")).expect("parse");
    assert!(!bsp.visibility.is_empty());
    assert_eq!(bsp.leafs[0].vis_offset, -1);
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("stats.json")).expect("stats"))
            .expect("json");
    assert_eq!(stats["sampling"]["violations"], 0);
    assert_eq!(stats["compute"]["leafs"], 50);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn vis_reads_a_prt2_file_with_clusters() {
    let dir = temp_dir("prt2");
    let world = VoxelWorld::random_caves([8, 8, 2], 50, 2);
    let bsp_path = dir.join("map.bsp");
    std::fs::write(&bsp_path, world.bsp().write().expect("bsp")).expect("write bsp");
    let prt = world.paired_portal_file();
    assert!(prt.write().starts_with("PRT2"));
    std::fs::write(dir.join("map.prt"), prt.write()).expect("write prt");
    let mut a = args(bsp_path.clone());
    a.stats = Some(dir.join("stats.json"));
    run(&a).expect("vis");
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("stats.json")).expect("stats"))
            .expect("json");
    assert_eq!(stats["sampling"]["violations"], 0);
    assert_eq!(stats["compute"]["leafs"], 50);
    assert_eq!(
        stats["compute"]["clusters"],
        prt.clusters.expect("PRT2").len()
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_mismatched_portal_file_is_refused_naming_both_files() {
    let dir = temp_dir("mismatch");
    let world = VoxelWorld::random_caves([8, 8, 2], 50, 2);
    let other = VoxelWorld::random_caves([8, 8, 2], 40, 3);
    let bsp_path = dir.join("map.bsp");
    let original = world.bsp().write().expect("bsp");
    std::fs::write(&bsp_path, &original).expect("write bsp");
    std::fs::write(dir.join("map.prt"), other.portal_file().write()).expect("write prt");
    let err = run(&args(bsp_path.clone())).expect_err("40 leaves against 50");
    let text = format!("{err:#}");
    assert!(
        text.contains("map.prt") && text.contains("map.bsp"),
        "{text}"
    );
    assert!(
        text.contains("40 leaves") && text.contains("50 vis"),
        "{text}"
    );
    assert_eq!(
        std::fs::read(&bsp_path).expect("read"),
        original,
        "BSP left untouched"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_missing_portal_file_says_what_is_needed() {
    let dir = temp_dir("missing");
    let bsp_path = dir.join("map.bsp");
    std::fs::write(
        &bsp_path,
        VoxelWorld::random_caves([4, 4, 1], 5, 1)
            .bsp()
            .write()
            .expect("bsp"),
    )
    .expect("write");
    let text = format!("{:#}", run(&args(bsp_path)).expect_err("no prt"));
    assert!(
        text.contains("map.prt") && text.contains("portal file"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
