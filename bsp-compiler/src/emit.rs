//! Writing the compiled models into a [`Bsp`]: planes, textures, shared vertices and edges,
//! faces, nodes, leaves (leaf 0 is the shared solid leaf), clip nodes and models; and the
//! world's portals into a PRT1 file (PRT2 when it has detail).

use crate::content_flags::ContentFlags;
use crate::faces::ModelFace;
use crate::gather::MapTexInfo;
use crate::hulls::emit_clipnodes;
use crate::model::ModelOutput;
use crate::planes::{PlaneId, PlaneSet};
use crate::portals::Portals;
use crate::texinfo::TextureRole;
use crate::tree::{Tree, engine_contents, is_see_through, vis_class};
use crate::wad_lookup::{TextureList, WadSet};
use crate::warnings::Warning;
use crate::weld::{VertexWelder, WeldClass, cut_to_max_vertices, fix_tjunctions};
use glam::DVec3;
use quake_formats::bsp::face_flags::FaceFlags;
use quake_formats::bsp::face_minlight::FaceMinlight;
use quake_formats::bsp::face_tone::FaceTone;
use quake_formats::bsp::leaf_flags::LeafFlags;
use quake_formats::bsp::limits::QUAKESPASM_MAX_WARP_FACE_VERTS;
use quake_formats::bsp::phong::FacePhong;
use quake_formats::bsp::{BspPlane, Face, Leaf, Model, Node, TexInfo, contents, texinfo_flags};
use quake_formats::entities::{Entity, write_entities};
use quake_formats::geom::{Bounds, Plane};
use quake_formats::int_hash::IntMap;
use quake_formats::prt::{PortalFile, PrtPortal};
use quake_formats::{Bsp, BspVersion};

/// What [`emit_drawing`] reads: every model's hull 0 (tree, portals, faces), and the tables
/// they name.
pub(crate) struct DrawingInput<'m, 't> {
    pub models: &'m [ModelDrawing<'m>],
    pub planes: &'t PlaneSet,
    pub texinfos: &'t [MapTexInfo],
    pub texture_names: &'t [String],
    /// The texture lump's order; the textures of `texture_names` are found in it (and added to
    /// it when missing).
    pub texture_list: TextureList,
    pub version: BspVersion,
    /// Faces with more edges are cut ([`crate::CompileOptions::max_edges`]; 0: never).
    pub max_edges: usize,
    /// Vis looks through liquids' surfaces ([`crate::CompileOptions::transwater`]).
    pub transwater: bool,
}

/// One model's hull 0: its tree, the portals around its leaves (and its clusters', when detail
/// split them), the faces on its nodes, and its bounds.
pub(crate) struct ModelDrawing<'a> {
    pub tree: &'a Tree,
    pub portals: &'a Portals,
    pub cluster_portals: Option<&'a Portals>,
    pub faces: &'a [ModelFace],
    pub bounds: Bounds,
}

/// What [`emit`] reads besides what [`emit_drawing`] wrote.
pub(crate) struct EmitInput<'a> {
    /// Each model's bounds ([`ModelOutput::bounds`]) and clip hulls.
    pub models: &'a [ModelOutput],
    pub wads: &'a WadSet,
    pub entities: &'a [Entity],
    pub warnings: &'a mut Vec<Warning>,
}

pub(crate) struct Emitted {
    pub bsp: Bsp,
    pub portals: PortalFile,
    /// Each BSP leaf's extended content flags, in leaf order.
    pub leaf_contents: Vec<ContentFlags>,
    pub tjunction_vertices: usize,
}

/// Planes written on first use.
struct PlaneTable<'a> {
    source: &'a PlaneSet,
    index: Vec<u32>,
    planes: Vec<BspPlane>,
}

impl PlaneTable<'_> {
    fn get(&mut self, id: PlaneId) -> u32 {
        if self.index[id as usize] == u32::MAX {
            self.index[id as usize] = self.push(self.source.get(id));
        }
        self.index[id as usize]
    }

    fn push(&mut self, p: &Plane) -> u32 {
        self.planes.push(BspPlane {
            normal: p.normal.as_vec3().to_array(),
            dist: p.dist as f32,
            kind: p.quake_type(),
        });
        (self.planes.len() - 1) as u32
    }
}

/// Texinfos written on first use, each naming its texture's slot in the texture lump.
struct TextureTable<'a> {
    infos: &'a [MapTexInfo],
    info_index: Vec<u32>,
    /// The lump slot of each texture of [`EmitInput::texture_names`].
    texture_slot: Vec<u32>,
    out_infos: Vec<TexInfo>,
    /// Whether a face shows the texture of each slot.
    shown: Vec<bool>,
}

impl TextureTable<'_> {
    fn get(&mut self, id: u32) -> u32 {
        if self.info_index[id as usize] == u32::MAX {
            let info = &self.infos[id as usize];
            let slot = self.texture_slot[info.texture as usize];
            self.shown[slot as usize] = true;
            self.info_index[id as usize] = self.out_infos.len() as u32;
            self.out_infos.push(TexInfo {
                vecs: info.vecs.map(|row| row.map(|c| c as f32)),
                miptex: slot,
                flags: if info.is_special() {
                    texinfo_flags::SPECIAL
                } else {
                    0
                },
            });
        }
        self.info_index[id as usize]
    }
}

/// The most edges a face of texture `role` may have: `max_edges` (0: no limit), and for liquids
/// no more than the buffer QuakeSpasm subdivides them from.
fn max_face_edges(max_edges: usize, role: TextureRole) -> Option<usize> {
    match (max_edges, role) {
        (0, _) => None,
        (n, TextureRole::Liquid(_)) => Some(n.min(QUAKESPASM_MAX_WARP_FACE_VERTS)),
        (n, _) => Some(n),
    }
}

/// How far engines widen a model's box on every side as they load the models lump (id's engine
/// did, in `Mod_LoadSubmodels`, and QuakeSpasm and DarkPlaces still do).
const ENGINE_MODEL_SPREAD: f64 = 1.0;

/// The box written for model `bounds` (its brushes'): a unit inside them on every side, as qbsp
/// writes it, so that the box engines load is the brushes' own again. That box is what QuakeC
/// sizes a door's travel and a trigger's field by, and what the server links a brush model into
/// the world with and the renderer culls it by: written exact, it would come out a unit too large
/// on every side and doors would travel two units further than on qbsp's files. A model thinner
/// than two units gets a box turned inside out, which the engine's widening turns back.
fn written_model_bounds(bounds: &Bounds) -> Bounds {
    let spread = DVec3::splat(ENGINE_MODEL_SPREAD);
    Bounds {
        mins: bounds.mins + spread,
        maxs: bounds.maxs - spread,
    }
}

/// `bounds` rounded outward to whole units, as qbsp writes node and leaf bounds in every BSP
/// version (BSP29 can only store whole units; BSP2 gets the same values).
fn whole_units(bounds: Bounds) -> Bounds {
    Bounds {
        mins: bounds.mins.floor(),
        maxs: bounds.maxs.ceil(),
    }
}

/// The internal nodes of a model's tree in output order (pre-order, all-solid subtrees left out).
fn node_order(tree: &Tree, solid: &[bool]) -> Vec<u32> {
    let mut order = Vec::new();
    let mut stack = vec![0u32];
    while let Some(n) = stack.pop() {
        let node = &tree.nodes[n as usize];
        if solid[n as usize] || node.is_leaf() {
            continue;
        }
        order.push(n);
        stack.push(node.children[1]);
        stack.push(node.children[0]);
    }
    order
}

/// A face in output order with its welded polygon.
struct PendingFace<'a> {
    model: usize,
    face: &'a ModelFace,
    vertices: Vec<u32>,
}

/// Hull 0 of every model written: vertices (welded, T-junctions fixed), edges, faces and the
/// planes and texinfos they name (numbered first, in face order); nodes and leaves (their planes
/// numbered by [`emit`], after each model's faces and before its clip nodes' as qbsp numbers
/// them); and the world's portal file. Needs nothing of the clip hulls, which may still be
/// building.
pub(crate) fn emit_drawing<'t>(mut input: DrawingInput<'_, 't>) -> DrawnBsp<'t> {
    let mut bsp = Bsp::new(input.version);
    let mut planes = PlaneTable {
        source: input.planes,
        index: vec![u32::MAX; input.planes.len()],
        planes: Vec::new(),
    };
    let texture_slot: Vec<u32> = input
        .texture_names
        .iter()
        .map(|name| input.texture_list.slot(name))
        .collect();
    let mut textures = TextureTable {
        infos: input.texinfos,
        info_index: vec![u32::MAX; input.texinfos.len()],
        texture_slot,
        out_infos: Vec::new(),
        shown: vec![false; input.texture_list.len()],
    };

    // Faces in output order: model by model, node by node.
    let solids: Vec<Vec<bool>> = input.models.iter().map(|m| m.tree.all_solid()).collect();
    let orders: Vec<Vec<u32>> = input
        .models
        .iter()
        .zip(&solids)
        .map(|(m, s)| node_order(m.tree, s))
        .collect();
    let mut welder = VertexWelder::default();
    let mut pending = Vec::new();
    for (mi, m) in input.models.iter().enumerate() {
        let mut by_node: Vec<Vec<usize>> = vec![Vec::new(); m.tree.nodes.len()];
        for (fi, f) in m.faces.iter().enumerate() {
            by_node[f.node as usize].push(fi);
        }
        for &n in &orders[mi] {
            for &fi in &by_node[n as usize] {
                let face = &m.faces[fi];
                let vertices = face
                    .winding
                    .points
                    .iter()
                    .map(|&p| welder.weld(p))
                    .collect();
                pending.push(PendingFace {
                    model: mi,
                    face,
                    vertices,
                });
            }
        }
    }
    let mut polygons: Vec<Vec<u32>> = pending
        .iter_mut()
        .map(|f| std::mem::take(&mut f.vertices))
        .collect();
    let classes: Vec<WeldClass> = pending
        .iter()
        .map(|f| {
            let texture = input.texinfos[f.face.texinfo as usize].texture;
            WeldClass::of(f.face.painted_from, &input.texture_names[texture as usize])
        })
        .collect();
    // Model by model, as ericw-tools does: a door's corner does not cut the wall it closes.
    let mut tjunction_vertices = 0;
    let mut start = 0;
    while start < pending.len() {
        let model = pending[start].model;
        let end = start + pending[start..].partition_point(|f| f.model == model);
        tjunction_vertices += fix_tjunctions(
            &welder.positions,
            &mut polygons[start..end],
            &classes[start..end],
        );
        start = end;
    }
    bsp.vertices = welder
        .positions
        .iter()
        .map(|p| p.as_vec3().to_array())
        .collect();
    if bsp.vertices.is_empty() {
        // Edge 0 (below) names vertex 0, which must exist even in a world with no faces (one of
        // only clip, hint or liquid-less invisible brushes).
        bsp.vertices.push([0.0; 3]);
    }

    // Faces, edges and, per model node and leaf, which faces they hold.
    bsp.edges.push([0, 0]); // edge 0 cannot be negated, so it is never used
    // Keyed by the contents the face is seen from too: only faces seen from the same contents
    // share an edge (see `ModelFace::seen_from`), each once each way.
    let mut edge_index: IntMap<(u32, u32, i32), (u32, bool)> = IntMap::default();
    let mut node_faces: IntMap<(usize, u32), (u32, u32)> = IntMap::default();
    let mut leaf_faces: IntMap<(usize, u32), Vec<u32>> = IntMap::default();
    // The bounds of the faces each leaf lists away from where they are seen (behind fences):
    // engines that cull a leaf by its bounds must not cull them.
    let mut leaf_growth: IntMap<(usize, u32), Bounds> = IntMap::default();
    let mut model_faces: Vec<(u32, u32)> = vec![(0, 0); input.models.len()];
    let mut phong = Vec::with_capacity(pending.len());
    let mut flags = Vec::with_capacity(pending.len());
    let mut surflight_groups = Vec::with_capacity(pending.len());
    let mut minlights = Vec::with_capacity(pending.len());
    let mut channels = Vec::with_capacity(pending.len());
    let mut tones = Vec::with_capacity(pending.len());
    let pieces = pending.iter().zip(polygons).flat_map(|(pf, poly)| {
        let max = max_face_edges(
            input.max_edges,
            input.texinfos[pf.face.texinfo as usize].role,
        );
        let pieces = match max {
            Some(max) => cut_to_max_vertices(poly, max, &welder.positions),
            None => vec![poly],
        };
        pieces.into_iter().map(move |poly| (pf, poly))
    });
    for (pf, poly) in pieces {
        if poly.len() < 3 {
            continue;
        }
        let f = pf.face;
        let face_index = bsp.faces.len() as u32;
        let first_edge = bsp.surfedges.len() as u32;
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            match edge_index.get_mut(&(b, a, f.seen_from)) {
                Some((e, reused)) if !*reused => {
                    *reused = true;
                    bsp.surfedges.push(-(*e as i32));
                }
                _ => {
                    let e = bsp.edges.len() as u32;
                    bsp.edges.push([a, b]);
                    edge_index.insert((a, b, f.seen_from), (e, false));
                    bsp.surfedges.push(e as i32);
                }
            }
        }
        let special = input.texinfos[f.texinfo as usize].is_special();
        bsp.faces.push(Face {
            plane: planes.get(f.plane),
            side: u32::from(f.back),
            first_edge,
            num_edges: poly.len() as u32,
            texinfo: textures.get(f.texinfo),
            styles: if special {
                [255; 4]
            } else {
                [0, 255, 255, 255]
            },
            light_offset: -1,
        });
        let info = &input.texinfos[f.texinfo as usize];
        phong.push(info.phong);
        flags.push(info.flags);
        surflight_groups.push(info.surflight_group);
        minlights.push(info.minlight);
        channels.push(info.channels);
        tones.push(info.tone);
        let range = node_faces
            .entry((pf.model, f.node))
            .or_insert((face_index, 0));
        range.1 += 1;
        let range = &mut model_faces[pf.model];
        if range.1 == 0 {
            range.0 = face_index;
        }
        range.1 += 1;
        for &leaf in &f.leaves {
            leaf_faces
                .entry((pf.model, leaf))
                .or_default()
                .push(face_index);
            if f.stored {
                let grown = leaf_growth.entry((pf.model, leaf)).or_insert(Bounds::EMPTY);
                *grown = grown.union(&f.winding.bounds());
            }
        }
    }
    // Nodes and leaves.
    bsp.leafs.push(Leaf::SHARED_SOLID);
    let mut leaf_contents = vec![ContentFlags::SOLID];
    let mut world_leaf_index: IntMap<u32, u32> = IntMap::default();
    let mut trees = Vec::with_capacity(input.models.len());
    for (mi, m) in input.models.iter().enumerate() {
        let (first_node, leaves_before) = (bsp.nodes.len(), bsp.leafs.len());
        let mut w = TreeWriter {
            model: mi,
            drawing: m,
            solid: &solids[mi],
            bsp: &mut bsp,
            node_faces: &node_faces,
            leaf_faces: &leaf_faces,
            leaf_growth: &leaf_growth,
            leaf_index: IntMap::default(),
            leaf_contents: &mut leaf_contents,
            transwater: input.transwater,
        };
        let (mut head, head_bounds) = w.node(0);
        if head < 0 {
            // Engines start at a node: give a one-leaf model a node with the leaf on both sides.
            w.bsp.nodes.push(Node {
                plane: ONE_LEAF_PLANE,
                children: [head, head],
                mins: head_bounds.mins.as_vec3().to_array(),
                maxs: head_bounds.maxs.as_vec3().to_array(),
                first_face: 0,
                num_faces: 0,
            });
            head = (w.bsp.nodes.len() - 1) as i32;
        }
        if mi == 0 {
            world_leaf_index = std::mem::take(&mut w.leaf_index);
        }
        trees.push(WrittenTree {
            head,
            nodes: first_node..bsp.nodes.len(),
            vis_leafs: (bsp.leafs.len() - leaves_before) as i32,
        });
    }
    let portals = world_portal_file(
        &input.models[0],
        &world_leaf_index,
        trees[0].vis_leafs,
        input.transwater,
    );
    DrawnBsp {
        bsp,
        planes,
        textures,
        texture_list: input.texture_list,
        trees,
        leaf_contents,
        portals,
        model_faces,
        face_lumps: FaceLumps {
            phong,
            flags,
            surflight_groups,
            minlights,
            channels,
            tones,
        },
        tjunction_vertices,
    }
}

/// Each written face's entry of the per-face BSPX lumps, in face order.
struct FaceLumps {
    phong: Vec<FacePhong>,
    flags: Vec<FaceFlags>,
    surflight_groups: Vec<i32>,
    minlights: Vec<FaceMinlight>,
    channels: Vec<u32>,
    tones: Vec<FaceTone>,
}

/// Where [`emit_drawing`] wrote a model's hull 0.
struct WrittenTree {
    /// The head node.
    head: i32,
    /// Its nodes, whose planes are still [`PlaneId`]s ([`ONE_LEAF_PLANE`] for a one-leaf
    /// model's node).
    nodes: std::ops::Range<usize>,
    /// How many leaves it wrote.
    vis_leafs: i32,
}

/// The plane of the node [`emit_drawing`] gives a one-leaf model until [`emit`] writes it: a
/// plane of its own (z = 0), not one of the map's.
const ONE_LEAF_PLANE: u32 = u32::MAX;

/// The BSP as far as [`emit_drawing`] writes it, and what [`emit`] needs to finish it.
pub(crate) struct DrawnBsp<'a> {
    bsp: Bsp,
    planes: PlaneTable<'a>,
    textures: TextureTable<'a>,
    texture_list: TextureList,
    trees: Vec<WrittenTree>,
    /// Each written leaf's extended content flags, in leaf order.
    leaf_contents: Vec<ContentFlags>,
    /// The world's portal file.
    portals: PortalFile,
    model_faces: Vec<(u32, u32)>,
    face_lumps: FaceLumps,
    tjunction_vertices: usize,
}

/// The rest of the BSP after [`emit_drawing`]: each model's node planes numbered, then its clip
/// nodes written (as qbsp numbers planes); models, textures and the other lumps.
pub(crate) fn emit(drawn: DrawnBsp, input: EmitInput) -> Emitted {
    let DrawnBsp {
        mut bsp,
        mut planes,
        textures,
        texture_list,
        trees,
        leaf_contents,
        portals,
        model_faces,
        face_lumps,
        tjunction_vertices,
    } = drawn;
    for ((m, tree), (first_face, num_faces)) in input.models.iter().zip(&trees).zip(model_faces) {
        for node in &mut bsp.nodes[tree.nodes.clone()] {
            node.plane = match node.plane {
                ONE_LEAF_PLANE => planes.push(&Plane::new(DVec3::new(0.0, 0.0, 1.0), 0.0)),
                id => planes.get(id),
            };
        }
        let mut clip_heads = [contents::EMPTY; 2];
        for (hull, tree) in m.hulls.iter().enumerate() {
            clip_heads[hull] = emit_clipnodes(tree, &mut |id| planes.get(id), &mut bsp.clipnodes);
        }
        let written = written_model_bounds(&m.bounds);
        bsp.models.push(Model {
            mins: written.mins.as_vec3().to_array(),
            maxs: written.maxs.as_vec3().to_array(),
            origin: [0.0; 3],
            head_nodes: [tree.head, clip_heads[0], clip_heads[1], 0],
            vis_leafs: tree.vis_leafs,
            first_face,
            num_faces,
        });
    }
    if bsp.clipnodes.is_empty() {
        for m in &mut bsp.models {
            m.head_nodes[3] = contents::EMPTY;
        }
    }

    bsp.textures.textures = input
        .wads
        .texture_lump(&texture_list, &textures.shown, input.warnings);
    bsp.texinfo = textures.out_infos;
    bsp.set_phong_faces(&face_lumps.phong);
    bsp.set_face_flags(&face_lumps.flags);
    bsp.set_surflight_groups(&face_lumps.surflight_groups);
    bsp.set_face_minlights(&face_lumps.minlights);
    bsp.set_face_channels(&face_lumps.channels);
    bsp.set_face_tones(&face_lumps.tones);
    let leaf_flags: Vec<LeafFlags> = leaf_contents
        .iter()
        .map(|c| LeafFlags {
            fence: c.contains(ContentFlags::WINDOW),
        })
        .collect();
    bsp.set_leaf_flags(&leaf_flags);
    bsp.planes = planes.planes;
    bsp.set_entity_text(&write_entities(input.entities));
    Emitted {
        bsp,
        portals,
        leaf_contents,
        tjunction_vertices,
    }
}

/// Writes a model's hull 0 nodes (their planes left as [`PlaneId`]s) and leaves.
struct TreeWriter<'a, 'b> {
    model: usize,
    drawing: &'a ModelDrawing<'a>,
    solid: &'a [bool],
    bsp: &'b mut Bsp,
    node_faces: &'b IntMap<(usize, u32), (u32, u32)>,
    leaf_faces: &'b IntMap<(usize, u32), Vec<u32>>,
    leaf_growth: &'b IntMap<(usize, u32), Bounds>,
    /// Tree leaf to BSP leaf.
    leaf_index: IntMap<u32, u32>,
    /// Each written leaf's extended content flags, in leaf order.
    leaf_contents: &'b mut Vec<ContentFlags>,
    /// Liquids are detail and translucent ([`DrawingInput::transwater`]).
    transwater: bool,
}

impl TreeWriter<'_, '_> {
    /// Write tree node `n`; returns its child value and bounds.
    ///
    /// As qbsp does, a leaf's bounds are those of its region (its portals, the outside box's
    /// included) and a node's those of its children, the shared solid leaf's regions below it
    /// included: a node's bounds hold its whole region, and the head node's the model's brushes
    /// grown by the outside box's margin. All are rounded outward to whole units.
    fn node(&mut self, n: u32) -> (i32, Bounds) {
        let tree = &self.drawing.tree;
        if self.solid[n as usize] {
            let region = tree
                .leaves_below(n)
                .into_iter()
                .fold(Bounds::EMPTY, |acc, l| {
                    acc.union(&self.drawing.portals.leaf_bounds(l))
                });
            return (-1, whole_units(region));
        }
        let node = &tree.nodes[n as usize];
        let Some(plane) = node.plane else {
            let bounds = self.drawing.portals.leaf_bounds(n);
            // A sliver leaf whose portals were all too small to keep: fall back to the model's box.
            let bounds = if bounds.is_empty() {
                self.drawing.bounds
            } else {
                bounds
            };
            let bounds = match self.leaf_growth.get(&(self.model, n)) {
                Some(grown) => bounds.union(grown),
                None => bounds,
            };
            let bounds = whole_units(bounds);
            let marks = self.leaf_faces.get(&(self.model, n));
            let first = self.bsp.marksurfaces.len() as u32;
            self.bsp.marksurfaces.extend(marks.into_iter().flatten());
            let index = self.bsp.leafs.len() as u32;
            self.leaf_contents.push(ContentFlags::of_leaf(
                node.contents,
                &node.brushes,
                self.transwater,
            ));
            self.bsp.leafs.push(Leaf {
                contents: engine_contents(node.contents),
                vis_offset: -1,
                mins: bounds.mins.as_vec3().to_array(),
                maxs: bounds.maxs.as_vec3().to_array(),
                first_marksurface: first,
                num_marksurfaces: self.bsp.marksurfaces.len() as u32 - first,
                ambient: [0; 4],
            });
            self.leaf_index.insert(n, index);
            return (-(index as i32) - 1, bounds);
        };
        let index = self.bsp.nodes.len();
        let (first_face, num_faces) = self
            .node_faces
            .get(&(self.model, n))
            .copied()
            .unwrap_or((0, 0));
        self.bsp.nodes.push(Node {
            plane,
            children: [0, 0],
            mins: [0.0; 3],
            maxs: [0.0; 3],
            first_face,
            num_faces,
        });
        let (front, fb) = self.node(node.children[0]);
        let (back, bb) = self.node(node.children[1]);
        let bounds = fb.union(&bb);
        let out = &mut self.bsp.nodes[index];
        out.children = [front, back];
        out.mins = bounds.mins.as_vec3().to_array();
        out.maxs = bounds.maxs.as_vec3().to_array();
        (index as i32, bounds)
    }
}

/// The world's portal file: PRT1 between see-through leaves, numbered from BSP leaf 1; or, when
/// the world has detail, PRT2 between its clusters (structural leaves). Without `transwater`
/// vis does not look across a liquid's surface (see [`vis_class`]).
fn world_portal_file(
    world: &ModelDrawing,
    leaf_index: &IntMap<u32, u32>,
    vis_leafs: i32,
    transwater: bool,
) -> PortalFile {
    let tree = &world.tree.nodes;
    let num_leafs = vis_leafs.max(0) as u32;
    let across = |a: i32, b: i32| transwater || vis_class(a) == vis_class(b);
    let Some(cluster_portals) = world.cluster_portals else {
        let mut portals = Vec::new();
        for p in &world.portals.portals {
            let (Some(&a), Some(&b)) = (leaf_index.get(&p.nodes[0]), leaf_index.get(&p.nodes[1]))
            else {
                continue;
            };
            let [ca, cb] = p.nodes.map(|n| tree[n as usize].contents);
            if is_see_through(ca) && is_see_through(cb) && across(ca, cb) {
                portals.push(PrtPortal {
                    leafs: [a - 1, b - 1],
                    winding: p.winding.clone(),
                });
            }
        }
        return PortalFile {
            num_leafs,
            portals,
            clusters: None,
        };
    };
    // Clusters in tree order, each with the vis leaves below it; a cluster is open to sight when
    // one of its leaves is.
    let mut clusters = Vec::new();
    let mut cluster_of: IntMap<u32, (u32, bool, i32)> = IntMap::default();
    let mut stack = vec![0u32];
    while let Some(n) = stack.pop() {
        let node = &tree[n as usize];
        if node.cluster.is_none() {
            if !node.is_leaf() {
                stack.push(node.children[1]);
                stack.push(node.children[0]);
            }
            continue;
        }
        let leaves = world.tree.leaves_below(n);
        let vis: Vec<u32> = leaves
            .iter()
            .filter_map(|l| leaf_index.get(l).map(|&i| i - 1))
            .collect();
        if vis.is_empty() {
            continue;
        }
        let open = leaves
            .iter()
            .any(|&l| is_see_through(tree[l as usize].contents));
        let structural = node.cluster.unwrap_or(node.contents);
        cluster_of.insert(n, (clusters.len() as u32, open, structural));
        clusters.push(vis);
    }
    let mut portals = Vec::new();
    for p in &cluster_portals.portals {
        if let (Some(&(a, true, ca)), Some(&(b, true, cb))) =
            (cluster_of.get(&p.nodes[0]), cluster_of.get(&p.nodes[1]))
            && across(ca, cb)
        {
            portals.push(PrtPortal {
                leafs: [a, b],
                winding: p.winding.clone(),
            });
        }
    }
    PortalFile {
        num_leafs,
        portals,
        clusters: Some(clusters),
    }
}
