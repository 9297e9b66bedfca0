//! `mapgen [OUT_DIR]`: regenerate the maps and WAD; `mapgen random --seed N OUT.map`: write one
//! random map; `mapgen clutter --brushes N OUT.map`: write a clutter benchmark map.

use anyhow::Context;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Directory to write into (default: the `maps/` directory of the source tree)
    pub out_dir: Option<PathBuf>,
    /// Write counts and timings as JSON to this file
    #[arg(long, value_name = "FILE.json")]
    pub stats: Option<PathBuf>,
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(clap::Subcommand, Debug, Clone)]
pub enum Command {
    /// Write the random map of a seed (the maps `tests/generated_maps.rs` checks)
    Random {
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Rooms joined by corridors
        #[arg(long, default_value_t = crate::random::RandomOptions::default().rooms)]
        rooms: usize,
        /// Brushes tried in each room
        #[arg(long, default_value_t = crate::random::RandomOptions::default().objects_per_room)]
        objects: usize,
        out: PathBuf,
    },
    /// Write a clutter benchmark map: rooms of heaped, turned brushes (bench/csg_scaling.sh)
    Clutter {
        /// Heaped brushes, besides the rooms' shells
        #[arg(long, default_value_t = 1000)]
        brushes: usize,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        out: PathBuf,
    },
}

/// The `maps/` directory this crate lives in.
pub fn default_out_dir() -> PathBuf {
    let gen_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    gen_dir.parent().unwrap_or(gen_dir).to_path_buf()
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    if let Some(Command::Random {
        seed,
        rooms,
        objects,
        out,
    }) = &args.command
    {
        let options = crate::random::RandomOptions {
            rooms: *rooms,
            objects_per_room: *objects,
        };
        let text = crate::random::random_map(*seed, &options).to_text();
        quake_formats::fsutil::write_atomic(out, text.as_bytes())
            .with_context(|| format!("writing {}", out.display()))?;
        eprintln!("wrote random map {seed} to {}", out.display());
        return Ok(());
    }
    if let Some(Command::Clutter { brushes, seed, out }) = &args.command {
        let text = crate::clutter::clutter_map(*brushes, *seed).to_text();
        quake_formats::fsutil::write_atomic(out, text.as_bytes())
            .with_context(|| format!("writing {}", out.display()))?;
        eprintln!(
            "wrote clutter map of {brushes} brushes to {}",
            out.display()
        );
        return Ok(());
    }
    let start = Instant::now();
    let dir = args.out_dir.clone().unwrap_or_else(default_out_dir);
    let files = crate::write_all(&dir)?;
    let seconds = start.elapsed().as_secs_f64();
    for f in &files {
        eprintln!(
            "{:<24} {:>8} bytes {:>4} brushes {:>3} entities",
            f.path,
            f.bytes.len(),
            f.brushes,
            f.entities
        );
    }
    eprintln!(
        "wrote {} files to {} in {:.3} s",
        files.len(),
        dir.display(),
        seconds
    );
    if let Some(path) = &args.stats {
        let list: Vec<serde_json::Value> = files
            .iter()
            .map(|f| {
                serde_json::json!({
                    "path": f.path, "bytes": f.bytes.len(),
                    "brushes": f.brushes, "entities": f.entities,
                })
            })
            .collect();
        let stats = serde_json::json!({ "files": list, "seconds": seconds });
        let text = serde_json::to_string_pretty(&stats)?;
        quake_formats::fsutil::write_atomic(path, text.as_bytes())
            .with_context(|| format!("writing stats to {}", path.display()))?;
    }
    Ok(())
}
