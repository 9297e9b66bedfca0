//! LibreQuake's start map as ericw-tools compiled it, decompiled and compiled again by Slipgate:
//! sealed, good brushes, the same contents away from leaf boundaries. Skipped (saying so) when
//! `../shared/corpus` is absent.

mod common;

use common::{contents_agreement, round_trip_with_wads, side_agreement, texture_agreement};
use decompile::{MapFormat, Options};
use glam::DVec3;
use quake_formats::Bsp;
use std::path::{Path, PathBuf};

fn corpus() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus");
    if dir.exists() {
        Some(dir)
    } else {
        println!("SKIPPED: no corpus at {}", dir.display());
        None
    }
}

#[test]
fn librequake_start_round_trips() {
    let Some(corpus) = corpus() else {
        return;
    };
    let path = corpus.join("public/bsp/librequake/start.bsp");
    let bsp = Bsp::read(&std::fs::read(&path).expect("read start.bsp")).expect("parse start.bsp");
    for format in [MapFormat::Quake, MapFormat::Valve] {
        let options = Options {
            format,
            ..Options::default()
        };
        let (decompiled, again) = round_trip_with_wads(
            &bsp,
            &options,
            "start-decompiled.map",
            vec![corpus.join("wads/librequake")],
        );
        let agreement = contents_agreement(&bsp, &again.bsp, 0, 20_000, 0.05);
        let sides = side_agreement(&bsp, 0, &decompiled.text, 0, DVec3::ZERO);
        let textures = texture_agreement(&bsp, &again.bsp, 0, 0.25);
        println!(
            "start.bsp ({format:?}): {:?}\n  contents: {agreement:?}\n  brush sides: {sides:?}\n  recompiled textures: {textures:?}",
            decompiled.stats
        );
        assert_eq!(
            agreement.far, 0,
            "contents differ away from leaf boundaries"
        );
        assert_eq!(textures.unmatched, 0, "faces lost");
        // A sliver of a face may sit where its brush side meets another's (one in start.bsp).
        let most = |n: usize, of: usize| n as f64 >= 0.995 * of as f64;
        assert!(
            most(sides.same_texture, sides.compared()),
            "brush sides lost textures"
        );
        assert!(
            most(textures.same_texture, textures.compared()),
            "recompiled faces lost textures"
        );
        if format == MapFormat::Valve {
            assert!(
                most(sides.same_projection, sides.compared()),
                "brush sides lost projections"
            );
        }
    }
}
