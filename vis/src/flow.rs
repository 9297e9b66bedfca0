//! Full vis: recursive portal flow with separating planes (Teller's method, as in Quake's vis).
//!
//! From a base portal, the flow walks leaf by leaf. At each step it keeps the part of the base
//! portal a sight line can still start from (`source`) and the part of the last portal it can
//! still pass through (`pass`). The next portal is clipped to what lies beyond both and, from
//! level 1 on, to the planes that separate source and pass: a line through both portals stays
//! within them. Whatever is left can be seen; an empty clip stops that branch.
//!
//! Levels (like classic vis' `-level`): 0 clips by portal planes only; 1 adds separators from
//! source edges to pass points; 2 adds those from pass edges to source points; 3 and 4 also
//! narrow the source by separators between the old and the new pass, which tightens every
//! deeper step. Every level is conservative; higher levels give smaller sets for more work.
//!
//! The level 1 and 2 separators of a step depend only on the step's source and pass, so they
//! are made once per leaf visit and shared by all portals out of that leaf (the source is not
//! first narrowed by each portal's plane: slightly looser, much cheaper).
//!
//! Pruning, which is what keeps the walk from following every one of the exponentially many
//! leaf paths through open areas:
//! - Each step carries the portals that might still be seen (`might`): the intersection, along
//!   the path, of each passed portal's bound (its mightsee, or its finished flow's result, which
//!   is why the result is the set of portals seen and not just leaves). Unseen portals lying
//!   wholly outside the step's separators are dropped from it too: no line through source and
//!   pass reaches them, nor any line through the portals passed later.
//! - A portal already seen is not walked through when no unseen portal is left that might be
//!   seen through it.
//! - A portal reached again with windings inside those of an earlier walk through it, and a
//!   `might` inside that walk's, is not walked through again ([`Explored`]).
//! - Sight is symmetric: the base's `might` loses every portal whose reverse has a finished flow
//!   that does not see the base's reverse, and the portals whose reverse's flow does see it
//!   count as seen from the start (so walks that could only reach them stop early; the price
//!   is that the other flow's over-estimate is taken over, about 0.5% more visible leaves).

use crate::bitset::{BitSet, WindowBits};
use crate::explored::Explored;
use crate::portals::{OneWayPortal, PortalGraph};
use crate::schedule::FlowPlan;
use glam::DVec3;
use quake_formats::geom::{ON_EPSILON, Plane};
use std::sync::OnceLock;

/// The shared inputs of every portal's flow.
pub struct FlowContext<'a> {
    /// The portals and the clusters they join.
    pub graph: &'a PortalGraph,
    /// Every portal's base vis set: what its flow may at most see.
    pub mightsee: &'a [BitSet],
    /// Finished portals' flow results: tighter than their mightsee. A flow uses only those
    /// `plan` allows ([`FlowPlan::bounds`]), so results do not depend on timing or sharding.
    pub results: &'a [OnceLock<BitSet>],
    /// The waves, and which finished flows each flow may use.
    pub plan: &'a FlowPlan,
    /// How hard separating planes are tested (0..=4): higher is tighter and slower.
    pub level: u8,
}

impl FlowContext<'_> {
    /// The finished flow of `portal` that the flow of `base` may use.
    #[inline]
    fn finished(&self, base: usize, portal: usize) -> Option<&BitSet> {
        if self.plan.bounds(base, portal) {
            self.results[portal].get()
        } else {
            None
        }
    }
}

/// One step of the walk: the state after passing through a portal (or the base, at the head).
struct Frame {
    source: Vec<DVec3>,
    pass: Vec<DVec3>,
    /// False at the head, where no portal has been passed yet.
    has_pass: bool,
    /// The plane of the portal passed (the base portal's at the head), facing onwards.
    plane: Plane,
    /// The portals that might still be seen.
    might: WindowBits,
    /// Separating planes between `source` and `pass`, oriented with the source behind; made
    /// once per frame, when first needed.
    separators: Vec<Plane>,
    separators_ready: bool,
}

impl Frame {
    fn new() -> Frame {
        Frame {
            source: Vec::new(),
            pass: Vec::new(),
            has_pass: false,
            plane: Plane::new(DVec3::ZERO, 0.0),
            might: WindowBits::default(),
            separators: Vec::new(),
            separators_ready: false,
        }
    }
}

/// Per-thread buffers, reused across portals so the hot loop does not allocate.
#[derive(Default)]
pub struct Workspace {
    /// Leaf visits made by the walks run with this workspace (a measure of flow work).
    pub visits: u64,
    /// Walks skipped because an explored state covered them.
    pub covered: u64,
    frames: Vec<Frame>,
    scratch: Vec<DVec3>,
    explored: Explored,
}

impl Workspace {
    fn take_frame(&mut self) -> Frame {
        self.frames.pop().unwrap_or_else(Frame::new)
    }
}

/// The portals seen through `base` (a conservative superset of the truly visible ones).
pub fn portal_flow(ctx: &FlowContext, base: usize, ws: &mut Workspace) -> BitSet {
    let graph = ctx.graph;
    let portal = &graph.portals[base];
    let bits = graph.portals.len();
    let mut head = ws.take_frame();
    head.source.clear();
    head.source.extend_from_slice(&portal.winding);
    head.pass.clear();
    head.has_pass = false;
    head.plane = portal.plane;
    head.separators_ready = false;
    let reverse = PortalGraph::reverse(base);
    let mut seen = BitSet::new(bits);
    head.might.assign_filtered(&ctx.mightsee[base], |r| {
        match ctx.finished(base, PortalGraph::reverse(r)) {
            Some(back) if back.contains(reverse) => {
                seen.insert(r);
                false
            }
            Some(_) => true,
            None => false,
        }
    });
    let mut walk = Walk {
        ctx,
        base_index: base,
        base: portal,
        seen,
    };
    ws.explored.reset(bits);
    walk.flow_cluster(ws, &mut head, portal.to_cluster);
    ws.frames.push(head);
    walk.seen
}

struct Walk<'a> {
    ctx: &'a FlowContext<'a>,
    base_index: usize,
    base: &'a OneWayPortal,
    /// Portals seen so far.
    seen: BitSet,
}

impl Walk<'_> {
    fn flow_cluster(&mut self, ws: &mut Workspace, prev: &mut Frame, leaf: u32) {
        let graph = self.ctx.graph;
        ws.visits += 1;
        let mut cur = ws.take_frame();
        for &q in &graph.cluster_portals[leaf as usize] {
            let q = q as usize;
            if !prev.might.contains(q) {
                continue;
            }
            let bound = (self.ctx.finished(self.base_index, q)).unwrap_or(&self.ctx.mightsee[q]);
            let more = cur.might.assign_and(&prev.might, bound, &self.seen);
            if !more && self.seen.contains(q) {
                continue; // nothing unseen can be seen through it
            }
            let portal = &graph.portals[q];
            if !clip_within(&portal.winding, portal, &self.base.plane, &mut cur.pass) {
                continue;
            }
            // The source part that can look through `portal` lies behind its plane.
            let behind = portal.plane.flipped();
            if !clip_within(&prev.source, self.base, &behind, &mut cur.source) {
                continue;
            }
            cur.plane = portal.plane;
            cur.has_pass = true;
            cur.separators_ready = false;
            // In the base's own leaf (no pass yet) a portal is seen unless coplanar with the base.
            if prev.has_pass
                && (!clip_in_place(&mut cur.pass, portal, &prev.plane, &mut ws.scratch)
                    || !self.narrow(ws, prev, &mut cur, portal))
            {
                continue;
            }
            self.seen.insert(q);
            if !more || !self.cull_might(&mut cur) {
                continue; // nothing unseen lies within sight through it
            }
            if ws.explored.covers(
                q,
                &cur.source,
                &cur.pass,
                &cur.might,
                self.base.plane.normal,
                portal.plane.normal,
            ) {
                ws.covered += 1;
                continue;
            }
            ws.explored.record(q, &cur.source, &cur.pass, &cur.might);
            self.flow_cluster(ws, &mut cur, portal.to_cluster);
        }
        ws.frames.push(cur);
    }

    fn ensure_separators(&self, frame: &mut Frame) {
        if frame.separators_ready {
            return;
        }
        frame.separators.clear();
        let mut keep = |plane| {
            frame.separators.push(plane);
            true
        };
        if self.ctx.level >= 1 {
            separating_planes(&frame.source, &frame.pass, true, &mut keep);
        }
        if self.ctx.level >= 2 {
            separating_planes(&frame.pass, &frame.source, false, &mut keep);
        }
        frame.separators_ready = true;
    }

    /// Drop from `frame.might` the unseen portals wholly outside the separators of its source
    /// and pass. False when no unseen portal is left, so the walk beyond can show nothing new.
    fn cull_might(&self, frame: &mut Frame) -> bool {
        self.ensure_separators(frame);
        let portals = &self.ctx.graph.portals;
        let separators = &frame.separators;
        // Spheres first: a plane culling by its sphere saves another's test of the points.
        frame.might.prune_unknown(&self.seen, |r| {
            let portal = &portals[r];
            separators.iter().any(|plane| portal.behind(plane))
                || separators.iter().any(|plane| portal.wholly_behind(plane))
        })
    }

    /// Clip the new pass through `portal` (and from level 3 the source) by separating planes;
    /// false when the line of sight is cut off.
    fn narrow(
        &self,
        ws: &mut Workspace,
        prev: &mut Frame,
        cur: &mut Frame,
        portal: &OneWayPortal,
    ) -> bool {
        let level = self.ctx.level;
        if level == 0 {
            return true;
        }
        self.ensure_separators(prev);
        for plane in &prev.separators {
            if !clip_in_place(&mut cur.pass, portal, plane, &mut ws.scratch) {
                return false;
            }
        }
        if level < 3 {
            return true;
        }
        // Each plane clips the source as soon as it is found: once nothing is left, the
        // remaining planes need not be made.
        let base = self.base;
        let mut clip = |plane: Plane| clip_in_place(&mut cur.source, base, &plane, &mut ws.scratch);
        separating_planes(&cur.pass, &prev.pass, true, &mut clip)
            && (level < 4 || separating_planes(&prev.pass, &cur.pass, false, &mut clip))
    }
}

/// Hand `found` the planes through an edge of `a` and a point of `b` that separate them: `b` in
/// front (at least one point strictly), `a` behind when `a_behind`, else in front and `b`
/// behind. Each edge of `a` has at most one such plane (more points of `b` only repeat it when
/// they lie in it), so the search for an edge stops at the first. Stops, returning false, as
/// soon as `found` returns false.
///
/// Candidates are tested with their normal not normalized, comparing squared distances against
/// the squared epsilon scaled by the normal's squared length: most are rejected, and this spares
/// them the square root and divisions, the slowest part of the search.
fn separating_planes(
    a: &[DVec3],
    b: &[DVec3],
    a_behind: bool,
    found: &mut impl FnMut(Plane) -> bool,
) -> bool {
    const EPSILON_2: f64 = ON_EPSILON * ON_EPSILON;
    let (n, m) = (a.len(), b.len());
    for i in 0..n {
        let l = if i + 1 == n { 0 } else { i + 1 };
        let edge = a[l] - a[i];
        'candidates: for (j, &bp) in b.iter().enumerate() {
            let raw = edge.cross(bp - a[i]);
            let len2 = raw.dot(raw);
            if len2 <= 1e-24 {
                continue; // `bp` on the edge's line: no plane
            }
            // `d` is the distance times the normal's length: `|d| > ON_EPSILON` in these terms.
            let reach2 = EPSILON_2 * len2;
            let beyond = |d: f64| d * d > reach2;
            // Orient so that `a` is behind; skip planes `a` lies in.
            let Some(a_side) = (0..n)
                .filter(|&k| k != i && k != l)
                .map(|k| raw.dot(a[k] - bp))
                .find(|&d| beyond(d))
            else {
                continue;
            };
            let sign = if a_side > 0.0 { -1.0 } else { 1.0 };
            // The neighbours of `bp` on the convex `b` are the usual ones to fail: first.
            let neighbours = [(j + 1) % m, (j + m - 1) % m];
            let behind = |k: usize| {
                let d = sign * raw.dot(b[k] - bp);
                k != j && d < 0.0 && beyond(d)
            };
            if neighbours.into_iter().any(behind) {
                continue;
            }
            let mut any_front = false;
            for (k, &v) in b.iter().enumerate() {
                let d = sign * raw.dot(v - bp);
                if k == j {
                    continue;
                }
                if d < 0.0 && beyond(d) {
                    continue 'candidates;
                }
                any_front |= d > 0.0 && beyond(d);
            }
            if !any_front {
                continue;
            }
            let normal = raw / len2.sqrt();
            let plane = Plane::new(normal, normal.dot(bp));
            if !found(if (sign > 0.0) == a_behind {
                plane
            } else {
                plane.flipped()
            }) {
                return false;
            }
            break;
        }
    }
    true
}

/// Keep the part of `input` in front of `plane` in `out`; points within [`ON_EPSILON`] count as
/// on the plane. False (and `out` unspecified) when no point lies in front: a winding lying in
/// the plane is cut away too.
pub fn clip_front(input: &[DVec3], plane: &Plane, out: &mut Vec<DVec3>) -> bool {
    out.clear();
    match cut(input, plane) {
        None => false,
        Some(false) => {
            out.extend_from_slice(input);
            true
        }
        Some(true) => {
            split_front(input, plane, out);
            true
        }
    }
}

/// How `plane` cuts `input`: `None` when no point lies in front (by more than [`ON_EPSILON`]),
/// else whether any lies behind, so that clipping changes the winding.
fn cut(input: &[DVec3], plane: &Plane) -> Option<bool> {
    let mut front = false;
    let mut back = false;
    for &p in input {
        let d = plane.distance(p);
        front |= d > ON_EPSILON;
        back |= d < -ON_EPSILON;
    }
    front.then_some(back)
}

/// Append to `out` the part of `input` in front of `plane`, which [`cut`] found to cut it.
fn split_front(input: &[DVec3], plane: &Plane, out: &mut Vec<DVec3>) {
    // Distances are computed again rather than kept: cheaper than a buffer for small windings.
    let n = input.len();
    let mut d = plane.distance(input[0]);
    for i in 0..n {
        let j = (i + 1) % n;
        let dn = plane.distance(input[j]);
        let p = input[i];
        if d >= -ON_EPSILON {
            out.push(p);
        }
        if d.abs() > ON_EPSILON && dn.abs() > ON_EPSILON && (dn > 0.0) != (d > 0.0) {
            let mut mid = p.lerp_monotonic(input[j], d / (d - dn));
            // Keep axial coordinates exact so axial splits do not drift.
            for axis in 0..3 {
                if plane.normal[axis] == 1.0 {
                    mid[axis] = plane.dist;
                } else if plane.normal[axis] == -1.0 {
                    mid[axis] = -plane.dist;
                }
            }
            out.push(mid);
        }
        d = dn;
    }
}

/// [`clip_front`] of `input`, a part of `bound`'s winding: a bounding sphere wholly on one side
/// of the plane decides without testing the points.
fn clip_within(input: &[DVec3], bound: &OneWayPortal, plane: &Plane, out: &mut Vec<DVec3>) -> bool {
    match bound.sphere_side(plane) {
        Some(true) => {
            out.clear();
            out.extend_from_slice(input);
            true
        }
        Some(false) => false,
        None => clip_front(input, plane, out),
    }
}

/// [`clip_within`] replacing `winding`, with `scratch` as the other buffer.
fn clip_in_place(
    winding: &mut Vec<DVec3>,
    bound: &OneWayPortal,
    plane: &Plane,
    scratch: &mut Vec<DVec3>,
) -> bool {
    match bound.sphere_side(plane) {
        Some(kept) => kept,
        None => match cut(winding, plane) {
            None => false,
            Some(false) => true,
            Some(true) => {
                scratch.clear();
                split_front(winding, plane, scratch);
                std::mem::swap(winding, scratch);
                true
            }
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::geom::DVec3Ext;
    use quake_formats::geom::{Split, Winding};
    use quake_formats::rng::SplitMix64;

    fn square() -> Vec<DVec3> {
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 64.0, 0.0),
            DVec3::new(64.0, 64.0, 0.0),
            DVec3::new(64.0, 0.0, 0.0),
        ]
    }

    #[test]
    fn clip_matches_the_shared_winding_split() {
        let plane = Plane::new(DVec3::new(0.6, 0.8, 0.0), 30.0);
        let mut out = Vec::new();
        assert!(clip_front(&square(), &plane, &mut out));
        let Split::Both { front, .. } = Winding::new(square()).split(&plane) else {
            panic!("expected a split");
        };
        assert_eq!(out, front.points);
    }

    #[test]
    fn clip_drops_windings_behind_or_in_the_plane() {
        let mut out = Vec::new();
        let up = Plane::new(DVec3::new(0.0, 0.0, 1.0), 0.0);
        assert!(!clip_front(&square(), &up, &mut out));
        assert!(!clip_front(
            &square(),
            &Plane::new(DVec3::new(1.0, 0.0, 0.0), 64.0),
            &mut out
        ));
        assert!(clip_front(
            &square(),
            &Plane::new(DVec3::new(1.0, 0.0, 0.0), -1.0),
            &mut out
        ));
        assert_eq!(out, square());
    }

    #[test]
    fn separators_of_two_parallel_squares_bound_the_frustum() {
        // Source at z=0, pass at z=64 shifted by 32 in x: the separators keep what lies
        // beyond the pass within the sheared prism.
        let source = square();
        let pass: Vec<DVec3> = square()
            .iter()
            .map(|&v| v + DVec3::new(32.0, 0.0, 64.0))
            .collect();
        let mut planes = Vec::new();
        separating_planes(&source, &pass, true, &mut |p| {
            planes.push(p);
            true
        });
        assert!(!planes.is_empty());
        for plane in &planes {
            assert!(source.iter().all(|&v| plane.distance(v) <= ON_EPSILON));
            assert!(pass.iter().all(|&v| plane.distance(v) >= -ON_EPSILON));
        }
        // A point at z=128 straight along the shear is kept; one far to the side is cut.
        let inside = DVec3::new(96.0, 32.0, 128.0);
        let outside = DVec3::new(-64.0, 32.0, 128.0);
        assert!(planes.iter().all(|p| p.distance(inside) >= -ON_EPSILON));
        assert!(planes.iter().any(|p| p.distance(outside) < -ON_EPSILON));
    }

    /// A regular polygon of 3 to 8 points, axial or on a random plane, somewhere in a map.
    fn random_winding(rng: &mut SplitMix64) -> Vec<DVec3> {
        let sides = 3 + rng.below(6);
        let mut coordinate = || rng.unit() * 2.0 - 1.0;
        let center = DVec3::new(coordinate(), coordinate(), coordinate()) * 1024.0;
        let axis = DVec3::new(coordinate(), coordinate(), coordinate());
        let (u, v) = match axis.cross(DVec3::new(0.0, 0.0, 1.0)).normalized() {
            Some(u) if coordinate() > 0.0 => (u, axis.cross(u).normalized().unwrap_or(u)),
            _ => (DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)),
        };
        let radius = 8.0 + (coordinate() + 1.0) * 64.0;
        (0..sides)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / sides as f64;
                center + u * (radius * t.cos()) + v * (radius * t.sin())
            })
            .collect()
    }

    /// The search with every candidate's normal normalized, as classic vis does it: the
    /// reference the scaled comparisons of [`separating_planes`] must agree with.
    fn separating_planes_normalized(a: &[DVec3], b: &[DVec3], a_behind: bool) -> Vec<Plane> {
        let mut out = Vec::new();
        let n = a.len();
        for i in 0..n {
            let l = (i + 1) % n;
            for (j, &bp) in b.iter().enumerate() {
                let Some(normal) = (a[l] - a[i]).cross(bp - a[i]).normalized() else {
                    continue;
                };
                let mut plane = Plane::new(normal, normal.dot(bp));
                let a_side = (0..n)
                    .filter(|&k| k != i && k != l)
                    .map(|k| plane.distance(a[k]))
                    .find(|d| d.abs() > ON_EPSILON);
                match a_side {
                    None => continue,
                    Some(d) if d > 0.0 => plane = plane.flipped(),
                    Some(_) => {}
                }
                let others = b.iter().enumerate().filter(|&(k, _)| k != j);
                let separates = others
                    .clone()
                    .all(|(_, &v)| plane.distance(v) >= -ON_EPSILON);
                if separates && others.clone().any(|(_, &v)| plane.distance(v) > ON_EPSILON) {
                    out.push(if a_behind { plane } else { plane.flipped() });
                    break;
                }
            }
        }
        out
    }

    #[test]
    fn separators_match_the_normalized_search() {
        let mut rng = SplitMix64::new(4);
        let mut found = 0;
        for _ in 0..2000 {
            let a = random_winding(&mut rng);
            let mut b = random_winding(&mut rng);
            if rng.below(4) == 0 {
                // Parallel edges: near-ties between candidates, as axial maps are full of.
                b = a.iter().map(|&v| v + DVec3::new(16.0, 0.0, 96.0)).collect();
            }
            for a_behind in [true, false] {
                let mut planes = Vec::new();
                separating_planes(&a, &b, a_behind, &mut |p| {
                    planes.push(p);
                    true
                });
                assert_eq!(planes, separating_planes_normalized(&a, &b, a_behind));
                found += planes.len();
            }
        }
        assert!(found > 1000, "too few separators to compare: {found}");
    }

    #[test]
    fn sphere_early_outs_agree_with_clipping_the_points() {
        let mut rng = SplitMix64::new(9);
        let mut scratch = Vec::new();
        for _ in 0..2000 {
            let winding = random_winding(&mut rng);
            let Some(plane) = Winding::new(winding.clone()).plane() else {
                continue;
            };
            let portal = OneWayPortal::new(winding.clone(), plane, 0, 1);
            let normal = DVec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5);
            let Some(normal) = normal.normalized() else {
                continue;
            };
            // Planes from far in front of the winding to far behind it.
            let offset = (rng.unit() * 2.0 - 1.0) * 2.0 * portal.radius;
            let cut = Plane::new(normal, normal.dot(portal.center) + offset);
            let mut expected = Vec::new();
            let kept = clip_front(&winding, &cut, &mut expected);
            let mut within = Vec::new();
            assert_eq!(clip_within(&winding, &portal, &cut, &mut within), kept);
            let mut in_place = winding.clone();
            assert_eq!(
                clip_in_place(&mut in_place, &portal, &cut, &mut scratch),
                kept
            );
            if kept {
                assert_eq!(within, expected);
                assert_eq!(in_place, expected);
            }
        }
    }
}
