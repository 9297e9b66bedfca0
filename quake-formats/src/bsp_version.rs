//! The BSP versions a file may be written in, apart from the BSP model so that errors can name
//! one without depending on it.

/// Which on-disk encoding a BSP uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BspVersion {
    /// Quake's original: 16-bit indices and bounds.
    Bsp29,
    /// The "BSP2" extension: 32-bit indices, float bounds.
    Bsp2,
    /// RMQ's first BSP2 ("2PSB", ericw-tools' `bsp2rmq`): BSP2's 32-bit indices, but nodes and
    /// leaves keep BSP29's 16-bit integer bounds.
    Bsp2Psb,
}

impl BspVersion {
    /// Whether indices and counts are 32-bit (BSP2, 2PSB) rather than BSP29's 16-bit ones.
    pub fn has_wide_indices(self) -> bool {
        matches!(self, BspVersion::Bsp2 | BspVersion::Bsp2Psb)
    }

    /// Whether node and leaf bounds are stored as 16-bit integers (BSP29, 2PSB) rather than
    /// BSP2's floats.
    pub fn has_short_bounds(self) -> bool {
        matches!(self, BspVersion::Bsp29 | BspVersion::Bsp2Psb)
    }
}

impl std::fmt::Display for BspVersion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BspVersion::Bsp29 => "BSP29",
            BspVersion::Bsp2 => "BSP2",
            BspVersion::Bsp2Psb => "2PSB",
        })
    }
}
