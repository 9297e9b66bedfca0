//! Finding the WADs a map names and the miptex for each texture it uses, with placeholders for
//! whatever is missing so the BSP still loads.

use crate::texinfo::TextureRole;
use crate::warnings::Warning;
use quake_formats::miptex::MipTex;
use quake_formats::wad::Wad;
use std::path::{Path, PathBuf};

/// The WADs a map's worldspawn names, as far as they were found.
#[derive(Debug, Default)]
pub struct WadSet {
    wads: Vec<(PathBuf, Wad)>,
}

/// The file names listed in a `"wad"` key (`;`-separated, paths in any style).
pub fn wad_file_names(key: &str) -> Vec<String> {
    key.split(';')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.rsplit(['/', '\\']).next().unwrap_or(s).to_string())
        .collect()
}

impl WadSet {
    /// Load each WAD named in `wad_key`, searching `search_dirs` in order by file name.
    pub fn load(wad_key: &str, search_dirs: &[PathBuf], warnings: &mut Vec<Warning>) -> WadSet {
        let mut wads = Vec::new();
        for name in wad_file_names(wad_key) {
            let found = search_dirs
                .iter()
                .map(|d| d.join(&name))
                .find(|p| p.is_file());
            let Some(path) = found else {
                warnings.push(Warning::MissingWad { name });
                continue;
            };
            match std::fs::read(&path)
                .map_err(|e| e.to_string())
                .and_then(|b| Wad::read(&b).map_err(|e| e.to_string()))
            {
                Ok(wad) => wads.push((path, wad)),
                Err(reason) => warnings.push(Warning::UnreadableWad { path, reason }),
            }
        }
        WadSet { wads }
    }

    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.wads.iter().map(|(p, _)| p.as_path())
    }

    /// The texture from the first WAD holding it, or a placeholder plus a warning.
    pub fn miptex(&self, name: &str, warnings: &mut Vec<Warning>) -> MipTex {
        if let Some(t) = self.wads.iter().find_map(|(_, w)| w.find_miptex(name))
            && t.mips.is_some()
        {
            return t;
        }
        warnings.push(Warning::MissingTexture {
            name: name.to_string(),
        });
        placeholder(name)
    }
}

/// A checkerboard miptex; sky placeholders get the 256x128 size engines assume for sky.
pub fn placeholder(name: &str) -> MipTex {
    let (w, h) = if TextureRole::of(name) == TextureRole::Sky {
        (256, 128)
    } else {
        (64, 64)
    };
    let mips = std::array::from_fn(|level| {
        let (lw, lh) = (w >> level, h >> level);
        let cell = (8 >> level).max(1);
        (0..lh)
            .flat_map(|y| {
                (0..lw).map(move |x| {
                    if (x / cell + y / cell) % 2 == 0 {
                        15
                    } else {
                        4
                    }
                })
            })
            .collect()
    });
    let short: String = name.chars().take(15).collect();
    MipTex::new(&short, w, h, mips)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wad_key_is_split_into_file_names() {
        assert_eq!(
            wad_file_names("gfx/base.wad; C:\\quake\\id1\\x.wad;;/abs/lq_dev.wad"),
            vec!["base.wad", "x.wad", "lq_dev.wad"]
        );
    }

    #[test]
    fn missing_wad_and_texture_give_placeholders() {
        let mut warnings = Vec::new();
        let set = WadSet::load("nope.wad", &[PathBuf::from("/nonexistent")], &mut warnings);
        let t = set.miptex("sky4", &mut warnings);
        assert_eq!((t.width, t.height), (256, 128));
        assert_eq!(t.name(), "sky4");
        let mips = t.mips.as_ref().expect("pixels");
        assert_eq!(mips[3].len(), 32 * 16);
        assert_eq!(warnings.len(), 2);
    }
}
