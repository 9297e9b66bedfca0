//! Three points per brush side, chosen so that the plane a compiler reads back from them is the
//! side's plane within the plane epsilons, and as round as that allows.
//!
//! A `.map` plane is read as Slipgate's compiler reads it: `Plane::from_points`, then snapped
//! about the points' centre (`Plane::snapped`), in the entity's own coordinates (the points less
//! its origin). Candidates are tried from the roundest: corners of the side (or of a BSP face on
//! it, where the compiler wrote the mapper's vertices) rounded to whole units, then to three and
//! six decimals, then points built on the plane itself; the first that reads back as the plane
//! is written. The unrounded points always read back (to `f64` rounding), so one is found.

use glam::DVec3;
use quake_formats::geom::{DVec3Ext, Plane, Winding};

/// Decimals a candidate's coordinates are rounded to, in the order tried (`None`: unrounded).
const ROUNDINGS: [Option<i32>; 4] = [Some(0), Some(3), Some(6), None];

/// How far apart the points built on a plane are: far enough that rounding to six decimals
/// turns the plane by well under `NORMAL_EPSILON`.
const SPAN: f64 = 64.0;

/// The plane a compiler reads from `points` written for an entity at `origin`.
pub(crate) fn read_back(points: [DVec3; 3], origin: DVec3) -> Option<Plane> {
    let [a, b, c] = points.map(|p| p - origin);
    Plane::from_points(a, b, c).map(|p| p.snapped((a + b + c) / 3.0))
}

/// Three points for `plane` (in the entity's coordinates), written in map coordinates (plus
/// `origin`). `polygons` are polygons on the plane, tried first, most trusted first: each is
/// clockwise seen from the front.
pub(crate) fn three_points(plane: &Plane, polygons: &[&Winding], origin: DVec3) -> [DVec3; 3] {
    let mut fallback = None;
    let corners = polygons.iter().filter_map(|w| spread_corners(w));
    for points in corners.chain(std::iter::once(on_plane(plane, polygons.first().copied()))) {
        let world = points.map(|p| p + origin);
        for digits in ROUNDINGS {
            let rounded = world.map(|p| round(p, digits));
            if let Some(ok) = reads_as(rounded, origin, plane) {
                return ok;
            }
        }
        fallback.get_or_insert(world);
    }
    // Not reached in practice (unrounded points on the plane read back as it); kept so a
    // degenerate plane still gives three points.
    fallback.unwrap_or_else(|| on_plane(plane, None).map(|p| p + origin))
}

/// `points` in the order that reads back as `plane`, if either order does.
fn reads_as(points: [DVec3; 3], origin: DVec3, plane: &Plane) -> Option<[DVec3; 3]> {
    let [a, b, c] = points;
    [[a, b, c], [c, b, a]]
        .into_iter()
        .find(|&p| read_back(p, origin).is_some_and(|back| back.same_as(plane)))
}

/// Three corners of `w` far apart (the first, the one furthest from it, the one furthest from
/// the line through both), in the polygon's order, so they wind as it does.
fn spread_corners(w: &Winding) -> Option<[DVec3; 3]> {
    let p = &w.points;
    if p.len() < 3 {
        return None;
    }
    let far = |from: usize| {
        (0..p.len()).max_by(|&i, &j| {
            (p[i] - p[from])
                .length_squared()
                .total_cmp(&(p[j] - p[from]).length_squared())
        })
    };
    let i = 0;
    let j = far(i)?;
    let line = (p[j] - p[i]).normalized()?;
    let off_line = |k: usize| {
        let d = p[k] - p[i];
        (d - line * d.dot(line)).length_squared()
    };
    let k = (0..p.len()).max_by(|&a, &b| off_line(a).total_cmp(&off_line(b)))?;
    if off_line(k) < 1e-6 {
        return None;
    }
    let mut idx = [i, j, k];
    idx.sort_unstable();
    Some(idx.map(|n| p[n]))
}

/// Three points on `plane` around the centre of `near` (or the plane's point nearest the
/// origin), `SPAN` apart, winding clockwise seen from the front.
fn on_plane(plane: &Plane, near: Option<&Winding>) -> [DVec3; 3] {
    let n = plane.normal;
    let centre = near.map_or(n * plane.dist, |w| {
        let c = w.center();
        c - n * plane.distance(c)
    });
    let helper = if n.z.abs() < 0.9 { DVec3::Z } else { DVec3::X };
    let u = n.cross(helper).normalize_or_zero();
    let v = n.cross(u);
    // Plane::from_points takes the normal as (a - b) × (c - b): u × v = n.
    [centre + u * SPAN, centre, centre + v * SPAN]
}

fn round(p: DVec3, digits: Option<i32>) -> DVec3 {
    match digits {
        Some(d) => {
            let m = 10f64.powi(d);
            (p * m).round() / m + DVec3::ZERO
        }
        None => p,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_on(plane: &Plane, size: f64) -> Winding {
        let pts = on_plane(plane, None);
        let (u, v) = ((pts[0] - pts[1]) / SPAN, (pts[2] - pts[1]) / SPAN);
        let c = pts[1];
        // Clockwise seen from the front: u × v = n, so go u then -v.
        Winding::new(vec![c, c + u * size, c + u * size + v * size, c + v * size])
    }

    #[test]
    fn built_points_read_back_as_their_plane() {
        for plane in [
            Plane::new(DVec3::Z, 12.0),
            Plane::new(
                DVec3::new(0.3, -0.4, 0.866_025_403_784_438_6).normalize(),
                -331.7,
            ),
            Plane::new(DVec3::new(-1.0, 2.0, 0.0).normalize(), 1234.5678),
        ] {
            let p = three_points(&plane, &[], DVec3::ZERO);
            assert!(
                read_back(p, DVec3::ZERO).expect("plane").same_as(&plane),
                "{plane:?}"
            );
        }
    }

    #[test]
    fn whole_corners_are_written_whole() {
        // A 45 degree wall through whole points.
        let plane = Plane::from_points(
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 64.0),
            DVec3::new(64.0, 64.0, 0.0),
        )
        .expect("plane");
        let noisy = |p: DVec3| p + DVec3::splat(1e-4);
        let w = Winding::new(vec![
            noisy(DVec3::new(0.0, 0.0, 0.0)),
            noisy(DVec3::new(0.0, 0.0, 64.0)),
            noisy(DVec3::new(64.0, 64.0, 64.0)),
            noisy(DVec3::new(64.0, 64.0, 0.0)),
        ]);
        let p = three_points(&plane, &[&w], DVec3::ZERO);
        assert!(p.iter().all(|v| v.round() == *v), "{p:?}");
        assert!(read_back(p, DVec3::ZERO).expect("plane").same_as(&plane));
    }

    #[test]
    fn points_are_in_map_coordinates_for_an_entity_with_an_origin() {
        let plane = Plane::new(DVec3::X, 8.0);
        let origin = DVec3::new(100.0, 50.5, -3.0);
        let w = square_on(&plane, 16.0);
        let p = three_points(&plane, &[&w], origin);
        assert!(p.iter().all(|v| (v.x - 108.0).abs() < 1e-9), "{p:?}");
        assert!(read_back(p, origin).expect("plane").same_as(&plane));
    }
}
