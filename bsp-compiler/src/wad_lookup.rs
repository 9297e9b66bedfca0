//! Finding the WADs a map names and the miptex for each texture it names, plus the other frames
//! of its animations, with placeholders for whatever is missing that the BSP needs to load.

use crate::texinfo::{AnimationFrame, TextureRole};
use crate::warnings::Warning;
use quake_formats::entities::Entity;
use quake_formats::miptex::MipTex;
use quake_formats::string_to_name16;
use quake_formats::wad::Wad;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// The WADs a map's worldspawn names, as far as they were found, and what a texture none of
/// them holds becomes.
#[derive(Debug, Default)]
pub struct WadSet {
    wads: Vec<FoundWad>,
    missing: MissingTextures,
}

/// What a texture no WAD holds becomes: by default, when a face shows it, a placeholder with
/// its name, 64x64 (sky 256x128), and a warning; otherwise an absent miptex.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MissingTextures {
    /// Folders whose loose pictures (`textures/NAME.png` or `.tga`, ericw-tools' `-path`) give
    /// such a texture its size; it is then written by name and size, without pixels. Only
    /// searched when no texture's pixels are written (`-notex`), as in ericw-tools.
    pub loose_dirs: Vec<PathBuf>,
    /// Write it as a 0x0 miptex with its name instead of a placeholder (ericw-tools'
    /// `-missing_textures_as_zero_size`), for engines that load it from elsewhere; others crash
    /// on it.
    pub zero_size: bool,
}

/// The picture formats loose textures are read from.
const LOOSE_EXTENSIONS: [&str; 2] = ["png", "tga"];

impl MissingTextures {
    /// The size of the loose picture of texture `name` (as the map writes it, or lowercase), if
    /// one of the folders holds one.
    fn loose_size(&self, name: &str) -> Option<(u32, u32)> {
        let names = [name.to_string(), name.to_ascii_lowercase()];
        self.loose_dirs.iter().find_map(|dir| {
            names.iter().find_map(|n| {
                LOOSE_EXTENSIONS.iter().find_map(|ext| {
                    image::image_dimensions(dir.join("textures").join(format!("{n}.{ext}"))).ok()
                })
            })
        })
    }
}

#[derive(Debug)]
struct FoundWad {
    path: PathBuf,
    wad: Wad,
    /// Whether its textures' pixels go into the BSP (not for `-xwadpath` folders).
    embed: bool,
}

/// Where a compile looks for the WADs a map names, in order (see [`WadSearch::candidates`]).
#[derive(Debug, Clone, PartialEq)]
pub struct WadSearch {
    /// Folders, each with whether the textures of WADs found there are embedded: the
    /// `--wad-dir` (`-wadpath`) folders, the `-xwadpath` ones (read for sizes only), the map's
    /// own folder, and the working directory (an empty path).
    pub folders: Vec<(PathBuf, bool)>,
    /// The WAD read when worldspawn names none: `MAP.wad` beside the map.
    pub beside_map: PathBuf,
}

/// The WAD names worldspawn's `wad` (or `_wad`) key lists (`;`-separated, paths in any style,
/// `\` read as `/`).
pub(crate) fn wad_names(worldspawn: &Entity) -> Vec<String> {
    let key = ["wad", "_wad"]
        .iter()
        .find_map(|k| worldspawn.get(k).filter(|v| !v.trim().is_empty()))
        .unwrap_or("");
    key.split(';')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.replace('\\', "/"))
        .collect()
}

impl WadSearch {
    /// The paths tried for the WAD `name`, in order, each with whether its textures are
    /// embedded: an absolute path as written; a relative one, folders and all, joined onto each
    /// folder; then the file name alone in each folder. (A name with a Windows drive, `C:/...`,
    /// is only looked for by its file name.)
    pub fn candidates(&self, name: &str) -> Vec<(PathBuf, bool)> {
        let path = Path::new(name);
        let drive = name.len() > 1 && name.as_bytes()[1] == b':';
        let mut out: Vec<(PathBuf, bool)> = Vec::new();
        if path.is_absolute() {
            out.push((path.to_path_buf(), true));
        } else if !drive {
            out.extend(
                self.folders
                    .iter()
                    .map(|(dir, embed)| (dir.join(path), *embed)),
            );
        }
        if let Some(file) = path.file_name().filter(|f| Path::new(f) != path) {
            out.extend(
                self.folders
                    .iter()
                    .map(|(dir, embed)| (dir.join(file), *embed)),
            );
        }
        let mut seen = HashSet::new();
        out.retain(|(p, _)| seen.insert(p.clone()));
        out
    }
}

impl WadSet {
    /// Load each WAD worldspawn names (`MAP.wad` beside the map when it names none), looking for
    /// each as [`WadSearch::candidates`] says; a WAD not found is a warning naming where it was
    /// looked for.
    pub fn load(worldspawn: &Entity, search: &WadSearch, warnings: &mut Vec<Warning>) -> WadSet {
        let mut names = wad_names(worldspawn);
        let beside_map = names.is_empty() && search.beside_map.is_file();
        if beside_map {
            names.push(search.beside_map.to_string_lossy().into_owned());
        }
        let mut wads = Vec::new();
        for name in names {
            let candidates = search.candidates(&name);
            let Some((path, embed)) = candidates.iter().find(|(p, _)| p.is_file()).cloned() else {
                warnings.push(Warning::MissingWad {
                    name,
                    looked: candidates.into_iter().map(|(p, _)| p).collect(),
                });
                continue;
            };
            match std::fs::read(&path)
                .map_err(|e| e.to_string())
                .and_then(|b| Wad::read(&b).map_err(|e| e.to_string()))
            {
                Ok(wad) => wads.push(FoundWad { path, wad, embed }),
                Err(reason) => warnings.push(Warning::UnreadableWad { path, reason }),
            }
        }
        WadSet {
            wads,
            missing: MissingTextures::default(),
        }
    }

    /// This set, with textures no WAD holds becoming what `missing` says.
    pub fn with_missing(self, missing: MissingTextures) -> WadSet {
        WadSet { missing, ..self }
    }

    /// The files the WADs were read from.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.wads.iter().map(|w| w.path.as_path())
    }

    /// The texture from the first WAD holding it with pixels, without them when that WAD's
    /// textures are not embedded (`-xwadpath`).
    fn find(&self, name: &str) -> Option<MipTex> {
        self.wads.iter().find_map(|w| {
            let mut t = w.wad.find_miptex(name).filter(|t| t.mips.is_some())?;
            if !w.embed {
                t.mips = None;
            }
            Some(t)
        })
    }

    /// The texture lump for `list`, each texture with whether a face shows it (`shown`), then
    /// the other frames engines need to link its animations. A texture no WAD holds is left
    /// out (an absent miptex, offset -1, as ericw-tools writes every missing texture), or 0x0
    /// with its name under [`MissingTextures::zero_size`]; but one a face shows, or an animation
    /// frame below one the lump holds, becomes a placeholder with a warning (see
    /// [`placeholder`]).
    pub(crate) fn texture_lump(
        &self,
        list: &TextureList,
        shown: &[bool],
        warnings: &mut Vec<Warning>,
    ) -> Vec<Option<MipTex>> {
        let mut entries = Vec::with_capacity(list.names.len());
        for (i, name) in list.names.iter().enumerate() {
            let shown = shown.get(i).copied().unwrap_or(false);
            let lump = lump_name(name);
            let found = self.find(&lump).or_else(|| {
                let (width, height) = self.missing.loose_size(name)?;
                Some(MipTex {
                    raw_name: string_to_name16(&lump),
                    width,
                    height,
                    mips: None,
                })
            });
            if found.is_none() && shown {
                warnings.push(Warning::MissingTexture { name: name.clone() });
            }
            if lump.starts_with('+')
                && AnimationFrame::of(&lump).is_none()
                && (shown || found.is_some())
            {
                warnings.push(Warning::BadAnimationName { name: name.clone() });
            }
            entries.push(LumpEntry {
                name: lump,
                found,
                shown,
            });
        }
        let completing = self.completing_frames(&entries);
        entries.extend(completing);

        // Each animation cycle's highest frame the lump holds, and the size of a real frame,
        // which a placeholder frame takes.
        let mut cycle_ends: HashMap<(String, bool), u8> = HashMap::new();
        let mut frame_sizes: HashMap<String, (u32, u32)> = HashMap::new();
        for e in &entries {
            let Some(frame) = AnimationFrame::of(&e.name) else {
                continue;
            };
            if e.shown || e.found.is_some() {
                let end = cycle_ends
                    .entry((frame.base.to_string(), frame.alternate))
                    .or_default();
                *end = (*end).max(frame.index + 1);
            }
            if let Some(t) = &e.found {
                frame_sizes
                    .entry(frame.base.to_string())
                    .or_insert((t.width, t.height));
            }
        }
        entries
            .into_iter()
            .map(|e| {
                let completes_cycle = AnimationFrame::of(&e.name).is_some_and(|f| {
                    cycle_ends
                        .get(&(f.base.to_string(), f.alternate))
                        .is_some_and(|&end| f.index < end)
                });
                if e.found.is_none() && !e.shown && completes_cycle {
                    warnings.push(Warning::MissingAnimationFrame {
                        name: e.name.clone(),
                    });
                }
                match e.found {
                    Some(MipTex {
                        width,
                        height,
                        mips: Some(mips),
                        ..
                    }) => Some(MipTex::new(&e.name, width, height, mips)),
                    Some(MipTex { width, height, .. }) => Some(MipTex {
                        raw_name: string_to_name16(&e.name),
                        width,
                        height,
                        mips: None,
                    }),
                    None if self.missing.zero_size => Some(MipTex {
                        raw_name: string_to_name16(&e.name),
                        width: 0,
                        height: 0,
                        mips: None,
                    }),
                    None if e.shown || completes_cycle => {
                        let size = AnimationFrame::of(&e.name)
                            .and_then(|f| frame_sizes.get(f.base).copied())
                            .unwrap_or_else(|| placeholder_size(&e.name));
                        Some(placeholder(&e.name, size))
                    }
                    None => None,
                }
            })
            .collect()
    }

    /// The frames the WADs hold that complete the animations among `entries`, which engines
    /// link from all `+0name`..`+9name` and `+aname`..`+jname` in the lump: in each cycle, the
    /// WADs' frames from the first on up to a gap (engines reject a cycle with one). The
    /// frames below a listed one are listed already ([`TextureList::of_map`]).
    fn completing_frames(&self, entries: &[LumpEntry]) -> Vec<LumpEntry> {
        let listed: HashSet<&str> = entries.iter().map(|e| e.name.as_str()).collect();
        let mut cycles_done = HashSet::new();
        let mut out = Vec::new();
        for e in entries {
            let Some(frame) = AnimationFrame::of(&e.name) else {
                continue;
            };
            for alternate in [false, true] {
                if !cycles_done.insert((frame.base, alternate)) {
                    continue;
                }
                for i in 0..10 {
                    let sibling = frame.sibling(alternate, i);
                    if listed.contains(sibling.as_str()) {
                        continue;
                    }
                    let Some(found) = self.find(&sibling) else {
                        break;
                    };
                    out.push(LumpEntry {
                        name: sibling,
                        found: Some(found),
                        shown: false,
                    });
                }
            }
        }
        out
    }
}

/// A texture of the lump being made: its name in the BSP, the WADs' miptex of it, and whether
/// a face shows it.
struct LumpEntry {
    name: String,
    found: Option<MipTex>,
    shown: bool,
}

/// The textures a BSP lists, in the order ericw-tools' qbsp lists them: `skip` first (qbsp
/// registers it before it reads the map), then each texture the map names on a brush face, in
/// the order the map first names it (letter case aside), whether or not any face of it is
/// drawn; a frame of an animation is followed by the frames below it in its cycle. Textures
/// are found by name (letter case aside) as texinfos refer to them.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct TextureList {
    /// The names as the map first writes them.
    names: Vec<String>,
    slots: HashMap<String, u32>,
}

impl TextureList {
    /// The list for a map whose brush faces name `face_textures`, in file order.
    pub(crate) fn of_map<'a>(face_textures: impl IntoIterator<Item = &'a str>) -> TextureList {
        let mut list = TextureList::default();
        list.slot(SKIP_TEXTURE);
        for name in face_textures {
            if list.slots.contains_key(&name.to_ascii_lowercase()) {
                continue;
            }
            list.slot(name);
            // Engines load an animation only with every frame below the highest one there.
            if let Some(frame) = AnimationFrame::of(name) {
                for i in 0..frame.index {
                    list.slot(&frame.sibling(frame.alternate, i));
                }
            }
        }
        list
    }

    /// The slot of texture `name`, added at the end when it is not listed yet.
    pub(crate) fn slot(&mut self, name: &str) -> u32 {
        let key = name.to_ascii_lowercase();
        if let Some(&slot) = self.slots.get(&key) {
            return slot;
        }
        let slot = self.names.len() as u32;
        self.names.push(name.to_string());
        self.slots.insert(key, slot);
        slot
    }

    /// How many textures are listed.
    pub(crate) fn len(&self) -> usize {
        self.names.len()
    }
}

/// The texture ericw-tools' qbsp always lists first.
const SKIP_TEXTURE: &str = "skip";

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
pub(crate) fn placeholder(name: &str, (w, h): (u32, u32)) -> MipTex {
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
    fn the_wad_key_lists_paths_as_written() {
        let mut world = Entity::default();
        world.set(
            "wad",
            "gfx/base.wad; C:\\quake\\id1\\x.wad;;/abs/lq_dev.wad",
        );
        assert_eq!(
            wad_names(&world),
            vec!["gfx/base.wad", "C:/quake/id1/x.wad", "/abs/lq_dev.wad"]
        );
        let mut world = Entity::default();
        world.set("_wad", "a.wad");
        assert_eq!(wad_names(&world), vec!["a.wad"]);
    }

    #[test]
    fn wads_are_looked_for_by_path_then_by_file_name() {
        let search = WadSearch {
            folders: vec![
                (PathBuf::from("/wads"), true),
                (PathBuf::from("/ext"), false),
                (PathBuf::new(), true),
            ],
            beside_map: PathBuf::from("/maps/m.wad"),
        };
        let paths = |name| -> Vec<(String, bool)> {
            search
                .candidates(name)
                .into_iter()
                .map(|(p, e)| (p.display().to_string(), e))
                .collect()
        };
        let s = |p: &str, e| (p.to_string(), e);
        assert_eq!(
            paths("gfx/base.wad"),
            [
                s("/wads/gfx/base.wad", true),
                s("/ext/gfx/base.wad", false),
                s("gfx/base.wad", true),
                s("/wads/base.wad", true),
                s("/ext/base.wad", false),
                s("base.wad", true),
            ]
        );
        assert_eq!(
            paths("/abs/q.wad"),
            [
                s("/abs/q.wad", true),
                s("/wads/q.wad", true),
                s("/ext/q.wad", false),
                s("q.wad", true),
            ]
        );
        assert_eq!(
            paths("C:/quake/x.wad"),
            [
                s("/wads/x.wad", true),
                s("/ext/x.wad", false),
                s("x.wad", true)
            ]
        );
        assert_eq!(paths("plain.wad").len(), 3);
    }

    fn wad_set(textures: &[(&str, u32)]) -> WadSet {
        let lumps = textures
            .iter()
            .map(|&(name, size)| WadLump::miptex(placeholder(name, (size, size))))
            .collect();
        WadSet {
            wads: vec![FoundWad {
                path: PathBuf::from("test.wad"),
                wad: Wad::new(lumps),
                embed: true,
            }],
            missing: MissingTextures::default(),
        }
    }

    /// The lump for a map whose faces show `shown` and name `unshown` too (after them).
    fn lump_of(
        set: &WadSet,
        shown: &[&str],
        unshown: &[&str],
        warnings: &mut Vec<Warning>,
    ) -> Vec<Option<MipTex>> {
        let mut list = TextureList::of_map(shown.iter().chain(unshown).copied());
        let mut is_shown = vec![false; list.len()];
        for name in shown {
            is_shown[list.slot(name) as usize] = true;
        }
        set.texture_lump(&list, &is_shown, warnings)
    }

    /// Each slot's name and width, `None` for an absent miptex.
    fn names_and_sizes(lump: &[Option<MipTex>]) -> Vec<Option<(String, u32)>> {
        lump.iter()
            .map(|t| t.as_ref().map(|t| (t.name(), t.width)))
            .collect()
    }

    fn entry(name: &str, size: u32) -> Option<(String, u32)> {
        Some((name.to_string(), size))
    }

    #[test]
    fn skip_comes_first_then_the_maps_textures_in_its_order() {
        let list = TextureList::of_map(["wall", "*water1", "Wall", "clip", "SKIP", "floor"]);
        assert_eq!(list.names, ["skip", "wall", "*water1", "clip", "floor"]);
        let mut list = TextureList::of_map(["+3button", "+1BUTTON", "+bdoor", "x"]);
        assert_eq!(
            list.names,
            [
                "skip", "+3button", "+0button", "+1button", "+2button", "+bdoor", "+adoor", "x"
            ]
        );
        assert_eq!(list.slot("+2BUTTON"), 4);
        assert_eq!(list.slot("new"), 8);
    }

    #[test]
    fn missing_wad_and_texture_give_placeholders() {
        let mut warnings = Vec::new();
        let mut world = Entity::default();
        world.set("wad", "nope.wad");
        let search = WadSearch {
            folders: vec![(PathBuf::from("/nonexistent"), true)],
            beside_map: PathBuf::from("/nonexistent/m.wad"),
        };
        let set = WadSet::load(&world, &search, &mut warnings);
        let lump = lump_of(&set, &["SKY4"], &["clip"], &mut warnings);
        // skip and clip, which no face shows, are absent, as ericw-tools leaves every texture
        // it cannot find.
        assert!(lump[0].is_none() && lump[2].is_none());
        let t = lump[1].as_ref().expect("a placeholder");
        assert_eq!((t.width, t.height), (256, 128));
        // Lowercase: DarkPlaces crashes on a sky texture named SKY4.
        assert_eq!(t.name(), "sky4");
        let mips = t.mips.as_ref().expect("pixels");
        assert_eq!(mips[3].len(), 32 * 16);
        // The missing WAD and the shown texture.
        assert_eq!(warnings.len(), 2);
    }

    #[test]
    fn textures_no_face_shows_are_written_when_a_wad_holds_them() {
        let set = wad_set(&[("skip", 64), ("clip", 32), ("wall", 128)]);
        let mut warnings = Vec::new();
        let lump = lump_of(&set, &["wall"], &["clip", "trigger"], &mut warnings);
        assert_eq!(
            names_and_sizes(&lump),
            [
                entry("skip", 64),
                entry("wall", 128),
                entry("clip", 32),
                None
            ]
        );
        assert_eq!(warnings, vec![]);
        let zero = set.with_missing(MissingTextures {
            zero_size: true,
            ..MissingTextures::default()
        });
        let lump = lump_of(&zero, &["wall"], &["trigger"], &mut warnings);
        assert_eq!(names_and_sizes(&lump)[2], entry("trigger", 0));
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
            ("skip", 64),
        ]);
        let mut warnings = Vec::new();
        let lump = lump_of(&set, &["wall", "+3BUTTON"], &[], &mut warnings);
        assert_eq!(warnings, vec![]);
        // The frames below a used one follow it; the WADs' other frames come last.
        assert_eq!(
            names_and_sizes(&lump),
            [
                entry("skip", 64),
                entry("wall", 128),
                entry("+3button", 32),
                entry("+0button", 32),
                entry("+1button", 32),
                entry("+2button", 32),
                entry("+abutton", 32),
            ]
        );
    }

    #[test]
    fn wad_frames_stop_at_a_gap_above_the_used_ones() {
        let set = wad_set(&[("+0x", 32), ("+1x", 32), ("+3x", 32), ("+bx", 32)]);
        let mut warnings = Vec::new();
        let lump = lump_of(&set, &["+0x"], &[], &mut warnings);
        assert_eq!(warnings, vec![]);
        // No +ax, so the alternates +bx alone would be a broken cycle.
        assert_eq!(
            names_and_sizes(&lump),
            [None, entry("+0x", 32), entry("+1x", 32)]
        );
    }

    #[test]
    fn gaps_below_a_used_frame_get_placeholders_of_the_animation_size() {
        let set = wad_set(&[("+0x", 32), ("+2x", 32)]);
        let mut warnings = Vec::new();
        let lump = lump_of(&set, &["+3x"], &[], &mut warnings);
        assert_eq!(
            names_and_sizes(&lump),
            [
                None,
                entry("+3x", 32),
                entry("+0x", 32),
                entry("+1x", 32),
                entry("+2x", 32)
            ]
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
    fn a_frame_below_one_a_wad_holds_is_needed_even_where_no_face_shows_it() {
        // Engines would refuse +1x (held, though only named on a buried face) without +0x.
        let set = wad_set(&[("+1x", 32)]);
        let mut warnings = Vec::new();
        let lump = lump_of(&set, &[], &["+1x", "+1y"], &mut warnings);
        assert_eq!(
            names_and_sizes(&lump),
            [None, entry("+1x", 32), entry("+0x", 32), None, None]
        );
        assert_eq!(
            warnings,
            vec![Warning::MissingAnimationFrame {
                name: "+0x".to_string()
            }]
        );
    }

    #[test]
    fn a_missing_animation_gets_complete_placeholder_cycles() {
        // QuakeSpasm stopped with "Missing frame 0 of +3BUTNN" on an id map without its WAD.
        let set = WadSet::default();
        let mut warnings = Vec::new();
        let lump = lump_of(&set, &["+3BUTNN", "+bButnn", "+0LIFT"], &[], &mut warnings);
        let lump: Vec<MipTex> = lump.into_iter().flatten().collect();
        assert_eq!(
            lump.iter().map(MipTex::name).collect::<Vec<_>>(),
            [
                "+3butnn", "+0butnn", "+1butnn", "+2butnn", "+bbutnn", "+abutnn", "+0lift"
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
        let set = wad_set(&[("+xbutton", 16)]);
        let lump = lump_of(&set, &["+xbutton"], &["+ybutton"], &mut warnings);
        assert_eq!(lump.len(), 3);
        // +ybutton is in no WAD and no face shows it: absent, so harmless.
        assert_eq!(
            warnings,
            vec![Warning::BadAnimationName {
                name: "+xbutton".to_string()
            }]
        );
    }
}
