//! The texture lump as engines load it: sizes, animation sequences, the texinfo that name them.

use super::{Checker, Rule};
use crate::bsp::limits::{MAX_ANIMATION_FRAMES, SKY_TEXTURE_SIZE};
use std::collections::{BTreeMap, BTreeSet};

pub(super) fn check(c: &mut Checker) {
    check_names_and_sizes(c);
    check_animations(c);
    check_texinfo_textures(c);
}

fn check_names_and_sizes(c: &mut Checker) {
    let bsp = c.bsp;
    for (i, t) in bsp.textures.textures.iter().enumerate() {
        let Some(t) = t else { continue };
        let name = t.name();
        if t.width % 16 != 0 || t.height % 16 != 0 {
            let detail = format!("{name} is {}x{}, not a multiple of 16", t.width, t.height);
            c.report(Rule::TextureAlignment, "textures", i, detail);
        }
        let prefix = name.get(..3).unwrap_or_default();
        let is_sky = prefix.eq_ignore_ascii_case("sky");
        if is_sky && prefix != "sky" {
            let detail = format!("{name} is a sky texture not named in lower case");
            c.report(Rule::SkyNameCase, "textures", i, detail);
        }
        if is_sky && [t.width, t.height] != SKY_TEXTURE_SIZE {
            let [w, h] = SKY_TEXTURE_SIZE;
            let detail = format!("{name} is {}x{}, not {w}x{h}", t.width, t.height);
            c.report(Rule::SkyTextureSize, "textures", i, detail);
        }
    }
}

/// A `+` texture's frame: `+0`..`+9` are the primary sequence, `+a`..`+j` (either case) the
/// alternate one, as the engines fold the character to upper case before reading it.
enum Frame {
    Primary(usize),
    Alternate(usize),
}

fn frame(c: Option<char>) -> Option<Frame> {
    let c = c?.to_ascii_uppercase();
    match c {
        '0'..='9' => Some(Frame::Primary(c as usize - '0' as usize)),
        'A'..='J' => Some(Frame::Alternate(c as usize - 'A' as usize)),
        _ => None,
    }
}

/// The textures of one animated sequence: all `+` names with the same text after the frame.
#[derive(Default)]
struct Sequence {
    /// The first texture in the lump (engines name the sequence after it).
    first: Option<(usize, String)>,
    primary: [bool; MAX_ANIMATION_FRAMES],
    alternate: [bool; MAX_ANIMATION_FRAMES],
}

fn check_animations(c: &mut Checker) {
    let bsp = c.bsp;
    let mut sequences: BTreeMap<String, Sequence> = BTreeMap::new();
    for (i, t) in bsp.textures.textures.iter().enumerate() {
        let Some(t) = t else { continue };
        let name = t.name();
        let mut chars = name.chars();
        if chars.next() != Some('+') {
            continue;
        }
        let frame_char = chars.next();
        let Some(frame) = frame(frame_char) else {
            let detail = format!("{name}: its frame is not 0-9 or a-j");
            c.report(Rule::AnimationName, "textures", i, detail);
            continue;
        };
        let sequence = sequences.entry(chars.collect()).or_default();
        sequence.first.get_or_insert((i, name.clone()));
        match frame {
            Frame::Primary(n) => sequence.primary[n] = true,
            Frame::Alternate(n) => sequence.alternate[n] = true,
        }
    }
    for sequence in sequences.values() {
        let Some((index, name)) = &sequence.first else {
            continue;
        };
        for (frames, which) in [
            (&sequence.primary, ""),
            (&sequence.alternate, " (alternate)"),
        ] {
            let count = frames.iter().rposition(|&f| f).map_or(0, |last| last + 1);
            for missing in (0..count).filter(|&n| !frames[n]) {
                let detail = format!("Missing frame {missing} of {name}{which}");
                c.report(Rule::AnimationFrames, "textures", *index, detail);
            }
        }
    }
}

/// Each texture a texinfo names must exist: vanilla engines refuse an index past the lump when
/// they load any texinfo, and every engine draws a face whose texture is missing as a
/// checkerboard. Reported once per texture index.
fn check_texinfo_textures(c: &mut Checker) {
    let bsp = c.bsp;
    let textures = &bsp.textures.textures;
    let drawn: BTreeSet<u32> = bsp.faces.iter().map(|f| f.texinfo).collect();
    let mut seen = BTreeSet::new();
    for (i, t) in bsp.texinfo.iter().enumerate() {
        let miptex = t.miptex as usize;
        if (t.miptex as i32) < 0 {
            continue; // `structure` reports negative indices
        }
        if !textures.is_empty() && miptex >= textures.len() {
            if seen.insert(miptex) {
                let detail = format!("miptex {miptex} is past the {} textures", textures.len());
                c.report(Rule::TexinfoMiptex, "texinfo", i, detail);
            }
        } else if drawn.contains(&(i as u32))
            && textures.get(miptex).is_none_or(Option::is_none)
            && seen.insert(miptex)
        {
            let detail = format!("texture {miptex} is not stored in the file");
            c.report(Rule::TextureMissing, "texinfo", i, detail);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_fold_case_and_stop_at_j() {
        assert!(matches!(frame(Some('7')), Some(Frame::Primary(7))));
        assert!(matches!(frame(Some('b')), Some(Frame::Alternate(1))));
        assert!(matches!(frame(Some('J')), Some(Frame::Alternate(9))));
        assert!(frame(Some('k')).is_none());
        assert!(frame(None).is_none());
    }
}
