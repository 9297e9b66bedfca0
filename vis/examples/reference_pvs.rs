//! Our PVS against one another tool wrote (a benchmark, not a test):
//! `cargo run --release -p slipgate-vis --example reference_pvs -- [MAP.map REFERENCE.bsp ...]`
//! (default: LibreQuake's start and e1m3 against the BSPs ericw-tools compiled from them).
//!
//! The map is compiled with the project's compiler and vised at levels 2 and 4. The two BSPs
//! have different leaves, so they are compared in world space: random point pairs, uniform in
//! the world's box and kept when both points lie in open leaves of both BSPs. For each pair we
//! ask each PVS whether the points' leaves may see each other, and trace the segment through
//! both trees for the truth.

use bsp_compiler::{CompileOptions, MapSource, compile};
use glam::DVec3;
use quake_formats::Bsp;

use quake_formats::rng::SplitMix64;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use vis::sample::{Hull0, is_open};
use vis::{Pvs, VisMode, VisOptions, compute_vis, read_pvs};

const PAIRS: usize = 1_000_000;
const CHUNK: usize = 4096;

/// One side of the comparison: a BSP's tree and its PVS.
struct Side {
    hull: Hull0,
    contents: Vec<i32>,
    pvs: Pvs,
}

impl Side {
    fn new(bsp: &Bsp, pvs: Pvs) -> Side {
        Side {
            hull: Hull0::new(bsp).expect("hull 0"),
            contents: bsp.leafs.iter().map(|l| l.contents).collect(),
            pvs,
        }
    }

    /// The vis leaf (row index) holding `p`, when it is open.
    fn open_leaf(&self, p: DVec3) -> Option<usize> {
        let leaf = self.hull.leaf_at(p);
        (leaf >= 1 && leaf <= self.pvs.num_leafs() && is_open(self.contents[leaf]))
            .then_some(leaf - 1)
    }
}

#[derive(Default)]
struct Counts {
    pairs: usize,
    /// Clear through our tree / through theirs.
    clear_ours: usize,
    clear_theirs: usize,
    in_ours: usize,
    in_theirs: usize,
    only_ours: usize,
    only_theirs: usize,
    /// Clear (through the same BSP's tree) but not in that BSP's PVS.
    too_small_ours: usize,
    too_small_theirs: usize,
}

impl Counts {
    fn add(&mut self, o: &Counts) {
        self.pairs += o.pairs;
        self.clear_ours += o.clear_ours;
        self.clear_theirs += o.clear_theirs;
        self.in_ours += o.in_ours;
        self.in_theirs += o.in_theirs;
        self.only_ours += o.only_ours;
        self.only_theirs += o.only_theirs;
        self.too_small_ours += o.too_small_ours;
        self.too_small_theirs += o.too_small_theirs;
    }
}

fn main() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus");
    let args: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    let pairs: Vec<(PathBuf, PathBuf)> = if args.is_empty() {
        ["start", "e1m3"]
            .iter()
            .map(|m| {
                (
                    corpus.join(format!("public/maps/librequake/{m}.map")),
                    corpus.join(format!("public/bsp/librequake/{m}.bsp")),
                )
            })
            .collect()
    } else {
        args.chunks_exact(2)
            .map(|c| (c[0].clone(), c[1].clone()))
            .collect()
    };
    println!(
        "| map | level | our leaves / reference leaves | pairs | clear (ours / ref tree) | in our PVS | in ref PVS | ours / ref | only ours | only ref | too small (ours / ref) |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (map, reference) in pairs {
        let source = MapSource::read(&map).expect("read map");
        let options = CompileOptions {
            wad_dirs: vec![corpus.join("wads/librequake")],
            ..CompileOptions::default()
        };
        let out = compile(&source, &options).expect("compile");
        let theirs_bsp = Bsp::read(&std::fs::read(&reference).expect("read")).expect("parse");
        let theirs = Side::new(&theirs_bsp, read_pvs(&theirs_bsp).expect("reference PVS"));
        for level in [2, 4] {
            let options = VisOptions {
                mode: VisMode::Full { level },
                ..VisOptions::default()
            };
            let ours = compute_vis(&out.portals, &options).expect("vis");
            let ours = Side::new(&out.bsp, ours.pvs);
            let world = &out.bsp.models[0];
            let lo = DVec3::new(
                world.mins[0] as f64,
                world.mins[1] as f64,
                world.mins[2] as f64,
            );
            let hi = DVec3::new(
                world.maxs[0] as f64,
                world.maxs[1] as f64,
                world.maxs[2] as f64,
            );
            let counts = (0..PAIRS.div_ceil(CHUNK))
                .into_par_iter()
                .map(|chunk| sample_chunk(&ours, &theirs, lo, hi, chunk as u64))
                .reduce(Counts::default, |mut a, b| {
                    a.add(&b);
                    a
                });
            let pct = |n: usize| 100.0 * n as f64 / counts.pairs as f64;
            let name = map
                .file_stem()
                .map_or(String::new(), |s| s.to_string_lossy().into_owned());
            println!(
                "| {name} | {level} | {} / {} | {} | {:.2}% / {:.2}% | {:.2}% | {:.2}% | {:.3} | {:.2}% | {:.2}% | {} / {} |",
                ours.pvs.num_leafs(),
                theirs.pvs.num_leafs(),
                counts.pairs,
                pct(counts.clear_ours),
                pct(counts.clear_theirs),
                pct(counts.in_ours),
                pct(counts.in_theirs),
                counts.in_ours as f64 / counts.in_theirs.max(1) as f64,
                pct(counts.only_ours),
                pct(counts.only_theirs),
                counts.too_small_ours,
                counts.too_small_theirs,
            );
        }
    }
}

/// `CHUNK` pairs of points open in both BSPs, drawn uniformly in the box `lo..hi`.
fn sample_chunk(ours: &Side, theirs: &Side, lo: DVec3, hi: DVec3, chunk: u64) -> Counts {
    let mut rng = SplitMix64::new(0x5eed ^ chunk.wrapping_mul(0x2545_f491_4f6c_dd1d));
    let mut point = || loop {
        let mut p = DVec3::ZERO;
        for i in 0..3 {
            p[i] = lo[i] + rng.unit() * (hi[i] - lo[i]);
        }
        if let (Some(a), Some(b)) = (ours.open_leaf(p), theirs.open_leaf(p)) {
            return (p, a, b);
        }
    };
    let mut c = Counts::default();
    for _ in 0..CHUNK.min(PAIRS - (chunk as usize) * CHUNK) {
        let (p, ours_p, theirs_p) = point();
        let (q, ours_q, theirs_q) = point();
        let in_ours = ours.pvs.sees(ours_p, ours_q);
        let in_theirs = theirs.pvs.sees(theirs_p, theirs_q);
        let clear_ours = ours.hull.segment_is_open(p, q);
        let clear_theirs = theirs.hull.segment_is_open(p, q);
        c.pairs += 1;
        c.clear_ours += usize::from(clear_ours);
        c.clear_theirs += usize::from(clear_theirs);
        c.in_ours += usize::from(in_ours);
        c.in_theirs += usize::from(in_theirs);
        c.only_ours += usize::from(in_ours && !in_theirs);
        c.only_theirs += usize::from(in_theirs && !in_ours);
        c.too_small_ours += usize::from(clear_ours && !in_ours);
        c.too_small_theirs += usize::from(clear_theirs && !in_theirs);
    }
    c
}
