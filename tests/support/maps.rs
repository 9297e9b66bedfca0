//! The maps the engine tests play, compiled as a mapper would: `slipgate bsp`, `vis`, `light`.
//!
//! A [`MapSet`] compiles each map once, on first use, whichever test asks first: the tests of both
//! engines walk the same set in the same order, and each asks for the next map in the background
//! while it plays the current one, so compiling overlaps playing.

use quake_formats::Bsp;
use quake_formats::entities::parse_entities;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Instant;

/// A map to compile and play.
pub struct Case {
    /// The name the engine loads it by (`maps/NAME.bsp`).
    pub name: String,
    pub map: PathBuf,
    /// Where `slipgate bsp` looks for the map's WADs.
    pub wad_dirs: Vec<PathBuf>,
    pub bsp_options: &'static [&'static str],
    /// Options for `slipgate light` (before the BSP).
    pub light_options: &'static [&'static str],
    /// A compile failure is expected for some (`maps/hard/`): it skips the map, saying so,
    /// instead of failing.
    pub may_fail_to_compile: bool,
    /// Why the view from the player start shows (next to) nothing, for the rare map built so:
    /// its screenshot need not be textured.
    pub empty_view: Option<&'static str>,
    /// An engine known to refuse the map, and the words of its error: a bug found and not yet
    /// fixed, reported as a note instead of a failure while the engine says exactly that.
    pub known_error: Option<KnownError>,
}

/// See [`Case::known_error`].
#[derive(Clone, Copy)]
pub struct KnownError {
    pub engine: &'static str,
    pub message: &'static str,
}

impl Case {
    pub fn new(map: PathBuf, wad_dirs: Vec<PathBuf>) -> Case {
        let name = map.file_stem().and_then(|s| s.to_str()).expect("map name");
        Case {
            name: name.to_string(),
            map,
            wad_dirs,
            bsp_options: &[],
            light_options: &[],
            may_fail_to_compile: false,
            empty_view: None,
            known_error: None,
        }
    }
}

/// A compiled map, ready to play.
#[derive(Clone)]
pub struct Compiled {
    pub name: String,
    pub bsp: PathBuf,
    /// The coloured light file beside the BSP, when light wrote one.
    pub lit: Option<PathBuf>,
    /// Where the player starts (the first `info_player_start`).
    pub start: Option<[f64; 3]>,
    /// "full" or why it was not.
    pub vis: &'static str,
    /// Wall time of the three stages.
    pub seconds: f64,
    /// See [`Case::empty_view`].
    pub empty_view: Option<&'static str>,
    /// See [`Case::known_error`].
    pub known_error: Option<KnownError>,
}

/// Why a map was not played.
pub enum NotCompiled {
    /// A map allowed to fail to compile did: skip it.
    Skipped(String),
    Failed(String),
}

pub struct MapSet {
    cases: Vec<Case>,
    compiled: Vec<OnceLock<Result<Compiled, NotCompiled>>>,
    dir: PathBuf,
}

impl MapSet {
    pub fn new(cases: Vec<Case>, dir: PathBuf) -> MapSet {
        let mut names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
        names.sort();
        names.dedup();
        assert_eq!(
            names.len(),
            cases.len(),
            "two maps of one name: they would share a BSP"
        );
        std::fs::create_dir_all(&dir).expect("scratch dir");
        let compiled = cases.iter().map(|_| OnceLock::new()).collect();
        MapSet {
            cases,
            compiled,
            dir,
        }
    }

    pub fn len(&self) -> usize {
        self.cases.len()
    }

    pub fn name(&self, index: usize) -> &str {
        &self.cases[index].name
    }

    /// Map `index`, compiled now unless it already was (or another test is compiling it, in
    /// which case this waits for that).
    pub fn get(&self, index: usize) -> &Result<Compiled, NotCompiled> {
        self.compiled[index].get_or_init(|| compile(&self.cases[index], &self.dir))
    }

    /// Start compiling map `index` in the background, if there is one.
    pub fn prefetch(&'static self, index: usize) {
        if index < self.len() {
            std::thread::spawn(move || {
                self.get(index);
            });
        }
    }
}

fn compile(case: &Case, dir: &Path) -> Result<Compiled, NotCompiled> {
    let started = Instant::now();
    let bsp = dir.join(format!("{}.bsp", case.name));
    let bsp_arg = path_str(&bsp);
    let mut bsp_args = vec!["bsp"];
    for wads in &case.wad_dirs {
        bsp_args.extend(["--wad-dir", path_str(wads)]);
    }
    bsp_args.extend(case.bsp_options);
    bsp_args.extend([path_str(&case.map), bsp_arg]);
    slipgate(&bsp_args).map_err(|e| {
        if case.may_fail_to_compile {
            NotCompiled::Skipped(e)
        } else {
            NotCompiled::Failed(e)
        }
    })?;
    // Full vis, as a mapper ships a map: the release build does it in seconds on every corpus
    // map. A leaking map (its pointfile written) gets no portal file and no vis: engines draw
    // it whole.
    let leaked = bsp.with_extension("pts").exists();
    if !leaked {
        slipgate(&["vis", bsp_arg]).map_err(NotCompiled::Failed)?;
    }
    let mut light_args = vec!["light"];
    light_args.extend(case.light_options);
    light_args.push(bsp_arg);
    slipgate(&light_args).map_err(NotCompiled::Failed)?;

    let bytes = std::fs::read(&bsp).expect("read the BSP");
    let text = Bsp::read(&bytes)
        .map(|b| String::from_utf8_lossy(&b.entities).into_owned())
        .unwrap_or_default();
    let entities = parse_entities(&text).unwrap_or_default();
    let start = entities
        .iter()
        .find(|e| e.classname() == "info_player_start")
        .and_then(|e| e.get_floats::<3>("origin"));
    let lit = Some(bsp.with_extension("lit")).filter(|p| p.exists());
    Ok(Compiled {
        name: case.name.clone(),
        bsp,
        lit,
        start,
        vis: if leaked { "none (leaks)" } else { "full" },
        seconds: started.elapsed().as_secs_f64(),
        empty_view: case.empty_view,
        known_error: case.known_error,
    })
}

fn slipgate(args: &[&str]) -> Result<(), String> {
    let out = Command::new(env!("CARGO_BIN_EXE_slipgate"))
        .args(args)
        .output()
        .expect("run slipgate");
    if out.status.success() {
        return Ok(());
    }
    Err(format!(
        "slipgate {} failed ({}):\n{}",
        args.join(" "),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    ))
}

pub fn path_str(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}
