//! `slipgate wad build DIR OUT.wad`, `slipgate wad list WAD`, `slipgate wad extract WAD|BSP
//! DIR|OUT.wad`.

use crate::build::{BuildOptions, Built, LevelErrors};
use crate::extract::{extract, list};
use crate::{build_folder, read_textures, read_wad};
use anyhow::{Context, Result};
use quake_formats::fsutil::{read_file, write_atomic};
use quake_formats::palette::Palette;
use std::path::{Path, PathBuf};
use std::time::Instant;

const CONVENTIONS: &str = "\
Every .png and .tga directly in DIR is a texture named after its file (lower case, at most 15 \
characters; a leading # stands for *, as in #water1.png for *water1). Sides that are not \
multiples of 16 are stretched up to the next multiple with bilinear filtering (wrapping at the \
edges, since textures tile), with a warning.

Colours are quantised to the game's palette: --palette FILE.lmp (768 bytes), else \
gfx/palette.lmp in the WAD's folder or up to three folders above it (a WAD written to \
id1/maps/ finds id1/gfx/palette.lmp, the palette engines draw it with), else Slipgate's own. \
Fullbright colours (indices 224-255, drawn unlit) are used only where a glow mask \
NAME_glow.png beside NAME.png is bright (a channel of at least 128), and there only. In { \
textures pixels with alpha under 128 become index 255, and no other pixel does; in sky textures \
they become index 0, the front layer's transparent colour, and no other pixel does.

Mip levels 1-3 are each the mean of 2x2 pixels of the true-colour level above (in the file's \
sRGB values, weighted by alpha), then every level is quantised with Floyd-Steinberg error \
diffusion (--no-dither: nearest colour). The summary gives each level's mean colour error both \
ways: per pixel, and of 2x2 block means (what a distant view sees).";

/// `slipgate wad`'s command line.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// `slipgate wad`'s three commands.
#[derive(clap::Subcommand, Debug, Clone)]
pub enum Command {
    /// Build a WAD2 from a folder of PNG and TGA pictures
    #[command(long_about = format!("Build a WAD2 from a folder of PNG and TGA pictures.\n\n{CONVENTIONS}"))]
    Build(BuildArgs),
    /// List a WAD's lumps: name, type, size, fullbright and transparent pixels
    List {
        /// The WAD to list
        wad: PathBuf,
    },
    /// Write a WAD's textures as PNG pictures (holes as alpha 0, fullbrights as NAME_glow.png)
    Extract(ExtractArgs),
}

/// `slipgate wad build`'s arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct BuildArgs {
    /// Folder of .png and .tga pictures
    pub dir: PathBuf,
    /// The WAD to write
    pub out: PathBuf,
    /// A 768-byte palette (palette.lmp); default: gfx/palette.lmp near OUT, else Slipgate's own
    #[arg(long, value_name = "FILE.lmp")]
    pub palette: Option<PathBuf>,
    /// Quantise each pixel to its nearest colour instead of diffusing the error
    #[arg(long)]
    pub no_dither: bool,
    /// Write every texture's sizes and per-level colour errors as JSON to this file
    #[arg(long, value_name = "FILE.json")]
    pub stats: Option<PathBuf>,
}

/// `slipgate wad extract`'s arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct ExtractArgs {
    /// The WAD to extract, or a BSP whose embedded textures to extract
    pub wad: PathBuf,
    /// Folder to write the pictures into (created if missing); a name ending in .wad writes the
    /// textures as a WAD instead
    pub dir: PathBuf,
    /// A 768-byte palette (palette.lmp); default: gfx/palette.lmp near WAD, else Slipgate's own
    #[arg(long, value_name = "FILE.lmp")]
    pub palette: Option<PathBuf>,
}

/// Do what `args` ask, printing a summary on stderr (and `list`'s table on stdout).
pub fn run(args: &Args) -> Result<()> {
    match &args.command {
        Command::Build(args) => run_build(args),
        Command::List { wad } => run_list(wad),
        Command::Extract(args) => run_extract(args),
    }
}

/// `--palette FILE`, else the game's `gfx/palette.lmp` near `wad` (see
/// [`quake_formats::palette::find_game_palette`]), else Slipgate's own; and the file it came from.
fn palette(explicit: Option<&Path>, wad: &Path) -> Result<(Palette, Option<PathBuf>)> {
    let dir = wad.parent().unwrap_or(Path::new("."));
    let Some(path) = explicit
        .map(Path::to_path_buf)
        .or_else(|| quake_formats::palette::find_game_palette(dir))
    else {
        return Ok((Palette::slipgate(), None));
    };
    let bytes = read_file(&path)?;
    let palette = Palette::from_bytes(&bytes).with_context(|| format!("{}", path.display()))?;
    Ok((palette, Some(path)))
}

/// How the summary names the palette used.
fn palette_name(path: Option<&Path>) -> String {
    path.map_or_else(
        || "Slipgate's own palette (no --palette, no gfx/palette.lmp near the WAD)".to_string(),
        |p| format!("palette {}", p.display()),
    )
}

fn progress_bar() -> indicatif::ProgressBar {
    let bar =
        indicatif::ProgressBar::with_draw_target(None, indicatif::ProgressDrawTarget::stderr());
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("wad {bar:40} {pos} textures {elapsed}")
    {
        bar.set_style(style);
    }
    bar
}

fn run_build(args: &BuildArgs) -> Result<()> {
    let started = Instant::now();
    let (palette, palette_path) = palette(args.palette.as_deref(), &args.out)?;
    let options = BuildOptions {
        palette,
        dither: !args.no_dither,
    };
    let bar = progress_bar();
    let built = build_folder(&args.dir, &args.out, &options, &|_| bar.inc(1))?;
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    warn(&built);
    summary(args, &built, palette_path.as_deref(), seconds);
    if let Some(path) = &args.stats {
        let json = serde_json::json!({
            "dir": args.dir,
            "wad": args.out,
            "dither": options.dither,
            "palette": palette_path,
            "textures": built.textures,
            "levels": built.level_errors(),
            "seconds": seconds,
        });
        write_atomic(path, serde_json::to_string_pretty(&json)?.as_bytes())?;
    }
    Ok(())
}

fn warn(built: &Built) {
    for t in &built.textures {
        if t.resized() {
            eprintln!(
                "warning: {}: {}x{} is not a multiple of 16: stretched to {}x{} (bilinear)",
                t.file.display(),
                t.source_size[0],
                t.source_size[1],
                t.size[0],
                t.size[1]
            );
        }
        if t.ignored_holes > 0 {
            eprintln!(
                "warning: {}: {} pixels have alpha under 128, drawn opaque (only {{ and sky \
                 textures have holes)",
                t.file.display(),
                t.ignored_holes
            );
        }
    }
}

fn summary(args: &BuildArgs, built: &Built, palette: Option<&Path>, seconds: f64) {
    let count = |f: &dyn Fn(&crate::build::TextureReport) -> bool| {
        built.textures.iter().filter(|t| f(t)).count()
    };
    eprintln!(
        "wad: {} textures from {} to {} ({} bytes): {} resized, {} with fullbright pixels, {} \
         with holes; {}",
        built.textures.len(),
        args.dir.display(),
        args.out.display(),
        std::fs::metadata(&args.out).map_or(0, |m| m.len()),
        count(&|t| t.resized()),
        count(&|t| t.fullbright_pixels > 0),
        count(&|t| t.transparent_pixels > 0),
        if args.no_dither {
            "nearest colour"
        } else {
            "dithered"
        }
    );
    eprintln!("  {}", palette_name(palette));
    eprint!("{}", error_table(&built.level_errors()));
    eprintln!("  time: {seconds:.2} s");
}

/// The mean colour error of each level, dithered and nearest, per pixel and per 2x2 block.
pub fn error_table(levels: &[LevelErrors; 4]) -> String {
    let mut out = String::from(
        "  mean colour error (RGB distance, 0-441) | per pixel: dithered, nearest | 2x2 blocks: dithered, nearest\n",
    );
    for (level, e) in levels.iter().enumerate() {
        out += &format!(
            "  mip {level} ({:>6} pixels)                   | {:>8.2} {:>8.2}            | {:>8.2} {:>8.2}\n",
            e.dithered.pixels, e.dithered.pixel, e.nearest.pixel, e.dithered.block, e.nearest.block
        );
    }
    out
}

fn run_list(path: &Path) -> Result<()> {
    let wad = read_wad(path)?;
    let entries = list(&wad);
    println!(
        "{:<16} {:<8} {:>9} {:>8} {:>10} {:>6}",
        "name", "type", "size", "bytes", "fullbright", "holes"
    );
    for e in &entries {
        let size = e.size.map_or("-".to_string(), |[w, h]| format!("{w}x{h}"));
        println!(
            "{:<16} {:<8} {:>9} {:>8} {:>10} {:>6}",
            e.name, e.kind, size, e.bytes, e.fullbright_pixels, e.transparent_pixels
        );
    }
    eprintln!("{}: {} lumps", path.display(), entries.len());
    Ok(())
}

fn run_extract(args: &ExtractArgs) -> Result<()> {
    let started = Instant::now();
    let wad = read_textures(&args.wad)?;
    if args
        .dir
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("wad"))
    {
        quake_formats::fsutil::write_atomic(&args.dir, &wad.write())?;
        eprintln!(
            "wrote the {} textures of {} to {}",
            wad.lumps.len(),
            args.wad.display(),
            args.dir.display()
        );
        return Ok(());
    }
    let (palette, palette_path) = palette(args.palette.as_deref(), &args.wad)?;
    let done = extract(&wad, &args.dir, &palette)?;
    eprintln!("{}", palette_name(palette_path.as_deref()));
    for why in &done.skipped {
        eprintln!("note: skipped {why}");
    }
    eprintln!(
        "extracted {} pictures from {} to {} in {:.2} s",
        done.written.len(),
        args.wad.display(),
        args.dir.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A WAD written into a game's `maps/` folder is quantised to that game's palette, which
    /// engines draw it with, not to Slipgate's.
    #[test]
    fn a_wad_beside_a_game_takes_its_palette() {
        let root =
            std::env::temp_dir().join(format!("slipgate-wad-palette-{}", std::process::id()));
        let (maps, gfx) = (root.join("id1").join("maps"), root.join("id1").join("gfx"));
        std::fs::create_dir_all(&maps).expect("maps");
        std::fs::create_dir_all(&gfx).expect("gfx");
        let mut game = [0u8; 768];
        game[3..6].copy_from_slice(&[200, 10, 10]);
        std::fs::write(gfx.join("palette.lmp"), game).expect("palette");
        let wad = maps.join("textures.wad");
        let (found, path) = palette(None, &wad).expect("found");
        assert_eq!(path, Some(gfx.join("palette.lmp")));
        assert_eq!(found.colors[1], [200, 10, 10]);
        // --palette wins; elsewhere it is Slipgate's own.
        let (_, path) =
            palette(Some(&gfx.join("palette.lmp")), &root.join("x.wad")).expect("explicit");
        assert_eq!(path, Some(gfx.join("palette.lmp")));
        let (own, path) = palette(None, &std::env::temp_dir().join("lone.wad")).expect("own");
        assert_eq!((own, path), (Palette::slipgate(), None));
        let _ = std::fs::remove_dir_all(&root);
    }
}
