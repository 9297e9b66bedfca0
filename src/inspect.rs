//! `info` and `convert`: looking at and rewriting files without compiling anything.

use anyhow::{Context, Result, bail};
use quake_formats::bsp::{LUMP_NAMES, Rule};
use quake_formats::fsutil::{read_file, write_atomic};
use quake_formats::lit::LitData;
use quake_formats::wad::Wad;
use quake_formats::{Bsp, BspVersion, Problem, Severity, validate};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Problems printed per rule before the rest are only counted.
const SHOWN_PER_RULE: usize = 20;

#[derive(clap::Args, Debug)]
pub struct InfoArgs {
    /// The BSP file to inspect
    #[arg(required_unless_present = "rules")]
    file: Option<PathBuf>,
    /// Print the rules the validator checks (id, severity, engines, message) and exit
    #[arg(long, conflicts_with = "file")]
    rules: bool,
}

#[derive(clap::Args, Debug)]
pub struct ConvertArgs {
    /// Input BSP or WAD
    input: PathBuf,
    /// Output file (written atomically)
    output: PathBuf,
    /// Write BSP2 (32-bit indices, float bounds)
    #[arg(long, conflicts_with = "bsp29")]
    bsp2: bool,
    /// Write BSP29 (fails with a clear error when the map exceeds its limits)
    #[arg(long)]
    bsp29: bool,
}

pub fn info(args: &InfoArgs) -> Result<ExitCode> {
    match &args.file {
        Some(file) => info_file(file),
        None => {
            print_rules();
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn info_file(file: &Path) -> Result<ExitCode> {
    let bytes = read_file(file)?;
    let bsp = Bsp::read(&bytes).with_context(|| format!("{}", file.display()))?;
    println!(
        "{}: {} ({} bytes)",
        file.display(),
        bsp.version,
        bytes.len()
    );
    print_counts(&bsp);
    let problems = validate(&bsp);
    print_problems(&problems);
    print_lit_beside(file, &bsp)?;
    let errors = problems
        .iter()
        .filter(|p| p.severity == Severity::Error)
        .count();
    Ok(if errors > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

fn print_counts(bsp: &Bsp) {
    let counts = [
        bsp.entities.len(),
        bsp.planes.len(),
        bsp.textures.textures.len(),
        bsp.vertices.len(),
        bsp.visibility.len(),
        bsp.nodes.len(),
        bsp.texinfo.len(),
        bsp.faces.len(),
        bsp.lighting.len(),
        bsp.clipnodes.len(),
        bsp.leafs.len(),
        bsp.marksurfaces.len(),
        bsp.edges.len(),
        bsp.surfedges.len(),
        bsp.models.len(),
    ];
    // Entities, visibility and lighting are byte blobs; the other lumps count records.
    const BYTE_LUMPS: [usize; 3] = [0, 4, 8];
    for (i, (name, count)) in LUMP_NAMES.iter().zip(counts).enumerate() {
        let unit = if BYTE_LUMPS.contains(&i) {
            " bytes"
        } else {
            ""
        };
        println!("  {name:<13} {count:>9}{unit}");
    }
    for lump in &bsp.bspx {
        println!("  BSPX {:<16} {:>9} bytes", lump.name(), lump.data.len());
    }
    let entities = quake_formats::entities::parse_entities(&bsp.entity_text()).unwrap_or_default();
    println!(
        "  {} entities, {} brush models",
        entities.len(),
        bsp.models.len()
    );
}

/// Whether a `.lit` beside the BSP is the one engines would pair with it and the light it holds.
fn print_lit_beside(file: &Path, bsp: &Bsp) -> Result<()> {
    let path = file.with_extension("lit");
    if !path.is_file() {
        return Ok(());
    }
    let data = read_file(&path)?;
    let rgb = match quake_formats::lit::read_any_lit(&data, bsp.luxel_count()) {
        Ok(LitData::Rgb(rgb)) => rgb,
        Ok(LitData::Hdr(words)) => {
            println!(
                "{}: {} luxels of HDR colour (E5BGR9; FTE reads it)",
                path.display(),
                words.len()
            );
            return Ok(());
        }
        Err(e) => {
            println!("warning: {}: {e}; engines ignore it", path.display());
            return Ok(());
        }
    };
    let luxels = bsp.lighting.len();
    let far = quake_formats::lit::grey_disagreements(&rgb, &bsp.lighting);
    if luxels > 0 && far as f64 / luxels as f64 > quake_formats::lit::LIT_MISMATCH_SHARE {
        println!(
            "warning: {}: {far} of {luxels} luxels' grey is more than {} from the lighting lump: \
             the colours of another light run (engines will draw them); light the BSP again",
            path.display(),
            quake_formats::lit::LIT_GREY_TOLERANCE
        );
    } else {
        println!(
            "{}: {luxels} luxels of colour, grey agrees with the lighting lump",
            path.display()
        );
    }
    Ok(())
}

/// Every problem, at most [`SHOWN_PER_RULE`] per rule, then a count per rule.
fn print_problems(problems: &[Problem]) {
    if problems.is_empty() {
        println!("valid: no problems found");
        return;
    }
    let mut by_rule: BTreeMap<Rule, Vec<&Problem>> = BTreeMap::new();
    for p in problems {
        by_rule.entry(p.rule).or_default().push(p);
    }
    for (rule, list) in &by_rule {
        for p in list.iter().take(SHOWN_PER_RULE) {
            println!("{p}");
        }
        if list.len() > SHOWN_PER_RULE {
            println!("  ... and {} more [{rule}]", list.len() - SHOWN_PER_RULE);
        }
    }
    let errors = problems
        .iter()
        .filter(|p| p.severity == Severity::Error)
        .count();
    let summary: Vec<String> = by_rule
        .iter()
        .map(|(rule, list)| format!("{rule} {}", list.len()))
        .collect();
    println!(
        "{errors} error(s), {} warning(s): {}",
        problems.len() - errors,
        summary.join(", ")
    );
}

fn print_rules() {
    for rule in Rule::ALL {
        let info = rule.info();
        println!("{} ({}; {})", info.id, info.severity, info.engines);
        println!("  message: {}", info.message);
        println!("  checks:  {}", info.checks);
    }
}

pub fn convert(args: &ConvertArgs) -> Result<()> {
    let bytes = read_file(&args.input)?;
    let name = args.input.display();
    let out = if bytes.starts_with(b"WAD2") {
        if args.bsp2 || args.bsp29 {
            bail!("{name}: --bsp2/--bsp29 apply to BSP files, not WADs");
        }
        Wad::read(&bytes)
            .with_context(|| format!("{name}"))?
            .write()
    } else {
        let bsp = Bsp::read(&bytes).with_context(|| format!("{name}"))?;
        quake_formats::check_usable(&bsp).with_context(|| format!("{name}"))?;
        let version = if args.bsp2 {
            BspVersion::Bsp2
        } else if args.bsp29 {
            BspVersion::Bsp29
        } else {
            bsp.version
        };
        let converted = bsp.converted(version).with_context(|| format!("{name}"))?;
        converted.write().with_context(|| format!("{name}"))?
    };
    write_atomic(&args.output, &out)?;
    println!("wrote {} ({} bytes)", args.output.display(), out.len());
    Ok(())
}
