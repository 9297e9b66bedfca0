//! Time against error, one plot per stage: one point per setting, one series per map and tool,
//! drawn as SVG and PNG with `plotters`.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::independent::IndependentReport;
use crate::settings::{Stage, Tool};
use crate::{Report, ReportError};

/// The files drawn for one stage.
#[derive(Debug, Clone)]
pub struct PlotFile {
    pub stage: Stage,
    /// File names inside the output folder.
    pub svg: String,
    pub png: String,
    /// The SVG itself, for inlining into the HTML page.
    pub svg_text: String,
}

struct Point {
    time: f64,
    error: f64,
    setting: String,
}

struct Series {
    name: String,
    points: Vec<Point>,
}

/// A plot's title and what its axes show.
struct Axes {
    title: String,
    time: &'static str,
    error: &'static str,
}

impl Axes {
    fn of(stage: Stage) -> Axes {
        Axes {
            title: format!("{}: time against error", stage.name()),
            time: stage.time_name(),
            error: stage.error_name(),
        }
    }
}

const SIZE: (u32, u32) = (900, 560);

/// Fonts for labels, looked for where Debian and most Linux systems keep them; without one the
/// plots are drawn without text.
const FONT_FILES: [&str; 4] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

/// Registers a system font with plotters once; false when none was found.
fn fonts_available() -> bool {
    static FOUND: OnceLock<bool> = OnceLock::new();
    *FOUND.get_or_init(|| {
        FONT_FILES.iter().any(|path| {
            let Ok(bytes) = std::fs::read(path) else {
                return false;
            };
            // plotters keeps fonts for the whole run; one font is leaked once.
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok()
        })
    })
}

/// Draws every stage that has points and returns what was written.
pub fn draw_all(report: &Report, out_dir: &Path) -> Result<Vec<PlotFile>, ReportError> {
    let mut files = Vec::new();
    for stage in Stage::ALL {
        let series = series_of(report, stage);
        if series.is_empty() {
            continue;
        }
        files.push(write_plot(
            out_dir,
            stage.name(),
            stage,
            &Axes::of(stage),
            &series,
        )?);
    }
    Ok(files)
}

/// The `--independent` report's one plot: both tools' light, error against the independent
/// reference over time, one series per map and tool; `None` when nothing was measured.
pub fn draw_independent(
    report: &IndependentReport,
    out_dir: &Path,
) -> Result<Option<PlotFile>, ReportError> {
    let series = series_from(report.rows.iter().filter_map(|row| {
        let (timing, figures) = (row.timing?, row.figures.as_ref()?);
        Some((
            &row.map,
            row.tool,
            &row.setting,
            timing.wall_seconds,
            figures.rmse,
        ))
    }));
    if series.is_empty() {
        return Ok(None);
    }
    let axes = Axes {
        title: "light: time against error, independent reference".into(),
        time: Stage::Light.time_name(),
        error: "RMSE against the independent reference (8-bit levels)",
    };
    write_plot(out_dir, "light-independent", Stage::Light, &axes, &series).map(Some)
}

/// Draws one plot as `NAME.png` and `NAME.svg` in `out_dir`.
fn write_plot(
    out_dir: &Path,
    name: &str,
    stage: Stage,
    axes: &Axes,
    series: &[Series],
) -> Result<PlotFile, ReportError> {
    let labels = fonts_available();
    let png = out_dir.join(format!("{name}.png"));
    let failed = |what: String| ReportError::Plot {
        path: png.clone(),
        what,
    };
    let mut pixels = vec![0u8; SIZE.0 as usize * SIZE.1 as usize * 3];
    draw(
        BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area(),
        axes,
        series,
        labels,
    )
    .map_err(failed)?;
    let png_bytes = encode_png(pixels).map_err(failed)?;
    quake_formats::fsutil::write_atomic(&png, &png_bytes).map_err(|source| {
        ReportError::Format {
            path: png.clone(),
            source,
        }
    })?;
    let mut svg_text = String::new();
    draw(
        SVGBackend::with_string(&mut svg_text, SIZE).into_drawing_area(),
        axes,
        series,
        labels,
    )
    .map_err(failed)?;
    let svg = out_dir.join(format!("{name}.svg"));
    quake_formats::fsutil::write_atomic(&svg, svg_text.as_bytes()).map_err(|source| {
        ReportError::Format {
            path: svg.clone(),
            source,
        }
    })?;
    Ok(PlotFile {
        stage,
        svg: format!("{name}.svg"),
        png: format!("{name}.png"),
        svg_text,
    })
}

/// A drawn plot as PNG bytes, through `image` like every other picture Slipgate writes.
fn encode_png(pixels: Vec<u8>) -> Result<Vec<u8>, String> {
    let picture = image::RgbImage::from_raw(SIZE.0, SIZE.1, pixels)
        .ok_or_else(|| "the plot's pixel buffer is not its size".to_string())?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    picture
        .write_to(&mut bytes, image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    Ok(bytes.into_inner())
}

/// The stage's points, by map and tool ([`series_from`]).
fn series_of(report: &Report, stage: Stage) -> Vec<Series> {
    series_from(
        report
            .rows
            .iter()
            .filter(|r| r.stage == stage)
            .filter_map(|row| {
                let (time, error) = (row.plot_time()?, row.plot_error()?);
                Some((&row.map, row.tool, &row.setting, time, error))
            }),
    )
}

/// One series per map and tool of the `(map, tool, setting, time, error)` points with a
/// finite, positive time and a finite error, its points in order of time.
fn series_from<'a>(
    points: impl Iterator<Item = (&'a String, Tool, &'a String, f64, f64)>,
) -> Vec<Series> {
    let mut by_key: BTreeMap<(String, Tool), Vec<Point>> = BTreeMap::new();
    for (map, tool, setting, time, error) in points {
        if time.is_finite() && time > 0.0 && error.is_finite() {
            by_key.entry((map.clone(), tool)).or_default().push(Point {
                time,
                error,
                setting: setting.clone(),
            });
        }
    }
    by_key
        .into_iter()
        .map(|((map, tool), mut points)| {
            points.sort_by(|a, b| a.time.total_cmp(&b.time));
            Series {
                name: format!("{map} ({})", tool.name()),
                points,
            }
        })
        .collect()
}

/// A time axis label: as many decimals as its size needs.
fn seconds_label(x: f64) -> String {
    match x {
        x if x >= 10.0 => format!("{x:.0}"),
        x if x >= 1.0 => format!("{x:.1}"),
        x if x >= 0.1 => format!("{x:.2}"),
        x => format!("{x:.3}"),
    }
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    axes: &Axes,
    series: &[Series],
    labels: bool,
) -> Result<(), String> {
    let text = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|e| text(&e))?;
    let points = || series.iter().flat_map(|s| &s.points);
    let t_min = points().map(|p| p.time).fold(f64::INFINITY, f64::min);
    let t_max = points().map(|p| p.time).fold(0.0, f64::max);
    let e_max = points().map(|p| p.error).fold(0.0, f64::max);
    // Room on the right for the last point's setting name.
    let x_range = (t_min / 1.5)..(t_max * 3.0);
    // Headroom above the highest point for the legend (about 20 pixels a series).
    let legend_share = if labels {
        (20.0 * series.len() as f64 + 30.0) / f64::from(SIZE.1 - 120)
    } else {
        0.0
    };
    let top = if e_max > 0.0 { e_max } else { 1.0 };
    let y_range = 0.0..top / (0.92 - legend_share).max(0.3);

    let mut builder = ChartBuilder::on(&root);
    builder.margin(20);
    if labels {
        builder
            .caption(axes.title.clone(), ("sans-serif", 22))
            .x_label_area_size(45)
            .y_label_area_size(70);
    }
    let mut chart = builder
        .build_cartesian_2d(x_range.log_scale(), y_range)
        .map_err(|e| text(&e))?;
    let mut mesh = chart.configure_mesh();
    if labels {
        mesh.x_desc(axes.time)
            .y_desc(axes.error)
            .x_labels(8)
            .x_label_formatter(&|x| seconds_label(*x))
            .y_label_formatter(&|y| format!("{y:.2}"));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw().map_err(|e| text(&e))?;

    for (i, s) in series.iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        // Points only: settings are not steps along one line.
        let dots = chart
            .draw_series(
                s.points
                    .iter()
                    .map(|p| Circle::new((p.time, p.error), 5, colour.filled())),
            )
            .map_err(|e| text(&e))?;
        if labels {
            dots.label(s.name.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, colour.filled()));
        }
        if labels {
            chart
                .draw_series(s.points.iter().map(|p| {
                    // Beside the dot, not on it.
                    EmptyElement::at((p.time, p.error))
                        + Text::new(
                            p.setting.clone(),
                            (8, -6),
                            ("sans-serif", 12).into_font().color(&colour),
                        )
                }))
                .map_err(|e| text(&e))?;
        }
    }
    if labels {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| text(&e))?;
    }
    root.present().map_err(|e| text(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_series() -> Vec<Series> {
        let point = |time, error, setting: &str| Point {
            time,
            error,
            setting: setting.into(),
        };
        vec![
            Series {
                name: "a (Slipgate)".into(),
                points: vec![point(0.01, 3.0, "default"), point(0.2, 0.5, "--extra4")],
            },
            Series {
                name: "a (ericw-tools)".into(),
                points: vec![point(0.05, 0.0, "default")],
            },
        ]
    }

    #[test]
    fn plots_draw_with_and_without_a_font() {
        for labels in [false, fonts_available()] {
            let mut svg = String::new();
            draw(
                SVGBackend::with_string(&mut svg, SIZE).into_drawing_area(),
                &Axes::of(Stage::Light),
                &two_series(),
                labels,
            )
            .expect("draws");
            assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
            assert_eq!(
                svg.contains("--extra4"),
                labels,
                "setting names only with a font"
            );
        }
    }

    #[test]
    fn time_labels_get_the_decimals_their_size_needs() {
        assert_eq!(seconds_label(0.01234), "0.012");
        assert_eq!(seconds_label(0.5), "0.50");
        assert_eq!(seconds_label(2.345), "2.3");
        assert_eq!(seconds_label(95.6), "96");
    }
}
