//! The rows of `bench/results/light-speed-error.md` for one map:
//! `cargo run --release -p slipgate-light --example speed_error -- MAP.bsp STRIDE`.
//! Time (best of 3) and rays are for the whole map; RMSE and max error
//! (8-bit levels) are against `--reference` on every STRIDE-th face, over the luxels engines
//! draw (each weighted by the area of the face it shows on), and the RMSE again over every
//! luxel of the lightmaps.

use light::settings::SoftRadius;
use light::{
    DrawnAreas, Options, Quality, RawLighting, compare, compare_drawn, compute_lighting,
    finish_lighting, trace_lighting,
};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let (Some(path), Some(stride)) = (args.next(), args.next()) else {
        anyhow::bail!("usage: speed_error MAP.bsp STRIDE");
    };
    let stride: usize = stride.parse()?;
    anyhow::ensure!(stride > 0, "STRIDE must be at least 1");
    let bsp = quake_formats::Bsp::read(&std::fs::read(&path)?)?;
    let faces: Vec<usize> = (0..bsp.faces.len()).step_by(stride).collect();
    let drawn = DrawnAreas::on_quake_grids(&bsp, &faces);
    let some_faces = Some(faces);
    let reference = trace_lighting(
        &bsp,
        &Options {
            quality: Quality::Reference,
            only_faces: some_faces.clone(),
            ..Options::default()
        },
    )?;
    println!(
        "reference on 1 face in {stride}: {:.1} s",
        reference.stats.seconds_trace
    );
    let (none, half) = (SoftRadius::Samples(0), SoftRadius::HalfLuxel);
    let modes = [
        ("default", Quality::Default, none),
        ("--extra", Quality::Extra, none),
        ("--extra4", Quality::Extra4, none),
        ("--soft 1", Quality::Default, SoftRadius::Samples(1)),
        ("--extra4 --soft", Quality::Extra4, half),
    ];
    println!(
        "| mode | trace time | rays | RMSE, drawn luxels | max | RMSE / max vs filtered \
         reference | RMSE, whole lightmaps |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, quality, soft) in modes {
        let mut options = Options {
            quality,
            ..Options::default()
        };
        options.overrides.soft = Some(soft);
        let mut best = f64::INFINITY;
        let mut rays = 0;
        for _ in 0..3 {
            let s = compute_lighting(&bsp, &options)?.stats;
            best = best.min(s.seconds_trace);
            rays = s.shadow_rays + s.sun_rays + s.dirt_rays;
        }
        let part = compute_lighting(
            &bsp,
            &Options {
                only_faces: some_faces.clone(),
                ..options.clone()
            },
        )?;
        let exact = finish_lighting(&reference);
        let e = compare_drawn(&part, &exact, &drawn);
        let whole = compare(&part, &exact);
        let per_axis = quality.samples_per_axis();
        let soft_reference = RawLighting {
            soft,
            ..reference.clone()
        };
        let filtered = soft_reference
            .softened(per_axis)
            .map_or(String::new(), |r| {
                let f = compare_drawn(&part, &finish_lighting(&r), &drawn);
                format!("{:.2} / {}", f.rmse, f.max)
            });
        println!(
            "| {name} | {best:.2} s | {:.1} M | {:.2} | {} | {filtered} | {:.2} |",
            rays as f64 / 1e6,
            e.rmse,
            e.max,
            whole.rmse
        );
    }
    Ok(())
}
