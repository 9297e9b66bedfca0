//! `misc_external_map` prefabs, as ericw-tools' qbsp has them: the point entity names another
//! `.map` (`_external_map`, relative to the map that names it), whose brushes (worldspawn's and
//! every brush entity's; its point entities and keys are ignored) are scaled
//! (`_external_map_scale`), rotated (`_external_map_angles` "pitch yaw roll", or the yaw alone in
//! `_external_map_angle`), moved to the entity's `origin`, and become one entity of class
//! `_external_map_classname` that keeps the entity's other keys. Prefabs may hold prefabs.

use crate::map::{MapBrush, MapEntity, MapFace, MapFile, parse_map, read_map_text};
use crate::texinfo::Projection;
use glam::{DAffine3, DMat3, DVec3};

use std::path::{Path, PathBuf};

pub(crate) const PREFAB_CLASSNAME: &str = "misc_external_map";
const KEY_FILE: &str = "_external_map";
const KEY_CLASSNAME: &str = "_external_map_classname";
const KEY_ANGLES: &str = "_external_map_angles";
const KEY_ANGLE: &str = "_external_map_angle";
const KEY_SCALE: &str = "_external_map_scale";

/// A prefab that cannot be imported, named by the entity that asks for it.
#[derive(Debug, thiserror::Error)]
#[error("{}:{line}: entity {entity} ({PREFAB_CLASSNAME}): {message}", file.display())]
pub struct PrefabError {
    /// The map holding the `misc_external_map`.
    pub file: PathBuf,
    /// The entity's line in that map.
    pub line: usize,
    /// The entity's index in that map.
    pub entity: usize,
    /// What is wrong.
    pub message: String,
}

/// Replace every `misc_external_map` of `map` (read from `path`) with the entity it makes.
pub fn expand_prefabs(map: MapFile, path: &Path) -> Result<MapFile, PrefabError> {
    let mut chain = vec![identity_of(path)];
    expand(map, path, &mut chain)
}

/// A file's identity for recursion checks: its canonical path when it exists.
fn identity_of(path: &Path) -> PathBuf {
    path.canonicalize().unwrap_or_else(|_| path.to_path_buf())
}

/// `chain` holds the files being expanded, outermost first.
fn expand(map: MapFile, path: &Path, chain: &mut Vec<PathBuf>) -> Result<MapFile, PrefabError> {
    let mut entities = Vec::with_capacity(map.entities.len());
    for (index, ent) in map.entities.into_iter().enumerate() {
        if ent.entity.classname() != PREFAB_CLASSNAME {
            entities.push(ent);
            continue;
        }
        let fail = |message: String| PrefabError {
            file: path.to_path_buf(),
            line: ent.line,
            entity: index,
            message,
        };
        entities.push(import(&ent, path, chain).map_err(fail)?);
    }
    Ok(MapFile { entities })
}

/// The entity one `misc_external_map` becomes; errors are messages for [`PrefabError`].
fn import(ent: &MapEntity, path: &Path, chain: &mut Vec<PathBuf>) -> Result<MapEntity, String> {
    let name = ent
        .entity
        .get(KEY_FILE)
        .filter(|n| !n.is_empty())
        .ok_or_else(|| format!("no \"{KEY_FILE}\" key naming the .map to import"))?;
    let classname = ent
        .entity
        .get(KEY_CLASSNAME)
        .filter(|c| !c.is_empty())
        .ok_or_else(|| format!("no \"{KEY_CLASSNAME}\" key saying what entity the prefab becomes"))?
        .to_string();
    let transform = Transform::of(ent)?;
    let file = prefab_path(path, name);
    let id = identity_of(&file);
    if chain.contains(&id) {
        let names: Vec<String> = chain
            .iter()
            .chain([&id])
            .map(|p| p.display().to_string())
            .collect();
        return Err(format!("recursive prefab: {}", names.join(" -> ")));
    }
    let text = read_map_text(&file).map_err(|e| format!("{}: {e}", file.display()))?;
    let prefab = parse_map(&file, &text).map_err(|e| e.to_string())?;
    chain.push(id);
    let prefab = expand(prefab, &file, chain).map_err(|e| e.to_string());
    chain.pop();
    let brushes = prefab?
        .entities
        .into_iter()
        .flat_map(|e| e.brushes)
        .map(|b| transform.brush(b))
        .collect();

    let mut entity = ent.entity.clone();
    for key in [KEY_FILE, KEY_CLASSNAME, KEY_ANGLES, KEY_ANGLE, KEY_SCALE] {
        entity.remove(key);
    }
    entity.set("classname", classname);
    // The brushes are placed in world space; a brush entity built from them sits at the origin.
    entity.set("origin", "0 0 0");
    Ok(MapEntity {
        entity,
        brushes,
        line: ent.line,
    })
}

/// `name` relative to the directory of the map that names it, unless absolute.
fn prefab_path(map: &Path, name: &str) -> PathBuf {
    let name = Path::new(name);
    match map.parent() {
        Some(dir) if name.is_relative() => dir.join(name),
        _ => name.to_path_buf(),
    }
}

/// Where a prefab's points go, with the inverse transpose for texture axes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Transform {
    place: DAffine3,
    /// The linear part's inverse transpose: texture axes map by it so that texels stay on the
    /// points.
    axes: DMat3,
    /// The determinant is negative (a mirror): face point order flips with it.
    mirrors: bool,
}

fn floats(text: &str) -> Option<Vec<f64>> {
    text.split_whitespace()
        .map(|w| w.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect()
}

impl Transform {
    fn of(ent: &MapEntity) -> Result<Transform, String> {
        let e = &ent.entity;
        let key_floats = |key: &str| e.get(key).map(|v| (v, floats(v)));
        let [pitch, yaw, roll] = match (key_floats(KEY_ANGLES), key_floats(KEY_ANGLE)) {
            (Some((_, Some(v))), _) if v.len() == 3 => [v[0], v[1], v[2]],
            (Some((text, _)), _) => {
                return Err(format!(
                    "\"{KEY_ANGLES}\" is {text:?}, not three numbers (pitch yaw roll)"
                ));
            }
            (None, Some((_, Some(v)))) if v.len() == 1 => [0.0, v[0], 0.0],
            (None, Some((text, _))) => {
                return Err(format!("\"{KEY_ANGLE}\" is {text:?}, not a number (yaw)"));
            }
            (None, None) => [0.0; 3],
        };
        let scale = match key_floats(KEY_SCALE) {
            None => DVec3::new(1.0, 1.0, 1.0),
            Some((_, Some(v))) if v.len() == 1 => DVec3::new(v[0], v[0], v[0]),
            Some((_, Some(v))) if v.len() == 3 => DVec3::new(v[0], v[1], v[2]),
            Some((text, _)) => {
                return Err(format!(
                    "\"{KEY_SCALE}\" is {text:?}, not one number or three (x y z)"
                ));
            }
        };
        if (0..3).any(|i| scale[i] == 0.0) {
            return Err(format!("\"{KEY_SCALE}\" has a zero scale"));
        }
        let offset = match e.get_floats::<3>("origin") {
            Some([x, y, z]) => DVec3::new(x, y, z),
            None if e.get("origin").is_some() => {
                return Err("\"origin\" is not three numbers".to_string());
            }
            None => DVec3::ZERO,
        };
        let rotation = rotation(pitch, yaw, roll);
        Ok(Transform {
            place: DAffine3::from_mat3_translation(rotation * DMat3::from_diagonal(scale), offset),
            // (R S)^-T = R^-T S^-T = R S^-1 for a rotation R and a diagonal S.
            axes: rotation * DMat3::from_diagonal(scale.recip()),
            mirrors: scale.x * scale.y * scale.z < 0.0,
        })
    }

    fn point(&self, p: DVec3) -> DVec3 {
        self.place.transform_point3(p)
    }

    fn brush(&self, brush: MapBrush) -> MapBrush {
        MapBrush {
            faces: brush.faces.into_iter().map(|f| self.face(f)).collect(),
            line: brush.line,
        }
    }

    /// The face moved, its texture moved with it: written as explicit (Valve) axes, which every
    /// rotation keeps exact.
    fn face(&self, face: MapFace) -> MapFace {
        let projection = match face.plane(DVec3::ZERO) {
            Some(plane) => {
                let vecs = face.projection.vecs(&plane);
                let [u, v] = vecs.map(|row| {
                    let axis = self.axes * DVec3::new(row[0], row[1], row[2]);
                    [
                        axis.x,
                        axis.y,
                        axis.z,
                        row[3] - axis.dot(self.place.translation),
                    ]
                });
                Projection::Valve {
                    u,
                    v,
                    scale: [1.0, 1.0],
                }
            }
            // A face without a plane is reported as a bad brush later; keep it as written.
            None => face.projection,
        };
        let [a, b, c] = face.points.map(|p| self.point(p));
        MapFace {
            points: if self.mirrors { [a, c, b] } else { [a, b, c] },
            projection,
            ..face
        }
    }
}

/// Rotation by `roll` about +X, then `pitch` about +Y (positive pitch turns +X down), then
/// `yaw` about +Z, in degrees.
fn rotation(pitch: f64, yaw: f64, roll: f64) -> DMat3 {
    snap(
        DMat3::from_rotation_z(yaw.to_radians())
            * (DMat3::from_rotation_y(pitch.to_radians())
                * DMat3::from_rotation_x(roll.to_radians())),
    )
}

/// Right angles give exact 0 and ±1, not 6e-17: brushes turned by them stay on the grid.
fn snap(m: DMat3) -> DMat3 {
    let snapped = |x: f64| {
        let r = x.round();
        if (x - r).abs() < 1e-12 { r } else { x }
    };
    DMat3::from_cols_array(&m.to_cols_array().map(snapped))
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::entities::Entity;
    use quake_formats::geom::DVec3Ext;

    fn entity(pairs: &[(&str, &str)]) -> MapEntity {
        MapEntity {
            entity: Entity {
                pairs: pairs
                    .iter()
                    .map(|(k, v)| (k.to_string(), v.to_string()))
                    .collect(),
                line: 1,
            },
            brushes: Vec::new(),
            line: 1,
        }
    }

    #[test]
    fn yaw_pitch_and_scale_move_points_as_documented() {
        let t = Transform::of(&entity(&[
            ("_external_map_angle", "90"),
            ("origin", "100 0 0"),
        ]))
        .expect("transform");
        // Facing +X, a yaw of 90 faces +Y.
        assert_eq!(
            t.point(DVec3::new(1.0, 0.0, 0.0)),
            DVec3::new(100.0, 1.0, 0.0)
        );
        let t = Transform::of(&entity(&[("_external_map_angles", "90 0 0")])).expect("pitch");
        assert_eq!(
            t.point(DVec3::new(1.0, 0.0, 0.0)),
            DVec3::new(0.0, 0.0, -1.0)
        );
        let t = Transform::of(&entity(&[("_external_map_scale", "2 -1 1")])).expect("scale");
        assert_eq!(
            t.point(DVec3::new(1.0, 1.0, 1.0)),
            DVec3::new(2.0, -1.0, 1.0)
        );
        assert!(t.mirrors);
    }

    #[test]
    fn bad_keys_are_errors() {
        for pairs in [
            [("_external_map_scale", "0")],
            [("_external_map_angles", "90 0")],
            [("_external_map_angle", "north")],
        ] {
            assert!(Transform::of(&entity(&pairs)).is_err(), "{pairs:?}");
        }
    }

    #[test]
    fn texture_axes_follow_the_points() {
        let face = MapFace {
            points: [
                DVec3::new(0.0, 0.0, 64.0),
                DVec3::new(0.0, 64.0, 64.0),
                DVec3::new(64.0, 0.0, 64.0),
            ],
            texture: "t".into(),
            projection: Projection::Standard {
                shift: [8.0, 4.0],
                rotation: 30.0,
                scale: [0.5, 2.0],
            },
            line: 1,
        };
        let t = Transform::of(&entity(&[
            ("_external_map_angles", "10 37 5"),
            ("_external_map_scale", "2 -1 1.5"),
            ("origin", "17 -40 3"),
        ]))
        .expect("transform");
        let before = face
            .projection
            .vecs(&face.plane(DVec3::ZERO).expect("plane"));
        let moved = t.face(face.clone());
        let after = moved
            .projection
            .vecs(&moved.plane(DVec3::ZERO).expect("plane"));
        let st = |vecs: &[[f64; 4]; 2], p: DVec3| {
            vecs.map(|r| DVec3::new(r[0], r[1], r[2]).dot(p) + r[3])
        };
        for p in [DVec3::new(3.0, 5.0, 64.0), DVec3::new(-20.0, 7.0, 64.0)] {
            let [s0, t0] = st(&before, p);
            let [s1, t1] = st(&after, t.point(p));
            assert!((s0 - s1).abs() < 1e-9 && (t0 - t1).abs() < 1e-9);
        }
        // The mirrored face still faces out of its brush: normals map by the inverse transpose.
        let n0 = face.plane(DVec3::ZERO).expect("plane").normal;
        let expected = (t.axes * n0).normalized().expect("normal");
        let normal = moved.plane(DVec3::ZERO).expect("plane").normal;
        assert!(normal.dot(expected) > 0.999, "{normal:?} vs {expected:?}");
    }
}
