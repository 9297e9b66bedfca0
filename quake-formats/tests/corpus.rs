//! Every BSP and WAD in `../shared/corpus` reads, passes the validator's error rules (with the
//! known warnings only) and writes back byte-identical;
//! the independent `qbsp` crate agrees with our counts.

use quake_formats::wad::{Wad, lump_type};
use quake_formats::{Bsp, BspVersion, validate};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn corpus_files(sub: &str, ext: &str) -> Option<Vec<PathBuf>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/corpus")
        .join(sub);
    if !dir.is_dir() {
        eprintln!(
            "SKIPPED: corpus not found at {} (tests need ../shared beside the repo)",
            dir.display()
        );
        return None;
    }
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("corpus dir").flatten() {
        let p = entry.path();
        if p.is_dir() {
            for e in std::fs::read_dir(&p).expect("corpus subdir").flatten() {
                if e.path().extension().is_some_and(|x| x == ext) {
                    out.push(e.path());
                }
            }
        }
    }
    out.sort();
    Some(out)
}

/// The rules a corpus BSP breaks. Real engines load these files, so they break none, except for
/// what the corpus notes: q1_cube.bsp was compiled without clip hulls (an error: QuakeSpasm stops
/// once the player joins); lq1m1.bsp has a 56x56 texture, textures its compiler did not find
/// (stored as missing) and 27 nodes whose planes miss their regions (Debian's DarkPlaces prints
/// "new portal was clipped away" 27 times loading it), all warnings. lq1m1.bsp and e1m3.bsp
/// (ericw-tools' output) have lit faces whose lightmap extents DarkPlaces and QuakeSpasm compute
/// differently (a warning).
fn known_rules(path: &Path) -> BTreeSet<&'static str> {
    if path.ends_with("q1_cube.bsp") {
        ["clip-hulls-missing"].into()
    } else if path.ends_with("e1m3.bsp") {
        ["lightmap-extents-engines-disagree"].into()
    } else if path.ends_with("lq1m1.bsp") {
        [
            "lightmap-extents-engines-disagree",
            "node-plane-outside-region",
            "texture-alignment",
            "texture-missing",
        ]
        .into()
    } else {
        BTreeSet::new()
    }
}

fn rule_ids(bsp: &Bsp) -> BTreeSet<&'static str> {
    validate(bsp).iter().map(|p| p.rule.id()).collect()
}

#[test]
fn corpus_bsps_round_trip_and_validate() {
    let Some(files) = corpus_files("public/bsp", "bsp") else {
        return;
    };
    assert!(
        files.len() >= 5,
        "expected the corpus BSPs, found {files:?}"
    );
    for path in files {
        let bytes = std::fs::read(&path).expect("read");
        let bsp = Bsp::read(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let problems = validate(&bsp);
        assert_eq!(
            rule_ids(&bsp),
            known_rules(&path),
            "{}: {problems:?}",
            path.display()
        );
        let out = bsp.write().expect("write");
        assert!(
            out == bytes,
            "{}: rewrite differs (len {} vs {})",
            path.display(),
            out.len(),
            bytes.len()
        );
    }
}

#[test]
fn corpus_bsps_convert_between_versions() {
    let Some(files) = corpus_files("public/bsp", "bsp") else {
        return;
    };
    for path in files {
        let bsp = Bsp::read(&std::fs::read(&path).expect("read")).expect("parse");
        let other = match bsp.version {
            BspVersion::Bsp29 => BspVersion::Bsp2,
            BspVersion::Bsp2 | BspVersion::Bsp2Psb => BspVersion::Bsp29,
        };
        // 2PSB holds BSP29's bounds and BSP2's indices.
        if let Ok(psb) = bsp.converted(BspVersion::Bsp2Psb) {
            let bytes = psb.write().expect("write 2PSB");
            let back = Bsp::read(&bytes).expect("read 2PSB");
            assert_eq!(back.faces, bsp.faces, "{}", path.display());
            assert_eq!(back.clipnodes, bsp.clipnodes, "{}", path.display());
            if bsp.version == BspVersion::Bsp29 {
                assert_eq!(back.nodes, bsp.nodes, "{}", path.display());
                assert_eq!(back.leafs, bsp.leafs, "{}", path.display());
            }
        }
        let Ok(converted) = bsp.converted(other) else {
            continue;
        };
        let bytes = converted.write().expect("write converted");
        let back = Bsp::read(&bytes).expect("read converted");
        assert_eq!(rule_ids(&back), known_rules(&path), "{}", path.display());
        let again = back.converted(bsp.version).expect("convert back");
        assert_eq!(again.faces, bsp.faces, "{}", path.display());
        assert_eq!(again.marksurfaces, bsp.marksurfaces, "{}", path.display());
        if bsp.version == BspVersion::Bsp29 {
            // BSP29 -> BSP2 -> BSP29 loses nothing.
            assert_eq!(again.nodes, bsp.nodes, "{}", path.display());
            assert_eq!(again.leafs, bsp.leafs, "{}", path.display());
        } else {
            // BSP2 -> BSP29 rounds float bounds outward to whole units.
            for (a, b) in again.nodes.iter().zip(&bsp.nodes) {
                assert!((0..3).all(|i| a.mins[i] <= b.mins[i] && a.maxs[i] >= b.maxs[i]));
            }
        }
    }
}

#[test]
fn qbsp_crate_agrees_with_our_counts() {
    let Some(files) = corpus_files("public/bsp", "bsp") else {
        return;
    };
    for path in files {
        let bytes = std::fs::read(&path).expect("read");
        let ours = Bsp::read(&bytes).expect("parse");
        // Write through our writer so the independent reader checks our output, not the input.
        let written = ours.write().expect("write");
        let theirs = qbsp::BspData::parse(qbsp::BspParseInput {
            bsp: &written,
            lit: None,
            settings: Default::default(),
        })
        .unwrap_or_else(|e| panic!("{}: qbsp: {e}", path.display()));
        assert_eq!(theirs.planes.len(), ours.planes.len());
        assert_eq!(theirs.vertices.len(), ours.vertices.len());
        assert_eq!(theirs.nodes.len(), ours.nodes.len());
        assert_eq!(theirs.tex_info.len(), ours.texinfo.len());
        assert_eq!(theirs.faces.len(), ours.faces.len());
        assert_eq!(theirs.clip_nodes.len(), ours.clipnodes.len());
        assert_eq!(theirs.leaves.len(), ours.leafs.len());
        assert_eq!(theirs.mark_surfaces.len(), ours.marksurfaces.len());
        assert_eq!(theirs.edges.len(), ours.edges.len());
        assert_eq!(theirs.surface_edges.len(), ours.surfedges.len());
        assert_eq!(theirs.models.len(), ours.models.len());
        assert_eq!(theirs.textures.len(), ours.textures.textures.len());
    }
}

#[test]
fn corpus_wads_round_trip() {
    let Some(files) = corpus_files("wads", "wad") else {
        return;
    };
    assert!(!files.is_empty());
    for path in files {
        let bytes = std::fs::read(&path).expect("read");
        let wad = Wad::read(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let has_miptex = wad.lumps.iter().any(|l| l.kind == lump_type::MIPTEX);
        assert!(has_miptex, "{}", path.display());
        assert!(wad.write() == bytes, "{}: rewrite differs", path.display());
    }
}
