//! `slipgate-vis`: compute the PVS of a compiled map from the `.prt` file beside it.

use crate::{VisMode, VisOptions};
use anyhow::{Context, Result};
use quake_formats::Bsp;
use quake_formats::fsutil::{read_file, write_atomic};
use quake_formats::prt::PortalFile;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// The compiled map; its portal file MAP.prt must lie beside it. Rewritten in place.
    pub bsp: PathBuf,
    /// Base vis only: quick and conservative, but sees more than it needs to
    #[arg(long)]
    pub fast: bool,
    /// Separating-plane testing level of the full flow (0..=4; higher is tighter and slower)
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u8).range(0..=4), conflicts_with = "fast")]
    pub level: u8,
    /// Portal file to read instead of MAP.prt
    #[arg(long)]
    pub prt: Option<PathBuf>,
    /// Worker threads (default: all cores)
    #[arg(long)]
    pub threads: Option<usize>,
    /// After computing, check the PVS against this many random sight lines traced through the map
    #[arg(long, default_value_t = 0)]
    pub sample_pairs: usize,
    /// Write counts and timings as JSON to this file
    #[arg(long)]
    pub stats: Option<PathBuf>,
}

pub fn run(args: &Args) -> Result<()> {
    let total = Instant::now();
    let bsp_name = args.bsp.display();
    let mut bsp = Bsp::read(&read_file(&args.bsp)?).with_context(|| format!("{bsp_name}"))?;
    let prt_path = args
        .prt
        .clone()
        .unwrap_or_else(|| args.bsp.with_extension("prt"));
    let prt = read_portals(&prt_path)?;
    crate::check_portals_match(&bsp, prt.num_leafs as usize)
        .with_context(|| format!("{} and {bsp_name}", prt_path.display()))?;

    let options = VisOptions {
        mode: if args.fast {
            VisMode::Fast
        } else {
            VisMode::Full { level: args.level }
        },
        threads: args.threads,
        progress: true,
    };
    let result =
        crate::compute_vis(&prt, &options).with_context(|| format!("{}", prt_path.display()))?;
    let c = &result.stats;
    if c.misoriented_portals > 0 {
        eprintln!(
            "warning: {}: {} of {} one-way portals face the wrong way or bound non-convex leaves",
            prt_path.display(),
            c.misoriented_portals,
            c.portals
        );
    }

    let start = Instant::now();
    let lump = crate::write_vis(&mut bsp, &result.pvs).with_context(|| format!("{bsp_name}"))?;
    let hearing = crate::ambient::ambient_levels(&mut bsp, &result.pvs)?;
    let bytes = bsp.write().with_context(|| format!("{bsp_name}"))?;
    write_atomic(&args.bsp, &bytes)?;
    let write_seconds = start.elapsed().as_secs_f64();

    let sampling = if args.sample_pairs > 0 {
        Some(crate::sample::sample_visibility(
            &bsp,
            &result.pvs,
            args.sample_pairs,
            1,
        )?)
    } else {
        None
    };

    let n = c.leafs.max(1) as f64;
    eprintln!(
        "vis ({}): {} leaves in {} clusters, {} one-way portals ({} degenerate dropped)",
        if args.fast {
            "fast".to_string()
        } else {
            format!("full, level {}", args.level)
        },
        c.leafs,
        c.clusters,
        c.portals,
        c.degenerate_portals
    );
    eprintln!(
        "  visible leaves per leaf: average {:.1} ({:.1}%), max {}",
        c.average_visible,
        100.0 * c.average_visible / n,
        c.max_visible
    );
    eprintln!(
        "  visibility lump: {} bytes ({} unique rows, {} bytes uncompressed); {hearing} leaves hear ambient sounds",
        lump.compressed_bytes, lump.unique_rows, lump.uncompressed_bytes
    );
    eprintln!(
        "  time: base vis {:.2} s, flow {:.2} s, write {:.2} s, total {:.2} s",
        c.base_seconds,
        c.flow_seconds,
        write_seconds,
        total.elapsed().as_secs_f64()
    );
    if let Some(s) = &sampling {
        eprintln!(
            "  sampling: {} pairs, {:.2}% visible by sight lines vs {:.2}% in the PVS; {} too small",
            s.pairs,
            100.0 * s.visible_fraction,
            100.0 * s.pvs_fraction,
            s.violations
        );
    }
    if let Some(path) = &args.stats {
        let json = serde_json::json!({
            "mode": if args.fast { "fast" } else { "full" },
            "level": args.level,
            "compute": c,
            "lump": lump,
            "ambient_leafs": hearing,
            "write_seconds": write_seconds,
            "total_seconds": total.elapsed().as_secs_f64(),
            "sampling": sampling,
        });
        write_atomic(path, serde_json::to_string_pretty(&json)?.as_bytes())?;
    }
    Ok(())
}

fn read_portals(path: &Path) -> Result<PortalFile> {
    let bytes =
        read_file(path).context("vis needs the portal file the compiler writes beside the BSP")?;
    PortalFile::parse(&String::from_utf8_lossy(&bytes))
        .with_context(|| format!("{}", path.display()))
}
