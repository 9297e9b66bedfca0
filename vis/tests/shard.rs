//! `vis --shard K/N` and `--merge` give the bytes of one whole run; bad sets of partials are
//! refused; a killed run resumed with `--resume` gives the bytes of an uninterrupted one.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use vis::Shard;
use vis::cli::{Args, run};
use vis::shards::partial_path;
use vis::synthetic::VoxelWorld;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("slipgate-shard-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Write `world`'s BSP and portal file as `dir/name.bsp` and `dir/name.prt`.
fn write_map(dir: &Path, name: &str, world: &VoxelWorld) -> PathBuf {
    let bsp = dir.join(format!("{name}.bsp"));
    std::fs::write(&bsp, world.bsp().write().expect("bsp")).expect("write bsp");
    std::fs::write(bsp.with_extension("prt"), world.portal_file().write()).expect("write prt");
    bsp
}

fn args(bsp: &Path) -> Args {
    Args {
        bsp: bsp.to_path_buf(),
        fast: false,
        level: 4,
        prt: None,
        threads: Some(2),
        sample_pairs: 0,
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
        ericw_only: vis::cli::EricwOnly::default(),
    }
}

fn shard_args(bsp: &Path, index: usize, count: usize) -> Args {
    Args {
        shard: Some(Shard { index, count }),
        ..args(bsp)
    }
}

fn merge_args(bsp: &Path, partials: Vec<PathBuf>) -> Args {
    Args {
        merge: true,
        partial: partials,
        ..args(bsp)
    }
}

/// The BSP bytes of one whole run on a fresh copy of the unvised `bsp`.
fn whole_run(bsp: &Path) -> Vec<u8> {
    let copy = bsp.with_file_name("whole.bsp");
    std::fs::copy(bsp, &copy).expect("copy");
    std::fs::copy(bsp.with_extension("prt"), copy.with_extension("prt")).expect("copy prt");
    run(&args(&copy)).expect("whole vis");
    std::fs::read(&copy).expect("read")
}

/// Run every shard of `count` on `bsp`, then merge; the merged BSP's bytes.
fn sharded_run(bsp: &Path, count: usize) -> Vec<u8> {
    for index in 0..count {
        run(&shard_args(bsp, index, count)).expect("shard");
    }
    run(&merge_args(bsp, Vec::new())).expect("merge");
    let bytes = std::fs::read(bsp).expect("read");
    for index in 0..count {
        std::fs::remove_file(partial_path(bsp, Shard { index, count })).expect("partial");
    }
    bytes
}

#[test]
fn shards_merged_give_the_bytes_of_one_run() {
    let dir = temp_dir("bytes");
    let world = VoxelWorld::random_caves([12, 12, 3], 200, 21);
    let bsp = write_map(&dir, "caves", &world);
    let unvised = std::fs::read(&bsp).expect("read");
    let whole = whole_run(&bsp);
    for count in [1, 2, 5, 17] {
        std::fs::write(&bsp, &unvised).expect("reset");
        assert!(sharded_run(&bsp, count) == whole, "{count} shards");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn more_shards_than_portals_still_merge_to_the_same_bytes() {
    let dir = temp_dir("tiny");
    let mut world = VoxelWorld::new([3, 1, 1], 64.0);
    world.open_box([0, 0, 0], [2, 0, 0]);
    let bsp = write_map(&dir, "tiny", &world);
    let portals = world.portal_file().portals.len();
    let whole = whole_run(&bsp);
    assert!(sharded_run(&bsp, 2 * portals + 3) == whole);
    std::fs::remove_dir_all(&dir).ok();
}

fn error_of(args: &Args) -> String {
    format!("{:#}", run(args).expect_err("refused"))
}

#[test]
fn missing_duplicated_mixed_and_foreign_partials_are_refused() {
    let dir = temp_dir("refused");
    let bsp = write_map(&dir, "caves", &VoxelWorld::random_caves([8, 8, 2], 60, 4));
    let other = write_map(&dir, "other", &VoxelWorld::random_caves([8, 8, 2], 60, 5));
    let unvised = std::fs::read(&bsp).expect("read");
    let part = |index, count| partial_path(&bsp, Shard { index, count });
    run(&shard_args(&bsp, 0, 3)).expect("shard 1/3");
    run(&shard_args(&bsp, 2, 3)).expect("shard 3/3");

    let err = error_of(&merge_args(&bsp, Vec::new()));
    assert!(err.contains("missing the partial of shard 2/3"), "{err}");

    let copy = dir.join("copy-of-1");
    std::fs::copy(part(0, 3), &copy).expect("copy");
    let err = error_of(&merge_args(&bsp, vec![part(0, 3), copy, part(2, 3)]));
    assert!(err.contains("shard 1/3 given twice"), "{err}");

    run(&shard_args(&bsp, 1, 2)).expect("shard 2/2");
    let err = error_of(&merge_args(&bsp, vec![part(0, 3), part(1, 2)]));
    assert!(err.contains("different shard counts"), "{err}");

    run(&shard_args(&other, 1, 3)).expect("other map's shard");
    let foreign = partial_path(&other, Shard { index: 1, count: 3 });
    let err = error_of(&merge_args(&bsp, vec![part(0, 3), foreign, part(2, 3)]));
    assert!(err.contains("other inputs"), "{err}");

    // Another level is another input.
    run(&shard_args(&bsp, 1, 3)).expect("shard 2/3");
    let err = error_of(&Args {
        level: 2,
        ..merge_args(&bsp, vec![part(0, 3), part(1, 3), part(2, 3)])
    });
    assert!(err.contains("other inputs"), "{err}");

    let err = error_of(&merge_args(&bsp, vec![bsp.clone()]));
    assert!(err.contains("not a Slipgate vis flow file"), "{err}");
    assert_eq!(
        std::fs::read(&bsp).expect("read"),
        unvised,
        "refusals write nothing"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_command_exits_1_naming_a_missing_shard() {
    let dir = temp_dir("exit");
    let bsp = write_map(&dir, "caves", &VoxelWorld::random_caves([8, 8, 2], 60, 4));
    let vis = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_slipgate-vis"))
            .args(extra)
            .arg(&bsp)
            .output()
            .expect("run slipgate-vis")
    };
    assert!(vis(&["--shard", "2/2"]).status.success());
    let out = vis(&["--merge"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("missing the partial of shard 1/2"),
        "{stderr}"
    );
    let out = vis(&["--shard", "3/2"]);
    assert!(!out.status.success());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_state_of_other_inputs_is_refused() {
    let dir = temp_dir("state");
    let bsp = write_map(&dir, "caves", &VoxelWorld::random_caves([8, 8, 2], 60, 4));
    let other = write_map(&dir, "other", &VoxelWorld::random_caves([8, 8, 2], 60, 5));
    // A state saved by a run on the other map, put where this map's run looks for one.
    let partial = dir.join("other.vis.1-of-1");
    run(&Args {
        partial: vec![partial.clone()],
        ..shard_args(&other, 0, 1)
    })
    .expect("shard");
    let state = vis::saved::SavedFlows::read(
        &std::fs::read(&partial).expect("read"),
        vis::saved::SavedKind::Partial,
    )
    .expect("partial");
    let state = vis::saved::SavedFlows {
        kind: vis::saved::SavedKind::State,
        ..state
    };
    std::fs::write(dir.join("caves.vis.state"), state.write()).expect("state");
    let err = error_of(&Args {
        resume: true,
        ..args(&bsp)
    });
    assert!(err.contains("saved from other inputs"), "{err}");
    std::fs::write(dir.join("caves.vis.state"), b"garbage").expect("state");
    let err = error_of(&Args {
        resume: true,
        ..args(&bsp)
    });
    assert!(err.contains("cannot resume from it"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Start `slipgate-vis` on `bsp`, SIGKILL it once it has saved its state, and return whether
/// it was killed (false: it finished first).
fn kill_after_first_save(bsp: &Path, extra: &[&str], state: &Path) -> bool {
    let mut child = Command::new(env!("CARGO_BIN_EXE_slipgate-vis"))
        .args(["--threads", "1", "--save-interval", "0.2"])
        .args(extra)
        .arg(bsp)
        .stderr(Stdio::null())
        .spawn()
        .expect("start slipgate-vis");
    let start = Instant::now();
    while !state.exists() {
        if child.try_wait().expect("wait").is_some() {
            return false;
        }
        assert!(start.elapsed() < Duration::from_secs(600), "no state saved");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().expect("SIGKILL");
    child.wait().expect("reap");
    true
}

#[test]
fn a_killed_run_resumed_gives_the_bytes_of_an_uninterrupted_one() {
    let dir = temp_dir("resume");
    let world = VoxelWorld::random_caves([18, 18, 4], 700, 8);
    let bsp = write_map(&dir, "caves", &world);
    let whole = whole_run(&bsp);
    let state = dir.join("caves.vis.state");
    if !kill_after_first_save(&bsp, &[], &state) {
        println!("SKIPPED: vis finished before its first state save; nothing to resume");
        std::fs::remove_dir_all(&dir).ok();
        return;
    }
    let status = Command::new(env!("CARGO_BIN_EXE_slipgate-vis"))
        .args(["--resume", "--threads", "2"])
        .arg(&bsp)
        .status()
        .expect("resume");
    assert!(status.success());
    assert!(
        std::fs::read(&bsp).expect("read") == whole,
        "resumed bytes differ"
    );
    assert!(!state.exists(), "a finished run removes its state");

    // A shard resumes the same way, into the same partial.
    let unvised = world.bsp().write().expect("bsp");
    std::fs::write(&bsp, &unvised).expect("reset");
    let shard_state = dir.join("caves.vis.1-of-2.state");
    if kill_after_first_save(&bsp, &["--shard", "1/2"], &shard_state) {
        let resumed = Command::new(env!("CARGO_BIN_EXE_slipgate-vis"))
            .args(["--resume", "--shard", "1/2"])
            .arg(&bsp)
            .status()
            .expect("resume shard");
        assert!(resumed.success());
    }
    run(&shard_args(&bsp, 1, 2)).expect("shard 2/2");
    run(&merge_args(&bsp, Vec::new())).expect("merge");
    assert!(
        std::fs::read(&bsp).expect("read") == whole,
        "merged bytes differ"
    );
    std::fs::remove_dir_all(&dir).ok();
}
