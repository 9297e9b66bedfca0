//! `build`: the whole pipeline on one map, stage after stage, the way a mapper's compile profile
//! runs qbsp, vis and light, ending with a preview picture.

use anyhow::{Context, Result};
use clap::{Args, FromArgMatches};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub struct BuildArgs {
    /// The .map to build; outputs go beside it (MAP.bsp, MAP.prt, MAP.png)
    map: PathBuf,
    /// Write BSP2 even when BSP29's limits hold
    #[arg(long)]
    bsp2: bool,
    /// Extra folders to search for the WADs the map names
    #[arg(long = "wad-dir", value_name = "DIR")]
    wad_dirs: Vec<PathBuf>,
    /// Quick preset: base vis only (conservative, coarser, much faster) and default light
    #[arg(long)]
    fast: bool,
    /// Release preset: full vis and light with --extra4 --soft --bounce
    #[arg(long, conflicts_with_all = ["fast", "extra"])]
    r#final: bool,
    /// Light with 2x2 samples per luxel
    #[arg(long)]
    extra: bool,
    /// Light with 4x4 samples per luxel
    #[arg(long)]
    extra4: bool,
    /// Blur the light over half a luxel's samples so shadow edges do not stair-step (light's
    /// --soft: with --extra or --extra4; one sample a luxel has nothing to blur)
    #[arg(long)]
    soft: bool,
    /// Ambient occlusion ("dirt") on every light
    #[arg(long)]
    dirt: bool,
    /// Bounced light (one pass of diffuse interreflection)
    #[arg(long)]
    bounce: bool,
    /// More options for the bsp stage, as one string (e.g. "-leaktest -wrbrushes"; ericw-tools'
    /// single-dash spellings work)
    #[arg(long, value_name = "OPTIONS", allow_hyphen_values = true)]
    bsp_opts: Option<String>,
    /// More options for the vis stage, as one string
    #[arg(long, value_name = "OPTIONS", allow_hyphen_values = true)]
    vis_opts: Option<String>,
    /// More options for the light stage, as one string (e.g. "-bounce 2 -lit")
    #[arg(long, value_name = "OPTIONS", allow_hyphen_values = true)]
    light_opts: Option<String>,
    /// Preview size, WIDTHxHEIGHT
    #[arg(long, default_value = "640x480")]
    size: String,
    /// Skip the preview picture
    #[arg(long)]
    no_preview: bool,
}

/// A stage's `--*-opts` string as arguments, spelled as the stage's own command takes them.
fn extra_args(opts: Option<&str>) -> Vec<OsString> {
    let words = std::iter::once(String::new())
        .chain(opts.unwrap_or("").split_whitespace().map(str::to_string));
    let normalised = batch::command_words(words);
    normalised.into_iter().skip(1).map(OsString::from).collect()
}

/// Parse a stage's own arguments, so `build` runs exactly what the stage's command would.
fn stage_args<A: Args + FromArgMatches>(name: &'static str, argv: Vec<OsString>) -> Result<A> {
    let command = A::augment_args(clap::Command::new(name).no_binary_name(true));
    let matches = command
        .try_get_matches_from(argv)
        .with_context(|| format!("arguments for the {name} stage"))?;
    Ok(A::from_arg_matches(&matches)?)
}

/// One stage's wall time and its main figures.
struct StageRun {
    name: &'static str,
    seconds: f64,
    figures: String,
}

/// Runs a stage's command with `argv`, timing it; `figures` summarises what it returned.
fn run_stage<A: Args + FromArgMatches, T>(
    name: &'static str,
    argv: Vec<OsString>,
    run: impl FnOnce(&A) -> Result<T>,
    figures: impl FnOnce(&T) -> String,
) -> Result<(StageRun, T)> {
    eprintln!("== {name}");
    let start = Instant::now();
    let out = run(&stage_args(name, argv)?)?;
    let stage = StageRun {
        name,
        seconds: start.elapsed().as_secs_f64(),
        figures: figures(&out),
    };
    Ok((stage, out))
}

pub fn build(args: &BuildArgs) -> Result<()> {
    let start = Instant::now();
    let bsp = args.map.with_extension("bsp");
    let stages = run_stages(args, &bsp)?;
    eprint!("{}", summary(&args.map, &stages));
    eprintln!(
        "build: {} in {:.2} s",
        args.map.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn run_stages(args: &BuildArgs, bsp: &Path) -> Result<Vec<StageRun>> {
    let mut stages = Vec::new();
    let mut argv: Vec<OsString> = vec![args.map.clone().into(), bsp.into()];
    if args.bsp2 {
        argv.push("--bsp2".into());
    }
    for dir in &args.wad_dirs {
        argv.extend(["--wad-dir".into(), dir.clone().into()]);
    }
    argv.extend(extra_args(args.bsp_opts.as_deref()));
    let (stage, compiled) = run_stage("bsp", argv, bsp_compiler::cli::run, |s| {
        s.as_ref().map_or(String::new(), bsp_figures)
    })?;
    stages.push(stage);

    // A leaking map has no .prt unless the bsp options asked for one (--keepprt).
    let leaked = compiled.is_some_and(|s| s.leaked);
    if leaked && !bsp.with_extension("prt").exists() {
        eprintln!("== vis skipped: the map leaks, and vis needs a sealed map (see the pointfile)");
    } else {
        let mut argv: Vec<OsString> = vec![bsp.into()];
        if args.fast {
            argv.push("--fast".into());
        }
        argv.extend(extra_args(args.vis_opts.as_deref()));
        crate::keep_freed_memory(false);
        let (stage, _) = run_stage("vis", argv, vis::cli::run, |r| {
            r.as_ref().map_or(String::new(), vis_figures)
        })?;
        crate::keep_freed_memory(true);
        stages.push(stage);
    }

    let mut argv: Vec<OsString> = vec![bsp.into()];
    for (on, flag) in [
        (args.extra, "--extra"),
        (args.extra4 || args.r#final, "--extra4"),
        (args.soft || args.r#final, "--soft"),
        (args.dirt, "--dirt"),
        (args.bounce || args.r#final, "--bounce"),
    ] {
        if on {
            argv.push(flag.into());
        }
    }
    argv.extend(extra_args(args.light_opts.as_deref()));
    let (stage, _) = run_stage("light", argv, light::cli::run, |s| {
        s.as_ref().map_or(String::new(), light_figures)
    })?;
    stages.push(stage);

    if !args.no_preview {
        let argv: Vec<OsString> = vec![
            bsp.into(),
            "--out".into(),
            args.map.with_extension("png").into(),
            "--size".into(),
            args.size.clone().into(),
        ];
        let (stage, ()) = run_stage("view", argv, runtime_viewer::cli::run, |()| String::new())?;
        stages.push(stage);
    }
    Ok(stages)
}

fn bsp_figures(s: &bsp_compiler::CompileStats) -> String {
    format!(
        "{} faces, {} leaves, {} nodes, {} clipnodes, {} portals",
        s.faces, s.leaves, s.nodes, s.clipnodes, s.vis_portals
    )
}

fn vis_figures(r: &vis::VisReport) -> String {
    format!(
        "PVS average {:.1} of {} leaves; visibility lump {:.1} KB",
        r.compute.average_visible,
        r.compute.leafs,
        r.lump.compressed_bytes as f64 / 1024.0
    )
}

fn light_figures(s: &light::Stats) -> String {
    let rays = s.shadow_rays + s.sun_rays + s.dirt_rays + s.bounce_rays;
    format!(
        "{:.2} M rays, {:.1} Mrays/s",
        rays as f64 / 1e6,
        s.rays_per_second / 1e6
    )
}

/// The table printed at the end of a build: time and the main figures of each stage, and the
/// sizes of the files written.
fn summary(map: &Path, stages: &[StageRun]) -> String {
    let size = |ext: &str| {
        let path = map.with_extension(ext);
        std::fs::metadata(&path).ok().map(|m| {
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            format!("{name} {:.0} KB", m.len() as f64 / 1024.0)
        })
    };
    let mut out = String::from("| stage | time | figures | files |\n|---|---|---|---|\n");
    for stage in stages {
        let files: Vec<String> = match stage.name {
            "bsp" => ["bsp", "prt"].iter().filter_map(|e| size(e)).collect(),
            "light" => size("lit").into_iter().collect(),
            "view" => size("png").into_iter().collect(),
            _ => Vec::new(),
        };
        out += &format!(
            "| {} | {:.2} s | {} | {} |\n",
            stage.name,
            stage.seconds,
            stage.figures,
            files.join(", ")
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_build(words: &[&str]) -> Result<BuildArgs, clap::Error> {
        let command = BuildArgs::augment_args(clap::Command::new("build").no_binary_name(true));
        BuildArgs::from_arg_matches(&command.try_get_matches_from(words)?)
    }

    #[test]
    fn final_is_a_preset_that_excludes_fast() {
        let f = parse_build(&["x.map", "--final"]).expect("--final parses");
        assert!(f.r#final && !f.fast);
        assert!(parse_build(&["x.map", "--final", "--fast"]).is_err());
        assert!(parse_build(&["x.map", "--fast"]).expect("--fast").fast);
    }

    #[test]
    fn summary_names_each_stage_s_figures() {
        let stats = bsp_compiler::CompileStats {
            faces: 61,
            leaves: 8,
            nodes: 34,
            ..Default::default()
        };
        let light = light::Stats {
            shadow_rays: 1_500_000,
            bounce_rays: 500_000,
            rays_per_second: 4e6,
            ..Default::default()
        };
        let stages = [
            StageRun {
                name: "bsp",
                seconds: 0.5,
                figures: bsp_figures(&stats),
            },
            StageRun {
                name: "light",
                seconds: 0.25,
                figures: light_figures(&light),
            },
        ];
        let table = summary(Path::new("/nonexistent/x.map"), &stages);
        assert!(
            table.contains("| bsp | 0.50 s | 61 faces, 8 leaves, 34 nodes, 0 clipnodes,"),
            "{table}"
        );
        assert!(table.contains("2.00 M rays, 4.0 Mrays/s"), "{table}");
    }

    #[test]
    fn stage_options_take_ericw_spellings() {
        let words = |a: Vec<OsString>| {
            a.into_iter()
                .map(|w| w.into_string().unwrap())
                .collect::<Vec<_>>()
        };
        assert_eq!(
            words(extra_args(Some("-leaktest  -maxnodesize 512"))),
            ["--leaktest", "--maxnodesize", "512"]
        );
        assert_eq!(
            words(extra_args(Some("-bounce 2 -lit"))),
            ["--bounce=2", "--lit"]
        );
        assert!(extra_args(None).is_empty());
        let light: light::cli::Args = stage_args("light", {
            let mut argv = vec![OsString::from("x.bsp")];
            argv.extend(extra_args(Some("-bounce 2 -lit -threads 1")));
            argv
        })
        .expect("light options parse");
        assert_eq!(
            (light.overrides.bounce, light.lit, light.threads),
            (Some(2), true, Some(1))
        );
    }
}
