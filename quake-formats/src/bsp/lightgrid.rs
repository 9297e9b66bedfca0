//! `LIGHTGRID_OCTREE`: light sampled on a regular grid through a map's open space, for engines
//! to light models with (ericw-tools' `-lightgrid`; read by FTE, QuakeSpasm-Spiked and
//! Ironwail).
//!
//! Little-endian: the grid's spacing (3 `f32`), its point counts (3 `i32`), its first point
//! (3 `f32`), the most styles any point has (`u8`) and the root (`u32`); then a `u32` count of
//! nodes, each a division point (3 `i32`, in grid points) and eight children (`u32`); then a
//! `u32` count of leaves, each its first point and size (3 `i32` each) followed by its points in
//! z, y, x order. A point is a style count (`u8`; 255: inside solid, no light to use) and that
//! many `(style, r, g, b)` bytes. A child or the root is a node index, a leaf index with
//! [`CHILD_LEAF`] set, or [`CHILD_OCCLUDED`] for a box of points all inside solid; child
//! `4x + 2y + z` of a node holds the points at or past its division point on the axes whose bit
//! is set.

use super::Bsp;
use crate::bytes::{PutLe, Reader};
use crate::error::{FormatError, Result};

/// The lump's BSPX name.
pub const LIGHTGRID_OCTREE: &str = "LIGHTGRID_OCTREE";
/// A child with this bit is a leaf index.
pub const CHILD_LEAF: u32 = 1 << 31;
/// A child that is this value holds only points inside solid.
pub const CHILD_OCCLUDED: u32 = 1 << 30;
/// A point's style count that marks it inside solid.
const OCCLUDED_POINT: u8 = 255;
/// Deeper than this no tree of a grid that fits `i32` point counts goes; a deeper walk is a cycle.
const MAX_WALK_DEPTH: usize = 64;
/// Nodes are split no deeper than this, and no box narrower than [`MIN_NODE_POINTS`] on an axis.
const MAX_BUILD_DEPTH: usize = 5;
/// Boxes narrower than this on any axis become leaves.
const MIN_NODE_POINTS: i32 = 4;
/// Boxes with fewer occluded points than this become leaves: splitting saves too little.
const MIN_OCCLUDED_TO_SPLIT: usize = 8;

/// The light of one style at a grid point, in lightmap bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridSample {
    /// The light style.
    pub style: u8,
    /// Red, green, blue.
    pub rgb: [u8; 3],
}

/// A grid point: `None` inside solid, else its light per style (empty: dark).
pub type GridPoint = Option<Vec<GridSample>>;

/// An interior node of the octree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridNode {
    /// The first grid point of the upper children on each axis.
    pub division: [i32; 3],
    /// The eight children: child `4x + 2y + z`.
    pub children: [u32; 8],
}

/// A box of grid points stored whole.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GridLeaf {
    /// Its first grid point.
    pub mins: [i32; 3],
    /// Its points along each axis.
    pub size: [i32; 3],
    /// Its points, z then y then x.
    pub points: Vec<GridPoint>,
}

/// A whole `LIGHTGRID_OCTREE` lump.
#[derive(Debug, Clone, PartialEq)]
pub struct LightGrid {
    /// Map units between grid points along each axis.
    pub spacing: [f32; 3],
    /// Grid points along each axis.
    pub size: [i32; 3],
    /// World position of grid point (0, 0, 0).
    pub mins: [f32; 3],
    /// The most styles any point has.
    pub styles: u8,
    /// The root: a node, a leaf ([`CHILD_LEAF`]) or [`CHILD_OCCLUDED`].
    pub root: u32,
    /// Interior nodes.
    pub nodes: Vec<GridNode>,
    /// Leaves.
    pub leafs: Vec<GridLeaf>,
}

impl LightGrid {
    /// The octree of a dense grid: `points` holds every grid point, z then y then x, `size`
    /// along each axis. Boxes of points all inside solid become [`CHILD_OCCLUDED`]; others are
    /// split in half on each axis while they are large, deep enough in the tree and hold enough
    /// solid to be worth it, and stored whole otherwise.
    ///
    /// # Panics
    /// When `points` does not hold `size`'s product of points.
    pub fn build(spacing: [f32; 3], mins: [f32; 3], size: [i32; 3], points: &[GridPoint]) -> Self {
        let count: i64 = size.iter().map(|&s| i64::from(s.max(0))).product();
        assert_eq!(
            points.len() as i64,
            count,
            "a dense grid of {size:?} points"
        );
        let styles = points
            .iter()
            .flatten()
            .map(|p| p.len() as u8)
            .max()
            .unwrap_or(0);
        let mut grid = LightGrid {
            spacing,
            size,
            mins,
            styles,
            root: CHILD_OCCLUDED,
            nodes: Vec::new(),
            leafs: Vec::new(),
        };
        if count > 0 {
            grid.root = grid.build_box(points, [0; 3], size, 0);
        }
        grid
    }

    /// The child that stands for the box of `size` points from `mins`, `depth` levels down.
    fn build_box(
        &mut self,
        dense: &[GridPoint],
        mins: [i32; 3],
        size: [i32; 3],
        depth: usize,
    ) -> u32 {
        let at = |x: i32, y: i32, z: i32| {
            let [w, h, _] = self.size;
            &dense[((z * h + y) * w + x) as usize]
        };
        let in_box = || {
            (mins[2]..mins[2] + size[2]).flat_map(move |z| {
                (mins[1]..mins[1] + size[1])
                    .flat_map(move |y| (mins[0]..mins[0] + size[0]).map(move |x| (x, y, z)))
            })
        };
        let occluded = in_box().filter(|&(x, y, z)| at(x, y, z).is_none()).count();
        let total: i32 = size.iter().product();
        if occluded == total as usize {
            return CHILD_OCCLUDED;
        }
        let leaf = size.iter().any(|&s| s < MIN_NODE_POINTS)
            || depth == MAX_BUILD_DEPTH
            || occluded < MIN_OCCLUDED_TO_SPLIT;
        if leaf {
            let points = in_box().map(|(x, y, z)| at(x, y, z).clone()).collect();
            self.leafs.push(GridLeaf { mins, size, points });
            return CHILD_LEAF | (self.leafs.len() - 1) as u32;
        }
        let division: [i32; 3] = std::array::from_fn(|a| mins[a] + size[a] / 2);
        let children = std::array::from_fn(|child| {
            let (lo, len) = octant(child, mins, size, division);
            self.build_box(dense, lo, len, depth + 1)
        });
        self.nodes.push(GridNode { division, children });
        (self.nodes.len() - 1) as u32
    }

    /// World position of grid point `index`.
    pub fn point_position(&self, index: [i32; 3]) -> [f32; 3] {
        std::array::from_fn(|a| self.mins[a] + index[a] as f32 * self.spacing[a])
    }

    /// Grid point `index` as the octree stores it: `None` outside the grid (or past a damaged
    /// child), `Some(None)` inside solid, `Some(Some(styles))` lit.
    pub fn point(&self, index: [i32; 3]) -> Option<&GridPoint> {
        if (0..3).any(|a| index[a] < 0 || index[a] >= self.size[a]) {
            return None;
        }
        let mut child = self.root;
        for _ in 0..MAX_WALK_DEPTH {
            if child == CHILD_OCCLUDED {
                return Some(&None);
            }
            if child & CHILD_LEAF != 0 {
                let leaf = self.leafs.get((child & !CHILD_LEAF) as usize)?;
                let local: [i32; 3] = std::array::from_fn(|a| index[a] - leaf.mins[a]);
                if (0..3).any(|a| local[a] < 0 || local[a] >= leaf.size[a]) {
                    return None;
                }
                let [w, h, _] = leaf.size;
                return leaf
                    .points
                    .get(((local[2] * h + local[1]) * w + local[0]) as usize);
            }
            let node = self.nodes.get(child as usize)?;
            let upper = |a: usize| usize::from(index[a] >= node.division[a]);
            child = node.children[4 * upper(0) + 2 * upper(1) + upper(2)];
        }
        None
    }

    /// The lump's bytes.
    pub fn write(&self) -> Vec<u8> {
        let mut out = Vec::new();
        self.spacing.iter().for_each(|&v| out.put_f32(v));
        self.size.iter().for_each(|&v| out.put_i32(v));
        self.mins.iter().for_each(|&v| out.put_f32(v));
        out.put_u8(self.styles);
        out.put_u32(self.root);
        out.put_u32(self.nodes.len() as u32);
        for n in &self.nodes {
            n.division.iter().for_each(|&v| out.put_i32(v));
            n.children.iter().for_each(|&c| out.put_u32(c));
        }
        out.put_u32(self.leafs.len() as u32);
        for l in &self.leafs {
            l.mins.iter().chain(&l.size).for_each(|&v| out.put_i32(v));
            for p in &l.points {
                match p {
                    None => out.put_u8(OCCLUDED_POINT),
                    Some(samples) => {
                        out.put_u8(samples.len() as u8);
                        for s in samples {
                            out.put_u8(s.style);
                            out.extend_from_slice(&s.rgb);
                        }
                    }
                }
            }
        }
        out
    }

    /// Reads a lump. Counts and sizes are checked against the bytes there are before anything
    /// is allocated for them, and every child against the nodes and leaves there are.
    ///
    /// # Errors
    /// [`FormatError::Truncated`] or [`FormatError::BadLump`] for a damaged lump.
    pub fn read(data: &[u8]) -> Result<LightGrid> {
        let bad = |detail: String| FormatError::BadLump {
            lump: LIGHTGRID_OCTREE,
            detail,
        };
        let mut r = Reader::new(data, LIGHTGRID_OCTREE);
        let spacing = r.f32x3()?;
        let size = [r.i32()?, r.i32()?, r.i32()?];
        let mins = r.f32x3()?;
        let styles = r.u8()?;
        let root = r.u32()?;
        if spacing.iter().chain(&mins).any(|v| !v.is_finite()) || spacing.iter().any(|&v| v <= 0.0)
        {
            return Err(bad(format!(
                "spacing {spacing:?} or first point {mins:?} is not usable"
            )));
        }
        if size.iter().any(|&s| s < 0) {
            return Err(bad(format!("negative grid size {size:?}")));
        }
        const NODE_LEN: usize = 12 + 32;
        let node_count = r.u32()? as usize;
        if node_count > data.len() / NODE_LEN {
            return Err(bad(format!("{node_count} nodes do not fit the lump")));
        }
        let mut nodes = Vec::with_capacity(node_count);
        for _ in 0..node_count {
            let division = [r.i32()?, r.i32()?, r.i32()?];
            let mut children = [0u32; 8];
            for c in &mut children {
                *c = r.u32()?;
            }
            nodes.push(GridNode { division, children });
        }
        let leaf_count = r.u32()? as usize;
        if leaf_count > data.len() / 24 {
            return Err(bad(format!("{leaf_count} leaves do not fit the lump")));
        }
        let mut leafs = Vec::with_capacity(leaf_count);
        for i in 0..leaf_count {
            let lmins = [r.i32()?, r.i32()?, r.i32()?];
            let lsize = [r.i32()?, r.i32()?, r.i32()?];
            let inside = (0..3).all(|a| {
                lmins[a] >= 0
                    && lsize[a] > 0
                    && i64::from(lmins[a]) + i64::from(lsize[a]) <= i64::from(size[a])
            });
            if !inside {
                return Err(bad(format!(
                    "leaf {i} ({lsize:?} points from {lmins:?}) is not inside the {size:?} grid"
                )));
            }
            let count: i64 = lsize.iter().map(|&s| i64::from(s)).product();
            // Every point takes at least a byte.
            if count > r.remaining() as i64 {
                return Err(bad(format!(
                    "leaf {i}'s {count} points do not fit the lump"
                )));
            }
            let mut points = Vec::with_capacity(count as usize);
            for _ in 0..count {
                let n = r.u8()?;
                if n == OCCLUDED_POINT {
                    points.push(None);
                    continue;
                }
                let mut samples = Vec::with_capacity(usize::from(n));
                for _ in 0..n {
                    let style = r.u8()?;
                    samples.push(GridSample {
                        style,
                        rgb: r.array::<3>()?,
                    });
                }
                points.push(Some(samples));
            }
            leafs.push(GridLeaf {
                mins: lmins,
                size: lsize,
                points,
            });
        }
        let grid = LightGrid {
            spacing,
            size,
            mins,
            styles,
            root,
            nodes,
            leafs,
        };
        grid.check_children()?;
        Ok(grid)
    }

    /// Every child (and the root) names a node or leaf there is, and no walk from the root
    /// goes deeper than [`MAX_WALK_DEPTH`] (a cycle).
    fn check_children(&self) -> Result<()> {
        let bad = |detail: String| FormatError::BadLump {
            lump: LIGHTGRID_OCTREE,
            detail,
        };
        let valid = |c: u32| {
            c == CHILD_OCCLUDED
                || (c & CHILD_LEAF != 0 && ((c & !CHILD_LEAF) as usize) < self.leafs.len())
                || (c & (CHILD_LEAF | CHILD_OCCLUDED) == 0 && (c as usize) < self.nodes.len())
        };
        let mut stack = vec![(self.root, 0usize)];
        while let Some((child, depth)) = stack.pop() {
            if !valid(child) {
                return Err(bad(format!("child {child:#x} names no node or leaf")));
            }
            if depth > MAX_WALK_DEPTH {
                return Err(bad("the nodes form a cycle".to_string()));
            }
            if child & (CHILD_LEAF | CHILD_OCCLUDED) == 0 {
                let node = &self.nodes[child as usize];
                stack.extend(node.children.iter().map(|&c| (c, depth + 1)));
            }
        }
        Ok(())
    }
}

/// Child `child`'s box of the box of `size` points from `mins` divided at `division`.
fn octant(
    child: usize,
    mins: [i32; 3],
    size: [i32; 3],
    division: [i32; 3],
) -> ([i32; 3], [i32; 3]) {
    let mut lo = [0; 3];
    let mut len = [0; 3];
    for a in 0..3 {
        if child & (4 >> a) != 0 {
            lo[a] = division[a];
            len[a] = mins[a] + size[a] - division[a];
        } else {
            lo[a] = mins[a];
            len[a] = division[a] - mins[a];
        }
    }
    (lo, len)
}

impl Bsp {
    /// The `LIGHTGRID_OCTREE` lump, if the file has one.
    ///
    /// # Errors
    /// What [`LightGrid::read`] finds wrong with it.
    pub fn light_grid(&self) -> Result<Option<LightGrid>> {
        self.bspx_lump(LIGHTGRID_OCTREE)
            .map(LightGrid::read)
            .transpose()
    }

    /// Stores `grid` as the `LIGHTGRID_OCTREE` lump.
    pub fn set_light_grid(&mut self, grid: &LightGrid) {
        self.set_bspx_lump(LIGHTGRID_OCTREE, grid.write());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lit(level: u8) -> GridPoint {
        Some(vec![GridSample {
            style: 0,
            rgb: [level; 3],
        }])
    }

    /// A 10x9x8 grid: solid below z = 3, lit above with the point's x, two styles at one point.
    fn dense() -> (Vec<GridPoint>, [i32; 3]) {
        let size = [10, 9, 8];
        let mut points = Vec::new();
        for z in 0..size[2] {
            for _y in 0..size[1] {
                for x in 0..size[0] {
                    points.push(if z < 3 { None } else { lit(x as u8) });
                }
            }
        }
        let last = points.len() - 1;
        points[last] = Some(vec![
            GridSample {
                style: 0,
                rgb: [1, 2, 3],
            },
            GridSample {
                style: 32,
                rgb: [4, 5, 6],
            },
        ]);
        (points, size)
    }

    #[test]
    fn every_point_reads_back_through_the_octree_and_the_lump() {
        let (points, size) = dense();
        let grid = LightGrid::build([32.0; 3], [-64.0, 0.0, 16.0], size, &points);
        assert!(!grid.nodes.is_empty(), "a grid with solid below is split");
        assert_eq!(grid.styles, 2);
        let read = LightGrid::read(&grid.write()).expect("reads");
        assert_eq!(read, grid);
        for z in 0..size[2] {
            for y in 0..size[1] {
                for x in 0..size[0] {
                    let i = ((z * size[1] + y) * size[0] + x) as usize;
                    assert_eq!(read.point([x, y, z]), Some(&points[i]), "point {x} {y} {z}");
                }
            }
        }
        assert_eq!(read.point([10, 0, 0]), None);
        assert_eq!(read.point_position([1, 2, 3]), [-32.0, 64.0, 112.0]);
    }

    #[test]
    fn the_independent_qbsp_reader_agrees_with_the_lump() {
        let (points, size) = dense();
        let grid = LightGrid::build([32.0; 3], [0.0; 3], size, &points);
        let mut bsp = Bsp::default();
        bsp.set_light_grid(&grid);
        assert_eq!(bsp.light_grid().expect("reads"), Some(grid.clone()));
        let bytes = bsp.bspx_lump(LIGHTGRID_OCTREE).expect("lump");
        let ctx = qbsp::reader::BspParseContext {
            format: qbsp::BspFormat::BSP29,
        };
        let theirs: qbsp::data::bspx::LightGridOctree<qbsp::data::bspx::SolidLightGridSample> =
            qbsp::reader::BspByteReader::new(bytes, &ctx)
                .read()
                .expect("qbsp reads the lump");
        assert_eq!(theirs.size.to_array(), size.map(|s| s as u32));
        assert_eq!(theirs.root_idx, grid.root);
        assert_eq!(theirs.nodes.len(), grid.nodes.len());
        assert_eq!(theirs.leafs.len(), grid.leafs.len());
        for (t, ours) in theirs.leafs.iter().zip(&grid.leafs) {
            for (cell, point) in t.cells().iter().zip(&ours.points) {
                match (cell, point) {
                    (qbsp::data::bspx::LightGridCell::Occluded, None) => {}
                    (qbsp::data::bspx::LightGridCell::Filled(samples), Some(ours)) => {
                        let theirs: Vec<(u8, [u8; 3])> =
                            samples.iter().map(|s| (s.style.0, s.color)).collect();
                        let ours: Vec<(u8, [u8; 3])> =
                            ours.iter().map(|s| (s.style, s.rgb)).collect();
                        assert_eq!(theirs, ours);
                    }
                    other => panic!("cells differ: {other:?}"),
                }
            }
        }
    }

    #[test]
    fn damaged_lumps_are_errors_not_panics() {
        let (points, size) = dense();
        let bytes = LightGrid::build([32.0; 3], [0.0; 3], size, &points).write();
        for cut in [0, 10, 40, bytes.len() - 1] {
            assert!(LightGrid::read(&bytes[..cut]).is_err(), "cut at {cut}");
        }
        let mut bad_root = bytes.clone();
        bad_root[37..41].copy_from_slice(&999u32.to_le_bytes());
        assert!(LightGrid::read(&bad_root).is_err());
        let mut huge_leaf_count = bytes.clone();
        let nodes = u32::from_le_bytes(bytes[41..45].try_into().expect("4 bytes")) as usize;
        let at = 45 + nodes * 44;
        huge_leaf_count[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(LightGrid::read(&huge_leaf_count).is_err());
        let mut cycle = LightGrid::build([32.0; 3], [0.0; 3], size, &points);
        let root = cycle.root as usize;
        cycle.nodes[root].children[0] = cycle.root;
        assert!(LightGrid::read(&cycle.write()).is_err());
    }

    #[test]
    fn an_all_solid_grid_is_one_occluded_root() {
        let grid = LightGrid::build([16.0; 3], [0.0; 3], [2, 2, 2], &vec![None; 8]);
        assert_eq!(
            (grid.root, grid.nodes.len(), grid.leafs.len()),
            (CHILD_OCCLUDED, 0, 0)
        );
        assert_eq!(grid.point([1, 1, 1]), Some(&None));
    }
}
