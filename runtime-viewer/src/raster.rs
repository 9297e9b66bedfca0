//! Drawing spans: perspective-correct texture coordinates computed exactly every `step` pixels
//! and interpolated linearly in between (Quake's every-16-pixels divide; step 1 is exact).

use crate::camera::{ScreenLinear, View};
use crate::edges::Span;
use crate::surface_cache::LitSurface;
use crate::world::Surface;

/// Texture coordinates over the screen for one surface: u/z, v/z and 1/z are screen-linear.
#[derive(Debug, Clone, Copy)]
pub struct TexMapping {
    pub inverse_depth: ScreenLinear,
    pub u_over_z: ScreenLinear,
    pub v_over_z: ScreenLinear,
    /// Coordinates are clamped to [0, size) (16.16 fixed point upper bounds).
    pub u_limit: i32,
    pub v_limit: i32,
}

impl TexMapping {
    /// Source texel (u, v) = ((s, t) - base) / 2^mip over a `size`-texel source.
    pub fn new(
        view: &View,
        surface: &Surface,
        inverse_depth: ScreenLinear,
        base: [i32; 2],
        mip: usize,
        size: (usize, usize),
    ) -> TexMapping {
        let o = view.origin;
        let k = 1.0 / (1 << mip) as f64;
        // s/z = (s_axis·o + s_offset - base) / z + s_axis·ray.
        let axis = |axis, offset: f64, base: i32| {
            view.ray_dot(axis)
                .plus(&inverse_depth.scaled(offset - base as f64))
                .scaled(k)
        };
        let fixed_limit = |n: usize| ((n.min(32767) as i32) << 16) - 1;
        TexMapping {
            inverse_depth,
            u_over_z: axis(
                surface.s_axis,
                surface.s_axis.dot(o) + surface.s_offset,
                base[0],
            ),
            v_over_z: axis(
                surface.t_axis,
                surface.t_axis.dot(o) + surface.t_offset,
                base[1],
            ),
            u_limit: fixed_limit(size.0),
            v_limit: fixed_limit(size.1),
        }
    }

    /// The mapping onto a surface-cache entry built at `mip` (its texel (0, 0) is `tex_mins`).
    pub fn onto_lit_surface(
        view: &View,
        surface: &Surface,
        inverse_depth: ScreenLinear,
        mip: usize,
        lit: &LitSurface,
    ) -> TexMapping {
        let base = surface.extents.tex_mins;
        TexMapping::new(
            view,
            surface,
            inverse_depth,
            base,
            mip,
            (lit.width, lit.height),
        )
    }

    /// Exact (u, v) in 16.16 fixed point at the centre of pixel (x, y), clamped to the source.
    #[inline]
    pub fn exact(&self, x: u32, y: u32) -> (i32, i32) {
        let (xc, yc) = (x as f64 + 0.5, y as f64 + 0.5);
        let z = 1.0 / self.inverse_depth.at(xc, yc).max(1e-12);
        let fixed = |v: f64, limit: i32| ((v * z * 65536.0).clamp(0.0, limit as f64)) as i32;
        (
            fixed(self.u_over_z.at(xc, yc), self.u_limit),
            fixed(self.v_over_z.at(xc, yc), self.v_limit),
        )
    }
}

/// Draw `spans` into `pixels` (rows of `width`), fetching colours with `fetch(u, v)` (integer
/// texels of the source).
pub fn draw_spans<F: Fn(i32, i32) -> u32>(
    pixels: &mut [u32],
    width: usize,
    spans: &[Span],
    map: &TexMapping,
    step: u32,
    fetch: F,
) {
    for_each_segment(spans, map, step, |seg| {
        let row = seg.y as usize * width;
        let (mut u, mut v) = (seg.u, seg.v);
        for px in &mut pixels[row + seg.x as usize..row + (seg.x + seg.len) as usize] {
            *px = fetch(u >> 16, v >> 16);
            u += seg.du;
            v += seg.dv;
        }
    });
}

/// Up to `step` pixels of a span whose texel coordinates (16.16 fixed point) are interpolated
/// linearly: pixel `x + k` shows `((u + k du) >> 16, (v + k dv) >> 16)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Segment {
    pub y: u32,
    pub x: u32,
    pub len: u32,
    pub u: i32,
    pub v: i32,
    pub du: i32,
    pub dv: i32,
}

/// Cut `spans` into segments of `step` pixels with exact texel coordinates at their ends.
#[inline]
pub fn for_each_segment<F: FnMut(Segment)>(
    spans: &[Span],
    map: &TexMapping,
    step: u32,
    mut visit: F,
) {
    let step = step.max(1);
    for span in spans {
        let mut x = span.x0;
        let (mut u, mut v) = map.exact(x, span.y);
        while x < span.x1 {
            let n = (span.x1 - x).min(step);
            // Interpolate towards the next segment's start, or the span's last pixel.
            let (next, divisor) = if x + n < span.x1 {
                (map.exact(x + n, span.y), n as i32)
            } else if n > 1 {
                (map.exact(span.x1 - 1, span.y), n as i32 - 1)
            } else {
                ((u, v), 1)
            };
            visit(Segment {
                y: span.y,
                x,
                len: n,
                u,
                v,
                du: (next.0 - u) / divisor,
                dv: (next.1 - v) / divisor,
            });
            (u, v) = next;
            x += n;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use glam::DVec3;
    use quake_formats::extents::LightmapExtents;
    use quake_formats::geom::Plane;

    fn floor_view() -> (View, Surface) {
        let view = Camera {
            origin: DVec3::new(0.0, 0.0, 50.0),
            angles: [30.0, 10.0, 0.0],
            width: 128,
            height: 64,
            fov_x: 90.0,
        }
        .view();
        let surface = Surface {
            plane: Plane::new(DVec3::new(0.0, 0.0, 1.0), 0.0),
            points: vec![],
            s_axis: DVec3::new(1.0, 0.0, 0.0),
            s_offset: 0.0,
            t_axis: DVec3::new(0.0, -1.0, 0.0),
            t_offset: 0.0,
            texture: 0,
            kind: crate::textures::TextureKind::Lit,
            extents: LightmapExtents {
                tex_mins: [0, 0],
                extents: [0, 0],
            },
            styles: [0, 255, 255, 255],
            light: None,
            free_lightmap: None,
        };
        (view, surface)
    }

    #[test]
    fn step_one_matches_the_exact_mapping_and_larger_steps_stay_close() {
        let (view, surface) = floor_view();
        let izi = view.inverse_depth(&surface.plane).expect("not edge-on");
        let base = [-4096, -4096];
        let map = TexMapping::new(&view, &surface, izi, base, 0, (8192, 8192));
        let spans = [Span {
            y: 50,
            x0: 3,
            x1: 120,
        }];
        let draw = |step| {
            let mut px = vec![0u32; 128 * 64];
            draw_spans(&mut px, 128, &spans, &map, step, |u, v| {
                ((u as u32) << 16) | v as u32
            });
            px
        };
        let exact = draw(1);
        for x in 3..120u32 {
            // The true texel under the pixel centre, by ray intersection.
            let d = view.ray(x as f64 + 0.5, 50.5);
            let p = view.origin + d * (-view.origin.z / d.z);
            let (s, t) = surface.st(p);
            let want =
                (((s - base[0] as f64).floor() as u32) << 16) | (t - base[1] as f64).floor() as u32;
            assert_eq!(exact[50 * 128 + x as usize], want, "pixel {x}");
        }
        for step in [8, 16, 32] {
            let approx = draw(step);
            for x in 3..120usize {
                let (a, b) = (exact[50 * 128 + x], approx[50 * 128 + x]);
                let du = ((a >> 16) as i32 - (b >> 16) as i32).abs();
                let dv = ((a & 0xffff) as i32 - (b & 0xffff) as i32).abs();
                assert!(du <= 2 && dv <= 2, "step {step} pixel {x}: {du} {dv}");
            }
        }
    }
}
