//! `.prt` portal files (PRT1), the compiler's hand-off to vis.
//!
//! ```text
//! PRT1
//! <leaf count>          (leaves that have PVS rows: BSP leaves minus leaf 0)
//! <portal count>
//! <points> <leaf a> <leaf b> (x y z ) (x y z ) ...
//! ```
//! Leaf numbers here count from BSP leaf 1.
//!
//! PRT2 (tyrutils/ericw-tools, for maps whose detail leaves are grouped into clusters) adds the
//! cluster count to the header, numbers portal ends by cluster, and ends with one line per
//! cluster listing its leaves, each list closed by `-1`:
//!
//! ```text
//! PRT2
//! <leaf count>
//! <cluster count>
//! <portal count>
//! <points> <cluster a> <cluster b> (x y z ) ...
//! <leaf> <leaf> ... -1          (one line per cluster)
//! ```

use crate::error::{FormatError, Result};
use crate::geom::Winding;
use glam::DVec3;

/// A portal between two vis leaves.
#[derive(Debug, Clone, PartialEq)]
pub struct PrtPortal {
    /// The two vis leaves (clusters in PRT2) the portal joins, 0 standing for BSP leaf 1.
    pub leafs: [u32; 2],
    /// The opening; its plane (clockwise seen from the front) faces `leafs[0]`.
    pub winding: Winding,
}

/// A whole portal file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PortalFile {
    /// Vis leaves (BSP leaves 1..=num_leafs).
    pub num_leafs: u32,
    /// Portals; their `leafs` are cluster numbers when `clusters` is set.
    pub portals: Vec<PrtPortal>,
    /// PRT2 only: the leaves of each cluster.
    pub clusters: Option<Vec<Vec<u32>>>,
}

impl PortalFile {
    /// Read a PRT1 or PRT2 file; a leaf or cluster number out of range is an error.
    pub fn parse(text: &str) -> Result<PortalFile> {
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim()));
        let mut next = |what: &str| -> Result<(usize, &str)> {
            lines
                .by_ref()
                .find(|(_, l)| !l.is_empty())
                .ok_or_else(|| FormatError::Syntax {
                    line: 0,
                    detail: format!("portal file ends before {what}"),
                })
        };
        let (line, magic) = next("the PRT1 or PRT2 header")?;
        let prt2 = match magic {
            "PRT1" => false,
            "PRT2" => true,
            _ => {
                return Err(FormatError::Syntax {
                    line,
                    detail: format!("expected PRT1 or PRT2, found {magic:?}"),
                });
            }
        };
        let num = |(line, s): (usize, &str), what: &str| -> Result<u32> {
            s.parse().map_err(|_| FormatError::Syntax {
                line,
                detail: format!("{what}: {s:?} is not a count"),
            })
        };
        let num_leafs = num(next("the leaf count")?, "leaf count")?;
        let num_clusters = if prt2 {
            num(next("the cluster count")?, "cluster count")?
        } else {
            num_leafs
        };
        let num_portals = num(next("the portal count")?, "portal count")?;
        let mut portals = Vec::with_capacity(num_portals.min(1 << 20) as usize);
        for _ in 0..num_portals {
            let (line, text) = next("all portals")?;
            portals.push(parse_portal(line, text, num_clusters)?);
        }
        let clusters = if prt2 {
            let mut clusters = Vec::with_capacity(num_clusters.min(1 << 20) as usize);
            for _ in 0..num_clusters {
                let (line, text) = next("every cluster's leaf list")?;
                clusters.push(parse_cluster(line, text, num_leafs)?);
            }
            Some(clusters)
        } else {
            None
        };
        Ok(PortalFile {
            num_leafs,
            portals,
            clusters,
        })
    }

    /// The file's text: PRT2 when `clusters` is set, PRT1 otherwise.
    pub fn write(&self) -> String {
        use std::fmt::Write;
        let mut out = String::new();
        // Writing into a String cannot fail.
        let _ = match &self.clusters {
            None => write!(out, "PRT1\n{}\n{}\n", self.num_leafs, self.portals.len()),
            Some(c) => write!(
                out,
                "PRT2\n{}\n{}\n{}\n",
                self.num_leafs,
                c.len(),
                self.portals.len()
            ),
        };
        for p in &self.portals {
            let _ = write!(out, "{} {} {}", p.winding.len(), p.leafs[0], p.leafs[1]);
            for v in &p.winding.points {
                // Each coordinate as the shortest text that reads back to the same `f32` (what
                // vis gets anyway).
                let _ = write!(out, " ({} {} {} )", v.x as f32, v.y as f32, v.z as f32);
            }
            out.push('\n');
        }
        for leafs in self.clusters.iter().flatten() {
            for leaf in leafs {
                let _ = write!(out, "{leaf} ");
            }
            out.push_str("-1\n");
        }
        out
    }
}

fn parse_cluster(line: usize, text: &str, num_leafs: u32) -> Result<Vec<u32>> {
    let err = |detail: String| FormatError::Syntax { line, detail };
    let mut leafs = Vec::new();
    for f in text.split_whitespace() {
        let v: i64 = f
            .parse()
            .map_err(|_| err(format!("cluster leaf {f:?} is not a number")))?;
        if v == -1 {
            return Ok(leafs);
        }
        if v < 0 || v >= num_leafs as i64 {
            return Err(err(format!(
                "leaf {v} is not below the leaf count {num_leafs}"
            )));
        }
        leafs.push(v as u32);
    }
    Err(err("cluster leaf list does not end with -1".to_string()))
}

fn parse_portal(line: usize, text: &str, num_ends: u32) -> Result<PrtPortal> {
    let err = |detail: String| FormatError::Syntax { line, detail };
    let cleaned = text.replace(['(', ')'], " ");
    let mut fields = cleaned.split_whitespace();
    let mut int = |what: &str| -> Result<u32> {
        let f = fields
            .next()
            .ok_or_else(|| err(format!("missing {what}")))?;
        f.parse()
            .map_err(|_| err(format!("{what} {f:?} is not a number")))
    };
    let count = int("point count")?;
    let a = int("first leaf")?;
    let b = int("second leaf")?;
    if a >= num_ends || b >= num_ends {
        return Err(err(format!(
            "portal end {a} or {b} is not below the leaf (or cluster) count {num_ends}"
        )));
    }
    if !(3..=1024).contains(&count) {
        return Err(err(format!("portal with {count} points")));
    }
    let mut coords = Vec::with_capacity(count as usize * 3);
    for f in fields {
        let v: f64 = f
            .parse()
            .map_err(|_| err(format!("coordinate {f:?} is not a number")))?;
        // Portal files hold single-precision coordinates (the writer rounds to f32).
        if !(v as f32).is_finite() {
            return Err(err(format!(
                "coordinate {f:?} is not a finite 32-bit number"
            )));
        }
        coords.push(v);
    }
    if coords.len() != count as usize * 3 {
        return Err(err(format!(
            "expected {} coordinates, found {}",
            count * 3,
            coords.len()
        )));
    }
    let points = coords
        .chunks(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect();
    Ok(PrtPortal {
        leafs: [a, b],
        winding: Winding::new(points),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::DVec3Ext;

    #[test]
    fn round_trip() {
        let file = PortalFile {
            num_leafs: 3,
            portals: vec![PrtPortal {
                leafs: [0, 2],
                winding: Winding::new(vec![
                    DVec3::new(0.0, 0.0, 0.0),
                    DVec3::new(0.0, 64.5, 0.0),
                    DVec3::new(-1e-3, 64.0, 128.0),
                ]),
            }],
            clusters: None,
        };
        let text = file.write();
        assert!(text.starts_with("PRT1\n3\n1\n3 0 2 ("));
        let back = PortalFile::parse(&text).expect("parse");
        assert_eq!(back.portals[0].leafs, [0, 2]);
        for (a, b) in back.portals[0]
            .winding
            .points
            .iter()
            .zip(&file.portals[0].winding.points)
        {
            assert!(a.near(*b, 1e-6));
        }
    }

    #[test]
    fn prt2_round_trip() {
        let text = "PRT2\n3\n2\n1\n3 0 1 (0 0 0 ) (0 64 0 ) (0 0 64 )\n0 1 -1\n2 -1\n";
        let file = PortalFile::parse(text).expect("parse");
        assert_eq!(file.clusters, Some(vec![vec![0, 1], vec![2]]));
        assert_eq!(PortalFile::parse(&file.write()).expect("reparse"), file);
        assert!(PortalFile::parse("PRT2\n3\n2\n0\n0 1\n2 -1\n").is_err());
    }

    #[test]
    fn bad_leaf_names_line() {
        let err =
            PortalFile::parse("PRT1\n2\n1\n3 0 5 (0 0 0) (1 0 0) (0 1 0)\n").expect_err("leaf 5");
        assert!(err.to_string().contains("line 4"), "{err}");
    }

    #[test]
    fn coordinates_beyond_single_precision_are_refused() {
        // Found by fuzzing (fuzz/corpus/prt/crash-62b6e2cb...): 1.2e45 read as f64, then
        // written as "inf", which the reader refuses.
        let text = "PRT1\n2\n1\n3 0 1 (0 0 0 ) (1157777777777777777777777777777777777777777772 0 0 ) (0 1 0 )\n";
        let err = PortalFile::parse(text).expect_err("beyond f32");
        assert!(err.to_string().contains("line 4"), "{err}");
    }
}
