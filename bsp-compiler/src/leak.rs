//! A leak as the mapper reads it: which entity the void reaches, the path from it, and the
//! brushes where that path leaves the map ([`crate::outside`] finds them).

use glam::DVec3;

/// A map brush: its entity, its number within the entity and its line, as a mapper finds it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MapBrushRef {
    /// The entity's index in the map.
    pub entity: usize,
    /// The brush's index within its entity.
    pub brush: usize,
    /// The brush's line in the `.map`.
    pub line: usize,
}

/// A leak as the mapper reads it: the entity, the path, and the brush faces where it leaves.
#[derive(Debug, Clone, PartialEq)]
pub struct LeakReport {
    /// The entity's index in the map.
    pub entity: usize,
    /// The entity's classname.
    pub classname: String,
    /// The entity's origin.
    pub origin: DVec3,
    /// The entity's line in the `.map`.
    pub line: usize,
    /// What the `.pts` file holds.
    pub pointfile: Vec<DVec3>,
    /// The brush faces beside the path where it leaves the map, nearest first, with textures.
    pub exit: Vec<(MapBrushRef, String, DVec3)>,
    /// The entity stands beyond the box around every brush of the map.
    pub beyond_brushes: bool,
}

impl std::fmt::Display for LeakReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = |p: &DVec3| format!("({} {} {})", round(p.x), round(p.y), round(p.z));
        write!(
            f,
            "entity {} ({}, line {}) at {} reaches the void",
            self.entity,
            self.classname,
            self.line,
            v(&self.origin)
        )?;
        if self.beyond_brushes {
            write!(f, "; it stands outside every brush of the map")?;
        }
        for (i, (b, texture, point)) in self.exit.iter().enumerate() {
            let lead = if i == 0 {
                "; the path leaves the map past"
            } else {
                ","
            };
            write!(
                f,
                "{lead} brush {} of entity {} (line {}, {texture}) near {}",
                b.brush,
                b.entity,
                b.line,
                v(point)
            )?;
        }
        Ok(())
    }
}

/// A coordinate to a tenth of a unit, without a trailing `.0`.
fn round(x: f64) -> f64 {
    // Adding 0.0 turns -0.0 into 0.0.
    (x * 10.0).round() / 10.0 + 0.0
}
