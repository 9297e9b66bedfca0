//! Noclip flight for the interactive window: held keys and mouse movement turned into camera
//! motion. Kept apart from the window itself so it is tested without a display.

use glam::DVec3;
use quake_formats::geom::DVec3Ext;

use crate::camera::{Camera, angle_vectors};

/// Units per second (Quake's running speed), and how much faster with the fast key held.
pub const FLY_SPEED: f64 = 320.0;
pub const FAST_FACTOR: f64 = 3.0;
/// Degrees of turn per pixel of mouse movement.
pub const MOUSE_DEGREES_PER_PIXEL: f64 = 0.25;
/// Degrees per second when turning with the arrow keys.
pub const KEY_TURN_SPEED: f64 = 140.0;
/// Pitch stays short of straight up or down, where yaw would lose its meaning.
pub const MAX_PITCH: f64 = 89.0;

/// What the player is doing this frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FlyInput {
    pub forward: bool,
    pub back: bool,
    pub left: bool,
    pub right: bool,
    pub up: bool,
    pub down: bool,
    pub fast: bool,
    /// Arrow keys: turn left / right, look up / down.
    pub turn_left: bool,
    pub turn_right: bool,
    pub look_up: bool,
    pub look_down: bool,
    /// Mouse movement since the last frame in pixels (x to the right, y downwards).
    pub mouse: (f64, f64),
}

fn axis(positive: bool, negative: bool) -> f64 {
    f64::from(u8::from(positive)) - f64::from(u8::from(negative))
}

/// Move and turn `camera` for `dt` seconds of `input`: movement follows the view direction
/// (pitch included, as noclip does), up and down follow the world's z axis.
pub fn fly(camera: &mut Camera, input: &FlyInput, dt: f64) {
    let [pitch, yaw, roll] = camera.angles;
    let key_yaw = axis(input.turn_left, input.turn_right) * KEY_TURN_SPEED * dt;
    let key_pitch = axis(input.look_down, input.look_up) * KEY_TURN_SPEED * dt;
    let yaw = (yaw - input.mouse.0 * MOUSE_DEGREES_PER_PIXEL + key_yaw).rem_euclid(360.0);
    let pitch =
        (pitch + input.mouse.1 * MOUSE_DEGREES_PER_PIXEL + key_pitch).clamp(-MAX_PITCH, MAX_PITCH);
    camera.angles = [pitch, yaw, roll];

    let (forward, right, _) = angle_vectors(camera.angles);
    let up = DVec3::new(0.0, 0.0, 1.0);
    let wish = forward * axis(input.forward, input.back)
        + right * axis(input.right, input.left)
        + up * axis(input.up, input.down);
    let Some(direction) = wish.normalized() else {
        return;
    };
    let speed = if input.fast {
        FLY_SPEED * FAST_FACTOR
    } else {
        FLY_SPEED
    };
    camera.origin += direction * (speed * dt);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            origin: DVec3::new(10.0, 20.0, 30.0),
            angles: [0.0, 90.0, 0.0],
            width: 64,
            height: 48,
            fov_x: 90.0,
        }
    }

    #[test]
    fn forward_follows_the_view_and_strafing_is_sideways() {
        let mut c = camera();
        let input = FlyInput {
            forward: true,
            ..FlyInput::default()
        };
        fly(&mut c, &input, 0.5);
        // Yaw 90 looks along +y.
        assert!(
            c.origin.near(DVec3::new(10.0, 180.0, 30.0), 1e-9),
            "{:?}",
            c.origin
        );
        let mut c = camera();
        let input = FlyInput {
            right: true,
            up: true,
            fast: true,
            ..FlyInput::default()
        };
        fly(&mut c, &input, 1.0);
        let d = FLY_SPEED * FAST_FACTOR / 2f64.sqrt();
        assert!(
            c.origin.near(DVec3::new(10.0 + d, 20.0, 30.0 + d), 1e-9),
            "{:?}",
            c.origin
        );
    }

    #[test]
    fn opposite_keys_cancel_and_idle_stays_put() {
        let mut c = camera();
        let input = FlyInput {
            forward: true,
            back: true,
            ..FlyInput::default()
        };
        fly(&mut c, &input, 1.0);
        assert_eq!(c.origin, camera().origin);
        assert_eq!(c.angles, camera().angles);
    }

    #[test]
    fn mouse_turns_and_pitch_is_clamped() {
        let mut c = camera();
        let input = FlyInput {
            mouse: (40.0, 1000.0),
            ..FlyInput::default()
        };
        fly(&mut c, &input, 0.01);
        // Mouse right turns right (yaw decreases); mouse down looks down (pitch increases).
        assert_eq!(c.angles, [MAX_PITCH, 80.0, 0.0]);
        let input = FlyInput {
            turn_left: true,
            look_up: true,
            ..FlyInput::default()
        };
        fly(&mut c, &input, 1.0);
        assert_eq!(
            c.angles,
            [MAX_PITCH - KEY_TURN_SPEED, 80.0 + KEY_TURN_SPEED, 0.0]
        );
    }
}
