//! The format's structure: every index, offset and range in bounds, every float finite.

use super::{Checker, Rule};
use crate::bsp::BspVersion;

impl Checker<'_> {
    /// `field` names the value in a problem's detail; it is formatted only for a problem.
    fn index(
        &mut self,
        lump: &'static str,
        index: usize,
        field: impl std::fmt::Display,
        value: u64,
        len: usize,
    ) {
        if value >= len as u64 {
            let detail = format!("{field} {value} is out of range (0..{len})");
            self.report(Rule::IndexRange, lump, index, detail);
        }
    }

    fn range(
        &mut self,
        lump: &'static str,
        index: usize,
        field: &str,
        (first, count): (u64, u64),
        len: usize,
    ) {
        if first + count > len as u64 {
            let end = first + count;
            let detail = format!("{field} {first}..{end} runs past the end ({len})");
            self.report(Rule::IndexRange, lump, index, detail);
        }
    }

    fn finite(&mut self, lump: &'static str, index: usize, values: &[f32]) {
        if values.iter().any(|v| !v.is_finite()) {
            let detail = "holds NaN or infinity".to_string();
            self.report(Rule::NonFinite, lump, index, detail);
        }
    }

    /// A node child or hull 0 head (`role`): a node index, or `-(leaf + 1)`.
    fn node_ref(&mut self, lump: &'static str, index: usize, role: &str, child: i32) {
        let bsp = self.bsp;
        if child >= 0 {
            let field = format_args!("{role} node");
            self.index(lump, index, field, child as u64, bsp.nodes.len());
        } else {
            let leaf = (-(child as i64 + 1)) as u64;
            let field = format_args!("{role} leaf");
            self.index(lump, index, field, leaf, bsp.leafs.len());
        }
    }

    /// A clip node child or clip hull head (`role`): a clip node index, or a contents value.
    fn clip_ref(&mut self, lump: &'static str, index: usize, role: &str, child: i32) {
        if child >= 0 {
            let len = self.bsp.clipnodes.len();
            let field = format_args!("{role} clip node");
            self.index(lump, index, field, child as u64, len);
        } else if child < -15 {
            let detail = format!("{role} contents {child} is not a contents value");
            self.report(Rule::ContentsValue, lump, index, detail);
        }
    }
}

pub(super) fn check(c: &mut Checker) {
    let bsp = c.bsp;
    if bsp.version == BspVersion::Bsp29
        && let Err(e) = bsp.check_bsp29_limits()
    {
        c.report(Rule::Bsp29Limit, "header", 0, e.to_string());
    }
    check_floats_and_planes(c);
    check_nodes(c);
    check_faces(c);
    check_leafs(c);
    check_indices(c);
    check_models(c);
}

fn check_floats_and_planes(c: &mut Checker) {
    let bsp = c.bsp;
    for (i, p) in bsp.planes.iter().enumerate() {
        c.finite(
            "planes",
            i,
            &[p.normal[0], p.normal[1], p.normal[2], p.dist],
        );
        let len = p
            .normal
            .iter()
            .map(|&n| (n as f64) * (n as f64))
            .sum::<f64>()
            .sqrt();
        if (len - 1.0).abs() > 0.01 {
            let detail = format!("normal has length {len:.4}, not 1");
            c.report(Rule::PlaneNormal, "planes", i, detail);
        }
    }
    for (i, v) in bsp.vertices.iter().enumerate() {
        c.finite("vertexes", i, v);
    }
    for (i, t) in bsp.texinfo.iter().enumerate() {
        c.finite("texinfo", i, &[t.vecs[0], t.vecs[1]].concat());
    }
}

fn check_nodes(c: &mut Checker) {
    let bsp = c.bsp;
    for (i, n) in bsp.nodes.iter().enumerate() {
        c.index("nodes", i, "plane", n.plane as u64, bsp.planes.len());
        c.node_ref("nodes", i, "child", n.children[0]);
        c.node_ref("nodes", i, "child", n.children[1]);
        let faces = (n.first_face as u64, n.num_faces as u64);
        c.range("nodes", i, "faces", faces, bsp.faces.len());
        c.finite("nodes", i, &[n.mins, n.maxs].concat());
    }
    for (i, n) in bsp.clipnodes.iter().enumerate() {
        c.index("clipnodes", i, "plane", n.plane as u64, bsp.planes.len());
        c.clip_ref("clipnodes", i, "child", n.children[0]);
        c.clip_ref("clipnodes", i, "child", n.children[1]);
    }
}

fn check_faces(c: &mut Checker) {
    let bsp = c.bsp;
    for (i, f) in bsp.faces.iter().enumerate() {
        c.index("faces", i, "plane", f.plane as u64, bsp.planes.len());
        if f.side > 1 {
            let detail = format!("side {} is neither 0 nor 1", f.side);
            c.report(Rule::IndexRange, "faces", i, detail);
        }
        if f.num_edges < 3 {
            let detail = format!("has {} edges, fewer than 3", f.num_edges);
            c.report(Rule::FaceEdges, "faces", i, detail);
        }
        let edges = (f.first_edge as u64, f.num_edges as u64);
        c.range("faces", i, "surfedges", edges, bsp.surfedges.len());
        c.index("faces", i, "texinfo", f.texinfo as u64, bsp.texinfo.len());
    }
    for (i, t) in bsp.texinfo.iter().enumerate() {
        // Engines read the index as signed: a negative one reads before the texture table.
        if (t.miptex as i32) < 0 {
            let detail = format!("miptex {} is negative", t.miptex as i32);
            c.report(Rule::IndexRange, "texinfo", i, detail);
        }
    }
}

fn check_leafs(c: &mut Checker) {
    let bsp = c.bsp;
    for (i, l) in bsp.leafs.iter().enumerate() {
        if l.contents >= 0 || l.contents < -15 {
            let detail = format!("contents {} is not a contents value", l.contents);
            c.report(Rule::ContentsValue, "leafs", i, detail);
        }
        // With no visibility data at all, engines treat every leaf as seeing everything.
        if l.vis_offset != -1 && !bsp.visibility.is_empty() {
            let offset = l.vis_offset as u32 as u64;
            c.index("leafs", i, "vis offset", offset, bsp.visibility.len());
        }
        let marks = (l.first_marksurface as u64, l.num_marksurfaces as u64);
        c.range("leafs", i, "mark surfaces", marks, bsp.marksurfaces.len());
        c.finite("leafs", i, &[l.mins, l.maxs].concat());
    }
}

/// The index-only lumps: mark surfaces, edges, surfedges.
fn check_indices(c: &mut Checker) {
    let bsp = c.bsp;
    for (i, &m) in bsp.marksurfaces.iter().enumerate() {
        c.index("marksurfaces", i, "face", m as u64, bsp.faces.len());
    }
    for (i, e) in bsp.edges.iter().enumerate() {
        c.index("edges", i, "vertex", e[0] as u64, bsp.vertices.len());
        c.index("edges", i, "vertex", e[1] as u64, bsp.vertices.len());
    }
    for (i, &se) in bsp.surfedges.iter().enumerate() {
        let edge = se.unsigned_abs() as u64;
        c.index("surfedges", i, "edge", edge, bsp.edges.len());
    }
}

fn check_models(c: &mut Checker) {
    let bsp = c.bsp;
    if bsp.models.is_empty() {
        c.report(
            Rule::NoWorldModel,
            "models",
            0,
            "no world model".to_string(),
        );
    }
    for (i, m) in bsp.models.iter().enumerate() {
        c.finite("models", i, &[m.mins, m.maxs, m.origin].concat());
        c.node_ref("models", i, "head", m.head_nodes[0]);
        for &h in &m.head_nodes[1..] {
            // Without clip nodes there is nothing to point at; `trees` reports the missing hulls.
            if h < 0 || !bsp.clipnodes.is_empty() {
                c.clip_ref("models", i, "head", h);
            }
        }
        let faces = (m.first_face as u64, m.num_faces as u64);
        c.range("models", i, "faces", faces, bsp.faces.len());
    }
}
