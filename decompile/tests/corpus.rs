//! LibreQuake's start map as ericw-tools compiled it, decompiled and compiled again by Slipgate:
//! sealed, good brushes, the same contents away from leaf boundaries. Skipped (saying so) when
//! `../shared/corpus` is absent.

mod common;

use common::{contents_agreement, round_trip_with_wads, side_agreement, texture_agreement};
use decompile::{MapFormat, Options};
use glam::DVec3;
use quake_formats::Bsp;
use std::path::{Path, PathBuf};

/// The share of the recompiled faces that must keep their texture (see `round_trip.rs`).
const MIN_RECOMPILED_TEXTURES: f64 = 0.85;

/// The corpus folder, or `None` (saying SKIPPED) when it is absent.
fn corpus() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus");
    dir.exists().then_some(dir).or_else(|| {
        println!("SKIPPED: no ../shared/corpus beside the repository");
        None
    })
}

#[test]
fn librequake_start_round_trips() {
    round_trip_corpus_map("start");
}

/// LibreQuake's larger maps (ericw-tools' compiles too).
#[test]
fn librequake_e1m3_and_lq1m1_round_trip() {
    round_trip_corpus_map("e1m3");
    round_trip_corpus_map("lq1m1");
}

fn round_trip_corpus_map(name: &str) {
    let Some(corpus) = corpus() else {
        return;
    };
    let path = corpus.join(format!("public/bsp/librequake/{name}.bsp"));
    let bsp = Bsp::read(&std::fs::read(&path).expect("read")).expect("parse");
    for format in [MapFormat::Quake, MapFormat::Valve] {
        let options = Options {
            format,
            ..Options::default()
        };
        let (decompiled, again) = round_trip_with_wads(
            &bsp,
            &options,
            &format!("{name}-decompiled.map"),
            vec![corpus.join("wads/librequake")],
        );
        let agreement = contents_agreement(&bsp, &again.bsp, 0, 20_000, 0.05);
        let sides = side_agreement(&bsp, 0, &decompiled.text, 0, DVec3::ZERO);
        let textures = texture_agreement(&bsp, &again.bsp, 0, 0.25);
        println!(
            "{name}.bsp ({format:?}): {:?}\n  contents: {agreement:?}\n  brush sides: {sides:?}\n  recompiled textures: {textures:?}",
            decompiled.stats
        );
        assert_eq!(
            agreement.far, 0,
            "{name}: contents differ away from leaf boundaries"
        );
        // Slivers: a face a fraction of a unit across may sit where its brush side meets
        // another's, or on a leaf too thin to be a brush.
        let most = |n: usize, of: usize| n as f64 >= 0.995 * of as f64;
        assert!(
            most(sides.same_texture, sides.compared()),
            "{name}: brush sides lost textures"
        );
        if format == MapFormat::Valve {
            assert!(
                most(sides.same_projection, sides.compared()),
                "{name}: brush sides lost projections"
            );
        }
        // The compiler lets regions thinner than a sixteenth of a unit join their neighbours
        // (ericw-tools keeps them): a few faces on such wedges go (39 of 9922 in lq1m1).
        assert!(
            textures.unmatched * 200 <= textures.compared(),
            "{name}: faces lost"
        );
        // Slipgate's compiler textures a leaf's face on a plane from one brush side, so where
        // the decompiled map has flush brushes of different textures on one plane one wins.
        assert!(
            textures.same_texture as f64 >= MIN_RECOMPILED_TEXTURES * textures.compared() as f64,
            "{name}: recompiled faces lost textures"
        );
    }
}
