//! The table printed at the end of a batch: one row per stage of each map (a cached stage's time,
//! in brackets, is what it took when it ran).

use crate::stages::MapOutcome;
use std::fmt::Write;

/// The summary table and a closing line of totals.
pub fn table(maps: &[MapOutcome]) -> String {
    let mut rows: Vec<[String; 6]> =
        vec![["map", "stage", "time", "counts", "cached", "result"].map(String::from)];
    for map in maps {
        for run in &map.stages {
            rows.push([
                map.map.clone(),
                run.stage.clone(),
                // A cached stage: what it took when it ran.
                if run.cached {
                    format!("({:.2} s)", run.seconds)
                } else {
                    format!("{:.2} s", run.seconds)
                },
                run.counts.clone(),
                if run.cached { "cached" } else { "ran" }.into(),
                "ok".into(),
            ]);
        }
        if let Some(failure) = &map.failure {
            rows.push([
                map.map.clone(),
                failure.stage.clone(),
                String::new(),
                String::new(),
                String::new(),
                format!("FAILED: {}", failure.message),
            ]);
        }
    }
    let widths: Vec<usize> = (0..5)
        .map(|c| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0))
        .collect();
    let mut out = String::new();
    for row in &rows {
        for (cell, width) in row.iter().zip(&widths) {
            let _ = write!(out, "{cell:<width$}  ");
        }
        let _ = writeln!(out, "{}", row[5]);
    }
    let runs = maps.iter().flat_map(|m| &m.stages);
    let (ran, cached) = runs.fold(
        (0, 0),
        |(r, c), s| if s.cached { (r, c + 1) } else { (r + 1, c) },
    );
    let failed = maps.iter().filter(|m| m.failure.is_some()).count();
    let _ = writeln!(
        out,
        "{} maps ({} failed): {ran} stages ran, {cached} cached",
        maps.len(),
        failed
    );
    out
}
