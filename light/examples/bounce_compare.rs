//! Bounce against the reference, ours and ericw-tools': `bounce_compare UNLIT.bsp STRIDE
//! [ERICW_LIT.bsp] [GRIDxSTRATA ...]`. Lights every STRIDE-th face of UNLIT.bsp with `--bounce`
//! (default and `--extra4`; from a point per face, the default, and gathered over the surfaces,
//! `-emissivequality high`) and with `--reference --bounce`, and reads ericw-tools' lightmaps of
//! the same faces from ERICW_LIT.bsp (its `light -bounce` of the same BSP); errors are in grey
//! levels. Each `GRIDxSTRATA` (for example `4x8`) also runs both modes with the fast bounce's
//! receivers every GRID luxels casting STRATA² rays each; a trailing `s` (`2x6s`) smooths the
//! receivers as the default mode does.

use light::{
    BounceDensity as Density, EmissiveQuality, Lighting, Options, Quality, compare,
    compute_lighting, lightmaps_in,
};
use quake_formats::Bsp;

/// RMSE, max and share of luxels more than 2 levels off.
fn report(name: &str, a: &Lighting, reference: &Lighting) {
    let e = compare(a, reference);
    println!(
        "{name}: RMSE {:.3}, max {}, > 2 levels {:.2} % of {} luxels",
        e.rmse,
        e.max,
        100.0 * e.over_2 as f64 / e.luxels.max(1) as f64,
        e.luxels
    );
}

/// `GRIDxSTRATA` or `GRIDxSTRATAs` as a density.
fn parse_density(arg: &str) -> Option<Density> {
    let (stride, strata) = arg.split_once('x')?;
    let (strata, smooth) = match strata.strip_suffix('s') {
        Some(s) => (s, true),
        None => (strata, false),
    };
    Some(Density {
        stride: stride.parse().ok().filter(|&s| s > 0)?,
        strata: strata.parse().ok().filter(|&s| s > 0)?,
        widen_last: false,
        smooth,
    })
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(path), Some(stride)) = (args.first(), args.get(1)) else {
        anyhow::bail!("usage: bounce_compare UNLIT.bsp STRIDE [ERICW_LIT.bsp] [GRIDxSTRATA ...]");
    };
    let stride: usize = stride.parse()?;
    anyhow::ensure!(stride > 0, "STRIDE must be at least 1");
    let theirs = args.get(2).filter(|a| parse_density(a).is_none());
    let mut densities = vec![None];
    for arg in args.iter().skip(2).filter(|a| Some(*a) != theirs) {
        let density =
            parse_density(arg).ok_or_else(|| anyhow::anyhow!("not GRIDxSTRATA: {arg}"))?;
        densities.push(Some(density));
    }
    let bsp = Bsp::read(&std::fs::read(path)?)?;
    let faces: Vec<usize> = (0..bsp.faces.len()).step_by(stride).collect();
    // `emission: None` is the default (`low`).
    let run = |quality: Quality,
               bounce: bool,
               emission: Option<EmissiveQuality>,
               density: Option<Density>| {
        let mut o = Options {
            quality,
            only_faces: Some(faces.clone()),
            bounce_density: density,
            ..Options::default()
        };
        o.overrides.bounce = bounce.then_some(1);
        o.overrides.emissive_quality = emission;
        compute_lighting(&bsp, &o)
    };
    let reference = run(Quality::Reference, true, None, None)?;
    println!(
        "reference with bounce: {:.1} s",
        reference.stats.seconds_total
    );
    let direct_reference = run(Quality::Reference, false, None, None)?;
    for (name, quality) in [("default", Quality::Default), ("--extra4", Quality::Extra4)] {
        let lit = run(quality, true, None, None)?;
        report(
            &format!(
                "ours {name} --bounce (from a point per face; {} bounce rays, {:.2} s)",
                lit.stats.bounce_rays, lit.stats.seconds_bounce
            ),
            &lit,
            &reference,
        );
        for &density in &densities {
            let lit = run(quality, true, Some(EmissiveQuality::High), density)?;
            let d = density.unwrap_or_else(|| Density::for_quality(quality));
            report(
                &format!(
                    "ours {name} --bounce -emissivequality high (grid {}, {} rays; {} bounce rays, {:.2} s)",
                    d.stride,
                    d.strata * d.strata,
                    lit.stats.bounce_rays,
                    lit.stats.seconds_bounce
                ),
                &lit,
                &reference,
            );
        }
        report(
            &format!("ours {name}, no bounce, vs direct reference"),
            &run(quality, false, None, None)?,
            &direct_reference,
        );
    }
    if let Some(theirs) = theirs {
        let lit = Bsp::read(&std::fs::read(theirs)?)?;
        let lightmaps = lightmaps_in(&lit, &faces);
        report("ericw-tools -bounce", &lightmaps, &reference);
        report(
            "ericw-tools -bounce vs our direct reference",
            &lightmaps,
            &direct_reference,
        );
    }
    Ok(())
}
