//! From light units to the bytes engines read: range scale, gamma, clamping, and the lighting
//! lump with each face's `styles` and `light_offset`; beside it, as a run asks
//! ([`Outputs`]), the `.lit` colour data, the `RGBLIGHTING`, `LIGHTINGDIR` and `LIGHTING_E5BGR9`
//! lumps and the `.lux` and HDR `.lit` files.

use quake_formats::Bsp;
use quake_formats::bsp::light_lumps::{
    DECOUPLED_LM, DecoupledLightmap, LIGHTING_E5BGR9, LIGHTINGDIR, LMOFFSET, LMSHIFT, RGBLIGHTING,
};
use quake_formats::bsp::limits::MAX_LIGHTMAPS;
use quake_formats::lit::{grey_level, pack_e5bgr9};

use crate::faces::OwnGrid;
use crate::settings::Settings;
use crate::trace::FaceLight;

/// Lightmap bytes that stand for light 1.0 (the texture's own colour) in HDR lightmaps: engines
/// scale lightmap bytes by 2/255, so 255 is twice the texture's colour ("overbright").
const HDR_ONE: f64 = 128.0;
/// The direction byte of a luxel no light with a direction reached: straight off the face.
const NO_DIRECTION: [u8; 3] = [128, 128, 255];

/// The forms of the lightmaps a run writes, beside the grey lump.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outputs {
    /// The grey lighting lump (false: `--novanilla`).
    pub grey_lump: bool,
    /// `RGBLIGHTING` (`--bspxlit`, or `--novanilla`).
    pub rgb_lump: bool,
    /// A `.lux` file (`--lux`).
    pub lux_file: bool,
    /// `LIGHTINGDIR` (`--bspxlux`).
    pub direction_lump: bool,
    /// The `.lit` in HDR form (`--hdr`).
    pub hdr_file: bool,
    /// `LIGHTING_E5BGR9` (`--bspxhdr`).
    pub hdr_lump: bool,
}

impl Default for Outputs {
    /// The grey lump alone (and a `.lit` when the light is coloured), as Quake's own tool.
    fn default() -> Self {
        Outputs {
            grey_lump: true,
            rgb_lump: false,
            lux_file: false,
            direction_lump: false,
            hdr_file: false,
            hdr_lump: false,
        }
    }
}

impl Outputs {
    /// The outputs `settings` ask for.
    pub fn from_settings(settings: &Settings) -> Outputs {
        Outputs {
            grey_lump: !settings.novanilla,
            rgb_lump: settings.bspxlit || settings.novanilla,
            lux_file: settings.lux,
            direction_lump: settings.bspxlux,
            hdr_file: settings.hdr,
            hdr_lump: settings.bspxhdr,
        }
    }

    /// Deluxemaps are wanted.
    pub fn directions(&self) -> bool {
        self.lux_file || self.direction_lump
    }

    /// HDR lightmaps are wanted.
    pub fn hdr(&self) -> bool {
        self.hdr_file || self.hdr_lump
    }
}

/// Style slot value for "unused".
const NO_STYLE: u8 = 255;

/// A face's final lightmaps: up to four styles, grey bytes and RGB bytes.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceLightmap {
    /// The face's index.
    pub face: usize,
    /// Luxels across (s).
    pub width: usize,
    /// Luxels down (t).
    pub height: usize,
    /// Style of each lightmap, brightest first; empty when no light reaches the face.
    pub styles: Vec<u8>,
    /// One byte per luxel per style: the brightest of the RGB channels.
    pub grey: Vec<Vec<u8>>,
    /// The channels themselves, per style, when the light is coloured or RGB output is asked
    /// for (else empty).
    pub rgb: Vec<Vec<[u8; 3]>>,
    /// Per style, each luxel's light as an E5BGR9 word, when HDR output is asked for (else
    /// empty).
    pub hdr: Vec<Vec<u32>>,
    /// Per style, each luxel's direction bytes, when deluxemaps are asked for (else empty).
    pub directions: Vec<Vec<[u8; 3]>>,
    /// The face's lightmaps on its own grid (`--world_units_per_luxel`, `_lmscale`), the same
    /// styles in the same order; these ones are then read from that grid.
    pub own_grid: Option<Box<OwnGridLightmap>>,
}

/// A face's lightmaps on its own grid: what its `DECOUPLED_LM` record, or its `LMSHIFT` and
/// `LMOFFSET`, describe.
#[derive(Debug, Clone, PartialEq)]
pub struct OwnGridLightmap {
    /// The lightmaps (their `face` and `own_grid` are the owner's and `None`).
    pub lightmap: FaceLightmap,
    /// The grid.
    pub grid: OwnGrid,
}

impl FaceLightmap {
    /// The grey bytes of `style`, when the face has a lightmap of that style.
    pub fn style_grey(&self, style: u8) -> Option<&[u8]> {
        let slot = self.styles.iter().position(|&s| s == style)?;
        self.grey.get(slot).map(Vec::as_slice)
    }
}

/// How light units become bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Finish {
    pub rangescale: f64,
    pub gamma: f64,
    /// Keep each luxel's RGB bytes, not only their mean: the light is coloured (for a `.lit`)
    /// or RGB output is asked for.
    pub rgb: bool,
    /// Keep each luxel's light as an E5BGR9 word.
    pub hdr: bool,
    /// Keep each luxel's direction bytes.
    pub directions: bool,
}

/// Light units to lightmap levels before clamping: range scale, then gamma.
pub(crate) fn to_levels(c: [f32; 3], finish: &Finish) -> [f64; 3] {
    let v = c.map(|x| (f64::from(x) * finish.rangescale).max(0.0));
    if finish.gamma == 1.0 {
        return v;
    }
    v.map(|x| 255.0 * (x / 255.0).powf(1.0 / finish.gamma))
}

/// Lightmap levels with all channels scaled down together if the brightest exceeds 255.
fn clamped(v: [f64; 3]) -> [f64; 3] {
    let max = v[0].max(v[1]).max(v[2]);
    if max > 255.0 {
        v.map(|x| x * 255.0 / max)
    } else {
        v
    }
}

/// Lightmap levels to bytes ([`clamped`], then rounded).
pub(crate) fn levels_to_bytes(v: [f64; 3]) -> [u8; 3] {
    clamped(v).map(to_byte)
}

/// A clamped level as its byte.
fn to_byte(x: f64) -> u8 {
    round_non_negative(x).clamp(0.0, 255.0) as u8
}

/// `x.round()` for `x` in 0..2^32 (NaN gives 0, as `round` then `as u8` do): `f64::round`
/// is a software routine on baseline x86-64, and this runs for every channel of every luxel.
/// `x - t` is exact there, so halves round up as `round` rounds them.
fn round_non_negative(x: f64) -> f64 {
    let t = f64::from(x as u32);
    if x - t >= 0.5 { t + 1.0 } else { t }
}

/// Light levels as an E5BGR9 word: [`HDR_ONE`] is 1.0, nothing is clamped.
fn levels_to_hdr(v: [f64; 3]) -> u32 {
    pack_e5bgr9(v.map(|x| (x / HDR_ONE) as f32))
}

/// A tangent-space unit direction as deluxemap bytes: each component `(c + 1) * 128`, clamped.
fn direction_bytes(d: [f32; 3]) -> [u8; 3] {
    if d == [0.0; 3] {
        return NO_DIRECTION;
    }
    d.map(|c| ((f64::from(c) + 1.0) * 128.0).clamp(0.0, 255.0) as u8)
}

/// One style's lightmap of a face: its style, grey and (when kept) RGB, HDR and direction
/// bytes, the sum of its channel bytes, and the brightness (mean channel level, before
/// rounding) of its brightest luxel.
struct StyleMap {
    style: u8,
    grey: Vec<u8>,
    rgb: Vec<[u8; 3]>,
    hdr: Vec<u32>,
    directions: Vec<[u8; 3]>,
    energy: u64,
    brightest: f64,
}

/// A style whose brightest luxel is dimmer than this many levels is not written, as
/// ericw-tools leaves it out: it would round to a lightmap of zeros and ones.
const DIMMEST_KEPT: f64 = 1.0;

/// Finishes one face. Returns the lightmap and how many styles were dropped
/// for exceeding four.
pub fn finish_face(light: &FaceLight, finish: &Finish) -> (FaceLightmap, usize) {
    let (maps, dropped) = keep_styles(style_maps(light, finish), finish);
    (lightmap_of(light, maps, finish), dropped)
}

/// Finishes a face lit on its own grid: `own` is its light there, `vanilla` the 16-texel light
/// read from it. The styles are chosen on its own grid (as ericw-tools chooses them) and both
/// lightmaps keep those, so one `styles` list describes both. Returns the 16-texel lightmap
/// carrying the other, and how many styles were dropped for exceeding four.
pub fn finish_face_on_own_grid(
    vanilla: &FaceLight,
    own: &FaceLight,
    grid: OwnGrid,
    finish: &Finish,
) -> (FaceLightmap, usize) {
    let (own_maps, dropped) = keep_styles(style_maps(own, finish), finish);
    let mut all = style_maps(vanilla, finish);
    let maps = own_maps
        .iter()
        .filter_map(|o| {
            let at = all.iter().position(|m| m.style == o.style)?;
            Some(all.swap_remove(at))
        })
        .collect();
    let mut lightmap = lightmap_of(vanilla, maps, finish);
    lightmap.own_grid = Some(Box::new(OwnGridLightmap {
        lightmap: lightmap_of(own, own_maps, finish),
        grid,
    }));
    (lightmap, dropped)
}

/// Each style of `light` as bytes, in its order.
fn style_maps(light: &FaceLight, finish: &Finish) -> Vec<StyleMap> {
    let mut maps: Vec<StyleMap> = Vec::with_capacity(light.styles.len());
    for (style, luxels) in &light.styles {
        // One pass, into buffers sized once: this runs for every luxel of the map.
        let kept = |on: bool| if on { luxels.len() } else { 0 };
        let mut map = StyleMap {
            style: *style,
            grey: Vec::with_capacity(luxels.len()),
            rgb: Vec::with_capacity(kept(finish.rgb)),
            hdr: Vec::with_capacity(kept(finish.hdr)),
            directions: Vec::new(),
            energy: 0,
            brightest: 0.0,
        };
        for &c in luxels {
            let levels = to_levels(c, finish);
            let shown = clamped(levels);
            map.brightest = map.brightest.max(shown.iter().sum::<f64>() / 3.0);
            let bytes = shown.map(to_byte);
            map.energy += bytes.iter().map(|&b| u64::from(b)).sum::<u64>();
            map.grey.push(grey_level(bytes));
            if finish.rgb {
                map.rgb.push(bytes);
            }
            if finish.hdr {
                map.hdr.push(levels_to_hdr(levels));
            }
        }
        if finish.directions {
            map.directions = match light.directions.iter().find(|(s, _)| s == style) {
                Some((_, d)) => d.iter().map(|&d| direction_bytes(d)).collect(),
                None => vec![NO_DIRECTION; luxels.len()],
            };
        }
        maps.push(map);
    }
    maps
}

/// The styles a face keeps of `maps`: those lit anywhere (a luxel [`DIMMEST_KEPT`] or
/// brighter, or with HDR output any light at all, which its words keep where the bytes are 0),
/// brightest first, four at most, as ericw-tools keeps them (a style dark all over is not
/// written, style 0 included: a face with none gets no lightmap, style 255 and no light
/// offset). Also says how many lit styles were dropped.
fn keep_styles(maps: Vec<StyleMap>, finish: &Finish) -> (Vec<StyleMap>, usize) {
    let lit = |m: &StyleMap| m.brightest >= DIMMEST_KEPT || (finish.hdr && m.brightest > 0.0);
    let mut maps: Vec<StyleMap> = maps.into_iter().filter(|m| lit(m)).collect();
    maps.sort_by_key(|m| std::cmp::Reverse(m.energy));
    let dropped = maps.len().saturating_sub(MAX_LIGHTMAPS);
    maps.truncate(MAX_LIGHTMAPS);
    (maps, dropped)
}

/// The lightmap of `light`'s face made of `maps`.
fn lightmap_of(light: &FaceLight, maps: Vec<StyleMap>, finish: &Finish) -> FaceLightmap {
    let mut lightmap = FaceLightmap {
        face: light.face,
        width: light.width,
        height: light.height,
        styles: Vec::with_capacity(maps.len()),
        grey: Vec::with_capacity(maps.len()),
        rgb: Vec::new(),
        hdr: Vec::new(),
        directions: Vec::new(),
        own_grid: None,
    };
    for map in maps {
        lightmap.styles.push(map.style);
        lightmap.grey.push(map.grey);
        if finish.rgb {
            lightmap.rgb.push(map.rgb);
        }
        if finish.hdr {
            lightmap.hdr.push(map.hdr);
        }
        if finish.directions {
            lightmap.directions.push(map.directions);
        }
    }
    lightmap
}

/// What [`write_lighting`] gives back for files beside the BSP.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LuxelData {
    /// Three bytes per luxel, when the maps kept RGB.
    pub rgb: Option<Vec<u8>>,
    /// One E5BGR9 word per luxel, when the maps kept HDR light.
    pub hdr: Option<Vec<u32>>,
    /// Three direction bytes per luxel, when the maps kept directions.
    pub directions: Option<Vec<u8>>,
}

/// Replaces the lighting data with `maps` (faces not listed, or without a style, get no
/// lightmap): the grey lump unless `outputs` leave it out (and with it the 16-texel lightmaps of
/// faces that have their own), the BSPX lumps `outputs` ask for, and `DECOUPLED_LM` or `LMSHIFT`
/// and `LMOFFSET` when faces have lightmaps on their own grids (those follow the 16-texel ones in
/// the same data); earlier lumps of those names are removed. Returns every luxel's RGB, HDR and
/// direction data the maps kept, for the files beside the BSP.
pub fn write_lighting(bsp: &mut Bsp, maps: &[FaceLightmap], outputs: &Outputs) -> LuxelData {
    // A face without a lit style gets no lightmap on either grid.
    let own_grids: Vec<(usize, &OwnGridLightmap)> = maps
        .iter()
        .filter(|m| !m.styles.is_empty())
        .filter_map(|m| Some((m.face, m.own_grid.as_deref()?)))
        .collect();
    let all = || {
        maps.iter()
            .chain(own_grids.iter().map(|(_, o)| &o.lightmap))
    };
    // Sized up front: growing them copied into fresh pages, which the kernel zeroes first.
    let luxels: usize = all().flat_map(|m| &m.grey).map(Vec::len).sum();
    let kept = |of: fn(&FaceLightmap) -> bool| maps.iter().any(|m| !m.styles.is_empty() && of(m));
    let mut data = LuxelWriter {
        grey: Vec::with_capacity(luxels),
        rgb: kept(|m| !m.rgb.is_empty()).then(|| Vec::with_capacity(3 * luxels)),
        hdr: kept(|m| !m.hdr.is_empty()).then(|| Vec::with_capacity(luxels)),
        dirs: kept(|m| !m.directions.is_empty()).then(|| Vec::with_capacity(3 * luxels)),
    };
    for f in &mut bsp.faces {
        f.styles = [NO_STYLE; 4];
        f.light_offset = -1;
    }
    for m in maps.iter().filter(|m| !m.styles.is_empty()) {
        let face = &mut bsp.faces[m.face];
        // Without the grey lump (`--novanilla`) a face lit on its own grid keeps only that
        // lightmap, as ericw-tools writes it: the 16-texel one is a fallback for old engines.
        let fallback = outputs.grey_lump || m.own_grid.is_none();
        face.light_offset = if fallback { data.push(m) } else { -1 };
        for (slot, &s) in m.styles.iter().enumerate() {
            face.styles[slot] = s;
        }
    }
    for name in [DECOUPLED_LM, LMSHIFT, LMOFFSET] {
        bsp.remove_bspx_lump(name);
    }
    let mut records: Option<Vec<DecoupledLightmap>> = None;
    let mut shifts: Option<(Vec<u8>, Vec<i32>)> = None;
    for (face, own) in own_grids {
        let m = &own.lightmap;
        let offset = data.push(m);
        match own.grid {
            OwnGrid::Decoupled(world_to_luxel) => {
                let records = records.get_or_insert_with(|| vec![NO_OWN_GRID; bsp.faces.len()]);
                records[face] = DecoupledLightmap {
                    // Wider grids are never made (`LuxelGrid::world_aligned`).
                    width: u16::try_from(m.width).unwrap_or(u16::MAX),
                    height: u16::try_from(m.height).unwrap_or(u16::MAX),
                    offset,
                    world_to_luxel,
                };
            }
            OwnGrid::Shifted(shift) => {
                // Faces on Quake's grid keep shift 4 and their 16-texel lightmap.
                let (shifts, offsets) = shifts.get_or_insert_with(|| {
                    let offsets = bsp.faces.iter().map(|f| f.light_offset).collect();
                    (vec![QUAKE_SHIFT; bsp.faces.len()], offsets)
                });
                (shifts[face], offsets[face]) = (shift, offset);
            }
        }
    }
    if let Some(records) = records {
        bsp.set_decoupled_lightmaps(&records);
    }
    if let Some((shifts, offsets)) = shifts {
        bsp.set_shifted_lightmaps(&shifts, &offsets);
    }
    let LuxelWriter {
        grey,
        rgb,
        hdr,
        dirs,
    } = data;
    bsp.lighting = if outputs.grey_lump { grey } else { Vec::new() };
    for name in [RGBLIGHTING, LIGHTINGDIR, LIGHTING_E5BGR9] {
        bsp.remove_bspx_lump(name);
    }
    if let Some(rgb) = rgb.as_ref().filter(|_| outputs.rgb_lump) {
        bsp.set_bspx_lump(RGBLIGHTING, rgb.clone());
    }
    if let Some(dirs) = dirs.as_ref().filter(|_| outputs.direction_lump) {
        bsp.set_bspx_lump(LIGHTINGDIR, dirs.clone());
    }
    if let Some(hdr) = hdr.as_ref().filter(|_| outputs.hdr_lump) {
        bsp.set_bspx_lump(
            LIGHTING_E5BGR9,
            hdr.iter().flat_map(|w: &u32| w.to_le_bytes()).collect(),
        );
    }
    LuxelData {
        rgb,
        hdr,
        directions: dirs,
    }
}

/// The `LMSHIFT` of Quake's 16-texel grid.
pub(crate) const QUAKE_SHIFT: u8 = 4;

/// The `DECOUPLED_LM` record of a face without a lightmap.
const NO_OWN_GRID: DecoupledLightmap = DecoupledLightmap {
    width: 0,
    height: 0,
    offset: -1,
    world_to_luxel: [[0.0; 4]; 2],
};

/// The lighting data being written, each form luxel for luxel.
struct LuxelWriter {
    grey: Vec<u8>,
    rgb: Option<Vec<u8>>,
    hdr: Option<Vec<u32>>,
    dirs: Option<Vec<u8>>,
}

impl LuxelWriter {
    /// Appends `m`'s lightmaps; returns where they start (in luxels).
    fn push(&mut self, m: &FaceLightmap) -> i32 {
        let start = self.grey.len() as i32;
        for g in &m.grey {
            self.grey.extend_from_slice(g);
        }
        if let Some(rgb) = &mut self.rgb {
            rgb.extend(m.rgb.iter().flatten().flatten());
        }
        if let Some(hdr) = &mut self.hdr {
            hdr.extend(m.hdr.iter().flatten());
        }
        if let Some(dirs) = &mut self.dirs {
            dirs.extend(m.directions.iter().flatten().flatten());
        }
        start
    }
}

/// The `.lit` of white light: each luxel's grey level of `lighting` (a lighting lump) in all
/// three channels.
pub fn grey_lit(lighting: &[u8]) -> Vec<u8> {
    let rgb: Vec<u8> = lighting.iter().flat_map(|&g| [g, g, g]).collect();
    quake_formats::lit::write_lit(&rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    const PLAIN: Finish = Finish {
        rangescale: 0.5,
        gamma: 1.0,
        rgb: true,
        hdr: false,
        directions: false,
    };

    /// Light units to bytes: scale, gamma, then all channels scaled down together if the
    /// brightest exceeds 255 (keeps the hue).
    fn to_bytes(c: [f32; 3], finish: &Finish) -> [u8; 3] {
        levels_to_bytes(to_levels(c, finish))
    }

    #[test]
    fn bytes_scale_and_keep_hue_when_clamping() {
        assert_eq!(to_bytes([300.0, 300.0, 300.0], &PLAIN), [150; 3]);
        assert_eq!(to_bytes([-20.0, 0.0, 1.0], &PLAIN), [0, 0, 1]);
        assert_eq!(to_bytes([1020.0, 510.0, 0.0], &PLAIN), [255, 128, 0]);
    }

    #[test]
    fn non_negative_rounding_matches_round() {
        let halves = (0..600).map(|k| f64::from(k) / 2.0);
        let near_halves = (0..600).flat_map(|k| {
            let h = f64::from(k) + 0.5;
            [h.next_down(), h.next_up()]
        });
        for x in halves.chain(near_halves).chain([0.0, 254.9999, 1e9]) {
            assert_eq!(round_non_negative(x), x.round(), "{x}");
        }
        assert_eq!(round_non_negative(f64::NAN) as u8, f64::NAN.round() as u8);
    }

    #[test]
    fn dark_styles_are_dropped_and_only_four_kept() {
        let styles = [0u8, 32, 33, 34, 35, 36]
            .iter()
            .enumerate()
            .map(|(i, &s)| (s, vec![[i as f32 * 10.0; 3]; 2]))
            .chain([(40, vec![[0.0; 3]; 2])])
            .collect();
        let light = FaceLight {
            face: 0,
            width: 2,
            height: 1,
            styles,
            directions: Vec::new(),
        };
        let (m, dropped) = finish_face(&light, &PLAIN);
        assert_eq!(m.styles, vec![36, 35, 34, 33]);
        assert_eq!(
            dropped, 1,
            "one lit style over the limit (the dark ones are not counted)"
        );
    }

    /// Regression: a style whose brightest luxel was under one level but rounded to a byte of 1
    /// was written; ericw-tools leaves such a style out.
    #[test]
    fn a_style_dimmer_than_one_level_is_not_written() {
        let face = |units: f32| FaceLight {
            face: 0,
            width: 2,
            height: 1,
            styles: vec![(0, vec![[units; 3], [0.0; 3]])],
            directions: Vec::new(),
        };
        // Half a light unit per level (PLAIN's range).
        let (dim, _) = finish_face(&face(1.8), &PLAIN);
        assert!(dim.styles.is_empty(), "{:?}", dim.grey);
        let (lit, _) = finish_face(&face(2.0), &PLAIN);
        assert_eq!((lit.styles, lit.grey), (vec![0], vec![vec![1, 0]]));
    }

    /// ericw-tools' `hdr` test: with HDR output, a face whose light rounds to bytes of 0 keeps
    /// its lightmap (grey 0), so the HDR words carry the light the bytes cannot.
    #[test]
    fn with_hdr_output_a_face_dimmer_than_one_level_keeps_its_lightmap() {
        let face = FaceLight {
            face: 0,
            width: 2,
            height: 1,
            styles: vec![(0, vec![[0.6; 3], [0.0; 3]])],
            directions: Vec::new(),
        };
        let (bytes_only, _) = finish_face(&face, &PLAIN);
        assert!(bytes_only.styles.is_empty());
        let hdr = Finish { hdr: true, ..PLAIN };
        let (m, _) = finish_face(&face, &hdr);
        assert_eq!((m.styles, m.grey), (vec![0], vec![vec![0, 0]]));
        assert_ne!(m.hdr[0][0], 0, "the HDR word keeps the light");
        let dark = FaceLight {
            styles: vec![(0, vec![[0.0; 3]; 2])],
            ..face
        };
        assert!(finish_face(&dark, &hdr).0.styles.is_empty());
    }

    /// Regression: a face no light reaches was written as style 0 with a lightmap of zeros;
    /// ericw-tools writes no lightmap at all (style 255, offset -1), which engines draw black.
    #[test]
    fn a_face_no_light_reaches_gets_no_lightmap() {
        let dark = FaceLight {
            face: 0,
            width: 2,
            height: 1,
            styles: vec![(0, vec![[0.0; 3]; 2])],
            directions: Vec::new(),
        };
        let (m, dropped) = finish_face(&dark, &PLAIN);
        assert!(m.styles.is_empty() && m.grey.is_empty());
        assert_eq!(dropped, 0);
        let mut bsp = Bsp::default();
        bsp.faces.push(face_without_light());
        let data = write_lighting(&mut bsp, &[m], &Outputs::default());
        assert_eq!(data, LuxelData::default());
        assert!(bsp.lighting.is_empty());
        assert_eq!(bsp.faces[0].styles, [NO_STYLE; 4]);
        assert_eq!(bsp.faces[0].light_offset, -1);
    }

    #[test]
    fn styles_are_ordered_brightest_first() {
        let light = FaceLight {
            face: 0,
            width: 1,
            height: 1,
            styles: vec![(0, vec![[10.0; 3]]), (32, vec![[90.0; 3]])],
            directions: Vec::new(),
        };
        assert_eq!(finish_face(&light, &PLAIN).0.styles, vec![32, 0]);
    }

    fn face_without_light() -> quake_formats::bsp::Face {
        quake_formats::bsp::Face {
            plane: 0,
            side: 0,
            first_edge: 0,
            num_edges: 0,
            texinfo: 0,
            styles: [NO_STYLE; 4],
            light_offset: -1,
        }
    }

    /// ericw-tools' grey: a coloured luxel is as bright in the grey lump as its brightest
    /// channel (a red light as bright as a white one in engines without colour).
    #[test]
    fn grey_is_the_brightest_channel() {
        let light = FaceLight {
            face: 0,
            width: 1,
            height: 1,
            styles: vec![(0, vec![[40.0, 20.0, 20.0]])],
            directions: Vec::new(),
        };
        let (out, _) = finish_face(&light, &PLAIN);
        assert_eq!(out.rgb[0], vec![[20, 10, 10]]);
        assert_eq!(out.grey[0], vec![20]);
    }

    #[test]
    fn white_light_keeps_only_grey_and_writes_the_same_lump() {
        let light = FaceLight {
            face: 0,
            width: 2,
            height: 1,
            styles: vec![(0, vec![[40.0; 3], [90.0; 3]]), (5, vec![[8.0; 3]; 2])],
            directions: Vec::new(),
        };
        let (with_rgb, _) = finish_face(&light, &PLAIN);
        let grey_only = Finish {
            rgb: false,
            ..PLAIN
        };
        let (without, _) = finish_face(&light, &grey_only);
        assert!(without.rgb.is_empty());
        assert_eq!(without.grey, with_rgb.grey);
        let mut bsp = Bsp::default();
        bsp.faces.push(face_without_light());
        let data = write_lighting(&mut bsp, &[without], &Outputs::default());
        assert_eq!(data, LuxelData::default());
        assert!(bsp.bspx.is_empty());
        assert_eq!(bsp.lighting, vec![20, 45, 4, 4]);
        assert_eq!(bsp.faces[0].styles, [0, 5, NO_STYLE, NO_STYLE]);
    }

    fn one_face_bsp() -> Bsp {
        let mut bsp = Bsp::default();
        bsp.faces.push(face_without_light());
        bsp
    }

    #[test]
    fn hdr_keeps_light_past_255_that_bytes_clamp() {
        let light = FaceLight {
            face: 0,
            width: 2,
            height: 1,
            styles: vec![(0, vec![[512.0, 256.0, 0.0], [256.0, 256.0, 256.0]])],
            directions: Vec::new(),
        };
        let finish = Finish { hdr: true, ..PLAIN };
        let (m, _) = finish_face(&light, &finish);
        // Range 0.5: levels 256, 128, 0 (past 255, so the bytes scale down) and 128 everywhere.
        assert_eq!(m.rgb[0][0], [255, 128, 0]);
        let unpack = quake_formats::lit::unpack_e5bgr9;
        assert_eq!(
            unpack(m.hdr[0][0]),
            [2.0, 1.0, 0.0],
            "1.0 is level 128, nothing clamped"
        );
        assert_eq!(unpack(m.hdr[0][1]), [1.0; 3]);
    }

    #[test]
    fn directions_become_bytes_and_unlit_luxels_face_straight_off() {
        let light = FaceLight {
            face: 0,
            width: 2,
            height: 1,
            styles: vec![(0, vec![[10.0; 3]; 2]), (32, vec![[10.0; 3]; 2])],
            directions: vec![(0, vec![[1.0, 0.0, 0.0], [0.0; 3]])],
        };
        let finish = Finish {
            directions: true,
            ..PLAIN
        };
        let (m, _) = finish_face(&light, &finish);
        assert_eq!(m.directions[0], vec![[255, 128, 128], NO_DIRECTION]);
        assert_eq!(
            m.directions[1],
            vec![NO_DIRECTION; 2],
            "a style with no direction"
        );
        let mut bsp = one_face_bsp();
        let outputs = Outputs {
            direction_lump: true,
            ..Outputs::default()
        };
        let data = write_lighting(&mut bsp, &[m], &outputs);
        let lump = bsp.bspx_lump(LIGHTINGDIR).expect("LIGHTINGDIR");
        assert_eq!(lump.len(), 3 * bsp.lighting.len());
        assert_eq!(data.directions.as_deref(), Some(lump));
    }

    #[test]
    fn novanilla_leaves_the_grey_lump_out_and_writes_rgblighting() {
        let light = FaceLight {
            face: 0,
            width: 2,
            height: 1,
            styles: vec![(0, vec![[40.0; 3], [90.0; 3]])],
            directions: Vec::new(),
        };
        let (m, _) = finish_face(&light, &PLAIN);
        let mut bsp = one_face_bsp();
        bsp.set_bspx_lump(LIGHTING_E5BGR9, vec![1, 2, 3, 4]);
        let outputs = Outputs {
            grey_lump: false,
            rgb_lump: true,
            ..Outputs::default()
        };
        write_lighting(&mut bsp, &[m], &outputs);
        assert!(bsp.lighting.is_empty());
        assert_eq!(
            bsp.bspx_lump(RGBLIGHTING),
            Some(&[20u8, 20, 20, 45, 45, 45][..])
        );
        assert_eq!(bsp.faces[0].light_offset, 0);
        assert_eq!(bsp.luxel_count(), 2);
        assert!(
            bsp.bspx_lump(LIGHTING_E5BGR9).is_none(),
            "a lump of an earlier run is removed"
        );
    }
}
