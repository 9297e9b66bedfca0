//! The states a portal flow has already walked on from, to skip paths that cannot see more.
//!
//! After passing a portal, everything the flow does next depends only on the state it reached:
//! the part of the base portal sight lines can still start from (`source`), the part of the
//! passed portal they can still go through (`pass`), and the bound of what might still be seen
//! (`might`). Clipping is monotone in the windings: a smaller source and a smaller pass let
//! fewer lines through, so they show no more. A second path reaching the same portal with
//! windings inside those of a path already walked on, and a bound inside that path's bound, can
//! see nothing that walk did not see (everything it skipped was already seen). In open areas,
//! where many leaf orders lead to the same portal unclipped, this cuts the walk from a number
//! of paths exponential in the depth down to a few per portal.

use crate::bitset::{WindowBits, WindowView};
use glam::DVec3;
use quake_formats::geom::DVec3Ext;
use quake_formats::geom::POINT_EPSILON;

/// At most this many states are kept per portal; later ones are walked without being kept.
const STATES_PER_PORTAL: usize = 4;

/// A state walked on from: its windings' places in [`Explored::points`] and its bound's window
/// (first word, and the words' place in [`Explored::words`]).
struct State {
    source: (usize, usize),
    pass: (usize, usize),
    might_lo: usize,
    might: (usize, usize),
}

/// The states walked on from, per portal, during one base portal's flow.
///
/// Their windings and bounds lie end to end in two buffers emptied at each flow's start, so
/// memory follows the largest single flow; a buffer per state, kept for reuse, would grow each
/// to the largest it ever held.
#[derive(Default)]
pub struct Explored {
    /// By portal: how many states are kept, and their places in `states`. Fixed slots rather
    /// than a list per portal: a flow touches most portals, and a list each would stay
    /// allocated.
    kept: Vec<(u8, [u32; STATES_PER_PORTAL])>,
    touched: Vec<u32>,
    states: Vec<State>,
    points: Vec<DVec3>,
    words: Vec<u64>,
}

/// The part `(start, end)` of `items`.
fn part<T>(items: &[T], (start, end): (usize, usize)) -> &[T] {
    &items[start..end]
}

/// Appends `new` to `items`; returns its part.
fn append<T: Copy>(items: &mut Vec<T>, new: &[T]) -> (usize, usize) {
    let start = items.len();
    items.extend_from_slice(new);
    (start, items.len())
}

impl Explored {
    /// Forget every state (the start of another base portal's flow over `portals` portals).
    pub fn reset(&mut self, portals: usize) {
        for &p in &self.touched {
            self.kept[p as usize].0 = 0;
        }
        self.touched.clear();
        self.states.clear();
        self.points.clear();
        self.words.clear();
        self.kept.resize(portals, (0, [0; STATES_PER_PORTAL]));
    }

    /// Whether a state already walked on from `portal` lets through everything this one does.
    /// `source_normal` and `pass_normal` are the normals of the windings' planes.
    pub fn covers(
        &self,
        portal: usize,
        source: &[DVec3],
        pass: &[DVec3],
        might: &WindowBits,
        source_normal: DVec3,
        pass_normal: DVec3,
    ) -> bool {
        let (count, slots) = &self.kept[portal];
        slots[..usize::from(*count)].iter().any(|&i| {
            let s = &self.states[i as usize];
            let bound = WindowView {
                lo: s.might_lo,
                words: part(&self.words, s.might),
            };
            convex_contains(part(&self.points, s.pass), pass, pass_normal)
                && convex_contains(part(&self.points, s.source), source, source_normal)
                && might.is_subset(bound)
        })
    }

    /// Remember a state about to be walked on from `portal`.
    pub fn record(&mut self, portal: usize, source: &[DVec3], pass: &[DVec3], might: &WindowBits) {
        let (count, slots) = &mut self.kept[portal];
        let n = usize::from(*count);
        if n >= STATES_PER_PORTAL {
            return;
        }
        if n == 0 {
            self.touched.push(portal as u32);
        }
        slots[n] = self.states.len() as u32;
        *count += 1;
        self.states.push(State {
            source: append(&mut self.points, source),
            pass: append(&mut self.points, pass),
            might_lo: might.view().lo,
            might: append(&mut self.words, might.view().words),
        });
    }
}

/// Whether the convex winding `inner` lies inside the convex winding `outer` (both in one plane
/// with normal `normal`), allowing [`POINT_EPSILON`].
pub fn convex_contains(outer: &[DVec3], inner: &[DVec3], normal: DVec3) -> bool {
    let n = outer.len();
    if n < 3 {
        return false;
    }
    let center = outer.iter().fold(DVec3::ZERO, |a, &v| a + v) / n as f64;
    (0..n).all(|i| {
        let a = outer[i];
        let Some(mut inward) = (outer[(i + 1) % n] - a).cross(normal).normalized() else {
            return true; // a repeated point: no edge
        };
        if inward.dot(center - a) < 0.0 {
            inward = -inward;
        }
        inner.iter().all(|&v| inward.dot(v - a) >= -POINT_EPSILON)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bitset::BitSet;

    fn square(size: f64, offset: f64) -> Vec<DVec3> {
        [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(offset + x * size, offset + y * size, 5.0))
            .collect()
    }

    #[test]
    fn containment_of_squares() {
        let up = DVec3::new(0.0, 0.0, 1.0);
        assert!(convex_contains(&square(64.0, 0.0), &square(32.0, 16.0), up));
        assert!(convex_contains(&square(64.0, 0.0), &square(64.0, 0.0), up));
        assert!(!convex_contains(
            &square(32.0, 16.0),
            &square(64.0, 0.0),
            up
        ));
        assert!(!convex_contains(&square(64.0, 0.0), &square(64.0, 1.0), up));
        // Either winding order.
        let mut reversed = square(64.0, 0.0);
        reversed.reverse();
        assert!(convex_contains(&reversed, &square(32.0, 16.0), up));
    }

    #[test]
    fn a_state_covers_smaller_ones_with_a_smaller_bound() {
        let up = DVec3::new(0.0, 0.0, 1.0);
        let mut explored = Explored::default();
        explored.reset(3);
        let might = |members: &[usize]| {
            let mut set = BitSet::new(100);
            for &i in members {
                set.insert(i);
            }
            let mut bits = WindowBits::default();
            bits.assign_filtered(&set, |_| false);
            bits
        };
        explored.record(
            1,
            &square(64.0, 0.0),
            &square(64.0, 0.0),
            &might(&[2, 5, 90]),
        );
        let small = square(32.0, 8.0);
        assert!(explored.covers(1, &small, &small, &might(&[5]), up, up));
        assert!(explored.covers(1, &small, &small, &might(&[]), up, up));
        assert!(!explored.covers(2, &small, &small, &might(&[5]), up, up));
        assert!(!explored.covers(1, &small, &small, &might(&[5, 7]), up, up));
        assert!(!explored.covers(1, &small, &square(64.0, 1.0), &might(&[5]), up, up));
        explored.reset(3);
        assert!(!explored.covers(1, &small, &small, &might(&[]), up, up));
    }
}
