//! Renders two BSPs of the same map (ours and another compiler's) from the first's spawn spots and
//! reports how bright each picture is and how far apart they are: the visual check of light's
//! bounce against LibreQuake's own BSPs (`bench/visual_check.sh`).
//!
//! `cargo run --release -p slipgate-viewer --example compare_lighting -- OURS.bsp THEIRS.bsp
//! OUT_DIR [--palette FILE.lmp] [--spots N]`
//!
//! For each spot it writes `N.ours.png`, `N.theirs.png` and `N.diff.png` (grey where both agree,
//! red where ours is darker, green where ours is brighter, at four times the difference) and
//! prints a Markdown table: mean brightness (Rec. 601 luma, 0-255) of each picture, their mean
//! absolute difference, and the share of pixels more than 16 levels apart.

use anyhow::{Context, Result, bail};
use runtime_viewer::image::write_png;
use runtime_viewer::textures::{pack, unpack};
use runtime_viewer::{Camera, Frame, RenderOptions, Renderer, World};
use std::path::{Path, PathBuf};

const WIDTH: usize = 640;
const HEIGHT: usize = 480;
/// Pixels further apart than this count as visibly different.
const VISIBLE_STEP: f64 = 16.0;

struct Args {
    ours: PathBuf,
    theirs: PathBuf,
    out_dir: PathBuf,
    palette: Option<PathBuf>,
    spots: usize,
}

fn parse_args() -> Result<Args> {
    let mut positional = Vec::new();
    let mut palette = None;
    let mut spots = 4;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--palette" => palette = Some(PathBuf::from(args.next().context("--palette FILE")?)),
            "--spots" => spots = args.next().context("--spots N")?.parse()?,
            _ => positional.push(PathBuf::from(a)),
        }
    }
    let [ours, theirs, out_dir] = <[PathBuf; 3]>::try_from(positional)
        .map_err(|_| anyhow::anyhow!("usage: OURS.bsp THEIRS.bsp OUT_DIR [--palette FILE]"))?;
    Ok(Args {
        ours,
        theirs,
        out_dir,
        palette,
        spots,
    })
}

fn luma(pixel: u32) -> f64 {
    let [r, g, b] = unpack(pixel);
    0.299 * r as f64 + 0.587 * g as f64 + 0.114 * b as f64
}

fn mean_luma(frame: &Frame) -> f64 {
    frame.pixels.iter().map(|&p| luma(p)).sum::<f64>() / frame.pixels.len() as f64
}

/// Grey where the pictures agree; red where `ours` is darker, green where brighter.
fn difference(ours: &Frame, theirs: &Frame) -> (Frame, f64, f64) {
    let mut diff = Frame::new(ours.width, ours.height);
    let (mut sum, mut visible) = (0.0, 0usize);
    for (i, (&a, &b)) in ours.pixels.iter().zip(&theirs.pixels).enumerate() {
        let d = luma(a) - luma(b);
        sum += d.abs();
        visible += usize::from(d.abs() > VISIBLE_STEP);
        let step = (d.abs() * 4.0).min(127.0) as u8;
        diff.pixels[i] = if d < 0.0 {
            pack([128 + step, 128 - step, 128 - step])
        } else {
            pack([128 - step, 128 + step, 128 - step])
        };
    }
    let n = ours.pixels.len() as f64;
    (diff, sum / n, visible as f64 / n)
}

fn render(world: &World, camera: &Camera) -> Frame {
    let mut renderer = Renderer::new(world, RenderOptions::default());
    let mut frame = Frame::new(camera.width, camera.height);
    renderer.render(world, camera, &mut frame);
    frame
}

fn load(path: &Path, palette: Option<&Path>) -> Result<World> {
    World::load(path, palette).with_context(|| format!("{}: cannot load", path.display()))
}

fn main() -> Result<()> {
    let args = parse_args()?;
    let ours = load(&args.ours, args.palette.as_deref())?;
    let theirs = load(&args.theirs, args.palette.as_deref())?;
    let spots = ours.spots();
    if spots.is_empty() {
        bail!("{}: no spawn spots", args.ours.display());
    }
    std::fs::create_dir_all(&args.out_dir)?;
    println!("| spot | origin | ours | theirs | mean abs diff | pixels > {VISIBLE_STEP} apart |");
    println!("|---|---|---|---|---|---|");
    let (mut total_ours, mut total_theirs) = (0.0, 0.0);
    let shown = spots.len().min(args.spots);
    for (n, &(origin, yaw)) in spots.iter().take(shown).enumerate() {
        let camera = Camera {
            origin,
            angles: [0.0, yaw, 0.0],
            width: WIDTH,
            height: HEIGHT,
            fov_x: 90.0,
        };
        let a = render(&ours, &camera);
        let b = render(&theirs, &camera);
        let (diff, mean_diff, visible) = difference(&a, &b);
        for (frame, name) in [(&a, "ours"), (&b, "theirs"), (&diff, "diff")] {
            write_png(frame, &args.out_dir.join(format!("{n}.{name}.png")))?;
        }
        let (la, lb) = (mean_luma(&a), mean_luma(&b));
        total_ours += la;
        total_theirs += lb;
        println!(
            "| {n} | {:.0} {:.0} {:.0} | {la:.1} | {lb:.1} | {mean_diff:.1} | {:.1}% |",
            origin.x,
            origin.y,
            origin.z,
            visible * 100.0
        );
    }
    println!(
        "| mean | | {:.1} | {:.1} | | |",
        total_ours / shown as f64,
        total_theirs / shown as f64
    );
    Ok(())
}
