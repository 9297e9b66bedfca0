//! The mottle of `_minlight_mottle`: a smooth noise of 0 to [`MOTTLE_LEVELS`] light units fixed in
//! the world, added to a mottled minimum light so that a surface lit by nothing else shows a
//! soft, blotchy pattern instead of one flat level (Quake II's tools' look).
//!
//! Value noise: each corner of a lattice of [`MOTTLE_CELL`]-unit cubes gets a value from a hash
//! of its coordinates, and a point mixes the eight corners of its cube trilinearly, so the
//! pattern is continuous across faces and does not change with the lightmap's scale.

use glam::DVec3;

/// The most the mottle adds, in light units.
pub const MOTTLE_LEVELS: f64 = 48.0;

/// Edge of the lattice's cubes, in map units.
pub const MOTTLE_CELL: f64 = 16.0;

/// The mottle at `point`: 0 to [`MOTTLE_LEVELS`].
pub fn mottle(point: DVec3) -> f64 {
    let cell = point / MOTTLE_CELL;
    let base = cell.floor();
    let f = cell - base;
    let [x, y, z] = base.to_array().map(|c| c as i64);
    let corner = |dx: i64, dy: i64, dz: i64| corner_value(x + dx, y + dy, z + dz);
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let plane = |dz: i64| {
        let near = lerp(corner(0, 0, dz), corner(1, 0, dz), f.x);
        let far = lerp(corner(0, 1, dz), corner(1, 1, dz), f.x);
        lerp(near, far, f.y)
    };
    lerp(plane(0), plane(1), f.z) / 255.0 * MOTTLE_LEVELS
}

/// A lattice corner's value, 0 to 255: its coordinates hashed (murmur3's finaliser spreads
/// every bit of them over the result).
fn corner_value(x: i64, y: i64, z: i64) -> f64 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ (z as u32).wrapping_mul(0xcb1a_b31f);
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^= h >> 16;
    f64::from(h & 0xff)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn lattice_corners_take_their_own_values_and_vary() {
        let at =
            |x: i64, y: i64, z: i64| mottle(DVec3::new(x as f64, y as f64, z as f64) * MOTTLE_CELL);
        let values: Vec<f64> = (-8..8).map(|i| at(i, 2 * i, -i)).collect();
        for (i, v) in (-8..8).zip(&values) {
            assert_eq!(*v, corner_value(i, 2 * i, -i) / 255.0 * MOTTLE_LEVELS);
        }
        let spread = values.iter().cloned().fold(f64::MIN, f64::max)
            - values.iter().cloned().fold(f64::MAX, f64::min);
        assert!(spread > MOTTLE_LEVELS / 2.0, "{values:?}");
    }

    proptest! {
        /// Within range everywhere, and continuous: points a tenth of a unit apart differ by
        /// little (a cell's slope is at most its 48 levels over 16 units, on each of 3 axes).
        #[test]
        fn the_mottle_is_bounded_and_smooth(
            x in -5000.0..5000.0f64, y in -5000.0..5000.0f64, z in -5000.0..5000.0f64,
            d in prop::array::uniform3(-0.1..0.1f64),
        ) {
            let p = DVec3::new(x, y, z);
            let (a, b) = (mottle(p), mottle(p + DVec3::from(d)));
            prop_assert!((0.0..=MOTTLE_LEVELS).contains(&a));
            prop_assert!((a - b).abs() <= 3.0 * 0.1 * MOTTLE_LEVELS / MOTTLE_CELL + 1e-9);
        }
    }
}
