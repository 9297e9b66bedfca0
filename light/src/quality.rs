//! How much work light spends per luxel.

/// How much work to spend per luxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Quality {
    /// One sample per luxel.
    Default,
    /// `--extra`: 2x2 samples per luxel.
    Extra,
    /// `--extra4`: 4x4 samples per luxel.
    Extra4,
    /// `--reference`: 16x16 samples per luxel, no light culling.
    Reference,
}

impl Quality {
    /// Samples along each axis of a luxel.
    pub fn samples_per_axis(self) -> usize {
        match self {
            Quality::Default => 1,
            Quality::Extra => 2,
            Quality::Extra4 => 4,
            Quality::Reference => 16,
        }
    }
}
