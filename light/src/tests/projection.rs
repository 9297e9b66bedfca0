//! Projected textures (`_project_texture`): the light shines the picture where it falls and
//! nothing around it.

use glam::DVec3;

use super::ericw_cases::{floor_rgb, light, lit};
use super::room_bsp;
use crate::lights::projection::{ProjectionKeys, Projector};
use quake_formats::palette::Palette;

/// The light over the room's floor, shining straight down, with `keys` added.
fn room(keys: &str) -> quake_formats::Bsp {
    room_bsp(&light(
        [0.0, 0.0, 100.0],
        &format!("\"light\" \"300\"\n{keys}"),
    ))
}

#[test]
fn a_projected_picture_tints_the_light_where_it_falls_and_nothing_around_it() {
    let projected =
        "\"_project_texture\" \"wall\"\n\"_project_mangle\" \"0 -90 0\"\n\"_project_fov\" \"30\"";
    let (plain_bsp, bsp) = (room(""), room(projected));
    let (plain, lighting) = (lit(&plain_bsp), lit(&bsp));
    assert!(lighting.warnings.is_empty(), "{:?}", lighting.warnings);
    // 30 degrees wide from 228 units up: the picture covers the floor within 61 units of the
    // middle.
    for (x, y) in [(100.0, 0.0), (0.0, -100.0), (90.0, 90.0)] {
        let outside = floor_rgb(&bsp, &lighting, x, y).unwrap_or([0; 3]);
        assert_eq!(outside, [0; 3], "at {x} {y}");
        let lit_plain = floor_rgb(&plain_bsp, &plain, x, y).expect("lit");
        assert!(lit_plain[0] > 5, "{lit_plain:?}");
    }
    // Inside, the plain light times twice the picture's colour there.
    let texture = bsp
        .textures
        .textures
        .iter()
        .flatten()
        .find(|t| t.name() == "wall")
        .expect("the wall texture");
    let keys = ProjectionKeys {
        entity: 0,
        origin: DVec3::new(0.0, 0.0, 100.0),
        texture: "wall".into(),
        angles: DVec3::new(0.0, -90.0, 0.0),
        fov: 30.0,
    };
    let picture = Projector::new(&keys, texture, &Palette::slipgate()).expect("pixels");
    for (x, y) in [(0.0, 0.0), (32.0, 16.0), (-16.0, 48.0)] {
        let [got, ..] = floor_rgb(&bsp, &lighting, x, y).expect("lit");
        let [plain_value, ..] = floor_rgb(&plain_bsp, &plain, x, y).expect("lit");
        let tint = picture.tint(DVec3::new(x, y, -128.0 + 1.0)).x;
        let want = f64::from(plain_value) * tint;
        assert!(
            (f64::from(got) - want).abs() <= 2.0 + want * 0.02,
            "at {x} {y}: {got}, plain {plain_value} tinted {want}"
        );
    }
}

#[test]
fn a_picture_the_bsp_lacks_warns_and_the_light_shines_unprojected() {
    let plain_bsp = room("");
    let bsp = room("\"_project_texture\" \"no_such_picture\"\n\"_project_fov\" \"200\"");
    let (plain, lighting) = (lit(&plain_bsp), lit(&bsp));
    let told: Vec<String> = lighting.warnings.iter().map(ToString::to_string).collect();
    for key in [
        "\"_project_texture\" is \"no_such_picture\"",
        "\"_project_fov\" is \"200\"",
    ] {
        assert!(told.iter().any(|w| w.contains(key)), "{key}: {told:?}");
    }
    for (x, y) in [(0.0, 0.0), (100.0, 0.0)] {
        assert_eq!(
            floor_rgb(&bsp, &lighting, x, y),
            floor_rgb(&plain_bsp, &plain, x, y)
        );
    }
}
