//! Every generated map is well-formed: its textures are in the WAD, its brushes are convex solids
//! with outward-facing planes, its entities sit in open space, and only `leak.map` leaks.

use glam::DVec3;
use mapgen::brush::{Brush, Map};
use mapgen::maps::{self, MapFile};
use quake_formats::geom::{Bounds, Plane, Winding};
use quake_formats::wad::Wad;

/// The faces of a brush as windings (each plane's huge square clipped behind every other plane),
/// or why the brush is not a valid convex solid.
fn windings(brush: &Brush) -> Result<Vec<Winding>, String> {
    let planes: Vec<Plane> = brush
        .faces
        .iter()
        .enumerate()
        .map(|(i, f)| f.plane().ok_or(format!("face {i}: collinear points")))
        .collect::<Result<_, _>>()?;
    if planes.len() < 4 {
        return Err(format!("only {} planes", planes.len()));
    }
    let mut out = Vec::new();
    for (i, plane) in planes.iter().enumerate() {
        let mut w = Some(Winding::base_for_plane(plane));
        for (j, other) in planes.iter().enumerate() {
            if j != i {
                w = w.and_then(|w| w.clip_front(&other.flipped(), false));
            }
        }
        match w {
            Some(w) if !w.is_tiny() => out.push(w),
            _ => return Err(format!("face {i} has no area")),
        }
    }
    Ok(out)
}

/// Volume by the divergence theorem over the face windings.
fn volume(faces: &[Winding]) -> f64 {
    faces
        .iter()
        .filter_map(|w| w.plane().map(|p| w.area() * p.dist / 3.0))
        .sum()
}

#[test]
fn every_brush_of_the_valid_maps_is_a_convex_solid_with_outward_planes() {
    for MapFile {
        path,
        map,
        all_brushes_valid,
        ..
    } in maps::all()
    {
        if !all_brushes_valid {
            continue;
        }
        for (e, entity) in map.entities.iter().enumerate() {
            for (b, brush) in entity.brushes.iter().enumerate() {
                let at = format!("{path}: entity {e} brush {b}");
                let faces = windings(brush).unwrap_or_else(|why| panic!("{at}: {why}"));
                assert_eq!(faces.len(), 6, "{at}");
                assert!(faces.iter().all(|w| w.len() == 4), "{at}: not a hexahedron");
                assert!(volume(&faces) > 0.1, "{at}: volume {}", volume(&faces));
                let points: Vec<DVec3> = faces.iter().flat_map(|w| w.points.clone()).collect();
                let centre = points.iter().fold(DVec3::ZERO, |a, &p| a + p) / points.len() as f64;
                for (face, w) in brush.faces.iter().zip(&faces) {
                    let plane = face.plane().expect("checked");
                    assert!(plane.distance(centre) < 0.0, "{at}: a plane faces inwards");
                    let own = w.plane().expect("winding plane");
                    assert!(own.normal.dot(plane.normal) > 0.999, "{at}: winding order");
                }
            }
        }
    }
}

#[test]
fn broken_map_has_exactly_four_bad_brushes_at_its_end() {
    let broken = maps::all()
        .into_iter()
        .find(|m| m.path == "hard/broken.map")
        .expect("broken.map");
    let world = &broken.map.entities[0].brushes;
    let bad: Vec<usize> = (0..world.len())
        .filter(|&i| windings(&world[i]).is_err() || world[i].faces.len() != 6)
        .collect();
    let n = world.len();
    assert_eq!(bad, vec![n - 4, n - 3, n - 2, n - 1]);
}

#[test]
fn the_wad_reads_back_and_has_every_texture_the_maps_use() {
    let pictures = mapgen::textures::picture_files().expect("pictures");
    let bytes = mapgen::textures::wad(&pictures).expect("WAD").write();
    let wad = Wad::read(&bytes).expect("WAD reads back");
    assert_eq!(wad.write(), bytes);
    for m in maps::all() {
        for name in m.map.textures() {
            let tex = wad
                .find_miptex(&name)
                .unwrap_or_else(|| panic!("{}: texture {name} not in the WAD", m.path));
            assert!(tex.width.is_multiple_of(16) && tex.height.is_multiple_of(16));
        }
    }
    let sky = wad.find_miptex("sky1").expect("sky");
    assert_eq!((sky.width, sky.height), (256, 128));
}

/// Brushes that seal: world and func_group brushes that are solid or sky.
fn sealing_boxes(map: &Map) -> Vec<Bounds> {
    let passable = |t: &str| t.starts_with('*') || ["clip", "trigger", "hint", "skip"].contains(&t);
    map.entities
        .iter()
        .filter(|e| matches!(e.get("classname"), Some("worldspawn" | "func_group")))
        .flat_map(|e| &e.brushes)
        .filter(|b| !b.faces.iter().any(|f| passable(&f.texture)))
        .filter_map(|b| {
            // Only axis-aligned boxes; the few rotated brushes stand inside rooms.
            let axial = b
                .faces
                .iter()
                .all(|f| f.plane().and_then(|p| p.axial()).is_some());
            let mut bounds = Bounds::EMPTY;
            b.faces
                .iter()
                .flat_map(|f| f.points)
                .for_each(|p| bounds.add_point(p));
            axial.then_some(bounds)
        })
        .collect()
}

/// Flood the open space from every point entity over a grid whose cell walls are the boxes'
/// faces (exact for axis-aligned boxes); true when some entity reaches the grid's border.
fn leaks(map: &Map) -> bool {
    let boxes = sealing_boxes(map);
    let axes: [Vec<f64>; 3] = std::array::from_fn(|axis| {
        let mut c: Vec<f64> = boxes
            .iter()
            .flat_map(|b| [b.mins[axis], b.maxs[axis]])
            .collect();
        c.sort_by(f64::total_cmp);
        c.dedup();
        let (lo, hi) = (c[0] - 1.0, c[c.len() - 1] + 1.0);
        [vec![lo], c, vec![hi]].concat()
    });
    let dims: [usize; 3] = std::array::from_fn(|a| axes[a].len() - 1);
    let index = |c: [usize; 3]| (c[2] * dims[1] + c[1]) * dims[0] + c[0];
    let mut solid = vec![false; dims.iter().product()];
    let cell_of = |axis: usize, v: f64| axes[axis].partition_point(|&c| c <= v) - 1;
    for b in &boxes {
        let lo: [usize; 3] = std::array::from_fn(|a| cell_of(a, b.mins[a]));
        let hi: [usize; 3] = std::array::from_fn(|a| cell_of(a, b.maxs[a]));
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                for x in lo[0]..hi[0] {
                    solid[index([x, y, z])] = true;
                }
            }
        }
    }
    let mut seen = solid.clone();
    let mut stack = Vec::new();
    for e in &map.entities {
        if let Some(o) = e.get("origin") {
            let o: Vec<f64> = o.split(' ').map(|v| v.parse().expect("number")).collect();
            let cell = std::array::from_fn(|a| cell_of(a, o[a]));
            assert!(
                !solid[index(cell)],
                "{:?} at {o:?} is inside a wall",
                e.get("classname")
            );
            stack.push(cell);
        }
    }
    while let Some(c) = stack.pop() {
        if seen[index(c)] {
            continue;
        }
        seen[index(c)] = true;
        if (0..3).any(|a| c[a] == 0 || c[a] == dims[a] - 1) {
            return true;
        }
        for a in 0..3 {
            for n in [c[a] - 1, c[a] + 1] {
                let mut next = c;
                next[a] = n;
                stack.push(next);
            }
        }
    }
    false
}

#[test]
fn only_the_leak_map_leaks_and_entities_stand_in_open_space() {
    for m in maps::all() {
        assert_eq!(leaks(&m.map), m.path == "leak/leak.map", "{}", m.path);
    }
}

#[test]
fn demo_has_the_promised_contents() {
    let demo = maps::demo();
    let classes: Vec<&str> = demo
        .entities
        .iter()
        .filter_map(|e| e.get("classname"))
        .collect();
    for class in [
        "func_door",
        "func_detail",
        "func_group",
        "info_player_start",
        "light",
    ] {
        assert!(classes.contains(&class), "no {class}");
    }
    assert!(demo.entities.iter().any(|e| e.get("style") == Some("1")));
    let textures = demo.textures();
    for t in [
        "sky1", "*water1", "door1", "light1", "clip", "hint", "skip", "trigger",
    ] {
        assert!(textures.iter().any(|x| x == t), "demo does not use {t}");
    }
    assert!(
        (100..=200).contains(&demo.brush_count()),
        "{} brushes",
        demo.brush_count()
    );
}
