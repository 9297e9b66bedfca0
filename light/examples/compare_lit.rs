//! Error of a lit BSP against a reference lit earlier: `compare_lit LIT.bsp REFERENCE.bsp STRIDE
//! [DIRECT.bsp]`, where REFERENCE.bsp is the same BSP lit with `--reference --face-stride
//! STRIDE`. Compares the grey bytes of every style of those faces, in 8-bit levels, as
//! `--compare-reference` does, so the slow reference is traced once for many runs. With
//! DIRECT.bsp (the reference without bounce), it also lists the faces lit only by bounce (no
//! direct light anywhere on them) that have luxels black where the reference is lit.

use light::{FaceLightmap, compare, lightmaps_in};
use quake_formats::Bsp;
use std::collections::HashMap;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (lit, reference, stride, direct) = match &args[..] {
        [a, b, c] => (a, b, c, None),
        [a, b, c, d] => (a, b, c, Some(d)),
        _ => anyhow::bail!("usage: compare_lit LIT.bsp REFERENCE.bsp STRIDE [DIRECT.bsp]"),
    };
    let stride: usize = stride.parse()?;
    anyhow::ensure!(stride > 0, "STRIDE must be at least 1");
    let read = |path: &String| -> anyhow::Result<Bsp> { Ok(Bsp::read(&std::fs::read(path)?)?) };
    let (lit, reference) = (read(lit)?, read(reference)?);
    let faces: Vec<usize> = (0..reference.faces.len()).step_by(stride).collect();
    let (ours, theirs) = (lightmaps_in(&lit, &faces), lightmaps_in(&reference, &faces));
    let e = compare(&ours, &theirs);
    println!(
        "RMSE {:.3}, max {} levels over {} luxels ({} differ by more than 8, {} by more than 2; \
         {} black where the reference is not, {} where it is above 2)",
        e.rmse, e.max, e.luxels, e.over_8, e.over_2, e.black, e.black_over_2
    );
    if let Some(direct) = direct {
        let direct = lightmaps_in(&read(direct)?, &faces);
        let style0 = |maps: &[FaceLightmap]| -> HashMap<usize, Vec<u8>> {
            maps.iter()
                .filter_map(|m| Some((m.face, m.style_grey(0)?.to_vec())))
                .collect()
        };
        let (ours, theirs, direct) = (
            style0(&ours.lightmaps),
            style0(&theirs.lightmaps),
            style0(&direct.lightmaps),
        );
        let (mut compared, mut faces_hit, mut luxels, mut luxels_over_2) = (0, 0, 0, 0);
        for (face, d) in &direct {
            let (Some(a), Some(r)) = (ours.get(face), theirs.get(face)) else {
                continue;
            };
            if d.iter().any(|&v| v > 0) || a.len() != r.len() {
                continue;
            }
            compared += 1;
            let black = |above: u8| {
                a.iter()
                    .zip(r)
                    .filter(|&(&x, &y)| x == 0 && y > above)
                    .count()
            };
            let (lit, over_2) = (black(0), black(2));
            if lit > 0 {
                println!(
                    "bounce-only face {face}: {lit} of {} luxels black where the reference is \
                     lit ({over_2} where it is above 2; reference up to {})",
                    a.len(),
                    r.iter().max().unwrap_or(&0)
                );
                faces_hit += 1;
                luxels += lit;
                luxels_over_2 += over_2;
            }
        }
        println!(
            "bounce-only faces: {compared}; with luxels black where the reference is lit: \
             {faces_hit} ({luxels} luxels, {luxels_over_2} where it is above 2)"
        );
    }
    Ok(())
}
