//! The interactive window (cargo feature `window`): the renderer's frames shown live with noclip
//! flight. W/A/S/D move, Q/E or Space/Ctrl go up and down, Shift is faster, the arrow keys turn,
//! and dragging with a mouse button held looks around (minifb cannot capture the pointer, so
//! looking is by dragging). Esc or closing the window quits.
//!
//! The picture is rendered at the window's size, so resizing the window changes the resolution.

use std::time::{Duration, Instant};

use minifb::{Key, MouseButton, MouseMode, Window, WindowOptions};

use crate::camera::Camera;
use crate::error::{Result, ViewerError};
use crate::fly::{FlyInput, fly};
use crate::render::{Frame, Renderer};
use crate::world::World;

/// Longest step the flight takes in one frame, so a stall does not throw the camera far.
const MAX_STEP: f64 = 0.1;
/// How often the title's frame rate and position are refreshed.
const TITLE_INTERVAL: Duration = Duration::from_millis(500);

/// What a session in the window amounted to.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WindowSummary {
    pub frames: u64,
    pub seconds: f64,
    /// Where the camera ended up, to resume with `--pos` and `--angles`.
    pub origin: [f64; 3],
    pub angles: [f64; 3],
}

fn window_error(error: minifb::Error) -> ViewerError {
    ViewerError::Window(error.to_string())
}

fn read_input(window: &Window, last_mouse: &mut Option<(f32, f32)>) -> FlyInput {
    let down = |keys: &[Key]| keys.iter().any(|&k| window.is_key_down(k));
    let dragging =
        window.get_mouse_down(MouseButton::Left) || window.get_mouse_down(MouseButton::Right);
    let mouse = window.get_mouse_pos(MouseMode::Pass);
    let moved = match (dragging, *last_mouse, mouse) {
        (true, Some(a), Some(b)) => ((b.0 - a.0) as f64, (b.1 - a.1) as f64),
        _ => (0.0, 0.0),
    };
    *last_mouse = mouse;
    FlyInput {
        forward: down(&[Key::W]),
        back: down(&[Key::S]),
        left: down(&[Key::A]),
        right: down(&[Key::D]),
        up: down(&[Key::E, Key::Space]),
        down: down(&[Key::Q, Key::LeftCtrl, Key::RightCtrl]),
        fast: down(&[Key::LeftShift, Key::RightShift]),
        turn_left: down(&[Key::Left]),
        turn_right: down(&[Key::Right]),
        look_up: down(&[Key::Up]),
        look_down: down(&[Key::Down]),
        mouse: moved,
    }
}

/// Open a window titled after `name` at the camera's size and fly through `world` until the
/// user quits. The renderer's clock (light styles, liquids) runs in real time from where the
/// renderer's options set it.
pub fn run_window(
    world: &World,
    renderer: &mut Renderer,
    mut camera: Camera,
    name: &str,
) -> Result<WindowSummary> {
    let options = WindowOptions {
        resize: true,
        ..WindowOptions::default()
    };
    let mut window =
        Window::new(name, camera.width, camera.height, options).map_err(window_error)?;
    // Render as fast as the machine allows; the frame rate is what the title reports.
    window.set_target_fps(0);
    let mut frame = Frame::new(camera.width, camera.height);
    let start_time = renderer.options.time;
    let start = Instant::now();
    let mut last = start;
    let mut last_title = start;
    let mut last_mouse = None;
    let (mut frames, mut frames_since_title) = (0u64, 0u32);
    while window.is_open() && !window.is_key_down(Key::Escape) {
        let now = Instant::now();
        let dt = (now - last).as_secs_f64().min(MAX_STEP);
        last = now;
        let input = read_input(&window, &mut last_mouse);
        fly(&mut camera, &input, dt);
        let (width, height) = window.get_size();
        if width > 0 && height > 0 {
            (camera.width, camera.height) = (width, height);
        }
        renderer.options.time = start_time + (now - start).as_secs_f64();
        let stats = renderer.render(world, &camera, &mut frame);
        window
            .update_with_buffer(&frame.pixels, frame.width, frame.height)
            .map_err(window_error)?;
        frames += 1;
        frames_since_title += 1;
        if now - last_title >= TITLE_INTERVAL {
            let fps = f64::from(frames_since_title) / (now - last_title).as_secs_f64();
            let o = camera.origin;
            window.set_title(&format!(
                "{name} - {fps:.0} fps at {}x{} - ({:.0} {:.0} {:.0}) - cache hits {:.0}%",
                camera.width,
                camera.height,
                o.x,
                o.y,
                o.z,
                stats.cache.hit_rate() * 100.0
            ));
            last_title = now;
            frames_since_title = 0;
        }
    }
    Ok(WindowSummary {
        frames,
        seconds: start.elapsed().as_secs_f64(),
        origin: camera.origin.to_array(),
        angles: camera.angles,
    })
}
