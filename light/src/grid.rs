//! Coarse grids over a face's grid of samples or luxels, and the cells between their lines.
//!
//! Work that changes slowly across a face is done at a coarse grid of positions and
//! interpolated between them: dirt occlusion ([`crate::dirt`]), the sun probes of the default
//! mode and the receivers of bounced light ([`crate::bounce`]). A grid takes every `stride`-th
//! position along an axis and always the last one, so every position lies in a cell whose two
//! lines are on the grid; [`cell_of`] says which cell and how far across it.

/// Every `stride`th index below `size`, and the last.
pub fn grid(size: usize, stride: usize) -> Vec<usize> {
    let mut at: Vec<usize> = (0..size).step_by(stride.max(1)).collect();
    if size > 0 && at.last() != Some(&(size - 1)) {
        at.push(size - 1);
    }
    at
}

/// Where receivers go along an axis of `size` luxels: every `stride`th index and the last, but a
/// step to the last of at most half a stride widens the cell before it instead (a cell of at
/// most `stride + stride / 2`). On maps of small faces the extra row and column of [`grid`]
/// are a large share of all receivers; leaving them out costs accuracy at face edges, where
/// bounce changes fastest, so only the default mode does.
pub fn receiver_grid(size: usize, stride: usize) -> Vec<usize> {
    let mut at = grid(size, stride);
    let n = at.len();
    if n >= 3 && at[n - 1] - at[n - 2] <= stride / 2 {
        at.remove(n - 2);
    }
    at
}

/// For each index below the grid's last: the grid cell it lies in and how far across.
pub fn cell_of(at: &[usize]) -> Vec<(usize, usize, f32)> {
    let Some(&last) = at.last() else {
        return Vec::new();
    };
    let mut out = Vec::with_capacity(last + 1);
    for (j, pair) in at.windows(2).enumerate() {
        for x in pair[0]..pair[1] {
            out.push((j, j + 1, (x - pair[0]) as f32 / (pair[1] - pair[0]) as f32));
        }
    }
    let j = at.len() - 1;
    out.push((j, j, 0.0));
    out
}

/// A grid of points where dirt is measured or sunlight probed, over a face's
/// grid of samples (`gw × gh` positions): every `stride`-th position along
/// each axis, and the last row and column, so every position lies in a cell.
pub struct SampleGrid {
    pub xs: Vec<usize>,
    pub ys: Vec<usize>,
    /// Per position along each axis: the grid lines before and after it
    /// (indices into `xs` / `ys`) and how far across it lies.
    cx: Vec<(usize, usize, f32)>,
    cy: Vec<(usize, usize, f32)>,
}

impl SampleGrid {
    pub fn new(gw: usize, gh: usize, stride: usize) -> SampleGrid {
        let xs = grid(gw, stride);
        let ys = grid(gh, stride);
        SampleGrid {
            cx: cell_of(&xs),
            cy: cell_of(&ys),
            xs,
            ys,
        }
    }

    /// The four grid positions around position (gx, gy) (itself first when
    /// it is on the grid), and how far across their cell it lies.
    #[inline]
    pub fn cell(&self, gx: usize, gy: usize) -> ([(usize, usize); 4], f32, f32) {
        let (x0, x1, fx) = self.cx[gx];
        let (y0, y1, fy) = self.cy[gy];
        let (x0, x1, y0, y1) = (self.xs[x0], self.xs[x1], self.ys[y0], self.ys[y1]);
        ([(x0, y0), (x1, y0), (x0, y1), (x1, y1)], fx, fy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dirt_grid_cells_reach_the_last_row_and_column() {
        // 6 × 3 positions, stride 2: lines at x 0, 2, 4, 5 and y 0, 2.
        let grid = SampleGrid::new(6, 3, 2);
        assert_eq!(
            grid.cell(0, 0),
            ([(0, 0), (2, 0), (0, 2), (2, 2)], 0.0, 0.0)
        );
        assert_eq!(
            grid.cell(3, 1),
            ([(2, 0), (4, 0), (2, 2), (4, 2)], 0.5, 0.5)
        );
        // Past the last full stride: the cell up to the last column, and the last column itself.
        assert_eq!(grid.cell(4, 1).0, [(4, 0), (5, 0), (4, 2), (5, 2)]);
        assert_eq!(
            grid.cell(5, 2),
            ([(5, 2), (5, 2), (5, 2), (5, 2)], 0.0, 0.0)
        );
    }

    #[test]
    fn receivers_widen_the_last_cell_rather_than_add_a_row() {
        assert_eq!(receiver_grid(2, 2), vec![0, 1]);
        assert_eq!(receiver_grid(3, 2), vec![0, 2]);
        assert_eq!(receiver_grid(4, 2), vec![0, 3]);
        assert_eq!(receiver_grid(6, 2), vec![0, 2, 5]);
        assert_eq!(receiver_grid(7, 2), vec![0, 2, 4, 6]);
        assert_eq!(receiver_grid(10, 4), vec![0, 4, 9]);
        assert_eq!(receiver_grid(11, 4), vec![0, 4, 10]);
        assert_eq!(receiver_grid(12, 4), vec![0, 4, 8, 11]);
        assert_eq!(receiver_grid(5, 1), vec![0, 1, 2, 3, 4]);
    }
}
