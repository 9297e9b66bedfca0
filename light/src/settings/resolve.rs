//! A setting's value from what the run was given and what worldspawn says, with warnings for
//! values light does not take as they are.

use std::fmt;

use quake_formats::entities::Entity;

use super::{Range, SettingValue};

/// Worldspawn, where map-wide keys are read.
#[derive(Debug, Clone, Copy)]
pub struct World<'a> {
    /// Its place in the entity lump.
    pub index: usize,
    /// The entity.
    pub entity: &'a Entity,
}

/// What resolving one setting needs of its declaration.
#[derive(Debug, Clone, Copy)]
pub struct Declared {
    /// How a value given to the run is named in warnings: its flag, without dashes.
    pub given_as: &'static str,
    /// Its worldspawn keys, the first present one winning.
    pub keys: &'static [&'static str],
    /// The values it takes.
    pub range: Range,
}

/// Where a value light warns about was given.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Given {
    /// A key of an entity.
    Key {
        /// The entity's place in the lump.
        entity: usize,
        /// Its `classname`.
        classname: String,
        /// Where it starts in the entity lump's text (0: unknown).
        line: usize,
        /// The key.
        key: &'static str,
    },
    /// Given to the run (on the command line): its flag, without dashes.
    Run(&'static str),
}

impl Given {
    /// Key `key` of `entity`, the `index`th of the lump.
    pub fn key(index: usize, entity: &Entity, key: &'static str) -> Given {
        Given::Key {
            entity: index,
            classname: entity.classname().to_string(),
            line: entity.line,
            key,
        }
    }
}

/// A setting's value light did not take as given, and what it did instead.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SettingWarning {
    /// Where the value was given.
    pub given: Given,
    /// The value as it was written.
    pub value: String,
    /// What is wrong with it and which value is used.
    pub problem: String,
}

impl fmt::Display for SettingWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.given {
            Given::Key {
                entity,
                classname,
                line: 0,
                key,
            } => write!(
                f,
                "entity {entity} ({classname}): key \"{key}\" is \"{}\": {}",
                self.value, self.problem
            ),
            Given::Key {
                entity,
                classname,
                line,
                key,
            } => write!(
                f,
                "entity {entity} ({classname}, line {line} of the entity lump): key \"{key}\" is \"{}\": {}",
                self.value, self.problem
            ),
            Given::Run(name) => write!(f, "--{name} {}: {}", self.value, self.problem),
        }
    }
}

/// A setting that is not at its default, its value and where it was given: what a run tells
/// of its settings, as ericw-tools' options summary does.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChosenSetting {
    /// The setting's flag, without dashes.
    pub flag: &'static str,
    /// Its value, as messages write it.
    pub value: String,
    /// Where it was given.
    pub given: Given,
}

impl fmt::Display for ChosenSetting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.given {
            Given::Run(_) => write!(f, "{} {} (command line)", self.flag, self.value),
            Given::Key { key, .. } => {
                write!(f, "{} {} (worldspawn \"{key}\")", self.flag, self.value)
            }
        }
    }
}

/// A flag's argument as the setting's value.
pub fn given<T: SettingValue>(text: &str) -> Result<T, String> {
    match T::read(text) {
        Some(Ok(value)) => Ok(value),
        Some(Err(expected)) => Err(format!("expected {expected}")),
        None => Err("expected a value".to_string()),
    }
}

/// What resolving the settings tells besides their values.
#[derive(Debug, Default)]
pub struct Told {
    /// Values not taken as given.
    pub warnings: Vec<SettingWarning>,
    /// Settings given a value (on the command line or in worldspawn), in the table's order.
    pub chosen: Vec<ChosenSetting>,
}

/// The setting `declared`: the value `given` to the run, else the first of its keys present
/// in `world`, else `default`; a value outside the range is held to it, and one that does not
/// read leaves the default, each with a warning. A value taken is told in `told.chosen`.
pub fn resolve<T: SettingValue>(
    declared: Declared,
    default: T,
    given: Option<T>,
    world: Option<World>,
    told: &mut Told,
) -> T {
    let warnings = &mut told.warnings;
    let (value, given, text) = match given {
        Some(value) => {
            let text = value.show();
            (value, Given::Run(declared.given_as), text)
        }
        None => match world.and_then(|w| first_key::<T>(declared.keys, w)) {
            None => return default,
            Some((at, text, Ok(value))) => (value, at, text),
            Some((given, value, Err(expected))) => {
                let problem = format!(
                    "expected {expected}; the default {} is used",
                    default.show()
                );
                warnings.push(SettingWarning {
                    given,
                    value,
                    problem,
                });
                return default;
            }
        },
    };
    let chosen = |value: &T, given: Given| ChosenSetting {
        flag: declared.given_as,
        value: value.show(),
        given,
    };
    match value.within(declared.range) {
        Ok(value) => {
            told.chosen.push(chosen(&value, given));
            value
        }
        Err(instead) => {
            let range = declared.range.show();
            let (value, problem) = match instead {
                Some(v) => {
                    let problem = format!("outside {range}; {} is used", v.show());
                    (v, problem)
                }
                None => {
                    let problem =
                        format!("outside {range}; the default {} is used", default.show());
                    (default, problem)
                }
            };
            told.chosen.push(chosen(&value, given.clone()));
            told.warnings.push(SettingWarning {
                given,
                value: text,
                problem,
            });
            value
        }
    }
}

/// The first of `keys` `world` holds with a value that is not blank: where it is, its text and
/// what it reads as.
fn first_key<T: SettingValue>(
    keys: &'static [&'static str],
    world: World,
) -> Option<(Given, String, Result<T, &'static str>)> {
    keys.iter().find_map(|&key| {
        let text = world.entity.get(key)?;
        let read = T::read(text)?;
        let at = Given::key(world.index, world.entity, key);
        Some((at, text.to_string(), read))
    })
}
