//! Damaged files give errors or validator problems that name the lump and index, never a panic.

use proptest::prelude::*;
use quake_formats::bsp::{BspPlane, Face, Leaf, Model, Node, TexInfo, contents};
use quake_formats::miptex::MipTex;
use quake_formats::{Bsp, BspVersion, FormatError, Severity, validate};

/// A one-face BSP built by hand: a 64x64 floor quad in one leaf.
fn tiny_bsp(version: BspVersion) -> Bsp {
    let mut bsp = Bsp::new(version);
    bsp.set_entity_text(
        "{\n\"classname\" \"worldspawn\"\n}\n{\n\"classname\" \"info_player_start\"\n}\n",
    );
    bsp.planes.push(BspPlane {
        normal: [0.0, 0.0, 1.0],
        dist: 0.0,
        kind: 2,
    });
    let mips = [vec![1u8; 256], vec![2; 64], vec![3; 16], vec![4; 4]];
    bsp.textures
        .textures
        .push(Some(MipTex::new("floor", 16, 16, mips)));
    bsp.vertices = vec![
        [0.0, 0.0, 0.0],
        [0.0, 64.0, 0.0],
        [64.0, 64.0, 0.0],
        [64.0, 0.0, 0.0],
    ];
    bsp.edges = vec![[0, 0], [0, 1], [1, 2], [2, 3], [3, 0]];
    bsp.surfedges = vec![1, 2, 3, 4];
    bsp.texinfo.push(TexInfo {
        vecs: [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]],
        miptex: 0,
        flags: 0,
    });
    bsp.faces.push(Face {
        plane: 0,
        side: 0,
        first_edge: 0,
        num_edges: 4,
        texinfo: 0,
        styles: [0, 255, 255, 255],
        light_offset: 0,
    });
    bsp.lighting = vec![128; 25];
    bsp.marksurfaces = vec![0];
    let leaf = |contents, marks| Leaf {
        contents,
        vis_offset: -1,
        mins: [0.0; 3],
        maxs: [64.0, 64.0, 64.0],
        first_marksurface: 0,
        num_marksurfaces: marks,
        ambient: [0; 4],
    };
    bsp.leafs = vec![leaf(contents::SOLID, 0), leaf(contents::EMPTY, 1)];
    bsp.nodes.push(Node {
        plane: 0,
        children: [-2, -1],
        mins: [0.0; 3],
        maxs: [64.0, 64.0, 64.0],
        first_face: 0,
        num_faces: 1,
    });
    bsp.models.push(Model {
        mins: [0.0; 3],
        maxs: [64.0, 64.0, 64.0],
        origin: [0.0; 3],
        head_nodes: [0, -1, -1, -1],
        vis_leafs: 1,
        first_face: 0,
        num_faces: 1,
    });
    bsp
}

#[test]
fn tiny_bsp_is_valid_in_both_versions() {
    for v in [BspVersion::Bsp29, BspVersion::Bsp2] {
        let bsp = tiny_bsp(v);
        assert_eq!(validate(&bsp), vec![]);
        let bytes = bsp.write().expect("write");
        assert_eq!(
            Bsp::read(&bytes).expect("read").write().expect("rewrite"),
            bytes
        );
        assert_eq!(bsp.leaf_at([32.0, 32.0, 8.0]), Some(1));
        assert_eq!(bsp.leaf_at([32.0, 32.0, -8.0]), Some(0));
    }
}

#[test]
fn truncation_anywhere_is_an_error() {
    let bytes = tiny_bsp(BspVersion::Bsp29).write().expect("write");
    for len in 0..bytes.len() {
        assert!(
            Bsp::read(&bytes[..len]).is_err(),
            "truncated to {len} bytes was accepted"
        );
    }
}

#[test]
fn lump_past_the_end_names_the_lump() {
    let mut bytes = tiny_bsp(BspVersion::Bsp29).write().expect("write");
    // Lump 7 (faces): its length field sits at 4 + 7 * 8 + 4.
    let at = 4 + 7 * 8 + 4;
    bytes[at..at + 4].copy_from_slice(&100_000i32.to_le_bytes());
    let err = Bsp::read(&bytes).expect_err("faces past the end");
    assert!(
        matches!(err, FormatError::LumpOutOfFile { lump: "faces", .. }),
        "{err}"
    );
}

#[test]
fn wrong_record_size_names_the_lump() {
    let mut bytes = tiny_bsp(BspVersion::Bsp29).write().expect("write");
    let at = 4 + 12 * 8 + 4; // edges length
    let len = i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    bytes[at..at + 4].copy_from_slice(&(len - 1).to_le_bytes());
    let err = Bsp::read(&bytes).expect_err("odd edge lump");
    assert!(err.to_string().contains("edges lump"), "{err}");
}

#[test]
fn out_of_range_indices_are_named() {
    let mut bsp = tiny_bsp(BspVersion::Bsp29);
    bsp.faces[0].texinfo = 9;
    bsp.edges[2][1] = 77;
    bsp.nodes[0].children[0] = -40;
    bsp.lighting.truncate(10);
    let problems: Vec<String> = validate(&bsp).iter().map(|p| p.to_string()).collect();
    let expect = [
        "faces[0]: texinfo 9 is out of range (0..1)",
        "edges[2]: vertex 77 is out of range (0..4)",
        "nodes[0]: child leaf 39 is out of range (0..2)",
    ];
    for e in expect {
        assert!(
            problems.iter().any(|p| p.contains(e)),
            "missing {e:?} in {problems:?}"
        );
    }
}

#[test]
fn nan_is_a_problem() {
    let mut bsp = tiny_bsp(BspVersion::Bsp2);
    bsp.vertices[1][2] = f32::NAN;
    let problems = validate(&bsp);
    assert!(
        problems
            .iter()
            .any(|p| p.lump == "vertexes" && p.index == 1 && p.severity == Severity::Error)
    );
}

#[test]
fn wrong_version_is_an_error() {
    let mut bytes = tiny_bsp(BspVersion::Bsp29).write().expect("write");
    bytes[..4].copy_from_slice(b"IBSP");
    assert!(matches!(
        Bsp::read(&bytes),
        Err(FormatError::UnknownBspVersion(_))
    ));
}

fn flip_bytes(mut bytes: Vec<u8>, flips: &[(usize, u8)]) -> Vec<u8> {
    let len = bytes.len();
    for &(at, value) in flips {
        bytes[at % len] ^= value;
    }
    bytes
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_byte_flips_never_panic(flips in proptest::collection::vec((any::<usize>(), 1u8..), 1..8), v2 in any::<bool>()) {
        let version = if v2 { BspVersion::Bsp2 } else { BspVersion::Bsp29 };
        let bytes = flip_bytes(tiny_bsp(version).write().expect("write"), &flips);
        if let Ok(bsp) = Bsp::read(&bytes) {
            let _ = validate(&bsp);
            let _ = bsp.write();
            let _ = bsp.leaf_at([1.0, 2.0, 3.0]);
        }
    }
}

/// The same on a real map when the corpus is present (fewer cases: it is larger).
#[test]
fn random_byte_flips_on_a_corpus_bsp_never_panic() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/corpus/public/bsp/librequake/start.bsp");
    let Ok(original) = std::fs::read(&path) else {
        eprintln!(
            "SKIPPED: {} not found (needs ../shared/corpus)",
            path.display()
        );
        return;
    };
    let mut runner = proptest::test_runner::TestRunner::new(ProptestConfig::with_cases(64));
    runner
        .run(
            &proptest::collection::vec((any::<usize>(), 1u8..), 1..16),
            |flips| {
                let bytes = flip_bytes(original.clone(), &flips);
                if let Ok(bsp) = Bsp::read(&bytes) {
                    let _ = validate(&bsp);
                    let _ = bsp.leaf_at([0.0, 0.0, 0.0]);
                }
                Ok(())
            },
        )
        .expect("no panics");
}

#[test]
fn pvs_rows_read_as_engines_read_them() {
    use quake_formats::PvsRow;
    let mut bsp = tiny_bsp(BspVersion::Bsp29);
    assert_eq!(bsp.pvs_row(1).expect("no vis data"), PvsRow::All);
    bsp.visibility = quake_formats::visrle::compress_row(&[0b1]);
    bsp.leafs[1].vis_offset = 0;
    let row = PvsRow::Row {
        bits: vec![0b1],
        complete: true,
    };
    assert_eq!(bsp.pvs_row(1).expect("row"), row);
    assert_eq!(bsp.pvs_row(0).expect("leaf 0"), PvsRow::All);
    bsp.leafs[1].vis_offset = 99;
    let err = bsp.pvs_row(1).expect_err("offset past the lump");
    assert!(err.to_string().contains("leaf 1"), "{err}");
}

/// The tiny BSP with every BSPX light lump, each sized and placed as light writes them.
fn tiny_bsp_with_light_lumps() -> Bsp {
    use quake_formats::bsp::light_lumps::{
        DecoupledLightmap, LIGHTING_E5BGR9, LIGHTINGDIR, RGBLIGHTING,
    };
    use quake_formats::bsp::lightgrid::{GridSample, LightGrid};
    let mut bsp = tiny_bsp(BspVersion::Bsp29);
    // The 16-texel lightmap (25 luxels) at 0, a 2x2 decoupled one after it.
    bsp.lighting = vec![128; 29];
    let rgb: Vec<u8> = (0..29 * 3).map(|i| i as u8).collect();
    bsp.set_bspx_lump(RGBLIGHTING, rgb);
    bsp.set_bspx_lump(LIGHTINGDIR, vec![128; 29 * 3]);
    let hdr = quake_formats::lit::pack_e5bgr9([1.5, 1.0, 0.5]).to_le_bytes();
    bsp.set_bspx_lump(LIGHTING_E5BGR9, hdr.repeat(29));
    bsp.set_decoupled_lightmaps(&[DecoupledLightmap {
        width: 2,
        height: 2,
        offset: 25,
        world_to_luxel: [[1.0 / 64.0, 0.0, 0.0, 0.0], [0.0, 1.0 / 64.0, 0.0, 0.0]],
    }]);
    let lit = Some(vec![GridSample {
        style: 0,
        rgb: [10, 20, 30],
    }]);
    let points: Vec<_> = (0..8)
        .map(|i| if i < 4 { None } else { lit.clone() })
        .collect();
    bsp.set_light_grid(&LightGrid::build([32.0; 3], [0.0; 3], [2, 2, 2], &points));
    bsp
}

fn rules_broken(bsp: &Bsp) -> Vec<quake_formats::bsp::Rule> {
    validate(bsp).iter().map(|p| p.rule).collect()
}

#[test]
fn bspx_light_lumps_as_light_writes_them_are_valid() {
    let bsp = tiny_bsp_with_light_lumps();
    assert_eq!(validate(&bsp), vec![]);
    let mut shifted = tiny_bsp(BspVersion::Bsp29);
    // An 8-texel grid: 9x9 luxels after the 25 of the 16-texel one.
    shifted.lighting = vec![128; 25 + 81];
    shifted.set_shifted_lightmaps(&[3], &[25]);
    assert_eq!(validate(&shifted), vec![]);
}

#[test]
fn damaged_bspx_light_lumps_break_their_rules() {
    use quake_formats::bsp::Rule;
    use quake_formats::bsp::light_lumps::{DECOUPLED_LM, RGBLIGHTING};
    use quake_formats::bsp::lightgrid::LIGHTGRID_OCTREE;

    let mut short_rgb = tiny_bsp_with_light_lumps();
    short_rgb.set_bspx_lump(RGBLIGHTING, vec![0; 10]);
    assert_eq!(rules_broken(&short_rgb), [Rule::BspxLightSize]);

    let mut past_end = tiny_bsp_with_light_lumps();
    let mut records = past_end
        .decoupled_lightmaps()
        .expect("reads")
        .expect("lump");
    records[0].offset = 27;
    past_end.set_decoupled_lightmaps(&records);
    assert_eq!(rules_broken(&past_end), [Rule::DecoupledLightmap]);
    records[0].offset = 25;
    records[0].world_to_luxel[1][3] = f32::NAN;
    past_end.set_decoupled_lightmaps(&records);
    assert_eq!(rules_broken(&past_end), [Rule::DecoupledLightmap]);

    let mut two_records = tiny_bsp_with_light_lumps();
    two_records.set_bspx_lump(DECOUPLED_LM, vec![0; 80]);
    assert_eq!(rules_broken(&two_records), [Rule::BspxFaceRecords]);

    let mut grid = tiny_bsp_with_light_lumps();
    grid.set_bspx_lump(LIGHTGRID_OCTREE, vec![0; 12]);
    assert_eq!(rules_broken(&grid), [Rule::LightGrid]);

    // A 4-texel grid over 64 texels: 17x17 luxels, far more than the lighting holds.
    let mut fine = tiny_bsp(BspVersion::Bsp29);
    fine.set_shifted_lightmaps(&[2], &[0]);
    assert_eq!(rules_broken(&fine), [Rule::ShiftedLightmap]);
    // A 320-texel face at one texel per luxel: 321 luxels, past the 256 engines must accept.
    fine.vertices.iter_mut().for_each(|v| v[0] *= 5.0);
    fine.lighting = vec![0; 400 * 70];
    fine.set_shifted_lightmaps(&[0], &[0]);
    assert!(rules_broken(&fine).contains(&Rule::ShiftedLightmap));
}

#[test]
fn light_only_in_rgblighting_is_a_warning_that_names_vanilla_engines() {
    use quake_formats::bsp::Rule;
    let mut bsp = tiny_bsp_with_light_lumps();
    bsp.lighting.clear();
    let problems = validate(&bsp);
    assert_eq!(
        problems.iter().map(|p| p.rule).collect::<Vec<_>>(),
        [Rule::NoVanillaLighting]
    );
    assert_eq!(problems[0].severity, Severity::Warning);
    assert!(
        problems[0].to_string().contains("QuakeSpasm"),
        "{}",
        problems[0]
    );
}

/// The `qbsp` crate, an independent reader, finds in our lumps what we wrote.
#[test]
fn the_qbsp_crate_reads_our_bspx_light_lumps() {
    let bsp = tiny_bsp_with_light_lumps();
    let bytes = bsp.write().expect("write");
    let theirs = qbsp::BspData::parse(qbsp::BspParseInput {
        bsp: &bytes,
        lit: None,
        settings: qbsp::BspParseSettings {
            use_bspx_rgb_lighting: false,
            ..Default::default()
        },
    })
    .expect("qbsp parses");
    let rgb = theirs.bspx.rgb_lighting.as_ref().expect("RGBLIGHTING");
    let ours = bsp
        .bspx_lump(quake_formats::bsp::light_lumps::RGBLIGHTING)
        .expect("lump");
    assert_eq!(rgb.len(), 29);
    assert!(rgb.iter().flatten().eq(ours.iter()));
    let decoupled = theirs.bspx.decoupled_lm.as_ref().expect("DECOUPLED_LM");
    let record = bsp.decoupled_lightmaps().expect("reads").expect("lump")[0];
    assert_eq!(decoupled.len(), 1);
    assert_eq!(decoupled[0].size.to_array(), [record.width, record.height]);
    assert_eq!(decoupled[0].offset.pixels, record.offset);
    let p = &decoupled[0].projection;
    // qbsp adds half a luxel to the offsets, as FTE does when it builds texture coordinates.
    assert_eq!(p.u_axis.to_array(), record.world_to_luxel[0][..3]);
    assert_eq!(p.u_offset - 0.5, record.world_to_luxel[0][3]);
    assert_eq!(p.v_axis.to_array(), record.world_to_luxel[1][..3]);
    assert_eq!(p.v_offset - 0.5, record.world_to_luxel[1][3]);
    let grid = theirs
        .bspx
        .light_grid_octree
        .as_ref()
        .expect("LIGHTGRID_OCTREE");
    assert_eq!(grid.size.to_array(), [2, 2, 2]);
}
