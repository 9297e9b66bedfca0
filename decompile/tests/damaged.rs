//! A damaged BSP is an error, not a panic: the gate every tool passes a BSP through refuses
//! broken indices, and whatever it lets through decompiles or fails with a typed error.

mod common;

use common::{compile_text, maps_dir};
use decompile::{DecompileError, Options, decompile};
use proptest::prelude::*;
use quake_formats::Bsp;
use std::sync::OnceLock;

/// demo.map compiled once, as bytes.
fn demo_bytes() -> &'static [u8] {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    BYTES.get_or_init(|| {
        let path = maps_dir().join("demo.map");
        let text = std::fs::read_to_string(&path).expect("demo.map");
        compile_text(&path, text).bsp.write().expect("write")
    })
}

fn demo() -> Bsp {
    Bsp::read(demo_bytes()).expect("read")
}

#[test]
fn out_of_range_indices_are_refused() {
    // The validator's own damage patterns: a texinfo, an edge's vertex and a node's child out
    // of range.
    let mut bsp = demo();
    bsp.faces[0].texinfo = 9999;
    bsp.edges[2][1] = 1 << 20;
    bsp.nodes[0].children[0] = -40_000;
    let err = decompile(&bsp, &Options::default()).expect_err("damaged");
    assert!(matches!(err, DecompileError::Unusable(_)), "{err}");
    assert!(err.to_string().contains("out of range"), "{err}");
}

#[test]
fn a_tree_with_a_cycle_is_refused() {
    let mut bsp = demo();
    bsp.nodes[1].children[0] = 0;
    let err = decompile(&bsp, &Options::default()).expect_err("cycle");
    assert!(matches!(err, DecompileError::Unusable(_)), "{err}");
}

#[test]
fn a_broken_entity_lump_is_an_error() {
    let mut bsp = demo();
    bsp.set_entity_text("{\n\"classname\" \"worldspawn\"\n\"message\"\n");
    let err = decompile(&bsp, &Options::default()).expect_err("entities");
    assert!(matches!(err, DecompileError::Entities(_)), "{err}");
    bsp.set_entity_text("{\n\"classname\" \"light\"\n}\n");
    let err = decompile(&bsp, &Options::default()).expect_err("no worldspawn");
    assert!(
        matches!(&err, DecompileError::NoWorldspawn { found } if found == "light"),
        "{err}"
    );
}

#[test]
fn an_entity_naming_a_missing_model_is_written_without_brushes() {
    let mut bsp = demo();
    let text = bsp.entity_text().replace("\"*1\"", "\"*77\"");
    bsp.set_entity_text(&text);
    let out = decompile(&bsp, &Options::default()).expect("decompile");
    assert!(
        out.warnings.iter().any(|w| w.to_string().contains("*77")),
        "{:?}",
        out.warnings
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Bytes flipped anywhere in the file: reading, the gate or decompiling may fail, never
    /// panic.
    #[test]
    fn random_byte_flips_never_panic(flips in proptest::collection::vec((any::<usize>(), 1u8..), 1..6)) {
        let mut bytes = demo_bytes().to_vec();
        let len = bytes.len();
        for (at, value) in flips {
            bytes[at % len] ^= value;
        }
        if let Ok(bsp) = Bsp::read(&bytes) {
            let _ = decompile(&bsp, &Options::default());
        }
    }

    /// Planes turned and moved at random keep every index sound: the decompiler must cope with
    /// whatever tree that makes.
    #[test]
    fn random_planes_never_panic(changes in proptest::collection::vec((any::<usize>(), -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -5000.0f32..5000.0), 1..8)) {
        let mut bsp = demo();
        let count = bsp.planes.len();
        for (at, x, y, z, dist) in changes {
            let plane = &mut bsp.planes[at % count];
            let len = (x * x + y * y + z * z).sqrt();
            if len > 0.1 {
                plane.normal = [x / len, y / len, z / len];
                plane.kind = 3;
            }
            plane.dist = dist;
        }
        let _ = decompile(&bsp, &Options::default());
    }
}
