//! `report.md`: a header naming the machine, then one table per stage.

use std::fmt::Write;

use crate::plot::PlotFile;
use crate::settings::Stage;
use crate::{Figures, Report, Row};

/// The header paragraph (shared with the HTML page).
pub fn header(report: &Report) -> String {
    let m = &report.machine;
    let build = if report.release {
        "Release build"
    } else {
        "DEBUG build (times are not representative; run `cargo run --release -- report`)"
    };
    let anchor = match &report.anchor {
        Some(a) => format!(
            "; ericw-tools from `{}` ran the same steps, interleaved with ours, on the same inputs",
            a.display()
        ),
        None => String::new(),
    };
    format!(
        "{date}, {cpu} ({cores} cores), Embree kernels {isa}; load average {start} at the start, \
         {end} at the end. {build}: best of {runs} runs by wall time{anchor}. Each step is a \
         child process (wall and CPU seconds, peak resident memory from the kernel). Vis and \
         light of both tools read Slipgate's BSP (compiled, then fully vised), the viewer our \
         default light; every error is measured by Slipgate's libraries against Slipgate's \
         slow exact references.",
        date = m.date,
        cpu = m.cpu,
        cores = m.cores,
        isa = m.embree_isa,
        start = m.load_start,
        end = m.load_end,
        runs = report.runs,
    )
}

pub fn render(report: &Report, plots: &[PlotFile]) -> String {
    let mut s = String::from("# Slipgate: speed against error\n\n");
    s += &header(report);
    s += "\n\nWritten by `slipgate report`; every figure is also in `report.json`.\n";
    for stage in Stage::ALL {
        let rows: Vec<&Row> = report.rows.iter().filter(|r| r.stage == stage).collect();
        if rows.is_empty() {
            continue;
        }
        let _ = write!(
            s,
            "\n## {}\n\n{}\n\n",
            stage.name(),
            stage_note(report, stage)
        );
        s += &table(stage, &rows);
        if let Some(p) = plots.iter().find(|p| p.stage == stage) {
            let _ = write!(
                s,
                "\n![{} time against error]({}) ([SVG]({}))\n",
                stage.name(),
                p.png,
                p.svg
            );
        }
    }
    let failures: Vec<&Row> = report.rows.iter().filter(|r| r.failure.is_some()).collect();
    if !failures.is_empty() {
        s += "\n## Failures\n\n";
        for r in failures {
            let why = r.failure.as_deref().unwrap_or_default();
            let why = why.lines().collect::<Vec<_>>().join(" / ");
            let _ = writeln!(
                s,
                "- {} {} {} ({}): {why}",
                r.map,
                r.stage.name(),
                r.setting,
                r.tool.name()
            );
        }
    }
    s
}

fn stage_note(report: &Report, stage: Stage) -> String {
    match stage {
        Stage::Bsp => "Counts of the written BSP (portals from its `.prt`); cracks from \
                       `bsp_compiler::cracks` (T-junctions, edges used by more than two faces \
                       and not as often as their reverse, duplicate vertices); hull agreement from `bsp_compiler::hull_check`: \
                       player-box moves traced through clip hull 1 and swept exactly through the \
                       map's brushes, counted when their stops are more than 0.1 units apart \
                       (a hull that agrees stops the engine's 1/32 short)."
            .into(),
        Stage::Vis => "PVS against sight lines sampled through hull 0: pairs seen but missing \
                       from the PVS must be 0; PVS / sampled is how many more pairs the PVS \
                       holds than sight lines show visible (1 is as tight as sampling tells)."
            .into(),
        Stage::Light => {
            let faces: Vec<String> = report
                .light_references
                .iter()
                .map(|r| {
                    let seconds: Vec<String> = r
                        .references
                        .iter()
                        .map(|t| format!("{} {:.2} s", t.measure.reference_name(), t.seconds))
                        .collect();
                    format!(
                        "{} every {} faces ({} faces; references: {})",
                        r.map,
                        r.face_stride,
                        r.faces,
                        seconds.join(", ")
                    )
                })
                .collect();
            format!(
                "Grey lightmap bytes of every style against `--reference` (16x16 samples per \
                 luxel, no culling; with bounce for the bouncing settings), in 8-bit levels, on \
                 {}, over the luxels engines draw (those within a luxel of the face, where \
                 bilinear filtering reads them), each weighted by the area of the face it shows \
                 on; RMSE over every luxel of the lightmaps (inside solid, past a triangle's \
                 corners) beside it. `--world_units_per_luxel 8` is measured on the faces' own grids (its \
                 `DECOUPLED_LM` lightmaps) against the reference lit on the same grids; \
                 `--lightgrid` on its grid's points (grey of each style at each open point of \
                 `LIGHTGRID_OCTREE`) against the reference's grid of the same points, which \
                 traces every direction of soft suns and sky domes and culls nothing by the PVS \
                 (the grid takes one ray per light and at most 16 directions per sun); a grid of \
                 other points is not measured (ericw-tools puts its points on whole units, \
                 where floors lie; ours sit half a unit off); the \
                 output-only modes (`--bspxlit --lux --hdr`) as the default light. The light \
                 grid column is the grid's own time in light's run (its `--stats`), beside that \
                 run's time lighting the faces and the grid's share of the whole run.",
                faces.join("; ")
            )
        }
        Stage::View => "Flythrough through the map's spawn spots (frames per second, best run); \
                        the start view against the exact ray-cast renderer (mean and max \
                        per-channel difference, share of pixels showing another face)."
            .into(),
    }
}

fn table(stage: Stage, rows: &[&Row]) -> String {
    let columns: &[&str] = match stage {
        Stage::Bsp => &[
            "faces",
            "leaves",
            "nodes",
            "clipnodes",
            "portals",
            "marksurfaces",
            "file KB",
            "cracks",
            "hull 1 disagreements",
            "worst gap",
        ],
        Stage::Vis => &[
            "PVS leaves (avg)",
            "sampled pairs",
            "seen, not in PVS",
            "PVS / sampled",
        ],
        Stage::Light => &[
            "RMSE, drawn luxels",
            "max",
            "> 2 levels",
            "compared",
            "RMSE, whole lightmaps",
            "light grid",
        ],
        Stage::View => &["fps", "mean diff", "max diff", "other face"],
    };
    let mut s = String::from("| map | setting | tool | wall | CPU | peak memory |");
    for c in columns {
        let _ = write!(s, " {c} |");
    }
    s += "\n|---|---|---|---|---|---|";
    s += &"---|".repeat(columns.len());
    s += "\n";
    for r in rows {
        let (wall, cpu, mem) = r.timing.map_or(("-".into(), "-".into(), "-".into()), |t| {
            (
                format!("{:.3} s", t.wall_seconds),
                format!("{:.3} s", t.cpu_seconds),
                format!("{:.0} MB", t.peak_rss_mb),
            )
        });
        let _ = write!(
            s,
            "| {} | {} | {} | {wall} | {cpu} | {mem} |",
            r.map,
            r.setting,
            r.tool.name()
        );
        let cells = match &r.figures {
            Some(f) => figure_cells(f),
            None => vec!["failed".into(); columns.len()],
        };
        for c in cells {
            let _ = write!(s, " {c} |");
        }
        s += "\n";
    }
    s
}

fn figure_cells(f: &Figures) -> Vec<String> {
    match f {
        Figures::Bsp(b) => vec![
            b.faces.to_string(),
            b.leaves.to_string(),
            b.nodes.to_string(),
            b.clipnodes.to_string(),
            b.portals.to_string(),
            b.marksurfaces.to_string(),
            format!("{:.0}", b.file_bytes as f64 / 1024.0),
            b.cracks().to_string(),
            format!("{} of {}", b.hull_disagreements, b.hull_traces),
            format!("{:.3}", b.hull_worst_gap),
        ],
        Figures::Vis(v) => vec![
            format!("{:.1} of {}", v.average_visible, v.leaves),
            v.sampled_pairs.to_string(),
            v.seen_not_in_pvs.to_string(),
            format!("{:.2}", v.pvs_over_sampled),
        ],
        Figures::Light(l) => vec![
            format!("{:.3}", l.rmse),
            l.max.to_string(),
            format!("{:.2} %", 100.0 * l.over_2_share),
            format!("{} {}", l.luxels, l.measured.counted()),
            l.whole_lightmaps_rmse
                .map_or("—".into(), |r| format!("{r:.3}")),
            l.grid_cost.map_or("—".into(), |g| {
                format!(
                    "{:.3} s ({:.1} % of the run; faces {:.3} s), {} of {} points open",
                    g.seconds,
                    100.0 * g.share,
                    g.lightmap_seconds,
                    g.open_points,
                    g.points
                )
            }),
        ],
        Figures::View(v) => vec![
            format!("{:.1}", v.fps),
            format!("{:.2}", v.mean_diff),
            format!("{:.0}", v.max_diff),
            format!("{:.2} %", 100.0 * v.face_mismatch),
        ],
    }
}
