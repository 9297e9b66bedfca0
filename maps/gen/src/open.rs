//! An open map for vis: a large sky-covered field, sealed, with pillars of many heights and
//! small rooms with doorways, all placed from a seed. Open areas are what makes portal flow
//! slow (every portal sees far), so this is the map vis's sharding is measured on.

use crate::brush::{Brush, Map, aabb};
use crate::entities::{light, player_start, standard, worldspawn};
use crate::level::{Level, Surfaces};
use quake_formats::rng::SplitMix64;

/// The seed of the committed `open/open.map`.
pub const SEED: u64 = 16;

/// The field is `CELLS` by `CELLS` cells of `CELL` units, `HEIGHT` high under the sky.
const CELLS: usize = 18;
const CELL: f64 = 256.0;
const HEIGHT: f64 = 512.0;
const WALL: f64 = 16.0;

const FIELD: Surfaces = Surfaces {
    floor: "floor1",
    wall: "brick1",
    ceiling: "sky1",
};

/// What stands in one cell of the field.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Cell {
    Empty,
    /// A square pillar of this half-width and height.
    Pillar {
        half: f64,
        height: f64,
    },
    /// The corner cell of a 2x2-cell room with a doorway on `door_side` (0..4: -x, +x, -y, +y).
    Room {
        door_side: usize,
    },
    /// Covered by a room that starts in another cell.
    Taken,
}

/// The open map made from `seed`.
pub fn open_map(seed: u64) -> Map {
    let cells = layout(seed);
    let mut level = Level::default();
    let side = CELLS as f64 * CELL;
    level.room(aabb([0.0, 0.0, 0.0], [side, side, HEIGHT]), FIELD);
    let mut world = level.brushes();
    let mut entities = Vec::new();
    for (i, cell) in cells.iter().enumerate() {
        let (x, y) = ((i % CELLS) as f64 * CELL, (i / CELLS) as f64 * CELL);
        match *cell {
            Cell::Pillar { half, height } => {
                let (cx, cy) = (x + CELL / 2.0, y + CELL / 2.0);
                world.push(Brush::cuboid(
                    aabb([cx - half, cy - half, 0.0], [cx + half, cy + half, height]),
                    "brick1",
                ));
            }
            Cell::Room { door_side } => {
                world.extend(room(x, y, door_side));
                entities.push(light([x + CELL, y + CELL, 112.0], 200));
            }
            Cell::Empty | Cell::Taken => {}
        }
    }
    let empty: Vec<usize> = (0..cells.len())
        .filter(|&i| cells[i] == Cell::Empty)
        .collect();
    let centre = |i: usize| {
        let c = |n: usize| n as f64 * CELL + CELL / 2.0;
        (c(i % CELLS), c(i / CELLS))
    };
    if let Some(&first) = empty.first() {
        let (x, y) = centre(first);
        entities.push(player_start([x, y, 24.0], 45));
    }
    // Sun-like lights high over the field, in a few empty cells.
    for &i in empty.iter().step_by(7) {
        let (x, y) = centre(i);
        entities.push(light([x, y, HEIGHT - 64.0], 400));
    }
    let mut all = vec![worldspawn("Slipgate open field").brushes(world)];
    all.extend(entities);
    standard(
        &[
            "Slipgate open field: a sealed sky-covered field with pillars and small rooms,",
            "generated from a seed (maps/gen/src/open.rs); vis's sharding is timed on it.",
        ],
        all,
    )
}

/// The cells of the field: about one in eight a room (2x2 cells), the rest mostly pillars.
fn layout(seed: u64) -> Vec<Cell> {
    let mut rng = SplitMix64::new(seed);
    let mut cells = vec![Cell::Empty; CELLS * CELLS];
    for i in 0..cells.len() {
        let (cx, cy) = (i % CELLS, i / CELLS);
        if cells[i] != Cell::Empty {
            continue;
        }
        let roll = rng.below(16);
        // Rooms keep one cell of field between them and the outer wall.
        let room_fits = cx > 0 && cy > 0 && cx + 2 < CELLS && cy + 2 < CELLS;
        let free = |j: usize| cells.get(j) == Some(&Cell::Empty);
        if roll < 2 && room_fits && [i + 1, i + CELLS, i + CELLS + 1].into_iter().all(free) {
            cells[i] = Cell::Room {
                door_side: rng.below(4),
            };
            for j in [i + 1, i + CELLS, i + CELLS + 1] {
                cells[j] = Cell::Taken;
            }
        } else if roll < 11 {
            let half = 16.0 * (1 + rng.below(4)) as f64;
            let height = 64.0 * (1 + rng.below(8)) as f64;
            cells[i] = Cell::Pillar { half, height };
        }
    }
    cells
}

/// A 2x2-cell room at (x, y) inset by a quarter cell: four walls, a roof and a doorway.
fn room(x: f64, y: f64, door_side: usize) -> Vec<Brush> {
    let (lo, hi) = (
        [x + 64.0, y + 64.0],
        [x + 2.0 * CELL - 64.0, y + 2.0 * CELL - 64.0],
    );
    let top = 160.0;
    let mut walls = vec![
        aabb([lo[0], lo[1], 0.0], [lo[0] + WALL, hi[1], top]),
        aabb([hi[0] - WALL, lo[1], 0.0], [hi[0], hi[1], top]),
        aabb(
            [lo[0] + WALL, lo[1], 0.0],
            [hi[0] - WALL, lo[1] + WALL, top],
        ),
        aabb(
            [lo[0] + WALL, hi[1] - WALL, 0.0],
            [hi[0] - WALL, hi[1], top],
        ),
    ];
    // Cut the doorway (64 wide, 96 high) out of the middle of one wall: the wall becomes the
    // parts beside and above it.
    let wall = walls.swap_remove(door_side);
    let axis = if door_side < 2 { 1 } else { 0 };
    let middle = (wall.mins[axis] + wall.maxs[axis]) / 2.0;
    let mut left = wall;
    left.maxs[axis] = middle - 32.0;
    let mut right = wall;
    right.mins[axis] = middle + 32.0;
    let mut lintel = wall;
    lintel.mins[axis] = middle - 32.0;
    lintel.maxs[axis] = middle + 32.0;
    lintel.mins[2] = 96.0;
    walls.extend([left, right, lintel]);
    walls.push(aabb([lo[0], lo[1], top], [hi[0], hi[1], top + WALL]));
    walls
        .into_iter()
        .map(|b| Brush::cuboid(b, "wood1"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_layout_is_fixed_by_the_seed_and_mixes_pillars_and_rooms() {
        assert_eq!(layout(SEED), layout(SEED));
        assert_ne!(layout(SEED), layout(SEED + 1));
        let cells = layout(SEED);
        let rooms = cells
            .iter()
            .filter(|c| matches!(c, Cell::Room { .. }))
            .count();
        let pillars = cells
            .iter()
            .filter(|c| matches!(c, Cell::Pillar { .. }))
            .count();
        assert!(
            rooms >= 8 && pillars >= 100,
            "{rooms} rooms, {pillars} pillars"
        );
    }
}
