//! The fly camera: a position, a yaw and a pitch, moved by WASD (+ Q/E down/up) at a speed in
//! scene units per second and turned by mouse drags. It starts where the scene's own camera
//! is, so leaving the camera path does not jump.

use glam::Vec3;
use lightgrid::scene::Camera;

/// Radians per pixel of mouse drag.
pub const TURN_PER_PIXEL: f32 = 0.004;
/// Pitch stays this far from straight up or down (the view's up vector is +y).
const PITCH_LIMIT: f32 = 1.55;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    pub eye: Vec3,
    /// Around +y, 0 looking down -z.
    pub yaw: f32,
    /// Above the horizon, radians.
    pub pitch: f32,
    /// Scene units per second.
    pub speed: f32,
}

/// Which movement keys are held: forward/back, right/left, up/down, each -1, 0 or 1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Movement {
    pub forward: f32,
    pub right: f32,
    pub up: f32,
}

impl Movement {
    pub fn is_still(&self) -> bool {
        self.forward == 0.0 && self.right == 0.0 && self.up == 0.0
    }
}

impl FlyCamera {
    /// At `camera`'s eye, looking where it looks; `speed` from the scene's extent (a tenth
    /// of its far plane per second).
    pub fn from_camera(camera: &Camera) -> FlyCamera {
        let d = (camera.target - camera.eye).normalize_or(Vec3::NEG_Z);
        FlyCamera {
            eye: camera.eye,
            yaw: (-d.x).atan2(-d.z),
            pitch: d.y.clamp(-1.0, 1.0).asin().clamp(-PITCH_LIMIT, PITCH_LIMIT),
            speed: (camera.far * 0.1).clamp(0.1, 1000.0),
        }
    }

    /// The unit view direction.
    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(-sy * cp, sp, -cy * cp)
    }

    /// Move by `m` for `dt` seconds (right is horizontal, up is world +y).
    pub fn advance(&mut self, m: Movement, dt: f32) {
        if !dt.is_finite() || dt <= 0.0 {
            return;
        }
        let f = self.forward();
        let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
        let v = f * m.forward + right * m.right + Vec3::Y * m.up;
        if v.length_squared() > 0.0 {
            self.eye += v.normalize() * self.speed * dt;
        }
    }

    /// Turn by a mouse drag of (dx, dy) pixels (right and down positive).
    pub fn turn(&mut self, dx: f32, dy: f32) {
        if !(dx.is_finite() && dy.is_finite()) {
            return;
        }
        self.yaw -= dx * TURN_PER_PIXEL;
        self.pitch = (self.pitch - dy * TURN_PER_PIXEL).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// The camera to render with, keeping `lens`' field of view and planes.
    pub fn camera(&self, lens: &Camera) -> Camera {
        Camera {
            eye: self.eye,
            target: self.eye + self.forward(),
            up: Vec3::Y,
            ..*lens
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(eye: Vec3, target: Vec3) -> Camera {
        Camera {
            eye,
            target,
            up: Vec3::Y,
            fov_y: 1.0,
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn starts_looking_where_the_camera_looks() {
        for target in [
            Vec3::new(3.0, 1.0, -2.0),
            Vec3::new(-5.0, -2.0, 4.0),
            Vec3::new(0.0, 0.5, 9.0),
        ] {
            let c = cam(Vec3::new(1.0, 2.0, 3.0), target);
            let fly = FlyCamera::from_camera(&c);
            let want = (c.target - c.eye).normalize();
            assert!((fly.forward() - want).length() < 1e-4, "{target}");
            let again = fly.camera(&c);
            assert_eq!(again.eye, c.eye);
            assert!(((again.target - again.eye).normalize() - want).length() < 1e-4);
            assert_eq!((again.fov_y, again.near, again.far), (1.0, 0.1, 100.0));
        }
    }

    #[test]
    fn moves_at_its_speed_and_turns_within_limits() {
        let mut fly = FlyCamera::from_camera(&cam(Vec3::ZERO, Vec3::NEG_Z));
        fly.speed = 2.0;
        fly.advance(
            Movement {
                forward: 1.0,
                ..Default::default()
            },
            0.5,
        );
        assert!((fly.eye - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-5);
        fly.advance(
            Movement {
                right: 1.0,
                ..Default::default()
            },
            1.0,
        );
        assert!((fly.eye - Vec3::new(2.0, 0.0, -1.0)).length() < 1e-5);
        let before = fly.eye;
        fly.advance(Movement::default(), 1.0);
        fly.advance(
            Movement {
                forward: 1.0,
                ..Default::default()
            },
            f32::NAN,
        );
        assert_eq!(fly.eye, before);
        fly.turn(0.0, -1e6);
        assert!(fly.pitch <= PITCH_LIMIT && fly.forward().y > 0.99);
        fly.turn(f32::NAN, 1.0);
        assert!(fly.pitch.is_finite() && fly.yaw.is_finite());
    }
}
