//! A strict structural check of a BSP: every index and offset in range, no NaN or infinity.

use super::records::texinfo_flags;
use super::{Bsp, BspVersion};
use crate::entities::parse_entities;
use crate::extents::LightmapExtents;

/// How bad a problem is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Severity {
    /// Engines read out of bounds or reject the file while loading it.
    Error,
    /// The file loads, but something will go wrong in play (named in the detail).
    Warning,
}

/// One thing wrong with a BSP, naming the lump and record.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    pub severity: Severity,
    pub lump: &'static str,
    /// The record's index in its lump (0 for whole-lump problems).
    pub index: usize,
    pub detail: String,
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let tag = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        write!(f, "{tag}: {}[{}]: {}", self.lump, self.index, self.detail)
    }
}

struct Checker<'a> {
    bsp: &'a Bsp,
    problems: Vec<Problem>,
}

impl Checker<'_> {
    fn report(&mut self, lump: &'static str, index: usize, detail: String) {
        self.problems.push(Problem {
            severity: Severity::Error,
            lump,
            index,
            detail,
        });
    }

    fn index(&mut self, lump: &'static str, index: usize, field: &str, value: u64, len: usize) {
        if value >= len as u64 {
            self.report(
                lump,
                index,
                format!("{field} {value} is out of range (0..{len})"),
            );
        }
    }

    fn range(
        &mut self,
        lump: &'static str,
        index: usize,
        field: &str,
        first: u64,
        count: u64,
        len: usize,
    ) {
        if first + count > len as u64 {
            self.report(
                lump,
                index,
                format!(
                    "{field} {first}..{} runs past the end ({len})",
                    first + count
                ),
            );
        }
    }

    fn finite(&mut self, lump: &'static str, index: usize, values: &[f32]) {
        if values.iter().any(|v| !v.is_finite()) {
            self.report(lump, index, "holds NaN or infinity".to_string());
        }
    }

    fn node_child(&mut self, index: usize, child: i32) {
        let bsp = self.bsp;
        if child >= 0 {
            self.index("nodes", index, "child node", child as u64, bsp.nodes.len());
        } else {
            let leaf = (-(child as i64 + 1)) as u64;
            self.index("nodes", index, "child leaf", leaf, bsp.leafs.len());
        }
    }

    fn clip_child(&mut self, lump: &'static str, index: usize, child: i32) {
        if child >= 0 {
            self.index(
                lump,
                index,
                "child clip node",
                child as u64,
                self.bsp.clipnodes.len(),
            );
        } else if child < -15 {
            self.report(
                lump,
                index,
                format!("child contents {child} is not a contents value"),
            );
        }
    }
}

/// Every problem found; with no [`Severity::Error`] engines can load the file's structure safely.
pub fn validate(bsp: &Bsp) -> Vec<Problem> {
    let mut c = Checker {
        bsp,
        problems: Vec::new(),
    };
    if bsp.version == BspVersion::Bsp29
        && let Err(e) = bsp.check_bsp29_limits()
    {
        c.report("header", 0, e.to_string());
    }
    if bsp.entities.last() != Some(&0) {
        c.report("entities", 0, "text is not NUL-terminated".to_string());
    }
    if let Err(e) = parse_entities(&bsp.entity_text()) {
        c.report("entities", 0, e.to_string());
    }
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
            c.report("planes", i, format!("normal has length {len:.4}, not 1"));
        }
    }
    for (i, t) in bsp.textures.textures.iter().enumerate() {
        if let Some(t) = t
            && (t.width % 16 != 0 || t.height % 16 != 0)
        {
            c.problems.push(Problem {
                severity: Severity::Warning,
                lump: "textures",
                index: i,
                detail: format!(
                    "{} is {}x{}, not a multiple of 16: vanilla engines refuse to load it",
                    t.name(),
                    t.width,
                    t.height
                ),
            });
        }
    }
    for (i, v) in bsp.vertices.iter().enumerate() {
        c.finite("vertexes", i, v);
    }
    for (i, n) in bsp.nodes.iter().enumerate() {
        c.index("nodes", i, "plane", n.plane as u64, bsp.planes.len());
        c.node_child(i, n.children[0]);
        c.node_child(i, n.children[1]);
        c.range(
            "nodes",
            i,
            "faces",
            n.first_face as u64,
            n.num_faces as u64,
            bsp.faces.len(),
        );
        c.finite("nodes", i, &[n.mins, n.maxs].concat());
    }
    for (i, t) in bsp.texinfo.iter().enumerate() {
        c.index(
            "texinfo",
            i,
            "miptex",
            t.miptex as u64,
            bsp.textures.textures.len(),
        );
        c.finite("texinfo", i, &[t.vecs[0], t.vecs[1]].concat());
    }
    for (i, f) in bsp.faces.iter().enumerate() {
        c.index("faces", i, "plane", f.plane as u64, bsp.planes.len());
        if f.side > 1 {
            c.report("faces", i, format!("side {} is neither 0 nor 1", f.side));
        }
        if f.num_edges < 3 {
            c.report(
                "faces",
                i,
                format!("has {} edges, fewer than 3", f.num_edges),
            );
        }
        c.range(
            "faces",
            i,
            "surfedges",
            f.first_edge as u64,
            f.num_edges as u64,
            bsp.surfedges.len(),
        );
        c.index("faces", i, "texinfo", f.texinfo as u64, bsp.texinfo.len());
        check_face_lightmap(&mut c, i);
    }
    for (i, l) in bsp.leafs.iter().enumerate() {
        if l.contents >= 0 || l.contents < -15 {
            c.report(
                "leafs",
                i,
                format!("contents {} is not a contents value", l.contents),
            );
        }
        // With no visibility data at all, engines treat every leaf as seeing everything.
        if l.vis_offset != -1 && !bsp.visibility.is_empty() {
            c.index(
                "leafs",
                i,
                "vis offset",
                l.vis_offset as u32 as u64,
                bsp.visibility.len(),
            );
        }
        c.range(
            "leafs",
            i,
            "mark surfaces",
            l.first_marksurface as u64,
            l.num_marksurfaces as u64,
            bsp.marksurfaces.len(),
        );
        c.finite("leafs", i, &[l.mins, l.maxs].concat());
    }
    for (i, n) in bsp.clipnodes.iter().enumerate() {
        c.index("clipnodes", i, "plane", n.plane as u64, bsp.planes.len());
        c.clip_child("clipnodes", i, n.children[0]);
        c.clip_child("clipnodes", i, n.children[1]);
    }
    for (i, &m) in bsp.marksurfaces.iter().enumerate() {
        c.index("marksurfaces", i, "face", m as u64, bsp.faces.len());
    }
    for (i, e) in bsp.edges.iter().enumerate() {
        c.index("edges", i, "vertex", e[0] as u64, bsp.vertices.len());
        c.index("edges", i, "vertex", e[1] as u64, bsp.vertices.len());
    }
    for (i, &se) in bsp.surfedges.iter().enumerate() {
        c.index(
            "surfedges",
            i,
            "edge",
            se.unsigned_abs() as u64,
            bsp.edges.len(),
        );
    }
    if bsp.models.is_empty() {
        c.report("models", 0, "no world model".to_string());
    }
    for (i, m) in bsp.models.iter().enumerate() {
        c.finite("models", i, &[m.mins, m.maxs, m.origin].concat());
        if m.head_nodes[0] >= 0 {
            c.index(
                "models",
                i,
                "head node",
                m.head_nodes[0] as u64,
                bsp.nodes.len(),
            );
        } else {
            c.node_child(i, m.head_nodes[0]);
        }
        if bsp.clipnodes.is_empty() && m.head_nodes[1..3].iter().any(|&h| h >= 0) {
            c.problems.push(Problem {
                severity: Severity::Warning,
                lump: "models",
                index: i,
                detail: "the file has no clip hulls: engines crash once a player or monster moves"
                    .to_string(),
            });
        } else {
            for &h in &m.head_nodes[1..] {
                c.clip_child("models", i, h);
            }
        }
        c.range(
            "models",
            i,
            "faces",
            m.first_face as u64,
            m.num_faces as u64,
            bsp.faces.len(),
        );
    }
    c.problems
}

/// A lit face's lightmaps (one per style) must lie inside the lighting lump.
fn check_face_lightmap(c: &mut Checker, i: usize) {
    let bsp = c.bsp;
    let f = &bsp.faces[i];
    if f.light_offset < 0 {
        return;
    }
    let Some(tex) = bsp.texinfo.get(f.texinfo as usize) else {
        return;
    };
    if tex.flags & texinfo_flags::SPECIAL != 0 {
        return;
    }
    let Some(points) = bsp.face_vertices(f) else {
        c.report("faces", i, "refers to a missing edge or vertex".to_string());
        return;
    };
    let ext = LightmapExtents::from_points(&points, &tex.vecs);
    let styles = f.styles.iter().filter(|&&s| s != 255).count().max(1);
    let needed = ext.luxel_count() * styles;
    let offset = f.light_offset as usize;
    if offset + needed > bsp.lighting.len() {
        c.report(
            "faces",
            i,
            format!(
                "lightmap at {offset} ({needed} bytes for {styles} style(s)) runs past the lighting lump ({} bytes)",
                bsp.lighting.len()
            ),
        );
    }
}
