//! Hostile input through every stage: compiled project maps with bytes flipped (deterministic
//! seeds) go through vis, light, view and convert. Each run ends in a clear error naming the file
//! (exit 1, the input left as it was) or a usable output, within a time and memory bound: never a
//! panic, a hang or an allocation sized by a damaged count.

#[path = "support/command.rs"]
mod command;

use quake_formats::Bsp;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Longer than any stage takes on these small maps in a debug build on a loaded machine, far
/// shorter than the minutes a damaged count used to cost.
const STAGE_TIMEOUT: Duration = Duration::from_secs(20);
/// Address space per run, in KiB (`ulimit -v`): a damaged count that sizes an allocation fails.
const ADDRESS_SPACE_KIB: u64 = 2 << 20;

fn scratch(name: &str) -> PathBuf {
    command::scratch("hostile", name)
}

fn project_map(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("maps")
        .join(relative)
}

/// How one bounded run of `slipgate` ended.
struct Run {
    /// `None` when a signal ended it (a panic aborts, an allocation failure aborts, a stack
    /// overflow segfaults) or the timeout killed it.
    code: Option<i32>,
    stderr: String,
    seconds: f64,
}

/// Runs `slipgate args` under [`ADDRESS_SPACE_KIB`], killing it after [`STAGE_TIMEOUT`].
fn run_bounded(args: &[&str]) -> Run {
    let start = Instant::now();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {ADDRESS_SPACE_KIB}; exec \"$@\""))
        .arg("sh")
        .arg(env!("CARGO_BIN_EXE_slipgate"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run slipgate");
    let stderr = child.stderr.take().expect("stderr");
    let reader = std::thread::spawn(move || std::io::read_to_string(stderr).unwrap_or_default());
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break Some(status);
        }
        if start.elapsed() > STAGE_TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Run {
        code: status.and_then(|s| s.code()),
        stderr: reader.join().unwrap_or_default(),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Compiles, vises and lights a project map into the scratch directory as `NAME.bsp`.
fn compile(map: &str, name: &str) -> PathBuf {
    let bsp = scratch(&format!("{name}.bsp"));
    let wad_dir = project_map("");
    let wad_dir = wad_dir.to_str().expect("utf8");
    let map = project_map(map);
    let b = bsp.to_str().expect("utf8");
    for args in [
        vec!["bsp", map.to_str().expect("utf8"), b, "--wad-dir", wad_dir],
        vec!["vis", b],
        vec!["light", b],
    ] {
        let out = command::slipgate(&args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    bsp
}

/// SplitMix64: deterministic flips from a seed, without a dependency.
struct Flips(u64);

impl Flips {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// `bytes` with 1 to 8 bytes replaced, chosen by `seed`; the header is spared half the time so
/// most flips reach the lumps instead of failing the read.
fn flipped(bytes: &[u8], seed: u64) -> Vec<u8> {
    let mut flips = Flips(seed);
    let mut out = bytes.to_vec();
    let skip = if seed.is_multiple_of(2) { 124 } else { 0 };
    for _ in 0..1 + flips.below(8) {
        let at = skip + flips.below(out.len() - skip);
        out[at] = flips.next() as u8;
    }
    out
}

/// One stage on one damaged file: how it ended, and whether that is acceptable.
fn check_stage(stage: &str, args: &[&str], input: &Path, before: &[u8], seed: u64) {
    let run = run_bounded(args);
    let what = format!("seed {seed}, {stage}");
    assert!(
        run.seconds < STAGE_TIMEOUT.as_secs_f64(),
        "{what}: still running after {:.0} s",
        run.seconds
    );
    match run.code {
        Some(0) => {}
        Some(1) => {
            let name = input.file_name().and_then(|n| n.to_str()).expect("name");
            assert!(
                run.stderr.contains(name),
                "{what}: error without the file name: {}",
                run.stderr
            );
            let after = std::fs::read(input).expect("read back");
            assert!(
                after == before,
                "{what}: failed but rewrote {}",
                input.display()
            );
        }
        code => panic!("{what}: ended with {code:?} (a signal): {}", run.stderr),
    }
}

#[test]
fn byte_flipped_bsps_end_in_an_error_or_a_usable_output_in_every_stage() {
    let good = std::fs::read(compile("test/corridors.map", "corridors")).expect("read");
    let prt = std::fs::read(scratch("corridors.prt")).expect("read prt");
    let input = scratch("flipped.bsp");
    let i = input.to_str().expect("utf8");
    let png = scratch("flipped.png");
    let converted = scratch("converted.bsp");
    let mut refused = 0;
    const SEEDS: u64 = 200;
    for seed in 0..SEEDS {
        let damaged = flipped(&good, seed);
        let stages: [(&str, Vec<&str>); 4] = [
            ("vis", vec!["vis", i]),
            ("light", vec!["light", i]),
            (
                "view",
                vec![
                    "view",
                    i,
                    "--size",
                    "64x48",
                    "--out",
                    png.to_str().expect("utf8"),
                ],
            ),
            (
                "convert",
                vec!["convert", i, converted.to_str().expect("utf8")],
            ),
        ];
        for (stage, args) in stages {
            std::fs::write(&input, &damaged).expect("write");
            std::fs::write(input.with_extension("prt"), &prt).expect("write prt");
            check_stage(stage, &args, &input, &damaged, seed);
        }
        let usable = Bsp::read(&damaged)
            .ok()
            .is_some_and(|bsp| quake_formats::check_usable(&bsp).is_ok());
        refused += usize::from(!usable);
    }
    // The flips must reach the gate often, or this test proves little.
    assert!(
        refused > SEEDS as usize / 4,
        "only {refused} of {SEEDS} refused"
    );
}

/// Each stage's outputs after a complete run, to compare what a killed run leaves with.
struct Outputs {
    bsp: Vec<u8>,
    prt: Vec<u8>,
    lit: Option<Vec<u8>>,
}

fn outputs(bsp: &Path) -> Outputs {
    Outputs {
        bsp: std::fs::read(bsp).expect("read bsp"),
        prt: std::fs::read(bsp.with_extension("prt")).expect("read prt"),
        lit: std::fs::read(bsp.with_extension("lit")).ok(),
    }
}

fn restore(bsp: &Path, outputs: &Outputs) {
    std::fs::write(bsp, &outputs.bsp).expect("write bsp");
    std::fs::write(bsp.with_extension("prt"), &outputs.prt).expect("write prt");
    let lit = bsp.with_extension("lit");
    match &outputs.lit {
        Some(bytes) => std::fs::write(&lit, bytes).expect("write lit"),
        None => {
            let _ = std::fs::remove_file(&lit);
        }
    }
}

/// Kills `slipgate args` with SIGKILL after `delay`, or lets it finish first.
fn kill_after(args: &[&str], delay: Duration) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_slipgate"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("run slipgate");
    let start = Instant::now();
    while start.elapsed() < delay {
        if child.try_wait().expect("wait").is_some() {
            return;
        }
        std::thread::sleep(Duration::from_micros(200));
    }
    let _ = child.kill();
    let _ = child.wait();
}

#[test]
fn a_stage_killed_at_any_moment_leaves_the_old_outputs_or_the_new_ones() {
    // The demo map: big enough that each stage takes a while, with coloured light (a .lit).
    let map = project_map("demo.map");
    let bsp = scratch("demo.bsp");
    let b = bsp.to_str().expect("utf8");
    let wad_dir = project_map("");
    let compile_args = [
        "bsp",
        map.to_str().expect("utf8"),
        b,
        "--wad-dir",
        wad_dir.to_str().expect("utf8"),
    ];
    let stages: [&[&str]; 3] = [&compile_args, &["vis", b], &["light", b]];
    // The files after each stage in turn, and how long each took.
    let mut after = Vec::new();
    let mut seconds = Vec::new();
    for args in stages {
        let start = Instant::now();
        let out = command::slipgate(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        seconds.push(start.elapsed().as_secs_f64());
        after.push(outputs(&bsp));
    }
    assert!(after[2].lit.is_some(), "the demo map's light writes a .lit");
    let mut flips = Flips(13);
    for (stage, args) in stages.into_iter().enumerate() {
        // Before a stage: what the stage before it left (before `bsp`: a finished build).
        let before = &after[if stage == 0 { 2 } else { stage - 1 }];
        let done = &after[stage];
        for kill in 0..8 {
            restore(&bsp, before);
            let delay = seconds[stage] * 1.2 * flips.below(1000) as f64 / 1000.0;
            kill_after(args, Duration::from_secs_f64(delay));
            let now = outputs(&bsp);
            let what = format!("{args:?} killed after {delay:.3} s (kill {kill})");
            assert!(
                now.bsp == before.bsp || now.bsp == done.bsp,
                "{what}: a partial .bsp"
            );
            assert!(
                now.prt == before.prt || now.prt == done.prt,
                "{what}: a partial .prt"
            );
            assert!(
                now.lit == before.lit || now.lit == done.lit,
                "{what}: a partial .lit"
            );
        }
    }
}

/// Why `lit` would colour `bsp` wrongly, if it would: engines check only its header and size (3
/// bytes a luxel after an 8-byte header), so a `.lit` from another run of the same size passes
/// them; its grey (each luxel's brightest channel, as `slipgate light` writes the lump) gives it
/// away.
fn lit_mismatch(bsp: &Bsp, lit: &[u8]) -> Option<String> {
    let rgb = match quake_formats::lit::read_lit(lit, bsp.lighting.len()) {
        Ok(rgb) => rgb,
        Err(e) => return Some(e.to_string()),
    };
    let off = rgb
        .chunks_exact(3)
        .zip(&bsp.lighting)
        .filter(|(c, grey)| quake_formats::lit::grey_level([c[0], c[1], c[2]]) != **grey)
        .count();
    (off > 0).then(|| {
        format!(
            "{off} of {} luxels' grey differs from the lump",
            rgb.len() / 3
        )
    })
}

/// Where a killed `slipgate light` left the pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Left {
    OldPair,
    OldBspAlone,
    NewBspAlone,
    NewPair,
}

/// Checks what a kill left beside the BSP against the pair before (`before`) and after
/// (`done`) the run: a whole, valid BSP, and beside it its own `.lit` or none.
fn check_left_pair(bsp: &Path, before: &Outputs, done: &Outputs, what: &str) -> Left {
    let now = outputs(bsp);
    let old = if now.bsp == before.bsp {
        true
    } else {
        assert!(now.bsp == done.bsp, "{what}: a partial .bsp");
        false
    };
    let read = Bsp::read(&now.bsp).unwrap_or_else(|e| panic!("{what}: {e}"));
    let errors: Vec<_> = quake_formats::validate(&read)
        .into_iter()
        .filter(|p| p.severity == quake_formats::Severity::Error)
        .collect();
    assert!(errors.is_empty(), "{what}: {errors:?}");
    let Some(lit) = &now.lit else {
        return if old {
            Left::OldBspAlone
        } else {
            Left::NewBspAlone
        };
    };
    if let Some(mismatch) = lit_mismatch(&read, lit) {
        panic!("{what}: the .lit beside the BSP is another run's: {mismatch}");
    }
    let own = if old { &before.lit } else { &done.lit };
    assert!(own.as_ref() == Some(lit), "{what}: a .lit from neither run");
    if old { Left::OldPair } else { Left::NewPair }
}

#[test]
fn light_killed_at_any_moment_leaves_a_bsp_with_its_own_lit_or_none() {
    const KILLS: usize = 50;
    // The demo map's coloured lights write a .lit; each relight below replaces it with one of
    // the same size but other colours, with none, or with a smaller one.
    let bsp = compile("demo.map", "pair");
    let b = bsp.to_str().expect("utf8");
    let before = outputs(&bsp);
    assert!(before.lit.is_some(), "the demo map's light writes a .lit");
    let mut flips = Flips(1313);
    let mut left = std::collections::BTreeMap::new();
    for extra in [
        &["--range", "0.3"][..],
        &["--nolit"],
        &["--face-stride", "2"],
    ] {
        let args: Vec<&str> = ["light", b].iter().chain(extra).copied().collect();
        let start = Instant::now();
        let out = command::slipgate(&args);
        let seconds = start.elapsed().as_secs_f64();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let done = outputs(&bsp);
        assert!(done.lit != before.lit, "{args:?} leaves the .lit as it was");
        // Half the kills anywhere in the run; the other half where the kills so far saw the
        // files change (the latest that left the old BSP to the earliest that left the new),
        // widened by a millisecond each way since runs start and end with some jitter.
        let (mut old_until, mut new_from) = (0.0_f64, seconds * 1.2);
        for kill in 0..KILLS {
            restore(&bsp, &before);
            let delay = if kill < KILLS / 2 {
                seconds * 1.2 * flips.below(1000) as f64 / 1000.0
            } else {
                let (lo, hi) = (
                    old_until.min(new_from) - 1e-3,
                    old_until.max(new_from) + 1e-3,
                );
                (lo + (hi - lo) * flips.below(1000) as f64 / 1000.0).max(0.0)
            };
            kill_after(&args, Duration::from_secs_f64(delay));
            let what = format!("{args:?} killed after {delay:.4} s (kill {kill})");
            let outcome = check_left_pair(&bsp, &before, &done, &what);
            if outcome <= Left::OldBspAlone {
                old_until = old_until.max(delay);
            } else {
                new_from = new_from.min(delay);
            }
            *left.entry((extra[0], outcome)).or_insert(0) += 1;
        }
    }
    eprintln!(
        "light killed {} times; what each kill left: {left:?}",
        3 * KILLS
    );
}
