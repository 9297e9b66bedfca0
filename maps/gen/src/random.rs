//! Random maps for property tests, the same map for the same seed: rooms on a grid joined by
//! corridors (sealed by construction: [`Level`] shells), each with random boxes, rotated, tilted
//! and sheared convex brushes (vertices off the grid), some of them `func_detail` or
//! `func_detail_illusionary`, water, slime or lava pits, lights, maybe a `func_door` in a
//! corridor, and the player start in the first room.
//!
//! Every brush stays inside the air of its room: rooms leave a cross-shaped band through their
//! centre free (corridors meet there and the player starts there) and keep things below
//! [`LIGHT_SPACE`] under their ceiling, where the lights hang.

use crate::brush::{Brush, Map, MapEntity, MapFormat, aabb, box_corners};
use crate::entities::WAD_NAME;
use crate::level::{Level, Surfaces};
use glam::DVec3;
use quake_formats::geom::Bounds;
use quake_formats::rng::SplitMix64;

/// What to generate.
#[derive(Debug, Clone)]
pub struct RandomOptions {
    /// Rooms (at least one).
    pub rooms: usize,
    /// Brushes placed in each room, most of them (the rest do not fit and are dropped).
    pub objects_per_room: usize,
}

impl Default for RandomOptions {
    fn default() -> Self {
        RandomOptions {
            rooms: 3,
            objects_per_room: 6,
        }
    }
}

/// Rooms sit on a grid of this pitch; each is at most [`MAX_HALF`] from its cell's centre, so
/// neighbours are at least 64 units apart and corridors cross the gap.
const CELL: f64 = 512.0;
const MIN_HALF: f64 = 128.0;
const MAX_HALF: f64 = 224.0;
/// Half the width of the band through each room's centre kept free of objects; corridors are at
/// most this wide on either side of it.
const BAND: f64 = 72.0;
/// The space under each ceiling kept free for lights.
const LIGHT_SPACE: f64 = 48.0;

const SURFACES: [Surfaces; 3] = [
    Surfaces {
        floor: "floor1",
        wall: "brick1",
        ceiling: "wood1",
    },
    Surfaces {
        floor: "floor1",
        wall: "metal1",
        ceiling: "metal1",
    },
    Surfaces::all("brick1"),
];
const OBJECT_TEXTURES: [&str; 5] = ["metal1", "trim1", "wood1", "brick1", "floor1"];
const LIQUIDS: [&str; 3] = ["*water1", "*water1", "*slime1"];

/// One room: its air and where it sits on the grid.
#[derive(Debug, Clone, Copy)]
struct Room {
    cell: Cell,
    air: Bounds,
}

impl Room {
    fn centre(&self) -> DVec3 {
        self.air.center()
    }
}

/// Where a room's objects go: the room's air in one quadrant outside the central band, below
/// the light space.
fn quadrant(room: &Room, sx: f64, sy: f64) -> Bounds {
    let c = room.centre();
    let (a, r) = (room.air.mins, room.air.maxs);
    let span = |centre: f64, lo: f64, hi: f64, s: f64| {
        if s < 0.0 {
            (lo, centre - BAND)
        } else {
            (centre + BAND, hi)
        }
    };
    let (x0, x1) = span(c.x, a.x, r.x, sx);
    let (y0, y1) = span(c.y, a.y, r.y, sy);
    aabb([x0, y0, a.z], [x1, y1, r.z - LIGHT_SPACE])
}

/// A multiple of `step` in `[lo, hi]` (`lo` itself when none is).
fn grid(rng: &mut SplitMix64, lo: f64, hi: f64, step: f64) -> f64 {
    let n = ((hi - lo) / step).floor().max(0.0) as usize;
    lo + step * rng.below(n + 1) as f64
}

pub(crate) fn pick<T: Copy>(rng: &mut SplitMix64, list: &[T]) -> T {
    list[rng.below(list.len())]
}

/// A room's place on the grid.
type Cell = (i32, i32);

/// Grid cells for `count` rooms, each new one beside an earlier one, with the links (indices of
/// two cells) between them: a random tree.
fn layout(rng: &mut SplitMix64, count: usize) -> (Vec<Cell>, Vec<(usize, usize)>) {
    let mut cells = vec![(0, 0)];
    let mut links = Vec::new();
    while cells.len() < count.max(1) {
        let from = rng.below(cells.len());
        let (dx, dy) = pick(rng, &[(1, 0), (-1, 0), (0, 1), (0, -1)]);
        let cell = (cells[from].0 + dx, cells[from].1 + dy);
        if !cells.contains(&cell) {
            links.push((from, cells.len()));
            cells.push(cell);
        }
    }
    (cells, links)
}

fn room_at(rng: &mut SplitMix64, cell: Cell) -> Room {
    let c = [f64::from(cell.0) * CELL, f64::from(cell.1) * CELL];
    let hx = grid(rng, MIN_HALF, MAX_HALF, 8.0);
    let hy = grid(rng, MIN_HALF, MAX_HALF, 8.0);
    let height = grid(rng, 160.0, 320.0, 16.0);
    Room {
        cell,
        air: aabb([c[0] - hx, c[1] - hy, 0.0], [c[0] + hx, c[1] + hy, height]),
    }
}

/// The air of a corridor from `a`'s centre to `b`'s, on the floor; its width leaves the band
/// free and lets the biggest monster (64 wide) through.
fn corridor(rng: &mut SplitMix64, a: &Room, b: &Room) -> Bounds {
    let half = grid(rng, 40.0, BAND - 8.0, 4.0);
    let height = grid(rng, 96.0, 128.0, 8.0)
        .min(a.air.maxs.z - LIGHT_SPACE)
        .min(b.air.maxs.z - LIGHT_SPACE);
    let (ca, cb) = (a.centre(), b.centre());
    let along = if a.cell.0 != b.cell.0 { 0 } else { 1 };
    let mut air = aabb(
        [ca.x - half, ca.y - half, 0.0],
        [ca.x + half, ca.y + half, height],
    );
    air.mins[along] = ca[along].min(cb[along]);
    air.maxs[along] = ca[along].max(cb[along]);
    air
}

/// A random rotation (about Z, sometimes tilted about X as well) of a shear, built from
/// normalised random vectors (square roots are exact everywhere, unlike sines), so every
/// platform makes the same map.
pub(crate) fn random_transform(rng: &mut SplitMix64) -> impl Fn(DVec3) -> DVec3 + use<> {
    let mut unit_pair = || loop {
        let (a, b) = (rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        let len = (a * a + b * b).sqrt();
        if len > 0.1 {
            break (a / len, b / len);
        }
    };
    let (cz, sz) = unit_pair();
    let (cx, sx) = unit_pair();
    let tilt = rng.chance(0.3);
    let (cx, sx) = if tilt { (cx, sx) } else { (1.0, 0.0) };
    let shear = if rng.chance(0.5) {
        rng.range(-0.6, 0.6)
    } else {
        0.0
    };
    move |p: DVec3| {
        let p = DVec3::new(p.x + shear * p.z, p.y, p.z);
        let p = DVec3::new(p.x, cx * p.y - sx * p.z, sx * p.y + cx * p.z);
        DVec3::new(cz * p.x - sz * p.y, sz * p.x + cz * p.y, p.z)
    }
}

pub(crate) fn bounds_of(points: &[DVec3]) -> Bounds {
    let mut b = Bounds::EMPTY;
    for &p in points {
        b.add_point(p);
    }
    b
}

/// One random brush inside `space`, or `None` when the one drawn does not fit.
fn object(rng: &mut SplitMix64, space: Bounds) -> Option<Brush> {
    let size = space.maxs - space.mins;
    if size.x < 16.0 || size.y < 16.0 || size.z < 16.0 {
        return None;
    }
    let texture = pick(rng, &OBJECT_TEXTURES);
    let half = [
        rng.range(4.0, size.x / 2.0),
        rng.range(4.0, size.y / 2.0),
        rng.range(4.0, size.z / 2.0),
    ];
    let corners = if rng.chance(0.4) {
        let half = half.map(|h| (h / 4.0).round().max(1.0) * 4.0);
        box_corners(aabb(half.map(|h| -h), half))
    } else {
        let f = random_transform(rng);
        box_corners(aabb(half.map(|h| -h), half)).map(f)
    };
    let extent = bounds_of(&corners);
    let mut offset = DVec3::ZERO;
    for i in 0..3 {
        let (lo, hi) = (
            space.mins[i] - extent.mins[i],
            space.maxs[i] - extent.maxs[i],
        );
        if lo > hi {
            return None;
        }
        // Objects on the floor half the time.
        offset[i] = if i == 2 && rng.chance(0.5) {
            lo
        } else {
            rng.range(lo, hi)
        };
    }
    Some(Brush::hexahedron(corners.map(|p| p + offset), [texture; 6]))
}

/// Brushes of one room, by the entity they go in.
#[derive(Default)]
struct Contents {
    world: Vec<Brush>,
    detail: Vec<Brush>,
    illusionary: Vec<Brush>,
    lights: Vec<MapEntity>,
}

fn furnish(
    rng: &mut SplitMix64,
    room: &Room,
    objects: usize,
    level: &mut Level,
    out: &mut Contents,
) {
    for _ in 0..objects {
        let space = quadrant(room, pick(rng, &[-1.0, 1.0]), pick(rng, &[-1.0, 1.0]));
        let Some(brush) = object(rng, space) else {
            continue;
        };
        match rng.below(10) {
            0..=5 => out.world.push(brush),
            6..=8 => out.detail.push(brush),
            _ => out.illusionary.push(brush),
        }
    }
    if rng.chance(0.5) {
        let q = quadrant(room, pick(rng, &[-1.0, 1.0]), pick(rng, &[-1.0, 1.0]));
        let (x0, y0) = (
            grid(rng, q.mins.x, q.maxs.x - 32.0, 8.0),
            grid(rng, q.mins.y, q.maxs.y - 32.0, 8.0),
        );
        let (x1, y1) = (
            grid(rng, x0 + 32.0, q.maxs.x, 8.0),
            grid(rng, y0 + 32.0, q.maxs.y, 8.0),
        );
        let depth = grid(rng, 32.0, 96.0, 8.0);
        let liquid = pick(rng, &LIQUIDS);
        level.room(aabb([x0, y0, -depth], [x1, y1, 0.0]), SURFACES[0]);
        let top = -grid(rng, 0.0, 16.0, 4.0);
        out.world
            .push(Brush::cuboid(aabb([x0, y0, -depth], [x1, y1, top]), liquid));
    }
    for _ in 0..1 + rng.below(2) {
        let a = room.air;
        let origin = [
            rng.range(a.mins.x + 16.0, a.maxs.x - 16.0),
            rng.range(a.mins.y + 16.0, a.maxs.y - 16.0),
            rng.range(a.maxs.z - LIGHT_SPACE + 8.0, a.maxs.z - 8.0),
        ]
        .map(|c| (c * 4.0).round() / 4.0);
        let mut light = MapEntity::point("light", origin)
            .key("light", &grid(rng, 150.0, 400.0, 10.0).to_string());
        if rng.chance(0.3) {
            let colour: Vec<String> = (0..3).map(|_| (64 + rng.below(192)).to_string()).collect();
            light = light.key("_color", &colour.join(" "));
        }
        out.lights.push(light);
    }
}

/// A door across corridor `air`, halfway between the rooms it joins.
fn door(air: Bounds, along: usize) -> MapEntity {
    let middle = ((air.mins[along] + air.maxs[along]) / 2.0).round();
    let mut b = air;
    b.mins[along] = middle - 4.0;
    b.maxs[along] = middle + 4.0;
    MapEntity::new("func_door")
        .key("angle", "-1")
        .key("speed", "100")
        .key("wait", "3")
        .key("lip", "8")
        .brushes([Brush::cuboid(b, "door1")])
}

/// The map for `seed`.
pub fn random_map(seed: u64, options: &RandomOptions) -> Map {
    let mut rng = SplitMix64::new(seed);
    let (cells, links) = layout(&mut rng, options.rooms);
    let rooms: Vec<Room> = cells.iter().map(|&c| room_at(&mut rng, c)).collect();
    let mut level = Level::default();
    for room in &rooms {
        level.room(room.air, pick(&mut rng, &SURFACES));
    }
    let mut doors = Vec::new();
    for &(a, b) in &links {
        let air = corridor(&mut rng, &rooms[a], &rooms[b]);
        level.room(air, SURFACES[1]);
        if rng.chance(0.5) {
            doors.push(door(
                air,
                if rooms[a].cell.0 != rooms[b].cell.0 {
                    0
                } else {
                    1
                },
            ));
        }
    }
    let mut contents = Contents::default();
    for room in &rooms {
        furnish(
            &mut rng,
            room,
            options.objects_per_room,
            &mut level,
            &mut contents,
        );
    }
    let mut world = level.brushes();
    world.append(&mut contents.world);
    let mut worldspawn = MapEntity::new("worldspawn")
        .key("message", &format!("Random map {seed}"))
        .key("wad", WAD_NAME);
    if rng.chance(0.3) {
        worldspawn = worldspawn.key("_minlight", &grid(&mut rng, 8.0, 32.0, 4.0).to_string());
    }
    let start = rooms[0].centre();
    let mut entities = vec![
        worldspawn.brushes(world),
        MapEntity::point("info_player_start", [start.x, start.y, 24.0]).key("angle", "0"),
    ];
    entities.append(&mut contents.lights);
    for (class, brushes) in [
        ("func_detail", contents.detail),
        ("func_detail_illusionary", contents.illusionary),
    ] {
        if !brushes.is_empty() {
            entities.push(MapEntity::new(class).brushes(brushes));
        }
    }
    entities.extend(doors);
    Map {
        comment: vec![format!(
            "Random map, seed {seed}, {} rooms: generated by slipgate-mapgen (maps/gen/src/random.rs).",
            rooms.len()
        )],
        format: MapFormat::Standard,
        entities,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_seed_gives_the_same_map_and_others_differ() {
        let options = RandomOptions::default();
        let a = random_map(5, &options);
        assert_eq!(a, random_map(5, &options));
        assert_ne!(a.to_text(), random_map(6, &options).to_text());
    }

    #[test]
    fn objects_stay_in_their_rooms_quadrants_and_light_space_stays_free() {
        for seed in 0..20 {
            let mut rng = SplitMix64::new(seed);
            let room = room_at(&mut rng, (1, -1));
            for (sx, sy) in [(-1.0, -1.0), (1.0, 1.0)] {
                let q = quadrant(&room, sx, sy);
                for _ in 0..20 {
                    let Some(brush) = object(&mut rng, q) else {
                        continue;
                    };
                    for p in brush.faces.iter().flat_map(|f| f.points) {
                        // Face points are corners, snapped to 1/10000.
                        for i in 0..3 {
                            assert!(
                                p[i] >= q.mins[i] - 1e-3 && p[i] <= q.maxs[i] + 1e-3,
                                "{p:?} {q:?}"
                            );
                        }
                    }
                }
            }
        }
    }
}
