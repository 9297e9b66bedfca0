//! `.pts` pointfiles: the path from a leaking entity to the void, one `x y z` point per line,
//! which engines draw as a dotted trail (`pointfile` console command).

use glam::DVec3;

/// The pointfile's text: one line per point, each coordinate as the shortest text of its `f32`.
pub fn write_pointfile(points: &[DVec3]) -> String {
    points
        .iter()
        .map(|p| format!("{} {} {}\n", p.x as f32, p.y as f32, p.z as f32))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::{FormatError, Result};

    /// The points of a pointfile's text; blank lines are skipped.
    fn parse_pointfile(text: &str) -> Result<Vec<DVec3>> {
        text.lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty())
            .map(|(i, l)| {
                let v: Vec<f64> = l
                    .split_whitespace()
                    .filter_map(|f| f.parse().ok())
                    .collect();
                match v[..] {
                    [x, y, z] => Ok(DVec3::new(x, y, z)),
                    _ => Err(FormatError::Syntax {
                        line: i + 1,
                        detail: format!("expected three numbers, found {l:?}"),
                    }),
                }
            })
            .collect()
    }

    #[test]
    fn round_trip() {
        let pts = vec![DVec3::new(1.0, -2.5, 3.0), DVec3::new(4096.0, 0.0, 0.125)];
        assert_eq!(parse_pointfile(&write_pointfile(&pts)).expect("parse"), pts);
    }
}
