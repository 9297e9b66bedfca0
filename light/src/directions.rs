//! Directions on the sphere: a `mangle`'s unit vector, a basis around a normal, and evenly spread
//! directions over a cap (sun penumbrae, sky domes) or points through a ball (`_deviance`).
//! All deterministic, so results depend on neither threads nor run.

use glam::DVec3;
use quake_formats::geom::DVec3Ext;

/// Unit vector of a "yaw pitch roll" triple (degrees; pitch 90 is up).
pub fn mangle_to_vec(yaw: f64, pitch: f64) -> DVec3 {
    let (y, p) = (yaw.to_radians(), pitch.to_radians());
    DVec3::new(y.cos() * p.cos(), y.sin() * p.cos(), p.sin())
}

/// Two unit vectors that make a right-handed orthonormal basis with unit `n`.
pub fn tangent_basis(n: DVec3) -> [DVec3; 2] {
    let helper = if n.z.abs() < 0.9 {
        DVec3::new(0.0, 0.0, 1.0)
    } else {
        DVec3::new(1.0, 0.0, 0.0)
    };
    let u = helper.cross(n).normalized().unwrap_or(helper);
    [u, n.cross(u)]
}

/// `n` unit directions spread evenly (a Fibonacci spiral) over the cap of
/// half-angle `half_angle_deg` around unit `center`; `[center]` for `n <= 1`
/// or a zero cap. Deterministic.
pub fn cap_directions(center: DVec3, half_angle_deg: f64, n: usize) -> Vec<DVec3> {
    if n <= 1 || half_angle_deg <= 0.0 {
        return vec![center];
    }
    let [u, v] = tangent_basis(center);
    let cos_cap = half_angle_deg.min(180.0).to_radians().cos();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            // Uniform in z is uniform in solid angle.
            let z = 1.0 - (1.0 - cos_cap) * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            u * (r * phi.cos()) + v * (r * phi.sin()) + center * z
        })
        .collect()
}

/// `count` points spread evenly through the ball of `radius` around
/// `center` (deterministic: a Fibonacci spiral over shells of equal volume).
pub fn ball_points(center: DVec3, radius: f64, count: usize) -> Vec<DVec3> {
    let dirs = cap_directions(DVec3::new(0.0, 0.0, 1.0), 180.0, count);
    dirs.into_iter()
        .enumerate()
        .map(|(i, d)| {
            // Radius by the cube root of an evenly spaced volume fraction,
            // scrambled by the golden ratio so shells do not line up with the spiral.
            let fraction = ((i as f64 + 0.5) * 0.618_033_988_749_895).fract();
            center + d * (radius * fraction.cbrt())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mangle_points_where_documented() {
        let v = mangle_to_vec(0.0, -90.0);
        assert!(v.near(DVec3::new(0.0, 0.0, -1.0), 1e-12));
        let v = mangle_to_vec(90.0, 0.0);
        assert!(v.near(DVec3::new(0.0, 1.0, 0.0), 1e-12));
    }

    #[test]
    fn cap_directions_stay_in_the_cap_and_are_unit() {
        let c = DVec3::new(0.0, 0.6, 0.8);
        let dirs = cap_directions(c, 10.0, 50);
        assert_eq!(dirs.len(), 50);
        for d in &dirs {
            assert!((d.length() - 1.0).abs() < 1e-9);
            assert!(d.dot(c) >= 10f64.to_radians().cos() - 1e-9);
        }
        let hemi = cap_directions(DVec3::new(0.0, 0.0, 1.0), 90.0, 200);
        let mean_z: f64 = hemi.iter().map(|d| d.z).sum::<f64>() / 200.0;
        assert!((mean_z - 0.5).abs() < 0.01, "uniform hemisphere: {mean_z}");
    }
}
