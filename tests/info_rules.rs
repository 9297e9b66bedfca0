//! `slipgate info` names every rule a BSP breaks: the demo map compiles to a BSP that passes all
//! of them, and for each rule a copy broken in just that way makes `info` name the rule (and exit
//! 1 when the rule is an error).

#[path = "support/command.rs"]
mod command;

use command::slipgate;
use quake_formats::bsp::light_lumps::{DecoupledLightmap, LMSHIFT, RGBLIGHTING};
use quake_formats::bsp::lightgrid::LIGHTGRID_OCTREE;
use quake_formats::bsp::{BspPlane, ClipNode, Node, Rule, contents, texinfo_flags};
use quake_formats::entities::{parse_entities, write_entities};
use quake_formats::extents::LightmapExtents;
use quake_formats::{Bsp, Severity, string_to_name16};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn scratch(name: &str) -> PathBuf {
    command::scratch("rules", name)
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("utf8 path")
}

/// `maps/demo.map` compiled by the command, once per test run.
fn demo() -> &'static (Bsp, Vec<u8>) {
    static DEMO: OnceLock<(Bsp, Vec<u8>)> = OnceLock::new();
    DEMO.get_or_init(|| {
        let maps = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps");
        let bsp = scratch("demo.bsp");
        let out = slipgate(&[
            "bsp",
            "--wad-dir",
            path_str(&maps),
            path_str(&maps.join("demo.map")),
            path_str(&bsp),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(&bsp).expect("read demo.bsp");
        (Bsp::read(&bytes).expect("parse demo.bsp"), bytes)
    })
}

/// Writes `bytes` as `name` and runs `slipgate info` on it: exit code and standard output.
fn info(name: &str, bytes: &[u8]) -> (Option<i32>, String) {
    let path = scratch(&format!("{name}.bsp"));
    std::fs::write(&path, bytes).expect("write bsp");
    let out = slipgate(&["info", path_str(&path)]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    (out.status.code(), text)
}

#[test]
fn the_demo_map_passes_every_rule() {
    let (code, text) = info("demo-unbroken", &demo().1);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("valid: no problems found"), "{text}");
}

#[test]
fn info_lists_the_rules() {
    let out = slipgate(&["info", "--rules"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for rule in Rule::ALL {
        let line = format!("{} ({};", rule.id(), rule.severity());
        assert!(text.contains(&line), "{line} missing from:\n{text}");
    }
}

#[test]
fn each_broken_copy_names_its_rule() {
    let (demo, demo_bytes) = demo();
    let mut covered = BTreeSet::new();
    let mut failures = Vec::new();
    for (rule, breaker) in breakers() {
        covered.insert(rule);
        let bytes = match breaker {
            Break::Model(change) => {
                let mut bsp = demo.clone();
                change(&mut bsp);
                bsp.write().expect("write broken bsp")
            }
            Break::Bytes(change) => change(demo_bytes),
        };
        let (code, text) = info(rule.id(), &bytes);
        let expected = match rule.severity() {
            Severity::Error => 1,
            Severity::Warning => 0,
        };
        let named = text.contains(&format!("[{}; ", rule.id()));
        if !named || code != Some(expected) {
            failures.push(format!(
                "{rule}: exit {code:?}, expected {expected}:\n{text}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    let missing: Vec<&str> = Rule::ALL
        .iter()
        .filter(|r| !covered.contains(r))
        .map(|r| r.id())
        .collect();
    assert!(
        missing.is_empty(),
        "rules without a broken copy: {missing:?}"
    );
}

/// How to break the demo BSP: through the model, or (for what our writer refuses to write) in the
/// file's bytes.
enum Break {
    Model(fn(&mut Bsp)),
    Bytes(fn(&[u8]) -> Vec<u8>),
}

fn breakers() -> Vec<(Rule, Break)> {
    use Break::{Bytes, Model};
    vec![
        (Rule::IndexRange, Model(|b| b.marksurfaces[0] = 60000)),
        (Rule::NonFinite, Model(|b| b.vertices[0][0] = f32::NAN)),
        (
            Rule::PlaneNormal,
            Model(|b| b.planes[0].normal = [2.0, 0.0, 0.0]),
        ),
        (Rule::Bsp29Limit, Bytes(too_many_vertices)),
        (
            Rule::EntityText,
            Model(|b| b.entities.truncate(b.entities.len() - 1)),
        ),
        (Rule::FaceEdges, Model(|b| b.faces[0].num_edges = 2)),
        (Rule::ContentsValue, Model(|b| b.leafs[1].contents = -20)),
        (Rule::LightmapRange, Model(lightmap_past_the_lump)),
        (Rule::NoWorldModel, Model(|b| b.models.clear())),
        (Rule::NoNodes, Model(|b| b.nodes.clear())),
        (
            Rule::WorldHeadNode,
            Model(|b| b.models[0].head_nodes[0] = 1),
        ),
        (Rule::HullNodeRange, Model(clip_head_written_last)),
        (Rule::TreeCycle, Model(node_loops)),
        (Rule::ClipHullsMissing, Model(|b| b.clipnodes.clear())),
        (Rule::NodeSameChildren, Model(node_with_one_child_twice)),
        (
            Rule::NodePlaneOutsideRegion,
            Model(node_plane_behind_its_region),
        ),
        (
            Rule::LeafZeroSolid,
            Model(|b| b.leafs[0].contents = contents::EMPTY),
        ),
        (
            Rule::SurfaceExtents,
            Model(|b| scale_texture_axes(b, 100.0)),
        ),
        (
            Rule::SurfaceExtentsVanilla,
            Model(|b| scale_texture_axes(b, 4.0)),
        ),
        (
            Rule::LightmapExtentsEnginesDisagree,
            Model(face_on_a_grid_line_the_engines_disagree_about),
        ),
        (Rule::UnlitFaceVerts, Model(liquid_face_with_61_edges)),
        (
            Rule::TextureAlignment,
            Model(|b| texture(b, "brick1").width = 56),
        ),
        (
            Rule::AnimationName,
            Model(|b| rename(b, "brick1", "+xbrick")),
        ),
        (
            Rule::AnimationFrames,
            Model(|b| rename(b, "brick1", "+1brick")),
        ),
        (
            Rule::SkyTextureSize,
            Model(|b| texture(b, "sky1").height = 64),
        ),
        (Rule::SkyNameCase, Model(|b| rename(b, "sky1", "SKY1"))),
        (Rule::TexinfoMiptex, Model(|b| b.texinfo[0].miptex = 500)),
        (Rule::TextureMissing, Model(texture_not_stored)),
        (Rule::LeafCount, Model(|b| add_solid_leafs(b, 32768))),
        (
            Rule::VisLeafs,
            Model(|b| b.models[0].vis_leafs = b.leafs.len() as i32),
        ),
        (Rule::VisLeafsVanilla, Model(many_vis_leafs)),
        (Rule::ModelCount, Model(|b| copy_models(b, 2048))),
        (Rule::ModelCountVanilla, Model(|b| copy_models(b, 256))),
        (Rule::Worldspawn, Model(no_worldspawn)),
        (Rule::WorldspawnFirst, Model(worldspawn_last)),
        (Rule::PlayerStart, Model(no_player_start)),
        (
            Rule::BspxLightSize,
            Model(|b| b.set_bspx_lump(RGBLIGHTING, vec![0; 3 * b.luxel_count() + 1])),
        ),
        (
            Rule::BspxFaceRecords,
            Model(|b| b.set_bspx_lump(LMSHIFT, vec![4; b.faces.len() - 1])),
        ),
        (Rule::ShiftedLightmap, Model(shift_past_30)),
        (
            Rule::DecoupledLightmap,
            Model(decoupled_projection_not_finite),
        ),
        (
            Rule::LightGrid,
            Model(|b| b.set_bspx_lump(LIGHTGRID_OCTREE, vec![1, 2, 3])),
        ),
        (Rule::NoVanillaLighting, Model(colour_without_grey)),
    ]
}

/// Every face's `LMSHIFT` 31 (no engine holds `1 << 31`), its `LMOFFSET` the first luxel.
fn shift_past_30(b: &mut Bsp) {
    let n = b.faces.len();
    b.set_shifted_lightmaps(&vec![31; n], &vec![0; n]);
}

/// A `DECOUPLED_LM` record per face, the first with a NaN in its projection.
fn decoupled_projection_not_finite(b: &mut Bsp) {
    let mut records = vec![
        DecoupledLightmap {
            width: 1,
            height: 1,
            offset: -1,
            world_to_luxel: [[0.0; 4]; 2],
        };
        b.faces.len()
    ];
    records[0].world_to_luxel[0][0] = f32::NAN;
    b.set_decoupled_lightmaps(&records);
}

/// One luxel of `RGBLIGHTING` and no grey lump (`-novanilla`), no face lit.
fn colour_without_grey(b: &mut Bsp) {
    for f in &mut b.faces {
        f.light_offset = -1;
        f.styles = [255; 4];
    }
    b.lighting.clear();
    b.set_bspx_lump(RGBLIGHTING, vec![200, 100, 0]);
}

/// A BSP29 vertex lump of 65537 vertices, past 16-bit edge indices: our writer refuses it, so
/// the lump is appended to the file and the header pointed at it.
fn too_many_vertices(bytes: &[u8]) -> Vec<u8> {
    const VERTEX_LUMP: usize = 3;
    let mut out = bytes.to_vec();
    let offset = out.len() as i32;
    out.extend(std::iter::repeat_n(0u8, 65537 * 12));
    let entry = 4 + VERTEX_LUMP * 8;
    out[entry..entry + 4].copy_from_slice(&offset.to_le_bytes());
    out[entry + 4..entry + 8].copy_from_slice(&(65537i32 * 12).to_le_bytes());
    out
}

/// A lit face whose lightmap lies past the (empty) lighting lump.
fn lightmap_past_the_lump(b: &mut Bsp) {
    let face = (0..b.faces.len())
        .find(|&i| b.texinfo[b.faces[i].texinfo as usize].flags & texinfo_flags::SPECIAL == 0)
        .expect("a lit face");
    b.lighting.clear();
    b.faces[face].light_offset = 0;
}

/// The compiler bug QuakeSpasm caught: the world's clip hull head written after the nodes below
/// it (here a new head whose both sides lead to the old one, so every trace goes there).
fn clip_head_written_last(b: &mut Bsp) {
    let world = &mut b.models[0];
    let old_head = world.head_nodes[1];
    let plane = b.clipnodes[old_head as usize].plane;
    world.head_nodes[1] = b.clipnodes.len() as i32;
    b.clipnodes.push(ClipNode {
        plane,
        children: [old_head, old_head],
    });
}

/// The world's first node below the head points back at itself.
fn node_loops(b: &mut Bsp) {
    let child = b.nodes[0]
        .children
        .into_iter()
        .find(|&c| c >= 0)
        .expect("the head has a node child");
    b.nodes[child as usize].children[0] = child;
}

fn node_with_one_child_twice(b: &mut Bsp) {
    let node = &mut b.nodes[0];
    node.children[1] = node.children[0];
}

/// A node put between the head and its front child whose plane, the head's moved far behind it,
/// misses the head's front half: its front child takes the whole region, its back child (the
/// solid leaf) none.
fn node_plane_behind_its_region(b: &mut Bsp) {
    let head = b.nodes[0];
    let moved = BspPlane {
        dist: b.planes[head.plane as usize].dist - 4096.0,
        ..b.planes[head.plane as usize]
    };
    b.planes.push(moved);
    let node = b.nodes.len() as i32;
    b.nodes.push(Node {
        plane: b.planes.len() as u32 - 1,
        children: [head.children[0], -1],
        ..head
    });
    b.nodes[0].children[0] = node;
}

/// Texture axes of every texinfo multiplied: faces span `factor` times the texels.
fn scale_texture_axes(b: &mut Bsp, factor: f32) {
    for t in &mut b.texinfo {
        for axis in &mut t.vecs {
            for v in &mut axis[..3] {
                *v *= factor;
            }
        }
    }
}

/// The first lit face, given a texinfo of its own turned 10 degrees, whose s offset is searched,
/// f32 step by f32 step around the values that put its furthest vertex on a grid line, for one
/// where QuakeSpasm's and DarkPlaces' texture coordinates snap to different lines.
fn face_on_a_grid_line_the_engines_disagree_about(b: &mut Bsp) {
    let face = b
        .faces
        .iter()
        .position(|f| b.texinfo[f.texinfo as usize].flags & texinfo_flags::SPECIAL == 0)
        .expect("a lit face");
    let points = b.face_vertices(&b.faces[face]).expect("face vertices");
    let mut info = b.texinfo[b.faces[face].texinfo as usize];
    let (sin, cos) = 10f32.to_radians().sin_cos();
    let [s, t] = info.vecs;
    for k in 0..3 {
        info.vecs[0][k] = cos * s[k] - sin * t[k];
        info.vecs[1][k] = sin * s[k] + cos * t[k];
    }
    let furthest = points
        .iter()
        .map(|p| p[0] * info.vecs[0][0] + p[1] * info.vecs[0][1] + p[2] * info.vecs[0][2])
        .fold(f32::NEG_INFINITY, f32::max);
    let offsets = (0..64).flat_map(|line| {
        let on_line = (16 * line) as f32 - furthest;
        (-64..64).map(move |step| f32::from_bits(on_line.to_bits().wrapping_add_signed(step)))
    });
    for offset in offsets {
        info.vecs[0][3] = offset;
        if LightmapExtents::engines_disagree(&points, &info.vecs)[0] {
            b.texinfo.push(info);
            b.faces[face].texinfo = (b.texinfo.len() - 1) as u32;
            return;
        }
    }
    panic!("no offset near a grid line makes the engines disagree on face {face}");
}

/// A water face re-pointed at 61 surfedges (its own edges, repeated).
fn liquid_face_with_61_edges(b: &mut Bsp) {
    let water = b.textures.find("*water1").expect("*water1") as u32;
    let face = b
        .faces
        .iter()
        .position(|f| b.texinfo[f.texinfo as usize].miptex == water)
        .expect("a water face");
    let f = b.faces[face];
    let own = b.surfedges[f.first_edge as usize..(f.first_edge + f.num_edges) as usize].to_vec();
    let first = b.surfedges.len() as u32;
    b.surfedges.extend(own.iter().cycle().take(61));
    b.faces[face].first_edge = first;
    b.faces[face].num_edges = 61;
}

fn texture<'a>(b: &'a mut Bsp, name: &str) -> &'a mut quake_formats::miptex::MipTex {
    let i = b.textures.find(name).expect("texture");
    b.textures.textures[i].as_mut().expect("stored texture")
}

fn rename(b: &mut Bsp, from: &str, to: &str) {
    texture(b, from).raw_name = string_to_name16(to);
}

/// The texture the first face draws with, left out of the file.
fn texture_not_stored(b: &mut Bsp) {
    let miptex = b.texinfo[b.faces[0].texinfo as usize].miptex as usize;
    b.textures.textures[miptex] = None;
}

fn add_solid_leafs(b: &mut Bsp, total: usize) {
    let solid = b.leafs[0];
    b.leafs.resize(total, solid);
}

fn many_vis_leafs(b: &mut Bsp) {
    add_solid_leafs(b, 9000);
    b.models[0].vis_leafs = 8500;
}

fn copy_models(b: &mut Bsp, total: usize) {
    let door = b.models[1];
    b.models.resize(total, door);
}

fn rewrite_entities(b: &mut Bsp, change: impl FnOnce(&mut Vec<quake_formats::entities::Entity>)) {
    let mut entities = parse_entities(&b.entity_text()).expect("entities");
    change(&mut entities);
    b.set_entity_text(&write_entities(&entities));
}

/// The world spawned as the last entity, a light as the first.
fn worldspawn_last(b: &mut Bsp) {
    rewrite_entities(b, |e| {
        let last = e.len() - 1;
        e.swap(0, last);
    });
}

fn no_worldspawn(b: &mut Bsp) {
    rewrite_entities(b, |e| e.retain(|e| e.classname() != "worldspawn"));
}

fn no_player_start(b: &mut Bsp) {
    rewrite_entities(b, |e| e.retain(|e| e.classname() != "info_player_start"));
}
