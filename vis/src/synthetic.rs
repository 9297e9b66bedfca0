//! Synthetic worlds with known visibility, for tests and benchmarks: a grid of cubic cells, each
//! solid or open. Every open cell is one leaf; neighbouring open cells share a square portal.
//! The same world also builds as a tiny BSP (an axis-aligned hull 0 tree), so sight lines can be
//! traced through it.

use glam::DVec3;
use quake_formats::Bsp;
use quake_formats::bsp::{BspPlane, Leaf, Model, Node, contents};
use quake_formats::geom::Winding;
use quake_formats::prt::{PortalFile, PrtPortal};
use quake_formats::rng::SplitMix64;

/// A box of `size` cells of `cell` units; outside the box is solid.
#[derive(Debug, Clone)]
pub struct VoxelWorld {
    size: [usize; 3],
    cell: f64,
    open: Vec<bool>,
}

impl VoxelWorld {
    /// All solid.
    pub fn new(size: [usize; 3], cell: f64) -> VoxelWorld {
        VoxelWorld {
            size,
            cell,
            open: vec![false; size[0] * size[1] * size[2]],
        }
    }

    /// Corridors and rooms carved by random walks from the middle; `cells` open cells at most.
    pub fn random_caves(size: [usize; 3], cells: usize, seed: u64) -> VoxelWorld {
        let mut world = VoxelWorld::new(size, 64.0);
        let mut rng = SplitMix64::new(seed);
        let mut at = size.map(|s| s / 2);
        let mut opened = 0;
        while opened < cells.min(size.iter().product()) {
            if !world.is_open(at) {
                world.set_open(at);
                opened += 1;
            }
            // Straight runs make corridors that see far; turns hide what lies behind them.
            let axis = rng.below(3);
            let up = rng.below(2) == 1;
            for _ in 0..1 + rng.below(4) {
                let next = at[axis] as i64 + if up { 1 } else { -1 };
                if next < 0 || next >= size[axis] as i64 {
                    break;
                }
                at[axis] = next as usize;
                if !world.is_open(at) {
                    world.set_open(at);
                    opened += 1;
                }
            }
        }
        world
    }

    /// Open every cell of the box `lo..=hi`.
    pub fn open_box(&mut self, lo: [usize; 3], hi: [usize; 3]) -> &mut Self {
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    self.set_open([x, y, z]);
                }
            }
        }
        self
    }

    fn set_open(&mut self, c: [usize; 3]) {
        let i = self.index(c);
        self.open[i] = true;
    }

    fn is_open(&self, c: [usize; 3]) -> bool {
        self.open[self.index(c)]
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.size[1] + c[1]) * self.size[0] + c[0]
    }

    fn cells(&self) -> impl Iterator<Item = [usize; 3]> + '_ {
        let [sx, sy, sz] = self.size;
        (0..sz).flat_map(move |z| (0..sy).flat_map(move |y| (0..sx).map(move |x| [x, y, z])))
    }

    /// The vis leaf (0-based, = BSP leaf - 1) of every open cell, in cell order.
    pub fn leaf_of(&self, c: [usize; 3]) -> Option<usize> {
        if !self.is_open(c) {
            return None;
        }
        Some(
            self.cells()
                .take_while(|&o| o != c)
                .filter(|&o| self.is_open(o))
                .count(),
        )
    }

    fn open_cells(&self) -> Vec<[usize; 3]> {
        self.cells().filter(|&c| self.is_open(c)).collect()
    }

    /// The vis leaf of each cell index (`u32::MAX` for solid cells).
    fn leaf_numbers(&self) -> Vec<u32> {
        let mut leaf = vec![u32::MAX; self.open.len()];
        for (i, c) in self.open_cells().into_iter().enumerate() {
            leaf[self.index(c)] = i as u32;
        }
        leaf
    }

    fn corner(&self, c: [usize; 3]) -> DVec3 {
        DVec3::new(
            c[0] as f64 * self.cell,
            c[1] as f64 * self.cell,
            c[2] as f64 * self.cell,
        )
    }

    /// PRT1 portals between neighbouring open cells, oriented as compilers write them.
    pub fn portal_file(&self) -> PortalFile {
        let cells = self.open_cells();
        let leaf = self.leaf_numbers();
        let mut portals = Vec::new();
        for &c in &cells {
            for axis in 0..3 {
                let mut n = c;
                n[axis] += 1;
                if n[axis] >= self.size[axis] || !self.is_open(n) {
                    continue;
                }
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let origin = self.corner(n);
                let mut du = DVec3::ZERO;
                du[u] = self.cell;
                let mut dv = DVec3::ZERO;
                dv[v] = self.cell;
                let mut winding =
                    Winding::new(vec![origin, origin + du, origin + du + dv, origin + dv]);
                // The winding's plane faces the first leaf, the lower cell.
                if winding.plane().is_some_and(|p| p.normal[axis] > 0.0) {
                    winding = winding.reversed();
                }
                portals.push(PrtPortal {
                    leafs: [leaf[self.index(c)], leaf[self.index(n)]],
                    winding,
                });
            }
        }
        PortalFile {
            num_leafs: cells.len() as u32,
            portals,
            clusters: None,
        }
    }

    /// PRT2 portals with open cells grouped in pairs along x (cells `2k` and `2k + 1` of a row
    /// when both are open; otherwise a cell is a cluster alone). Portals inside a pair are left
    /// out; the others join clusters.
    pub fn paired_portal_file(&self) -> PortalFile {
        let cells = self.open_cells();
        let mut cluster_of = Vec::with_capacity(cells.len());
        let mut clusters: Vec<Vec<u32>> = Vec::new();
        for (leaf, &c) in cells.iter().enumerate() {
            let mut partner = c;
            partner[0] ^= 1;
            let paired = partner[0] < self.size[0] && self.is_open(partner);
            if paired && partner[0] < c[0] {
                // The second of a pair joins the first one's cluster.
                let cluster = cluster_of[leaf - 1];
                clusters[cluster as usize].push(leaf as u32);
                cluster_of.push(cluster);
            } else {
                cluster_of.push(clusters.len() as u32);
                clusters.push(vec![leaf as u32]);
            }
        }
        let leafs = self.portal_file();
        let portals = leafs
            .portals
            .into_iter()
            .filter_map(|p| {
                let ends = p.leafs.map(|l| cluster_of[l as usize]);
                (ends[0] != ends[1]).then_some(PrtPortal {
                    leafs: ends,
                    winding: p.winding,
                })
            })
            .collect();
        PortalFile {
            num_leafs: leafs.num_leafs,
            portals,
            clusters: Some(clusters),
        }
    }

    /// A BSP with an axis-aligned hull 0 tree: open cells are leaves 1..=N (empty), everything
    /// else is the solid leaf 0. No faces; enough for vis lumps and tracing.
    pub fn bsp(&self) -> Bsp {
        let mut bsp = Bsp::default();
        bsp.leafs.push(Leaf::SHARED_SOLID);
        for c in self.open_cells() {
            let lo = self.corner(c).as_vec3().to_array();
            let hi = self.corner(c.map(|x| x + 1)).as_vec3().to_array();
            bsp.leafs.push(Leaf {
                contents: contents::EMPTY,
                vis_offset: -1,
                mins: lo,
                maxs: hi,
                first_marksurface: 0,
                num_marksurfaces: 0,
                ambient: [0; 4],
            });
        }
        let head = self.build_tree(&mut bsp, &self.leaf_numbers(), [0; 3], self.size);
        let hi = self.corner(self.size).as_vec3().to_array();
        bsp.models.push(Model {
            mins: [0.0; 3],
            maxs: hi,
            origin: [0.0; 3],
            head_nodes: [head, 0, 0, 0],
            vis_leafs: (bsp.leafs.len() - 1) as i32,
            first_face: 0,
            num_faces: 0,
        });
        bsp
    }

    /// The subtree over cells `lo..hi`: a node index, or `-(leaf + 1)`.
    fn build_tree(&self, bsp: &mut Bsp, leafs: &[u32], lo: [usize; 3], hi: [usize; 3]) -> i32 {
        let any_open = (lo[0]..hi[0])
            .any(|x| (lo[1]..hi[1]).any(|y| (lo[2]..hi[2]).any(|z| self.is_open([x, y, z]))));
        if !any_open {
            return -1;
        }
        let axis = (0..3).max_by_key(|&a| hi[a] - lo[a]).unwrap_or(0);
        if hi[axis] - lo[axis] == 1 {
            // Vis leaf i is BSP leaf i + 1, named by the child value -(i + 1) - 1.
            return -(leafs[self.index(lo)] as i32 + 2);
        }
        let mid = (lo[axis] + hi[axis]) / 2;
        let node = bsp.nodes.len();
        let mut normal = [0.0f32; 3];
        normal[axis] = 1.0;
        bsp.planes.push(BspPlane {
            normal,
            dist: (mid as f64 * self.cell) as f32,
            kind: axis as i32,
        });
        bsp.nodes.push(Node {
            plane: (bsp.planes.len() - 1) as u32,
            children: [0, 0],
            mins: self.corner(lo).as_vec3().to_array(),
            maxs: self.corner(hi).as_vec3().to_array(),
            first_face: 0,
            num_faces: 0,
        });
        let (mut front_lo, mut back_hi) = (lo, hi);
        front_lo[axis] = mid;
        back_hi[axis] = mid;
        let front = self.build_tree(bsp, leafs, front_lo, hi);
        let back = self.build_tree(bsp, leafs, lo, back_hi);
        bsp.nodes[node].children = [front, back];
        node as i32
    }
}
