//! What light assignment needs to know about the camera: view transform, projection scale,
//! near/far, frame size; and the conversions between pixels, depth and view space.
//!
//! View space is right-handed with the camera looking down -z; "view distance" `w = -z`.

use super::{Camera, PointLight};
use glam::{Mat4, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct ViewSetup {
    pub view: Mat4,
    /// proj[0][0] and proj[1][1]: x_ndc = p00 * x / w, y_ndc = p11 * y / w.
    pub p00: f32,
    pub p11: f32,
    pub near: f32,
    pub far: f32,
    pub width: u32,
    pub height: u32,
}

/// A light in view space.
#[derive(Clone, Copy, Debug)]
pub struct ViewLight {
    pub center: Vec3,
    pub radius: f32,
}

impl ViewSetup {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let proj = camera.proj(width as f32 / height as f32);
        ViewSetup {
            view: camera.view(),
            p00: proj.x_axis.x,
            p11: proj.y_axis.y,
            near: camera.near,
            far: camera.far,
            width,
            height,
        }
    }

    pub fn to_view(&self, l: &PointLight) -> ViewLight {
        ViewLight {
            center: self.view.transform_point3(l.position),
            radius: l.range,
        }
    }

    /// View distance of a [0, 1] depth-buffer value (inverse of the projection's depth).
    pub fn view_distance(&self, ndc_depth: f32) -> f32 {
        let r = self.far / (self.near - self.far);
        r * self.near / (ndc_depth + r)
    }

    /// View-space position of the sample at the centre of pixel (x, y) at view distance `w`.
    pub fn sample_position(&self, x: u32, y: u32, w: f32) -> Vec3 {
        let ndc_x = (x as f32 + 0.5) / self.width as f32 * 2.0 - 1.0;
        let ndc_y = 1.0 - (y as f32 + 0.5) / self.height as f32 * 2.0;
        Vec3::new(ndc_x / self.p00 * w, ndc_y / self.p11 * w, -w)
    }
}
