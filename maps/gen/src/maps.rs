//! The project's maps: the demo, a Valve 220 room, hard cases for the compiler, a leak pair and
//! a corridor map for clip-hull traces.

use crate::brush::{Brush, Map, MapEntity, MapFormat, aabb, box_corners};
use crate::entities::{light, player_start, standard, worldspawn};
use crate::level::{Level, Surfaces};
use glam::DVec3;
use quake_formats::geom::Bounds;

/// One generated map: where it goes, what it is for, and whether every brush in it is meant to be
/// a valid convex solid (`broken.map` is not).
#[derive(Debug, Clone)]
pub struct MapFile {
    pub path: &'static str,
    pub purpose: &'static str,
    pub map: Map,
    pub all_brushes_valid: bool,
}

const STONE: Surfaces = Surfaces {
    floor: "floor1",
    wall: "brick1",
    ceiling: "wood1",
};
const METAL: Surfaces = Surfaces {
    floor: "floor1",
    wall: "metal1",
    ceiling: "metal1",
};

fn b(lo: [f64; 3], hi: [f64; 3]) -> Bounds {
    aabb(lo, hi)
}

fn cuboid(lo: [f64; 3], hi: [f64; 3], texture: &str) -> Brush {
    Brush::cuboid(b(lo, hi), texture)
}

/// A ceiling lamp: 32x32x8 hanging from `ceiling` at (x, y), glowing underneath, and the light
/// just below it.
fn lamp(x: f64, y: f64, ceiling: f64) -> (Brush, MapEntity) {
    let trim = "trim1";
    let lo = [x - 16.0, y - 16.0, ceiling - 8.0];
    let hi = [x + 16.0, y + 16.0, ceiling];
    let brush = Brush::cuboid_faces(b(lo, hi), [trim, trim, trim, trim, "light1", trim]);
    (brush, light([x, y, ceiling - 24.0], 250))
}

pub fn demo() -> Map {
    let mut level = Level::default();
    level
        .room(b([0., 0., 0.], [512., 512., 192.]), STONE) // A: start
        .room(b([512., 192., 0.], [768., 320., 128.]), METAL) // corridor A-B
        .room(b([768., 0., 0.], [1280., 512., 224.]), STONE) // B: pool
        .room(b([768., 544., 0.], [1280., 1024., 256.]), STONE) // C: lava
        .room(b([512., 704., 0.], [768., 832., 128.]), METAL) // corridor C-D
        .room(b([0., 576., 0.], [512., 1024., 192.]), METAL) // D: steps
        .room(b([992., 512., 0.], [1056., 544., 128.]), METAL) // doorway B-C
        .room(
            b([192., 192., 192.], [320., 320., 256.]),
            Surfaces::all("sky1"),
        ) // sky over A
        .room(b([896., 128., -96.], [1152., 384., 0.]), STONE) // pool pit
        .room(b([832., 800., -64.], [960., 928., 0.]), STONE) // lava pit
        .room(b([320., 896., -32.], [448., 1008., 0.]), STONE); // slime trough
    let mut world = level.brushes();
    world.extend([
        cuboid([896., 128., -96.], [1152., 384., -8.], "*water1"),
        cuboid([832., 800., -64.], [960., 928., -16.], "*lava1"),
        cuboid([320., 896., -32.], [448., 1008., -4.], "*slime1"),
        // Keeps players out of the lava.
        cuboid([832., 800., 0.], [960., 928., 64.], "clip"),
        // Trim around room A, columns beside the door in room B.
        cuboid([0., 0., 128.], [512., 8., 144.], "trim1"),
        cuboid([0., 504., 128.], [512., 512., 144.], "trim1"),
        cuboid([0., 8., 128.], [8., 504., 144.], "trim1"),
        cuboid([504., 8., 128.], [512., 504., 144.], "trim1"),
        cuboid([944., 480., 0.], [976., 512., 224.], "metal1"),
        cuboid([1072., 480., 0.], [1104., 512., 224.], "metal1"),
        Brush::cuboid_faces(
            b([632., 192., 0.], [640., 320., 128.]),
            ["hint", "hint", "skip", "skip", "skip", "skip"],
        ),
    ]);
    let mut lights = vec![
        // Beside (not on) the func_detail pillars at 96..128 and 384..416.
        light([176., 176., 160.], 250),
        light([336., 336., 160.], 250),
        light([640., 256., 96.], 200),
        light([896., 256., 192.], 300).key("_color", "128 160 255"),
        light([1152., 256., 192.], 250),
        light([896., 864., 96.], 250)
            .key("style", "1")
            .key("_color", "255 150 80"),
        light([1152., 640., 200.], 300),
        light([1152., 960., 200.], 250),
        light([640., 768., 96.], 200),
        light([256., 640., 160.], 200),
    ];
    for (x, y, ceiling) in [(256., 64., 192.), (128., 800., 192.), (384., 800., 192.)] {
        let (brush, lamp_light) = lamp(x, y, ceiling);
        world.push(brush);
        lights.push(lamp_light);
    }
    let mut entities = vec![
        worldspawn("Slipgate demo").brushes(world),
        player_start([64., 256., 24.], 0),
    ];
    entities.extend(lights);
    entities.extend([
        MapEntity::new("func_door")
            .key("angle", "-1")
            .key("speed", "120")
            .key("wait", "4")
            .key("lip", "8")
            .brushes([Brush::cuboid_faces(
                b([992., 520., 0.], [1056., 536., 128.]),
                ["metal1", "metal1", "door1", "door1", "metal1", "metal1"],
            )]),
        MapEntity::new("func_detail").brushes([
            cuboid([96., 96., 0.], [128., 128., 192.], "metal1"),
            cuboid([384., 384., 0.], [416., 416., 192.], "metal1"),
        ]),
        MapEntity::new("func_detail").brushes([
            cuboid([1152., 928., 0.], [1216., 992., 64.], "wood1"),
            cuboid([1168., 944., 64.], [1200., 976., 96.], "wood1"),
            cuboid([1152., 864., 0.], [1184., 896., 32.], "wood1"),
        ]),
        MapEntity::new("func_group")
            .key("_tb_type", "_tb_group")
            .key("_tb_name", "steps")
            .key("_tb_id", "1")
            .brushes([
                cuboid([0., 704., 0.], [128., 896., 48.], "wood1"),
                cuboid([128., 704., 0.], [160., 896., 32.], "wood1"),
                cuboid([160., 704., 0.], [192., 896., 16.], "wood1"),
            ]),
        MapEntity::new("trigger_once")
            .key("message", "The metal hall")
            .brushes([cuboid([576., 704., 0.], [608., 832., 128.], "trigger")]),
    ]);
    standard(
        &[
            "Slipgate demo map, generated by `cargo run -p slipgate-mapgen`; do not edit by hand.",
            "Rooms: A (start, sky window), B (pool, door north), C (lava), D (steps, slime).",
        ],
        entities,
    )
}

/// Rotation of the XY plane by an angle given as (cos, sin).
fn rotate_z(p: DVec3, (c, s): (f64, f64)) -> DVec3 {
    DVec3::new(c * p.x - s * p.y, s * p.x + c * p.y, p.z)
}

fn rotate_x(p: DVec3, (c, s): (f64, f64)) -> DVec3 {
    DVec3::new(p.x, c * p.y - s * p.z, s * p.y + c * p.z)
}

const DEG45: (f64, f64) = (
    std::f64::consts::FRAC_1_SQRT_2,
    std::f64::consts::FRAC_1_SQRT_2,
);
/// (cos 30°, sin 30°); sqrt is exact to the last bit everywhere, unlike cos/sin.
fn deg30() -> (f64, f64) {
    (3f64.sqrt() / 2.0, 0.5)
}

/// A box of half-size `half` centred on the origin, transformed by `f`, then moved to `centre`.
fn transformed_box(half: [f64; 3], centre: [f64; 3], f: impl Fn(DVec3) -> DVec3) -> [DVec3; 8] {
    let neg = half.map(|h| -h);
    box_corners(b(neg, half)).map(|p| f(p) + DVec3::new(centre[0], centre[1], centre[2]))
}

pub fn demo220() -> Map {
    let mut level = Level::default();
    level.room(b([0., 0., 0.], [384., 256., 160.]), STONE);
    let mut world = level.brushes();
    world.push(Brush::hexahedron(
        transformed_box([24., 24., 80.], [192., 128., 80.], |p| rotate_z(p, DEG45)),
        ["metal1"; 6],
    ));
    let mut map = standard(
        &["A small room in Valve 220 format, generated by slipgate-mapgen."],
        vec![
            worldspawn("Valve 220 room")
                .key("mapversion", "220")
                .brushes(world),
            player_start([48., 48., 24.], 45),
            // Clear of the rotated pillar around (192 128).
            light([96., 200., 128.], 300),
        ],
    );
    map.format = MapFormat::Valve220;
    map
}

/// A hard-case map: one room with `inside` brushes, a player start and a light.
fn hard_case(comment: &[&str], air: Bounds, inside: Vec<Brush>, start: [f64; 3]) -> Map {
    let mut level = Level::default();
    level.room(air, STONE);
    hard_case_level(comment, &level, inside, start)
}

fn hard_case_level(comment: &[&str], level: &Level, inside: Vec<Brush>, start: [f64; 3]) -> Map {
    let mut world = level.brushes();
    world.extend(inside);
    standard(
        comment,
        vec![
            worldspawn("Slipgate hard case").brushes(world),
            player_start(start, 0),
            light([start[0] + 32.0, start[1], start[2] + 96.0], 300),
        ],
    )
}

fn thin() -> Map {
    let mut level = Level::default();
    level
        .room(b([0., 0., 0.], [512., 512., 256.]), STONE)
        .room_with_thickness(b([512., 192., 0.], [640., 320., 128.]), METAL, 1.0);
    hard_case_level(
        &[
            "Thin brushes: walls and plates 1 unit thick, on the grid and at half-unit offsets,",
            "one 0.5 units thick, and an alcove (x 512..640) sealed by 1-unit walls.",
        ],
        &level,
        vec![
            cuboid([128., 64., 0.], [129., 448., 128.], "metal1"),
            cuboid([256.5, 64., 0.], [257.5, 448., 128.], "metal1"),
            cuboid([320., 64., 64.], [448., 448., 65.], "wood1"),
            cuboid([320., 64., 96.5], [448., 448., 97.5], "wood1"),
            cuboid([384.5, 200.5, 0.], [385., 300.5, 40.], "trim1"),
        ],
        [64., 256., 24.],
    )
}

/// A box whose corners on the side `moved` (a corner-index bit) are shifted along `axis` in
/// proportion to their X, by `rise` units over 1024.
fn sheared(lo: [f64; 3], hi: [f64; 3], moved: usize, axis: usize, rise: f64, tex: &str) -> Brush {
    let corners = box_corners(b(lo, hi));
    let corners = std::array::from_fn(|i| {
        let mut p = corners[i];
        if i & moved != 0 {
            p[axis] += rise * (p.x - lo[0]) / 1024.0;
        }
        p
    });
    Brush::hexahedron(corners, [tex; 6])
}

fn near_parallel() -> Map {
    hard_case(
        &[
            "Near-parallel planes: faces that differ from their neighbours by about 1/1024 rad,",
            "e.g. the wall through (0 32 0) (1024 33 0) (0 32 64) beside an axial face at y 33.",
        ],
        b([0., 0., 0.], [1024., 512., 256.]),
        vec![
            sheared([0., 0., 0.], [1024., 32., 64.], 2, 1, 1.0, "brick1"),
            cuboid([0., 33., 0.], [1024., 64., 32.], "metal1"),
            sheared([0., 128., 0.], [1024., 256., 16.], 4, 2, 1.0, "floor1"),
            cuboid([0., 256., 0.], [1024., 384., 16.], "floor1"),
            cuboid([0., 384., 224.], [1024., 512., 256.], "wood1"),
            sheared([0., 384., 200.], [1024., 512., 224.], 4, 2, -2.0, "wood1"),
        ],
        [64., 448., 24.],
    )
}

fn offgrid() -> Map {
    let tilt = |p: DVec3| rotate_x(rotate_z(p, deg30()), DEG45);
    hard_case(
        &[
            "Off-grid and rotated brushes: non-integer plane points (4 decimals) and boxes",
            "rotated 45 and 30 degrees about Z, and one tilted 45 degrees about X as well.",
        ],
        b([0., 0., 0.], [768., 768., 256.]),
        vec![
            cuboid([12.3456, 40.75, 0.], [76.5432, 104.125, 48.0625], "metal1"),
            cuboid(
                [600.125, 600.875, 0.5],
                [700.3333, 650.6667, 33.3333],
                "wood1",
            ),
            Brush::hexahedron(
                transformed_box([32., 32., 48.], [256., 256., 48.], |p| rotate_z(p, DEG45)),
                ["brick1"; 6],
            ),
            Brush::hexahedron(
                transformed_box([48., 24., 32.], [512., 256., 32.], |p| rotate_z(p, deg30())),
                ["metal1"; 6],
            ),
            Brush::hexahedron(
                transformed_box([32., 32., 32.], [384., 512., 128.], tilt),
                ["trim1"; 6],
            ),
        ],
        [64., 700., 24.],
    )
}

fn huge_coords() -> Map {
    let near = 30000.0;
    let far = near - 256.0;
    let mut level = Level::default();
    level
        .room(b([far; 3], [near; 3]), STONE)
        .room(b([-near; 3], [-far; 3]), STONE);
    let mut map = hard_case_level(
        &[
            "Huge coordinates: two sealed rooms, x y z in 29744..30000 and -30000..-29744,",
            "within BSP29's 32767 even after hull expansion.",
        ],
        &level,
        vec![
            cuboid([far + 96.; 3], [far + 160.; 3], "metal1"),
            cuboid([-far - 160.; 3], [-far - 96.; 3], "metal1"),
        ],
        [far + 64., far + 64., far + 24.],
    );
    let start = [-near + 64., -near + 64., -near + 24.];
    map.entities.extend([
        MapEntity::point("info_player_deathmatch", start).key("angle", "0"),
        light([start[0] + 32., start[1], start[2] + 96.], 300),
    ]);
    map
}

fn coplanar() -> Map {
    let tiles = (0..64).map(|i| {
        let (x, y) = ((i % 8) as f64 * 64.0, (i / 8) as f64 * 64.0);
        let texture = ["floor1", "metal1"][(i % 8 / 2 + i / 16) % 2];
        cuboid([x, y, 0.], [x + 64., y + 64., 8.], texture)
    });
    hard_case(
        &[
            "Coplanar faces: 64 floor tiles (8x8 of 64 units, tops at z 8), in 2x2 blocks of the",
            "same texture alternating floor1 and metal1.",
        ],
        b([0., 0., 0.], [512., 512., 192.]),
        tiles.collect(),
        [32., 32., 32.],
    )
}

fn tjunctions() -> Map {
    hard_case(
        &[
            "T-junctions: a big block (x 128..160, y 64..448, z 0..192) with small brushes",
            "against its sides and top whose edges end in the middle of its faces' edges.",
        ],
        b([0., 0., 0.], [512., 512., 256.]),
        vec![
            cuboid([128., 64., 0.], [160., 448., 192.], "brick1"),
            cuboid([160., 96., 0.], [192., 160., 40.], "metal1"),
            cuboid([160., 160., 0.], [192., 200., 72.], "metal1"),
            cuboid([160., 240., 100.], [192., 280., 140.], "wood1"),
            cuboid([160., 320., 0.], [224., 352., 24.], "wood1"),
            cuboid([128., 200., 192.], [160., 232., 216.], "trim1"),
            cuboid([96., 400., 0.], [128., 448., 120.], "metal1"),
            cuboid([96., 64., 0.], [128., 100., 50.], "metal1"),
        ],
        [400., 256., 24.],
    )
}

fn broken() -> Map {
    let mut three_planes = cuboid([200., 64., 0.], [264., 128., 64.], "metal1");
    three_planes.faces = vec![
        three_planes.faces[0].clone(),
        three_planes.faces[2].clone(),
        three_planes.faces[5].clone(),
    ];
    let mut duplicate = cuboid([200., 200., 0.], [264., 264., 64.], "metal1");
    duplicate.faces.push(duplicate.faces[5].clone());
    let mut no_volume = cuboid([300., 64., 0.], [340., 128., 64.], "metal1");
    no_volume.faces[1] = cuboid([260., 64., 0.], [300., 128., 64.], "metal1").faces[1].clone();
    let mut collinear = cuboid([300., 200., 0.], [340., 264., 64.], "metal1");
    let [p, q, _] = collinear.faces[5].points;
    collinear.faces[5].points[2] = q + (q - p);
    let mut map = hard_case(
        &[],
        b([0., 0., 0.], [512., 512., 192.]),
        vec![
            cuboid([64., 64., 0.], [128., 128., 64.], "wood1"),
            cuboid([384., 384., 0.], [448., 448., 96.], "wood1"),
            three_planes,
            duplicate,
            no_volume,
            collinear,
        ],
        [64., 256., 24.],
    );
    let first_bad = map.entities[0].brushes.len() - 4;
    map.comment = vec![
        "Broken brushes: the compiler must report them, drop their unusable faces, skip what".into(),
        "cannot be built, and compile the rest.".into(),
        format!(
            "Worldspawn brushes {first_bad}..{}: only 3 planes; a duplicate plane (the +Z face twice:",
            first_bad + 3
        ),
        "the repeat is dropped, the brush kept); opposite planes at x 300 (no volume: the later face"
            .into(),
        "is dropped, leaving the brush open); a face with collinear points (dropped, leaving it open)."
            .into(),
    ];
    map
}

/// Two rooms joined by a corridor; with `leak`, a 32x32 hole in the second room's east wall.
fn leak_pair(leak: bool) -> Map {
    let mut level = Level::default();
    level
        .room(b([0., 0., 0.], [384., 384., 160.]), STONE)
        .room(b([384., 128., 0.], [512., 256., 128.]), METAL)
        .room(b([512., 0., 0.], [896., 384., 160.]), STONE);
    let comment = if leak {
        level.hole(b([896., 176., 32.], [912., 208., 64.]));
        "Leaks: a 32x32 hole in the east wall at x 896..912, y 176..208, z 32..64."
    } else {
        "Sealed: leak.map with its hole filled."
    };
    standard(
        &[comment],
        vec![
            worldspawn("Slipgate leak test").brushes(level.brushes()),
            player_start([64., 192., 24.], 0),
            light([192., 192., 128.], 300),
            light([704., 192., 128.], 300),
        ],
    )
}

/// Coordinates the clip-hull trace test relies on; written into the map's comment and README.
pub const CORRIDORS_LAYOUT: &[&str] = &[
    "Corridor A: open x 0..1024, y 0..128, z 0..128 (floor top z 0, walls y 0 and y 128,",
    "  end wall x 0, ceiling z 128); pillar x 512..544, y 0..64, z 0..128 blocks its south half.",
    "Corridor B: open x 1024..1152, y 0..1024, z 0..128 (walls x 1024 for y > 128 and x 1152,",
    "  end wall y 1024); steps across it: y 384..416 top z 16, y 416..448 top z 32,",
    "  y 448..1024 platform top z 48.",
    "Hull 1 (player, -16 -16 -24 .. 16 16 32) stands at origin z 24 on the floor, z 72 on the",
    "platform. In corridor A its centre stays in y 16..112, and with y < 80 it cannot enter",
    "  x 496..560 (the pillar grown by 16).",
];

fn corridors() -> Map {
    let mut level = Level::default();
    level
        .room(b([0., 0., 0.], [1024., 128., 128.]), METAL)
        .room(b([1024., 0., 0.], [1152., 1024., 128.]), METAL);
    let mut world = level.brushes();
    world.extend([
        cuboid([512., 0., 0.], [544., 64., 128.], "brick1"),
        cuboid([1024., 384., 0.], [1152., 416., 16.], "wood1"),
        cuboid([1024., 416., 0.], [1152., 448., 32.], "wood1"),
        cuboid([1024., 448., 0.], [1152., 1024., 48.], "wood1"),
    ]);
    let mut comment = vec!["Clip-hull trace test map."];
    comment.extend(CORRIDORS_LAYOUT);
    standard(
        &comment,
        vec![
            worldspawn("Slipgate corridors").brushes(world),
            player_start([64., 64., 24.], 0),
            light([256., 64., 96.], 300),
            light([768., 64., 96.], 300),
            light([1088., 256., 96.], 300),
            light([1088., 768., 112.], 300),
        ],
    )
}

/// Every map, in the order they are written.
pub fn all() -> Vec<MapFile> {
    fn valid(path: &'static str, purpose: &'static str, map: Map) -> MapFile {
        MapFile {
            path,
            purpose,
            map,
            all_brushes_valid: true,
        }
    }
    vec![
        valid(
            "demo.map",
            "Demo: 4 rooms, 2 corridors, door, water, lava, slime, sky window, coloured and flickering lights, func_detail, func_group, trigger, hint, clip.",
            demo(),
        ),
        valid(
            "demo220.map",
            "A small room in Valve 220 format (`mapversion` 220), with a rotated pillar.",
            demo220(),
        ),
        valid(
            "hard/thin.map",
            "Hard case: 1-unit and 0.5-unit brushes, half-unit offsets, an alcove sealed by 1-unit walls.",
            thin(),
        ),
        valid(
            "hard/near_parallel.map",
            "Hard case: faces about 1/1024 rad from their neighbours' planes.",
            near_parallel(),
        ),
        valid(
            "hard/offgrid.map",
            "Hard case: non-integer plane points and rotated boxes (45, 30 degrees, tilted).",
            offgrid(),
        ),
        valid(
            "hard/huge_coords.map",
            "Hard case: two sealed rooms near +30000 and -30000 on every axis.",
            huge_coords(),
        ),
        valid(
            "hard/coplanar.map",
            "Hard case: 64 coplanar floor tiles of two textures.",
            coplanar(),
        ),
        valid(
            "hard/tjunctions.map",
            "Hard case: small brushes whose edges end mid-edge on a big block.",
            tjunctions(),
        ),
        MapFile {
            path: "hard/broken.map",
            purpose: "Hard case: 4 invalid brushes (3 planes, duplicate plane, no volume, collinear points) to report: unusable faces dropped, what cannot be built skipped; the rest compiles.",
            map: broken(),
            all_brushes_valid: false,
        },
        valid(
            "leak/leak.map",
            "Leak test: two rooms, a 32x32 hole in an outer wall; must report a leak and write a pointfile.",
            leak_pair(true),
        ),
        valid(
            "leak/sealed.map",
            "Leak test: the same map sealed; must not leak.",
            leak_pair(false),
        ),
        valid(
            "test/corridors.map",
            "Clip-hull trace test: corridors, a pillar, steps and a platform at documented coordinates.",
            corridors(),
        ),
        valid(
            "open/open.map",
            "Vis timing: a sealed sky-covered field with pillars and small rooms, from a seed (`open.rs`); full vis takes minutes.",
            crate::open::open_map(crate::open::SEED),
        ),
    ]
}
