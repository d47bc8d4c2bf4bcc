//! Perspective camera and the camera path of an animation.
//!
//! Conventions: right-handed world, y up; view space looks down -z; clip depth is reversed-Z
//! in WebGPU's [0, 1] (near maps to 1, far to 0: `crate::depth`).

use glam::{Mat4, Vec3, Vec4};

/// A perspective camera at one frame: where it is, what it looks at, and its frustum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Position of the eye, in world space.
    pub eye: Vec3,
    /// World-space point the camera looks at (the view direction is `target - eye`).
    pub target: Vec3,
    /// World-space up direction; need not be unit length or orthogonal to the view direction.
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// Distance to the near plane along the view direction, in scene units; maps to depth 1.
    pub near: f32,
    /// Distance to the far plane along the view direction, in scene units; maps to depth 0.
    pub far: f32,
}

impl Camera {
    /// Refuse a camera no view can be built from: non-finite values, the eye on its target,
    /// `up` along the view direction, a field of view outside (0, π), or planes that
    /// `depth::check_planes` refuses.
    pub fn validate(&self) -> crate::error::Result<()> {
        let bad = |why: String| Err(crate::error::Error::invalid("camera", why));
        let vectors = [self.eye, self.target, self.up];
        if !(vectors.iter().all(|v| v.is_finite()) && self.fov_y.is_finite()) {
            return bad(format!(
                "needs finite values; eye {}, target {}, up {}, fov_y {}",
                self.eye, self.target, self.up, self.fov_y
            ));
        }
        let forward = self.target - self.eye;
        if forward.length_squared() == 0.0 || forward.cross(self.up).length_squared() == 0.0 {
            return bad(format!(
                "eye {} to target {} with up {} gives no view direction",
                self.eye, self.target, self.up
            ));
        }
        if !(self.fov_y > 0.0 && self.fov_y < std::f32::consts::PI) {
            return bad(format!(
                "field of view {} rad is not between 0 and π",
                self.fov_y
            ));
        }
        crate::depth::check_planes(self.near, self.far)
    }

    /// World space to view space (for files: the glTF export's camera node).
    pub fn view(&self) -> Mat4 {
        self.rotation() * Mat4::from_translation(-self.eye)
    }

    /// Camera-relative space to view space: [`Self::view`] without the translation. The
    /// renderer draws and shades in camera-relative space (world positions minus the eye),
    /// so a scene far from the origin loses no precision to a large translation in f32.
    pub fn rotation(&self) -> Mat4 {
        let f = (self.target - self.eye).normalize();
        let s = f.cross(self.up).normalize();
        let u = s.cross(f);
        Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::W,
        )
    }

    /// Right-handed reversed-Z perspective: depth 1 at `near` and 0 at `far`
    /// (`depth = A / w - B`, `crate::depth`).
    pub fn proj(&self, aspect: f32) -> Mat4 {
        let h = 1.0 / (self.fov_y * 0.5).tan();
        let w = h / aspect;
        let (a, b) = crate::depth::coefficients(self.near, self.far);
        // clip.z = b z + a, clip.w = -z: depth = a / w - b for w = -z.
        Mat4::from_cols(
            Vec4::new(w, 0.0, 0.0, 0.0),
            Vec4::new(0.0, h, 0.0, 0.0),
            Vec4::new(0.0, 0.0, b, -1.0),
            Vec4::new(0.0, 0.0, a, 0.0),
        )
    }
}

/// Keyframed eye/target positions, interpolated with a Catmull-Rom spline so the camera moves
/// without stopping at keys.
#[derive(Clone, Debug)]
pub struct CameraPath {
    /// (frame, eye, target), frames increasing.
    pub keys: Vec<(u32, Vec3, Vec3)>,
    /// The camera's up at each key, interpolated as the eyes and targets are; empty for +y
    /// throughout (the catalog's cameras). A file's camera keeps its roll this way, and one
    /// looking straight up or down its orientation.
    pub ups: Vec<Vec3>,
    /// Vertical field of view in radians, the same at every frame.
    pub fov_y: f32,
    /// Near-plane distance in scene units, the same at every frame.
    pub near: f32,
    /// Far-plane distance in scene units, the same at every frame.
    pub far: f32,
}

fn catmull_rom(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3, t: f32) -> Vec3 {
    let t2 = t * t;
    let t3 = t2 * t;
    0.5 * ((2.0 * p1)
        + (p2 - p0) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3)
}

impl CameraPath {
    /// A camera that does not move.
    pub fn fixed(eye: Vec3, target: Vec3, fov_y_deg: f32, near: f32, far: f32) -> Self {
        CameraPath {
            keys: vec![(0, eye, target)],
            ups: Vec::new(),
            fov_y: fov_y_deg.to_radians(),
            near,
            far,
        }
    }

    /// Number of frames the path spans (last key frame + 1).
    pub fn frame_count(&self) -> u32 {
        self.keys.last().map_or(1, |k| k.0 + 1)
    }

    /// The camera at `frame`: eye, target and up interpolated between the keys around it,
    /// held at the first or last key outside them.
    pub fn at(&self, frame: u32) -> Camera {
        let n = self.keys.len();
        let seg = self
            .keys
            .windows(2)
            .position(|w| frame >= w[0].0 && frame <= w[1].0);
        let ups = self.ups.len() == n;
        let up_at = |k: usize| if ups { self.ups[k] } else { Vec3::Y };
        let (eye, target, up) = match seg {
            None => {
                let k = if frame < self.keys[0].0 { 0 } else { n - 1 };
                (self.keys[k].1, self.keys[k].2, up_at(k))
            }
            Some(i) => {
                let (f1, f2) = (self.keys[i].0, self.keys[i + 1].0);
                let t = (frame - f1) as f32 / (f2 - f1).max(1) as f32;
                let k = |j: isize| self.keys[j.clamp(0, n as isize - 1) as usize];
                let (a, b, c, d) = (
                    k(i as isize - 1),
                    k(i as isize),
                    k(i as isize + 1),
                    k(i as isize + 2),
                );
                let j = |d: isize| (i as isize + d).clamp(0, n as isize - 1) as usize;
                let up = catmull_rom(up_at(j(-1)), up_at(j(0)), up_at(j(1)), up_at(j(2)), t);
                (
                    catmull_rom(a.1, b.1, c.1, d.1, t),
                    catmull_rom(a.2, b.2, c.2, d.2, t),
                    up.try_normalize().unwrap_or(up_at(j(0))),
                )
            }
        };
        Camera {
            eye,
            target,
            up,
            fov_y: self.fov_y,
            near: self.near,
            far: self.far,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_camera_no_view_can_be_built_from_is_refused_with_the_reason() {
        let good = Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y: 1.0,
            near: 0.05,
            far: 1e6,
        };
        good.validate().unwrap();
        let cases = [
            (
                Camera {
                    eye: Vec3::NAN,
                    ..good
                },
                "needs finite values",
            ),
            (
                Camera {
                    up: Vec3::new(0.0, f32::INFINITY, 0.0),
                    ..good
                },
                "needs finite values",
            ),
            (
                Camera {
                    fov_y: f32::NAN,
                    ..good
                },
                "needs finite values",
            ),
            (
                Camera {
                    target: good.eye,
                    ..good
                },
                "no view direction",
            ),
            (
                Camera {
                    up: good.target - good.eye,
                    ..good
                },
                "no view direction",
            ),
            (
                Camera {
                    up: Vec3::ZERO,
                    ..good
                },
                "no view direction",
            ),
            (Camera { fov_y: 0.0, ..good }, "not between 0 and"),
            (
                Camera {
                    fov_y: -1.0,
                    ..good
                },
                "not between 0 and",
            ),
            (
                Camera {
                    fov_y: std::f32::consts::PI,
                    ..good
                },
                "not between 0 and",
            ),
            (Camera { near: 0.0, ..good }, "0 < near < far"),
            (
                Camera {
                    far: f32::INFINITY,
                    ..good
                },
                "0 < near < far",
            ),
        ];
        for (camera, want) in cases {
            let e = camera.validate().unwrap_err().to_string();
            assert!(e.contains(want), "{camera:?}: {e}");
        }
    }
}
