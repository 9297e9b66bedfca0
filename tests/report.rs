//! `slipgate report` on the project's small map: a row per stage and setting, finite figures,
//! and image files that decode.

#[path = "support/command.rs"]
mod command;

use std::path::Path;

/// Every setting `slipgate report` measures, as its tables name them.
const SETTINGS: [(&str, &str); 16] = [
    ("bsp", "default"),
    ("vis", "fast"),
    ("vis", "full"),
    ("light", "default"),
    ("light", "--extra"),
    ("light", "--extra4"),
    ("light", "--soft"),
    ("light", "--bounce"),
    ("light", "--extra4 --soft --bounce"),
    ("light", "--world_units_per_luxel 8"),
    ("light", "--lightgrid"),
    ("light", "--bspxlit --lux --hdr"),
    ("view", "span step 1"),
    ("view", "span step 8"),
    ("view", "span step 16"),
    ("view", "span step 32"),
];

/// Whether `text` is well-formed enough: every opened tag closed in order.
fn tags_balance(text: &str) -> bool {
    let mut open: Vec<String> = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find('<') {
        let Some(len) = rest[start..].find('>') else {
            return false;
        };
        let tag = &rest[start + 1..start + len];
        rest = &rest[start + len + 1..];
        if tag.starts_with('?') || tag.starts_with('!') || tag.ends_with('/') {
            continue;
        }
        let name = |t: &str| t.split_whitespace().next().unwrap_or_default().to_string();
        if let Some(closing) = tag.strip_prefix('/') {
            if open.pop() != Some(name(closing)) {
                return false;
            }
        } else {
            open.push(name(tag));
        }
    }
    open.is_empty()
}

fn check_png(path: &Path) {
    let bytes = std::fs::read(path).expect("png written");
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{}",
        path.display()
    );
    let picture =
        image::load_from_memory_with_format(&bytes, image::ImageFormat::Png).expect("png decodes");
    assert!(picture.width() > 100 && picture.height() > 100);
}

#[test]
fn report_measures_every_stage_and_setting_and_draws_its_plots() {
    let out = command::scratch("report", "out");
    let run = command::slipgate(&[
        "report",
        "--out-dir",
        out.to_str().expect("utf8"),
        "--runs",
        "1",
        "--reference-faces",
        "16",
        "--sample-pairs",
        "20000",
        "--view-frames",
        "10",
        "--hull-traces",
        "300",
        "maps/test/corridors.map",
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");

    let md = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    for (stage, setting) in SETTINGS {
        let section = md
            .split("\n## ")
            .find(|s| s.starts_with(&format!("{stage}\n")))
            .unwrap_or_else(|| panic!("no {stage} section:\n{md}"));
        let row = format!("| corridors | {setting} | Slipgate |");
        let found: Vec<&str> = section.lines().filter(|l| l.starts_with(&row)).collect();
        assert_eq!(found.len(), 1, "{stage} {setting}:\n{md}");
        assert!(!found[0].contains("failed"), "{}", found[0]);
    }

    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).expect("report.json"))
            .expect("report.json parses");
    let rows = json["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), SETTINGS.len());
    for row in rows {
        let wall = row["timing"]["wall_seconds"].as_f64().expect("a time");
        assert!(wall.is_finite() && wall > 0.0, "{row}");
        let figures = &row["figures"];
        let error = match row["stage"].as_str() {
            Some("bsp") => {
                assert!(figures["bsp"]["hull_traces"].as_u64() > Some(0), "{row}");
                assert!(
                    figures["bsp"]["hull_worst_gap"]
                        .as_f64()
                        .is_some_and(f64::is_finite)
                );
                figures["bsp"]["tjunctions"].as_f64()
            }
            Some("vis") => {
                assert_eq!(figures["vis"]["seen_not_in_pvs"], 0, "{row}");
                figures["vis"]["pvs_over_sampled"].as_f64()
            }
            Some("light") => {
                assert!(figures["light"]["luxels"].as_u64() > Some(0), "{row}");
                // Read back from the lit BSP, --extra4 is close to the reference: a misread
                // lightmap would be far off.
                if row["setting"] == "--extra4" {
                    assert!(figures["light"]["rmse"].as_f64() < Some(1.0), "{row}");
                }
                // The grid's own cost is read from light's --stats, and only its run has one.
                let grid_cost = &figures["light"]["grid_cost"];
                if row["setting"] == "--lightgrid" {
                    assert_eq!(figures["light"]["measured"], "light_grid", "{row}");
                    assert!(grid_cost["seconds"].as_f64() > Some(0.0), "{row}");
                    assert!(grid_cost["share"].as_f64() < Some(1.0), "{row}");
                } else {
                    assert!(grid_cost.is_null(), "{row}");
                }
                if row["setting"] == "--world_units_per_luxel 8" {
                    let own = &figures["light"]["measured"]["own_grids"];
                    assert_eq!(own["world_units_per_luxel"], 8.0, "{row}");
                }
                figures["light"]["rmse"].as_f64()
            }
            Some("view") => figures["view"]["mean_diff"].as_f64(),
            other => panic!("unknown stage {other:?}"),
        };
        assert!(error.is_some_and(f64::is_finite), "{row}");
    }

    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    assert!(tags_balance(&html), "report.html's tags do not balance");
    for stage in ["bsp", "vis", "light", "view"] {
        check_png(&out.join(format!("{stage}.png")));
        let svg = std::fs::read_to_string(out.join(format!("{stage}.svg"))).expect("svg");
        assert!(svg.trim_start().starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(tags_balance(&svg), "{stage}.svg's tags do not balance");
        assert!(md.contains(&format!("({stage}.png)")));
    }
    assert_eq!(html.matches("<svg").count(), 4);
    std::fs::remove_dir_all(out.parent().expect("scratch dir")).ok();
}

#[test]
fn tag_balance_catches_unclosed_tags() {
    assert!(tags_balance("<?xml?><svg a=\"1\"><g><line/></g></svg>"));
    assert!(!tags_balance("<svg><g></svg>"));
    assert!(!tags_balance("<svg>"));
}

#[test]
fn report_independent_without_python_says_what_to_install() {
    let out = command::scratch("report-independent-python", "out");
    let run = command::slipgate(&[
        "report",
        "--independent",
        "--anchor",
        "/nonexistent/ericw-tools",
        "--python",
        "/nonexistent/python3",
        "--out-dir",
        out.to_str().expect("utf8"),
        "bench/independent/testmaps/open_wall.map",
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "{stderr}");
    assert!(stderr.contains("pip install mitsuba numpy"), "{stderr}");
    std::fs::remove_dir_all(out.parent().expect("scratch dir")).ok();
}

#[test]
fn report_independent_judges_both_tools_against_the_reference() {
    let anchor = Path::new("../shared/anchors/ericw-tools/bin");
    if !anchor.join("light").is_file() {
        eprintln!("SKIPPED: ericw-tools not found at {}", anchor.display());
        return;
    }
    let has_mitsuba = std::process::Command::new("python3")
        .args([
            "-c",
            "import numpy, mitsuba; mitsuba.set_variant('llvm_ad_rgb')",
        ])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_mitsuba {
        eprintln!("SKIPPED: python3 with mitsuba and numpy not found");
        return;
    }
    let out = command::scratch("report-independent", "out");
    let run = command::slipgate(&[
        "report",
        "--independent",
        "--runs",
        "1",
        "--out-dir",
        out.to_str().expect("utf8"),
        "bench/independent/testmaps/open_wall.map",
        "bench/independent/testmaps/fence_wall.map",
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let json: serde_json::Value = serde_json::from_slice(
        &std::fs::read(out.join("independent.json")).expect("independent.json"),
    )
    .expect("independent.json parses");
    let rows = json["rows"].as_array().expect("rows");
    // two maps, two tools at two settings
    assert_eq!(rows.len(), 8, "{json}");
    for row in rows {
        // one light in front of a wall (in fence_wall through a sheet of fence texture whose every
        // texel is a hole, which the reference must see through as both tools do): both tools
        // within a level of physics
        let rmse = row["figures"]["rmse"].as_f64().expect("an error");
        assert!(rmse < 1.0, "{row}");
        assert!(row["figures"]["noise"].as_f64() < Some(0.2), "{row}");
    }
    let md = std::fs::read_to_string(out.join("independent.md")).expect("independent.md");
    assert!(md.contains("| open_wall | -extra4 -soft |"), "{md}");
    check_png(&out.join("light-independent.png"));
    let html = std::fs::read_to_string(out.join("independent.html")).expect("independent.html");
    assert!(
        tags_balance(&html),
        "independent.html's tags do not balance"
    );
    std::fs::remove_dir_all(out.parent().expect("scratch dir")).ok();
}
