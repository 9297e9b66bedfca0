//! Which faces get T-junction vertices from which, as ericw-tools decides: solid, sky and liquid
//! faces give their vertices to every face; detail walls, fences and illusionary brushes give
//! none to solid or sky faces (detail walls give theirs to detail walls); see-through faces and
//! liquids take every vertex. Each model on its own.

mod common;

use common::{box_brush, brush_entity, compile_text, face_texture, faces_at, room_map_with};
use quake_formats::Bsp;

/// The kinds of brush of ericw-tools' T-junction matrix: entity class, its extra keys, texture.
const KINDS: [(&str, &str, &str, &str); 9] = [
    ("solid", "worldspawn", "", "wall"),
    ("detail", "func_detail", "", "wall"),
    ("detail wall", "func_detail_wall", "", "wall"),
    ("fence", "func_detail_fence", "", "{fence"),
    (
        "fence, mirrored inside",
        "func_detail_fence",
        "\"_mirrorinside\" \"1\"\n",
        "{fence",
    ),
    ("illusionary", "func_detail_illusionary", "", "{fence"),
    (
        "illusionary, _noclipfaces",
        "func_detail_illusionary",
        "\"_noclipfaces\" \"1\"\n",
        "{fence",
    ),
    ("water", "worldspawn", "", "*water"),
    ("sky", "worldspawn", "", "sky1"),
];

/// Whether a face of the row's kind takes the vertices of the column's kind (ericw-tools'
/// `tjuncMatrix`).
const TAKES: [[bool; 9]; 9] = {
    const T: bool = true;
    const F: bool = false;
    [
        [T, T, F, F, F, F, F, T, T],
        [T, T, F, F, F, F, F, T, T],
        [T, T, T, F, F, F, F, T, T],
        [T; 9],
        [T; 9],
        [T; 9],
        [T; 9],
        [T; 9],
        [T, T, F, F, F, F, F, T, T],
    ]
};

/// Where the base block of row `h` and column `v` stands (its lowest corner): 64 x 32 x 16,
/// with a 32 wide block of the column's kind on its top, 16 in from each end, both flush with
/// the base's front (y = -16): the top block's lower front corners lie inside the base's front
/// face's top edge.
fn base(h: usize, v: usize) -> [f64; 3] {
    [128.0 * h as f64 - 576.0, -16.0, 48.0 * v as f64 - 112.0]
}

/// A closed room around `lo..hi`, walls 16 thick.
fn box_room(lo: [f64; 3], hi: [f64; 3]) -> String {
    let t = 16.0;
    let (a, b) = (lo.map(|c| c - t), hi.map(|c| c + t));
    [
        box_brush(a, [b[0], b[1], lo[2]], "floor"),
        box_brush([a[0], a[1], hi[2]], b, "ceiling"),
        box_brush([a[0], a[1], lo[2]], [lo[0], b[1], hi[2]], "wall"),
        box_brush([hi[0], a[1], lo[2]], [b[0], b[1], hi[2]], "wall"),
        box_brush([lo[0], a[1], lo[2]], [hi[0], lo[1], hi[2]], "wall"),
        box_brush([lo[0], hi[1], lo[2]], [hi[0], b[1], hi[2]], "wall"),
    ]
    .concat()
}

fn matrix_map() -> String {
    let mut brushes = vec![String::new(); KINDS.len()];
    for h in 0..KINDS.len() {
        for v in 0..KINDS.len() {
            let [x, y, z] = base(h, v);
            brushes[h] += &box_brush([x, y, z], [x + 64.0, y + 32.0, z + 16.0], KINDS[h].3);
            brushes[v] += &box_brush(
                [x + 16.0, y, z + 16.0],
                [x + 48.0, y + 32.0, z + 32.0],
                KINDS[v].3,
            );
        }
    }
    let mut world = box_room([-640.0, -128.0, -128.0], [640.0, 128.0, 384.0]);
    let mut entities = String::new();
    for ((_, class, keys, _), list) in KINDS.iter().zip(&brushes) {
        if *class == "worldspawn" {
            world += list;
        } else {
            entities += &format!("{{\n\"classname\" \"{class}\"\n{keys}{list}}}\n");
        }
    }
    format!(
        "{{\n\"classname\" \"worldspawn\"\n{world}}}\n{entities}\
         {{\n\"classname\" \"info_player_start\"\n\"origin\" \"0 -96 -100\"\n}}\n"
    )
}

fn has_vertex(bsp: &Bsp, face: usize, p: [f32; 3]) -> bool {
    let vertices = bsp.face_vertices(&bsp.faces[face]).expect("vertices");
    vertices
        .iter()
        .any(|v| (0..3).all(|i| (v[i] - p[i]).abs() < 0.01))
}

#[test]
fn t_junctions_follow_ericw_tools_matrix() {
    let out = compile_text(&matrix_map());
    assert!(out.leak.is_none(), "{:?}", out.leak);
    let bsp = &out.bsp;
    let mut wrong = Vec::new();
    for (h, row) in TAKES.iter().enumerate() {
        for (v, &expected) in row.iter().enumerate() {
            let [x, y, z] = base(h, v);
            let middle = [x + 32.0, y, z + 8.0].map(|c| c as f32);
            let front = faces_at(bsp, 0, middle, Some([0.0, -1.0, 0.0]));
            assert_eq!(front.len(), 1, "{} under {}", KINDS[h].0, KINDS[v].0);
            let corner = [x + 16.0, y, z + 16.0].map(|c| c as f32);
            if has_vertex(bsp, front[0], corner) != expected {
                wrong.push(format!("{} under {}", KINDS[h].0, KINDS[v].0));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "T-junctions differ from ericw-tools': {wrong:?}"
    );
}

/// A pillar standing in the corner of the -x wall and the floor: its lower corners lie on the
/// wall's and the floor's shared edge. As a `func_detail_wall` it adds no vertex to the world's
/// faces there, which stay whole (ericw-tools' `detailWallTjuncs`); as `func_detail` it cuts
/// them, and they have its corners.
#[test]
fn a_detail_wall_adds_no_vertices_to_the_faces_behind_it() {
    let pillar = box_brush([-128.0, -16.0, -128.0], [-96.0, 16.0, 0.0], "pillar");
    for (class, expected) in [("func_detail_wall", false), ("func_detail", true)] {
        let out = compile_text(&room_map_with(false, "", &brush_entity(class, &pillar)));
        assert_eq!(
            world_faces_with_vertex(&out.bsp, [-128.0, 16.0, -128.0], "pillar"),
            expected,
            "{class}"
        );
    }
}

/// A `func_wall` block in the same corner: its corners go into no world face, since T-junctions
/// are fixed model by model, as in ericw-tools.
#[test]
fn brush_models_give_the_world_no_vertices() {
    let block = box_brush([-128.0, -16.0, -128.0], [-96.0, 16.0, -64.0], "block");
    let out = compile_text(&room_map_with(
        false,
        "",
        &brush_entity("func_wall", &block),
    ));
    assert!(!world_faces_with_vertex(
        &out.bsp,
        [-128.0, 16.0, -128.0],
        "block"
    ));
}

/// Whether a world face not textured `except` has a vertex at `p`.
fn world_faces_with_vertex(bsp: &Bsp, p: [f32; 3], except: &str) -> bool {
    let world = &bsp.models[0];
    let first = world.first_face as usize;
    (first..first + world.num_faces as usize)
        .filter(|&f| face_texture(bsp, f) != except)
        .any(|f| has_vertex(bsp, f, p))
}

/// The crack check reads what each face is made of from the BSP, and counts none of the vertices
/// the compiler leaves out of solid faces on purpose: a fence's or an illusionary brush's
/// standing in the corner leaves no crack.
#[test]
fn the_crack_check_counts_no_vertex_left_out_on_purpose() {
    let pillar = box_brush([-128.0, -16.0, -128.0], [-96.0, 16.0, 0.0], "{fence");
    for class in ["func_detail_fence", "func_detail_illusionary"] {
        let out = compile_text(&room_map_with(false, "", &brush_entity(class, &pillar)));
        assert!(!world_faces_with_vertex(
            &out.bsp,
            [-128.0, 16.0, -128.0],
            "{fence"
        ));
        let cracks = bsp_compiler::cracks::find_cracks(&out.bsp);
        assert!(cracks.is_empty(), "{class}: {}", cracks.summary());
    }
}
