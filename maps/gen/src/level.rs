//! Sealed levels from "air" boxes: every room gets a solid shell around it, and the shells are cut
//! where other rooms' air overlaps them, so rooms that touch or overlap are joined by openings and
//! everything else stays sealed.

use crate::brush::Brush;
use quake_formats::geom::Bounds;

/// Textures of a room's shell.
#[derive(Debug, Clone, Copy)]
pub struct Surfaces {
    pub floor: &'static str,
    pub wall: &'static str,
    pub ceiling: &'static str,
}

impl Surfaces {
    pub const fn all(texture: &'static str) -> Surfaces {
        Surfaces {
            floor: texture,
            wall: texture,
            ceiling: texture,
        }
    }
}

#[derive(Debug, Clone)]
struct Room {
    air: Bounds,
    surfaces: Surfaces,
    thickness: f64,
}

/// Rooms in order: a room's shell only fills space that no earlier room's shell (or air) took,
/// so the shell brushes never overlap.
#[derive(Debug, Clone, Default)]
pub struct Level {
    rooms: Vec<Room>,
    holes: Vec<Bounds>,
}

impl Level {
    /// Add a room of open space with a shell of the default 16 units.
    pub fn room(&mut self, air: Bounds, surfaces: Surfaces) -> &mut Level {
        self.room_with_thickness(air, surfaces, 16.0)
    }

    pub fn room_with_thickness(
        &mut self,
        air: Bounds,
        surfaces: Surfaces,
        thickness: f64,
    ) -> &mut Level {
        self.rooms.push(Room {
            air,
            surfaces,
            thickness,
        });
        self
    }

    /// Cut a hole through whatever shell overlaps `hole`, without sealing it: a leak.
    pub fn hole(&mut self, hole: Bounds) -> &mut Level {
        self.holes.push(hole);
        self
    }

    pub fn brushes(&self) -> Vec<Brush> {
        let mut brushes = Vec::new();
        for (index, room) in self.rooms.iter().enumerate() {
            let taken = self.rooms[..index]
                .iter()
                .map(|r| grow(r.air, r.thickness))
                .chain(self.rooms.iter().map(|r| r.air))
                .chain(self.holes.iter().copied());
            let mut pieces = shell(room);
            for cut in taken {
                pieces = pieces
                    .into_iter()
                    .flat_map(|(b, tex)| subtract(b, cut).into_iter().map(move |p| (p, tex)))
                    .collect();
            }
            brushes.extend(pieces.into_iter().map(|(b, tex)| Brush::cuboid(b, tex)));
        }
        brushes
    }
}

fn grow(b: Bounds, by: f64) -> Bounds {
    Bounds {
        mins: b.mins - glam::DVec3::new(by, by, by),
        maxs: b.maxs + glam::DVec3::new(by, by, by),
    }
}

/// The six slabs around a room's air: floor and ceiling span the whole grown box, the X walls
/// the grown Y extent, the Y walls only the air's X extent, so the slabs do not overlap.
fn shell(room: &Room) -> Vec<(Bounds, &'static str)> {
    let (air, t, s) = (room.air, room.thickness, room.surfaces);
    let outer = grow(air, t);
    let slab = |axis: usize, high: bool, span: Bounds| {
        let mut b = span;
        if high {
            b.mins[axis] = air.maxs[axis];
            b.maxs[axis] = air.maxs[axis] + t;
        } else {
            b.mins[axis] = air.mins[axis] - t;
            b.maxs[axis] = air.mins[axis];
        }
        b
    };
    let mut walls_x = outer;
    walls_x.mins.z = air.mins.z;
    walls_x.maxs.z = air.maxs.z;
    let mut walls_y = walls_x;
    walls_y.mins.x = air.mins.x;
    walls_y.maxs.x = air.maxs.x;
    vec![
        (slab(2, false, outer), s.floor),
        (slab(2, true, outer), s.ceiling),
        (slab(0, false, walls_x), s.wall),
        (slab(0, true, walls_x), s.wall),
        (slab(1, false, walls_y), s.wall),
        (slab(1, true, walls_y), s.wall),
    ]
}

/// `a` minus `b` as up to six boxes; `a` itself when they do not overlap with positive volume.
pub fn subtract(a: Bounds, b: Bounds) -> Vec<Bounds> {
    if (0..3).any(|i| a.maxs[i] <= b.mins[i] || b.maxs[i] <= a.mins[i]) {
        return vec![a];
    }
    let mut pieces = Vec::new();
    let mut rest = a;
    for axis in 0..3 {
        if rest.mins[axis] < b.mins[axis] {
            let mut below = rest;
            below.maxs[axis] = b.mins[axis];
            pieces.push(below);
            rest.mins[axis] = b.mins[axis];
        }
        if rest.maxs[axis] > b.maxs[axis] {
            let mut above = rest;
            above.mins[axis] = b.maxs[axis];
            pieces.push(above);
            rest.maxs[axis] = b.maxs[axis];
        }
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::aabb;

    fn volume(b: &Bounds) -> f64 {
        (0..3).map(|i| b.maxs[i] - b.mins[i]).product()
    }

    #[test]
    fn subtraction_keeps_the_volume_outside_the_cut() {
        let a = aabb([0.0, 0.0, 0.0], [64.0, 64.0, 64.0]);
        let b = aabb([16.0, -8.0, 32.0], [32.0, 80.0, 96.0]);
        let pieces = subtract(a, b);
        let total: f64 = pieces.iter().map(volume).sum();
        assert_eq!(total, 64.0 * 64.0 * 64.0 - 16.0 * 64.0 * 32.0);
        assert_eq!(
            subtract(a, aabb([64.0, 0.0, 0.0], [80.0, 8.0, 8.0])),
            vec![a]
        );
    }

    #[test]
    fn one_room_has_six_slabs_filling_its_shell() {
        let air = aabb([0.0, 0.0, 0.0], [128.0, 64.0, 32.0]);
        let brushes = Level::default()
            .room(air, Surfaces::all("brick1"))
            .brushes();
        assert_eq!(brushes.len(), 6);
        let shell = shell(&Room {
            air,
            surfaces: Surfaces::all("x"),
            thickness: 16.0,
        });
        let total: f64 = shell.iter().map(|(b, _)| volume(b)).sum();
        assert_eq!(total, volume(&grow(air, 16.0)) - volume(&air));
    }
}
