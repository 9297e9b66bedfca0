//! Property tests over seeded random maps (`mapgen::random`): every map compiles sealed, passes
//! every validator rule, has no cracks, its clip hulls 1 and 2 stop a swept box where its
//! brushes do (`bsp_compiler::hull_check`), its PVS is never too small against sight lines
//! (`vis::sample`), and its lightmaps hold no NaN and nothing brighter than its lights can make.
//!
//! The light bound: with linear falloff a light of value `L` gives at most `L` light units at any
//! point (less with distance, the angle factor and colour at most 1), and minlight only raises
//! luxels to its level, so no luxel exceeds `max(minlight, sum of L)` light units, nor
//! `min(255, ceil(that × rangescale))` as a byte (`rangescale` is `_range`, 0.5 by default).
//!
//! A failing map is shrunk by deleting brushes while the same property still fails, and both
//! maps are written to a scratch directory, named in the failure with the seed.

#[path = "support/hard.rs"]
mod hard;

use bsp_compiler::hull_check::{HullCheckOptions, hull_agreement};
use bsp_compiler::map::{MapFile, parse_map};
use bsp_compiler::{CompileOptions, MapSource, compile};
use mapgen::brush::Map;
use mapgen::random::{RandomOptions, random_map};
use quake_formats::entities::Entity;
use quake_formats::{Severity, validate};
use std::path::{Path, PathBuf};

/// Moves traced per clip hull, and sight-line pairs sampled, per map.
const HULL_TRACES: usize = 2000;
const SIGHT_PAIRS: usize = 20_000;

/// A property a map broke, and how.
#[derive(Debug)]
struct Failure {
    property: &'static str,
    detail: String,
    /// How badly, where the property measures it: the worst gap for hull agreement, the number
    /// of cracks for no cracks; infinite otherwise.
    measured: f64,
}

fn fail(property: &'static str, detail: impl Into<String>) -> Failure {
    Failure {
        property,
        detail: detail.into(),
        measured: f64::INFINITY,
    }
}

/// A seed of the big run that fails for a known cause not yet fixed: accepted (and printed as
/// `KNOWN`) only while it fails the same property, measuring at most `bound`.
struct KnownFailure {
    seed: u64,
    property: &'static str,
    /// What it measured when it was listed.
    measured: f64,
    bound: f64,
    cause: &'static str,
}

/// None at present: seeds 1007, 1022, 1038, 1045, 1077 and 1198 (hull gaps of 0.11-0.18, a
/// tilted bevel taken as axial) and 1012 (an edge on a water surface taken as a crack) are
/// fixed; `maps/hard/random_*.map` hold them shrunk.
const KNOWN_FAILURES: [KnownFailure; 0] = [];

/// Every property of one map's text; the first one broken. `seed` seeds the sampling.
fn check(text: &str, seed: u64) -> Result<(), Failure> {
    let source = MapSource {
        path: PathBuf::from(format!("random_{seed}.map")),
        text: text.to_string(),
    };
    let options = CompileOptions {
        wad_dirs: vec![hard::maps_dir()],
        ..CompileOptions::default()
    };
    let out = compile(&source, &options).map_err(|e| fail("compiles", e.to_string()))?;
    if let Some(leak) = &out.leak {
        return Err(fail("sealed", format!("{leak:?}")));
    }
    let mut bsp = out.bsp;
    let errors: Vec<String> = validate(&bsp)
        .into_iter()
        .filter(|p| p.severity == Severity::Error)
        .map(|p| p.to_string())
        .collect();
    if !errors.is_empty() {
        return Err(fail("validates", errors.join("\n")));
    }
    let cracks = bsp_compiler::cracks::find_cracks(&bsp);
    if !cracks.is_empty() {
        let count =
            cracks.tjunctions.len() + cracks.overused_edges.len() + cracks.duplicate_vertices.len();
        return Err(Failure {
            measured: count as f64,
            ..fail("no cracks", cracks.summary())
        });
    }
    let parsed = parse_map(&source.path, text).map_err(|e| fail("parses", e.to_string()))?;
    for hull in [1, 2] {
        let options = HullCheckOptions {
            traces: HULL_TRACES,
            seed,
            hull,
            ..HullCheckOptions::default()
        };
        let r = hull_agreement(&parsed, &bsp, &options)
            .map_err(|e| fail("hull agreement", e.to_string()))?;
        if r.disagreements > 0 {
            let property = if hull == 1 {
                "hull 1 agreement"
            } else {
                "hull 2 agreement"
            };
            return Err(Failure {
                measured: r.worst_gap,
                ..fail(property, format!("{r:#?}"))
            });
        }
    }
    let vis = vis::compute_vis(&out.portals, &vis::VisOptions::default())
        .map_err(|e| fail("vis", e.to_string()))?;
    let sight = vis::sample::sample_visibility(&bsp, &vis.pvs, SIGHT_PAIRS, seed)
        .map_err(|e| fail("vis", e.to_string()))?;
    if sight.violations > 0 {
        return Err(fail("vis never too small", format!("{sight:#?}")));
    }
    vis::write_vis(&mut bsp, &vis.pvs).map_err(|e| fail("vis", e.to_string()))?;
    check_light(&parsed, &bsp)
}

/// The brightest any luxel may be, in light units (see the module notes).
fn light_bound(map: &MapFile) -> f64 {
    let value = |e: &Entity, key: &str| e.get_float(key).unwrap_or(0.0);
    let lights: f64 = map
        .entities
        .iter()
        .map(|e| &e.entity)
        .filter(|e| e.classname() == "light")
        .map(|e| value(e, "light").max(0.0))
        .sum();
    lights.max(value(&map.entities[0].entity, "_minlight"))
}

fn check_light(map: &MapFile, bsp: &quake_formats::Bsp) -> Result<(), Failure> {
    let raw = light::trace_lighting(bsp, &light::Options::default())
        .map_err(|e| fail("light", e.to_string()))?;
    let bound = light_bound(map);
    let units = raw
        .faces
        .iter()
        .flat_map(|f| &f.styles)
        .flat_map(|(_, luxels)| luxels.iter().flatten());
    let mut brightest = 0.0f64;
    for &v in units {
        if v.is_nan() {
            return Err(fail("light has no NaN", "a luxel is NaN"));
        }
        brightest = brightest.max(f64::from(v));
    }
    if brightest > bound {
        return Err(fail(
            "light within its bound",
            format!("{brightest} light units, bound {bound}"),
        ));
    }
    let byte_bound = (bound * raw.rangescale).ceil().min(255.0) as u8;
    let finished = light::finish_lighting(&raw);
    let brightest_byte = finished
        .lightmaps
        .iter()
        .flat_map(|m| m.rgb.iter().flatten().flatten())
        .copied()
        .max()
        .unwrap_or(0);
    if brightest_byte > byte_bound {
        return Err(fail(
            "light within its bound",
            format!("luxel byte {brightest_byte}, bound {byte_bound}"),
        ));
    }
    Ok(())
}

/// `map` with brushes deleted, one at a time, for as long as `property` still fails.
fn shrink(map: &Map, seed: u64, property: &str) -> Map {
    let still_fails =
        |m: &Map| matches!(check(&m.to_text(), seed), Err(f) if f.property == property);
    let mut map = map.clone();
    loop {
        let mut changed = false;
        for e in (0..map.entities.len()).rev() {
            for b in (0..map.entities[e].brushes.len()).rev() {
                let mut smaller = map.clone();
                smaller.entities[e].brushes.remove(b);
                if still_fails(&smaller) {
                    map = smaller;
                    changed = true;
                }
            }
        }
        if !changed {
            return map;
        }
    }
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("slipgate-generated-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir.join(name)
}

fn write(path: &Path, map: &Map) {
    std::fs::write(path, map.to_text()).expect("write map");
}

/// Print a line about a known failure straight to stderr, past the test harness's capture, so
/// that it shows in every run's log, passing or not.
fn known_line(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{line}");
}

/// Check the maps of `seeds`; report every failure (seed, property, the map and a shrunk map)
/// except those `known` lists, which are printed as `KNOWN` while they still match.
fn check_seeds(seeds: std::ops::Range<u64>, options: &RandomOptions, known: &[KnownFailure]) {
    let mut failures = Vec::new();
    for seed in seeds.clone() {
        let map = random_map(seed, options);
        let listed = known.iter().find(|k| k.seed == seed);
        let Err(failure) = check(&map.to_text(), seed) else {
            if let Some(k) = listed {
                known_line(&format!(
                    "KNOWN seed {seed} ({}) now passes: take it off the list",
                    k.property
                ));
            }
            continue;
        };
        let matching =
            listed.filter(|k| k.property == failure.property && failure.measured <= k.bound);
        if let Some(k) = matching {
            known_line(&format!(
                "KNOWN seed {seed}: {} fails, measuring {:.3} (listed {:.3}, bound {}): {}",
                k.property, failure.measured, k.measured, k.bound, k.cause
            ));
            continue;
        }
        let original = scratch(&format!("seed_{seed}.map"));
        write(&original, &map);
        let small = shrink(&map, seed, failure.property);
        let shrunk = scratch(&format!("seed_{seed}_shrunk.map"));
        write(&shrunk, &small);
        eprintln!(
            "seed {seed}: {} fails (measuring {}): {}\n  map {}\n  shrunk to {} brushes: {}",
            failure.property,
            failure.measured,
            failure.detail,
            original.display(),
            small.brush_count(),
            shrunk.display()
        );
        failures.push(format!("seed {seed}: {}", failure.property));
    }
    assert!(
        failures.is_empty(),
        "{} of {} seeds failed: {failures:#?}",
        failures.len(),
        seeds.count()
    );
}

#[test]
fn random_maps_keep_every_property() {
    check_seeds(0..24, &RandomOptions::default(), &[]);
}

/// The seed a shrunk map was found with, from its header ("random map seed N"), so its check
/// replays the moves and sight lines that found it; 1 when it names none.
fn found_seed(text: &str) -> u64 {
    let marker = "random map seed ";
    text.lines()
        .take_while(|l| l.starts_with("//"))
        .find_map(|l| {
            let rest = &l[l.find(marker)? + marker.len()..];
            let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
            digits.parse().ok()
        })
        .unwrap_or(1)
}

/// The maps this test found, shrunk (`maps/hard/random_*.map`), keep every property, checked
/// with the seed that found each.
#[test]
fn shrunk_failures_keep_every_property() {
    let found: Vec<PathBuf> = hard::hard_maps()
        .into_iter()
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("random_"))
        })
        .collect();
    assert!(!found.is_empty(), "no maps/hard/random_*.map");
    for path in found {
        let text = std::fs::read_to_string(&path).expect("read map");
        if let Err(f) = check(&text, found_seed(&text)) {
            panic!("{}: {} fails: {}", path.display(), f.property, f.detail);
        }
    }
}

/// Many more, and bigger, maps: `cargo test --release -- --ignored`. The few that fail for a
/// known cause are listed in [`KNOWN_FAILURES`].
#[test]
#[ignore]
fn many_random_maps_keep_every_property() {
    check_seeds(
        1000..1200,
        &RandomOptions {
            rooms: 4,
            objects_per_room: 10,
        },
        &KNOWN_FAILURES,
    );
}

#[test]
fn the_generator_makes_what_the_properties_need() {
    // Each map has rooms joined by openings, off-grid brushes, detail, liquid, a door, lights and
    // a player start somewhere among the first seeds.
    let texts: Vec<String> = (0..6)
        .map(|s| random_map(s, &RandomOptions::default()).to_text())
        .collect();
    for wanted in [
        "func_detail",
        "func_door",
        "*water1",
        "\"classname\" \"light\"",
        "info_player_start",
    ] {
        assert!(
            texts.iter().any(|t| t.contains(wanted)),
            "no map has {wanted}"
        );
    }
    assert!(
        texts.iter().any(|t| t.contains(".")),
        "no vertex off the grid"
    );
}
