//! Reading a light or brush entity's keys, naming the entity and key when one does not read.

use glam::DVec3;
use quake_formats::entities::Entity;

use crate::error::LightError;
use crate::settings::{Given, SettingWarning, normalize_color};

/// Reads a numeric key of entity `index`, naming the entity on failure.
pub struct Keys<'a> {
    /// The entity.
    pub entity: &'a Entity,
    /// Its place in the lump.
    pub index: usize,
}

impl Keys<'_> {
    pub fn bad(&self, key: &str, want: &str) -> LightError {
        LightError::Entity {
            index: self.index,
            classname: self.entity.classname().to_string(),
            detail: format!(
                "key \"{key}\" is \"{}\", expected {want}",
                self.entity.get(key).unwrap_or("")
            ),
        }
    }

    /// A warning that `key` (present) is not taken as written: `problem` says why and what is
    /// used instead.
    pub fn warning(&self, key: &'static str, problem: &str) -> SettingWarning {
        SettingWarning {
            given: Given::Key {
                entity: self.index,
                classname: self.entity.classname().to_string(),
                key,
            },
            value: self.entity.get(key).unwrap_or("").to_string(),
            problem: problem.to_string(),
        }
    }

    pub fn float(&self, key: &str) -> Result<Option<f64>, LightError> {
        match self.entity.get(key) {
            None => Ok(None),
            Some(v) if v.trim().is_empty() => Ok(None),
            Some(_) => self
                .entity
                .get_float(key)
                .filter(|f| f.is_finite())
                .map(Some)
                .ok_or_else(|| self.bad(key, "a number")),
        }
    }

    /// The first of `keys` that is present.
    pub fn float_any(&self, keys: &[&str]) -> Result<Option<f64>, LightError> {
        for k in keys {
            if let Some(v) = self.float(k)? {
                return Ok(Some(v));
            }
        }
        Ok(None)
    }

    pub fn vec3(&self, key: &str) -> Result<Option<DVec3>, LightError> {
        match self.entity.get(key) {
            None => Ok(None),
            Some(v) if v.trim().is_empty() => Ok(None),
            Some(_) => self
                .entity
                .get_floats::<3>(key)
                .filter(|f| f.iter().all(|c| c.is_finite()))
                .map(|[x, y, z]| Some(DVec3::new(x, y, z)))
                .ok_or_else(|| self.bad(key, "three numbers")),
        }
    }

    /// A colour in 0..255 or 0..1 notation, as 1.0 = full channel.
    pub fn color_any(&self, keys: &[&str]) -> Result<DVec3, LightError> {
        for k in keys {
            if let Some(c) = self.vec3(k)? {
                return Ok(normalize_color(c));
            }
        }
        Ok(DVec3::new(1.0, 1.0, 1.0))
    }

    pub fn style(&self) -> Result<u8, LightError> {
        match self.float("style")? {
            None => Ok(0),
            Some(s) if s.fract() == 0.0 && (0.0..=254.0).contains(&s) => Ok(s as u8),
            Some(_) => Err(self.bad("style", "a whole number from 0 to 254")),
        }
    }
}
