//! Running compiled maps in real engines with real game code: QuakeSpasm and DarkPlaces (Debian's
//! `quakespasm`, `darkplaces`, `darkplaces-server`) on a game directory that links LibreQuake's
//! `id1` from `../shared/engine` (progs.dat, models, sounds).
//!
//! Each run is driven by a script (`slipgate.cfg`, run with `+exec`) that loads the map, lets a
//! fixed number of frames pass and quits. `host_framerate` fixes the game time of a frame, so a
//! run covers the same game time however fast the machine is, and the frames run as fast as the
//! machine can go (QuakeSpasm: exactly one game frame per script `wait`; DarkPlaces paces its
//! server by the wall clock, so a `wait` is one client frame and at least one server frame).
//!
//! - [`Engine::serve`]: the dedicated server spawns the map and runs five seconds of game time:
//!   items drop to the floor, monsters wake and walk, trains move, every one of them tracing the
//!   clip hulls.
//! - [`Engine::play`]: the client, in a virtual X display (`xvfb-run`, Mesa's software OpenGL),
//!   spawns at the player start and screenshots the view the mapper set up there (uncompressed
//!   TGA, kept in the run's directory; it must not be blank), then turns on god mode, takes every
//!   weapon, walks, jumps, turns and fires rockets, lightning and grenades for eight seconds of
//!   game time, and prints the player's state: the test checks the player fired.
//!
//! A run fails on a fatal error message, an exit status other than 0 (a crash signal included),
//! or a timeout; the engine is stopped early once it printed a fatal error.

use crate::maps::{Compiled, path_str};
use std::collections::{BTreeMap, HashSet};
use std::fs::File;
use std::os::unix::fs::{MetadataExt, symlink};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// Game seconds per frame (`host_framerate`): Quake's own longest frame.
const FRAME_SECONDS: f32 = 0.1;
/// Frames the dedicated server runs after spawning the map.
const SERVER_FRAMES: usize = 50;
/// Frames QuakeSpasm's client waits after `map` before acting: the local connection signs on in
/// a few frames.
const SIGNON_FRAMES: usize = 20;
/// Frames DarkPlaces' client waits once the player entity exists (it polls for that) and before
/// acting, so the last sign-on step is done and the client sends moves.
const SPAWNED_FRAMES: usize = 10;
/// What the player does: commands, then the frames to let pass.
const PLAY: &[(&[&str], usize)] = &[
    // All weapons and ammunition, the rocket launcher in hand.
    (&["god", "impulse 9"], 2),
    (&["+forward"], 10),
    (&["+jump"], 2),
    (&["-jump", "+right"], 5),
    (&["-right", "impulse 7", "+attack"], 10),
    (&["-attack", "impulse 8", "+attack", "+left"], 10),
    (
        &[
            "-attack",
            "-left",
            "-forward",
            "+back",
            "+moveleft",
            "+jump",
        ],
        10,
    ),
    (
        &[
            "-jump",
            "-back",
            "-moveleft",
            "impulse 6",
            "+attack",
            "+lookup",
        ],
        3,
    ),
    (&["-lookup", "+lookdown"], 3),
    (&["-lookdown"], 4),
    // Long enough for the grenades to bounce and go off.
    (&["-attack"], 25),
];
/// The rockets `impulse 9` gives: fewer at the end means the player fired.
const ROCKETS_GIVEN: f32 = 100.0;
/// The screenshot's size (smaller is faster in software OpenGL).
const SCREEN: (u32, u32) = (320, 240);
/// Distinct colours the screenshot (the world only) must hold: a lit, textured view has
/// thousands, an empty or black one a handful.
const MIN_VIEW_COLOURS: usize = 64;
const SERVER_TIMEOUT: Duration = Duration::from_secs(60);
/// DarkPlaces renders a 320x240 frame in a tenth of a second in software on a quiet machine;
/// the limit leaves room for a busy one.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(180);
/// Beyond this a player start's coordinates wrap in QuakeSpasm's default protocol (666 sends
/// 13.3 fixed point), so its client uses RMQ's (999), which sends floats.
const PROTOCOL_666_LIMIT: f64 = 4096.0;

/// Output that means the engine stopped the map or crashed: QuakeSpasm's `Sys_Error`
/// ("QUAKE ERROR"), DarkPlaces' ("Quake Error"), both engines' `Host_Error` (QuakeC's `error()`
/// and runtime errors end in one), DarkPlaces' QuakeC crash report.
const FATAL: &[&str] = &[
    "QUAKE ERROR",
    "Quake Error",
    "Host_Error",
    "Sys_Error",
    "SERVER ERROR",
    "QuakeC crash report",
];
/// Warnings that blame the BSP file itself (its lumps, its `.lit`): failures too. Every message
/// of either engine's BSP loader starts `Mod_`; the `.lit` checks are separate.
const BSP_FAULTS: &[&str] = &["Mod_", "Corrupt .lit", "Unknown .lit", "Empty .lit"];
/// Worth a line in the test's output, never a failure: a standard limit exceeded (QuakeSpasm
/// with `developer 1`), submodels with no faces (trigger brushes; BSPs from other compilers show
/// it too), an animated texture whose WAD has one frame, and the game code's complaints about the
/// map's own entities (LibreQuake start's teleporter with no target, e3m4's `movetarget_f`,
/// monsters placed in walls). Missing sounds the game code asks for (`boss2/*`,
/// `hknight/hit.wav`) and map keys the progs has no field for are benign and not listed.
const NOTES: &[&str] = &[
    "exceeds",
    "empty submodel",
    "only one frame",
    "OBJECT ERROR",
    "in wall",
    "can't find target",
];

#[derive(Clone, Copy, PartialEq)]
pub enum Kind {
    QuakeSpasm,
    DarkPlaces,
}

pub struct Engine {
    pub kind: Kind,
    /// The dedicated server, when installed.
    server: Option<PathBuf>,
    /// The client, when installed and `xvfb-run` is too.
    client: Option<PathBuf>,
    xvfb: Option<PathBuf>,
    /// `../shared/engine/id1`.
    data: PathBuf,
    /// Where runs make their game directories and keep logs and screenshots.
    runs: PathBuf,
}

/// What a run that passed leaves to report.
pub struct Outcome {
    pub seconds: f64,
    /// The game time the server reached, when the engine can print it (DarkPlaces).
    pub game_time: Option<f32>,
    pub screenshot: Option<PathBuf>,
    pub view_colours: Option<usize>,
    /// Lines matching [`NOTES`], with how often each came.
    pub notes: Vec<String>,
}

/// Finished with this status, or stopped by the test (after a fatal message, or on a timeout).
enum Ended {
    Exited(ExitStatus),
    StoppedAfterFatal,
    TimedOut(Duration),
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::QuakeSpasm => "quakespasm",
            Kind::DarkPlaces => "darkplaces",
        }
    }
}

fn on_path(program: &str) -> Option<PathBuf> {
    // Debian installs games in /usr/games, which is not on every PATH (root's, for one).
    let search = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&search)
        .chain([PathBuf::from("/usr/games")])
        .map(|dir| dir.join(program))
        .find(|p| p.is_file())
}

impl Engine {
    /// The engine, or `None` after a `SKIPPED:` line saying what is missing. A missing server or
    /// client (or `xvfb-run`) skips that half only, saying so.
    pub fn find(kind: Kind, scratch: &Path) -> Option<Engine> {
        let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/engine/id1");
        if !data.join("progs.dat").is_file() {
            eprintln!(
                "SKIPPED: {} not found (needs ../shared/engine)",
                data.display()
            );
            return None;
        }
        let (server_exe, client_exe, package) = match kind {
            Kind::QuakeSpasm => ("quakespasm", "quakespasm", "quakespasm"),
            Kind::DarkPlaces => (
                "darkplaces-server",
                "darkplaces",
                "darkplaces darkplaces-server",
            ),
        };
        let (server, client) = (on_path(server_exe), on_path(client_exe));
        if server.is_none() && client.is_none() {
            eprintln!("SKIPPED: {client_exe} not found (apt-get install {package})");
            return None;
        }
        if server.is_none() {
            eprintln!("SKIPPED: {server_exe} not found: no dedicated server runs");
        }
        let xvfb = on_path("xvfb-run");
        if client.is_none() {
            eprintln!("SKIPPED: {client_exe} not found: no client runs");
        } else if xvfb.is_none() {
            eprintln!(
                "SKIPPED: xvfb-run not found: no {client_exe} client runs (apt-get install xvfb xauth libgl1-mesa-dri)"
            );
        }
        Some(Engine {
            kind,
            client: client.filter(|_| xvfb.is_some()),
            server,
            xvfb,
            data,
            runs: scratch.join(kind.name()),
        })
    }

    pub fn has_server(&self) -> bool {
        self.server.is_some()
    }

    pub fn has_client(&self) -> bool {
        self.client.is_some()
    }

    /// Spawn the map in the dedicated server and run [`SERVER_FRAMES`] frames.
    pub fn serve(&self, map: &Compiled) -> Result<Outcome, String> {
        let exe = self.server.as_ref().expect("a server");
        let game = Game::new(self, map, "server");
        let mut script = self.frame_settings(true);
        script += &format!(
            "map {}\n{}echo slipgate: served\n",
            map.name,
            waits(SERVER_FRAMES)
        );
        if self.kind == Kind::DarkPlaces {
            script += "prvm_global server time\n";
        }
        script += "quit\n";
        game.write_script(&script);
        let mut args = game.engine_args(self.kind);
        if self.kind == Kind::QuakeSpasm {
            args.extend(strings(&["-dedicated", "1"]));
        }
        // A server needs a UDP port; tests run servers at once, so each gets a free one.
        args.extend(["-port".to_string(), free_udp_port().to_string()]);
        args.extend(game.script_args());
        let run = game.run(exe, &args, &[], SERVER_TIMEOUT);
        game.clear_user_dir();
        let mut required = vec!["Server spawned.", "slipgate: served"];
        let game_time = game_time(&run.output);
        if self.kind == Kind::DarkPlaces {
            required.push("time:");
        }
        run.check(&required)?;
        let enough = SERVER_FRAMES as f32 * FRAME_SECONDS;
        if let Some(time) = game_time.filter(|&t| t < enough) {
            return Err(run.fail(&format!("the server reached game time {time} < {enough}")));
        }
        game.clean_up();
        Ok(run.outcome(game_time, None, None))
    }

    /// Play the map in the client from the player start, which it screenshots first.
    pub fn play(&self, map: &Compiled) -> Result<Outcome, String> {
        let xvfb = self.xvfb.as_ref().expect("xvfb-run");
        let game = Game::new(self, map, "client");
        self.write_client_scripts(&game, map);
        // Mesa's llvmpipe can deadlock joining its worker threads at exit (XCloseDisplay):
        // without worker threads it cannot. No shader cache in the user's home.
        let env = [
            ("LP_NUM_THREADS", "0"),
            ("MESA_SHADER_CACHE_DISABLE", "true"),
        ];
        let run = game.run(xvfb, &self.client_args(&game), &env, CLIENT_TIMEOUT);
        let shot = game.take_screenshot();
        game.clear_user_dir();
        run.check(&["godmode ON", "slipgate: played"])?;
        let min_colours = if map.empty_view.is_some() {
            1
        } else {
            MIN_VIEW_COLOURS
        };
        let (shot, colours) = shot
            .and_then(|shot| check_screenshot(shot, min_colours))
            .map_err(|e| run.fail(&e))?;
        let player = PlayerReport::parse(self.kind, &run.output).map_err(|e| run.fail(&e))?;
        if player.health <= 0.0 || player.rockets >= ROCKETS_GIVEN {
            return Err(run.fail(&format!(
                "the player did not play: health {}, rockets {} (of {ROCKETS_GIVEN} given)",
                player.health, player.rockets
            )));
        }
        let game_time = game_time(&run.output);
        let played = play_frames() as f32 * FRAME_SECONDS;
        if let Some(time) = game_time.filter(|&t| t < played) {
            return Err(run.fail(&format!("game time {time} < the {played} s played")));
        }
        game.clean_up();
        Ok(run.outcome(game_time, Some(shot), Some(colours)))
    }

    /// Where the player stands after walking forward from the player start for `frames` frames
    /// in QuakeSpasm's client (god mode, so nothing stops the walk but the map).
    pub fn walk(&self, map: &Compiled, frames: usize) -> Result<[f32; 3], String> {
        assert!(self.kind == Kind::QuakeSpasm, "walks are QuakeSpasm's");
        let xvfb = self.xvfb.as_ref().expect("xvfb-run");
        let game = Game::new(self, map, "walk");
        let script = format!(
            "{}noexit 1\nmap {}\n{}god\n+forward\n{}-forward\n{}edict 1\n\
             echo slipgate: walked\nquit\n",
            self.frame_settings(false),
            map.name,
            waits(SIGNON_FRAMES),
            waits(frames),
            waits(2)
        );
        game.write_script(&script);
        let env = [
            ("LP_NUM_THREADS", "0"),
            ("MESA_SHADER_CACHE_DISABLE", "true"),
        ];
        let run = game.run(xvfb, &self.client_args(&game), &env, CLIENT_TIMEOUT);
        game.clear_user_dir();
        run.check(&["godmode ON", "slipgate: walked"])?;
        let origin = player_origin(&run.output).map_err(|e| run.fail(&e))?;
        game.clean_up();
        Ok(origin)
    }

    /// The client's script: load the map, wait for the player, [`play_script`], report.
    fn write_client_scripts(&self, game: &Game, map: &Compiled) {
        let mut script = self.frame_settings(false);
        // An exit the player walks into (LibreQuake start's episode gates) would load a map that
        // is not there; with noexit the game code hurts the player instead, and god mode holds.
        script += "noexit 1\n";
        match self.kind {
            Kind::QuakeSpasm => {
                script += &format!("map {}\n{}", map.name, waits(SIGNON_FRAMES));
                script += &play_script("screenshot tga");
                script += "edict 1\nquit\n";
            }
            Kind::DarkPlaces => {
                // A `wait` holds back what the server stuffs into the command buffer, and sign-on
                // needs that (`cl_begindownloads`): so no waits before the player exists.
                // `defer 0` runs the poll again next frame without holding the buffer.
                script += "sv_cheats 1\nset slipgate_health 0\n\
                    alias slipgate_poll \"prvm_edictget server 1 health slipgate_health; slipgate_poll_$slipgate_health\"\n\
                    alias slipgate_poll_0 \"defer 0 slipgate_poll\"\n\
                    alias slipgate_poll_100 \"exec slipgate_play.cfg\"\n";
                script += &format!("map {}\nslipgate_poll\n", map.name);
                let play = waits(SPAWNED_FRAMES) + &play_script("screenshot") + DARKPLACES_REPORT;
                game.write_file("slipgate_play.cfg", &play);
            }
        }
        game.write_script(&script);
    }

    /// `xvfb-run` arguments: a virtual screen of [`SCREEN`]'s size and the client in it.
    fn client_args(&self, game: &Game) -> Vec<String> {
        let exe = self.client.as_ref().expect("a client");
        let (width, height) = (SCREEN.0.to_string(), SCREEN.1.to_string());
        let display = next_display().to_string();
        let screen = format!("-screen 0 {width}x{height}x24");
        let mut args = strings(&["-a", "-n", &display, "-s", &screen, path_str(exe)]);
        args.extend(game.engine_args(self.kind));
        match self.kind {
            Kind::QuakeSpasm => args.extend(strings(&[
                "-width", &width, "-height", &height, "-window", "-noudp",
            ])),
            Kind::DarkPlaces => {
                // Its single-player server opens a UDP port too.
                args.extend(["-port".to_string(), free_udp_port().to_string()]);
                args.extend(strings(&["+vid_fullscreen", "0", "+vid_width", &width]));
                args.extend(strings(&["+vid_height", &height]));
            }
        }
        args.push("-nosound".to_string());
        args.extend(game.script_args());
        args
    }

    /// Script lines that fix each frame's game time and let frames run as fast as they can.
    fn frame_settings(&self, dedicated: bool) -> String {
        let mut lines = format!("host_framerate {FRAME_SECONDS}\n");
        match (self.kind, dedicated) {
            // host_maxfps would otherwise hold frames to 72 a second; a dedicated server also
            // sleeps sys_ticrate seconds between frames.
            (Kind::QuakeSpasm, true) => lines += "host_maxfps 1000\nsys_ticrate 0.01\n",
            // No console lines over the screenshot.
            (Kind::QuakeSpasm, false) => lines += "host_maxfps 1000\ncon_notifytime 0\n",
            // The dedicated server runs a frame every sys_ticrate wall seconds.
            (Kind::DarkPlaces, true) => lines += "sys_ticrate 0.01\n",
            // The single-player server runs as many frames as the wall time since the last
            // client frame holds, each at most sys_ticrate long: the longest frame, so a slow
            // (software-rendered) client frame is one server frame, not ten. No frame rate cap,
            // no console lines over the screenshot, screenshots as TGA.
            (Kind::DarkPlaces, false) => {
                lines += "sys_ticrate 0.1\nsv_fixedframeratesingleplayer 0\ncl_maxfps 0\n\
                          cl_maxidlefps 0\ncon_notify 0\nscr_screenshot_jpeg 0\n\
                          scr_screenshot_png 0\n"
            }
        }
        lines
    }
}

/// Read the screenshot: [`SCREEN`]'s size and at least `min_colours` colours. `Ok` holds it and
/// its colour count.
fn check_screenshot(shot: PathBuf, min_colours: usize) -> Result<(PathBuf, usize), String> {
    let image = image::open(&shot)
        .map_err(|e| format!("screenshot {}: {e}", shot.display()))?
        .into_rgb8();
    let (width, height) = (SCREEN.0, SCREEN.1);
    if image.dimensions() != (width, height) {
        return Err(format!(
            "screenshot {} is {}x{}, not {width}x{height}",
            shot.display(),
            image.width(),
            image.height()
        ));
    }
    let colours = image.pixels().collect::<HashSet<_>>().len();
    if colours < min_colours {
        return Err(format!(
            "screenshot {} is blank: {colours} colours",
            shot.display()
        ));
    }
    Ok((shot, colours))
}

/// DarkPlaces' end of play: the player's state and the game time.
const DARKPLACES_REPORT: &str = "prvm_edictget server 1 health slipgate_health\n\
    prvm_edictget server 1 ammo_rockets slipgate_rockets\n\
    echo slipgate: health $slipgate_health rockets $slipgate_rockets\n\
    prvm_global server time\nquit\n";

fn waits(frames: usize) -> String {
    "wait\n".repeat(frames)
}

fn play_frames() -> usize {
    PLAY.iter().map(|(_, frames)| frames).sum()
}

/// The screenshot of the view from the player start (the world only: no status bar, no weapon),
/// then [`PLAY`].
fn play_script(screenshot: &str) -> String {
    let mut script = format!(
        "viewsize 120\nr_drawviewmodel 0\n{}{screenshot}\nviewsize 100\nr_drawviewmodel 1\n",
        waits(2)
    );
    for (commands, frames) in PLAY {
        for command in *commands {
            script += command;
            script += "\n";
        }
        script += &waits(*frames);
    }
    script + "echo slipgate: played\n"
}

/// The player's state at the end of play.
struct PlayerReport {
    health: f32,
    rockets: f32,
}

impl PlayerReport {
    fn parse(kind: Kind, output: &str) -> Result<PlayerReport, String> {
        let missing = || "the player's state was not printed".to_string();
        match kind {
            // `edict 1` prints the player's fields, one a line, leaving out the zero ones.
            Kind::QuakeSpasm => {
                let fields = output
                    .split("EDICT 1:")
                    .nth(1)
                    .ok_or_else(missing)?
                    .lines()
                    .skip(1)
                    .take_while(|l| !l.trim().is_empty());
                let mut report = PlayerReport {
                    health: 0.0,
                    rockets: 0.0,
                };
                for line in fields {
                    let mut words = line.split_whitespace();
                    let (Some(key), Some(value)) = (words.next(), words.next()) else {
                        continue;
                    };
                    let value = value.parse().unwrap_or(0.0);
                    match key {
                        "health" => report.health = value,
                        "ammo_rockets" => report.rockets = value,
                        _ => {}
                    }
                }
                Ok(report)
            }
            Kind::DarkPlaces => {
                let line = output
                    .lines()
                    .find_map(|l| l.trim().strip_prefix("slipgate: health "))
                    .ok_or_else(missing)?;
                let words: Vec<&str> = line.split_whitespace().collect();
                match words[..] {
                    [health, "rockets", rockets] => Ok(PlayerReport {
                        health: health.parse().map_err(|_| missing())?,
                        rockets: rockets.parse().map_err(|_| missing())?,
                    }),
                    _ => Err(missing()),
                }
            }
        }
    }
}

/// The player's origin as QuakeSpasm's `edict 1` prints it (`origin  '  64.0  64.0  24.0'`).
fn player_origin(output: &str) -> Result<[f32; 3], String> {
    let missing = || "the player's origin was not printed".to_string();
    let fields = output.split("EDICT 1:").nth(1).ok_or_else(missing)?;
    let line = fields
        .lines()
        .find_map(|l| l.trim().strip_prefix("origin"))
        .ok_or_else(missing)?;
    let numbers: Vec<f32> = line
        .trim()
        .trim_matches('\'')
        .split_whitespace()
        .map(|w| w.parse().map_err(|_| missing()))
        .collect::<Result<_, _>>()?;
    numbers.try_into().map_err(|_| missing())
}

/// The server's game time as DarkPlaces' `prvm_global server time` prints it.
fn game_time(output: &str) -> Option<f32> {
    output
        .lines()
        .find_map(|l| l.trim().strip_prefix("time: "))
        .and_then(|t| t.trim().parse().ok())
}

/// A game directory for one run: `base/id1` links the game data, `base/NAME/maps` the map.
struct Game {
    base: PathBuf,
    /// Unique, so the engine's per-user directory (`~/.quakespasm/NAME`) is this run's alone.
    name: String,
    /// DarkPlaces' home directory (it writes under `$HOME/.darkplaces/NAME`); QuakeSpasm finds
    /// the home directory from the user database, whatever `HOME` says.
    home: PathBuf,
    kind: Kind,
    /// The player starts beyond what QuakeSpasm's default protocol can send.
    far_start: bool,
}

struct Run {
    ended: Ended,
    output: String,
    seconds: f64,
    log_dir: PathBuf,
}

impl Game {
    fn new(engine: &Engine, map: &Compiled, mode: &str) -> Game {
        let base = engine.runs.join(&map.name).join(mode);
        if base.exists() {
            std::fs::remove_dir_all(&base).expect("clear an old run");
        }
        let name = format!(
            "slipgate-{}-{}-{}-{mode}",
            std::process::id(),
            engine.kind.name(),
            map.name
        );
        let maps = base.join(&name).join("maps");
        std::fs::create_dir_all(&maps).expect("game dir");
        symlink(&engine.data, base.join("id1")).expect("link id1");
        symlink(&map.bsp, maps.join(format!("{}.bsp", map.name))).expect("link the BSP");
        if let Some(lit) = &map.lit {
            symlink(lit, maps.join(format!("{}.lit", map.name))).expect("link the .lit");
        }
        let far_start = map
            .start
            .is_some_and(|start| start.iter().any(|c| c.abs() >= PROTOCOL_666_LIMIT));
        let game = Game {
            home: base.join("home"),
            base,
            name,
            kind: engine.kind,
            far_start,
        };
        game.clear_user_dir();
        std::fs::create_dir_all(&game.home).expect("home dir");
        game
    }

    fn write_file(&self, file: &str, text: &str) {
        std::fs::write(self.base.join(&self.name).join(file), text).expect("write a script");
    }

    fn write_script(&self, text: &str) {
        self.write_file("slipgate.cfg", text);
    }

    fn engine_args(&self, kind: Kind) -> Vec<String> {
        let mut args = strings(&["-basedir", path_str(&self.base), "-game", &self.name]);
        if kind == Kind::QuakeSpasm && self.far_start {
            args.extend(strings(&["-protocol", "999"]));
        }
        args
    }

    /// Developer messages (limit warnings, "Server spawned."), then the script.
    fn script_args(&self) -> Vec<String> {
        strings(&["+developer", "1", "+exec", "slipgate.cfg"])
    }

    fn user_dir(&self) -> PathBuf {
        match self.kind {
            Kind::QuakeSpasm => user_home().join(".quakespasm").join(&self.name),
            Kind::DarkPlaces => self.home.join(".darkplaces").join(&self.name),
        }
    }

    fn clear_user_dir(&self) {
        std::fs::remove_dir_all(self.user_dir()).ok();
    }

    fn run(&self, program: &Path, args: &[String], env: &[(&str, &str)], limit: Duration) -> Run {
        let started = Instant::now();
        let (ended, output) = run(program, args, env, &self.home, &self.base, limit);
        Run {
            ended,
            output,
            seconds: started.elapsed().as_secs_f64(),
            log_dir: self.base.clone(),
        }
    }

    /// Move the screenshot the engine wrote into the run's directory.
    fn take_screenshot(&self) -> Result<PathBuf, String> {
        let dir = match self.kind {
            Kind::QuakeSpasm => self.user_dir(),
            Kind::DarkPlaces => self.user_dir().join("screenshots"),
        };
        let written = std::fs::read_dir(&dir)
            .ok()
            .and_then(|entries| {
                entries
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .find(|p| p.extension().is_some_and(|e| e == "tga"))
            })
            .ok_or_else(|| format!("no screenshot in {}", dir.display()))?;
        let shot = self.base.join("screenshot.tga");
        std::fs::rename(&written, &shot).map_err(|e| e.to_string())?;
        Ok(shot)
    }

    /// After a run that passed: remove the game directory (links and scripts) and DarkPlaces'
    /// home; the logs and the screenshot stay. (What the engine wrote under the user's home goes
    /// after every run, passed or not.)
    fn clean_up(&self) {
        std::fs::remove_dir_all(&self.home).ok();
        std::fs::remove_dir_all(self.base.join(&self.name)).ok();
        std::fs::remove_file(self.base.join("id1")).ok();
    }
}

/// The home directory QuakeSpasm writes under: the user database's (it asks `getpwuid`), whatever
/// `HOME` says; `HOME` only when the database has no entry for this user.
fn user_home() -> PathBuf {
    let uid = std::fs::metadata("/proc/self").map(|m| m.uid()).ok();
    let passwd = std::fs::read_to_string("/etc/passwd").unwrap_or_default();
    let from_database = passwd.lines().find_map(|line| {
        let fields: Vec<&str> = line.split(':').collect();
        let line_uid = fields.get(2)?.parse::<u32>().ok();
        let home = fields.get(5)?;
        (line_uid.is_some() && line_uid == uid).then(|| PathBuf::from(home))
    });
    from_database
        .or_else(|| std::env::var_os("HOME").map(PathBuf::from))
        .expect("a home directory")
}

impl Run {
    /// `Ok` when the engine exited with status 0, printed every `required` line, no fatal message
    /// and no BSP fault.
    fn check(&self, required: &[&str]) -> Result<(), String> {
        let mut problems = Vec::new();
        match &self.ended {
            Ended::Exited(status) => {
                if let Some(problem) = exit_problem(*status) {
                    problems.push(problem);
                }
            }
            Ended::StoppedAfterFatal => {
                problems.push("stopped by the test after a fatal error".to_string())
            }
            Ended::TimedOut(limit) => problems.push(format!("timed out after {limit:?}")),
        }
        for line in self.output.lines() {
            if FATAL.iter().chain(BSP_FAULTS).any(|s| line.contains(s)) {
                problems.push(line.trim().to_string());
            }
        }
        for line in required {
            if !self.output.contains(line) {
                problems.push(format!("never printed {line:?}"));
            }
        }
        if problems.is_empty() {
            return Ok(());
        }
        Err(self.fail(&problems.join("\n  ")))
    }

    fn fail(&self, problem: &str) -> String {
        let tail: Vec<&str> = self.output.lines().rev().take(40).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        format!(
            "{problem}\n  --- last lines of the engine's output (all of it in {}) ---\n{}",
            self.log_dir.display(),
            tail.join("\n")
        )
    }

    fn outcome(
        &self,
        game_time: Option<f32>,
        screenshot: Option<PathBuf>,
        view_colours: Option<usize>,
    ) -> Outcome {
        Outcome {
            seconds: self.seconds,
            game_time,
            screenshot,
            view_colours,
            notes: notes(&self.output),
        }
    }
}

/// What is wrong with an engine's exit status, if anything. `xvfb-run` exits with its command's
/// status, which a shell reports as 128 + the signal for a command killed by one.
pub fn exit_problem(status: ExitStatus) -> Option<String> {
    if let Some(signal) = status.signal() {
        return Some(format!(
            "killed by signal {signal} ({})",
            signal_name(signal)
        ));
    }
    match status.code() {
        Some(0) => None,
        Some(code) if code > 128 => Some(format!(
            "killed by signal {} ({}) (exit status {code})",
            code - 128,
            signal_name(code - 128)
        )),
        Some(code) => Some(format!("exit status {code}")),
        None => Some(format!("{status}")),
    }
}

fn signal_name(signal: i32) -> &'static str {
    match signal {
        4 => "SIGILL",
        6 => "SIGABRT",
        7 => "SIGBUS",
        8 => "SIGFPE",
        9 => "SIGKILL",
        11 => "SIGSEGV",
        15 => "SIGTERM",
        _ => "signal",
    }
}

/// The lines matching [`NOTES`], those that differ only in numbers (entity numbers,
/// coordinates) counted as one.
fn notes(output: &str) -> Vec<String> {
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for line in output.lines() {
        if NOTES.iter().any(|n| line.contains(n)) {
            *counts.entry(without_numbers(line.trim())).or_default() += 1;
        }
    }
    counts
        .into_iter()
        .map(|(line, n)| {
            if n > 1 {
                format!("{line} (x{n})")
            } else {
                line
            }
        })
        .collect()
}

/// `line` with each run of digits replaced by `#`.
fn without_numbers(line: &str) -> String {
    let mut text = String::with_capacity(line.len());
    for c in line.chars() {
        if !c.is_ascii_digit() {
            text.push(c);
        } else if !text.ends_with('#') {
            text.push('#');
        }
    }
    text
}

/// Run `program` in its own process group (killed whole when stopped: `xvfb-run` starts the X
/// server and the engine as children) with output to files in `dir`. Stops it a little after it
/// prints a fatal message (a client may carry on with the console up) or at `limit`.
fn run(
    program: &Path,
    args: &[String],
    env: &[(&str, &str)],
    home: &Path,
    dir: &Path,
    limit: Duration,
) -> (Ended, String) {
    let (stdout, stderr) = (dir.join("stdout.txt"), dir.join("stderr.txt"));
    let mut child = Command::new(program)
        .args(args)
        .envs(env.iter().copied())
        .env("HOME", home)
        .stdin(Stdio::null())
        .stdout(File::create(&stdout).expect("log"))
        .stderr(File::create(&stderr).expect("log"))
        .process_group(0)
        .spawn()
        .unwrap_or_else(|e| panic!("start {}: {e}", program.display()));
    let read = || {
        let text = |p: &Path| std::fs::read_to_string(p).unwrap_or_default();
        text(&stdout) + &text(&stderr)
    };
    let started = Instant::now();
    let mut fatal_at: Option<Instant> = None;
    let mut polls = 0u32;
    let ended = loop {
        if let Some(status) = child.try_wait().expect("wait for the engine") {
            break Ended::Exited(status);
        }
        polls += 1;
        if fatal_at.is_none()
            && polls.is_multiple_of(25)
            && FATAL.iter().any(|s| read().contains(s))
        {
            fatal_at = Some(Instant::now());
        }
        let grace_over = fatal_at.is_some_and(|t| t.elapsed() > Duration::from_secs(2));
        if grace_over || started.elapsed() > limit {
            stop(&mut child);
            break if grace_over {
                Ended::StoppedAfterFatal
            } else {
                Ended::TimedOut(limit)
            };
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    (ended, read())
}

/// TERM the process group first (Xvfb then removes its lock file), then KILL it. The child is
/// reaped only after, so its group id cannot be reused meanwhile.
fn stop(child: &mut std::process::Child) {
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
}

/// The first X display number `xvfb-run -a` tries: distinct per run within this process, and
/// spread by process id across processes, so runs at once do not race for the same number.
fn next_display() -> u32 {
    static NEXT: AtomicU32 = AtomicU32::new(0);
    200 + std::process::id() % 400 * 16 + NEXT.fetch_add(1, Ordering::Relaxed) % 16
}

/// A UDP port nothing holds right now (the OS picks it; the socket closes before the engine
/// binds it, a race no other run of ours takes part in).
fn free_udp_port() -> u16 {
    std::net::UdpSocket::bind("127.0.0.1:0")
        .and_then(|s| s.local_addr())
        .map(|a| a.port())
        .unwrap_or(26000)
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_count_lines_that_differ_in_numbers_as_one() {
        let output = "warning: empty submodel *7 in maps/e1m3.bsp\n\
                      warning: empty submodel *15 in maps/e1m3.bsp\n\
                      Server spawned.\n\
                      walkmonster in wall at: '1712.0 -480.0 256.0'\n";
        assert_eq!(
            notes(output),
            [
                "walkmonster in wall at: '#.# -#.# #.#'",
                "warning: empty submodel *# in maps/e#m#.bsp (x2)",
            ]
        );
    }

    #[test]
    fn each_engine_reports_the_players_state_its_own_way() {
        let quakespasm = "EDICT 1:\nmodelindex 4.0\nhealth         100.0\nammo_rockets    98.0\n\n";
        let player = PlayerReport::parse(Kind::QuakeSpasm, quakespasm).expect("parse");
        assert_eq!((player.health, player.rockets), (100.0, 98.0));
        let darkplaces = "slipgate: health 100 rockets 96 \ntime: 11.1\n";
        let player = PlayerReport::parse(Kind::DarkPlaces, darkplaces).expect("parse");
        assert_eq!((player.health, player.rockets), (100.0, 96.0));
        assert_eq!(game_time(darkplaces), Some(11.1));
        assert!(PlayerReport::parse(Kind::QuakeSpasm, "no edicts").is_err());
    }

    #[test]
    fn quakespasm_prints_the_players_origin_as_a_quoted_vector() {
        let output = "EDICT 1:\nmodelindex 4.0\norigin        ' 991.9  64.0  24.0'\n";
        assert_eq!(player_origin(output), Ok([991.9, 64.0, 24.0]));
        assert!(player_origin("EDICT 1:\nhealth 100.0\n").is_err());
    }
}
