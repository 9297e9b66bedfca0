//! ericw-tools' own light tests (`tests/test_ltface.cc` of ericwa/ericw-tools, on its
//! `testmaps/`), restated on small maps of our own that the compiler builds here: each test
//! says which case it restates and checks what that case asserts.

use glam::DVec3;
use quake_formats::Bsp;

use super::{map_box, options, room_bsp, sealed_room_brushes, slab_bsp};
use crate::faces::{FaceGeom, Spacing, face_geometry};
use crate::{Lighting, Quality, compute_lighting};

/// `text` compiled by the bsp compiler, sealed.
fn compiled(text: &str) -> Bsp {
    let source = bsp_compiler::MapSource {
        path: std::path::PathBuf::from("ericw_case.map"),
        text: text.to_string(),
    };
    let out =
        bsp_compiler::compile(&source, &bsp_compiler::CompileOptions::default()).expect("compile");
    assert!(out.leak.is_none(), "the map leaks");
    out.bsp
}

/// `bsp` lit at the default quality.
pub(super) fn lit(bsp: &Bsp) -> Lighting {
    compute_lighting(bsp, &options(Quality::Default)).expect("light")
}

/// Whether `p` lies on `face` (on its plane, inside its edges, whichever way they turn).
fn face_holds(face: &FaceGeom, p: DVec3) -> bool {
    const ON: f64 = 0.01;
    let n = face.plane.normal;
    let sides: Vec<f64> = face
        .points
        .iter()
        .zip(face.points.iter().cycle().skip(1))
        .map(|(&a, &b)| (b - a).normalize_or_zero().cross(p - a).dot(n))
        .collect();
    face.plane.distance(p).abs() < ON
        && (sides.iter().all(|&d| d <= ON) || sides.iter().all(|&d| d >= -ON))
}

/// The style-0 bytes of the luxel over `p` on the face of `model` facing `normal` there: its
/// RGB, or its grey three times when the light is not coloured. `None` when no such face holds
/// `p` or that face has no style-0 lightmap.
fn luxel_rgb(
    bsp: &Bsp,
    lighting: &Lighting,
    model: usize,
    p: DVec3,
    normal: DVec3,
) -> Option<[u8; 3]> {
    luxel_rgb_in(bsp, lighting, (model, p, normal), 0)
}

/// [`luxel_rgb`] in `style`, of the face of `model` facing `normal` at `p` (`at`).
fn luxel_rgb_in(
    bsp: &Bsp,
    lighting: &Lighting,
    at: (usize, DVec3, DVec3),
    style: u8,
) -> Option<[u8; 3]> {
    let (model, p, normal) = at;
    let faces = face_geometry(bsp, |_| DVec3::ZERO, |_| Spacing::Quake).expect("faces");
    let face = faces
        .iter()
        .find(|f| f.model == model && f.plane.normal.dot(normal) > 0.999 && face_holds(f, p))?;
    let m = lighting.lightmaps.iter().find(|m| m.face == face.index)?;
    let slot = m.styles.iter().position(|&s| s == style)?;
    let [sv, tv] = face
        .vecs
        .map(|v| DVec3::new(v[0].into(), v[1].into(), v[2].into()));
    let (s, t) = (
        sv.dot(p) + f64::from(face.vecs[0][3]),
        tv.dot(p) + f64::from(face.vecs[1][3]),
    );
    let mins = face.extents.tex_mins.map(f64::from);
    let col = ((s - mins[0]) / 16.0).round() as usize;
    let row = ((t - mins[1]) / 16.0).round() as usize;
    let at = row.min(m.height - 1) * m.width + col.min(m.width - 1);
    match m.rgb.get(slot) {
        Some(rgb) => Some(rgb[at]),
        None => Some([m.grey[slot][at]; 3]),
    }
}

/// The floor luxel of [`room_bsp`] under `(x, y)`.
pub(super) fn floor_rgb(bsp: &Bsp, lighting: &Lighting, x: f64, y: f64) -> Option<[u8; 3]> {
    luxel_rgb(bsp, lighting, 0, DVec3::new(x, y, -128.0), DVec3::Z)
}

/// A light entity of [`room_bsp`] at `origin` with `keys`.
pub(super) fn light(origin: [f64; 3], keys: &str) -> String {
    let [x, y, z] = origin;
    format!("{{\n\"classname\" \"light\"\n\"origin\" \"{x} {y} {z}\"\n{keys}\n}}\n")
}

/// `lightHlform` (`q1_light_hlform`): Half-Life's `"light" "R G B I"` is a colour and a
/// brightness, and three numbers a colour at the default brightness, whether the colour is
/// written 0–255 or 0–1. ericw-tools lights the floor under `"255 127 0"` 113 56 0; each form
/// here lights the floor as the same light written with `_color` does, orange through the
/// `.lit`. A brightness of 0 lights nothing, as ericw-tools 2.0 lights nothing from it.
#[test]
fn half_life_light_values_are_coloured() {
    let orange = |light_value: &str| {
        let bsp = room_bsp(&light([0.0, 0.0, -48.0], light_value));
        let lighting = lit(&bsp);
        assert!(lighting.coloured, "{light_value}: no .lit");
        floor_rgb(&bsp, &lighting, 0.0, 0.0)
    };
    let three = orange("\"light\" \"255 127 0\"");
    assert_eq!(three, orange("\"_color\" \"255 127 0\""));
    let [r, g, b] = three.expect("the floor is lit");
    assert!(r > 100 && g.abs_diff(r / 2) <= 1 && b == 0, "{three:?}");
    assert_eq!(
        orange("\"light\" \"1 0.5 0 100\""),
        orange("\"light\" \"100\"\n\"_color\" \"1 0.5 0\"")
    );
    assert_eq!(
        orange("\"light\" \"255 127 0 200\""),
        orange("\"light\" \"200\"\n\"_color\" \"255 127 0\"")
    );
    // An explicit `_color` wins over the colour of the Half-Life form.
    assert_eq!(
        orange("\"light\" \"255 127 0 200\"\n\"_color\" \"0 0 255\""),
        orange("\"light\" \"200\"\n\"_color\" \"0 0 255\"")
    );
    for nothing in ["\"light\" \"0\"", "\"light\" \"255 127 0 0\""] {
        let bsp = room_bsp(&light([0.0, 0.0, -48.0], nothing));
        let lighting = lit(&bsp);
        assert!(
            lighting.lightmaps.iter().all(|m| m.styles.is_empty()),
            "{nothing} lit a face"
        );
    }
}

/// `lightInvalidDelay` (`q1_light_invalid_delay`): a light whose `delay` names no falloff
/// formula is a warning, not an error, and lights nothing: every luxel of the map is black.
#[test]
fn a_light_with_an_unknown_delay_lights_nothing() {
    let bsp = room_bsp(&light([0.0, 0.0, 0.0], "\"delay\" \"15\""));
    let lighting = lit(&bsp);
    assert!(
        lighting.lightmaps.iter().all(|m| m.styles.is_empty()),
        "a face is lit"
    );
    let told: Vec<String> = lighting.warnings.iter().map(ToString::to_string).collect();
    assert!(
        told.iter()
            .any(|w| w.contains("key \"delay\" is \"15\"") && w.contains("lights nothing")),
        "{told:?}"
    );
    // The same light with a formula lights the room.
    let bsp = room_bsp(&light([0.0, 0.0, 0.0], "\"delay\" \"1\""));
    assert!(floor_rgb(&bsp, &lit(&bsp), 0.0, 0.0).is_some_and(|c| c[0] > 0));
}

/// `lightSunArtifact` (`q1_light_sun_artifact`): a red sun at 45° over a floor boxed in by sky,
/// whose ceiling is a grid of sky brushes of two textures (so their faces meet at many seams).
/// Every luxel of the floor takes the same red: no sun ray slips through a seam between two
/// triangles (ericw-tools builds its Embree scene robust for this; 56 of 5,400 luxels here were
/// black before ours was).
#[test]
fn sun_rays_do_not_slip_through_seams_in_the_sky() {
    const CELL: f64 = 224.0;
    let (x1, y1, ceiling) = (4.0 * CELL, 6.0 * CELL, 320.0);
    let sky = |lo, hi, texture: &str| map_box(lo, hi).replace("wall", texture);
    let mut world = map_box([0.0, 0.0, -16.0], [x1, y1, 0.0]);
    for (lo, hi) in [
        ([-16.0, -16.0, -16.0], [0.0, y1 + 16.0, ceiling]),
        ([x1, -16.0, -16.0], [x1 + 16.0, y1 + 16.0, ceiling]),
        ([0.0, -16.0, -16.0], [x1, 0.0, ceiling]),
        ([0.0, y1, -16.0], [x1, y1 + 16.0, ceiling]),
    ] {
        world += &sky(lo, hi, "sky1");
    }
    for i in 0..4 {
        for j in 0..6 {
            let (x, y) = (f64::from(i) * CELL, f64::from(j) * CELL);
            let texture = if (i + j) % 2 == 0 { "sky1" } else { "sky2" };
            world += &sky(
                [x, y, ceiling],
                [x + CELL, y + CELL, ceiling + 16.0],
                texture,
            );
        }
    }
    let bsp = compiled(&format!(
        "{{\n\"classname\" \"worldspawn\"\n{world}}}\n\
         {}{{\n\"classname\" \"info_player_start\"\n\"origin\" \"64 64 40\"\n}}\n",
        light(
            [100.0, 100.0, 100.0],
            "\"_sun\" \"1\"\n\"_color\" \"1 0 0\"\n\"mangle\" \"0 -45 0\""
        )
    ));
    let lighting = lit(&bsp);
    let faces = face_geometry(&bsp, |_| DVec3::ZERO, |_| Spacing::Quake).expect("faces");
    let mut luxels = Vec::new();
    for face in faces.iter().filter(|f| f.plane.normal.z > 0.999) {
        let m = lighting.lightmaps.iter().find(|m| m.face == face.index);
        let m = m.expect("a lightmap for every upward face");
        luxels.extend(m.rgb.first().expect("red light: a .lit").iter().copied());
    }
    assert!(luxels.len() > 5000, "{} luxels", luxels.len());
    let red = luxels[0];
    assert!(red[0] > 100 && red[1] == 0 && red[2] == 0, "{red:?}");
    let odd = luxels.iter().filter(|&&c| c != red).count();
    assert_eq!(
        odd,
        0,
        "{odd} of {} upward luxels are not {red:?}",
        luxels.len()
    );
}

/// `suntexture` (`q1_light_suntexture`): two `_sun` lights, each with `_suntexture` naming one
/// of two sky textures, shine only through the sky faces of their own texture: the floor under
/// one sky is red, under the other blue (ericw-tools: 35 0 0 and 0 0 142 there). A
/// `_suntexture` the map has no texture of is a warning and filters nothing.
#[test]
fn a_sun_with_a_sky_texture_shines_only_through_that_sky() {
    let (x1, y1, ceiling) = (512.0, 256.0, 256.0);
    let mut world = map_box([-16.0, -16.0, -16.0], [x1 + 16.0, y1 + 16.0, 0.0]);
    for (lo, hi) in [
        ([-16.0, -16.0, 0.0], [0.0, y1 + 16.0, ceiling]),
        ([x1, -16.0, 0.0], [x1 + 16.0, y1 + 16.0, ceiling]),
        ([0.0, -16.0, 0.0], [x1, 0.0, ceiling]),
        ([0.0, y1, 0.0], [x1, y1 + 16.0, ceiling]),
    ] {
        world += &map_box(lo, hi);
    }
    let half = x1 / 2.0;
    world += &map_box([-16.0, -16.0, ceiling], [half, y1 + 16.0, ceiling + 16.0])
        .replace("wall", "sky_red");
    world += &map_box(
        [half, -16.0, ceiling],
        [x1 + 16.0, y1 + 16.0, ceiling + 16.0],
    )
    .replace("wall", "sky_blue");
    let sun = |color: &str, texture: &str| {
        light(
            [64.0, 64.0, 64.0],
            &format!(
                "\"_sun\" \"1\"\n\"mangle\" \"0 -90 0\"\n\"_color\" \"{color}\"\n\"_suntexture\" \"{texture}\""
            ),
        )
    };
    let map = |suns: &str| {
        compiled(&format!(
            "{{\n\"classname\" \"worldspawn\"\n{world}}}\n{suns}\
             {{\n\"classname\" \"info_player_start\"\n\"origin\" \"64 64 40\"\n}}\n"
        ))
    };
    let floor = |bsp: &Bsp, lighting: &Lighting, x: f64| {
        luxel_rgb(bsp, lighting, 0, DVec3::new(x, y1 / 2.0, 0.0), DVec3::Z).expect("a lit floor")
    };
    let bsp = map(&(sun("1 0 0", "sky_red") + &sun("0 0 1", "SKY_BLUE")));
    let lighting = lit(&bsp);
    let [r, g, b] = floor(&bsp, &lighting, half / 2.0);
    assert!(
        r > 100 && g == 0 && b == 0,
        "under the red sky: {:?}",
        [r, g, b]
    );
    let [r, g, b] = floor(&bsp, &lighting, half * 1.5);
    assert!(
        r == 0 && g == 0 && b > 100,
        "under the blue sky: {:?}",
        [r, g, b]
    );

    let bsp = map(&sun("0 1 0", "no_such_sky"));
    let lighting = lit(&bsp);
    for x in [half / 2.0, half * 1.5] {
        let [r, g, b] = floor(&bsp, &lighting, x);
        assert!(r == 0 && g > 100 && b == 0, "at x {x}: {:?}", [r, g, b]);
    }
    let told: Vec<String> = lighting.warnings.iter().map(ToString::to_string).collect();
    assert!(
        told.iter()
            .any(|w| w.contains("\"_suntexture\" is \"no_such_sky\"")),
        "{told:?}"
    );
}

/// `litWater`'s third cube (`q1_litwater`): a `func_group` keyed `_lightignore 1` and
/// `_minlight 100` is merged into the world, yet its faces take its minlight and no light, as a
/// brush model's would (ericw-tools: 50 50 50 on its top under a light). The compiler records
/// the keys of merged entities per face; `_minlight_exclude` leaves a texture's faces without
/// any minlight, and `_dirt -1` and `_bounce 0` are kept per face too.
#[test]
fn keys_of_merged_entities_reach_light_per_face() {
    let top = |classname: &str, keys: &str| {
        let bsp = slab_bsp(classname, keys, "wall");
        let lighting = lit(&bsp);
        luxel_rgb(&bsp, &lighting, 0, DVec3::new(0.0, 0.0, -48.0), DVec3::Z)
    };
    let ignored = "\"_lightignore\" \"1\"\n\"_minlight\" \"100\"";
    assert_eq!(top("func_group", ignored), Some([50, 50, 50]));
    assert_eq!(top("func_detail", ignored), Some([50, 50, 50]));
    let lit_top = top("func_group", "").expect("a lit top");
    assert!(lit_top[0] > 60, "{lit_top:?}");
    let dark = top("func_group", "\"_lightignore\" \"1\"");
    assert!(dark.is_none_or(|c| c == [0, 0, 0]), "{dark:?}");
    let excluded = format!("{ignored}\n\"_minlight_exclude\" \"WALL\"");
    let none = top("func_group", &excluded);
    assert!(none.is_none_or(|c| c == [0, 0, 0]), "{none:?}");

    let bsp = slab_bsp(
        "func_group",
        "\"_dirt\" \"-1\"\n\"_bounce\" \"0\"\n\"_minlight\" \"20\"\n\"_mincolor\" \"255 0 0\"",
        "wall",
    );
    let flags = bsp.face_flags().expect("lump").expect("flags");
    let marked = flags.iter().filter(|f| f.no_dirt && f.no_bounce).count();
    assert_eq!(marked, 6, "the slab's six faces");
    let minlights = bsp.face_minlights().expect("lump").expect("minlights");
    let red: Vec<_> = minlights.iter().filter(|m| m.level == 20.0).collect();
    assert_eq!(red.len(), 6);
    assert!(red.iter().all(|m| m.color == [1.0, 0.0, 0.0]), "{red:?}");
}

/// ericw-tools' `-nolights`: light entities are ignored (a `_sun` light's too), worldspawn's
/// minlight still lights the map.
#[test]
fn nolights_leaves_only_the_worlds_own_light() {
    let bsp = room_bsp(&(light([0.0, 0.0, -48.0], "") + &light([0.0, 0.0, 0.0], "\"_sun\" \"1\"")));
    let mut opts = options(Quality::Default);
    opts.overrides.minlight = Some(20.0);
    let with_lights = compute_lighting(&bsp, &opts).expect("light");
    let lit = floor_rgb(&bsp, &with_lights, 0.0, 0.0).expect("a lit floor");
    assert!(lit[0] > 20, "{lit:?}");
    opts.overrides.nolights = Some(true);
    let lighting = compute_lighting(&bsp, &opts).expect("light");
    assert_eq!(floor_rgb(&bsp, &lighting, 0.0, 0.0), Some([10, 10, 10]));
    assert_eq!(
        floor_rgb(&bsp, &lighting, 100.0, -100.0),
        Some([10, 10, 10])
    );
}

/// ericw-tools' `_maxlight` (worldspawn, and a brush model's own): no luxel is brighter than
/// that many levels; a brighter sample is dimmed with its colour kept.
#[test]
fn maxlight_caps_the_light_and_keeps_its_colour() {
    let bsp = room_bsp(&light(
        [0.0, 0.0, -96.0],
        "\"light\" \"600\"\n\"_color\" \"255 128 0\"",
    ));
    let mut opts = options(Quality::Default);
    let free = compute_lighting(&bsp, &opts).expect("light");
    let [r, g, _] = floor_rgb(&bsp, &free, 0.0, 0.0).expect("lit");
    assert!(r > 200, "{r}");
    opts.overrides.maxlight = Some(60.0);
    let capped = compute_lighting(&bsp, &opts).expect("light");
    let brightest = capped
        .lightmaps
        .iter()
        .flat_map(|m| m.rgb.iter().flatten())
        .map(|c| c[0].max(c[1]).max(c[2]))
        .max();
    assert_eq!(brightest, Some(60));
    let [cr, cg, cb] = floor_rgb(&bsp, &capped, 0.0, 0.0).expect("lit");
    assert_eq!(cr, 60);
    let (ratio, capped_ratio) = (f64::from(g) / f64::from(r), f64::from(cg) / f64::from(cr));
    assert!(
        (ratio - capped_ratio).abs() < 0.03 && cb == 0,
        "{ratio} {capped_ratio}"
    );

    // A brush model's own cap wins over the world's (none here).
    let bsp = slab_bsp("func_wall", "\"_maxlight\" \"20\"", "wall");
    let lighting = lit(&bsp);
    let top = luxel_rgb(&bsp, &lighting, 1, DVec3::new(0.0, 0.0, -48.0), DVec3::Z);
    assert_eq!(top, Some([20, 20, 20]));
    let floor = floor_rgb(&bsp, &lighting, 100.0, 100.0).expect("lit");
    assert!(floor[0] > 20, "{floor:?}");
}

/// ericw-tools' `_shadowworldonly`: the model shadows the world's faces, not another model's.
/// A slab with it over the floor, a plate (another brush model) on the floor under it: the
/// floor beside the plate is in the slab's shadow, the plate's top is lit as without the slab.
#[test]
fn a_world_only_shadow_falls_on_the_world_alone() {
    let slab = map_box([-32.0, -32.0, -64.0], [32.0, 32.0, -48.0]);
    let plate = map_box([-16.0, -16.0, -128.0], [16.0, 16.0, -120.0]);
    let room = |slab_keys: &str| {
        room_bsp(&format!(
            "{{\n\"classname\" \"func_wall\"\n{slab_keys}\n{slab}}}\n\
             {{\n\"classname\" \"func_wall\"\n{plate}}}\n{}",
            light([0.0, 0.0, 64.0], "")
        ))
    };
    let look = |bsp: &Bsp| {
        let lighting = lit(bsp);
        let plate_top = luxel_rgb(bsp, &lighting, 2, DVec3::new(0.0, 0.0, -120.0), DVec3::Z);
        let floor = floor_rgb(bsp, &lighting, 24.0, 0.0);
        (
            plate_top.expect("a lit plate")[0],
            floor.map_or(0, |c| c[0]),
        )
    };
    let (plate_open, floor_open) = look(&room(""));
    assert!(
        plate_open > 20 && floor_open > 20,
        "{plate_open} {floor_open}"
    );
    let (plate, floor) = look(&room("\"_shadowworldonly\" \"1\"\n\"_shadow\" \"1\""));
    assert_eq!(floor, 0, "the world is in the slab's shadow");
    assert_eq!(plate, plate_open, "the plate is not");
}

/// ericw-tools' light channels (its test "light channel mask"): a light lights the models whose
/// `_object_channel_mask` shares a bit with its `_light_channel_mask` (the world is on channel
/// 1), and a model on another channel than 1 casts shadows on the lights of its channel
/// (their `_shadow_channel_mask`, by default their light channels) and on no other. A slab
/// over a plate on the floor, both brush models; the light above them.
#[test]
fn light_channels_choose_what_a_light_lights_and_what_shadows_it() {
    let slab = map_box([-32.0, -32.0, -64.0], [32.0, 32.0, -48.0]);
    let plate = map_box([-16.0, -16.0, -128.0], [16.0, 16.0, -120.0]);
    let look = |slab_keys: &str, plate_keys: &str, light_keys: &str| {
        let bsp = room_bsp(&format!(
            "{{\n\"classname\" \"func_wall\"\n{slab_keys}\n{slab}}}\n\
             {{\n\"classname\" \"func_wall\"\n{plate_keys}\n{plate}}}\n{}",
            light([0.0, 0.0, 64.0], light_keys)
        ));
        let lighting = lit(&bsp);
        let red = |rgb: Option<[u8; 3]>| rgb.map_or(0, |c| c[0]);
        let slab_top = luxel_rgb(&bsp, &lighting, 1, DVec3::new(0.0, 0.0, -48.0), DVec3::Z);
        let plate_top = luxel_rgb(&bsp, &lighting, 2, DVec3::new(0.0, 0.0, -120.0), DVec3::Z);
        let floor = floor_rgb(&bsp, &lighting, 100.0, 100.0);
        (red(slab_top), red(plate_top), red(floor))
    };
    let (slab, plate, floor) = look("", "", "");
    assert!(
        slab > 20 && plate > 20 && floor > 20,
        "{slab} {plate} {floor}"
    );
    let on_2 = "\"_object_channel_mask\" \"2\"";
    // A channel-2 light lights the channel-2 plate, not the world nor the channel-1 slab,
    // which casts no shadow (no `_shadow`).
    let (slab2, plate2, floor2) = look("", on_2, "\"_light_channel_mask\" \"2\"");
    assert_eq!(
        (slab2, floor2),
        (0, 0),
        "the world and the slab are on channel 1"
    );
    assert_eq!(plate2, plate, "the plate takes the light as before");
    // The channel-2 slab shadows the channel-2 plate from the channel-2 light, and is lit.
    let (slab3, plate3, _) = look(on_2, on_2, "\"_light_channel_mask\" \"2\"");
    assert_eq!(plate3, 0, "a model on channel 2 casts shadows on channel 2");
    assert!(slab3 > 20, "{slab3}");
    // A channel-1 light: the channel-2 slab neither takes its light nor blocks it; with
    // `_shadow_channel_mask 3`, it blocks it.
    let (slab4, plate4, floor4) = look(on_2, "", "");
    assert_eq!((slab4, plate4, floor4), (0, plate, floor));
    let (_, plate5, _) = look(on_2, "", "\"_shadow_channel_mask\" \"3\"");
    assert_eq!(plate5, 0, "shadow channels 1 and 2: the slab blocks");
}

/// ericw-tools' "light channel mask" for entities merged into the world: a `func_detail` with
/// `_object_channel_mask 2` takes the light of channel-2 lights and casts no shadow on channel
/// 1 (the compiler records its faces' mask in `SLIPGATE_FACECHANNELS`).
#[test]
fn a_merged_entity_on_another_channel_takes_its_lights_and_casts_on_them_alone() {
    let slab = map_box([-32.0, -32.0, -64.0], [32.0, 32.0, -48.0]);
    let look = |slab_keys: &str, light_keys: &str| {
        let bsp = room_bsp(&format!(
            "{{\n\"classname\" \"func_detail\"\n{slab_keys}\n{slab}}}\n{}",
            light([0.0, 0.0, 64.0], light_keys)
        ));
        let lighting = lit(&bsp);
        let red = |rgb: Option<[u8; 3]>| rgb.map_or(0, |c| c[0]);
        let slab_top = luxel_rgb(&bsp, &lighting, 0, DVec3::new(0.0, 0.0, -48.0), DVec3::Z);
        (red(slab_top), red(floor_rgb(&bsp, &lighting, 0.0, 0.0)))
    };
    let (slab, floor) = look("", "");
    assert!(slab > 20, "{slab}");
    assert_eq!(floor, 0, "in the slab's shadow");
    let on_2 = "\"_object_channel_mask\" \"2\"";
    let (slab1, floor1) = look(on_2, "");
    assert_eq!(slab1, 0, "a channel-1 light does not light the slab");
    assert!(
        floor1 > 20,
        "the slab casts no shadow on channel 1: {floor1}"
    );
    let (slab2, floor2) = look(on_2, "\"_light_channel_mask\" \"2\"");
    assert_eq!(
        (slab2, floor2),
        (slab, 0),
        "a channel-2 light lights the slab alone"
    );
}

/// ericw-tools' "light channel mask / dirt interaction": dirt comes from what shares a light
/// channel. A box on the floor beside a lit spot: as a shadow caster on channel 1 it darkens
/// the floor at its foot with dirt; on channel 2 it does not (the light lights both channels).
#[test]
fn dirt_comes_only_from_models_on_the_same_channel() {
    let block = map_box([32.0, -32.0, -128.0], [64.0, 32.0, -64.0]);
    let floor_at_foot = |block_keys: &str| {
        let bsp = room_bsp(&format!(
            "{{\n\"classname\" \"func_wall\"\n{block_keys}\n{block}}}\n{}",
            light([0.0, 0.0, 64.0], "\"_light_channel_mask\" \"3\"")
        ));
        let mut opts = options(Quality::Default);
        opts.overrides.dirt = Some(true);
        let lighting = compute_lighting(&bsp, &opts).expect("light");
        floor_rgb(&bsp, &lighting, 26.0, 0.0).expect("lit")[0]
    };
    let open = floor_at_foot("");
    let dirty = floor_at_foot("\"_shadow\" \"1\"");
    let other_channel = floor_at_foot("\"_object_channel_mask\" \"2\"");
    assert!(dirty < open, "{dirty} {open}");
    assert_eq!(other_channel, open);
}

/// ericw-tools' `_lightcolorscale` (a brush model's key): `0` greys the light of its faces, each
/// luxel taking its brightest channel in all three; `0.5` keeps half the colour; the world's
/// light keeps its colour.
#[test]
fn light_color_scale_greys_a_models_faces() {
    let slab = map_box([-32.0, -32.0, -64.0], [32.0, 32.0, -48.0]);
    let look = |keys: &str| {
        let bsp = room_bsp(&format!(
            "{{\n\"classname\" \"func_wall\"\n{keys}\n{slab}}}\n{}",
            light([0.0, 0.0, 64.0], "\"_color\" \"255 64 0\"")
        ));
        let lighting = lit(&bsp);
        let top = luxel_rgb(&bsp, &lighting, 1, DVec3::new(0.0, 0.0, -48.0), DVec3::Z);
        (
            top.expect("a lit slab"),
            floor_rgb(&bsp, &lighting, 100.0, 100.0).expect("lit"),
        )
    };
    let (coloured, floor) = look("");
    assert!(
        coloured[0] > coloured[1] && coloured[2] == 0,
        "{coloured:?}"
    );
    let (grey, grey_floor) = look("\"_lightcolorscale\" \"0\"");
    assert_eq!(grey, [coloured[0]; 3], "the brightest channel in all three");
    assert_eq!(grey_floor, floor, "the world keeps its colour");
    let (half, _) = look("\"_lightcolorscale\" \"0.5\"");
    let mid = |c: u8| (f32::from(coloured[0]) + f32::from(c)) / 2.0;
    for k in 0..3 {
        assert!(
            (f32::from(half[k]) - mid(coloured[k])).abs() <= 1.0,
            "{half:?} against {coloured:?}"
        );
    }
}

/// `_lightcolorscale` and `_maxlight` on a `func_detail`, whose brushes join the world: the
/// compiler records them per face (`SLIPGATE_FACETONE`), as ericw-tools' qbsp records them in
/// its texinfo, and they act on the slab's faces alone.
#[test]
fn a_merged_entitys_colour_scale_and_cap_act_on_its_faces_only() {
    let slab = map_box([-32.0, -32.0, -64.0], [32.0, 32.0, -48.0]);
    let look = |keys: &str| {
        let bsp = room_bsp(&format!(
            "{{\n\"classname\" \"func_detail\"\n{keys}\n{slab}}}\n{}",
            light([0.0, 0.0, 64.0], "\"_color\" \"255 64 0\"")
        ));
        let lighting = lit(&bsp);
        let top = luxel_rgb(&bsp, &lighting, 0, DVec3::new(0.0, 0.0, -48.0), DVec3::Z);
        (
            top.expect("a lit slab"),
            floor_rgb(&bsp, &lighting, 100.0, 100.0).expect("lit"),
        )
    };
    let (coloured, floor) = look("");
    assert!(
        coloured[0] > 40 && coloured[1] < coloured[0],
        "{coloured:?}"
    );
    let (grey, grey_floor) = look("\"_lightcolorscale\" \"0\"");
    assert_eq!(grey, [coloured[0]; 3], "the brightest channel in all three");
    assert_eq!(grey_floor, floor, "the world keeps its colour");
    let (capped, capped_floor) = look("\"_maxlight\" \"20\"");
    assert!(capped[0] <= 21 && capped[0] >= 19, "{capped:?}");
    assert_eq!(capped_floor, floor, "the world is not capped");
}

/// ericw-tools' `_spotlightautofalloff`: a linear spotlight aimed at a `target` fades to zero
/// just past its cone at the target (the distance plus the cone's radius there), instead of
/// at its brightness in units. 224 units above the floor, light 600, angle 40: zero at 305.5
/// units, so the floor under it takes 600 − 224 × 600 / 305.5 ≈ 160 where it took 376.
#[test]
fn spotlight_autofalloff_fades_out_at_the_target() {
    let bsp = room_bsp(&format!(
        "{}{{\n\"classname\" \"info_null\"\n\"targetname\" \"spot\"\n\"origin\" \"0 0 -128\"\n}}\n",
        light([0.0, 0.0, 96.0], "\"light\" \"600\"\n\"target\" \"spot\"")
    ));
    let mut opts = options(Quality::Default);
    let plain = floor_rgb(
        &bsp,
        &compute_lighting(&bsp, &opts).expect("light"),
        0.0,
        0.0,
    );
    opts.overrides.spotlight_autofalloff = Some(true);
    let auto = floor_rgb(
        &bsp,
        &compute_lighting(&bsp, &opts).expect("light"),
        0.0,
        0.0,
    );
    let (plain, auto) = (
        f64::from(plain.expect("lit")[0]),
        f64::from(auto.expect("lit")[0]),
    );
    let want = (600.0 - 224.0 * 600.0 / (224.0 + 224.0 * 20f64.to_radians().tan())) / 376.0;
    assert!(
        (auto / plain - want).abs() < 0.02,
        "{auto} / {plain}, want {want}"
    );
}

/// ericw-tools' `-surflight_subdivide` (worldspawn `_surflightsubdivision`, `_choplight`): the
/// grid a `_surface` light's copies are spread on; halving it puts more copies on the faces.
#[test]
fn surface_light_spacing_is_a_setting() {
    let bsp = room_bsp(&light(
        [0.0, 0.0, 0.0],
        "\"_surface\" \"wall\"\n\"light\" \"20\"",
    ));
    let copies = |spacing: Option<f64>| {
        let mut opts = options(Quality::Default);
        opts.overrides.surflight_subdivide = spacing;
        compute_lighting(&bsp, &opts)
            .expect("light")
            .stats
            .surface_lights
    };
    let (default, finer) = (copies(None), copies(Some(64.0)));
    assert!(default > 0 && finer > 2 * default, "{default} {finer}");
    assert_eq!(copies(Some(128.0)), default, "128 units by default");
}

/// `detailFence` (`q1_detail_fence`): a `func_detail_fence` (here all `skip`, as there, so it has
/// no faces) around a light and the floor under it. Its inside is written solid, which stops
/// players; the compiler marks those leaves and light takes them as open, so the light is not
/// "in solid" and the floor inside the fence takes the light it takes without the fence.
/// ericw-tools lights the middle of this floor 118; without the marks it was black.
#[test]
fn the_inside_of_a_fence_is_lit_as_open_space() {
    let room = |fence: bool| {
        let mut entities = light([0.0, 0.0, -64.0], "");
        if fence {
            let brush = map_box([-64.0, -64.0, -128.0], [64.0, 64.0, 0.0]).replace("wall", "skip");
            entities += &format!("{{\n\"classname\" \"func_detail_fence\"\n{brush}}}\n");
        }
        room_bsp(&entities)
    };
    let fenced = room(true);
    let flags = fenced.leaf_flags().expect("leaf flags read");
    assert!(
        flags.is_some_and(|f| f.iter().any(|l| l.fence)),
        "the compiler marks the fence's leaves"
    );
    assert!(
        crate::samples::solid_at(&fenced, [0.0, 0.0, -64.0]),
        "solid to engines"
    );
    let lighting = lit(&fenced);
    assert!(
        lighting.stats.lights_nudged == 0,
        "the light is not in solid"
    );
    let open = room(false);
    let open_lighting = lit(&open);
    for (x, y) in [(0.0, 0.0), (32.0, 32.0), (-48.0, 16.0), (100.0, 100.0)] {
        let inside = floor_rgb(&fenced, &lighting, x, y).expect("the floor is lit");
        let without = floor_rgb(&open, &open_lighting, x, y).expect("the floor is lit");
        assert!(inside[0] > 40, "({x}, {y}): {inside:?}");
        assert!(
            inside[0].abs_diff(without[0]) <= 1,
            "({x}, {y}): {inside:?} against {without:?}"
        );
    }
}

/// `switchableshadowSelfShadows` (`q1_light_switchableshadow_selfshadows`): a `_switchableshadow`
/// door with `_minlight 25`, a slab on the floor with a fin standing on it, lit from beside the
/// fin. The door always shadows itself: where the fin hides the light from the slab, style 0
/// holds the door's minlight alone and the door's switchable style (32) nothing; on the floor
/// beyond the door the light the fin blocks is in style 32 alone. ericw-tools writes 12 (its
/// minlight) and 0 on the door, 0 and 89 on the floor.
#[test]
fn a_switchable_shadow_always_shadows_its_own_model() {
    let door = |keys: &str| {
        let brushes = map_box([-32.0, -48.0, -128.0], [32.0, 48.0, -112.0])
            + &map_box([0.0, -32.0, -112.0], [16.0, 32.0, -48.0]);
        room_bsp(&format!(
            "{{\n\"classname\" \"func_door\"\n{keys}\n{brushes}}}\n{}",
            light([100.0, 0.0, -60.0], "\"light\" \"500\"")
        ))
    };
    let slab_behind_fin = (1, DVec3::new(-16.0, 0.0, -112.0), DVec3::Z);
    let floor_behind_door = (0, DVec3::new(-88.0, 0.0, -128.0), DVec3::Z);
    let switchable = door("\"_switchableshadow\" \"1\"\n\"_minlight\" \"25\"");
    let lighting = lit(&switchable);
    let at = |at, style| luxel_rgb_in(&switchable, &lighting, at, style).unwrap_or([0; 3]);
    // Within one of ericw-tools' value, as its own check allows.
    let minlight = at(slab_behind_fin, 0);
    assert!(
        minlight.iter().all(|c| c.abs_diff(12) <= 1),
        "the door's minlight: {minlight:?}"
    );
    assert_eq!(
        at(slab_behind_fin, 32),
        [0; 3],
        "nothing in the door's style"
    );
    assert_eq!(at(floor_behind_door, 0), [0; 3], "the door's shadow");
    // The light the door blocks: what the floor takes where the door casts no shadow.
    let open = door("");
    let open_floor = luxel_rgb_in(&open, &lit(&open), floor_behind_door, 0);
    let open_floor = open_floor.expect("the floor is lit without the door's shadow");
    assert!(open_floor[0] > 40, "{open_floor:?}");
    assert_eq!(
        at(floor_behind_door, 32),
        open_floor,
        "the blocked light, in style 32"
    );
}

/// `surflightGroup` (`q1_light_surflight_group`): two boxes topped with `bolt16` on either side
/// of a wall, one of the world's, one a `func_detail` with `_surflight_group 1`, and two
/// `_surface` templates for `bolt16`: a red one without a group and a blue one of group 1. Each
/// box's top takes the light of its own group's template alone (ericw-tools: 75 0 0 and 0 0 75);
/// the compiler records the detail box's group in the BSP, as its entity is merged away.
#[test]
fn surface_lights_go_only_on_faces_of_their_group() {
    // A box whose top (`map_box`'s fifth plane) is `bolt16`.
    let lamp = |lo, hi| {
        let mut lines: Vec<String> = map_box(lo, hi).lines().map(String::from).collect();
        lines[5] = lines[5].replace("wall", "bolt16");
        lines.join("\n") + "\n"
    };
    let bsp = compiled(&format!(
        "{{\n\"classname\" \"worldspawn\"\n{}{}{}}}\n\
         {{\n\"classname\" \"func_detail\"\n\"_surflight_group\" \"1\"\n{}}}\n{}{}\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"-90 -90 -100\"\n}}\n",
        sealed_room_brushes(),
        lamp([-64.0, -96.0, -128.0], [64.0, -32.0, -112.0]),
        map_box([-128.0, -8.0, -128.0], [128.0, 8.0, -32.0]),
        lamp([-64.0, 32.0, -128.0], [64.0, 96.0, -112.0]),
        light(
            [0.0, -64.0, 0.0],
            "\"_surface\" \"bolt16\"\n\"_color\" \"1 0 0\""
        ),
        light(
            [0.0, 64.0, 0.0],
            "\"_surface\" \"bolt16\"\n\"_surflight_group\" \"1\"\n\"_color\" \"0 0 1\""
        ),
    ));
    let lighting = lit(&bsp);
    let top = |y| {
        luxel_rgb(&bsp, &lighting, 0, DVec3::new(0.0, y, -112.0), DVec3::Z)
            .expect("the box's top is lit")
    };
    let [r, g, b] = top(-64.0);
    assert!(
        r > 40 && g == 0 && b == 0,
        "the world's box: {:?}",
        [r, g, b]
    );
    let blue = top(64.0);
    assert_eq!(
        blue,
        [0, 0, r],
        "the detail box: the blue template's light alone"
    );
}
