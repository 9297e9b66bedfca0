//! The void outside a map: a leak's is refused, but a map with no point entity in its open space
//! (a test room, a prefab) keeps its outside unfilled without leaking, and vis runs through it.

use bsp_compiler::{CompileOptions, CompileOutput, MapSource, compile};
use quake_formats::prt::PortalFile;
use std::path::PathBuf;
use vis::{Outside, VisError, VisOptions, check_portals_match, check_sealed, compute_vis, store};

/// An axis-aligned box brush in the standard format.
fn cuboid(lo: [i32; 3], hi: [i32; 3]) -> String {
    let [a, b, c] = lo;
    let [x, y, z] = hi;
    format!(
        "{{\n( {a} {b} {c} ) ( {a} {y} {c} ) ( {a} {b} {z} ) wall 0 0 0 1 1\n\
         ( {x} {b} {c} ) ( {x} {b} {z} ) ( {x} {y} {c} ) wall 0 0 0 1 1\n\
         ( {a} {b} {c} ) ( {a} {b} {z} ) ( {x} {b} {c} ) wall 0 0 0 1 1\n\
         ( {a} {y} {c} ) ( {x} {y} {c} ) ( {a} {y} {z} ) wall 0 0 0 1 1\n\
         ( {a} {b} {c} ) ( {x} {b} {c} ) ( {a} {y} {c} ) wall 0 0 0 1 1\n\
         ( {a} {b} {z} ) ( {a} {y} {z} ) ( {x} {b} {z} ) wall 0 0 0 1 1\n}}\n"
    )
}

/// A room 256 units wide inside 16-unit walls, with a 32-unit gap in its +x wall when `hole`,
/// and `entities` after worldspawn.
fn room(hole: bool, entities: &str) -> String {
    let mut brushes = [
        cuboid([-144, -144, -144], [144, 144, -128]),
        cuboid([-144, -144, 128], [144, 144, 144]),
        cuboid([-144, -144, -128], [-128, 144, 128]),
        cuboid([-128, -144, -128], [128, -128, 128]),
        cuboid([-128, 128, -128], [128, 144, 128]),
    ]
    .concat();
    if hole {
        brushes += &cuboid([128, -144, -128], [144, 0, 128]);
        brushes += &cuboid([128, 32, -128], [144, 144, 128]);
    } else {
        brushes += &cuboid([128, -144, -128], [144, 144, 128]);
    }
    format!("{{\n\"classname\" \"worldspawn\"\n{brushes}}}\n{entities}")
}

fn point_entity(classname: &str, origin: &str, extra: &str) -> String {
    format!("{{\n\"classname\" \"{classname}\"\n\"origin\" \"{origin}\"\n{extra}}}\n")
}

fn compiled(text: String) -> CompileOutput {
    let source = MapSource {
        path: PathBuf::from("inline.map"),
        text,
    };
    compile(&source, &CompileOptions::default()).expect("compile")
}

/// Vis runs on the compiled map through its portal file, as the command line does.
fn vis_runs(out: &mut CompileOutput) {
    let prt = PortalFile::parse(&out.portals.write()).expect("portal file");
    check_portals_match(&out.bsp, prt.num_leafs as usize).expect("portals match");
    let result = compute_vis(&prt, &VisOptions::default()).expect("vis");
    store(&mut out.bsp, &result.pvs, Default::default()).expect("store");
    assert!(!out.bsp.visibility.is_empty());
}

#[test]
fn a_map_without_entities_in_open_space_includes_the_outside() {
    let buried = point_entity("light", "-136 0 0", "");
    let marked = point_entity("info_null", "400 0 0", "\"_nofill\" \"1\"\n");
    let at_origin = point_entity("light", "0 0 0", "");
    for entities in [String::new(), buried, marked, at_origin] {
        // Even an open box: with nothing to flood from, there is no leak to find.
        for hole in [false, true] {
            let mut out = compiled(room(hole, &entities));
            assert!(out.leak.is_none(), "{entities}");
            assert!(
                matches!(check_sealed(&out.bsp), Ok(Outside::Included { .. })),
                "{entities} hole {hole}"
            );
            vis_runs(&mut out);
        }
    }
}

#[test]
fn a_leaks_void_is_refused_and_a_sealed_map_is_filled() {
    let start = point_entity("info_player_start", "-32 -32 -100", "");
    let out = compiled(room(true, &start));
    assert!(out.leak.is_some());
    assert!(matches!(check_sealed(&out.bsp), Err(VisError::Void { .. })));

    let mut out = compiled(room(false, &start));
    assert!(out.leak.is_none());
    assert_eq!(check_sealed(&out.bsp).expect("sealed"), Outside::Filled);
    vis_runs(&mut out);
}
