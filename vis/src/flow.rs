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
use quake_formats::geom::{ON_EPSILON, Plane, Vec3};

/// The shared inputs of every portal's flow.
pub struct FlowContext<'a> {
    pub graph: &'a PortalGraph,
    pub mightsee: &'a [BitSet],
    /// Finished portals' flow results: tighter than their mightsee.
    pub done: &'a [Option<BitSet>],
    pub level: u8,
}

/// One step of the walk: the state after passing through a portal (or the base, at the head).
struct Frame {
    source: Vec<Vec3>,
    pass: Vec<Vec3>,
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
            plane: Plane::new(Vec3::ZERO, 0.0),
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
    scratch: Vec<Vec3>,
    planes: Vec<Plane>,
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
        match &ctx.done[PortalGraph::reverse(r)] {
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
            let bound = self.ctx.done[q].as_ref().unwrap_or(&self.ctx.mightsee[q]);
            let more = cur.might.assign_and(&prev.might, bound, &self.seen);
            if !more && self.seen.contains(q) {
                continue; // nothing unseen can be seen through it
            }
            let portal = &graph.portals[q];
            if !clip_front(&portal.winding, &self.base.plane, &mut cur.pass) {
                continue;
            }
            // The source part that can look through `portal` lies behind its plane.
            if !clip_front(&prev.source, &portal.plane.flipped(), &mut cur.source) {
                continue;
            }
            cur.plane = portal.plane;
            cur.has_pass = true;
            cur.separators_ready = false;
            // In the base's own leaf (no pass yet) a portal is seen unless coplanar with the base.
            if prev.has_pass
                && (!clip_in_place(&mut cur.pass, &prev.plane, &mut ws.scratch)
                    || !self.narrow(ws, prev, &mut cur))
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
        if self.ctx.level >= 1 {
            separating_planes(&frame.source, &frame.pass, true, &mut frame.separators);
        }
        if self.ctx.level >= 2 {
            separating_planes(&frame.pass, &frame.source, false, &mut frame.separators);
        }
        frame.separators_ready = true;
    }

    /// Drop from `frame.might` the unseen portals wholly outside the separators of its source
    /// and pass. False when no unseen portal is left, so the walk beyond can show nothing new.
    fn cull_might(&self, frame: &mut Frame) -> bool {
        self.ensure_separators(frame);
        let portals = &self.ctx.graph.portals;
        let separators = &frame.separators;
        frame.might.prune_unknown(&self.seen, |r| {
            separators
                .iter()
                .any(|plane| portals[r].wholly_behind(plane))
        })
    }

    /// Clip the new pass (and from level 3 the source) by separating planes; false when the
    /// line of sight is cut off.
    fn narrow(&self, ws: &mut Workspace, prev: &mut Frame, cur: &mut Frame) -> bool {
        let level = self.ctx.level;
        if level == 0 {
            return true;
        }
        self.ensure_separators(prev);
        for plane in &prev.separators {
            if !clip_in_place(&mut cur.pass, plane, &mut ws.scratch) {
                return false;
            }
        }
        if level >= 3 {
            ws.planes.clear();
            separating_planes(&cur.pass, &prev.pass, true, &mut ws.planes);
            if level >= 4 {
                separating_planes(&prev.pass, &cur.pass, false, &mut ws.planes);
            }
            for plane in &ws.planes {
                if !clip_in_place(&mut cur.source, plane, &mut ws.scratch) {
                    return false;
                }
            }
        }
        true
    }
}

/// Append the planes through an edge of `a` and a point of `b` that separate them: `b` in front
/// (at least one point strictly), `a` behind when `a_behind`, else in front and `b` behind.
/// Each edge of `a` has at most one such plane (more points of `b` only repeat it when they lie
/// in it), so the search for an edge stops at the first.
fn separating_planes(a: &[Vec3], b: &[Vec3], a_behind: bool, out: &mut Vec<Plane>) {
    let n = a.len();
    for i in 0..n {
        let l = (i + 1) % n;
        let edge = a[l] - a[i];
        for (j, &bp) in b.iter().enumerate() {
            let Some(normal) = edge.cross(bp - a[i]).normalized() else {
                continue;
            };
            let mut plane = Plane::new(normal, normal.dot(bp));
            // Orient so that `a` is behind; skip planes `a` lies in.
            let a_side = a
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != i && k != l)
                .map(|(_, &v)| plane.distance(v))
                .find(|d| d.abs() > ON_EPSILON);
            match a_side {
                None => continue,
                Some(d) if d > 0.0 => plane = plane.flipped(),
                Some(_) => {}
            }
            let mut any_front = false;
            let separates = b
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != j)
                .all(|(_, &v)| {
                    let d = plane.distance(v);
                    any_front |= d > ON_EPSILON;
                    d >= -ON_EPSILON
                });
            if separates && any_front {
                out.push(if a_behind { plane } else { plane.flipped() });
                break;
            }
        }
    }
}

/// Keep the part of `input` in front of `plane` in `out`; points within [`ON_EPSILON`] count as
/// on the plane. False (and `out` unspecified) when no point lies in front: a winding lying in
/// the plane is cut away too.
pub fn clip_front(input: &[Vec3], plane: &Plane, out: &mut Vec<Vec3>) -> bool {
    const STACK_POINTS: usize = 64;
    let n = input.len();
    let mut stack_dists = [0.0f64; STACK_POINTS];
    let mut heap_dists = Vec::new();
    let dists: &mut [f64] = if n <= STACK_POINTS {
        &mut stack_dists[..n]
    } else {
        heap_dists.resize(n, 0.0);
        &mut heap_dists
    };
    let mut front = false;
    let mut back = false;
    for (d, &p) in dists.iter_mut().zip(input) {
        *d = plane.distance(p);
        front |= *d > ON_EPSILON;
        back |= *d < -ON_EPSILON;
    }
    out.clear();
    if !front {
        return false;
    }
    if !back {
        out.extend_from_slice(input);
        return true;
    }
    for i in 0..n {
        let (p, d) = (input[i], dists[i]);
        if d >= -ON_EPSILON {
            out.push(p);
        }
        if d.abs() <= ON_EPSILON {
            continue;
        }
        let j = (i + 1) % n;
        let dn = dists[j];
        if dn.abs() <= ON_EPSILON || (dn > 0.0) == (d > 0.0) {
            continue;
        }
        let mut mid = p.lerp(input[j], d / (d - dn));
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
    true
}

/// [`clip_front`] replacing `winding`, with `scratch` as the other buffer.
fn clip_in_place(winding: &mut Vec<Vec3>, plane: &Plane, scratch: &mut Vec<Vec3>) -> bool {
    let kept = clip_front(winding, plane, scratch);
    std::mem::swap(winding, scratch);
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use quake_formats::geom::{Split, Winding};

    fn square() -> Vec<Vec3> {
        vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 64.0, 0.0),
            Vec3::new(64.0, 64.0, 0.0),
            Vec3::new(64.0, 0.0, 0.0),
        ]
    }

    #[test]
    fn clip_matches_the_shared_winding_split() {
        let plane = Plane::new(Vec3::new(0.6, 0.8, 0.0), 30.0);
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
        let up = Plane::new(Vec3::new(0.0, 0.0, 1.0), 0.0);
        assert!(!clip_front(&square(), &up, &mut out));
        assert!(!clip_front(
            &square(),
            &Plane::new(Vec3::new(1.0, 0.0, 0.0), 64.0),
            &mut out
        ));
        assert!(clip_front(
            &square(),
            &Plane::new(Vec3::new(1.0, 0.0, 0.0), -1.0),
            &mut out
        ));
        assert_eq!(out, square());
    }

    #[test]
    fn separators_of_two_parallel_squares_bound_the_frustum() {
        // Source at z=0, pass at z=64 shifted by 32 in x: the separators keep what lies
        // beyond the pass within the sheared prism.
        let source = square();
        let pass: Vec<Vec3> = square()
            .iter()
            .map(|&v| v + Vec3::new(32.0, 0.0, 64.0))
            .collect();
        let mut planes = Vec::new();
        separating_planes(&source, &pass, true, &mut planes);
        assert!(!planes.is_empty());
        for plane in &planes {
            assert!(source.iter().all(|&v| plane.distance(v) <= ON_EPSILON));
            assert!(pass.iter().all(|&v| plane.distance(v) >= -ON_EPSILON));
        }
        // A point at z=128 straight along the shear is kept; one far to the side is cut.
        let inside = Vec3::new(96.0, 32.0, 128.0);
        let outside = Vec3::new(-64.0, 32.0, 128.0);
        assert!(planes.iter().all(|p| p.distance(inside) >= -ON_EPSILON));
        assert!(planes.iter().any(|p| p.distance(outside) < -ON_EPSILON));
    }
}
