//! The `settings!` macro: one declaration per setting becomes the typed [`super::Settings`],
//! the [`super::Overrides`] a run is given, the [`super::TABLE`] the command line and the docs
//! are built from, and the resolution of worldspawn keys against the given values.

/// What the table says about one setting, for the command line, messages and the docs.
#[derive(Debug, Clone, Copy)]
pub struct Setting {
    /// The field of [`super::Settings`] and [`super::Overrides`] it fills.
    pub field: &'static str,
    /// Its command-line flag (`--flag`): the declared one, else its first worldspawn key
    /// without the underscore, as ericw-tools takes every worldspawn key as an option.
    pub flag: &'static str,
    /// Another spelling of the flag (ericw-tools').
    pub alias: Option<&'static str>,
    /// The flag's value when it is given without one (`--bounce` = `--bounce=1`).
    pub missing: Option<&'static str>,
    /// The worldspawn keys that set it, the first present one winning.
    pub keys: &'static [&'static str],
    /// What its values mean.
    pub help: &'static str,
    /// The values it takes.
    pub range: super::Range,
    /// Its flag is a switch (takes no value).
    pub switch: bool,
    /// Numbers its flag's value may be given as, each its own argument (`--lightgrid_dist 16 16
    /// 32`).
    pub words: usize,
    /// Its default, as the docs write it.
    pub default: fn() -> String,
    /// Whether a flag's argument reads as a value of the setting (else what was expected).
    pub check: fn(&str) -> Result<(), &'static str>,
}

impl Setting {
    /// The flag's other spellings: the declared alias, and each worldspawn key without its
    /// underscore (`-sunlight2`, `-minlight_dirt`), as ericw-tools takes them.
    pub fn aliases(&self) -> Vec<&'static str> {
        let mut out: Vec<&'static str> = Vec::new();
        let keys = self.keys.iter().map(|k| without_underscore(k));
        for name in self.alias.into_iter().chain(keys) {
            if name != self.flag && !out.contains(&name) {
                out.push(name);
            }
        }
        out
    }
}

/// A worldspawn key as a flag: without its leading underscore.
pub const fn without_underscore(key: &'static str) -> &'static str {
    match key.as_bytes() {
        [b'_', rest @ ..] => match std::str::from_utf8(rest) {
            Ok(name) => name,
            Err(_) => key,
        },
        _ => key,
    }
}

/// Declares the settings. Each entry reads
///
/// ```text
/// /// Help text (the flag's help, the docs' meaning, the fields' doc comment).
/// field: Type = default, flag "name" [alias "other"] [missing "value"], keys ["_key", ...], range Range::...;
/// ```
///
/// with `flag ...,` left out for a setting whose flag is its first key without the underscore,
/// and `keys []` for one only the command line sets. `Type` implements
/// [`super::SettingValue`].
macro_rules! settings {
    ($(
        $(#[doc = $doc:literal])+
        $field:ident: $ty:ty = $default:expr,
        $(flag $flag:literal $(alias $alias:literal)? $(missing $missing:literal)?,)?
        keys [$($key:literal),*],
        range $range:expr;
    )*) => {
        /// Every setting of a run, resolved: the command line's value, else worldspawn's, else
        /// the default.
        #[derive(Debug, Clone, PartialEq)]
        pub struct Settings {
            $($(#[doc = $doc])+ pub $field: $ty,)*
        }

        impl Default for Settings {
            fn default() -> Settings {
                Settings { $($field: $default,)* }
            }
        }

        /// The settings a run is given (on the command line): each given one wins over
        /// worldspawn's key.
        #[derive(Debug, Clone, Default, PartialEq)]
        pub struct Overrides {
            $($(#[doc = $doc])+ pub $field: Option<$ty>,)*
        }

        /// Every setting, in the order of their declarations.
        pub static TABLE: &[Setting] = &[$(Setting {
            field: stringify!($field),
            flag: settings!(@flag [$($flag)?] [$($key),*]),
            alias: settings!(@opt $($($alias)?)?),
            missing: settings!(@opt $($($missing)?)?),
            keys: &[$($key),*],
            help: concat!($($doc),+),
            range: $range,
            switch: <$ty as SettingValue>::SWITCH,
            words: <$ty as SettingValue>::WORDS,
            default: || <$ty as SettingValue>::show(&$default),
            check: |text| match <$ty as SettingValue>::read(text) {
                Some(Ok(_)) => Ok(()),
                Some(Err(expected)) => Err(expected),
                None => Err("a value"),
            },
        }),*];

        impl Settings {
            /// Each setting from `overrides`, else from worldspawn (`world`), else its default;
            /// and the warnings for values that did not read or lay outside their range, and
            /// where each value not left at its default came from.
            pub fn resolve(
                world: Option<World>,
                overrides: &Overrides,
            ) -> (Settings, Told) {
                let mut told = Told::default();
                let settings = Settings {
                    $($field: resolve(
                        Declared {
                            given_as: settings!(@flag [$($flag)?] [$($key),*]),
                            keys: &[$($key),*],
                            range: $range,
                        },
                        $default,
                        overrides.$field.clone(),
                        world,
                        &mut told,
                    ),)*
                };
                (settings, told)
            }
        }

        impl Overrides {
            /// Sets the setting whose field is `field` from a flag's argument `text`.
            ///
            /// # Errors
            /// What was expected, when `text` does not read as the setting's value or no
            /// setting has that field.
            pub fn set(&mut self, field: &str, text: &str) -> Result<(), String> {
                match field {
                    $(stringify!($field) => {
                        self.$field = Some(given::<$ty>(text)?);
                    })*
                    _ => return Err(format!("no setting is called {field}")),
                }
                Ok(())
            }
        }
    };
    (@flag [$flag:literal] [$($key:literal),*]) => { $flag };
    (@flag [] [$key:literal $(, $rest:literal)*]) => { without_underscore($key) };
    (@opt) => { None };
    (@opt $x:literal) => { Some($x) };
}

pub(super) use settings;
