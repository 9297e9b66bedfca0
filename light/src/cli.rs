//! Command line of `slipgate-light` (mounted by the lead as `slipgate light`).

use std::path::{Path, PathBuf};

use anyhow::Context;
use quake_formats::Bsp;
use quake_formats::fsutil::{Staged, read_file, write_atomic};

use quake_formats::palette::Palette;

use crate::lights::GlobalOverrides;
use crate::{
    ErrorStats, Options, Quality, compare, compute_lighting, finish_lighting, trace_lighting,
};

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
    /// Average each luxel with its neighbours within N luxels (`--soft` = 1, `--soft=N`).
    #[arg(
        long,
        value_name = "N",
        num_args = 0..=1,
        require_equals = true,
        default_missing_value = "1"
    )]
    pub soft: Option<usize>,
    /// Light contributions below this (in light units) count as zero.
    #[arg(long, default_value_t = 0.001)]
    pub gate: f64,
    /// Scale every light's fade distance (overrides worldspawn `_dist`).
    #[arg(long)]
    pub dist: Option<f64>,
    /// Scale brightness to bytes (overrides worldspawn `_range`, default 0.5).
    #[arg(long)]
    pub range: Option<f64>,
    /// Directions per sun penumbra and per sky dome.
    #[arg(long, default_value_t = 100)]
    pub sunsamples: usize,
    /// Dirt (ambient occlusion) on every light, whatever worldspawn `_dirt` says
    /// (lights with `_dirt -1` still opt out).
    #[arg(long)]
    pub dirt: bool,
    /// Dirt ray pattern: 0 ordered, 1 random (overrides worldspawn `_dirtmode`).
    #[arg(long, value_name = "N")]
    pub dirtmode: Option<f64>,
    /// Dirt ray length (overrides worldspawn `_dirtdepth`, default 128).
    #[arg(long, value_name = "UNITS")]
    pub dirtdepth: Option<f64>,
    /// Dirt strength (overrides worldspawn `_dirtscale`, default 1).
    #[arg(long, value_name = "N")]
    pub dirtscale: Option<f64>,
    /// Dirt exponent (overrides worldspawn `_dirtgain`, default 1).
    #[arg(long, value_name = "N")]
    pub dirtgain: Option<f64>,
    /// Dirt cone angle from the normal in degrees, 1-90 (overrides `_dirtangle`, default 88).
    #[arg(long, value_name = "DEGREES")]
    pub dirtangle: Option<f64>,
    /// Add minlight to every luxel's light instead of raising dark luxels to it.
    #[arg(long)]
    pub addmin: bool,
    /// Diffuse interreflection, N passes (`--bounce` = 1; overrides worldspawn `_bounce`).
    #[arg(
        long,
        value_name = "N",
        num_args = 0..=1,
        require_equals = true,
        default_missing_value = "1"
    )]
    pub bounce: Option<usize>,
    /// Brightness of bounced light (overrides worldspawn `_bouncescale`, default 1).
    #[arg(long, value_name = "S")]
    pub bouncescale: Option<f64>,
    /// 0 = surfaces reflect grey, 1 = their texture's mean colour (overrides
    /// `_bouncecolorscale`, default 0).
    #[arg(long, value_name = "W")]
    pub bouncecolorscale: Option<f64>,
    /// Styled (switchable, animated) light bounces too (as worldspawn `_bouncestyled 1`).
    #[arg(long)]
    pub bouncestyled: bool,
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
    /// Only update the entity lump: give switchable lights (`targetname`) their styles without
    /// relighting, after `slipgate bsp --onlyents` replaced the entities.
    #[arg(long, conflicts_with_all = ["compare_reference", "bench_occlusion"])]
    pub onlyents: bool,
    /// Worker threads for tracing (default: one per core).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub threads: Option<u16>,
    /// Consider every light for every face (no range, plane-side or PVS culling).
    #[arg(long)]
    pub no_cull: bool,
    /// Write counts and timings as JSON.
    #[arg(long, value_name = "FILE.json")]
    pub stats: Option<PathBuf>,
    /// Measurement: light only every Nth face (the others get no lightmap).
    #[arg(long, value_name = "N")]
    pub face_stride: Option<usize>,
    /// Measurement: also light the same faces with --reference and report the error.
    #[arg(long)]
    pub compare_reference: bool,
    /// Measurement: time a bare occlusion loop over up to this many shadow rays.
    #[arg(long, value_name = "RAYS")]
    pub bench_occlusion: Option<usize>,
}

impl Args {
    fn options(&self, quality: Quality) -> Options {
        Options {
            quality,
            soft_radius: self.soft.unwrap_or(0),
            gate: self.gate,
            overrides: GlobalOverrides {
                dist: self.dist,
                range: self.range,
                sunsamples: self.sunsamples,
                dirt: self.dirt,
                dirt_mode: self.dirtmode,
                dirt_depth: self.dirtdepth,
                dirt_scale: self.dirtscale,
                dirt_gain: self.dirtgain,
                dirt_angle: self.dirtangle,
                addmin: self.addmin,
                bounce: self.bounce,
                bounce_scale: self.bouncescale,
                bounce_color_scale: self.bouncecolorscale,
                bounce_styled: self.bouncestyled,
            },
            only_faces: None,
            no_cull: self.no_cull,
            progress: true,
            palette: None,
            bounce_density: None,
        }
    }

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
}

fn lit_path(bsp: &Path) -> PathBuf {
    bsp.with_extension("lit")
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

/// Light's options whose value is optional (`--bounce [N]`, `--soft [N]`): a following number
/// is their value ([`quake_formats::cli::join_optional_values`]).
pub fn join_optional_values(args: impl IntoIterator<Item = String>) -> Vec<String> {
    quake_formats::cli::join_optional_values(args, &["--bounce", "--soft"])
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
    /// The library options these arguments ask for, with the palette `run` would find.
    pub fn lighting_options(&self) -> anyhow::Result<Options> {
        let mut options = self.options(self.quality());
        options.palette = find_palette(self)?;
        Ok(options)
    }

    /// The `.lit` to write beside `bsp`, which [`crate::apply_lighting`] just lit and which
    /// returned `coloured` (`--lit` and `--nolit` decide; `None`: no `.lit`).
    pub fn lit_to_write(&self, bsp: &Bsp, coloured: Option<Vec<u8>>) -> Option<Vec<u8>> {
        match self.lit_file() {
            LitFile::WhenColoured => coloured,
            // White light: each luxel's grey level in all three channels.
            LitFile::Always => coloured.or_else(|| {
                let rgb: Vec<u8> = bsp.lighting.iter().flat_map(|&g| [g, g, g]).collect();
                Some(quake_formats::lit::write_lit(&rgb))
            }),
            LitFile::Never => None,
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

pub fn run(args: &Args) -> anyhow::Result<()> {
    match args.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(usize::from(n))
            .build()
            .context("starting the worker threads")?
            .install(|| run_with_current_threads(args)),
        None => run_with_current_threads(args),
    }
}

fn run_with_current_threads(args: &Args) -> anyhow::Result<()> {
    let path = &args.bsp;
    let data = read_file(path)?;
    let mut bsp = Bsp::read(&data).with_context(|| format!("{}", path.display()))?;
    if args.onlyents {
        return update_entities_only(args, bsp);
    }
    let mut options = args.lighting_options()?;
    if let Some(stride) = args.face_stride {
        anyhow::ensure!(stride > 0, "--face-stride must be at least 1");
        options.only_faces = Some((0..bsp.faces.len()).step_by(stride).collect());
    }
    let lighting =
        compute_lighting(&bsp, &options).with_context(|| format!("lighting {}", path.display()))?;
    let s = &lighting.stats;
    let rays = s.shadow_rays + s.sun_rays + s.dirt_rays + s.placement_rays;
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
        "light: {rays} rays ({} shadow, {} sun, {} dirt, {} placement) in {:.2} s trace + {:.2} s setup: {:.2} Mrays/s",
        s.shadow_rays,
        s.sun_rays,
        s.dirt_rays,
        s.placement_rays,
        s.seconds_trace,
        s.seconds_setup,
        s.rays_per_second / 1e6
    );
    if s.fullbright {
        eprintln!(
            "light: no lights, suns or minlight: lighting lump left empty (engines draw the map fullbright)"
        );
    }
    if s.faces_with_dropped_styles > 0 {
        eprintln!(
            "light: warning: {} faces are reached by more than 4 light styles; the dimmest were dropped",
            s.faces_with_dropped_styles
        );
    }

    let mut extra = serde_json::Map::new();
    if args.compare_reference {
        let mut reference = options.clone();
        reference.quality = Quality::Reference;
        let raw = trace_lighting(&bsp, &reference)?;
        let exact = finish_lighting(&raw, 0);
        let report = |what: &str, e: &ErrorStats| {
            eprintln!(
                "light: against {what}: RMSE {:.3}, max {} levels over {} luxels ({} differ by more than 8)",
                e.rmse, e.max, e.luxels, e.over_8
            );
        };
        let r = &exact.stats;
        eprintln!(
            "light: --reference took {:.2} s, {} rays",
            r.seconds_total,
            r.shadow_rays + r.sun_rays + r.dirt_rays + r.placement_rays
        );
        let e: ErrorStats = compare(&lighting, &exact);
        report("--reference", &e);
        extra.insert("error_vs_reference".into(), serde_json::to_value(e)?);
        if options.soft_radius > 0 {
            // The filter blurs on purpose: also measure against the reference blurred the same way.
            let e = compare(&lighting, &finish_lighting(&raw, options.soft_radius));
            report("--reference with the same --soft filter", &e);
            extra.insert(
                "error_vs_filtered_reference".into(),
                serde_json::to_value(e)?,
            );
        }
        extra.insert(
            "reference_seconds".into(),
            serde_json::to_value(r.seconds_total)?,
        );
    }
    if let Some(max_rays) = args.bench_occlusion {
        let prep = crate::prepare(&bsp, &options)?;
        let b = crate::bench::bare_occlusion(&bsp, &prep, options.gate, max_rays);
        eprintln!(
            "light: bare occlusion loop: {} rays in {:.3} s: {:.2} Mrays/s",
            b.rays,
            b.seconds,
            b.rays_per_second / 1e6
        );
        extra.insert("bare_occlusion".into(), serde_json::to_value(b)?);
    }

    let lit = crate::apply_lighting(&mut bsp, &lighting);
    let lit = args.lit_to_write(&bsp, lit);
    let out = args.output.as_ref().unwrap_or(path);
    place_lit_pair(out, &bsp.write()?, lit)?;
    if let Some(stats_path) = &args.stats {
        let mut json = serde_json::to_value(&lighting.stats)?;
        if let serde_json::Value::Object(map) = &mut json {
            map.extend(extra);
            map.insert("quality".into(), serde_json::to_value(options.quality)?);
        }
        write_atomic(stats_path, serde_json::to_string_pretty(&json)?.as_bytes())?;
    }
    Ok(())
}

/// One step of putting a lit BSP and its `.lit` in place.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PairStep {
    RemoveOldLit,
    PlaceBsp,
    PlaceLit,
}

/// Engines take a `.lit` whose size is three times the BSP's lighting lump (QuakeSpasm and
/// DarkPlaces check only that; older engines not even that), so an old `.lit` beside the new BSP
/// would paint the old light's colours over it. The old `.lit` goes before the new BSP arrives and
/// the new one after: a kill between any two steps leaves a BSP with its own `.lit` or with none.
const PAIR_ORDER: [PairStep; 3] = [
    PairStep::RemoveOldLit,
    PairStep::PlaceBsp,
    PairStep::PlaceLit,
];

/// Puts the lit BSP at `out` and its `.lit` (or none) beside it in [`PAIR_ORDER`], after both are
/// written in full under temporary names (failing to write either leaves the old pair untouched).
fn place_lit_pair(out: &Path, bsp: &[u8], lit: Option<Vec<u8>>) -> anyhow::Result<()> {
    let lit_file = lit_path(out);
    let mut staged_bsp = Some(Staged::write(out, bsp)?);
    let mut staged_lit = lit
        .map(|bytes| Staged::write(&lit_file, &bytes))
        .transpose()?;
    for step in PAIR_ORDER {
        let staged = match step {
            PairStep::RemoveOldLit => {
                remove_old_lit(&lit_file, staged_lit.is_none())?;
                None
            }
            PairStep::PlaceBsp => staged_bsp.take(),
            PairStep::PlaceLit => staged_lit.take(),
        };
        if let Some(staged) = staged {
            staged.commit()?;
        }
    }
    Ok(())
}

/// Removes a `.lit` left from an earlier run, saying so when no new one replaces it.
fn remove_old_lit(lit_file: &Path, none_wanted: bool) -> anyhow::Result<()> {
    if !lit_file.exists() {
        return Ok(());
    }
    std::fs::remove_file(lit_file)
        .with_context(|| format!("removing stale {}", lit_file.display()))?;
    if none_wanted {
        eprintln!(
            "light: removed {} (left from an earlier run; no .lit is wanted now)",
            lit_file.display()
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
                        PairStep::RemoveOldLit => lit = None,
                        PairStep::PlaceBsp => bsp = Run::New,
                        PairStep::PlaceLit if wants_lit => lit = Some(Run::New),
                        PairStep::PlaceLit => {}
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
        let lit = lit_path(&bsp);
        std::fs::write(&bsp, b"old bsp").expect("write");
        std::fs::write(&lit, b"old lit").expect("write");
        place_lit_pair(&bsp, b"new bsp", Some(b"new lit".to_vec())).expect("place");
        assert_eq!(std::fs::read(&bsp).expect("bsp"), b"new bsp");
        assert_eq!(std::fs::read(&lit).expect("lit"), b"new lit");
        place_lit_pair(&bsp, b"grey bsp", None).expect("place");
        assert_eq!(std::fs::read(&bsp).expect("bsp"), b"grey bsp");
        assert!(!lit.exists(), "the old .lit outlived a run that wants none");
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
    }
}
