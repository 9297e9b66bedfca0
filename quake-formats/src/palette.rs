//! The 768-byte palette (256 RGB colours) that indexes every texture pixel.

use crate::error::{FormatError, Result};
use std::path::{Path, PathBuf};

/// How many folders above a file's own the game palette is looked for.
const PALETTE_SEARCH_DEPTH: usize = 3;

/// `gfx/palette.lmp` in `dir` or the nearest of its parents (up to three) that has one: Quake
/// keeps maps and WADs in `id1/maps/` and the palette in `id1/gfx/`, and engines draw every
/// texture through that palette.
pub fn find_game_palette(dir: &Path) -> Option<PathBuf> {
    dir.ancestors()
        .take(PALETTE_SEARCH_DEPTH + 1)
        .map(|a| a.join("gfx").join("palette.lmp"))
        .find(|p| p.is_file())
}

/// Palette indices from here up are "fullbright": drawn unlit by engines.
pub const FIRST_FULLBRIGHT: u8 = 224;

/// The colour of each palette index that texture pixels hold.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Palette {
    /// RGB of each index, 0-255 per channel.
    pub colors: [[u8; 3]; 256],
}

impl Palette {
    /// Read a palette file's 768 bytes (e.g. `gfx/palette.lmp`); any other size is an error.
    pub fn from_bytes(data: &[u8]) -> Result<Palette> {
        if data.len() != 768 {
            return Err(FormatError::PaletteSize(data.len()));
        }
        let mut colors = [[0u8; 3]; 256];
        for (c, rgb) in colors.iter_mut().zip(data.chunks_exact(3)) {
            c.copy_from_slice(rgb);
        }
        Ok(Palette { colors })
    }

    /// The 768 bytes of a palette file.
    pub fn to_bytes(&self) -> Vec<u8> {
        self.colors.iter().flatten().copied().collect()
    }

    /// Slipgate's own palette, used when no game palette is given: 14 ramps of 16 shades
    /// (greys, then hues around the colour wheel), then 32 fullbright colours. Defined here,
    /// not taken from any game's data.
    pub fn slipgate() -> Palette {
        let mut colors = [[0u8; 3]; 256];
        // Base hues (r, g, b) for the ramps; ramp 0 is grey.
        const HUES: [[f64; 3]; 14] = [
            [1.0, 1.0, 1.0],
            [0.55, 0.42, 0.30],
            [0.62, 0.50, 0.36],
            [0.45, 0.45, 0.55],
            [0.75, 0.35, 0.25],
            [0.35, 0.55, 0.30],
            [0.30, 0.40, 0.70],
            [0.80, 0.65, 0.30],
            [0.60, 0.30, 0.55],
            [0.35, 0.60, 0.60],
            [0.70, 0.55, 0.45],
            [0.50, 0.55, 0.35],
            [0.85, 0.45, 0.10],
            [0.40, 0.30, 0.25],
        ];
        for (ramp, hue) in HUES.iter().enumerate() {
            for shade in 0..16 {
                let level = (shade as f64 + 1.0) / 16.0;
                let c = &mut colors[ramp * 16 + shade];
                for ch in 0..3 {
                    c[ch] = (255.0 * (hue[ch] * level).min(1.0)).round() as u8;
                }
            }
        }
        // Fullbrights: fire, light fixtures and magic, each a ramp of 8 bright shades.
        const BRIGHT: [[f64; 3]; 4] = [
            [1.0, 0.55, 0.15],
            [1.0, 0.95, 0.70],
            [0.45, 0.65, 1.0],
            [1.0, 0.25, 0.20],
        ];
        for (ramp, hue) in BRIGHT.iter().enumerate() {
            for shade in 0..8 {
                let level = 0.6 + 0.4 * (shade as f64 + 1.0) / 8.0;
                let c = &mut colors[FIRST_FULLBRIGHT as usize + ramp * 8 + shade];
                for ch in 0..3 {
                    c[ch] = (255.0 * (hue[ch] * level).min(1.0)).round() as u8;
                }
            }
        }
        Palette { colors }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let p = Palette::slipgate();
        assert_eq!(Palette::from_bytes(&p.to_bytes()).expect("768 bytes"), p);
        assert!(Palette::from_bytes(&[0; 767]).is_err());
    }
}

#[cfg(test)]
mod search_tests {
    use super::*;

    #[test]
    fn the_game_palette_is_found_in_the_nearest_parent_with_one() {
        let root = std::env::temp_dir().join(format!("slipgate-palette-{}", std::process::id()));
        let maps = root.join("game").join("id1").join("maps");
        std::fs::create_dir_all(&maps).expect("folders");
        assert_eq!(find_game_palette(&maps), None);
        let gfx = root.join("game").join("id1").join("gfx");
        std::fs::create_dir_all(&gfx).expect("gfx");
        std::fs::write(gfx.join("palette.lmp"), [0u8; 768]).expect("palette");
        assert_eq!(find_game_palette(&maps), Some(gfx.join("palette.lmp")));
        // No more than three folders up.
        let deep = maps.join("a").join("b").join("c");
        std::fs::create_dir_all(&deep).expect("deep");
        assert_eq!(find_game_palette(&deep), None);
        assert_eq!(
            find_game_palette(&maps.join("a").join("b")),
            Some(gfx.join("palette.lmp"))
        );
        let _ = std::fs::remove_dir_all(&root);
    }
}
