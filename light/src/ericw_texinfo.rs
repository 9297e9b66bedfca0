//! ericw-tools' `MAPNAME.texinfo.json`: what ericw-tools' qbsp records beside a BSP of the keys of
//! the entities it merges into the world (`func_detail*`, `func_group`) and of brush entities, per
//! texinfo (`_shadow -1`, `_dirt -1`, `_bounce -1`, `_lightignore`, `_minlight`, `_phong`,
//! `_surflight_group`...), which its light reads. When a BSP from ericw-tools' qbsp is lit by
//! Slipgate, the command line reads that file and hands its keys to light as the lumps Slipgate's
//! own compiler writes ([`quake_formats::bsp::face_flags`] and its neighbours), per face.
//!
//! The file is one JSON object: texinfo number (as a string) to an object of the flags that are
//! set, such as `"no_shadow": true`, `"minlight": 100.0`, `"minlight_color": [255, 0, 0]`,
//! `"phong_angle": 89.0`, `"phong_group": 2`, `"surflight_group": 3`, `"object_channel_mask": 2`,
//! `"maxlight": 40.0`, `"lightcolorscale": 0.0`.

use std::collections::HashMap;

use quake_formats::Bsp;
use quake_formats::bsp::face_channels::DEFAULT_CHANNELS;
use quake_formats::bsp::face_flags::FaceFlags;
use quake_formats::bsp::face_minlight::FaceMinlight;
use quake_formats::bsp::face_tone::FaceTone;
use quake_formats::bsp::phong::FacePhong;
use serde_json::Value;

/// The keys one texinfo carries.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct TexinfoKeys {
    flags: FaceFlags,
    minlight: FaceMinlight,
    phong_angle: f32,
    phong_angle_concave: f32,
    phong_group: i64,
    surflight_group: i32,
    /// Its light channels (`_object_channel_mask`; `None`: the world's).
    channels: Option<u32>,
    /// Its `_maxlight` and `_lightcolorscale`.
    tone: FaceTone,
}

impl TexinfoKeys {
    fn from_json(entry: &Value) -> TexinfoKeys {
        let flag = |name: &str| entry.get(name).and_then(Value::as_bool).unwrap_or(false);
        let number = |name: &str| entry.get(name).and_then(Value::as_f64);
        let whole = |name: &str| entry.get(name).and_then(Value::as_i64).unwrap_or(0);
        let minlight = match number("minlight").filter(|&m| m != 0.0) {
            Some(level) => {
                let bytes = entry
                    .get("minlight_color")
                    .and_then(Value::as_array)
                    .map(|c| c.iter().filter_map(Value::as_f64).collect::<Vec<_>>());
                let color = match bytes.as_deref() {
                    // ericw-tools writes no colour (or black) for a white minlight.
                    Some(&[r, g, b]) if r + g + b > 0.0 => [r, g, b].map(|c| (c / 255.0) as f32),
                    _ => [1.0; 3],
                };
                FaceMinlight {
                    level: level as f32,
                    color,
                }
            }
            None => FaceMinlight::default(),
        };
        TexinfoKeys {
            flags: FaceFlags {
                no_shadow: flag("no_shadow"),
                no_dirt: flag("no_dirt"),
                no_bounce: flag("no_bounce"),
                light_ignore: flag("light_ignore"),
                no_minlight: flag("no_minlight"),
                no_ambient: false,
            },
            minlight,
            phong_angle: number("phong_angle").unwrap_or(0.0) as f32,
            phong_angle_concave: quake_formats::bsp::phong::concave_from_key(number(
                "phong_angle_concave",
            )),
            phong_group: whole("phong_group"),
            surflight_group: i32::try_from(whole("surflight_group")).unwrap_or(0),
            channels: u32::try_from(whole("object_channel_mask"))
                .ok()
                .filter(|&m| m != 0),
            tone: FaceTone::from_keys(number("maxlight"), number("lightcolorscale")),
        }
    }
}

/// Names of the lumps [`add_face_keys`] added to a BSP.
pub type AddedLumps = Vec<&'static str>;

/// Adds to `bsp`, which has none of Slipgate's per-face key lumps ([`has_face_key_lumps`]), those
/// lumps made from `json` (the text of ericw-tools' `MAPNAME.texinfo.json`): the names of the
/// lumps added (none when no texinfo carries a key light reads), to be taken out again before the
/// BSP is written.
///
/// # Errors
/// Text that is not JSON, or not an object.
pub fn add_face_keys(bsp: &mut Bsp, json: &str) -> Result<AddedLumps, String> {
    let value: Value = serde_json::from_str(json).map_err(|e| e.to_string())?;
    let Value::Object(entries) = value else {
        return Err("expected an object of texinfo numbers".to_string());
    };
    let by_texinfo: HashMap<usize, TexinfoKeys> = entries
        .iter()
        .filter_map(|(k, v)| Some((k.parse().ok()?, TexinfoKeys::from_json(v))))
        .collect();
    let keys: Vec<TexinfoKeys> = bsp
        .faces
        .iter()
        .map(|f| {
            by_texinfo
                .get(&(f.texinfo as usize))
                .copied()
                .unwrap_or_default()
        })
        .collect();
    // Faces with the same phong group number and angles smooth together.
    let mut phong_ids: HashMap<(i64, u32, u32), u32> = HashMap::new();
    let phong: Vec<FacePhong> = keys
        .iter()
        .map(|k| {
            if k.phong_angle <= 0.0 {
                return FacePhong::default();
            }
            let next = phong_ids.len() as u32 + 1;
            let key = (
                k.phong_group,
                k.phong_angle.to_bits(),
                k.phong_angle_concave.to_bits(),
            );
            let group = *phong_ids.entry(key).or_insert(next);
            FacePhong {
                group,
                angle: k.phong_angle.min(180.0),
                concave: k.phong_angle_concave,
            }
        })
        .collect();
    let flags: Vec<FaceFlags> = keys.iter().map(|k| k.flags).collect();
    bsp.set_face_flags(&flags);
    let minlights: Vec<FaceMinlight> = keys.iter().map(|k| k.minlight).collect();
    bsp.set_face_minlights(&minlights);
    bsp.set_phong_faces(&phong);
    let groups: Vec<i32> = keys.iter().map(|k| k.surflight_group).collect();
    bsp.set_surflight_groups(&groups);
    let channels: Vec<u32> = keys
        .iter()
        .map(|k| k.channels.unwrap_or(DEFAULT_CHANNELS))
        .collect();
    bsp.set_face_channels(&channels);
    let tones: Vec<FaceTone> = keys.iter().map(|k| k.tone).collect();
    bsp.set_face_tones(&tones);
    // Each is left out when no face has a key of its kind.
    Ok(FACE_KEY_LUMPS
        .into_iter()
        .filter(|name| bsp.bspx_lump(name).is_some())
        .collect())
}

/// The per-face key lumps Slipgate's compiler writes.
const FACE_KEY_LUMPS: [&str; 7] = [
    quake_formats::bsp::face_flags::LUMP_NAME,
    quake_formats::bsp::face_minlight::LUMP_NAME,
    quake_formats::bsp::phong::LUMP_NAME,
    quake_formats::bsp::phong::CONCAVE_LUMP_NAME,
    quake_formats::bsp::surflight_group::LUMP_NAME,
    quake_formats::bsp::face_channels::LUMP_NAME,
    quake_formats::bsp::face_tone::LUMP_NAME,
];

/// Whether `bsp` carries any of the per-face key lumps Slipgate's compiler writes (then it was
/// compiled by Slipgate, and ericw-tools' file beside it, if any, is stale).
pub fn has_face_key_lumps(bsp: &Bsp) -> bool {
    FACE_KEY_LUMPS
        .iter()
        .any(|name| bsp.bspx_lump(name).is_some())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A BSP of `n` faces, face `i` on texinfo `i`.
    fn bsp_with_faces(n: usize) -> Bsp {
        let face = quake_formats::bsp::Face {
            plane: 0,
            side: 0,
            first_edge: 0,
            num_edges: 0,
            texinfo: 0,
            styles: [255; 4],
            light_offset: -1,
        };
        let mut bsp = Bsp::default();
        bsp.faces = (0..n as u32)
            .map(|texinfo| quake_formats::bsp::Face { texinfo, ..face })
            .collect();
        bsp
    }

    #[test]
    fn texinfo_keys_become_per_face_lumps_and_are_named_for_removal() {
        let mut bsp = bsp_with_faces(3);
        let json = r#"{
            "0": {},
            "1": {"light_ignore": true, "minlight": 100.0, "no_shadow": true,
                  "object_channel_mask": 8},
            "2": {"minlight": 20.0, "minlight_color": [255, 0, 0], "phong_angle": 89.0,
                  "surflight_group": 4, "is_special": true, "maxlight": 40.0,
                  "lightcolorscale": 0.0}
        }"#;
        let added = add_face_keys(&mut bsp, json).expect("read");
        assert_eq!(added.len(), 6, "{added:?}");
        let flags = bsp.face_flags().expect("lump").expect("flags");
        assert_eq!(flags[0], FaceFlags::default());
        assert!(flags[1].light_ignore && flags[1].no_shadow && !flags[1].no_dirt);
        let minlights = bsp.face_minlights().expect("lump").expect("minlights");
        assert_eq!(minlights[1].level, 100.0);
        assert_eq!(minlights[1].color, [1.0; 3]);
        assert_eq!(minlights[2].color, [1.0, 0.0, 0.0]);
        let phong = bsp.phong_faces().expect("lump").expect("phong");
        assert_eq!((phong[2].group, phong[2].angle), (1, 89.0));
        assert_eq!(phong[0].group, 0);
        assert_eq!(bsp.surflight_groups().expect("lump"), Some(vec![0, 0, 4]));
        assert_eq!(bsp.face_channels().expect("lump"), Some(vec![1, 8, 1]));
        let tones = bsp.face_tones().expect("lump").expect("tones");
        assert_eq!(tones[0], FaceTone::default());
        assert_eq!(
            (tones[2].maxlight(), tones[2].color_scale()),
            (Some(40.0), Some(0.0))
        );
        assert!(has_face_key_lumps(&bsp));
        for name in added {
            bsp.remove_bspx_lump(name);
        }
        assert!(!has_face_key_lumps(&bsp));

        let mut plain = bsp_with_faces(2);
        assert_eq!(
            add_face_keys(&mut plain, r#"{"0": {"is_special": true}}"#),
            Ok(vec![])
        );
        assert!(add_face_keys(&mut plain, "[1, 2]").is_err());
        assert!(add_face_keys(&mut plain, "not json").is_err());
    }
}
