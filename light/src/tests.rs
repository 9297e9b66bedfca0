//! End-to-end tests on tiny synthetic BSPs (world model only, no BSP tree,
//! no vis) and, when present, on the corpus maps.

use glam::{DVec3, Vec3};
use quake_formats::Bsp;
use quake_formats::bsp::{BspPlane, Face, Model, TexInfo, texinfo_flags};
use quake_formats::extents::LightmapExtents;
use quake_formats::geom::DVec3Ext;

use quake_formats::miptex::{MipTex, TextureLump};

use crate::bounce::EmissiveQuality;
use crate::dirt::DirtMode;
use crate::faces::{FaceKind, Spacing, face_geometry};
use crate::samples::face_samples;
use crate::settings::SoftRadius;
use crate::{
    Options, Quality, apply_lighting, compare, compute_lighting, trace_lighting,
    update_entities_only,
};

mod ericw_cases;
mod projection;

/// A polygon with its outward normal and whether it is sky.
struct Poly {
    points: Vec<[f32; 3]>,
    normal: [f32; 3],
    sky: bool,
}

fn quad(a: [f32; 3], b: [f32; 3], c: [f32; 3], d: [f32; 3], normal: [f32; 3]) -> Poly {
    Poly {
        points: vec![a, b, c, d],
        normal,
        sky: false,
    }
}

/// A sky ceiling at z 512, facing down over the test floors.
fn sky_ceiling() -> Poly {
    Poly {
        sky: true,
        ..quad(
            [-512.0, -512.0, 512.0],
            [768.0, -512.0, 512.0],
            [768.0, 768.0, 512.0],
            [-512.0, 768.0, 512.0],
            [0.0, 0.0, -1.0],
        )
    }
}

/// The six outward faces of the box `lo..hi`.
fn box_faces(lo: [f32; 3], hi: [f32; 3]) -> Vec<Poly> {
    // Corner i takes hi on axis k when bit k of i is set; each face lists its corners
    // counter-clockwise seen from outside.
    let corner = |i: usize| std::array::from_fn(|k| if i >> k & 1 == 1 { hi[k] } else { lo[k] });
    const FACES: [([usize; 4], [f32; 3]); 6] = [
        ([4, 5, 7, 6], [0.0, 0.0, 1.0]),
        ([0, 2, 3, 1], [0.0, 0.0, -1.0]),
        ([1, 3, 7, 5], [1.0, 0.0, 0.0]),
        ([0, 4, 6, 2], [-1.0, 0.0, 0.0]),
        ([2, 6, 7, 3], [0.0, 1.0, 0.0]),
        ([0, 1, 5, 4], [0.0, -1.0, 0.0]),
    ];
    FACES
        .iter()
        .map(|&([a, b, c, d], normal)| quad(corner(a), corner(b), corner(c), corner(d), normal))
        .collect()
}

/// qbsp's axial texture projection for a normal.
fn axial_vecs(n: [f32; 3]) -> [[f32; 4]; 2] {
    let [x, y, z] = n.map(f32::abs);
    if z >= x && z >= y {
        [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0]]
    } else if x >= y {
        [[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0]]
    } else {
        [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0]]
    }
}

fn mip(name: &str) -> MipTex {
    MipTex::new(
        name,
        16,
        16,
        [vec![0; 256], vec![0; 64], vec![0; 16], vec![0; 4]],
    )
}

/// A BSP whose world model is `polys` (no nodes, leaves or vis: everything
/// is in the open and visible) and whose entity lump is `entities`.
fn synthetic_bsp(polys: &[Poly], entities: &str) -> Bsp {
    synthetic_bsp_models(&[polys], entities)
}

/// Like [`synthetic_bsp`], with brush model `m` made of `models[m]`
/// (model 0 is the world).
fn synthetic_bsp_models(models: &[&[Poly]], entities: &str) -> Bsp {
    let mut bsp = Bsp::default();
    bsp.set_entity_text(entities);
    bsp.textures = TextureLump {
        textures: vec![Some(mip("wall")), Some(mip("sky1"))],
    };
    bsp.edges.push([0, 0]);
    for polys in models {
        let first_face = bsp.faces.len() as u32;
        for p in *polys {
            add_poly(&mut bsp, p);
        }
        bsp.models.push(Model {
            mins: [-1e4; 3],
            maxs: [1e4; 3],
            origin: [0.0; 3],
            head_nodes: [0; 4],
            vis_leafs: 0,
            first_face,
            num_faces: bsp.faces.len() as u32 - first_face,
        });
    }
    bsp
}

/// Appends `p` as a face with its own plane and axial texinfo.
fn add_poly(bsp: &mut Bsp, p: &Poly) {
    let n = p.normal;
    let dist = n[0] * p.points[0][0] + n[1] * p.points[0][1] + n[2] * p.points[0][2];
    bsp.planes.push(BspPlane {
        normal: n,
        dist,
        kind: 5,
    });
    bsp.texinfo.push(TexInfo {
        vecs: axial_vecs(n),
        miptex: u32::from(p.sky),
        flags: if p.sky { texinfo_flags::SPECIAL } else { 0 },
    });
    let first_vertex = bsp.vertices.len() as u32;
    let first_edge = bsp.surfedges.len() as u32;
    bsp.vertices.extend(&p.points);
    let count = p.points.len() as u32;
    for i in 0..count {
        bsp.surfedges.push(bsp.edges.len() as i32);
        bsp.edges
            .push([first_vertex + i, first_vertex + (i + 1) % count]);
    }
    bsp.faces.push(Face {
        plane: bsp.planes.len() as u32 - 1,
        side: 0,
        first_edge,
        num_edges: count,
        texinfo: bsp.texinfo.len() as u32 - 1,
        styles: [255; 4],
        light_offset: -1,
    });
}

fn floor(size: f32) -> Poly {
    floor_rect(size, size)
}

/// An upward floor over x 0..`x`, y 0..`y` at z 0.
fn floor_rect(x: f32, y: f32) -> Poly {
    quad(
        [0.0, 0.0, 0.0],
        [0.0, y, 0.0],
        [x, y, 0.0],
        [x, 0.0, 0.0],
        [0.0, 0.0, 1.0],
    )
}

/// Floor 0..256, a 64-unit box floating over its middle, a light above.
fn shadow_scene(light_keys: &str) -> Bsp {
    let mut polys = vec![floor(256.0)];
    polys.extend(box_faces([96.0, 96.0, 32.0], [160.0, 160.0, 96.0]));
    let ents = format!(
        "{{ \"classname\" \"worldspawn\" }}\n{{ \"classname\" \"light\" \"origin\" \"128 128 192\" {light_keys} }}\n"
    );
    synthetic_bsp(&polys, &ents)
}

fn options(quality: Quality) -> Options {
    Options {
        quality,
        ..Options::default()
    }
}

#[test]
fn soft_blurs_by_samples_as_ericw_tools_does() {
    // The shadow scene's box, its light off centre, so that the shadow's edges cross luxels
    // off their middles.
    let mut polys = vec![floor(256.0)];
    polys.extend(box_faces([96.0, 96.0, 32.0], [160.0, 160.0, 96.0]));
    let light =
        "\"origin\" \"133 123 192\" \"light\" \"200\" \"delay\" \"3\" \"_anglescale\" \"0\"";
    let ents =
        format!("{{ \"classname\" \"worldspawn\" }}\n{{ \"classname\" \"light\" {light} }}\n");
    let bsp = synthetic_bsp(&polys, &ents);
    let floor = |quality, soft| {
        let mut options = options(quality);
        options.overrides.soft = Some(soft);
        let lighting = compute_lighting(&bsp, &options).expect("light");
        let floor = lighting.lightmaps.into_iter().find(|m| m.face == 0);
        floor.expect("floor").grey.remove(0)
    };
    let (none, half) = (SoftRadius::Samples(0), SoftRadius::HalfLuxel);
    // `--soft` alone is half a luxel's samples: nothing with one sample a luxel.
    assert_eq!(floor(Quality::Default, half), floor(Quality::Default, none));
    assert_ne!(
        floor(Quality::Default, SoftRadius::Samples(1)),
        floor(Quality::Default, none)
    );
    // Two samples each way with `--extra4`: the shadow's edge softens, its middle stays dark.
    let soft = floor(Quality::Extra4, half);
    assert_eq!(soft, floor(Quality::Extra4, SoftRadius::Samples(2)));
    let hard = floor(Quality::Extra4, none);
    assert_ne!(soft, hard);
    let centre = 8 * 17 + 8;
    assert_eq!((soft[centre], hard[centre]), (0, 0));
    assert_eq!(soft.iter().map(|&b| u64::from(b)).sum::<u64>() / 17, {
        hard.iter().map(|&b| u64::from(b)).sum::<u64>() / 17
    });
}

#[test]
fn box_shadow_has_the_projected_size() {
    // Constant falloff and no angle term: every lit luxel gets exactly 200 * 0.5.
    let bsp = shadow_scene("\"light\" \"200\" \"delay\" \"3\" \"_anglescale\" \"0\"");
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let floor = lighting
        .lightmaps
        .iter()
        .find(|m| m.face == 0)
        .expect("floor");
    assert_eq!((floor.width, floor.height), (17, 17));
    // The box's top edge (z 96, half-width 32) seen from the light (z 192),
    // projected onto the sample plane (z 1).
    let half = 32.0 * (192.0 - 1.0) / (192.0 - 96.0);
    let (lo, hi) = (128.0 - half, 128.0 + half);
    let tex_mins = LightmapExtents::from_points(
        &bsp.face_vertices(&bsp.faces[0]).expect("verts"),
        &bsp.texinfo[0].vecs,
    )
    .tex_mins;
    let mut dark = 0;
    for y in 0..floor.height {
        for x in 0..floor.width {
            let value = floor.grey[0][y * floor.width + x];
            let wx = f64::from(tex_mins[0]) + 16.0 * x as f64;
            let wy = -(f64::from(tex_mins[1]) + 16.0 * y as f64);
            let inside = (lo..hi).contains(&wx) && (lo..hi).contains(&wy);
            assert_eq!(value, if inside { 0 } else { 100 }, "luxel at {wx} {wy}");
            dark += usize::from(value == 0);
        }
    }
    // 7x7 luxels: the shadow is 127.3 units wide, within one 16-unit luxel of 7 * 16.
    assert_eq!(dark, 49);
    assert!((2.0 * half - 7.0 * 16.0).abs() < 16.0);
}

#[test]
fn samples_by_a_wall_stay_on_their_side_and_do_not_bleed() {
    // A 100-unit floor (its luxel grid reaches x = 112) against a wall at x = 100,
    // a light on the wall's far side.
    let mut polys = vec![floor(100.0)];
    polys.extend(box_faces([100.0, -50.0, -50.0], [140.0, 150.0, 200.0]));
    let ents = "{ \"classname\" \"worldspawn\" }\n{ \"classname\" \"light\" \"origin\" \"180 50 40\" \"delay\" \"3\" }\n";
    let bsp = synthetic_bsp(&polys, ents);
    let faces = face_geometry(&bsp, |_| DVec3::ZERO, |_| Spacing::Quake).expect("faces");
    let (samples, counts) = face_samples(&faces[0], 1, &bsp);
    assert_eq!(samples.width, 8, "grid 0..112 has 8 luxels across");
    assert!(counts.clamped >= 8, "{counts:?}");
    for p in &samples.points {
        // Moved onto the floor's edge, and half a unit back from the wall if that is solid.
        assert!(p[0] <= 100.0, "sample {p:?} left behind the wall");
        assert!(
            (p[2] - 1.0).abs() < 1e-4 || (p[2] - 0.5).abs() < 1e-4,
            "sample {p:?} stands a unit above the floor, or half a unit when nudged"
        );
    }
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let floor = lighting
        .lightmaps
        .iter()
        .find(|m| m.face == 0)
        .expect("floor");
    assert!(
        floor
            .style_grey(0)
            .is_none_or(|g| g.iter().all(|&v| v == 0)),
        "light bled under the wall"
    );
}

/// A floor strip 256 units long, from y `y0` to `y1`.
fn floor_strip(y0: f32, y1: f32) -> Poly {
    quad(
        [0.0, y0, 0.0],
        [0.0, y1, 0.0],
        [256.0, y1, 0.0],
        [256.0, y0, 0.0],
        [0.0, 0.0, 1.0],
    )
}

/// The floor strips `polys` (the first from y 0, under 16 wide) as one plane: how many faces
/// continue the first, and whether its second luxel row (at y 16, past its edge) stays where
/// the grid puts it, over the face there.
fn second_row_over_the_plane(polys: &[Poly]) -> (usize, bool) {
    let bsp = synthetic_bsp(polys, "{ \"classname\" \"worldspawn\" }");
    let faces = face_geometry(&bsp, |_| DVec3::ZERO, |_| Spacing::Quake).expect("faces");
    let (samples, _) = face_samples(&faces[0], 1, &bsp);
    assert_eq!(samples.height, 2);
    let past: Vec<&[f32; 3]> = samples.points.iter().filter(|p| p[1] > 8.0).collect();
    let stays = past.len() == samples.width && past.iter().all(|p| p[1] == 16.0 && p[2] == 1.0);
    (faces[0].continuations.len(), stays)
}

/// Regression: a luxel past a face's edge was moved back onto the face even where a face on the
/// same plane continues it (a thin strip beside a floor), so it measured the strip's edge instead
/// of the surface it stands over; ericw-tools places it on the continuing face.
#[test]
fn samples_past_an_edge_land_on_the_face_that_continues_it() {
    let polys = [floor_strip(0.0, 8.0), floor_strip(8.0, 256.0)];
    assert_eq!(second_row_over_the_plane(&polys), (1, true));
}

/// Regression: only a face sharing an edge counted as continuing one, so a luxel past a thin
/// strip, over a face two edges away, was moved back onto the strip; ericw-tools follows the
/// point across up to three faces of the plane.
#[test]
fn samples_past_an_edge_follow_the_plane_across_faces() {
    let polys = [
        floor_strip(0.0, 4.0),
        floor_strip(4.0, 8.0),
        floor_strip(8.0, 256.0),
    ];
    assert_eq!(second_row_over_the_plane(&polys), (2, true));
}

/// A face's continuations number the faces it may walk onto, itself first and the others in
/// face order, and say edge by edge which of them lies across, in that numbering, though every
/// face's continuations look the edges up in one shared table.
#[test]
fn continuations_number_the_faces_across_each_edge_from_the_face_itself() {
    let polys = [
        floor_strip(0.0, 4.0),
        floor_strip(4.0, 8.0),
        floor_strip(8.0, 256.0),
    ];
    let bsp = synthetic_bsp(&polys, "{ \"classname\" \"worldspawn\" }");
    let faces = face_geometry(&bsp, |_| DVec3::ZERO, |_| Spacing::Quake).expect("faces");
    let face_of = |c: &crate::faces::Continuations, k: usize| c.face(k).map(|(f, _)| f);
    let crossed = |c: &crate::faces::Continuations, k: usize| {
        let mut to: Vec<usize> = (0..4).filter_map(|edge| c.across(k, edge)).collect();
        to.sort_unstable();
        to
    };
    let middle = &faces[1].continuations;
    assert_eq!(middle.len(), 2);
    assert_eq!(
        [0, 1, 2].map(|k| face_of(middle, k)),
        [Some(1), Some(0), Some(2)]
    );
    // The middle strip's long edges lead to both neighbours; each neighbour's back to it.
    assert_eq!(crossed(middle, 0), [1, 2]);
    assert_eq!(crossed(middle, 1), [0]);
    assert_eq!(crossed(middle, 2), [0]);
    // Seen from the first strip, the same faces have other numbers.
    let first = &faces[0].continuations;
    assert_eq!(
        [0, 1, 2].map(|k| face_of(first, k)),
        [Some(0), Some(1), Some(2)]
    );
    assert_eq!(crossed(first, 0), [1]);
    assert_eq!(crossed(first, 1), [0, 2]);
    assert!(first.region(2).is_some() && first.region(3).is_none());
}

/// Regression: a luxel past a face's edge and past the face continuing the plane there as well
/// was moved back onto the face's own outline; ericw-tools walks it across the edge onto the
/// continuing face and moves it onto that face's outline, where the surface it stands over ends.
/// Here the luxel row the grid puts at y 16 lies past a strip 8 wide and past the 4-wide strip beside
/// it: it belongs at the far edge of the second strip (y 12), not at the first one's (y 8).
#[test]
fn samples_past_the_continuing_face_move_onto_its_outline() {
    let polys = [floor_strip(0.0, 8.0), floor_strip(8.0, 12.0)];
    let bsp = synthetic_bsp(&polys, "{ \"classname\" \"worldspawn\" }");
    let faces = face_geometry(&bsp, |_| DVec3::ZERO, |_| Spacing::Quake).expect("faces");
    let (samples, _) = face_samples(&faces[0], 1, &bsp);
    assert_eq!(samples.height, 2);
    let past: Vec<&[f32; 3]> = samples.points.iter().filter(|p| p[1] > 8.0).collect();
    assert_eq!(past.len(), samples.width);
    assert!(past.iter().all(|p| p[1] == 12.0 && p[2] == 1.0), "{past:?}");
}

#[test]
fn sample_points_invert_an_angled_projection() {
    // A sloped face with a skewed, off-grid texture projection.
    let poly = Poly {
        points: vec![
            [3.3, 0.0, 0.0],
            [3.3, 90.7, 30.2],
            [77.1, 90.7, 30.2],
            [77.1, 0.0, 0.0],
        ],
        normal: {
            let n = DVec3::new(0.0, -30.2, 90.7).normalized().expect("n");
            n.as_vec3().to_array()
        },
        sky: false,
    };
    let mut bsp = synthetic_bsp(&[poly], "{ \"classname\" \"worldspawn\" }");
    bsp.texinfo[0].vecs = [[0.9, 0.1, 0.0, 5.5], [0.05, -0.7, -0.3, -3.25]];
    let faces = face_geometry(&bsp, |_| DVec3::ZERO, |_| Spacing::Quake).expect("faces");
    let (samples, _) = face_samples(&faces[0], 1, &bsp);
    let ext = faces[0].extents;
    assert_eq!([samples.width, samples.height], ext.luxel_size());
    let v = bsp.texinfo[0].vecs;
    let n = faces[0].plane.normal;
    let region = faces[0].region();
    let mut exact = 0;
    for y in 0..samples.height {
        for x in 0..samples.width {
            let p = Vec3::from(samples.points[y * samples.width + x]).as_dvec3() - n;
            assert!(faces[0].plane.distance(p).abs() < 1e-3);
            let st = ext.luxel_st(x, y);
            let tex = |p: DVec3, axis: usize| {
                let a = v[axis];
                p.x * f64::from(a[0])
                    + p.y * f64::from(a[1])
                    + p.z * f64::from(a[2])
                    + f64::from(a[3])
            };
            if region.nearest(p).near(p, 1e-3) && (0..2).all(|a| (tex(p, a) - st[a]).abs() < 1e-2) {
                exact += 1;
            } else {
                // Outside the face: moved onto it, at its edge.
                assert!(
                    region.nearest(p).near(p, 1e-3),
                    "luxel {x},{y}: {p:?} is off the face"
                );
            }
        }
    }
    assert!(
        exact >= 4,
        "luxels inside the face keep their exact positions"
    );
}

#[test]
fn default_is_close_to_reference_on_the_shadow_scene() {
    // Linear falloff with the default angle term: smooth gradients plus one hard shadow.
    let bsp = shadow_scene("\"light\" \"300\"");
    let default = compute_lighting(&bsp, &options(Quality::Default)).expect("default");
    let extra4 = compute_lighting(&bsp, &options(Quality::Extra4)).expect("extra4");
    let reference = compute_lighting(&bsp, &options(Quality::Reference)).expect("reference");
    let e_default = compare(&default, &reference);
    let e_extra4 = compare(&extra4, &reference);
    // Point samples miss partial coverage of shadow-edge luxels: a few levels
    // RMSE, up to the full lit value on an edge luxel.
    assert!(e_default.rmse < 8.0, "{e_default:?}");
    assert!(e_default.max <= 80, "{e_default:?}");
    // 4x4 supersampling lands within a few levels of 16x16 everywhere.
    assert!(e_extra4.rmse < 2.0, "{e_extra4:?}");
    assert!(e_extra4.max <= 12, "{e_extra4:?}");
    assert!(e_extra4.rmse < e_default.rmse);
}

/// A right triangle 48 units a side on the floor, a light over it.
fn triangle_scene() -> Bsp {
    let triangle = Poly {
        points: vec![[0.0, 0.0, 0.0], [0.0, 48.0, 0.0], [48.0, 0.0, 0.0]],
        normal: [0.0, 0.0, 1.0],
        sky: false,
    };
    let ents =
        "{ \"classname\" \"worldspawn\" }\n{ \"classname\" \"light\" \"origin\" \"16 16 64\" }\n";
    synthetic_bsp(&[triangle], ents)
}

/// The error over drawn luxels leaves out the luxels no engine draws (the far corner of a
/// triangle's lightmap) and weighs the others by the area of the face each shows on.
#[test]
fn error_over_drawn_luxels_weighs_luxels_by_the_face_they_show_on() {
    let bsp = triangle_scene();
    let lit = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let drawn = crate::DrawnAreas::on_quake_grids(&bsp, &[0]);
    let areas = drawn.of(0).expect("the face is drawn");
    // 4 x 4 luxels; those at (48, 48), (32, 48) and (48, 32) are a luxel or more from the
    // hypotenuse along an axis.
    assert_eq!(areas.len(), 16);
    assert_eq!(areas.iter().filter(|&&a| a == 0.0).count(), 3, "{areas:?}");
    let unseen = areas
        .iter()
        .position(|&a| a == 0.0)
        .expect("a corner no one sees");
    let with_luxel = |i: usize, value: u8| {
        let mut other = lit.clone();
        other.lightmaps[0].grey[0][i] = value;
        other
    };
    let off = |i: usize| {
        let v = lit.lightmaps[0].grey[0][i];
        if v >= 128 { v - 100 } else { v + 100 }
    };
    let e = crate::compare_drawn(&with_luxel(unseen, off(unseen)), &lit, &drawn);
    assert_eq!((e.luxels, e.max), (13, 0), "{e:?}");
    assert_eq!(compare(&with_luxel(unseen, off(unseen)), &lit).max, 100);
    // One luxel 100 levels off: the RMSE is 100 times the root of its share of the areas.
    let total: f64 = areas.iter().sum();
    for i in (0..16).filter(|&i| areas[i] > 0.0) {
        let e = crate::compare_drawn(&with_luxel(i, off(i)), &lit, &drawn);
        let expected = 100.0 * (areas[i] / total).sqrt();
        assert!((e.rmse - expected).abs() < 1e-9, "luxel {i}: {e:?}");
    }
}

/// Regression: a map with no light source was written with a lighting lump of zeros, which
/// engines draw black; an empty lump they draw fullbright, as an unlit map.
#[test]
fn a_map_without_light_sources_is_left_fullbright() {
    let mut dark = synthetic_bsp(&[floor(256.0)], "{ \"classname\" \"worldspawn\" }\n");
    let lighting = compute_lighting(&dark, &options(Quality::Default)).expect("light");
    assert!(lighting.stats.fullbright);
    assert!(apply_lighting(&mut dark, &lighting).lit.is_none());
    assert!(dark.lighting.is_empty());
    assert!(dark.faces.iter().all(|f| f.light_offset == -1));

    // A minlight alone is a light source.
    let mut dim = synthetic_bsp(
        &[floor(256.0)],
        "{ \"classname\" \"worldspawn\" \"light\" \"20\" }\n",
    );
    let lighting = compute_lighting(&dim, &options(Quality::Default)).expect("light");
    assert!(!lighting.stats.fullbright);
    apply_lighting(&mut dim, &lighting);
    assert!(!dim.lighting.is_empty() && dim.lighting.iter().all(|&v| v > 0));
}

#[test]
fn lit_file_only_for_coloured_light() {
    let mut white = shadow_scene("\"light\" \"300\"");
    let lighting = compute_lighting(&white, &options(Quality::Default)).expect("white");
    assert!(apply_lighting(&mut white, &lighting).lit.is_none());
    assert!(!white.lighting.is_empty());

    let mut red = shadow_scene("\"light\" \"300\" \"_color\" \"255 0 0\"");
    let lighting = compute_lighting(&red, &options(Quality::Default)).expect("red");
    let lit = apply_lighting(&mut red, &lighting)
        .lit
        .expect("coloured map gets a .lit");
    assert_eq!(lit.len(), 8 + 3 * red.lighting.len());
    let rgb = quake_formats::lit::read_lit(&lit, red.lighting.len()).expect("valid .lit");
    assert!(rgb.chunks(3).all(|c| c[1] == 0 && c[2] == 0));
    assert!(rgb.chunks(3).any(|c| c[0] > 0));
    // Faces point into the lump; everything else in the BSP survives a write/read.
    let again = Bsp::read(&red.write().expect("write")).expect("read");
    assert_eq!(again.lighting, red.lighting);
    assert_eq!(again.faces[0].styles, [0, 255, 255, 255]);
    assert_eq!(again.faces[0].light_offset, 0);
}

#[test]
fn switchable_lights_get_their_own_style() {
    let mut bsp = shadow_scene("\"light\" \"300\" \"targetname\" \"lamp\"");
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    apply_lighting(&mut bsp, &lighting);
    // Style 0 is dark all over, so only the switchable style is written.
    assert_eq!(bsp.faces[0].styles, [32, 255, 255, 255]);
    assert!(bsp.entity_text().contains("\"style\" \"32\""));
    let floor = &lighting.lightmaps[0];
    assert!(floor.grey[0].iter().any(|&v| v > 20));
}

#[test]
fn onlyents_styles_switchable_lights_and_keeps_lightmaps() {
    let mut bsp = shadow_scene("\"light\" \"300\"");
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    apply_lighting(&mut bsp, &lighting);
    let (lightmaps, faces) = (bsp.lighting.clone(), bsp.faces.clone());
    // What `slipgate bsp --onlyents` leaves after the light got a name.
    let renamed = bsp.entity_text().replace(
        "\"classname\" \"light\"",
        "\"classname\" \"light\" \"targetname\" \"lamp\"",
    );
    bsp.set_entity_text(&renamed);
    assert_eq!(update_entities_only(&mut bsp).expect("entities"), 1);
    assert!(bsp.entity_text().contains("\"style\" \"32\""));
    assert_eq!(
        (bsp.lighting.clone(), bsp.faces.clone()),
        (lightmaps, faces)
    );
}

/// Runs `slipgate light ARGS` on `bsp` written into a scratch folder; returns the folder.
fn light_cli(name: &str, bsp: &Bsp, args: &[&str]) -> std::path::PathBuf {
    use clap::Parser;
    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: crate::cli::Args,
    }
    let dir = std::env::temp_dir().join(format!("slipgate-light-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    let path = dir.join("scene.bsp");
    std::fs::write(&path, bsp.write().expect("write")).expect("write bsp");
    let mut argv = vec!["light".to_string()];
    argv.extend(args.iter().map(|a| a.to_string()));
    argv.push(path.display().to_string());
    let cli = Cli::try_parse_from(argv).expect("arguments");
    crate::cli::run(&cli.args).expect("light");
    dir
}

/// `--compare-reference` reports the error over the luxels engines draw and over every luxel,
/// in its output and its `--stats` file.
#[test]
fn compare_reference_measures_drawn_luxels_and_whole_lightmaps() {
    let stats = std::env::temp_dir().join(format!(
        "slipgate-light-{}-compare-stats.json",
        std::process::id()
    ));
    let stats_arg = stats.display().to_string();
    let dir = light_cli(
        "compare-reference",
        &triangle_scene(),
        &["--compare-reference", "--stats", &stats_arg],
    );
    let text = std::fs::read_to_string(&stats).expect("stats file");
    let json: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    let luxels = |key: &str| json[key]["luxels"].as_u64().expect(key);
    let drawn = luxels("error_vs_reference");
    let whole = luxels("error_whole_lightmaps_vs_reference");
    // Three luxels of the triangle's lightmap lie past its hypotenuse.
    assert_eq!((drawn, whole), (13, 16));
    std::fs::remove_dir_all(dir).ok();
    std::fs::remove_file(stats).ok();
}

#[test]
fn lit_and_nolit_force_or_forbid_the_lit_file() {
    let white = shadow_scene("\"light\" \"300\"");
    let dir = light_cli("lit", &white, &["--lit"]);
    let bsp = Bsp::read(&std::fs::read(dir.join("scene.bsp")).expect("bsp")).expect("read");
    let lit = std::fs::read(dir.join("scene.lit")).expect("--lit writes a .lit for white light");
    let rgb = quake_formats::lit::read_lit(&lit, bsp.lighting.len()).expect("valid .lit");
    assert!(
        rgb.chunks(3)
            .zip(&bsp.lighting)
            .all(|(c, &g)| c == [g, g, g])
    );

    let red = shadow_scene("\"light\" \"300\" \"_color\" \"255 0 0\"");
    let dir = light_cli("nolit", &red, &["--nolit"]);
    assert!(!dir.join("scene.lit").exists(), "--nolit writes no .lit");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn threads_option_gives_the_same_bytes() {
    let scene = shadow_scene("\"light\" \"300\"");
    let one = light_cli("threads1", &scene, &["--threads", "1"]);
    let two = light_cli("threads2", &scene, &["--threads", "2"]);
    let read = |d: &std::path::Path| std::fs::read(d.join("scene.bsp")).expect("bsp");
    assert_eq!(read(&one), read(&two));
    std::fs::remove_dir_all(one).ok();
    std::fs::remove_dir_all(two).ok();
}

#[test]
fn sun_reaches_only_what_sees_the_sky() {
    // A floor under a sky ceiling, with an opaque slab shading part of it.
    let mut polys = vec![floor(256.0)];
    polys.push(sky_ceiling());
    polys.extend(box_faces([0.0, 0.0, 200.0], [128.0, 256.0, 208.0]));
    let ents = "{ \"classname\" \"worldspawn\" \"_sunlight\" \"200\" \"_anglescale\" \"0\" }\n";
    let bsp = synthetic_bsp(&polys, ents);
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let floor = lighting
        .lightmaps
        .iter()
        .find(|m| m.face == 0)
        .expect("floor");
    for x in 0..floor.width {
        let v = floor.grey[0][8 * floor.width + x];
        let wx = 16 * x;
        if wx > 0 && wx < 128 {
            assert_eq!(v, 0, "x {wx} is under the slab");
        } else if wx > 128 {
            assert_eq!(v, 100, "x {wx} sees the sky");
        }
    }
}

/// The corpus BSP at `path` (under `../shared/corpus/public/bsp`), or `None` with a note that
/// the test is skipped when the corpus is not there.
fn corpus_bsp(path: &str) -> Option<Bsp> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/corpus/public/bsp")
        .join(path);
    let Ok(data) = std::fs::read(&path) else {
        eprintln!("SKIPPED: {} not found", path.display());
        return None;
    };
    Some(Bsp::read(&data).expect("read"))
}

/// Default against reference on a sample of start.bsp's faces, leaving out those engines do not
/// draw lit: faces whose texture is fullbright in every texel, and faces whose middle stands in
/// solid or sky (the walls inside its sky brushes). On those the reference measures only the
/// few of its 256 points per luxel that a nudge frees into a room beside. Slow in debug builds:
/// `cargo test -p slipgate-light --release -- --ignored`.
#[test]
#[ignore = "slow: run with --release -- --ignored"]
fn start_bsp_default_against_reference() {
    let Some(bsp) = corpus_bsp("librequake/start.bsp") else {
        return;
    };
    let prep = crate::prepare::prepare(&bsp, &Options::default()).expect("prepare");
    let drawn_lit = |f: &&crate::faces::FaceGeom| {
        let front = f.centroid() + f.plane.normal;
        !bsp.face_texture(&bsp.faces[f.index])
            .is_some_and(quake_formats::miptex::MipTex::is_all_fullbright)
            && !crate::samples::solid_at(&bsp, front.as_vec3().to_array())
    };
    let only: Vec<usize> = prep
        .faces
        .iter()
        .filter(|f| f.index % 8 == 0)
        .filter(drawn_lit)
        .map(|f| f.index)
        .collect();
    let run = |quality| {
        let o = Options {
            quality,
            only_faces: Some(only.clone()),
            ..Options::default()
        };
        compute_lighting(&bsp, &o).expect("light")
    };
    let reference = run(Quality::Reference);
    let e = compare(&run(Quality::Default), &reference);
    eprintln!("start.bsp default vs reference: {e:?}");
    let e4 = compare(&run(Quality::Extra4), &reference);
    eprintln!("start.bsp extra4 vs reference: {e4:?}");
    // Samples stand where ericw-tools puts them: one per luxel, on the face's edge or nudged
    // half a unit out of solid beside it. The largest differences are where that one point
    // takes a light a few units away (the `_surface` copies beside start's fixtures) or
    // misses it.
    assert!(e.rmse < 10.5, "{e:?}");
    assert!(e4.rmse < 2.6, "{e4:?}");
    assert!(e4.rmse < e.rmse, "{e4:?} {e:?}");
}

/// ericw-tools' cube has no light entity: it stays fullbright, and the file still round-trips
/// (breaking no rule but the missing clip hulls it was compiled without).
#[test]
fn q1_cube_without_lights_stays_fullbright_and_round_trips() {
    let Some(mut bsp) = corpus_bsp("ericw-tools/q1_cube.bsp") else {
        return;
    };
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    assert!(lighting.stats.fullbright);
    assert!(
        apply_lighting(&mut bsp, &lighting).lit.is_none(),
        "no lights, no .lit"
    );
    assert!(bsp.lighting.is_empty());
    let again = Bsp::read(&bsp.write().expect("write")).expect("read back");
    assert_eq!(again.faces, bsp.faces);
    let errors: Vec<&str> = quake_formats::validate(&again)
        .iter()
        .filter(|p| p.severity == quake_formats::Severity::Error)
        .map(|p| p.rule.id())
        .collect();
    assert!(
        errors.iter().all(|&id| id == "clip-hulls-missing"),
        "{errors:?}"
    );
}

/// A floor (x 0..192, y 0..256) ending at the foot of a wall block (x from 192), lit evenly
/// (constant falloff, no angle term) from above. The floor ends at the wall, as the compiler
/// cuts it: these BSPs have no tree to tell that a sample under the wall is in solid.
fn corner_scene(world_keys: &str, light_keys: &str) -> Bsp {
    let mut polys = vec![floor_rect(192.0, 256.0)];
    polys.extend(box_faces([192.0, -64.0, 0.0], [320.0, 320.0, 256.0]));
    let ents = format!(
        "{{ \"classname\" \"worldspawn\" {world_keys} }}\n{{ \"classname\" \"light\" \"origin\" \"96 128 200\" \"light\" \"200\" \"delay\" \"3\" \"_anglescale\" \"0\" {light_keys} }}\n"
    );
    synthetic_bsp(&polys, &ents)
}

/// Grey style-0 values of floor row `y` (luxels 0..=12 reach x = 192).
fn floor_row(bsp: &Bsp, options: &Options, y: usize) -> Vec<u8> {
    let lighting = compute_lighting(bsp, options).expect("light");
    let m = lighting
        .lightmaps
        .iter()
        .find(|m| m.face == 0)
        .expect("floor");
    m.grey[0][y * m.width..y * m.width + 12].to_vec()
}

#[test]
fn dirt_darkens_the_corner_but_not_the_open_floor() {
    let plain = floor_row(&corner_scene("", ""), &options(Quality::Default), 8);
    assert!(plain.iter().all(|&v| v == 100), "{plain:?}");
    for mode in ["0", "1"] {
        let keys = format!("\"_dirt\" \"1\" \"_dirtmode\" \"{mode}\"");
        let dirty = floor_row(&corner_scene(&keys, ""), &options(Quality::Default), 8);
        // Luxel 11 is 16 units from the wall's foot; luxels 0..=3 are over 128 units away.
        assert!(dirty[11] < 90, "mode {mode}: corner {dirty:?}");
        assert!(
            dirty[11] < dirty[9] && dirty[9] < dirty[6],
            "mode {mode}: {dirty:?}"
        );
        assert!(
            dirty[..4].iter().all(|&v| v == 100),
            "mode {mode}: open {dirty:?}"
        );
    }
}

#[test]
fn a_liquid_surface_takes_no_dirt() {
    // ericw-tools never darkens a lit liquid by dirt: the corner scene's floor as water stays
    // as bright by the wall as in the open, where as a wall texture it darkens there.
    let mut bsp = corner_scene("\"_dirt\" \"1\"", "");
    bsp.textures.textures.push(Some(mip("*water1")));
    bsp.texinfo[0].miptex = bsp.textures.textures.len() as u32 - 1;
    let row = floor_row(&bsp, &options(Quality::Default), 8);
    assert!(row.iter().all(|&v| v == 100), "{row:?}");
}

#[test]
fn dirt_switches_per_light_and_from_the_command_line() {
    // The light opts out of worldspawn's dirt.
    let opted_out = floor_row(
        &corner_scene("\"_dirt\" \"1\"", "\"_dirt\" \"-1\""),
        &options(Quality::Default),
        8,
    );
    assert!(opted_out.iter().all(|&v| v == 100), "{opted_out:?}");
    // --dirt turns it on without any key in the map; a stronger scale darkens more.
    let mut forced = options(Quality::Default);
    forced.overrides.dirt = Some(true);
    let on = floor_row(&corner_scene("", ""), &forced, 8);
    assert!(on[11] < 80, "{on:?}");
    forced.overrides.dirt_scale = Some(2.0);
    let stronger = floor_row(&corner_scene("", ""), &forced, 8);
    assert!(stronger[11] < on[11], "{stronger:?} vs {on:?}");
    // Minlight takes dirt too (worldspawn `light` is minlight; the light is off).
    let min_only = floor_row(
        &corner_scene(
            "\"light\" \"100\" \"_dirt\" \"1\"",
            "\"_nostaticlight\" \"1\"",
        ),
        &options(Quality::Default),
        8,
    );
    assert!(
        min_only[11] < min_only[2] && min_only[2] == 50,
        "{min_only:?}"
    );
    let min_clean = floor_row(
        &corner_scene(
            "\"light\" \"100\" \"_dirt\" \"1\" \"_minlight_dirt\" \"-1\"",
            "\"_nostaticlight\" \"1\"",
        ),
        &options(Quality::Default),
        8,
    );
    assert!(min_clean.iter().all(|&v| v == 50), "{min_clean:?}");
}

/// A 1/x² light 2 units above a floor (where `_surface` copies sit) gives each luxel the light
/// at its one sample point, a unit above the floor, as ericw-tools does: the brightest luxel is
/// the one whose point lies nearest the light, at the formula's value there.
#[test]
fn a_light_just_above_a_floor_lights_each_luxel_at_its_sample_point() {
    let ents = "{ \"classname\" \"worldspawn\" }\n{ \"classname\" \"light\" \"origin\" \"133 141 2\" \"light\" \"0.5\" \"delay\" \"2\" }\n";
    let bsp = synthetic_bsp(&[floor(256.0)], ents);
    let lit = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let brightest = lit.lightmaps[0].grey[0]
        .iter()
        .copied()
        .max()
        .expect("luxels");
    // The nearest sample point: (128, 144, 1), sqrt(35) units from the light, whose cosine
    // there is 1 / sqrt(35); inverse square at 128 units, anglescale 0.5, range 0.5.
    let d2 = 35.0_f64;
    let expected = 0.5 * 128.0 * 128.0 / d2 * (0.5 + 0.5 / d2.sqrt()) * 0.5;
    assert!(
        (f64::from(brightest) - expected).abs() <= 1.0,
        "{brightest} against {expected}"
    );
}

/// An octagonal column (radius 64, height 128, axis through 256 256) on a
/// floor, lit from the side by a constant light with a pure cosine term.
fn column_scene(world_keys: &str) -> Bsp {
    let mut polys = vec![floor(512.0)];
    let corner = |k: usize| {
        let a = (k as f64 + 0.5) * std::f64::consts::TAU / 8.0;
        [256.0 + 64.0 * a.cos() as f32, 256.0 + 64.0 * a.sin() as f32]
    };
    for k in 0..8 {
        let ([x0, y0], [x1, y1]) = (corner(k), corner(k + 1));
        let mid = (k as f64 + 1.0) * std::f64::consts::TAU / 8.0;
        let n = [mid.cos() as f32, mid.sin() as f32, 0.0];
        // Clockwise seen from outside.
        polys.push(quad(
            [x0, y0, 0.0],
            [x0, y0, 128.0],
            [x1, y1, 128.0],
            [x1, y1, 0.0],
            n,
        ));
    }
    let ents = format!(
        "{{ \"classname\" \"worldspawn\" {world_keys} }}\n{{ \"classname\" \"light\" \"origin\" \"600 300 64\" \"light\" \"400\" \"delay\" \"3\" \"_anglescale\" \"1\" }}\n"
    );
    synthetic_bsp(&polys, &ents)
}

/// For each pair of neighbouring column faces that both face the light, how fast the light
/// changes across their shared edge (between the two samples standing on the faces nearest it,
/// at mid height) over how fast it changes at most between neighbouring samples within either
/// face: near 1 where the light turns smoothly over the edge, far above where it steps.
fn edge_jumps(world_keys: &str) -> Vec<f64> {
    let bsp = column_scene(world_keys);
    let prep = crate::prepare::prepare(&bsp, &Options::default()).expect("prepare");
    let light_reaches = crate::reach::light_reaches(&prep.point_lights, 0.001);
    let setup = crate::trace::TraceSetup {
        suns: &[],
        dirt: None,
        ..prep.trace_setup(&light_reaches, 0.001, true, true)
    };
    // Value and position of every sample at mid height of each column face.
    let rows: Vec<Vec<(DVec3, f64)>> = (1..=8)
        .map(|f| {
            let geom = &prep.faces[f];
            let (mut samples, _) = face_samples(geom, 1, &bsp);
            if let Some(normals) = crate::phong::sample_normals(&samples, &prep.faces, &prep.phong)
            {
                samples.normals = normals;
            }
            let rules = crate::trace::FaceRules::default();
            let mut scratch = crate::trace::TraceScratch::default();
            let (light, _) = crate::trace::trace_face(&setup, &samples, &rules, &mut scratch);
            let light = light.finish(
                &[],
                crate::trace::HiddenLuxels::FromNeighbours,
                crate::luxels::ToLuxels::OpenMeans,
            );
            // Samples that walked off the face onto its neighbour stand for that face.
            let own = |i: usize| samples.landed.get(i).is_none_or(|&g| g as usize == f);
            samples
                .points
                .iter()
                .zip(&light.styles[0].1)
                .enumerate()
                .filter(|&(i, _)| own(i))
                .map(|(_, (&p, v))| (Vec3::from(p).as_dvec3(), f64::from(v[0])))
                .filter(|(p, _)| (p.z - 64.0).abs() <= 8.0)
                .collect()
        })
        .collect();
    let mut jumps = Vec::new();
    let steepest = |row: &[(DVec3, f64)]| {
        row.windows(2)
            .map(|w| (w[1].1 - w[0].1).abs() / (w[1].0 - w[0].0).length())
            .fold(0.0, f64::max)
    };
    for k in 0..8 {
        let (a, b) = (&rows[k], &rows[(k + 1) % 8]);
        if a.iter().chain(b).any(|&(_, v)| v <= 0.0) {
            continue; // not both facing the light
        }
        // The shared corner's position at mid height.
        let ang = (k as f64 + 1.5) * std::f64::consts::TAU / 8.0;
        let edge = DVec3::new(256.0 + 64.0 * ang.cos(), 256.0 + 64.0 * ang.sin(), 64.0);
        let nearest = |row: &[(DVec3, f64)]| {
            *row.iter()
                .min_by(|x, y| (x.0 - edge).length().total_cmp(&(y.0 - edge).length()))
                .expect("samples")
        };
        let ((pa, va), (pb, vb)) = (nearest(a), nearest(b));
        let across = (va - vb).abs() / (pa - pb).length().max(1e-3);
        jumps.push(across / steepest(a).max(steepest(b)).max(1e-3));
    }
    jumps
}

#[test]
fn phong_smooths_a_column_without_facet_bands() {
    let flat = edge_jumps("");
    let smooth = edge_jumps("\"_phong\" \"1\"");
    assert!(flat.len() >= 2, "{flat:?}");
    assert_eq!(flat.len(), smooth.len());
    // Flat facets 45 degrees apart: a cosine step at each edge, far steeper than the light
    // changes within a face.
    assert!(flat.iter().all(|&j| j > 10.0), "{flat:?}");
    // Smoothed: across an edge the light changes no faster than within the faces.
    assert!(smooth.iter().all(|&j| j < 1.5), "{smooth:?}");
}

/// Regression: on a `_phong` column a luxel past a face's edge was moved back onto that edge;
/// ericw-tools walks it onto the face smoothed with it beyond the edge, on that face's plane,
/// where it takes that face's normal. Without `_phong` the faces do not continue each other.
#[test]
fn samples_past_a_phong_face_walk_onto_the_smoothed_face() {
    let walked = |world_keys: &str| {
        let bsp = column_scene(world_keys);
        let prep = crate::prepare::prepare(&bsp, &Options::default()).expect("prepare");
        let (samples, _) = face_samples(&prep.faces[1], 1, &bsp);
        let mut on_others = 0;
        for (i, &g) in samples.landed.iter().enumerate() {
            if g == 1 {
                continue;
            }
            on_others += 1;
            // Lifted a unit off the other face's plane (half a unit more or less if nudged).
            let p = Vec3::from(samples.points[i]).as_dvec3();
            let off = prep.faces[g as usize].plane.distance(p);
            assert!((0.4..=1.6).contains(&off), "sample {i} on face {g}: {off}");
        }
        on_others
    };
    assert!(walked("\"_phong\" \"1\"") > 0);
    assert_eq!(walked(""), 0);
}

/// Culling is exact: on a `_phong` column, the faces just past the light's terminator have the
/// light behind their flat plane but in front of their smoothed corner normals, so culling by
/// that plane would darken them.
#[test]
fn culling_leaves_phong_faces_lit_from_behind_their_plane() {
    let bsp = column_scene("\"_phong\" \"1\"");
    let culled = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let everything = compute_lighting(
        &bsp,
        &Options {
            no_cull: true,
            ..options(Quality::Default)
        },
    )
    .expect("light");
    let e = crate::compare(&culled, &everything);
    assert!(e.luxels > 0);
    assert_eq!(e.max, 0, "{e:?}");
}

/// Floor 0..256 (world) and brush model *1: a pedestal (x, y 96..160, up to
/// z 64) under a wider slab (32..224, z 64..80), keyed `model_keys`. Light
/// comes from high up on the +x side, from a constant light or (`sun`) a sun
/// under a sky ceiling: the slab hides the pedestal's +x face (face 3) and
/// the floor strip just beyond it.
fn overhang_scene(model_keys: &str, sun: bool) -> Bsp {
    let mut world = vec![floor(256.0)];
    let mut model = box_faces([96.0, 96.0, 0.0], [160.0, 160.0, 64.0]);
    model.extend(box_faces([32.0, 32.0, 64.0], [224.0, 224.0, 80.0]));
    let (world_keys, light) = if sun {
        world.push(sky_ceiling());
        let keys = "\"_sunlight\" \"200\" \"_sun_mangle\" \"180 -57 0\" \"_anglescale\" \"0\"";
        (keys, String::new())
    } else {
        let light = "{ \"classname\" \"light\" \"origin\" \"400 128 400\" \"light\" \"200\" \"delay\" \"3\" \"_anglescale\" \"0\" }\n";
        ("", light.to_string())
    };
    let ents = format!(
        "{{ \"classname\" \"worldspawn\" {world_keys} }}\n\
         {{ \"classname\" \"func_wall\" \"model\" \"*1\" {model_keys} }}\n{light}"
    );
    synthetic_bsp_models(&[&world, &model], &ents)
}

/// The grey style-0 value of the luxel of `face` at texture coordinates
/// `(s, t)` (the luxel whose centre grid point is nearest).
fn luxel_at(bsp: &Bsp, lighting: &crate::Lighting, face: usize, s: f64, t: f64) -> u8 {
    let faces = face_geometry(bsp, |_| DVec3::ZERO, |_| Spacing::Quake).expect("faces");
    let mins = faces[face].extents.tex_mins;
    let m = lighting
        .lightmaps
        .iter()
        .find(|m| m.face == face)
        .expect("lit face");
    let col = ((s - f64::from(mins[0])) / 16.0).round() as usize;
    let row = ((t - f64::from(mins[1])) / 16.0).round() as usize;
    m.style_grey(0).map_or(0, |g| {
        g[row.min(m.height - 1) * m.width + col.min(m.width - 1)]
    })
}

#[test]
fn shadowself_shadows_the_model_but_not_the_floor() {
    for sun in [false, true] {
        let run = |keys: &str| {
            let bsp = overhang_scene(keys, sun);
            let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
            // Floor at x 176, y 128 (s = x, t = -y); the pedestal's +x
            // face (s = y, t = -z) at its middle.
            let pedestal = bsp.models[1].first_face as usize + 2;
            (
                luxel_at(&bsp, &lighting, 0, 176.0, -128.0),
                luxel_at(&bsp, &lighting, pedestal, 128.0, -32.0),
            )
        };
        let (floor, pedestal) = run("");
        assert_eq!(
            (floor, pedestal),
            (100, 100),
            "sun {sun}: no shadows from the model"
        );
        let (floor, pedestal) = run("\"_shadow\" \"1\"");
        assert_eq!(
            (floor, pedestal),
            (0, 0),
            "sun {sun}: the model shadows everything"
        );
        for key in ["_shadowself", "_selfshadow"] {
            let (floor, pedestal) = run(&format!("\"{key}\" \"1\""));
            assert_eq!(
                (floor, pedestal),
                (100, 0),
                "sun {sun}, {key}: only its own faces"
            );
        }
    }
}

#[test]
fn addmin_adds_minlight_instead_of_raising_to_it() {
    // Worldspawn minlight 40 (20 in bytes) under a light that gives 100.
    let bsp = corner_scene("\"light\" \"40\"", "");
    let floor = floor_row(&bsp, &options(Quality::Default), 8);
    assert!(floor.iter().all(|&v| v == 100), "floor: {floor:?}");
    let mut add = options(Quality::Default);
    add.overrides.addmin = Some(true);
    let added = floor_row(&bsp, &add, 8);
    assert!(added.iter().all(|&v| v == 120), "added: {added:?}");
    // Where no light reaches, both give the minlight itself.
    let dark = corner_scene("\"light\" \"40\"", "\"_nostaticlight\" \"1\"");
    assert_eq!(
        floor_row(&dark, &add, 8),
        floor_row(&dark, &options(Quality::Default), 8)
    );
    assert!(floor_row(&dark, &add, 8).iter().all(|&v| v == 20));
}

#[test]
fn dirt_cone_follows_the_phong_normal() {
    // The floor of the corner scene: the wall stands at x = 192.
    let bsp = corner_scene("", "");
    let prep = crate::prepare::prepare(&bsp, &Options::default()).expect("prepare");
    let (mut samples, _) = face_samples(&prep.faces[0], 1, &bsp);
    let sampling = crate::lights::dirt_sampling(&crate::settings::Settings::default());
    let occlusion = |samples: &crate::samples::FaceSamples| {
        let all: Vec<usize> = (0..samples.points.len()).collect();
        crate::dirt::occlusion_at(
            samples,
            &all,
            (0, 1),
            &sampling,
            crate::dirt::DirtRays::All,
            &prep.scene,
        )
        .0
    };
    let flat = occlusion(&samples);
    let tilted = |x: f64| {
        DVec3::new(x, 0.0, 1.0)
            .normalized()
            .expect("unit")
            .as_vec3()
            .to_array()
    };
    // Normals leaning 45 degrees toward the wall, then away from it.
    samples.normals = vec![tilted(1.0); samples.points.len()];
    let toward = occlusion(&samples);
    samples.normals = vec![tilted(-1.0); samples.points.len()];
    let away = occlusion(&samples);
    let near_wall = |values: &[f32]| {
        let (i, _) = samples
            .points
            .iter()
            .enumerate()
            .find(|(_, p)| (p[1] - 128.0).abs() < 8.0 && (p[0] - 160.0).abs() < 8.0)
            .expect("a sample near the wall");
        values[i]
    };
    assert!(
        near_wall(&toward) > near_wall(&flat) + 0.05 && near_wall(&flat) > near_wall(&away) + 0.05,
        "toward {} flat {} away {}",
        near_wall(&toward),
        near_wall(&flat),
        near_wall(&away)
    );
    // Far from the wall nothing occludes, even for cones that lean into
    // the floor (those rays are folded back above it).
    for values in [&flat, &toward, &away] {
        for (p, v) in samples.points.iter().zip(values.iter()) {
            if p[0] < 48.0 && (16.0..240.0).contains(&p[1]) {
                assert_eq!(*v, 0.0, "at {p:?}");
            }
        }
    }
}

/// A `.map` brush from planes given as three points each (Quake's order:
/// the normal is `(a - b) × (c - b)`, pointing out of the brush).
fn map_brush(planes: &[[[f64; 3]; 3]]) -> String {
    let mut s = String::from("{\n");
    for plane in planes {
        for p in plane {
            s += &format!("( {} {} {} ) ", p[0], p[1], p[2]);
        }
        s += "wall 0 0 0 1 1\n";
    }
    s + "}\n"
}

/// The axis-aligned box `lo..hi` as a `.map` brush.
fn map_box(lo: [f64; 3], hi: [f64; 3]) -> String {
    let ([x0, y0, z0], [x1, y1, z1]) = (lo, hi);
    map_brush(&[
        [[x1, y0, z0], [x1, y0, z1], [x1, y1, z0]],
        [[x0, y0, z0], [x0, y1, z0], [x0, y0, z1]],
        [[x0, y1, z0], [x1, y1, z0], [x0, y1, z1]],
        [[x0, y0, z0], [x0, y0, z1], [x1, y0, z0]],
        [[x0, y0, z1], [x0, y1, z1], [x1, y0, z1]],
        [[x0, y0, z0], [x1, y0, z0], [x0, y1, z0]],
    ])
}

/// A sealed room (inside -128..128) with an octagonal `func_detail` column
/// (about 48 units in radius, from the floor up to z 0) keyed `detail_keys`,
/// compiled by the bsp compiler.
fn detail_column_bsp(detail_keys: &str) -> Bsp {
    let lo = -128.0;
    let world = sealed_room_brushes();
    // Counter-clockwise seen from above.
    let ring = [
        [48.0, -20.0],
        [48.0, 20.0],
        [20.0, 48.0],
        [-20.0, 48.0],
        [-48.0, 20.0],
        [-48.0, -20.0],
        [-20.0, -48.0],
        [20.0, -48.0],
    ];
    let mut planes: Vec<[[f64; 3]; 3]> = (0..8)
        .map(|k| {
            let ([px, py], [qx, qy]) = (ring[k], ring[(k + 1) % 8]);
            [[qx, qy, lo], [px, py, lo], [px, py, 0.0]]
        })
        .collect();
    planes.push([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]);
    planes.push([[0.0, 0.0, lo], [1.0, 0.0, lo], [0.0, 1.0, lo]]);
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n{world}}}\n\
         {{\n\"classname\" \"func_detail\"\n{detail_keys}\n{}}}\n\
         {{\n\"classname\" \"light\"\n\"origin\" \"100 20 -40\"\n}}\n\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"-90 -90 -100\"\n}}\n",
        map_brush(&planes)
    );
    let source = bsp_compiler::MapSource {
        path: std::path::PathBuf::from("detail_column.map"),
        text,
    };
    let out =
        bsp_compiler::compile(&source, &bsp_compiler::CompileOptions::default()).expect("compile");
    assert!(out.leak.is_none(), "the room leaks");
    out.bsp
}

/// The sealed room of [`detail_column_bsp`] with a `func_door` keyed `door_keys` (x 96..140,
/// y -16..16, z -128..-64) standing on the floor and reaching 12 units into the +x wall
/// (128..144), and a light in the room, compiled by the bsp compiler.
fn door_in_wall_bsp(door_keys: &str) -> Bsp {
    let world = sealed_room_brushes();
    let door = map_box([96.0, -16.0, -128.0], [140.0, 16.0, -64.0]);
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n{world}}}\n\
         {{\n\"classname\" \"func_door\"\n{door_keys}\n{door}}}\n\
         {{\n\"classname\" \"light\"\n\"origin\" \"0 0 -32\"\n}}\n\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"-90 -90 -100\"\n}}\n"
    );
    let source = bsp_compiler::MapSource {
        path: std::path::PathBuf::from("door_in_wall.map"),
        text,
    };
    let out =
        bsp_compiler::compile(&source, &bsp_compiler::CompileOptions::default()).expect("compile");
    assert!(out.leak.is_none(), "the room leaks");
    out.bsp
}

/// The index of the face of [`door_in_wall_bsp`]'s door (model 1) that faces along a normal.
fn door_face_facing(bsp: &Bsp) -> impl Fn(DVec3) -> usize {
    let prep = crate::prepare::prepare(bsp, &Options::default()).expect("prepare");
    move |normal| {
        prep.faces
            .iter()
            .find(|f| f.model == 1 && f.plane.normal.dot(normal) > 0.99)
            .map(|f| f.index)
            .expect("door face")
    }
}

/// Regression: a door's faces inside the wall it slides into were black (their rays start in
/// the wall's solid), so they showed black once the door moved. As in ericw-tools, samples in
/// the world's solid are occluded: a luxel with some open samples keeps their mean, one with
/// none its open neighbours' (on a face half in the wall), and a face with no open luxel at
/// all takes its model's mean.
#[test]
fn door_faces_inside_a_wall_are_not_black() {
    let bsp = door_in_wall_bsp("");
    let door_face = door_face_facing(&bsp);
    let (end, top, front) = (
        door_face(DVec3::X),
        door_face(DVec3::Z),
        door_face(-DVec3::X),
    );
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let end_grey = face_grey(&lighting, end);
    assert!(!end_grey.is_empty(), "the buried face has a lightmap");
    assert!(
        end_grey.iter().all(|&v| v > 10 && v == end_grey[0]),
        "{end_grey:?}"
    );
    assert!(face_grey(&lighting, front).iter().all(|&v| v > 10));
    // The top's luxels over the wall (x beyond 128) take the door's light too, as its buried
    // end does (ericw-tools' autominlight), not their neighbours'.
    let top_grey = face_grey(&lighting, top);
    assert!(top_grey.iter().all(|&v| v > 10), "{top_grey:?}");
    let width = top_grey.len() / 3;
    for row in top_grey.chunks(width) {
        assert_eq!(row[width - 1], end_grey[0], "{top_grey:?}");
    }
}

/// Regression: a brush model that casts shadows (`_shadow 1`) had its faces inside the world's
/// solid filled with its open faces' light, so a plaque set into a wall with a light behind it
/// read 255 on its buried front. ericw-tools gives such a model's samples in solid no light: a
/// face wholly in the wall has no lightmap, a luxel half in it (at `-extra4`) the light of its
/// open half spread over the whole. The same door without `_shadow` is filled
/// ([`door_faces_inside_a_wall_are_not_black`]).
#[test]
fn a_buried_door_face_takes_the_light_at_the_doors_middle() {
    // ericw-tools' autominlight: the luxels of a brush model's faces inside solid take the
    // direct light at the middle of the model's box, scaled once more by the range scale. The
    // door's middle (118 0 -96) is 134.2 units from the light (300, linear): 165.8 light units,
    // halved to 82.9, written at the range scale of 0.5 as 41.
    let bsp = door_in_wall_bsp("");
    let end = door_face_facing(&bsp)(DVec3::X);
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let grey = face_grey(&lighting, end);
    assert!(
        !grey.is_empty() && grey.iter().all(|&v| v.abs_diff(41) <= 1),
        "{grey:?}"
    );
}

#[test]
fn autominlight_keys_turn_it_off_everywhere_or_take_it_elsewhere() {
    let end_grey = |bsp: &Bsp| {
        let end = door_face_facing(bsp)(DVec3::X);
        face_grey(
            &compute_lighting(bsp, &options(Quality::Default)).expect("light"),
            end,
        )
    };
    // `-1`: the buried end takes no light.
    let off = end_grey(&door_in_wall_bsp("\"_autominlight\" \"-1\""));
    assert!(off.iter().all(|&v| v == 0), "{off:?}");
    // `1`: every luxel of the door takes at least the door's light, the buried end that light.
    let bsp = door_in_wall_bsp("\"_autominlight\" \"1\"");
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let door_face = door_face_facing(&bsp);
    for normal in [DVec3::X, -DVec3::X, DVec3::Z, -DVec3::Y] {
        let grey = face_grey(&lighting, door_face(normal));
        assert!(grey.iter().all(|&v| v + 1 >= 41), "{normal}: {grey:?}");
    }
    // A target 8 units under the light (300, linear): 292, halved to 146, written as 73.
    let mut bsp = door_in_wall_bsp("\"_autominlight_target\" \"spot\"");
    let text = bsp.entity_text()
        + "{\n\"classname\" \"info_null\"\n\"targetname\" \"spot\"\n\"origin\" \"0 0 -40\"\n}\n";
    bsp.set_entity_text(&text);
    let spot = end_grey(&bsp);
    assert!(
        !spot.is_empty() && spot.iter().all(|&v| v.abs_diff(73) <= 1),
        "{spot:?}"
    );
}

#[test]
fn a_shadow_casting_models_faces_inside_a_wall_stay_dark() {
    let bsp = door_in_wall_bsp("\"_shadow\" \"1\"");
    let door_face = door_face_facing(&bsp);
    let (end, top) = (door_face(DVec3::X), door_face(DVec3::Z));
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    assert!(
        face_grey(&lighting, end).iter().all(|&v| v == 0),
        "buried end lit"
    );
    // The top's last column (x 144) stands over the wall: its sample is in solid.
    let top_grey = face_grey(&lighting, top);
    let width = top_grey.len() / 3;
    for row in top_grey.chunks(width) {
        assert!(row[width - 2] > 10, "{top_grey:?}");
        assert_eq!(row[width - 1], 0, "{top_grey:?}");
    }
    // At -extra4 the column before it (x 128) is half over the wall: half its samples add
    // nothing.
    let extra4 = compute_lighting(&bsp, &options(Quality::Extra4)).expect("light");
    assert!(face_grey(&extra4, end).iter().all(|&v| v == 0));
    let top4 = face_grey(&extra4, top);
    for row in top4.chunks(width) {
        let (open, half) = (f64::from(row[width - 3]), f64::from(row[width - 2]));
        assert!((half - open / 2.0).abs() < 0.2 * open, "{top4:?}");
        assert_eq!(row[width - 1], 0, "{top4:?}");
    }
}

/// As in ericw-tools, a sample point within a tenth of a unit of a node's plane is in solid
/// when either side of it is: on the room's floor or within 0.1 over it, it is; 0.2 over it,
/// or in the room's middle, it is not. A sample lifted onto the floor's plane is nudged into the
/// room.
#[test]
fn a_point_on_a_solid_surface_is_in_solid() {
    let bsp = room_bsp("");
    let solid = |z: f32| crate::samples::solid_at(&bsp, [0.0, 0.0, z]);
    assert!(solid(-128.0) && solid(-127.95) && solid(-128.05));
    assert!(!solid(-127.8) && !solid(0.0));
    let floor = crate::prepare::prepare(&bsp, &Options::default())
        .expect("prepare")
        .faces
        .into_iter()
        .find(|f| f.model == 0 && f.plane.normal.z > 0.99)
        .expect("the floor");
    let (samples, counts) = face_samples(&floor, 1, &bsp);
    assert!(counts.nudged > 0, "{counts:?}");
    for (i, p) in samples.points.iter().enumerate() {
        let occluded = samples.occluded.get(i).copied().unwrap_or(false);
        assert!(occluded || !crate::samples::solid_at(&bsp, *p), "{p:?}");
    }
}

/// The worldspawn brushes of a sealed room, inside -128..128 on every axis, 16 units thick.
fn sealed_room_brushes() -> String {
    let (lo, hi, t) = (-128.0, 128.0, 16.0);
    let (a, b) = (lo - t, hi + t);
    let mut world = String::new();
    for (l, h) in [
        ([a, a, a], [b, b, lo]),
        ([a, a, hi], [b, b, b]),
        ([a, a, lo], [lo, b, hi]),
        ([hi, a, lo], [b, b, hi]),
        ([lo, a, lo], [hi, lo, hi]),
        ([lo, hi, lo], [hi, b, hi]),
    ] {
        world += &map_box(l, h);
    }
    world
}

/// A sealed room (inside -128..128 on every axis) with `entities` (entity blocks) after its
/// worldspawn, compiled by the bsp compiler.
fn room_bsp(entities: &str) -> Bsp {
    let world = sealed_room_brushes();
    let text = format!(
        "{{\n\"classname\" \"worldspawn\"\n{world}}}\n{entities}\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"-90 -90 -100\"\n}}\n"
    );
    let source = bsp_compiler::MapSource {
        path: std::path::PathBuf::from("room.map"),
        text,
    };
    let out =
        bsp_compiler::compile(&source, &bsp_compiler::CompileOptions::default()).expect("compile");
    assert!(out.leak.is_none(), "the room leaks");
    out.bsp
}

/// [`room_bsp`] with a slab (x, y -32..32, z -64..-48) of `texture` brushes in a `classname`
/// entity keyed `keys` above the floor, and a light over it.
fn slab_bsp(classname: &str, keys: &str, texture: &str) -> Bsp {
    let slab = map_box([-32.0, -32.0, -64.0], [32.0, 32.0, -48.0]).replace("wall", texture);
    room_bsp(&format!(
        "{{\n\"classname\" \"{classname}\"\n{keys}\n{slab}}}\n\
         {{\n\"classname\" \"light\"\n\"origin\" \"0 0 64\"\n}}\n"
    ))
}

/// LibreQuake start's face 543 is a wall whose middle a light fixture covers (a detail brush
/// one unit thick, `_surface` lights 2 units in front of it). The sample of the luxel behind
/// the fixture's middle lies on the fixture's front, is in solid, and is nudged half a unit
/// out in front of it, where the copy there lights it: ericw-tools writes 254 for it (the
/// glow round the fixture in engines that filter lightmaps), and the luxels beside the
/// fixture keep the room's dim light.
#[test]
#[ignore = "slow: run with --release -- --ignored"]
fn the_luxel_behind_a_wall_fixture_is_lit_as_in_ericw_tools() {
    let Some(bsp) = corpus_bsp("librequake/start.bsp") else {
        return;
    };
    let o = Options {
        only_faces: Some(vec![543]),
        ..options(Quality::Default)
    };
    let lighting = compute_lighting(&bsp, &o).expect("light");
    let m = lighting
        .lightmaps
        .iter()
        .find(|m| m.face == 543)
        .expect("face 543 lit");
    let grey = m.style_grey(0).expect("style 0");
    assert_eq!([m.width, m.height], [7, 6]);
    let at = |x: usize, y: usize| grey[y * m.width + x];
    assert!(at(3, 3) > 200, "{grey:?}");
    assert!((0..3).all(|x| at(x, 2) < 40), "{grey:?}");
}

/// ericw-tools moves a light in solid, or lying on a surface, 2 units out: a light on the floor
/// of [`room_bsp`] lights the floor (from 2 units up), and one sunk a unit into it too; with
/// `_nonudge 1` neither does.
#[test]
fn lights_on_or_in_a_floor_are_moved_out_and_light_it() {
    let mean_of = |light_keys: &str, side: f64| {
        let bsp = room_bsp(&format!("{{\n\"classname\" \"light\"\n{light_keys}\n}}\n"));
        let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
        let prep = crate::prepare::prepare(&bsp, &Options::default()).expect("prepare");
        let floors: Vec<usize> = prep
            .faces
            .iter()
            .filter(|f| f.plane.normal.z * side > 0.99 && f.centroid().z * side < -127.0)
            .map(|f| f.index)
            .collect();
        let bytes: Vec<u8> = lighting
            .lightmaps
            .iter()
            .filter(|m| floors.contains(&m.face))
            .flat_map(|m| m.style_grey(0).unwrap_or(&[]).to_vec())
            .collect();
        (
            lighting.stats.lights_nudged,
            bytes.iter().map(|&b| f64::from(b)).sum::<f64>() / bytes.len().max(1) as f64,
        )
    };
    let floor_mean = |light_keys: &str| mean_of(light_keys, 1.0);
    let above = floor_mean("\"origin\" \"0 0 -126\"");
    assert_eq!(above.0, 0);
    for sunk in ["\"origin\" \"0 0 -128\"", "\"origin\" \"0 0 -129\""] {
        let (moved, mean) = floor_mean(sunk);
        assert_eq!(moved, 1, "{sunk}");
        assert!(mean > above.1 * 0.8, "{sunk}: {mean} against {}", above.1);
    }
    let kept = floor_mean("\"origin\" \"0 0 -129\"\n\"_nonudge\" \"1\"");
    assert_eq!(kept, (0, 0.0));
    // Regression: a light on a ceiling (the back of its plane, as Quake stores it, is the
    // room) was taken to be in the open, stayed level with the ceiling and lit none of it.
    let (moved, ceiling) = mean_of("\"origin\" \"0 0 128\"", -1.0);
    assert_eq!(moved, 1);
    assert!(ceiling > above.1 * 0.8, "{ceiling} against {}", above.1);
}

/// Regression: a light in solid that no step of the nudge frees (here in a room's corner, on
/// three walls) lit the room, its rays leaving the solid through the backs of its faces, though
/// the warning said it lit nothing; in ericw-tools it lights nothing, and now it is dropped.
#[test]
fn a_light_stuck_in_solid_lights_nothing() {
    let light = "{\n\"classname\" \"light\"\n\"origin\" \"-128 -128 -128\"\n}\n";
    let bsp = room_bsp(light);
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let lit: Vec<usize> = lighting
        .lightmaps
        .iter()
        .filter(|m| !m.styles.is_empty())
        .map(|m| m.face)
        .collect();
    assert!(lit.is_empty(), "faces lit: {lit:?}");
    assert!(
        lighting
            .warnings
            .iter()
            .any(|w| w.problem.contains("in solid")),
        "{:?}",
        lighting.warnings
    );
}

/// The light on the floor's luxel under the middle of [`slab_bsp`]'s slab.
fn floor_under_slab(bsp: &Bsp) -> u8 {
    floor_under_slab_in(bsp, 0)
}

/// [`floor_under_slab`] in `style` (0 where the floor has no lightmap of that style).
fn floor_under_slab_in(bsp: &Bsp, style: u8) -> u8 {
    let lighting = compute_lighting(bsp, &options(Quality::Default)).expect("light");
    let prep = crate::prepare::prepare(bsp, &Options::default()).expect("prepare");
    let floor = prep
        .faces
        .iter()
        .find(|f| {
            f.model == 0
                && f.plane.normal.z > 0.99
                && f.centroid().x.abs() < 64.0
                && f.centroid().z < -100.0
        })
        .expect("floor");
    let mins = floor.extents.tex_mins;
    let m = lighting
        .lightmaps
        .iter()
        .find(|m| m.face == floor.index)
        .expect("lit floor");
    // The luxel under the slab's middle (world x, y 0: s = x, t = -y).
    let (col, row) = (
        (-f64::from(mins[0]) / 16.0).round() as usize,
        (-f64::from(mins[1]) / 16.0).round() as usize,
    );
    m.style_grey(style).map_or(0, |g| g[row * m.width + col])
}

/// Regression: a brush model of `skip` brushes with `_shadow 1` cast no shadow (it has no faces
/// to trace); its solid comes from the BSP's tree, as in ericw-tools.
#[test]
fn a_skip_model_with_shadow_casts_its_shadow() {
    let skip_slab = |keys: &str| {
        let bsp = slab_bsp("func_wall", keys, "skip");
        assert_eq!(bsp.models[1].num_faces, 0, "the slab has no faces");
        floor_under_slab(&bsp)
    };
    assert!(skip_slab("") > 20, "no shadow without _shadow");
    assert_eq!(skip_slab("\"_shadow\" \"1\""), 0, "shadow of the skip slab");
}

/// A `_switchableshadow` model's shadow is on a style of its own: the light it blocks goes
/// there (the game turns the style off to show the shadow), and its style is written into the
/// entity as `switchshadstyle`.
#[test]
fn a_switchable_shadow_puts_the_light_it_blocks_on_its_own_style() {
    let open = floor_under_slab(&slab_bsp("func_wall", "\"_shadow\" \"-1\"", "wall"));
    assert!(open > 20, "no shadow at all: {open}");
    let bsp = slab_bsp("func_wall", "\"_switchableshadow\" \"1\"", "wall");
    assert_eq!(floor_under_slab_in(&bsp, 0), 0, "shadow in style 0");
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    let text = lighting.entity_text.as_deref().expect("entities rewritten");
    assert!(text.contains("\"switchshadstyle\" \"32\""), "{text}");
    assert_eq!(
        floor_under_slab_in(&bsp, 32),
        open,
        "the blocked light, in style 32"
    );
    assert_eq!(lighting.stats.switchable_styles, 1);
}

/// ericw-tools' `_shadow -1` on world brushes, and its shadowless `func_detail_illusionary`:
/// the compiler marks the faces (`SLIPGATE_FACEFLAGS`) and light leaves them out of the scene.
#[test]
fn world_brushes_cast_no_shadow_where_their_entity_says_so() {
    let slab = |classname: &str, keys: &str| floor_under_slab(&slab_bsp(classname, keys, "wall"));
    assert_eq!(slab("func_detail", ""), 0, "a detail slab shadows");
    assert!(slab("func_detail", "\"_shadow\" \"-1\"") > 20);
    assert!(slab("func_group", "\"_shadow\" \"-1\"") > 20);
    assert!(slab("func_detail_illusionary", "") > 20);
    assert_eq!(slab("func_detail_illusionary", "\"_shadow\" \"1\""), 0);
}

#[test]
fn phong_on_func_detail_reaches_light_through_the_bsp() {
    // The column's side faces: vertical, near the axis (the room's walls are 128 out).
    let column_sides = |prep: &crate::prepare::Prepared| -> Vec<usize> {
        prep.faces
            .iter()
            .filter(|f| f.plane.normal.z.abs() < 0.1)
            .filter(|f| (f.centroid() - DVec3::new(0.0, 0.0, f.centroid().z)).length() < 60.0)
            .map(|f| f.index)
            .collect()
    };

    let plain = detail_column_bsp("");
    assert_eq!(plain.phong_faces().expect("lump"), None);
    let prep = crate::prepare::prepare(&plain, &Options::default()).expect("prepare");
    assert_eq!(column_sides(&prep).len(), 8);
    assert!(
        prep.phong.iter().all(Option::is_none),
        "no key, no smoothing"
    );

    let smooth = detail_column_bsp("\"_phong\" \"1\"");
    let lump = smooth
        .phong_faces()
        .expect("lump")
        .expect("phong lump written");
    let prep = crate::prepare::prepare(&smooth, &Options::default()).expect("prepare");
    let sides = column_sides(&prep);
    assert_eq!(sides.len(), 8);
    let group = lump[sides[0]].group;
    for &f in &sides {
        assert_eq!(lump[f].group, group, "one group for the whole column");
        assert_eq!(lump[f].angle, 89.0);
        let corners = prep.phong[f].as_ref().expect("smoothed");
        let normal = prep.faces[f].plane.normal;
        // At each vertical edge the normal is halfway to the neighbour's,
        // 45 / 2 degrees off this face's.
        let tilted = corners
            .iter()
            .filter(|c| (c.dot(normal) - 22.5f64.to_radians().cos()).abs() < 1e-3)
            .count();
        assert!(tilted >= 4, "face {f}: {corners:?}");
    }
    // The world's faces are in no group; the column's top is in the column's.
    for f in prep.faces.iter().filter(|f| !sides.contains(&f.index)) {
        let column_top = f.plane.normal.z > 0.9 && f.centroid().z.abs() < 1.0;
        let want = if column_top { group } else { 0 };
        assert_eq!(lump[f.index].group, want, "face {}", f.index);
    }
    compute_lighting(&smooth, &options(Quality::Default)).expect("light");
    assert!(lump.iter().all(|r| r.concave == 0.0));

    // `_phong_angle_concave` on the func_detail reaches light too (its own lump).
    let concave = detail_column_bsp("\"_phong\" \"1\"\n\"_phong_angle_concave\" \"10\"");
    let lump = concave.phong_faces().expect("lump").expect("written");
    let prep = crate::prepare::prepare(&concave, &Options::default()).expect("prepare");
    for f in column_sides(&prep) {
        assert_eq!((lump[f].angle, lump[f].concave), (89.0, 10.0));
    }
}

/// The largest difference in red between the luxels of two lightings of the same faces.
fn worst_red_difference(a: &[Vec<[f32; 3]>], b: &[Vec<[f32; 3]>]) -> f32 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| (x[0] - y[0]).abs())
        .fold(0.0f32, f32::max)
}

/// Every lit face's luxels (style 0) and the rays cast, at `per_axis`
/// samples per luxel axis, with adaptive supersampling on or off.
fn traced_faces(bsp: &Bsp, per_axis: usize, adaptive: bool) -> (Vec<Vec<[f32; 3]>>, u64) {
    let rules = crate::trace::FaceRules {
        dirt: true,
        ..Default::default()
    };
    lit_faces(bsp, per_axis, adaptive, &rules, 0.0)
}

/// As [`traced_faces`], with `rules` and `bounce` light units of bounced light added to every
/// luxel (darkened by dirt when `rules` says so).
fn lit_faces(
    bsp: &Bsp,
    per_axis: usize,
    adaptive: bool,
    rules: &crate::trace::FaceRules,
    bounce: f32,
) -> (Vec<Vec<[f32; 3]>>, u64) {
    let luxels = crate::luxels::ToLuxels::OpenMeans;
    lit_faces_with(bsp, per_axis, (rules, bounce, luxels), |prep, reaches| {
        prep.trace_setup(reaches, 0.001, true, adaptive)
    })
}

/// As [`lit_faces`], tracing with the setup `setup` makes and finishing `to_luxels`.
fn lit_faces_with(
    bsp: &Bsp,
    per_axis: usize,
    (rules, bounce, to_luxels): (&crate::trace::FaceRules, f32, crate::luxels::ToLuxels),
    setup: impl for<'a> Fn(
        &'a crate::prepare::Prepared,
        &'a crate::reach::LightReaches,
    ) -> crate::trace::TraceSetup<'a>,
) -> (Vec<Vec<[f32; 3]>>, u64) {
    let prep = crate::prepare::prepare(bsp, &Options::default()).expect("prepare");
    let light_reaches = crate::reach::light_reaches(&prep.point_lights, 0.001);
    let setup = setup(&prep, &light_reaches);
    let mut rays = 0;
    let luxels = prep
        .faces
        .iter()
        .filter(|f| f.kind == FaceKind::Lit)
        .map(|geom| {
            let (samples, _) = face_samples(geom, per_axis, bsp);
            let mut scratch = crate::trace::TraceScratch::default();
            let (raw, counts) = crate::trace::trace_face(&setup, &samples, rules, &mut scratch);
            rays += counts.shadow_rays + counts.sun_rays + counts.dirt_rays;
            let bounced = [(0, vec![[bounce; 3]; samples.width * samples.height])];
            let bounce = if bounce > 0.0 { &bounced[..] } else { &[] };
            let light = raw.finish(
                bounce,
                crate::trace::HiddenLuxels::FromNeighbours,
                to_luxels,
            );
            light.styles[0].1.clone()
        })
        .collect();
    (luxels, rays)
}

/// A right triangle of floor (legs of 256 along x and y) under a box and a light: the corner
/// of its lightmap past the long side lies more than a luxel off the face (occluded samples).
fn shaded_triangle_scene(lights: &str) -> Bsp {
    let mut polys = vec![Poly {
        points: vec![[0.0, 0.0, 0.0], [0.0, 256.0, 0.0], [256.0, 0.0, 0.0]],
        normal: [0.0, 0.0, 1.0],
        sky: false,
    }];
    polys.extend(box_faces([32.0, 32.0, 32.0], [96.0, 96.0, 96.0]));
    synthetic_bsp(
        &polys,
        &format!("{{ \"classname\" \"worldspawn\" }}\n{lights}"),
    )
}

/// Every lit face's luxels as a run finishes them (occluded samples filled), and the rays
/// cast, at `per_axis` samples a luxel axis, adaptive, with `change` made to the setup.
fn traced_as_run(
    bsp: &Bsp,
    per_axis: usize,
    change: fn(&mut crate::trace::TraceSetup<'_>),
) -> (Vec<Vec<[f32; 3]>>, u64) {
    let rules = crate::trace::FaceRules::default();
    let luxels = crate::luxels::ToLuxels::AsEricw { soft_radius: 0 };
    lit_faces_with(bsp, per_axis, (&rules, 0.0, luxels), |prep, reaches| {
        let mut setup = prep.trace_setup(reaches, 0.001, true, true);
        change(&mut setup);
        setup
    })
}

#[test]
fn occluded_samples_cast_no_rays_when_their_light_is_not_used() {
    let light = "{ \"classname\" \"light\" \"origin\" \"128 128 192\" \"light\" \"200\" }";
    let bsp = shaded_triangle_scene(light);
    for per_axis in [1, 4] {
        let (all, all_rays) = traced_as_run(&bsp, per_axis, |s| s.raw_light_read = true);
        let (open, open_rays) = traced_as_run(&bsp, per_axis, |_| {});
        assert_eq!(all, open, "{per_axis}x{per_axis}");
        // At 4x4 this triangle's occluded samples sit where open ones' rays go already.
        let fewer = if per_axis == 1 {
            open_rays < all_rays
        } else {
            open_rays <= all_rays
        };
        assert!(fewer, "{per_axis}: {open_rays}, {all_rays}");
    }
}

/// A world face whose every sample lies inside solid (a face buried in a wall, which ericw-tools'
/// qbsp keeps for detail brushes and no engine draws) takes no light from lights, suns or bounce,
/// and casts no ray for them: ericw-tools lights no sample in solid, and writes no lightmap for
/// such a face. It takes minlight, as there.
#[test]
fn a_world_face_wholly_inside_solid_takes_only_minlight() {
    let light = "{ \"classname\" \"light\" \"origin\" \"128 128 192\" \"light\" \"400\" }";
    let bsp = shaded_triangle_scene(light);
    let prep = crate::prepare::prepare(&bsp, &Options::default()).expect("prepare");
    let light_reaches = crate::reach::light_reaches(&prep.point_lights, 0.001);
    let setup = prep.trace_setup(&light_reaches, 0.001, true, true);
    let floor = &prep.faces[0];
    let minlight = crate::lights::Minlight {
        level: 20.0,
        add: false,
        color: DVec3::ONE,
        dirt: None,
        exclude_texture: None,
    };
    let luxels = crate::luxels::ToLuxels::AsEricw { soft_radius: 0 };
    let lit = |buried: bool, minlight: Option<&crate::lights::Minlight>| {
        let (mut samples, _) = face_samples(floor, 1, &bsp);
        if buried {
            samples.occluded = vec![true; samples.points.len()];
        }
        let rules = crate::trace::FaceRules {
            minlight,
            ..Default::default()
        };
        let mut scratch = crate::trace::TraceScratch::default();
        let (raw, counts) = crate::trace::trace_face(&setup, &samples, &rules, &mut scratch);
        let bounced = [(0, vec![[50.0; 3]; samples.width * samples.height])];
        let light = raw.finish(&bounced, crate::trace::HiddenLuxels::FromNeighbours, luxels);
        (light.styles[0].1.clone(), counts.shadow_rays)
    };
    let (open, open_rays) = lit(false, None);
    assert!(open.iter().any(|l| l[0] > 60.0) && open_rays > 0);
    let (buried, buried_rays) = lit(true, None);
    assert!(buried.iter().all(|l| l[0] == 0.0), "{buried:?}");
    assert_eq!(buried_rays, 0);
    let (floored, _) = lit(true, Some(&minlight));
    assert!(floored.iter().all(|l| l[0] == 20.0), "{floored:?}");
}

/// An inverse-square light that brings the floor at most 9 units, under a minlight of 100:
/// style 0 is the floor at every sample whatever the light's shadows, so it casts no ray.
#[test]
fn lights_under_the_minlight_floor_cast_no_rays() {
    let light =
        "{ \"classname\" \"light\" \"origin\" \"64 128 192\" \"light\" \"20\" \"delay\" \"2\" }";
    let bsp = shaded_triangle_scene(light);
    let minlight = crate::lights::Minlight {
        level: 100.0,
        add: false,
        color: DVec3::ONE,
        dirt: None,
        exclude_texture: None,
    };
    let rules = crate::trace::FaceRules {
        minlight: Some(&minlight),
        ..Default::default()
    };
    let luxels = crate::luxels::ToLuxels::AsEricw { soft_radius: 0 };
    let lit = |raw_light_read: bool| {
        lit_faces_with(&bsp, 1, (&rules, 0.0, luxels), |prep, reaches| {
            crate::trace::TraceSetup {
                raw_light_read,
                ..prep.trace_setup(reaches, 0.001, true, true)
            }
        })
    };
    let (floored, floored_rays) = lit(false);
    let (traced, traced_rays) = lit(true);
    assert_eq!(floored, traced);
    assert!(floored.iter().flatten().all(|l| *l == [100.0; 3]));
    assert_eq!(floored_rays, 0);
    assert!(traced_rays > 0);
}

/// Eight dim lights around the shaded triangle scene, each adding about half a light unit to
/// the floor, so that a budget of 2 units takes some of them and not the others.
#[test]
fn faint_lights_move_no_luxel_by_more_than_the_budget() {
    let lights: String = (0..8)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / 8.0;
            let (x, y) = (128.0 + 400.0 * a.cos(), 128.0 + 400.0 * a.sin());
            format!(
                "{{ \"classname\" \"light\" \"origin\" \"{x:.0} {y:.0} 96\" \"light\" \"10\" \
                 \"delay\" \"2\" \"_anglescale\" \"0\" }}\n"
            )
        })
        .collect();
    let bsp = shaded_triangle_scene(&lights);
    for per_axis in [1, 4] {
        let (full, full_rays) = traced_as_run(&bsp, per_axis, |s| s.faint_budget = 0.0);
        let (faint, faint_rays) = traced_as_run(&bsp, per_axis, |s| s.faint_budget = 2.0);
        let worst = worst_red_difference(&full, &faint);
        assert!(worst <= 2.0, "{per_axis}: {worst}");
        assert!(
            faint_rays < full_rays,
            "{per_axis}: {faint_rays} >= {full_rays}"
        );
    }
}

#[test]
fn adaptive_supersampling_matches_tracing_every_sub_sample() {
    // Straight shadow edges wider than a luxel, from a light and from a sun;
    // the floor's last luxel column overhangs its edge (moved samples).
    let scenes = [
        shadow_scene("\"light\" \"200\" \"delay\" \"3\" \"_anglescale\" \"0\""),
        overhang_scene("\"_shadow\" \"1\"", false),
        overhang_scene("\"_shadow\" \"1\"", true),
        corner_scene("", ""),
    ];
    for (k, bsp) in scenes.iter().enumerate() {
        for per_axis in [2, 4] {
            let (full, full_rays) = traced_faces(bsp, per_axis, false);
            let (adaptive, adaptive_rays) = traced_faces(bsp, per_axis, true);
            assert_eq!(full, adaptive, "scene {k}, {per_axis}x{per_axis}");
            assert!(
                adaptive_rays < full_rays,
                "scene {k}: {adaptive_rays} >= {full_rays}"
            );
        }
    }
}

#[test]
fn adaptive_dirt_stays_close_to_measuring_every_sample() {
    let bsp = corner_scene("\"_dirt\" \"1\"", "");
    for per_axis in [1, 4] {
        let (full, full_rays) = traced_faces(&bsp, per_axis, false);
        let (adaptive, adaptive_rays) = traced_faces(&bsp, per_axis, true);
        let worst = worst_red_difference(&full, &adaptive);
        // Samples measured in both runs cast the same rays and agree exactly
        // (no ray here meets an edge: see the next test), so this is the
        // interpolation error alone: 3.3 light units at 1×1 (2.1 when
        // `DIRT_SMOOTH` was 0.05) and 0.2 at 4×4, the same with Embree's SSE2,
        // SSE4.2, AVX and AVX2 kernels. The bound, 2 grey levels of this 200
        // light, is below one dirt ray's whole weight (200 / 48 = 4.2 units):
        // a ray that came out differently fails.
        assert!(worst <= 4.0, "{per_axis}: {worst}");
        assert!(adaptive_rays < full_rays, "{adaptive_rays} >= {full_rays}");
    }
}

/// Where only bounced light takes dirt (here the light has `_dirt -1`), a supersampled sample's
/// occlusion is the bilinear mean of its luxel's corners, edges included. Without
/// supersampling a fine cell is two luxels wide, too coarse at this wall's foot, so there it
/// keeps the usual rule. Samples measured for bounce alone cast half the dirt rays
/// (`dirt::DirtRays::Half`: the 8-azimuth pattern against 16).
#[test]
fn dirt_that_only_bounce_takes_is_interpolated_and_stays_close() {
    let bsp = corner_scene("\"_dirt\" \"1\" \"_bounce\" \"1\"", "\"_dirt\" \"-1\"");
    let rules = crate::trace::FaceRules {
        dirt: true,
        bounce_dirt: Some(crate::dirt::DirtResponse {
            scale: 1.0,
            gain: 1.0,
        }),
        ..Default::default()
    };
    for per_axis in [1, 4] {
        let (full, full_rays) = lit_faces(&bsp, per_axis, false, &rules, 100.0);
        let (adaptive, adaptive_rays) = lit_faces(&bsp, per_axis, true, &rules, 100.0);
        let worst = worst_red_difference(&full, &adaptive);
        // 100 units of bounce: at most 7 % off (6.1 light units at both densities; 2.0 and 1.2
        // with every ray), the same with each of Embree's kernels.
        assert!(worst <= 7.0, "{per_axis}: {worst}");
        assert!(
            adaptive_rays * 2 < full_rays,
            "{adaptive_rays} of {full_rays}"
        );
    }
}

#[test]
fn dirt_occlusion_does_not_depend_on_the_rays_traced_beside_it() {
    // A ray that meets a triangle's edge exactly is a tie Embree breaks one
    // way or the other depending on the kernel: the CPU's vector width, and
    // whether the packet holds one ray or many. Ordered rays of axial faces
    // run along the axis planes and diagonals, and before they started off
    // the sample (dirt::RAY_START_SHIFT) they met grid-aligned edges exactly
    // from grid-aligned samples (at the wall's foot, in the floor edge's
    // plane; and 32 up and 32 across, onto that edge): one sample measured
    // alone and among its neighbours differed.
    let bsp = corner_scene("\"_dirt\" \"1\"", "");
    for mode in [DirtMode::Ordered, DirtMode::Random] {
        let mut prep = crate::prepare::prepare(&bsp, &Options::default()).expect("prepare");
        prep.lights.dirt.mode = mode;
        for geom in prep.faces.iter().filter(|f| f.kind == FaceKind::Lit) {
            for per_axis in [1, 2] {
                let (samples, _) = face_samples(geom, per_axis, &bsp);
                let all: Vec<usize> = (0..samples.points.len()).collect();
                let measure = |indices: &[usize]| {
                    crate::dirt::occlusion_at(
                        &samples,
                        indices,
                        (geom.model, 1),
                        &prep.lights.dirt,
                        crate::dirt::DirtRays::All,
                        &prep.scene,
                    )
                    .0
                };
                let alone: Vec<f32> = all.iter().map(|&i| measure(&[i])[0]).collect();
                assert_eq!(
                    measure(&all),
                    alone,
                    "{mode:?}, face {}, {per_axis}x{per_axis}",
                    geom.index
                );
            }
        }
    }
}

/// `maps/demo.map` compiled by slipgate-bsp, with a sun and a sky dome added
/// to its worldspawn, so that every kind of ray is traced.
fn demo_bsp_with_sun() -> Bsp {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps/demo.map");
    let source = bsp_compiler::MapSource::read(&path).expect("maps/demo.map");
    let out =
        bsp_compiler::compile(&source, &bsp_compiler::CompileOptions::default()).expect("compile");
    let mut bsp = out.bsp;
    let worldspawn = "\"classname\" \"worldspawn\"";
    let text = bsp.entity_text().replacen(
        worldspawn,
        &format!(
            "{worldspawn} \"_sunlight\" \"150\" \"_sun_mangle\" \"30 -60 0\" \"_sunlight2\" \"60\""
        ),
        1,
    );
    assert_ne!(text, bsp.entity_text(), "demo.map has a worldspawn");
    bsp.set_entity_text(&text);
    bsp
}

/// In the default mode the dome's directions (each carrying 1/65 of it) are probed every
/// other luxel and filled in where a cell's probes agree (`VisibilityScratch::trace_probed`).
/// The single sun (one direction) is traced at every luxel.
#[test]
fn probed_sky_dome_stays_close_to_tracing_every_luxel() {
    let bsp = demo_bsp_with_sun();
    let (full, full_rays) = traced_faces(&bsp, 1, false);
    let (probed, probed_rays) = traced_faces(&bsp, 1, true);
    let worst = worst_red_difference(&full, &probed);
    // The dome is 60 light units over 65 directions: a luxel whose probes missed one is 0.92
    // off; the bound allows for one, as another CPU's kernel may break a tie otherwise.
    assert!(worst <= 1.2, "{worst}");
    // 0.69 M rays instead of 1.18 M here (shadow and dirt rays included).
    assert!(probed_rays < full_rays, "{probed_rays} >= {full_rays}");
}

#[test]
fn output_does_not_depend_on_the_thread_count() {
    // Faces are lit in parallel: nothing a face's result rests on (its packets,
    // probes, dirt grid, shared points) may depend on which thread lit it.
    let bsp = demo_bsp_with_sun();
    let lit_bytes = |threads: usize, options: &Options| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        let lighting = pool
            .install(|| compute_lighting(&bsp, options))
            .expect("light");
        let mut lit = bsp.clone();
        let files = apply_lighting(&mut lit, &lighting);
        (
            lit.lighting.clone(),
            lit.write().expect("BSP encodes"),
            files,
        )
    };
    for (quality, dirt_mode, soft) in [
        (Quality::Default, DirtMode::Ordered, SoftRadius::Samples(0)),
        (Quality::Extra, DirtMode::Random, SoftRadius::HalfLuxel),
    ] {
        let mut options = options(quality);
        options.overrides.soft = Some(soft);
        options.overrides.dirt = Some(true);
        options.overrides.dirt_mode = Some(dirt_mode);
        options.overrides.sunsamples = Some(16);
        // The BSPX lumps and the files beside the BSP too.
        let o = &mut options.overrides;
        (o.bspxlit, o.lux, o.bspxlux, o.hdr, o.bspxhdr) =
            (Some(true), Some(true), Some(true), Some(true), Some(true));
        o.lightgrid = Some(true);
        // Bounce gathers across faces: one pass, and two with supersampling.
        options.overrides.bounce = Some(if quality == Quality::Default { 1 } else { 2 });
        let one = lit_bytes(1, &options);
        assert!(one.0.iter().any(|&b| b > 0), "{quality:?}: lit");
        assert!(
            one == lit_bytes(2, &options),
            "{quality:?}, dirt mode {dirt_mode:?}: 1 and 2 threads differ"
        );
    }
}

#[test]
fn shared_leaf_walk_agrees_with_walking_each_point() {
    // Clusters of points (a luxel's square) inside the room, inside the
    // column, inside the walls and straddling their faces.
    let bsp = detail_column_bsp("");
    let per_point = |p: &[f32; 3]| crate::samples::solid_at(&bsp, *p);
    let mut solid_seen = 0;
    for cx in (-160..=160).step_by(20) {
        for cz in (-160..=160).step_by(20) {
            let cluster: Vec<[f32; 3]> = (0..16)
                .map(|k| {
                    let (u, v) = ((k % 4) as f32 * 5.0, (k / 4) as f32 * 5.0);
                    [cx as f32 + u, 0.5 * cz as f32 + v, cz as f32 + 0.3 * u]
                })
                .collect();
            let expected: Vec<bool> = cluster.iter().map(per_point).collect();
            solid_seen += expected.iter().filter(|&&s| s).count();
            for tile in [1, 3, 4, 16] {
                assert_eq!(
                    crate::samples::solid_points_in_tiles(&bsp, &cluster, tile),
                    expected,
                    "cluster at {cx} {cz} in tiles of {tile}"
                );
            }
        }
    }
    assert!(solid_seen > 0, "some clusters reach into solid");
    assert!(crate::samples::solid_points_in_tiles(&bsp, &[], 4).is_empty());
}

#[test]
fn dirt_is_measured_only_where_light_arrives() {
    // The corner scene, and the same room with a linear light whose reach
    // (40 units) ends far above the floor: its dark samples need no dirt rays.
    let lit = corner_scene("\"_dirt\" \"1\"", "");
    let mut polys = vec![floor(256.0)];
    polys.extend(box_faces([192.0, -64.0, 0.0], [320.0, 320.0, 256.0]));
    let dark = synthetic_bsp(
        &polys,
        "{ \"classname\" \"worldspawn\" \"_dirt\" \"1\" }\n\
         { \"classname\" \"light\" \"origin\" \"96 128 200\" \"light\" \"40\" }\n",
    );
    let rays = |bsp: &Bsp| {
        compute_lighting(bsp, &options(Quality::Default))
            .expect("light")
            .stats
            .dirt_rays
    };
    let (lit_rays, dark_rays) = (rays(&lit), rays(&dark));
    assert!(lit_rays > 0);
    assert!(dark_rays < lit_rays, "{dark_rays} >= {lit_rays}");
}

#[test]
fn embree_errors_are_told_once() {
    // `SLIPGATE_EMBREE_CONFIG=isa=avx512` on a CPU without it printed the
    // message twice: once as the light error, once as its source.
    let error = crate::LightError::from(crate::embree::EmbreeError::InvalidInput("bad".into()));
    let told = format!("{:#}", anyhow::Error::from(error));
    assert_eq!(told.matches("bad").count(), 1, "{told}");
}

/// Grey style-0 bytes of `face`, when it has a lightmap.
fn face_grey(lighting: &crate::Lighting, face: usize) -> Vec<u8> {
    lighting
        .lightmaps
        .iter()
        .find(|m| m.face == face)
        .and_then(|m| m.style_grey(0).map(<[u8]>::to_vec))
        .unwrap_or_default()
}

/// Index of the box's underside in [`shadow_scene`] (floor, then the box's +z and −z faces).
const BOX_UNDERSIDE: usize = 2;

#[test]
fn bounce_lights_the_underside_of_the_box_only_when_asked() {
    let bsp = shadow_scene("");
    let plain = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    assert!(face_grey(&plain, BOX_UNDERSIDE).iter().all(|&b| b == 0));
    let mut bounced = options(Quality::Default);
    bounced.overrides.bounce = Some(1);
    let lit = compute_lighting(&bsp, &bounced).expect("light");
    let under = face_grey(&lit, BOX_UNDERSIDE);
    assert!(under.iter().all(|&b| b > 0), "lit by the floor: {under:?}");
    assert!(!lit.coloured, "grey reflectance keeps white light white");
    // Worldspawn's key does the same; a light's `_bounce 0` opts its light out.
    let keyed = shadow_scene("")
        .entity_text()
        .replace("\"worldspawn\"", "\"worldspawn\" \"_bounce\" \"1\"");
    let mut by_key = bsp.clone();
    by_key.set_entity_text(&keyed);
    let from_key = compute_lighting(&by_key, &options(Quality::Default)).expect("light");
    assert_eq!(face_grey(&from_key, BOX_UNDERSIDE), under);
    let opted_out = compute_lighting(&shadow_scene("\"_bounce\" \"0\""), &bounced).expect("light");
    assert!(face_grey(&opted_out, BOX_UNDERSIDE).iter().all(|&b| b == 0));
    // `_bouncescale` scales the light's share: none at 0, half at 0.5, more above 1.
    let scaled = |scale: &str| {
        let keys = format!("\"_bouncescale\" \"{scale}\"");
        let lit = compute_lighting(&shadow_scene(&keys), &bounced).expect("light");
        face_grey(&lit, BOX_UNDERSIDE)
    };
    assert!(scaled("0").iter().all(|&b| b == 0));
    assert_eq!(scaled("1"), under);
    let (half, double) = (scaled("0.5"), scaled("2"));
    for ((&h, &d), &u) in half.iter().zip(&double).zip(&under) {
        assert!(
            h.abs_diff(u / 2) <= 1 && d.abs_diff(u * 2) <= 1,
            "{h} {d} {u}"
        );
    }
}

/// Only faces that block light outright reflect bounced light, as in ericw-tools: a slab
/// that casts no shadow (`func_detail_illusionary`, `_shadow -1`) or whose shadow is
/// switchable reflects none; the same slab as plain detail, or a `_shadow 1` model, does.
#[test]
fn only_faces_that_cast_a_solid_shadow_reflect_bounced_light() {
    let slab_reflects = |classname: &str, keys: &str| {
        let bsp = slab_bsp(classname, keys, "wall");
        let prep = crate::prepare::prepare(&bsp, &Options::default()).expect("prepare");
        let palette = quake_formats::palette::Palette::slipgate();
        let reflectance =
            crate::bounce::face_reflectance(&bsp, &prep.faces, &prep.lights, &palette);
        // The slab's top: it faces the light, 48 units under the room's middle.
        let top = prep
            .faces
            .iter()
            .find(|f| f.plane.normal.z > 0.99 && (f.centroid().z + 48.0).abs() < 0.5)
            .expect("the slab's top");
        reflectance[top.index].is_some()
    };
    assert!(slab_reflects("func_detail", ""));
    assert!(slab_reflects("func_wall", "\"_shadow\" \"1\""));
    assert!(
        !slab_reflects("func_wall", ""),
        "a model casts no shadow unless asked"
    );
    assert!(!slab_reflects("func_detail_illusionary", ""));
    assert!(!slab_reflects("func_detail", "\"_shadow\" \"-1\""));
    assert!(!slab_reflects(
        "func_wall",
        "\"_shadow\" \"1\" \"_switchableshadow\" \"1\""
    ));
}

#[test]
fn bounce_is_close_to_the_reference_and_never_black_where_it_is_lit() {
    // The reference integrates over the reflecting surfaces, as `high` gathers.
    let bsp = shadow_scene("");
    let mut fast = options(Quality::Default);
    fast.overrides.bounce = Some(1);
    fast.overrides.emissive_quality = Some(EmissiveQuality::High);
    let mut exact = options(Quality::Reference);
    exact.overrides.bounce = Some(1);
    let reference = compute_lighting(&bsp, &exact).expect("reference");
    let ref_under = face_grey(&reference, BOX_UNDERSIDE);
    assert!(ref_under.iter().all(|&b| b > 0), "reference: {ref_under:?}");
    for quality in [Quality::Default, Quality::Extra4] {
        fast.quality = quality;
        let lit = compute_lighting(&bsp, &fast).expect("light");
        let under = face_grey(&lit, BOX_UNDERSIDE);
        for (i, (&a, &r)) in under.iter().zip(&ref_under).enumerate() {
            assert!(
                r == 0 || a > 0,
                "{quality:?}: luxel {i} black, reference {r}"
            );
            assert!(
                a.abs_diff(r) <= 1,
                "{quality:?}: luxel {i}: {a} against {r}"
            );
        }
        // Bounce adds little error to the direct light's own.
        let direct = compare(
            &compute_lighting(&bsp, &options(quality)).expect("light"),
            &compute_lighting(&bsp, &options(Quality::Reference)).expect("reference"),
        );
        let e = compare(&lit, &reference);
        assert!(
            e.rmse < direct.rmse + 0.5,
            "{quality:?}: {e:?} against {direct:?}"
        );
    }
}

/// Floor 0..256 lit from above, and over its middle at z 64 an upward face textured `texture`
/// (face 1): a liquid's surface lets the light through to the floor below it.
fn pool_surface_scene(texture: &str) -> Bsp {
    let surface = quad(
        [64.0, 64.0, 64.0],
        [64.0, 192.0, 64.0],
        [192.0, 192.0, 64.0],
        [192.0, 64.0, 64.0],
        [0.0, 0.0, 1.0],
    );
    let ents = "{ \"classname\" \"worldspawn\" }\n\
                { \"classname\" \"light\" \"origin\" \"128 128 192\" }\n";
    let mut bsp = synthetic_bsp(&[floor(256.0), surface], ents);
    bsp.textures.textures.push(Some(mip(texture)));
    let last = bsp.texinfo.len() - 1;
    bsp.texinfo[last].miptex = bsp.textures.textures.len() as u32 - 1;
    bsp
}

#[test]
fn a_liquid_surface_takes_bounced_light_from_both_sides() {
    // ericw-tools gathers onto liquids (two-sided receivers) from either side, with no cosine
    // of their own: the lit floor under the surface bounces up through it. An ordinary face
    // in its place faces away from the floor, which it shadows anyway.
    let mut bounced = options(Quality::Default);
    bounced.overrides.bounce = Some(1);
    let surface_bounce = |texture: &str| {
        let bsp = pool_surface_scene(texture);
        let with = compute_lighting(&bsp, &bounced).expect("light");
        let without = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
        let (a, b) = (face_grey(&with, 1), face_grey(&without, 1));
        assert_eq!(a.len(), b.len());
        a.iter()
            .zip(&b)
            .map(|(&a, &b)| i32::from(a) - i32::from(b))
            .collect::<Vec<_>>()
    };
    let liquid = surface_bounce("*water1");
    assert!(liquid.iter().all(|&d| d >= 8), "{liquid:?}");
    let wall = surface_bounce("wall2");
    assert!(wall.iter().all(|&d| d == 0), "{wall:?}");
}

/// Bounced light alone (with bounce minus without), style 0, per luxel of every face.
fn bounce_part(bsp: &Bsp, options: &Options) -> Vec<f32> {
    let with = trace_lighting(bsp, options).expect("light");
    let mut plain = options.clone();
    plain.overrides.bounce = None;
    let without = trace_lighting(bsp, &plain).expect("light");
    with.faces
        .iter()
        .zip(&without.faces)
        .flat_map(|(a, b)| a.styles[0].1.iter().zip(&b.styles[0].1))
        .map(|(a, b)| a[0] - b[0])
        .collect()
}

#[test]
fn fast_bounce_converges_to_the_reference_at_every_luxel_with_more_rays() {
    // At --extra4 both read the same direct light; gathering at every luxel leaves only the
    // fast method's noise (and its one point per luxel against the reference's 256).
    let bsp = shadow_scene("");
    let mut exact = options(Quality::Reference);
    exact.overrides.bounce = Some(1);
    let reference = bounce_part(&bsp, &exact);
    let peak = reference.iter().copied().fold(0.0f32, f32::max);
    assert!(peak > 1.0, "the scene has bounce: {peak}");
    let rms_error = |strata: usize| {
        let mut fast = options(Quality::Extra4);
        fast.overrides.bounce = Some(1);
        fast.overrides.emissive_quality = Some(EmissiveQuality::High);
        fast.bounce_density = Some(crate::bounce::Density {
            stride: 1,
            strata,
            widen_last: false,
            smooth: false,
        });
        let b = bounce_part(&bsp, &fast);
        assert_eq!(b.len(), reference.len());
        let sum: f64 = b
            .iter()
            .zip(&reference)
            .map(|(x, r)| f64::from(x - r).powi(2))
            .sum();
        (sum / b.len() as f64).sqrt()
    };
    // Measured: 2.9, 0.48, 0.13 (48²: 0.11) light units, peak 6.1.
    let errors = [2, 8, 24].map(rms_error);
    assert!(
        errors[0] > 2.0 * errors[1] && errors[1] > 2.0 * errors[2],
        "{errors:?}"
    );
    assert!(
        errors[2] < 0.03 * f64::from(peak),
        "{errors:?}, peak {peak}"
    );
}

#[test]
fn coloured_bounce_writes_a_lit_only_when_the_texture_is_coloured() {
    let mut bsp = shadow_scene("");
    let mut options = options(Quality::Default);
    options.overrides.bounce = Some(1);
    options.overrides.bounce_color_scale = Some(1.0);
    // Palette index 0 (every texel of the test textures) grey, then red.
    let mut palette = quake_formats::palette::Palette::slipgate();
    palette.colors[0] = [128, 128, 128];
    options.palette = Some(palette.clone());
    assert!(!compute_lighting(&bsp, &options).expect("light").coloured);
    palette.colors[0] = [200, 40, 40];
    options.palette = Some(palette);
    let lit = compute_lighting(&bsp, &options).expect("light");
    assert!(lit.coloured);
    let under = lit
        .lightmaps
        .iter()
        .find(|m| m.face == BOX_UNDERSIDE)
        .expect("underside");
    assert!(
        under.rgb[0].iter().all(|c| c[0] > c[1]),
        "reddened by the floor"
    );
    let lit_bytes = apply_lighting(&mut bsp, &lit);
    assert!(lit_bytes.lit.is_some());
}

/// The lumps and files of a run with every BSPX light output asked for, read back by the
/// independent `qbsp` crate.
fn light_with_bspx_outputs(light_keys: &str) -> (Bsp, crate::LightFiles, qbsp::BspData) {
    let mut bsp = shadow_scene(light_keys);
    let mut options = options(Quality::Default);
    let o = &mut options.overrides;
    (o.bspxlit, o.lux, o.bspxlux, o.hdr, o.bspxhdr) =
        (Some(true), Some(true), Some(true), Some(true), Some(true));
    let lighting = compute_lighting(&bsp, &options).expect("light");
    let files = apply_lighting(&mut bsp, &lighting);
    let bytes = bsp.write().expect("BSP encodes");
    let theirs = qbsp::BspData::parse(qbsp::BspParseInput {
        bsp: &bytes,
        lit: None,
        settings: qbsp::BspParseSettings::default(),
    })
    .expect("qbsp reads the BSP");
    (bsp, files, theirs)
}

#[test]
fn qbsp_reads_the_bspx_light_lumps_as_written() {
    let (bsp, files, theirs) =
        light_with_bspx_outputs("\"light\" \"300\" \"_color\" \"255 128 0\"");
    let luxels = bsp.lighting.len();
    // qbsp takes RGBLIGHTING in place of the grey lump, as engines that read it do.
    let Some(qbsp::data::lighting::BspLighting::Colored(rgb)) = &theirs.lighting else {
        panic!("qbsp did not take RGBLIGHTING's colour");
    };
    let ours = bsp.bspx_lump(quake_formats::bsp::light_lumps::RGBLIGHTING);
    assert_eq!(rgb.len(), luxels);
    assert_eq!(
        ours.map(<[u8]>::to_vec),
        Some(rgb.iter().flatten().copied().collect())
    );
    let lit = files.lit.expect("-hdr writes the HDR .lit");
    let quake_formats::lit::LitData::Hdr(hdr_words) =
        quake_formats::lit::read_any_lit(&lit, luxels).expect(".lit reads")
    else {
        panic!("-hdr's .lit is not HDR");
    };
    let hdr_lump = theirs
        .bspx
        .get_unparsed("LIGHTING_E5BGR9")
        .expect("LIGHTING_E5BGR9");
    assert_eq!(hdr_lump.len(), 4 * luxels);
    let lump_words: Vec<u32> = hdr_lump
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        .collect();
    assert_eq!(lump_words, hdr_words, "the lump and the HDR .lit agree");
    // Unclamped luxels: the HDR value (1.0 at byte 128) is the byte within rounding.
    for (c, &w) in rgb.iter().zip(&lump_words) {
        let hdr = quake_formats::lit::unpack_e5bgr9(w);
        if c.iter().all(|&b| b < 255) {
            for (b, h) in c.iter().zip(hdr) {
                assert!(
                    (f32::from(*b) - h * 128.0).abs() <= 1.0,
                    "{c:?} against {hdr:?}"
                );
            }
        }
    }
    let dir_lump = theirs
        .bspx
        .get_unparsed("LIGHTINGDIR")
        .expect("LIGHTINGDIR");
    assert_eq!(dir_lump.len(), 3 * luxels);
    let lux = files.lux.expect("-lux writes a .lux");
    assert_eq!(&lux[..4], b"QLIT");
    assert_eq!(&lux[8..], dir_lump, "the .lux and LIGHTINGDIR agree");
}

#[test]
fn deluxemap_points_towards_the_light_in_tangent_space() {
    // The light hangs at (128 128 192) over the floor (0..256); the floor's texture s axis is
    // world x and its t axis world -y, so tangent space is x, y, up there.
    let (bsp, _, theirs) = light_with_bspx_outputs("\"light\" \"300\"");
    let dirs = theirs
        .bspx
        .get_unparsed("LIGHTINGDIR")
        .expect("LIGHTINGDIR");
    let floor = &bsp.faces[0];
    let offset = usize::try_from(floor.light_offset).expect("the floor is lit");
    let (w, h) = (17, 17);
    let at = |x: usize, y: usize| {
        let i = 3 * (offset + y * w + x);
        [dirs[i], dirs[i + 1], dirs[i + 2]]
    };
    let centre = at(w / 2, h / 2);
    assert!(centre[2] > 250, "straight above the middle: {centre:?}");
    // Luxel rows run along t, which is world -y: the first row is the floor's +y edge, where
    // the light lies towards world -y, the tangent's negative y.
    let corner = at(0, 0);
    assert!(
        corner[0] > 150,
        "towards +x from the x = 0 edge: {corner:?}"
    );
    assert!(
        corner[1] < 106,
        "towards -y from the y = 256 edge: {corner:?}"
    );
    assert!(corner[2] > 150, "and upwards: {corner:?}");
}

#[test]
fn novanilla_writes_colour_only_in_rgblighting() {
    let mut bsp = shadow_scene("\"light\" \"300\" \"_color\" \"255 0 0\"");
    let mut options = options(Quality::Default);
    options.overrides.novanilla = Some(true);
    let lighting = compute_lighting(&bsp, &options).expect("light");
    let files = apply_lighting(&mut bsp, &lighting);
    assert!(files.lit.is_none(), "RGBLIGHTING carries the colour");
    assert!(bsp.lighting.is_empty());
    let bytes = bsp.write().expect("BSP encodes");
    let theirs = qbsp::BspData::parse(qbsp::BspParseInput {
        bsp: &bytes,
        lit: None,
        settings: qbsp::BspParseSettings::default(),
    })
    .expect("qbsp reads the BSP");
    let Some(qbsp::data::lighting::BspLighting::Colored(rgb)) = theirs.lighting else {
        panic!("qbsp did not take RGBLIGHTING's colour");
    };
    assert_eq!(rgb.len(), bsp.luxel_count());
    assert!(rgb.iter().any(|c| c[0] > 0) && rgb.iter().all(|c| c[1] == 0 && c[2] == 0));
}

/// The light grid over [`shadow_scene`] (a box 0..256 by 0..256 by 0..128) with a light that
/// ignores the angle of incidence, so a face receives what a grid point beside it does.
fn shadow_scene_grid() -> (Bsp, quake_formats::bsp::lightgrid::LightGrid, Vec<u8>) {
    let mut bsp = shadow_scene("\"light\" \"300\" \"_anglescale\" \"0\"");
    bsp.models[0].mins = [0.0; 3];
    bsp.models[0].maxs = [256.0, 256.0, 128.0];
    let mut options = options(Quality::Default);
    options.overrides.lightgrid = Some(true);
    let lighting = compute_lighting(&bsp, &options).expect("light");
    assert!(lighting.stats.grid_rays > 0);
    let grid = lighting
        .light_grid
        .clone()
        .expect("--lightgrid gives a grid");
    apply_lighting(&mut bsp, &lighting);
    let bytes = bsp.write().expect("BSP encodes");
    (bsp, grid, bytes)
}

#[test]
fn grid_points_take_the_light_of_the_floor_beside_them() {
    let (bsp, grid, _) = shadow_scene_grid();
    assert_eq!(grid.spacing, [32.0; 3]);
    assert_eq!(grid.mins, [0.5; 3], "half a unit off the floor's plane");
    let floor = &bsp.faces[0];
    let offset = usize::try_from(floor.light_offset).expect("the floor is lit");
    // Floor luxel (i, j) stands at x = 16 i, y = 256 - 16 j (its t axis is world -y).
    let luxel = |x: usize, y: usize| bsp.lighting[offset + (256 - y) / 16 * 17 + x / 16];
    let point = |x: i32, y: i32| {
        let p = grid.point([x / 32, y / 32, 0]).expect("inside the grid");
        let styles = p.as_ref().expect("in the open");
        styles.iter().find(|s| s.style == 0).map_or(0, |s| s.rgb[0])
    };
    // In the light, off the box's shadow.
    let (lit_face, lit_grid) = (luxel(32, 32), point(32, 32));
    assert!(lit_face > 20, "the floor is lit there: {lit_face}");
    assert!(
        lit_face.abs_diff(lit_grid) <= 1,
        "face {lit_face}, grid {lit_grid}"
    );
    // In the box's shadow.
    assert_eq!((luxel(128, 128), point(128, 128)), (0, 0));
}

#[test]
fn qbsp_reads_the_light_grid_as_written() {
    let (_, grid, bytes) = shadow_scene_grid();
    let theirs = qbsp::BspData::parse(qbsp::BspParseInput {
        bsp: &bytes,
        lit: None,
        settings: qbsp::BspParseSettings::default(),
    })
    .expect("qbsp reads the BSP");
    let octree = theirs.bspx.light_grid_octree.expect("LIGHTGRID_OCTREE");
    assert_eq!(octree.step.to_array(), grid.spacing);
    assert_eq!(octree.mins.to_array(), grid.mins);
    assert_eq!(octree.size.to_array().map(|s| s as i32), grid.size);
}

#[test]
fn a_run_without_lightgrid_removes_an_old_grid() {
    let (mut bsp, _, _) = shadow_scene_grid();
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    apply_lighting(&mut bsp, &lighting);
    assert!(
        bsp.bspx_lump(quake_formats::bsp::lightgrid::LIGHTGRID_OCTREE)
            .is_none()
    );
}

#[test]
fn a_grid_row_finds_the_leaves_leaf_at_does() {
    let bsp = demo_bsp_with_sun();
    let m = &bsp.models[0];
    let (mins, maxs) = (
        DVec3::from(m.mins.map(f64::from)),
        DVec3::from(m.maxs.map(f64::from)),
    );
    let mut rows = 0;
    for (y, z) in [(0.3, 0.2), (0.5, 0.5), (0.71, 0.13), (0.9, 0.8)] {
        let at = |x: f64| mins + (maxs - mins) * DVec3::new(x, y, z);
        let points: Vec<DVec3> = (0..=200).map(|i| at(f64::from(i) / 200.0)).collect();
        let walked = crate::lightgrid::leaves_along(&bsp, &points);
        let each: Vec<_> = points
            .iter()
            .map(|p| bsp.leaf_at(p.as_vec3().to_array()))
            .collect();
        assert_eq!(walked, each);
        rows += usize::from(each.windows(2).any(|w| w[0] != w[1]));
    }
    assert!(rows >= 3, "the rows cross leaves");
}

/// Lit water: a liquid face the compiler wrote without `TEX_SPECIAL` gets a lightmap, one
/// written special gets none, and neither shades the floor under it (liquids let light through).
#[test]
fn lit_liquids_get_lightmaps_and_let_light_through() {
    let surface = |x0: f32, x1: f32| {
        quad(
            [x0, 0.0, 64.0],
            [x0, 256.0, 64.0],
            [x1, 256.0, 64.0],
            [x1, 0.0, 64.0],
            [0.0, 0.0, 1.0],
        )
    };
    let polys = [floor(256.0), surface(0.0, 128.0), surface(128.0, 256.0)];
    let ents = "{ \"classname\" \"worldspawn\" }\n\
                { \"classname\" \"light\" \"origin\" \"128 128 192\" \"light\" \"300\" }\n";
    let mut bsp = synthetic_bsp(&polys, ents);
    let open = synthetic_bsp(&[floor(256.0)], ents);
    bsp.textures.textures.push(Some(mip("*water0")));
    let water = bsp.textures.textures.len() as u32 - 1;
    for (face, flags) in [(1, 0), (2, texinfo_flags::SPECIAL)] {
        let info = &mut bsp.texinfo[bsp.faces[face].texinfo as usize];
        info.miptex = water;
        info.flags = flags;
    }
    let opts = options(Quality::Default);
    let lighting = compute_lighting(&bsp, &opts).expect("light");
    let lit: Vec<usize> = lighting.lightmaps.iter().map(|m| m.face).collect();
    assert_eq!(lit, [0, 1]);
    assert!(luxel_at(&bsp, &lighting, 1, 64.0, 128.0) > 0);
    let without_water = compute_lighting(&open, &opts).expect("light");
    for s in [64.0, 192.0] {
        assert_eq!(
            luxel_at(&bsp, &lighting, 0, s, 128.0),
            luxel_at(&open, &without_water, 0, s, 128.0)
        );
    }
}

/// Light passes the open texels (index 255) of fence textures, as in ericw-tools: under a grate
/// of open and opaque stripes the floor is lit in stripes; a fence texture with no open texel
/// shadows like any face.
#[test]
fn light_passes_the_open_texels_of_fence_textures() {
    let ents = "{ \"classname\" \"worldspawn\" }\n\
                { \"classname\" \"light\" \"origin\" \"128 128 192\" \"light\" \"300\" }\n";
    let grate = || {
        quad(
            [32.0, 32.0, 64.0],
            [32.0, 224.0, 64.0],
            [224.0, 224.0, 64.0],
            [224.0, 32.0, 64.0],
            [0.0, 0.0, 1.0],
        )
    };
    let floor_under = |texels: Vec<u8>| {
        let mut bsp = synthetic_bsp(&[floor(256.0), grate()], ents);
        let mips = [texels, vec![1; 64], vec![1; 16], vec![1; 4]];
        bsp.textures
            .textures
            .push(Some(MipTex::new("{grate", 16, 16, mips)));
        let info = &mut bsp.texinfo[bsp.faces[1].texinfo as usize];
        info.miptex = bsp.textures.textures.len() as u32 - 1;
        info.vecs = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]];
        let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
        (64..=192)
            .step_by(16)
            .map(|s| luxel_at(&bsp, &lighting, 0, f64::from(s), 128.0))
            .collect::<Vec<u8>>()
    };
    // Texel columns 0..8 open, 8..16 opaque.
    let stripes: Vec<u8> = (0..256).map(|i| if i % 16 < 8 { 255 } else { 1 }).collect();
    let striped = floor_under(stripes);
    assert!(striped.iter().any(|&v| v > 20), "{striped:?}");
    assert!(striped.iter().any(|&v| v < 5), "{striped:?}");
    let solid = floor_under(vec![1; 256]);
    assert!(solid.iter().all(|&v| v < 5), "{solid:?}");
}

/// Faces textured `trigger` or `skip` (brush models engines never draw) get no lightmap, as in
/// ericw-tools, and lit faces beside them are lit as before.
#[test]
fn trigger_and_skip_faces_get_no_lightmap() {
    let ents = "{ \"classname\" \"worldspawn\" }\n\
                { \"classname\" \"light\" \"origin\" \"128 128 64\" \"light\" \"300\" }\n";
    let opts = options(Quality::Default);
    for name in ["trigger", "SKIP"] {
        let mut bsp = synthetic_bsp(&[floor(256.0), floor(256.0)], ents);
        bsp.textures.textures.push(Some(mip(name)));
        let info = &mut bsp.texinfo[bsp.faces[1].texinfo as usize];
        info.miptex = bsp.textures.textures.len() as u32 - 1;
        let lighting = compute_lighting(&bsp, &opts).expect("light");
        let lit: Vec<usize> = lighting.lightmaps.iter().map(|m| m.face).collect();
        assert_eq!(lit, [0], "{name}");
    }
}

/// A lit liquid's surface is lit from both sides, as ericw-tools lights it: a light under the
/// water lights the surface seen from above about as a light as far above it would, where a solid
/// face on the same plane takes nothing from below.
#[test]
fn lit_liquid_surfaces_take_light_from_under_them() {
    let surface = || {
        quad(
            [0.0, 0.0, 64.0],
            [0.0, 256.0, 64.0],
            [256.0, 256.0, 64.0],
            [256.0, 0.0, 64.0],
            [0.0, 0.0, 1.0],
        )
    };
    let scene = |light_z: f32, texture: &str| {
        let ents = format!(
            "{{ \"classname\" \"worldspawn\" }}\n\
             {{ \"classname\" \"light\" \"origin\" \"128 128 {light_z}\" \"light\" \"300\" }}\n"
        );
        let mut bsp = synthetic_bsp(&[floor(256.0), surface()], &ents);
        bsp.textures.textures.push(Some(mip(texture)));
        let info = &mut bsp.texinfo[bsp.faces[1].texinfo as usize];
        info.miptex = bsp.textures.textures.len() as u32 - 1;
        info.flags = 0;
        bsp
    };
    let opts = options(Quality::Default);
    let surface_luxel = |bsp: &Bsp| {
        let lighting = compute_lighting(bsp, &opts).expect("light");
        lighting
            .lightmaps
            .iter()
            .any(|m| m.face == 1)
            .then(|| luxel_at(bsp, &lighting, 1, 128.0, 128.0))
    };
    let from_below = surface_luxel(&scene(32.0, "*water0"));
    let from_above = surface_luxel(&scene(96.0, "*water0"));
    let (Some(below), Some(above)) = (from_below, from_above) else {
        panic!("lit from below {from_below:?}, from above {from_above:?}");
    };
    // The samples stand a little in front of the surface.
    assert!(below > 40 && below.abs_diff(above) <= 2, "{below} {above}");
    assert_eq!(surface_luxel(&scene(32.0, "metal1")).unwrap_or(0), 0);
}

/// `options` with faces lit on their own grids, `units` map units per luxel.
fn on_own_grids(quality: Quality, units: f64) -> Options {
    let mut o = options(quality);
    o.overrides.world_units_per_luxel = Some(units);
    o
}

/// `lighting` with each face's lightmaps on its own grid in place of its 16-texel ones.
fn own_grid_lightmaps(lighting: &crate::Lighting) -> crate::Lighting {
    crate::own_grids(lighting).expect("lightmaps on the faces' own grids")
}

#[test]
fn qbsp_reads_the_decoupled_lightmaps_as_written() {
    let mut bsp = shadow_scene("\"light\" \"300\"");
    let lighting = compute_lighting(&bsp, &on_own_grids(Quality::Default, 8.0)).expect("light");
    apply_lighting(&mut bsp, &lighting);
    let ours = bsp
        .decoupled_lightmaps()
        .expect("DECOUPLED_LM reads")
        .expect("DECOUPLED_LM is written");
    // The floor, 256 units square: 33 luxels each way at 8 units, and still its 17x17
    // lightmap of 16 texels at `light_offset`.
    let floor = &ours[0];
    assert_eq!((floor.width, floor.height), (33, 33));
    let vanilla = &lighting.lightmaps[0];
    assert_eq!((vanilla.face, vanilla.width, vanilla.height), (0, 17, 17));
    assert!(bsp.faces[0].light_offset >= 0 && floor.offset >= 0);
    assert_ne!(
        i64::from(bsp.faces[0].light_offset),
        i64::from(floor.offset)
    );
    let problems: Vec<_> = quake_formats::validate(&bsp)
        .into_iter()
        .filter(|p| p.lump == quake_formats::bsp::light_lumps::DECOUPLED_LM)
        .collect();
    assert!(problems.is_empty(), "{problems:?}");
    let bytes = bsp.write().expect("BSP encodes");
    let theirs = qbsp::BspData::parse(qbsp::BspParseInput {
        bsp: &bytes,
        lit: None,
        settings: qbsp::BspParseSettings::default(),
    })
    .expect("qbsp reads the BSP");
    let records = theirs.bspx.decoupled_lm.expect("qbsp reads DECOUPLED_LM");
    assert_eq!(records.len(), ours.len());
    for (face, (t, o)) in records.iter().zip(&ours).enumerate() {
        assert_eq!([t.size.x, t.size.y], [o.width, o.height], "face {face}");
        assert_eq!(t.offset.pixels, o.offset, "face {face}");
        let p = &t.projection;
        // qbsp shifts the projection half a luxel, as FTE does when it draws the lump.
        let rows = [
            [p.u_axis.x, p.u_axis.y, p.u_axis.z, p.u_offset - 0.5],
            [p.v_axis.x, p.v_axis.y, p.v_axis.z, p.v_offset - 0.5],
        ];
        assert_eq!(rows, o.world_to_luxel, "face {face}");
    }
    // Every face with light has its own grid (sky-less scene); a face no light reaches has
    // none on either grid.
    for (face, r) in bsp.faces.iter().zip(&ours) {
        assert_eq!(r.offset >= 0, face.styles[0] != 255, "{r:?}");
    }
}

#[test]
fn eight_units_per_luxel_are_no_further_from_the_reference_than_sixteen_texels() {
    // Linear falloff with the default angle term: smooth gradients plus one hard shadow.
    let bsp = shadow_scene("\"light\" \"300\"");
    let run = |o: &Options| compute_lighting(&bsp, o).expect("light");
    let e16 = compare(
        &run(&options(Quality::Default)),
        &run(&options(Quality::Reference)),
    );
    let default8 = run(&on_own_grids(Quality::Default, 8.0));
    let reference8 = run(&on_own_grids(Quality::Reference, 8.0));
    let e8 = compare(
        &own_grid_lightmaps(&default8),
        &own_grid_lightmaps(&reference8),
    );
    // The 16-texel lightmap read from the 8-unit one, against the 16-texel reference.
    let e8_vanilla = compare(&default8, &run(&options(Quality::Reference)));
    eprintln!("16 texels: {e16:?}\n8 units: {e8:?}\n8 units read at 16 texels: {e8_vanilla:?}");
    assert!(e8.rmse <= e16.rmse, "{e8:?} against {e16:?}");
    assert!(e8.max <= e16.max, "{e8:?} against {e16:?}");
}

/// What a lit BSP file holds on the faces' own grids reads back as the run lit it, through
/// `DECOUPLED_LM` and through `LMSHIFT` and `LMOFFSET`.
#[test]
fn own_grid_lightmaps_read_back_from_the_lit_file_as_lit() {
    let mut shifted = options(Quality::Default);
    shifted.overrides.lmshift = Some(3);
    for options in [on_own_grids(Quality::Default, 8.0), shifted] {
        let mut bsp = shadow_scene("\"light\" \"300\"");
        let lighting = compute_lighting(&bsp, &options).expect("light");
        apply_lighting(&mut bsp, &lighting);
        let lit = Bsp::read(&bsp.write().expect("BSP encodes")).expect("BSP decodes");
        let faces: Vec<usize> = (0..lit.faces.len()).collect();
        let read = crate::own_grid_lightmaps_in(&lit, &faces).expect("own-grid lumps read");
        let lit_own = own_grid_lightmaps(&lighting);
        let as_lit = |l: &crate::Lighting| -> Vec<_> {
            let with_light = l.lightmaps.iter().filter(|m| !m.styles.is_empty());
            with_light
                .map(|m| (m.face, m.width, m.height, m.styles.clone(), m.grey.clone()))
                .collect()
        };
        assert_eq!(as_lit(&read), as_lit(&lit_own), "{:?}", options.overrides);
        assert!(!read.lightmaps.is_empty());
    }
    let unlit = shadow_scene("\"light\" \"300\"");
    let read = crate::own_grid_lightmaps_in(&unlit, &[0, 1]).expect("no lumps to read");
    assert!(read.lightmaps.is_empty(), "no face has its own grid");
}

/// Without a sun to thin or a PVS to cull by, the reference samples the grid as a run does;
/// grids of other points do not compare.
#[test]
fn the_light_grid_reference_of_a_sunless_map_is_the_grid() {
    let (bsp, grid, _) = shadow_scene_grid();
    let mut reference = options(Quality::Reference);
    reference.overrides.lightgrid = Some(true);
    reference.only_faces = Some(Vec::new());
    let exact = compute_lighting(&bsp, &reference).expect("light");
    assert!(
        exact.lightmaps.iter().all(|m| m.styles.is_empty()),
        "no face lit"
    );
    let exact = exact.light_grid.expect("the reference samples the grid");
    let e = crate::compare_grids(&grid, &exact).expect("the same points");
    assert!(e.luxels > 0 && e.rmse == 0.0, "{e:?}");
    let wider = quake_formats::bsp::lightgrid::LightGrid {
        spacing: [64.0; 3],
        ..exact
    };
    assert_eq!(crate::compare_grids(&grid, &wider), None);
}

/// A floor lit by a light on the far side of a thin wall standing on it: the near floor stays
/// dark at every spacing, on its own grid and in the 16-texel lightmap read from it.
#[test]
fn no_light_reaches_under_a_thin_wall_at_any_spacing() {
    let bsp = thin_wall_scene();
    let world_units = [8.0, 4.0].map(|u| on_own_grids(Quality::Default, u));
    // 8 and 4 texels.
    let texels = [3, 2].map(|shift| {
        let mut o = options(Quality::Default);
        o.overrides.lmshift = Some(shift);
        o
    });
    for options in world_units.iter().chain(&texels) {
        let lighting = compute_lighting(&bsp, options).expect("light");
        let own = own_grid_lightmaps(&lighting);
        for l in [&lighting, &own] {
            assert!(
                face_grey(l, 0).iter().all(|&v| v == 0),
                "{:?}: light bled under the wall: {:?}",
                options.overrides,
                face_grey(l, 0)
            );
            assert!(
                face_grey(l, 1).iter().all(|&v| v > 0),
                "{:?}: far floor lit",
                options.overrides
            );
        }
    }
}

/// Two floors either side of a thin wall standing between them, a light over the far one.
fn thin_wall_scene() -> Bsp {
    let near = quad(
        [0.0, 0.0, 0.0],
        [0.0, 100.0, 0.0],
        [100.0, 100.0, 0.0],
        [100.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
    );
    let far = quad(
        [104.0, 0.0, 0.0],
        [104.0, 100.0, 0.0],
        [200.0, 100.0, 0.0],
        [200.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
    );
    let mut polys = vec![near, far];
    polys.extend(box_faces([100.0, -50.0, -50.0], [104.0, 150.0, 200.0]));
    let ents = "{ \"classname\" \"worldspawn\" }\n{ \"classname\" \"light\" \"origin\" \"150 50 40\" \"delay\" \"3\" }\n";
    synthetic_bsp(&polys, ents)
}

#[test]
fn own_grids_give_the_same_bytes_on_one_and_two_threads() {
    let bsp = demo_bsp_with_sun();
    let world_units = on_own_grids(Quality::Default, 8.0);
    let mut texels = options(Quality::Default);
    texels.overrides.lmshift = Some(3);
    for mut options in [world_units, texels] {
        let o = &mut options.overrides;
        (o.dirt, o.bounce, o.sunsamples, o.bspxlit) = (Some(true), Some(1), Some(16), Some(true));
        let lit_bytes = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            let lighting = pool
                .install(|| compute_lighting(&bsp, &options))
                .expect("light");
            let mut lit = bsp.clone();
            apply_lighting(&mut lit, &lighting);
            lit.write().expect("BSP encodes")
        };
        let one = lit_bytes(1);
        assert!(
            one == lit_bytes(2),
            "{:?}: 1 and 2 threads differ",
            options.overrides
        );
    }
}

/// A 64-unit floor (the world, keyed `world_keys`) under a 64-unit plate 32 units up (a
/// `func_wall`, model 1, keyed `plate_keys`), lit from above.
fn floor_and_plate(world_keys: &str, plate_keys: &str) -> Bsp {
    let world = [floor(64.0)];
    let model = [quad(
        [0.0, 0.0, 32.0],
        [0.0, 64.0, 32.0],
        [64.0, 64.0, 32.0],
        [64.0, 0.0, 32.0],
        [0.0, 0.0, 1.0],
    )];
    let ents = format!(
        "{{ \"classname\" \"worldspawn\" {world_keys} }}\n\
         {{ \"classname\" \"func_wall\" \"model\" \"*1\" {plate_keys} }}\n\
         {{ \"classname\" \"light\" \"origin\" \"32 32 100\" }}\n"
    );
    synthetic_bsp_models(&[&world, &model], &ents)
}

/// A brush entity's own `_world_units_per_luxel` wins over the map's, and counts only while
/// the map's is set (as in ericw-tools).
#[test]
fn brush_entities_set_their_own_spacing() {
    let bsp = floor_and_plate("", "\"_world_units_per_luxel\" \"4\"");
    let sizes = |o: &Options| {
        let lighting = compute_lighting(&bsp, o).expect("light");
        lighting
            .lightmaps
            .iter()
            .map(|m| m.own_grid.as_deref().map(|g| g.lightmap.width))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        sizes(&on_own_grids(Quality::Default, 16.0)),
        vec![Some(5), Some(17)]
    );
    assert_eq!(sizes(&options(Quality::Default)), vec![None, None]);
}

/// worldspawn's `_lightmap_scale` (ericw-tools' `-lmscale`) lights every model at that fraction
/// of 16 texels, over a brush entity's own `_lmscale`.
#[test]
fn the_maps_lightmap_scale_wins_over_each_models() {
    let mut bsp = floor_and_plate("\"_lightmap_scale\" \"0.5\"", "\"_lmscale\" \"0.25\"");
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    apply_lighting(&mut bsp, &lighting);
    assert_eq!(
        bsp.lightmap_shifts().expect("LMSHIFT reads"),
        Some(vec![3, 3])
    );
}

/// `_lmscale` on a brush entity lights its faces at a fraction of 16 texels, written as
/// `LMSHIFT` and `LMOFFSET`; the world keeps Quake's grid (shift 4, its 16-texel lightmap).
#[test]
fn lmscale_writes_lmshift_and_lmoffset() {
    let mut bsp = floor_and_plate("", "\"_lmscale\" \"0.25\"");
    let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
    apply_lighting(&mut bsp, &lighting);
    assert_eq!(
        bsp.lightmap_shifts().expect("LMSHIFT reads"),
        Some(vec![4, 2])
    );
    let offsets = bsp
        .lightmap_offsets()
        .expect("LMOFFSET reads")
        .expect("LMOFFSET");
    assert_eq!(offsets[0], bsp.faces[0].light_offset);
    let own = lighting.lightmaps[1].own_grid.as_deref().expect("own grid");
    // 64 units at 4 texels a luxel: 17 across, where Quake's grid has 5.
    assert_eq!((own.lightmap.width, lighting.lightmaps[1].width), (17, 5));
    let at = usize::try_from(offsets[1]).expect("an offset");
    assert_eq!(bsp.lighting[at..at + 17 * 17], own.lightmap.grey[0][..]);
    assert!(own.lightmap.grey[0].iter().all(|&v| v > 0));
    let problems: Vec<_> = quake_formats::validate(&bsp)
        .into_iter()
        .filter(|p| {
            use quake_formats::bsp::light_lumps::{LMOFFSET, LMSHIFT};
            p.lump == LMSHIFT || p.lump == LMOFFSET
        })
        .collect();
    assert!(problems.is_empty(), "{problems:?}");
    // -lmshift overrides every model's `_lmscale`.
    let mut o = options(Quality::Default);
    o.overrides.lmshift = Some(3);
    let lighting = compute_lighting(&bsp, &o).expect("light");
    apply_lighting(&mut bsp, &lighting);
    assert_eq!(
        bsp.lightmap_shifts().expect("LMSHIFT reads"),
        Some(vec![3, 3])
    );
    // 4, the default, leaves each model its `_lmscale`.
    o.overrides.lmshift = Some(4);
    let lighting = compute_lighting(&bsp, &o).expect("light");
    apply_lighting(&mut bsp, &lighting);
    let shifts = bsp.lightmap_shifts().expect("LMSHIFT reads");
    assert_eq!(shifts, Some(vec![4, 2]));
}

/// With `--novanilla`, faces lit on their own grids keep only those lightmaps (no 16-texel
/// fallback), as ericw-tools writes them.
#[test]
fn novanilla_keeps_only_the_own_grid_lightmaps() {
    let mut bsp = shadow_scene("\"light\" \"300\"");
    let mut options = on_own_grids(Quality::Default, 8.0);
    options.overrides.novanilla = Some(true);
    let lighting = compute_lighting(&bsp, &options).expect("light");
    apply_lighting(&mut bsp, &lighting);
    assert!(bsp.faces.iter().all(|f| f.light_offset == -1));
    let records = bsp
        .decoupled_lightmaps()
        .expect("DECOUPLED_LM reads")
        .expect("DECOUPLED_LM");
    let luxels: usize = lighting
        .lightmaps
        .iter()
        .map(|m| {
            let own = &m.own_grid.as_deref().expect("own grid").lightmap;
            own.styles.len() * own.width * own.height
        })
        .sum();
    assert_eq!(bsp.luxel_count(), luxels, "no 16-texel lightmaps written");
    for (face, r) in bsp.faces.iter().zip(&records) {
        assert_eq!(r.offset >= 0, face.styles[0] != 255, "{r:?}");
    }
    let problems: Vec<_> = quake_formats::validate(&bsp)
        .into_iter()
        .filter(|p| p.lump == quake_formats::bsp::light_lumps::DECOUPLED_LM)
        .collect();
    assert!(problems.is_empty(), "{problems:?}");
}

/// Every key light reads, from the settings table and the entity keys' list, with a value that
/// does not read (or reads only in part): the map is lit, and a warning names the entity and the
/// key (the first of an entity's repeated keys is the one read, so the bad value comes first).
/// ericw-tools lights such maps; light once stopped at the first such key.
#[test]
fn no_key_value_stops_light() {
    use crate::entity_keys::{ENTITY_KEYS, Kind};
    let room = room_bsp(
        "{\n\"classname\" \"func_wall\"\n\"model\" \"*1\"\n}\n"
            .replace(
                "\"model\" \"*1\"\n",
                &map_box([-16.0, -16.0, -128.0], [16.0, 16.0, -96.0]),
            )
            .as_str(),
    );
    assert_eq!(room.models.len(), 2, "the room and its func_wall");
    let bad_values = |kind: Kind| -> &'static [&'static str] {
        match kind {
            Kind::Number | Kind::Whole => &["junk", "-", "7x"],
            Kind::Switch => &["maybe", "2"],
            Kind::Vector | Kind::Color => &["1 2", "%top", "1 0 0x"],
            Kind::Brightness => &["bright", "1 2", "150x"],
            Kind::Text => &[],
        }
    };
    // Keys read only beside another: that one too.
    let beside = |key: &str| match key {
        "_samples" => "\"_deviance\" \"8\"\n",
        "_surface_offset" | "_surface_spotlight" | "_surflight_group" => "\"_surface\" \"wall\"\n",
        "_minlight_color" | "_mincolor" => "\"_minlight\" \"8\"\n",
        "_phong_angle_concave" => "\"_phong\" \"1\"\n",
        "_project_mangle" | "_project_fov" | "angles" => "\"_project_texture\" \"wall\"\n",
        _ => "",
    };
    let light_with = |key: &str, value: &str| {
        format!(
            "{{\n\"classname\" \"worldspawn\"\n}}\n\
             {{\n\"classname\" \"light\"\n\"{key}\" \"{value}\"\n{}\"origin\" \"0 0 0\"\n}}\n\
             {{\n\"classname\" \"func_wall\"\n\"model\" \"*1\"\n}}\n",
            beside(key)
        )
    };
    let model_with = |key: &str, value: &str| {
        format!(
            "{{\n\"classname\" \"worldspawn\"\n}}\n\
             {{\n\"classname\" \"light\"\n\"origin\" \"0 0 0\"\n}}\n\
             {{\n\"classname\" \"func_wall\"\n\"model\" \"*1\"\n\"{key}\" \"{value}\"\n{}}}\n",
            beside(key)
        )
    };
    let world_with = |key: &str, value: &str| {
        format!(
            "{{\n\"classname\" \"worldspawn\"\n\"{key}\" \"{value}\"\n}}\n\
             {{\n\"classname\" \"light\"\n\"origin\" \"0 0 0\"\n}}\n\
             {{\n\"classname\" \"func_wall\"\n\"model\" \"*1\"\n}}\n"
        )
    };
    let mut cases: Vec<(String, &str, String)> = Vec::new();
    for key in ENTITY_KEYS {
        for value in bad_values(key.kind) {
            for name in key.names {
                if key.on.lights() {
                    cases.push((light_with(name, value), name, value.to_string()));
                }
                if key.on.models() {
                    cases.push((model_with(name, value), name, value.to_string()));
                }
            }
        }
    }
    for setting in crate::settings::TABLE {
        for name in setting.keys {
            // A text setting takes any value.
            for value in ["junk", "1 2", "%top"]
                .into_iter()
                .filter(|v| (setting.check)(v).is_err())
            {
                cases.push((world_with(name, value), name, value.to_string()));
            }
        }
    }
    assert!(cases.len() > 150, "{} cases", cases.len());
    let mut bsp = room.clone();
    for (entities, key, value) in cases {
        bsp.set_entity_text(&entities);
        let lighting = compute_lighting(&bsp, &options(Quality::Default))
            .unwrap_or_else(|e| panic!("\"{key}\" \"{value}\" stopped light: {e}"));
        let told = lighting
            .warnings
            .iter()
            .map(ToString::to_string)
            .find(|w| w.contains(&format!("key \"{key}\" is \"{value}\"")));
        let told = told.unwrap_or_else(|| {
            panic!(
                "\"{key}\" \"{value}\": no warning names it: {:?}",
                lighting.warnings
            )
        });
        assert!(told.starts_with("entity "), "{told}");
        assert!(told.contains(" line "), "{told}");
    }
}

/// `_minlight_mottle`: worldspawn's mottles the world's minimum light, a slow noise of 0 to 48
/// light units added to it (ericw-tools' range; its floor here spans 27 to 48 bytes, median
/// 37, and ours the same within 2); a brush model's own `_minlight_mottle 0` keeps its faces
/// flat, and without the key nothing is mottled.
#[test]
fn mottled_minlight_rises_from_the_floor_by_up_to_48_levels() {
    let wall = map_box([-16.0, -16.0, -128.0], [16.0, 16.0, -96.0]);
    let bsp = room_bsp(&format!("{{\n\"classname\" \"func_wall\"\n{wall}}}\n"));
    let model_faces = |m: usize| {
        let model = &bsp.models[m];
        let first = model.first_face as usize;
        first..first + model.num_faces as usize
    };
    let (world, wall_faces) = (model_faces(0), model_faces(1));
    let bytes = |bsp: &Bsp, world_keys: &str, wall_keys: &str| {
        let mut bsp = bsp.clone();
        bsp.set_entity_text(&format!(
            "{{\n\"classname\" \"worldspawn\"\n\"_minlight\" \"50\"\n{world_keys}}}\n\
             {{\n\"classname\" \"func_wall\"\n\"model\" \"*1\"\n{wall_keys}}}\n"
        ));
        let lighting = compute_lighting(&bsp, &options(Quality::Default)).expect("light");
        let of = |faces: &std::ops::Range<usize>| -> Vec<u8> {
            (lighting.lightmaps.iter())
                .filter(|m| faces.contains(&m.face) && !m.styles.is_empty())
                .flat_map(|m| m.grey[0].clone())
                .collect()
        };
        (of(&world), of(&wall_faces))
    };
    let (flat_world, flat_wall) = bytes(&bsp, "", "");
    assert!(flat_world.iter().chain(&flat_wall).all(|&b| b == 25));
    let (world_bytes, wall_bytes) = bytes(
        &bsp,
        "\"_minlight_mottle\" \"1\"\n",
        "\"_minlight_mottle\" \"0\"\n",
    );
    assert!(wall_bytes.iter().all(|&b| b == 25), "{wall_bytes:?}");
    let mut sorted = world_bytes.clone();
    sorted.sort_unstable();
    let (low, median, high) = (
        sorted[0],
        sorted[sorted.len() / 2],
        sorted[sorted.len() - 1],
    );
    assert!(low >= 25 && high <= 49, "{low} to {high}");
    assert!((35..=39).contains(&median), "median {median}");
    assert!(high - low > 15, "{low} to {high}");
    // The mottle is fixed in the world: a second run gives the same bytes.
    assert_eq!(
        bytes(&bsp, "\"_minlight_mottle\" \"1\"\n", "").0,
        world_bytes
    );
}

/// ericw-tools' estimate of a brush model's light (its "autominlight", which luxels in solid
/// take) includes bounced light: the bottom of a `func_wall` sunk into the floor, every sample
/// in solid, takes more with bounce than without, and exactly its model's light either way.
#[test]
fn a_sunk_brush_models_hidden_face_takes_bounced_light_too() {
    let wall = map_box([-16.0, -16.0, -136.0], [16.0, 16.0, -96.0]);
    let light = "{\n\"classname\" \"light\"\n\"origin\" \"0 64 0\"\n\"light\" \"300\"\n}\n";
    let bsp = room_bsp(&format!(
        "{{\n\"classname\" \"func_wall\"\n{wall}}}\n{light}"
    ));
    let faces = face_geometry(&bsp, |_| DVec3::ZERO, |_| Spacing::Quake).expect("faces");
    let bottom = faces
        .iter()
        .find(|f| f.model == 1 && f.plane.normal.z < -0.99)
        .expect("the func_wall's bottom")
        .index;
    let bottom_light = |bounce: usize| {
        let mut options = options(Quality::Default);
        options.overrides.bounce = Some(bounce);
        let lighting = compute_lighting(&bsp, &options).expect("light");
        let map = lighting
            .lightmaps
            .iter()
            .find(|m| m.face == bottom)
            .expect("a lightmap");
        let luxels = &map.grey[0];
        assert!(luxels.iter().all(|&l| l == luxels[0]), "{luxels:?}");
        luxels[0]
    };
    let (direct, bounced) = (bottom_light(0), bottom_light(1));
    assert!(direct > 0 && bounced > direct, "{direct} then {bounced}");
}
