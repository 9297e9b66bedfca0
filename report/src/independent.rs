//! `slipgate report --independent`: both light tools against an independent reference.
//!
//! Each map's benchmark form (`bench/independent/benchmark_map.py`) is compiled and fully vised by
//! ericw-tools' `qbsp` and `vis`; Slipgate's and ericw-tools' `light` then light copies of that
//! one BSP at each setting, interleaved, N times (the best wall time counts); and the last BSP of
//! each is judged by `bench/independent/reference.py`, a physical model traced with Mitsuba 3
//! that shares no code with Slipgate's light. Python 3 with `mitsuba` and `numpy` runs the
//! scripts: the report says so plainly when they are missing.
//!
//! Output: `independent.md`, `independent.json`, `independent.html` and one plot of error against
//! time with both tools' points (`light-independent.svg`, `.png`).

use std::path::{Path, PathBuf};
use std::process::Command;

use quake_formats::miptex::MipTex;
use quake_formats::wad::{Wad, WadLump};

use crate::plot::PlotFile;
use crate::process::{Timing, run_timed};
use crate::run::{
    MapWork, Timings, absolute, absolute_all, link_wad_dirs, map_work, progress_bar, record,
    write_json, write_report_file,
};
use crate::settings::Tool;
use crate::{Machine, ReportError};

/// What to measure and where to write it.
#[derive(Debug, Clone)]
pub struct IndependentOptions {
    /// The `.map` files whose benchmark forms are measured.
    pub maps: Vec<PathBuf>,
    /// Where the report, its plot and the maps' work folders go.
    pub out_dir: PathBuf,
    /// Each light runs this many times; the best wall time counts.
    pub runs: usize,
    /// ericw-tools' `bin` folder (`qbsp`, `vis`, `light`).
    pub anchor: PathBuf,
    /// The `slipgate` binary whose light is timed.
    pub slipgate: PathBuf,
    /// Folders searched for the WADs maps name.
    pub wad_dirs: Vec<PathBuf>,
    /// The folder holding `benchmark_map.py` and `reference.py`.
    pub scripts: PathBuf,
    /// The Python 3 interpreter that runs them.
    pub python: PathBuf,
    /// Whether the timed binary is a release build (said in the header).
    pub release: bool,
    /// Draw a progress bar on stderr (only when it is a terminal).
    pub progress: bool,
}

/// One light setting as each tool spells it.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LightSetting {
    /// The setting's name in tables: `default` or ericw-tools' options.
    pub name: String,
    /// Slipgate's options.
    pub ours: Vec<String>,
    /// ericw-tools' options.
    pub theirs: Vec<String>,
}

/// The settings measured: each tool's default, and its best sampling with the blur mappers
/// release with.
pub fn light_settings() -> Vec<LightSetting> {
    let strings = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    vec![
        LightSetting {
            name: "default".into(),
            ours: vec![],
            theirs: vec![],
        },
        LightSetting {
            name: "-extra4 -soft".into(),
            ours: strings(&["--extra4", "--soft"]),
            theirs: strings(&["-extra4", "-soft"]),
        },
    ]
}

/// What `reference.py` found for one lit BSP (its `--json`).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ReferenceFigures {
    /// Area-weighted RMS difference from the reference over the drawn luxels, in 8-bit levels.
    pub rmse: f64,
    /// Drawn luxels judged.
    pub drawn_luxels: usize,
    /// The reference's own Monte Carlo standard error, RMS over the same luxels.
    pub noise: f64,
    /// Mean of the lightmap minus the reference.
    pub bias: f64,
    /// Every Nth lightmapped face was judged; this is N.
    pub every: usize,
    /// Faces judged.
    pub faces: usize,
    /// Seconds the reference took to compute (it is cached per BSP, so one tool's run pays).
    pub reference_seconds: f64,
}

/// One tool at one setting on one map.
#[derive(Debug, Clone, serde::Serialize)]
pub struct IndependentRow {
    /// The map's name (its file name without extension).
    pub map: String,
    /// The setting's name, as in [`LightSetting::name`].
    pub setting: String,
    /// Whose light ran.
    pub tool: Tool,
    /// Best of the runs by wall time; `None` when every run failed.
    pub timing: Option<Timing>,
    /// The lightmap judged by the reference; `None` when lighting or judging failed.
    pub figures: Option<ReferenceFigures>,
    /// Why the step or its judgement failed.
    pub failure: Option<String>,
}

/// Everything one `--independent` report measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct IndependentReport {
    /// The machine it ran on.
    pub machine: Machine,
    /// Runs of every light; the best counts.
    pub runs: usize,
    /// Whether the timed binary was a release build.
    pub release: bool,
    /// ericw-tools' `bin` folder.
    pub anchor: PathBuf,
    /// The maps measured (their sources; each is measured in benchmark form).
    pub maps: Vec<PathBuf>,
    /// The settings measured.
    pub settings: Vec<LightSetting>,
    /// Every tool at every setting on every map.
    pub rows: Vec<IndependentRow>,
}

/// Why Python cannot run the reference, or `None` when it can: the interpreter, Mitsuba 3 with
/// its `llvm_ad_rgb` variant, and numpy.
pub fn python_problem(python: &Path) -> Option<String> {
    let out = Command::new(python)
        .args([
            "-c",
            "import numpy, mitsuba; mitsuba.set_variant('llvm_ad_rgb')",
        ])
        .output();
    match out {
        Err(e) => Some(format!(
            "Python 3 (`{}`) could not be run ({e}); --independent needs it with Mitsuba 3 and \
             numpy: pip install mitsuba numpy",
            python.display()
        )),
        Ok(o) if !o.status.success() => {
            let err = String::from_utf8_lossy(&o.stderr);
            let last = err.lines().last().unwrap_or("").trim().to_string();
            Some(format!(
                "Python (`{}`) cannot run the independent reference: Mitsuba 3 with its \
                 llvm_ad_rgb variant and numpy are needed (pip install mitsuba numpy; the variant \
                 needs libLLVM): {last}",
                python.display()
            ))
        }
        Ok(_) => None,
    }
}

/// Runs the whole `--independent` report and writes its files into `options.out_dir`.
pub fn run(options: &IndependentOptions) -> Result<IndependentReport, ReportError> {
    if options.maps.is_empty() {
        return Err(ReportError::NoMaps);
    }
    let anchor_as_given = options.anchor.clone();
    let options = &IndependentOptions {
        maps: absolute_all(&options.maps)?,
        wad_dirs: absolute_all(&options.wad_dirs)?,
        out_dir: absolute(&options.out_dir)?,
        slipgate: absolute(&options.slipgate)?,
        anchor: absolute(&options.anchor)?,
        scripts: absolute(&options.scripts)?,
        ..options.clone()
    };
    for script in [BENCHMARK_SCRIPT, REFERENCE_SCRIPT] {
        let path = options.scripts.join(script);
        if !path.is_file() {
            return Err(ReportError::Measure {
                path,
                what: "the independent reference's script is missing (run from the project's \
                       root, or give --scripts)"
                    .into(),
            });
        }
    }
    if let Some(problem) = python_problem(&options.python) {
        return Err(ReportError::Measure {
            path: options.python.clone(),
            what: problem,
        });
    }
    let work_root = options.out_dir.join("work-independent");
    std::fs::create_dir_all(&work_root).map_err(ReportError::io(&work_root))?;
    link_wad_dirs(&options.wad_dirs, &work_root)?;
    let maps = map_work(&options.maps, &work_root)?;
    let settings = light_settings();
    let tools = [Tool::Slipgate, Tool::EricwTools];
    let runs = options.runs.max(1);
    let progress = progress_bar(
        options.progress,
        (maps.len() * (1 + settings.len() * tools.len() * (runs + 1))) as u64,
    );
    let load_start = crate::machine::load_average();

    let mut compiled: Vec<Result<PathBuf, String>> = Vec::new();
    for map in &maps {
        progress.set_message(format!("compiling the benchmark form of {}", map.name));
        compiled.push(compile(options, map, &work_root).map_err(|e| e.to_string()));
        progress.inc(1);
    }
    let mut timings = Timings::new();
    for run in 0..runs {
        for (m, map) in maps.iter().enumerate() {
            for (s, setting) in settings.iter().enumerate() {
                for &tool in &tools {
                    progress.set_message(format!(
                        "run {}/{runs}: {} light {} ({})",
                        run + 1,
                        map.name,
                        setting.name,
                        tool.name()
                    ));
                    let result = match &compiled[m] {
                        Ok(bsp) => light_once(options, map, bsp, setting, s, tool),
                        Err(e) => Err(ReportError::Measure {
                            path: map.source.clone(),
                            what: format!("compiling its benchmark form failed: {e}"),
                        }),
                    };
                    record(&mut timings, (m, s, tool), result);
                    progress.inc(1);
                }
            }
        }
    }
    let mut rows = Vec::new();
    for (m, map) in maps.iter().enumerate() {
        for (s, setting) in settings.iter().enumerate() {
            for &tool in &tools {
                progress.set_message(format!(
                    "judging {} light {} ({})",
                    map.name,
                    setting.name,
                    tool.name()
                ));
                let timing = timings
                    .get(&(m, s, tool))
                    .cloned()
                    .unwrap_or_else(|| Err("not run".into()));
                let figures = match &timing {
                    Ok(_) => judge(options, &lit_bsp(map, s, tool)).map_err(|e| e.to_string()),
                    Err(e) => Err(e.clone()),
                };
                rows.push(IndependentRow {
                    map: map.name.clone(),
                    setting: setting.name.clone(),
                    tool,
                    timing: timing.as_ref().ok().copied(),
                    failure: figures.as_ref().err().cloned(),
                    figures: figures.ok(),
                });
                progress.inc(1);
            }
        }
    }
    progress.finish_and_clear();
    let mut machine = Machine::probe(
        &options.slipgate,
        compiled.iter().flatten().next().map(PathBuf::as_path),
        &work_root.join("isa-probe.bsp"),
    );
    machine.load_start = load_start;
    machine.load_end = crate::machine::load_average();
    let report = IndependentReport {
        machine,
        runs,
        release: options.release,
        anchor: anchor_as_given,
        maps: options.maps.clone(),
        settings,
        rows,
    };
    write_files(&report, &options.out_dir)?;
    Ok(report)
}

const BENCHMARK_SCRIPT: &str = "benchmark_map.py";
const REFERENCE_SCRIPT: &str = "reference.py";
/// A placeholder texture's side in texels, and its palette index (a mid grey).
const PLACEHOLDER_SIZE: u32 = 16;
const PLACEHOLDER_INDEX: u8 = 8;

/// The map's benchmark form, compiled and fully vised by ericw-tools: the BSP both tools light.
fn compile(
    options: &IndependentOptions,
    map: &MapWork,
    work_root: &Path,
) -> Result<PathBuf, ReportError> {
    let bench_map = map.dir.join(format!("{}.map", map.name));
    let mut c = Command::new(&options.python);
    c.arg(options.scripts.join(BENCHMARK_SCRIPT))
        .arg(&map.source)
        .arg(&bench_map);
    run_timed(&mut c, &map.dir.join("benchmark.log"))?;
    let mut qbsp = Command::new(options.anchor.join("qbsp"));
    let text = std::fs::read(&bench_map).map_err(ReportError::io(&bench_map))?;
    let text = String::from_utf8_lossy(&text);
    if wads_found(&text, &options.wad_dirs) {
        // each folder as it is (for WADs named by file name) and through its link (for
        // LibreQuake's relative paths: see `link_wad_dirs`)
        for (i, dir) in options.wad_dirs.iter().enumerate() {
            qbsp.arg("-wadpath").arg(dir);
            qbsp.arg("-wadpath")
                .arg(work_root.join(format!("wp{i}/a/b/c/d")));
        }
    } else {
        // The map's WADs are not here (id's are not free): a grey placeholder under each of its
        // texture names, which is what light needs of them (liquids and sky go by name).
        let wad = map.dir.join("placeholder.wad");
        write_placeholder_wad(&texture_names(&text), &wad)?;
        let with_wad = set_wad_key(&text, &wad);
        quake_formats::fsutil::write_atomic(&bench_map, with_wad.as_bytes()).map_err(|source| {
            ReportError::Format {
                path: bench_map.clone(),
                source,
            }
        })?;
    }
    qbsp.arg(&bench_map).current_dir(&map.dir);
    run_timed(&mut qbsp, &map.dir.join("qbsp.log"))?;
    let bsp = bench_map.with_extension("bsp");
    let mut vis = Command::new(options.anchor.join("vis"));
    vis.arg(&bsp).current_dir(&map.dir);
    run_timed(&mut vis, &map.dir.join("vis.log"))?;
    Ok(bsp)
}

/// Whether any WAD the map's worldspawn names is in one of the folders.
fn wads_found(map_text: &str, wad_dirs: &[PathBuf]) -> bool {
    let Some(value) = worldspawn_wad(map_text) else {
        return false;
    };
    value
        .split(';')
        .filter_map(|w| Path::new(w.trim()).file_name())
        .any(|name| wad_dirs.iter().any(|d| d.join(name).is_file()))
}

/// The value of the first `"wad"` key (worldspawn's, the map's first entity).
fn worldspawn_wad(map_text: &str) -> Option<&str> {
    map_text.lines().find_map(|line| {
        let rest = line.trim().strip_prefix("\"wad\"")?;
        let rest = rest.trim().strip_prefix('"')?;
        rest.strip_suffix('"')
    })
}

/// The map with its `"wad"` key naming `wad` alone (added to worldspawn when it has none).
fn set_wad_key(map_text: &str, wad: &Path) -> String {
    let key = format!("\"wad\" \"{}\"", wad.display());
    let has_key = worldspawn_wad(map_text).is_some();
    let mut out = String::with_capacity(map_text.len() + key.len() + 1);
    let mut done = false;
    for line in map_text.lines() {
        if !done && has_key && line.trim().starts_with("\"wad\"") {
            out += &key;
            done = true;
        } else {
            out += line;
            if !done && !has_key && line.trim() == "{" {
                out += "\n";
                out += &key;
                done = true;
            }
        }
        out += "\n";
    }
    out
}

/// Every texture name a map's brush faces use: the word after a face's three points.
fn texture_names(map_text: &str) -> Vec<String> {
    let mut names: Vec<String> = map_text
        .lines()
        .filter(|l| l.trim_start().starts_with('('))
        .filter_map(|l| {
            let mut rest = l;
            for _ in 0..3 {
                rest = &rest[rest.find(')')? + 1..];
            }
            rest.split_whitespace().next().map(str::to_string)
        })
        .collect();
    names.sort();
    names.dedup();
    names
}

/// A WAD of flat grey textures under the given names.
fn write_placeholder_wad(names: &[String], path: &Path) -> Result<(), ReportError> {
    let lumps = names
        .iter()
        .map(|name| {
            let mips = std::array::from_fn(|level| {
                vec![PLACEHOLDER_INDEX; MipTex::mip_len(PLACEHOLDER_SIZE, PLACEHOLDER_SIZE, level)]
            });
            WadLump::miptex(MipTex::new(name, PLACEHOLDER_SIZE, PLACEHOLDER_SIZE, mips))
        })
        .collect();
    quake_formats::fsutil::write_atomic(path, &Wad::new(lumps).write()).map_err(|source| {
        ReportError::Format {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// Where one tool's light of one setting writes.
fn lit_bsp(map: &MapWork, setting: usize, tool: Tool) -> PathBuf {
    let tool = match tool {
        Tool::Slipgate => "slipgate",
        Tool::EricwTools => "ericw",
    };
    map.dir
        .join(format!("{tool}-{setting}"))
        .join(format!("{}.bsp", map.name))
}

/// Lights a fresh copy of `bsp` once with one tool at one setting, timed.
fn light_once(
    options: &IndependentOptions,
    map: &MapWork,
    bsp: &Path,
    setting: &LightSetting,
    index: usize,
    tool: Tool,
) -> Result<Timing, ReportError> {
    let out = lit_bsp(map, index, tool);
    let dir = out.parent().unwrap_or(&map.dir).to_path_buf();
    std::fs::create_dir_all(&dir).map_err(ReportError::io(&dir))?;
    std::fs::copy(bsp, &out).map_err(ReportError::io(bsp))?;
    // a .lit left by an earlier run would be judged with this run's lightmap
    let lit = out.with_extension("lit");
    if lit.exists() {
        std::fs::remove_file(&lit).map_err(ReportError::io(&lit))?;
    }
    let mut c = match tool {
        Tool::Slipgate => {
            let mut c = Command::new(&options.slipgate);
            c.arg("light").args(&setting.ours);
            c
        }
        Tool::EricwTools => {
            let mut c = Command::new(options.anchor.join("light"));
            c.args(&setting.theirs);
            c
        }
    };
    c.arg(&out).current_dir(&dir);
    run_timed(&mut c, &out.with_extension("log"))
}

/// `reference.py`'s figures for one lit BSP.
fn judge(options: &IndependentOptions, lit: &Path) -> Result<ReferenceFigures, ReportError> {
    let json = lit.with_extension("reference.json");
    let mut c = Command::new(&options.python);
    c.arg(options.scripts.join(REFERENCE_SCRIPT))
        .arg("--quiet")
        .arg("--json")
        .arg(&json)
        .arg(lit);
    run_timed(&mut c, &lit.with_extension("reference.log"))?;
    let text = std::fs::read_to_string(&json).map_err(ReportError::io(&json))?;
    serde_json::from_str(&text).map_err(|e| ReportError::Measure {
        path: json,
        what: e.to_string(),
    })
}

/// independent.json, independent.md, the plot and independent.html.
fn write_files(report: &IndependentReport, out_dir: &Path) -> Result<(), ReportError> {
    let write = |name: &str, bytes: &[u8]| write_report_file(out_dir, name, bytes);
    write_json(report, out_dir, "independent.json")?;
    let plot = crate::plot::draw_independent(report, out_dir)?;
    let markdown = render_markdown(report, plot.as_ref());
    write("independent.md", markdown.as_bytes())?;
    let html = crate::html::page(
        "Slipgate: light against an independent reference",
        &header(report),
        &markdown,
        plot.as_slice(),
    );
    write("independent.html", html.as_bytes())?;
    Ok(())
}

/// The header paragraph: when, where, how.
pub fn header(report: &IndependentReport) -> String {
    let m = &report.machine;
    let build = if report.release {
        "Release build"
    } else {
        "DEBUG build (times are not representative; run `cargo run --release -- report`)"
    };
    format!(
        "{date}, {cpu} ({cores} cores); load average {start} at the start, {end} at the end. \
         {build}. Each map's benchmark form (`bench/independent/benchmark_map.py`: inverse-square \
         point lights with Lambert's law, no minlight, dirt or jitter; spotlights, sun and sky \
         kept) is compiled and fully vised by ericw-tools from `{anchor}`; both tools light \
         copies of that BSP, interleaved, best of {runs} runs by wall time (whole process). The \
         error is `bench/independent/reference.py`'s: the area-weighted RMS difference, in 8-bit \
         levels, between each drawn luxel's style-0 light and its mean irradiance over its \
         footprint, computed with Mitsuba 3 by code that shares nothing with Slipgate's light \
         (its README says how).",
        date = m.date,
        cpu = m.cpu,
        cores = m.cores,
        start = m.load_start,
        end = m.load_end,
        anchor = report.anchor.display(),
        runs = report.runs,
    )
}

/// `independent.md`: the header, one row per map and setting with both tools side by side.
pub fn render_markdown(report: &IndependentReport, plot: Option<&PlotFile>) -> String {
    use std::fmt::Write;
    let mut s = String::from("# Slipgate: light against an independent reference\n\n");
    s += &header(report);
    s += "\n\nWritten by `slipgate report --independent`; every figure is also in \
          `independent.json`.\n\n## light\n\n";
    s += "| map | setting | Slipgate: time | Slipgate: error | ericw-tools: time | \
          ericw-tools: error | ericw-tools' time / Slipgate's | reference noise | judged |\n";
    s += "|---|---|---|---|---|---|---|---|---|\n";
    let find = |map: &str, setting: &str, tool: Tool| {
        report
            .rows
            .iter()
            .find(|r| r.map == map && r.setting == setting && r.tool == tool)
    };
    let mut names: Vec<&str> = Vec::new();
    for r in &report.rows {
        if !names.contains(&r.map.as_str()) {
            names.push(&r.map);
        }
    }
    for map in names {
        for setting in &report.settings {
            let ours = find(map, &setting.name, Tool::Slipgate);
            let theirs = find(map, &setting.name, Tool::EricwTools);
            let time = |r: Option<&IndependentRow>| {
                r.and_then(|r| r.timing)
                    .map_or("-".into(), |t| format!("{:.3} s", t.wall_seconds))
            };
            let error = |r: Option<&IndependentRow>| {
                r.and_then(|r| r.figures.as_ref())
                    .map_or("failed".into(), |f| format!("{:.3}", f.rmse))
            };
            let ratio = match (ours.and_then(|r| r.timing), theirs.and_then(|r| r.timing)) {
                (Some(a), Some(b)) if a.wall_seconds > 0.0 => {
                    format!("{:.1}x", b.wall_seconds / a.wall_seconds)
                }
                _ => "-".into(),
            };
            let judged = ours.or(theirs).and_then(|r| r.figures.as_ref()).map_or(
                ("-".into(), "-".into()),
                |f| {
                    (
                        format!("{:.3}", f.noise),
                        format!(
                            "{} luxels, every {} face ({} faces); reference {:.0} s",
                            f.drawn_luxels,
                            ordinal(f.every),
                            f.faces,
                            f.reference_seconds
                        ),
                    )
                },
            );
            let _ = writeln!(
                s,
                "| {map} | {} | {} | {} | {} | {} | {ratio} | {} | {} |",
                setting.name,
                time(ours),
                error(ours),
                time(theirs),
                error(theirs),
                judged.0,
                judged.1
            );
        }
    }
    if let Some(p) = plot {
        let _ = write!(
            s,
            "\n![light: time against error, both tools]({}) ([SVG]({}))\n",
            p.png, p.svg
        );
    }
    let failures: Vec<&IndependentRow> =
        report.rows.iter().filter(|r| r.failure.is_some()).collect();
    if !failures.is_empty() {
        s += "\n## Failures\n\n";
        for r in failures {
            let why = r.failure.as_deref().unwrap_or_default();
            let why = why.lines().collect::<Vec<_>>().join(" / ");
            let _ = writeln!(s, "- {} {} ({}): {why}", r.map, r.setting, r.tool.name());
        }
    }
    s
}

/// `1st`, `2nd`, `5th`: how often a subset's faces come.
fn ordinal(n: usize) -> String {
    let suffix = match (n % 10, n % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

#[cfg(test)]
mod tests {
    use super::*;

    const MAP: &str = "// entity 0\n{\n\"classname\" \"worldspawn\"\n\"wad\" \"../wads/base.wad;gfx.wad\"\n\
                       {\n( 0 0 0 ) ( 0 1 0 ) ( 0 0 1 ) *water1 0 0 0 1 1\n\
                       ( 0 0 0 ) ( 1 0 0 ) ( 0 0 1 ) {fence [ 1 0 0 0 ] [ 0 1 0 0 ] 0 1 1\n\
                       ( 0 0 0 ) ( 1 0 0 ) ( 0 1 0 ) *water1 0 0 0 1 1\n}\n}\n";

    #[test]
    fn texture_names_are_read_after_the_three_points() {
        assert_eq!(texture_names(MAP), vec!["*water1", "{fence"]);
    }

    #[test]
    fn the_wad_key_is_found_replaced_or_added() {
        assert_eq!(worldspawn_wad(MAP), Some("../wads/base.wad;gfx.wad"));
        let set = set_wad_key(MAP, Path::new("/tmp/p.wad"));
        assert_eq!(worldspawn_wad(&set), Some("/tmp/p.wad"));
        assert_eq!(
            set.matches("\"wad\"").count(),
            1,
            "the key is replaced, not added"
        );
        let without = MAP.replace("\"wad\" \"../wads/base.wad;gfx.wad\"\n", "");
        let added = set_wad_key(&without, Path::new("/tmp/p.wad"));
        assert_eq!(worldspawn_wad(&added), Some("/tmp/p.wad"));
        assert_eq!(added.lines().nth(2), Some("\"wad\" \"/tmp/p.wad\""));
    }

    #[test]
    fn a_wad_counts_as_found_by_its_file_name_in_a_folder() {
        let dir = std::env::temp_dir().join(format!("report-wads-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        assert!(!wads_found(MAP, std::slice::from_ref(&dir)));
        std::fs::write(dir.join("gfx.wad"), b"").expect("writes");
        assert!(wads_found(MAP, std::slice::from_ref(&dir)));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn the_placeholder_wad_holds_every_name() {
        let dir = std::env::temp_dir().join(format!("report-placeholder-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("p.wad");
        write_placeholder_wad(&texture_names(MAP), &path).expect("writes");
        let wad = Wad::read(&std::fs::read(&path).expect("reads")).expect("a WAD");
        assert!(wad.find_miptex("*water1").is_some() && wad.find_miptex("{fence").is_some());
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_missing_interpreter_is_named_with_what_to_install() {
        let problem = python_problem(Path::new("/nonexistent/python3")).expect("a problem");
        assert!(problem.contains("pip install mitsuba numpy"), "{problem}");
    }

    #[test]
    fn ordinals() {
        let got: Vec<String> = [1, 2, 3, 4, 11, 12, 21, 22].map(ordinal).to_vec();
        assert_eq!(
            got,
            ["1st", "2nd", "3rd", "4th", "11th", "12th", "21st", "22nd"]
        );
    }
}
