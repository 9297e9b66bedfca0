//! End-to-end: a real Quake engine loads the BSPs Slipgate writes.
//!
//! The engine is QuakeSpasm (Debian's `quakespasm`), started on a scratch game directory holding
//! the free game data from `../shared/engine/id1`, a generated `progs.dat` (`support/progs.rs`:
//! the data has none and a server cannot start without one) and the map.
//!
//! - The dedicated server (`-dedicated`) loads the map as a game server does: every lump is read
//!   and checked (faces and their lightmap extents, textures, lighting and the `.lit`,
//!   visibility, clip hulls, submodels), the entities are spawned and two physics frames run.
//!   It does not render, so lightmap pages and textures are never built from the data.
//! - When `xvfb-run` is installed, the client also loads the map in a virtual X display (Mesa's
//!   software OpenGL), which builds the lightmaps and uploads the textures, and takes a
//!   screenshot from the player start (kept in the scratch directory, printed by the test).
//!
//! Maps: every project map (and `demo.map` again as BSP2) and two corpus maps. The engine writes
//! into the user's `~/.quakespasm` (its `id1/` and a directory per run, which the test removes).
//! Skips, saying so, when `quakespasm` is not installed or `../shared` is absent.
#![cfg(unix)]

#[path = "support/progs.rs"]
mod progs;
#[path = "support/corpus.rs"]
mod support_corpus;

use quake_formats::Bsp;
use quake_formats::entities::{Entity, parse_entities};
use std::fs::File;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};
use support_corpus::corpus;

/// A load takes about a second; the limit only keeps a hung engine from hanging the test.
const ENGINE_TIMEOUT: Duration = Duration::from_secs(20);

/// Output (any case) that means the engine rejected or distrusted the map. Fatal errors print
/// "QUAKE ERROR" on stderr; the model loader's messages start with `Mod_`; with `developer 1`
/// it also warns when a count "exceeds" a standard limit or a `.lit` is "corrupt".
const FAILURE_SIGNS: &[&str] = &[
    "quake error",
    "host_error",
    "sys_error",
    "mod_",
    "exceeds",
    "bad",
    "corrupt",
    "couldn't spawn",
];

/// Map keys the generated progs has no field for (`wad`, `light`, `_sunlight` ...): harmless.
const BENIGN_SUFFIX: &str = "is not a field";

/// Frames the client waits after signing on before moving to the start and after moving,
/// so the console has gone and the view has followed.
const SETTLE_FRAMES: usize = 20;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

struct Engine {
    exe: PathBuf,
    /// The free game data: palette, colormap, `gfx.wad`.
    data: PathBuf,
    /// Where this test compiles maps and builds game directories.
    scratch: PathBuf,
    /// `xvfb-run`, for the client pass.
    xvfb: Option<PathBuf>,
    /// The first X display number `xvfb-run` tries: distinct per process and test, so tests
    /// running at once do not race for the same free number.
    display: u32,
}

fn on_path(program: &str, extra: &[&str]) -> Option<PathBuf> {
    let search = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&search)
        .chain(extra.iter().map(PathBuf::from))
        .map(|dir| dir.join(program))
        .find(|p| p.is_file())
}

/// The engine and game data, or `None` (after saying why) when either is missing. `index`
/// tells the tests apart (0..8).
fn engine(test: &str, index: u32) -> Option<Engine> {
    // Debian installs games in /usr/games, which is not on every PATH (root's, for one).
    let Some(exe) = on_path("quakespasm", &["/usr/games"]) else {
        eprintln!(
            "SKIPPED: quakespasm not found on PATH or in /usr/games (apt-get install quakespasm)"
        );
        return None;
    };
    let data = repo().join("../shared/engine/id1");
    if !data.is_dir() {
        eprintln!("SKIPPED: {} not found (needs ../shared)", data.display());
        return None;
    }
    let xvfb = on_path("xvfb-run", &[]);
    if xvfb.is_none() {
        eprintln!("note: xvfb-run not found; only the dedicated server loads the maps");
    }
    let pid = std::process::id();
    let scratch = std::env::temp_dir().join(format!("slipgate-engine-{pid}/{test}"));
    std::fs::create_dir_all(&scratch).expect("scratch dir");
    Some(Engine {
        exe,
        data,
        scratch,
        xvfb,
        display: 100 + pid % 500 * 8 + index,
    })
}

/// A game directory ready to run one map.
struct Game {
    base: PathBuf,
    /// The mod directory's name (under `base`), unique so the engine's per-user directory
    /// (see [`Game::user_dir`]) is ours alone.
    name: String,
    entities: Vec<Entity>,
}

impl Game {
    /// Where the engine writes files for this game (screenshots): `~/.quakespasm/<game>`, found
    /// from the user's home directory whatever `-basedir` says.
    fn user_dir(&self) -> Option<PathBuf> {
        let home = std::env::var_os("HOME").map(PathBuf::from)?;
        Some(home.join(".quakespasm").join(&self.name))
    }

    fn remove_user_dir(&self) {
        if let Some(dir) = self.user_dir() {
            std::fs::remove_dir_all(dir).ok();
        }
    }
}

/// A map to compile (with extra `slipgate bsp` options) and load as `name`.
struct Case {
    map: PathBuf,
    name: String,
    bsp_options: &'static [&'static str],
}

impl Case {
    fn new(map: PathBuf) -> Case {
        let name = map.file_stem().and_then(|s| s.to_str()).expect("map name");
        Case {
            name: name.to_string(),
            map,
            bsp_options: &[],
        }
    }
}

impl Engine {
    /// Compile a case as the command does (bsp, vis, light) into the scratch directory.
    fn compile(&self, case: &Case) -> Result<PathBuf, String> {
        let bsp = self.scratch.join(format!("{}.bsp", case.name));
        let (map_arg, bsp_arg, wads) = (path_str(&case.map), path_str(&bsp), repo().join("maps"));
        let mut bsp_args = vec!["bsp", "--wad-dir", path_str(&wads), map_arg, bsp_arg];
        bsp_args.extend(case.bsp_options);
        // Fast vis: the visibility lump is encoded as by the full flow, which only costs time
        // here (11 s on e1m1).
        let stages: [&[&str]; 3] = [&bsp_args, &["vis", "--fast", bsp_arg], &["light", bsp_arg]];
        for args in stages {
            let out = Command::new(env!("CARGO_BIN_EXE_slipgate"))
                .args(args)
                .output()
                .expect("run slipgate");
            if !out.status.success() {
                return Err(format!(
                    "slipgate {} failed:\n{}",
                    args.join(" "),
                    String::from_utf8_lossy(&out.stderr)
                ));
            }
        }
        Ok(bsp)
    }

    /// A game directory for map `name`: the game data, a progs with a spawn function for each
    /// class in the map, the player model, `bsp` and the `.lit` beside it.
    fn game(&self, name: &str, bsp: &Path, client: bool) -> Game {
        let pass = if client { "client" } else { "server" };
        let base = self.scratch.join(format!("{name}-{pass}"));
        let game = format!("slipgate-test-{}-{name}", std::process::id());
        let (id1, dir) = (base.join("id1"), base.join(&game));
        std::fs::create_dir_all(dir.join("maps")).expect("game dir");
        std::fs::create_dir_all(dir.join("progs")).expect("game dir");
        std::fs::create_dir_all(&id1).expect("game dir");
        for entry in std::fs::read_dir(&self.data).expect("game data") {
            let entry = entry.expect("game data entry");
            let link = id1.join(entry.file_name());
            if !link.exists() {
                std::os::unix::fs::symlink(entry.path(), link).expect("symlink game data");
            }
        }
        let bytes = std::fs::read(bsp).expect("read bsp");
        let text = Bsp::read(&bytes)
            .map(|b| String::from_utf8_lossy(&b.entities).into_owned())
            .unwrap_or_default();
        let entities = parse_entities(&text).unwrap_or_default();
        let classes: Vec<&str> = entities.iter().map(|e| e.classname()).collect();
        let write = |path: PathBuf, bytes: &[u8]| std::fs::write(path, bytes).expect("write");
        write(dir.join("progs.dat"), &progs::minimal_progs(&classes));
        write(dir.join(progs::PLAYER_MODEL), &progs::placeholder_model());
        write(dir.join(format!("maps/{name}.bsp")), &bytes);
        // The client runs command-line commands only when quake.rc says so.
        write(dir.join("quake.rc"), b"stuffcmds\n");
        let lit = bsp.with_extension("lit");
        if lit.exists() {
            std::fs::copy(&lit, dir.join(format!("maps/{name}.lit"))).expect("copy lit");
        }
        Game {
            base,
            name: game,
            entities,
        }
    }

    /// Run the dedicated server on map `name`. `Ok` holds the lines that show it loaded; `Err`
    /// says what went wrong, with the engine's output.
    fn load(&self, name: &str, bsp: &Path) -> Result<String, String> {
        let game = self.game(name, bsp, false);
        let args = self.engine_args(&game, &["-dedicated", "1"]);
        let args = [args, strings(&["+map", name, "+status", "+quit"])].concat();
        let (status, output) = run(&self.exe, &args, &[], &game.base);
        game.remove_user_dir();
        // `status` prints "map:     NAME" only when a server is running that map.
        let running = output
            .lines()
            .any(|l| l.strip_prefix("map:").map(str::trim) == Some(name));
        let required = ["Server spawned."];
        verdict(name, status, &output, &required, running, &game.base)?;
        std::fs::remove_dir_all(&game.base).ok();
        let shown = ["SpawnServer", "inhibited", "Server spawned", "map:"];
        Ok(lines_with(&output, &shown))
    }

    /// Run the client on map `name` in a virtual display and screenshot the player start.
    /// `Ok` holds the screenshot's path.
    fn render(&self, xvfb: &Path, name: &str, bsp: &Path) -> Result<PathBuf, String> {
        let game = self.game(name, bsp, true);
        let start = game
            .entities
            .iter()
            .find(|e| e.classname() == "info_player_start");
        let origin = start.and_then(|e| e.get_floats::<3>("origin"));
        let [x, y, z] = origin.unwrap_or_default();
        let yaw = start.and_then(|e| e.get_float("angle")).unwrap_or(0.0);
        let wait = "wait\n".repeat(SETTLE_FRAMES);
        // The progs neither places the player nor gives it health (a dead player's view is
        // rolled), so the script does both (cheats a single-player server accepts).
        let script = format!(
            "scr_conspeed 100000\ncon_notifytime 0\n{wait}give h 100\n\
             setpos {x} {y} {} 0 {yaw} 0\n{wait}screenshot\nquit\n",
            z + 22.0
        );
        std::fs::write(game.base.join(&game.name).join("shot.cfg"), script).expect("write");
        let display = self.display.to_string();
        let mut args = strings(&["-a", "-n", &display, "-s", "-screen 0 640x480x24"]);
        args.push(path_str(&self.exe).to_string());
        args.extend(self.engine_args(&game, &["-width", "640", "-height", "480", "-window"]));
        // The default protocol (666) sends positions as 13.3 fixed point, so a view beyond
        // +-4096 (maps/hard/huge_coords.map) wraps into the void; RMQ's (999) sends floats.
        if [x, y, z].iter().any(|c| c.abs() >= 4096.0) {
            args.extend(strings(&["-protocol", "999"]));
        }
        args.extend(strings(&["-nosound", "+map", name, "+exec", "shot.cfg"]));
        // Mesa's llvmpipe can deadlock joining its worker threads at exit (XCloseDisplay), after
        // the screenshot: without worker threads it cannot. No shader cache in the user's home.
        let env = [
            ("LP_NUM_THREADS", "0"),
            ("MESA_SHADER_CACHE_DISABLE", "true"),
        ];
        let (status, output) = run(xvfb, &args, &env, &game.base);

        let shot = game.base.join("screenshot.png");
        if let Some(dir) = game.user_dir() {
            std::fs::rename(dir.join("spasm0000.png"), &shot).ok();
        }
        game.remove_user_dir();
        let required = ["CL_SignonReply: 4", "Wrote spasm0000.png"];
        verdict(name, status, &output, &required, shot.exists(), &game.base)?;
        Ok(shot)
    }

    /// Arguments every run shares: the game directory, the mod in it, developer messages (the
    /// limit warnings and "Server spawned." are developer messages).
    fn engine_args(&self, game: &Game, mode: &[&str]) -> Vec<String> {
        let mut args = strings(mode);
        args.extend(strings(&[
            "-basedir",
            path_str(&game.base),
            "-game",
            &game.name,
        ]));
        // Tests run engines in parallel, and two on the default UDP port clash. The client needs
        // no network; a dedicated server refuses to start without one, so it gets a free port.
        if mode.contains(&"-dedicated") {
            args.extend(["-port".to_string(), free_udp_port().to_string()]);
        } else {
            args.push("-noudp".to_string());
        }
        args.extend(strings(&["+developer", "1"]));
        args
    }

    /// Compile and load every case; panic listing all the cases that failed.
    fn check(&self, cases: &[Case]) {
        let mut failed = Vec::new();
        for case in cases {
            let name = case.name.as_str();
            let start = Instant::now();
            let bsp = match self.compile(case) {
                Ok(bsp) => bsp,
                Err(e) => {
                    failed.push(e);
                    continue;
                }
            };
            match self.load(name, &bsp) {
                Ok(lines) => eprintln!("{name}: server loaded it: {lines}"),
                Err(e) => failed.push(e),
            }
            if let Some(xvfb) = &self.xvfb {
                match self.render(xvfb, name, &bsp) {
                    Ok(shot) => eprintln!("{name}: client rendered it: {}", shot.display()),
                    Err(e) => failed.push(e),
                }
            }
            eprintln!("{name}: compiled and loaded in {:.1?}", start.elapsed());
        }
        assert!(failed.is_empty(), "{}", failed.join("\n\n"));
    }
}

/// Run `program` with `env` in its own process group (killed whole on timeout: xvfb-run starts
/// the X server and the engine as children), output to files in `dir`; the exit status, `None`
/// on timeout, and stdout followed by stderr.
fn run(
    program: &Path,
    args: &[String],
    env: &[(&str, &str)],
    dir: &Path,
) -> (Option<ExitStatus>, String) {
    let (stdout, stderr) = (dir.join("stdout.txt"), dir.join("stderr.txt"));
    let mut child = Command::new(program)
        .args(args)
        .envs(env.iter().copied())
        .stdin(Stdio::null())
        .stdout(File::create(&stdout).expect("log"))
        .stderr(File::create(&stderr).expect("log"))
        .process_group(0)
        .spawn()
        .unwrap_or_else(|e| panic!("start {}: {e}", program.display()));
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for the engine") {
            break Some(status);
        }
        if start.elapsed() > ENGINE_TIMEOUT {
            // TERM first so Xvfb removes its lock file; the child is not reaped before the end,
            // so its group id cannot be reused meanwhile.
            let group = format!("-{}", child.id());
            for signal in ["-TERM", "-KILL"] {
                Command::new("kill")
                    .args([signal, "--", &group])
                    .stderr(Stdio::null())
                    .status()
                    .expect("signal the engine's process group");
                std::thread::sleep(Duration::from_millis(500));
            }
            child.wait().expect("reap the engine");
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let read = |p: &Path| std::fs::read_to_string(p).unwrap_or_default();
    (status, read(&stdout) + &read(&stderr))
}

/// `Ok` when the engine exited cleanly, printed every `required` line, no failure sign, and
/// `done` holds; otherwise the reasons and the whole output.
fn verdict(
    name: &str,
    status: Option<ExitStatus>,
    output: &str,
    required: &[&str],
    done: bool,
    dir: &Path,
) -> Result<(), String> {
    let failures: Vec<&str> = output
        .lines()
        .filter(|l| !l.ends_with(BENIGN_SUFFIX))
        .filter(|l| FAILURE_SIGNS.iter().any(|s| l.to_lowercase().contains(s)))
        .collect();
    let missing: Vec<&&str> = required.iter().filter(|r| !output.contains(**r)).collect();
    if status.is_some_and(|s| s.success()) && failures.is_empty() && missing.is_empty() && done {
        return Ok(());
    }
    Err(format!(
        "{name}: quakespasm did not load it (exit {status:?}, missing {missing:?}){}\n\
         --- engine output (also in {}) ---\n{output}",
        failures
            .iter()
            .map(|l| format!("\n  {l}"))
            .collect::<String>(),
        dir.display()
    ))
}

fn lines_with(output: &str, needles: &[&str]) -> String {
    let lines: Vec<&str> = output
        .lines()
        .filter(|l| needles.iter().any(|n| l.contains(n)))
        .collect();
    lines.join(" | ")
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

#[test]
fn engine_loads_the_project_maps() {
    let Some(engine) = engine("project", 0) else {
        return;
    };
    let demo = repo().join("maps/demo.map");
    let mut maps = vec![demo.clone(), repo().join("maps/leak/sealed.map")];
    let hard = std::fs::read_dir(repo().join("maps/hard")).expect("maps/hard");
    let mut hard: Vec<PathBuf> = hard
        .map(|e| e.expect("maps/hard entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "map"))
        .collect();
    hard.sort();
    maps.extend(hard);
    let mut cases: Vec<Case> = maps.into_iter().map(Case::new).collect();
    cases.push(Case {
        map: demo,
        name: "demo_bsp2".to_string(),
        bsp_options: &["--bsp2"],
    });
    engine.check(&cases);
}

#[test]
fn engine_loads_librequake_start() {
    let Some(engine) = engine("start", 1) else {
        return;
    };
    let Some(map) = corpus("public/maps/librequake/start.map") else {
        return;
    };
    engine.check(&[Case::new(map)]);
}

#[test]
fn engine_loads_id_e1m1() {
    let Some(engine) = engine("e1m1", 2) else {
        return;
    };
    let Some(map) = corpus("public/maps/id/e1m1.map") else {
        return;
    };
    engine.check(&[Case::new(map)]);
}

/// The check itself: a BSP from another compiler passes, and a damaged one fails.
#[test]
fn engine_check_passes_a_known_good_bsp_and_fails_a_broken_one() {
    let Some(engine) = engine("check", 3) else {
        return;
    };
    let Some(good) = corpus("public/bsp/librequake/start.bsp") else {
        return;
    };
    if let Err(e) = engine.load("known_good", &good) {
        panic!("{e}");
    }

    // Point marksurface 0 at face 60000.
    let mut bytes = std::fs::read(&good).expect("read");
    let lump_offset = |i: usize| {
        let at = 4 + i * 8;
        i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as usize
    };
    let marksurfaces = lump_offset(11);
    bytes[marksurfaces..marksurfaces + 2].copy_from_slice(&60000u16.to_le_bytes());
    let damaged = engine.scratch.join("damaged.bsp");
    std::fs::write(&damaged, bytes).expect("write");
    let err = engine
        .load("damaged", &damaged)
        .expect_err("the engine must reject a damaged BSP");
    assert!(err.contains("bad surface number"), "{err}");
}

/// A UDP port nothing holds right now (the OS picks it; the socket closes before the engine
/// binds it, a race no other test of ours takes part in).
fn free_udp_port() -> u16 {
    std::net::UdpSocket::bind("127.0.0.1:0")
        .and_then(|s| s.local_addr())
        .map(|a| a.port())
        .unwrap_or(26000)
}
