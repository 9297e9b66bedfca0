//! Lights placed in solid, or on a surface, are moved out before anything is traced, as
//! ericw-tools does: id's maps and many since have lights whose origin lies on a floor or just
//! inside a wall, which light nothing where they stand (their rays start in solid, or below the
//! samples, which sit a unit off their faces).
//!
//! A light counts as in solid as a sample point does (`samples::solid_at`): in a solid or sky
//! leaf of the world, or within `ON_PLANE` of a node's plane with solid on either side, so a
//! light on a floor or on a ceiling is in it. It moves [`NUDGE`] units
//! along the first axis direction (−x, +x, −y, +y, −z, +z) that leaves it in the open. A light
//! that no such step frees is dropped, with a warning: it lights nothing in ericw-tools, whose
//! shadow rays meet the outside of the solid it is in, while ours, cast from the light, would
//! leave that solid through its faces' backs and light the room around it. `_nonudge 1` keeps a
//! light where the mapper put it.

use glam::DVec3;
use quake_formats::Bsp;

use crate::lights::PointLight;

/// How far a light is moved: past the samples, which sit one unit off their faces.
pub const NUDGE: f64 = 2.0;

/// Whether a light at `p` is in solid: the sample points' test, ericw-tools' for lights too.
fn in_solid(bsp: &Bsp, p: DVec3) -> bool {
    crate::samples::solid_at(bsp, p.as_vec3().to_array())
}

/// The first step from `origin` that lies in the open, if any.
fn nudged(bsp: &Bsp, origin: DVec3) -> Option<DVec3> {
    let steps = [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .flat_map(|axis| [-axis, axis])
        .map(|step| origin + step * NUDGE);
    steps.into_iter().find(|&p| !in_solid(bsp, p))
}

/// `p` if it lies in the open, else the first of its steps that does (as a light moves).
pub fn free_point(bsp: &Bsp, p: DVec3) -> Option<DVec3> {
    if in_solid(bsp, p) {
        nudged(bsp, p)
    } else {
        Some(p)
    }
}

/// What [`nudge_out_of_solid`] did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Nudges {
    /// Lights moved.
    pub moved: usize,
    /// Entity indices of lights in solid that no step frees (dropped).
    pub stuck: Vec<usize>,
}

/// Moves every light of `lights` (but those of the entities in `keep`, and those that give no
/// light) out of solid, and drops those no step frees; see the module comment.
pub fn nudge_out_of_solid(bsp: &Bsp, lights: &mut Vec<PointLight>, keep: &[usize]) -> Nudges {
    let mut out = Nudges::default();
    lights.retain_mut(|light| {
        if light.light == 0.0 || keep.contains(&light.entity) || !in_solid(bsp, light.origin) {
            return true;
        }
        match nudged(bsp, light.origin) {
            Some(p) => {
                light.origin = p;
                out.moved += 1;
                true
            }
            None => {
                out.stuck.push(light.entity);
                false
            }
        }
    });
    out
}
