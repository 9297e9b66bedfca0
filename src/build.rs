//! `build`: the whole pipeline on one map, stage after stage, the way a mapper's compile profile
//! runs qbsp, vis and light, ending with a preview picture.

use anyhow::{Context, Result};
use clap::{Args, FromArgMatches};
use std::ffi::OsString;
use std::path::PathBuf;
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
    /// Base vis only (conservative, coarser, much faster)
    #[arg(long)]
    fast: bool,
    /// Light with 2x2 samples per luxel
    #[arg(long)]
    extra: bool,
    /// Light with 4x4 samples per luxel
    #[arg(long)]
    extra4: bool,
    /// Filter lightmaps so shadow edges do not stair-step
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
    let normalised = light::cli::join_optional_values(crate::normalise_single_dash(words));
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

pub fn build(args: &BuildArgs) -> Result<()> {
    let start = Instant::now();
    let bsp = args.map.with_extension("bsp");

    let mut argv: Vec<OsString> = vec![args.map.clone().into(), bsp.clone().into()];
    if args.bsp2 {
        argv.push("--bsp2".into());
    }
    for dir in &args.wad_dirs {
        argv.extend(["--wad-dir".into(), dir.clone().into()]);
    }
    argv.extend(extra_args(args.bsp_opts.as_deref()));
    eprintln!("== bsp");
    bsp_compiler::cli::run(&stage_args("bsp", argv)?)?;

    let mut argv: Vec<OsString> = vec![bsp.clone().into()];
    if args.fast {
        argv.push("--fast".into());
    }
    argv.extend(extra_args(args.vis_opts.as_deref()));
    eprintln!("== vis");
    vis::cli::run(&stage_args("vis", argv)?)?;

    let mut argv: Vec<OsString> = vec![bsp.clone().into()];
    for (on, flag) in [
        (args.extra, "--extra"),
        (args.extra4, "--extra4"),
        (args.soft, "--soft"),
        (args.dirt, "--dirt"),
        (args.bounce, "--bounce"),
    ] {
        if on {
            argv.push(flag.into());
        }
    }
    argv.extend(extra_args(args.light_opts.as_deref()));
    eprintln!("== light");
    light::cli::run(&stage_args("light", argv)?)?;

    if !args.no_preview {
        let png = args.map.with_extension("png");
        let argv: Vec<OsString> = vec![
            bsp.clone().into(),
            "--out".into(),
            png.into(),
            "--size".into(),
            args.size.clone().into(),
        ];
        eprintln!("== view");
        runtime_viewer::cli::run(&stage_args("view", argv)?)?;
    }
    eprintln!(
        "build: {} in {:.2} s",
        args.map.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
            (light.bounce, light.lit, light.threads),
            (Some(2), true, Some(1))
        );
    }
}
