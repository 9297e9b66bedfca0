//! Finding the WADs a map names and the miptex for each texture it uses, plus the other frames
//! of its animations, with placeholders for whatever is missing so the BSP still loads.

use crate::texinfo::{AnimationFrame, TextureRole};
use crate::warnings::Warning;
use quake_formats::miptex::MipTex;
use quake_formats::wad::Wad;
use std::collections::{HashMap, HashSet};
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

    /// The texture from the first WAD holding it with pixels.
    fn find(&self, name: &str) -> Option<MipTex> {
        self.wads
            .iter()
            .find_map(|(_, w)| w.find_miptex(name))
            .filter(|t| t.mips.is_some())
    }

    /// The texture lump for the textures faces use (`used`, in the order texinfos refer to
    /// them): those textures, then the other frames engines need to link their animations.
    /// Textures no WAD holds become placeholders, with a warning.
    pub fn texture_lump(&self, used: &[&str], warnings: &mut Vec<Warning>) -> Vec<MipTex> {
        let mut entries = Vec::with_capacity(used.len());
        for &name in used {
            let lump = lump_name(name);
            let found = self.find(&lump);
            if found.is_none() {
                warnings.push(Warning::MissingTexture {
                    name: name.to_string(),
                });
            }
            if lump.starts_with('+') && AnimationFrame::of(&lump).is_none() {
                warnings.push(Warning::BadAnimationName {
                    name: name.to_string(),
                });
            }
            entries.push((lump, found));
        }
        let completing = self.completing_frames(&entries, warnings);
        entries.extend(completing);

        // A placeholder frame takes the size of a real frame of its animation.
        let mut frame_sizes: HashMap<String, (u32, u32)> = HashMap::new();
        for (name, found) in &entries {
            if let (Some(frame), Some(t)) = (AnimationFrame::of(name), found) {
                frame_sizes
                    .entry(frame.base.to_string())
                    .or_insert((t.width, t.height));
            }
        }
        entries
            .into_iter()
            .map(|(name, found)| match found {
                Some(MipTex {
                    width,
                    height,
                    mips: Some(mips),
                    ..
                }) => MipTex::new(&name, width, height, mips),
                _ => {
                    let size = AnimationFrame::of(&name)
                        .and_then(|f| frame_sizes.get(f.base).copied())
                        .unwrap_or_else(|| placeholder_size(&name));
                    placeholder(&name, size)
                }
            })
            .collect()
    }

    /// The frames that complete the animations among `entries`, which engines link from all
    /// `+0name`..`+9name` and `+aname`..`+jname` in the lump and reject when one has a gap: in
    /// each cycle, every frame below the highest one used (placeholders where no WAD holds
    /// them, as the map needs those), and the WADs' frames from the first on up to a gap.
    fn completing_frames(
        &self,
        entries: &[(String, Option<MipTex>)],
        warnings: &mut Vec<Warning>,
    ) -> Vec<(String, Option<MipTex>)> {
        let used: HashSet<&str> = entries.iter().map(|(n, _)| n.as_str()).collect();
        let mut cycles_done = HashSet::new();
        let mut out = Vec::new();
        for (name, _) in entries {
            let Some(frame) = AnimationFrame::of(name) else {
                continue;
            };
            for alternate in [false, true] {
                if !cycles_done.insert((frame.base, alternate)) {
                    continue;
                }
                let used_end = (0..10)
                    .rev()
                    .find(|&i| used.contains(frame.sibling(alternate, i).as_str()))
                    .map_or(0, |i| i + 1);
                for i in 0..10 {
                    let sibling = frame.sibling(alternate, i);
                    if used.contains(sibling.as_str()) {
                        continue;
                    }
                    let found = self.find(&sibling);
                    if found.is_none() {
                        if i >= used_end {
                            break;
                        }
                        warnings.push(Warning::MissingAnimationFrame {
                            name: sibling.clone(),
                        });
                    }
                    out.push((sibling, found));
                }
            }
        }
        out
    }
}

/// The name a texture gets in the BSP: at most 15 characters, lowercase as in id's BSPs.
/// Engines depend on the case: DarkPlaces (2018) counts sky textures by a case-sensitive `sky`
/// before it lowercases names, so `SKY4` overruns its texture array and crashes it, and
/// QuakeSpasm links animation frames by case-sensitive name.
fn lump_name(name: &str) -> String {
    name.chars()
        .take(15)
        .collect::<String>()
        .to_ascii_lowercase()
}

/// Sky placeholders get the 256x128 engines assume for sky; others the common 64x64.
fn placeholder_size(name: &str) -> (u32, u32) {
    if TextureRole::of(name) == TextureRole::Sky {
        (256, 128)
    } else {
        (64, 64)
    }
}

/// A checkerboard miptex named `name`. Unlike an absent miptex (offset -1, ericw-tools' choice)
/// it keeps the name, so engines still draw a missing sky as sky, warp a missing liquid, link
/// missing animation frames and may load a replacement image of that name; and id-derived
/// engines, which clear the texinfo's special flag for an absent miptex, do not then reject a
/// large unsubdivided sky or liquid face ("Bad surface extents").
pub fn placeholder(name: &str, (w, h): (u32, u32)) -> MipTex {
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
    MipTex::new(name, w, h, mips)
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::wad::WadLump;

    #[test]
    fn wad_key_is_split_into_file_names() {
        assert_eq!(
            wad_file_names("gfx/base.wad; C:\\quake\\id1\\x.wad;;/abs/lq_dev.wad"),
            vec!["base.wad", "x.wad", "lq_dev.wad"]
        );
    }

    /// A set holding one WAD of `(name, size)` textures.
    fn wad_set(textures: &[(&str, u32)]) -> WadSet {
        let lumps = textures
            .iter()
            .map(|&(name, size)| WadLump::miptex(placeholder(name, (size, size))))
            .collect();
        WadSet {
            wads: vec![(PathBuf::from("test.wad"), Wad::new(lumps))],
        }
    }

    fn names_and_sizes(lump: &[MipTex]) -> Vec<(String, u32)> {
        lump.iter().map(|t| (t.name(), t.width)).collect()
    }

    #[test]
    fn missing_wad_and_texture_give_placeholders() {
        let mut warnings = Vec::new();
        let set = WadSet::load("nope.wad", &[PathBuf::from("/nonexistent")], &mut warnings);
        let lump = set.texture_lump(&["SKY4"], &mut warnings);
        let t = &lump[0];
        assert_eq!((t.width, t.height), (256, 128));
        // Lowercase: DarkPlaces crashes on a sky texture named SKY4.
        assert_eq!(t.name(), "sky4");
        let mips = t.mips.as_ref().expect("pixels");
        assert_eq!(mips[3].len(), 32 * 16);
        assert_eq!(warnings.len(), 2);
    }

    #[test]
    fn a_used_frame_brings_its_whole_animation() {
        let set = wad_set(&[
            ("+0button", 32),
            ("+1button", 32),
            ("+2button", 32),
            ("+3button", 32),
            ("+abutton", 32),
            ("+0other", 32),
            ("WALL", 128),
        ]);
        let mut warnings = Vec::new();
        let lump = set.texture_lump(&["wall", "+3BUTTON"], &mut warnings);
        assert_eq!(warnings, vec![]);
        // The used textures keep their places; the other frames follow.
        assert_eq!(
            names_and_sizes(&lump),
            [
                ("wall", 128),
                ("+3button", 32),
                ("+0button", 32),
                ("+1button", 32),
                ("+2button", 32),
                ("+abutton", 32),
            ]
            .map(|(n, s)| (n.to_string(), s))
        );
    }

    #[test]
    fn wad_frames_stop_at_a_gap_above_the_used_ones() {
        let set = wad_set(&[("+0x", 32), ("+1x", 32), ("+3x", 32), ("+bx", 32)]);
        let mut warnings = Vec::new();
        let lump = set.texture_lump(&["+0x"], &mut warnings);
        assert_eq!(warnings, vec![]);
        // No +ax, so the alternates +bx alone would be a broken cycle.
        assert_eq!(
            names_and_sizes(&lump),
            [("+0x", 32), ("+1x", 32)].map(|(n, s)| (n.to_string(), s))
        );
    }

    #[test]
    fn gaps_below_a_used_frame_get_placeholders_of_the_animation_size() {
        let set = wad_set(&[("+0x", 32), ("+2x", 32)]);
        let mut warnings = Vec::new();
        let lump = set.texture_lump(&["+3x"], &mut warnings);
        assert_eq!(
            names_and_sizes(&lump),
            [("+3x", 32), ("+0x", 32), ("+1x", 32), ("+2x", 32)].map(|(n, s)| (n.to_string(), s))
        );
        assert_eq!(
            warnings,
            vec![
                Warning::MissingTexture {
                    name: "+3x".to_string()
                },
                Warning::MissingAnimationFrame {
                    name: "+1x".to_string()
                },
            ]
        );
    }

    #[test]
    fn a_missing_animation_gets_complete_placeholder_cycles() {
        // QuakeSpasm stopped with "Missing frame 0 of +3BUTNN" on an id map without its WAD.
        let set = WadSet::default();
        let mut warnings = Vec::new();
        let lump = set.texture_lump(&["+3BUTNN", "+bButnn", "+0LIFT"], &mut warnings);
        assert_eq!(
            lump.iter().map(MipTex::name).collect::<Vec<_>>(),
            [
                "+3butnn", "+bbutnn", "+0lift", "+0butnn", "+1butnn", "+2butnn", "+abutnn"
            ]
        );
        assert!(lump.iter().all(|t| (t.width, t.height) == (64, 64)));
        assert_eq!(
            warnings
                .iter()
                .filter(|w| matches!(w, Warning::MissingAnimationFrame { .. }))
                .count(),
            4
        );
    }

    #[test]
    fn a_plus_without_a_frame_is_reported() {
        let mut warnings = Vec::new();
        let lump = wad_set(&[("+xbutton", 16)]).texture_lump(&["+xbutton"], &mut warnings);
        assert_eq!(lump.len(), 1);
        assert_eq!(
            warnings,
            vec![Warning::BadAnimationName {
                name: "+xbutton".to_string()
            }]
        );
    }
}
