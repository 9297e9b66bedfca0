//! Per-face agreement of two lightings of the same BSP: `ericw_agreement OURS.bsp THEIRS.bsp
//! [WORST]`, where both files are one compiled, vised BSP lit by two tools (ours, and
//! ericw-tools' `light` at the same setting; `bench/light_agreement.sh` runs both). For every
//! face it takes the mean of each style's grey lightmap, and counts the faces with the same
//! styles (in whichever order each tool wrote them: both put the brightest first, and near ties
//! fall either way) whose means agree within 5 levels style by style, the faces one tool lights
//! and the other leaves without a lightmap, and the faces whose styles differ. It counts again
//! over the luxels engines draw: those within a luxel of the face (bilinear filtering reads no
//! further), leaving out the corners of a triangle's lightmap that no pixel shows and the faces
//! whose texture is fullbright in every texel (engines draw those unlit). Then it
//! lists the WORST faces (default 20) that differ most, with their model, texture and centre,
//! to look at in the map.

use light::{DrawnAreas, FaceLightmap, lightmaps_in};
use quake_formats::Bsp;

/// Per-face means within this many levels count as agreeing.
const AGREE_LEVELS: f64 = 5.0;

/// The mean of each style's lightmap of one face, over the luxels `seen` marks (all when it
/// is `None` or does not fit).
fn style_means(map: &FaceLightmap, seen: Option<&[bool]>) -> Vec<(u8, f64)> {
    let seen = seen.filter(|s| s.len() == map.width * map.height && s.contains(&true));
    map.styles
        .iter()
        .zip(&map.grey)
        .map(|(&style, grey)| {
            let (sum, n) = grey
                .iter()
                .enumerate()
                .filter(|(i, _)| seen.is_none_or(|s| s[*i]))
                .fold((0u64, 0u64), |(sum, n), (_, &v)| {
                    (sum + u64::from(v), n + 1)
                });
            (style, sum as f64 / n.max(1) as f64)
        })
        .collect()
}

/// Each face's style means in order of style, `None` for a face without a lightmap; over the
/// luxels engines draw when `drawn_only`.
fn faces_means(bsp: &Bsp, drawn_only: bool) -> Vec<Option<Vec<(u8, f64)>>> {
    let all: Vec<usize> = (0..bsp.faces.len()).collect();
    let drawn = drawn_only.then(|| DrawnAreas::on_quake_grids(bsp, &all));
    let mut out = vec![None; bsp.faces.len()];
    for map in lightmaps_in(bsp, &all).lightmaps {
        let seen = match drawn.as_ref().map(|d| d.of(map.face)) {
            None => None,
            Some(None) => continue,
            Some(Some(areas)) => Some(areas.iter().map(|&a| a > 0.0).collect::<Vec<bool>>()),
        };
        let mut means = style_means(&map, seen.as_deref());
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
        .face_texture(f)
        .map_or_else(|| "?".to_string(), |t| t.name());
    format!(
        "face {face} (model {}, {texture}) at ({:.0} {:.0} {:.0})",
        models[face], centre[0], centre[1], centre[2]
    )
}

/// Counts of one comparison of per-face means.
#[derive(Default)]
struct Tally {
    same_styles: u32,
    agree: u32,
    darker: u32,
    brighter: u32,
    only_ours: u32,
    only_theirs: u32,
    style_differs: u32,
    neither: u32,
    sum_ours: f64,
    sum_theirs: f64,
    /// Per face with the same styles: the difference, the face, and both means.
    differences: Vec<(f64, usize, f64, f64)>,
}

impl Tally {
    fn of(a: &[Option<Vec<(u8, f64)>>], b: &[Option<Vec<(u8, f64)>>]) -> Tally {
        let mut t = Tally::default();
        for (face, pair) in a.iter().zip(b).enumerate() {
            match pair {
                (None, None) => t.neither += 1,
                (Some(_), None) => t.only_ours += 1,
                (None, Some(_)) => t.only_theirs += 1,
                (Some(x), Some(y)) => {
                    if x.iter().map(|s| s.0).ne(y.iter().map(|s| s.0)) {
                        t.style_differs += 1;
                        continue;
                    }
                    t.same_styles += 1;
                    // The style whose means differ most speaks for the face.
                    let (mx, my) = x
                        .iter()
                        .zip(y)
                        .map(|(x, y)| (x.1, y.1))
                        .max_by(|p, q| (p.0 - p.1).abs().total_cmp(&(q.0 - q.1).abs()))
                        .unwrap_or_default();
                    t.sum_ours += mx;
                    t.sum_theirs += my;
                    let d = mx - my;
                    if d.abs() <= AGREE_LEVELS {
                        t.agree += 1;
                    } else if d < 0.0 {
                        t.darker += 1;
                    } else {
                        t.brighter += 1;
                    }
                    t.differences.push((d.abs(), face, mx, my));
                }
            }
        }
        t
    }
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
    let whole = Tally::of(&faces_means(&ours, false), &faces_means(&theirs, false));
    let drawn = Tally::of(&faces_means(&ours, true), &faces_means(&theirs, true));
    let n = f64::from(whole.same_styles.max(1));
    println!(
        "{} faces with the same styles: {} ({:.1}%) within {AGREE_LEVELS} levels, \
         {} darker, {} brighter; mean {:.1} (ours) against {:.1}",
        whole.same_styles,
        whole.agree,
        100.0 * f64::from(whole.agree) / n,
        whole.darker,
        whole.brighter,
        whole.sum_ours / n,
        whole.sum_theirs / n
    );
    println!(
        "lightmap only in ours: {}, only in theirs: {}, styles differ: {}, neither: {}",
        whole.only_ours, whole.only_theirs, whole.style_differs, whole.neither
    );
    println!(
        "over the luxels engines draw: {} ({:.1}%) within {AGREE_LEVELS} levels, {} darker, \
         {} brighter",
        drawn.agree,
        100.0 * f64::from(drawn.agree) / f64::from(drawn.same_styles.max(1)),
        drawn.darker,
        drawn.brighter
    );
    let mut differences = whole.differences;
    differences.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    for &(_, face, mx, my) in differences.iter().take(worst) {
        println!(
            "  {}: ours {mx:.1}, theirs {my:.1}",
            describe(&ours, &models, face)
        );
    }
    Ok(())
}
