//! The command line of `slipgate light` and `slipgate-light`: arguments (the settings' flags
//! built from [`crate::settings::TABLE`]), the progress bar, what is printed, and the files
//! written (the BSP and its `.lit` as a pair, `--stats`).

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Arg, ArgMatches, Command, FromArgMatches};
use quake_formats::Bsp;
use quake_formats::fsutil::{Staged, read_file, write_atomic};
use quake_formats::palette::Palette;

use crate::settings::{Overrides, Setting, TABLE};
use crate::{LightFiles, Lighting, Options, Quality, compare_with_reference, compute_lighting};

quake_formats::ericw_accepted! {
    /// ericw-tools' light options that Slipgate's light accepts without acting on them.
    pub struct EricwOnly with reporting {
        defaultpaths: bool => "the palette is found as --palette says",
        nodefaultpaths: bool => "the palette is found as --palette says",
        novisapprox: bool => "lights are culled by the PVS, which never cuts light off early",
        dirtdebug: bool => "no debug lightmaps; `slipgate view --lightmap-only` shows the light",
        phongdebug: bool => "no debug lightmaps; `slipgate view --lightmap-only` shows the light",
        bouncedebug: bool => "no debug lightmaps; `slipgate view --lightmap-only` shows the light",
        surflight_dump: bool => "surface lights are not written out",
        lit2: bool => "the .lit2 format is not written",
        litonly: bool => "the BSP is always written with its .lit",
        nolighting: bool => "light is always computed",
        wrnormals: bool => "no normals lump is written",
        gamedir: Option<String> => "light reads textures from the BSP and the palette as --palette says",
        basedir: Option<String> => "light reads textures from the BSP and the palette as --palette says",
        filepriority: Option<String> => "light reads textures from the BSP",
        path: Vec<String> => "light reads textures from the BSP",
        visapprox: Option<String> => "lights are culled by the PVS, which never cuts light off early",
        facestyles: Option<String> => "a face keeps the 4 styles BSP29 and BSP2 hold",
        exportobj: bool => "no .obj is written",
        radlights: Option<String> => ".rad files are not read; `_surface` light entities make surface lights",
        lightgrid_format: Option<String> => "the light grid is written as LIGHTGRID_OCTREE",
        bouncelightsdebug: bool => "no debug lightmaps; `slipgate view --lightmap-only` shows the light",
        phongdebug_obj: bool => "no debug output; `slipgate view --lightmap-only` shows the light",
        debugoccluded: bool => "no debug lightmaps; `slipgate view --lightmap-only` shows the light",
        debugneighbours: bool => "no debug lightmaps; `slipgate view --lightmap-only` shows the light",
        debugmottle: bool => "no debug lightmaps; `slipgate view --lightmap-only` shows the light",
        highlightseams: bool => "no debug lightmaps; `slipgate view --lightmap-only` shows the light",
    }
}

/// Light a BSP: compute lightmaps from its light entities.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// The BSP to light.
    pub bsp: PathBuf,
    /// Where to write the lit BSP (default: overwrite the input). A `.lit` goes beside it.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// 2x2 samples per luxel.
    #[arg(long, conflicts_with_all = ["extra4", "reference"])]
    pub extra: bool,
    /// 4x4 samples per luxel.
    #[arg(long, conflicts_with = "reference")]
    pub extra4: bool,
    /// The slow exact answer: 16x16 samples per luxel and no light culling.
    #[arg(long)]
    pub reference: bool,
    /// The map-wide settings (each wins over its worldspawn key); boxed, being most of the
    /// arguments' size.
    #[command(flatten)]
    pub overrides: Box<Overrides>,
    /// Palette for texture colours (`--bouncecolorscale`); default: `gfx/palette.lmp` in the
    /// BSP's folder or up to three above it, else Slipgate's own palette.
    #[arg(long, value_name = "FILE.lmp")]
    pub palette: Option<PathBuf>,
    /// Always write a `.lit` beside the BSP, even when every light is white (ericw-tools' `-lit`).
    #[arg(long, conflicts_with = "nolit")]
    pub lit: bool,
    /// Never write a `.lit`, even for coloured light (engines then show it grey); a `.lit` left
    /// from an earlier run is removed.
    #[arg(long)]
    pub nolit: bool,
    /// Both `--bspxlit` and `--bspxlux`: colour and directions in the BSP (ericw-tools' `-bspx`).
    #[arg(long)]
    pub bspx: bool,
    /// Only update the entity lump: give switchable lights (`targetname`) their styles without
    /// relighting, after `slipgate bsp --onlyents` replaced the entities.
    #[arg(long, conflicts_with_all = ["compare_reference", "bench_occlusion"])]
    pub onlyents: bool,
    /// Worker threads for tracing (default: one per core).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub threads: Option<u16>,
    /// ericw-tools' options accepted with a note (hidden from the help); boxed, being many.
    #[command(flatten)]
    pub ericw_only: Box<EricwOnly>,
    /// Consider every light for every face (no range, plane-side or PVS culling).
    #[arg(long)]
    pub no_cull: bool,
    /// Write counts and timings as JSON.
    #[arg(long, value_name = "FILE.json")]
    pub stats: Option<PathBuf>,
    /// Measurement: light only every Nth face (the others get no lightmap).
    #[arg(long, value_name = "N")]
    pub face_stride: Option<usize>,
    /// Measurement: also light the same faces with --reference and report the error, over the
    /// luxels engines draw (each weighted by the area of the face it shows on) and over every
    /// luxel of the lightmaps.
    #[arg(long)]
    pub compare_reference: bool,
    /// Measurement: time a bare occlusion loop over up to this many shadow rays.
    #[arg(long, value_name = "RAYS")]
    pub bench_occlusion: Option<usize>,
}

/// The settings' flags, one per setting of [`TABLE`] that has one.
impl clap::Args for Overrides {
    fn augment_args(command: Command) -> Command {
        command.args(TABLE.iter().map(setting_arg))
    }

    fn augment_args_for_update(command: Command) -> Command {
        Overrides::augment_args(command)
    }
}

impl FromArgMatches for Overrides {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Overrides, clap::Error> {
        let mut overrides = Overrides::default();
        overrides.update_from_arg_matches(matches)?;
        Ok(overrides)
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        for s in TABLE {
            if let Some(text) = matches.get_one::<String>(s.field) {
                self.set(s.field, text)
                    .map_err(|e| clap::Error::raw(clap::error::ErrorKind::ValueValidation, e))?;
            }
        }
        Ok(())
    }
}

/// The flag of setting `s`: a switch (whose value, `0`, `1` or `-1` as ericw-tools takes them,
/// may follow), a value, or a value that may be left out (`--bounce`), with the setting's help
/// and worldspawn keys; each of its keys without the underscore is a spelling of it too.
fn setting_arg(s: &'static Setting) -> Arg {
    let help = s.help.split_whitespace().collect::<Vec<_>>().join(" ");
    let help = help.trim_end_matches('.').to_string();
    let help = match s.keys {
        [] => help,
        keys => format!("{help} [worldspawn {}]", keys.join(", ")),
    };
    let mut arg = Arg::new(s.field)
        .long(s.flag)
        .aliases(s.aliases())
        .help(help)
        .value_name(if s.switch { "0|1" } else { "N" })
        .value_parser(move |text: &str| {
            (s.check)(text)
                .map(|()| text.to_string())
                .map_err(|expected| format!("expected {expected}"))
        });
    if let Some(missing) = optional_value(s) {
        arg = arg
            .num_args(0..=1)
            .require_equals(true)
            .default_missing_value(missing);
    }
    arg
}

/// The value setting `s`'s flag means when given without one: on for a switch.
fn optional_value(s: &Setting) -> Option<&'static str> {
    if s.switch { Some("1") } else { s.missing }
}

/// Light's options whose value may be left out (`--bounce [N]`, `--soft [N]`) or is several
/// numbers (`--lightgrid_dist 16 16 32`) take the numbers that follow them
/// ([`quake_formats::cli::join_optional_values`]).
pub fn join_optional_values(args: impl IntoIterator<Item = String>) -> Vec<String> {
    let joining: Vec<(String, usize)> = TABLE
        .iter()
        .filter(|s| optional_value(s).is_some() || s.words > 1)
        .flat_map(|s| {
            let names = std::iter::once(s.flag).chain(s.aliases());
            names
                .map(|name| (format!("--{name}"), s.words))
                .collect::<Vec<_>>()
        })
        .collect();
    let joining: Vec<(&str, usize)> = joining.iter().map(|(f, n)| (f.as_str(), *n)).collect();
    quake_formats::cli::join_optional_values(args, &joining)
}

/// The files written beside a lit BSP, each `None` when there is none (and an old one goes).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Companions {
    /// The `.lit`.
    pub lit: Option<Vec<u8>>,
    /// The `.lux`.
    pub lux: Option<Vec<u8>>,
}

impl Companions {
    /// Each companion's file extension and bytes (`None`: not written).
    pub fn by_extension(self) -> [(&'static str, Option<Vec<u8>>); 2] {
        [("lit", self.lit), ("lux", self.lux)]
    }
}

/// Whether to write a `.lit` file beside the lit BSP.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LitFile {
    /// Only when some light is coloured.
    WhenColoured,
    Always,
    Never,
}

impl Args {
    fn quality(&self) -> Quality {
        if self.reference {
            Quality::Reference
        } else if self.extra4 {
            Quality::Extra4
        } else if self.extra {
            Quality::Extra
        } else {
            Quality::Default
        }
    }

    /// The library options these arguments ask for, with the palette `run` would find (and no
    /// progress reported).
    pub fn lighting_options(&self) -> anyhow::Result<Options> {
        let mut overrides = Overrides::clone(&self.overrides);
        if self.bspx {
            overrides.bspxlit = overrides.bspxlit.or(Some(true));
            overrides.bspxlux = overrides.bspxlux.or(Some(true));
        }
        Ok(Options {
            quality: self.quality(),
            overrides,
            no_cull: self.no_cull,
            palette: find_palette(self)?,
            ..Options::default()
        })
    }

    /// The files to write beside `bsp`, which [`crate::apply_lighting`] just lit and which
    /// returned `files`: the `.lit` as `--lit` and `--nolit` decide, and the `.lux`.
    pub fn companion_files(&self, bsp: &Bsp, files: LightFiles) -> Companions {
        let lit = match self.lit_file() {
            LitFile::WhenColoured => files.lit,
            LitFile::Always => files
                .lit
                .or(files.rgb_lit)
                .or_else(|| Some(crate::grey_lit(&bsp.lighting))),
            LitFile::Never => None,
        };
        Companions {
            lit,
            lux: files.lux,
        }
    }

    fn lit_file(&self) -> LitFile {
        if self.nolit {
            LitFile::Never
        } else if self.lit {
            LitFile::Always
        } else {
            LitFile::WhenColoured
        }
    }
}

/// The palette `--palette` names, else `gfx/palette.lmp` in the BSP's folder or up to three
/// folders above it; `None`: Slipgate's own.
fn find_palette(args: &Args) -> anyhow::Result<Option<Palette>> {
    let dir = args.bsp.parent().unwrap_or(Path::new("."));
    let found = args
        .palette
        .clone()
        .or_else(|| quake_formats::palette::find_game_palette(dir));
    found
        .map(|path| {
            let data = read_file(&path)?;
            Palette::from_bytes(&data).with_context(|| format!("{}", path.display()))
        })
        .transpose()
}

/// Runs `slipgate light` with `args`: the run's counts and timings, or `None` for `--onlyents`.
///
/// # Errors
/// Files that do not read or write, a BSP light refuses, or what [`compute_lighting`] reports.
pub fn run(args: &Args) -> anyhow::Result<Option<crate::Stats>> {
    for note in args.ericw_only.notes() {
        eprintln!("note: {note}");
    }
    // Opening Embree's library takes milliseconds, which reading and checking the BSP need not
    // wait for: on a thread of its own, it is open when the scene is made. Should it fail (or
    // no thread start), making the device opens it, or says why it cannot.
    if !args.onlyents {
        let _ = std::thread::Builder::new()
            .name("embree-open".to_string())
            .spawn(|| {
                let _ = crate::embree::open_library();
            });
    }
    let stats = match args.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(usize::from(n))
            .build()
            .context("starting the worker threads")?
            .install(|| run_with_current_threads(args)),
        None => run_with_current_threads(args),
    };
    // On this thread, not the pool's: a pool's spawned frees run even after it is dropped.
    crate::wait_for_background_frees();
    stats
}

fn run_with_current_threads(args: &Args) -> anyhow::Result<Option<crate::Stats>> {
    let path = &args.bsp;
    let data = read_file(path)?;
    let mut bsp = Bsp::read(&data).with_context(|| format!("{}", path.display()))?;
    if args.onlyents {
        return update_entities_only(args, bsp).map(|()| None);
    }
    let ericw_lumps = ericw_face_keys(&mut bsp, path);
    let mut options = args.lighting_options()?;
    options.progress = quake_formats::progress::terminal();
    if let Some(stride) = args.face_stride {
        anyhow::ensure!(stride > 0, "--face-stride must be at least 1");
        options.only_faces = Some((0..bsp.faces.len()).step_by(stride).collect());
    }
    let lighting =
        compute_lighting(&bsp, &options).with_context(|| format!("lighting {}", path.display()))?;
    print_summary(&lighting);

    let extra = measurements(args, &bsp, &options, &lighting)?;

    for name in ericw_lumps {
        bsp.remove_bspx_lump(name);
    }
    let files = crate::apply_lighting(&mut bsp, &lighting);
    let companions = args.companion_files(&bsp, files);
    let out = args.output.as_ref().unwrap_or(path);
    place_with_companions(out, &bsp.write()?, companions)?;
    if let Some(stats_path) = &args.stats {
        let mut json = serde_json::to_value(&lighting.stats)?;
        if let serde_json::Value::Object(map) = &mut json {
            map.extend(extra);
            map.insert("quality".into(), serde_json::to_value(options.quality)?);
        }
        write_atomic(stats_path, serde_json::to_string_pretty(&json)?.as_bytes())?;
    }
    Ok(Some(lighting.stats))
}

/// For a BSP from ericw-tools' qbsp (none of Slipgate's per-face key lumps), the keys of its
/// merged and brush entities from the `MAPNAME.texinfo.json` ericw-tools wrote beside it, added
/// to `bsp` as those lumps: their names, to be taken out before the BSP is written. A file that
/// does not read is a warning; the map is lit without it.
fn ericw_face_keys(bsp: &mut Bsp, path: &Path) -> crate::ericw_texinfo::AddedLumps {
    let json_path = path.with_extension("texinfo.json");
    if crate::ericw_texinfo::has_face_key_lumps(bsp) || !json_path.is_file() {
        return Vec::new();
    }
    let read = std::fs::read_to_string(&json_path).map_err(|e| e.to_string());
    match read.and_then(|text| crate::ericw_texinfo::add_face_keys(bsp, &text)) {
        Ok(added) => {
            if !added.is_empty() {
                eprintln!(
                    "light: per-face keys of func_detail, func_group and brush entities read from {}",
                    json_path.display()
                );
            }
            added
        }
        Err(e) => {
            eprintln!(
                "warning: {}: {e}; lit without its per-face keys",
                json_path.display()
            );
            Vec::new()
        }
    }
}

/// The measurements `--compare-reference` and `--bench-occlusion` ask for, printed and as
/// fields for `--stats`.
fn measurements(
    args: &Args,
    bsp: &Bsp,
    options: &Options,
    lighting: &Lighting,
) -> anyhow::Result<serde_json::Map<String, serde_json::Value>> {
    let mut extra = serde_json::Map::new();
    if args.compare_reference {
        let c = compare_with_reference(bsp, options, lighting)?;
        eprintln!(
            "light: --reference took {:.2} s, {} rays",
            c.reference_seconds, c.reference_rays
        );
        let report = |what: &str, e: &crate::ErrorStats| {
            eprintln!(
                "light: against {what}: RMSE {:.3}, max {} levels over {} luxels ({} differ by more than 8)",
                e.rmse, e.max, e.luxels, e.over_8
            );
        };
        report(
            "--reference, luxels engines draw (weighted by the face area each shows on)",
            &c.error,
        );
        extra.insert("error_vs_reference".into(), serde_json::to_value(c.error)?);
        report(
            "--reference, every luxel of the lightmaps (inside solid too)",
            &c.error_whole_lightmaps,
        );
        extra.insert(
            "error_whole_lightmaps_vs_reference".into(),
            serde_json::to_value(c.error_whole_lightmaps)?,
        );
        if let Some(e) = &c.error_own_grids {
            report(
                "--reference on the faces' own grids, luxels engines draw",
                e,
            );
            extra.insert(
                "error_own_grids_vs_reference".into(),
                serde_json::to_value(e)?,
            );
        }
        if let Some(e) = &c.error_filtered {
            report(
                "--reference with the same --soft filter, luxels engines draw",
                e,
            );
            extra.insert(
                "error_vs_filtered_reference".into(),
                serde_json::to_value(e)?,
            );
        }
        extra.insert(
            "reference_seconds".into(),
            serde_json::to_value(c.reference_seconds)?,
        );
    }
    if let Some(max_rays) = args.bench_occlusion {
        let b = crate::bare_occlusion(bsp, options, max_rays)?;
        eprintln!(
            "light: bare occlusion loop: {} rays in {:.3} s: {:.2} Mrays/s",
            b.rays,
            b.seconds,
            b.rays_per_second / 1e6
        );
        extra.insert("bare_occlusion".into(), serde_json::to_value(b)?);
    }

    Ok(extra)
}

/// What the run did, and its warnings, on stderr.
fn print_summary(lighting: &Lighting) {
    if !lighting.chosen_settings.is_empty() {
        let chosen: Vec<String> = lighting
            .chosen_settings
            .iter()
            .map(ToString::to_string)
            .collect();
        eprintln!("light: settings: {}", chosen.join(", "));
    }
    for w in &lighting.warnings {
        eprintln!("light: warning: {w}");
    }
    let s = &lighting.stats;
    let rays = s.shadow_rays + s.sun_rays + s.dirt_rays;
    if s.lights_nudged > 0 {
        eprintln!(
            "light: {} lights moved out of solid (or off the surface they lay on)",
            s.lights_nudged
        );
    }
    eprintln!(
        "light: {} of {} faces, {} luxels ({} samples), {} point + {} surface lights, {} sun directions",
        s.faces_lit,
        s.faces,
        s.luxels,
        s.samples,
        s.point_lights,
        s.surface_lights,
        s.sun_directions
    );
    eprintln!(
        "light: {rays} rays ({} shadow, {} sun, {} dirt) in {:.2} s trace + {:.2} s setup: {:.2} Mrays/s",
        s.shadow_rays,
        s.sun_rays,
        s.dirt_rays,
        s.seconds_trace,
        s.seconds_setup,
        rays as f64 / s.seconds_trace.max(1e-9) / 1e6
    );
    if s.bounce_passes > 0 {
        eprintln!(
            "light: bounce: {} pass{}, {} rays in {:.2} s",
            s.bounce_passes,
            if s.bounce_passes == 1 { "" } else { "es" },
            s.bounce_rays,
            s.seconds_bounce
        );
    }
    if s.grid_points > 0 {
        eprintln!(
            "light: light grid: {} points ({} in the open), {} rays in {:.2} s",
            s.grid_points, s.grid_points_open, s.grid_rays, s.seconds_lightgrid
        );
    }
    if s.fullbright {
        eprintln!(
            "light: no lights, suns or minlight: lighting lump left empty (engines draw the map fullbright)"
        );
    }
    if !lighting.outputs.grey_lump && !s.fullbright {
        eprintln!(
            "light: warning: --novanilla: no grey lighting lump; engines without BSPX RGBLIGHTING (vanilla Quake, DarkPlaces, QuakeSpasm before 0.96) draw this map unlit"
        );
    }
    if s.faces_with_dropped_styles > 0 {
        eprintln!(
            "light: warning: {} faces are reached by more than 4 light styles; the dimmest were dropped",
            s.faces_with_dropped_styles
        );
    }
}

/// One step of putting a lit BSP and its companions (`.lit`, `.lux`) in place.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PairStep {
    RemoveOldCompanions,
    PlaceBsp,
    PlaceCompanions,
}

/// Engines take a `.lit` (or `.lux`) whose size is three times the BSP's lighting lump
/// (QuakeSpasm and DarkPlaces check only that; older engines not even that), so an old one beside
/// the new BSP would paint the old light's colours over it. The old companions go before the new
/// BSP arrives and the new ones after: a kill between any two steps leaves a BSP with its own
/// companions or with none.
const PAIR_ORDER: [PairStep; 3] = [
    PairStep::RemoveOldCompanions,
    PairStep::PlaceBsp,
    PairStep::PlaceCompanions,
];

/// Puts the lit BSP at `out` and its companions (or none) beside it in [`PAIR_ORDER`], after all
/// are written in full under temporary names (failing to write any leaves the old files
/// untouched).
fn place_with_companions(out: &Path, bsp: &[u8], companions: Companions) -> anyhow::Result<()> {
    let mut staged_bsp = Some(Staged::write(out, bsp)?);
    let mut staged = Vec::new();
    let mut unwanted = Vec::new();
    for (extension, bytes) in companions.by_extension() {
        let path = out.with_extension(extension);
        match bytes {
            Some(bytes) => staged.push(Staged::write(&path, &bytes)?),
            None => unwanted.push(path),
        }
    }
    for step in PAIR_ORDER {
        match step {
            PairStep::RemoveOldCompanions => {
                for s in &staged {
                    remove_old_companion(s.target(), false)?;
                }
                for path in &unwanted {
                    remove_old_companion(path, true)?;
                }
            }
            PairStep::PlaceBsp => {
                if let Some(bsp) = staged_bsp.take() {
                    bsp.commit()?;
                }
            }
            PairStep::PlaceCompanions => {
                for s in staged.drain(..) {
                    s.commit()?;
                }
            }
        }
    }
    Ok(())
}

/// Removes a companion file left from an earlier run, saying so when no new one replaces it.
fn remove_old_companion(file: &Path, none_wanted: bool) -> anyhow::Result<()> {
    if !file.exists() {
        return Ok(());
    }
    std::fs::remove_file(file).with_context(|| format!("removing stale {}", file.display()))?;
    if none_wanted {
        eprintln!(
            "light: removed {} (left from an earlier run; none is wanted now)",
            file.display()
        );
    }
    Ok(())
}

/// `--onlyents`: the entity lump gets the switchable lights' styles; lightmaps and `.lit` stay.
fn update_entities_only(args: &Args, mut bsp: Bsp) -> anyhow::Result<()> {
    let path = &args.bsp;
    let named = crate::update_entities_only(&mut bsp)
        .with_context(|| format!("entities of {}", path.display()))?;
    eprintln!("light: --onlyents: {named} switchable light names given styles; lightmaps kept");
    let out = args.output.as_ref().unwrap_or(path);
    write_atomic(out, &bsp.write()?)?;
    if let Some(stats_path) = &args.stats {
        let json = serde_json::json!({ "onlyents": true, "switchable_names_styled": named });
        write_atomic(stats_path, serde_json::to_string_pretty(&json)?.as_bytes())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strings(a: &[&str]) -> Vec<String> {
        a.iter().map(|s| s.to_string()).collect()
    }

    #[derive(clap::Parser)]
    struct LightCli {
        #[command(flatten)]
        args: Args,
    }

    /// A profile written for ericw-tools' light runs unchanged: its options that only change how
    /// light reports, or its debug outputs, are accepted, each with a note.
    #[test]
    fn ericw_tools_only_options_are_accepted_with_a_note() {
        use clap::Parser;
        let words = strings(&[
            "light",
            "-nopercent",
            "-extra4",
            "-dirtdebug",
            "-surflight_subdivide",
            "64",
            "-emissivequality",
            "high",
            "-path",
            "a",
            "-path",
            "b",
            "-visapprox",
            "vis",
            "-bspx",
            "x.bsp",
        ]);
        let words =
            join_optional_values(quake_formats::cli::normalise_single_dash(words.into_iter()));
        let cli = LightCli::try_parse_from(words).expect("parses");
        let notes = cli.args.ericw_only.notes();
        assert_eq!(notes.len(), 4, "{notes:?}");
        let overrides = cli.args.lighting_options().expect("options").overrides;
        assert_eq!(
            (overrides.bspxlit, overrides.bspxlux),
            (Some(true), Some(true))
        );
        assert_eq!(overrides.surflight_subdivide, Some(64.0), "an option now");
        assert_eq!(
            overrides.emissive_quality,
            Some(crate::bounce::EmissiveQuality::High)
        );
        assert!(
            notes[0].starts_with("-nopercent has no effect"),
            "{notes:?}"
        );
        assert!(cli.args.extra4);
        assert_eq!(cli.args.bsp, PathBuf::from("x.bsp"));
    }

    /// Every setting is an option, as in ericw-tools 2.0: a worldspawn key without its
    /// underscore names it, and a switch takes `0`, `1` or `-1` after it or nothing.
    #[test]
    fn every_setting_is_an_option_with_ericw_tools_spellings() {
        use clap::Parser;
        let parse = |args: &[&str]| {
            let words = join_optional_values(quake_formats::cli::normalise_single_dash(
                strings(args).into_iter(),
            ));
            LightCli::try_parse_from(words)
                .unwrap_or_else(|e| panic!("{args:?}: {e}"))
                .args
        };
        let a = parse(&[
            "light",
            "-sunlight2",
            "0",
            "-minlight_dirt",
            "0",
            "-dirt",
            "0",
            "-sunlight_color",
            "255",
            "0",
            "0",
            "-mincolor",
            "0.5",
            "0.5",
            "1",
            "x.bsp",
        ]);
        let o = &a.overrides;
        assert_eq!(o.sunlight2, Some(0.0));
        assert_eq!(o.minlight_dirt, Some(crate::settings::DirtToggle::AsDirt));
        assert_eq!(o.dirt, Some(false));
        assert_eq!(o.sunlight_color.map(|c| c.0), Some(glam::DVec3::X));
        assert!(o.minlight_color.is_some());
        assert_eq!(a.bsp, PathBuf::from("x.bsp"));
        for (args, on) in [
            (&["light", "-dirt", "x.bsp"][..], true),
            (&["light", "-dirt", "1", "x.bsp"][..], true),
            (&["light", "-dirt", "-1", "x.bsp"][..], false),
            (&["light", "x.bsp", "-dirt"][..], true),
        ] {
            assert_eq!(parse(args).overrides.dirt, Some(on), "{args:?}");
        }
    }

    /// Which run wrote a file of the pair.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    enum Run {
        Old,
        New,
    }

    #[test]
    fn every_moment_of_the_pair_order_shows_a_bsp_with_its_own_lit_or_none() {
        for had_lit in [false, true] {
            for wants_lit in [false, true] {
                let mut bsp = Run::Old;
                let mut lit = had_lit.then_some(Run::Old);
                let what = format!("old .lit: {had_lit}, new .lit: {wants_lit}");
                for step in PAIR_ORDER {
                    match step {
                        PairStep::RemoveOldCompanions => lit = None,
                        PairStep::PlaceBsp => bsp = Run::New,
                        PairStep::PlaceCompanions if wants_lit => lit = Some(Run::New),
                        PairStep::PlaceCompanions => {}
                    }
                    assert!(
                        lit.is_none_or(|lit| lit == bsp),
                        "{what}: a kill after {step:?} leaves a {bsp:?} BSP beside a {lit:?} .lit"
                    );
                }
                assert_eq!(
                    (bsp, lit),
                    (Run::New, wants_lit.then_some(Run::New)),
                    "{what}"
                );
            }
        }
    }

    #[test]
    fn placing_a_pair_replaces_or_removes_the_old_lit_and_leaves_no_temporaries() {
        let dir = std::env::temp_dir().join(format!("slipgate-light-pair-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let bsp = dir.join("map.bsp");
        let lit = bsp.with_extension("lit");
        let lux = bsp.with_extension("lux");
        std::fs::write(&bsp, b"old bsp").expect("write");
        std::fs::write(&lit, b"old lit").expect("write");
        std::fs::write(&lux, b"old lux").expect("write");
        let both = Companions {
            lit: Some(b"new lit".to_vec()),
            lux: None,
        };
        place_with_companions(&bsp, b"new bsp", both).expect("place");
        assert_eq!(std::fs::read(&bsp).expect("bsp"), b"new bsp");
        assert_eq!(std::fs::read(&lit).expect("lit"), b"new lit");
        assert!(!lux.exists(), "the old .lux outlived a run that wants none");
        let lux_only = Companions {
            lit: None,
            lux: Some(b"new lux".to_vec()),
        };
        place_with_companions(&bsp, b"grey bsp", lux_only).expect("place");
        assert_eq!(std::fs::read(&bsp).expect("bsp"), b"grey bsp");
        assert!(!lit.exists(), "the old .lit outlived a run that wants none");
        assert_eq!(std::fs::read(&lux).expect("lux"), b"new lux");
        place_with_companions(&bsp, b"grey bsp", Companions::default()).expect("place");
        let mut names: Vec<_> = std::fs::read_dir(&dir)
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        names.sort();
        assert_eq!(names, ["map.bsp"], "temporaries left behind");
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    #[test]
    fn optional_values_join_only_numbers() {
        let joined = join_optional_values(strings(&["light", "--bounce", "2", "x.bsp"]));
        assert_eq!(joined, strings(&["light", "--bounce=2", "x.bsp"]));
        let alone = join_optional_values(strings(&["light", "--bounce", "x.bsp", "--soft"]));
        assert_eq!(alone, strings(&["light", "--bounce", "x.bsp", "--soft"]));
        let three = strings(&["light", "--lightgrid_dist", "16", "16", "32", "2", "x.bsp"]);
        let three = join_optional_values(three);
        assert_eq!(
            three,
            strings(&["light", "--lightgrid_dist=16 16 32", "2", "x.bsp"])
        );
        let one = join_optional_values(strings(&["light", "--lightgrid_dist", "24.5", "x.bsp"]));
        assert_eq!(one, strings(&["light", "--lightgrid_dist=24.5", "x.bsp"]));
    }
}
