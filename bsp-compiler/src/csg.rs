//! CSG between brushes: a side buried inside other brushes of at least its contents strength
//! (solid > detail wall > fence > sky > lava > slime > water > illusionary) can never be seen,
//! so it never splits the tree; but illusionary brushes stay seen inside liquids. Detail brushes
//! only hide the sides of other detail brushes, and brushes of one contents where either has
//! `_noclipfaces` hide none of each other's. Faces between touching or overlapping brushes
//! disappear that way, and trees (above all the clip hulls, whose grown brushes overlap a lot)
//! get far fewer splits.
//!
//! This is sound for leaf contents: inside a leaf, the boundary of the stronger brushes' union
//! is made of visible sides, which have all been used as node planes above the leaf.

use crate::bounds_tree::BoundsTree;
use crate::brush::{Brush, Side};
use crate::planes::PlaneSet;
use crate::tree::{contents_priority, keeps_sides_inside};
use glam::DVec3;
use quake_formats::geom::{Bounds, ON_EPSILON, Plane, PlaneSide, Split, Winding};
use rayon::prelude::*;

/// Mark every side of `brushes` that lies wholly inside other brushes as buried. Returns how
/// many.
pub fn mark_hidden_sides(brushes: &mut [Brush], planes: &PlaneSet) -> usize {
    let pad = DVec3::new(ON_EPSILON, ON_EPSILON, ON_EPSILON);
    let index = BoundsTree::new(
        brushes
            .iter()
            .map(|b| Bounds {
                mins: b.bounds.mins - pad,
                maxs: b.bounds.maxs + pad,
            })
            .collect(),
    );
    let padded = index.boxes();
    // Every side is clipped against by each brush its owner overlaps: its outward plane and
    // exact axis worked out once.
    let outward: Vec<Vec<Bounding>> = brushes
        .par_iter()
        .map(|b| {
            b.sides
                .iter()
                .map(|s| {
                    let plane = b.outward(s, planes);
                    Bounding {
                        plane,
                        axis: axial_axis(&plane),
                    }
                })
                .collect()
        })
        .collect();
    let hidden: Vec<Vec<bool>> = (0..brushes.len())
        .into_par_iter()
        .map(|i| {
            let me = &brushes[i];
            let prio = contents_priority(me.contents);
            let mut covers = Vec::new();
            index.overlapping(&padded[i], &mut covers);
            covers.retain(|&j| {
                // Structure must not depend on detail: only detail is hidden by detail.
                // Illusionary brushes stay seen inside liquids, `_noclipfaces` ones inside
                // brushes of their contents.
                j != i
                    && contents_priority(brushes[j].contents) >= prio
                    && (me.is_detail() || !brushes[j].is_detail())
                    && !keeps_sides_inside(&brushes[j], me)
            });
            covers.sort_unstable();
            me.sides
                .iter()
                .zip(&outward[i])
                .map(|(s, own)| s.buried || buried(s, own, &covers, brushes, &outward))
                .collect()
        })
        .collect();
    let mut count = 0;
    for (b, flags) in brushes.iter_mut().zip(hidden) {
        for (s, h) in b.sides.iter_mut().zip(flags) {
            count += usize::from(h && !s.buried);
            s.buried |= h;
        }
    }
    count
}

/// A side's outward plane, and the axis it lies exactly along (see [`axial_axis`]).
struct Bounding {
    plane: Plane,
    axis: Option<usize>,
}

/// A part of a side not yet found covered, with its bounds and, once known, whether it is tiny.
struct Piece {
    winding: Winding,
    bounds: Bounds,
    tiny: Option<bool>,
}

/// Whether `side` (whose outward plane is `own`) is entirely inside the brushes `covers`, whose
/// sides' outward planes `outward` holds.
fn buried(
    side: &Side,
    own: &Bounding,
    covers: &[usize],
    brushes: &[Brush],
    outward: &[Vec<Bounding>],
) -> bool {
    // The pieces of the side still uncovered, each with its bounds: a cover only clips the
    // pieces it reaches, so pieces do not multiply by every cover of the whole side.
    let mut pieces = vec![Piece {
        winding: side.winding.clone(),
        bounds: side.winding.bounds(),
        tiny: None,
    }];
    let mut clipped = Vec::new();
    for &j in covers {
        let other = &brushes[j];
        // Pieces are clipped each on its own, so their order does not matter: those the cover
        // misses stay where they are.
        let mut k = 0;
        while k < pieces.len() {
            if other.bounds.intersects(&pieces[k].bounds) {
                let piece = pieces.swap_remove(k);
                clip_outside(piece, &outward[j], own.plane.normal, &mut clipped);
            } else {
                k += 1;
            }
        }
        pieces.append(&mut clipped);
        if pieces.is_empty() {
            return true;
        }
    }
    false
}

/// Push the parts of `piece` outside the brush whose sides' outward planes are `sides`. A part
/// lying on one of its sides counts as inside when the two face each other (touching brushes)
/// and outside when they face the same way.
fn clip_outside(piece: Piece, sides: &[Bounding], facing: DVec3, out: &mut Vec<Piece>) {
    let Piece {
        winding: mut rest,
        bounds,
        mut tiny,
    } = piece;
    // `rest`'s bounds, computed again only when a split changes it.
    let mut rest_bounds = Some(bounds);
    for Bounding { plane, axis } in sides {
        // Classify first: most windings lie wholly on one side, and splitting would copy them.
        let side = match *axis {
            Some(k) => axial_side(plane, k, rest_bounds.get_or_insert_with(|| rest.bounds())),
            None => rest.side_of(plane),
        };
        // Outside the brush past this side: in front of it, or lying on it facing the same way.
        let outside = match side {
            PlaneSide::Front => true,
            PlaneSide::On => plane.normal.dot(facing) > 0.0,
            PlaneSide::Back | PlaneSide::Cross => false,
        };
        if outside {
            let bounds = rest_bounds.unwrap_or_else(|| rest.bounds());
            out.push(Piece {
                winding: rest,
                bounds,
                tiny,
            });
            return;
        }
        if side == PlaneSide::Cross
            && let Split::Both { front, back } = rest.split(plane)
        {
            if !front.is_tiny() {
                out.push(Piece {
                    bounds: front.bounds(),
                    winding: front,
                    tiny: Some(false),
                });
            }
            rest = back;
            rest_bounds = None;
            tiny = None;
        }
        if *tiny.get_or_insert_with(|| rest.is_tiny()) {
            return;
        }
    }
}

/// The axis a plane's normal lies along (one component ±1, the others 0), if it does.
fn axial_axis(plane: &Plane) -> Option<usize> {
    let n = plane.normal.to_array();
    (0..3).find(|&k| n[k].abs() == 1.0 && (0..3).all(|j| j == k || n[j] == 0.0))
}

/// Where a winding whose points' box is `bounds` lies against `plane`, whose normal lies along
/// axis `k`: a point's distance from it is then its coordinate (or its negation) less the
/// plane's distance, exactly, so the box's extremes give the points' extreme distances, as
/// [`Winding::side_of`] finds them point by point.
fn axial_side(plane: &Plane, k: usize, bounds: &Bounds) -> PlaneSide {
    let (lo, hi) = if plane.normal[k] > 0.0 {
        (bounds.mins[k] - plane.dist, bounds.maxs[k] - plane.dist)
    } else {
        (-bounds.maxs[k] - plane.dist, -bounds.mins[k] - plane.dist)
    };
    PlaneSide::of_both(hi > ON_EPSILON, lo < -ON_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::tests::box_planes;
    use quake_formats::bsp::contents;

    fn cube(planes: &mut PlaneSet, mins: DVec3, maxs: DVec3, c: i32) -> Brush {
        Brush::from_planes(&box_planes(mins, maxs), planes, c, 0).expect("brush")
    }

    #[test]
    fn touching_faces_are_hidden_and_outer_faces_are_not() {
        let mut planes = PlaneSet::new();
        let mut brushes = vec![
            cube(
                &mut planes,
                DVec3::ZERO,
                DVec3::new(64.0, 64.0, 64.0),
                contents::SOLID,
            ),
            cube(
                &mut planes,
                DVec3::new(64.0, 0.0, 0.0),
                DVec3::new(128.0, 64.0, 64.0),
                contents::SOLID,
            ),
        ];
        assert_eq!(mark_hidden_sides(&mut brushes, &planes), 2);
        assert_eq!(
            brushes
                .iter()
                .flat_map(|b| &b.sides)
                .filter(|s| s.buried)
                .count(),
            2
        );
    }

    /// Touching brushes of one contents keep their sides (and so the faces between them) when
    /// either has `_noclipfaces`; a plain pair hides both.
    #[test]
    fn noclipfaces_brushes_hide_none_of_their_contents_sides() {
        let mut planes = PlaneSet::new();
        for (first, second, hidden) in [(false, false, 2), (true, false, 0), (false, true, 0)] {
            let mut brushes = vec![
                cube(
                    &mut planes,
                    DVec3::ZERO,
                    DVec3::new(64.0, 64.0, 64.0),
                    contents::SOLID,
                ),
                cube(
                    &mut planes,
                    DVec3::new(64.0, 0.0, 0.0),
                    DVec3::new(128.0, 64.0, 64.0),
                    contents::SOLID,
                ),
            ];
            brushes[0].no_clip_faces = first;
            brushes[1].no_clip_faces = second;
            assert_eq!(mark_hidden_sides(&mut brushes, &planes), hidden);
        }
        // A stronger brush still hides a `_noclipfaces` one's sides.
        let mut brushes = vec![
            cube(
                &mut planes,
                DVec3::ZERO,
                DVec3::new(128.0, 128.0, 128.0),
                contents::SOLID,
            ),
            cube(
                &mut planes,
                DVec3::new(32.0, 32.0, 32.0),
                DVec3::new(64.0, 64.0, 64.0),
                contents::WATER,
            ),
        ];
        brushes[1].no_clip_faces = true;
        assert_eq!(mark_hidden_sides(&mut brushes, &planes), 6);
    }

    #[test]
    fn solid_inside_water_stays_visible_but_water_inside_solid_does_not() {
        let mut planes = PlaneSet::new();
        let mut brushes = vec![
            cube(
                &mut planes,
                DVec3::ZERO,
                DVec3::new(128.0, 128.0, 128.0),
                contents::WATER,
            ),
            cube(
                &mut planes,
                DVec3::new(32.0, 32.0, 32.0),
                DVec3::new(64.0, 64.0, 64.0),
                contents::SOLID,
            ),
        ];
        assert_eq!(mark_hidden_sides(&mut brushes, &planes), 0);
        let mut brushes = vec![
            cube(
                &mut planes,
                DVec3::ZERO,
                DVec3::new(128.0, 128.0, 128.0),
                contents::SOLID,
            ),
            cube(
                &mut planes,
                DVec3::new(32.0, 32.0, 32.0),
                DVec3::new(64.0, 64.0, 64.0),
                contents::WATER,
            ),
        ];
        assert_eq!(mark_hidden_sides(&mut brushes, &planes), 6);
    }

    proptest::proptest! {
        /// Against an axial plane, the side from the winding's box is the side its points give,
        /// for points near the plane (within a few epsilons) as well as far from it.
        #[test]
        fn an_axial_side_from_the_box_is_the_points_side(
            points in proptest::collection::vec(
                (-4i32..4, -4i32..4, -4i32..4, -3i32..4),
                1..8,
            ),
            axis in 0usize..3,
            flip: bool,
            dist in -2i32..3,
        ) {
            let eps = ON_EPSILON;
            let points: Vec<DVec3> = points
                .iter()
                .map(|&(x, y, z, near)| {
                    let mut p = DVec3::new(x as f64, y as f64, z as f64) * 16.0;
                    // Some coordinates within a few epsilons of the plane.
                    p[axis] = f64::from(dist) * 16.0 + f64::from(near) * eps * 0.75;
                    if near == 3 {
                        p[axis] += 40.0;
                    }
                    p
                })
                .collect();
            let w = Winding::new(points);
            let mut normal = DVec3::ZERO;
            normal[axis] = if flip { -1.0 } else { 1.0 };
            let plane = Plane::new(normal, normal[axis] * f64::from(dist) * 16.0);
            proptest::prop_assert_eq!(axial_axis(&plane), Some(axis));
            proptest::prop_assert_eq!(axial_side(&plane, axis, &w.bounds()), w.side_of(&plane));
        }

        /// A side marked buried lies inside the other boxes: points just outside it, all over
        /// it, are inside some other box.
        #[test]
        fn buried_sides_are_covered(
            boxes in proptest::collection::vec(
                ((-4i32..4, -4i32..4, -4i32..4), (1i32..5, 1i32..5, 1i32..5)),
                2..6,
            ),
        ) {
            let mut planes = PlaneSet::new();
            let boxes: Vec<(DVec3, DVec3)> = boxes
                .iter()
                .map(|&((x, y, z), (w, d, h))| {
                    let lo = DVec3::new(x as f64, y as f64, z as f64) * 16.0;
                    (lo, lo + DVec3::new(w as f64, d as f64, h as f64) * 16.0)
                })
                .collect();
            let mut brushes: Vec<Brush> = boxes
                .iter()
                .map(|&(lo, hi)| cube(&mut planes, lo, hi, contents::SOLID))
                .collect();
            mark_hidden_sides(&mut brushes, &planes);
            for (i, b) in brushes.iter().enumerate() {
                for s in b.sides.iter().filter(|s| s.buried) {
                    let out = b.outward(s, &planes).normal;
                    let pts = &s.winding.points;
                    let c = s.winding.center();
                    // Corners pulled a little towards the centre, then pushed out of the side.
                    for &p in pts.iter().chain(std::iter::once(&c)) {
                        let probe = p + (c - p) * 0.01 + out * 0.5;
                        let covered = boxes.iter().enumerate().any(|(j, &(lo, hi))| {
                            j != i && Bounds { mins: lo, maxs: hi }.contains(probe)
                        });
                        proptest::prop_assert!(covered, "box {} side at {:?}", i, probe);
                    }
                }
            }
        }
    }
}
