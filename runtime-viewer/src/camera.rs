//! The camera in Quake's conventions and the view it makes: basis vectors, projection, frustum
//! and the screen-linear forms that perspective texture mapping is built from.
//!
//! Axes: x forward at yaw 0, y left, z up; yaw turns counter-clockwise seen from above; positive
//! pitch looks down. Pixel (i, j) covers [i, i+1) x [j, j+1); its centre is (i + 0.5, j + 0.5).

use glam::DVec3;
use quake_formats::geom::DVec3Ext;
use quake_formats::geom::Plane;

/// Anything nearer than this (map units along the view axis) is clipped away.
pub const NEAR_CLIP: f64 = 0.5;

/// Where the eye is, where it looks and the picture it makes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// The eye's position in map units.
    pub origin: DVec3,
    /// Pitch, yaw, roll in degrees.
    pub angles: [f64; 3],
    /// Picture width in pixels.
    pub width: usize,
    /// Picture height in pixels.
    pub height: usize,
    /// Horizontal field of view in degrees.
    pub fov_x: f64,
}

/// `c + dx * x + dy * y` over screen coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ScreenLinear {
    pub c: f64,
    pub dx: f64,
    pub dy: f64,
}

impl ScreenLinear {
    #[inline]
    pub fn at(&self, x: f64, y: f64) -> f64 {
        self.c + self.dx * x + self.dy * y
    }

    pub fn scaled(&self, k: f64) -> ScreenLinear {
        ScreenLinear {
            c: self.c * k,
            dx: self.dx * k,
            dy: self.dy * k,
        }
    }

    pub fn plus(&self, o: &ScreenLinear) -> ScreenLinear {
        ScreenLinear {
            c: self.c + o.c,
            dx: self.dx + o.dx,
            dy: self.dy + o.dy,
        }
    }
}

/// Quake's forward, right and up vectors for pitch/yaw/roll in degrees.
pub fn angle_vectors(angles: [f64; 3]) -> (DVec3, DVec3, DVec3) {
    let [p, y, r] = angles.map(f64::to_radians);
    let (sp, cp) = p.sin_cos();
    let (sy, cy) = y.sin_cos();
    let (sr, cr) = r.sin_cos();
    let forward = DVec3::new(cp * cy, cp * sy, -sp);
    let right = DVec3::new(-sr * sp * cy + cr * sy, -sr * sp * sy - cr * cy, -sr * cp);
    let up = DVec3::new(cr * sp * cy + sr * sy, cr * sp * sy - sr * cy, cr * cp);
    (forward, right, up)
}

/// Everything derived from a camera for one frame.
#[derive(Debug, Clone)]
pub struct View {
    pub origin: DVec3,
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub width: usize,
    pub height: usize,
    /// Pixels per unit of x/z (and y/z) at the screen centre.
    pub scale: f64,
    pub center: (f64, f64),
    /// Left, right, top, bottom planes through the eye, facing inwards.
    pub frustum: [Plane; 4],
    pub near: Plane,
}

impl Camera {
    pub(crate) fn view(&self) -> View {
        let (forward, right, up) = angle_vectors(self.angles);
        let w = self.width as f64;
        let h = self.height as f64;
        let scale = (w / 2.0) / (self.fov_x.to_radians() / 2.0).tan();
        let center = (w / 2.0, h / 2.0);
        let side = |n: DVec3| {
            let n = n.normalized().unwrap_or(forward);
            Plane::new(n, n.dot(self.origin))
        };
        let (ax, ay) = (center.0 / scale, center.1 / scale);
        let frustum = [
            side(right + forward * ax),
            side(-right + forward * ax),
            side(-up + forward * ay),
            side(up + forward * ay),
        ];
        let near = Plane::new(forward, forward.dot(self.origin) + NEAR_CLIP);
        View {
            origin: self.origin,
            forward,
            right,
            up,
            width: self.width,
            height: self.height,
            scale,
            center,
            frustum,
            near,
        }
    }
}

impl View {
    /// The ray direction through screen point (x, y), with unit depth along `forward`.
    pub fn ray(&self, x: f64, y: f64) -> DVec3 {
        self.forward + self.right * ((x - self.center.0) / self.scale)
            - self.up * ((y - self.center.1) / self.scale)
    }

    /// `ray(x, y) · v` as a screen-linear form.
    pub fn ray_dot(&self, v: DVec3) -> ScreenLinear {
        let (r, u) = (self.right.dot(v) / self.scale, self.up.dot(v) / self.scale);
        ScreenLinear {
            c: self.forward.dot(v) - r * self.center.0 + u * self.center.1,
            dx: r,
            dy: -u,
        }
    }

    /// Depth of `p` along the view axis.
    pub fn depth(&self, p: DVec3) -> f64 {
        self.forward.dot(p - self.origin)
    }

    /// Screen position of a point in front of the eye.
    pub fn project(&self, p: DVec3) -> (f64, f64) {
        let d = p - self.origin;
        let z = self.forward.dot(d);
        (
            self.center.0 + self.scale * self.right.dot(d) / z,
            self.center.1 - self.scale * self.up.dot(d) / z,
        )
    }

    /// 1/z over the screen for points on `plane`; `None` when the eye is (nearly) on it.
    pub fn inverse_depth(&self, plane: &Plane) -> Option<ScreenLinear> {
        let denom = plane.dist - plane.normal.dot(self.origin);
        (denom.abs() > 1e-9).then(|| self.ray_dot(plane.normal).scaled(1.0 / denom))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(angles: [f64; 3]) -> View {
        Camera {
            origin: DVec3::new(10.0, 20.0, 30.0),
            angles,
            width: 320,
            height: 200,
            fov_x: 90.0,
        }
        .view()
    }

    #[test]
    fn quake_axes() {
        let (f, r, u) = angle_vectors([0.0, 0.0, 0.0]);
        assert!(f.near(DVec3::new(1.0, 0.0, 0.0), 1e-12));
        assert!(r.near(DVec3::new(0.0, -1.0, 0.0), 1e-12));
        assert!(u.near(DVec3::new(0.0, 0.0, 1.0), 1e-12));
        let (f, _, _) = angle_vectors([0.0, 90.0, 0.0]);
        assert!(
            f.near(DVec3::new(0.0, 1.0, 0.0), 1e-12),
            "yaw turns counter-clockwise"
        );
        let (f, _, _) = angle_vectors([30.0, 0.0, 0.0]);
        assert!(f.z < 0.0, "positive pitch looks down");
    }

    #[test]
    fn projection_and_rays_agree() {
        let v = cam([10.0, 37.0, 5.0]);
        let p = v.origin + v.ray(100.5, 40.25) * 55.0;
        let (x, y) = v.project(p);
        assert!((x - 100.5).abs() < 1e-9 && (y - 40.25).abs() < 1e-9);
        assert!((v.depth(p) - 55.0).abs() < 1e-9);
        let centre = v.origin + v.forward * 10.0;
        let (x, y) = v.project(centre);
        assert!((x - 160.0).abs() < 1e-9 && (y - 100.0).abs() < 1e-9);
    }

    #[test]
    fn frustum_contains_the_screen_and_nothing_else() {
        let v = cam([0.0, 0.0, 0.0]);
        for (x, y, inside) in [
            (0.01, 0.01, true),
            (319.99, 199.99, true),
            (-1.0, 100.0, false),
            (160.0, 201.0, false),
        ] {
            let p = v.origin + v.ray(x, y) * 100.0;
            let all_in = v.frustum.iter().all(|pl| pl.distance(p) >= 0.0);
            assert_eq!(all_in, inside, "({x}, {y})");
        }
    }

    #[test]
    fn inverse_depth_is_linear_on_screen() {
        let v = cam([5.0, 20.0, 0.0]);
        let plane = Plane::new(DVec3::new(1.0, 0.0, 0.0), 300.0);
        let izi = v.inverse_depth(&plane).expect("not edge-on");
        for (x, y) in [(3.5, 7.5), (160.5, 100.5), (300.0, 190.0)] {
            let d = v.ray(x, y);
            let t = (plane.dist - plane.normal.dot(v.origin)) / plane.normal.dot(d);
            assert!((izi.at(x, y) - 1.0 / t).abs() < 1e-12);
        }
    }
}
