//! The report's run: every timed step of every map, N times over, ours and the anchor's
//! interleaved; then each stage's output measured once against its reference; then the files.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::measure::{self, LightReferences, ViewFigures};
use crate::process::{Timing, run_timed};
use crate::settings::{Setting, Stage, Tool, all_settings};
use crate::{
    Figures, LightReference, Machine, Options, ReferenceSeconds, Report, ReportError, Row,
};

/// One map and the folder its intermediate files go to.
pub(crate) struct MapWork {
    pub(crate) source: PathBuf,
    pub(crate) name: String,
    pub(crate) dir: PathBuf,
}

/// The best timing of a step so far, or why it failed.
pub(crate) type Timings = BTreeMap<(usize, usize, Tool), Result<Timing, String>>;

/// `p` as an absolute path (steps run in their map's work folder).
pub(crate) fn absolute(p: &PathBuf) -> Result<PathBuf, ReportError> {
    std::path::absolute(p).map_err(ReportError::io(p))
}

/// Each of `paths` as an absolute path.
pub(crate) fn absolute_all(paths: &[PathBuf]) -> Result<Vec<PathBuf>, ReportError> {
    paths.iter().map(absolute).collect()
}

/// Runs the whole report and writes its files into `options.out_dir`.
pub fn run(options: &Options) -> Result<Report, ReportError> {
    if options.maps.is_empty() {
        return Err(ReportError::NoMaps);
    }
    let anchor_as_given = options.anchor.clone();
    // Steps run in their map's work folder, so every path they are given must be absolute.
    let options = &Options {
        maps: absolute_all(&options.maps)?,
        wad_dirs: absolute_all(&options.wad_dirs)?,
        out_dir: absolute(&options.out_dir)?,
        slipgate: absolute(&options.slipgate)?,
        anchor: options.anchor.as_ref().map(absolute).transpose()?,
        ..options.clone()
    };
    let work_root = options.out_dir.join("work");
    std::fs::create_dir_all(&work_root).map_err(ReportError::io(&work_root))?;
    let maps = map_work(&options.maps, &work_root)?;
    let settings = all_settings();
    let mut tools = vec![Tool::Slipgate];
    if options.anchor.is_some() {
        tools.push(Tool::EricwTools);
        link_wad_dirs(&options.wad_dirs, &work_root)?;
    }
    let steps: Vec<(usize, Tool)> = settings
        .iter()
        .enumerate()
        .flat_map(|(i, s)| {
            tools
                .iter()
                .filter(|&&t| t == Tool::Slipgate || s.theirs.is_some())
                .map(move |&t| (i, t))
        })
        .collect();
    let progress = progress_bar(
        options.progress,
        (maps.len() * (steps.len() * options.runs.max(1) + steps.len())) as u64,
    );
    let load_start = crate::machine::load_average();
    let mut timings = Timings::new();
    let mut fps: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    for run in 0..options.runs.max(1) {
        for (m, map) in maps.iter().enumerate() {
            for &(s, tool) in &steps {
                let setting = &settings[s];
                progress.set_message(format!(
                    "run {}/{}: {} {} {} ({})",
                    run + 1,
                    options.runs.max(1),
                    map.name,
                    setting.stage.name(),
                    setting.name,
                    tool.name()
                ));
                let mut result = time_step(options, map, setting, tool);
                if let (Ok(_), Stage::View) = (&result, setting.stage) {
                    match measure::flythrough_fps(&stats_file(map, setting)) {
                        Ok(f) => {
                            let best = fps.entry((m, s)).or_insert(0.0);
                            *best = best.max(f);
                        }
                        Err(e) => result = Err(e),
                    }
                }
                record(&mut timings, (m, s, tool), result);
                progress.inc(1);
            }
        }
    }
    let mut machine = Machine::probe(
        &options.slipgate,
        maps.first().map(|m| m.dir.join("vis-full.bsp")).as_deref(),
        &work_root.join("isa-probe.bsp"),
    );
    machine.load_start = load_start;
    let mut rows = Vec::new();
    let mut light_references = Vec::new();
    for (m, map) in maps.iter().enumerate() {
        let mut references: Option<Result<LightReferences, String>> = None;
        for &(s, tool) in &steps {
            let setting = &settings[s];
            progress.set_message(format!(
                "measuring {} {} {} ({})",
                map.name,
                setting.stage.name(),
                setting.name,
                tool.name()
            ));
            let timing = timings.get(&(m, s, tool)).cloned();
            let measured = match &timing {
                Some(Ok(_)) => measure_step(
                    options,
                    map,
                    setting,
                    tool,
                    &mut references,
                    fps.get(&(m, s)).copied(),
                )
                .map_err(|e| e.to_string()),
                Some(Err(e)) => Err(e.clone()),
                None => Err("not run".into()),
            };
            let (figures, failure) = match measured {
                Ok(f) => (Some(f), None),
                Err(e) => (None, Some(e)),
            };
            rows.push(Row {
                map: map.name.clone(),
                stage: setting.stage,
                setting: setting.name.clone(),
                tool,
                timing: timing.and_then(Result::ok),
                figures,
                failure,
            });
            progress.inc(1);
        }
        if let Some(Ok(r)) = &references {
            light_references.push(LightReference {
                map: map.name.clone(),
                face_stride: r.face_stride,
                faces: r.faces.len(),
                references: r
                    .taken
                    .iter()
                    .map(|&(measure, _, seconds)| ReferenceSeconds { measure, seconds })
                    .collect(),
            });
        }
    }
    progress.finish_and_clear();
    machine.load_end = crate::machine::load_average();
    let report = Report {
        machine,
        runs: options.runs.max(1),
        release: options.release,
        anchor: anchor_as_given,
        maps: options.maps.clone(),
        light_references,
        rows,
    };
    write_files(&report, &options.out_dir)?;
    Ok(report)
}

pub(crate) fn progress_bar(wanted: bool, len: u64) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if !wanted || !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    if let Ok(style) =
        ProgressStyle::with_template("{elapsed_precise} {wide_bar} {pos}/{len} {msg}")
    {
        bar.set_style(style);
    }
    bar
}

/// Keeps the faster of two successes; a failure counts only while nothing succeeded.
pub(crate) fn record(
    timings: &mut Timings,
    key: (usize, usize, Tool),
    result: Result<Timing, ReportError>,
) {
    let entry = timings.entry(key).or_insert(Err("not run".into()));
    match (result, &*entry) {
        (Ok(t), Ok(best)) => *entry = Ok(Timing::best(Some(*best), t)),
        (Ok(t), Err(_)) => *entry = Ok(t),
        (Err(e), Err(_)) => *entry = Err(e.to_string()),
        (Err(_), Ok(_)) => {}
    }
}

/// Each map's work folder, named after the map (numbered when two maps share a name).
pub(crate) fn map_work(maps: &[PathBuf], work_root: &Path) -> Result<Vec<MapWork>, ReportError> {
    let mut out: Vec<MapWork> = Vec::new();
    for source in maps {
        let stem = source
            .file_stem()
            .map_or_else(|| "map".into(), |s| s.to_string_lossy().into_owned());
        let mut name = stem.clone();
        let mut n = 2;
        while out.iter().any(|m| m.name == name) {
            name = format!("{stem}-{n}");
            n += 1;
        }
        let dir = work_root.join(&name);
        std::fs::create_dir_all(&dir).map_err(ReportError::io(&dir))?;
        out.push(MapWork {
            source: source.clone(),
            name,
            dir,
        });
    }
    Ok(out)
}

/// ericw-tools' `qbsp -wadpath DIR` appends a map's whole relative `wad` path to DIR, and
/// LibreQuake's maps name `../../../../texture-wads/NAME.wad`: so each WAD folder gets a link
/// `wpN/texture-wads` and qbsp is given `wpN/a/b/c/d`.
pub(crate) fn link_wad_dirs(wad_dirs: &[PathBuf], work_root: &Path) -> Result<(), ReportError> {
    for (i, dir) in wad_dirs.iter().enumerate() {
        let base = work_root.join(format!("wp{i}"));
        let deep = base.join("a/b/c/d");
        std::fs::create_dir_all(&deep).map_err(ReportError::io(&deep))?;
        let link = base.join("texture-wads");
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(dir, &link).map_err(ReportError::io(&link))?;
    }
    Ok(())
}

/// The file a step writes (or, for the viewer, reads).
fn output_file(map: &MapWork, setting: &Setting, tool: Tool) -> PathBuf {
    let prefix = if tool == Tool::EricwTools {
        "ericw-"
    } else {
        ""
    };
    map.dir.join(format!("{prefix}{}.bsp", setting.key()))
}

/// The `--stats` file a step of ours writes: light's own timings, the viewer's flythrough.
fn stats_file(map: &MapWork, setting: &Setting) -> PathBuf {
    output_file(map, setting, Tool::Slipgate).with_extension("json")
}

/// What each stage reads: our compile for vis, our full vis for light, our default light for
/// the viewer, so both tools work on the same input.
fn input_file(map: &MapWork, stage: Stage) -> PathBuf {
    map.dir.join(match stage {
        Stage::Bsp => "",
        Stage::Vis => "bsp-default.bsp",
        Stage::Light => "vis-full.bsp",
        Stage::View => "light-default.bsp",
    })
}

fn copy(from: &Path, to: &Path) -> Result<(), ReportError> {
    std::fs::copy(from, to).map_err(ReportError::io(from))?;
    Ok(())
}

/// Runs one step once, timed.
fn time_step(
    options: &Options,
    map: &MapWork,
    setting: &Setting,
    tool: Tool,
) -> Result<Timing, ReportError> {
    let out = output_file(map, setting, tool);
    let input = input_file(map, setting.stage);
    let log = out.with_extension("log");
    let mut command = match (tool, &options.anchor) {
        (Tool::EricwTools, Some(anchor)) => {
            ericw_command(anchor, options, map, setting, &input, &out)?
        }
        _ => slipgate_command(options, map, setting, &input, &out)?,
    };
    command.current_dir(&map.dir);
    run_timed(&mut command, &log)
}

fn slipgate_command(
    options: &Options,
    map: &MapWork,
    setting: &Setting,
    input: &Path,
    out: &Path,
) -> Result<Command, ReportError> {
    let mut c = Command::new(&options.slipgate);
    c.arg(setting.stage.name());
    match setting.stage {
        Stage::Bsp => {
            c.arg(&map.source).arg(out);
            for dir in &options.wad_dirs {
                c.arg("--wad-dir").arg(dir);
            }
        }
        Stage::Vis => {
            copy_stage_input(setting.stage, input, out)?;
            c.arg(out);
        }
        Stage::Light => {
            copy_stage_input(setting.stage, input, out)?;
            // Light's own timings, for what the light grid cost.
            c.arg(out).arg("--stats").arg(stats_file(map, setting));
        }
        Stage::View => {
            let (w, h) = options.view_size;
            c.arg(input)
                .arg("--bench")
                .arg(options.view_frames.max(1).to_string())
                .arg("--size")
                .arg(format!("{w}x{h}"))
                .arg("--stats")
                .arg(stats_file(map, setting));
        }
    }
    c.args(&setting.ours);
    Ok(c)
}

fn ericw_command(
    anchor: &Path,
    options: &Options,
    map: &MapWork,
    setting: &Setting,
    input: &Path,
    out: &Path,
) -> Result<Command, ReportError> {
    let program = match setting.stage {
        Stage::Bsp => "qbsp",
        Stage::Vis => "vis",
        Stage::Light => "light",
        Stage::View => unreachable!("ericw-tools has no viewer step"),
    };
    let mut c = Command::new(anchor.join(program));
    c.args(setting.theirs.iter().flatten());
    match setting.stage {
        Stage::Bsp => {
            let work_root = map.dir.parent().unwrap_or(&map.dir);
            for i in 0..options.wad_dirs.len() {
                c.arg("-wadpath")
                    .arg(work_root.join(format!("wp{i}/a/b/c/d")));
            }
            if let Some(dir) = map.source.parent() {
                c.arg("-wadpath").arg(dir);
            }
            c.arg(&map.source).arg(out);
        }
        _ => {
            copy_stage_input(setting.stage, input, out)?;
            c.arg(out);
        }
    }
    Ok(c)
}

/// Vis and light rewrite their BSP in place, so each run works on its own copy of the input
/// (vis with its portal file).
fn copy_stage_input(stage: Stage, input: &Path, out: &Path) -> Result<(), ReportError> {
    copy(input, out)?;
    if stage == Stage::Vis {
        copy(&input.with_extension("prt"), &out.with_extension("prt"))?;
    }
    Ok(())
}

/// Measures a finished step's output against its stage's reference.
fn measure_step(
    options: &Options,
    map: &MapWork,
    setting: &Setting,
    tool: Tool,
    references: &mut Option<Result<LightReferences, String>>,
    best_fps: Option<f64>,
) -> Result<Figures, ReportError> {
    let out = output_file(map, setting, tool);
    Ok(match setting.stage {
        Stage::Bsp => Figures::Bsp(measure::bsp_figures(
            &out,
            &map.source,
            options.hull_traces,
        )?),
        Stage::Vis => Figures::Vis(measure::vis_figures(&out, options.sample_pairs)?),
        Stage::Light => {
            let refs = references.get_or_insert_with(|| {
                LightReferences::new(&input_file(map, Stage::Light), options.reference_faces)
                    .map_err(|e| e.to_string())
            });
            let refs = refs.as_mut().map_err(|e| ReportError::Measure {
                path: input_file(map, Stage::Light),
                what: format!("light's reference: {e}"),
            })?;
            let measure = setting.light_measure();
            let mut figures = measure::light_figures(&out, measure, refs.for_measure(measure)?)?;
            if tool == Tool::Slipgate {
                figures.grid_cost = measure::grid_cost(&stats_file(map, setting))?;
            }
            Figures::Light(figures)
        }
        Stage::View => Figures::View(view_figures(options, map, setting, best_fps)?),
    })
}

/// Renders the default-lit map's start view at a span step beside the reference renderer.
fn view_figures(
    options: &Options,
    map: &MapWork,
    setting: &Setting,
    best_fps: Option<f64>,
) -> Result<ViewFigures, ReportError> {
    let out = output_file(map, setting, Tool::Slipgate);
    let png = out.with_extension("png");
    let stats = map.dir.join(format!("{}-reference.json", setting.key()));
    let (w, h) = options.view_size;
    let mut c = Command::new(&options.slipgate);
    c.arg("view")
        .arg(input_file(map, Stage::View))
        .arg("--reference")
        .arg("--out")
        .arg(&png)
        .arg("--size")
        .arg(format!("{w}x{h}"))
        .arg("--stats")
        .arg(&stats)
        .args(&setting.ours)
        .current_dir(&map.dir);
    run_timed(&mut c, &out.with_extension("reference.log"))?;
    let span_step = setting
        .ours
        .last()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let reference = measure::reference_comparison(&stats)?;
    Ok(ViewFigures {
        span_step,
        fps: best_fps.unwrap_or(0.0),
        mean_diff: reference.mean_diff,
        max_diff: f64::from(reference.max_diff),
        face_mismatch: reference.face_mismatch,
    })
}

/// Writes `bytes` as `out_dir/name`, whole or not at all.
pub(crate) fn write_report_file(
    out_dir: &Path,
    name: &str,
    bytes: &[u8],
) -> Result<(), ReportError> {
    let path = out_dir.join(name);
    quake_formats::fsutil::write_atomic(&path, bytes)
        .map_err(|source| ReportError::Format { path, source })
}

/// Writes `value` as pretty JSON to `out_dir/name`.
pub(crate) fn write_json(
    value: &impl serde::Serialize,
    out_dir: &Path,
    name: &str,
) -> Result<(), ReportError> {
    let json = serde_json::to_string_pretty(value).map_err(|e| ReportError::Measure {
        path: out_dir.join(name),
        what: e.to_string(),
    })?;
    write_report_file(out_dir, name, json.as_bytes())
}

/// report.json, report.md, the plots and report.html.
fn write_files(report: &Report, out_dir: &Path) -> Result<(), ReportError> {
    let write = |name: &str, bytes: &[u8]| write_report_file(out_dir, name, bytes);
    write_json(report, out_dir, "report.json")?;
    let plots = crate::plot::draw_all(report, out_dir)?;
    write(
        "report.md",
        crate::markdown::render(report, &plots).as_bytes(),
    )?;
    write(
        "report.html",
        crate::html::render(report, &plots).as_bytes(),
    )?;
    Ok(())
}
