//! Per-face agreement of two lightings of the same BSP: `ericw_agreement OURS.bsp THEIRS.bsp
//! [WORST]`, where both files are one compiled, vised BSP lit by two tools (ours, and
//! ericw-tools' `light` at the same setting; `bench/light_agreement.sh` runs both). For every
//! face it takes the mean of each style's grey lightmap, and counts the faces with the same
//! styles (in whichever order each tool wrote them: both put the brightest first, and near ties
//! fall either way) whose means agree within 5 levels style by style, the faces one tool lights
//! and the other leaves without a lightmap, and the faces whose styles differ; then it lists the WORST faces (default 20) that
//! differ most, with their model, texture and centre, to look at in the map.

use light::{FaceLightmap, lightmaps_in};
use quake_formats::Bsp;

/// Per-face means within this many levels count as agreeing.
const AGREE_LEVELS: f64 = 5.0;

/// The mean of each style's lightmap of one face.
fn style_means(map: &FaceLightmap) -> Vec<(u8, f64)> {
    map.styles
        .iter()
        .zip(&map.grey)
        .map(|(&style, grey)| {
            let sum: u64 = grey.iter().map(|&v| u64::from(v)).sum();
            (style, sum as f64 / grey.len().max(1) as f64)
        })
        .collect()
}

/// Each face's style means in order of style, `None` for a face without a lightmap.
fn faces_means(bsp: &Bsp) -> Vec<Option<Vec<(u8, f64)>>> {
    let all: Vec<usize> = (0..bsp.faces.len()).collect();
    let mut out = vec![None; bsp.faces.len()];
    for map in lightmaps_in(bsp, &all).lightmaps {
        let mut means = style_means(&map);
        means.sort_by_key(|&(style, _)| style);
        out[map.face] = Some(means);
    }
    out
}

/// The model each face belongs to.
fn face_models(bsp: &Bsp) -> Vec<usize> {
    let mut out = vec![0; bsp.faces.len()];
    for (m, model) in bsp.models.iter().enumerate() {
        let first = model.first_face as usize;
        for f in first..(first + model.num_faces as usize).min(out.len()) {
            out[f] = m;
        }
    }
    out
}

fn describe(bsp: &Bsp, models: &[usize], face: usize) -> String {
    let f = &bsp.faces[face];
    let centre = bsp.face_vertices(f).map_or([0.0; 3], |v| {
        let n = v.len().max(1) as f32;
        let s = v
            .iter()
            .fold([0.0f32; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]]);
        [s[0] / n, s[1] / n, s[2] / n]
    });
    let texture = bsp
        .texinfo
        .get(f.texinfo as usize)
        .and_then(|ti| bsp.textures.textures.get(ti.miptex as usize))
        .and_then(Option::as_ref)
        .map_or_else(|| "?".to_string(), |t| t.name());
    format!(
        "face {face} (model {}, {texture}) at ({:.0} {:.0} {:.0})",
        models[face], centre[0], centre[1], centre[2]
    )
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (ours, theirs, worst) = match &args[..] {
        [a, b] => (a, b, 20),
        [a, b, n] => (a, b, n.parse()?),
        _ => anyhow::bail!("usage: ericw_agreement OURS.bsp THEIRS.bsp [WORST]"),
    };
    let read = |path: &String| -> anyhow::Result<Bsp> { Ok(Bsp::read(&std::fs::read(path)?)?) };
    let (ours, theirs) = (read(ours)?, read(theirs)?);
    anyhow::ensure!(
        ours.faces.len() == theirs.faces.len(),
        "the BSPs have {} and {} faces: light copies of one BSP",
        ours.faces.len(),
        theirs.faces.len()
    );
    let models = face_models(&ours);
    let (a, b) = (faces_means(&ours), faces_means(&theirs));
    let (mut same_styles, mut agree, mut darker, mut brighter) = (0, 0, 0, 0);
    let (mut only_ours, mut only_theirs, mut style_differs, mut neither) = (0, 0, 0, 0);
    let (mut sum_ours, mut sum_theirs) = (0.0, 0.0);
    let mut differences: Vec<(f64, usize, f64, f64)> = Vec::new();
    for face in 0..a.len() {
        match (&a[face], &b[face]) {
            (None, None) => neither += 1,
            (Some(_), None) => only_ours += 1,
            (None, Some(_)) => only_theirs += 1,
            (Some(x), Some(y)) => {
                if x.iter().map(|s| s.0).ne(y.iter().map(|s| s.0)) {
                    style_differs += 1;
                    continue;
                }
                same_styles += 1;
                // The style whose means differ most speaks for the face.
                let (mx, my) = x
                    .iter()
                    .zip(y)
                    .map(|(x, y)| (x.1, y.1))
                    .max_by(|p, q| (p.0 - p.1).abs().total_cmp(&(q.0 - q.1).abs()))
                    .unwrap_or_default();
                sum_ours += mx;
                sum_theirs += my;
                let d = mx - my;
                if d.abs() <= AGREE_LEVELS {
                    agree += 1;
                } else if d < 0.0 {
                    darker += 1;
                } else {
                    brighter += 1;
                }
                differences.push((d.abs(), face, mx, my));
            }
        }
    }
    let n = f64::from(same_styles.max(1));
    println!(
        "{same_styles} faces with the same styles: {agree} ({:.1}%) within {AGREE_LEVELS} levels, \
         {darker} darker, {brighter} brighter; mean {:.1} (ours) against {:.1}",
        100.0 * f64::from(agree) / n,
        sum_ours / n,
        sum_theirs / n
    );
    println!(
        "lightmap only in ours: {only_ours}, only in theirs: {only_theirs}, styles differ: \
         {style_differs}, neither: {neither}"
    );
    differences.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    for &(_, face, mx, my) in differences.iter().take(worst) {
        println!(
            "  {}: ours {mx:.1}, theirs {my:.1}",
            describe(&ours, &models, face)
        );
    }
    Ok(())
}
