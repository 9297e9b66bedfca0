//! Extended content flags: what each BSP leaf holds, in more words than the one contents value
//! engines read. ericw-tools' qbsp writes them beside the BSP as `MAPNAME.content.json` (its
//! light and test suite read them back); Slipgate writes the same file.
//!
//! The file is a JSON array with one entry per BSP leaf, in leaf order (leaf 0, the shared solid
//! leaf, first): the names of the leaf's flags, in ericw-tools' bit order, e.g. `["SOLID"]`,
//! `[]` for an empty leaf, `["WATER","TRANSLUCENT","DETAIL"]` for water (liquids are detail and
//! translucent unless `-notranswater`), `["WINDOW","MIRROR_INSIDE_SET","TRANSLUCENT","DETAIL"]`
//! for a leaf inside a `func_detail_fence` (solid in the BSP).

use crate::brush::Brush;
use crate::tree::{
    DETAIL_WALL, FENCE, ILLUSIONARY, ILLUSIONARY_IN_LAVA, ILLUSIONARY_IN_SLIME,
    ILLUSIONARY_IN_WATER, VISBLOCKER,
};
use quake_formats::bsp::contents;

/// The flags of one leaf, as a set of ericw-tools' content bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ContentFlags(u64);

impl ContentFlags {
    /// Solid: leaf 0, and every leaf of a solid brush.
    pub const SOLID: ContentFlags = ContentFlags(1 << 0);
    /// Sky.
    pub const SKY: ContentFlags = ContentFlags(1 << 1);
    /// Inside a `func_detail_wall` (solid in the BSP).
    pub const DETAIL_WALL: ContentFlags = ContentFlags(1 << 2);
    /// Inside a `func_detail_fence` (solid in the BSP, with faces seen through it).
    pub const WINDOW: ContentFlags = ContentFlags(1 << 3);
    /// Inside a `func_illusionary_visblocker` (empty in the BSP).
    pub const ILLUSIONARY_VISBLOCKER: ContentFlags = ContentFlags(1 << 4);
    /// Lava.
    pub const LAVA: ContentFlags = ContentFlags(1 << 6);
    /// Slime.
    pub const SLIME: ContentFlags = ContentFlags(1 << 7);
    /// Water.
    pub const WATER: ContentFlags = ContentFlags(1 << 8);
    /// Inside a `func_detail_illusionary` (empty, or the liquid around it, in the BSP).
    pub const MIST: ContentFlags = ContentFlags(1 << 9);
    /// The brush's faces are drawn from inside too (`_mirrorinside 1`).
    pub const MIRROR_INSIDE: ContentFlags = ContentFlags(1 << 16);
    /// Whether faces are drawn from inside was decided (by `_mirrorinside`, or by the kind of
    /// brush).
    pub const MIRROR_INSIDE_SET: ContentFlags = ContentFlags(1 << 17);
    /// Seen through.
    pub const TRANSLUCENT: ContentFlags = ContentFlags(1 << 25);
    /// Detail: not a vis cluster of its own.
    pub const DETAIL: ContentFlags = ContentFlags(1 << 29);

    /// The flags Slipgate writes, with ericw-tools' names, in its bit order.
    const NAMED: [(ContentFlags, &'static str); 13] = [
        (Self::SOLID, "SOLID"),
        (Self::SKY, "SKY"),
        (Self::DETAIL_WALL, "DETAIL_WALL"),
        (Self::WINDOW, "WINDOW"),
        (Self::ILLUSIONARY_VISBLOCKER, "ILLUSIONARY_VISBLOCKER"),
        (Self::LAVA, "LAVA"),
        (Self::SLIME, "SLIME"),
        (Self::WATER, "WATER"),
        (Self::MIST, "MIST"),
        (Self::MIRROR_INSIDE, "MIRROR_INSIDE"),
        (Self::MIRROR_INSIDE_SET, "MIRROR_INSIDE_SET"),
        (Self::TRANSLUCENT, "TRANSLUCENT"),
        (Self::DETAIL, "DETAIL"),
    ];

    /// No flags: an empty leaf.
    pub const EMPTY: ContentFlags = ContentFlags(0);

    /// Whether every flag of `other` is set.
    pub fn contains(self, other: ContentFlags) -> bool {
        self.0 & other.0 == other.0
    }

    /// The names of the set flags, in ericw-tools' bit order.
    pub fn names(self) -> Vec<&'static str> {
        Self::NAMED
            .iter()
            .filter(|(f, _)| self.contains(*f))
            .map(|&(_, name)| name)
            .collect()
    }

    /// The flags of a leaf of compiler contents `leaf_contents` filled by `brushes`, as
    /// ericw-tools gives them: liquids are detail and translucent when vis sees through them
    /// (`transwater`); fences and illusionary brushes are detail and translucent, and say
    /// whether their faces are drawn from inside (`_mirrorinside`, off unless set); a liquid
    /// brush says so only when its entity sets `_mirrorinside`.
    pub(crate) fn of_leaf(leaf_contents: i32, brushes: &[Brush], transwater: bool) -> ContentFlags {
        let liquid = |c: i32| {
            let flags = match c {
                contents::WATER => Self::WATER,
                contents::SLIME => Self::SLIME,
                _ => Self::LAVA,
            };
            if transwater {
                flags | Self::TRANSLUCENT | Self::DETAIL
            } else {
                flags
            }
        };
        // The mirror flags of the leaf's first brush of contents `c`.
        let mirror = |c: i32, default_set: bool| match brushes
            .iter()
            .find(|b| b.contents == c)
            .map(|b| b.mirror_inside)
        {
            Some(Some(true)) => Self::MIRROR_INSIDE | Self::MIRROR_INSIDE_SET,
            Some(Some(false)) => Self::MIRROR_INSIDE_SET,
            _ if default_set => Self::MIRROR_INSIDE_SET,
            _ => Self::EMPTY,
        };
        let see_through = Self::TRANSLUCENT | Self::DETAIL;
        let illusionary = Self::MIST | see_through | mirror(ILLUSIONARY, true);
        match leaf_contents {
            contents::SOLID => Self::SOLID,
            contents::SKY => Self::SKY,
            c @ (contents::WATER | contents::SLIME | contents::LAVA) => {
                liquid(c) | mirror(c, false)
            }
            FENCE => Self::WINDOW | see_through | mirror(FENCE, true),
            DETAIL_WALL => Self::DETAIL_WALL | Self::DETAIL,
            ILLUSIONARY => illusionary,
            ILLUSIONARY_IN_WATER => liquid(contents::WATER) | illusionary,
            ILLUSIONARY_IN_SLIME => liquid(contents::SLIME) | illusionary,
            ILLUSIONARY_IN_LAVA => liquid(contents::LAVA) | illusionary,
            VISBLOCKER => Self::ILLUSIONARY_VISBLOCKER,
            _ => Self::EMPTY,
        }
    }
}

impl std::ops::BitOr for ContentFlags {
    type Output = ContentFlags;
    fn bitor(self, rhs: ContentFlags) -> ContentFlags {
        ContentFlags(self.0 | rhs.0)
    }
}

/// The `.content.json` text for leaves of these flags: a tab-indented array of arrays of names,
/// laid out as ericw-tools writes it (no newline at the end). The names need no escaping.
pub fn content_json(leaves: &[ContentFlags]) -> String {
    let entries: Vec<String> = leaves
        .iter()
        .map(|f| match f.names().as_slice() {
            [] => "\t[]".to_string(),
            names => {
                let quoted: Vec<String> = names.iter().map(|n| format!("\t\t\"{n}\"")).collect();
                format!("\t[\n{}\n\t]", quoted.join(",\n"))
            }
        })
        .collect();
    if entries.is_empty() {
        return "[]".to_string();
    }
    format!("[\n{}\n]", entries.join(",\n"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_ericw_bit_order() {
        let fence = ContentFlags::of_leaf(FENCE, &[], true);
        assert_eq!(
            fence.names(),
            ["WINDOW", "MIRROR_INSIDE_SET", "TRANSLUCENT", "DETAIL"]
        );
        let slime = ContentFlags::of_leaf(contents::SLIME, &[], true);
        assert_eq!(slime.names(), ["SLIME", "TRANSLUCENT", "DETAIL"]);
        let mist_in_water = ContentFlags::of_leaf(ILLUSIONARY_IN_WATER, &[], true);
        assert_eq!(
            mist_in_water.names(),
            [
                "WATER",
                "MIST",
                "MIRROR_INSIDE_SET",
                "TRANSLUCENT",
                "DETAIL"
            ]
        );
    }

    #[test]
    fn opaque_water_is_neither_detail_nor_translucent() {
        let water = ContentFlags::of_leaf(contents::WATER, &[], false);
        assert_eq!(water.names(), ["WATER"]);
    }

    #[test]
    fn empty_sky_and_solid() {
        assert!(
            ContentFlags::of_leaf(contents::EMPTY, &[], true)
                .names()
                .is_empty()
        );
        assert_eq!(
            ContentFlags::of_leaf(contents::SKY, &[], true).names(),
            ["SKY"]
        );
        assert_eq!(
            ContentFlags::of_leaf(contents::SOLID, &[], true).names(),
            ["SOLID"]
        );
    }

    #[test]
    fn json_is_laid_out_as_ericw_writes_it() {
        let leaves = [
            ContentFlags::SOLID,
            ContentFlags::EMPTY,
            ContentFlags::of_leaf(contents::WATER, &[], true),
        ];
        assert_eq!(
            content_json(&leaves),
            "[\n\t[\n\t\t\"SOLID\"\n\t],\n\t[],\n\t[\n\t\t\"WATER\",\n\t\t\"TRANSLUCENT\",\n\t\t\"DETAIL\"\n\t]\n]"
        );
    }
}
