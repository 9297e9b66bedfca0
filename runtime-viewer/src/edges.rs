//! Hidden-surface removal with a global edge list and sorted spans (Abrash's design for Quake).
//!
//! Every visible polygon is clipped to the frustum, projected, and turned into edges. Scanline by
//! scanline the active edges are walked left to right; a leading edge brings its surface onto a
//! stack kept in front-to-back order (BSP key first, then 1/z at that pixel), a trailing edge
//! takes it off, and whenever the top of the stack changes a span is emitted for the surface that
//! was on top. Every pixel therefore belongs to exactly one span and is drawn once; pixels that no
//! surface covers belong to the background surface (index 0).
//!
//! Edges cover the scanlines whose centres (y + 0.5) lie in [top, bottom); a span starts at the
//! first pixel whose centre is at or right of its edge. Two polygons sharing an edge compute it
//! from the same projected endpoints in the same direction, so they meet without gaps or overlap.

use glam::DVec3;
use quake_formats::geom::Winding;

use crate::camera::{ScreenLinear, View};

/// Index of the background surface, under everything.
pub const BACKGROUND: u32 = 0;

/// A polygon's surface as the span generator sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpanSurface {
    /// The BSP face drawn, or `u32::MAX` for the background.
    pub face: u32,
    pub key: u32,
    pub inverse_depth: ScreenLinear,
}

/// Pixels [x0, x1) of row y.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Span {
    pub y: u32,
    pub x0: u32,
    pub x1: u32,
}

#[derive(Debug, Clone, Copy)]
struct Edge {
    /// x where the edge crosses the current scanline's centre.
    x: f64,
    dxdy: f64,
    y_first: i32,
    y_last: i32,
    surface: u32,
    leading: bool,
}

/// What the edge list did in one frame.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct EdgeStats {
    /// Polygons handed to the edge list.
    pub polygons: usize,
    /// Polygons that clipping to the frustum, or projecting to no area, left nothing of.
    pub clipped_away: usize,
    /// Edges that cross at least one scanline centre.
    pub edges: usize,
    /// Spans emitted, the background's included.
    pub spans: usize,
}

/// The per-frame edge and span buffers, reused between frames.
#[derive(Debug, Default)]
pub struct EdgeList {
    pub surfaces: Vec<SpanSurface>,
    edges: Vec<Edge>,
    /// Spans of surface i are `spans[span_start[i]..span_start[i + 1]]`.
    pub spans: Vec<Span>,
    pub span_start: Vec<u32>,
    raw_spans: Vec<(u32, Span)>,
    screen: Vec<(f64, f64)>,
    pub stats: EdgeStats,
}

impl EdgeList {
    pub fn begin(&mut self) {
        self.surfaces.clear();
        self.surfaces.push(SpanSurface {
            face: u32::MAX,
            key: u32::MAX,
            inverse_depth: ScreenLinear::default(),
        });
        self.edges.clear();
        self.stats = EdgeStats::default();
    }

    /// Clip `points` (a convex polygon facing the eye) to the frustum planes named by
    /// `clip_flags` and the near plane, and add its edges. Returns false when nothing is left.
    pub fn add_polygon(
        &mut self,
        view: &View,
        points: &[DVec3],
        clip_flags: u8,
        surface: SpanSurface,
    ) -> bool {
        self.stats.polygons += 1;
        let mut clipped: Option<Winding> = None;
        let planes = view
            .frustum
            .iter()
            .enumerate()
            .filter(|(i, _)| clip_flags & (1 << i) != 0)
            .map(|(_, p)| p)
            .chain(std::iter::once(&view.near));
        for plane in planes {
            let current = clipped.as_ref().map_or(points, |w| &w.points);
            if current.iter().all(|&p| plane.distance(p) >= 0.0) {
                continue;
            }
            match Winding::new(current.to_vec()).clip_front(plane, false) {
                Some(w) if w.points.len() >= 3 => clipped = Some(w),
                _ => {
                    self.stats.clipped_away += 1;
                    return false;
                }
            }
        }
        let points = clipped.as_ref().map_or(points, |w| &w.points);
        let (w, h) = (view.width as f64, view.height as f64);
        self.screen.clear();
        self.screen.extend(points.iter().map(|&p| {
            let (x, y) = view.project(p);
            (x.clamp(0.0, w), y.clamp(0.0, h))
        }));
        let n = self.screen.len();
        let twice_area: f64 = (0..n)
            .map(|i| {
                let (a, b) = (self.screen[i], self.screen[(i + 1) % n]);
                a.0 * b.1 - b.0 * a.1
            })
            .sum();
        if twice_area.abs() < 1e-9 {
            self.stats.clipped_away += 1;
            return false;
        }
        // Seen clockwise on screen (positive area with y down), edges going down are on the right.
        let clockwise = twice_area > 0.0;
        let index = self.surfaces.len() as u32;
        let before = self.edges.len();
        for i in 0..n {
            let (a, b) = (self.screen[i], self.screen[(i + 1) % n]);
            let down = b.1 > a.1;
            let (top, bottom) = if down { (a, b) } else { (b, a) };
            let y_first = (top.1 - 0.5).ceil() as i32;
            let y_last = (bottom.1 - 0.5).ceil() as i32 - 1;
            if y_last < y_first {
                continue;
            }
            let dxdy = (bottom.0 - top.0) / (bottom.1 - top.1);
            self.edges.push(Edge {
                x: top.0 + (y_first as f64 + 0.5 - top.1) * dxdy,
                dxdy,
                y_first,
                y_last,
                surface: index,
                leading: down != clockwise,
            });
        }
        if self.edges.len() == before {
            return false;
        }
        self.surfaces.push(surface);
        true
    }

    /// Walk the edges scanline by scanline and produce the spans, grouped by surface.
    pub fn scan(&mut self, width: usize, height: usize) {
        self.edges.sort_by_key(|e| e.y_first);
        self.stats.edges = self.edges.len();
        self.raw_spans.clear();
        let mut span_state = vec![0i32; self.surfaces.len()];
        let mut active: Vec<Edge> = Vec::new();
        let mut stack: Vec<u32> = Vec::new();
        let mut next = 0;
        for y in 0..height as i32 {
            while next < self.edges.len() && self.edges[next].y_first <= y {
                active.push(self.edges[next]);
                next += 1;
            }
            // Nearly sorted from the last scanline: insertion sort, trailing before leading.
            for i in 1..active.len() {
                let mut j = i;
                while j > 0 && edge_before(&active[j], &active[j - 1]) {
                    active.swap(j, j - 1);
                    j -= 1;
                }
            }
            stack.clear();
            stack.push(BACKGROUND);
            let mut span_x = 0u32;
            let yc = y as f64 + 0.5;
            for e in &active {
                let px = ((e.x - 0.5).ceil().max(0.0) as u32).min(width as u32);
                let s = e.surface;
                let state = &mut span_state[s as usize];
                if e.leading {
                    *state += 1;
                    if *state != 1 {
                        continue;
                    }
                    let xc = px as f64 + 0.5;
                    let mut at = stack.len();
                    while at > 1 && self.in_front(stack[at - 1], s, xc, yc) {
                        at -= 1;
                    }
                    if at == stack.len() {
                        let top = stack[at - 1];
                        self.emit(top, y, span_x, px);
                        span_x = px;
                    }
                    stack.insert(at, s);
                } else {
                    *state -= 1;
                    if *state != 0 {
                        continue;
                    }
                    let Some(at) = stack.iter().rposition(|&t| t == s) else {
                        continue;
                    };
                    if at == stack.len() - 1 {
                        self.emit(s, y, span_x, px);
                        span_x = px;
                    }
                    stack.remove(at);
                }
            }
            debug_assert_eq!(stack.len(), 1, "unbalanced edges on scanline {y}");
            let top = *stack.last().unwrap_or(&BACKGROUND);
            self.emit(top, y, span_x, width as u32);
            active.retain_mut(|e| {
                e.x += e.dxdy;
                e.y_last > y
            });
        }
        self.group_spans();
    }

    fn in_front(&self, a: u32, b: u32, x: f64, y: f64) -> bool {
        let (sa, sb) = (&self.surfaces[a as usize], &self.surfaces[b as usize]);
        sa.key < sb.key
            || (sa.key == sb.key && sa.inverse_depth.at(x, y) > sb.inverse_depth.at(x, y))
    }

    #[inline]
    fn emit(&mut self, surface: u32, y: i32, x0: u32, x1: u32) {
        if x1 > x0 {
            self.raw_spans.push((
                surface,
                Span {
                    y: y as u32,
                    x0,
                    x1,
                },
            ));
        }
    }

    /// Counting sort of the spans by surface, keeping scanline order within each.
    fn group_spans(&mut self) {
        let n = self.surfaces.len();
        self.span_start.clear();
        self.span_start.resize(n + 1, 0);
        for (s, _) in &self.raw_spans {
            self.span_start[*s as usize + 1] += 1;
        }
        for i in 0..n {
            self.span_start[i + 1] += self.span_start[i];
        }
        let mut cursor: Vec<u32> = self.span_start[..n].to_vec();
        self.spans.clear();
        self.spans
            .resize(self.raw_spans.len(), Span { y: 0, x0: 0, x1: 0 });
        for (s, span) in &self.raw_spans {
            let c = &mut cursor[*s as usize];
            self.spans[*c as usize] = *span;
            *c += 1;
        }
        self.stats.spans = self.spans.len();
    }

    pub fn spans_of(&self, surface: usize) -> &[Span] {
        &self.spans[self.span_start[surface] as usize..self.span_start[surface + 1] as usize]
    }
}

fn edge_before(a: &Edge, b: &Edge) -> bool {
    a.x < b.x || (a.x == b.x && !a.leading && b.leading)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use proptest::prelude::*;
    use quake_formats::geom::Plane;

    fn view() -> View {
        Camera {
            origin: DVec3::ZERO,
            angles: [0.0; 3],
            width: 64,
            height: 48,
            fov_x: 90.0,
        }
        .view()
    }

    /// A square facing the eye at distance `x`, spanning y in [y0, y1] and z in [z0, z1]
    /// (clockwise seen from the eye).
    fn wall(x: f64, y0: f64, y1: f64, z0: f64, z1: f64) -> Vec<DVec3> {
        vec![
            DVec3::new(x, y1, z1),
            DVec3::new(x, y0, z1),
            DVec3::new(x, y0, z0),
            DVec3::new(x, y1, z0),
        ]
    }

    fn surface(v: &View, face: u32, key: u32, x: f64) -> SpanSurface {
        let plane = Plane::new(DVec3::new(-1.0, 0.0, 0.0), -x);
        SpanSurface {
            face,
            key,
            inverse_depth: v.inverse_depth(&plane).expect("not edge-on"),
        }
    }

    /// Which face covers each pixel (`u32::MAX` for the background); panics when a pixel is
    /// covered twice or not at all.
    fn coverage(list: &EdgeList, w: usize, h: usize) -> Vec<u32> {
        let mut owner: Vec<Option<u32>> = vec![None; w * h];
        for s in 0..list.surfaces.len() {
            for span in list.spans_of(s) {
                for x in span.x0..span.x1 {
                    let px = &mut owner[span.y as usize * w + x as usize];
                    assert!(px.is_none(), "pixel ({x}, {}) drawn twice", span.y);
                    *px = Some(list.surfaces[s].face);
                }
            }
        }
        owner
            .iter()
            .map(|o| o.expect("every pixel drawn"))
            .collect()
    }

    #[test]
    fn nearer_key_wins_and_every_pixel_is_drawn_once() {
        let v = view();
        let mut list = EdgeList::default();
        list.begin();
        // Far wall covering the whole view, near square in the middle; near has the smaller key.
        assert!(list.add_polygon(
            &v,
            &wall(100.0, -200.0, 200.0, -200.0, 200.0),
            0b1111,
            surface(&v, 1, 5, 100.0)
        ));
        assert!(list.add_polygon(
            &v,
            &wall(50.0, -10.0, 10.0, -10.0, 10.0),
            0,
            surface(&v, 2, 1, 50.0)
        ));
        list.scan(64, 48);
        let owner = coverage(&list, 64, 48);
        assert_eq!(owner[24 * 64 + 32], 2);
        assert_eq!(owner[0], 1);
        // The near square spans x in [25.6, 38.4] on screen: pixel centres 26.5 ..= 37.5.
        let row: Vec<usize> = (0..64).filter(|&x| owner[24 * 64 + x] == 2).collect();
        assert_eq!(row, (26..38).collect::<Vec<_>>());
    }

    #[test]
    fn equal_keys_sort_by_depth() {
        let v = view();
        let mut list = EdgeList::default();
        list.begin();
        assert!(list.add_polygon(
            &v,
            &wall(50.0, -10.0, 10.0, -10.0, 10.0),
            0,
            surface(&v, 2, 3, 50.0)
        ));
        assert!(list.add_polygon(
            &v,
            &wall(40.0, -5.0, 5.0, -5.0, 5.0),
            0,
            surface(&v, 3, 3, 40.0)
        ));
        list.scan(64, 48);
        let owner = coverage(&list, 64, 48);
        assert_eq!(owner[24 * 64 + 32], 3);
    }

    #[test]
    fn neighbours_sharing_an_edge_leave_no_crack() {
        let v = view();
        let mut list = EdgeList::default();
        list.begin();
        // Two walls meeting at y = 3.3 (a slanted shared edge after projection would do too).
        assert!(list.add_polygon(
            &v,
            &wall(30.0, 3.3, 100.0, -100.0, 100.0),
            0b1111,
            surface(&v, 1, 0, 30.0)
        ));
        assert!(list.add_polygon(
            &v,
            &wall(30.0, -100.0, 3.3, -100.0, 100.0),
            0b1111,
            surface(&v, 2, 0, 30.0)
        ));
        list.scan(64, 48);
        let owner = coverage(&list, 64, 48);
        assert!(
            owner.iter().all(|&o| o == 1 || o == 2),
            "background showed through"
        );
    }

    #[test]
    fn polygons_behind_the_eye_are_dropped() {
        let v = view();
        let mut list = EdgeList::default();
        list.begin();
        assert!(!list.add_polygon(
            &v,
            &wall(-10.0, -5.0, 5.0, -5.0, 5.0),
            0b1111,
            surface(&v, 1, 0, -10.0)
        ));
        list.scan(64, 48);
        assert!(coverage(&list, 64, 48).iter().all(|&o| o == u32::MAX));
    }

    proptest::proptest! {
        /// Random fronto-parallel rectangles with distinct keys: every pixel is drawn once, by
        /// the nearest-keyed rectangle whose projection covers its centre (or the background).
        #[test]
        fn spans_partition_the_screen_by_key(
            rects in proptest::collection::vec(
                (10.0f64..200.0, -80.0f64..80.0, 1.0f64..60.0, -80.0f64..80.0, 1.0f64..60.0),
                1..8,
            ),
            keys in Just(()).prop_perturb(|_, mut rng| {
                let mut k: Vec<u32> = (0..8).collect();
                for i in (1..k.len()).rev() {
                    k.swap(i, (rng.next_u32() as usize) % (i + 1));
                }
                k
            }),
        ) {
            let v = view();
            let mut list = EdgeList::default();
            list.begin();
            let mut screen_rects = Vec::new();
            for (i, &(d, y0, dy, z0, dz)) in rects.iter().enumerate() {
                let pts = wall(d, y0, y0 + dy, z0, z0 + dz);
                list.add_polygon(&v, &pts, 0b1111, surface(&v, i as u32, keys[i], d));
                let (xa, ya) = v.project(DVec3::new(d, y0 + dy, z0 + dz));
                let (xb, yb) = v.project(DVec3::new(d, y0, z0));
                screen_rects.push((xa, ya, xb, yb, keys[i], i as u32));
            }
            list.scan(64, 48);
            let owner = coverage(&list, 64, 48);
            for py in 0..48 {
                for px in 0..64 {
                    let (cx, cy) = (px as f64 + 0.5, py as f64 + 0.5);
                    let near_edge = screen_rects.iter().any(|r| {
                        [r.0 - cx, r.2 - cx, r.1 - cy, r.3 - cy].iter().any(|d| d.abs() < 1e-6)
                    });
                    if near_edge {
                        continue;
                    }
                    let want = screen_rects
                        .iter()
                        .filter(|r| r.0 <= cx && cx < r.2 && r.1 <= cy && cy < r.3)
                        .min_by_key(|r| r.4)
                        .map_or(u32::MAX, |r| r.5);
                    proptest::prop_assert_eq!(owner[py * 64 + px], want, "pixel ({}, {})", px, py);
                }
            }
        }
    }
}
