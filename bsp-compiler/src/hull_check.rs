//! Whether a compiled BSP's clip hulls agree with the map's brushes: a box swept through the
//! hull as engines do it ([`crate::trace::trace_hull`]) must stop where the same box swept
//! exactly through the solid brushes stops.
//!
//! The exact side grows each brush that blocks the world's hulls by the hull's box in `f64`: its
//! own planes plus every bevel (the bounding box's axial planes, and planes along an edge and an
//! axis that touch the brush at that edge with the whole brush behind them), each pushed out by
//! the box's support along its normal. Those are all the facets of the brush's Minkowski sum
//! with the box, so a point is inside the grown brush exactly when the box there overlaps the
//! brush, and a segment clipped against the planes gives the exact first contact.
//!
//! Moves start at random points of the world's open space that the box reaches from a point
//! entity (hull 0 open there, the box at least [`START_CLEARANCE`] from every brush, and a
//! straight sweep to it from the entity or an earlier start that touches no brush: the compiler
//! fills each hull's space no entity reaches), go a random direction and length, and are traced
//! both ways. A hull trace that stops first must stop next to a brush: the gap is how far its
//! stop is from every grown brush (the largest plane distance, never more than the true
//! distance). A hull trace that goes further must not have passed through a brush: the gap is
//! how deep its path reached inside one. An agreeing trace stops [`crate::trace`]'s epsilon
//! (1/32) short of a brush; it may also stop where its path passes within that epsilon of a
//! brush's edge without touching it, as engines do.

use crate::gather::{EntityBrushes, occupant};
use crate::hulls::{HULL_BOXES, supporting_plane};
use crate::map::{MapBrush, MapFile};
use crate::texinfo::TextureRole;
use crate::trace::{HullTrace, trace_hull};
use glam::{DVec3, Vec3};
use quake_formats::bsp::contents;
use quake_formats::geom::DVec3Ext;
use quake_formats::geom::{Bounds, ON_EPSILON, Plane, Winding};
use quake_formats::rng::SplitMix64;
use quake_formats::{Bsp, FormatError};

/// How far (units) a hull trace that stops first may stop from every brush, and how deep a hull
/// trace may reach into one: the engine's trace epsilon (1/32), planes stored in `f32` (under
/// 1/1000 within ±4096) and the compiler's plane snapping (`DIST_EPSILON`), with room to spare.
pub const HULL_AGREEMENT_TOLERANCE: f64 = 0.1;

/// Moves start where the box is at least this far from every brush, so rounding a start point
/// to `f32` never puts it in solid.
pub const START_CLEARANCE: f64 = 0.5;

/// Start points tried per trace before sampling gives up (a world with little open space).
const TRIES_PER_TRACE: usize = 200;

/// Disagreements kept as examples.
const EXAMPLES: usize = 10;

/// What [`hull_agreement`] traces.
#[derive(Debug, Clone)]
pub struct HullCheckOptions {
    /// Moves to trace.
    pub traces: usize,
    /// Seed of the random starts, directions and lengths.
    pub seed: u64,
    /// 1 (player) or 2 (shambler).
    pub hull: usize,
    /// Longest move, in units.
    pub max_move: f64,
}

impl Default for HullCheckOptions {
    fn default() -> Self {
        HullCheckOptions {
            traces: 2000,
            seed: 1,
            hull: 1,
            max_move: 128.0,
        }
    }
}

/// One move on which the hull and the brushes disagree.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HullDisagreement {
    /// Where the move starts.
    pub start: [f64; 3],
    /// Where the move would end unblocked.
    pub end: [f64; 3],
    /// Where the hull trace stopped.
    pub hull_end: [f64; 3],
    /// The hull trace called the start solid.
    pub hull_start_solid: bool,
    /// Where the exact sweep stopped.
    pub exact_end: [f64; 3],
    /// How far from every brush the hull stopped, or how deep into one it went (for a hull that
    /// calls the start solid: how far the box there is from every brush).
    pub gap: f64,
}

/// What [`hull_agreement`] measured.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct HullAgreement {
    /// Moves traced (fewer than asked when open space was too hard to find).
    pub traces: usize,
    /// Moves whose stops are more than [`HULL_AGREEMENT_TOLERANCE`] apart.
    pub disagreements: usize,
    /// The largest gap of any move, agreeing or not.
    pub worst_gap: f64,
    /// The first few disagreements.
    pub examples: Vec<HullDisagreement>,
}

/// Why [`hull_agreement`] could not measure.
#[derive(Debug, thiserror::Error)]
pub enum HullCheckError {
    /// The hull asked for is not 1 or 2.
    #[error("hull {0} is not a clip hull (1 or 2)")]
    NotAClipHull(usize),
    /// The BSP fails `quake_formats::check_usable`.
    #[error(transparent)]
    Unusable(#[from] FormatError),
}

/// Trace `options.traces` random moves of hull `options.hull`'s box through `bsp`'s world and
/// through `map`'s brushes (prefabs already expanded), and count where they disagree.
pub fn hull_agreement(
    map: &MapFile,
    bsp: &Bsp,
    options: &HullCheckOptions,
) -> Result<HullAgreement, HullCheckError> {
    if !(1..=2).contains(&options.hull) {
        return Err(HullCheckError::NotAClipHull(options.hull));
    }
    quake_formats::check_usable(bsp)?;
    let (mins, maxs) = HULL_BOXES[options.hull - 1];
    let solids = world_hull_solids(map, mins, maxs);
    let world = &bsp.models[0];
    let space = Bounds {
        mins: Vec3::from(world.mins).as_dvec3(),
        maxs: Vec3::from(world.maxs).as_dvec3(),
    };
    let mut rng = SplitMix64::new(options.seed);
    let mut out = HullAgreement::default();
    let mut reached = entity_points(map, &solids);
    for _ in 0..options.traces {
        let Some(start) = open_point(bsp, &solids, space, &mut rng, &reached) else {
            break;
        };
        reached.push(start);
        let end = start + random_direction(&mut rng) * rng.range(1.0, options.max_move);
        let end = end.as_vec3().as_dvec3();
        let hull = trace_hull(
            bsp,
            0,
            options.hull,
            start.as_vec3().to_array(),
            end.as_vec3().to_array(),
        );
        let exact = sweep(&solids, start, end);
        let gap = compare(start, &hull, exact, &solids);
        out.traces += 1;
        out.worst_gap = out.worst_gap.max(gap);
        if gap > HULL_AGREEMENT_TOLERANCE {
            out.disagreements += 1;
            if out.examples.len() < EXAMPLES {
                out.examples.push(HullDisagreement {
                    start: start.to_array(),
                    end: end.to_array(),
                    hull_end: Vec3::from(hull.end).as_dvec3().to_array(),
                    hull_start_solid: hull.start_solid,
                    exact_end: start.lerp_monotonic(end, exact).to_array(),
                    gap,
                });
            }
        }
    }
    Ok(out)
}

/// How far the hull's stop is from what the brushes allow (see the module notes).
fn compare(start: DVec3, hull: &HullTrace, exact: f64, solids: &[GrownBrush]) -> f64 {
    if hull.start_solid || hull.all_solid {
        return clearance(solids, start);
    }
    let hull_fraction = f64::from(hull.fraction);
    let hull_end = Vec3::from(hull.end).as_dvec3();
    if hull_fraction < exact {
        clearance(solids, hull_end).max(0.0)
    } else if hull_fraction > exact {
        solids
            .iter()
            .map(|s| s.depth_along(start, hull_end))
            .fold(0.0, f64::max)
    } else {
        0.0
    }
}

/// A brush grown by the hull's box: a point is inside when the box there overlaps the brush.
#[derive(Debug, Clone)]
struct GrownBrush {
    planes: Vec<Plane>,
    bounds: Bounds,
}

/// Whether a map brush of an entity of class `class` is solid in the world's clip hulls, as the
/// compiler builds them: world and detail brushes (sky too) but not liquids, hints or
/// illusionary detail; clip brushes in any entity merged into the world.
fn blocks_world_hulls(class: EntityBrushes, brush: &MapBrush) -> bool {
    let roles: Vec<TextureRole> = brush
        .faces
        .iter()
        .map(|f| TextureRole::of(&f.texture))
        .collect();
    if class == EntityBrushes::Submodel || roles.contains(&TextureRole::Origin) {
        return false;
    }
    if roles.contains(&TextureRole::Clip) {
        return true;
    }
    if roles
        .iter()
        .any(|r| matches!(r, TextureRole::Hint | TextureRole::HintSkip))
    {
        return false;
    }
    match class {
        EntityBrushes::Illusionary | EntityBrushes::VisBlocker => false,
        _ => {
            roles.contains(&TextureRole::Sky)
                || !roles
                    .iter()
                    .any(|r| matches!(r, TextureRole::Liquid(_) | TextureRole::LiquidSkip(_)))
        }
    }
}

/// Every brush solid in the world's hulls, grown by the box `mins..maxs`.
fn world_hull_solids(map: &MapFile, mins: DVec3, maxs: DVec3) -> Vec<GrownBrush> {
    let mut out = Vec::new();
    for (index, entity) in map.entities.iter().enumerate() {
        let class = EntityBrushes::of(index, entity.entity.classname());
        for brush in &entity.brushes {
            if !blocks_world_hulls(class, brush) {
                continue;
            }
            let planes: Option<Vec<Plane>> =
                brush.faces.iter().map(|f| f.plane(DVec3::ZERO)).collect();
            if let Some(grown) = planes.and_then(|p| grow(&p, mins, maxs)) {
                out.push(grown);
            }
        }
    }
    out
}

/// The convex brush bounded by `faces` (outward planes) grown by the box; `None` when the planes
/// bound no volume (the compiler skips such brushes too).
fn grow(faces: &[Plane], mins: DVec3, maxs: DVec3) -> Option<GrownBrush> {
    let windings: Vec<Winding> = faces
        .iter()
        .enumerate()
        .filter_map(|(i, face)| {
            let mut w = Winding::base_for_plane(face);
            for (j, other) in faces.iter().enumerate() {
                if i != j {
                    w = w.clip_front(&other.flipped(), false)?;
                }
            }
            (!w.is_tiny()).then_some(w)
        })
        .collect();
    if windings.len() < 4 {
        return None;
    }
    let points: Vec<DVec3> = windings.iter().flat_map(|w| w.points.clone()).collect();
    let mut bounds = Bounds::EMPTY;
    for &p in &points {
        bounds.add_point(p);
    }
    let mut planes: Vec<Plane> = windings.iter().filter_map(Winding::plane).collect();
    for axis in 0..3 {
        let mut n = DVec3::ZERO;
        n[axis] = 1.0;
        planes.push(Plane::new(n, bounds.maxs[axis]));
        planes.push(Plane::new(-n, -bounds.mins[axis]));
    }
    for w in &windings {
        for (i, &p) in w.points.iter().enumerate() {
            let Some(edge) = (w.points[(i + 1) % w.len()] - p).normalized() else {
                continue;
            };
            for axis in 0..3 {
                let mut a = DVec3::ZERO;
                a[axis] = 1.0;
                let Some(n) = edge.cross(a).normalized() else {
                    continue;
                };
                for n in [n, -n] {
                    let bevel = supporting_plane(n, &points);
                    if bevel.distance(p) >= -ON_EPSILON {
                        planes.push(bevel);
                    }
                }
            }
        }
    }
    for plane in &mut planes {
        plane.dist += support(plane.normal, -maxs, -mins);
    }
    Some(GrownBrush {
        planes,
        bounds: Bounds {
            mins: bounds.mins - maxs,
            maxs: bounds.maxs - mins,
        },
    })
}

/// The largest `n · p` over the box `mins..maxs`.
fn support(n: DVec3, mins: DVec3, maxs: DVec3) -> f64 {
    (0..3).map(|i| (n[i] * mins[i]).max(n[i] * maxs[i])).sum()
}

impl GrownBrush {
    /// The part of the segment `a`→`b` strictly inside, as fractions of it; entering at 0 when
    /// `a` is inside.
    fn inside(&self, a: DVec3, b: DVec3) -> Option<(f64, f64)> {
        let (mut enter, mut leave) = (0.0f64, 1.0f64);
        for plane in &self.planes {
            let (da, db) = (plane.distance(a), plane.distance(b));
            if da >= 0.0 && db >= 0.0 {
                return None;
            }
            if da < 0.0 && db < 0.0 {
                continue;
            }
            let t = da / (da - db);
            if da >= 0.0 {
                enter = enter.max(t);
            } else {
                leave = leave.min(t);
            }
        }
        (enter < leave).then_some((enter, leave))
    }

    /// How deep inside (behind its nearest plane) the segment `a`→`b` reaches; 0 when it stays
    /// out. Depth along the segment is concave (a minimum of linear functions), so a ternary
    /// search finds its peak.
    fn depth_along(&self, a: DVec3, b: DVec3) -> f64 {
        let Some((mut lo, mut hi)) = self.inside(a, b) else {
            return 0.0;
        };
        let depth = |t: f64| -self.clearance(a.lerp_monotonic(b, t));
        for _ in 0..60 {
            let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if depth(m1) < depth(m2) {
                lo = m1;
            } else {
                hi = m2;
            }
        }
        depth((lo + hi) / 2.0).max(0.0)
    }

    /// How far in front of its nearest plane `p` is (negative inside): at most the distance to
    /// the grown brush.
    fn clearance(&self, p: DVec3) -> f64 {
        self.planes
            .iter()
            .map(|plane| plane.distance(p))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// The exact sweep: the fraction of the move `a`→`b` at which the box first touches a brush.
fn sweep(solids: &[GrownBrush], a: DVec3, b: DVec3) -> f64 {
    let reach = Bounds {
        mins: a.min(b),
        maxs: a.max(b),
    };
    solids
        .iter()
        .filter(|s| s.bounds.intersects(&reach))
        .filter_map(|s| s.inside(a, b))
        .fold(1.0, |first, (enter, _)| first.min(enter))
}

/// The least clearance of `p` from any grown brush.
fn clearance(solids: &[GrownBrush], p: DVec3) -> f64 {
    solids
        .iter()
        .map(|s| s.clearance(p))
        .fold(f64::INFINITY, f64::min)
}

/// Reached points tried, nearest first, before a start point is taken to be out of reach.
const REACH_TRIES: usize = 8;

/// Where the map's point entities hold space open for the compiler's fill (as it takes them),
/// where the box there is not inside a brush.
fn entity_points(map: &MapFile, solids: &[GrownBrush]) -> Vec<DVec3> {
    map.entities
        .iter()
        .enumerate()
        .filter(|(_, e)| e.brushes.is_empty())
        .filter_map(|(i, e)| occupant(e, i))
        .map(|o| o.origin)
        .filter(|&p| clearance(solids, p) >= -ON_EPSILON)
        .collect()
}

/// A random point (exact in `f32`) in the world's open space: open in hull 0 (so inside the map,
/// not in the filled outside) with the box clear of every brush by [`START_CLEARANCE`], and
/// reached by a sweep touching no brush from one of the [`REACH_TRIES`] nearest `reached` points.
fn open_point(
    bsp: &Bsp,
    solids: &[GrownBrush],
    space: Bounds,
    rng: &mut SplitMix64,
    reached: &[DVec3],
) -> Option<DVec3> {
    (0..TRIES_PER_TRACE).find_map(|_| {
        let mut p = DVec3::ZERO;
        for i in 0..3 {
            p[i] = rng.range(space.mins[i], space.maxs[i]);
        }
        let p = p.as_vec3().as_dvec3();
        let open = matches!(
            hull0_contents(bsp, p),
            contents::EMPTY | contents::WATER | contents::SLIME | contents::LAVA
        );
        if !open || clearance(solids, p) <= START_CLEARANCE {
            return None;
        }
        let mut nearest: Vec<DVec3> = reached.to_vec();
        let tries = REACH_TRIES.min(nearest.len());
        if tries == 0 {
            return None;
        }
        nearest.select_nth_unstable_by(tries - 1, |a, b| {
            (*a - p)
                .length_squared()
                .total_cmp(&(*b - p).length_squared())
        });
        nearest[..tries]
            .iter()
            .any(|&from| sweep(solids, from, p) >= 1.0)
            .then_some(p)
    })
}

/// The contents of the world's hull 0 at `p` (the file passed the tools' gate, so the walk
/// stays in bounds and ends).
fn hull0_contents(bsp: &Bsp, p: DVec3) -> i32 {
    let mut node = bsp.models[0].head_nodes[0];
    while node >= 0 {
        let n = &bsp.nodes[node as usize];
        let plane = &bsp.planes[n.plane as usize];
        let d = Vec3::from(plane.normal).as_dvec3().dot(p) - f64::from(plane.dist);
        node = n.children[usize::from(d < 0.0)];
    }
    bsp.leafs[(-(node + 1)) as usize].contents
}

/// A direction uniform over the sphere.
fn random_direction(rng: &mut SplitMix64) -> DVec3 {
    let z = rng.range(-1.0, 1.0);
    let angle = rng.range(0.0, std::f64::consts::TAU);
    let r = (1.0 - z * z).sqrt();
    DVec3::new(r * angle.cos(), r * angle.sin(), z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CompileOptions, MapSource, compile};
    use std::path::PathBuf;

    fn cuboid(lo: [f64; 3], hi: [f64; 3], texture: &str) -> String {
        let [x0, y0, z0] = lo;
        let [x1, y1, z1] = hi;
        format!(
            "{{\n( {x0} 0 0 ) ( {x0} 1 0 ) ( {x0} 0 1 ) {texture} 0 0 0 1 1\n\
             ( {x1} 0 0 ) ( {x1} 0 1 ) ( {x1} 1 0 ) {texture} 0 0 0 1 1\n\
             ( 0 {y0} 0 ) ( 0 {y0} 1 ) ( 1 {y0} 0 ) {texture} 0 0 0 1 1\n\
             ( 0 {y1} 0 ) ( 1 {y1} 0 ) ( 0 {y1} 1 ) {texture} 0 0 0 1 1\n\
             ( 0 0 {z0} ) ( 1 0 {z0} ) ( 0 1 {z0} ) {texture} 0 0 0 1 1\n\
             ( 0 0 {z1} ) ( 0 1 {z1} ) ( 1 0 {z1} ) {texture} 0 0 0 1 1\n}}\n"
        )
    }

    /// A sealed 512x384x256 room with a pillar, a water pool, an illusionary block (the box
    /// passes through both) and a func_detail crate, plus `extra` entities.
    fn room(extra: &str) -> String {
        let mut text = String::from("{\n\"classname\" \"worldspawn\"\n");
        let (lo, hi) = ([0.0, 0.0, 0.0], [512.0, 384.0, 256.0]);
        for axis in 0..3 {
            let (mut below, mut above) = (
                ([-16.0; 3], [528.0, 400.0, 272.0]),
                ([-16.0; 3], [528.0, 400.0, 272.0]),
            );
            below.1[axis] = lo[axis];
            above.0[axis] = hi[axis];
            text += &cuboid(below.0, below.1, "wall");
            text += &cuboid(above.0, above.1, "wall");
        }
        text += &cuboid([200.0, 150.0, 0.0], [264.0, 200.0, 256.0], "wall");
        text += &cuboid([300.0, 20.0, 0.0], [480.0, 120.0, 48.0], "*water");
        text += "}\n{\n\"classname\" \"func_detail\"\n";
        text += &cuboid([40.0, 250.0, 0.0], [104.0, 330.0, 40.0], "crate");
        text += "}\n{\n\"classname\" \"func_detail_illusionary\"\n";
        text += &cuboid([380.0, 250.0, 60.0], [440.0, 330.0, 200.0], "crate");
        text += "}\n{\n\"classname\" \"info_player_start\"\n\"origin\" \"100 100 40\"\n}\n";
        text + extra
    }

    fn compiled(text: &str) -> (MapFile, Bsp) {
        let source = MapSource {
            path: PathBuf::from("room.map"),
            text: text.to_string(),
        };
        let out = compile(&source, &CompileOptions::default()).expect("compiles");
        assert!(out.leak.is_none(), "sealed");
        let map = crate::map::parse_map(&source.path, text).expect("parses");
        (map, out.bsp)
    }

    #[test]
    fn a_box_room_agrees_for_both_hulls() {
        let (map, bsp) = compiled(&room(""));
        for hull in [1, 2] {
            let options = HullCheckOptions {
                traces: 3000,
                hull,
                ..HullCheckOptions::default()
            };
            let r = hull_agreement(&map, &bsp, &options).expect("checked");
            assert_eq!(r.traces, 3000, "hull {hull}");
            assert_eq!(r.disagreements, 0, "hull {hull}: {r:#?}");
            // Moves that meet a wall head on stop the engine's epsilon short of it.
            assert!(
                (r.worst_gap - 1.0 / 32.0).abs() < 1e-3,
                "hull {hull}: {r:#?}"
            );
        }
    }

    #[test]
    fn a_hull_that_differs_from_the_brushes_is_found() {
        // Compile the room with a clip-textured crate the brushes checked against do not have:
        // the hull has a box the exact sweep goes through.
        let (_, bsp) = compiled(&room(
            &("{\n\"classname\" \"func_group\"\n".to_string()
                + &cuboid([150.0, 40.0, 0.0], [230.0, 120.0, 100.0], "clip")
                + "}\n"),
        ));
        let (map, _) = compiled(&room(""));
        let options = HullCheckOptions {
            traces: 3000,
            ..HullCheckOptions::default()
        };
        let r = hull_agreement(&map, &bsp, &options).expect("checked");
        assert!(r.disagreements > 0, "{r:#?}");
        assert!(r.worst_gap > 1.0);
        let e = &r.examples[0];
        assert!(e.gap > HULL_AGREEMENT_TOLERANCE);
    }

    #[test]
    fn grown_brushes_overlap_exactly_where_the_box_does() {
        // A wedge: a box cut by a 45-degree slope on its top front edge.
        let n = DVec3::new(1.0, 0.0, 1.0).normalized().expect("n");
        let mut faces: Vec<Plane> = (0..3)
            .flat_map(|axis| {
                let mut e = DVec3::ZERO;
                e[axis] = 1.0;
                [Plane::new(e, 64.0), Plane::new(-e, 0.0)]
            })
            .collect();
        faces.push(Plane::new(n, n.dot(DVec3::new(64.0, 0.0, 32.0))));
        let (mins, maxs) = HULL_BOXES[0];
        let grown = grow(&faces, mins, maxs).expect("grown");
        let mut rng = SplitMix64::new(3);
        for _ in 0..20000 {
            let p = DVec3::new(
                rng.range(-40.0, 110.0),
                rng.range(-40.0, 110.0),
                rng.range(-70.0, 110.0),
            );
            // The box overlaps the wedge when some point of it is inside: check on a fine grid.
            let inside = grown.clearance(p) < 0.0;
            let overlaps = box_overlaps_wedge(p, mins, maxs, &faces);
            let margin = grown.clearance(p).abs();
            if margin > 0.5 {
                assert_eq!(inside, overlaps, "{p:?}");
            }
        }
    }

    /// Whether the box at `p` overlaps the convex solid behind `faces`: a small linear program
    /// solved by brute force over the box's corners and the solid's vertices.
    fn box_overlaps_wedge(p: DVec3, mins: DVec3, maxs: DVec3, faces: &[Plane]) -> bool {
        // Separating axis test over the candidate axes of a box and a convex polytope: the
        // solid's normals, the box's axes and cross products of their edges (the wedge's edges
        // are along the axes and along the slope's edge, the y axis).
        let lo = p + mins;
        let hi = p + maxs;
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect();
        let solid = grow(faces, DVec3::ZERO, DVec3::ZERO).expect("solid");
        let vertices: Vec<DVec3> = faces
            .iter()
            .enumerate()
            .filter_map(|(i, f)| {
                let mut w = Winding::base_for_plane(f);
                for (j, o) in faces.iter().enumerate() {
                    if i != j {
                        w = w.clip_front(&o.flipped(), false)?;
                    }
                }
                Some(w.points)
            })
            .flatten()
            .collect();
        let axes = solid.planes.iter().map(|pl| pl.normal).chain([
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ]);
        for axis in axes {
            let project = |pts: &[DVec3]| {
                pts.iter()
                    .map(|q| q.dot(axis))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), d| {
                        (a.min(d), b.max(d))
                    })
            };
            let (a0, a1) = project(&corners);
            let (b0, b1) = project(&vertices);
            if a1 <= b0 || b1 <= a0 {
                return false;
            }
        }
        true
    }
}
