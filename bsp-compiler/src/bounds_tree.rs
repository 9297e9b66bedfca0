//! A bounding-volume tree over boxes: which of them overlap a given box, at a cost that grows
//! with the boxes found rather than with all of them. CSG asks it for each brush's neighbours;
//! a sweep along one axis would also visit every brush that only shares that axis's span (a
//! column of brushes, a long wall along it).

use quake_formats::geom::Bounds;

/// Leaves hold at most this many boxes.
const LEAF_SIZE: usize = 4;

/// A node: the boxes `items[start..start + count]` below it, and for an inner node the index
/// of its second child (its first follows it).
#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Bounds,
    start: u32,
    count: u32,
    second: u32,
    leaf: bool,
}

/// The boxes it was built from, numbered by their place in that list.
#[derive(Debug, Clone)]
pub struct BoundsTree {
    boxes: Vec<Bounds>,
    nodes: Vec<Node>,
    items: Vec<u32>,
}

impl BoundsTree {
    pub fn new(boxes: Vec<Bounds>) -> BoundsTree {
        let mut tree = BoundsTree {
            items: (0..boxes.len() as u32).collect(),
            boxes,
            nodes: Vec::new(),
        };
        if !tree.boxes.is_empty() {
            tree.build(0, tree.items.len());
        }
        tree
    }

    /// Add the node of `items[start..end]` and the nodes below it; returns its index.
    fn build(&mut self, start: usize, end: usize) -> u32 {
        let items = &mut self.items[start..end];
        let boxes = &self.boxes;
        let bounds = items
            .iter()
            .fold(Bounds::EMPTY, |acc, &i| acc.union(&boxes[i as usize]));
        let index = self.nodes.len() as u32;
        let leaf = items.len() <= LEAF_SIZE;
        self.nodes.push(Node {
            bounds,
            start: start as u32,
            count: (end - start) as u32,
            second: 0,
            leaf,
        });
        if leaf {
            return index;
        }
        // Halve at the median centre along the axis the centres spread most on.
        let centres = items.iter().fold(Bounds::EMPTY, |mut acc, &i| {
            acc.add_point(boxes[i as usize].center());
            acc
        });
        let spread = centres.maxs - centres.mins;
        let axis = (0..3)
            .max_by(|&a, &b| spread[a].total_cmp(&spread[b]))
            .unwrap_or(0);
        let middle = items.len() / 2;
        items.select_nth_unstable_by(middle, |&a, &b| {
            boxes[a as usize].center()[axis]
                .total_cmp(&boxes[b as usize].center()[axis])
                .then(a.cmp(&b))
        });
        self.build(start, start + middle);
        let second = self.build(start + middle, end);
        self.nodes[index as usize].second = second;
        index
    }

    /// Push onto `out` every box that overlaps or touches `query` (in no particular order).
    pub fn overlapping(&self, query: &Bounds, out: &mut Vec<usize>) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !node.bounds.intersects(query) {
                continue;
            }
            if node.leaf {
                let items = &self.items[node.start as usize..(node.start + node.count) as usize];
                out.extend(
                    items
                        .iter()
                        .map(|&i| i as usize)
                        .filter(|&i| self.boxes[i].intersects(query)),
                );
            } else {
                stack.push(node.second);
                stack.push(n + 1);
            }
        }
    }

    /// The boxes the tree was built from.
    pub fn boxes(&self) -> &[Bounds] {
        &self.boxes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    proptest::proptest! {
        /// The tree finds exactly the boxes a comparison with every box finds.
        #[test]
        fn finds_what_comparing_every_box_finds(
            boxes in proptest::collection::vec(
                ((-50i32..50, -50i32..50, -50i32..50), (0i32..30, 0i32..30, 0i32..30)),
                0..60,
            ),
            query in ((-60i32..60, -60i32..60, -60i32..60), (0i32..40, 0i32..40, 0i32..40)),
        ) {
            let to_bounds = |((x, y, z), (w, d, h)): ((i32, i32, i32), (i32, i32, i32))| {
                let lo = DVec3::new(x as f64, y as f64, z as f64);
                Bounds { mins: lo, maxs: lo + DVec3::new(w as f64, d as f64, h as f64) }
            };
            let boxes: Vec<Bounds> = boxes.into_iter().map(to_bounds).collect();
            let query = to_bounds(query);
            let tree = BoundsTree::new(boxes.clone());
            let mut found = Vec::new();
            tree.overlapping(&query, &mut found);
            found.sort_unstable();
            let expected: Vec<usize> =
                (0..boxes.len()).filter(|&i| boxes[i].intersects(&query)).collect();
            proptest::prop_assert_eq!(found, expected);
        }
    }
}
