//! `decompile`: a compiled BSP back into a `.map` (ericw-tools' `bsputil --decompile`).

use anyhow::{Context, Result};
use quake_formats::Bsp;
use quake_formats::fsutil::{read_file, write_atomic};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct DecompileArgs {
    /// The BSP to decompile
    bsp: PathBuf,
    /// The .map to write (default: the BSP's name with -decompile.map)
    out: Option<PathBuf>,
    /// Write Valve 220 texture axes (exact for every face) instead of Quake's format
    #[arg(long)]
    valve: bool,
}

pub fn decompile(args: &DecompileArgs) -> Result<()> {
    let bytes = read_file(&args.bsp)?;
    let bsp = Bsp::read(&bytes).with_context(|| format!("{}", args.bsp.display()))?;
    let options = decompile::Options {
        format: if args.valve {
            decompile::MapFormat::Valve
        } else {
            decompile::MapFormat::Quake
        },
        ..decompile::Options::default()
    };
    let out = decompile::decompile(&bsp, &options)
        .with_context(|| format!("decompiling {}", args.bsp.display()))?;
    let path = args.out.clone().unwrap_or_else(|| {
        let stem = args.bsp.file_stem().unwrap_or_default().to_string_lossy();
        args.bsp.with_file_name(format!("{stem}-decompile.map"))
    });
    // Quake's text is Latin-1: chars above U+00FF do not occur (the lump was Latin-1 too).
    let latin1: Vec<u8> = out
        .text
        .chars()
        .map(|c| u8::try_from(u32::from(c)).unwrap_or(b'?'))
        .collect();
    write_atomic(&path, &latin1)?;
    for w in &out.warnings {
        eprintln!("warning: {w}");
    }
    let s = &out.stats;
    eprintln!(
        "wrote {}: {} entities ({} with brushes), {} brushes, {} faces textured, {} without a face \
         (skip)",
        path.display(),
        s.entities,
        s.brush_entities,
        s.brushes,
        s.textured_faces,
        s.untextured_faces
    );
    Ok(())
}
