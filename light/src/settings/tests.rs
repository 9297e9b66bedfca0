use super::*;
use quake_formats::entities::parse_entities;

fn resolve_text(world: &str, overrides: &Overrides) -> (Settings, Vec<SettingWarning>) {
    let (settings, told) = resolve_told(world, overrides);
    (settings, told.warnings)
}

fn resolve_told(world: &str, overrides: &Overrides) -> (Settings, Told) {
    let entities = parse_entities(world).expect("parse");
    let world = World {
        index: 0,
        entity: &entities[0],
    };
    Settings::resolve(Some(world), overrides)
}

/// The run tells each setting given a value and where it came from, as ericw-tools' options
/// summary does.
#[test]
fn the_settings_chosen_say_where_they_came_from() {
    let world = r#"{ "classname" "worldspawn" "_sunlight2" "40" "_bounce" "2" }"#;
    let overrides = Overrides {
        bounce: Some(1),
        dirt: Some(true),
        ..Overrides::default()
    };
    let (_, told) = resolve_told(world, &overrides);
    let said: Vec<String> = told.chosen.iter().map(ToString::to_string).collect();
    assert_eq!(
        said,
        [
            "sunlight2 40 (worldspawn \"_sunlight2\")",
            "dirt 1 (command line)",
            "bounce 1 (command line)"
        ]
    );
}

#[test]
fn the_command_line_wins_over_worldspawn_which_wins_over_the_default() {
    let world = r#"{ "classname" "worldspawn" "_dist" "2" "_range" "0.7" "light" "5" "_sunlight_mangle" "0 -45 0" "_gamma" " " }"#;
    let overrides = Overrides {
        range: Some(0.9),
        ..Overrides::default()
    };
    let (s, warnings) = resolve_text(world, &overrides);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(s.dist, 2.0);
    assert_eq!(s.range, 0.9);
    assert_eq!(s.minlight, 5.0, "`light` stands for `_minlight`");
    assert_eq!(s.sun_mangle, DVec3::new(0.0, -45.0, 0.0));
    assert_eq!(s.gamma, 1.0, "a blank value is absent");
    assert_eq!(s.bounce, 0);
    assert_eq!(
        Settings::resolve(None, &Overrides::default()).0,
        Settings::default()
    );
}

#[test]
fn worldspawn_values_out_of_range_or_unreadable_warn_and_fall_back() {
    let world = r#"{ "classname" "worldspawn" "_dirtangle" "120" "_gamma" "0" "_bounce" "1.5" "_sunlight_color" "255 200" "_bouncescale" "-2" }"#;
    let (s, warnings) = resolve_text(world, &Overrides::default());
    assert_eq!(s.dirt_angle, 90.0, "clamped");
    assert_eq!(s.gamma, 1.0, "the default");
    assert_eq!(s.bounce, 0);
    assert_eq!(s.sunlight_color, Color::WHITE);
    assert_eq!(s.bounce_scale, 0.0);
    let messages: Vec<String> = warnings.iter().map(ToString::to_string).collect();
    assert_eq!(
        messages,
        [
            "entity 0 (worldspawn, line 1 of the entity lump): key \"_gamma\" is \"0\": outside > 0; the default 1 is used",
            "entity 0 (worldspawn, line 1 of the entity lump): key \"_sunlight_color\" is \"255 200\": expected three numbers; the default white is used",
            "entity 0 (worldspawn, line 1 of the entity lump): key \"_dirtangle\" is \"120\": outside 1–90 (clamped); 90 is used",
            "entity 0 (worldspawn, line 1 of the entity lump): key \"_bounce\" is \"1.5\": expected a whole number, 0 or more; the default 0 is used",
            "entity 0 (worldspawn, line 1 of the entity lump): key \"_bouncescale\" is \"-2\": outside ≥ 0 (clamped); 0 is used",
        ]
    );
    // ericw-tools' range for `-sunsamples`: 8 to 2048, clamped with a warning.
    for (given, used) in [(0, 8), (4000, 2048)] {
        let overrides = Overrides {
            sunsamples: Some(given),
            ..Overrides::default()
        };
        let (s, told) = Settings::resolve(None, &overrides);
        assert_eq!(s.sunsamples, used);
        assert_eq!(
            told.warnings[0].to_string(),
            format!("--sunsamples {given}: outside 8–2048 (clamped); {used} is used")
        );
    }
}

#[test]
fn flags_and_keys_are_each_declared_once() {
    let mut names: Vec<&str> = TABLE
        .iter()
        .flat_map(|s| std::iter::once(s.flag).chain(s.aliases()))
        .collect();
    let mut keys: Vec<&str> = TABLE.iter().flat_map(|s| s.keys.iter().copied()).collect();
    for list in [&mut names, &mut keys] {
        let n = list.len();
        list.sort_unstable();
        list.dedup();
        assert_eq!(list.len(), n, "repeated: {list:?}");
    }
    for s in TABLE {
        assert!(!s.help.trim().is_empty(), "{} has no help", s.field);
        let default = (s.default)();
        if !written_in_words(&default) {
            assert_eq!(
                (s.check)(&default),
                Ok(()),
                "{}'s default reads back",
                s.field
            );
        }
    }
}

/// `docs/mapping.md` lists every setting with its keys, flag and default as the table declares
/// them. `SLIPGATE_WRITE_DOCS=1 cargo test -p slipgate-light docs` rewrites the list.
#[test]
fn the_docs_list_every_setting_as_declared() {
    crate::docs::check_generated_table(
        "light settings: generated from light/src/settings/mod.rs",
        "light settings",
        &markdown_table(),
    );
}

/// ericw-tools' other spellings of worldspawn's sun and dirt keys (its light.rst lists them):
/// `_sun_light`, `_sun_angle`, `_sun_color` and `_dirty`.
#[test]
fn ericw_tools_other_spellings_of_sun_and_dirt_keys_are_read() {
    let world = r#"{ "classname" "worldspawn" "_sun_light" "150" "_sun_angle" "30 -60 0" "_sun_color" "255 128 0" "_dirty" "1" }"#;
    let (s, warnings) = resolve_text(world, &Overrides::default());
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(s.sunlight, 150.0);
    assert_eq!(s.sun_mangle, DVec3::new(30.0, -60.0, 0.0));
    assert!((s.sunlight_color.0 - DVec3::new(1.0, 128.0 / 255.0, 0.0)).length() < 1e-9);
    assert!(s.dirt);
}
