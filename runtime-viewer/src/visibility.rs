//! Which surfaces might be seen, in front-to-back order: the camera's leaf and its PVS row,
//! nodes culled by the frustum, faces culled by facing, and a sort key per face from the order
//! of the BSP walk (smaller keys are nearer).

use glam::DVec3;
use quake_formats::PvsRow;
use quake_formats::bsp::contents;
use quake_formats::geom::ON_EPSILON;

use crate::camera::View;
use crate::world::World;

/// A surface to draw: a world face, or a brush model fragment (`leaf`, index in that leaf).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidate {
    pub face: u32,
    pub key: u32,
    pub fragment: Option<(u32, u32)>,
    /// Bit i set: the polygon may cross frustum plane i and must be clipped against it.
    pub clip_flags: u8,
}

/// What the visibility pass let through in one frame.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct VisStats {
    /// The leaf the eye is in (0, the solid leaf, when it is outside the map).
    pub camera_leaf: usize,
    /// Leaves the PVS row (or its absence) lets through.
    pub pvs_leaves: usize,
    /// Leaves reached by the walk after frustum culling.
    pub drawn_leaves: usize,
    /// Nodes and leaves whose boxes lie wholly outside the frustum.
    pub frustum_culled: usize,
    /// Faces and brush model pieces skipped for facing away from the eye.
    pub backfaces: usize,
    /// Surfaces handed on to be drawn.
    pub candidates: usize,
}

/// Frame-stamped marks, kept between frames so nothing is cleared per frame.
#[derive(Debug, Clone)]
pub struct Visibility {
    frame: u32,
    leaf_mark: Vec<u32>,
    node_mark: Vec<u32>,
    face_mark: Vec<u32>,
    /// The walk's pending steps, kept to reuse the allocation.
    stack: Vec<Step>,
}

/// Pending work of the front-to-back walk.
#[derive(Debug, Clone, Copy)]
enum Step {
    Visit {
        child: i32,
        clip_flags: u8,
    },
    /// A node's own faces, once its near side is done; `facing_side` is `None` when the eye
    /// lies (nearly) on its plane and every face there is edge-on.
    NodeFaces {
        node: u32,
        facing_side: Option<u32>,
        clip_flags: u8,
    },
}

struct Walk<'a> {
    world: &'a World,
    view: &'a View,
    out: &'a mut Vec<Candidate>,
    stats: VisStats,
    key: u32,
}

impl Visibility {
    pub fn new(world: &World) -> Visibility {
        Visibility {
            frame: 0,
            leaf_mark: vec![0; world.bsp.leafs.len()],
            node_mark: vec![0; world.bsp.nodes.len()],
            face_mark: vec![0; world.bsp.faces.len()],
            stack: Vec::new(),
        }
    }

    /// Fill `out` with this view's candidates in front-to-back order.
    pub fn collect(&mut self, world: &World, view: &View, out: &mut Vec<Candidate>) -> VisStats {
        out.clear();
        self.frame = self.frame.wrapping_add(1).max(1);
        let o = view.origin;
        let camera_leaf = world.bsp.leaf_at(o.as_vec3().to_array()).unwrap_or(0);
        let pvs_leaves = self.mark_leaves(world, camera_leaf);
        let mut walk = Walk {
            world,
            view,
            out,
            stats: VisStats {
                camera_leaf,
                pvs_leaves,
                ..VisStats::default()
            },
            key: 0,
        };
        if let Some(root) = world.root() {
            self.walk(&mut walk, root);
        }
        walk.stats.candidates = walk.out.len();
        walk.stats
    }

    /// Mark the leaves in the camera leaf's PVS row and every node above them.
    fn mark_leaves(&mut self, world: &World, camera_leaf: usize) -> usize {
        let bsp = &world.bsp;
        // Outside the map, no vis data or a damaged offset: everything is visible, as in engines.
        let row = match bsp.pvs_row(camera_leaf) {
            Ok(PvsRow::Row { bits, .. }) => Some(bits),
            _ => None,
        };
        let mut count = 0;
        for leaf in 1..bsp.leafs.len() {
            let bit = leaf - 1;
            let visible = match &row {
                Some(row) => row.get(bit / 8).is_some_and(|b| b & (1 << (bit % 8)) != 0),
                None => true,
            };
            if !visible && leaf != camera_leaf {
                continue;
            }
            count += 1;
            self.leaf_mark[leaf] = self.frame;
            let mut node = world.leaf_parent[leaf];
            while node >= 0 && self.node_mark[node as usize] != self.frame {
                self.node_mark[node as usize] = self.frame;
                node = world.node_parent[node as usize];
            }
        }
        count
    }

    /// Walk the tree from `root` front to back: the near side of each node, then its faces
    /// that look towards the eye (all with one key), then the far side. An explicit stack keeps
    /// a degenerate, very deep tree from overflowing the thread's stack.
    fn walk(&mut self, w: &mut Walk, root: i32) {
        let mut stack = std::mem::take(&mut self.stack);
        stack.clear();
        stack.push(Step::Visit {
            child: root,
            clip_flags: 0b1111,
        });
        while let Some(step) = stack.pop() {
            match step {
                Step::Visit { child, clip_flags } => {
                    self.visit(w, child, clip_flags, &mut stack);
                }
                Step::NodeFaces {
                    node,
                    facing_side,
                    clip_flags,
                } => {
                    if let Some(side) = facing_side {
                        self.node_faces(w, node as usize, side, clip_flags);
                    }
                    w.key += 1;
                }
            }
        }
        self.stack = stack;
    }

    /// Cull `child` by the PVS marks and the frustum; a leaf is collected now, a node queues its
    /// near side, its faces and its far side.
    fn visit(&mut self, w: &mut Walk, child: i32, mut clip_flags: u8, stack: &mut Vec<Step>) {
        let bsp = &w.world.bsp;
        let (mins, maxs) = if child < 0 {
            let leaf = (-(child + 1)) as usize;
            match bsp.leafs.get(leaf) {
                Some(l) if self.leaf_mark[leaf] == self.frame && l.contents != contents::SOLID => {
                    (l.mins, l.maxs)
                }
                _ => return,
            }
        } else {
            match bsp.nodes.get(child as usize) {
                Some(n) if self.node_mark[child as usize] == self.frame => (n.mins, n.maxs),
                _ => return,
            }
        };
        for (i, plane) in w.view.frustum.iter().enumerate() {
            if clip_flags & (1 << i) == 0 {
                continue;
            }
            // The box corners furthest along and against the plane's normal.
            let corner = |toward: bool| {
                DVec3::new(
                    pick((plane.normal.x >= 0.0) == toward, mins[0], maxs[0]),
                    pick((plane.normal.y >= 0.0) == toward, mins[1], maxs[1]),
                    pick((plane.normal.z >= 0.0) == toward, mins[2], maxs[2]),
                )
            };
            if plane.distance(corner(true)) < 0.0 {
                w.stats.frustum_culled += 1;
                return;
            }
            if plane.distance(corner(false)) >= 0.0 {
                clip_flags &= !(1 << i);
            }
        }
        if child < 0 {
            self.visit_leaf(w, (-(child + 1)) as usize, clip_flags);
            return;
        }
        let node = &bsp.nodes[child as usize];
        let Some(plane) = w.world.node_plane(child as usize) else {
            return;
        };
        let d = plane.distance(w.view.origin);
        let near = usize::from(d < 0.0);
        // Pushed in reverse: near side first, then this node's faces, then the far side.
        stack.push(Step::Visit {
            child: node.children[1 - near],
            clip_flags,
        });
        stack.push(Step::NodeFaces {
            node: child as u32,
            facing_side: (d.abs() > ON_EPSILON).then_some(near as u32),
            clip_flags,
        });
        stack.push(Step::Visit {
            child: node.children[near],
            clip_flags,
        });
    }

    /// The node's faces seen in the PVS that look towards the eye's side.
    fn node_faces(&mut self, w: &mut Walk, node: usize, facing_side: u32, clip_flags: u8) {
        let bsp = &w.world.bsp;
        let node = &bsp.nodes[node];
        let first = node.first_face as usize;
        for f in first..first + node.num_faces as usize {
            let Some(face) = bsp.faces.get(f) else { break };
            if self.face_mark.get(f) != Some(&self.frame) {
                continue;
            }
            if face.side != facing_side {
                w.stats.backfaces += 1;
                continue;
            }
            w.out.push(Candidate {
                face: f as u32,
                key: w.key,
                fragment: None,
                clip_flags,
            });
        }
    }

    fn visit_leaf(&mut self, w: &mut Walk, leaf: usize, clip_flags: u8) {
        w.stats.drawn_leaves += 1;
        let bsp = &w.world.bsp;
        let l = &bsp.leafs[leaf];
        let first = l.first_marksurface as usize;
        let marks = bsp
            .marksurfaces
            .get(first..first + l.num_marksurfaces as usize)
            .unwrap_or_default();
        for &f in marks {
            if let Some(m) = self.face_mark.get_mut(f as usize) {
                *m = self.frame;
            }
        }
        // Brush model pieces in this leaf sort together; their order within it is by depth.
        for (i, frag) in w.world.leaf_fragments[leaf].iter().enumerate() {
            let Some(s) = &w.world.surfaces[frag.face as usize] else {
                continue;
            };
            if s.plane.distance(w.view.origin) <= ON_EPSILON {
                w.stats.backfaces += 1;
                continue;
            }
            w.out.push(Candidate {
                face: frag.face,
                key: w.key,
                fragment: Some((leaf as u32, i as u32)),
                clip_flags,
            });
        }
        w.key += 1;
    }
}

fn pick(first: bool, a: f32, b: f32) -> f64 {
    if first { b as f64 } else { a as f64 }
}
