//! Mouse and keyboard state and how it moves the [`Rig`]: orbit / pan / zoom to cursor / roll
//! in orbit mode, WASD + R/F flying and mouse look in fly mode, with optional inertia.

use glam::{Vec2, Vec3};
use winit::event::{ElementState, MouseButton};
use winit::keyboard::KeyCode;

use super::rig::Rig;

/// Time constant of inertia (s): after a release the motion decays as `exp(−t / τ)`.
const INERTIA_TAU: f32 = 0.15;
/// A drag that paused this long before the release leaves no inertia (s).
const RELEASE_PAUSE: f32 = 0.06;
/// Time over which the drag rate is averaged for the release velocity (s).
const SPIN_AVERAGING: f32 = 0.05;
/// Fastest inertial turn (rad/s).
const MAX_SPIN: f32 = 2.0 * std::f32::consts::PI;
/// Wheel zoom per notch (closer).
const ZOOM_STEP: f32 = 0.85;
/// Roll speed (rad/s) of Q/E.
const ROLL_SPEED: f32 = 1.0;

/// Orbit or fly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Orbit around the pivot (the default).
    Orbit,
    /// First-person flying.
    Fly,
}

/// Keys held for continuous motion.
#[derive(Debug, Default, Clone, Copy)]
struct Held {
    w: bool,
    a: bool,
    s: bool,
    d: bool,
    r: bool,
    f: bool,
    q: bool,
    e: bool,
    shift: bool,
}

/// The input state.
#[derive(Debug)]
pub struct Controls {
    /// Orbit or fly.
    pub mode: Mode,
    /// Whether motion continues and decays after input stops.
    pub inertia: bool,
    /// Fly speed (world units per second; Shift ×4), set from the scene's size.
    pub fly_speed: f32,
    held: Held,
    left: bool,
    pan: bool,
    cursor: Vec2,
    /// Mouse motion (px) since the last frame, for the left and the pan buttons.
    drag: Vec2,
    pan_drag: Vec2,
    wheel: f32,
    /// Angular velocity (yaw, pitch) of orbit or look (rad/s) and fly velocity.
    spin: Vec2,
    velocity: Vec3,
    since_motion: f32,
}

impl Default for Controls {
    fn default() -> Self {
        Controls {
            mode: Mode::Orbit,
            inertia: true,
            fly_speed: 1.0,
            held: Held::default(),
            left: false,
            pan: false,
            cursor: Vec2::ZERO,
            drag: Vec2::ZERO,
            pan_drag: Vec2::ZERO,
            wheel: 0.0,
            spin: Vec2::ZERO,
            velocity: Vec3::ZERO,
            since_motion: 0.0,
        }
    }
}

impl Controls {
    /// The cursor moved to `pos` (image pixels: physical × --resolution-scale).
    pub fn cursor_moved(&mut self, pos: Vec2) {
        let d = pos - self.cursor;
        self.cursor = pos;
        if self.left {
            self.drag += d;
        }
        if self.pan {
            self.pan_drag += d;
        }
    }

    /// A mouse button changed.
    pub fn button(&mut self, button: MouseButton, state: ElementState) {
        let down = state == ElementState::Pressed;
        match button {
            MouseButton::Left => {
                // A press stops the spin; so does a release after a pause (or without inertia).
                if down || !self.inertia || self.since_motion > RELEASE_PAUSE {
                    self.spin = Vec2::ZERO;
                }
                self.left = down;
            }
            MouseButton::Right | MouseButton::Middle => self.pan = down,
            _ => {}
        }
    }

    /// The wheel turned by `notches` (positive: away from the user, i.e. closer).
    pub fn wheel(&mut self, notches: f32) {
        self.wheel += notches;
    }

    /// A movement key changed; `false` when the key is not one (for the command keys).
    pub fn key(&mut self, code: KeyCode, state: ElementState) -> bool {
        let down = state == ElementState::Pressed;
        let h = &mut self.held;
        let slot = match code {
            KeyCode::KeyW => &mut h.w,
            KeyCode::KeyA => &mut h.a,
            KeyCode::KeyS => &mut h.s,
            KeyCode::KeyD => &mut h.d,
            KeyCode::KeyR => &mut h.r,
            KeyCode::KeyF if self.mode == Mode::Fly => &mut h.f,
            KeyCode::KeyQ => &mut h.q,
            KeyCode::KeyE => &mut h.e,
            KeyCode::ShiftLeft | KeyCode::ShiftRight => &mut h.shift,
            _ => return false,
        };
        *slot = down;
        true
    }

    /// Stops every motion (after a jump to another camera).
    pub fn stop(&mut self) {
        self.spin = Vec2::ZERO;
        self.velocity = Vec3::ZERO;
        self.drag = Vec2::ZERO;
        self.pan_drag = Vec2::ZERO;
        self.wheel = 0.0;
    }

    /// Applies the input of the last `dt` seconds to `rig` for an image of `size` pixels;
    /// returns whether motion continues without new input (held keys, inertia).
    pub fn update(&mut self, rig: &mut Rig, dt: f32, size: (u32, u32)) -> bool {
        let dt = dt.clamp(1e-4, 0.1);
        let per_px = std::f32::consts::PI / size.1.max(1) as f32;
        let drag = std::mem::take(&mut self.drag);
        let pan = std::mem::take(&mut self.pan_drag);
        let wheel = std::mem::take(&mut self.wheel);
        if drag != Vec2::ZERO {
            self.since_motion = 0.0;
        } else {
            self.since_motion += dt;
        }
        // Mouse: orbit (drag right turns the content right, drag down raises the camera)
        // or look (drag up looks up).
        // (A drag is applied even when the button was released before this frame.)
        let turn = if drag != Vec2::ZERO {
            let t = Vec2::new(-drag.x, drag.y) * per_px;
            // The release velocity: the drag's rate averaged over the last ~50 ms (one big
            // jump in a short frame must not fling the camera around), at most MAX_SPIN.
            let a = 1.0 - (-dt / SPIN_AVERAGING).exp();
            let spin = self.spin + (t / dt - self.spin) * a;
            self.spin = if self.inertia {
                spin.clamp_length_max(MAX_SPIN)
            } else {
                Vec2::ZERO
            };
            t
        } else if self.left || !self.inertia {
            self.spin = Vec2::ZERO; // held still, or no inertia
            Vec2::ZERO
        } else {
            self.spin *= (-dt / INERTIA_TAU).exp();
            if self.spin.length() < 0.02 {
                self.spin = Vec2::ZERO;
            }
            self.spin * dt
        };
        match self.mode {
            Mode::Orbit => rig.orbit(turn.x, turn.y),
            Mode::Fly => rig.look(turn.x, -turn.y),
        }
        if pan != Vec2::ZERO {
            rig.pan(pan, size.1);
        }
        let h = self.held;
        let axis = |p: bool, n: bool| f32::from(u8::from(p)) - f32::from(u8::from(n));
        if wheel != 0.0 {
            match self.mode {
                Mode::Orbit => rig.zoom_at(ZOOM_STEP.powf(wheel), self.cursor, size.0, size.1),
                Mode::Fly => rig.translate(rig.forward() * wheel * 0.1 * self.fly_speed),
            }
        }
        let mut keys_move = false;
        match self.mode {
            Mode::Orbit => {
                let roll = axis(h.e, h.q);
                if roll != 0.0 {
                    rig.roll(roll * ROLL_SPEED * dt);
                    keys_move = true;
                }
            }
            Mode::Fly => {
                let dir = rig.forward() * axis(h.w, h.s)
                    + rig.right() * axis(h.d, h.a)
                    + rig.up * axis(h.r, h.f);
                let speed = self.fly_speed * if h.shift { 4.0 } else { 1.0 };
                let target = dir * speed;
                keys_move = dir != Vec3::ZERO;
                self.velocity = if self.inertia {
                    target + (self.velocity - target) * (-dt / INERTIA_TAU).exp()
                } else {
                    target
                };
                if !keys_move && self.velocity.length() < 1e-3 * self.fly_speed {
                    self.velocity = Vec3::ZERO;
                }
                rig.translate(self.velocity * dt);
            }
        }
        keys_move || self.spin != Vec2::ZERO || self.velocity != Vec3::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use splatgl::camera::Camera;

    fn rig() -> Rig {
        let cam = Camera::look_at(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y, 0.9, 320, 240);
        Rig::from_camera(&cam, Vec3::new(0.0, 1.0, 5.0).length(), Vec3::Y)
    }

    fn wrap(a: f32) -> f32 {
        (a + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI
    }

    /// One 30 px jump in a 1 ms frame, then release: the drag turns by exactly its pixels,
    /// inertia continues in the same direction but by at most `MAX_SPIN · τ`, and nothing
    /// without inertia.
    #[test]
    fn inertia_continues_a_drag_within_bounds() {
        for inertia in [true, false] {
            let (mut c, mut r) = (Controls::default(), rig());
            c.inertia = inertia;
            let (a0, _) = r.azimuth_distance();
            c.cursor_moved(Vec2::new(100.0, 100.0));
            c.button(MouseButton::Left, ElementState::Pressed);
            c.cursor_moved(Vec2::new(130.0, 100.0));
            c.update(&mut r, 0.001, (320, 240));
            c.button(MouseButton::Left, ElementState::Released);
            let (a1, _) = r.azimuth_distance();
            let drag = wrap(a1 - a0);
            assert!(
                (drag + 30.0 * std::f32::consts::PI / 240.0).abs() < 1e-4,
                "{drag}"
            );
            let mut still = true;
            for _ in 0..300 {
                still = !c.update(&mut r, 0.01, (320, 240));
            }
            let extra = wrap(r.azimuth_distance().0 - a1);
            assert!(still, "inertia stops");
            if inertia {
                assert!(
                    extra < 0.0 && -extra <= MAX_SPIN * INERTIA_TAU * 1.01,
                    "{extra}"
                );
            } else {
                assert_eq!(extra, 0.0);
            }
        }
    }
}
